//! Integrators: convergence orders on non-autonomous problems, dense output orders,
//! agreement between independent methods, bad input, determinism.

use nalgebra::{SVector, Vector1, Vector2};
use nonsmooth::Dynamics;
use nonsmooth::drive::RunError;
use nonsmooth::integrate::{
    DenseOutput, Dop853, Dopri5, IntegrateError, Rk4, Rosenbrock23, StepOptions, Stepper,
    Tolerances,
};

/// Least-squares slope of log(err) against log(h).
fn convergence_order(hs: &[f64], errs: &[f64]) -> Option<f64> {
    let n = hs.len() as f64;
    let lx: Vec<f64> = hs.iter().map(|h| h.ln()).collect();
    let ly: Vec<f64> = errs.iter().map(|e| e.ln()).collect();
    let mx = lx.iter().sum::<f64>() / n;
    let my = ly.iter().sum::<f64>() / n;
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    Some(sxy / sxx)
}

/// `x'' + x = cos 2t`, `x(0) = 1`, `v(0) = 0`: `x = 4/3·cos t − 1/3·cos 2t` (non-autonomous).
struct Forced;
impl Dynamics<f64, 2> for Forced {
    fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        dy[0] = y[1];
        dy[1] = -y[0] + (2.0 * t).cos();
    }
}
fn forced_exact(t: f64) -> Vector2<f64> {
    Vector2::new(
        4.0 / 3.0 * t.cos() - (2.0 * t).cos() / 3.0,
        -4.0 / 3.0 * t.sin() + 2.0 / 3.0 * (2.0 * t).sin(),
    )
}

/// `y' = y·cos t`, `y(0) = 1`: `y = exp(sin t)` (nonlinear in t, catches wrong nodes c_i).
struct ExpSin;
impl Dynamics<f64, 1> for ExpSin {
    fn rhs(&self, t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
        dy[0] = y[0] * t.cos();
    }
}

/// A stepper forced to take fixed steps `h`: huge tolerances, `h_init = h_max = h`.
fn fixed<St>(make: impl Fn(Tolerances<f64, 1>, StepOptions<f64>) -> St, h: f64) -> St {
    let tol = Tolerances::new(1e10, 1e10).unwrap();
    let opts = StepOptions::default()
        .with_h_init(h)
        .unwrap()
        .with_h_max(h)
        .unwrap();
    make(tol, opts)
}

fn global_error<St: Stepper<f64, 1>>(mut st: St, t_end: f64) -> f64 {
    st.reset_state(0.0, Vector1::new(1.0));
    while st.current().0 < t_end {
        st.step(&ExpSin, t_end).unwrap();
    }
    (st.current().1[0] - t_end.sin().exp()).abs()
}

fn measured_order<St: Stepper<f64, 1>>(make: impl Fn(f64) -> St, hs: &[f64], t_end: f64) -> f64 {
    let errs: Vec<f64> = hs.iter().map(|&h| global_error(make(h), t_end)).collect();
    convergence_order(hs, &errs).unwrap()
}

fn halvings(h0: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| h0 / 2f64.powi(i as i32)).collect()
}

#[test]
fn convergence_orders_on_a_non_autonomous_problem() {
    let p = measured_order(|h| Rk4::new(h).unwrap(), &halvings(0.2, 6), 3.0);
    assert!((p - 4.0).abs() < 0.15, "RK4 order {p}");
    let p = measured_order(|h| fixed(Dopri5::with_options, h), &halvings(0.2, 5), 3.0);
    assert!((p - 5.0).abs() < 0.15, "DOPRI5 order {p}");
    // Four levels only: at the fifth (h = 1/16) the 8th-order error (~1e-16) is below the
    // f64 round-off floor of the run (~1e-13).
    let p = measured_order(|h| fixed(Dop853::with_options, h), &halvings(1.0, 4), 2.0);
    assert!((p - 8.0).abs() < 0.15, "DOP853 order {p}");
    let p = measured_order(
        |h| fixed(Rosenbrock23::with_options, h),
        &halvings(0.05, 6),
        3.0,
    );
    assert!((p - 2.0).abs() < 0.15, "Rosenbrock23 order {p}");
}

