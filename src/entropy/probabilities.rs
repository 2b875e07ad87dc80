//! A validated discrete distribution and the estimator trait that produces one.

use super::EntropyError;
use crate::Real;
use crate::scalar::{epsilon, lit, to_f64};

/// A discrete probability distribution `p_1 … p_N` with every `p_i > 0` and `Σ p_i = 1`.
///
/// Zero-probability states carry no information for the entropies of this module (and
/// `ln 0` would poison them), so a `Probabilities` never holds a zero: constructors either
/// reject zeros ([`new`](Self::new)) or drop them and say how many
/// ([`new_dropping_zeros`](Self::new_dropping_zeros), [`from_weights`](Self::from_weights),
/// [`from_counts`](Self::from_counts), [`dropped_zeros`](Self::dropped_zeros)). This is the
/// paper's "some zeroes in the frequencies sequence should be eliminated".
///
/// After validation the values are renormalized by their sum, so `Σ p_i = 1` to rounding, and
/// `ln p_i` is computed once and stored: every entropy evaluation then costs one `expm1` per
/// state and allocates nothing.
///
/// # Examples
/// ```
/// use nonsmooth::entropy::{Probabilities, shannon};
///
/// let p = Probabilities::<f64>::from_counts(&[3, 0, 1])?; // the empty bin is dropped
/// assert_eq!(p.as_slice(), &[0.75, 0.25]);
/// assert_eq!(p.dropped_zeros(), 1);
/// assert!((shannon(&p) - (-(0.75f64 * 0.75f64.ln() + 0.25 * 0.25f64.ln()))).abs() < 1e-15);
/// # Ok::<(), nonsmooth::entropy::EntropyError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Probabilities<T> {
    p: Vec<T>,
    #[cfg_attr(feature = "serde", serde(skip))]
    ln_p: Vec<T>,
    dropped_zeros: usize,
}

impl<T: Real> Probabilities<T> {
    /// The tolerance on `|Σ p_i − 1|` accepted by [`new`](Self::new) and
    /// [`new_dropping_zeros`](Self::new_dropping_zeros): `√ε_mach` (`1.5e-8` for `f64`,
    /// `3.5e-4` for `f32`).
    pub fn sum_tolerance() -> T {
        epsilon::<T>().sqrt()
    }

    /// Validates a probability vector in which zeros are *not* allowed.
    ///
    /// # Errors
    /// [`EntropyError::EmptyDistribution`] for an empty vector,
    /// [`EntropyError::InvalidProbability`] for a negative or non-finite value,
    /// [`EntropyError::ZeroProbability`] for a zero, [`EntropyError::NotNormalized`] if
    /// `|Σ p_i − 1| > ` [`sum_tolerance`](Self::sum_tolerance).
    pub fn new(p: Vec<T>) -> Result<Self, EntropyError> {
        Self::validated(p, false)
    }

    /// Validates a probability vector and drops its zeros (counted in
    /// [`dropped_zeros`](Self::dropped_zeros)).
    ///
    /// # Errors
    /// As [`new`](Self::new), except that zeros are dropped instead of rejected;
    /// [`EntropyError::EmptyDistribution`] if nothing positive is left.
    pub fn new_dropping_zeros(p: Vec<T>) -> Result<Self, EntropyError> {
        Self::validated(p, true)
    }

    /// Normalizes non-negative weights (e.g. a density or counts as reals) into
    /// probabilities, dropping the zero weights.
    ///
    /// # Errors
    /// [`EntropyError::InvalidProbability`] for a negative or non-finite weight,
    /// [`EntropyError::EmptyDistribution`] if no weight is positive.
    pub fn from_weights(weights: &[T]) -> Result<Self, EntropyError> {
        let mut largest = T::zero();
        for (index, &w) in weights.iter().enumerate() {
            if !w.is_finite() || w < T::zero() {
                return Err(EntropyError::InvalidProbability {
                    index,
                    value: to_f64(w),
                });
            }
            largest = largest.max(w);
        }
        if largest == T::zero() {
            return Err(EntropyError::EmptyDistribution);
        }
        // Scale by the largest weight first so that the sum cannot overflow.
        let p: Vec<T> = weights.iter().map(|&w| w / largest).collect();
        Ok(Self::normalized(p))
    }

