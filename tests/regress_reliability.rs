//! Regressions of the reliability probe: no loop without progress in the integrators, the
//! driver and the samplers; invalid settings set through public fields are errors before
//! the first step.

use nalgebra::Vector2;
use nonsmooth::drive::RunError;
use nonsmooth::drive::Simulation;
use nonsmooth::excite::RampedRotor;
use nonsmooth::integrate::{
    Dop853, Dopri5, IntegrateError, Rk4, Rosenbrock23, StepOptions, Stepper, Tolerances,
};
use nonsmooth::sample::{PhaseClock, Stroboscopic};
use nonsmooth::signal::PhaseSection;
use nonsmooth::testing::HarmonicOscillator;

fn osc() -> HarmonicOscillator<f64> {
    HarmonicOscillator::new(1.0).unwrap()
}

fn tol() -> Tolerances<f64, 2> {
    Tolerances::new(1e-8, 1e-10).unwrap()
}

fn y0() -> Vector2<f64> {
    Vector2::new(1.0, 0.0)
}

#[test]
fn nan_tolerances_through_public_fields_fail_before_the_first_step() {
    // Before: rtol NaN gave a minimum step of 0 at t0 = 0 and uncapped rejections.
    let mut bad = tol();
    bad.rtol[1] = f64::NAN;
    let r = Simulation::new(osc(), Dopri5::new(bad)).run(0.0, y0(), 1.0, &mut ());
    assert!(
        matches!(
            r,
            Err(RunError::Integrate(IntegrateError::InvalidSettings(_)))
        ),
        "{r:?}"
    );
    let mut neg = tol();
    neg.atol[0] = -1.0;
    let r = Simulation::new(osc(), Dop853::new(neg)).run(0.0, y0(), 1.0, &mut ());
    assert!(matches!(
        r,
        Err(RunError::Integrate(IntegrateError::InvalidSettings(_)))
    ));
    // Step options through public fields.
    let mut opts = StepOptions::default();
    opts.fac_min = f64::NAN;
    let r = Simulation::new(osc(), Rosenbrock23::with_options(tol(), opts)).run(
        0.0,
        y0(),
        1.0,
        &mut (),
    );
    assert!(matches!(
        r,
        Err(RunError::Integrate(IntegrateError::InvalidSettings(_)))
    ));
    // Driven directly (no driver): the stepper still terminates, with an error.
    let mut st = Dopri5::new(bad);
    st.reset_state(0.0, y0());
    assert!(st.step(&osc(), 1.0).is_err());
}

#[test]
fn a_step_below_the_time_resolution_is_an_error_not_a_loop() {
    // Before: Rk4 with h = 1e-12 at t0 = 1e6 made no progress (t + h == t) until the cap.
    let mut st = Rk4::<f64, 2>::new(1e-12).unwrap();
    st.reset_state(1e6, y0());
    let r = st.step(&osc(), 1e6 + 1.0);
    assert!(
        matches!(r, Err(IntegrateError::StepSizeTooSmall { .. })),
        "{r:?}"
    );
    // Through the driver the work bound catches it first.
    let r = Simulation::new(osc(), Rk4::new(1e-12).unwrap()).run(1e6, y0(), 1e6 + 1.0, &mut ());
    assert!(
        matches!(
            r,
            Err(RunError::Integrate(IntegrateError::WorkExceedsCap { .. }))
        ),
        "{r:?}"
    );
}

#[test]
fn work_that_provably_exceeds_the_cap_fails_at_once() {
    // h_max = 1e-300; h_max = 1e-7 over 1e3 s; a landing grid of 1e-9 over 1 s. Before,
    // each ran to the 10^8-step cap (18–46 s).
    for (h_max, t_end) in [(1e-300, 1.0), (1e-7, 1e3)] {
        let opts = StepOptions::default().with_h_max(h_max).unwrap();
        let r = Simulation::new(osc(), Dopri5::with_options(tol(), opts)).run(
            0.0,
            y0(),
            t_end,
            &mut (),
        );
        match r {
            Err(RunError::Integrate(IntegrateError::WorkExceedsCap {
                needed, max_steps, ..
            })) => {
                assert!(needed >= t_end / h_max * 0.999 && max_steps == 100_000_000);
            }
            other => panic!("h_max {h_max}: {other:?}"),
        }
    }
    let r = Simulation::new(osc(), Dopri5::new(tol()))
        .landing_grid(Some((0.0, 1e-9)))
        .unwrap()
        .run(0.0, y0(), 1.0, &mut ());
    assert!(
        matches!(
            r,
            Err(RunError::Integrate(IntegrateError::WorkExceedsCap { .. }))
        ),
        "{r:?}"
    );
    // An ordinary h_max still runs.
    let opts = StepOptions::default().with_h_max(0.01).unwrap();
    let out = Simulation::new(osc(), Dopri5::with_options(tol(), opts))
        .run(0.0, y0(), 10.0, &mut ())
        .unwrap();
    assert!(out.stats.accepted >= 1000);
}

