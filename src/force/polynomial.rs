//! Polynomial springs: the cubic (Duffing) spring and any polynomial stiffness.

use crate::lanes::{LaneMath, Lanes};
use crate::validate::ParameterError;
use crate::validate::finite;
use crate::{ForceLaw, Real};

/// A cubic (Duffing) spring `F = k₁·u + k₃·u³`, `u = x − x₀`.
///
/// Deserialization (feature `serde`) applies the constructors' checks.
///
/// # Model
/// $$F(x, \dot x) = k_1 u + k_3 u^3, \qquad u = x - x_0,\qquad
/// \partial_x F = k_1 + 3 k_3 u^2 .$$
/// Either coefficient may be negative: `k₃ > 0` hardens, `k₃ < 0` softens, `k₁ < 0 < k₃`
/// is the two-well (Holmes) Duffing oscillator; `k₁ = 0, k₃ = 1` is the Ueda oscillator
/// `ẍ + kẋ + x³ = B cos t` (see [`DuffingUeda`](crate::systems::DuffingUeda)).
///
/// # Examples
/// ```
/// use nonsmooth::{ForceLaw, force::CubicSpring};
/// let s = CubicSpring::new(-1.0, 1.0).unwrap();
/// assert_eq!(s.force(2.0, 0.0), -2.0 + 8.0);
/// assert_eq!(s.partials(2.0, 0.0), (-1.0 + 12.0, 0.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CubicSpring<T> {
    k1: T,
    k3: T,
    x0: T,
}

crate::serde_check::deserialize_checked! {
    "CubicSpring", CubicSpring<T: Real> { k1: T, k3: T, x0: T },
    |raw| -> ParameterError { CubicSpring::new(raw.k1, raw.k3)?.with_rest_position(raw.x0)? }
}

impl<T: Real> CubicSpring<T> {
    /// `k1·x + k3·x³` with the rest position at `x = 0`.
    ///
    /// # Errors
    /// [`ParameterError`] if a coefficient is not finite.
    pub fn new(k1: T, k3: T) -> Result<Self, ParameterError> {
        Ok(Self {
            k1: finite("k1", k1)?,
            k3: finite("k3", k3)?,
            x0: T::zero(),
        })
    }

    /// Moves the rest position to `x0`.
    ///
    /// # Errors
    /// [`ParameterError`] if `x0` is not finite.
    pub fn with_rest_position(mut self, x0: T) -> Result<Self, ParameterError> {
        self.x0 = finite("x0", x0)?;
        Ok(self)
    }

    /// `(k₁, k₃)`.
    pub fn coefficients(&self) -> (T, T) {
        (self.k1, self.k3)
    }
}

impl<T: Real> ForceLaw<T> for CubicSpring<T> {
    #[inline(always)]
    fn force(&self, x: T, _v: T) -> T {
        let u = x - self.x0;
        u * (self.k1 + self.k3 * u * u)
    }
    #[inline(always)]
    fn partials(&self, x: T, _v: T) -> (T, T) {
        let u = x - self.x0;
        (self.k1 + (self.k3 + self.k3 + self.k3) * u * u, T::zero())
    }
}

/// A polynomial spring `F = Σ_{i=1}^{D} c_i·u^i`, `u = x − x₀` (Horner evaluation).
///
/// # Model
/// $$F(x,\dot x) = \sum_{i=1}^{D} c_i u^i,\qquad
/// \partial_x F = \sum_{i=1}^{D} i\,c_i u^{i-1} .$$
/// `coefficients[i]` multiplies `u^{i+1}`; there is no constant term (a constant force is
/// an excitation). Without the `serde` derive (a const-generic array); use
/// [`CubicSpring`] for the common cubic case.
///
/// # Examples
/// ```
/// use nonsmooth::{ForceLaw, force::Polynomial};
/// // u + 2u² − u⁵
/// let p = Polynomial::new([1.0, 2.0, 0.0, 0.0, -1.0]).unwrap();
/// assert_eq!(p.force(2.0, 0.0), 2.0 + 8.0 - 32.0);
/// assert_eq!(p.partials(2.0, 0.0).0, 1.0 + 8.0 - 80.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Polynomial<T, const D: usize> {
    c: [T; D],
    x0: T,
}

impl<T: Real, const D: usize> Polynomial<T, D> {
    /// The polynomial with `coefficients[i]` on `u^{i+1}`, rest position `x = 0`.
    ///
    /// # Errors
    /// [`ParameterError`] (`"coefficients"`) if a coefficient is not finite or `D == 0`.
    pub fn new(coefficients: [T; D]) -> Result<Self, ParameterError> {
        if D == 0 {
            return Err(ParameterError::new(
                "coefficients",
                0.0,
                "at least one coefficient",
            ));
        }
        for &c in &coefficients {
            finite("coefficients", c)?;
        }
        Ok(Self {
            c: coefficients,
            x0: T::zero(),
        })
    }

