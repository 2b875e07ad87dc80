//! Samplers and sweeps on the paper's model: the impact-adding sequence, period detection,
//! determinism across thread counts, hysteresis and transitions, the ramp.

use nalgebra::Vector2;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::sample::Regime;
use nonsmooth::sweep::{
    Stop, SweepBranch, SweepConfig, SweepDirection, SweepError, SweepPoint, SweepResult,
    SweepSystem, hysteresis, run_point, sweep, transitions,
};
use nonsmooth::systems::paper::{PAPER, PaperOscillator};

fn stop() -> Stop {
    Stop {
        position: 0,
        velocity: 1,
        level: PAPER.x_i,
    }
}

fn make(w: f64) -> nonsmooth::Result<SweepSystem<PaperOscillator<f64>>> {
    Ok(SweepSystem {
        system: PAPER.oscillator::<f64>(w)?,
        period: std::f64::consts::TAU / w,
        stop: Some(stop()),
    })
}

fn stepper() -> Dopri5<f64, 2> {
    Dopri5::new(Tolerances::per_component(1e-8, [1e-12, 1e-10]).unwrap())
}

fn x0() -> Vector2<f64> {
    Vector2::new(PAPER.static_equilibrium().unwrap(), 0.0)
}

/// The paper's settings at one frequency from rest: 100 transient periods, 50 recorded.
fn at(w: f64) -> SweepPoint<2> {
    let cfg = SweepConfig::new(vec![w]).unwrap().record(50).unwrap();
    run_point(&cfg, w, make(w).unwrap(), stepper(), x0(), 100).unwrap()
}

#[test]
fn impact_adding_sequence() {
    // Paper, Sect. 3 and 5 (Fig. 8): period-1 orbits with 0, 1, 2, 3, 4, 5 impacts per
    // forcing period at ω = 14, 14.1, 15, 16, 17, 17.5 rad/s.
    for (w, n) in [
        (14.0, 0.0),
        (14.1, 1.0),
        (15.0, 2.0),
        (16.0, 3.0),
        (17.0, 4.0),
        (17.5, 5.0),
    ] {
        let p = at(w);
        assert_eq!(p.regime, Regime::Periodic(1), "ω = {w}");
        assert_eq!(p.impacts_per_period, n, "ω = {w}");
        assert_eq!(p.impacts, 50 * n as u64);
        if n > 0.0 {
            // The intervals of a period-1 orbit with n impacts sum to the period n-by-n.
            let per: f64 = p.intervals[..n as usize].iter().sum();
            assert!(
                (per - std::f64::consts::TAU / w).abs() < 1e-6,
                "ω = {w}: {per}"
            );
        }
    }
}

#[test]
fn irregular_at_18_and_period_two_with_five_impacts_at_19() {
    let p = at(18.0);
    assert_eq!(p.regime, Regime::NotPeriodic);
    let mut iv = p.intervals.clone();
    iv.sort_by(f64::total_cmp);
    iv.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    assert!(
        iv.len() > 20,
        "irregular motion has many distinct intervals: {}",
        iv.len()
    );
    let p = at(19.0);
    assert_eq!(p.regime, Regime::Periodic(2));
    assert_eq!(p.impacts, 125, "5 impacts per 2 periods over 50 periods");
}

#[test]
fn permanent_contact_has_negative_margin_and_no_impacts() {
    let p = at(14.0);
    assert_eq!(p.impacts, 0);
    // The cart stays pressed into the stop: x > x_I throughout.
    assert!(p.grazing_margin < 0.0);
    assert!(p.intervals.is_empty());
}

#[cfg(feature = "parallel")]
#[test]
fn sweep_is_bit_identical_whatever_the_thread_count() {
    let cfg = SweepConfig::grid(19.0, 19.1, 0.05)
        .unwrap()
        .transients(30, 10)
        .record(10)
        .unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let a = one.install(|| sweep(&cfg, make, stepper, x0()).unwrap());
    let b = sweep(&cfg, make, stepper, x0()).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.branches.len(), 2);
    // Independent starts, in parallel over values.
    let cfg = cfg.continuation(false);
    let c = one.install(|| sweep(&cfg, make, stepper, x0()).unwrap());
    let d = sweep(&cfg, make, stepper, x0()).unwrap();
    assert_eq!(c, d);
}

#[test]
fn continuation_carries_the_state() {
    let cfg = SweepConfig::grid(19.0, 19.1, 0.05)
        .unwrap()
        .direction(SweepDirection::Up)
        .transients(30, 10)
        .record(5)
        .unwrap();
    let r = sweep(&cfg, make, stepper, x0()).unwrap();
    let pts = &r.branches[0].points;
    assert_eq!(pts.len(), 3);
    // The second value started where the first ended: re-running it from that state
    // reproduces it exactly.
    let again = run_point(
        &cfg,
        19.05,
        make(19.05).unwrap(),
        stepper(),
        pts[0].end_state,
        10,
    )
    .unwrap();
    assert_eq!(again, pts[1]);
}

