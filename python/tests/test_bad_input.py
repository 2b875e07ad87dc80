"""Bad input from Python never crashes or hangs the interpreter: NaN, ±inf, negative masses,
wrong shapes, unknown law names and huge sizes, fed to every entry point, each raise a
Python exception (ValueError or TypeError for rejected input, a NonsmoothError for a run
that fails)."""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import nonsmooth as ns

BAD_FLOATS = st.sampled_from([math.nan, math.inf, -math.inf])
HUGE = st.integers(min_value=2**40, max_value=2**62)
JUNK = st.one_of(st.text(max_size=3), st.lists(st.floats(), max_size=3),
                 st.dictionaries(st.text(max_size=2), st.integers(), max_size=2))
#: Not a finite number > 0 (a tolerance, a step, a separation).
NOT_POSITIVE = st.one_of(BAD_FLOATS, st.floats(max_value=0.0, allow_nan=False), JUNK)
#: Not a finite number.
NOT_FINITE = st.one_of(BAD_FLOATS, JUNK)
#: Not a count (a non-negative integer of sensible size).
NOT_COUNT = st.one_of(BAD_FLOATS, st.integers(max_value=-1), HUGE, JUNK,
                      st.floats(allow_nan=False).filter(lambda x: x != int(x) if math.isfinite(x) else True))
#: Not a value of a description's field.
NOT_FIELD = st.one_of(BAD_FLOATS, st.floats(max_value=0.0, allow_nan=False), HUGE,
                      st.text(max_size=5), st.none())
EXPECTED = (ValueError, TypeError, ns.NonsmoothError)
FAST = settings(max_examples=25, deadline=None)


def raises(f: Callable[[], Any]) -> None:
    with pytest.raises(EXPECTED):
        f()


PAPER = ns.paper(20.0)


@FAST
@given(BAD_FLOATS)
def test_system_constructors_reject_non_finite(x: float) -> None:
    raises(lambda: ns.paper(x))
    raises(lambda: ns.paper(20.0, m=x))
    raises(lambda: ns.duffing_ueda(k=x))
    raises(lambda: ns.two_dof_impact(x))
    raises(lambda: ns.bouncing_ball(gamma=x))
    raises(lambda: ns.relay_feedback(zeta=x))
    raises(lambda: PAPER.with_parameters(omega=x))


@FAST
@given(st.floats(max_value=0.0, allow_nan=False))
def test_negative_masses_and_frequencies(m: float) -> None:
    raises(lambda: ns.paper(20.0, m=m))
    raises(lambda: ns.paper(m))
    raises(lambda: ns.two_dof_impact(m1=m))
    raises(lambda: ns.describe({"model": "mechanical", "masses": [m], "parameters": {"omega": 1.0}}))


@FAST
@given(st.text(min_size=1, max_size=12))
def test_unknown_law_and_parameter_names(name: str) -> None:
    d = {"model": "mechanical", "masses": [1.0], "parameters": {"omega": 1.0},
         "elements": [{"law": name + "_law", "dof": 0, "k": 1.0}]}
    raises(lambda: ns.describe(d))
    raises(lambda: PAPER.with_parameters(**{name + "_p": 1.0}))
    raises(lambda: ns.sweep(PAPER, name + "_p", [1.0, 2.0]))
    raises(lambda: ns.continuation(PAPER, name + "_p", 1.0, 2.0, 0.1))


@FAST
@given(NOT_FIELD)
def test_describe_rejects_bad_values(x: Any) -> None:
    for key in ("masses", "elements", "loads", "surfaces", "parameters", "model"):
        d: dict[str, Any] = {"model": "mechanical", "masses": [1.0],
                             "parameters": {"omega": 1.0}}
        d[key] = x
        raises(lambda: ns.describe(d))
    base = {"model": "mechanical", "masses": [1.0], "parameters": {"omega": 1.0}}
    if not isinstance(x, (int, float)) or not math.isfinite(x):
        # A law's value: a number or a parameter's name; junk, NaN and ±inf are rejected.
        e = [{"law": "hertz", "dof": 0, "position": x, "k": 1.0}]
        if not (isinstance(x, str) and x.isidentifier() and x not in ("x0", "v0")):
            raises(lambda: ns.describe({**base, "elements": e}))
    if isinstance(x, (int, float)) and x <= 0:
        raises(lambda: ns.describe({**base, "masses": [x]}))
        raises(lambda: ns.describe({**base, "parameters": {"omega": x}}))


