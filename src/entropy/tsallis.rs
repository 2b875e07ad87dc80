//! Entropy definitions: Shannon, Tsallis, the Tsallis maximum and the redundancy.
//!
//! All functions are continuous through `q = 1` and evaluated in the `expm1` form given in
//! the [module docs](super), which keeps full relative precision for `|q − 1|` down to the
//! smallest representable spacing around 1.

use super::{EntropyError, Probabilities};
use crate::Real;
use crate::scalar::{lit, to_f64};

/// Shannon entropy `S_1 = −Σ p_i ln p_i` (nats): the `q → 1` limit of [`tsallis`].
///
/// # Examples
/// ```
/// use nonsmooth::entropy::{Probabilities, shannon};
/// let p = Probabilities::new(vec![0.25_f64; 4])?;
/// assert!((shannon(&p) - 4f64.ln()).abs() < 1e-15);
/// # Ok::<(), nonsmooth::entropy::EntropyError>(())
/// ```
pub fn shannon<T: Real>(p: &Probabilities<T>) -> T {
    -p.as_slice()
        .iter()
        .zip(p.ln_probabilities())
        .fold(T::zero(), |s, (&pi, &li)| s + pi * li)
}

/// Tsallis entropy with `k = 1`,
/// $$ S_q = \frac{1}{q-1}\Bigl(1 - \sum_i p_i^{\,q}\Bigr), $$
/// equal to [`shannon`] at `q = 1` and continuous there.
///
/// # Errors
/// [`EntropyError::InvalidQ`] if `q` is not finite.
///
/// # Examples
/// ```
/// use nonsmooth::entropy::{Probabilities, shannon, tsallis};
/// let p = Probabilities::new(vec![0.5_f64, 0.3, 0.2])?;
/// // q = 2: the Gini–Simpson index 1 − Σ p².
/// assert!((tsallis(&p, 2.0)? - (1.0 - 0.25 - 0.09 - 0.04)).abs() < 1e-15);
/// // Continuous through q = 1.
/// assert!((tsallis(&p, 1.0 + 1e-12)? - shannon(&p)).abs() < 1e-12);
/// # Ok::<(), nonsmooth::entropy::EntropyError>(())
/// ```
pub fn tsallis<T: Real>(p: &Probabilities<T>, q: T) -> Result<T, EntropyError> {
    check_q(q)?;
    representable("the Tsallis entropy", q, tsallis_unchecked(p, q))
}

/// The largest Tsallis entropy of `n` states (for `q > 0`), attained at `p_i = 1/n`:
/// $$ S_{q,\max} = \frac{1 - n^{\,1-q}}{q-1}, \qquad S_{1,\max} = \ln n. $$
///
/// For `q ≤ 0` the formula is still evaluated (it is then the *smallest* entropy of `n`
/// occupied states).
///
/// # Errors
/// [`EntropyError::EmptyDistribution`] if `n = 0`, [`EntropyError::InvalidQ`] if `q` is not
/// finite.
pub fn tsallis_max<T: Real>(n: usize, q: T) -> Result<T, EntropyError> {
    if n == 0 {
        return Err(EntropyError::EmptyDistribution);
    }
    check_q(q)?;
    representable(
        "the largest Tsallis entropy",
        q,
        tsallis_max_unchecked(ln_states(n), q),
    )
}

/// The redundancy
/// $$ R(q) = 1 - \frac{S_q}{S_{q,\max}}, $$
/// `0` for equiprobable states, in `[0, 1]` for `q > 0` (up to rounding), `R(0) = 0` and
/// `R ≤ 0` for `q < 0`. At `q = 1` it is `1 − S_1/ln N`.
///
/// # Errors
/// [`EntropyError::SingleState`] if `N = 1` (then `S_q = S_q,max = 0` and `R` is undefined),
/// [`EntropyError::InvalidQ`] if `q` is not finite.
///
/// # Examples
/// ```
/// use nonsmooth::entropy::{Probabilities, redundancy};
/// let uniform = Probabilities::new(vec![0.2_f64; 5])?;
/// assert!(redundancy(&uniform, 0.7)?.abs() < 1e-15);
/// let skewed = Probabilities::new(vec![0.9_f64, 0.1])?;
/// assert!(redundancy(&skewed, 0.7)? > 0.3);
/// # Ok::<(), nonsmooth::entropy::EntropyError>(())
/// ```
pub fn redundancy<T: Real>(p: &Probabilities<T>, q: T) -> Result<T, EntropyError> {
    check_q(q)?;
    if p.len() < 2 {
        return Err(EntropyError::SingleState);
    }
    representable(
        "the redundancy",
        q,
        redundancy_unchecked(p, ln_states(p.len()), q),
    )
}