#[test]
fn sweep_errors_are_reported() {
    let cfg = SweepConfig::grid(19.0, 19.1, 0.05)
        .unwrap()
        .transients(1, 1)
        .record(1)
        .unwrap();
    let bad = |w: f64| -> nonsmooth::Result<SweepSystem<PaperOscillator<f64>>> {
        if w > 19.04 {
            Err(nonsmooth::ParameterError::new("omega", w, "test").into())
        } else {
            make(w)
        }
    };
    match sweep(&cfg, bad, stepper, x0()) {
        Err(SweepError::Failed { param, .. }) => assert!((param - 19.05).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    let bad_period = |w: f64| -> nonsmooth::Result<SweepSystem<PaperOscillator<f64>>> {
        Ok(SweepSystem {
            period: -1.0,
            ..make(w)?
        })
    };
    assert!(matches!(
        sweep(&cfg, bad_period, stepper, x0()),
        Err(SweepError::InvalidPeriod { .. })
    ));
    // A non-finite initial state.
    assert!(matches!(
        sweep(&cfg, make, stepper, Vector2::new(f64::NAN, 0.0)),
        Err(SweepError::Failed { .. })
    ));
}

fn point(param: f64, regime: Regime, ipp: f64, x: f64) -> SweepPoint<2> {
    SweepPoint {
        param,
        poincare: vec![Vector2::new(x, 0.0); 4],
        intervals: vec![],
        impact_velocities: vec![],
        impacts: (ipp * 4.0) as u64,
        impacts_per_period: ipp,
        regime,
        grazing_margin: 0.0,
        end_state: Vector2::zeros(),
    }
}

#[test]
fn hysteresis_and_transitions_on_constructed_branches() {
    let p1 = Regime::Periodic(1);
    let up = SweepBranch {
        direction: SweepDirection::Up,
        points: vec![
            point(1.0, p1, 1.0, 1.0),
            point(2.0, p1, 1.0, 1.0),
            point(3.0, p1, 1.0, 1.1),
            point(4.0, p1, 2.0, 2.0),
        ],
    };
    let down = SweepBranch {
        direction: SweepDirection::Down,
        points: vec![
            point(4.0, p1, 2.0, 2.0),
            point(3.0, p1, 2.0, 2.0),
            point(2.0, p1, 2.0, 2.0),
            point(1.0, p1, 1.0, 1.0),
        ],
    };
    let r = SweepResult {
        branches: vec![up.clone(), down],
    };
    assert_eq!(hysteresis(&r, 1e-6), vec![(2.0, 3.0)]);
    let t = transitions(&up);
    assert_eq!(t.len(), 1);
    assert_eq!(
        (
            t[0].before,
            t[0].after,
            t[0].impacts_before,
            t[0].impacts_after
        ),
        (3.0, 4.0, 1.0, 2.0)
    );
}

#[test]
fn ramp_sections_follow_the_phase() {
    use nonsmooth::sweep::ramp;
    let rate = 8.0905e-3;
    let osc = PAPER.ramped::<f64>(19.0, rate).unwrap();
    let exc = *osc.excitation();
    let rec = ramp(osc, exc, stop(), stepper(), x0(), 30.0).unwrap();
    assert!(rec.sections.len() > 80);
    for s in &rec.sections {
        // φ(t_i) = 2πi exactly (to rounding), ω(t_i) = ω0 + r·t_i.
        let phi = (19.0 + 0.5 * rate * s.t) * s.t;
        assert!((phi - std::f64::consts::TAU * s.index as f64).abs() < 1e-9);
        assert!((s.omega - (19.0 + rate * s.t)).abs() < 1e-12);
    }
    assert!(!rec.impacts.is_empty());
    assert!(rec.impacts.iter().all(|i| i.velocity > 0.0));
    assert_eq!((rec.dropped_sections, rec.dropped_impacts), (0, 0));

    // A bounded run keeps the first `capacity` records, counts the rest, and they are the
    // unbounded run's records.
    use nonsmooth::sweep::ramp_with_capacity;
    let capped = ramp_with_capacity(osc, exc, stop(), stepper(), x0(), 30.0, 10).unwrap();
    assert_eq!(capped.sections[..], rec.sections[..10]);
    assert_eq!(capped.impacts[..], rec.impacts[..10.min(rec.impacts.len())]);
    assert_eq!(
        capped.dropped_sections,
        (rec.sections.len() - capped.sections.len()) as u64
    );
    assert_eq!(
        capped.dropped_impacts,
        (rec.impacts.len() - capped.impacts.len()) as u64
    );
}

#[test]
fn sweep_config_rejects_degenerate_input() {
    // A step far too small for the range would allocate 10¹⁸ values.
    assert!(matches!(
        SweepConfig::grid(0.0, 1.0, 1e-18),
        Err(SweepError::TooManyValues { .. })
    ));
    assert!(matches!(
        SweepConfig::grid(0.0, f64::MAX, 1.0),
        Err(SweepError::TooManyValues { .. })
    ));
    // An ordinary grid still builds.
    assert!(SweepConfig::grid(0.0, 1.0, 0.25).is_ok());
    let cfg = SweepConfig::new(vec![14.0]).unwrap();
    for (tol, max) in [
        (f64::NAN, 4),
        (-1.0, 4),
        (f64::INFINITY, 4),
        (0.0, 4),
        (1e-6, 0),
    ] {
        assert!(
            matches!(
                cfg.clone().period_detection(tol, max),
                Err(SweepError::InvalidPeriodDetection { .. })
            ),
            "tol {tol}, max period {max}"
        );
    }
    assert!(cfg.period_detection(1e-6, 8).is_ok());
}

#[test]
fn huge_transient_and_record_fail_on_the_step_cap_not_on_overflow() {
    // `transient + record` does not fit a u32: the run's end is computed in f64 and the
    // step cap stops it with an error.
    let cfg = SweepConfig::new(vec![14.0])
        .unwrap()
        .record(u32::MAX)
        .unwrap()
        .max_steps(1000);
    let r = run_point(&cfg, 14.0, make(14.0).unwrap(), stepper(), x0(), u32::MAX);
    assert!(matches!(r, Err(SweepError::Failed { .. })), "{r:?}");
}
