//! Lyapunov exponents: the top exponent by two nearby trajectories (Benettin) and the
//! spectrum by the tangent-space (QR) method, a separation (`d0`) study, and the
//! exponent-versus-parameter diagram.
//!
//! # The two methods
//! Every estimator is a configuration of one renormalizing runner: a flow (one stepper on an
//! augmented system, the event engine with resets, Filippov runs) and a renormalization (a
//! separation vector, or `K` tangent vectors re-orthonormalized by QR); the grid, the
//! transient, the records, the statistics and the errors are written once. Sizes are
//! inferred: `M = 2N` and `M = N + N·K` come from the type system ([`PairDimension`],
//! [`TangentDimension`]) in the constructors that take the system's tolerances.
//!
//! **Two trajectories** ([`TwoTrajectory`]). A reference trajectory `y` and a perturbed one
//! `ỹ = y + δ` are integrated *together* as one system of dimension `M = 2N`
//! ([`PerturbedPair`]), so that both take exactly the same steps and their discretizations
//! are correlated. Every interval `τ` the separation is measured and pulled back to `d0`
//! along its current direction:
//! $$d_k = \|\tilde y(t_k) - y(t_k)\|_w,\qquad
//!   \tilde y(t_k) \leftarrow y(t_k) + \frac{d_0}{d_k}\,\bigl(\tilde y(t_k) - y(t_k)\bigr),\qquad
//!   \lambda_1 \approx \frac{1}{n\tau}\sum_{k=1}^{n}\ln\frac{d_k}{d_0},$$
//! with `t_k = t_0 + kτ` (computed from `k`, never accumulated). The denominator of each term
//! is the separation actually realized after the previous renormalization (it equals `d0` up
//! to rounding). No Jacobian is needed, which is why this is the method of choice for
//! nonsmooth models; its price is the choice of `d0`: too small and the integration and
//! rounding errors of the difference dominate, too large and the estimate stops being local
//! (the pair feels the nonlinearity — for an impact oscillator: the two trajectories hit the
//! stop at noticeably different times). [`separation_study`] scans `d0` over decades;
//! choose `d0` in the plateau (for the paper's model and the study behind its value see
//! [`systems::paper::lyapunov::D0`](crate::systems::paper::lyapunov::D0)).
//!
//! **Tangent space** ([`TangentSpace`]). `K ≤ N` tangent vectors are integrated with the
//! state through the variational equations ([`Variational`], dimension `M = N + N·K`)
//! $$\dot y = f(t, y),\qquad \dot\Phi = J(t, y)\,\Phi,\qquad J = \partial f/\partial y,$$
//! and re-orthonormalized every `τ` by modified Gram–Schmidt,
//! `Φ(t_k) = Q_k R_k`, `Φ ← Q_k`:
//! $$\lambda_j \approx \frac{1}{n\tau}\sum_{k=1}^{n}\ln (R_k)_{jj},\qquad j = 1..K .$$
//! With `K = N` the sum of the spectrum is the time average of `tr J` (Liouville), a check
//! that does not depend on the length of the run. It needs
//! [`Dynamics::jacobian`].
//!
//! **Through sliding** ([`FilippovTwoTrajectory`]). For a Filippov system (a field
//! discontinuous across switching surfaces, with sliding on them) the two trajectories are
//! two event-driven runs of [`FilippovSimulation`](crate::filippov::FilippovSimulation);
//! the state is continuous, so the separation is measured at the grid times whatever the
//! modes. It checks the tangent-space estimate
//! [`FilippovSimulation::exponents`](crate::filippov::FilippovSimulation::exponents)
//! (saltation matrices at crossings and sliding entries, the sliding field's Jacobian
//! while sliding).
//!
//! # The norm
//! Both methods measure separations in a weighted Euclidean [`Norm`]
//! $$\|\delta\|_w = \Bigl(\sum_i (\delta_i/w_i)^2\Bigr)^{1/2},$$
//! with `w_i` the characteristic scale of component `i` (units of the component). The limit
//! exponents do not depend on the norm (all norms on `ℝᴺ` are equivalent), but finite-time
//! estimates, the meaning of `d0` and the conditioning of Gram–Schmidt do: in SI units a
//! position of `~10⁻³ m` and a velocity of `~3·10⁻²` m/s differ by a factor of about 30, and
//! an unweighted norm would let the velocity alone decide. The tangent method works in the
//! scaled coordinates `ψ = D⁻¹δ`, `D = diag(w)` (so `ψ̇ = D⁻¹JD ψ`, and Gram–Schmidt is
//! Euclidean in `ψ`).
//!
//! # Statistical spread
//! The per-interval rates `s_k = ln(d_k/d_0)/τ` are correlated, so their naive standard
//! error is too small. The [`Estimate::spread`] is the standard error of the mean from
//! `B` contiguous blocks (default 10): with block means `m_b`,
//! $$\sigma_{\bar\lambda} = \Bigl(\frac{1}{B(B-1)}\sum_{b=1}^{B}(m_b - \bar m)^2\Bigr)^{1/2},$$
//! valid when a block is much longer than the correlation time. The running estimate after
//! each interval is kept as the convergence [`history`](Estimate::history).
//!
//! # Where the Jacobian is singular
//! A law with a cusp in the rate — a contact damping `sgn(ẋ)|ẋ|^{p}` with `p < 1`, a
//! friction regularized on a small scale `ε` — has an infinite (or a very large) slope
//! `∂F/∂ẋ` at `ẋ = 0`. For the exact cusp the variational equations are not defined
//! wherever the rate reverses in contact, and `∂F/∂ẋ` returned by the law (e.g.
//! [`HertzContact`](crate::force::HertzContact)) is the largest finite number there. (The
//! singularity is integrable along a trajectory — `∫|ẋ|^{p−1}dt` converges when `ẍ ≠ 0` —
//! but no step-based integrator can evaluate `J` at it.) The QR method then fails at the
//! first reversal in contact ([`IntegrateError::StepSizeTooSmall`]), while the
//! two-trajectory method, which never forms `J`, runs at its usual cost. With a rate
//! regularization `sgn(ẋ)|ẋ|^{p} → ẋ(ẋ²+η²)^{(p−1)/2}` the Jacobian is finite but very
//! large in short windows around each reversal; those windows are strongly contracting (the
//! large entry is damping), so they cannot blow the tangent vectors up, and the QR method
//! estimates the exponents of the regularized flow. The paper's model, with both methods
//! compared, is documented in [`systems::paper::lyapunov`](crate::systems::paper::lyapunov).
//!
//! # Examples
//! ```
//! use nalgebra::Vector3;
//! use nonsmooth::integrate::{Dopri5, Tolerances};
//! use nonsmooth::lyapunov::{Norm, TwoTrajectory};
//! # #[derive(Clone, Copy)]
//! # struct Lorenz;
//! # impl nonsmooth::Dynamics<f64, 3> for Lorenz {
//! #     fn rhs(&self, _t: f64, y: &nalgebra::SVector<f64, 3>, dy: &mut nalgebra::SVector<f64, 3>) {
//! #         dy[0] = 10.0 * (y[1] - y[0]);
//! #         dy[1] = y[0] * (28.0 - y[2]) - y[1];
//! #         dy[2] = y[0] * y[1] - 8.0 / 3.0 * y[2];
//! #     }
//! # }
//! // The Lorenz system (σ, ρ, β) = (10, 28, 8/3); the pair has dimension 2·3 = 6, inferred
//! // from the system's tolerances (no size is written).
//! let tol = Tolerances::new(1e-9, 1e-9)?;
//! let mut est = TwoTrajectory::from_tolerances(Lorenz, &tol, Dopri5::new, 1e-8, Norm::Euclidean)?;
//! est.start(0.0, Vector3::new(1.0, 1.0, 20.0))?;
//! est.transient(1.0, 20)?;
//! let e = est.estimate(1.0, 200)?;
//! // Literature: λ₁ ≈ 0.906; 200 time units give a rough estimate.
//! assert!((e.exponent - 0.906).abs() < 0.15, "{} ± {}", e.exponent, e.spread);
//! # Ok::<(), nonsmooth::Error>(())
//! ```
//!
//! # References
//! G. Benettin, L. Galgani, A. Giorgilli, J.-M. Strelcyn, *Lyapunov characteristic
//! exponents for smooth dynamical systems and for Hamiltonian systems*, Meccanica 15
//! (1980); A. Wolf et al., *Determining Lyapunov exponents from a time series*, Physica D 16
//! (1985).

