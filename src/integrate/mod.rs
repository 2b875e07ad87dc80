//! Time integration: steppers with dense output and adaptive step-size control.
//!
//! A [`Stepper`] owns its state `(t, y)` and advances it by one *accepted* step at a time;
//! after each step its [`DenseOutput`] covers the step and interpolates inside it. Caches
//! (the first-same-as-last derivative) are dropped by [`Stepper::reset_state`], which the
//! event machinery calls after a state reset.
//!
//! | method | type | order | dense output | for |
//! |---|---|---|---|---|
//! | [`Dopri5`] | explicit, embedded 5(4), FSAL | 5 | 4th order (Hairer's continuous extension) | default |
//! | [`Dop853`] | explicit, embedded 8(5,3) | 8 | 7th order | tight tolerances |
//! | [`Tsit5`] | explicit, embedded 5(4), FSAL | 5 | 4th order (free) | alternative to DOPRI5 |
//! | [`Vern6`] | explicit, embedded 6(5), FSAL | 6 | 6th order (3 extra stages) | smooth flows, moderate t |
//! | [`Rk4`] | explicit, fixed step | 4 | cubic Hermite (3rd order) | reference, tests |
//! | [`Rosenbrock23`] | linearly implicit, embedded 2(3), FSAL | 2 | quadratic (the method's own) | stiff phases |
//! | [`CuspImplicit`] | implicit Euler extrapolated, 3(2), mechanical form | 3 | limited cubic Hermite | creep at a velocity cusp ([`cusp`]) |
//!
//! # Step-size control
//! The error of a step is measured in the weighted RMS norm
//! $$\|e\| = \sqrt{\frac1N\sum_i \Bigl(\frac{e_i}{a_i + r_i\max(|y_{0,i}|,|y_{1,i}|)}\Bigr)^2}$$
//! with per-component absolute (`a_i`) and relative (`r_i`) [`Tolerances`]; a step is
//! accepted when `‖e‖ ≤ 1`. The next step comes from a PI controller (Gustafsson; the
//! constants of Hairer's DOPRI5: `β = 0.04`, safety 0.9, factor in `[0.2, 10]`). Failure
//! counters are per step: [`IntegrateError::StepSizeTooSmall`] is raised when a step would
//! fall below `StepOptions::h_min` or below `16·ε_mach·|t|`, never because rejections
//! accumulated over a long run.

mod adaptive;
pub mod cusp;
mod dop853;
pub(crate) mod dopri5;
mod erk;
mod rk4;
mod rosenbrock;
mod tsit5;
pub mod turning;
mod vern6;

pub use adaptive::{Adaptive, Interpolant, Method, MethodDense};
pub use cusp::{
    CuspDense, CuspImplicit, CuspInterpolant, CuspMethod, CuspSwitch, CuspSwitchDense, SwitchCounts,
};
pub use dop853::{Dop853, Dop853Dense, Dop853Interpolant, Dop853Method};
pub use dopri5::{Dopri5, Dopri5Dense, Dopri5Interpolant, Dopri5Method};
pub use erk::{ExplicitTableau, PowerInterpolant};
pub use rk4::{HermiteDense, Rk4};
pub use rosenbrock::{
    Rosenbrock23, Rosenbrock23Dense, Rosenbrock23Interpolant, Rosenbrock23Method,
};
pub use tsit5::{Tsit5, Tsit5Dense, Tsit5Interpolant, Tsit5Method};
pub use turning::{SegmentCounts, TurningDense, TurningPoints};
pub use vern6::{Vern6, Vern6Dense, Vern6Interpolant, Vern6Method};

use nalgebra::SVector;
use thiserror::Error;

use crate::scalar::{lit, to_f64};
use crate::validate::ParameterError;
use crate::validate::positive;
use crate::{Dynamics, Real};