    /// Turns occupation counts (e.g. histogram bins) into probabilities `c_i / Σ c`,
    /// dropping the empty states.
    ///
    /// # Errors
    /// [`EntropyError::EmptyDistribution`] if every count is zero (or there are none).
    pub fn from_counts(counts: &[u64]) -> Result<Self, EntropyError> {
        let total: u128 = counts.iter().map(|&c| u128::from(c)).sum();
        if total == 0 {
            return Err(EntropyError::EmptyDistribution);
        }
        let total = total as f64;
        let occupied = counts.iter().filter(|&&c| c > 0).count();
        let mut p = Vec::with_capacity(occupied);
        let mut ln_p = Vec::with_capacity(occupied);
        for &c in counts.iter().filter(|&&c| c > 0) {
            // The quotient is formed in f64 (exact counts up to 2^53) and rounded once to T.
            let pi = c as f64 / total;
            p.push(lit::<T>(pi));
            ln_p.push(lit::<T>(pi.ln()));
        }
        Ok(Self {
            p,
            ln_p,
            dropped_zeros: counts.len() - occupied,
        })
    }

    fn validated(p: Vec<T>, drop_zeros: bool) -> Result<Self, EntropyError> {
        if p.is_empty() {
            return Err(EntropyError::EmptyDistribution);
        }
        let mut sum = T::zero();
        let mut zeros = 0;
        for (index, &pi) in p.iter().enumerate() {
            if !pi.is_finite() || pi < T::zero() {
                return Err(EntropyError::InvalidProbability {
                    index,
                    value: to_f64(pi),
                });
            }
            if pi == T::zero() {
                if !drop_zeros {
                    return Err(EntropyError::ZeroProbability { index });
                }
                zeros += 1;
            }
            sum += pi;
        }
        if zeros == p.len() {
            return Err(EntropyError::EmptyDistribution);
        }
        let tolerance = Self::sum_tolerance();
        if (sum - T::one()).abs() > tolerance {
            return Err(EntropyError::NotNormalized {
                sum: to_f64(sum),
                tolerance: to_f64(tolerance),
            });
        }
        Ok(Self::normalized(p))
    }

    /// Drops zeros, divides by the sum and caches the logarithms. `p` is finite, `≥ 0`, with
    /// at least one positive entry and no overflow in its sum; every entry removed (zero, or
    /// underflowed to zero by the division) is counted as dropped.
    fn normalized(mut p: Vec<T>) -> Self {
        let n_before = p.len();
        p.retain(|&pi| pi > T::zero());
        let sum = p.iter().fold(T::zero(), |s, &pi| s + pi);
        for pi in p.iter_mut() {
            *pi /= sum;
        }
        // Division by a sum ≥ the largest entry cannot overflow, but may underflow a tiny
        // entry to zero: drop those too.
        p.retain(|&pi| pi > T::zero());
        let dropped_zeros = n_before - p.len();
        let ln_p = p.iter().map(|&pi| pi.ln()).collect();
        Self {
            p,
            ln_p,
            dropped_zeros,
        }
    }

    /// The probabilities `p_i` (all `> 0`).
    pub fn as_slice(&self) -> &[T] {
        &self.p
    }

    /// The cached natural logarithms `ln p_i` (all finite, `≤ 0`).
    pub fn ln_probabilities(&self) -> &[T] {
        &self.ln_p
    }

    /// The number of states `N` (all with positive probability).
    pub fn len(&self) -> usize {
        self.p.len()
    }

    /// Always `false`: a `Probabilities` holds at least one state.
    pub fn is_empty(&self) -> bool {
        self.p.is_empty()
    }

    /// How many zero-probability states (or empty bins) were dropped on construction.
    pub fn dropped_zeros(&self) -> usize {
        self.dropped_zeros
    }

    /// Iterates over the probabilities.
    pub fn iter(&self) -> std::slice::Iter<'_, T> {
        self.p.iter()
    }

    /// `true` if all states are equally probable to within a few rounding errors
    /// (`max p − min p ≤ 4·ε_mach·max p`), i.e. `R(q) ≡ 0`.
    pub fn is_equiprobable(&self) -> bool {
        let (lo, hi) = self.p.iter().fold((T::one(), T::zero()), |(lo, hi), &pi| {
            (lo.min(pi), hi.max(pi))
        });
        hi - lo <= lit::<T>(4.0) * epsilon::<T>() * hi
    }
}

impl<'a, T> IntoIterator for &'a Probabilities<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.p.iter()
    }
}

