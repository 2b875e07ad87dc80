//! The `nonsmooth` Python package's extension module (`nonsmooth._nonsmooth`): systems from
//! the crate's catalogue or described with the study files' schema, and the crate's
//! instruments, numpy in and out. The Python layer (`nonsmooth/*.py`) validates shapes and
//! packs the results into dataclasses; this module checks every value again before the
//! crate sees it, runs the work off the interpreter (`interrupt`), and raises the crate's
//! errors as exceptions (`errors`).

mod analysis;
mod errors;
mod family;
mod filippov;
mod interrupt;
mod lanes;
mod record;
mod runs;
mod stepping;
mod study;
mod system;

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicUsize;

use numpy::{PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::analysis::{ContinuationSpec, Detect, LyapunovSpec, OrbitSpec, SweepSpec, finite};
use crate::errors::{Fail, value};
use crate::interrupt::Cancel;
use crate::runs::RunSpec;
use crate::system::{PySystem, check_state};
use nonsmooth::sweep::SweepDirection;

/// The most samples, events or grid values one call returns (10⁸ doubles: 800 MB).
const MAX_OUTPUT: usize = 100_000_000;

fn positive(name: &str, v: f64) -> Result<(), Fail> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(value(format!("{name} must be finite and > 0 (got {v})")))
    }
}

fn y0_or_rest(sys: &PySystem, y0: Option<Vec<f64>>) -> Result<Vec<f64>, Fail> {
    let y0 = match y0 {
        Some(y) => y,
        None => sys.kind.rest_state()?,
    };
    check_state("y0", &y0, sys.kind.dimension())?;
    Ok(y0)
}

fn check_atol(sys: &PySystem, atol: &Option<Vec<f64>>) -> Result<(), Fail> {
    if let Some(a) = atol {
        let n = sys.kind.dimension();
        if a.len() != n {
            return Err(value(format!(
                "atol has {} components; the system's state has {n}",
                a.len()
            )));
        }
        for (i, &x) in a.iter().enumerate() {
            if !(x.is_finite() && x > 0.0) {
                return Err(value(format!("atol[{i}] must be finite and > 0 (got {x})")));
            }
        }
    }
    Ok(())
}

fn check_rtol(rtol: f64) -> Result<(), Fail> {
    positive("rtol", rtol)?;
    if rtol >= 1.0 {
        return Err(value(format!("rtol must be < 1 (got {rtol})")));
    }
    Ok(())
}

/// Runs a system from `t0` to `t_end`; samples at `t_eval` (sorted, within the span).
#[pyfunction]
#[pyo3(signature = (system, t0, t_end, y0, t_eval, rtol, atol, max_steps, max_events))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    system: &PySystem,
    t0: f64,
    t_end: f64,
    y0: Option<Vec<f64>>,
    t_eval: PyReadonlyArray1<'py, f64>,
    rtol: f64,
    atol: Option<Vec<f64>>,
    max_steps: usize,
    max_events: usize,
) -> PyResult<Bound<'py, PyDict>> {
    time_span(t0, t_end)?;
    let t_eval = t_eval.to_vec()?;
    if t_eval.len() > MAX_OUTPUT {
        return Err(value(format!(
            "t_eval has {} times; at most {MAX_OUTPUT}",
            t_eval.len()
        ))
        .into());
    }
    for (i, &t) in t_eval.iter().enumerate() {
        if !(t >= t0 && t <= t_end) || (i > 0 && t < t_eval[i - 1]) {
            return Err(value(format!(
                "t_eval must be sorted within [t0, t_end] (t_eval[{i}] = {t})"
            ))
            .into());
        }
    }
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    if max_steps == 0 {
        return Err(value("max_steps must be >= 1").into());
    }
    let y0 = y0_or_rest(system, y0)?;
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |cancel: &Cancel| {
        runs::simulate(
            &kind,
            RunSpec {
                t0,
                t_end,
                y0,
                t_eval,
                rtol,
                atol,
                max_steps,
                max_events: max_events.min(MAX_OUTPUT),
                cancel: cancel.clone(),
            },
        )
    })?;
    rec.into_py(py)
}