/// Why an integration failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum IntegrateError {
    /// The step size fell below the minimum (a singularity, an unresolved discontinuity or
    /// too-tight tolerances).
    #[error(
        "step size too small at t = {t}: h = {h} (loosen the tolerances or check the model for a singularity)"
    )]
    StepSizeTooSmall {
        /// Time of the failing step.
        t: f64,
        /// The step size that was too small.
        h: f64,
    },
    /// The right-hand side returned NaN or ∞.
    #[error(
        "the right-hand side is not finite at t = {t} (NaN or infinity in the state derivative)"
    )]
    NonFiniteRhs {
        /// Where.
        t: f64,
    },
    /// The initial state contains NaN or ∞.
    #[error("the initial state is not finite (component {index} = {value})")]
    NonFiniteState {
        /// The offending component.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The final time is not after the initial time, or a time is not finite.
    #[error("invalid time span: t0 = {t0}, t_end = {t_end} (need finite t_end > t0)")]
    InvalidTimeSpan {
        /// Start.
        t0: f64,
        /// End.
        t_end: f64,
    },
    /// The run needed more accepted steps than allowed.
    #[error("maximum number of steps ({max_steps}) reached at t = {t}")]
    MaxSteps {
        /// Time reached.
        t: f64,
        /// The cap.
        max_steps: usize,
    },
    /// A dense-output evaluation outside the last step.
    #[error("interpolation at t = {t} outside the last step [{t0}, {t1}]")]
    OutsideStep {
        /// Requested time.
        t: f64,
        /// Step start.
        t0: f64,
        /// Step end.
        t1: f64,
    },
    /// A tolerance or step option set through a public field is invalid.
    #[error("invalid integrator settings: {0}")]
    InvalidSettings(ParameterError),
    /// The run provably needs more steps than the cap allows (its span over the largest
    /// step it may take), detected before the first step.
    #[error(
        "the run needs at least {needed:e} steps (span {span} over the largest step {h}), more than the cap of {max_steps}"
    )]
    WorkExceedsCap {
        /// The lower bound on the steps needed.
        needed: f64,
        /// `t_end − t0`.
        span: f64,
        /// The largest step the run may take (`h_max`, a fixed step or a landing grid).
        h: f64,
        /// The cap.
        max_steps: usize,
    },
    /// The stepper was used before [`Stepper::reset_state`] gave it a state.
    #[error("the stepper has no state: call reset_state first")]
    NotInitialized,
    /// The linear system of an implicit stage is singular.
    #[error("singular iteration matrix at t = {t}")]
    SingularMatrix {
        /// Where.
        t: f64,
    },
    /// A partial derivative of the right-hand side is infinite at the step's start (a
    /// law with a cusp reports it as the largest finite value, which the system's
    /// Jacobian may scale: an entry beyond `√MAX` counts as infinite; the exact
    /// contact-rate law `sgn(v)|v|^{n3}`, `n3 < 1`, at `v = 0` in contact). A linearly implicit method
    /// linearizes there: its stage and its error estimate in that direction vanish, and
    /// it would step on with a wrong state instead of failing.
    #[error(
        "the Jacobian is infinite at t = {t} (entry ({row}, {col})): a linearly implicit method cannot step from this state; use an explicit method, or a regularized law (η > 0)"
    )]
    InfiniteJacobian {
        /// Where.
        t: f64,
        /// Row of the entry (the component of the right-hand side).
        row: usize,
        /// Column of the entry (the state component).
        col: usize,
    },
    /// An implicit cusp step ([`CuspImplicit`]) needs a system in mechanical form: a state
    /// `(q, v)` of `N = 2n` components whose first `n` derivatives are the last `n`
    /// components.
    #[error(
        "the implicit cusp step needs a state (q, v) with q' = v: component {index} of the derivative at t = {t} is not the velocity"
    )]
    NotMechanical {
        /// Where.
        t: f64,
        /// The first component that breaks the form.
        index: usize,
    },
    /// A parameter of the integrator is invalid.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// A [`CuspSwitch`] run is stiffness-bound by a velocity cusp that the system does not
    /// declare: the relaxation rate of velocity `index` grows as `|v|` shrinks, as a power
    /// `|v|^{q−1}` with `q < 1` does, and the explicit stepper creeps (it would take steps
    /// of nanoseconds to the step cap).
    #[error(
        "velocity {index} has a cusp where the explicit stepper is stiffness-bound (at t = {t}, v = {velocity:e}: a relaxation rate growing as |v|^(q-1), q ≈ {exponent:.3}) but the system declares none: declare it (Dynamics::cusp_exponent) so that CuspSwitch steps it implicitly"
    )]
    UndeclaredCusp {
        /// Where.
        t: f64,
        /// The velocity's index (in `0..N/2`).
        index: usize,
        /// Its value.
        velocity: f64,
        /// The exponent `q` estimated from the rates at `v/2` and `v/4`.
        exponent: f64,
    },
}

/// Per-component absolute and relative tolerances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances<T, const N: usize> {
    /// Relative tolerances `r_i`.
    pub rtol: SVector<T, N>,
    /// Absolute tolerances `a_i`.
    pub atol: SVector<T, N>,
}

/// `rtol`, checked: finite, and at least the machine epsilon `ε` of `T` (a relative
/// error below the spacing of the numbers cannot be reached: the step would shrink without
/// end, as it did at `rtol = 10⁻³⁰⁰`, creeping to the step cap).
fn reachable_rtol<T: Real>(rtol: T) -> Result<T, ParameterError> {
    positive("rtol", rtol)?;
    if rtol < T::default_epsilon() {
        return Err(ParameterError::new(
            "rtol",
            to_f64(rtol),
            "at least the machine epsilon (2.2e-16 for f64, 1.2e-7 for f32): smaller relative errors are below the arithmetic's reach",
        ));
    }
    Ok(rtol)
}

