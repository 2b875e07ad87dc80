//! Integration tests of parameter identification (`nonsmooth::identify`).

use std::cell::Cell;

use nonsmooth::identify::{
    FitTermination, IdentifyError, M2_TO_MM2, NelderMeadOptions, ParamValues, Parameter,
    ParameterSpace, Transform, fit_nelder_mead, objective_f0, objective_f0_mm2,
};
use nonsmooth::signal::{Location, SignalError, TimeSeries};

fn rosenbrock(p: &ParamValues) -> Result<f64, IdentifyError> {
    let (a, b) = (p.get("a")?, p.get("b")?);
    Ok((1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2))
}

// ---------------------------------------------------------------- Nelder–Mead

#[test]
fn rosenbrock_in_named_parameters() {
    let space = ParameterSpace::new([Parameter::new("a", -1.2), Parameter::new("b", 1.0)]).unwrap();
    let calls = Cell::new(0u64);
    let r = fit_nelder_mead(
        &space,
        |p| {
            calls.set(calls.get() + 1);
            rosenbrock(p)
        },
        &NelderMeadOptions::default().with_tolerances(1e-10, 1e-16),
    )
    .unwrap();
    assert_eq!(r.termination, FitTermination::Converged);
    assert!((r.values["a"] - 1.0).abs() < 1e-6, "{}", r.values);
    assert!((r.values["b"] - 1.0).abs() < 1e-6, "{}", r.values);
    assert!(r.objective < 1e-12);
    assert!((r.initial_objective - 24.2).abs() < 1e-13);
    assert_eq!(r.evaluations, calls.get());
    assert_eq!(r.failed_evaluations, 0);
    assert_eq!(r.history.len() as u64, r.iterations + 1);
    assert!(r.history.windows(2).all(|w| w[1] <= w[0]));
    assert_eq!(*r.history.last().unwrap(), r.objective);
    assert!(r.iterations <= 400, "{}", r.iterations);
    // Nelder–Mead makes 1–2 calls per iteration, n more on a shrink.
    assert!(r.evaluations >= r.iterations + 3 && r.evaluations <= 4 * r.iterations + 3);
}

#[test]
fn rosenbrock_with_log_parameters_and_scales() {
    // The same valley in parameters of very different scale, both log-transformed:
    // a = A/1e8, b = B·1e3, minimum at A = 1e8, B = 1e-3.
    let space = ParameterSpace::new([
        Parameter::positive("A", 0.5e8),
        Parameter::positive("B", 2.0e-3),
    ])
    .unwrap();
    let saw_nonpositive = Cell::new(false);
    let r = fit_nelder_mead(
        &space,
        |p| {
            let (a, b) = (p["A"] / 1e8, p["B"] * 1e3);
            if p["A"] <= 0.0 || p["B"] <= 0.0 {
                saw_nonpositive.set(true);
            }
            Ok::<_, String>((1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2))
        },
        &NelderMeadOptions::default().with_tolerances(1e-10, 1e-16),
    )
    .unwrap();
    assert!(!saw_nonpositive.get());
    assert!((r.values["A"] / 1e8 - 1.0).abs() < 1e-6, "{}", r.values);
    assert!((r.values["B"] * 1e3 - 1.0).abs() < 1e-6, "{}", r.values);
}

