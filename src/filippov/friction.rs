//! A Filippov system from the crate's parts: a [`Mechanical`] model with a set-valued
//! Coulomb contact on any coordinate against a moving surface ([`Coulomb`]).

use nalgebra::{SMatrix, SVector};

use super::system::{Filippov, Region};
use crate::drive::Coulomb;
use crate::excite::Excitation;
use crate::model::{Elements, Loads, Mechanical};
use crate::scalar::to_f64;
use crate::validate::ParameterError;
use crate::{Dynamics, Real};

/// Coulomb friction on a coordinate `w·q` of a [`Mechanical`] model rubbing on a surface of
/// velocity `u(t)`, as a Filippov system of state `(q, q̇)` (`M = 2N`) with one surface:
/// $$ H = w\\cdot\\dot q - u(t), \\qquad
///    M\\ddot q = f(t, q, \\dot q) \\mp F_k\\, w \\quad (H \\gtrless 0). $$
/// Sliding on `H = 0` is sticking; the equivalent control is the stick force
/// `F = F_k(1 − 2α)`, and a stick ends where it reaches `±F_k`. This is the law of
/// [`StickSlip`](crate::drive::StickSlip) with a static limit equal to the kinetic force.
///
/// # Example
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::drive::Coulomb;
/// use nonsmooth::excite::Constant;
/// use nonsmooth::filippov::{CoulombFriction, FilippovSimulation, TransitionKind};
/// use nonsmooth::force::LinearSpring;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::model::{Coordinate, Element, Mechanical};
///
/// // A block on a spring (k = 1) on a belt at 0.5, friction 1: stuck until k x = 1.
/// let model = Mechanical::with_masses([1.0_f64])?
///     .with_elements(Element::on_dof(0, LinearSpring::new(1.0)?)?);
/// let friction = Coulomb::new(Coordinate::dof(0)?, Constant::new(0.5)?, 1.0, 1.0)?;
/// let system = CoulombFriction::new(&model, friction)?;
/// let mut sim = FilippovSimulation::new(system, Dopri5::new(Tolerances::new(1e-10, 1e-12)?));
/// let run = sim.run(0.0, SVector::from([0.0, 0.5]), 3.0, &mut ())?;
/// assert_eq!(run.transitions[0].kind, TransitionKind::SlidingExit);
/// assert!((run.transitions[0].t - 2.0).abs() < 1e-10);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct CoulombFriction<'a, T: Real, const N: usize, El, Ld, U> {
    model: &'a Mechanical<T, N, El, Ld>,
    friction: Coulomb<T, N, U>,
    /// `M⁻¹w`.
    m_w: SVector<T, N>,
}

impl<'a, T, const N: usize, El, Ld, U> CoulombFriction<'a, T, N, El, Ld, U>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    U: Excitation<T>,
{
    /// `model` with the friction contact `friction`.
    ///
    /// # Errors
    /// [`ParameterError`] unless the static limit equals the kinetic force (a static limit
    /// above it is not a Filippov convexification: use
    /// [`StickSlip`](crate::drive::StickSlip)).
    pub fn new(
        model: &'a Mechanical<T, N, El, Ld>,
        friction: Coulomb<T, N, U>,
    ) -> Result<Self, ParameterError> {
        if friction.static_limit() != friction.kinetic() {
            return Err(ParameterError::new(
                "static friction limit",
                to_f64(friction.static_limit()),
                "equal to the kinetic friction force for a Filippov system",
            ));
        }
        let (m_w, _) = model.mobility(friction.coordinate().weights());
        Ok(Self {
            model,
            friction,
            m_w,
        })
    }
}

impl<T, const N: usize, const M: usize, El, Ld, U> Filippov<T, M, 1>
    for CoulombFriction<'_, T, N, El, Ld, U>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    U: Excitation<T>,
{
    #[inline(always)]
    fn surface(&self, _i: usize, t: T, y: &SVector<T, M>) -> T {
        self.friction.slip_velocity(t, y)
    }

    fn gradient(&self, _i: usize, _t: T, _y: &SVector<T, M>) -> SVector<T, M> {
        let w = self.friction.coordinate().weights();
        let mut g = SVector::<T, M>::zeros();
        for k in 0..N {
            g[N + k] = w[k];
        }
        g
    }

    fn surface_time_rate(&self, _i: usize, t: T, _y: &SVector<T, M>) -> T {
        -self.friction.surface_velocity().force_rate(t)
    }

    #[inline(always)]
    fn field(&self, sides: &[Region; 1], t: T, y: &SVector<T, M>, dy: &mut SVector<T, M>) {
        // Friction opposes the slip: −F_k above the surface (slipping forward), +F_k below.
        let force = -sides[0].sign::<T>() * self.friction.kinetic();
        super::load::sided_field(self.model, &self.m_w, force, t, y, dy);
    }

    fn field_jacobian(
        &self,
        _sides: &[Region; 1],
        t: T,
        y: &SVector<T, M>,
    ) -> Option<SMatrix<T, M, M>> {
        // The friction force is constant in each region.
        self.model.jacobian(t, y)
    }

    fn time_scale(&self, t: T) -> Option<T> {
        match (
            self.model.forcing_time_scale(t),
            self.friction.surface_velocity().time_scale(t),
        ) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}