mod diagram;
mod filippov;
pub mod hybrid;
mod lanes;
mod runner;
mod sizes;
mod tangent;
mod two_trajectory;

pub use diagram::{
    Diagram, DiagramDirection, DiagramPoint, DiagramSettings, IntervalRule, tle_diagram,
};
pub use filippov::FilippovTwoTrajectory;
pub use hybrid::{HybridTangentSpace, HybridTwoTrajectory, Saltation};
pub use lanes::tle_independent;
#[cfg(feature = "parallel")]
pub use lanes::tle_independent_parallel;
pub use sizes::{Dims, PairDimension, TangentDimension};
pub use tangent::{Spectrum, TangentSpace, Variational, tangent_tolerances};
pub use two_trajectory::{
    PerturbedPair, SeparationPoint, TwoTrajectory, decades, pair_tolerances, separation_study,
};

use nalgebra::SVector;
use thiserror::Error;

use crate::drive::RunError;
use crate::integrate::{IntegrateError, Stats, Stepper};
use crate::scalar::{lit, to_f64};
use crate::validate::ParameterError;
use crate::{Dynamics, Real};

/// Errors of this module.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum LyapunovError {
    /// The initial separation `d0` is not finite and > 0.
    #[error("invalid initial separation d0 = {d0}: must be finite and > 0")]
    InvalidSeparation {
        /// The rejected `d0`.
        d0: f64,
    },
    /// The separation `d0` cannot be represented on top of the state (it is lost to rounding).
    #[error(
        "the separation d0 = {d0} is not resolved at this state (realized {realized}): increase d0 or rescale the norm"
    )]
    UnresolvedSeparation {
        /// The requested `d0`.
        d0: f64,
        /// The separation actually realized after rounding.
        realized: f64,
    },
    /// The renormalization interval `τ` is not finite and > 0.
    #[error("invalid renormalization interval tau = {tau}: must be finite and > 0")]
    InvalidInterval {
        /// The rejected `τ`.
        tau: f64,
    },
    /// Too few intervals to average over.
    #[error("invalid number of intervals {intervals}: at least {minimum} are needed")]
    TooFewIntervals {
        /// The requested number.
        intervals: usize,
        /// The minimum.
        minimum: usize,
    },
    /// More intervals than one estimate records ([`MAX_INTERVALS`]).
    #[error("{intervals} intervals requested; at most {maximum} per estimate")]
    TooManyIntervals {
        /// The requested number.
        intervals: usize,
        /// The maximum.
        maximum: usize,
    },
    /// The number of blocks for the standard error is < 2.
    #[error("invalid number of blocks {blocks}: at least 2 are needed for a spread")]
    InvalidBlocks {
        /// The requested number.
        blocks: usize,
    },
    /// A weight of [`Norm::Weighted`] is not finite and > 0.
    #[error("invalid norm weight w[{index}] = {value}: must be finite and > 0")]
    InvalidWeight {
        /// The component.
        index: usize,
        /// The rejected weight.
        value: f64,
    },
    /// The initial perturbation direction is zero or not finite.
    #[error("invalid perturbation direction (zero or not finite)")]
    InvalidDirection,
    /// The augmented dimension `M` does not match the system's `N`.
    #[error(
        "augmented dimension M = {found} does not match: {what} needs M = {expected} for N = {n}"
    )]
    Dimension {
        /// Which construction (`"two trajectories (M = 2N)"`, `"tangent space (M = N + N·K)"`).
        what: &'static str,
        /// The system's dimension `N`.
        n: usize,
        /// The required `M`.
        expected: usize,
        /// The given `M`.
        found: usize,
    },
    /// The number of tangent vectors `K` is not in `1..=N`.
    #[error("invalid number of tangent vectors K = {k}: must be in 1..={n}")]
    TangentCount {
        /// `K`.
        k: usize,
        /// `N`.
        n: usize,
    },
    /// A state or time is NaN or infinite.
    #[error("non-finite input: {what} = {value}")]
    NonFinite {
        /// What was rejected (`"t0"`, `"y0[1]"`, ...).
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// `estimate`/`transient` was called before `start`.
    #[error("the estimator has no state: call start first")]
    NotStarted,
    /// The system provides no Jacobian (needed by the tangent-space method).
    #[error(
        "the system provides no Jacobian at t = {t}: use the two-trajectory method or implement Dynamics::jacobian"
    )]
    NoJacobian {
        /// Where it was requested.
        t: f64,
    },
    /// The separation collapsed to zero or became non-finite over an interval.
    #[error(
        "the separation became {separation} at t = {t} (collapsed or overflowed): shorten the interval tau or change d0"
    )]
    SeparationLost {
        /// End of the interval.
        t: f64,
        /// The separation found there.
        separation: f64,
    },
    /// A tangent vector collapsed (zero or non-finite Gram–Schmidt factor).
    #[error(
        "tangent vector {index} collapsed at t = {t} (R[{index}][{index}] = {value}): shorten the interval tau"
    )]
    TangentCollapse {
        /// End of the interval.
        t: f64,
        /// The column.
        index: usize,
        /// The diagonal entry of `R`.
        value: f64,
    },
    /// A diagram was requested for an empty parameter list.
    #[error("the parameter list is empty")]
    NoParameters,
    /// A parameter value of a diagram is invalid.
    #[error("invalid parameter value {value}: {requirement}")]
    InvalidParameter {
        /// The value.
        value: f64,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// A run failed (a rejected setting, the integration, the events), or the system could
    /// not be built. Converts into the crate's [`Error`](crate::Error) as the run's error
    /// itself (`Error::Integrate(..)`, …).
    #[error(transparent)]
    Run(#[from] RunError),
    /// A builder of the system at a parameter value failed with an error of another layer
    /// (its message).
    #[error("building the system failed: {0}")]
    Build(String),
    /// A run of a Filippov system failed where only sliding motion can fail (two surfaces
    /// met at once, a repelling surface, drift off the surface, …); its engine errors are
    /// [`Run`](Self::Run).
    #[error(transparent)]
    Filippov(crate::filippov::FilippovError),
}

impl From<crate::filippov::FilippovError> for LyapunovError {
    /// The engine's errors as [`Run`](LyapunovError::Run), the rest as
    /// [`Filippov`](LyapunovError::Filippov).
    fn from(e: crate::filippov::FilippovError) -> Self {
        match e {
            crate::filippov::FilippovError::Run(e) => LyapunovError::Run(e),
            e => LyapunovError::Filippov(e),
        }
    }
}

/// `Result` with [`LyapunovError`].
pub(crate) type Result<T, E = LyapunovError> = std::result::Result<T, E>;

crate::drive::from_engine_errors!(LyapunovError);

/// Default number of blocks for the standard error.
pub const DEFAULT_BLOCKS: usize = 10;

/// Default cap of accepted steps per renormalization interval.
pub const DEFAULT_MAX_STEPS_PER_INTERVAL: usize = 10_000_000;

/// A weighted Euclidean norm for separations (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Norm<T, const N: usize> {
    /// `‖δ‖ = (Σ δ_i²)^{1/2}`: for systems whose components share a scale (Lorenz).
    Euclidean,
    /// `‖δ‖ = (Σ (δ_i/w_i)²)^{1/2}` with `w_i > 0` the characteristic scale of component `i`.
    Weighted([T; N]),
}

