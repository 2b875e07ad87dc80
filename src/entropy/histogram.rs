//! The paper's probabilities estimator: a fixed-width histogram on a given range.

use super::{EntropyError, Probabilities, ProbabilitiesEstimator};
use crate::Real;
use crate::scalar::{epsilon, lit, to_f64};

/// A histogram with bins of fixed width on `[min, max]`: the paper's estimator of the
/// distribution of inter-impact intervals (Sect. 4: the interval `(0.05, 0.3)` with step
/// `0.001`).
///
/// # Bins and edge conventions
/// - The edges are `e_i = min + i·width` for `i = 0 … n−1`, each computed directly (never
///   by accumulating `+= width`), and `e_n = max` exactly.
/// - The number of bins is `n = (max − min)/width` when that ratio is an integer up to
///   rounding (relative to the magnitudes of `min`, `max` and `n`), so `(0.05, 0.3, 0.001)`
///   has exactly 250 bins; otherwise `n = ⌈(max − min)/width⌉` and the **last bin is
///   shorter**, `[e_{n−1}, max]` (its [`HistogramBin::density`] accounts for that).
/// - Bins are half-open, `[e_i, e_{i+1})`, except the last, which is **closed**:
///   `[e_{n−1}, max]`, so a sample equal to `max` is counted. A sample is assigned to the bin
///   whose *computed* edges contain it, so samples exactly on an edge go to the upper bin
///   consistently (no division rounding can move them).
/// - Samples `< min` or `> max` are not counted in any bin; they are tallied as
///   [`RangeTally::below`] / [`RangeTally::above`] and reported, and the probabilities are
///   relative to the samples *inside* the range. NaN or infinite samples are errors.
/// - Empty bins are dropped from the [`Probabilities`] (the paper's "some zeroes should be
///   eliminated") but kept, with count 0, in [`HistogramEstimate::bins`] for plotting.
///
/// # Examples
/// ```
/// use nonsmooth::entropy::Histogram;
///
/// let h = Histogram::new(0.0, 1.0, 0.25)?;
/// assert_eq!(h.bins(), 4);
/// let est = h.estimate(&[0.1, 0.25, 0.3, 1.0, 1.5, -0.2])?;
/// let counts: Vec<u64> = est.bins.iter().map(|b| b.count).collect();
/// assert_eq!(counts, [1, 2, 0, 1]); // 0.25 opens bin 1; 1.0 closes the last bin
/// assert_eq!((est.tally.below, est.tally.above), (1, 1));
/// assert_eq!(est.probabilities.as_slice(), &[0.25, 0.5, 0.25]); // empty bin dropped
/// # Ok::<(), nonsmooth::entropy::EntropyError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Histogram<T> {
    min: T,
    max: T,
    width: T,
    inv_width: T,
    bins: usize,
}

/// How the samples of one histogram fell with respect to its range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RangeTally {
    /// Samples in `[min, max]` (counted in a bin).
    pub in_range: usize,
    /// Samples `< min` (not counted).
    pub below: usize,
    /// Samples `> max` (not counted).
    pub above: usize,
}

impl RangeTally {
    /// All samples seen.
    pub fn total(&self) -> usize {
        self.in_range + self.below + self.above
    }
}

/// One bin of a histogram, for plotting (the paper's Fig. 6a).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HistogramBin<T> {
    /// Lower edge `e_i` (included).
    pub lower: T,
    /// Upper edge `e_{i+1}` (excluded, except for the last bin).
    pub upper: T,
    /// Bin centre `(lower + upper)/2`.
    pub centre: T,
    /// Samples in the bin.
    pub count: u64,
    /// `count / in_range`: the normalized histogram (sums to 1 over the bins).
    pub probability: T,
    /// `probability / (upper − lower)`: the density estimate (integrates to 1).
    pub density: T,
}

/// The result of [`Histogram::estimate`]: the probabilities of the occupied bins and the
/// full histogram for plotting.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct HistogramEstimate<T> {
    /// Probabilities of the occupied bins, in bin order (`N` = number of occupied bins;
    /// [`Probabilities::dropped_zeros`] = number of empty bins).
    pub probabilities: Probabilities<T>,
    /// Every bin, empty ones included, in order.
    pub bins: Vec<HistogramBin<T>>,
    /// Samples inside, below and above the range.
    pub tally: RangeTally,
}

