//! Observed order of convergence.

use crate::validate::ParameterError;

/// A least-squares fit `log err ≈ log C + p·log h`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ConvergenceFit {
    /// The observed order `p` (the slope).
    pub order: f64,
    /// The constant `log C` (natural logarithm; the intercept).
    pub log_constant: f64,
    /// The largest `|log err − (log C + p·log h)|` over the data: small when the errors are
    /// in the asymptotic regime, large when roundoff or a pre-asymptotic level spoils them.
    pub max_residual: f64,
}

/// Fits `log(error) = log C + p·log(h)` by least squares.
///
/// # Formula
/// $$p = \frac{\sum_i (\ell_i - \bar\ell)(e_i - \bar e)}{\sum_i (\ell_i - \bar\ell)^2},\qquad
///   \ell_i = \ln h_i,\ e_i = \ln \mathrm{err}_i .$$
///
/// # Errors
/// [`ParameterError`] unless both slices have the same length ≥ 3, every value is finite
/// and > 0, and the step sizes are not all equal.
///
/// # Examples
/// ```
/// use nonsmooth::testing::convergence_fit;
/// let hs = [0.1, 0.05, 0.025, 0.0125];
/// let errs: Vec<f64> = hs.iter().map(|h: &f64| 3.0 * h.powi(4)).collect();
/// let fit = convergence_fit(&hs, &errs)?;
/// assert!((fit.order - 4.0).abs() < 1e-12 && (fit.log_constant - 3f64.ln()).abs() < 1e-12);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
pub fn convergence_fit(hs: &[f64], errors: &[f64]) -> Result<ConvergenceFit, ParameterError> {
    if hs.len() < 3 {
        return Err(ParameterError::new("hs.len()", hs.len() as f64, ">= 3"));
    }
    if errors.len() != hs.len() {
        return Err(ParameterError::new(
            "errors.len()",
            errors.len() as f64,
            "equal to hs.len()",
        ));
    }
    if let Some(&h) = hs.iter().find(|h| !(h.is_finite() && **h > 0.0)) {
        return Err(ParameterError::new("hs", h, "finite and > 0"));
    }
    if let Some(&e) = errors.iter().find(|e| !(e.is_finite() && **e > 0.0)) {
        return Err(ParameterError::new("errors", e, "finite and > 0"));
    }
    let n = hs.len() as f64;
    let lh: Vec<f64> = hs.iter().map(|h| h.ln()).collect();
    let le: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
    let mh = lh.iter().sum::<f64>() / n;
    let me = le.iter().sum::<f64>() / n;
    let sxx: f64 = lh.iter().map(|l| (l - mh) * (l - mh)).sum();
    if sxx <= 0.0 {
        return Err(ParameterError::new("hs", hs[0], "not all equal"));
    }
    let sxy: f64 = lh.iter().zip(&le).map(|(l, e)| (l - mh) * (e - me)).sum();
    let order = sxy / sxx;
    let log_constant = me - order * mh;
    let max_residual = lh
        .iter()
        .zip(&le)
        .map(|(l, e)| (e - (log_constant + order * l)).abs())
        .fold(0.0, f64::max);
    Ok(ConvergenceFit {
        order,
        log_constant,
        max_residual,
    })
}

/// The observed order of convergence: the least-squares slope of `log(error)` against
/// `log(h)` (see [`convergence_fit`]).
///
/// # Errors
/// As [`convergence_fit`].
///
/// # Examples
/// ```
/// use nonsmooth::testing::convergence_order;
/// let p = convergence_order(&[0.4, 0.2, 0.1], &[1.6e-3, 2.0e-4, 2.5e-5])?;
/// assert!((p - 3.0).abs() < 1e-12);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
pub fn convergence_order(hs: &[f64], errors: &[f64]) -> Result<f64, ParameterError> {
    convergence_fit(hs, errors).map(|f| f.order)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_known_orders_with_noise() {
        let hs: Vec<f64> = (0..6).map(|i| 0.1 / 2f64.powi(i)).collect();
        for p in [1.0, 2.0, 5.0, 8.0] {
            // A ±5 % multiplicative wobble must not move the slope by more than ~0.05.
            let errs: Vec<f64> = hs
                .iter()
                .enumerate()
                .map(|(i, h)| 0.7 * h.powf(p) * if i % 2 == 0 { 1.05 } else { 0.95 })
                .collect();
            let fit = convergence_fit(&hs, &errs).unwrap();
            assert!((fit.order - p).abs() < 0.05, "p = {p}: {}", fit.order);
            assert!(fit.max_residual < 0.1);
        }
    }

    #[test]
    fn validation() {
        assert!(convergence_order(&[0.1, 0.05], &[1.0, 0.5]).is_err());
        assert!(convergence_order(&[0.1, 0.05, 0.025], &[1.0, 0.5]).is_err());
        assert!(convergence_order(&[0.1, 0.05, 0.0], &[1.0, 0.5, 0.2]).is_err());
        assert!(convergence_order(&[0.1, 0.05, 0.02], &[1.0, 0.0, 0.2]).is_err());
        assert!(convergence_order(&[0.1, 0.05, 0.02], &[1.0, f64::NAN, 0.2]).is_err());
        assert!(convergence_order(&[0.1, 0.1, 0.1], &[1.0, 0.5, 0.2]).is_err());
        let e = convergence_order(&[0.1, 0.05], &[1.0, 0.5]).unwrap_err();
        assert_eq!(e.name, "hs.len()");
    }
}
