use nalgebra::{SMatrix, SVector};

use crate::excite::Excitation;
use crate::model::{Coordinate, Element, Load, Mechanical};
use crate::roots::brent;
use crate::scalar::lit;
use crate::validate::ParameterError;
use crate::validate::positive;
use crate::{Dynamics, ForceLaw, Real};

/// A 1-DOF oscillator `m·ẍ + ΣF(x, ẋ) = f(t)` with state `y = (x, ẋ)`.
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
///
/// # Implementation
/// The oscillator is the one-DOF [`Mechanical`] system with the laws as one element on
/// `q₀` and the excitation as one load on it (a thin layer: its Jacobian, `∂f/∂t` and cusp
/// declarations are the system's; its right-hand side is the system's written out for one
/// DOF, the same values to the bit); it keeps the scalar constructor, the accessors and the
/// bracketing static equilibrium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oscillator<T: Real, L, E> {
    model: OneDof<T, L, E>,
}

/// The one-DOF mechanical system behind an [`Oscillator`].
type OneDof<T, L, E> = Mechanical<T, 1, Element<T, 1, L>, Load<T, 1, E>>;

impl<T: Real, L: ForceLaw<T>, E: Excitation<T>> Oscillator<T, L, E> {
    /// Assembles the oscillator.
    ///
    /// # Errors
    /// [`ParameterError`] unless `mass` is finite and > 0.
    pub fn new(mass: T, laws: L, excitation: E) -> Result<Self, ParameterError> {
        let q = Coordinate::first();
        Ok(Self {
            model: Mechanical::with_masses([positive("mass", mass)?])?
                .with_elements(Element::new(q, laws))
                .with_loads(Load {
                    coordinate: q,
                    excitation,
                }),
        })
    }

    /// The mass `m`.
    pub fn mass(&self) -> T {
        self.model.mass_matrix()[(0, 0)]
    }

    /// The force laws.
    pub fn laws(&self) -> &L {
        &self.model.elements().law
    }

    /// The excitation.
    pub fn excitation(&self) -> &E {
        &self.model.loads().excitation
    }

    /// The same oscillator as a one-DOF [`Mechanical`] system.
    pub fn mechanical(&self) -> &OneDof<T, L, E> {
        &self.model
    }

    /// The same oscillator with another excitation (e.g. another forcing frequency).
    pub fn with_excitation<E2: Excitation<T>>(self, excitation: E2) -> Oscillator<T, L, E2> {
        let coordinate = self.model.loads().coordinate;
        Oscillator {
            model: self.model.with_loads(Load {
                coordinate,
                excitation,
            }),
        }
    }

    /// The restoring force `ΣF(x, 0)` (all velocity-dependent terms vanish at rest for
    /// odd dampers and friction).
    pub fn restoring_force(&self, x: T) -> T {
        self.laws().force(x, T::zero())
    }

    /// The static stiffness `∂ΣF/∂x` at `(x, 0)`.
    pub fn static_stiffness(&self, x: T) -> T {
        self.laws().partials(x, T::zero()).0
    }

    /// The static equilibrium `X0` with `ΣF(X0, 0) = 0`, bracketed in `[lo, hi]`, solved
    /// by Brent's method to machine precision.
    ///
    /// # Errors
    /// [`RootError`](crate::roots::RootError) if the restoring force does not change sign
    /// on `[lo, hi]` (no equilibrium there).
    pub fn static_equilibrium(&self, lo: T, hi: T) -> Result<T, crate::roots::RootError> {
        let f = |x: T| self.restoring_force(x);
        let tol = T::default_epsilon() * (lo.abs().max(hi.abs()));
        brent(f, lo, hi, f(lo), f(hi), tol, 200)
    }
}

impl<T: Real, L: ForceLaw<T>, E: Excitation<T>> Dynamics<T, 2> for Oscillator<T, L, E> {
    /// The one-DOF case of [`Mechanical`]'s right-hand side written out,
    /// `ẍ = (f(t) − F(x, ẋ))/m`: the same values to the bit (tested), without the general
    /// coordinate and matrix bookkeeping on the hot path.
    #[inline(always)]
    fn rhs(&self, t: T, y: &SVector<T, 2>, dy: &mut SVector<T, 2>) {
        let force = self.excitation().force(t) - self.laws().force(y[0], y[1]);
        dy[0] = y[1];
        dy[1] = force * self.model.inverse_mass_matrix()[(0, 0)];
    }

    fn jacobian(&self, t: T, y: &SVector<T, 2>) -> Option<SMatrix<T, 2, 2>> {
        self.model.jacobian(t, y)
    }

    fn time_derivative(&self, t: T, y: &SVector<T, 2>) -> Option<SVector<T, 2>> {
        self.model.time_derivative(t, y)
    }

    /// The laws' declared cusp exponent (the smallest of them): the one-DOF system's.
    fn velocity_exponent(&self) -> Option<T> {
        Dynamics::<T, 2>::velocity_exponent(&self.model)
    }

