//! The first-order low-pass filter `(θs + 1)^{-1}`.

use super::{Location, SignalError, validate_samples};
use crate::Real;
use crate::scalar::{lit, to_f64};
use crate::validate::positive;

/// The filter's state before the first sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum InitialState<T> {
    /// `y_0 = u_0`: the filter starts settled on the first input sample (no start-up
    /// transient). The default, right for measured records that start mid-motion.
    #[default]
    FirstSample,
    /// `y_0 = 0`: the filter starts at rest (the textbook step response).
    Zero,
    /// `y_0` given.
    Value(T),
}

/// The first-order low-pass filter with transfer function `1/(θs + 1)`, the smoothing of a
/// measured position (the paper's choice of `θ` is
/// [`systems::paper::low_pass`](crate::systems::paper::low_pass)).
///
/// Deserialization (feature `serde`) applies the constructor's check of `θ`.
///
/// # Formula
/// The filter is the ODE `θ·ẏ = u − y`. Holding the input constant over each sample interval
/// (zero-order hold, `u(t) = u_n` on `[t_n, t_{n+1})`) the ODE is solved exactly:
/// $$ y_{n+1} = a_n\,y_n + (1 - a_n)\,u_n, \qquad a_n = e^{-h_n/\theta},
///    \quad h_n = t_{n+1} - t_n . $$
/// Each step uses its own `h_n`, so non-uniform sampling is handled exactly (under the
/// zero-order-hold assumption). The update is evaluated as `y_n + b_n·(u_n − y_n)` with
/// `b_n = 1 − a_n = −expm1(−h_n/θ)` (no cancellation for `h ≪ θ`, and a constant input is
/// reproduced exactly); for steps within a relative jitter `|h_n − h_ref|/θ ≤ 10⁻⁴` of
/// the last step for which `expm1` was evaluated, `b_n` follows from a cubic Taylor
/// correction (error below `5·10⁻¹⁸`), so a nominally uniform grid costs one `expm1` in all.
/// Output sample `y_n` is the filter state at `t_n`, before input `u_n` acts.
///
/// For a unit step input (`u_n = 1`, state [`InitialState::Zero`]) the output is therefore
/// exactly `y_n = 1 − e^{−(t_n − t_0)/θ}` at every sample point, whatever the sampling —
/// the discretization introduces no error for piecewise-constant inputs.
///
/// # Examples
/// ```
/// use nonsmooth::signal::{InitialState, LowPass};
/// let t = [0.0_f64, 0.5e-3, 1.0e-3, 2.5e-3];
/// let u = [1.0; 4];
/// let y = LowPass::new(1e-3)?.with_initial(InitialState::Zero).filter(&t, &u)?;
/// for (yi, ti) in y.iter().zip(&t) {
///     assert!((yi - (1.0 - (-ti / 1e-3_f64).exp())).abs() < 1e-15);
/// }
/// # Ok::<(), nonsmooth::signal::SignalError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LowPass<T> {
    theta: T,
    initial: InitialState<T>,
}

crate::serde_check::deserialize_checked! {
    "LowPass", LowPass<T: Real> { theta: T, initial: InitialState<T> },
    |raw| -> SignalError { LowPass::new(raw.theta)?.with_initial(raw.initial) }
}

impl<T: Real> LowPass<T> {
    /// A filter with time constant `theta` (seconds) starting at
    /// [`InitialState::FirstSample`].
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `theta` is finite and `> 0`.
    pub fn new(theta: T) -> Result<Self, SignalError> {
        Ok(Self {
            theta: positive("theta", theta)?,
            initial: InitialState::FirstSample,
        })
    }

    /// Sets the initial state.
    #[must_use]
    pub fn with_initial(mut self, initial: InitialState<T>) -> Self {
        self.initial = initial;
        self
    }

    /// The time constant `θ`.
    pub fn theta(&self) -> T {
        self.theta
    }

    /// The initial-state rule.
    pub fn initial(&self) -> InitialState<T> {
        self.initial
    }

