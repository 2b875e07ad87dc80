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
    /// The mass matrix is not positive definite (a Cholesky pivot, or a diagonal entry of
    /// a diagonal mass matrix, is not positive, or its inverse is not finite).
    #[error(
        "the mass matrix is not positive definite at t = {t} (pivot {pivot} = {value:e}, or its inverse is not finite)"
    )]
    MassMatrix {
        /// Time of the evaluation.
        t: f64,
        /// The failing pivot.
        pivot: usize,
        /// Its value.
        value: f64,
    },
    /// The mass matrix is not symmetric: `M[row][col]` and `M[col][row]` differ by more
    /// than rounding (`64 ε max(|M_ii|, |M_jj|)`).
    #[error(
        "the mass matrix is not symmetric at t = {t}: M[{row}][{col}] = {value:e} but M[{col}][{row}] = {transposed:e}"
    )]
    MassAsymmetric {
        /// Time of the evaluation.
        t: f64,
        /// The row of the entry.
        row: usize,
        /// Its column.
        col: usize,
        /// `M[row][col]`.
        value: f64,
        /// `M[col][row]`.
        transposed: f64,
    },
    /// The iteration matrix `W = M + hθC + h²θ²K` of the implicit forces is singular (its
    /// LU factorization meets a zero or non-finite pivot): the step is too large for the
    /// forces' negative stiffness or damping, or `M` itself is singular.
    #[error(
        "the iteration matrix W = M + hθC + h²θ²K is singular at t = {t} (pivot {pivot} = {value:e}): shorten the step h = {h:e} or check the force Jacobians"
    )]
    IterationMatrix {
        /// Time of the evaluation.
        t: f64,
        /// The step.
        h: f64,
        /// The failing pivot column.
        pivot: usize,
        /// The largest pivot candidate.
        value: f64,
    },
    /// The clock cannot resolve the step: near `t` neighbouring floating-point times are
    /// farther apart than `h/1024`, so the steps `t_{k+1} − t_k` would be rounded to
    /// lengths other than `h` (or to 0).
    #[error(
        "the clock cannot resolve the step h = {h:e} at t = {t:e}: neighbouring times there are up to {spacing:e} apart (more than h/1024); start the clock nearer 0"
    )]
    Clock {
        /// The largest time of the run.
        t: f64,
        /// The step.
        h: f64,
        /// The spacing of floating-point times near `t` (`ε·|t|`).
        spacing: f64,
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
