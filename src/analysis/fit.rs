//! Least-squares fit of a truncated Fourier series in the forcing frequency.

use nalgebra::{DMatrix, DVector};

use super::AnalysisError;
use super::spectrum::check_finite;
use crate::Real;
use crate::scalar::{lit, to_f64};

/// A truncated Fourier series in the forcing frequency `ω`, fitted by least squares:
/// $$x(t) \approx a_0 + \sum_{k=1}^{K} \bigl(a_k \cos k\omega t + b_k \sin k\omega t\bigr).$$
///
/// `a[k − 1]` and `b[k − 1]` hold `a_k` and `b_k`. The coefficients are in the time origin of
/// the time stamps that were fitted (see the [module docs](super#time-origin)).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HarmonicFit<T> {
    /// The forcing frequency `ω` (rad/s).
    pub omega: T,
    /// The mean `a_0`.
    pub a0: T,
    /// The cosine coefficients `a_1, …, a_K`.
    pub a: Vec<T>,
    /// The sine coefficients `b_1, …, b_K`.
    pub b: Vec<T>,
    /// The root-mean-square residual `√(Σ r_i²/n)`.
    pub residual_rms: T,
    /// The 2-norm condition number of the design matrix (1 for a uniform grid over whole
    /// periods up to a factor √2, large when the samples span a small part of a period).
    pub condition: T,
}

impl<T: Real> HarmonicFit<T> {
    /// The number of harmonics `K`.
    pub fn harmonics(&self) -> usize {
        self.a.len()
    }

    /// The fitted series at time `t`.
    pub fn evaluate(&self, t: T) -> T {
        let mut x = self.a0;
        for (k, (&a, &b)) in self.a.iter().zip(&self.b).enumerate() {
            let (s, c) = (lit::<T>((k + 1) as f64) * self.omega * t).sin_cos();
            x += a * c + b * s;
        }
        x
    }

    /// The amplitude `√(a_k² + b_k²)` of harmonic `k ≥ 1` (`None` if `k` is 0 or > K).
    pub fn amplitude(&self, k: usize) -> Option<T> {
        let i = k.checked_sub(1)?;
        Some(self.a.get(i)?.hypot(*self.b.get(i)?))
    }

    /// The phase `φ_k` of harmonic `k ≥ 1` written as `A_k·cos(kωt + φ_k)`:
    /// `φ_k = atan2(−b_k, a_k)` (`None` if `k` is 0 or > K).
    pub fn phase(&self, k: usize) -> Option<T> {
        let i = k.checked_sub(1)?;
        Some((-*self.b.get(i)?).atan2(*self.a.get(i)?))
    }
}