#[test]
fn failing_region_is_avoided_not_fatal() {
    // Minimum at (1.9, 0); the "simulation" fails for a > 2 (Err) and returns NaN for
    // a < -1: both are bad points, the fit still converges.
    let space = ParameterSpace::new([Parameter::new("a", 0.0), Parameter::new("b", 0.5)]).unwrap();
    let r = fit_nelder_mead(
        &space,
        |p| {
            let (a, b) = (p["a"], p["b"]);
            if a > 2.0 {
                return Err(format!("simulation diverged at a = {a}"));
            }
            if a < -1.0 {
                return Ok(f64::NAN);
            }
            Ok((a - 1.9).powi(2) + b * b)
        },
        &NelderMeadOptions::default().with_tolerances(1e-10, 1e-14),
    )
    .unwrap();
    assert_eq!(r.termination, FitTermination::Converged);
    assert!((r.values["a"] - 1.9).abs() < 1e-6, "{}", r.values);
    assert!(r.values["b"].abs() < 1e-6);
    assert!(r.failed_evaluations > 0);
    assert!(
        r.last_failure
            .as_deref()
            .is_some_and(|m| m.starts_with("simulation diverged") || m.contains("NaN")),
        "{:?}",
        r.last_failure
    );
    // A finite penalty instead of +∞ works as well.
    let r2 = fit_nelder_mead(
        &space,
        |p| {
            if p["a"] > 2.0 {
                Err("diverged")
            } else {
                Ok((p["a"] - 1.9).powi(2) + p["b"].powi(2))
            }
        },
        &NelderMeadOptions::default()
            .with_failure_penalty(1e6)
            .with_tolerances(1e-10, 1e-14),
    )
    .unwrap();
    assert!((r2.values["a"] - 1.9).abs() < 1e-6);
}

#[test]
fn bounds_are_respected_and_reached() {
    // Unconstrained minimum at (3, −2); bounds a ∈ [0, 2], b ≥ −1 put it at (2, −1).
    let space = ParameterSpace::new([
        Parameter::new("a", 1.0).with_bounds(0.0, 2.0),
        Parameter::new("b", 0.0).with_lower(-1.0),
        Parameter::positive("c", 5.0).with_upper(8.0),
    ])
    .unwrap();
    let violated = Cell::new(false);
    let r = fit_nelder_mead(
        &space,
        |p| {
            let (a, b, c) = (p["a"], p["b"], p["c"]);
            if !(0.0..=2.0).contains(&a) || b < -1.0 || !(c > 0.0 && c <= 8.0) {
                violated.set(true);
            }
            Ok::<_, String>((a - 3.0).powi(2) + (b + 2.0).powi(2) + (c.ln() - 1.0).powi(2))
        },
        &NelderMeadOptions::default().with_tolerances(1e-10, 1e-14),
    )
    .unwrap();
    assert!(!violated.get());
    assert!((r.values["a"] - 2.0).abs() < 1e-6, "{}", r.values);
    assert!((r.values["b"] + 1.0).abs() < 1e-6, "{}", r.values);
    assert!((r.values["c"] - 1f64.exp()).abs() < 1e-6, "{}", r.values);
    assert!((r.objective - 2.0).abs() < 1e-10);
}

#[test]
fn caps_target_and_restarts() {
    let space = ParameterSpace::new([Parameter::new("a", -1.2), Parameter::new("b", 1.0)]).unwrap();
    let r = fit_nelder_mead(
        &space,
        rosenbrock,
        &NelderMeadOptions::default().with_max_iterations(10),
    )
    .unwrap();
    assert_eq!(r.termination, FitTermination::MaxIterations);
    assert_eq!(r.iterations, 10);
    let r = fit_nelder_mead(
        &space,
        rosenbrock,
        &NelderMeadOptions::default().with_max_evaluations(30),
    )
    .unwrap();
    assert_eq!(r.termination, FitTermination::MaxEvaluations);
    assert!(r.evaluations >= 30 && r.evaluations < 30 + 4);
    let r = fit_nelder_mead(
        &space,
        rosenbrock,
        &NelderMeadOptions::default().with_target(1e-3),
    )
    .unwrap();
    assert_eq!(r.termination, FitTermination::TargetReached);
    assert!(r.objective <= 1e-3);
    // Restarts stop as soon as one brings no improvement; the history covers every run.
    let r = fit_nelder_mead(
        &space,
        rosenbrock,
        &NelderMeadOptions::default()
            .with_tolerances(1e-6, 1e-12)
            .with_restarts(5),
    )
    .unwrap();
    assert!(r.runs >= 2 && r.runs <= 6, "{}", r.runs);
    assert_eq!(r.history.len() as u64, r.iterations + r.runs as u64);
    assert!(r.history.windows(2).all(|w| w[1] <= w[0]));
    assert!((r.values["a"] - 1.0).abs() < 1e-5);
}