impl<T: Real, const N: usize> Tolerances<T, N> {
    /// The same `rtol` and `atol` for every component.
    ///
    /// # Errors
    /// [`ParameterError`] unless both are finite and > 0 and `rtol` is at least the
    /// machine epsilon of `T` (below it no step can meet the tolerance).
    pub fn new(rtol: T, atol: T) -> Result<Self, ParameterError> {
        reachable_rtol(rtol)?;
        positive("atol", atol)?;
        Ok(Self {
            rtol: SVector::repeat(rtol),
            atol: SVector::repeat(atol),
        })
    }

    /// One `rtol` and an `atol` per component (e.g. metres for `x`, m/s for `ẋ`).
    ///
    /// # Errors
    /// [`ParameterError`] unless all are finite and > 0 and `rtol` is at least the machine
    /// epsilon of `T`.
    pub fn per_component(rtol: T, atol: [T; N]) -> Result<Self, ParameterError> {
        reachable_rtol(rtol)?;
        for a in atol {
            positive("atol", a)?;
        }
        Ok(Self {
            rtol: SVector::repeat(rtol),
            atol: SVector::from(atol),
        })
    }

    /// Checks every component (finite and > 0, `rtol` at least the machine epsilon): the
    /// fields are public, so a value set through them is checked here, by
    /// [`Stepper::check`] before each run.
    ///
    /// # Errors
    /// [`ParameterError`] naming `rtol` or `atol`.
    pub fn validate(&self) -> Result<(), ParameterError> {
        for i in 0..N {
            reachable_rtol(self.rtol[i])?;
            positive("atol", self.atol[i])?;
        }
        Ok(())
    }

    /// The weighted RMS norm of `err` relative to `y0`, `y1` (see the module docs).
    #[inline(always)]
    pub fn error_norm(&self, err: &SVector<T, N>, y0: &SVector<T, N>, y1: &SVector<T, N>) -> T {
        let mut s = T::zero();
        for i in 0..N {
            let sc = self.atol[i] + self.rtol[i] * y0[i].abs().max(y1[i].abs());
            let q = err[i] / sc;
            s += q * q;
        }
        (s / lit::<T>(N as f64)).sqrt()
    }
}

/// Step-size options shared by the adaptive steppers.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct StepOptions<T> {
    /// Initial step (`None`: chosen automatically, Hairer's algorithm).
    pub h_init: Option<T>,
    /// Largest step allowed.
    pub h_max: T,
    /// Smallest step allowed; below it the step fails with
    /// [`IntegrateError::StepSizeTooSmall`].
    pub h_min: T,
    /// Safety factor of the controller.
    pub safety: T,
    /// Smallest step-size ratio `h_new/h`.
    pub fac_min: T,
    /// Largest step-size ratio `h_new/h`.
    pub fac_max: T,
    /// PI controller constant `β` (0 gives the classical I controller).
    pub beta: T,
    /// Gustafsson's predictive correction on accepted steps (default `false`): when the
    /// errors grow while the steps shrink — the approach to a point where the solution is
    /// not smooth — the next step is cut by the observed trend instead of being tried at
    /// the PI controller's size and rejected. It can only shorten the PI proposal.
    ///
    /// It saves rejected steps and evaluations next to non-smooth points, but at equal
    /// *accuracy* it gains little, and it scatters the Poincaré points of periodic orbits
    /// more (the steps it accepts next to non-smooth points carry errors the embedded
    /// estimate underrates; `docs/performance.md` gives the figures). Hence off by default.
    pub predictive: bool,
}

impl<T: Real> Default for StepOptions<T> {
    fn default() -> Self {
        Self {
            h_init: None,
            h_max: T::max_value().unwrap_or(lit(1e300)),
            h_min: T::zero(),
            safety: lit(0.9),
            fac_min: lit(0.2),
            fac_max: lit(10.0),
            beta: lit(0.04),
            predictive: false,
        }
    }
}

