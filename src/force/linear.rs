//! Linear spring and viscous damper.

use crate::lanes::{LaneMath, Lanes};
use crate::validate::ParameterError;
use crate::validate::non_negative;
use crate::{ForceLaw, Real};

/// A linear spring `F = k·(x − x₀)`.
///
/// Deserialization (feature `serde`) applies the constructors' checks.
///
/// # Model
/// $$F(x, \dot x) = k\,(x - x_0), \qquad k \ge 0 .$$
///
/// # Examples
/// ```
/// use nonsmooth::{ForceLaw, force::LinearSpring};
/// let s = LinearSpring::new(1418.9).unwrap();
/// assert_eq!(s.force(1e-3, 5.0), 1.4189);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LinearSpring<T> {
    k: T,
    x0: T,
}

crate::serde_check::deserialize_checked! {
    "LinearSpring", LinearSpring<T: Real> { k: T, x0: T },
    |raw| -> ParameterError { LinearSpring::new(raw.k)?.with_rest_position(raw.x0)? }
}

impl<T: Real> LinearSpring<T> {
    /// A spring of stiffness `k` (N/m) with its rest position at `x = 0`.
    ///
    /// # Errors
    /// [`ParameterError`] if `k` is negative or not finite.
    pub fn new(k: T) -> Result<Self, ParameterError> {
        Ok(Self {
            k: non_negative("k", k)?,
            x0: T::zero(),
        })
    }

    /// Moves the rest position to `x0`.
    ///
    /// # Errors
    /// [`ParameterError`] if `x0` is not finite.
    pub fn with_rest_position(mut self, x0: T) -> Result<Self, ParameterError> {
        self.x0 = crate::validate::finite("x0", x0)?;
        Ok(self)
    }

    /// The stiffness `k`.
    pub fn stiffness(&self) -> T {
        self.k
    }
}

impl<T: Real> ForceLaw<T> for LinearSpring<T> {
    #[inline(always)]
    fn force(&self, x: T, _v: T) -> T {
        self.k * (x - self.x0)
    }
    #[inline(always)]
    fn partials(&self, _x: T, _v: T) -> (T, T) {
        (self.k, T::zero())
    }
}

/// A linear viscous damper `F = c·ẋ`.
///
/// Deserialization (feature `serde`) applies the constructor's checks.
///
/// # Model
/// $$F(x, \dot x) = c\,\dot x, \qquad c \ge 0 .$$
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ViscousDamper<T> {
    c: T,
}

crate::serde_check::deserialize_checked! {
    "ViscousDamper", ViscousDamper<T: Real> { c: T },
    |raw| -> ParameterError { ViscousDamper::new(raw.c)? }
}

impl<T: Real> ViscousDamper<T> {
    /// A damper with coefficient `c` (N·s/m).
    ///
    /// # Errors
    /// [`ParameterError`] if `c` is negative or not finite.
    pub fn new(c: T) -> Result<Self, ParameterError> {
        Ok(Self {
            c: non_negative("c", c)?,
        })
    }

    /// The damping coefficient `c`.
    pub fn coefficient(&self) -> T {
        self.c
    }
}

impl<T: Real> ForceLaw<T> for ViscousDamper<T> {
    #[inline(always)]
    fn force(&self, _x: T, v: T) -> T {
        self.c * v
    }
    #[inline(always)]
    fn partials(&self, _x: T, _v: T) -> (T, T) {
        (T::zero(), self.c)
    }
}

impl super::LaneLaw for LinearSpring<f64> {
    /// `(k, x0)` per lane.
    type Packed<V: Lanes> = (V, V);
    fn pack<V: Lanes>(&self) -> (V, V) {
        (V::splat(self.k), V::splat(self.x0))
    }
    fn pack_lane<V: Lanes>(&self, p: &mut (V, V), lane: usize) {
        p.0 = p.0.with_lane(lane, self.k);
        p.1 = p.1.with_lane(lane, self.x0);
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &(V, V), _math: LaneMath, x: V, _v: V) -> V {
        p.0 * (x - p.1)
    }
}

impl super::LaneLaw for ViscousDamper<f64> {
    /// `c` per lane.
    type Packed<V: Lanes> = V;
    fn pack<V: Lanes>(&self) -> V {
        V::splat(self.c)
    }
    fn pack_lane<V: Lanes>(&self, p: &mut V, lane: usize) {
        *p = p.with_lane(lane, self.c);
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &V, _math: LaneMath, _x: V, v: V) -> V {
        *p * v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert!(LinearSpring::new(-1.0).is_err());
        assert!(LinearSpring::new(f64::NAN).is_err());
        assert!(LinearSpring::new(f64::INFINITY).is_err());
        assert!(ViscousDamper::new(-0.1).is_err());
        assert!(ViscousDamper::new(f64::NAN).is_err());
        assert!(
            LinearSpring::new(1.0)
                .unwrap()
                .with_rest_position(f64::NAN)
                .is_err()
        );
        let e = LinearSpring::new(-2.0).unwrap_err();
        assert!(e.to_string().contains("`k`"), "{e}");
    }

    #[test]
    fn values_f32() {
        let s = LinearSpring::new(2.0_f32)
            .unwrap()
            .with_rest_position(1.0)
            .unwrap();
        assert_eq!(s.force(3.0, 0.0), 4.0);
        assert_eq!(ViscousDamper::new(3.0_f32).unwrap().force(0.0, 2.0), 6.0);
    }
}