#[test]
fn parameter_values_by_name() {
    let space = ParameterSpace::new([
        Parameter::new("k", 1418.9),
        Parameter::positive("k_I", 2.3983e8),
    ])
    .unwrap();
    assert_eq!(space.parameters()[1].transform(), Transform::Log);
    let p = space.initial_values();
    assert_eq!(p.to_string(), "k = 1418.9, k_I = 239830000");
    assert_eq!(
        p.get("b"),
        Err(IdentifyError::UnknownParameter { name: "b".into() })
    );
    assert_eq!(space.index_of("k_I").unwrap(), 1);
    let v = space.values(vec![1000.0, 1e8]).unwrap();
    assert_eq!(
        v.iter().collect::<Vec<_>>(),
        vec![("k", 1000.0), ("k_I", 1e8)]
    );
    assert!(matches!(
        space.values(vec![1000.0, -1.0]),
        Err(IdentifyError::NonPositiveUnderLog { .. })
    ));
    assert!(matches!(
        space.values(vec![1000.0]),
        Err(IdentifyError::DimensionMismatch { .. })
    ));
}

// ---------------------------------------------------------------- F0

fn series(t: &[f64], f: impl Fn(f64) -> f64) -> TimeSeries {
    TimeSeries::new(t.to_vec(), t.iter().map(|&t| f(t)).collect(), None).unwrap()
}

#[test]
fn f0_of_a_linear_difference_is_the_trapezoid_sum() {
    // d(t) = a·t between measured (uniform grid) and simulation (another grid, linear data so
    // its interpolation is exact). The trapezoidal rule on d² = a²t² errs by Σ h_i³·a²/6.
    let a = 2e-3;
    let tm: Vec<f64> = (0..=1000).map(|i| i as f64 * 1e-3).collect();
    let measured = series(&tm, |t| 1e-3 + 5e-4 * t + a * t);
    let ts: Vec<f64> = (0..=333).map(|i| i as f64 * 3.003e-3).collect();
    let xs: Vec<f64> = ts.iter().map(|&t| 1e-3 + 5e-4 * t).collect();
    let (t1, t2) = (0.1234, 0.8766);
    let f0 = objective_f0(&measured, &ts, &xs, (t1, t2)).unwrap();
    let exact = a * a * (t2 * t2 * t2 - t1 * t1 * t1) / 3.0 / (t2 - t1);
    // Nodes: t1, samples in (t1, t2), t2.
    let mut nodes = vec![t1];
    nodes.extend(tm.iter().copied().filter(|&t| t > t1 && t < t2));
    nodes.push(t2);
    let trap_error: f64 = nodes
        .windows(2)
        .map(|w| (w[1] - w[0]).powi(3) * a * a / 6.0)
        .sum::<f64>()
        / (t2 - t1);
    assert!(
        (f0 - (exact + trap_error)).abs() < 1e-9 * exact,
        "{f0:e} vs {:e}",
        exact + trap_error
    );
    assert!(
        (objective_f0_mm2(&measured, &ts, &xs, (t1, t2)).unwrap() - f0 * M2_TO_MM2).abs() < 1e-20
    );
}

#[test]
fn f0_of_a_constant_offset_and_the_paper_scale() {
    // An offset of 0.09985 mm gives F0 = 0.00997 mm², the paper's value.
    let t: Vec<f64> = (0..=2000).map(|i| i as f64 * 5e-4).collect();
    let sim = |t: f64| 1e-3 * (20.465 * t).sin() - 2.0e-3;
    let off = 0.00997_f64.sqrt() * 1e-3;
    let measured = series(&t, |t| sim(t) + off);
    let xs: Vec<f64> = t.iter().map(|&t| sim(t)).collect();
    let f0 = objective_f0_mm2(&measured, &t, &xs, (0.0, 1.0)).unwrap();
    assert!((f0 - 0.00997).abs() < 1e-12, "{f0}");
}