impl<T: Real, const N: usize> Norm<T, N> {
    /// A weighted norm, validated.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidWeight`] unless every weight is finite and > 0.
    pub fn weighted(weights: [T; N]) -> Result<Self, LyapunovError> {
        let n = Norm::Weighted(weights);
        n.validate()?;
        Ok(n)
    }

    /// Checks the weights.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidWeight`] unless every weight is finite and > 0.
    pub fn validate(&self) -> Result<(), LyapunovError> {
        if let Norm::Weighted(w) = self {
            for (index, &v) in w.iter().enumerate() {
                if !(v.is_finite() && v > T::zero()) {
                    return Err(LyapunovError::InvalidWeight {
                        index,
                        value: to_f64(v),
                    });
                }
            }
        }
        Ok(())
    }

    /// The scales `w_i` (all 1 for [`Norm::Euclidean`]).
    pub fn scales(&self) -> SVector<T, N> {
        match self {
            Norm::Euclidean => SVector::repeat(T::one()),
            Norm::Weighted(w) => SVector::from(*w),
        }
    }

    /// `‖δ‖_w`.
    #[inline]
    pub fn norm(&self, delta: &SVector<T, N>) -> T {
        match self {
            Norm::Euclidean => delta.norm(),
            Norm::Weighted(w) => {
                let mut s = T::zero();
                for i in 0..N {
                    let q = delta[i] / w[i];
                    s += q * q;
                }
                s.sqrt()
            }
        }
    }
}