def test_describe_rejects_structure() -> None:
    base = {"model": "mechanical", "masses": [1.0], "parameters": {"omega": 1.0}}
    raises(lambda: ns.describe({**base, "masses": [1.0] * 5}))
    raises(lambda: ns.describe({**base, "masses": []}))
    raises(lambda: ns.describe({**base, "elements": [{"law": "hertz", "dof": 3, "position": 0, "k": 1}]}))
    raises(lambda: ns.describe({**base, "surfaces": [{"dof": 0, "position": 0}] * 5}))
    raises(lambda: ns.describe({**base, "unknown_key": 1}))
    raises(lambda: ns.describe({"model": "paper"}))
    raises(lambda: ns.describe({**base, "parameters": {}}))
    raises(lambda: ns.describe("not a dict"))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"system\.elements\[0\]\.k"):
        ns.describe({**base, "elements": [{"law": "linear_spring", "dof": 0, "k": -1.0}]})


@FAST
@given(NOT_FINITE, NOT_POSITIVE, NOT_COUNT)
def test_simulate_rejects_bad_input(x: Any, p: Any, n: Any) -> None:
    raises(lambda: ns.simulate(PAPER, (0.0, x)))
    raises(lambda: ns.simulate(PAPER, (x, 1.0)))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), y0=[x, 0.0]))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), rtol=p))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), atol=[p, 1.0]))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), dt=p))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), t_eval=[0.5, x]))
    if not isinstance(n, int) or n < 0:
        raises(lambda: ns.simulate(PAPER, (0.0, 1.0), max_steps=n))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), max_steps=0))
    raises(lambda: ns.simulate(PAPER, (1.0, 0.0)))


@FAST
@given(st.integers(min_value=0, max_value=6).filter(lambda n: n != 2))
def test_wrong_shapes(n: int) -> None:
    y = np.zeros(n)
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), y0=y))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), atol=np.ones(n)))
    raises(lambda: ns.poincare(PAPER, 5, y0=y))
    raises(lambda: ns.lyapunov(PAPER, 5, y0=y))
    raises(lambda: ns.periodic_orbit(PAPER, y))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), y0=np.zeros((2, 2))))
    raises(lambda: ns.tsallis_q(np.ones((n + 1, 2)), 0.0, 1.0, 0.1))


@FAST
@given(HUGE)
def test_huge_sizes_are_refused_not_attempted(n: int) -> None:
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), dt=1.0 / n))
    raises(lambda: ns.poincare(PAPER, n))
    raises(lambda: ns.sweep(PAPER, "omega", [20.0, 21.0], record=n))
    raises(lambda: ns.lyapunov(PAPER, n))
    raises(lambda: ns.periodic_orbit(PAPER, multiple=n))
    raises(lambda: ns.continuation(PAPER, "omega", 19.0, 21.0, 0.1, max_points=n))
    raises(lambda: ns.tsallis_q([0.1, 0.2], 0.0, 1.0, 1.0 / n))
    raises(lambda: ns.simulate(PAPER, (0.0, 1.0), max_events=n))
    raises(lambda: ns.study.run("spec.toml", "out", shard=(1, n)))
    raises(lambda: ns.impacts(PAPER, (0.0, 1.0), capacity=n))


@FAST
@given(NOT_FINITE, NOT_POSITIVE, NOT_COUNT)
def test_instruments_reject_bad_settings(x: Any, p: Any, n: Any) -> None:
    raises(lambda: ns.poincare(PAPER, n))
    raises(lambda: ns.poincare(PAPER, 5, transient=n))
    raises(lambda: ns.poincare(PAPER, 5, period_tol=p))
    raises(lambda: ns.poincare(PAPER, 5, rtol=p))
    raises(lambda: ns.sweep(PAPER, "omega", [20.0, x]))
    raises(lambda: ns.sweep(PAPER, "omega", [20.0, 21.0], record=n))
    raises(lambda: ns.sweep(PAPER, "omega", [21.0, 20.0]))
    raises(lambda: ns.sweep(PAPER, "omega", []))
    raises(lambda: ns.sweep(PAPER, "omega", [20.0, 21.0], direction=str(x)))
    raises(lambda: ns.sweep(PAPER, "m", [-2.0, 1.0]))
    raises(lambda: ns.lyapunov(PAPER, n))
    raises(lambda: ns.lyapunov(PAPER, 10, d0=p))
    raises(lambda: ns.lyapunov(PAPER, 10, tau=p))
    raises(lambda: ns.lyapunov(PAPER, 10, method=str(x)))
    raises(lambda: ns.lyapunov(PAPER, 10, t0=x))
    raises(lambda: ns.periodic_orbit(PAPER, period=p))
    raises(lambda: ns.periodic_orbit(PAPER, multiple=n))
    raises(lambda: ns.periodic_orbit(PAPER, xtol=p))
    raises(lambda: ns.continuation(PAPER, "omega", x, 21.0, 0.1))
    raises(lambda: ns.continuation(PAPER, "omega", 19.0, 21.0, p))
    raises(lambda: ns.continuation(PAPER, "omega", 19.0, 21.0, 0.1, grazing=(0, x, "min")))
    raises(lambda: ns.continuation(PAPER, "omega", 19.0, 21.0, 0.1, grazing=(5, 0.0, "min")))
    raises(lambda: ns.tsallis_q([0.1, x], 0.0, 1.0, 0.1))
    raises(lambda: ns.tsallis_q([0.1, 0.2], x, 1.0, 0.1))
    raises(lambda: ns.tsallis_q([0.1, 0.2], 0.0, 1.0, p))
    raises(lambda: ns.impacts(PAPER, (0.0, 1.0), record_from=x))
    raises(lambda: ns.impacts(PAPER, (0.0, 1.0), surface=n))


