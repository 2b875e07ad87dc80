//! Catalogue systems written out by hand, as independent checks of the element assembly.

use nalgebra::SVector;

use crate::Dynamics;
use crate::systems::TwoDofImpact;

/// The 2-DOF impact oscillator of [`TwoDofImpact`] with its right-hand side written out by
/// hand (relative coordinates, signs and the Hertz–Hunt–Crossley stop spelled explicitly,
/// `F·cos ωt` with libm's `cos`), to check [`TwoDofImpact::model`] against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoDofImpactByHand {
    /// The parameters.
    pub params: TwoDofImpact,
    /// The forcing frequency.
    pub omega: f64,
}

impl Dynamics<f64, 4> for TwoDofImpactByHand {
    fn rhs(&self, t: f64, y: &SVector<f64, 4>, dy: &mut SVector<f64, 4>) {
        let p = &self.params;
        let (q1, q2, v1, v2) = (y[0], y[1], y[2], y[3]);
        let coupling = p.k2 * (q2 - q1) + p.c2 * (v2 - v1);
        let d = q2 - p.gap;
        let contact = if d >= 0.0 {
            let f = p.k_contact * (d * d.sqrt() + p.b_contact * d * d.sqrt() * v2);
            f.max(0.0)
        } else {
            0.0
        };
        dy[0] = v1;
        dy[1] = v2;
        dy[2] = (p.force * (self.omega * t).cos() - p.k1 * q1 - p.c1 * v1 + coupling) / p.m1;
        dy[3] = (-coupling - contact) / p.m2;
    }
}

/// The Duffing–Ueda oscillator `ẍ + kẋ + x³ = B cos ωt` written out by hand, with its
/// Jacobian (an independent reference for [`DuffingUeda`](crate::systems::DuffingUeda)'s
/// assembled model).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DuffingUedaByHand {
    /// The parameters.
    pub params: crate::systems::DuffingUeda,
}

impl Dynamics<f64, 2> for DuffingUedaByHand {
    fn rhs(&self, t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
        let p = &self.params;
        let (x, v) = (y[0], y[1]);
        dy[0] = v;
        dy[1] = p.b * (p.omega * t).cos() - p.k * v - x * x * x;
    }

    fn jacobian(&self, _t: f64, y: &SVector<f64, 2>) -> Option<nalgebra::SMatrix<f64, 2, 2>> {
        Some(nalgebra::SMatrix::<f64, 2, 2>::new(
            0.0,
            1.0,
            -3.0 * y[0] * y[0],
            -self.params.k,
        ))
    }
}