    /// One exact step of length `h` from state `y` with held input `u`:
    /// `e^{−h/θ}·y + (1 − e^{−h/θ})·u`, evaluated as `y − expm1(−h/θ)·(u − y)` (for
    /// streaming use; no validation).
    #[inline]
    pub fn advance(&self, y: T, u: T, h: T) -> T {
        blend(y, u, -(-h / self.theta).exp_m1())
    }

    fn initial_value(&self, u0: T) -> Result<T, SignalError> {
        match self.initial {
            InitialState::FirstSample => Ok(u0),
            InitialState::Zero => Ok(T::zero()),
            InitialState::Value(v) if v.is_finite() => Ok(v),
            InitialState::Value(v) => Err(SignalError::NonFinite {
                location: Location::Sample(0),
                what: "initial filter state".into(),
                value: to_f64(v),
            }),
        }
    }

    /// Filters `u` sampled at times `t` in place (`u` is overwritten by `y`).
    ///
    /// The data are validated before anything is written, so on error `u` is unchanged.
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`] if the lengths differ, [`SignalError::TooFewSamples`]
    /// for an empty input, [`SignalError::NonIncreasingTime`] / [`SignalError::NonFinite`]
    /// (with the sample index) for bad times or values, or a non-finite
    /// [`InitialState::Value`].
    pub fn filter_inplace(&self, t: &[T], u: &mut [T]) -> Result<(), SignalError> {
        validate_samples(t, u, "x", 1)?;
        let y0 = self.initial_value(u[0])?;
        self.apply(t, u, y0);
        Ok(())
    }

    /// The recursion on validated data (`t.len() == u.len() ≥ 1`).
    fn apply(&self, t: &[T], u: &mut [T], y0: T) {
        let inv_theta = T::one() / self.theta;
        // Factors for a reference step; steps that differ from it by a relative jitter
        // |d| ≤ 1e-4 (d = (h − h_ref)/θ, e.g. rounding of t = i·h) are corrected by the
        // cubic Taylor polynomial of 1 − e^{−d} (error ≤ d⁴/24 < 5e-18) instead of a new exp.
        let gain = |h: T| -(-h * inv_theta).exp_m1();
        let tol: T = lit(1e-4);
        let (half, sixth): (T, T) = (lit(0.5), lit(1.0 / 6.0));
        let mut h_ref = if t.len() > 1 { t[1] - t[0] } else { T::zero() };
        let mut b_ref = gain(h_ref);
        let mut y = y0;
        let mut t_prev = t[0];
        // u[n] is replaced by y[n]; y[n+1] needs the *input* u[n], read before overwrite.
        let mut u_prev = u[0];
        u[0] = y;
        for n in 1..u.len() {
            let h = t[n] - t_prev;
            let d = (h - h_ref) * inv_theta;
            let b = if d.abs() <= tol {
                // 1 − e^{−h/θ} = b_ref + (1 − b_ref)(1 − e^{−d}),  1 − e^{−d} ≈ d − d²/2 + d³/6.
                let c = d * (T::one() - d * (half - d * sixth));
                b_ref + (T::one() - b_ref) * c
            } else {
                h_ref = h;
                b_ref = gain(h);
                b_ref
            };
            y = blend(y, u_prev, b);
            u_prev = u[n];
            u[n] = y;
            t_prev = t[n];
        }
    }

    /// Filters `u` sampled at `t` into `out` (resized to `u.len()`).
    ///
    /// # Errors
    /// As [`filter_inplace`](Self::filter_inplace).
    pub fn filter_into(&self, t: &[T], u: &[T], out: &mut Vec<T>) -> Result<(), SignalError> {
        validate_samples(t, u, "x", 1)?;
        let y0 = self.initial_value(u[0])?;
        out.clear();
        out.extend_from_slice(u);
        self.apply(t, out, y0);
        Ok(())
    }

    /// Filters `u` sampled at `t`, returning a new vector.
    ///
    /// # Errors
    /// As [`filter_inplace`](Self::filter_inplace).
    pub fn filter(&self, t: &[T], u: &[T]) -> Result<Vec<T>, SignalError> {
        let mut out = Vec::with_capacity(u.len());
        self.filter_into(t, u, &mut out)?;
        Ok(out)
    }
}

/// `y + b·(u − y)` for `b ∈ [0, 1]`: leaves a constant input exactly unchanged. When
/// `u − y` overflows (finite values of opposite sign near the range's end) the convex
/// combination `(1 − b)·y + b·u` is used instead, clamped to `[min(y, u), max(y, u)]`
/// where the exact value lies, so finite inputs never give an infinite output.
#[inline]
fn blend<T: Real>(y: T, u: T, b: T) -> T {
    let d = u - y;
    if d.is_finite() {
        y + b * d
    } else {
        let (lo, hi) = if y < u { (y, u) } else { (u, y) };
        ((T::one() - b) * y + b * u).max(lo).min(hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opposite_extremes_stay_finite() {
        // u − y overflows: the output must stay finite and between the inputs.
        let t = [0.0_f64, 1e-3, 2e-3, 3e-3];
        let u = [1.7e308, -1.7e308, f64::MAX, -f64::MAX];
        for init in [InitialState::FirstSample, InitialState::Zero] {
            let y = LowPass::new(1e-3)
                .unwrap()
                .with_initial(init)
                .filter(&t, &u)
                .unwrap();
            assert!(
                y.iter().all(|v| v.is_finite() && v.abs() <= f64::MAX),
                "{y:?}"
            );
        }
        let f = LowPass::new(1e-3_f64).unwrap();
        let y = f.advance(-f64::MAX, f64::MAX, 1e-3);
        // e^{-1}·(−M) + (1 − e^{-1})·M = (1 − 2e^{-1})·M.
        let exact = (1.0 - 2.0 * (-1.0_f64).exp()) * f64::MAX;
        assert!((y - exact).abs() <= 1e-15 * f64::MAX, "{y} vs {exact}");
    }

    #[test]
    fn rejects_bad_theta() {
        assert!(LowPass::new(0.0_f64).is_err());
        assert!(LowPass::new(-1.0_f64).is_err());
        assert!(LowPass::new(f64::NAN).is_err());
        assert_eq!(LowPass::new(1e-3_f64).unwrap().theta(), 1e-3);
    }

    #[test]
    fn first_sample_start_keeps_a_constant() {
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 1e-4).collect();
        let y = LowPass::new(1e-3).unwrap().filter(&t, &[3.25; 50]).unwrap();
        assert!(y.iter().all(|&v| v == 3.25));
    }

    #[test]
    fn step_response_nonuniform_f32() {
        let t = [0.0_f32, 1e-4, 3e-4, 3.5e-4, 1e-3, 4e-3];
        let f = LowPass::new(1e-3_f32)
            .unwrap()
            .with_initial(InitialState::Zero);
        let y = f.filter(&t, &[1.0; 6]).unwrap();
        for (yi, ti) in y.iter().zip(&t) {
            assert!((yi - (1.0 - (-ti / 1e-3).exp())).abs() < 1e-6);
        }
    }

    #[test]
    fn initial_value_is_used() {
        let t = [0.0, 1e-3];
        let f = LowPass::new(1e-3)
            .unwrap()
            .with_initial(InitialState::Value(2.0));
        let y = f.filter(&t, &[0.0, 0.0]).unwrap();
        assert_eq!(y[0], 2.0);
        assert!((y[1] - 2.0 * (-1.0_f64).exp()).abs() < 1e-15);
        let bad = f.with_initial(InitialState::Value(f64::INFINITY));
        assert!(bad.filter(&t, &[0.0, 0.0]).is_err());
    }

    #[test]
    fn error_leaves_input_untouched() {
        let mut u = [1.0, 2.0, 3.0];
        let err = LowPass::new(1.0)
            .unwrap()
            .filter_inplace(&[0.0, 2.0, 1.0], &mut u)
            .unwrap_err();
        assert!(matches!(
            err,
            SignalError::NonIncreasingTime {
                location: Location::Sample(2),
                ..
            }
        ));
        assert_eq!(u, [1.0, 2.0, 3.0]);
    }
}
