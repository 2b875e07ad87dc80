//! The catalogue of systems: each entry against an independent formulation.

use nalgebra::{SVector, Vector2};
use nonsmooth::Dynamics;
use nonsmooth::drive::Simulation;
use nonsmooth::event::{Direction, Event, Stop};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::sample::ImpactSequence;
use nonsmooth::sweep::{SweepConfig, SweepDirection, SweepSystem, sweep};
use nonsmooth::systems::TwoDofImpact;
use nonsmooth::systems::paper::PAPER;
use nonsmooth::testing::TwoDofImpactByHand;

#[test]
fn paper_model_as_mechanical_system_is_bit_identical() {
    let osc = PAPER.oscillator::<f64>(20.465).unwrap();
    let mech = PAPER.mechanical::<f64>(20.465).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    for (k, y) in [
        Vector2::new(-2.5e-3, 3e-2),
        Vector2::new(x0, 2e-4),
        Vector2::new(x0, -3e-8),
        Vector2::new(x0 + 1e-6, -0.1),
    ]
    .iter()
    .enumerate()
    {
        let t = 0.1 * k as f64 + 0.0123;
        let (mut a, mut b) = (Vector2::zeros(), Vector2::zeros());
        osc.rhs(t, y, &mut a);
        mech.rhs(t, y, &mut b);
        assert_eq!(a, b, "rhs at {y:?}");
        assert_eq!(osc.jacobian(t, y), mech.jacobian(t, y));
        assert_eq!(osc.time_derivative(t, y), mech.time_derivative(t, y));
    }
    // Whole runs with impacts: the same steps, the same impacts, bit for bit.
    let tol = Tolerances::per_component(1e-8, [1e-12, 1e-10]).unwrap();
    let stop = Stop {
        position: 0,
        velocity: 1,
        level: PAPER.x_i,
    };
    let a = {
        let mut imp = ImpactSequence::new(0, 0, 1, PAPER.x_i, 0.0, 1000).unwrap();
        let out = Simulation::new(osc, Dopri5::new(tol))
            .with_events(Event::new(stop, Direction::Rising))
            .run(0.0, Vector2::new(x0, 0.0), 10.0, &mut imp)
            .unwrap();
        let times: Vec<f64> = imp.impacts().iter().map(|i| i.t).collect();
        (out.y, out.stats, times)
    };
    let b = {
        let mut imp = ImpactSequence::new(0, 0, 1, PAPER.x_i, 0.0, 1000).unwrap();
        let out = Simulation::new(mech, Dopri5::new(tol))
            .with_events(Event::new(stop, Direction::Rising))
            .run(0.0, Vector2::new(x0, 0.0), 10.0, &mut imp)
            .unwrap();
        let times: Vec<f64> = imp.impacts().iter().map(|i| i.t).collect();
        (out.y, out.stats, times)
    };
    assert!(a.2.len() > 20, "{} impacts", a.2.len());
    assert_eq!(a, b);
}

