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
    Mode(#[from] crate::drive::modes::ModeError),
    /// A sampler or sweep was misconfigured or failed.
    #[error(transparent)]
    Sweep(#[from] crate::sweep::SweepError),
    /// A Lyapunov estimate failed.
    #[error(transparent)]
    Lyapunov(#[from] crate::lyapunov::LyapunovError),
    /// A periodic orbit could not be computed.
    #[error(transparent)]
    Orbit(#[from] crate::orbit::OrbitError),
    /// An entropy estimate failed.
    #[error(transparent)]
    Entropy(#[from] crate::entropy::EntropyError),
    /// A harmonic analysis or approximation failed.
    #[error(transparent)]
    Analysis(#[from] crate::analysis::AnalysisError),
    /// Measured data could not be read or processed.
    #[error(transparent)]
    Signal(#[from] crate::signal::SignalError),
    /// Parameter identification failed.
    #[error(transparent)]
    Identify(#[from] crate::identify::IdentifyError),
    /// Writing output failed.
    #[error("output error: {0}")]
    Output(String),
}

/// `Result` with the crate's [`Error`](enum@Error).
pub type Result<T, E = Error> = std::result::Result<T, E>;