impl<T: Real> StepOptions<T> {
    /// Checks the options (the fields are public): `h_max > 0` (may be the largest finite
    /// value), `0 ≤ h_min ≤ h_max`, `h_init` finite and > 0 if set, `0 < safety ≤ 1`,
    /// `0 < fac_min < 1 < fac_max`, `β ≥ 0`, all finite.
    ///
    /// # Errors
    /// [`ParameterError`] naming the first invalid option.
    pub fn validate(&self) -> Result<(), ParameterError> {
        positive("h_max", self.h_max)?;
        crate::validate::non_negative("h_min", self.h_min)?;
        if self.h_min > self.h_max {
            return Err(ParameterError::new("h_min", to_f64(self.h_min), "<= h_max"));
        }
        if let Some(h) = self.h_init {
            positive("h_init", h)?;
        }
        positive("safety", self.safety)?;
        if self.safety > T::one() {
            return Err(ParameterError::new("safety", to_f64(self.safety), "<= 1"));
        }
        positive("fac_min", self.fac_min)?;
        if !(self.fac_min < T::one()) {
            return Err(ParameterError::new("fac_min", to_f64(self.fac_min), "< 1"));
        }
        positive("fac_max", self.fac_max)?;
        if !(self.fac_max > T::one()) {
            return Err(ParameterError::new("fac_max", to_f64(self.fac_max), "> 1"));
        }
        crate::validate::non_negative("beta", self.beta)?;
        Ok(())
    }

    /// Sets the largest step.
    ///
    /// # Errors
    /// [`ParameterError`] unless `h_max` is finite and > 0.
    pub fn with_h_max(mut self, h_max: T) -> Result<Self, ParameterError> {
        self.h_max = positive("h_max", h_max)?;
        Ok(self)
    }

    /// Sets the smallest step.
    ///
    /// # Errors
    /// [`ParameterError`] unless `h_min` is finite and ≥ 0.
    pub fn with_h_min(mut self, h_min: T) -> Result<Self, ParameterError> {
        self.h_min = crate::validate::non_negative("h_min", h_min)?;
        Ok(self)
    }

    /// Switches Gustafsson's predictive correction on or off (see
    /// [`predictive`](Self::predictive)).
    pub fn with_predictive(mut self, on: bool) -> Self {
        self.predictive = on;
        self
    }

    /// Sets the initial step.
    ///
    /// # Errors
    /// [`ParameterError`] unless `h` is finite and > 0.
    pub fn with_h_init(mut self, h: T) -> Result<Self, ParameterError> {
        self.h_init = Some(positive("h_init", h)?);
        Ok(self)
    }
}

/// Counters of the work done.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Stats {
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Jacobian evaluations (implicit methods).
    pub jacobian_evals: u64,
    /// LU decompositions (implicit methods).
    pub decompositions: u64,
    /// Located events.
    pub events: u64,
}

impl core::ops::AddAssign<&Stats> for Stats {
    /// Adds another run's counters (a run made of several integrations).
    fn add_assign(&mut self, o: &Stats) {
        self.rhs_evals += o.rhs_evals;
        self.accepted += o.accepted;
        self.rejected += o.rejected;
        self.jacobian_evals += o.jacobian_evals;
        self.decompositions += o.decompositions;
        self.events += o.events;
    }
}

impl Stats {
    /// The work done since the counters read `earlier` (`self − earlier`, counter by
    /// counter; the counters only grow).
    pub(crate) fn since(&self, earlier: &Stats) -> Stats {
        Stats {
            rhs_evals: self.rhs_evals - earlier.rhs_evals,
            accepted: self.accepted - earlier.accepted,
            rejected: self.rejected - earlier.rejected,
            jacobian_evals: self.jacobian_evals - earlier.jacobian_evals,
            decompositions: self.decompositions - earlier.decompositions,
            events: self.events - earlier.events,
        }
    }
}

/// Interpolation inside the last accepted step.
///
/// Valid only for the last accepted step; its span is `[t0, t1]` of that step.
pub trait DenseOutput<T: Real, const N: usize> {
    /// The step's `(t0, t1)`.
    fn span(&self) -> (T, T);

    /// The states at the step's ends.
    fn endpoints(&self) -> (&SVector<T, N>, &SVector<T, N>);

    /// The derivatives `f(t, y)` at the step's ends.
    fn end_derivatives(&self) -> (&SVector<T, N>, &SVector<T, N>);