#[test]
fn section_clocks_too_fine_for_the_span_are_errors_and_late_starts_are_fast() {
    // Period 1e-300: 10^300 sections per run. Before, the sampler looped inside one step.
    let mut s = Stroboscopic::<f64, 2>::periodic(0.0, 1e-300, 0.0, 10).unwrap();
    let r = Simulation::new(osc(), Dopri5::new(tol())).run(0.0, y0(), 1.0, &mut s);
    assert!(matches!(r, Err(RunError::Parameter(_))), "{r:?}");
    // A period below the time resolution at t0 = 1e6 (sections coincide).
    let mut s = Stroboscopic::<f64, 2>::periodic(0.0, 1e-11, 0.0, 10).unwrap();
    let r = Simulation::new(osc(), Dopri5::new(tol())).run(1e6, y0(), 1e6 + 1e-9, &mut s);
    assert!(matches!(r, Err(RunError::Parameter(_))), "{r:?}");
    // A phase clock started at t0 = 1e11: before, the first section index was counted up
    // from 0 (≈ 10^11 calls). Now a bisection; sections are then taken as usual.
    let rotor = RampedRotor::new(0.01, 20.0, 1e-9).unwrap();
    let mut s = Stroboscopic::<f64, 2, _>::new(PhaseClock(rotor), 0.0, 100).unwrap();
    let t0 = 1e11;
    let out = Simulation::new(osc(), Dopri5::new(tol()))
        .run(t0, y0(), t0 + 10.0, &mut s)
        .unwrap();
    assert_eq!(out.t, t0 + 10.0);
    let pts = s.points();
    // ω(t0) = 20 + 100 = 120 rad/s: ≈ 191 sections in 10 s, capacity 100.
    assert_eq!(pts.len(), 100);
    assert!(pts[0].t >= t0 && pts[0].t < t0 + 0.06, "{}", pts[0].t);
    assert!(pts.windows(2).all(|w| w[1].index == w[0].index + 1));
}

#[test]
fn phase_sections_reject_unresolvable_phases_instead_of_overflowing() {
    // Before: offset −1.7e308 (the probe used −1.8e308, which is −inf as a literal) overflowed the i64 level index; a phase of 1e20 cannot
    // resolve levels 2π apart.
    assert!(PhaseSection::<f64>::new().with_offset(-1.7e308).is_err());
    assert!(PhaseSection::<f64>::new().with_offset(1e13).is_err());
    let sec = PhaseSection::<f64>::new()
        .with_input(nonsmooth::signal::PhaseInput::Unwrapped)
        .with_offset(0.5)
        .unwrap();
    let t = [0.0, 1.0, 2.0];
    let x = [0.0, 1.0, 2.0];
    assert!(sec.sample(&t, &[1e20, 1e20 + 1e5, 1e20 + 2e5], &x).is_err());
    assert!(sec.sample(&t, &[0.0, 1e13, 2e13], &x).is_err());
    // An ordinary unwrapped phase still works: levels 0.5, 6.78, 13.07, 19.35 in 0..20.
    let pts = sec.sample(&t, &[0.0, 10.0, 20.0], &x).unwrap();
    assert_eq!(pts.len(), 4);
}

