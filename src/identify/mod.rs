//! Parameter identification: the mean-squared-difference objective `F0` and Nelder–Mead
//! fitting over named, optionally bounded or log-transformed parameters.
//!
//! A model's parameters `μ` are estimated from a measured record by minimizing
//! $$ F_0(\mu) = \frac{1}{t_2 - t_1}\int_{t_1}^{t_2}
//!    \bigl(x_\mathrm{exp}(t) - x_\mathrm{sim}(t;\mu)\bigr)^2\,dt $$
//! with the Nelder–Mead method (as the paper does with MATLAB's `fminsearch`).
//! The pieces here are independent of the integrator:
//!
//! - [`ParameterSpace`] / [`Parameter`]: names, initial values, bounds and a
//!   [`Transform`] (log for positive parameters), with the bijection to the optimizer's
//!   unconstrained vector (MINUIT-style `sin` / `sqrt` bound maps);
//! - [`objective_f0`]: `F0` by the trapezoidal rule on the measured samples inside the
//!   window, the simulation linearly interpolated onto them (m², or mm² with
//!   [`objective_f0_mm2`]);
//! - [`fit_nelder_mead`]: the Nelder–Mead simplex method (the `fminsearch` variant, written
//!   here because argmin's needs a feature the crate does not enable — see
//!   [`fit_nelder_mead`]) in the unconstrained coordinates; failing simulations are bad points,
//!   never crashes; a [`FitReport`] with the fitted values by name, evaluations,
//!   iterations, convergence history and termination reason;
//! - [`ModelFit`]: the whole loop for any model given as a builder (simulate, compare on
//!   the window, minimize).
//!
//! The paper's configuration (its model's parameter names and fit) is in
//! [`systems::paper`](crate::systems::paper).
//!
//! # Example
//! ```
//! use nonsmooth::identify::{NelderMeadOptions, Parameter, ParameterSpace, fit_nelder_mead};
//! // Rosenbrock's function in named parameters; its minimum is at a = b = 1.
//! let space = ParameterSpace::new([Parameter::new("a", -1.2), Parameter::new("b", 1.0)])?;
//! let report = fit_nelder_mead(
//!     &space,
//!     |p| {
//!         let (a, b) = (p.get("a")?, p.get("b")?);
//!         Ok::<f64, nonsmooth::identify::IdentifyError>((1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2))
//!     },
//!     &NelderMeadOptions::default().with_tolerances(1e-10, 1e-16),
//! )?;
//! assert!((report.values["a"] - 1.0).abs() < 1e-6);
//! assert!((report.values["b"] - 1.0).abs() < 1e-6);
//! # Ok::<(), nonsmooth::identify::IdentifyError>(())
//! ```

mod fit;
mod model_fit;
mod objective;
mod space;

pub use fit::{FitReport, FitTermination, NelderMeadOptions, fit_nelder_mead};
pub use model_fit::ModelFit;
pub(crate) use model_fit::{simulate_at_nodes, window_nodes};
pub use objective::{M2_TO_MM2, objective_f0, objective_f0_mm2};
pub use space::{ParamValues, Parameter, ParameterSpace, Transform};

use crate::drive::RunError;
use crate::model::ModelError;
use crate::roots::RootError;
use crate::signal::SignalError;
use crate::validate::ParameterError;

