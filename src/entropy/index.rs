//! The entropy index `q* = argmax_q R(q)` and the redundancy curve `R(q)`.

use super::tsallis::{ln_states, redundancy_unchecked};
use super::{EntropyError, Probabilities};
use crate::Real;
use crate::scalar::{epsilon, lit, to_f64};

/// An end of a [`QRange`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum RangeEnd {
    /// The lower end `lo`.
    Lower,
    /// The upper end `hi`.
    Upper,
}

/// The interval `[lo, hi]` (`0 < lo < hi`) searched for the entropy index, with the scan
/// resolution and the tolerance of the refinement.
///
/// The maximizer first evaluates `R` on `scan_points` equally spaced values
/// `q_k = lo + k·(hi − lo)/(scan_points − 1)` (each computed directly, the last equal to `hi`),
/// takes the best one — so a redundancy with several local maxima is handled, as long as the
/// global peak is wider than the scan step — and refines it by golden-section search on
/// `[q_{k−1}, q_{k+1}]` until that bracket is narrower than `tolerance`.
///
/// The default `[0.05, 5]`, 100 points (step 0.05), tolerance `√ε_mach` is justified in the
/// [module docs](super#shape-of-rq-and-the-default-q-range).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct QRange<T> {
    lo: T,
    hi: T,
    scan_points: usize,
    tolerance: T,
}

impl<T: Real> Default for QRange<T> {
    /// `[0.05, 5]`, [`DEFAULT_SCAN_POINTS`](Self::DEFAULT_SCAN_POINTS) scan points, tolerance
    /// `√ε_mach` (`1.5e-8` for `f64`, `3.5e-4` for `f32`).
    fn default() -> Self {
        Self {
            lo: lit(0.05),
            hi: lit(5.0),
            scan_points: Self::DEFAULT_SCAN_POINTS,
            tolerance: epsilon::<T>().sqrt(),
        }
    }
}

impl<T: Real> QRange<T> {
    /// The default number of scan points: 100 (a step of 0.05 on `[0.05, 5]`, much narrower
    /// than the width of the peak of `R` for the distributions studied in the module docs).
    pub const DEFAULT_SCAN_POINTS: usize = 100;

    /// The range `[lo, hi]` with the default scan and tolerance.
    ///
    /// # Errors
    /// [`EntropyError::InvalidQRange`] unless `0 < lo < hi` and both are finite (the
    /// maximum-entropy reading of `R` needs `q > 0`; for `q ≤ 0`, `R ≤ 0`).
    pub fn new(lo: T, hi: T) -> Result<Self, EntropyError> {
        if !(lo.is_finite() && hi.is_finite() && T::zero() < lo && lo < hi) {
            return Err(EntropyError::InvalidQRange {
                lo: to_f64(lo),
                hi: to_f64(hi),
                requirement: "need finite 0 < lo < hi",
            });
        }
        Ok(Self {
            lo,
            hi,
            ..Self::default()
        })
    }

    /// Sets the number of scan points.
    ///
    /// # Errors
    /// [`EntropyError::TooFewPoints`] if `points < 3`.
    pub fn with_scan_points(mut self, points: usize) -> Result<Self, EntropyError> {
        if points < 3 {
            return Err(EntropyError::TooFewPoints { points, minimum: 3 });
        }
        self.scan_points = points;
        Ok(self)
    }

    /// Sets the absolute tolerance on `q*`.
    ///
    /// Tolerances below about `√ε_mach·|q*|` cannot be met meaningfully (`R` is flat to
    /// second order at its maximum); the refinement then stops at the rounding limit.
    ///
    /// # Errors
    /// [`EntropyError::InvalidTolerance`] unless `tolerance` is finite and `> 0`.
    pub fn with_tolerance(mut self, tolerance: T) -> Result<Self, EntropyError> {
        if !(tolerance.is_finite() && tolerance > T::zero()) {
            return Err(EntropyError::InvalidTolerance {
                tolerance: to_f64(tolerance),
            });
        }
        self.tolerance = tolerance;
        Ok(self)
    }

    /// Lower end.
    pub fn lo(&self) -> T {
        self.lo
    }

