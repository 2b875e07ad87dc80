"""Numbers against closed or exact forms: the relay feedback system's sliding orbit (its
period and Floquet multipliers against the exact piecewise-linear flow), the accumulation
time of a ball dropped on a rigid floor, and a described 2-DOF system against the same
system of the crate's catalogue."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

import nonsmooth as ns

F64 = npt.NDArray[np.float64]


class ExactRelay:
    """ẋ = A x + b u, u = −sgn(x₁), solved exactly piece by piece: the regions x₁ < 0
    (u = 1) and x₁ > 0 (u = −1) by the matrix exponential, sliding on x₁ = 0 (while
    |x₂| < 1, the equivalent control) by the sliding field A_s = A − b·(row 0 of A)/b₁."""

    def __init__(self, zeta: float = 0.05, omega: float = 25.0, sigma: float = 1.0):
        z, w = zeta, omega
        self.a = np.array([[-(2 * z * w + 1), 1, 0], [-(2 * z * w + w * w), 0, 1],
                           [-w * w, 0, 0]], dtype=float)
        self.b = np.array([1.0, -2 * sigma, 1.0])
        self.aib = np.linalg.solve(self.a, self.b)
        self.a_s = self.a - np.outer(self.b, self.a[0]) / self.b[0]

    @staticmethod
    def _expm(m: F64, t: float) -> F64:
        """e^{mt} by scaling and squaring of the Taylor series (the sliding field's matrix
        is defective: an eigendecomposition would not do)."""
        a = m * t
        norm = float(np.max(np.sum(np.abs(a), axis=1)))
        s = max(0, int(math.ceil(math.log2(norm))) + 1) if norm > 0 else 0
        a = a / 2.0**s
        term = np.eye(3)
        out = np.eye(3)
        for k in range(1, 25):
            term = term @ a / k
            out = out + term
        for _ in range(s):
            out = out @ out
        return out

    def flow(self, piece: str, x: F64, t: float) -> F64:
        if piece == "slide":
            return self._expm(self.a_s, t) @ x
        u = 1.0 if piece == "minus" else -1.0
        return self._expm(self.a, t) @ (x + self.aib * u) - self.aib * u

    @staticmethod
    def event(piece: str, x: F64) -> float:
        return float(x[0]) if piece != "slide" else 1.0 - abs(float(x[1]))

    def next_switch(self, piece: str, x: F64, horizon: float) -> float:
        """The first time the piece's event function changes sign (scan, then bisection)."""
        # The sign inside the piece (not of g at the start, which is 0 after a transition).
        g0 = -1.0 if piece == "minus" else 1.0
        dt, lo = 1e-3, 0.0
        k = 1
        while k * dt <= horizon + dt:
            hi = k * dt
            g = self.event(piece, self.flow(piece, x, hi))
            if g * g0 < 0 or (piece == "slide" and g < 0):
                a, b = lo, hi
                for _ in range(200):
                    m = 0.5 * (a + b)
                    if m <= a or m >= b:
                        break
                    gm = self.event(piece, self.flow(piece, x, m))
                    if (gm * g0 > 0) if piece != "slide" else (gm > 0):
                        a = m
                    else:
                        b = m
                return b
            lo = hi
            k += 1
        return math.inf

    def flow_for(self, x: F64, t_total: float) -> F64:
        """The exact flow over `t_total` from `x` (in a region, |x₁| > 0)."""
        piece = "minus" if x[0] < 0 else "plus"
        t = 0.0
        x = np.array(x, dtype=float)
        while True:
            ts = self.next_switch(piece, x, t_total - t)
            if t + ts >= t_total:
                return self.flow(piece, x, t_total - t)
            x = self.flow(piece, x, ts)
            t += ts
            if piece == "slide":
                piece = "plus" if x[1] > 0 else "minus"
            else:
                x[0] = 0.0
                piece = "slide" if abs(x[1]) < 1 else ("plus" if piece == "minus" else "minus")


