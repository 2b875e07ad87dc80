"""The instruments one by one: shapes, and numbers that the crate's own tests establish."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest

import nonsmooth as ns

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_system_parameters_and_rest_state() -> None:
    s = ns.paper(14.0)
    assert s.name == "paper" and s.dimension == 2
    assert s.parameters["omega"] == 14.0 and s.parameters["x_i"] == -2.086e-3
    assert math.isclose(s.period, 2 * math.pi / 14.0)
    # The static equilibrium against the stop (paper: −2.0807e-3 m).
    assert abs(s.rest_state[0] + 2.0807e-3) < 5e-8 and s.rest_state[1] == 0.0
    t = s.with_parameters(omega=20.0, c=7.0)
    assert t.parameters["omega"] == 20.0 and t.parameters["c"] == 7.0
    assert s.parameters["omega"] == 14.0
    assert ns.two_dof_impact().state_names == ["x1", "x2", "v1", "v2"]


def test_simulate_samples_on_the_grid_and_records_impacts() -> None:
    s = ns.paper(20.465)
    run = ns.simulate(s, (0.0, 50 * s.period), dt=s.period / 16)
    assert run.t.shape == (801,) and run.y.shape == (801, 2)
    assert run.t[0] == 0.0 and run.t[-1] == pytest.approx(50 * s.period)
    assert np.array_equal(run.y[0], s.rest_state)
    assert run.termination == "reached_end"
    assert len(run.event_t) > 20 and np.all(np.diff(run.event_t) > 0)
    # Impacts: rising crossings of the stop x = x_I.
    assert np.allclose(run.event_y[:, 0], s.parameters["x_i"], atol=1e-12)
    assert np.all(run.event_y[:, 1] > 0)
    assert run.stats.accepted > 0 and run.stats.rhs_evals > run.stats.accepted


def test_impacts_match_the_section_intervals() -> None:
    # A periodic regime (period 2 at ω = 19 rad/s): the two runs take different steps (the
    # section run lands on the period grid) and agree to the integration error.
    s = ns.paper(19.0)
    sec = ns.poincare(s, 50, transient=200)
    imp = ns.impacts(s, (0.0, 250 * s.period), record_from=200 * s.period)
    assert sec.period == 2
    assert abs(imp.count - sec.impacts) <= 1
    k = min(len(sec.intervals), len(imp.interval)) - 2
    assert np.allclose(imp.interval[-k:], sec.intervals[-k:], rtol=0, atol=1e-5)
    assert np.all(imp.velocity > 0)


def test_poincare_of_a_period_one_orbit() -> None:
    # At ω = 13 rad/s the cart has not yet reached the stop's grazing (ω ≈ 14.07): a
    # period-1 orbit without impacts.
    sec = ns.poincare(ns.paper(13.0), 20)
    assert sec.period == 1 and sec.impacts == 0
    assert np.ptp(sec.poincare[:, 0]) < 1e-9


def test_sweep_up_and_down_with_hysteresis() -> None:
    # The sweep of tests/paper.rs (grazing_points_of_fig3b): [20.5, 25] in steps of 0.02.
    s = ns.paper(20.5)
    values = 20.5 + 0.02 * np.arange(226)
    res = ns.sweep(s, "omega", values, record=30, rtol=1e-8)
    assert [b.direction for b in res.branches] == ["up", "down"]
    up, down = res.branches
    assert np.allclose(up.params, values) and np.allclose(down.params, values[::-1])
    # Coexisting attractors near 22.71 rad/s (the paper; tests/paper.rs).
    assert any(a <= 22.74 and b >= 22.70 for a, b in res.hysteresis), res.hysteresis


def test_sweep_independent_starts_do_not_depend_on_threads() -> None:
    s = ns.duffing_ueda()
    v = np.linspace(0.8, 1.2, 6)
    res = ns.sweep(s, "omega", v, continuation=False, direction="up", transient=(20, 10),
                   record=10, rtol=1e-8)
    again = ns.sweep(s, "omega", v, continuation=False, direction="up", transient=(20, 10),
                     record=10, rtol=1e-8)
    a = np.concatenate([p.poincare for p in res.branches[0].points])
    b = np.concatenate([p.poincare for p in again.branches[0].points])
    assert np.array_equal(a, b)


def test_lyapunov_spectrum_of_a_stable_orbit_is_negative() -> None:
    est = ns.lyapunov(ns.duffing_ueda(b=0.5), 200, method="spectrum", transient=50)
    assert est.exponents.shape == (2,)
    assert est.exponents[0] < 0
    # Liouville: the sum is the mean trace of the Jacobian, −k.
    assert est.exponents.sum() == pytest.approx(-0.05, abs=2e-3)


def test_lyapunov_through_resets_of_the_bouncing_ball() -> None:
    est = ns.lyapunov(ns.bouncing_ball(gamma=3.5, e=0.9), 300, transient=100, tau=1.0)
    assert est.top > 0  # chaotic bouncing (examples/bouncing_ball.rs)


def test_periodic_orbit_and_continuation_to_the_first_grazing() -> None:
    s = ns.paper(13.0)
    y = ns.poincare(s, 1, transient=400).end_state
    orbit = ns.periodic_orbit(s, y)
    assert orbit.stable and orbit.residual < 1e-9
    assert orbit.period == pytest.approx(2 * math.pi / 13.0)
    assert orbit.monodromy.shape == (2, 2) and orbit.multipliers.shape == (2,)
    branch = ns.continuation(s, "omega", 13.0, 14.3, 0.005, y0=orbit.state, max_step=0.2,
                             grazing=(0, s.parameters["x_i"], "min"), rtol=1e-8)
    graze = [b for b in branch.bifurcations if b.kind == "grazing"]
    assert graze, branch.bifurcations
    # The first grazing (tests/paper.rs: near 14.07 rad/s).
    assert 14.0 < graze[0].p < 14.15


def test_tsallis_q_of_a_known_distribution() -> None:
    rng = np.random.default_rng(7)
    x = rng.exponential(0.05, 20_000) + 0.05
    q = ns.tsallis_q(x, 0.05, 0.3, 0.01)
    assert q.states > 1 and 0.05 < q.q < 5 and not q.at_bound


def test_study_run_and_merge_like_the_cli(tmp_path: pathlib.Path) -> None:
    spec = ROOT / "examples" / "studies" / "smoke.toml"
    seen: list[tuple[int, int]] = []
    for i in (1, 2):
        r = ns.study.run(spec, tmp_path / "shards", shard=(i, 2),
                         progress=lambda d, t: seen.append((d, t)))
        assert r.points == 12
    table = ns.study.merge(tmp_path / "shards", tmp_path / "merged.csv")
    assert (table.nx, table.ny) == (8, 3)
    assert table.grid("period").shape == (3, 8)
    assert table.failed == 0 and np.all(table.ok == 1)
    assert any(pathlib.Path(f).exists() for f in table.files)
    assert all(t == 24 for _, t in seen)
    with pytest.raises(ns.StudyError):
        ns.study.merge(tmp_path / "nothing-here")


def test_described_system_from_a_study_file() -> None:
    path = ROOT / "examples" / "studies" / "impact_damper_2dof.toml"
    # omega is the study's axis: it has no value in the file.
    with pytest.raises(ValueError, match="omega"):
        ns.load(path)
    s = ns.load(path, omega=1.0)
    assert s.name == "mechanical" and s.dimension == 4
    assert s.parameters["gap"] == 0.1 and s.period == pytest.approx(2 * math.pi)
    sec = ns.poincare(s, 20, transient=50, surface=1)
    assert sec.poincare.shape == (20, 4) and sec.impacts > 0
