"""nonsmooth: dynamics of nonsmooth mechanical systems from Python.

The Rust crate ``nonsmooth`` (impacts, compliant Hertz contact, dry friction, Filippov
sliding, event-locating integrators, Poincaré sections, sweeps, Lyapunov exponents, the
Tsallis entropy index, periodic orbits and their continuation, studies) with numpy in and
out. Every right-hand side runs compiled: systems come from the catalogue
(:func:`paper`, :func:`duffing_ueda`, :func:`two_dof_impact`, :func:`bouncing_ball`,
:func:`relay_feedback`, :func:`belt_friction`, :func:`woodpecker`) or from a description in the study files' schema
(:func:`describe`, :func:`load`). Long calls release the GIL, use every core where the
crate does (sweeps, studies) and stop on Ctrl-C with ``KeyboardInterrupt``.

Errors: rejected input raises ``ValueError`` (or ``TypeError``) naming the value; a failed
run raises :class:`NonsmoothError` or one of its subclasses (:class:`ZenoError`,
:class:`WorkLimitError`, :class:`ConvergenceError`, :class:`IntegrationError`,
:class:`StudyError`) with the crate's message.
"""

from __future__ import annotations

import json
import math
import os
from typing import Any, Mapping, Optional, Union

import numpy as np
import numpy.typing as npt

from . import _checks as _c
from . import study
from ._nonsmooth import (
    ConvergenceError,
    IntegrationError,
    NonsmoothError,
    StudyError,
    System,
    WorkLimitError,
    ZenoError,
    __version__,
    belt_friction,
    bouncing_ball,
    duffing_ueda,
    paper,
    relay_feedback,
    two_dof_impact,
    woodpecker,
)
from . import _nonsmooth as _ext
from ._results import (
    Bifurcation,
    Branch,
    BranchPoint,
    EnsembleResult,
    EntropyIndex,
    Impacts,
    LyapunovEstimate,
    ModeChange,
    PeriodicOrbit,
    Section,
    Stats,
    SweepBranch,
    SweepResult,
    SweepTransition,
    Trajectory,
    TimeStepRun,
    Transition,
)

