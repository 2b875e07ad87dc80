//! Glocker's woodpecker toy: a sleeve with a little play around a pole, a bird on a
//! rotational spring, impacts of the sleeve's edges and of the beak on the pole, Coulomb
//! friction at all three contacts — a classic of time-stepping with many contacts
//! ([`timestep`](crate::timestep)).
//!
//! # Model
//! Coordinates `q = (y, φ_S, φ_B)` (the sleeve's height, the sleeve's and the bird's
//! angles), the small-angle (linearized) mass matrix
//! ```text
//! M = | m_S+m_B   m_B l_S        m_B l_G         |
//!     | m_B l_S   J_S+m_B l_S²   m_B l_S l_G     |
//!     | m_B l_G   m_B l_S l_G    J_B+m_B l_G²    |
//! ```
//! gravity and the spring `c_φ (φ_B − φ_S)`, and three contacts with the pole
//! ([`Woodpecker::contacts`]): the beak `g₁ = l_S + l_G − l_B − r_0 − h_B φ_B` with tangent
//! row `(1, l_S, l_G − l_B)` and `e = 0.5`; the sleeve's edges `g₂,₃ = r_S − r_0 ± h_S φ_S`
//! with tangent row `(1, r_S, 0)` and `e = 0`; `μ = 0.3` everywhere.
//!
//! # References
//! Ch. Glocker, PhD thesis, TU München (1995), pp. 162ff.; R. I. Leine, Ch. Glocker,
//! D. H. van Campen, *Nonlinear dynamics of the woodpecker toy*, J. Vib. Control 9 (2003).
//! The constants and the initial state ([`Woodpecker::Q0`], [`Woodpecker::V0`]) are those
//! of the Siconos platform's mechanics example `Woodpecker` (`siconos/siconos-tutorials`),
//! whose reference run the crate's tests compare against.

use crate::timestep::{Lagrangian, LinearContact, TimeStepError};

/// The woodpecker toy's smooth part (constant mass matrix, gravity, the rotational spring);
/// its contacts are [`Woodpecker::contacts`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Woodpecker;

impl Woodpecker {
    /// Sleeve mass `m_S` (kg).
    pub const M_S: f64 = 3.0e-4;
    /// Sleeve inertia `J_S` (kg m²).
    pub const J_S: f64 = 5.0e-9;
    /// Bird mass `m_B` (kg).
    pub const M_B: f64 = 4.5e-3;
    /// Bird inertia `J_B` (kg m²).
    pub const J_B: f64 = 7.0e-7;
    /// Pole radius `r_0` (m).
    pub const R_0: f64 = 2.5e-3;
    /// Sleeve's inner radius `r_S` (m).
    pub const R_S: f64 = 3.1e-3;
    /// Sleeve's half height `h_S` (m).
    pub const H_S: f64 = 5.8e-3;
    /// Sleeve to spring joint `l_S` (m).
    pub const L_S: f64 = 1.0e-2;
    /// Joint to the bird's centre of mass `l_G` (m).
    pub const L_G: f64 = 1.5e-2;
    /// Joint to the beak, vertically `h_B` (m).
    pub const H_B: f64 = 2.0e-2;
    /// Joint to the beak, horizontally `l_B` (m).
    pub const L_B: f64 = 2.01e-2;
    /// Spring stiffness `c_φ` (N m/rad).
    pub const C_PHI: f64 = 5.6e-3;
    /// Gravity `g` (m/s²).
    pub const G: f64 = 9.81;
    /// Siconos' initial positions `(y, φ_S, φ_B)`, a point near the limit cycle.
    pub const Q0: [f64; 3] = [0.0, -0.1036, -0.2788];
    /// Siconos' initial velocities `(ẏ, ω_S, ω_B)`.
    pub const V0: [f64; 3] = [-0.3411, 4.8572e-15, -7.4583];

    /// The beak (`g₁`) and the sleeve's edges (`g₂`, `g₃`), in this order.
    ///
    /// # Errors
    /// None with these constants ([`LinearContact::new`]'s checks).
    pub fn contacts() -> Result<[LinearContact<f64, 3>; 3], TimeStepError> {
        let (ls, lg, lb) = (Self::L_S, Self::L_G, Self::L_B);
        let sleeve = [1.0, Self::R_S, 0.0];
        let play = Self::R_S - Self::R_0;
        Ok([
            LinearContact::new(
                [0.0, 0.0, -Self::H_B],
                ls + lg - lb - Self::R_0,
                [1.0, ls, lg - lb],
                0.5,
                0.3,
            )?,
            LinearContact::new([0.0, Self::H_S, 0.0], play, sleeve, 0.0, 0.3)?,
            LinearContact::new([0.0, -Self::H_S, 0.0], play, sleeve, 0.0, 0.3)?,
        ])
    }
}

impl Lagrangian<f64> for Woodpecker {
    fn dofs(&self) -> usize {
        3
    }
    fn mass(&self, _q: &[f64], m: &mut [f64]) {
        let (ms, js, mb, jb) = (Self::M_S, Self::J_S, Self::M_B, Self::J_B);
        let (ls, lg) = (Self::L_S, Self::L_G);
        m.copy_from_slice(&[
            ms + mb,
            mb * ls,
            mb * lg,
            mb * ls,
            js + mb * ls * ls,
            mb * ls * lg,
            mb * lg,
            mb * ls * lg,
            jb + mb * lg * lg,
        ]);
    }
    fn forces(&self, _t: f64, q: &[f64], _v: &[f64], f: &mut [f64]) {
        let (ms, mb, g) = (Self::M_S, Self::M_B, Self::G);
        let spring = Self::C_PHI * (q[2] - q[1]);
        f[0] = -(ms + mb) * g;
        f[1] = spring - mb * Self::L_S * g;
        f[2] = -spring - mb * Self::L_G * g;
    }
    /// The spring's stiffness `c_φ` on `φ_B − φ_S`; no damping.
    fn force_jacobians(
        &self,
        _t: f64,
        _q: &[f64],
        _v: &[f64],
        k: &mut [f64],
        c: &mut [f64],
    ) -> bool {
        let s = Self::C_PHI;
        k.copy_from_slice(&[0.0, 0.0, 0.0, 0.0, s, -s, 0.0, -s, s]);
        c.fill(0.0);
        true
    }
    fn potential(&self, _t: f64, q: &[f64]) -> f64 {
        let (ms, mb, g) = (Self::M_S, Self::M_B, Self::G);
        let d = q[2] - q[1];
        (ms + mb) * g * q[0]
            + mb * g * (Self::L_S * q[1] + Self::L_G * q[2])
            + 0.5 * Self::C_PHI * d * d
    }
}
