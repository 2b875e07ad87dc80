//! Regularized dry (Coulomb) friction.

use crate::lanes::{LaneMath, Lanes, mask};
use crate::validate::ParameterError;
use crate::validate::{non_negative, normal_square, positive};
use crate::{ForceLaw, Real};

/// How the sign function of Coulomb friction is smoothed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Regularization {
    /// `sgn v ≈ v/√(v²+ε²)`.
    Sqrt,
    /// `sgn v ≈ tanh(v/ε)`.
    Tanh,
}

/// Dry friction of magnitude `T` with a regularized sign function.
///
/// Deserialization (feature `serde`) applies the constructor's checks.
///
/// # Model
/// $$F(\dot x) = T\,\frac{\dot x}{\sqrt{\dot x^2+\varepsilon^2}} \quad\text{(Sqrt)},\qquad
///   F(\dot x) = T\tanh(\dot x/\varepsilon) \quad\text{(Tanh)} .$$
/// Both tend to `T·sgn ẋ` for `|ẋ| ≫ ε`, and both have the slope `T/ε` at `ẋ = 0`: with
/// `T = 0.5 N` and `ε = 10⁻⁶ m/s` that is `5·10⁵ N·s/m`, which makes the equation of motion
/// stiff near every velocity reversal.
///
/// # References
/// The resistance force `F_R` of the impact oscillator of
/// [`systems::paper`](crate::systems::paper) (its eq. (1)) is [`DryFriction::sqrt`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DryFriction<T> {
    t: T,
    eps: T,
    reg: Regularization,
}

crate::serde_check::deserialize_checked! {
    "DryFriction", DryFriction<T: Real> { t: T, eps: T, reg: Regularization },
    |raw| -> ParameterError { DryFriction::new(raw.t, raw.eps, raw.reg)? }
}

impl<T: Real> DryFriction<T> {
    /// Friction of magnitude `t` (N) regularized with `v/√(v²+ε²)`.
    ///
    /// # Errors
    /// [`ParameterError`] if `t < 0`, `eps ≤ 0`, or either is not finite.
    pub fn sqrt(t: T, eps: T) -> Result<Self, ParameterError> {
        Self::new(t, eps, Regularization::Sqrt)
    }

    /// Friction of magnitude `t` (N) regularized with `tanh(v/ε)`.
    ///
    /// # Errors
    /// [`ParameterError`] if `t < 0`, `eps ≤ 0`, or either is not finite.
    pub fn tanh(t: T, eps: T) -> Result<Self, ParameterError> {
        Self::new(t, eps, Regularization::Tanh)
    }

    /// Friction with an explicit regularization.
    ///
    /// # Errors
    /// [`ParameterError`] if `t < 0`, `eps ≤ 0`, either is not finite, `eps²`
    /// underflows (`eps < 1.5·10⁻¹⁵⁴` for `f64`: the force at `v = 0` would be `0/0`) or
    /// overflows, or the slope at `v = 0`, `T/eps`, is not finite.
    pub fn new(t: T, eps: T, reg: Regularization) -> Result<Self, ParameterError> {
        let t = non_negative("T", t)?;
        let eps = normal_square("eps", positive("eps", eps)?)?;
        if !(t / eps).is_finite() {
            return Err(ParameterError::new(
                "eps",
                crate::scalar::to_f64(eps),
                "large enough that the slope T/eps at v = 0 is finite",
            ));
        }
        Ok(Self { t, eps, reg })
    }

    /// The friction magnitude `T`.
    pub fn magnitude(&self) -> T {
        self.t
    }

    /// The regularization velocity `ε`.
    pub fn epsilon(&self) -> T {
        self.eps
    }

    /// The regularization kind.
    pub fn regularization(&self) -> Regularization {
        self.reg
    }
}

impl<T: Real> ForceLaw<T> for DryFriction<T> {
    #[inline(always)]
    fn force(&self, _x: T, v: T) -> T {
        match self.reg {
            Regularization::Sqrt => {
                let s = v * v + self.eps * self.eps;
                let f = self.t * v / s.sqrt();
                if s.is_finite() && f.is_finite() {
                    f
                } else {
                    // `v²` or `T·v` overflowed: `v/hypot(v, ε)` is in [−1, 1].
                    self.t * (v / v.hypot(self.eps))
                }
            }
            Regularization::Tanh => self.t * (v / self.eps).tanh(),
        }
    }

