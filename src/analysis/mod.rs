//! Harmonic analysis of periodic responses and the paper's approximate solutions
//! (Sect. 5: "The system behavior at low frequencies").
//!
//! | tool | what | paper |
//! |---|---|---|
//! | [`AmplitudeSpectrum`], [`SpectrumAnalyzer`] | one-sided amplitude spectrum of a uniformly sampled signal covering a whole number of forcing periods; harmonic amplitudes and phases; how many harmonics dominate | Fig. 9b |
//! | [`fit_harmonics`] → [`HarmonicFit`] | least-squares truncated Fourier series $a_0 + \sum_k (a_k\cos k\omega t + b_k \sin k\omega t)$ | eq. (3) |
//! | [`LinearizedResponse`] | the linearization about the static equilibrium $X_0$ and its grazing estimate | eq. (4), $\omega = 15.657$ |
//! | [`steady_samples`], [`first_grazing`] | steady response sampled over whole periods from a simulation; the exact first grazing by a bracketing search in ω | eq. (3), Fig. 9, ω ≈ 14 |
//! | [`AmplitudePhase`] | the amplitude–phase (one-point harmonic balance) method and its grazing estimate | eqs. (5)–(6), $\omega = 12.789$ |
//!
//! # Time origin
//! All phases and Fourier coefficients are given in the time origin of the `t` values passed
//! in. The paper's coefficients refer to the stroboscopic Poincaré section
//! $t = 2\pi i/\omega$; for a constant forcing frequency any time measured from $t = 0$ of the
//! simulation is such an origin (the basis functions $\cos k\omega t$, $\sin k\omega t$ are
//! $2\pi/\omega$-periodic), so simulated samples can be passed with their own time stamps.
//!
//! # Scalars
//! The fit and the approximations are generic over [`Real`](crate::Real) (`f64`, `f32`).
//! The spectrum works in `f64`: `rustfft`'s scalar bound (`num_traits::Signed`, …) is not
//! compatible with the crate's `Real` bound (method ambiguities such as `abs`), and spectra
//! of measured or simulated data are computed in `f64` anyway.
//!
//! # References
//! The paper's Sect. 5, eqs. (2)–(6) and Fig. 9.

mod approx;
mod fit;
mod order;
mod spectrum;
mod steady;

pub use approx::{
    AmplitudeLaw, AmplitudePhase, AmplitudePhaseSolution, ForcingAmplitude, LinearizedResponse,
    TurningPoint,
};
pub use fit::{HarmonicFit, fit_harmonics};
pub use order::observed_order;
pub use spectrum::{
    AmplitudeSpectrum, DOMINANCE_THRESHOLD, HarmonicComponent, PERIOD_TOLERANCE, SPACING_TOLERANCE,
    SpectrumAnalyzer,
};
pub use steady::{SteadySamples, first_grazing, steady_min_gap, steady_samples};

use crate::roots::RootError;
use crate::validate::ParameterError;