    /// Upper end.
    pub fn hi(&self) -> T {
        self.hi
    }

    /// Number of scan points.
    pub fn scan_points(&self) -> usize {
        self.scan_points
    }

    /// Absolute tolerance on `q*`.
    pub fn tolerance(&self) -> T {
        self.tolerance
    }
}

/// The entropy index of a distribution: the maximizer of the redundancy `R(q)` on a
/// [`QRange`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EntropyIndex<T> {
    /// The entropy index `q*`.
    pub q: T,
    /// The maximal redundancy `R(q*)`.
    pub redundancy: T,
    /// The number of states `N`.
    pub states: usize,
    /// `Some(end)` if the maximum sits at an end of the range (within the tolerance): the
    /// true maximizer is then probably outside it, and the range should be widened.
    pub at_bound: Option<RangeEnd>,
    /// Local maxima seen in the scan (ends included); more than 1 means `R(q)` is not
    /// unimodal on the range and the global one was taken.
    pub scan_maxima: usize,
    /// Evaluations of `R(q)` (scan plus refinement).
    pub evaluations: usize,
}

/// One point of the redundancy curve `R(q)` (the paper's Fig. 6b).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RedundancyPoint<T> {
    /// Entropy index `q`.
    pub q: T,
    /// Redundancy `R(q)`.
    pub redundancy: T,
}

/// The entropy index `q* = argmax_q R(q)` of a distribution on `range`.
///
/// See [`QRange`] for the algorithm (coarse scan, then golden-section refinement of the best
/// bracket) and the [module docs](super) for the formulas and the meaning of `q*`. One
/// evaluation of `R` costs `N` calls of `expm1`; nothing is allocated.
///
/// # Errors
/// [`EntropyError::SingleState`] if `N = 1`; [`EntropyError::Equiprobable`] if all states
/// are equally probable (`R ≡ 0`, see [`Probabilities::is_equiprobable`]);
/// [`EntropyError::NonFiniteRedundancy`] if `R` overflows on the range.
///
/// # Examples
/// ```
/// use nonsmooth::entropy::{Probabilities, QRange, entropy_index, redundancy};
///
/// let p = Probabilities::from_counts(&[50, 30, 12, 5, 2, 1])?;
/// let index = entropy_index(&p, &QRange::default())?;
/// assert!(index.at_bound.is_none());
/// // A maximum: R is lower on either side.
/// let r = |q: f64| redundancy(&p, q).unwrap();
/// assert!(r(index.q - 1e-3) < index.redundancy && r(index.q + 1e-3) < index.redundancy);
/// # Ok::<(), nonsmooth::entropy::EntropyError>(())
/// ```
pub fn entropy_index<T: Real>(
    p: &Probabilities<T>,
    range: &QRange<T>,
) -> Result<EntropyIndex<T>, EntropyError> {
    if p.len() < 2 {
        return Err(EntropyError::SingleState);
    }
    if p.is_equiprobable() {
        return Err(EntropyError::Equiprobable { states: p.len() });
    }
    let ln_n = ln_states::<T>(p.len());
    let m = maximize(
        |q| redundancy_unchecked(p, ln_n, q),
        range.lo,
        range.hi,
        range.scan_points,
        range.tolerance,
    )?;
    Ok(EntropyIndex {
        q: m.x,
        redundancy: m.fx,
        states: p.len(),
        at_bound: m.at_bound,
        scan_maxima: m.scan_maxima,
        evaluations: m.evaluations,
    })
}

