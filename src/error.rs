//! The crate's error type.
//!
//! One non-generic [`Error`](enum@Error) collects the module errors. Diagnostics are stored as `f64`
//! (whatever the scalar type of the computation) so that errors are `Send + Sync + 'static`
//! and can be printed, logged and matched without generic parameters.

use thiserror::Error;

pub use crate::validate::ParameterError;

/// The crate's error: every fallible function returns [`Result`].
#[derive(Debug, Clone, Error)]
#[non_exhaustive]
pub enum Error {
    /// A constructor rejected a parameter.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// A bracketing root search failed.
    #[error(transparent)]
    Root(#[from] crate::roots::RootError),
    /// A model could not be assembled or analysed.
    #[error(transparent)]
    Model(#[from] crate::model::ModelError),
    /// Time integration failed.
    #[error(transparent)]
    Integrate(#[from] crate::integrate::IntegrateError),
    /// Event handling failed (e.g. an accumulation of events).
    #[error(transparent)]
    Event(#[from] crate::event::EventError),
    /// A run through modes (sticking, stick–slip) was started inconsistently or left its
    /// constraint.
    #[error(transparent)]
    Mode(#[from] crate::drive::ModeError),
    /// A sampler or sweep was misconfigured or failed.
    #[error(transparent)]
    Sweep(#[from] crate::sweep::SweepError),
    /// A Lyapunov estimate failed.
    #[error(transparent)]
    Lyapunov(crate::lyapunov::LyapunovError),
    /// A periodic orbit could not be computed.
    #[error(transparent)]
    Orbit(crate::orbit::OrbitError),
    /// An entropy estimate failed.
    #[error(transparent)]
    Entropy(#[from] crate::entropy::EntropyError),
    /// A harmonic analysis or approximation failed.
    #[error(transparent)]
    Analysis(#[from] crate::analysis::AnalysisError),
    /// Measured data could not be read or processed.
    #[error(transparent)]
    Signal(crate::signal::SignalError),
    /// Parameter identification failed.
    #[error(transparent)]
    Identify(crate::identify::IdentifyError),
    /// A Filippov run (sliding on switching surfaces) or its monodromy failed.
    #[error(transparent)]
    Filippov(#[from] crate::filippov::FilippovError),
    /// A time-stepping run (Moreau–Jean) failed.
    #[error(transparent)]
    TimeStep(#[from] crate::timestep::TimeStepError),
    /// A complementarity problem was not solved.
    #[error(transparent)]
    Lcp(#[from] crate::timestep::lcp::LcpError),
    /// Writing output failed.
    #[error("output error: {0}")]
    Output(String),
}

impl From<std::io::Error> for Error {
    /// Reading or writing a file or stream: [`Error::Output`] with the system's message.
    fn from(e: std::io::Error) -> Self {
        Error::Output(format!("input/output: {e}"))
    }
}

impl From<csv::Error> for Error {
    /// Reading or writing CSV: [`Error::Output`] with the reader's or writer's message.
    fn from(e: csv::Error) -> Self {
        Error::Output(format!("CSV: {e}"))
    }
}

impl From<crate::drive::RunError> for Error {
    /// Variant by variant: a run's error keeps its kind (`RunError::Event(e)` becomes
    /// [`Error::Event`]`(e)`).
    fn from(e: crate::drive::RunError) -> Self {
        use crate::drive::RunError;
        match e {
            RunError::Parameter(e) => Error::Parameter(e),
            RunError::Root(e) => Error::Root(e),
            RunError::Model(e) => Error::Model(e),
            RunError::Integrate(e) => Error::Integrate(e),
            RunError::Event(e) => Error::Event(e),
            RunError::Mode(e) => Error::Mode(e),
        }
    }
}

impl From<crate::signal::SignalError> for Error {
    /// A simulation's error keeps its kind (`SignalError::Run(e)` becomes `Error::from(e)`,
    /// e.g. [`Error::Integrate`]); the others become [`Error::Signal`].
    fn from(e: crate::signal::SignalError) -> Self {
        use crate::signal::SignalError;
        match e {
            SignalError::Run(e) => e.into(),
            e => Error::Signal(e),
        }
    }
}

impl From<crate::identify::IdentifyError> for Error {
    /// A simulation's error keeps its kind (`IdentifyError::Run(e)` becomes
    /// `Error::from(e)`, e.g. [`Error::Integrate`]); the others become [`Error::Identify`].
    fn from(e: crate::identify::IdentifyError) -> Self {
        use crate::identify::IdentifyError;
        match e {
            IdentifyError::Run(e) => e.into(),
            e => Error::Identify(e),
        }
    }
}

impl From<Error> for crate::identify::IdentifyError {
    /// For model builders ([`ModelFit`](crate::identify::ModelFit)) that use the crate's
    /// constructors: the module error inside `e` (a run's kinds as
    /// [`IdentifyError::Run`](crate::identify::IdentifyError::Run)), or the message of an
    /// error without a variant there ([`IdentifyError::Other`](crate::identify::IdentifyError::Other)).
    fn from(e: Error) -> Self {
        use crate::drive::RunError;
        use crate::identify::IdentifyError;
        match e.into_run() {
            Ok(RunError::Parameter(e)) => IdentifyError::Parameter(e),
            Ok(e) => IdentifyError::Run(e),
            Err(Error::Signal(e)) => e.into(),
            Err(Error::Identify(e)) => e,
            Err(other) => IdentifyError::Other(other.to_string()),
        }
    }
}

impl From<crate::lyapunov::LyapunovError> for Error {
    /// A failed run inside the estimate as the run's error itself, the rest as
    /// [`Error::Lyapunov`].
    fn from(e: crate::lyapunov::LyapunovError) -> Self {
        match e {
            crate::lyapunov::LyapunovError::Run(e) => e.into(),
            e => Error::Lyapunov(e),
        }
    }
}

impl From<crate::orbit::OrbitError> for Error {
    /// A failed run (or variational set-up) inside the orbit computation as that error
    /// itself, the rest as [`Error::Orbit`].
    fn from(e: crate::orbit::OrbitError) -> Self {
        match e {
            crate::orbit::OrbitError::Run(e) => e.into(),
            crate::orbit::OrbitError::Lyapunov(e) => e.into(),
            e => Error::Orbit(e),
        }
    }
}

impl Error {
    /// The run's error inside `self`, if it is one of the engine's (parameters, roots,
    /// models, integration, events, modes).
    fn into_run(self) -> std::result::Result<crate::drive::RunError, Self> {
        use crate::drive::RunError;
        match self {
            Error::Parameter(e) => Ok(RunError::Parameter(e)),
            Error::Root(e) => Ok(RunError::Root(e)),
            Error::Model(e) => Ok(RunError::Model(e)),
            Error::Integrate(e) => Ok(RunError::Integrate(e)),
            Error::Event(e) => Ok(RunError::Event(e)),
            Error::Mode(e) => Ok(RunError::Mode(e)),
            other => Err(other),
        }
    }
}

impl From<Error> for crate::lyapunov::LyapunovError {
    /// For a system builder that returns the crate's `Result`: the engine's errors as
    /// `Run`, a Lyapunov error as itself, the rest by message as `Build`.
    fn from(e: Error) -> Self {
        use crate::lyapunov::LyapunovError;
        match e.into_run() {
            Ok(e) => LyapunovError::Run(e),
            Err(Error::Lyapunov(e)) => e,
            Err(other) => LyapunovError::Build(other.to_string()),
        }
    }
}

impl From<Error> for crate::orbit::OrbitError {
    /// For a problem builder that returns the crate's `Result`: the engine's errors as
    /// `Run`, orbit and Lyapunov errors as themselves, the rest by message as `Build`.
    fn from(e: Error) -> Self {
        use crate::orbit::OrbitError;
        match e.into_run() {
            Ok(e) => OrbitError::Run(e),
            Err(Error::Orbit(e)) => e,
            Err(Error::Lyapunov(e)) => OrbitError::Lyapunov(e),
            Err(other) => OrbitError::Build(other.to_string()),
        }
    }
}

impl From<Error> for crate::sweep::RunFailure {
    /// The engine's error inside `e` (a sweep's run failed with it), or its message.
    fn from(e: Error) -> Self {
        match e.into_run() {
            Ok(e) => e.into(),
            Err(other) => crate::sweep::RunFailure::Other(other.to_string()),
        }
    }
}

/// `Result` with the crate's [`Error`](enum@Error).
pub type Result<T, E = Error> = std::result::Result<T, E>;