/// A top-exponent estimate with its convergence history.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Estimate<T> {
    /// The estimate `λ = (1/(nτ)) Σ ln(d_k/d0)` (1/time unit).
    pub exponent: T,
    /// Its standard error from blocks (see the module docs).
    pub spread: T,
    /// The running estimate after each interval (`history[n−1] == exponent`).
    pub history: Vec<T>,
    /// The finite-time rates `ln(d_k/d0)/τ` of the single intervals.
    pub local: Vec<T>,
    /// The renormalization interval `τ`.
    pub interval: T,
    /// The number of blocks behind [`spread`](Self::spread).
    pub blocks: usize,
    /// Work done (augmented system).
    pub stats: Stats,
}

impl<T: Real> Estimate<T> {
    /// The number of intervals averaged.
    pub fn intervals(&self) -> usize {
        self.local.len()
    }

    /// The standard error recomputed with another number of blocks (`None` if
    /// `blocks < 2` or `blocks > intervals`).
    pub fn standard_error(&self, blocks: usize) -> Option<T> {
        if blocks < 2 || blocks > self.local.len() {
            return None;
        }
        Some(block_standard_error(self.local.len(), blocks, |k| {
            self.local[k]
        }))
    }
}

/// The time `t0 + k·τ` of the `k`-th renormalization.
#[inline(always)]
pub(crate) fn grid_time<T: Real>(t0: T, tau: T, k: usize) -> T {
    t0 + tau * lit::<T>(k as f64)
}