impl<T: Real> HistogramEstimate<T> {
    /// The number of occupied bins `N`.
    pub fn occupied(&self) -> usize {
        self.probabilities.len()
    }
}

impl<T: Real> Histogram<T> {
    /// The largest number of bins accepted: `2^24`, up to which every bin index is exact in
    /// `f32` (and the counts buffer stays below 128 MiB).
    pub const MAX_BINS: usize = 1 << 24;

    /// A histogram on `[min, max]` with bins of width `bin_width` (see the type docs for the
    /// edge conventions).
    ///
    /// # Errors
    /// [`EntropyError::InvalidRange`] unless `min`, `max` are finite with `min < max`;
    /// [`EntropyError::InvalidBinWidth`] unless `bin_width` is finite and `> 0`;
    /// [`EntropyError::UnresolvableBinWidth`] if it gives more than
    /// [`MAX_BINS`](Self::MAX_BINS) bins or is below `8·ε_mach·max(|min|, |max|)`, where
    /// the edges could not be told apart.
    pub fn new(min: T, max: T, bin_width: T) -> Result<Self, EntropyError> {
        if !(min.is_finite() && max.is_finite() && min < max) {
            return Err(EntropyError::InvalidRange {
                min: to_f64(min),
                max: to_f64(max),
            });
        }
        if !(bin_width.is_finite() && bin_width > T::zero()) {
            return Err(EntropyError::InvalidBinWidth {
                width: to_f64(bin_width),
            });
        }
        let eps = epsilon::<T>();
        let scale = min.abs().max(max.abs());
        let ratio = to_f64((max - min) / bin_width);
        let unusable = |bins: f64| EntropyError::UnresolvableBinWidth {
            min: to_f64(min),
            max: to_f64(max),
            width: to_f64(bin_width),
            bins,
            limit: Self::MAX_BINS,
        };
        if bin_width <= lit::<T>(8.0) * eps * scale
            || !ratio.is_finite()
            || ratio > Self::MAX_BINS as f64 + 0.5
        {
            return Err(unusable(ratio));
        }
        // `ratio` carries the rounding of `min`, `max`, their difference and the quotient:
        // accept it as an integer within a few of those rounding errors.
        let eps = to_f64(eps);
        let tolerance = 16.0 * eps * (to_f64(scale) / to_f64(bin_width) + ratio);
        let nearest = ratio.round();
        let bins = if nearest >= 1.0 && (ratio - nearest).abs() <= tolerance {
            nearest
        } else {
            ratio.ceil().max(1.0)
        };
        if bins > Self::MAX_BINS as f64 {
            return Err(unusable(bins));
        }
        Ok(Self {
            min,
            max,
            width: bin_width,
            inv_width: T::one() / bin_width,
            bins: bins as usize,
        })
    }

    /// Lower end of the range.
    pub fn min(&self) -> T {
        self.min
    }

    /// Upper end of the range.
    pub fn max(&self) -> T {
        self.max
    }

    /// The bin width (all bins but possibly the last, see the type docs).
    pub fn bin_width(&self) -> T {
        self.width
    }

    /// The number of bins `n`.
    pub fn bins(&self) -> usize {
        self.bins
    }

    /// Edge `e_i = min + i·width` for `i < n`, and `e_n = max` (`i ≥ n` gives `max`).
    #[inline]
    pub fn edge(&self, i: usize) -> T {
        if i == 0 {
            self.min
        } else if i >= self.bins {
            self.max
        } else {
            self.min + lit::<T>(i as f64) * self.width
        }
    }

    /// The bin holding `x`, or `None` if `x` is outside `[min, max]` or NaN.
    #[inline]
    pub fn bin_of(&self, x: T) -> Option<usize> {
        if !(x >= self.min && x <= self.max) {
            return None;
        }
        // A guess from the reciprocal width (x ≥ min, so truncation is the floor; `as`
        // saturates), then corrected against the computed edges, which define the bins.
        let guess = to_f64((x - self.min) * self.inv_width);
        let i = (guess as usize).min(self.bins - 1);
        // The guess is almost always right: keep the rare walks out of line.
        Some(if x < self.edge(i) {
            self.walk_down(x, i)
        } else if i + 1 < self.bins && x >= self.edge(i + 1) {
            self.walk_up(x, i)
        } else {
            i
        })
    }

