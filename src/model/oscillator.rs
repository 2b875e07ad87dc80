use nalgebra::{SMatrix, SVector};

use crate::error::{ParameterError, Result};
use crate::excite::Excitation;
use crate::roots::brent;
use crate::scalar::lit;
use crate::validate::positive;
use crate::{Dynamics, ForceLaw, Real};

/// A 1-DOF oscillator `m·ẍ + ΣF(x, ẋ) = f(t)` with state `y = (x, ẋ)`.
///
/// Deserialization (feature `serde`) applies the constructor's check of the mass (`1/m` is
/// recomputed); the laws and the excitation check themselves.
///
/// # Model
/// $$\dot y_0 = y_1, \qquad \dot y_1 = \frac{f(t) - F(y_0, y_1)}{m},$$
/// with `F` the (summed) force law and `f` the excitation. The Jacobian follows from the
/// laws' partials:
/// $$J = \begin{pmatrix} 0 & 1 \\ -F_x/m & -F_v/m \end{pmatrix}.$$
///
/// # Examples
/// ```
/// use nonsmooth::{Dynamics, model::Oscillator, excite::Harmonic};
/// use nonsmooth::force::{LinearSpring, ViscousDamper};
/// use nalgebra::Vector2;
///
/// let laws = (LinearSpring::new(4.0)?, ViscousDamper::new(0.1)?);
/// let osc = Oscillator::new(1.0, laws, Harmonic::new(1.0, 1.5, 0.0)?)?;
/// let mut dy = Vector2::zeros();
/// osc.rhs(0.0, &Vector2::new(1.0, 0.0), &mut dy);
/// assert_eq!(dy, Vector2::new(0.0, -4.0));
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Oscillator<T, L, E> {
    mass: T,
    inv_mass: T,
    laws: L,
    excitation: E,
}

crate::serde_check::deserialize_checked! {
    "Oscillator",
    Oscillator<T: Real, L, E> { mass: T, inv_mass: T, laws: L, excitation: E },
    |raw| -> ParameterError { Oscillator::assemble(raw.mass, raw.laws, raw.excitation)? }
}

impl<T: Real, L, E> Oscillator<T, L, E> {
    /// The checks and the assembly of [`new`](Self::new), shared with deserialization.
    fn assemble(mass: T, laws: L, excitation: E) -> Result<Self, ParameterError> {
        let mass = positive("mass", mass)?;
        Ok(Self {
            mass,
            inv_mass: T::one() / mass,
            laws,
            excitation,
        })
    }
}

impl<T: Real, L: ForceLaw<T>, E: Excitation<T>> Oscillator<T, L, E> {
    /// Assembles the oscillator.
    ///
    /// # Errors
    /// [`ParameterError`] unless `mass` is finite and > 0.
    pub fn new(mass: T, laws: L, excitation: E) -> Result<Self, ParameterError> {
        Self::assemble(mass, laws, excitation)
    }

    /// The mass `m`.
    pub fn mass(&self) -> T {
        self.mass
    }

    /// The force laws.
    pub fn laws(&self) -> &L {
        &self.laws
    }

    /// The excitation.
    pub fn excitation(&self) -> &E {
        &self.excitation
    }

    /// The same oscillator with another excitation (e.g. another forcing frequency).
    pub fn with_excitation<E2: Excitation<T>>(self, excitation: E2) -> Oscillator<T, L, E2> {
        Oscillator {
            mass: self.mass,
            inv_mass: self.inv_mass,
            laws: self.laws,
            excitation,
        }
    }

    /// The restoring force `ΣF(x, 0)` (all velocity-dependent terms vanish at rest for
    /// odd dampers and friction).
    pub fn restoring_force(&self, x: T) -> T {
        self.laws.force(x, T::zero())
    }

    /// The static stiffness `∂ΣF/∂x` at `(x, 0)`.
    pub fn static_stiffness(&self, x: T) -> T {
        self.laws.partials(x, T::zero()).0
    }

    /// The static equilibrium `X0` with `ΣF(X0, 0) = 0`, bracketed in `[lo, hi]`, solved
    /// by Brent's method to machine precision.
    ///
    /// # Errors
    /// [`Error::Root`](crate::Error::Root) if the restoring force does not change sign on
    /// `[lo, hi]` (no equilibrium there).
    pub fn static_equilibrium(&self, lo: T, hi: T) -> Result<T> {
        let f = |x: T| self.restoring_force(x);
        let tol = T::default_epsilon() * (lo.abs().max(hi.abs()));
        Ok(brent(f, lo, hi, f(lo), f(hi), tol, 200)?)
    }
}

impl<T: Real, L: ForceLaw<T>, E: Excitation<T>> Dynamics<T, 2> for Oscillator<T, L, E> {
    #[inline(always)]
    fn rhs(&self, t: T, y: &SVector<T, 2>, dy: &mut SVector<T, 2>) {
        let x = y[0];
        let v = y[1];
        dy[0] = v;
        dy[1] = (self.excitation.force(t) - self.laws.force(x, v)) * self.inv_mass;
    }

    fn jacobian(&self, _t: T, y: &SVector<T, 2>) -> Option<SMatrix<T, 2, 2>> {
        let (fx, fv) = self.laws.partials(y[0], y[1]);
        Some(SMatrix::<T, 2, 2>::new(
            T::zero(),
            T::one(),
            -fx * self.inv_mass,
            -fv * self.inv_mass,
        ))
    }

    fn time_derivative(&self, t: T, _y: &SVector<T, 2>) -> Option<SVector<T, 2>> {
        Some(SVector::<T, 2>::new(
            T::zero(),
            self.excitation.force_rate(t) * self.inv_mass,
        ))
    }
}

/// Total mechanical energy helper for tests: `½m·v² + ∫₀ˣ F(s, 0) ds` is not generally
/// available, so only the kinetic part is offered.
impl<T: Real, L, E> Oscillator<T, L, E> {
    /// Kinetic energy `½·m·v²`.
    pub fn kinetic_energy(&self, v: T) -> T {
        lit::<T>(0.5) * self.mass * v * v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::{LinearSpring, ViscousDamper};

    #[test]
    fn jacobian_from_partials() {
        let osc = Oscillator::new(
            2.0,
            (
                LinearSpring::new(8.0).unwrap(),
                ViscousDamper::new(1.0).unwrap(),
            ),
            (),
        )
        .unwrap();
        let j = osc
            .jacobian(0.0, &SVector::<f64, 2>::new(0.1, 0.2))
            .unwrap();
        assert_eq!(j, SMatrix::<f64, 2, 2>::new(0.0, 1.0, -4.0, -0.5));
        assert!(Oscillator::new(-1.0, (), ()).is_err());
        assert!(Oscillator::<f64, (), ()>::new(f64::NAN, (), ()).is_err());
    }

    #[test]
    fn equilibrium_of_a_shifted_spring() {
        let s = LinearSpring::new(3.0)
            .unwrap()
            .with_rest_position(0.25)
            .unwrap();
        let osc = Oscillator::new(1.0, s, ()).unwrap();
        assert!((osc.static_equilibrium(-1.0, 1.0).unwrap() - 0.25_f64).abs() < 1e-15);
        assert!(osc.static_equilibrium(0.5, 1.0).is_err());
    }
}