/// Probe values of the reliability issue: each was accepted and later gave NaN/∞ from
/// finite input; each is now rejected by its constructor (or evaluates finitely).
#[test]
fn constructors_reject_what_would_later_be_nan() {
    use nonsmooth::ForceLaw;
    use nonsmooth::excite::{Excitation, UnbalancedRotor};
    use nonsmooth::force::{DryFriction, HertzContact};
    assert!(UnbalancedRotor::new(0.49, 1e265).is_err());
    assert!(RampedRotor::new(2.0, 3e184, 0.5).is_err());
    assert!(DryFriction::sqrt(8.5, 1.6e-308).is_err());
    let h = HertzContact::new(0.0, 1e8)
        .unwrap()
        .with_damping(0.8, 1.5, 0.2)
        .unwrap();
    assert!(h.with_rate_regularization(1e-300).is_err());
    // The exact law (η = 0, n3 < 1): ∂F/∂v at v = 0 in contact is the largest finite
    // value, as documented (it was +∞), also for a subnormal n3.
    for n3 in [0.2_f64, 5e-324] {
        let exact = HertzContact::new(0.0_f64, 1e8)
            .unwrap()
            .with_damping(0.8, 1.5, n3)
            .unwrap();
        let (dx, dv) = exact.partials(1e-3, 0.0);
        assert!(dx.is_finite() && dv.is_finite(), "n3 {n3}: {dx} {dv}");
        assert!(exact.force(1e-3, 0.0).is_finite());
    }
    let r = UnbalancedRotor::new(0.49_f64, 1e30).unwrap();
    assert!(r.force(1.0).is_finite() && r.force_rate(1.0).is_finite());
}

#[test]
fn lyapunov_interval_counts_and_times_are_bounded() {
    use nonsmooth::lyapunov::{LyapunovError, Norm, TwoTrajectory, decades};
    // decades(i32::MIN, i32::MAX, 1) overflowed; now clamped to the f64 range.
    let d = decades::<f64>(i32::MIN, i32::MAX, 1);
    assert_eq!(d.len(), 616);
    assert!(d.iter().all(|v| v.is_finite() && *v > 0.0));
    assert!(decades::<f64>(0, 1, usize::MAX).len() <= 1_000_001);
    let mut est =
        TwoTrajectory::from_tolerances(osc(), &tol(), Dopri5::new, 1e-8, Norm::Euclidean).unwrap();
    // estimate(τ, usize::MAX) panicked with a capacity overflow.
    est.start(0.0, y0()).unwrap();
    let r = est.estimate(1.0, usize::MAX);
    assert!(
        matches!(r, Err(LyapunovError::TooManyIntervals { .. })),
        "{r:?}"
    );
    // At t0 = 1e17 an interval of 1 does not advance time: it reported 0 ± 0.
    est.start(1e17, y0()).unwrap();
    let r = est.estimate(1.0, 10);
    assert!(
        matches!(r, Err(LyapunovError::InvalidInterval { .. })),
        "{r:?}"
    );
}

mod properties {
    use super::*;
    use nonsmooth::ForceLaw;
    use nonsmooth::excite::{Excitation, UnbalancedRotor};
    use nonsmooth::force::{Bilinear, CubicSpring, DryFriction, HertzContact};
    use proptest::prelude::*;