    /// Writes `y(t)` into `out` without checking the span (for callers that already know
    /// `t ∈ [t0, t1]`; outside it the polynomial is extrapolated).
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, N>);

    /// Bounds on the interpolant, if known: `(dev, mag)` with
    /// `|y_k(t) − ℓ_k(t)| ≤ dev_k` on the step, where `ℓ_k` is the chord between the ends'
    /// `y_k` (the interpolant's own values there), and `mag_k` a bound on the magnitudes of
    /// the terms `y_k(t)` is summed from (for a rounding allowance). The event search
    /// turns them into bounds on an event function
    /// ([`EventFunction::chord_bounds`](crate::event::EventFunction::chord_bounds)) to
    /// rule out a crossing without searching the step. Default `None`; given by
    /// [`Dopri5`]'s interpolant.
    fn chord_bounds(&self) -> Option<(SVector<T, N>, SVector<T, N>)> {
        None
    }

    /// Writes `y(t)` into `out`.
    ///
    /// # Errors
    /// [`IntegrateError::OutsideStep`] if `t` is outside the step (beyond a relative
    /// rounding margin).
    fn interpolate_into(&self, t: T, out: &mut SVector<T, N>) -> Result<(), IntegrateError> {
        let (t0, t1) = self.span();
        let margin = lit::<T>(8.0) * T::default_epsilon() * (t0.abs().max(t1.abs()));
        if t < t0.min(t1) - margin || t > t0.max(t1) + margin {
            return Err(IntegrateError::OutsideStep {
                t: to_f64(t),
                t0: to_f64(t0),
                t1: to_f64(t1),
            });
        }
        self.interpolate_unchecked(t, out);
        Ok(())
    }

    /// `y(t)` by value.
    ///
    /// # Errors
    /// As [`interpolate_into`](DenseOutput::interpolate_into).
    fn interpolate(&self, t: T) -> Result<SVector<T, N>, IntegrateError> {
        let mut out = SVector::zeros();
        self.interpolate_into(t, &mut out)?;
        Ok(out)
    }
}

/// A one-step integrator that owns its state.
///
/// ```
/// use nonsmooth::integrate::{Dopri5, Stepper, Tolerances, DenseOutput};
/// use nonsmooth::Dynamics;
/// use nalgebra::SVector;
///
/// struct Decay;
/// impl Dynamics<f64, 1> for Decay {
///     fn rhs(&self, _t: f64, y: &SVector<f64, 1>, dy: &mut SVector<f64, 1>) { dy[0] = -y[0]; }
/// }
/// let mut st = Dopri5::new(Tolerances::new(1e-10, 1e-12)?);
/// st.reset_state(0.0, SVector::<f64, 1>::new(1.0));
/// while st.current().0 < 1.0 {
///     st.step(&Decay, 1.0)?;
/// }
/// assert!((st.current().1[0] - (-1.0f64).exp()).abs() < 1e-9);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
pub trait Stepper<T: Real, const N: usize> {
    /// The dense output of the last accepted step.
    type Dense: DenseOutput<T, N>;

    /// Sets the state to `(t, y)` and drops every cached derivative (the next step
    /// re-evaluates `f(t, y)`). The step-size history is kept, and so is the clock's
    /// origin (see [`start`](Self::start)).
    fn reset_state(&mut self, t: T, y: SVector<T, N>);

    /// Starts a run at `(t, y)`: [`reset_state`](Self::reset_state), and the crate's
    /// steppers count the run's time from `t`. They keep the elapsed time
    /// `τ = t − t_start` and advance it by their steps, the clock being `t_start + τ`: a run
    /// started far from `t = 0` takes the steps, and reaches the accuracy, of the same run
    /// started at 0 (the clock and the state would otherwise drift apart by up to half an
    /// ulp of `t` per step, 6·10⁻⁵ at `t = 10¹²`). The drivers call it at the start of a
    /// run and [`reset_state`](Self::reset_state) at its events. Default:
    /// [`reset_state`](Self::reset_state).
    fn start(&mut self, t: T, y: SVector<T, N>) {
        self.reset_state(t, y);
    }

    /// Advances by one accepted step, never past `t_limit`.
    ///
    /// # Errors
    /// [`IntegrateError`] if the step cannot be taken.
    fn step<S: Dynamics<T, N>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError>;

    /// The current `(t, y)`.
    fn current(&self) -> (T, &SVector<T, N>);

    /// The dense output of the last accepted step.
    fn dense(&self) -> &Self::Dense;

    /// Work counters since construction.
    fn stats(&self) -> &Stats;

    /// Mutable work counters (the driver records events here).
    fn stats_mut(&mut self) -> &mut Stats;

    /// The order of the propagated solution.
    fn order(&self) -> u8;

    /// Checks the settings that public fields could have set past the constructors' checks
    /// (tolerances, step options); the driver calls it before a run.
    ///
    /// # Errors
    /// [`IntegrateError::InvalidSettings`] naming the offending setting.
    fn check(&self) -> Result<(), IntegrateError> {
        Ok(())
    }

    /// The largest step this stepper takes (`h_max`, or the fixed step), if bounded: the
    /// driver fails a run at once when `(t_end − t0)/max_step` exceeds its step cap.
    fn max_step(&self) -> Option<T> {
        None
    }
}

/// The state every one-step method keeps: `(t, y)`, the cached derivative `f(t, y)` (the
/// first-same-as-last stage), the proposed next step and the work counters.
#[derive(Debug, Clone)]
pub(crate) struct Core<T: Real, const N: usize> {
    pub(crate) t: T,
    /// The run's start ([`Stepper::start`]): the clock is `origin + tau`.
    origin: T,
    /// The time elapsed since `origin`, advanced by the steps.
    tau: T,
    pub(crate) y: SVector<T, N>,
    pub(crate) f: SVector<T, N>,
    f_valid: bool,
    initialized: bool,
    pub(crate) h: Option<T>,
    pub(crate) stats: Stats,
}

