//! The identification objective `F0` (the paper's, Sect. 2).

use super::IdentifyError;
use crate::signal::{TimeSeries, validate_samples};

/// Square metres to square millimetres (`1 m² = 10⁶ mm²`).
pub const M2_TO_MM2: f64 = 1.0e6;

/// The mean squared difference between a measured and a simulated record over a window,
/// the paper's identification objective (Sect. 2), in m² when positions are in metres.
///
/// # Formula
/// $$ F_0 = \frac{1}{t_2 - t_1}\int_{t_1}^{t_2} \bigl(x_\mathrm{exp}(t) - x_\mathrm{sim}(t)\bigr)^2\,dt . $$
/// The integral is the trapezoidal rule on the nodes `t_1`, every measured sample strictly
/// inside `(t_1, t_2)`, and `t_2`. At each node `x_sim` is the **linear** interpolant of the
/// simulated samples (the simulation's own grid may differ from the measured one; sample the
/// simulation at least as densely as the measurement, or on the measured times, for the
/// interpolation error to be negligible). At the window ends `x_exp` is the linear
/// interpolant of the measured samples (exact when `t_1`, `t_2` are sample times). For
/// piecewise-linear signals on a common grid the result is exact up to the trapezoidal rule's
/// `O(h²)` error on the squared difference.
///
/// For positions in metres, [`objective_f0_mm2`] or a factor [`M2_TO_MM2`] gives mm².
///
/// # Errors
/// - [`IdentifyError::InvalidWindow`] if `t1`, `t2` are not finite or `t1 ≥ t2`;
/// - [`IdentifyError::WindowOutsideData`] if `[t1, t2]` is not inside the measured or the
///   simulated time span;
/// - [`IdentifyError::EmptyWindow`] if fewer than two measured samples lie in `[t1, t2]`;
/// - [`IdentifyError::Signal`] if the simulated arrays are invalid (unequal lengths, fewer
///   than two samples, non-increasing or non-finite time, non-finite `x`), with the sample
///   index.
///
/// # Examples
/// ```
/// use nonsmooth::identify::objective_f0;
/// use nonsmooth::signal::TimeSeries;
/// // A constant offset of 0.1 mm gives F0 = (1e-4 m)² = 1e-8 m² = 0.01 mm².
/// let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.01).collect();
/// let x: Vec<f64> = t.iter().map(|t| 1e-3 * (6.0 * t).sin()).collect();
/// let measured = TimeSeries::new(t.clone(), x.iter().map(|v| v + 1e-4).collect(), None)?;
/// let f0 = objective_f0(&measured, &t, &x, (0.2, 0.8))?;
/// assert!((f0 - 1e-8).abs() < 1e-20);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
pub fn objective_f0(
    measured: &TimeSeries,
    simulated_t: &[f64],
    simulated_x: &[f64],
    window: (f64, f64),
) -> Result<f64, IdentifyError> {
    let (t1, t2) = window;
    if !(t1.is_finite() && t2.is_finite() && t1 < t2) {
        return Err(IdentifyError::InvalidWindow { t1, t2 });
    }
    validate_samples(simulated_t, simulated_x, "simulated x", 2)?;
    let (tm, xm) = (measured.t(), measured.x());
    for (which, t) in [("measured", tm), ("simulated", simulated_t)] {
        let (start, end) = match (t.first(), t.last()) {
            (Some(&a), Some(&b)) => (a, b),
            _ => (f64::NAN, f64::NAN),
        };
        if !(start <= t1 && t2 <= end) {
            return Err(IdentifyError::WindowOutsideData {
                which,
                t1,
                t2,
                start,
                end,
            });
        }
    }
    // Measured samples in [t1, t2]: indices lo..hi.
    let lo = tm.partition_point(|&t| t < t1);
    let hi = tm.partition_point(|&t| t <= t2);
    if hi - lo < 2 {
        return Err(IdentifyError::EmptyWindow {
            t1,
            t2,
            samples: hi - lo,
        });
    }
    let mut sim = Interpolator::new(simulated_t, simulated_x);
    let mut meas = Interpolator::new(tm, xm);
    let sq = |t: f64, x_exp: f64, sim: &mut Interpolator<'_>| {
        let d = x_exp - sim.at(t);
        d * d
    };
    // Nodes: t1, the samples strictly inside, t2.
    let mut t_prev = t1;
    let mut f_prev = sq(t1, meas.at(t1), &mut sim);
    let mut sum = 0.0;
    for n in lo..hi {
        let t = tm[n];
        if t <= t1 || t >= t2 {
            continue;
        }
        let f = sq(t, xm[n], &mut sim);
        sum += 0.5 * (f + f_prev) * (t - t_prev);
        t_prev = t;
        f_prev = f;
    }
    let f = sq(t2, meas.at(t2), &mut sim);
    sum += 0.5 * (f + f_prev) * (t2 - t_prev);
    Ok(sum / (t2 - t1))
}

/// [`objective_f0`] in mm² (for positions in metres).
///
/// # Errors
/// As [`objective_f0`].
pub fn objective_f0_mm2(
    measured: &TimeSeries,
    simulated_t: &[f64],
    simulated_x: &[f64],
    window: (f64, f64),
) -> Result<f64, IdentifyError> {
    Ok(objective_f0(measured, simulated_t, simulated_x, window)? * M2_TO_MM2)
}

/// Linear interpolation on validated, increasing `t` for non-decreasing queries.
struct Interpolator<'a> {
    t: &'a [f64],
    x: &'a [f64],
    k: usize,
    started: bool,
}

impl<'a> Interpolator<'a> {
    fn new(t: &'a [f64], x: &'a [f64]) -> Self {
        Self {
            t,
            x,
            k: 0,
            started: false,
        }
    }

    /// `x(q)` for `t[0] ≤ q ≤ t[last]`; queries must not decrease.
    fn at(&mut self, q: f64) -> f64 {
        let last = self.t.len() - 1;
        if !self.started {
            // First query: jump by bisection, then walk.
            self.k = self.t.partition_point(|&t| t <= q).saturating_sub(1);
            self.started = true;
        }
        while self.k + 1 < last && self.t[self.k + 1] <= q {
            self.k += 1;
        }
        let k = self.k.min(last - 1);
        let (ta, tb) = (self.t[k], self.t[k + 1]);
        let s = (q - ta) / (tb - ta);
        self.x[k] + s * (self.x[k + 1] - self.x[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolator_hits_nodes_and_ends() {
        let t = [0.0, 1.0, 3.0];
        let x = [0.0, 2.0, -2.0];
        let mut i = Interpolator::new(&t, &x);
        assert_eq!(i.at(0.0), 0.0);
        assert_eq!(i.at(0.5), 1.0);
        assert_eq!(i.at(1.0), 2.0);
        assert_eq!(i.at(2.0), 0.0);
        assert_eq!(i.at(3.0), -2.0);
        let mut j = Interpolator::new(&t, &x);
        assert_eq!(j.at(3.0), -2.0);
    }
}
