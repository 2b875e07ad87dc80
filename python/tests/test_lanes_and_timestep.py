"""The ensemble (starts in SIMD lanes) against the scalar runs, and Moreau–Jean
time-stepping against Newton's impact law."""

from __future__ import annotations

import numpy as np
import pytest

import nonsmooth as ns


def test_ensemble_records_equal_the_scalar_runs_bit_for_bit() -> None:
    cart = ns.paper(20.0)
    omegas = np.array([19.0, 20.465, 22.0, 22.73, 23.5])
    res = ns.ensemble(cart, parameter="omega", values=omegas, transient=50, record=20)
    assert res.errors == [None] * len(omegas)
    for w, sec in zip(omegas, res.sections):
        assert sec is not None
        one = ns.poincare(ns.paper(float(w)), 20, transient=50)
        assert sec.param == w
        assert np.array_equal(sec.poincare, one.poincare)
        assert np.array_equal(sec.intervals, one.intervals)
        assert (sec.impacts, sec.period) == (one.impacts, one.period)
    assert res.end_states.shape == (5, 2) and res.periods.shape == (5,)


def test_ensemble_over_initial_states() -> None:
    duffing = ns.duffing_ueda(b=0.5)
    y0 = np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.5], [2.0, -1.0]])
    res = ns.ensemble(duffing, y0, transient=100, record=10)
    assert all(e is None for e in res.errors)
    for j, sec in enumerate(res.sections):
        assert sec is not None
        one = ns.poincare(duffing, 10, transient=100, y0=y0[j])
        assert np.array_equal(sec.poincare, one.poincare)


def test_ensemble_rejects_mismatched_starts() -> None:
    with pytest.raises(ValueError):
        ns.ensemble(ns.paper(20.0), np.zeros((3, 2)), parameter="omega", values=[19.0, 20.0])
    with pytest.raises(ValueError):
        ns.ensemble(ns.paper(20.0), np.zeros((2, 3)))
    with pytest.raises(ValueError):
        ns.ensemble(ns.paper(20.0), parameter="omega")
    with pytest.raises(ValueError, match="not available"):
        ns.ensemble(ns.relay_feedback())


def test_timestep_ball_follows_newtons_law() -> None:
    ball = ns.bouncing_ball(gamma=1.5, e=0.9)
    run = ns.timestep(ball, (0.0, 5.0), 1e-4)
    assert run.steps == 50_000 and run.t_final == pytest.approx(5.0)
    assert run.q.shape == (50_001, 1) and run.energy.shape == (50_001, 3)
    assert len(run.impact_t) > 3
    # ġ⁺ = −e ġ⁻ at each impact (the relative velocities of ball and table).
    assert np.allclose(run.impact_post, -0.9 * run.impact_pre, rtol=1e-9, atol=1e-12)
    # The ball stays above the table but for the penetration of one step, h·|ġ|.
    table = ball.parameters["amplitude"] * np.sin(ball.parameters["omega"] * run.t)
    assert np.min(run.q[:, 0] - table) > -1e-4 * np.max(np.abs(run.impact_pre))


def test_timestep_woodpecker_hits_with_its_beak() -> None:
    run = ns.timestep(ns.woodpecker(), (0.0, 0.1), 2e-5, every=10)
    assert run.q.shape[1] == 3 and run.contacts.shape[1] == 7
    assert 0 in set(run.impact_contact.tolist())
    assert np.isfinite(run.q).all()
    with pytest.raises(ValueError, match="timestep"):
        ns.simulate(ns.woodpecker(), (0.0, 1.0))
    with pytest.raises(ValueError):
        ns.timestep(ns.paper(20.0), (0.0, 1.0), 1e-3)
    with pytest.raises(ValueError):
        ns.timestep(ns.woodpecker(), (0.0, 1.0), 1e-12)


def test_belt_sliding_bifurcations_on_a_branch() -> None:
    # tests/filippov.rs (sliding_bifurcations_on_a_branch_of_the_belt_oscillator): the
    # orbit of the forcing period followed in F₀ from the pure-slip orbit at 0.6 meets a
    # grazing-sliding, then a switching-sliding, then a crossing-sliding bifurcation.
    belt = ns.belt_friction(f0=0.6)
    y0 = [1.0 + 0.6 / (1.0 - 4.0), 0.0]
    branch = ns.continuation(belt, "f0", 0.5, 2.2, 0.05, y0=y0, rtol=1e-12)
    assert branch.end == "parameter_range"
    kinds = [b.kind for b in branch.bifurcations]
    assert kinds == ["grazing_sliding", "switching_sliding", "crossing_sliding"], kinds
    run = ns.simulate(belt.with_parameters(f0=2.0), (0.0, 40.0), rtol=1e-10)
    assert any(t.kind == "sliding_entry" for t in run.transitions)  # sticking to the belt