impl<T: Real, const N: usize> Core<T, N> {
    pub(crate) fn new(h: Option<T>) -> Self {
        Self {
            t: T::zero(),
            origin: T::zero(),
            tau: T::zero(),
            y: SVector::zeros(),
            f: SVector::zeros(),
            f_valid: false,
            initialized: false,
            h,
            stats: Stats::default(),
        }
    }

    /// Sets the state and drops the derivative cache (the clock's origin is kept).
    pub(crate) fn reset(&mut self, t: T, y: SVector<T, N>) {
        self.t = t;
        self.tau = t - self.origin;
        self.y = y;
        self.f_valid = false;
        self.initialized = true;
    }

    /// Starts a run at `(t, y)`: the clock's origin is `t` ([`Stepper::start`]).
    pub(crate) fn start(&mut self, t: T, y: SVector<T, N>) {
        self.origin = t;
        self.reset(t, y);
    }

    /// The step `(hs, t_new, tau_new)` of a trial `h` from the state, cut to land on
    /// `t_limit` when it would reach it ([`clamp_to_limit`], on the elapsed time), and
    /// whether it lands. The clock is `origin + τ`: with the origin at 0 this is `t + h`.
    #[inline(always)]
    pub(crate) fn trial_step(&self, h: T, t_limit: T) -> (T, T, T, bool) {
        let (hs, lands) = clamp_to_limit(self.tau, h, t_limit - self.origin);
        if lands {
            (hs, t_limit, t_limit - self.origin, true)
        } else {
            let tau = self.tau + hs;
            (hs, self.origin + tau, tau, false)
        }
    }

    /// The fixed step `h` from the state, `(h, t_new, tau_new)`, or the rest to `t_limit`
    /// where that is within `10⁻⁹` of a step (it lands there).
    pub(crate) fn fixed_step(&self, h: T, t_limit: T) -> (T, T, T) {
        let rest = (t_limit - self.origin) - self.tau;
        if h >= rest * (T::one() - lit(1e-9)) {
            (rest, t_limit, t_limit - self.origin)
        } else {
            let tau = self.tau + h;
            (h, self.origin + tau, tau)
        }
    }

    /// Checks that there is a state and that `t_limit` lies ahead, and caches `f(t, y)`.
    #[inline(always)]
    pub(crate) fn begin<S: Dynamics<T, N>>(
        &mut self,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        if !self.initialized {
            return Err(IntegrateError::NotInitialized);
        }
        if !(t_limit > self.t) {
            return Err(IntegrateError::InvalidTimeSpan {
                t0: to_f64(self.t),
                t_end: to_f64(t_limit),
            });
        }
        if !self.f_valid {
            sys.rhs(self.t, &self.y, &mut self.f);
            self.stats.rhs_evals += 1;
            if !all_finite(&self.f) {
                return Err(IntegrateError::NonFiniteRhs { t: to_f64(self.t) });
            }
            self.f_valid = true;
        }
        Ok(())
    }

    /// The proposed step, or Hairer's initial guess for a method of order `order`.
    #[inline(always)]
    pub(crate) fn proposed<S: Dynamics<T, N>>(
        &mut self,
        sys: &S,
        order: u8,
        tol: &Tolerances<T, N>,
        h_max: T,
        t_limit: T,
    ) -> T {
        match self.h {
            Some(h) => h,
            None => initial_step(
                sys,
                self.t,
                &self.y,
                &self.f,
                order,
                tol,
                h_max,
                t_limit - self.t,
                &mut self.stats.rhs_evals,
            ),
        }
    }