#[test]
fn f0_window_and_data_errors() {
    let t: Vec<f64> = (0..=10).map(|i| i as f64 * 0.1).collect();
    let m = series(&t, |t| t);
    let x = t.clone();
    assert_eq!(
        objective_f0(&m, &t, &x, (0.5, 0.5)),
        Err(IdentifyError::InvalidWindow { t1: 0.5, t2: 0.5 })
    );
    assert!(matches!(
        objective_f0(&m, &t, &x, (f64::NAN, 0.5)),
        Err(IdentifyError::InvalidWindow { .. })
    ));
    assert!(matches!(
        objective_f0(&m, &t, &x, (-0.1, 0.5)),
        Err(IdentifyError::WindowOutsideData {
            which: "measured",
            ..
        })
    ));
    assert!(matches!(
        objective_f0(&m, &t[..5], &x[..5], (0.1, 0.5)),
        Err(IdentifyError::WindowOutsideData {
            which: "simulated",
            ..
        })
    ));
    assert_eq!(
        objective_f0(&m, &t, &x, (0.31, 0.39)),
        Err(IdentifyError::EmptyWindow {
            t1: 0.31,
            t2: 0.39,
            samples: 0
        })
    );
    let mut bad_t = t.clone();
    bad_t[4] = bad_t[3];
    assert_eq!(
        objective_f0(&m, &bad_t, &x, (0.1, 0.5)),
        Err(IdentifyError::Signal(SignalError::NonIncreasingTime {
            location: Location::Sample(4),
            previous: t[3],
            t: t[3]
        }))
    );
    assert!(matches!(
        objective_f0(&m, &t, &x[..3], (0.1, 0.5)),
        Err(IdentifyError::Signal(SignalError::LengthMismatch { .. }))
    ));
    // Identical records: F0 = 0 exactly.
    assert_eq!(objective_f0(&m, &t, &x, (0.0, 1.0)).unwrap(), 0.0);
}

#[test]
fn identification_recovers_a_damped_oscillation() {
    // "Measured": x(t) = A e^{−ζωt} cos(ω_d t), ω = 20.465, ζ = 0.05, A = 1 mm, sampled at
    // 2 kHz; "simulation": the same closed form on its own 1.5 kHz grid. F0 + Nelder–Mead
    // must return the true ω and ζ from a 10 % / 60 % wrong start.
    let model = |w: f64, z: f64, t: f64| {
        let wd = w * (1.0 - z * z).sqrt();
        1e-3 * (-z * w * t).exp() * (wd * t).cos()
    };
    let (w_true, z_true) = (20.465, 0.05);
    let tm: Vec<f64> = (0..=4000).map(|i| i as f64 * 5e-4).collect();
    let measured = series(&tm, |t| model(w_true, z_true, t));
    let ts: Vec<f64> = (0..=3000).map(|i| i as f64 / 1500.0).collect();
    let space = ParameterSpace::new([
        Parameter::positive("omega", 22.5),
        Parameter::new("zeta", 0.08).with_bounds(0.0, 1.0),
    ])
    .unwrap();
    let r = fit_nelder_mead(
        &space,
        |p| {
            let xs: Vec<f64> = ts
                .iter()
                .map(|&t| model(p["omega"], p["zeta"], t))
                .collect();
            objective_f0(&measured, &ts, &xs, (0.1, 1.9))
        },
        &NelderMeadOptions::default().with_tolerances(1e-8, 1e-12),
    )
    .unwrap();
    assert_eq!(r.termination, FitTermination::Converged);
    // The simulation's linear interpolation (h = 0.67 ms) biases F0 by O(h²), which moves
    // the optimum by far less than this.
    assert!(
        (r.values["omega"] / w_true - 1.0).abs() < 1e-4,
        "{}",
        r.values
    );
    assert!(
        (r.values["zeta"] / z_true - 1.0).abs() < 1e-3,
        "{}",
        r.values
    );
    assert!(r.objective < 1e-6 * r.initial_objective);
}

