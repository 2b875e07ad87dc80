//! The error of the time-stepping module.

use thiserror::Error;

use super::lcp::LcpError;
use crate::validate::ParameterError;

/// Why a time-stepping scheme could not be built or a step not taken.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum TimeStepError {
    /// A parameter was rejected.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// Sizes do not fit (a state of the wrong length, a contact on a missing body).
    #[error("{what} is {got}, expected {expected}")]
    Dimension {
        /// What.
        what: &'static str,
        /// The size or index given.
        got: usize,
        /// What the system requires (a length, or the bound an index must stay below).
        expected: usize,
    },
    /// The mass matrix is not symmetric positive definite (Cholesky fails).
    #[error("the mass matrix is not positive definite at t = {t} (pivot {pivot} = {value:e})")]
    MassMatrix {
        /// Time of the evaluation.
        t: f64,
        /// The failing pivot.
        pivot: usize,
        /// Its value.
        value: f64,
    },
    /// A contact was given to a complementarity solver that cannot treat it (friction to
    /// Lemke or projected Gauss–Seidel).
    #[error(
        "contact {contact} has friction μ = {mu} but the solver {solver} is frictionless: use Solver::Nsgs"
    )]
    FrictionUnsupported {
        /// The contact.
        contact: usize,
        /// Its friction coefficient.
        mu: f64,
        /// The solver.
        solver: &'static str,
    },
    /// The contact problem of a step was not solved.
    #[error("step {step} (t = {t}): {source}")]
    Contact {
        /// The step index (from 0).
        step: usize,
        /// The step's start time.
        t: f64,
        /// The solver's error (with its residual).
        #[source]
        source: LcpError,
    },
    /// The position projection did not bring every gap to `≥ −tolerance`.
    #[error(
        "step {step} (t = {t}): the position projection left contact {contact} at gap {gap:e} \
         after {iterations} iterations (tolerance {tolerance:e})"
    )]
    Projection {
        /// The step index.
        step: usize,
        /// The step's end time (where the positions are projected).
        t: f64,
        /// The most penetrated contact.
        contact: usize,
        /// Its gap.
        gap: f64,
        /// The projection's iterations.
        iterations: usize,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// A force, gap, Jacobian or the new state is not finite.
    #[error("step {step} (t = {t}): {what}[{index}] = {value} is not finite")]
    NonFinite {
        /// The step index.
        step: usize,
        /// The step's start time.
        t: f64,
        /// Which quantity.
        what: &'static str,
        /// Its index.
        index: usize,
        /// Its value.
        value: f64,
    },
}