@FAST
@given(NOT_FINITE, NOT_POSITIVE, NOT_COUNT)
def test_ensemble_and_timestep_reject_bad_input(x: Any, p: Any, n: Any) -> None:
    raises(lambda: ns.ensemble(PAPER, [x, 0.0]))
    raises(lambda: ns.ensemble(PAPER, parameter="omega", values=[20.0, x]))
    raises(lambda: ns.ensemble(PAPER, parameter="omega", values=[20.0, -1.0]))
    raises(lambda: ns.ensemble(PAPER, record=n))
    raises(lambda: ns.ensemble(PAPER, rtol=p))
    ball = ns.bouncing_ball()
    raises(lambda: ns.timestep(ball, (0.0, x), 1e-3))
    raises(lambda: ns.timestep(ball, (0.0, 1.0), p))
    raises(lambda: ns.timestep(ball, (0.0, 1.0), 1e-3, q0=[x]))
    raises(lambda: ns.timestep(ball, (0.0, 1.0), 1e-3, q0=[0.0, 1.0]))
    raises(lambda: ns.timestep(ball, (0.0, 1.0), 1e-3, theta=x))
    if not isinstance(n, int) or n < 0:
        raises(lambda: ns.timestep(ball, (0.0, 1.0), 1e-3, every=n))


def test_run_failures_are_nonsmooth_errors() -> None:
    # A step cap far below what the run needs.
    with pytest.raises(ns.WorkLimitError, match="maximum number of steps"):
        ns.simulate(PAPER, (0.0, 10.0), max_steps=5)
    # Systems without an impact surface, or not smooth, refuse what they cannot do.
    with pytest.raises(ValueError, match="no impact surface"):
        ns.impacts(ns.duffing_ueda(), (0.0, 10.0))
    with pytest.raises(ValueError, match="not available"):
        ns.sweep(ns.relay_feedback(), "zeta", [0.05, 0.06])
    with pytest.raises(ValueError, match="surface 2"):
        ns.poincare(PAPER, 5, surface=2)
    # Empty histogram: every sample outside the range.
    with pytest.raises(ValueError):
        ns.tsallis_q([5.0, 6.0], 0.0, 1.0, 0.1)
    # A study file that does not exist.
    with pytest.raises((ns.StudyError, ValueError, OSError)):
        ns.study.run("/nonexistent/spec.toml", "/tmp/out")
    with pytest.raises(OSError):
        ns.load("/nonexistent/system.toml")


@FAST
@given(BAD_FLOATS, st.floats(max_value=0.0, allow_nan=False))
def test_remaining_constructors_reject_bad_values(x: float, neg: float) -> None:
    raises(lambda: ns.belt_friction(f0=x))
    raises(lambda: ns.belt_friction(u=x))
    raises(lambda: ns.belt_friction(omega=neg))
    raises(lambda: ns.belt_friction(fk=neg))
    raises(lambda: ns.duffing_ueda(omega=neg))
    raises(lambda: ns.two_dof_impact(m2=neg))
    raises(lambda: ns.two_dof_impact(0.7, k1=x))
    raises(lambda: ns.bouncing_ball(e=x))
    raises(lambda: ns.bouncing_ball(e=neg - 1.0))
    raises(lambda: ns.belt_friction().with_parameters(f0=x))
    raises(lambda: ns.relay_feedback().with_parameters(zeta=x))
    raises(lambda: ns.paper(20.0, **{"not a parameter": 1.0}))
    raises(lambda: ns.paper(20.0, m="heavy"))  # type: ignore[arg-type]
    raises(lambda: ns.woodpecker(1.0))  # type: ignore[call-arg]