/// The impact sequence on one surface from `record_from` on.
#[pyfunction]
#[pyo3(signature = (system, t0, t_end, y0, record_from, surface, rtol, atol, max_steps, capacity))]
#[allow(clippy::too_many_arguments)]
fn impacts<'py>(
    py: Python<'py>,
    system: &PySystem,
    t0: f64,
    t_end: f64,
    y0: Option<Vec<f64>>,
    record_from: f64,
    surface: usize,
    rtol: f64,
    atol: Option<Vec<f64>>,
    max_steps: usize,
    capacity: usize,
) -> PyResult<Bound<'py, PyDict>> {
    time_span(t0, t_end)?;
    if !record_from.is_finite() {
        return Err(value(format!("record_from must be finite (got {record_from})")).into());
    }
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    if max_steps == 0 || capacity == 0 || capacity > MAX_OUTPUT {
        return Err(value(format!(
            "max_steps must be >= 1 and capacity in [1, {MAX_OUTPUT}]"
        ))
        .into());
    }
    let y0 = y0_or_rest(system, y0)?;
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |cancel: &Cancel| {
        let run = RunSpec {
            t0,
            t_end,
            y0,
            t_eval: Vec::new(),
            rtol,
            atol,
            max_steps,
            max_events: 0,
            cancel: cancel.clone(),
        };
        runs::impacts(&kind, surface, run, record_from, capacity)
    })?;
    rec.into_py(py)
}

fn detect(period_tol: f64, max_period: usize, max_steps: usize) -> Result<Detect, Fail> {
    positive("period_tol", period_tol)?;
    if max_period == 0 || max_steps == 0 {
        return Err(value("max_period and max_steps must be >= 1"));
    }
    Ok(Detect {
        period_tol,
        max_period,
        max_steps,
    })
}

/// The stroboscopic section of one run.
#[pyfunction]
#[pyo3(signature = (system, y0, transient, record, surface, rtol, atol, period_tol, max_period, max_steps))]
#[allow(clippy::too_many_arguments)]
fn poincare<'py>(
    py: Python<'py>,
    system: &PySystem,
    y0: Option<Vec<f64>>,
    transient: u32,
    record: u32,
    surface: usize,
    rtol: f64,
    atol: Option<Vec<f64>>,
    period_tol: f64,
    max_period: usize,
    max_steps: usize,
) -> PyResult<Bound<'py, PyDict>> {
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    let d = detect(period_tol, max_period, max_steps)?;
    if record == 0 {
        return Err(value("record must be >= 1").into());
    }
    if u64::from(transient) + u64::from(record) > nonsmooth::study::MAX_PERIODS {
        return Err(value(format!(
            "transient + record = {} periods; at most {}",
            u64::from(transient) + u64::from(record),
            nonsmooth::study::MAX_PERIODS
        ))
        .into());
    }
    let y0 = y0_or_rest(system, y0)?;
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |_: &Cancel| {
        analysis::poincare(&kind, surface, y0, transient, record, rtol, atol, d)
    })?;
    rec.into_py(py)
}

/// A sweep over a parameter.
#[pyfunction]
#[pyo3(signature = (system, parameter, values, direction, continuation, transient_first, transient_step, record, y0, surface, rtol, atol, period_tol, max_period, max_steps, hysteresis_tol))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    system: &PySystem,
    parameter: String,
    values: PyReadonlyArray1<'py, f64>,
    direction: &str,
    continuation: bool,
    transient_first: u32,
    transient_step: u32,
    record: u32,
    y0: Option<Vec<f64>>,
    surface: usize,
    rtol: f64,
    atol: Option<Vec<f64>>,
    period_tol: f64,
    max_period: usize,
    max_steps: usize,
    hysteresis_tol: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let values = values.to_vec()?;
    if values.len() > nonsmooth::sweep::MAX_VALUES {
        return Err(value(format!(
            "{} values; at most {}",
            values.len(),
            nonsmooth::sweep::MAX_VALUES
        ))
        .into());
    }
    finite("values", &values)?;
    system.kind.parameter(&parameter)?;
    let direction = match direction {
        "up" => SweepDirection::Up,
        "down" => SweepDirection::Down,
        "both" => SweepDirection::Both,
        other => {
            return Err(value(format!(
                "direction must be 'up', 'down' or 'both' (got {other:?})"
            ))
            .into());
        }
    };
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    positive("hysteresis_tol", hysteresis_tol)?;
    let d = detect(period_tol, max_period, max_steps)?;
    let y0 = y0_or_rest(system, y0)?;
    // Every value must give a valid system: fail here, naming it, not inside the sweep.
    for &v in &values {
        system
            .kind
            .with_parameter(&parameter, v)
            .map_err(|e| e.context(&format!("{parameter} = {v}")))?;
    }
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |cancel: &Cancel| {
        analysis::run_sweep(
            &kind,
            surface,
            SweepSpec {
                parameter,
                values,
                direction,
                continuation,
                transient_first,
                transient_step,
                record,
                y0,
                rtol,
                atol,
                detect: d,
                hysteresis_tol,
                cancel: cancel.clone(),
            },
        )
    })?;
    rec.into_py(py)
}