__all__ = [
    "System", "paper", "duffing_ueda", "two_dof_impact", "bouncing_ball", "relay_feedback", "belt_friction",
    "describe", "load", "simulate", "impacts", "poincare", "sweep", "lyapunov", "tsallis_q",
    "periodic_orbit", "continuation", "ensemble", "timestep", "study", "woodpecker",
    "Trajectory", "Impacts", "Section", "SweepResult", "SweepBranch", "SweepTransition",
    "LyapunovEstimate", "EntropyIndex", "PeriodicOrbit", "Branch", "BranchPoint",
    "Bifurcation", "Stats", "ModeChange", "Transition", "EnsembleResult", "TimeStepRun",
    "NonsmoothError", "ZenoError", "WorkLimitError", "ConvergenceError", "IntegrationError",
    "StudyError", "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]


def _non_finite_path(value: Any, path: str) -> Optional[str]:
    """The path of the first non-finite float in a nested description, if any."""
    if isinstance(value, float) and not math.isfinite(value):
        return path
    if isinstance(value, Mapping):
        for k, v in value.items():
            p = _non_finite_path(v, f"{path}.{k}")
            if p:
                return p
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            p = _non_finite_path(v, f"{path}[{i}]")
            if p:
                return p
    return None


def _parameters(parameters: Mapping[str, Any]) -> dict[str, float]:
    return {str(k): _c.number(f"parameter {k}", v) for k, v in parameters.items()}


def describe(description: Mapping[str, Any], **parameters: float) -> System:
    """A mechanical system from a description in the study files' schema (the ``system``
    table with ``model = "mechanical"``), as a dict.

    Keys: ``masses`` (one per degree of freedom, 1 to 4, kg or nondimensional),
    ``elements`` (each a ``law`` — ``linear_spring`` (``k``, ``x0``), ``viscous_damper``
    (``c``), ``cubic_spring`` (``k1``, ``k3``), ``hertz`` (``position``, ``k``, ``n1``,
    ``b``, ``n2``, ``n3``, ``side``), ``dry_friction`` (``t``, ``eps``) — on ``dof = i`` or
    ``between = [i, j]``, the coordinate ``q_i − q_j``), ``loads`` (``amplitude·cos(ωt +
    phase)`` on a ``dof``), ``surfaces`` (impact surfaces at ``position`` on a coordinate;
    with ``restitution`` a rigid stop with Newton's law) and ``parameters`` (``omega``, the
    forcing frequency in rad/s, is required; any name used as a value above). The state is
    ``(q_1 … q_N, q̇_1 … q̇_N)``. The equations are ``M q̈ + Σ_e F_e(c_e, ċ_e) ∂c_e/∂q =
    Σ_l f_l(t)``, every law compiled.

    Keyword arguments set parameters (over ``parameters`` of the description).

    Raises ``ValueError`` naming the field (``system.elements[2].law``) for a bad
    description.
    """
    if not isinstance(description, Mapping):
        raise TypeError(f"a description is a dict (got {type(description).__name__})")
    bad = _non_finite_path(description, "system")
    if bad:
        raise ValueError(f"`{bad}` must be finite")
    try:
        text = json.dumps(description, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ValueError(f"system description: {e}") from None
    return _ext.describe_json(text, _parameters(parameters))


def load(path: PathLike, **parameters: float) -> System:
    """A mechanical system from a TOML file: a ``system`` table in the study files' schema,
    or a whole study file (its ``[system]`` table); keyword arguments set parameters (a
    study's axis parameters, e.g. ``omega``, have no value in the file). See
    :func:`describe`."""
    with open(os.fspath(path), encoding="utf-8") as f:
        text = f.read()
    return _ext.describe_toml(text, _parameters(parameters))


def _y0(system: System, y0: Any) -> Optional[list[float]]:
    return None if y0 is None else _c.vector("y0", y0, system.dimension)


def _span(t_span: Any) -> tuple[float, float]:
    try:
        t0, t1 = t_span
    except (TypeError, ValueError):
        raise ValueError("t_span must be a pair (t0, t_end)") from None
    a, b = _c.number("t_span[0]", t0), _c.number("t_span[1]", t1)
    if not b > a:
        raise ValueError(f"t_span must have t_end > t0 (got {a}, {b})")
    return a, b


def simulate(
    system: System,
    t_span: tuple[float, float],
    y0: Optional[npt.ArrayLike] = None,
    *,
    t_eval: Optional[npt.ArrayLike] = None,
    dt: Optional[float] = None,
    rtol: float = 1e-8,
    atol: Union[None, float, npt.ArrayLike] = None,
    max_steps: int = 10_000_000,
    max_events: int = 1_000_000,
) -> Trajectory:
    """Integrates ``system`` over ``t_span = (t0, t_end)`` (s) from ``y0`` (default: the
    system's rest state) with DOPRI5 and event location.

    Samples: at ``t_eval`` (sorted, within the span) or on the grid ``t0 + i·dt``
    (computed from ``i``, never accumulated), interpolated on each step's dense output;
    none if neither is given. Every impact (a rising crossing of a surface's penetration,
    located on the dense output) is recorded with the state before and after its reset.
    A rigid stop runs through chattering and sticking (modes ``Free``/``Stuck``), a
    Filippov system through crossings and sliding.

    Tolerances: the local error of each component ``i`` is kept below
    ``atol_i + rtol·|y_i|``; ``atol`` defaults to ``rtol`` times the system's scales
    (for the paper's cart ``(1e-4 m, 1e-2 m/s)·rtol``).

    Raises ``WorkLimitError`` after ``max_steps`` steps, ``ZenoError`` for an
    accumulation of impacts the run cannot pass, ``ValueError`` for bad input.
    """
    t0, t1 = _span(t_span)
    r, a = _c.tolerances(rtol, atol, system.dimension)
    if t_eval is not None and dt is not None:
        raise ValueError("give t_eval or dt, not both")
    if dt is not None:
        h = _c.positive("dt", dt)
        n = math.floor((t1 - t0) / h * (1 + 1e-12)) + 1
        if n > _c.MAX_OUTPUT:
            raise ValueError(f"dt = {h} gives {n} samples; at most {_c.MAX_OUTPUT}")
        te = t0 + np.arange(n, dtype=np.float64) * h
        te = te[te <= t1]
    elif t_eval is not None:
        te = _c.array("t_eval", t_eval)
    else:
        te = np.zeros(0)
    d = _ext.simulate(
        system, t0, t1, _y0(system, y0), te, r, a,
        _c.integer("max_steps", max_steps, 1, 2**63 - 1),
        _c.integer("max_events", max_events, 0, _c.MAX_OUTPUT),
    )
    return Trajectory._from(d)


def impacts(
    system: System,
    t_span: tuple[float, float],
    y0: Optional[npt.ArrayLike] = None,
    *,
    record_from: Optional[float] = None,
    surface: int = 0,
    rtol: float = 1e-8,
    atol: Union[None, float, npt.ArrayLike] = None,
    max_steps: int = 10_000_000,
    capacity: int = 10_000_000,
) -> Impacts:
    """The inter-impact sequence on impact surface ``surface`` of a smooth system:
    impact times ``t_j`` (s) from ``record_from`` (default ``t0``) on, impact velocities
    (the penetration's rate at ``t_j``), intervals ``T_j = t_j − t_{j−1}`` (s).

    Raises ``ValueError`` for a system without that surface.
    """
    t0, t1 = _span(t_span)
    r, a = _c.tolerances(rtol, atol, system.dimension)
    rf = t0 if record_from is None else _c.number("record_from", record_from)
    d = _ext.impacts(
        system, t0, t1, _y0(system, y0), rf, _c.integer("surface", surface, 0, 3), r, a,
        _c.integer("max_steps", max_steps, 1, 2**63 - 1),
        _c.integer("capacity", capacity, 1, _c.MAX_OUTPUT),
    )
    return Impacts._from(d)


def poincare(
    system: System,
    periods: int,
    *,
    transient: int = 100,
    y0: Optional[npt.ArrayLike] = None,
    surface: int = 0,
    rtol: float = 1e-8,
    atol: Union[None, float, npt.ArrayLike] = None,
    period_tol: float = 1e-4,
    max_period: int = 16,
    max_steps: int = 10_000_000,
) -> Section:
    """The stroboscopic (Poincaré) section ``t_i = i·T``, ``T = 2π/ω``, of one run from
    ``y0`` at ``t = 0``: ``transient`` forcing periods are discarded, ``periods`` recorded,
    with the impacts on ``surface`` in the recorded window (their intervals and
    velocities), impacts per period and the detected period (the smallest ``p ≤
    max_period`` with ``|y_{i+p} − y_i| ≤ period_tol·scale`` over the window).

    The run is the crate's sweep point (``sweep::run_point``): its numbers are the Rust
    run's, bit for bit.
    """
    r, a = _c.tolerances(rtol, atol, system.dimension)
    d = _ext.poincare(
        system, _y0(system, y0), _c.integer("transient", transient),
        _c.integer("periods", periods, 1), _c.integer("surface", surface, 0, 3), r, a,
        _c.positive("period_tol", period_tol), _c.integer("max_period", max_period, 1),
        _c.integer("max_steps", max_steps, 1, 2**63 - 1),
    )
    return Section._from(d)


def sweep(
    system: System,
    parameter: str,
    values: npt.ArrayLike,
    *,
    direction: str = "both",
    continuation: bool = True,
    transient: tuple[int, int] = (100, 50),
    record: int = 50,
    y0: Optional[npt.ArrayLike] = None,
    surface: int = 0,
    rtol: float = 1e-8,
    atol: Union[None, float, npt.ArrayLike] = None,
    period_tol: float = 1e-4,
    max_period: int = 16,
    max_steps: int = 10_000_000,
    hysteresis_tol: float = 1e-3,
) -> SweepResult:
    """Sweeps ``parameter`` (``"omega"`` or any parameter of the system) over the strictly
    increasing ``values``: at each value ``transient[0]`` forcing periods (then
    ``transient[1]`` after each step) are discarded and ``record`` recorded, as in
    :func:`poincare`.

    With ``continuation`` each value starts from the previous value's end state (phase 0),
    following one attractor; ``direction="both"`` runs the up and down branches
    concurrently and reports where they differ (``hysteresis``: coexisting attractors).
    Without continuation every value starts from ``y0`` and the values run in parallel on
    every core. Results do not depend on the number of threads.
    """
    if not isinstance(parameter, str):
        raise TypeError("parameter must be a name (str)")
    v = _c.array("values", values, 10_000_000)
    if v.size == 0:
        raise ValueError("values is empty")
    if np.any(np.diff(v) <= 0):
        raise ValueError("values must be strictly increasing")
    if direction not in ("up", "down", "both"):
        raise ValueError(f"direction must be 'up', 'down' or 'both' (got {direction!r})")
    try:
        first, step = transient
    except (TypeError, ValueError):
        raise ValueError("transient must be a pair (first, per_step)") from None
    r, a = _c.tolerances(rtol, atol, system.dimension)
    d = _ext.sweep(
        system, parameter, v, direction, bool(continuation),
        _c.integer("transient[0]", first), _c.integer("transient[1]", step),
        _c.integer("record", record, 1), _y0(system, y0),
        _c.integer("surface", surface, 0, 3), r, a, _c.positive("period_tol", period_tol),
        _c.integer("max_period", max_period, 1),
        _c.integer("max_steps", max_steps, 1, 2**63 - 1),
        _c.positive("hysteresis_tol", hysteresis_tol),
    )
    return SweepResult._from(d)


def lyapunov(
    system: System,
    intervals: int,
    *,
    method: str = "two_trajectory",
    transient: int = 0,
    tau: Optional[float] = None,
    d0: Optional[float] = None,
    y0: Optional[npt.ArrayLike] = None,
    t0: float = 0.0,
    rtol: float = 1e-8,
    atol: Union[None, float, npt.ArrayLike] = None,
) -> LyapunovEstimate:
    """Lyapunov exponents (1/s) from ``y0`` at ``t0``, renormalized every ``tau`` seconds
    (default: the forcing period), ``transient`` intervals discarded, ``intervals``
    averaged.

    ``method="two_trajectory"`` (Benettin): a reference and a perturbed trajectory at
    separation ``d0`` in the weighted norm ``‖δ‖ = (Σ (δ_i/w_i)²)^{1/2}`` (``w`` =
    ``system.scales``), pulled back every interval,
    ``λ₁ ≈ (1/nτ) Σ ln(d_k/d0)``. Needs no Jacobian: it runs through resets (rigid
    stops, with the impact law applied to both trajectories) and sliding (Filippov
    systems). ``method="spectrum"``: the whole spectrum by the variational equations
    with QR re-orthonormalization (smooth systems; needs the model's Jacobian).
    """
    if method not in ("two_trajectory", "spectrum"):
        raise ValueError(f"method must be 'two_trajectory' or 'spectrum' (got {method!r})")
    r, a = _c.tolerances(rtol, atol, system.dimension)
    d = _ext.lyapunov(
        system, method, _y0(system, y0), _c.number("t0", t0),
        None if tau is None else _c.positive("tau", tau),
        _c.integer("transient", transient, 0, 100_000_000),
        _c.integer("intervals", intervals, 1, 100_000_000),
        None if d0 is None else _c.positive("d0", d0), r, a,
    )
    return LyapunovEstimate._from(d)


def tsallis_q(
    samples: npt.ArrayLike,
    lo: float,
    hi: float,
    step: float,
    *,
    q_range: Optional[tuple[float, float]] = None,
) -> EntropyIndex:
    """The entropy index ``q*`` of ``samples`` (e.g. inter-impact intervals, s): the
    histogram on ``[lo, hi)`` with bins of ``step`` gives probabilities ``p_i``; ``q*``
    maximizes the redundancy ``R(q) = 1 − S_q/S_q^max`` of the Tsallis entropy
    ``S_q = (1 − Σ p_i^q)/(q − 1)`` over ``q_range`` (default ``[0.05, 5]``).

    The paper's index: ``tsallis_q(section.intervals, 0.05, 0.3, 0.001)``.
    """
    s = _c.array("samples", samples)
    qr = None
    if q_range is not None:
        try:
            q_lo, q_hi = q_range
        except (TypeError, ValueError):
            raise ValueError("q_range must be a pair (lo, hi)") from None
        qr = (_c.number("q_range[0]", q_lo), _c.number("q_range[1]", q_hi))
    d = _ext.tsallis_q(s, _c.number("lo", lo), _c.number("hi", hi), _c.positive("step", step), qr)
    return EntropyIndex(float(d["q"]), float(d["redundancy"]), int(d["states"]),
                        bool(d["at_bound"]), int(d["scan_maxima"]))


def periodic_orbit(
    system: System,
    y0: Optional[npt.ArrayLike] = None,
    *,
    multiple: int = 1,
    period: Optional[float] = None,
    t0: float = 0.0,
    rtol: float = 1e-10,
    atol: Union[None, float, npt.ArrayLike] = None,
    xtol: float = 1e-11,
    max_iterations: int = 20,
) -> PeriodicOrbit:
    """A periodic orbit through (near) ``y0`` by shooting: Newton's method on
    ``P(y) − y = 0``, ``P`` the flow over the period (``multiple`` forcing periods, or
    ``period`` s; for an autonomous system ``period`` is a guess and is solved for, with a
    phase condition), its Jacobian the monodromy matrix from the variational equations,
    with saltation matrices at impacts and sliding. The Floquet multipliers are the
    eigenvalues of the monodromy matrix.

    Raises ``ConvergenceError`` if Newton does not converge.
    """
    r, a = _c.tolerances(rtol, atol, system.dimension)
    d = _ext.periodic_orbit(
        system, _y0(system, y0), _c.number("t0", t0),
        _c.integer("multiple", multiple, 1, 10_000),
        None if period is None else _c.positive("period", period), r, a,
        _c.positive("xtol", xtol), _c.integer("max_iterations", max_iterations, 1, 10_000),
    )
    return PeriodicOrbit._from(d)


def continuation(
    system: System,
    parameter: str,
    lo: float,
    hi: float,
    step: float,
    *,
    y0: Optional[npt.ArrayLike] = None,
    downward: bool = False,
    multiple: int = 1,
    max_step: Optional[float] = None,
    max_points: Optional[int] = None,
    t0: float = 0.0,
    rtol: float = 1e-10,
    atol: Union[None, float, npt.ArrayLike] = None,
    grazing: Optional[tuple[int, float, str]] = None,
    contact_changes: bool = False,
    period: Optional[float] = None,
) -> Branch:
    """Follows the periodic orbit through (near) ``y0`` in ``parameter`` within
    ``[lo, hi]`` by pseudo-arclength continuation (first step ``step``), starting at the
    system's own value and going up (or ``downward``), and locates folds (a multiplier
    through +1), period doublings (−1), Neimark–Sacker points (a complex pair through the
    unit circle) and, with ``grazing = (component, level, "min" | "max")``, grazing: the
    orbit's extremum of that state component touching ``level`` (``contact_changes``:
    any local extremum).

    A Filippov system (:func:`relay_feedback`, :func:`belt_friction`) is followed over the
    grid ``p₀ + k·step`` by shooting with the monodromy through sliding, and its sliding
    bifurcations are located: ``grazing_sliding``, ``crossing_sliding``,
    ``switching_sliding``, ``adding_sliding`` (``period`` guesses an autonomous orbit's
    period).
    """
    if not isinstance(parameter, str):
        raise TypeError("parameter must be a name (str)")
    g = None
    if grazing is not None:
        try:
            comp, level, ext = grazing
        except (TypeError, ValueError):
            raise ValueError("grazing must be (component, level, 'min' | 'max')") from None
        if ext not in ("min", "max"):
            raise ValueError(f"grazing extremum must be 'min' or 'max' (got {ext!r})")
        g = (_c.integer("grazing component", comp, 0, system.dimension - 1),
             _c.number("grazing level", level), ext == "max")
    r, a = _c.tolerances(rtol, atol, system.dimension)
    d = _ext.continuation(
        system, parameter, _c.number("lo", lo), _c.number("hi", hi),
        _c.positive("step", step), None if max_step is None else _c.positive("max_step", max_step),
        None if max_points is None else _c.integer("max_points", max_points, 1, 10_000_000),
        bool(downward), _c.integer("multiple", multiple, 1, 10_000), _y0(system, y0),
        _c.number("t0", t0), r, a, g, bool(contact_changes),
        None if period is None else _c.positive("period", period),
    )
    return Branch._from(d)


def ensemble(
    system: System,
    y0: Optional[npt.ArrayLike] = None,
    *,
    parameter: Optional[str] = None,
    values: Optional[npt.ArrayLike] = None,
    transient: int = 100,
    record: int = 50,
    surface: int = 0,
    rtol: float = 1e-8,
    atol: Union[None, float, npt.ArrayLike] = None,
    period_tol: float = 1e-4,
    max_period: int = 16,
    max_steps: int = 10_000_000,
) -> EnsembleResult:
    """Many starts of one smooth system at once, in the SIMD lanes of the crate's ensemble
    integrator (DOPRI5 with every lane's own step, error control and events), on every
    core: ``y0`` is one initial state or an ``(n, dim)`` array of them; with
    ``parameter`` each start ``j`` runs at ``values[j]``. Each start runs ``transient``
    then ``record`` forcing periods from ``t = 0`` and gives the record :func:`poincare`
    gives for it, to the bit. A failed start does not stop the others.
    """
    n_dim = system.dimension
    if y0 is None:
        y0s = [[float(x) for x in system.rest_state]]
    else:
        a = _c.floats("y0", y0)
        if a.ndim == 1:
            y0s = [_c.vector("y0", a, n_dim)]
        elif a.ndim == 2:
            if a.shape[0] > _c.MAX_OUTPUT:
                raise ValueError(f"{a.shape[0]} initial states; at most {_c.MAX_OUTPUT}")
            y0s = [_c.vector(f"y0[{j}]", row, n_dim) for j, row in enumerate(a)]
        else:
            raise ValueError(f"y0 must be one state or an (n, {n_dim}) array (got shape {a.shape})")
    if (parameter is None) != (values is None):
        raise ValueError("give parameter and values together")
    if parameter is not None and not isinstance(parameter, str):
        raise TypeError("parameter must be a name (str)")
    v = np.zeros(0) if values is None else _c.array("values", values, 10_000_000)
    if parameter is not None and len(y0s) != 1 and len(y0s) != v.size:
        raise ValueError(f"{len(y0s)} initial states for {v.size} values")
    r, a_tol = _c.tolerances(rtol, atol, n_dim)
    d = _ext.ensemble(
        system, parameter, v, y0s, _c.integer("transient", transient),
        _c.integer("record", record, 1), _c.integer("surface", surface, 0, 3), r, a_tol,
        _c.positive("period_tol", period_tol), _c.integer("max_period", max_period, 1),
        _c.integer("max_steps", max_steps, 1, 2**63 - 1),
    )
    return EnsembleResult._from(d)


def timestep(
    system: System,
    t_span: tuple[float, float],
    h: float,
    *,
    q0: Optional[npt.ArrayLike] = None,
    v0: Optional[npt.ArrayLike] = None,
    theta: float = 0.5,
    every: int = 1,
    max_records: int = 10_000_000,
    impact_speed: float = 1e-6,
) -> TimeStepRun:
    """Moreau–Jean time-stepping of a rigid-contact system (:func:`bouncing_ball`,
    :func:`woodpecker`) over ``t_span`` with the fixed step ``h`` (s): on ``t_k = t0 + kh``
    the free velocity ``v_free = v_k + h M⁻¹((1−θ)f_k + θ f_{k+1})``, one complementarity
    problem for the impulses of the active contacts (Newton's impact law, Coulomb friction
    where the contact has it), ``v_{k+1} = v_free + M⁻¹Hᵀp``, ``q_{k+1} = q_k +
    h((1−θ)v_k + θv_{k+1})``. Impacts accumulate (Zeno) without stalling the scheme.
    """
    t0, t1 = _span(t_span)
    hh = _c.positive("h", h)
    if (t1 - t0) / hh > 1e10:
        raise ValueError(f"{(t1 - t0) / hh:.3g} steps of h = {hh}; at most 1e10")
    th = _c.number("theta", theta)
    q = None if q0 is None else _c.vector("q0", q0)
    vv = None if v0 is None else _c.vector("v0", v0)
    d = _ext.timestep(
        system, t0, t1, hh, th, q, vv, _c.integer("every", every, 1, 2**63 - 1),
        _c.integer("max_records", max_records, 1, _c.MAX_OUTPUT),
        _c.positive("impact_speed", impact_speed),
    )
    return TimeStepRun._from(d)