/// Standard error of the mean of `x(0..n)` from `blocks` contiguous blocks of (nearly)
/// equal size (block `b` covers `[b·n/B, (b+1)·n/B)`). Needs `2 ≤ blocks ≤ n`.
pub(crate) fn block_standard_error<T: Real>(n: usize, blocks: usize, x: impl Fn(usize) -> T) -> T {
    debug_assert!(blocks >= 2 && blocks <= n);
    let block_mean = |b: usize| {
        let (lo, hi) = (b * n / blocks, (b + 1) * n / blocks);
        let mut s = T::zero();
        for k in lo..hi {
            s += x(k);
        }
        s / lit::<T>((hi - lo) as f64)
    };
    let bf = lit::<T>(blocks as f64);
    let mut mean = T::zero();
    for b in 0..blocks {
        mean += block_mean(b);
    }
    mean /= bf;
    let mut ss = T::zero();
    for b in 0..blocks {
        let d = block_mean(b) - mean;
        ss += d * d;
    }
    (ss / (bf * (bf - T::one()))).sqrt()
}

pub(crate) fn check_interval<T: Real>(tau: T) -> Result<T, LyapunovError> {
    if tau.is_finite() && tau > T::zero() {
        Ok(tau)
    } else {
        Err(LyapunovError::InvalidInterval { tau: to_f64(tau) })
    }
}

/// As [`check_interval`], and `t + τ > t` in floating point (an interval below the time
/// resolution at `t` would make no progress and report 0 ± 0).
pub(crate) fn check_interval_at<T: Real>(t: T, tau: T) -> Result<T, LyapunovError> {
    let tau = check_interval(tau)?;
    if t + tau > t {
        Ok(tau)
    } else {
        Err(LyapunovError::InvalidInterval { tau: to_f64(tau) })
    }
}

pub(crate) fn check_intervals(intervals: usize, minimum: usize) -> Result<(), LyapunovError> {
    if intervals < minimum {
        Err(LyapunovError::TooFewIntervals { intervals, minimum })
    } else if intervals > MAX_INTERVALS {
        Err(LyapunovError::TooManyIntervals {
            intervals,
            maximum: MAX_INTERVALS,
        })
    } else {
        Ok(())
    }
}

/// The most intervals one estimate records (10⁸: its history and local rates take 16 bytes
/// per interval, 1.6 GB at the limit).
pub const MAX_INTERVALS: usize = 100_000_000;

/// `direction` scaled to unit length in `norm`.
///
/// # Errors
/// [`LyapunovError::InvalidDirection`] if it is zero or not finite.
pub(crate) fn unit_direction<T: Real, const N: usize>(
    norm: &Norm<T, N>,
    direction: SVector<T, N>,
) -> Result<SVector<T, N>, LyapunovError> {
    let n = norm.norm(&direction);
    if !(n.is_finite() && n > T::zero() && direction.iter().all(|v| v.is_finite())) {
        return Err(LyapunovError::InvalidDirection);
    }
    Ok(direction / n)
}

