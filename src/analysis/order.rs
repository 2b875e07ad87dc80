//! The observed order of convergence of a method from its errors at several step sizes.
//!
//! An error that behaves as `e(h) ≈ C·hᵖ` is a line of slope `p` in `(ln h, ln e)`; with
//! more than two step sizes the slope is fitted by least squares,
//! $$p = \frac{\sum_i (x_i - \bar x)(y_i - \bar y)}{\sum_i (x_i - \bar x)^2},
//!   \qquad x_i = \ln h_i,\; y_i = \ln e_i,$$
//! which averages out the scatter of single ratios `ln(e₁/e₂)/ln(h₁/h₂)`.

use super::AnalysisError;

/// The least-squares slope of `ln e` against `ln h`: the observed order `p` of an error
/// `e ≈ C·hᵖ` (a step size, a tolerance or a regularization parameter as `h`).
///
/// # Errors
/// [`AnalysisError::ConvergenceData`] unless `h` and `e` have the same length ≥ 2, every
/// value is finite and > 0, and not every `h` is the same.
///
/// ```
/// # use nonsmooth::analysis::observed_order;
/// let h = [0.1, 0.05, 0.025];
/// let e: Vec<f64> = h.iter().map(|h: &f64| 3.0 * h.powi(4)).collect();
/// assert!((observed_order(&h, &e)? - 4.0).abs() < 1e-12);
/// # Ok::<(), nonsmooth::analysis::AnalysisError>(())
/// ```
pub fn observed_order(h: &[f64], e: &[f64]) -> Result<f64, AnalysisError> {
    let bad = |reason: String| AnalysisError::ConvergenceData { reason };
    if h.len() != e.len() {
        return Err(bad(format!(
            "{} step sizes but {} errors",
            h.len(),
            e.len()
        )));
    }
    if h.len() < 2 {
        return Err(bad(format!("{} points, at least 2 needed", h.len())));
    }
    for (name, xs) in [("h", h), ("e", e)] {
        if let Some((i, x)) = xs
            .iter()
            .enumerate()
            .find(|(_, x)| !(x.is_finite() && **x > 0.0))
        {
            return Err(bad(format!("{name}[{i}] = {x} is not finite and > 0")));
        }
    }
    let xs: Vec<f64> = h.iter().map(|h| h.ln()).collect();
    let ys: Vec<f64> = e.iter().map(|e| e.ln()).collect();
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    if !(sxx > 0.0) {
        return Err(bad(format!("every step size is {}", h[0])));
    }
    Ok(sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::observed_order;

    #[test]
    fn recovers_the_order_of_a_power_law_and_rejects_bad_data() {
        let h = [0.2, 0.1, 0.05, 0.025];
        // A power law with a higher-order term: the fit lies between the two orders,
        // near the leading one.
        let e: Vec<f64> = h.iter().map(|h| 2.0 * h * h + 0.5 * h * h * h).collect();
        let p = observed_order(&h, &e).unwrap();
        assert!((2.0..2.1).contains(&p), "{p}");
        // Exactly first order.
        let e1: Vec<f64> = h.iter().map(|h| 7.0 * h).collect();
        assert!((observed_order(&h, &e1).unwrap() - 1.0).abs() < 1e-12);
        assert!(observed_order(&h, &e1[..3]).is_err());
        assert!(observed_order(&h[..1], &e1[..1]).is_err());
        assert!(observed_order(&[0.1, 0.1], &[1.0, 2.0]).is_err());
        let msg = observed_order(&[0.1, 0.0], &[1.0, 2.0])
            .unwrap_err()
            .to_string();
        assert!(msg.contains("h[1] = 0"), "{msg}");
        assert!(observed_order(&[0.1, 0.2], &[f64::NAN, 2.0]).is_err());
    }
}
