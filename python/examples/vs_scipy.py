"""The paper's model with SciPy's `solve_ivp` (RK45 with an impact event and dense
output) and with `nonsmooth`, at equal error; prints the time ratio.

The model (the paper's cart, ω = 20.465 rad/s, on its chaotic attractor):
m ẍ + k x + c ẋ + T ẋ/√(ẋ² + ε²) + F_I(x, ẋ) = m₀e ω² sin ωt, with the contact
F_I = k_I (d^{3/2} + b d^{3/2} ẋ (ẋ² + η²)^{(n₃−1)/2}) for d = x − x_I > 0 (the crate's
law, written out in Python). Error: the RMS error of x at the 10 stroboscopic times
t_i = 2πi/ω from a state on the attractor, against `nonsmooth` at rtol = 1e-12. Time:
100 forcing periods with every impact located, median of 3 runs. `nonsmooth` runs at the
largest rtol whose error is at most SciPy's.

    python python/examples/vs_scipy.py [RTOL]     # SciPy's rtol, default 1e-8
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from typing import Any, Callable

import numpy as np
import numpy.typing as npt
from scipy.integrate import solve_ivp  # type: ignore[import-untyped]

import nonsmooth as ns

OMEGA = 20.465
F64 = npt.NDArray[np.float64]


def paper_rhs(cart: ns.System) -> Callable[[float, F64], tuple[float, float]]:
    p = cart.parameters
    m, k, c, t_fr, eps = p["m"], p["k"], p["c"], p["t"], p["eps"]
    k_i, b, n3, x_i, eta = p["k_i"], p["b"], p["n3"], p["x_i"], p["eta"]
    amp = p["m0e"] * OMEGA * OMEGA
    half = (n3 - 1.0) * 0.5
    sqrt, exp, log, sin = math.sqrt, math.exp, math.log, math.sin

    def rhs(t: float, y: F64) -> tuple[float, float]:
        x, v = y[0], y[1]
        total = k * x + c * v + t_fr * v / sqrt(v * v + eps * eps)
        d = x - x_i
        if d > 0.0:
            p1 = d * sqrt(d)
            f = p1 + b * p1 * (v * exp(half * log(v * v + eta * eta)))
            if f > 0.0:
                total += k_i * f
        return (v, (amp * sin(OMEGA * t) - total) / m)

    return rhs


def scipy_run(cart: ns.System, y0: F64, periods: int, rtol: float) -> Any:
    x_i = cart.parameters["x_i"]

    def impact(t: float, y: F64) -> float:
        return float(y[0] - x_i)

    impact.direction = 1.0  # type: ignore[attr-defined]
    t_end = periods * cart.period
    t_eval = cart.period * np.arange(1, periods + 1)
    t_eval[-1] = t_end
    return solve_ivp(paper_rhs(cart), (0.0, t_end), list(y0), method="RK45", t_eval=t_eval,
                     events=[impact], dense_output=True, rtol=rtol,
                     atol=[rtol * 1e-4, rtol * 1e-2])


def ns_run(cart: ns.System, y0: F64, periods: int, rtol: float) -> ns.Trajectory:
    t = cart.period * np.arange(1, periods + 1)
    t[-1] = periods * cart.period
    return ns.simulate(cart, (0.0, periods * cart.period), y0, t_eval=t, rtol=rtol)


def timed(f: Callable[[], Any], reps: int = 3) -> float:
    times = []
    for _ in range(reps):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    rtol = float(sys.argv[1]) if len(sys.argv) > 1 else 1e-8
    cart = ns.paper(OMEGA)
    y0 = ns.poincare(cart, 1, transient=100).end_state
    ref = ns_run(cart, y0, 10, 1e-12).y[:, 0]

    def rms(x: F64) -> float:
        return float(np.sqrt(np.mean((x - ref) ** 2)))

    sp = scipy_run(cart, y0, 10, rtol)
    err_sp = rms(sp.y[0])
    choice = None
    for r in (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11):
        e = rms(ns_run(cart, y0, 10, r).y[:, 0])
        if e <= err_sp:
            choice = (r, e)
            break
    if choice is None:
        raise SystemExit("no rtol of nonsmooth reaches SciPy's error")
    r_ns, err_ns = choice
    t_sp = timed(lambda: scipy_run(cart, y0, 100, rtol), reps=1 if rtol < 1e-9 else 3)
    t_ns = timed(lambda: ns_run(cart, y0, 100, r_ns))
    n_sp = len(scipy_run(cart, y0, 100, rtol).t_events[0])
    n_ns = len(ns_run(cart, y0, 100, r_ns).event_t)
    print(f"SciPy RK45  rtol {rtol:.0e}: RMS error of x {err_sp:.2e} m, 100 periods in "
          f"{t_sp:.3f} s ({n_sp} impacts)")
    print(f"nonsmooth   rtol {r_ns:.0e}: RMS error of x {err_ns:.2e} m, 100 periods in "
          f"{t_ns:.4f} s ({n_ns} impacts)")
    print(f"time ratio SciPy / nonsmooth at equal error: {t_sp / t_ns:.0f}x")


if __name__ == "__main__":
    main()