/// Errors of the harmonic analysis and of the approximate solutions.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// The time and value slices have different lengths.
    #[error("{t} time stamps but {x} values: the slices must have the same length")]
    LengthMismatch {
        /// Number of time stamps.
        t: usize,
        /// Number of values.
        x: usize,
    },
    /// Too few samples for the requested harmonics.
    #[error("{samples} samples, at least {required} needed for the requested harmonics")]
    TooFewSamples {
        /// Samples given.
        samples: usize,
        /// Samples required.
        required: usize,
    },
    /// A time stamp or value is NaN or infinite.
    #[error("non-finite {what} at index {index}")]
    NonFinite {
        /// `"time"` or `"value"`.
        what: &'static str,
        /// Index of the first offending sample.
        index: usize,
    },
    /// The forcing frequency is not finite and positive.
    #[error("invalid angular frequency {omega}: must be finite and > 0")]
    InvalidFrequency {
        /// The rejected `ω` (rad/s).
        omega: f64,
    },
    /// A [`SpectrumAnalyzer`] planned for one length was given another.
    #[error("the analyzer was planned for {planned} samples but got {samples}")]
    PlanLengthMismatch {
        /// The planned length.
        planned: usize,
        /// The length given.
        samples: usize,
    },
    /// The time stamps are not increasing and uniformly spaced.
    #[error(
        "samples are not uniformly spaced: t[{index}] deviates from t0 + {index}·dt by {deviation} dt (dt = {dt})"
    )]
    NonUniformSampling {
        /// Index of the worst sample.
        index: usize,
        /// Its deviation from the uniform grid, in units of `dt`.
        deviation: f64,
        /// The mean spacing.
        dt: f64,
    },
    /// The samples do not cover a whole number of forcing periods.
    #[error(
        "the samples cover {periods} forcing periods (span n·dt = {span}, period {period}), not a whole number{hint}"
    )]
    NotWholePeriods {
        /// `n·dt` (the sampled window, one `dt` past the last sample).
        span: f64,
        /// The forcing period `2π/ω`.
        period: f64,
        /// `span/period`.
        periods: f64,
        /// A remediation hint (may be empty).
        hint: &'static str,
    },
    /// The requested harmonic lies at or above the Nyquist frequency of the sample.
    #[error("harmonic {harmonic} is not resolved: the largest resolved harmonic is {max_harmonic}")]
    HarmonicOutOfRange {
        /// The requested harmonic `j`.
        harmonic: usize,
        /// The largest `j` with `j·P < n/2`.
        max_harmonic: usize,
    },
    /// The least-squares problem is numerically rank deficient (e.g. the samples span a tiny
    /// fraction of a period).
    #[error(
        "the harmonic basis is numerically rank deficient on these time stamps (condition number {condition})"
    )]
    IllConditioned {
        /// Ratio of the largest to the smallest singular value of the design matrix.
        condition: f64,
    },
    /// A parameter of an approximation is invalid.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// Convergence data that has no observed order: fewer than two points, slices of
    /// different lengths, a step or error that is not finite and > 0, or a single step size.
    #[error("no observed order from these data: {reason}")]
    ConvergenceData {
        /// What is wrong, naming the index and value.
        reason: String,
    },
    /// The restoring force has no zero in the given interval.
    #[error("no static equilibrium in [{lo}, {hi}]: the restoring force does not change sign")]
    NoEquilibrium {
        /// Lower end of the search interval.
        lo: f64,
        /// Upper end of the search interval.
        hi: f64,
    },
    /// The frequency bracket is not an interval of positive frequencies.
    #[error("invalid frequency bracket [{lo}, {hi}]: need 0 < lo < hi, both finite")]
    InvalidBracket {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// The grazing condition does not change sign over the frequency bracket.
    #[error(
        "no grazing of the stop at {x_stop} in ω ∈ [{lo}, {hi}]: the gap (stop − turning point) is {gap_lo} and {gap_hi} at the ends"
    )]
    NoGrazingBracket {
        /// The stop position.
        x_stop: f64,
        /// Lower end of the bracket.
        lo: f64,
        /// Upper end of the bracket.
        hi: f64,
        /// Grazing function at `lo`.
        gap_lo: f64,
        /// Grazing function at `hi`.
        gap_hi: f64,
    },
    /// The amplitude–phase equations have no root on the requested branch.
    #[error("the amplitude–phase equations have no {branch} solution at ω = {omega}")]
    NoSolution {
        /// The forcing frequency.
        omega: f64,
        /// `"upper"` or `"lower"`.
        branch: &'static str,
    },
    /// The stop lies on the other side of the equilibrium than the requested turning point.
    #[error(
        "the stop at {x_stop} is not on the {branch} side of the equilibrium X0 = {x0}: use the other turning point"
    )]
    WrongSide {
        /// The stop position.
        x_stop: f64,
        /// The equilibrium.
        x0: f64,
        /// `"upper"` or `"lower"`.
        branch: &'static str,
    },
    /// A root search failed to converge.
    #[error(transparent)]
    Root(#[from] RootError),
    /// A simulation behind a steady-state analysis failed.
    #[error("simulation failed: {0}")]
    Simulation(String),
}