/// Local error of the dense output at `t0 + 0.37h` after one step from the exact state:
/// `O(h^{p*+1})` for a dense output of order `p*`.
fn dense_local_order<St: Stepper<f64, 2>>(make: impl Fn(f64) -> St, hs: &[f64]) -> f64 {
    let t0 = 0.3;
    let errs: Vec<f64> = hs
        .iter()
        .map(|&h| {
            let mut st = make(h);
            st.reset_state(t0, forced_exact(t0));
            st.step(&Forced, t0 + h).unwrap();
            let t = t0 + 0.37 * h;
            let y = st.dense().interpolate(t).unwrap();
            (y - forced_exact(t)).norm()
        })
        .collect();
    convergence_order(hs, &errs).unwrap()
}

fn fixed2<St>(make: impl Fn(Tolerances<f64, 2>, StepOptions<f64>) -> St, h: f64) -> St {
    let tol = Tolerances::new(1e10, 1e10).unwrap();
    let opts = StepOptions::default()
        .with_h_init(h)
        .unwrap()
        .with_h_max(h)
        .unwrap();
    make(tol, opts)
}

#[test]
fn dense_output_orders() {
    // DOPRI5's continuous extension is 4th order: local error h^5.
    let p = dense_local_order(|h| fixed2(Dopri5::with_options, h), &halvings(0.4, 5));
    assert!((p - 5.0).abs() < 0.15, "DOPRI5 dense {p}");
    // DOP853's dense output is 7th order: local error h^8.
    let p = dense_local_order(|h| fixed2(Dop853::with_options, h), &halvings(1.6, 5));
    assert!((p - 8.0).abs() < 0.15, "DOP853 dense {p}");
    // Cubic Hermite: local error h^4.
    let p = dense_local_order(|h| Rk4::new(h).unwrap(), &halvings(0.4, 5));
    assert!((p - 4.0).abs() < 0.15, "Hermite dense {p}");
    // Rosenbrock23's own interpolant is 2nd order: local error h^3.
    let p = dense_local_order(|h| fixed2(Rosenbrock23::with_options, h), &halvings(0.1, 5));
    assert!((p - 3.0).abs() < 0.15, "Rosenbrock23 dense {p}");
}

fn adaptive_end<St: Stepper<f64, 2>>(mut st: St, t_end: f64) -> Vector2<f64> {
    st.reset_state(0.0, forced_exact(0.0));
    while st.current().0 < t_end {
        st.step(&Forced, t_end).unwrap();
    }
    assert_eq!(
        st.current().0,
        t_end,
        "the last step lands exactly on the limit"
    );
    *st.current().1
}

#[test]
fn adaptive_methods_meet_their_tolerance_and_agree() {
    let t_end = 20.0;
    let exact = forced_exact(t_end);
    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let a = adaptive_end(Dopri5::new(tol), t_end);
    let b = adaptive_end(Dop853::new(tol), t_end);
    let c = adaptive_end(
        Rosenbrock23::new(Tolerances::new(1e-9, 1e-11).unwrap()),
        t_end,
    );
    assert!((a - exact).norm() < 1e-8, "{}", (a - exact).norm());
    assert!((b - exact).norm() < 1e-8, "{}", (b - exact).norm());
    assert!((a - b).norm() < 1e-8);
    // A 2nd-order method whose local error is controlled: global error ~ 10³·rtol here.
    assert!((c - exact).norm() < 1e-5, "{}", (c - exact).norm());
}

/// A stiff linear problem `y' = −λ(y − cos t)`, λ = 1e5: the implicit method takes
/// far fewer steps than the explicit one.
struct Stiff;
impl Dynamics<f64, 1> for Stiff {
    fn rhs(&self, t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
        dy[0] = -1e5 * (y[0] - t.cos());
    }
    fn jacobian(&self, _t: f64, _y: &Vector1<f64>) -> Option<nalgebra::Matrix1<f64>> {
        Some(nalgebra::Matrix1::new(-1e5))
    }
}

fn run_to<St: Stepper<f64, 1>>(st: &mut St, t_end: f64) -> f64 {
    st.reset_state(0.0, Vector1::new(1.0));
    while st.current().0 < t_end {
        st.step(&Stiff, t_end).unwrap();
    }
    st.current().1[0]
}

#[test]
fn rosenbrock_pays_on_a_stiff_problem() {
    let tol = Tolerances::new(1e-6, 1e-9).unwrap();
    let mut ros = Rosenbrock23::new(tol);
    let mut dp = Dopri5::new(tol);
    let yr = run_to(&mut ros, 2.0);
    let yd = run_to(&mut dp, 2.0);
    // Quasi-static solution y ≈ cos t + sin t/λ.
    let exact = 2.0_f64.cos() + 2.0_f64.sin() / 1e5;
    assert!((yr - exact).abs() < 1e-5, "{yr} vs {exact}");
    assert!((yd - exact).abs() < 1e-5, "{yd} vs {exact}");
    assert!(
        ros.stats().rhs_evals * 20 < dp.stats().rhs_evals,
        "{:?} vs {:?}",
        ros.stats(),
        dp.stats()
    );
}

