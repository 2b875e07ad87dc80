//! Tsallis and Shannon entropy, redundancy, and the entropy index `q` of a sample.
//!
//! A chaotic regime of an impact oscillator can be characterized by the distribution of its
//! inter-impact intervals `T_j`: the sample is arranged in a normalized histogram, empty bins
//! are dropped, and the resulting probabilities `p_i`, `i = 1…N`, are described by the
//! Tsallis entropy with the index `q` that maximizes the redundancy (the paper's values are
//! in [`systems::paper`](crate::systems::paper), "Results").
//!
//! As in DynamicalSystems.jl / ComplexityMeasures.jl, the *definition* of an entropy is kept
//! apart from how the probabilities are *estimated*:
//!
//! | step | type / function |
//! |---|---|
//! | estimate probabilities from a sample | [`ProbabilitiesEstimator`], [`Histogram`] → [`HistogramEstimate`] |
//! | validated distribution (no zeros, sums to 1) | [`Probabilities`] |
//! | entropies of a distribution | [`tsallis`], [`tsallis_max`], [`shannon`], [`redundancy`] |
//! | entropy index `q*` and the curve `R(q)` | [`entropy_index`] with [`QRange`] → [`EntropyIndex`]; [`redundancy_curve`] |
//!
//! # Formulas
//! Tsallis entropy (Boltzmann's constant `k = 1`) of `N` probabilities `p_i > 0`,
//! `Σ p_i = 1`:
//! $$ S_q = \frac{1}{q-1}\Bigl(1 - \sum_{i=1}^{N} p_i^{\,q}\Bigr), \qquad
//!    \lim_{q\to 1} S_q = S_1 = -\sum_{i=1}^{N} p_i \ln p_i \quad\text{(Shannon)}. $$
//! For `q > 0` it is largest for equiprobable states `p_i = 1/N`:
//! $$ S_{q,\max} = \frac{1 - N^{\,1-q}}{q-1}, \qquad \lim_{q\to1} S_{q,\max} = \ln N. $$
//! The redundancy measures how far the distribution is from equiprobability,
//! $$ R(q) = 1 - \frac{S_q}{S_{q,\max}} \in [0, 1] \quad (q > 0,\ N \ge 2), $$
//! and the entropy index is its maximizer (the maximum entropy principle applied to the
//! choice of `q`):
//! $$ q^* = \arg\max_{q} R(q). $$
//!
//! ## Numerics near `q = 1`
//! The textbook forms lose all digits as `q → 1` (`0/0`). With `δ = q − 1` and
//! `Σ p_i = 1` they are rewritten exactly as
//! $$ S_q = -\sum_i p_i\,\frac{\operatorname{expm1}(\delta\ln p_i)}{\delta}, \qquad
//!    S_{q,\max} = -\frac{\operatorname{expm1}(-\delta\ln N)}{\delta}, $$
//! which keep full relative precision for every `δ ≠ 0` (`expm1(x)/δ → ln p` smoothly) and
//! are replaced by the Shannon limits at `δ = 0` exactly. The logarithms `ln p_i` are
//! computed once, when the [`Probabilities`] are built, so one evaluation of `R(q)` costs `N`
//! calls of `expm1` and allocates nothing.
//!
//! ## Shape of `R(q)` and the default `q` range
//! For `N ≥ 2`, `R(0) = 0` exactly (every `p_i^0 = 1`), `0 ≤ R(q) ≤ 1` for `q > 0`, and
//! `R(q) → 0` as `q → ∞`, so the maximum is attained at a finite positive `q`. For `q < 0`,
//! `R ≤ 0`: the maximum-entropy reading needs `q > 0`. Over two-state, near-uniform,
//! dominant-state, geometric and Zipf distributions with up to `10⁴` states and probability
//! ratios up to `10⁶` (a histogram of `10⁶` samples), `q*` stays within about `[0.15, 2.48]`;
//! two states give the largest values (`q* → 2.47` near equiprobability) and long geometric
//! tails the smallest. The default range [`QRange::default`] is therefore `[0.05, 5]`,
//! with a margin on both sides; a maximum at either end is reported in
//! [`EntropyIndex::at_bound`] so that the range can be widened.
//!
//! ## Interpretation
//! `q* < 1` means that rare events weigh in the distribution (many improbable states affect
//! the behaviour); `q* > 1` means the frequent events dominate; `q*` growing towards 1 at
//! the edge of a chaotic window marks an attractor that becomes almost periodic. A strictly
//! periodic regime fills a single bin (`N = 1`), for which `R` — and so `q*` — is undefined
//! ([`EntropyError::SingleState`]); equiprobable occupied bins (a periodic orbit sampled
//! over whole periods) give `R ≡ 0` and no index either ([`EntropyError::Equiprobable`]).
//!
//! Read `q*` together with `N` and `R(q*)`. Near equiprobability, `p_i = (1 + ε_i)/N`,
//! $$ R(q) \approx \frac{\overline{\varepsilon^2}}{2}\,\frac{q\,(q-1)}{N^{\,q-1} - 1}, $$
//! so `q*` tends to a value that depends on `N` only (1.633 for `N = 3`, 0.902 for 10,
//! 0.608 for 100, 0.569 for 250) while `R(q*)` tends to 0: a tiny `R(q*)` flags an index
//! that describes the number of occupied bins rather than the shape of the distribution
//! (e.g. a periodic orbit sampled over a fractional number of periods).
//!
//! # Example
//! ```
//! use nonsmooth::entropy::{Histogram, QRange, entropy_index};
//!
//! // A deterministic "interval" sequence from the logistic map, mapped into (0.08, 0.28).
//! let mut x = 0.3_f64;
//! let intervals: Vec<f64> = (0..20_000)
//!     .map(|_| {
//!         x = 3.9 * x * (1.0 - x);
//!         0.08 + 0.2 * x
//!     })
//!     .collect();
//!
//! // Bins of 0.001 on [0.05, 0.3], empty bins dropped.
//! let hist = Histogram::new(0.05, 0.3, 0.001)?.estimate(&intervals)?;
//! assert_eq!(hist.tally.below + hist.tally.above, 0);
//! let index = entropy_index(&hist.probabilities, &QRange::default())?;
//! assert!(index.q > 0.05 && index.q < 5.0 && index.at_bound.is_none());
//! # Ok::<(), nonsmooth::entropy::EntropyError>(())
//! ```
//!
//! # References
//! - C. Tsallis, *Possible generalization of Boltzmann–Gibbs statistics*, J. Stat. Phys. 52
//!   (1988) 479–487 (the entropy `S_q`).
//! - E. T. Jaynes, *Information theory and statistical mechanics*, Phys. Rev. 106 (1957)
//!   620–630 (the maximum entropy principle).