    /// The bin of `x` below bin `i`, for `min ≤ x < e_i`.
    #[cold]
    #[inline(never)]
    fn walk_down(&self, x: T, mut i: usize) -> usize {
        while i > 0 && x < self.edge(i) {
            i -= 1;
        }
        i
    }

    /// The bin of `x` above bin `i`, for `e_{i+1} ≤ x ≤ max`.
    #[cold]
    #[inline(never)]
    fn walk_up(&self, x: T, mut i: usize) -> usize {
        while i + 1 < self.bins && x >= self.edge(i + 1) {
            i += 1;
        }
        i
    }

    /// Counts `samples` into `counts` (overwritten; its length must be [`bins`](Self::bins))
    /// without allocating, and returns how many fell inside, below and above the range.
    ///
    /// # Errors
    /// [`EntropyError::CountsLength`] if `counts.len() != bins()`,
    /// [`EntropyError::EmptySample`] for an empty sample,
    /// [`EntropyError::NonFiniteSample`] at the first NaN/∞ sample (the contents of `counts`
    /// are then unspecified).
    pub fn counts_into(
        &self,
        samples: &[T],
        counts: &mut [u64],
    ) -> Result<RangeTally, EntropyError> {
        if counts.len() != self.bins {
            return Err(EntropyError::CountsLength {
                expected: self.bins,
                got: counts.len(),
            });
        }
        if samples.is_empty() {
            return Err(EntropyError::EmptySample);
        }
        counts.fill(0);
        let mut tally = RangeTally::default();
        for (index, &x) in samples.iter().enumerate() {
            if !x.is_finite() {
                return Err(EntropyError::NonFiniteSample {
                    index,
                    value: to_f64(x),
                });
            }
            match self.bin_of(x) {
                Some(i) => {
                    counts[i] += 1;
                    tally.in_range += 1;
                }
                None if x < self.min => tally.below += 1,
                None => tally.above += 1,
            }
        }
        Ok(tally)
    }

    /// The counts of `samples` in every bin and the tally; errors if nothing is in range.
    fn counts(&self, samples: &[T]) -> Result<(Vec<u64>, RangeTally), EntropyError> {
        let mut counts = vec![0; self.bins];
        let tally = self.counts_into(samples, &mut counts)?;
        if tally.in_range == 0 {
            return Err(EntropyError::AllOutsideRange {
                total: tally.total(),
                below: tally.below,
                above: tally.above,
                min: to_f64(self.min),
                max: to_f64(self.max),
            });
        }
        Ok((counts, tally))
    }

    /// The normalized histogram of `samples`: the probabilities of the occupied bins (empty
    /// bins dropped), every bin with its count, probability and density, and the range tally.
    ///
    /// # Errors
    /// [`EntropyError::EmptySample`], [`EntropyError::NonFiniteSample`], and
    /// [`EntropyError::AllOutsideRange`] if no sample lies in `[min, max]`.
    pub fn estimate(&self, samples: &[T]) -> Result<HistogramEstimate<T>, EntropyError> {
        let (counts, tally) = self.counts(samples)?;
        let inside = tally.in_range as f64;
        let bins = counts
            .iter()
            .enumerate()
            .map(|(i, &count)| {
                let lower = self.edge(i);
                let upper = self.edge(i + 1);
                let probability = lit::<T>(count as f64 / inside);
                HistogramBin {
                    lower,
                    upper,
                    centre: (lower + upper) * lit(0.5),
                    count,
                    probability,
                    density: probability / (upper - lower),
                }
            })
            .collect();
        Ok(HistogramEstimate {
            probabilities: Probabilities::from_counts(&counts)?,
            bins,
            tally,
        })
    }
}