/// Fits `x(t) ≈ a_0 + Σ_{k=1..K} (a_k cos kωt + b_k sin kωt)` to the samples `(t_i, x_i)`
/// by linear least squares (Householder QR of the `n × (2K+1)` design matrix; the condition
/// number from the SVD of its triangle).
///
/// The time stamps need not be uniform nor cover whole periods; when they do (a uniform grid
/// over whole periods), the basis is orthogonal and the fit agrees with the
/// [`AmplitudeSpectrum`](super::AmplitudeSpectrum)'s harmonics. Measure `t` from a Poincaré section
/// `t = 2πi/ω` to get the coefficients in the paper's time origin; any time counted from the
/// start of a constant-frequency simulation is such an origin.
///
/// # Errors
/// - [`AnalysisError::LengthMismatch`] if `t` and `x` differ in length;
/// - [`AnalysisError::InvalidFrequency`] unless `omega` is finite and > 0;
/// - [`AnalysisError::TooFewSamples`] if `n < 2K + 1`;
/// - [`AnalysisError::NonFinite`] for a NaN/∞ time stamp or value;
/// - [`AnalysisError::IllConditioned`] if the design matrix is numerically rank deficient
///   (smallest singular value below `n·ε` times the largest: e.g. repeated time stamps, or
///   samples at a spacing that aliases two harmonics onto each other).
///
/// # Examples
/// ```
/// use nonsmooth::analysis::fit_harmonics;
/// let omega = 14.0_f64;
/// let t: Vec<f64> = (0..200).map(|i| 0.003 * i as f64).collect(); // not whole periods
/// let x: Vec<f64> = t.iter()
///     .map(|&t| -2.08e-3 + 3.9e-6 * (omega * t).sin() + 6.7e-7 * (2.0 * omega * t).cos())
///     .collect();
/// let fit = fit_harmonics(&t, &x, omega, 2)?;
/// assert!((fit.a0 + 2.08e-3).abs() < 1e-15);
/// assert!((fit.b[0] - 3.9e-6).abs() < 1e-16 && (fit.a[1] - 6.7e-7).abs() < 1e-16);
/// assert!(fit.residual_rms < 1e-17);
/// # Ok::<(), nonsmooth::analysis::AnalysisError>(())
/// ```
pub fn fit_harmonics<T: Real>(
    t: &[T],
    x: &[T],
    omega: T,
    harmonics: usize,
) -> Result<HarmonicFit<T>, AnalysisError> {
    if t.len() != x.len() {
        return Err(AnalysisError::LengthMismatch {
            t: t.len(),
            x: x.len(),
        });
    }
    if !(omega.is_finite() && omega > T::zero()) {
        return Err(AnalysisError::InvalidFrequency {
            omega: to_f64(omega),
        });
    }
    let n = t.len();
    let p = 2 * harmonics + 1;
    if n < p {
        return Err(AnalysisError::TooFewSamples {
            samples: n,
            required: p,
        });
    }
    check_finite(t, x)?;

    // Columns 1, cos ωt, sin ωt, cos 2ωt, sin 2ωt, …; the higher harmonics by the angle
    // addition formulas from one sin_cos per sample (error growth ~k·ε, negligible for the
    // handful of harmonics fitted).
    let mut design = DMatrix::<T>::zeros(n, p);
    for (i, &ti) in t.iter().enumerate() {
        design[(i, 0)] = T::one();
        let (s1, c1) = (omega * ti).sin_cos();
        let (mut s, mut c) = (s1, c1);
        for k in 1..=harmonics {
            design[(i, 2 * k - 1)] = c;
            design[(i, 2 * k)] = s;
            (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
        }
    }
    let rhs = DVector::<T>::from_column_slice(x);
    // Householder QR (Q never formed), then the small p×p triangle R: its singular values
    // are those of the design matrix (condition number) and it is solved by back
    // substitution.
    let qr = design.clone().qr();
    let mut qtb = rhs.clone();
    qr.q_tr_mul(&mut qtb);
    let r = qr.unpack_r();
    let sv = r.clone().svd(false, false).singular_values;
    let (smax, smin) = (sv.max(), sv.min());
    if !smin.is_finite() || smin <= smax * lit::<T>(n as f64) * T::default_epsilon() {
        return Err(AnalysisError::IllConditioned {
            condition: to_f64(smax) / to_f64(smin),
        });
    }
    let condition = smax / smin;
    let coef = r
        .solve_upper_triangular(&qtb.rows(0, p).into_owned())
        .ok_or(AnalysisError::IllConditioned {
            condition: to_f64(condition),
        })?;
    let residual = &rhs - &design * &coef;
    let residual_rms = (residual.norm_squared() / lit::<T>(n as f64)).sqrt();
    let a = (1..=harmonics).map(|k| coef[2 * k - 1]).collect();
    let b = (1..=harmonics).map(|k| coef[2 * k]).collect();
    Ok(HarmonicFit {
        omega,
        a0: coef[0],
        a,
        b,
        residual_rms,
        condition,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_coefficients_on_an_irregular_grid() {
        let omega = 2.3_f64;
        // Irregular, not whole periods.
        let t: Vec<f64> = (0..97)
            .map(|i| 0.05 * i as f64 + 0.01 * (i as f64).sin())
            .collect();
        let f = |t: f64| {
            0.4 - 1.2 * (omega * t).cos() + 0.5 * (omega * t).sin() + 0.03 * (3.0 * omega * t).sin()
        };
        let x: Vec<f64> = t.iter().map(|&t| f(t)).collect();
        let fit = fit_harmonics(&t, &x, omega, 3).unwrap();
        let expect_a = [-1.2, 0.0, 0.0];
        let expect_b = [0.5, 0.0, 0.03];
        assert!((fit.a0 - 0.4).abs() < 1e-12);
        for k in 0..3 {
            assert!((fit.a[k] - expect_a[k]).abs() < 1e-12, "a{}", k + 1);
            assert!((fit.b[k] - expect_b[k]).abs() < 1e-12, "b{}", k + 1);
        }
        assert!(fit.residual_rms < 1e-13);
        assert!((fit.evaluate(1.234) - f(1.234)).abs() < 1e-12);
        assert!((fit.amplitude(1).unwrap() - 1.3).abs() < 1e-12);
        assert!(fit.amplitude(0).is_none() && fit.amplitude(4).is_none());
        // −1.2 cos + 0.5 sin = 1.3 cos(ωt + φ), φ = atan2(−0.5, −1.2).
        assert!((fit.phase(1).unwrap() - (-0.5_f64).atan2(-1.2)).abs() < 1e-12);
    }

    #[test]
    fn aliased_grid_is_rank_deficient() {
        // Sampling once per period makes cos ωt ≡ 1 on the grid: same column as the mean.
        let omega = 1.0_f64;
        let t: Vec<f64> = (0..10).map(|i| std::f64::consts::TAU * i as f64).collect();
        let x = vec![1.0; 10];
        assert!(matches!(
            fit_harmonics(&t, &x, omega, 1),
            Err(AnalysisError::IllConditioned { .. })
        ));
    }

    #[test]
    fn f32_fit() {
        let omega = 14.0_f32;
        let t: Vec<f32> = (0..64).map(|i| i as f32 * 0.01).collect();
        let x: Vec<f32> = t
            .iter()
            .map(|&t| 1.0 + 0.5 * (omega * t).sin() - 0.25 * (2.0 * omega * t).cos())
            .collect();
        let fit = fit_harmonics(&t, &x, omega, 2).unwrap();
        assert!((fit.a0 - 1.0).abs() < 1e-5);
        assert!((fit.b[0] - 0.5).abs() < 1e-5);
        assert!((fit.a[1] + 0.25).abs() < 1e-5);
    }
}