/// `R(q)` on `points` equally spaced values of `q` from `lo` to `hi` (both included, each
/// computed directly), for plotting (the paper's Fig. 6b).
///
/// `q ≤ 0` is allowed here (`R(0) = 0`, `R < 0` below).
///
/// # Errors
/// [`EntropyError::SingleState`] if `N = 1`; [`EntropyError::InvalidQRange`] unless `lo < hi`
/// are finite; [`EntropyError::TooFewPoints`] if `points < 2`.
///
/// # Examples
/// ```
/// use nonsmooth::entropy::{Probabilities, redundancy_curve};
///
/// let p = Probabilities::new(vec![0.7_f64, 0.2, 0.1])?;
/// let curve = redundancy_curve(&p, 0.0, 3.0, 31)?;
/// assert_eq!(curve.len(), 31);
/// assert_eq!((curve[0].q, curve[30].q), (0.0, 3.0));
/// assert!(curve[0].redundancy.abs() < 1e-15); // R(0) = 0
/// # Ok::<(), nonsmooth::entropy::EntropyError>(())
/// ```
pub fn redundancy_curve<T: Real>(
    p: &Probabilities<T>,
    lo: T,
    hi: T,
    points: usize,
) -> Result<Vec<RedundancyPoint<T>>, EntropyError> {
    if p.len() < 2 {
        return Err(EntropyError::SingleState);
    }
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(EntropyError::InvalidQRange {
            lo: to_f64(lo),
            hi: to_f64(hi),
            requirement: "need finite lo < hi",
        });
    }
    if points < 2 {
        return Err(EntropyError::TooFewPoints { points, minimum: 2 });
    }
    let ln_n = ln_states::<T>(p.len());
    Ok((0..points)
        .map(|k| {
            let q = grid(lo, hi, points, k);
            RedundancyPoint {
                q,
                redundancy: redundancy_unchecked(p, ln_n, q),
            }
        })
        .collect())
}

/// `lo + k·(hi − lo)/(n − 1)`, with the last point exactly `hi`.
#[inline]
fn grid<T: Real>(lo: T, hi: T, n: usize, k: usize) -> T {
    if k + 1 >= n {
        hi
    } else {
        lo + (hi - lo) * lit::<T>(k as f64 / (n - 1) as f64)
    }
}

/// The result of [`maximize`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct Maximum<T> {
    x: T,
    fx: T,
    at_bound: Option<RangeEnd>,
    scan_maxima: usize,
    evaluations: usize,
}

/// The largest number of golden-section steps (each shrinks the bracket by 0.618; 200 steps
/// reduce it by 10^-42, far beyond any tolerance — the cap only guards against stalls).
const MAX_GOLDEN_STEPS: usize = 200;

/// Maximizes `f` on `[lo, hi]`: scan `points` equally spaced values, then refine the best
/// by golden-section search on its neighbours' bracket down to width `tol`.
fn maximize<T: Real, F: FnMut(T) -> T>(
    mut f: F,
    lo: T,
    hi: T,
    points: usize,
    tol: T,
) -> Result<Maximum<T>, EntropyError> {
    debug_assert!(points >= 3 && lo < hi);
    let mut evaluations = 0;
    let mut eval = |x: T| {
        evaluations += 1;
        let y = f(x);
        if y.is_finite() {
            Ok(y)
        } else {
            Err(EntropyError::NonFiniteRedundancy { q: to_f64(x) })
        }
    };

    // Coarse scan: the best grid point and the local maxima (without storing the scan).
    let (mut best_k, mut best_f) = (0, eval(lo)?);
    let (mut f_prev2, mut f_prev) = (best_f, best_f);
    let mut scan_maxima = 0;
    for k in 1..points {
        let fk = eval(grid(lo, hi, points, k))?;
        if k == 1 && f_prev > fk {
            scan_maxima += 1; // at lo
        }
        if k >= 2 && f_prev > f_prev2 && f_prev >= fk {
            scan_maxima += 1; // interior, at k − 1
        }
        if k == points - 1 && fk > f_prev {
            scan_maxima += 1; // at hi
        }
        if fk > best_f {
            best_k = k;
            best_f = fk;
        }
        f_prev2 = f_prev;
        f_prev = fk;
    }

    // Refine on the bracket of the best scan point.
    let a = grid(lo, hi, points, best_k.saturating_sub(1));
    let b = grid(lo, hi, points, (best_k + 1).min(points - 1));
    let (mut x, mut fx) = golden(&mut eval, a, b, tol)?;
    let x_scan = grid(lo, hi, points, best_k);
    if best_f > fx {
        (x, fx) = (x_scan, best_f);
    }
    let near = |x: T, end: T| (x - end).abs() <= tol + lit::<T>(4.0) * epsilon::<T>() * end.abs();
    let mut at_bound = None;
    if best_k == 0 && near(x, lo) {
        at_bound = Some(RangeEnd::Lower);
    } else if best_k == points - 1 && near(x, hi) {
        at_bound = Some(RangeEnd::Upper);
    }
    Ok(Maximum {
        x,
        fx,
        at_bound,
        scan_maxima,
        evaluations,
    })
}

