//! A rigid ball bouncing on a sinusoidally vibrating table.
//!
//! # Model
//! $$\ddot y = -g \;\text{ while } y > s(t) = A\sin\omega t,\qquad
//!   \dot y^+ = \dot s - e\,(\dot y^- - \dot s) \;\text{ at } y = s(t),$$
//! a [`Mechanical`] system of one unit mass with a constant load `−g`, the contact surface
//! [`Gap::above`] the table (penetration `s(t) − y`) and the built-in reset
//! [`NewtonImpact`]. Its dimensionless acceleration `Γ = Aω²/g` organizes the dynamics:
//! for `Γ < 1` the ball comes to rest on the table after chattering, above it period-1
//! bouncing is born and doubles its period on the way to chaos.
//!
//! # References
//! P. J. Holmes, *J. Sound Vib.* 84 (1982) 173–189; A. Mehta, J. M. Luck, *Phys. Rev. Lett.*
//! 65 (1990) 393–396; the chattering/sticking terminology of C. Budd, F. Dux, *Phil. Trans.
//! R. Soc. A* 347 (1994) 365–389. The exact impact map (parabolic flights, roots of
//! `y(t) = s(t)`) is `testing::BallOnTableExact` (feature `testing`).

use crate::Real;
use crate::event::{Gap, NewtonImpact};
use crate::excite::{Constant, Harmonic};
use crate::model::{Coordinate, Load, Mechanical};
use crate::scalar::lit;
use crate::timestep::{Contact, Geometry, Jacobian};
use crate::validate::ParameterError;
use crate::validate::positive;

/// The ball in flight: state `(y, ẏ)`.
pub type BallModel<T> = Mechanical<T, 1, (), Load<T, 1, Constant<T>>>;

/// The table as a contact surface (penetration `s(t) − y`).
pub type Table<T> = Gap<T, 1, Harmonic<T>>;

/// The parameters of the ball on the vibrating table (SI units).
///
/// Deserialization (feature `serde`) applies [`validate`](Self::validate).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BouncingBallTable {
    /// Gravity `g` (m/s²).
    pub g: f64,
    /// Table amplitude `A` (m).
    pub amplitude: f64,
    /// Table angular frequency `ω` (rad/s).
    pub omega: f64,
    /// Restitution coefficient `e ∈ [0, 1]`.
    pub e: f64,
}

crate::serde_check::deserialize_checked! {
    "BouncingBallTable", BouncingBallTable { g: f64, amplitude: f64, omega: f64, e: f64 },
    |raw| -> ParameterError {
        raw.validate()?;
        raw
    }
}

impl BouncingBallTable {
    /// The table shaken at `Γ = Aω²/g` with `ω = 2π rad/s` (period 1 s), `g = 9.81 m/s²`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `gamma` is finite and > 0 and `0 ≤ e ≤ 1`.
    pub fn with_gamma(gamma: f64, e: f64) -> Result<Self, ParameterError> {
        let gamma = positive("gamma", gamma)?;
        let g = 9.81;
        let omega = std::f64::consts::TAU;
        let p = Self {
            g,
            amplitude: gamma * g / (omega * omega),
            omega,
            e,
        };
        p.validate()?;
        Ok(p)
    }

    /// `Γ = Aω²/g`.
    pub fn gamma(&self) -> f64 {
        self.amplitude * self.omega * self.omega / self.g
    }

    /// Checks every parameter.
    ///
    /// # Errors
    /// [`ParameterError`] naming the first invalid one.
    pub fn validate(&self) -> Result<(), ParameterError> {
        positive("g", self.g)?;
        positive("amplitude", self.amplitude)?;
        positive("omega", self.omega)?;
        if !(self.e >= 0.0 && self.e <= 1.0) {
            return Err(ParameterError::new("e", self.e, "in [0, 1]"));
        }
        Ok(())
    }

    /// The ball's free flight.
    ///
    /// # Errors
    /// [`Error::Parameter`](crate::Error::Parameter) for invalid parameters.
    pub fn model<T: Real>(&self) -> crate::Result<BallModel<T>> {
        self.validate()?;
        Ok(Mechanical::with_masses([T::one()])?
            .with_loads(Load::on_dof(0, Constant::new(-lit::<T>(self.g))?)?))
    }

    /// The table surface `s(t) = A sin ωt` (the ball must stay above it).
    ///
    /// # Errors
    /// [`Error::Parameter`](crate::Error::Parameter) for invalid parameters.
    pub fn table<T: Real>(&self) -> crate::Result<Table<T>> {
        self.validate()?;
        Ok(Gap::above(
            Coordinate::dof(0)?,
            Harmonic::new(lit(self.amplitude), lit(self.omega), T::zero())?,
        ))
    }

    /// The impact law `ẏ⁺ = ṡ − e(ẏ⁻ − ṡ)`.
    ///
    /// # Errors
    /// [`Error::Parameter`](crate::Error::Parameter) for invalid parameters.
    pub fn impact<T: Real>(&self) -> crate::Result<NewtonImpact<T, 1, Harmonic<T>>> {
        Ok(NewtonImpact::unit_mass(self.table()?, lit(self.e))?)
    }

    /// The table's position and velocity `(s(t), ṡ(t))` (libm's `sin`/`cos`).
    pub fn table_motion(&self, t: f64) -> (f64, f64) {
        let ph = self.omega * t;
        (
            self.amplitude * ph.sin(),
            self.amplitude * self.omega * ph.cos(),
        )
    }

    /// The table period `2π/ω`.
    pub fn period(&self) -> f64 {
        std::f64::consts::TAU / self.omega
    }

    /// The table as a contact of the ball's coordinate for Moreau–Jean time-stepping
    /// ([`MoreauJean`](crate::timestep::MoreauJean) with [`model`](Self::model)): gap
    /// `g = y − A sin ωt`, its explicit time derivative `−Aω cos ωt` as the drift, Newton's
    /// restitution `e`, no friction.
    ///
    /// # Errors
    /// [`ParameterError`] for invalid parameters.
    pub fn contact(&self) -> Result<TableContact, ParameterError> {
        self.validate()?;
        Ok(TableContact {
            amplitude: self.amplitude,
            omega: self.omega,
            e: self.e,
        })
    }
}

/// The vibrating table as a time-stepping contact ([`BouncingBallTable::contact`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableContact {
    amplitude: f64,
    omega: f64,
    e: f64,
}

impl Contact<f64> for TableContact {
    fn evaluate(&self, t: f64, q: &[f64], jac: &mut Jacobian<'_, f64>) -> Geometry<f64> {
        jac.normal(0, 1.0);
        Geometry {
            gap: q[0] - self.amplitude * (self.omega * t).sin(),
        }
    }
    fn drift(&self, t: f64, _q: &[f64]) -> [f64; 2] {
        [-self.amplitude * self.omega * (self.omega * t).cos(), 0.0]
    }
    fn restitution(&self) -> f64 {
        self.e
    }
}