@FAST
@given(BAD_FLOATS, st.floats(max_value=0.0, allow_nan=False))
def test_described_systems_reject_bad_parameters(x: float, neg: float) -> None:
    base = {"model": "mechanical", "masses": ["m"], "parameters": {"omega": 1.0, "m": 1.0},
            "elements": [{"law": "linear_spring", "dof": 0, "k": "k"}]}
    s = ns.describe(base, k=1.0)
    raises(lambda: s.with_parameters(m=x))
    raises(lambda: s.with_parameters(m=neg))
    raises(lambda: s.with_parameters(k=neg - 1.0))
    raises(lambda: s.with_parameters(omega=neg))
    raises(lambda: s.with_parameters(unknown=1.0))
    raises(lambda: ns.describe(base, k=x))
    raises(lambda: ns.describe(base))  # k has no value
    raises(lambda: ns.sweep(s, "k", [neg - 1.0, 1.0]))
    raises(lambda: ns.poincare(s, 5, surface=1))


@FAST
@given(st.text(max_size=40))
def test_load_rejects_junk_files(text: str) -> None:
    import os
    import tempfile
    fd, path = tempfile.mkstemp(suffix=".toml")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        raises(lambda: ns.load(path))
        raises(lambda: ns.load(path, omega=math.nan))
    finally:
        os.unlink(path)


@FAST
@given(st.text(max_size=30), JUNK)
def test_study_entry_points_reject_bad_paths_and_shards(name: str, junk: Any) -> None:
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        raises(lambda: ns.study.run(f"{d}/{name}.toml", f"{d}/out"))
        raises(lambda: ns.study.merge(f"{d}/{name}-missing"))
        raises(lambda: ns.study.merge(d))  # no shards
        raises(lambda: ns.study.run(f"{d}/x.toml", f"{d}/out", shard=junk))
        raises(lambda: ns.study.run(f"{d}/x.toml", f"{d}/out", shard=(0, 1)))
        raises(lambda: ns.study.run(f"{d}/x.toml", f"{d}/out", progress=junk))
        spec = f"{d}/bad.toml"
        with open(spec, "w", encoding="utf-8") as f:
            f.write(f'name = "x"\n[system]\nmodel = "{name}_model"\n')
        raises(lambda: ns.study.run(spec, f"{d}/out"))


@FAST
@given(HUGE)
def test_huge_arrays_and_counts_of_the_other_entry_points(n: int) -> None:
    raises(lambda: ns.ensemble(PAPER, transient=n))
    raises(lambda: ns.ensemble(PAPER, max_period=n))
    raises(lambda: ns.timestep(ns.bouncing_ball(), (0.0, 1.0), 1.0 / n))
    raises(lambda: ns.timestep(ns.bouncing_ball(), (0.0, 1.0), 1e-3, max_records=n))
    raises(lambda: ns.lyapunov(PAPER, 10, transient=n))
    raises(lambda: ns.periodic_orbit(PAPER, max_iterations=n))
    raises(lambda: ns.poincare(PAPER, 5, max_period=n, transient=n))
    # An array larger than the limits, as a view (no memory behind it).
    big = np.broadcast_to(np.float64(20.0), (min(n, 2**40),))
    raises(lambda: ns.sweep(PAPER, "omega", big))
    raises(lambda: ns.ensemble(PAPER, parameter="omega", values=big))
    raises(lambda: ns.tsallis_q(big, 0.0, 1.0, 0.1))


def test_text_is_not_read_as_a_number() -> None:
    # numpy reads "0" as 0.0; a state or an array given as text is refused instead (found by
    # the property tests above, which draw short strings).
    for y0 in (["0", 0.0], ["1e-3", "0"], [b"0", 0.0]):
        with pytest.raises(TypeError, match="y0 must hold numbers"):
            ns.simulate(PAPER, (0.0, 1.0), y0=y0)
        with pytest.raises(TypeError, match="y0 must hold numbers"):
            ns.ensemble(PAPER, y0)
    with pytest.raises(TypeError, match="t_eval must hold numbers"):
        ns.simulate(PAPER, (0.0, 1.0), t_eval=["0.5"])
