//! Piecewise-linear stiffness with a gap: backlash (dead zone) and bilinear stops.

use crate::lanes::{LaneMath, Lanes};
use crate::validate::ParameterError;
use crate::validate::non_negative;
use crate::{ForceLaw, Real};

/// A continuous piecewise-linear spring: stiffness `k_in` on `[lo, hi]` and `k_in + k_out`
/// outside.
///
/// Deserialization (feature `serde`) applies the constructor's checks, `lo ≤ hi` included.
///
/// # Model
/// $$F(x,\dot x) = k_{in}\,x + k_{out}\big[(x - x_{hi})^+ - (x_{lo} - x)^+\big],$$
/// with `(·)⁺ = max(·, 0)`. Special cases:
/// - [`backlash`](Bilinear::backlash)`(k, b)`: `k_in = 0`, `[lo, hi] = [−b, b]` — the dead
///   zone of a gear pair or a clearance joint with total free play `2b`;
/// - [`one_sided`](Bilinear::one_sided)`(k, k_s, d)`: a spring `k` plus a linear stop `k_s`
///   engaging at `x = d` (`lo = −∞`), the classical bilinear impact oscillator.
///
/// The force is continuous; `∂F/∂x` jumps at `lo` and `hi`. At a kink the partial is the
/// one of the inner piece (`k_in`): the Jacobian is then exact on both sides except on the
/// kink itself, which a trajectory crosses in measure zero.
///
/// # Examples
/// ```
/// use nonsmooth::{ForceLaw, force::Bilinear};
/// let gear = Bilinear::backlash(2.0_f64, 0.1).unwrap();
/// assert_eq!(gear.force(0.05, 0.0), 0.0);
/// assert!((gear.force(0.3, 0.0) - 0.4).abs() < 1e-15);
/// assert!((gear.force(-0.3, 0.0) + 0.4).abs() < 1e-15);
/// let stop = Bilinear::one_sided(1.0, 9.0, 0.5).unwrap();
/// assert_eq!(stop.force(-4.0, 0.0), -4.0);
/// assert_eq!(stop.force(1.0, 0.0), 1.0 + 9.0 * 0.5);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Bilinear<T> {
    k_in: T,
    k_out: T,
    lo: T,
    hi: T,
}

crate::serde_check::deserialize_checked! {
    "Bilinear", Bilinear<T: Real> { k_in: T, k_out: T, lo: T, hi: T },
    |raw| -> ParameterError { Bilinear::new(raw.k_in, raw.k_out, raw.lo, raw.hi)? }
}

impl<T: Real> Bilinear<T> {
    /// Stiffness `k_in` on `[lo, hi]`, `k_in + k_out` outside. `lo` may be `−∞` and `hi`
    /// `+∞` (no kink on that side).
    ///
    /// # Errors
    /// [`ParameterError`] unless `k_in, k_out` are finite and ≥ 0 and `lo ≤ hi` with
    /// `lo < +∞`, `hi > −∞` (neither NaN).
    pub fn new(k_in: T, k_out: T, lo: T, hi: T) -> Result<Self, ParameterError> {
        let k_in = non_negative("k_in", k_in)?;
        let k_out = non_negative("k_out", k_out)?;
        if !(lo <= hi) || !(lo.is_finite() || lo < T::zero()) {
            return Err(ParameterError::new(
                "lo",
                crate::scalar::to_f64(lo),
                "not NaN, < +inf and <= hi",
            ));
        }
        if !(hi.is_finite() || hi > T::zero()) {
            return Err(ParameterError::new(
                "hi",
                crate::scalar::to_f64(hi),
                "not NaN, > -inf and >= lo",
            ));
        }
        Ok(Self {
            k_in,
            k_out,
            lo,
            hi,
        })
    }

    /// A dead zone of half-width `b ≥ 0` with stiffness `k` on contact:
    /// `F = k·(x − b)` for `x > b`, `0` on `[−b, b]`, `k·(x + b)` for `x < −b`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `k` and `b` are finite and ≥ 0.
    pub fn backlash(k: T, b: T) -> Result<Self, ParameterError> {
        let b = non_negative("b", b)?;
        Self::new(T::zero(), k, -b, b)
    }

    /// A spring `k` with a linear stop of stiffness `k_stop` engaging at `x = d`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `k, k_stop ≥ 0` and `d` are finite.
    pub fn one_sided(k: T, k_stop: T, d: T) -> Result<Self, ParameterError> {
        let d = crate::validate::finite("d", d)?;
        let minus_infinity = -(T::one() / T::zero());
        Self::new(k, k_stop, minus_infinity, d)
    }

