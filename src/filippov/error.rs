//! The error of Filippov runs: the engine's [`RunError`] and what only sliding motion can
//! meet (two surfaces at once, a repelling surface, drift off the surface, no progress).

use thiserror::Error;

use crate::drive::RunError;
use crate::event::EventError;
use crate::integrate::IntegrateError;
use crate::validate::ParameterError;

/// Why a Filippov run (or its monodromy) failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FilippovError {
    /// The integration, event handling or a setting of the run failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// Two switching surfaces are met at once (a codimension-2 point): the event-driven
    /// method of one surface at a time does not apply there.
    #[error(
        "surfaces {first} and {second} are met at once at t = {t} (H_{second} = {value} within {tolerance} of 0): a codimension-2 point, where the method of one surface at a time does not apply"
    )]
    Codimension2 {
        /// Time of the event.
        t: f64,
        /// The surface whose event was located.
        first: usize,
        /// The other surface met there.
        second: usize,
        /// `H_second` at the event.
        value: f64,
        /// The tolerance it is within (relative tolerance times the surface's scale).
        tolerance: f64,
    },
    /// Both vector fields point away from the surface (a repelling sliding region): the
    /// continuation is not unique.
    #[error(
        "surface {surface} repels on both sides at t = {t} (H_x·F₋ = {rate_minus}, H_x·F₊ = {rate_plus}): the forward solution is not unique"
    )]
    Repelling {
        /// Time.
        t: f64,
        /// The surface.
        surface: usize,
        /// `H_x·F₋ + H_t`.
        rate_minus: f64,
        /// `H_x·F₊ + H_t`.
        rate_plus: f64,
    },
    /// Both fields are tangent to the surface to first and second order: no side can be
    /// chosen.
    #[error(
        "both fields are tangent to surface {surface} to second order at t = {t}: no side can be chosen"
    )]
    Degenerate {
        /// Time.
        t: f64,
        /// The surface.
        surface: usize,
    },
    /// While sliding, the state left the surface by more than the drift tolerance (checked
    /// on the dense output between step ends, not only at them).
    #[error(
        "sliding on surface {surface}: |H| = {value} at t = {t} exceeds the drift tolerance {tolerance}"
    )]
    Drift {
        /// Time (a step end or an interior sample).
        t: f64,
        /// The surface.
        surface: usize,
        /// `|H|` there.
        value: f64,
        /// The tolerance (relative tolerance times the surface's scale).
        tolerance: f64,
    },
    /// Transitions follow each other without time advancing.
    #[error(
        "{count} transitions without progress at t = {t} (last mode {mode}): the mode logic does not advance"
    )]
    NoProgress {
        /// Time.
        t: f64,
        /// Transitions at (within rounding of) this time.
        count: usize,
        /// The last mode's name.
        mode: &'static str,
    },
    /// A surface's value, gradient or time rate, a normal rate or a second-order rate met
    /// where the run decides a mode (a start, an arrival, an exit) or checks the drift is
    /// not finite.
    #[error("surface {surface}: {quantity} is not finite at t = {t} ({value})")]
    NonFinite {
        /// Time.
        t: f64,
        /// The surface.
        surface: usize,
        /// What is not finite: `"the value H"`, `"the gradient ∇H"`, `"the time rate
        /// ∂H/∂t"`, a normal rate `∇H·F± + ∂H/∂t` (a field that is not finite) or the
        /// second-order rate of the tangency test.
        quantity: &'static str,
        /// Its value (for the gradient, its first non-finite component).
        value: f64,
    },
    /// A crossing with zero normal rate (a grazing decided by the second-order test): its
    /// saltation matrix is unbounded, the monodromy does not exist.
    #[error(
        "the crossing of surface {surface} at t = {t} is tangential: its saltation matrix is unbounded (a grazing), the monodromy does not exist"
    )]
    GrazingSaltation {
        /// Time.
        t: f64,
        /// The surface.
        surface: usize,
    },
    /// Newton's method for a periodic orbit did not converge.
    #[error(
        "periodic orbit: no convergence after {iterations} Newton iterations (residual {residual}, last step {step})"
    )]
    NoConvergence {
        /// Iterations done.
        iterations: usize,
        /// `‖φ_T(x) − x‖∞` at the last iterate.
        residual: f64,
        /// `‖Δ‖∞` of the last Newton step.
        step: f64,
    },
    /// The Newton system of a periodic orbit is singular (e.g. the phase condition is
    /// tangent to the section, or a multiplier is 1 for a forced orbit).
    #[error("periodic orbit: singular Newton system at iteration {iteration}")]
    Singular {
        /// The iteration.
        iteration: usize,
    },
    /// A dimension given as a const parameter does not match (the augmented state of the
    /// variational equations must have `N + N²` components).
    #[error("dimension {got} given, {expected} required ({what})")]
    Dimension {
        /// What the dimension is of.
        what: &'static str,
        /// The required dimension.
        expected: usize,
        /// The given one.
        got: usize,
    },
}

impl From<ParameterError> for FilippovError {
    fn from(e: ParameterError) -> Self {
        FilippovError::Run(e.into())
    }
}

impl From<IntegrateError> for FilippovError {
    fn from(e: IntegrateError) -> Self {
        FilippovError::Run(e.into())
    }
}

impl From<EventError> for FilippovError {
    fn from(e: EventError) -> Self {
        FilippovError::Run(e.into())
    }
}

/// `Result` with [`FilippovError`].
pub(crate) type Result<T, E = FilippovError> = std::result::Result<T, E>;