/// Lyapunov exponents.
#[pyfunction]
#[pyo3(signature = (system, method, y0, t0, tau, transient, intervals, d0, rtol, atol))]
#[allow(clippy::too_many_arguments)]
fn lyapunov<'py>(
    py: Python<'py>,
    system: &PySystem,
    method: &str,
    y0: Option<Vec<f64>>,
    t0: f64,
    tau: Option<f64>,
    transient: usize,
    intervals: usize,
    d0: Option<f64>,
    rtol: f64,
    atol: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let spectrum = match method {
        "two_trajectory" => false,
        "spectrum" => true,
        other => {
            return Err(value(format!(
                "method must be 'two_trajectory' or 'spectrum' (got {other:?})"
            ))
            .into());
        }
    };
    if !t0.is_finite() {
        return Err(value(format!("t0 must be finite (got {t0})")).into());
    }
    if let Some(t) = tau {
        positive("tau", t)?;
    }
    if let Some(d) = d0 {
        positive("d0", d)?;
    }
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    let y0 = y0_or_rest(system, y0)?;
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |cancel: &Cancel| {
        analysis::lyapunov(
            &kind,
            LyapunovSpec {
                spectrum,
                y0,
                t0,
                tau,
                transient,
                intervals,
                d0,
                rtol,
                atol,
                cancel: cancel.clone(),
            },
        )
    })?;
    rec.into_py(py)
}

/// A periodic orbit by shooting.
#[pyfunction]
#[pyo3(signature = (system, y0, t0, multiple, period, rtol, atol, xtol, max_iterations))]
#[allow(clippy::too_many_arguments)]
fn periodic_orbit<'py>(
    py: Python<'py>,
    system: &PySystem,
    y0: Option<Vec<f64>>,
    t0: f64,
    multiple: u32,
    period: Option<f64>,
    rtol: f64,
    atol: Option<Vec<f64>>,
    xtol: f64,
    max_iterations: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if !t0.is_finite() {
        return Err(value(format!("t0 must be finite (got {t0})")).into());
    }
    if multiple == 0 {
        return Err(value("multiple must be >= 1").into());
    }
    if let Some(p) = period {
        positive("period", p)?;
    }
    positive("xtol", xtol)?;
    if max_iterations == 0 {
        return Err(value("max_iterations must be >= 1").into());
    }
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    let y0 = y0_or_rest(system, y0)?;
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |_: &Cancel| {
        analysis::periodic_orbit(
            &kind,
            OrbitSpec {
                y0,
                t0,
                multiple,
                period,
                rtol,
                atol,
                xtol,
                max_iterations,
            },
        )
    })?;
    rec.into_py(py)
}

