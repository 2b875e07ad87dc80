//! The driver's error: what a run, an observer's check or a mode's segment reports.
//!
//! [`RunError`] holds the errors of the layers the driver stands on (parameters, roots,
//! models, integration, events) and its own ([`ModeError`]). It converts into the crate's
//! [`Error`](crate::Error) variant by variant (a `RunError::Event(e)` becomes
//! `Error::Event(e)`), so code that matches on the crate's error is unchanged by the
//! layer it came through.

use thiserror::Error;

use crate::event::EventError;
use crate::integrate::IntegrateError;
use crate::model::ModelError;
use crate::roots::RootError;
use crate::validate::ParameterError;

/// `Result` with [`RunError`].
pub(crate) type Result<T, E = RunError> = std::result::Result<T, E>;

/// The error of [`Simulation::run`](super::Simulation::run), of observers' checks
/// ([`Observer::check`](super::Observer::check)), of mode segments
/// ([`ModeSystem::segment`](super::ModeSystem::segment)) and of the runs through modes.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RunError {
    /// A parameter was rejected (a setting of the run, an observer's or event's index).
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// A bracketing root search failed.
    #[error(transparent)]
    Root(#[from] RootError),
    /// A model could not be assembled or analysed.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Time integration failed.
    #[error(transparent)]
    Integrate(#[from] IntegrateError),
    /// Event handling failed (an accumulation of events, sticking, a non-finite event value).
    #[error(transparent)]
    Event(#[from] EventError),
    /// A run through modes was started inconsistently or left its constraint.
    #[error(transparent)]
    Mode(#[from] ModeError),
}

/// Errors of runs through modes.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModeError {
    /// The start mode contradicts the start state: e.g. stuck while the force needed to
    /// hold the contact exceeds the static limit, slipping forward while the slip velocity
    /// is negative, or starting inside a rigid surface.
    #[error(
        "start mode {mode} contradicts the state at t = {t}: {quantity} = {value}, must be {requirement}"
    )]
    InconsistentStart {
        /// The start mode.
        mode: &'static str,
        /// The start time.
        t: f64,
        /// The quantity that contradicts the mode.
        quantity: &'static str,
        /// Its value.
        value: f64,
        /// What the mode requires of it.
        requirement: String,
    },
    /// A constrained mode left its constraint by more than the documented tolerance (the
    /// integration drifted, e.g. a stuck body sinking into a rigid surface).
    #[error(
        "the constraint of mode {mode} is violated at t = {t}: {quantity} = {value} exceeds the tolerance {tolerance}"
    )]
    ConstraintDrift {
        /// The mode.
        mode: &'static str,
        /// Time (a step end or a dense sample).
        t: f64,
        /// The constraint quantity (penetration, slip velocity).
        quantity: &'static str,
        /// Its value.
        value: f64,
        /// The tolerance.
        tolerance: f64,
    },
}

/// `From` the engine's errors (parameters, roots, models, integration, events, modes) for an
/// instrument's error type with a `Run(RunError)` variant, so that `?` works inside it.
macro_rules! from_engine_errors {
    ($target:ty) => {
        $crate::drive::from_engine_errors!(
            @each $target,
            $crate::validate::ParameterError,
            $crate::roots::RootError,
            $crate::model::ModelError,
            $crate::integrate::IntegrateError,
            $crate::event::EventError,
            $crate::drive::ModeError
        );
    };
    (@each $target:ty, $($err:ty),+) => {$(
        impl From<$err> for $target {
            fn from(e: $err) -> Self {
                <$target>::Run(e.into())
            }
        }
    )+};
}
pub(crate) use from_engine_errors;
