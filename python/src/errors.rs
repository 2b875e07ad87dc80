//! The crate's errors as Python exceptions: rejected input is a `ValueError` carrying the
//! crate's message (which names the value); a run that fails is a `NonsmoothError`, or one
//! of its subclasses for the failures a caller may want to catch by kind.

use nonsmooth::Error;
use nonsmooth::event::EventError;
use nonsmooth::integrate::IntegrateError;
use nonsmooth::lyapunov::LyapunovError;
use nonsmooth::orbit::OrbitError;
use nonsmooth::sweep::{RunFailure, SweepError};
use pyo3::exceptions::{PyException, PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    _nonsmooth,
    NonsmoothError,
    PyException,
    "A run of the engine failed (the message is the crate's)."
);
pyo3::create_exception!(
    _nonsmooth,
    ZenoError,
    NonsmoothError,
    "Events accumulated (Zeno) or a body stuck to a surface where the run cannot follow."
);
pyo3::create_exception!(
    _nonsmooth,
    WorkLimitError,
    NonsmoothError,
    "A run reached its step or work cap (`max_steps`)."
);
pyo3::create_exception!(
    _nonsmooth,
    ConvergenceError,
    NonsmoothError,
    "An iteration (Newton on a periodic orbit, a root search) did not converge."
);
pyo3::create_exception!(
    _nonsmooth,
    IntegrationError,
    NonsmoothError,
    "The integrator failed (step size too small, a non-finite right-hand side)."
);
pyo3::create_exception!(
    _nonsmooth,
    StudyError,
    NonsmoothError,
    "A study failed (missing or inconsistent shards, a damaged shard, an i/o error)."
);

/// What went wrong, decided on the worker thread and raised with the GIL.
#[derive(Debug, Clone, PartialEq)]
pub enum Fail {
    /// Rejected input: `ValueError`.
    Value(String),
    /// A failed run: `NonsmoothError`.
    Run(String),
    /// An accumulation of events: `ZenoError`.
    Zeno(String),
    /// A step or work cap: `WorkLimitError`.
    Work(String),
    /// No convergence: `ConvergenceError`.
    Convergence(String),
    /// The integrator failed: `IntegrationError`.
    Integration(String),
    /// A study failed: `StudyError` (a rejected spec is a `ValueError`).
    Study(String),
    /// Stopped by Ctrl-C: `KeyboardInterrupt`.
    Interrupted,
}

pub type Result<T> = std::result::Result<T, Fail>;

impl Fail {
    /// The exception.
    pub fn into_py(self) -> PyErr {
        match self {
            Fail::Value(m) => PyValueError::new_err(m),
            Fail::Run(m) => NonsmoothError::new_err(m),
            Fail::Zeno(m) => ZenoError::new_err(m),
            Fail::Work(m) => WorkLimitError::new_err(m),
            Fail::Convergence(m) => ConvergenceError::new_err(m),
            Fail::Integration(m) => IntegrationError::new_err(m),
            Fail::Study(m) => StudyError::new_err(m),
            Fail::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
        }
    }

    /// The same kind with `context: ` before the message.
    pub fn context(self, context: &str) -> Self {
        let f = |m: String| format!("{context}: {m}");
        match self {
            Fail::Value(m) => Fail::Value(f(m)),
            Fail::Run(m) => Fail::Run(f(m)),
            Fail::Zeno(m) => Fail::Zeno(f(m)),
            Fail::Work(m) => Fail::Work(f(m)),
            Fail::Convergence(m) => Fail::Convergence(f(m)),
            Fail::Integration(m) => Fail::Integration(f(m)),
            Fail::Study(m) => Fail::Study(f(m)),
            Fail::Interrupted => Fail::Interrupted,
        }
    }
}

impl From<Fail> for PyErr {
    fn from(f: Fail) -> Self {
        f.into_py()
    }
}

/// A `ValueError` with `message`.
pub fn value(message: impl Into<String>) -> Fail {
    Fail::Value(message.into())
}

/// The kind of an integrator error, with `message`.
fn integrate(e: &IntegrateError, message: String) -> Fail {
    match e {
        IntegrateError::MaxSteps { .. } | IntegrateError::WorkExceedsCap { .. } => {
            Fail::Work(message)
        }
        IntegrateError::InvalidTimeSpan { .. }
        | IntegrateError::NonFiniteState { .. }
        | IntegrateError::InvalidSettings(_)
        | IntegrateError::Parameter(_) => Fail::Value(message),
        _ => Fail::Integration(message),
    }
}

/// The kind of an event error, with `message`.
fn event(e: &EventError, message: String) -> Fail {
    match e {
        EventError::Zeno { .. } | EventError::Sticking { .. } => Fail::Zeno(message),
        EventError::IndexOutOfRange { .. } => Fail::Value(message),
        _ => Fail::Run(message),
    }
}