/// `Ok(value)` if it is finite, else [`EntropyError::NotRepresentable`].
fn representable<T: Real>(quantity: &'static str, q: T, value: T) -> Result<T, EntropyError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(EntropyError::NotRepresentable {
            quantity,
            q: to_f64(q),
        })
    }
}

fn check_q<T: Real>(q: T) -> Result<(), EntropyError> {
    if q.is_finite() {
        Ok(())
    } else {
        Err(EntropyError::InvalidQ { q: to_f64(q) })
    }
}

/// `ln n` in `T`.
pub(crate) fn ln_states<T: Real>(n: usize) -> T {
    lit::<T>(n as f64).ln()
}

/// `Σ_i (p_i^q − p_i)`, computed without cancellation for `q` near 1.
#[inline]
fn sum_pq_minus_p<T: Real>(p: &Probabilities<T>, q: T) -> T {
    let delta = q - T::one();
    let mut s = T::zero();
    for (&pi, &li) in p.as_slice().iter().zip(p.ln_probabilities()) {
        let x = delta * li;
        // p^q − p = p·(p^δ − 1) = p·expm1(δ ln p): exact in form, no cancellation for small
        // δ. For |δ ln p| > 1 the difference is well conditioned and exp(q ln p) − p avoids
        // the overflow of expm1(δ ln p) for large |δ ln p| (tiny p, q far below 1).
        s += if x.abs() <= T::one() {
            pi * x.exp_m1()
        } else {
            (q * li).exp() - pi
        };
    }
    s
}

/// [`tsallis`] without the check on `q`.
#[inline]
pub(crate) fn tsallis_unchecked<T: Real>(p: &Probabilities<T>, q: T) -> T {
    let delta = q - T::one();
    if delta == T::zero() {
        shannon(p)
    } else {
        // (1 − Σ p^q)/δ = −Σ (p^q − p)/δ, using Σ p = 1.
        -sum_pq_minus_p(p, q) / delta
    }
}

/// [`tsallis_max`] from `ln N`, without checks.
#[inline]
pub(crate) fn tsallis_max_unchecked<T: Real>(ln_n: T, q: T) -> T {
    let delta = q - T::one();
    if delta == T::zero() {
        ln_n
    } else {
        // (1 − N^{−δ})/δ = −expm1(−δ ln N)/δ.
        -(-delta * ln_n).exp_m1() / delta
    }
}

/// [`redundancy`] from `ln N` (`N ≥ 2`), without checks. Never NaN: where `S_q` or
/// `S_q,max` overflows (`q` far below 1) the ratio is taken in logarithms (see
/// [`redundancy_far_below_one`]); `−∞` only where the exact `R` is below `−f64::MAX`.
#[inline]
pub(crate) fn redundancy_unchecked<T: Real>(p: &Probabilities<T>, ln_n: T, q: T) -> T {
    let s = tsallis_unchecked(p, q);
    let m = tsallis_max_unchecked(ln_n, q);
    if s.is_finite() && m.is_finite() {
        T::one() - s / m
    } else {
        redundancy_far_below_one(p, ln_n, q)
    }
}