    /// The adaptive retry loop of every embedded stepper: trial steps from the proposal
    /// `h`, each cut to land on `t_limit` when it would reach it ([`clamp_to_limit`]), the
    /// rejected ones retried with the controller's smaller step, until one is accepted.
    /// `trial(stats, hs, t_new)` computes one trial step of size `hs` ending at `t_new`
    /// (counting its own work in `stats`). A step below the minimum, or more than 20
    /// non-finite trials in a row, end the step with an error: it never loops without
    /// progress. The accepted trial is returned for the stepper's dense output and
    /// [`accept`](Self::accept).
    #[inline(always)]
    pub(crate) fn adapt<F>(
        &mut self,
        ctrl: &mut Controller<T>,
        t_limit: T,
        mut h: T,
        mut trial: F,
    ) -> Result<Accepted<T, N>, IntegrateError>
    where
        F: FnMut(&mut Stats, T, T) -> Result<Trial<T, N>, IntegrateError>,
    {
        let t = self.t;
        let mut nonfinite = 0u32;
        loop {
            let (hs, t_new, tau_new, lands) = self.trial_step(h, t_limit);
            if (hs < min_step(t, ctrl.opts.h_min) || !(t_new > t)) && !lands {
                return Err(IntegrateError::StepSizeTooSmall {
                    t: to_f64(t),
                    h: to_f64(hs),
                });
            }
            let tr = trial(&mut self.stats, hs, t_new)?;
            let err = match tr.err {
                Some(e) => e,
                None => {
                    nonfinite += 1;
                    if nonfinite > 20 {
                        return Err(IntegrateError::NonFiniteRhs { t: to_f64(t) });
                    }
                    crate::scalar::nan()
                }
            };
            let (accept, h_next) = ctrl.propose(err, hs);
            if accept {
                return Ok(Accepted {
                    hs,
                    t_new,
                    tau_new,
                    lands,
                    h,
                    h_next,
                    y: tr.y,
                    f: tr.f,
                });
            }
            self.stats.rejected += 1;
            h = h_next;
        }
    }

    /// Takes an accepted step: the new state and derivative, and the next proposed step
    /// (not shrunk below the untruncated proposal `h` when the step was cut to land on the
    /// limit).
    #[inline(always)]
    pub(crate) fn accept(&mut self, a: &Accepted<T, N>) {
        self.t = a.t_new;
        self.tau = a.tau_new;
        self.y = a.y;
        self.f = a.f;
        self.h = Some(if a.lands { a.h_next.max(a.h) } else { a.h_next });
        self.stats.accepted += 1;
    }
}

/// One trial step: the new state, its derivative, and the error norm (`None` where the
/// state or the derivative is not finite).
pub(crate) struct Trial<T: Real, const N: usize> {
    pub(crate) y: SVector<T, N>,
    pub(crate) f: SVector<T, N>,
    pub(crate) err: Option<T>,
}

impl<T: Real, const N: usize> Trial<T, N> {
    /// The trial `(y, f)`, with the error norm `err()` computed only where both are finite.
    #[inline(always)]
    pub(crate) fn new(y: SVector<T, N>, f: SVector<T, N>, err: impl FnOnce() -> T) -> Self {
        let err = (all_finite(&y) && all_finite(&f)).then(err);
        Self { y, f, err }
    }
}

/// The accepted trial of [`Core::adapt`]: its size `hs`, end `t_new` (and `tau_new`), whether it was cut
/// to land on the limit, the untruncated proposal `h`, the controller's next step, and
/// the new state and derivative.
pub(crate) struct Accepted<T: Real, const N: usize> {
    pub(crate) hs: T,
    pub(crate) t_new: T,
    /// The elapsed time since the clock's origin at `t_new`.
    pub(crate) tau_new: T,
    pub(crate) lands: bool,
    pub(crate) h: T,
    pub(crate) h_next: T,
    pub(crate) y: SVector<T, N>,
    pub(crate) f: SVector<T, N>,
}

/// PI step-size controller state (shared by the embedded methods).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Controller<T> {
    pub(crate) opts: StepOptions<T>,
    /// `1/q − 0.75·β` with `q` the order used for the error estimate.
    expo: T,
    /// `ln` of the error norm of the last accepted step (floored at `ln 10⁻⁴`).
    ln_err_old: T,
    /// The last accepted step (0 before the first) and `ln` of its error norm floored at
    /// `ln 10⁻²`, for the predictive correction.
    h_acc: T,
    ln_err_acc: T,
    rejected_last: bool,
}

impl<T: Real> Controller<T> {
    pub(crate) fn new(opts: StepOptions<T>, error_order: T) -> Self {
        let expo = T::one() / error_order - lit::<T>(0.75) * opts.beta;
        Self {
            opts,
            expo,
            ln_err_old: lit::<T>(1e-4).ln(),
            h_acc: T::zero(),
            ln_err_acc: T::zero(),
            rejected_last: false,
        }
    }