/// Golden-section maximization on `[a, b]` down to a bracket of width `tol` (or the
/// rounding limit); returns the best point evaluated inside the final bracket.
fn golden<T: Real, F: FnMut(T) -> Result<T, EntropyError>>(
    f: &mut F,
    a: T,
    b: T,
    tol: T,
) -> Result<(T, T), EntropyError> {
    let g = lit::<T>(0.618_033_988_749_894_9);
    let four_eps = lit::<T>(4.0) * epsilon::<T>();
    let (mut a, mut b) = (a, b);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let mut fc = f(c)?;
    let mut fd = f(d)?;
    for _ in 0..MAX_GOLDEN_STEPS {
        if b - a <= tol + four_eps * a.abs().max(b.abs()) {
            break;
        }
        if fc >= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c)?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d)?;
        }
    }
    // The ends of the initial bracket are scan points, compared by the caller.
    Ok(if fc >= fd { (c, fc) } else { (d, fd) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maximizer_finds_global_peak_of_bimodal_function() {
        // Two well-separated peaks (tails below 1e-18 at the other's centre): a low one at 1
        // and the global one at 3.3.
        let f = |x: f64| {
            0.5 * (-20.0 * (x - 1.0).powi(2)).exp() + 0.8 * (-8.0 * (x - 3.3).powi(2)).exp()
        };
        let m = maximize(f, 0.05, 5.0, 100, 1e-10).unwrap();
        assert!((m.x - 3.3).abs() < 1e-6, "{m:?}");
        assert_eq!(m.scan_maxima, 2);
        assert_eq!(m.at_bound, None);
        // Golden on the scan bracket: about log(0.1/1e-10)/log(1/0.618) ≈ 43 steps.
        assert!(m.evaluations < 100 + 50, "{}", m.evaluations);
    }

    #[test]
    fn maximizer_reports_range_ends() {
        let m = maximize(|x: f64| -x, 0.05, 5.0, 100, 1e-9).unwrap();
        assert_eq!(m.at_bound, Some(RangeEnd::Lower));
        assert_eq!(m.x, 0.05);
        assert_eq!(m.scan_maxima, 1);
        let m = maximize(|x: f64| x, 0.05, 5.0, 100, 1e-9).unwrap();
        assert_eq!(m.at_bound, Some(RangeEnd::Upper));
        assert_eq!(m.x, 5.0);
        // A peak inside the first scan cell is not at the bound.
        let m = maximize(|x: f64| -(x - 0.07).powi(2), 0.05, 5.0, 100, 1e-9).unwrap();
        assert_eq!(m.at_bound, None);
        assert!((m.x - 0.07).abs() < 1e-8);
    }

    #[test]
    fn maximizer_stops_at_rounding_limit_and_reports_nan() {
        // A tolerance far below the spacing of f32 values still terminates.
        let m = maximize(|x: f32| -(x - 1.3) * (x - 1.3), 0.05, 5.0, 100, 1e-30).unwrap();
        assert!((m.x - 1.3).abs() < 1e-3);
        assert!(matches!(
            maximize(
                |x: f64| if x > 2.0 { f64::NAN } else { x },
                0.05,
                5.0,
                10,
                1e-9
            ),
            Err(EntropyError::NonFiniteRedundancy { .. })
        ));
    }

    #[test]
    fn grid_is_exact_at_ends() {
        assert_eq!(grid(0.05_f64, 5.0, 100, 0), 0.05);
        assert_eq!(grid(0.05_f64, 5.0, 100, 99), 5.0);
        assert!((grid(0.05_f64, 5.0, 100, 50) - (0.05 + 50.0 * 0.05)).abs() < 1e-15);
    }
}