/// A branch of periodic orbits followed in a parameter.
#[pyfunction]
#[pyo3(signature = (system, parameter, lo, hi, step, max_step, max_points, downward, multiple, y0, t0, rtol, atol, grazing, contact_changes, period))]
#[allow(clippy::too_many_arguments)]
fn continuation<'py>(
    py: Python<'py>,
    system: &PySystem,
    parameter: String,
    lo: f64,
    hi: f64,
    step: f64,
    max_step: Option<f64>,
    max_points: Option<usize>,
    downward: bool,
    multiple: u32,
    y0: Option<Vec<f64>>,
    t0: f64,
    rtol: f64,
    atol: Option<Vec<f64>>,
    grazing: Option<(usize, f64, bool)>,
    contact_changes: bool,
    period: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    system.kind.parameter(&parameter)?;
    if let Some(p) = period {
        positive("period", p)?;
    }
    if !t0.is_finite() {
        return Err(value(format!("t0 must be finite (got {t0})")).into());
    }
    if multiple == 0 {
        return Err(value("multiple must be >= 1").into());
    }
    if let Some((c, level, _)) = grazing {
        if c >= system.kind.dimension() || !level.is_finite() {
            return Err(value(format!(
                "grazing: component {c} must be < {} and the level finite (got {level})",
                system.kind.dimension()
            ))
            .into());
        }
    }
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    let y0 = y0_or_rest(system, y0)?;
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |_: &Cancel| {
        analysis::continuation(
            &kind,
            ContinuationSpec {
                parameter,
                lo,
                hi,
                step,
                max_step,
                max_points,
                downward,
                multiple,
                y0,
                t0,
                rtol,
                atol,
                grazing,
                contact_changes,
            },
            period,
        )
    })?;
    rec.into_py(py)
}

/// The entropy index of samples.
#[pyfunction]
#[pyo3(signature = (samples, lo, hi, step, q_range))]
fn tsallis_q<'py>(
    py: Python<'py>,
    samples: PyReadonlyArray1<'py, f64>,
    lo: f64,
    hi: f64,
    step: f64,
    q_range: Option<(f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let samples = samples.to_vec()?;
    let rec = interrupt::run(py, move |_: &Cancel| {
        analysis::tsallis_q(&samples, lo, hi, step, q_range)
    })?;
    rec.into_py(py)
}

/// Many starts of one system in SIMD lanes.
#[pyfunction]
#[pyo3(signature = (system, parameter, values, y0s, transient, record, surface, rtol, atol, period_tol, max_period, max_steps))]
#[allow(clippy::too_many_arguments)]
fn ensemble<'py>(
    py: Python<'py>,
    system: &PySystem,
    parameter: Option<String>,
    values: PyReadonlyArray1<'py, f64>,
    y0s: Vec<Vec<f64>>,
    transient: u32,
    record: u32,
    surface: usize,
    rtol: f64,
    atol: Option<Vec<f64>>,
    period_tol: f64,
    max_period: usize,
    max_steps: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let values = values.to_vec()?;
    finite("values", &values)?;
    if let Some(name) = &parameter {
        system.kind.parameter(name)?;
    }
    let n = values.len().max(y0s.len());
    if n == 0 || n > nonsmooth::sweep::MAX_VALUES {
        return Err(value(format!(
            "{n} starts; between 1 and {}",
            nonsmooth::sweep::MAX_VALUES
        ))
        .into());
    }
    if parameter.is_some() && values.len() != n {
        return Err(value(format!("{} values for {n} starts", values.len())).into());
    }
    if y0s.len() != 1 && y0s.len() != n {
        return Err(value(format!("{} initial states for {n} starts", y0s.len())).into());
    }
    for (j, y) in y0s.iter().enumerate() {
        check_state(&format!("y0[{j}]"), y, system.kind.dimension())?;
    }
    if record == 0 {
        return Err(value("record must be >= 1").into());
    }
    check_rtol(rtol)?;
    check_atol(system, &atol)?;
    let d = detect(period_tol, max_period, max_steps)?;
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |cancel: &Cancel| {
        lanes::ensemble(
            &kind,
            surface,
            lanes::EnsembleSpec {
                parameter,
                values,
                y0s,
                transient,
                record,
                rtol,
                atol,
                detect: d,
                cancel: cancel.clone(),
            },
        )
    })?;
    rec.into_py(py)
}