impl<T: Real> ProbabilitiesEstimator<T> for Histogram<T> {
    /// The probabilities of the occupied bins (see [`Histogram::estimate`]).
    fn probabilities(&self, samples: &[T]) -> Result<Probabilities<T>, EntropyError> {
        let (counts, _) = self.counts(samples)?;
        Probabilities::from_counts(&counts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_grid_has_250_bins() {
        let h = Histogram::new(0.05_f64, 0.3, 0.001).unwrap();
        assert_eq!(h.bins(), 250);
        assert_eq!(h.edge(250), 0.3);
        let h = Histogram::new(0.05_f32, 0.3, 0.001).unwrap();
        assert_eq!(h.bins(), 250);
        // Offsets far from zero still give the integer count.
        let h = Histogram::new(100.0_f64, 100.3, 0.001).unwrap();
        assert_eq!(h.bins(), 300);
    }

    #[test]
    fn partial_last_bin() {
        let h = Histogram::new(0.0_f64, 1.0, 0.3).unwrap();
        assert_eq!(h.bins(), 4);
        assert_eq!(h.edge(3), 0.8999999999999999); // 3·0.3 in f64, computed directly
        assert_eq!(h.edge(4), 1.0);
        assert_eq!(h.bin_of(0.95), Some(3));
        assert_eq!(h.bin_of(1.0), Some(3));
        let est = h.estimate(&[0.95]).unwrap();
        let last = est.bins[3];
        assert!((last.density - 1.0 / (1.0 - 0.8999999999999999)).abs() < 1e-9);
        // Width larger than the range: one bin.
        assert_eq!(Histogram::new(0.0_f64, 1.0, 5.0).unwrap().bins(), 1);
    }

    #[test]
    fn edges_are_consistent_with_bins() {
        let h = Histogram::new(0.05_f64, 0.3, 0.001).unwrap();
        for i in 0..h.bins() {
            let e = h.edge(i);
            assert_eq!(h.bin_of(e), Some(i), "edge {i} = {e}");
            let below = e - e.abs() * f64::EPSILON;
            if i > 0 && below < e {
                assert_eq!(h.bin_of(below), Some(i - 1));
            }
        }
        assert_eq!(h.bin_of(0.3), Some(249));
        assert_eq!(h.bin_of(0.30000000000000004), None);
        assert_eq!(h.bin_of(0.049999999999999996), None);
        assert_eq!(h.bin_of(f64::NAN), None);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(matches!(
            Histogram::new(1.0, 1.0, 0.1),
            Err(EntropyError::InvalidRange { .. })
        ));
        assert!(matches!(
            Histogram::new(2.0, 1.0, 0.1),
            Err(EntropyError::InvalidRange { .. })
        ));
        assert!(matches!(
            Histogram::new(f64::NEG_INFINITY, 1.0, 0.1),
            Err(EntropyError::InvalidRange { .. })
        ));
        assert!(matches!(
            Histogram::new(0.0, 1.0, 0.0),
            Err(EntropyError::InvalidBinWidth { .. })
        ));
        assert!(matches!(
            Histogram::new(0.0, 1.0, -0.1),
            Err(EntropyError::InvalidBinWidth { .. })
        ));
        assert!(matches!(
            Histogram::new(0.0, 1.0, f64::NAN),
            Err(EntropyError::InvalidBinWidth { .. })
        ));
        assert!(matches!(
            Histogram::new(0.0, 1.0, 1e-9),
            Err(EntropyError::UnresolvableBinWidth { .. })
        ));
        assert!(matches!(
            Histogram::new(1e9, 1e9 + 1.0, 1e-9),
            Err(EntropyError::UnresolvableBinWidth { .. })
        ));
        assert!(matches!(
            Histogram::new(-1e308, 1e308, 1.0),
            Err(EntropyError::UnresolvableBinWidth { .. })
        ));
    }

    #[test]
    fn counts_into_checks_buffer() {
        let h = Histogram::new(0.0_f64, 1.0, 0.5).unwrap();
        let mut c = [9u64; 3];
        assert_eq!(
            h.counts_into(&[0.1], &mut c),
            Err(EntropyError::CountsLength {
                expected: 2,
                got: 3
            })
        );
        let mut c = [9u64; 2];
        let t = h.counts_into(&[0.1, 0.6, 0.7, 2.0], &mut c).unwrap();
        assert_eq!(c, [1, 2]);
        assert_eq!(
            t,
            RangeTally {
                in_range: 3,
                below: 0,
                above: 1
            }
        );
    }
}