    /// Magnitudes 1e-100 … 1e100 with either sign, and 0.
    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            Just(0.0),
            (-100.0f64..100.0, any::<bool>()).prop_map(|(e, s)| {
                let v = 10f64.powf(e);
                if s { v } else { -v }
            }),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        /// A constructor either rejects its input or returns a law that never yields NaN
        /// at moderate states (|x|, |v| ≤ 1e3 around the contact point), and never panics.
        #[test]
        fn accepted_laws_never_yield_nan(a in value(), b in value(), c in value(), d in value()) {
            let states = [(0.0, 0.0), (1e-3, 0.0), (1e-3, -1.0), (-1.0, 1e3), (1e3, -1e-3)];
            let check = |f: &dyn Fn(f64, f64) -> (f64, f64, f64)| {
                for &(x, v) in &states {
                    let (g, p, q) = f(x, v);
                    assert!(!g.is_nan() && !p.is_nan() && !q.is_nan(), "({x}, {v}): {g} {p} {q}");
                }
            };
            if let Ok(l) = DryFriction::sqrt(a.abs(), b) {
                check(&|x, v| { let (p, q) = l.partials(x, v); (l.force(x, v), p, q) });
            }
            if let Ok(l) = DryFriction::tanh(a.abs(), b) {
                check(&|x, v| { let (p, q) = l.partials(x, v); (l.force(x, v), p, q) });
            }
            if let Ok(l) = HertzContact::new(0.0, a)
                .and_then(|h| h.with_damping(b, 1.5, c.abs()))
                .and_then(|h| h.with_rate_regularization(d.abs()))
            {
                check(&|x, v| { let (p, q) = l.partials(x * 1e-6, v); (l.force(x * 1e-6, v), p, q) });
            }
            if let Ok(l) = CubicSpring::new(a, b) {
                check(&|x, v| { let (p, q) = l.partials(x, v); (l.force(x, v), p, q) });
            }
            if let Ok(l) = Bilinear::new(a.abs(), b.abs(), c.min(d), c.max(d)) {
                check(&|x, v| { let (p, q) = l.partials(x, v); (l.force(x, v), p, q) });
            }
            if let Ok(r) = UnbalancedRotor::new(a.abs(), b) {
                for t in [0.0, 1.0, 1e3] {
                    prop_assert!(r.force(t).is_finite() && r.force_rate(t).is_finite());
                }
            }
            if let Ok(r) = RampedRotor::new(a.abs(), b, c) {
                prop_assert!(r.force(0.0).is_finite() && r.force_rate(0.0).is_finite());
            }
        }
    }
}

#[test]
fn implicit_method_on_the_exact_contact_law_reports_the_cause() {
    // The exact law (η = 0, n3 < 1) has ∂F/∂v = ∞ at v = 0 in contact, reported as the
    // largest finite value. Rosenbrock23 started at rest in contact used to step on with
    // it: the stage and the error estimate in v vanished, the velocity stayed 0 and the
    // run ended with a wrong state (about 2 evaluations per period; 6.9e-4 m off at
    // ω = 17 against DOPRI5). It now stops with the cause; DOPRI5 runs the same start.
    use nonsmooth::Dynamics;
    use nonsmooth::systems::paper::PAPER;
    let p = nonsmooth::systems::paper::PaperParameters { eta: 0.0, ..PAPER };
    let sys = p.oscillator(14.0_f64).unwrap();
    let x0 = p.x_i + 1e-6; // in contact: δ = x − x_I > 0
    let y0 = Vector2::new(x0, 0.0);
    let mut f = Vector2::zeros();
    sys.rhs(0.0, &y0, &mut f);
    assert!(f.iter().all(|v| v.is_finite()));
    let jac = sys.jacobian(0.0, &y0).unwrap();
    assert!(jac.iter().all(|v| v.is_finite()), "{jac}");
    let stepper = Rosenbrock23::new(Tolerances::new(1e-8, 1e-10).unwrap());
    let err = Simulation::new(sys, stepper)
        .run(0.0, y0, 0.05, &mut ())
        .unwrap_err();
    assert!(
        matches!(
            err,
            nonsmooth::drive::RunError::Integrate(IntegrateError::InfiniteJacobian {
                row: 1,
                col: 1,
                ..
            })
        ),
        "{err}"
    );
    assert!(err.to_string().contains("Jacobian is infinite"), "{err}");
    // The explicit method integrates the same start and leaves rest.
    let out = Simulation::new(sys, Dopri5::new(Tolerances::new(1e-8, 1e-10).unwrap()))
        .run(0.0, y0, 0.05, &mut ())
        .unwrap();
    assert!(out.y[1] != 0.0 && out.stats.accepted > 0);
    // Off v = 0 the partial is finite: the implicit method runs, and agrees with DOPRI5.
    let y1 = Vector2::new(x0, 1e-6);
    let tol = Tolerances::new(1e-8, 1e-10).unwrap();
    let r = Simulation::new(sys, Rosenbrock23::new(tol))
        .run(0.0, y1, 0.05, &mut ())
        .unwrap();
    let d = Simulation::new(sys, Dopri5::new(tol))
        .run(0.0, y1, 0.05, &mut ())
        .unwrap();
    assert!((r.y[0] - d.y[0]).abs() < 1e-9, "{} vs {}", r.y, d.y);
}