def test_relay_orbit_period_and_multipliers_against_the_exact_flow() -> None:
    relay = ns.relay_feedback()
    run = ns.simulate(relay, (0.0, 40.0), dt=0.01, rtol=1e-12, atol=1e-14)
    # A start in the middle of a region piece (|x₁| well away from the switching surface).
    k = int(np.flatnonzero(np.abs(run.y[:, 0]) > 1e-3)[-1])
    assert run.transitions and any(t.kind == "sliding_entry" for t in run.transitions)
    # A period guess from the simulation: every second sliding entry after a long region
    # piece (the orbit is symmetric, seven sliding segments per half period).
    entries = [t.t for t in run.transitions if t.kind == "sliding_entry"]
    marks = [b for a, b in zip(entries, entries[1:]) if b - a > 1.0]
    guess = round(marks[-1] - marks[-3], 2)
    orbit = ns.periodic_orbit(relay, run.y[k], period=guess, rtol=1e-12)
    exact = ExactRelay()
    # The exact flow closes over the period found: the period is the exact one.
    back = exact.flow_for(orbit.state, orbit.period)
    assert np.max(np.abs(back - orbit.state)) < 1e-8, back - orbit.state
    # Exact monodromy: central differences of the exact period map, Richardson-extrapolated.
    def central(h: float) -> F64:
        d = np.zeros((3, 3))
        for j in range(3):
            e = np.zeros(3)
            e[j] = h
            d[:, j] = (exact.flow_for(orbit.state + e, orbit.period)
                       - exact.flow_for(orbit.state - e, orbit.period)) / (2 * h)
        return d
    h = 2.5e-7
    phi = (4 * central(0.5 * h) - central(h)) / 3
    mus_exact = sorted(np.linalg.eigvals(phi), key=lambda z: -abs(z))
    mus = orbit.multipliers
    for a, b in zip(mus, mus_exact):
        assert abs(a - b) < 1e-5, (mus, mus_exact)
    # The trivial multiplier 1 (an autonomous flow) and 0 (sliding collapses x₁).
    assert np.min(np.abs(mus - 1)) < 1e-6
    assert np.min(np.abs(mus)) < 1e-6
    assert orbit.stable


def test_zeno_ball_sticks_at_the_accumulation_time() -> None:
    # A unit mass dropped from h = 1 m onto a rigid floor with restitution r: the impacts
    # accumulate at t∞ = t₀(1 + r)/(1 − r), t₀ = √(2h/g). Gravity is a load −g·cos(ωt)
    # with ω = 10⁻¹² rad/s, constant to the last bit over the run.
    g, h, r = 9.81, 1.0, 0.5
    ball = ns.describe({
        "model": "mechanical",
        "masses": [1.0],
        "parameters": {"omega": 1e-12},
        "loads": [{"dof": 0, "amplitude": g, "phase": math.pi}],
        "surfaces": [{"dof": 0, "position": 0.0, "side": "lower", "restitution": r}],
    })
    run = ns.simulate(ball, (0.0, 4.0), [h, 0.0], rtol=1e-12, atol=1e-14)
    t0 = math.sqrt(2 * h / g)
    t_inf = t0 * (1 + r) / (1 - r)
    assert abs(run.event_t[0] - t0) < 1e-9
    assert len(run.stick_t) >= 1
    assert abs(run.stick_t[0] - t_inf) < 1e-6, (run.stick_t[0], t_inf)
    # Resting on the floor afterwards.
    assert abs(run.y_final[0]) < 1e-9 and abs(run.y_final[1]) < 1e-9
    # Impact times form the geometric sequence t₀ + 2rt₀(1 + r + … + r^{j−1}).
    n = min(10, len(run.event_t))
    want = [t0 + 2 * r * t0 * (1 - r**j) / (1 - r) for j in range(n)]
    assert np.allclose(run.event_t[:n], want, atol=1e-8)


def test_described_two_dof_equals_the_catalogue_system() -> None:
    p = ns.two_dof_impact(0.7).parameters
    described = ns.describe({
        "model": "mechanical",
        "masses": [p["m1"], p["m2"]],
        "parameters": {"omega": 0.7},
        "elements": [
            {"law": "linear_spring", "dof": 0, "k": p["k1"]},
            {"law": "viscous_damper", "dof": 0, "c": p["c1"]},
            {"law": "linear_spring", "between": [1, 0], "k": p["k2"]},
            {"law": "viscous_damper", "between": [1, 0], "c": p["c2"]},
            {"law": "hertz", "dof": 1, "position": p["gap"], "k": p["k_contact"],
             "b": p["b_contact"], "n3": 1.0},
        ],
        "loads": [{"dof": 0, "amplitude": p["force"]}],
        "surfaces": [{"dof": 1, "position": p["gap"]}],
    })
    assert described.dimension == 4
    a = ns.simulate(ns.two_dof_impact(0.7), (0.0, 60.0), dt=0.5, rtol=1e-11)
    b = ns.simulate(described, (0.0, 60.0), dt=0.5, rtol=1e-11)
    assert np.allclose(a.y, b.y, rtol=0, atol=1e-8), np.max(np.abs(a.y - b.y))
    assert len(a.event_t) == len(b.event_t) > 0
    assert np.allclose(a.event_t, b.event_t, atol=1e-8)
    sa = ns.poincare(ns.two_dof_impact(0.7), 20, transient=50, rtol=1e-10)
    sb = ns.poincare(described, 20, transient=50, rtol=1e-10)
    # Over 70 forcing periods on an attractor that is not periodic here, the difference of
    # the two rounding sequences (cos ωt against sin(ωt + π/2), the sums of the laws in
    # another order) grows to ~1e-6.
    assert sa.impacts == sb.impacts and sa.period == sb.period
    assert np.allclose(sa.poincare, sb.poincare, atol=1e-5)