#[test]
fn bad_input_is_reported() {
    use nonsmooth::drive::Simulation;
    let tol = Tolerances::new(1e-8, 1e-10).unwrap();
    let mut sim = Simulation::new(Forced, Dopri5::new(tol));
    let e = sim
        .run(0.0, Vector2::new(f64::NAN, 0.0), 1.0, &mut ())
        .unwrap_err();
    assert!(
        matches!(
            e,
            RunError::Integrate(IntegrateError::NonFiniteState { index: 0, .. })
        ),
        "{e}"
    );
    let e = sim
        .run(0.0, Vector2::new(1.0, f64::INFINITY), 1.0, &mut ())
        .unwrap_err();
    assert!(
        matches!(
            e,
            RunError::Integrate(IntegrateError::NonFiniteState { index: 1, .. })
        ),
        "{e}"
    );
    let e = sim
        .run(1.0, Vector2::new(1.0, 0.0), 0.5, &mut ())
        .unwrap_err();
    assert!(
        matches!(
            e,
            RunError::Integrate(IntegrateError::InvalidTimeSpan { .. })
        ),
        "{e}"
    );
    let e = sim
        .run(0.0, Vector2::new(1.0, 0.0), f64::NAN, &mut ())
        .unwrap_err();
    assert!(
        matches!(
            e,
            RunError::Integrate(IntegrateError::InvalidTimeSpan { .. })
        ),
        "{e}"
    );
    assert!(Tolerances::<f64, 2>::new(0.0, 1e-9).is_err());
    assert!(Tolerances::<f64, 2>::new(1e-6, -1.0).is_err());
    assert!(Tolerances::<f64, 2>::per_component(1e-6, [1e-9, 0.0]).is_err());
    assert!(Tolerances::<f64, 2>::new(f64::NAN, 1e-9).is_err());
    assert!(Rk4::<f64, 2>::new(0.0).is_err());
    assert!(Rk4::<f64, 2>::new(-1e-3).is_err());
    assert!(StepOptions::<f64>::default().with_h_max(0.0).is_err());
    // A stepper used before it has a state.
    let mut st = Dopri5::<f64, 2>::new(tol);
    assert_eq!(
        st.step(&Forced, 1.0).unwrap_err(),
        IntegrateError::NotInitialized
    );
    // The step cap ends a run with an error instead of running on.
    let mut sim = Simulation::new(Forced, Dopri5::new(tol))
        .max_steps(10)
        .unwrap();
    let e = sim.run(0.0, forced_exact(0.0), 100.0, &mut ()).unwrap_err();
    assert!(
        matches!(
            e,
            RunError::Integrate(IntegrateError::MaxSteps { max_steps: 10, .. })
        ),
        "{e}"
    );
    assert!(
        Simulation::new(Forced, Dopri5::new(tol))
            .max_steps(0)
            .is_err()
    );
}

/// A right-hand side that turns NaN beyond t = 1.
struct Blows;
impl Dynamics<f64, 2> for Blows {
    fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        dy[0] = y[1];
        dy[1] = if t > 1.0 { f64::NAN } else { -y[0] };
    }
}

#[test]
fn nan_mid_run_is_an_error_not_a_hang() {
    use nonsmooth::drive::Simulation;
    let tol = Tolerances::new(1e-8, 1e-10).unwrap();
    for e in [
        Simulation::new(Blows, Dopri5::new(tol))
            .run(0.0, Vector2::new(1.0, 0.0), 5.0, &mut ())
            .unwrap_err(),
        Simulation::new(Blows, Dop853::new(tol))
            .run(0.0, Vector2::new(1.0, 0.0), 5.0, &mut ())
            .unwrap_err(),
        Simulation::new(Blows, Rosenbrock23::new(tol))
            .run(0.0, Vector2::new(1.0, 0.0), 5.0, &mut ())
            .unwrap_err(),
        Simulation::new(Blows, Rk4::new(0.01).unwrap())
            .run(0.0, Vector2::new(1.0, 0.0), 5.0, &mut ())
            .unwrap_err(),
    ] {
        assert!(
            matches!(
                e,
                RunError::Integrate(
                    IntegrateError::NonFiniteRhs { .. } | IntegrateError::StepSizeTooSmall { .. }
                )
            ),
            "{e}"
        );
    }
}