mod histogram;
mod index;
mod probabilities;
mod tsallis;

pub use histogram::{Histogram, HistogramBin, HistogramEstimate, RangeTally};
pub use index::{EntropyIndex, QRange, RangeEnd, RedundancyPoint, entropy_index, redundancy_curve};
pub use probabilities::{Probabilities, ProbabilitiesEstimator};
pub use tsallis::{redundancy, shannon, tsallis, tsallis_max};

/// Errors of this module.
///
/// Diagnostics are stored as `f64` whatever the scalar type of the computation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EntropyError {
    /// The sample has no elements.
    #[error("empty sample: at least one value is needed to estimate probabilities")]
    EmptySample,
    /// A sample value is NaN or infinite.
    #[error("sample value #{index} is not finite ({value})")]
    NonFiniteSample {
        /// Position in the sample.
        index: usize,
        /// The value (as `f64`).
        value: f64,
    },
    /// The histogram range is not finite or not increasing.
    #[error("invalid histogram range [{min}, {max}]: both ends must be finite with min < max")]
    InvalidRange {
        /// Lower end.
        min: f64,
        /// Upper end.
        max: f64,
    },
    /// The bin width is not finite and positive.
    #[error("invalid bin width {width}: must be finite and > 0")]
    InvalidBinWidth {
        /// The rejected width.
        width: f64,
    },
    /// The bin width is too small to be resolved at the magnitude of the range ends (bin
    /// edges `min + i·width` would not be strictly increasing), or gives too many bins.
    #[error(
        "bin width {width} on [{min}, {max}] is unusable: it gives {bins} bins (limit {limit}) \
         or is below the floating-point resolution at this magnitude; use a wider bin"
    )]
    UnresolvableBinWidth {
        /// Lower end.
        min: f64,
        /// Upper end.
        max: f64,
        /// The rejected width.
        width: f64,
        /// The number of bins it would give (saturated).
        bins: f64,
        /// The largest number of bins accepted.
        limit: usize,
    },
    /// Every sample fell outside the histogram range.
    #[error(
        "all {total} samples lie outside the histogram range [{min}, {max}] \
         ({below} below, {above} above)"
    )]
    AllOutsideRange {
        /// Samples in the sample.
        total: usize,
        /// Samples `< min`.
        below: usize,
        /// Samples `> max`.
        above: usize,
        /// Lower end of the range.
        min: f64,
        /// Upper end of the range.
        max: f64,
    },
    /// A buffer passed to [`Histogram::counts_into`] has the wrong length.
    #[error("counts buffer has length {got}, the histogram has {expected} bins")]
    CountsLength {
        /// Number of bins.
        expected: usize,
        /// Length of the buffer.
        got: usize,
    },
    /// A probability (or weight) is negative, NaN or infinite.
    #[error("probability #{index} = {value} is invalid: must be finite and >= 0")]
    InvalidProbability {
        /// Position.
        index: usize,
        /// The value (as `f64`).
        value: f64,
    },
    /// A probability is exactly zero where zeros are not accepted.
    #[error(
        "probability #{index} is zero; zero-probability states must be dropped explicitly \
         (use Probabilities::new_dropping_zeros)"
    )]
    ZeroProbability {
        /// Position.
        index: usize,
    },
    /// The probabilities do not sum to 1 within the tolerance.
    #[error("probabilities sum to {sum}, not 1 (tolerance {tolerance})")]
    NotNormalized {
        /// Their sum.
        sum: f64,
        /// The accepted deviation from 1.
        tolerance: f64,
    },
    /// No state with positive probability is left (empty input, or all zeros).
    #[error("no state with positive probability: the distribution is empty")]
    EmptyDistribution,
    /// Only one state is occupied (`N = 1`): `S_q = S_q,max = 0` for every `q`, so the
    /// redundancy `R = 1 − S_q/S_q,max` and the entropy index are undefined.
    #[error(
        "a single occupied state (N = 1): S_q = S_q,max = 0, so the redundancy R(q) and the \
         entropy index are undefined (a periodic sequence fills one bin; use narrower bins)"
    )]
    SingleState,
    /// All occupied states are equally probable: `R(q) ≡ 0`, so no `q` maximizes it.
    #[error(
        "the {states} occupied states are equiprobable: R(q) = 0 for every q and the entropy \
         index is undefined"
    )]
    Equiprobable {
        /// Number of states `N`.
        states: usize,
    },
    /// An entropy index `q` is NaN or infinite.
    #[error("entropy index q = {q} is not finite")]
    InvalidQ {
        /// The rejected value.
        q: f64,
    },
    /// The exact value is finite but beyond the floating-point range (for `q` far below 1
    /// the terms `p_i^q` grow like `p_min^q`: e.g. `R(q)` at `q = −10³⁰⁰`).
    #[error("{quantity} at q = {q} is beyond the floating-point range")]
    NotRepresentable {
        /// Which quantity overflowed.
        quantity: &'static str,
        /// The `q` asked for.
        q: f64,
    },
    /// A `q` range is not finite, not increasing, or (for the maximization) not positive.
    #[error("invalid q range [{lo}, {hi}]: {requirement}")]
    InvalidQRange {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
        /// What the range must satisfy.
        requirement: &'static str,
    },
    /// Too few points for a scan or a curve.
    #[error("{points} grid points requested, at least {minimum} are needed")]
    TooFewPoints {
        /// Requested number.
        points: usize,
        /// Minimum accepted.
        minimum: usize,
    },
    /// The maximizer's tolerance is not finite and positive.
    #[error("invalid q tolerance {tolerance}: must be finite and > 0")]
    InvalidTolerance {
        /// The rejected tolerance.
        tolerance: f64,
    },
    /// `R(q)` evaluated to NaN or infinity (overflow for extreme `q`).
    #[error("the redundancy is not finite at q = {q}; narrow the q range")]
    NonFiniteRedundancy {
        /// Where.
        q: f64,
    },
}