    /// `(k_in, k_out, lo, hi)`.
    pub fn parameters(&self) -> (T, T, T, T) {
        (self.k_in, self.k_out, self.lo, self.hi)
    }
}

impl<T: Real> ForceLaw<T> for Bilinear<T> {
    #[inline(always)]
    fn force(&self, x: T, _v: T) -> T {
        let above = x - self.hi;
        let below = self.lo - x;
        let mut f = self.k_in * x;
        if above > T::zero() {
            f += self.k_out * above;
        } else if below > T::zero() {
            f -= self.k_out * below;
        }
        f
    }
    #[inline(always)]
    fn partials(&self, x: T, _v: T) -> (T, T) {
        if x > self.hi || x < self.lo {
            (self.k_in + self.k_out, T::zero())
        } else {
            (self.k_in, T::zero())
        }
    }
}

impl super::LaneLaw for Bilinear<f64> {
    /// `(k_in, k_out, lo, hi)` per lane.
    type Packed<V: Lanes> = [V; 4];
    fn pack<V: Lanes>(&self) -> [V; 4] {
        [self.k_in, self.k_out, self.lo, self.hi].map(V::splat)
    }
    fn pack_lane<V: Lanes>(&self, p: &mut [V; 4], lane: usize) {
        for (v, x) in p.iter_mut().zip([self.k_in, self.k_out, self.lo, self.hi]) {
            *v = v.with_lane(lane, x);
        }
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &[V; 4], _math: LaneMath, x: V, _v: V) -> V {
        let [k_in, k_out, lo, hi] = *p;
        let zero = V::splat(0.0);
        let above = x - hi;
        let below = lo - x;
        let f = k_in * x;
        // The scalar branches: above the upper limit, else below the lower one.
        let up = above.gt(zero);
        let down = !up & below.gt(zero);
        let f = up.select(f + k_out * above, f);
        down.select(f - k_out * below, f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::finite_difference_partials;

    #[test]
    fn validation() {
        assert!(Bilinear::new(-1.0, 1.0, -1.0, 1.0).is_err());
        assert!(Bilinear::new(1.0, f64::NAN, -1.0, 1.0).is_err());
        assert!(Bilinear::new(1.0, 1.0, 1.0, -1.0).is_err());
        assert!(Bilinear::new(1.0, 1.0, f64::NAN, 1.0).is_err());
        assert!(Bilinear::new(1.0, 1.0, f64::INFINITY, f64::INFINITY).is_err());
        assert!(Bilinear::new(1.0, 1.0, f64::NEG_INFINITY, f64::NEG_INFINITY).is_err());
        assert!(Bilinear::new(1.0, 1.0, f64::NEG_INFINITY, f64::INFINITY).is_ok());
        assert!(Bilinear::backlash(1.0, -0.1).is_err());
        assert!(Bilinear::one_sided(1.0, 1.0, f64::NAN).is_err());
    }

    #[test]
    fn continuous_odd_and_finite_everywhere() {
        let g = Bilinear::backlash(3.0_f64, 0.25).unwrap();
        let s = Bilinear::one_sided(1.0, 4.0, 0.5).unwrap();
        for law in [g, s] {
            for &k in &[law.lo, law.hi] {
                if k.is_finite() {
                    let (a, b) = (law.force(k - 1e-12, 0.0), law.force(k + 1e-12, 0.0));
                    assert!((a - b).abs() < 1e-10, "jump at {k}: {a} {b}");
                }
            }
            for x in [-1e300_f64, -2.0, -0.1, 0.0, 0.3, 2.0, 1e300] {
                assert!(law.force(x, 0.0).is_finite() || x.abs() > 1e299, "{x}");
                assert!(!law.force(x, 0.0).is_nan());
                // Away from the kinks the analytic partial matches finite differences.
                let (d, _) = law.partials(x, 0.0);
                if x.abs() < 10.0 {
                    let (fd, _) = finite_difference_partials(&law, x, 0.0);
                    assert!((d - fd).abs() < 1e-6, "{x}: {d} {fd}");
                }
            }
        }
        // The dead zone is odd and zero inside.
        for x in [0.0_f64, 0.1, 0.25, 0.7, 3.0] {
            assert_eq!(g.force(x, 0.0), -g.force(-x, 0.0));
        }
        assert_eq!(g.force(0.2, 0.0), 0.0);
        assert_eq!(s.partials(-1e6, 0.0).0, 1.0);
        assert_eq!(s.partials(1.0, 0.0).0, 5.0);
    }
}