    /// Moves the rest position to `x0`.
    ///
    /// # Errors
    /// [`ParameterError`] if `x0` is not finite.
    pub fn with_rest_position(mut self, x0: T) -> Result<Self, ParameterError> {
        self.x0 = finite("x0", x0)?;
        Ok(self)
    }

    /// The coefficients (`[i]` on `u^{i+1}`).
    pub fn coefficients(&self) -> &[T; D] {
        &self.c
    }
}

impl<T: Real, const D: usize> ForceLaw<T> for Polynomial<T, D> {
    #[inline]
    fn force(&self, x: T, _v: T) -> T {
        let u = x - self.x0;
        // u·(c₁ + u·(c₂ + … + u·c_D))
        let mut acc = T::zero();
        for &c in self.c.iter().rev() {
            acc = acc * u + c;
        }
        acc * u
    }
    #[inline]
    fn partials(&self, x: T, _v: T) -> (T, T) {
        let u = x - self.x0;
        // Σ i·c_i·u^{i−1}, Horner from the top.
        let mut acc = T::zero();
        for (i, &c) in self.c.iter().enumerate().rev() {
            acc = acc * u + c * crate::scalar::lit::<T>((i + 1) as f64);
        }
        (acc, T::zero())
    }
}

impl super::LaneLaw for CubicSpring<f64> {
    /// `(k₁, k₃, x₀)` per lane.
    type Packed<V: Lanes> = [V; 3];
    fn pack<V: Lanes>(&self) -> [V; 3] {
        [self.k1, self.k3, self.x0].map(V::splat)
    }
    fn pack_lane<V: Lanes>(&self, p: &mut [V; 3], lane: usize) {
        for (v, x) in p.iter_mut().zip([self.k1, self.k3, self.x0]) {
            *v = v.with_lane(lane, x);
        }
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &[V; 3], _math: LaneMath, x: V, _v: V) -> V {
        let u = x - p[2];
        u * (p[0] + p[1] * u * u)
    }
}

impl<const D: usize> super::LaneLaw for Polynomial<f64, D> {
    /// The coefficients and `x₀` per lane.
    type Packed<V: Lanes> = ([V; D], V);
    fn pack<V: Lanes>(&self) -> ([V; D], V) {
        (self.c.map(V::splat), V::splat(self.x0))
    }
    fn pack_lane<V: Lanes>(&self, p: &mut ([V; D], V), lane: usize) {
        for (v, &c) in p.0.iter_mut().zip(&self.c) {
            *v = v.with_lane(lane, c);
        }
        p.1 = p.1.with_lane(lane, self.x0);
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &([V; D], V), _math: LaneMath, x: V, _v: V) -> V {
        let u = x - p.1;
        let mut acc = V::splat(0.0);
        for &c in p.0.iter().rev() {
            acc = acc * u + c;
        }
        acc * u
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert!(CubicSpring::new(f64::NAN, 1.0).is_err());
        assert!(CubicSpring::new(1.0, f64::INFINITY).is_err());
        assert!(
            CubicSpring::new(1.0, 1.0)
                .unwrap()
                .with_rest_position(f64::NAN)
                .is_err()
        );
        assert!(Polynomial::<f64, 0>::new([]).is_err());
        assert!(Polynomial::new([1.0, f64::NAN]).is_err());
    }

    #[test]
    fn cubic_equals_the_polynomial_and_partials_match_finite_differences() {
        let c = CubicSpring::new(-0.7_f64, 1.3)
            .unwrap()
            .with_rest_position(0.2)
            .unwrap();
        let p = Polynomial::new([-0.7, 0.0, 1.3])
            .unwrap()
            .with_rest_position(0.2)
            .unwrap();
        for x in [-2.0_f64, -0.3, 0.0, 0.2, 0.9, 3.0] {
            let (a, b) = (c.force(x, 1.0), p.force(x, 1.0));
            assert!((a - b).abs() <= 1e-14 * a.abs().max(1.0), "{x}: {a} {b}");
            let (dc, _) = c.partials(x, 1.0);
            let (dp, _) = p.partials(x, 1.0);
            // A central difference with a fixed step (the default's step is scaled by |x|
            // and too small at x = 0 for a law whose rest position is not 0).
            let h = 1e-5;
            let fd = (c.force(x + h, 1.0) - c.force(x - h, 1.0)) / (2.0 * h);
            assert!((dc - dp).abs() <= 1e-13 * dc.abs().max(1.0));
            assert!(
                (dc - fd).abs() <= 1e-7 * dc.abs().max(1.0),
                "{x}: {dc} {fd}"
            );
        }
        // An explicit value: u = 1.8 → −0.7·1.8 + 1.3·1.8³.
        let u: f64 = 1.8;
        assert!((c.force(2.0, 0.0) - (-0.7 * u + 1.3 * u.powi(3))).abs() < 1e-14);
    }
}