    /// The laws' declared contact onset (the first of them): the one-DOF system's (the
    /// laws act on `x` itself, so the onset is theirs unchanged).
    fn contact_onset(&self) -> Option<crate::force::ContactOnset<T>> {
        Dynamics::<T, 2>::contact_onset(&self.model)
    }
}

impl<T: Real, L: ForceLaw<T>, E: Excitation<T>> Oscillator<T, L, E> {
    /// Kinetic energy `½·m·v²`.
    pub fn kinetic_energy(&self, v: T) -> T {
        lit::<T>(0.5) * self.mass() * v * v
    }
}

/// The serialized form of an [`Oscillator`]: mass, laws, excitation (rebuilt through
/// [`Oscillator::new`] on deserialize).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
struct OscillatorData<T, L, E> {
    mass: T,
    laws: L,
    excitation: E,
}

#[cfg(feature = "serde")]
impl<T, L, E> serde::Serialize for Oscillator<T, L, E>
where
    T: Real + serde::Serialize,
    L: ForceLaw<T> + serde::Serialize + Clone,
    E: Excitation<T> + serde::Serialize + Clone,
{
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        OscillatorData {
            mass: self.mass(),
            laws: self.laws().clone(),
            excitation: self.excitation().clone(),
        }
        .serialize(serializer)
    }
}

#[cfg(feature = "serde")]
impl<'de, T, L, E> serde::Deserialize<'de> for Oscillator<T, L, E>
where
    T: Real + serde::Deserialize<'de>,
    L: ForceLaw<T> + serde::Deserialize<'de>,
    E: Excitation<T> + serde::Deserialize<'de>,
{
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let v = OscillatorData::<T, L, E>::deserialize(deserializer)?;
        Oscillator::new(v.mass, v.laws, v.excitation).map_err(serde::de::Error::custom)
    }
}

/// The lane form: the one-DOF [`Mechanical`] the oscillator is (its right-hand side is
/// the same to the bit, and so is the lane form's, lane by lane).
impl<L, E> crate::LaneDynamics<2> for Oscillator<f64, L, E>
where
    L: crate::force::LaneLaw + Clone + core::fmt::Debug + Send + Sync,
    E: crate::excite::LaneExcitation + Clone + core::fmt::Debug + Send + Sync,
{
    type Packed<V: crate::lanes::Lanes> =
        crate::model::MechanicalPacked<V, 1, Element<f64, 1, L>, Load<f64, 1, E>>;
    type Time<V: crate::lanes::Lanes> = [V; 1];

    fn pack<V: crate::lanes::Lanes>(&self) -> Self::Packed<V> {
        <OneDof<f64, L, E> as crate::LaneDynamics<2>>::pack(&self.model)
    }
    fn pack_lane<V: crate::lanes::Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
        <OneDof<f64, L, E> as crate::LaneDynamics<2>>::pack_lane(&self.model, packed, lane)
    }
    /// No time scale is declared (the driver's default `None`).
    fn constant_time_scale(&self) -> bool {
        true
    }
    fn same_structure(&self, other: &Self) -> bool {
        <OneDof<f64, L, E> as crate::LaneDynamics<2>>::same_structure(&self.model, &other.model)
    }
    #[inline(always)]
    fn time_lanes<V: crate::lanes::Lanes>(
        packed: &Self::Packed<V>,
        math: crate::lanes::LaneMath,
        t: V,
    ) -> [V; 1] {
        <OneDof<f64, L, E> as crate::LaneDynamics<2>>::time_lanes(packed, math, t)
    }
    #[inline(always)]
    fn rhs_lanes<V: crate::lanes::Lanes>(
        packed: &Self::Packed<V>,
        math: crate::lanes::LaneMath,
        t: V,
        time: &[V; 1],
        y: &[V; 2],
        dy: &mut [V; 2],
    ) {
        <OneDof<f64, L, E> as crate::LaneDynamics<2>>::rhs_lanes(packed, math, t, time, y, dy)
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
    fn right_hand_side_is_the_mechanical_systems_to_the_bit() {
        use crate::systems::paper::PAPER;
        let osc = PAPER.oscillator::<f64>(20.465).unwrap();
        let x0 = PAPER.static_equilibrium().unwrap();
        for (i, y) in [
            SVector::<f64, 2>::new(-2.5e-3, 3e-2),
            SVector::<f64, 2>::new(x0, 2e-4),
            SVector::<f64, 2>::new(x0 - 1e-5, -3e-8),
            SVector::<f64, 2>::new(x0, 0.0),
        ]
        .iter()
        .enumerate()
        {
            let t = 0.123 * i as f64;
            let (mut a, mut b) = (SVector::zeros(), SVector::zeros());
            osc.rhs(t, y, &mut a);
            osc.mechanical().rhs(t, y, &mut b);
            assert_eq!(a, b, "state {y:?}");
        }
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