/// The kind of the run failure inside a sweep, with the sweep's whole `message`.
fn failure(e: &RunFailure, message: String) -> Fail {
    match e {
        RunFailure::Parameter(_) | RunFailure::Model(_) => Fail::Value(message),
        RunFailure::Integrate(i) => integrate(i, message),
        RunFailure::Event(ev) => event(ev, message),
        RunFailure::Root(_) => Fail::Convergence(message),
        _ => Fail::Run(message),
    }
}

fn lyapunov(e: &LyapunovError, message: String) -> Fail {
    match e {
        LyapunovError::UnresolvedSeparation { .. } => Fail::Run(message),
        LyapunovError::InvalidSeparation { .. }
        | LyapunovError::InvalidInterval { .. }
        | LyapunovError::TooFewIntervals { .. }
        | LyapunovError::TooManyIntervals { .. }
        | LyapunovError::InvalidBlocks { .. }
        | LyapunovError::InvalidWeight { .. }
        | LyapunovError::InvalidDirection
        | LyapunovError::Dimension { .. } => Fail::Value(message),
        _ => classify(&Error::from(e.clone())).with_message(message),
    }
}

fn orbit(e: &OrbitError, message: String) -> Fail {
    match e {
        OrbitError::NotConverged { .. } | OrbitError::Singular { .. } => Fail::Convergence(message),
        OrbitError::InvalidSetting { .. } => Fail::Value(message),
        OrbitError::Run(r) => classify(&Error::from(r.clone())).with_message(message),
        OrbitError::Lyapunov(l) => lyapunov(l, message),
        _ => Fail::Run(message),
    }
}

impl Fail {
    fn with_message(self, message: String) -> Self {
        match self {
            Fail::Value(_) => Fail::Value(message),
            Fail::Run(_) => Fail::Run(message),
            Fail::Zeno(_) => Fail::Zeno(message),
            Fail::Work(_) => Fail::Work(message),
            Fail::Convergence(_) => Fail::Convergence(message),
            Fail::Integration(_) => Fail::Integration(message),
            Fail::Study(_) => Fail::Study(message),
            Fail::Interrupted => Fail::Interrupted,
        }
    }
}

/// The crate's error as the exception of its kind, with the crate's message.
pub fn classify(e: &Error) -> Fail {
    let message = e.to_string();
    match e {
        Error::Parameter(_) | Error::Model(_) => Fail::Value(message),
        Error::Integrate(i) => integrate(i, message),
        Error::Event(ev) => event(ev, message),
        Error::Root(_) => Fail::Convergence(message),
        Error::Sweep(SweepError::Failed { source, .. }) => failure(source, message),
        Error::Sweep(_) => Fail::Value(message),
        Error::Lyapunov(l) => lyapunov(l, message),
        Error::Orbit(o) => orbit(o, message),
        Error::Entropy(en) => {
            use nonsmooth::entropy::EntropyError;
            match en {
                EntropyError::SingleState | EntropyError::Equiprobable { .. } => Fail::Run(message),
                _ => Fail::Value(message),
            }
        }
        _ => Fail::Run(message),
    }
}

impl From<Error> for Fail {
    fn from(e: Error) -> Self {
        classify(&e)
    }
}

macro_rules! via_error {
    ($($t:ty),*) => {$(
        impl From<$t> for Fail {
            fn from(e: $t) -> Self {
                classify(&Error::from(e))
            }
        }
    )*};
}
via_error!(
    nonsmooth::ParameterError,
    nonsmooth::drive::RunError,
    IntegrateError,
    EventError,
    SweepError,
    LyapunovError,
    OrbitError,
    nonsmooth::entropy::EntropyError
);

impl From<nonsmooth::study::StudyError> for Fail {
    fn from(e: nonsmooth::study::StudyError) -> Self {
        use nonsmooth::study::StudyError as S;
        let message = e.to_string();
        match e {
            S::Toml(_) | S::InvalidSpec { .. } | S::InvalidPlan { .. } => Fail::Value(message),
            _ => Fail::Study(message),
        }
    }
}

impl From<nonsmooth::filippov::FilippovError> for Fail {
    fn from(e: nonsmooth::filippov::FilippovError) -> Self {
        use nonsmooth::filippov::FilippovError as F;
        let message = e.to_string();
        match &e {
            F::Run(r) => classify(&Error::from(r.clone())).with_message(message),
            F::NoConvergence { .. } | F::Singular { .. } => Fail::Convergence(message),
            _ => Fail::Run(message),
        }
    }
}

impl From<nonsmooth::timestep::TimeStepError> for Fail {
    fn from(e: nonsmooth::timestep::TimeStepError) -> Self {
        use nonsmooth::timestep::TimeStepError as T;
        let message = e.to_string();
        match &e {
            T::Parameter(_) | T::Dimension { .. } => Fail::Value(message),
            _ => Fail::Run(message),
        }
    }
}

/// Registers the exceptions in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("NonsmoothError", py.get_type::<NonsmoothError>())?;
    m.add("ZenoError", py.get_type::<ZenoError>())?;
    m.add("WorkLimitError", py.get_type::<WorkLimitError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add("IntegrationError", py.get_type::<IntegrationError>())?;
    m.add("StudyError", py.get_type::<StudyError>())?;
    Ok(())
}
