//! Long calls off the interpreter: the work runs on a worker thread while the calling thread,
//! with the GIL released, waits in slices of 50 ms and checks for signals between them. On
//! Ctrl-C the cancel flag is set; the work observes it where the crate offers a hook (an
//! observer that stops the run, the sweep's per-value builder, the study's points) and
//! returns at once; the call raises `KeyboardInterrupt` without a result. Work with no hook
//! left (one estimator interval, one shooting problem) is left to finish on its thread after
//! a grace second, and its result is dropped: nothing is written half.

use std::panic::AssertUnwindSafe;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use nalgebra::SVector;
use nonsmooth::drive::{Control, EventRecord, Observer, StepView};
use nonsmooth::integrate::DenseOutput;
use pyo3::prelude::*;

use crate::errors::{Fail, NonsmoothError, Result};

/// The cancel flag of one call.
#[derive(Debug, Clone, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// Whether Ctrl-C was pressed.
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    fn set(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// `Err(Interrupted)` once Ctrl-C was pressed.
    pub fn check(&self) -> Result<()> {
        if self.is_set() {
            Err(Fail::Interrupted)
        } else {
            Ok(())
        }
    }
}

/// An observer that stops a run once the flag is set (the run then ends with
/// `Termination::ObserverStopped`, which the caller turns into `KeyboardInterrupt`).
#[derive(Debug, Clone)]
pub struct Watch(pub Cancel);

impl<const N: usize> Observer<f64, N> for Watch {
    fn on_step<D: DenseOutput<f64, N>>(&mut self, _step: &StepView<'_, f64, N, D>) -> Control {
        if self.0.is_set() {
            Control::Stop
        } else {
            Control::Continue
        }
    }
    fn on_event(&mut self, _e: &EventRecord<f64, N>) -> Control {
        if self.0.is_set() {
            Control::Stop
        } else {
            Control::Continue
        }
    }
}

/// The state at `y0` (filled in by the caller's checks).
pub fn state<const N: usize>(y: &[f64]) -> SVector<f64, N> {
    SVector::<f64, N>::from_iterator(y.iter().copied())
}

/// Runs `job` on a worker thread with the GIL released, checking for Ctrl-C every 50 ms.
///
/// # Errors
/// The job's failure as its exception; `KeyboardInterrupt` (or any exception a signal handler
/// raised) on Ctrl-C; `NonsmoothError` if the worker could not start or panicked (a defect:
/// inputs are checked before they reach the crate).
pub fn run<R, F>(py: Python<'_>, job: F) -> PyResult<R>
where
    R: Send + 'static,
    F: FnOnce(&Cancel) -> Result<R> + Send + 'static,
{
    run_with_progress(py, job, None)
}

/// A progress report: the counter the work increments, the total, and the Python callable
/// `callback(done, total)` called from the waiting thread when the counter moved.
pub type Progress<'py> = (Arc<AtomicUsize>, usize, Bound<'py, PyAny>);

/// [`run`], calling the progress callback (with the GIL) as the work advances.
///
/// # Errors
/// As [`run`]; an exception raised by the callback cancels the work and is raised.
pub fn run_with_progress<R, F>(
    py: Python<'_>,
    job: F,
    progress: Option<Progress<'_>>,
) -> PyResult<R>
where
    R: Send + 'static,
    F: FnOnce(&Cancel) -> Result<R> + Send + 'static,
{
    let mut reported = 0usize;
    let cancel = Cancel::default();
    let flag = cancel.clone();
    let (tx, rx) = channel();
    // `detach` needs a `Sync` handle on the receiver.
    let rx = std::sync::Mutex::new(rx);
    std::thread::Builder::new()
        .name("nonsmooth-worker".into())
        .stack_size(64 << 20)
        .spawn(move || {
            // Last resort: a panic is a defect, reported as an exception, never an abort.
            let out = std::panic::catch_unwind(AssertUnwindSafe(|| job(&flag)));
            let _ = tx.send(out);
        })
        .map_err(|e| NonsmoothError::new_err(format!("cannot start a worker thread: {e}")))?;
    loop {
        match py.detach(|| wait(&rx, Duration::from_millis(50))) {
            Ok(Ok(out)) => return out.map_err(Fail::into_py),
            Ok(Err(panic)) => {
                let what = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                return Err(NonsmoothError::new_err(format!(
                    "internal error (please report): {what}"
                )));
            }
            Err(RecvTimeoutError::Timeout) => {
                let report = match &progress {
                    Some((done, total, callback)) => {
                        let now = done.load(Ordering::Relaxed);
                        if now != reported {
                            reported = now;
                            callback.call1((now, *total)).map(|_| ())
                        } else {
                            Ok(())
                        }
                    }
                    None => Ok(()),
                };
                if let Err(e) = report.and_then(|_| py.check_signals()) {
                    cancel.set();
                    // Give the work a second to reach a hook and return.
                    let _ = py.detach(|| wait(&rx, Duration::from_secs(1)));
                    return Err(e);
                }
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(NonsmoothError::new_err(
                    "the worker thread ended without a result",
                ));
            }
        }
    }
}

type Outcome<R> = std::thread::Result<Result<R>>;

fn wait<R>(
    rx: &std::sync::Mutex<std::sync::mpsc::Receiver<Outcome<R>>>,
    timeout: Duration,
) -> std::result::Result<Outcome<R>, RecvTimeoutError> {
    match rx.lock() {
        Ok(rx) => rx.recv_timeout(timeout),
        Err(_) => Err(RecvTimeoutError::Disconnected),
    }
}