pub(crate) fn check_blocks(blocks: usize) -> Result<usize, LyapunovError> {
    if blocks < 2 {
        Err(LyapunovError::InvalidBlocks { blocks })
    } else {
        Ok(blocks)
    }
}

/// Validates a per-interval step cap.
pub(crate) fn check_max_steps(max_steps: usize) -> Result<usize> {
    if max_steps == 0 {
        return Err(ParameterError::new("max_steps", 0.0, ">= 1").into());
    }
    Ok(max_steps)
}

/// Names `y0[i]` for diagnostics (indices beyond 7 share a name).
pub(crate) fn component_name(i: usize) -> &'static str {
    const NAMES: [&str; 8] = [
        "y0[0]", "y0[1]", "y0[2]", "y0[3]", "y0[4]", "y0[5]", "y0[6]", "y0[7]",
    ];
    NAMES.get(i).copied().unwrap_or("y0[i > 7]")
}

pub(crate) fn check_state<T: Real, const N: usize>(
    t0: T,
    y0: &SVector<T, N>,
) -> Result<(), LyapunovError> {
    if !t0.is_finite() {
        return Err(LyapunovError::NonFinite {
            what: "t0",
            value: to_f64(t0),
        });
    }
    for (i, v) in y0.iter().enumerate() {
        if !v.is_finite() {
            return Err(LyapunovError::NonFinite {
                what: component_name(i),
                value: to_f64(*v),
            });
        }
    }
    Ok(())
}

/// Steps `stepper` on `sys` until it lands on `t_target` (at most `max_steps` steps).
pub(crate) fn integrate_to<T: Real, const M: usize, D: Dynamics<T, M>, St: Stepper<T, M>>(
    stepper: &mut St,
    sys: &D,
    t_target: T,
    max_steps: usize,
) -> Result<(), IntegrateError> {
    let mut steps = 0usize;
    while stepper.current().0 < t_target {
        if steps >= max_steps {
            return Err(IntegrateError::MaxSteps {
                t: to_f64(stepper.current().0),
                max_steps,
            });
        }
        stepper.step(sys, t_target)?;
        steps += 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_standard_error_matches_hand_computation() {
        // Four blocks of two: means 1, 2, 3, 4 → mean 2.5, sample var 5/3, se = sqrt(5/12).
        let x = [1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0];
        let se = block_standard_error(8, 4, |k| x[k]);
        assert!((se - (5.0_f64 / 12.0).sqrt()).abs() < 1e-15);
        // A constant series has zero spread; unequal blocks are allowed.
        assert_eq!(block_standard_error(7, 3, |_| 0.25_f64), 0.0);
    }

    #[test]
    fn norms() {
        let d = SVector::<f64, 2>::new(3e-3, 4e-2);
        assert!((Norm::Euclidean.norm(&d) - (9e-6_f64 + 16e-4).sqrt()).abs() < 1e-18);
        let w = Norm::weighted([1e-3, 1e-2]).unwrap();
        assert!((w.norm(&d) - 5.0).abs() < 1e-14);
        assert_eq!(
            Norm::weighted([1.0, 0.0]),
            Err(LyapunovError::InvalidWeight {
                index: 1,
                value: 0.0
            })
        );
        assert!(Norm::weighted([f64::NAN, 1.0]).is_err());
        assert!(Norm::Weighted([-1.0_f64, 1.0]).validate().is_err());
        let p = Norm::<f32, 2>::Weighted([1e-3, 3e-2]);
        assert!((p.norm(&SVector::<f32, 2>::new(1e-3, 3e-2)) - 2.0_f32.sqrt()).abs() < 1e-6);
        assert_eq!(p.scales()[1], 3e-2_f32);
    }

    #[test]
    fn validation_helpers() {
        assert!(check_interval(0.0_f64).is_err());
        assert!(check_interval(f64::INFINITY).is_err());
        assert!(check_interval(-1.0_f64).is_err());
        assert_eq!(check_interval(0.5_f64), Ok(0.5));
        assert!(check_intervals(1, 2).is_err());
        assert!(check_blocks(1).is_err());
        assert!(check_state(0.0, &SVector::<f64, 2>::new(1.0, f64::NAN)).is_err());
        assert!(check_state(f64::NAN, &SVector::<f64, 2>::zeros()).is_err());
        assert_eq!(grid_time(1.0_f64, 0.1, 10), 1.0 + 0.1 * 10.0);
    }
}