/// Errors of parameter identification.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IdentifyError {
    /// An option was rejected.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// Measured or simulated data are invalid.
    #[error(transparent)]
    Signal(SignalError),
    /// A simulation failed (the step cap, an accumulation of events, …).
    #[error(transparent)]
    Run(#[from] RunError),
    /// A parameter space needs at least one parameter.
    #[error("the parameter space is empty")]
    EmptySpace,
    /// Two parameters share a name.
    #[error("parameter `{name}` is defined twice")]
    DuplicateParameter {
        /// The name.
        name: String,
    },
    /// No parameter has this name.
    #[error("unknown parameter `{name}`")]
    UnknownParameter {
        /// The name asked for.
        name: String,
    },
    /// An initial value is NaN or infinite.
    #[error("initial value of `{name}` is not finite ({value})")]
    NonFiniteInitial {
        /// The parameter.
        name: String,
        /// The value.
        value: f64,
    },
    /// A value is NaN or infinite (in a value vector, or after mapping from the optimizer).
    #[error("value of `{name}` is not finite ({value})")]
    NonFiniteValue {
        /// The parameter.
        name: String,
        /// The value.
        value: f64,
    },
    /// Bounds are NaN or `lower ≥ upper`.
    #[error("invalid bounds for `{name}`: [{lower}, {upper}]")]
    InvalidBounds {
        /// The parameter.
        name: String,
        /// Lower bound (−∞ if none).
        lower: f64,
        /// Upper bound (+∞ if none).
        upper: f64,
    },
    /// A value (the initial one, or one passed in) lies outside the bounds.
    #[error("`{name}` = {value} is outside its bounds [{lower}, {upper}]")]
    OutsideBounds {
        /// The parameter.
        name: String,
        /// The value.
        value: f64,
        /// Lower bound (−∞ if none).
        lower: f64,
        /// Upper bound (+∞ if none).
        upper: f64,
    },
    /// A log-transformed parameter has a value or upper bound `≤ 0`.
    #[error("`{name}` is log-transformed but its {what} is {value} (must be > 0)")]
    NonPositiveUnderLog {
        /// The parameter.
        name: String,
        /// `"initial value"`, `"value"` or `"upper bound"`.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// A vector has the wrong number of entries.
    #[error("expected {expected} parameter values, got {found}")]
    DimensionMismatch {
        /// The number of parameters.
        expected: usize,
        /// The length given.
        found: usize,
    },
    /// No usable start-simplex step exists for a parameter (bounds too tight).
    #[error("cannot build a start simplex step for `{name}` = {value} within its bounds")]
    DegenerateSimplex {
        /// The parameter.
        name: String,
        /// Its value.
        value: f64,
    },
    /// The time window is not finite or `t1 ≥ t2`.
    #[error("invalid window [{t1}, {t2}]: need finite t1 < t2")]
    InvalidWindow {
        /// Window start.
        t1: f64,
        /// Window end.
        t2: f64,
    },
    /// The window is not covered by the data.
    #[error("window [{t1}, {t2}] is outside the {which} data span [{start}, {end}]")]
    WindowOutsideData {
        /// `"measured"` or `"simulated"`.
        which: &'static str,
        /// Window start.
        t1: f64,
        /// Window end.
        t2: f64,
        /// First sample time.
        start: f64,
        /// Last sample time.
        end: f64,
    },
    /// Too few measured samples in the window.
    #[error("window [{t1}, {t2}] contains {samples} measured samples, at least 2 required")]
    EmptyWindow {
        /// Window start.
        t1: f64,
        /// Window end.
        t2: f64,
        /// Samples found.
        samples: usize,
    },
    /// The objective failed at the initial values, so there is nothing to start from.
    #[error("the objective failed at the initial parameters: {message}")]
    InitialPointFailed {
        /// The objective's error message.
        message: String,
    },
    /// Any other error of a model builder (an error of the crate without a variant here,
    /// see [`ModelFit`]), by its message.
    #[error("{0}")]
    Other(String),
}

impl From<SignalError> for IdentifyError {
    /// A simulation's error inside a [`SignalError`] becomes [`IdentifyError::Run`].
    fn from(e: SignalError) -> Self {
        match e {
            SignalError::Run(e) => Self::Run(e),
            e => Self::Signal(e),
        }
    }
}

impl From<ModelError> for IdentifyError {
    /// A model that could not be built: [`IdentifyError::Run`] with [`RunError::Model`].
    fn from(e: ModelError) -> Self {
        Self::Run(e.into())
    }
}

impl From<RootError> for IdentifyError {
    /// A failed root search (e.g. for an initial state): [`IdentifyError::Run`] with
    /// [`RunError::Root`].
    fn from(e: RootError) -> Self {
        Self::Run(e.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn types_are_send_sync_clone() {
        fn check<T: Send + Sync + Clone + 'static>() {}
        check::<IdentifyError>();
        check::<ParameterSpace>();
        check::<ParamValues>();
        check::<FitReport>();
        check::<NelderMeadOptions>();
    }
}