/// The generic fit on a catalogue system other than the paper's: the coupling stiffness and
/// the primary damping of the 2-DOF impact oscillator recovered from a noisy synthetic
/// record of the secondary mass (which hits its stop), starting 20 % off.
#[test]
fn model_fit_recovers_two_dof_parameters_from_a_noisy_record() {
    use nalgebra::SVector;
    use nonsmooth::identify::{ModelFit, Parameter};
    use nonsmooth::signal::ModelExperiment;
    use nonsmooth::systems::TwoDofImpact;

    let truth = TwoDofImpact::default();
    let omega = 0.7;
    let y0 = SVector::<f64, 4>::zeros();
    let data = ModelExperiment::new(truth.model::<f64>(omega).unwrap(), y0, 80.0)
        .unwrap()
        .with_component(1)
        .unwrap()
        .with_sample_interval(0.05)
        .unwrap()
        .with_noise(1e-3, 11)
        .unwrap()
        .generate_with_impacts(truth.stop::<f64>().unwrap())
        .unwrap();
    assert!(data.impacts.len() > 3, "{} impacts", data.impacts.len());
    let tol = nonsmooth::integrate::Tolerances::new(1e-10, 1e-12).unwrap();
    let fit = ModelFit::new(data.measured, (0.0, 80.0), 1, move |p| {
        let m = TwoDofImpact {
            k2: p.get("k2")?,
            c1: p.get("c1")?,
            ..truth
        };
        Ok((m.model::<f64>(omega)?, y0))
    })
    .unwrap()
    .fit_parameter(Parameter::positive("k2", 0.6))
    .unwrap()
    .fit_parameter(Parameter::positive("c1", 0.04))
    .unwrap()
    .with_tolerances(tol);
    let report = fit.run().unwrap();
    let k2 = report.values.get("k2").unwrap();
    let c1 = report.values.get("c1").unwrap();
    // Noise 1e-3 on an amplitude ≈ 0.2 over 1600 samples: the parameters are determined
    // to well under 1 %.
    assert!((k2 / truth.k2 - 1.0).abs() < 5e-3, "k2 = {k2}");
    assert!((c1 / truth.c1 - 1.0).abs() < 2e-2, "c1 = {c1}");
    // F0 at the optimum is the noise variance (1e-6) within sampling error.
    assert!(
        (report.objective / 1e-6 - 1.0).abs() < 0.15,
        "F0 = {}",
        report.objective
    );
    // An unknown name fails at the initial point, with a clear error.
    let bad = ModelFit::new(
        fit_record(),
        (0.0, 1.0),
        0,
        move |p: &nonsmooth::identify::ParamValues| {
            Ok((
                TwoDofImpact {
                    k1: p.get("kk")?,
                    ..truth
                }
                .model::<f64>(omega)?,
                y0,
            ))
        },
    )
    .unwrap()
    .fit_parameter(Parameter::positive("k1", 1.0))
    .unwrap();
    assert!(bad.run().is_err());
    assert!(
        ModelFit::new(
            fit_record(),
            (0.0, 1.0),
            4,
            |_p: &nonsmooth::identify::ParamValues| { Ok((truth.model::<f64>(omega)?, y0)) }
        )
        .is_err()
    );
}

fn fit_record() -> nonsmooth::signal::TimeSeries {
    let t: Vec<f64> = (0..=10).map(|i| 0.1 * i as f64).collect();
    nonsmooth::signal::TimeSeries::new(t, vec![0.0; 11], None).unwrap()
}