/// Moreau–Jean time-stepping.
#[pyfunction]
#[pyo3(signature = (system, t0, t_end, h, theta, q0, v0, every, max_records, impact_speed))]
#[allow(clippy::too_many_arguments)]
fn timestep<'py>(
    py: Python<'py>,
    system: &PySystem,
    t0: f64,
    t_end: f64,
    h: f64,
    theta: f64,
    q0: Option<Vec<f64>>,
    v0: Option<Vec<f64>>,
    every: usize,
    max_records: usize,
    impact_speed: f64,
) -> PyResult<Bound<'py, PyDict>> {
    time_span(t0, t_end)?;
    positive("h", h)?;
    if (t_end - t0) / h > 1e10 {
        return Err(value(format!(
            "{} steps of h = {h}; at most 1e10",
            (t_end - t0) / h
        ))
        .into());
    }
    positive("impact_speed", impact_speed)?;
    if every == 0 || max_records == 0 || max_records > MAX_OUTPUT {
        return Err(value(format!(
            "every must be >= 1 and max_records in [1, {MAX_OUTPUT}]"
        ))
        .into());
    }
    for (what, x) in [("q0", &q0), ("v0", &v0)] {
        if let Some(x) = x {
            finite(what, x)?;
        }
    }
    let kind = system.kind.clone();
    let rec = interrupt::run(py, move |cancel: &Cancel| {
        stepping::timestep(
            &kind,
            stepping::StepSpec {
                t0,
                t_end,
                h,
                theta,
                q0,
                v0,
                every,
                max_records,
                impact_speed,
                cancel: cancel.clone(),
            },
        )
    })?;
    rec.into_py(py)
}

/// Runs one shard of a study file into a directory.
#[pyfunction]
#[pyo3(signature = (spec, out, shard, count, progress))]
fn study_run<'py>(
    py: Python<'py>,
    spec: PathBuf,
    out: PathBuf,
    shard: usize,
    count: usize,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let total = study::points(&spec)?;
    let done = Arc::new(AtomicUsize::new(0));
    let counter = done.clone();
    let rec = interrupt::run_with_progress(
        py,
        move |cancel: &Cancel| study::run(spec, out, (shard, count), counter, cancel),
        progress.map(|p| (done, total, p)),
    )?;
    rec.into_py(py)
}

/// Merges the shards of a study.
#[pyfunction]
#[pyo3(signature = (dir, out))]
fn study_merge<'py>(
    py: Python<'py>,
    dir: PathBuf,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let rec = interrupt::run(py, move |_: &Cancel| study::merge(dir, out))?;
    rec.into_py(py)
}

#[pymodule]
fn _nonsmooth(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<PySystem>()?;
    m.add_function(wrap_pyfunction!(system::paper, m)?)?;
    m.add_function(wrap_pyfunction!(system::duffing_ueda, m)?)?;
    m.add_function(wrap_pyfunction!(system::two_dof_impact, m)?)?;
    m.add_function(wrap_pyfunction!(system::bouncing_ball, m)?)?;
    m.add_function(wrap_pyfunction!(system::relay_feedback, m)?)?;
    m.add_function(wrap_pyfunction!(system::woodpecker, m)?)?;
    m.add_function(wrap_pyfunction!(system::belt_friction, m)?)?;
    m.add_function(wrap_pyfunction!(system::describe_json, m)?)?;
    m.add_function(wrap_pyfunction!(system::describe_toml, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(impacts, m)?)?;
    m.add_function(wrap_pyfunction!(poincare, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(lyapunov, m)?)?;
    m.add_function(wrap_pyfunction!(periodic_orbit, m)?)?;
    m.add_function(wrap_pyfunction!(continuation, m)?)?;
    m.add_function(wrap_pyfunction!(tsallis_q, m)?)?;
    m.add_function(wrap_pyfunction!(ensemble, m)?)?;
    m.add_function(wrap_pyfunction!(timestep, m)?)?;
    m.add_function(wrap_pyfunction!(study_run, m)?)?;
    m.add_function(wrap_pyfunction!(study_merge, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

/// A time span `(t0, t_end)` must be finite with `t_end > t0`.
fn time_span(t0: f64, t_end: f64) -> PyResult<()> {
    if t0.is_finite() && t_end.is_finite() && t_end > t0 {
        Ok(())
    } else {
        Err(value(format!(
            "the time span must be finite with t_end > t0 (got t0 = {t0}, t_end = {t_end})"
        ))
        .into())
    }
}