#[test]
fn two_dof_impact_oscillator_matches_the_hand_written_model() {
    let p = TwoDofImpact::default();
    // Impacting period-1 responses (ω = 0.5, 0.6) and a non-impacting one (0.35).
    let values = vec![0.35, 0.5, 0.6, 0.9];
    let config = SweepConfig::new(values.clone())
        .unwrap()
        .direction(SweepDirection::Up)
        .continuation(false)
        .transients(300, 0)
        .record(10)
        .unwrap();
    let tol = Tolerances::per_component(1e-12, [1e-14; 4]).unwrap();
    let assembled = sweep(
        &config,
        |w: f64| -> nonsmooth::Result<SweepSystem<_, _>> {
            Ok(SweepSystem {
                system: p.model::<f64>(w)?,
                period: TwoDofImpact::period(w),
                stop: Some(p.stop::<f64>()?),
            })
        },
        || Dopri5::new(tol),
        SVector::zeros(),
    )
    .unwrap();
    let by_hand = sweep(
        &config,
        |w: f64| -> nonsmooth::Result<SweepSystem<_, _>> {
            Ok(SweepSystem {
                system: TwoDofImpactByHand {
                    params: p,
                    omega: w,
                },
                period: TwoDofImpact::period(w),
                stop: Some(p.stop::<f64>()?),
            })
        },
        || Dopri5::new(tol),
        SVector::zeros(),
    )
    .unwrap();
    let impacts: Vec<u64> = assembled.branches[0]
        .points
        .iter()
        .map(|q| q.impacts)
        .collect();
    // No impacts far below resonance; one per period on the impacting branch.
    assert_eq!(impacts, vec![0, 10, 10, 10], "{impacts:?}");
    for (a, b) in assembled.branches[0]
        .points
        .iter()
        .zip(&by_hand.branches[0].points)
    {
        assert_eq!(a.impacts, b.impacts);
        for (x, y) in a.poincare.iter().zip(&b.poincare) {
            // Measured 2e-10 at these tolerances (7e-7 at rtol 1e-9): the integration
            // error, not the assembly, sets the difference.
            assert!((x - y).amax() < 1e-8, "ω = {}: {x:?} vs {y:?}", a.param);
        }
        for (u, v) in a.impact_velocities.iter().zip(&b.impact_velocities) {
            assert!((u - v).abs() < 1e-8);
        }
    }
    // Bad parameters are errors naming the field.
    let bad = TwoDofImpact {
        m2: -1.0,
        ..TwoDofImpact::default()
    };
    match bad.model::<f64>(1.0) {
        Err(nonsmooth::Error::Parameter(e)) => assert_eq!(e.name, "m2"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn sweeps_run_over_any_parameter() {
    // The 2-DOF oscillator at ω = 0.6 swept in its gap d: impacts stop once the gap exceeds
    // the secondary mass's steady amplitude A without contact (measured 0.431).
    let omega = 0.6;
    let config = SweepConfig::grid(0.1, 0.9, 0.2)
        .unwrap()
        .direction(SweepDirection::Up)
        .continuation(false)
        .transients(200, 0)
        .record(10)
        .unwrap();
    let tol = Tolerances::per_component(1e-9, [1e-11; 4]).unwrap();
    let res = sweep(
        &config,
        |gap: f64| -> nonsmooth::Result<SweepSystem<_, _>> {
            let p = TwoDofImpact {
                gap,
                ..TwoDofImpact::default()
            };
            Ok(SweepSystem {
                system: p.model::<f64>(omega)?,
                period: TwoDofImpact::period(omega),
                stop: Some(p.stop::<f64>()?),
            })
        },
        || Dopri5::new(tol),
        SVector::zeros(),
    )
    .unwrap();
    let impacts: Vec<u64> = res.branches[0].points.iter().map(|q| q.impacts).collect();
    let gaps: Vec<f64> = res.branches[0].points.iter().map(|q| q.param).collect();
    assert_eq!(gaps.len(), 5);
    assert_eq!(impacts, vec![10, 5, 0, 0, 0], "{gaps:?}: {impacts:?}");
    // Without contact the response does not depend on the gap, so the grazing margin is
    // d − A at every non-impacting gap.
    let pts = &res.branches[0].points;
    let amplitude = pts[4].param - pts[4].grazing_margin;
    assert!((amplitude - 0.431).abs() < 1e-3, "{amplitude}");
    for p in &pts[2..] {
        assert!(
            (p.param - p.grazing_margin - amplitude).abs() < 1e-7,
            "{}",
            p.param
        );
    }
}

/// Stroboscopic points at `t = 2πi`, `i = 1..=n`.
fn ueda_sections<S: Dynamics<f64, 2>, St: nonsmooth::integrate::Stepper<f64, 2>>(
    system: S,
    stepper: St,
    n: usize,
) -> Vec<Vector2<f64>> {
    use nonsmooth::sample::Stroboscopic;
    let tau = std::f64::consts::TAU;
    let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, tau, 0.5 * tau, n + 1).unwrap();
    let mut sim = Simulation::new(system, stepper);
    sim.run(
        0.0,
        Vector2::new(3.0, 0.0),
        (n as f64 + 0.25) * tau,
        &mut strobe,
    )
    .unwrap();
    strobe.points().iter().map(|p| p.y).collect()
}

/// Duffing–Ueda: the assembled model (cubic spring + damper + cosine load) against the
/// hand-written equation on a second integrator; λ₁ two ways against Ueda's ≈ 0.10; the
/// QR sum against `tr J = −k`.
///
/// Measured (600 periods, release): two trajectories 0.0966 ± 0.0048, QR 0.0938 ± 0.0040,
/// λ₁ + λ₂ = −0.05 to 3·10⁻¹¹; over 5000 periods 0.1025 ± 0.0019 and 0.1047 ± 0.0021.
/// Sections agree to 5.6·10⁻¹⁰ over 12 periods.
#[test]
fn duffing_ueda_against_hand_written_and_its_exponents() {
    use nonsmooth::integrate::Dop853;
    use nonsmooth::lyapunov::{Norm, TangentSpace, TwoTrajectory};
    use nonsmooth::systems::DuffingUeda;
    use nonsmooth::testing::DuffingUedaByHand;
    let p = DuffingUeda::default();
    let tight = Tolerances::new(1e-13, 1e-13).unwrap();
    let a = ueda_sections(p.model::<f64>().unwrap(), Dopri5::new(tight), 12);
    let b = ueda_sections(DuffingUedaByHand { params: p }, Dop853::new(tight), 12);
    assert_eq!((a.len(), b.len()), (12, 12));
    for (i, (u, v)) in a.iter().zip(&b).enumerate() {
        assert!((u - v).amax() < 1e-7, "section {i}: {u} vs {v}");
    }
    // A sign error in the cubic term or a sine load would not stay on Ueda's attractor.
    assert!(a.iter().all(|y| (1.0..3.6).contains(&y[0])), "{a:?}");

    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let tau = std::f64::consts::TAU;
    let y0 = Vector2::new(3.0, 0.0);
    let mut pair = TwoTrajectory::from_tolerances(
        p.model::<f64>().unwrap(),
        &tol,
        Dopri5::new,
        1e-8,
        Norm::Euclidean,
    )
    .unwrap();
    pair.start(0.0, y0).unwrap();
    pair.transient(tau, 50).unwrap();
    let two = pair.estimate(tau, 600).unwrap();
    let mut qr = TangentSpace::from_tolerances(
        p.model::<f64>().unwrap(),
        &tol,
        Dopri5::new,
        (1e-10, 1e-12),
        Norm::Euclidean,
    )
    .unwrap();
    qr.start(0.0, y0).unwrap();
    qr.transient(tau, 50).unwrap();
    let spec = qr.estimate(tau, 600).unwrap();
    for (name, l, s) in [
        ("two trajectories", two.exponent, two.spread),
        ("QR", spec.top(), spec.spread[0]),
    ] {
        assert!((l - 0.10).abs() < 3.0 * s + 0.02, "{name}: {l} ± {s}");
    }
    assert!((spec.sum() + p.k).abs() < 1e-8, "sum {}", spec.sum());
}
