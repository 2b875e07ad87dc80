//! A two-degree-of-freedom impact oscillator: a forced primary mass carrying a secondary
//! mass that hits a compliant one-sided stop.
//!
//! # Model
//! $$\begin{aligned}
//! m_1\ddot q_1 + c_1\dot q_1 + k_1 q_1 - c_2(\dot q_2-\dot q_1) - k_2(q_2-q_1) &= F\cos\omega t,\\
//! m_2\ddot q_2 + c_2(\dot q_2-\dot q_1) + k_2(q_2-q_1) + F_c(q_2, \dot q_2) &= 0,
//! \end{aligned}$$
//! with the Hertz stop `F_c = k_c[δ^{3/2} + b·δ^{3/2}·δ̇]⁺`, `δ = q_2 − d`, on the secondary
//! mass at the gap `d` above its rest position. Assembled from the crate's parts: a
//! [`Mechanical`] system with the elements `(k1, c1)` on `q_1`, `(k2, c2)` on `q_2 − q_1` and
//! the contact on `q_2`, and a cosine [`Harmonic`] load on `q_1`; impacts are the rising
//! crossings of the [`Gap`] `q_2 − d`.
//!
//! # References
//! The configuration (primary system with an attached impacting secondary mass, forced
//! harmonically) is the classical 2-DOF impact oscillator of the impact-damper literature
//! (e.g. A. C. J. Luo, J. H. Xie, *Chaos* 12 (2002) 1039–1047, with a rigid stop; D. J. Wagg,
//! *J. Sound Vib.* 275 (2004) 517–541). Here the stop is compliant (Hertz with
//! Hunt–Crossley damping) and the parameter set [`TwoDofImpact::default`] is this crate's
//! nondimensional illustration, not taken from either paper.

use crate::Real;
use crate::event::Gap;
use crate::excite::Harmonic;
use crate::force::{HertzContact, LinearSpring, ViscousDamper};
use crate::model::{Coordinate, Element, Load, Mechanical};
use crate::scalar::lit;
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative, positive};

/// The elements of [`TwoDofImpactModel`]: primary suspension, coupling, stop.
pub type TwoDofElements<T> = (
    Element<T, 2, (LinearSpring<T>, ViscousDamper<T>)>,
    Element<T, 2, (LinearSpring<T>, ViscousDamper<T>)>,
    Element<T, 2, HertzContact<T>>,
);

/// The assembled model: state `(q_1, q_2, q̇_1, q̇_2)`.
pub type TwoDofImpactModel<T> = Mechanical<T, 2, TwoDofElements<T>, Load<T, 2, Harmonic<T>>>;

/// The parameters of the 2-DOF impact oscillator (nondimensional).
///
/// Deserialization (feature `serde`) applies [`validate`](Self::validate).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TwoDofImpact {
    /// Primary mass `m_1`.
    pub m1: f64,
    /// Secondary mass `m_2`.
    pub m2: f64,
    /// Primary stiffness `k_1` (to the ground).
    pub k1: f64,
    /// Coupling stiffness `k_2`.
    pub k2: f64,
    /// Primary damping `c_1`.
    pub c1: f64,
    /// Coupling damping `c_2`.
    pub c2: f64,
    /// Forcing amplitude `F` on the primary mass.
    pub force: f64,
    /// Gap `d` between the secondary mass at rest and the stop.
    pub gap: f64,
    /// Contact stiffness `k_c` (force per length^{3/2}).
    pub k_contact: f64,
    /// Contact damping `b` (Hunt–Crossley, per velocity).
    pub b_contact: f64,
}

crate::serde_check::deserialize_checked! {
    "TwoDofImpact",
    TwoDofImpact {
        m1: f64,
        m2: f64,
        k1: f64,
        k2: f64,
        c1: f64,
        c2: f64,
        force: f64,
        gap: f64,
        k_contact: f64,
        b_contact: f64,
    },
    |raw| -> ParameterError {
        raw.validate()?;
        raw
    }
}

impl Default for TwoDofImpact {
    /// `m1 = 1, m2 = 0.5, k1 = 1, k2 = 0.5, c1 = c2 = 0.05, F = 0.1, d = 0.2,
    /// k_c = 10³, b = 0.2`: a primary resonance near ω ≈ 0.7 and impacts of the secondary
    /// mass on a band of forcing frequencies around it.
    fn default() -> Self {
        Self {
            m1: 1.0,
            m2: 0.5,
            k1: 1.0,
            k2: 0.5,
            c1: 0.05,
            c2: 0.05,
            force: 0.1,
            gap: 0.2,
            k_contact: 1e3,
            b_contact: 0.2,
        }
    }
}

impl TwoDofImpact {
    /// Checks every parameter (masses, stiffnesses, contact stiffness finite and > 0;
    /// dampings and contact damping ≥ 0; force and gap finite).
    ///
    /// # Errors
    /// [`ParameterError`] naming the first invalid parameter.
    pub fn validate(&self) -> Result<(), ParameterError> {
        positive("m1", self.m1)?;
        positive("m2", self.m2)?;
        positive("k1", self.k1)?;
        positive("k2", self.k2)?;
        non_negative("c1", self.c1)?;
        non_negative("c2", self.c2)?;
        finite("force", self.force)?;
        finite("gap", self.gap)?;
        positive("k_contact", self.k_contact)?;
        non_negative("b_contact", self.b_contact)?;
        Ok(())
    }

    /// The model forced at `omega` (`F·cos ωt` on the primary mass).
    ///
    /// # Errors
    /// [`Error::Parameter`](crate::Error::Parameter) for an invalid parameter or `omega`.
    pub fn model<T: Real>(&self, omega: T) -> crate::Result<TwoDofImpactModel<T>> {
        self.validate()?;
        let contact = HertzContact::new(lit::<T>(self.gap), lit(self.k_contact))?.with_damping(
            lit(self.b_contact),
            lit(1.5),
            T::one(),
        )?;
        Ok(Mechanical::with_masses([lit(self.m1), lit(self.m2)])?
            .with_elements((
                Element::on_dof(
                    0,
                    (
                        LinearSpring::new(lit(self.k1))?,
                        ViscousDamper::new(lit(self.c1))?,
                    ),
                )?,
                Element::between(
                    1,
                    0,
                    (
                        LinearSpring::new(lit(self.k2))?,
                        ViscousDamper::new(lit(self.c2))?,
                    ),
                )?,
                Element::on_dof(1, contact)?,
            ))
            .with_loads(Load::on_dof(0, Harmonic::cosine(lit(self.force), omega)?)?))
    }

    /// The stop as a contact surface for events and samplers: the penetration `q_2 − d`
    /// (impacts are its rising crossings).
    ///
    /// # Errors
    /// [`Error::Parameter`](crate::Error::Parameter) if the gap is not finite.
    pub fn stop<T: Real>(&self) -> Result<Gap<T, 2>, crate::Error> {
        let c = Coordinate::dof(1).map_err(crate::Error::from)?;
        Ok(Gap::below(c.with_offset(-lit::<T>(self.gap))?, ()))
    }

    /// The forcing period `2π/ω`.
    pub fn period(omega: f64) -> f64 {
        std::f64::consts::TAU / omega
    }
}