/// Estimates a [`Probabilities`] from a sample of real values (the "probabilities
/// estimator" of DynamicalSystems.jl): the entropy definitions of this module do not know
/// how the distribution was obtained.
///
/// [`Histogram`](super::Histogram) is the paper's estimator.
///
/// # Implementing an estimator
/// ```
/// use nonsmooth::entropy::{EntropyError, Probabilities, ProbabilitiesEstimator, shannon};
///
/// /// Each distinct value is a state (for samples that are already discrete).
/// struct DistinctValues;
///
/// impl ProbabilitiesEstimator<f64> for DistinctValues {
///     fn probabilities(&self, samples: &[f64]) -> Result<Probabilities<f64>, EntropyError> {
///         if samples.is_empty() {
///             return Err(EntropyError::EmptySample);
///         }
///         let mut sorted = samples.to_vec();
///         sorted.sort_by(f64::total_cmp);
///         let mut counts = vec![1u64];
///         for w in sorted.windows(2) {
///             if w[0] == w[1] { *counts.last_mut().unwrap() += 1 } else { counts.push(1) }
///         }
///         Probabilities::from_counts(&counts)
///     }
/// }
///
/// let p = DistinctValues.probabilities(&[1.0, 2.0, 1.0, 2.0])?;
/// assert!((shannon(&p) - 2f64.ln()).abs() < 1e-15);
/// # Ok::<(), EntropyError>(())
/// ```
pub trait ProbabilitiesEstimator<T: Real> {
    /// The distribution of `samples`.
    ///
    /// # Errors
    /// Implementation-specific; typically [`EntropyError::EmptySample`] and
    /// [`EntropyError::NonFiniteSample`].
    fn probabilities(&self, samples: &[T]) -> Result<Probabilities<T>, EntropyError>;
}

impl<T: Real, E: ProbabilitiesEstimator<T> + ?Sized> ProbabilitiesEstimator<T> for &E {
    fn probabilities(&self, samples: &[T]) -> Result<Probabilities<T>, EntropyError> {
        (**self).probabilities(samples)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_validates() {
        assert!(Probabilities::new(vec![0.5, 0.5]).is_ok());
        assert_eq!(
            Probabilities::<f64>::new(vec![]),
            Err(EntropyError::EmptyDistribution)
        );
        assert_eq!(
            Probabilities::new(vec![0.5, 0.0, 0.5]),
            Err(EntropyError::ZeroProbability { index: 1 })
        );
        assert!(matches!(
            Probabilities::new(vec![0.5, -0.1, 0.6]),
            Err(EntropyError::InvalidProbability { index: 1, .. })
        ));
        assert!(matches!(
            Probabilities::new(vec![0.5, f64::NAN]),
            Err(EntropyError::InvalidProbability { index: 1, .. })
        ));
        assert!(matches!(
            Probabilities::new(vec![0.5, 0.6]),
            Err(EntropyError::NotNormalized { .. })
        ));
        let p = Probabilities::new_dropping_zeros(vec![0.0, 0.25, 0.0, 0.75]).unwrap();
        assert_eq!(p.as_slice(), &[0.25, 0.75]);
        assert_eq!(p.dropped_zeros(), 2);
        assert_eq!(
            Probabilities::new_dropping_zeros(vec![0.0_f64, 0.0]),
            Err(EntropyError::EmptyDistribution)
        );
    }

    #[test]
    fn renormalizes_within_tolerance() {
        let p = Probabilities::new(vec![0.5, 0.5 + 1e-10]).unwrap();
        let s: f64 = p.iter().sum();
        assert!((s - 1.0).abs() <= 2.0 * f64::EPSILON);
        assert_eq!(p.ln_probabilities()[0], p.as_slice()[0].ln());
    }

    #[test]
    fn weights_and_counts() {
        let p = Probabilities::from_weights(&[2.0_f32, 0.0, 6.0]).unwrap();
        assert_eq!(p.as_slice(), &[0.25, 0.75]);
        assert_eq!(p.dropped_zeros(), 1);
        // No overflow in the sum of huge weights; underflowed tiny ones are dropped.
        let p = Probabilities::from_weights(&[1e308, 1e308, 1e-320]).unwrap();
        assert_eq!(p.as_slice(), &[0.5, 0.5]);
        assert_eq!(p.dropped_zeros(), 1);
        assert_eq!(
            Probabilities::<f64>::from_weights(&[0.0, 0.0]),
            Err(EntropyError::EmptyDistribution)
        );
        assert!(matches!(
            Probabilities::from_weights(&[1.0, f64::INFINITY]),
            Err(EntropyError::InvalidProbability { index: 1, .. })
        ));
        let p = Probabilities::<f64>::from_counts(&[0, 1, 0, 3, 0]).unwrap();
        assert_eq!(p.as_slice(), &[0.25, 0.75]);
        assert_eq!(p.dropped_zeros(), 3);
        assert_eq!(
            Probabilities::<f64>::from_counts(&[0, 0]),
            Err(EntropyError::EmptyDistribution)
        );
        assert_eq!(
            Probabilities::<f64>::from_counts(&[]),
            Err(EntropyError::EmptyDistribution)
        );
    }

    #[test]
    fn equiprobability() {
        assert!(
            Probabilities::<f64>::from_counts(&[7, 7, 0, 7])
                .unwrap()
                .is_equiprobable()
        );
        assert!(
            !Probabilities::<f64>::from_counts(&[7, 8])
                .unwrap()
                .is_equiprobable()
        );
        assert!(
            Probabilities::<f64>::from_counts(&[1])
                .unwrap()
                .is_equiprobable()
        );
    }
}