    #[inline(always)]
    fn partials(&self, _x: T, v: T) -> (T, T) {
        let dv = match self.reg {
            Regularization::Sqrt => {
                let e2 = self.eps * self.eps;
                let s = v * v + e2;
                let num = self.t * e2;
                let den = s * s.sqrt();
                let dv = num / den;
                // `T·ε²/s^{3/2}` directly while its parts are normal numbers; otherwise
                // (`s^{3/2}` overflowing or underflowing, `T·ε²` subnormal or 0) the same
                // value as `(T/ε)·(ε/r)³` with `r = hypot(v, ε) ≥ ε`: at most `T/ε`, which
                // the constructor keeps finite.
                let min = crate::scalar::lit::<T>(f64::MIN_POSITIVE);
                if num > min && den > min && den.is_finite() && dv.is_finite() {
                    dv
                } else {
                    let q = self.eps / v.hypot(self.eps);
                    self.t / self.eps * (q * q * q)
                }
            }
            Regularization::Tanh => {
                let th = (v / self.eps).tanh();
                self.t / self.eps * (T::one() - th * th)
            }
        };
        (T::zero(), dv)
    }
}

/// `(T, ε, ε², tanh mask)` per lane.
#[derive(Debug, Clone, Copy)]
pub struct DryFrictionLanes<V> {
    t: V,
    eps: V,
    eps2: V,
    tanh: V,
}

impl super::LaneLaw for DryFriction<f64> {
    type Packed<V: Lanes> = DryFrictionLanes<V>;
    fn pack<V: Lanes>(&self) -> DryFrictionLanes<V> {
        let z = V::splat(0.0);
        let mut p = DryFrictionLanes {
            t: z,
            eps: z,
            eps2: z,
            tanh: z,
        };
        for i in 0..V::LANES {
            self.pack_lane(&mut p, i);
        }
        p
    }
    fn pack_lane<V: Lanes>(&self, p: &mut DryFrictionLanes<V>, lane: usize) {
        p.t = p.t.with_lane(lane, self.t);
        p.eps = p.eps.with_lane(lane, self.eps);
        p.eps2 = p.eps2.with_lane(lane, self.eps * self.eps);
        p.tanh = p
            .tanh
            .with_lane(lane, mask(self.reg == Regularization::Tanh));
    }
    /// The scalar law's operations; its overflow branch (`v/hypot(v, ε)`) and the `tanh`
    /// form are evaluated lane by lane for the lanes that need them.
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &DryFrictionLanes<V>, _math: LaneMath, _x: V, v: V) -> V {
        let s = v * v + p.eps2;
        let mut f = p.t * v / s.sqrt();
        let slow = p.tanh | !(s.finite() & f.finite());
        let bits = slow.bits();
        if bits != 0 {
            for i in 0..V::LANES {
                if bits & (1 << i) != 0 {
                    let (t, eps, vi) = (p.t.lane(i), p.eps.lane(i), v.lane(i));
                    let fi = if p.tanh.lane(i) != 0.0 {
                        t * (vi / eps).tanh()
                    } else {
                        t * (vi / vi.hypot(eps))
                    };
                    f = f.with_lane(i, fi);
                }
            }
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_slope() {
        for f in [
            DryFriction::<f64>::sqrt(0.63133, 1e-6).unwrap(),
            DryFriction::<f64>::tanh(0.63133, 1e-6).unwrap(),
        ] {
            assert!((f.force(0.0, 1.0) - 0.63133).abs() < 1e-9);
            assert!((f.force(0.0, -1.0) + 0.63133).abs() < 1e-9);
            assert_eq!(f.force(0.0, 0.0), 0.0);
            assert!((f.partials(0.0, 0.0).1 - 0.63133e6).abs() < 1e-6);
        }
    }

    #[test]
    fn validation() {
        assert!(DryFriction::sqrt(0.5, 0.0).is_err());
        assert!(DryFriction::sqrt(0.5, -1e-6).is_err());
        assert!(DryFriction::tanh(-0.5, 1e-6).is_err());
        assert!(DryFriction::sqrt(f64::NAN, 1e-6).is_err());
        assert!(DryFriction::sqrt(0.5, f64::INFINITY).is_err());
    }
}