/// `R(q)` for `q < 1` when `X = Σ p_i^q` or `Y = N^{1−q}` overflows.
///
/// # Formula
/// For `q < 1`, `S_q = (X − 1)/(1 − q)` and `S_q,max = (Y − 1)/(1 − q)`, so
/// $$ 1 - R = \frac{X - 1}{Y - 1}
///    = \frac{X}{Y}\,\frac{1 - 1/X}{1 - 1/Y}, \qquad
///    \ln\frac{X}{Y} = \ln\frac{1}{N}\sum_i e^{\,q \ln(N p_i)} , $$
/// the last a log-sum-exp of the moderate numbers `ln(N p_i)` (shifted by its largest term).
/// Then `R = −expm1(ln(X/Y) + ln1p(−1/X) − ln1p(−1/Y))`.
#[cold]
fn redundancy_far_below_one<T: Real>(p: &Probabilities<T>, ln_n: T, q: T) -> T {
    let terms = p.ln_probabilities().iter().map(|&li| q * (li + ln_n));
    let neg_inf = -lit::<T>(f64::INFINITY);
    let top = terms.clone().fold(neg_inf, T::max);
    if !top.is_finite() {
        // q·ln(N p_i) = +∞ for some i: X/Y, and so −R, is beyond the range.
        return neg_inf;
    }
    let sum = terms.fold(T::zero(), |s, x| s + (x - top).exp());
    let ln_ratio = top + sum.ln() - ln_n;
    let ln_y = (T::one() - q) * ln_n;
    let ln_x = ln_ratio + ln_y;
    let correction = (-(-ln_x).exp()).ln_1p() - (-(-ln_y).exp()).ln_1p();
    -(ln_ratio + correction).exp_m1()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive_tsallis(p: &[f64], q: f64) -> f64 {
        (1.0 - p.iter().map(|x| x.powf(q)).sum::<f64>()) / (q - 1.0)
    }

    #[test]
    fn matches_naive_form_away_from_one() {
        let v = vec![0.5, 0.2, 0.15, 0.1, 0.05];
        let p = Probabilities::new(v.clone()).unwrap();
        for &q in &[-2.0, 0.0, 0.05, 0.3, 0.62, 1.5, 2.0, 3.7, 10.0] {
            let s = tsallis(&p, q).unwrap();
            let n = naive_tsallis(&v, q);
            assert!(
                (s - n).abs() <= 1e-14 * n.abs().max(1.0),
                "q = {q}: {s} vs {n}"
            );
            let m = tsallis_max::<f64>(5, q).unwrap();
            let nm = (1.0 - 5f64.powf(1.0 - q)) / (q - 1.0);
            assert!((m - nm).abs() <= 1e-14 * nm.abs().max(1.0));
        }
        // q = 0: S_0 = N − 1 for every distribution of N occupied states, so R(0) = 0.
        assert!((tsallis(&p, 0.0).unwrap() - 4.0).abs() < 1e-14);
        assert!(redundancy(&p, 0.0).unwrap().abs() < 1e-15);
    }

    #[test]
    fn large_exponents_do_not_overflow() {
        // expm1(δ ln p) with δ ln p ≈ 8e2 would overflow; p^q − p must not.
        let p = Probabilities::new(vec![1.0 - 1e-300, 1e-300_f64]).unwrap();
        let s = tsallis(&p, -0.2).unwrap();
        assert!(s.is_finite());
        let n = naive_tsallis(p.as_slice(), -0.2);
        assert!((s - n).abs() <= 1e-12 * n.abs());
    }

    #[test]
    fn far_below_one_is_never_nan() {
        // X = Σ p^q and Y = N^{1−q} overflow; R comes from the log form.
        let p = Probabilities::new(vec![0.5_f64, 0.3, 0.2]).unwrap();
        let ln_n = ln_states::<f64>(3);
        // At q = −1000 the direct form overflows (0.2^q ≈ 10⁶⁹⁹); R = 1 − (X − 1)/(Y − 1)
        // with X/Y = mean((N p_i)^q) dominated by the smallest p: (0.6)^q/3 ≈ e^509.7.
        let q = -1000.0;
        assert!(!tsallis_unchecked(&p, q).is_finite());
        let r = redundancy_unchecked(&p, ln_n, q);
        let ln_ratio = q * (0.6_f64).ln() - 3f64.ln();
        assert!(((1.0 - r).ln() - ln_ratio).abs() < 1e-9 * ln_ratio, "{r}");
        // Beyond the range: an error, never NaN.
        for q in [-1.3e199, -1e300, -f64::MAX] {
            assert!(!redundancy_unchecked(&p, ln_n, q).is_nan());
            assert!(matches!(
                redundancy(&p, q),
                Err(EntropyError::NotRepresentable { .. })
            ));
            assert!(matches!(
                tsallis(&p, q),
                Err(EntropyError::NotRepresentable { .. })
            ));
        }
        // Uniform: R = 0 exactly, however far q is from 1.
        let u = Probabilities::new(vec![0.25_f64; 4]).unwrap();
        for q in [-1e6, -1.3e199, -f64::MAX] {
            assert_eq!(redundancy(&u, q), Ok(0.0), "q = {q}");
        }
        // Agreement where both forms apply: q = −400 (direct) vs the log form.
        let q = -400.0;
        let direct = redundancy(&p, q).unwrap();
        let logs = redundancy_far_below_one(&p, ln_n, q);
        assert!(
            (direct - logs).abs() <= 1e-12 * direct.abs(),
            "{direct} vs {logs}"
        );
    }

    #[test]
    fn checks() {
        let p = Probabilities::new(vec![1.0_f64]).unwrap();
        assert_eq!(redundancy(&p, 0.5), Err(EntropyError::SingleState));
        assert_eq!(tsallis(&p, 0.5), Ok(0.0));
        assert_eq!(tsallis_max::<f64>(1, 0.5), Ok(0.0));
        assert_eq!(
            tsallis_max::<f64>(0, 0.5),
            Err(EntropyError::EmptyDistribution)
        );
        assert!(matches!(
            tsallis(&p, f64::NAN),
            Err(EntropyError::InvalidQ { .. })
        ));
        let p2 = Probabilities::new(vec![0.5_f64, 0.5]).unwrap();
        assert!(matches!(
            redundancy(&p2, f64::INFINITY),
            Err(EntropyError::InvalidQ { .. })
        ));
    }
}