    /// Given the error norm of a trial step of size `h`, returns `(accept, h_next)`.
    ///
    /// One `ln` and one `exp` per call: `fac = err^expo / err_old^β` is evaluated as
    /// `exp(expo·ln err − β·ln err_old)` with `ln err_old` kept from the last acceptance.
    #[inline(always)]
    pub(crate) fn propose(&mut self, err: T, h: T) -> (bool, T) {
        let o = &self.opts;
        if !err.is_finite() {
            self.rejected_last = true;
            return (false, h * lit(0.1));
        }
        let ln_err = if err > T::zero() {
            err.ln()
        } else {
            lit::<T>(-700.0)
        };
        if err <= T::one() {
            // PI: fac = err^expo / err_old^β.
            let fac = (self.expo * ln_err - o.beta * self.ln_err_old).exp();
            let mut fac = (fac / o.safety)
                .max(T::one() / o.fac_max)
                .min(T::one() / o.fac_min);
            if o.predictive {
                if self.h_acc > T::zero() {
                    // Gustafsson (1994): (h_acc/h)·(err²/err_acc)^{1/q}, as in Hairer's
                    // RADAU5; only ever shortens the PI proposal.
                    let gus = self.h_acc / h
                        * ((lit::<T>(2.0) * ln_err - self.ln_err_acc)
                            * (self.expo + lit::<T>(0.75) * o.beta))
                            .exp()
                        / o.safety;
                    fac = fac.max(gus.max(T::one() / o.fac_max).min(T::one() / o.fac_min));
                }
                self.h_acc = h;
                self.ln_err_acc = ln_err.max(lit::<T>(1e-2).ln());
            }
            let mut h_new = h / fac;
            if self.rejected_last {
                h_new = h_new.min(h);
            }
            self.ln_err_old = ln_err.max(lit::<T>(1e-4).ln());
            self.rejected_last = false;
            (true, h_new.min(o.h_max))
        } else {
            let fac11 = (self.expo * ln_err).exp();
            let fac = (fac11 / o.safety).min(T::one() / o.fac_min);
            self.rejected_last = true;
            (false, h / fac)
        }
    }
}

/// Hairer's initial step-size guess for a method of order `order`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_step<T: Real, const N: usize, S: Dynamics<T, N>>(
    sys: &S,
    t0: T,
    y0: &SVector<T, N>,
    f0: &SVector<T, N>,
    order: u8,
    tol: &Tolerances<T, N>,
    h_max: T,
    dir_span: T,
    evals: &mut u64,
) -> T {
    let mut d0 = T::zero();
    let mut d1 = T::zero();
    for i in 0..N {
        let sc = tol.atol[i] + tol.rtol[i] * y0[i].abs();
        d0 += (y0[i] / sc) * (y0[i] / sc);
        d1 += (f0[i] / sc) * (f0[i] / sc);
    }
    let n = lit::<T>(N as f64);
    d0 = (d0 / n).sqrt();
    d1 = (d1 / n).sqrt();
    let mut h0 = if d0 < lit(1e-5) || d1 < lit(1e-5) {
        lit(1e-6)
    } else {
        lit::<T>(0.01) * d0 / d1
    };
    h0 = h0.min(h_max).min(dir_span.abs());
    let y1 = y0 + f0 * h0;
    let mut f1 = SVector::zeros();
    sys.rhs(t0 + h0, &y1, &mut f1);
    *evals += 1;
    let mut d2 = T::zero();
    for i in 0..N {
        let sc = tol.atol[i] + tol.rtol[i] * y0[i].abs();
        let q = (f1[i] - f0[i]) / sc;
        d2 += q * q;
    }
    d2 = (d2 / n).sqrt() / h0;
    let dm = d1.max(d2);
    let h1 = if dm <= lit(1e-15) {
        (h0 * lit(1e-3)).max(lit(1e-6))
    } else {
        (lit::<T>(0.01) / dm).powf(T::one() / lit::<T>(order as f64 + 1.0))
    };
    let h = (h0 * lit(100.0)).min(h1).min(h_max).min(dir_span.abs());
    if h.is_finite() && h > T::zero() {
        h
    } else {
        lit(1e-6)
    }
}

/// `true` if every component is finite.
#[inline(always)]
pub(crate) fn all_finite<T: Real, const N: usize>(y: &SVector<T, N>) -> bool {
    y.iter().all(|v| v.is_finite())
}

/// Validates an initial state.
pub(crate) fn check_state<T: Real, const N: usize>(
    y: &SVector<T, N>,
) -> Result<(), IntegrateError> {
    for (i, v) in y.iter().enumerate() {
        if !v.is_finite() {
            return Err(IntegrateError::NonFiniteState {
                index: i,
                value: to_f64(*v),
            });
        }
    }
    Ok(())
}

/// The smallest step that still advances `t` meaningfully.
#[inline(always)]
pub(crate) fn min_step<T: Real>(t: T, h_min: T) -> T {
    (lit::<T>(16.0) * T::default_epsilon() * t.abs()).max(h_min)
}

/// Clamps a trial step so that `t + h` does not pass `t_limit`; returns `(h, lands)` where
/// `lands` says the step ends exactly on `t_limit` (a step within 1 % of the limit is
/// stretched to it rather than leaving a sliver).
#[inline(always)]
pub(crate) fn clamp_to_limit<T: Real>(t: T, h: T, t_limit: T) -> (T, bool) {
    let rest = t_limit - t;
    if h >= rest * lit(0.99) {
        (rest, true)
    } else {
        (h, false)
    }
}