#[test]
fn f32_integration() {
    struct Osc;
    impl Dynamics<f32, 2> for Osc {
        fn rhs(&self, _t: f32, y: &SVector<f32, 2>, dy: &mut SVector<f32, 2>) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }
    let mut st = Dopri5::new(Tolerances::<f32, 2>::new(1e-5, 1e-6).unwrap());
    st.reset_state(0.0, SVector::<f32, 2>::new(1.0, 0.0));
    while st.current().0 < 3.0 {
        st.step(&Osc, 3.0).unwrap();
    }
    assert!((st.current().1[0] - 3.0_f32.cos()).abs() < 1e-4);
}

/// `ẍ = −x`, autonomous: the error after 10 s does not depend on where the clock starts.
struct Harmonic1;
impl Dynamics<f64, 2> for Harmonic1 {
    fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }
}

/// The error of a run of `ẍ = −x` from `(1, 0)` at `t0` to `t0 + 10`.
fn clock_error<St: Stepper<f64, 2>>(st: St, t0: f64) -> f64 {
    let mut sim = nonsmooth::drive::Simulation::new(Harmonic1, st);
    let span = (t0 + 10.0) - t0;
    let out = sim
        .run(t0, Vector2::new(1.0, 0.0), t0 + 10.0, &mut ())
        .unwrap();
    let exact = Vector2::new(span.cos(), -span.sin());
    (out.y - exact).norm()
}

#[test]
fn adaptive_steppers_keep_their_accuracy_far_from_t_0() {
    // A run counts its time from its start (Stepper::start: the clock is t₀ + τ, τ the
    // sum of the steps). Before, far from 0 the state advanced by h and the clock by
    // fl(t + h) − t, and at rtol 1e-10 the errors from 1e9 / 1e12 were 3.2e-7 / 1.1e-3
    // (DOPRI5) against 3.0e-10 from 0; now they are those from 0.
    let tol = Tolerances::new(1e-10, 1e-10).unwrap();
    for t0 in [1e9, 1e12] {
        let pairs = [
            (
                "DOPRI5",
                clock_error(Dopri5::new(tol), 0.0),
                clock_error(Dopri5::new(tol), t0),
            ),
            (
                "DOP853",
                clock_error(Dop853::new(tol), 0.0),
                clock_error(Dop853::new(tol), t0),
            ),
            (
                "Tsit5",
                clock_error(nonsmooth::integrate::Tsit5::new(tol), 0.0),
                clock_error(nonsmooth::integrate::Tsit5::new(tol), t0),
            ),
            (
                "Vern6",
                clock_error(nonsmooth::integrate::Vern6::new(tol), 0.0),
                clock_error(nonsmooth::integrate::Vern6::new(tol), t0),
            ),
        ];
        for (name, from0, far) in pairs {
            println!("{name}: error {from0:.2e} from 0, {far:.2e} from {t0:e}");
            assert!(
                far <= 2.0 * from0 && from0 < 1e-8,
                "{name} from {t0:e}: {far:e} against {from0:e}"
            );
        }
    }
}

#[test]
fn a_relative_tolerance_below_the_arithmetic_is_refused() {
    // rtol = atol = 1e-300 was accepted, and Tsit5 crept to the step cap near t = 0.
    for (rtol, atol) in [(1e-300, 1e-300), (1e-17, 1e-10), (f64::EPSILON / 2.0, 1.0)] {
        let e = Tolerances::<f64, 2>::new(rtol, atol)
            .unwrap_err()
            .to_string();
        assert!(e.contains("rtol") && e.contains("machine epsilon"), "{e}");
        assert!(Tolerances::<f64, 2>::per_component(rtol, [atol; 2]).is_err());
    }
    assert!(Tolerances::<f64, 2>::new(f64::EPSILON, 1e-300).is_ok());
    assert!(Tolerances::<f32, 2>::new(1e-8, 1e-8).is_err());
    // Set through the public field: refused by the run's check.
    let mut tol = Tolerances::<f64, 2>::new(1e-10, 1e-10).unwrap();
    tol.rtol[1] = 1e-300;
    let mut sim =
        nonsmooth::drive::Simulation::new(Harmonic1, nonsmooth::integrate::Tsit5::new(tol));
    let e = sim
        .run(0.0, Vector2::new(1.0, 0.0), 2.0, &mut ())
        .unwrap_err();
    assert!(e.to_string().contains("rtol"), "{e}");
}
