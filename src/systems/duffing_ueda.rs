//! The Duffing–Ueda oscillator: a damped, harmonically forced cubic spring.
//!
//! # Model
//! $$\ddot x + k\,\dot x + x^3 = B\cos\omega t ,$$
//! a [`Mechanical`] system of one unit mass with the elements
//! [`CubicSpring`]`(0, 1)` and [`ViscousDamper`]`(k)` and a cosine [`Harmonic`] load. The
//! phase-space volume contracts at the constant rate `tr J = −k`, so the Lyapunov exponents
//! of every orbit sum to `−k` exactly — an independent check of any spectrum estimate.
//!
//! # References
//! Y. Ueda, "Randomly transitional phenomena in the system governed by Duffing's
//! equation", *J. Stat. Phys.* 20 (1979) 181–196; the chaotic attractor at `k = 0.05`,
//! `B = 7.5`, `ω = 1` ([`DuffingUeda::default`]) is "Ueda's attractor", whose top
//! Lyapunov exponent is ≈ 0.10 per unit time.

use crate::Real;
use crate::excite::Harmonic;
use crate::force::{CubicSpring, ViscousDamper};
use crate::model::{Element, Load, Mechanical};
use crate::scalar::lit;
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative, positive};

/// The elements of [`DuffingUedaModel`]: cubic spring and damper on `x`.
pub type DuffingUedaElements<T> = Element<T, 1, (CubicSpring<T>, ViscousDamper<T>)>;

/// The assembled model: state `(x, ẋ)`.
pub type DuffingUedaModel<T> = Mechanical<T, 1, DuffingUedaElements<T>, Load<T, 1, Harmonic<T>>>;

/// The parameters of the Duffing–Ueda oscillator `ẍ + kẋ + x³ = B cos ωt`.
///
/// Deserialization (feature `serde`) applies [`validate`](Self::validate).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DuffingUeda {
    /// Damping `k ≥ 0`.
    pub k: f64,
    /// Forcing amplitude `B`.
    pub b: f64,
    /// Forcing frequency `ω > 0`.
    pub omega: f64,
}

crate::serde_check::deserialize_checked! {
    "DuffingUeda", DuffingUeda { k: f64, b: f64, omega: f64 },
    |raw| -> ParameterError {
        raw.validate()?;
        raw
    }
}

impl Default for DuffingUeda {
    /// Ueda's chaotic attractor: `k = 0.05`, `B = 7.5`, `ω = 1`.
    fn default() -> Self {
        Self {
            k: 0.05,
            b: 7.5,
            omega: 1.0,
        }
    }
}

impl DuffingUeda {
    /// `k ≥ 0`, `B` finite, `ω > 0`, all finite.
    ///
    /// # Errors
    /// [`ParameterError`] naming the first invalid parameter.
    pub fn validate(&self) -> Result<(), ParameterError> {
        non_negative("k", self.k)?;
        finite("b", self.b)?;
        positive("omega", self.omega)?;
        Ok(())
    }

    /// The forcing period `2π/ω`.
    pub fn period(&self) -> f64 {
        std::f64::consts::TAU / self.omega
    }

    /// The model in the scalar type `T`.
    ///
    /// # Errors
    /// [`Error::Parameter`](crate::Error::Parameter) for an invalid parameter.
    pub fn model<T: Real>(&self) -> crate::Result<DuffingUedaModel<T>> {
        self.validate()?;
        Ok(Mechanical::with_masses([T::one()])?
            .with_elements(Element::on_dof(
                0,
                (
                    CubicSpring::new(T::zero(), T::one())?,
                    ViscousDamper::new(lit(self.k))?,
                ),
            )?)
            .with_loads(Load::on_dof(
                0,
                Harmonic::cosine(lit(self.b), lit(self.omega))?,
            )?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dynamics;
    use nalgebra::Vector2;

    #[test]
    fn right_hand_side_and_jacobian_by_hand() {
        let p = DuffingUeda::default();
        let m = p.model::<f64>().unwrap();
        let (t, x, v) = (0.7, 1.3, -0.4);
        let y = Vector2::new(x, v);
        let mut dy = Vector2::zeros();
        m.rhs(t, &y, &mut dy);
        let a = 7.5 * t.cos() - 0.05 * v - x * x * x;
        assert_eq!(dy[0], v);
        assert!((dy[1] - a).abs() < 1e-14, "{} vs {a}", dy[1]);
        let j = m.jacobian(t, &y).unwrap();
        assert!((j[(1, 0)] + 3.0 * x * x).abs() < 1e-14);
        assert!((j[(1, 1)] + 0.05).abs() < 1e-15);
        assert!((j.trace() + 0.05).abs() < 1e-15);
    }

    #[test]
    fn validation() {
        for bad in [
            DuffingUeda {
                k: -0.1,
                ..Default::default()
            },
            DuffingUeda {
                b: f64::NAN,
                ..Default::default()
            },
            DuffingUeda {
                omega: 0.0,
                ..Default::default()
            },
        ] {
            assert!(bad.model::<f64>().is_err());
        }
    }
}
