//! N-degree-of-freedom mechanical systems assembled from elements.

use nalgebra::{SMatrix, SVector};
use thiserror::Error;

use crate::excite::Excitation;
use crate::force::{ContactOnset, Side, min_exponent};
use crate::linalg::Lu;
use crate::scalar::{lit, to_f64};
use crate::validate::ParameterError;
use crate::validate::finite;
use crate::{Dynamics, ForceLaw, Real};

mod lanes;
pub use lanes::{LaneElements, LaneLoads, MechanicalLanes, MechanicalPacked};

/// Why a model could not be assembled or analysed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A degree-of-freedom index outside `0..N`.
    #[error("degree of freedom {index} out of range: the system has {dofs} degrees of freedom")]
    DofOutOfRange {
        /// The index.
        index: usize,
        /// The number of degrees of freedom.
        dofs: usize,
    },
    /// A relative coordinate `q_i − q_j` with `i == j` (identically zero).
    #[error("relative coordinate q_{index} − q_{index} is identically zero")]
    DegenerateCoordinate {
        /// The repeated index.
        index: usize,
    },
    /// The mass matrix is not symmetric positive definite.
    #[error("the mass matrix is not symmetric positive definite ({reason})")]
    MassMatrix {
        /// What failed.
        reason: &'static str,
    },
    /// The mass matrix is positive definite but its inverse is not finite in the scalar
    /// type (masses too small, e.g. below about `5.6·10⁻³⁰⁹` for `f64`).
    #[error(
        "the inverse of the mass matrix overflows (smallest diagonal mass {smallest_mass:e}): rescale the units"
    )]
    MassInverseOverflow {
        /// The smallest diagonal entry of the mass matrix.
        smallest_mass: f64,
    },
    /// A matrix entry is not finite.
    #[error("matrix `{name}` has a non-finite entry at ({row}, {col})")]
    NonFiniteMatrix {
        /// The matrix.
        name: &'static str,
        /// Row.
        row: usize,
        /// Column.
        col: usize,
    },
    /// Newton's method for the static equilibrium did not converge.
    #[error(
        "static equilibrium: Newton did not converge in {iterations} iterations (residual {residual} N); try another initial guess"
    )]
    EquilibriumNotConverged {
        /// Iterations used.
        iterations: usize,
        /// The force residual `‖R(q)‖∞` at the last iterate.
        residual: f64,
    },
    /// The tangent stiffness is singular at an iterate of the equilibrium search.
    #[error(
        "static equilibrium: the tangent stiffness is singular at iteration {iteration} (a free rigid-body mode, or a guess inside a gap of every element)"
    )]
    SingularStiffness {
        /// The iteration.
        iteration: usize,
    },
}

/// A scalar coordinate of an `N`-DOF system: the linear form
/// $$g(q) = \sum_k w_k q_k + o,$$
/// a single degree of freedom (`w = e_i`), a relative coordinate (`w = e_i − e_j`, e.g. the
/// gap between two masses) or any other linear combination. Its rate is `ġ = w·q̇`.
///
/// An element acting on `g` with force `F(g, ġ)` contributes the generalized forces
/// `w·F` to the left-hand side (virtual work), so the sign bookkeeping of relative
/// coordinates is done once, here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coordinate<T: Real, const N: usize> {
    weights: SVector<T, N>,
    offset: T,
    /// The sparsity of `w`, derived from it, so that the common shapes cost no
    /// multiplications by `±1` or `0` on the hot path (same values to the bit).
    shape: Shape,
    /// `i` for [`Shape::Dof`]`(i)`, else `N`: the commonest shape as one comparison.
    dof: usize,
}

/// The sparsity pattern of a coordinate's weights (and whether its offset is zero).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    /// `w = e_i`, `o = 0`.
    Dof(usize),
    /// `w = e_i`, `o ≠ 0`.
    DofOffset(usize),
    /// `w = e_plus − e_minus`.
    Pair { plus: usize, minus: usize },
    /// Anything else.
    General,
}

impl Shape {
    fn of<T: Real, const N: usize>(w: &SVector<T, N>, offset: T) -> Self {
        let mut nonzero = (0..N).filter(|&k| w[k] != T::zero());
        let (one, minus_one) = (T::one(), -T::one());
        match (nonzero.next(), nonzero.next(), nonzero.next()) {
            (Some(i), None, None) if w[i] == one && offset == T::zero() => Self::Dof(i),
            (Some(i), None, None) if w[i] == one => Self::DofOffset(i),
            (Some(a), Some(b), None) if w[a] == one && w[b] == minus_one => {
                Self::Pair { plus: a, minus: b }
            }
            (Some(a), Some(b), None) if w[a] == minus_one && w[b] == one => {
                Self::Pair { plus: b, minus: a }
            }
            _ => Self::General,
        }
    }
}

impl<T: Real, const N: usize> Coordinate<T, N> {
    /// The coordinate `q_i`.
    ///
    /// # Errors
    /// [`ModelError::DofOutOfRange`] unless `i < N`.
    pub fn dof(i: usize) -> Result<Self, ModelError> {
        check_dof::<N>(i)?;
        Ok(Self::unit(i))
    }

    /// The relative coordinate `q_i − q_j` (e.g. the extension of a spring from mass `j` to
    /// mass `i`, or the approach of mass `i` towards mass `j`).
    ///
    /// # Errors
    /// [`ModelError::DofOutOfRange`] unless both indices are `< N`;
    /// [`ModelError::DegenerateCoordinate`] if `i == j`.
    pub fn relative(i: usize, j: usize) -> Result<Self, ModelError> {
        check_dof::<N>(i)?;
        check_dof::<N>(j)?;
        if i == j {
            return Err(ModelError::DegenerateCoordinate { index: i });
        }
        let mut weights = SVector::zeros();
        weights[i] = T::one();
        weights[j] = -T::one();
        Ok(Self::from_weights(weights))
    }

    /// `q₀` (infallible: every system has a first DOF).
    pub(crate) fn first() -> Self {
        Self::unit(0)
    }

    /// `q_i` for a checked `i < N`.
    fn unit(i: usize) -> Self {
        let mut weights = SVector::zeros();
        weights[i] = T::one();
        Self::from_weights(weights)
    }

    fn from_weights(weights: SVector<T, N>) -> Self {
        Self {
            weights,
            offset: T::zero(),
            shape: Shape::General,
            dof: N,
        }
        .reshaped()
    }

    /// Derives `shape` and `dof` from the weights and the offset.
    fn reshaped(mut self) -> Self {
        self.shape = Shape::of(&self.weights, self.offset);
        self.dof = match self.shape {
            Shape::Dof(i) => i,
            _ => N,
        };
        self
    }

    /// Any linear combination `Σ w_k q_k`.
    ///
    /// # Errors
    /// [`ParameterError`] if a weight is not finite or all are zero.
    pub fn linear(weights: [T; N]) -> Result<Self, ParameterError> {
        let mut any = false;
        for &w in &weights {
            finite("weight", w)?;
            any |= w != T::zero();
        }
        if !any {
            return Err(ParameterError::new("weights", 0.0, "not all zero"));
        }
        Ok(Self::from_weights(SVector::from(weights)))
    }

    /// The same coordinate plus a constant offset `o` (e.g. `q_2 − q_1 + gap`).
    ///
    /// # Errors
    /// [`ParameterError`] unless `offset` is finite.
    pub fn with_offset(mut self, offset: T) -> Result<Self, ParameterError> {
        self.offset = finite("offset", offset)?;
        Ok(self.reshaped())
    }

    /// The coordinate with its sign reversed, `−g` (e.g. to put a stop on the other side).
    pub fn reversed(mut self) -> Self {
        self.weights = -self.weights;
        self.offset = -self.offset;
        self.reshaped()
    }

    /// The weights `w`.
    pub fn weights(&self) -> &SVector<T, N> {
        &self.weights
    }

    /// The offset `o`.
    pub fn offset(&self) -> T {
        self.offset
    }

    /// `Σ |w_k|·x_k` (with bounds `x_k ≥ 0` on the components: a bound on `|w·x|`).
    pub(crate) fn weighted_bound(&self, x: &[T]) -> T {
        self.weights
            .iter()
            .zip(x)
            .fold(T::zero(), |acc, (w, v)| acc + w.abs() * *v)
    }

    /// `g(q)`: `o + Σ w_k q_k` summed in index order.
    #[inline(always)]
    pub fn value(&self, q: &[T]) -> T {
        self.combine(self.offset, q)
    }

    /// `ġ = w·q̇`.
    #[inline(always)]
    pub fn rate(&self, qd: &[T]) -> T {
        self.combine(T::zero(), qd)
    }

    /// `start + Σ w_k x_k` in index order. Terms with `w_k = 0` and multiplications by
    /// `±1` are skipped for the sparse shapes: the same value (adding `±0` or multiplying
    /// by `±1` is exact), without their latency on the right-hand side's critical path.
    #[inline(always)]
    fn combine(&self, start: T, x: &[T]) -> T {
        // Indices are `< N` by construction; `min` states it to the compiler (no bounds
        // check, and the index is the constant 0 for one DOF).
        // The commonest shape first, as a plain test (`o = 0` for it, and `start` is `o`
        // or 0).
        if self.dof < N {
            return x[self.dof];
        }
        match self.shape {
            Shape::Dof(i) | Shape::DofOffset(i) => start + x[i.min(N - 1)],
            Shape::Pair { plus, minus } => {
                if start == T::zero() {
                    x[plus] - x[minus]
                } else if plus < minus {
                    start + x[plus] - x[minus]
                } else {
                    start - x[minus] + x[plus]
                }
            }
            Shape::General => {
                let mut g = start;
                for (w, v) in self.weights.iter().zip(x) {
                    g += *w * *v;
                }
                g
            }
        }
    }

    /// `out += w·f`.
    #[inline(always)]
    fn distribute(&self, f: T, out: &mut SVector<T, N>) {
        if self.dof < N {
            out[self.dof] += f;
            return;
        }
        match self.shape {
            Shape::Dof(i) | Shape::DofOffset(i) => out[i.min(N - 1)] += f,
            Shape::Pair { plus, minus } => {
                out[plus] += f;
                out[minus] -= f;
            }
            Shape::General => {
                for k in 0..N {
                    out[k] += self.weights[k] * f;
                }
            }
        }
    }
}

fn check_dof<const N: usize>(i: usize) -> Result<(), ModelError> {
    if i < N {
        Ok(())
    } else {
        Err(ModelError::DofOutOfRange { index: i, dofs: N })
    }
}

/// A force law acting on a [`Coordinate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Element<T: Real, const N: usize, L> {
    /// Where the law acts.
    pub coordinate: Coordinate<T, N>,
    /// The law `F(g, ġ)`.
    pub law: L,
}

impl<T: Real, const N: usize, L: ForceLaw<T>> Element<T, N, L> {
    /// The law `law` acting on `coordinate`.
    pub fn new(coordinate: Coordinate<T, N>, law: L) -> Self {
        Self { coordinate, law }
    }

    /// The law acting on DOF `i`.
    ///
    /// # Errors
    /// [`ModelError::DofOutOfRange`] unless `i < N`.
    pub fn on_dof(i: usize, law: L) -> Result<Self, ModelError> {
        Ok(Self::new(Coordinate::dof(i)?, law))
    }

    /// The law acting on the relative coordinate `q_i − q_j`.
    ///
    /// # Errors
    /// As [`Coordinate::relative`].
    pub fn between(i: usize, j: usize, law: L) -> Result<Self, ModelError> {
        Ok(Self::new(Coordinate::relative(i, j)?, law))
    }
}

/// A set of elements whose generalized forces and tangent matrices add up: an [`Element`],
/// `()`, tuples of up to twelve sets and arrays `[E; K]` of sets (e.g. the links of a
/// chain). Implemented by value, no `dyn`.
///
/// # Cusp declarations
/// [`velocity_exponent_on`](Elements::velocity_exponent_on) and
/// [`contact_onset_on`](Elements::contact_onset_on) report what the elements' laws declare
/// ([`ForceLaw::velocity_exponent`], [`ForceLaw::contact_onset`]) together with the
/// coordinate each law acts on: a law's declaration is about its own coordinate `g`, and
/// only the caller knows what it means for the state it steps. The one-DOF [`Mechanical`]
/// system maps them to its `(x, ẋ)` (see its [`Dynamics`] impl); a stepper for `N`
/// degrees of freedom can read them per coordinate. Both are provided (`None` by
/// default): an implementation of its own that does not override them declares nothing.
pub trait Elements<T: Real, const N: usize> {
    /// Adds `Σ w·F(g, ġ)` to `out`.
    fn add_forces(&self, q: &[T], qd: &[T], out: &mut SVector<T, N>);

    /// Adds the tangent stiffness `Σ F_g·w wᵀ` to `k` and damping `Σ F_ġ·w wᵀ` to `c`.
    fn add_tangent(&self, q: &[T], qd: &[T], k: &mut SMatrix<T, N, N>, c: &mut SMatrix<T, N, N>);

    /// The smallest of the velocity exponents that the elements' laws declare
    /// ([`ForceLaw::velocity_exponent`], the exponent `q` of a term `∝ sgn(ġ)|ġ|^q` in the
    /// rate of the law's coordinate `g`), each passed through `map` with the coordinate
    /// the law acts on: `map` returns the exponent in the caller's terms, or `None` to
    /// leave that element out. `None` if no element's law declares one (or `map` leaves
    /// them all out).
    ///
    /// ```
    /// use nonsmooth::force::{HertzContact, LinearSpring};
    /// use nonsmooth::model::{Coordinate, Element, Elements};
    ///
    /// let stop = HertzContact::new(1e-3, 1e7)?.with_damping(0.5, 1.5, 0.25)?;
    /// let elements = (
    ///     Element::<f64, 2, _>::on_dof(0, LinearSpring::new(100.0)?)?,
    ///     Element::between(1, 0, stop)?,
    /// );
    /// // The cusp is in the rate of q₁ − q₀, with q = 0.25.
    /// let relative = Coordinate::relative(1, 0)?;
    /// assert_eq!(elements.velocity_exponent_on(&|_, q| Some(q)), Some(0.25));
    /// let on = |c: &Coordinate<f64, 2>, q| (*c == relative).then_some(q);
    /// assert_eq!(elements.velocity_exponent_on(&on), Some(0.25));
    /// let off = |c: &Coordinate<f64, 2>, q| (*c != relative).then_some(q);
    /// assert_eq!(elements.velocity_exponent_on(&off), None);
    /// // The stop, in the terms of q₁ − q₀.
    /// let stop_at = elements.contact_onset_on(&|_, o| Some(o.position));
    /// assert_eq!(stop_at, Some(1e-3));
    /// # Ok::<(), nonsmooth::Error>(())
    /// ```
    fn velocity_exponent_on<Map>(&self, _map: &Map) -> Option<T>
    where
        Self: Sized,
        Map: Fn(&Coordinate<T, N>, T) -> Option<T>,
    {
        None
    }

    /// The first contact onset, in element order, that the elements' laws declare
    /// ([`ForceLaw::contact_onset`], a stop `g_I` and side of the law's coordinate `g`) and
    /// `map` accepts: `map` receives the coordinate the law acts on and the onset in that
    /// coordinate's terms, and returns it in the caller's terms, or `None` to skip it. One
    /// stop is reported, as for a sum of laws.
    fn contact_onset_on<R, Map>(&self, _map: &Map) -> Option<R>
    where
        Self: Sized,
        Map: Fn(&Coordinate<T, N>, ContactOnset<T>) -> Option<R>,
    {
        None
    }
}

impl<T: Real, const N: usize> Elements<T, N> for () {
    #[inline(always)]
    fn add_forces(&self, _q: &[T], _qd: &[T], _out: &mut SVector<T, N>) {}
    #[inline(always)]
    fn add_tangent(
        &self,
        _q: &[T],
        _qd: &[T],
        _k: &mut SMatrix<T, N, N>,
        _c: &mut SMatrix<T, N, N>,
    ) {
    }
}

impl<T: Real, const N: usize, L: ForceLaw<T>> Elements<T, N> for Element<T, N, L> {
    #[inline(always)]
    fn add_forces(&self, q: &[T], qd: &[T], out: &mut SVector<T, N>) {
        let g = self.coordinate.value(q);
        let gd = self.coordinate.rate(qd);
        let f = self.law.force(g, gd);
        self.coordinate.distribute(f, out);
    }

    fn add_tangent(&self, q: &[T], qd: &[T], k: &mut SMatrix<T, N, N>, c: &mut SMatrix<T, N, N>) {
        let g = self.coordinate.value(q);
        let gd = self.coordinate.rate(qd);
        let (fg, fv) = self.law.partials(g, gd);
        let w = &self.coordinate.weights;
        for i in 0..N {
            if w[i] == T::zero() {
                continue;
            }
            for j in 0..N {
                k[(i, j)] += fg * w[i] * w[j];
                c[(i, j)] += fv * w[i] * w[j];
            }
        }
    }

    fn velocity_exponent_on<Map>(&self, map: &Map) -> Option<T>
    where
        Map: Fn(&Coordinate<T, N>, T) -> Option<T>,
    {
        self.law
            .velocity_exponent()
            .and_then(|q| map(&self.coordinate, q))
    }

    fn contact_onset_on<R, Map>(&self, map: &Map) -> Option<R>
    where
        Map: Fn(&Coordinate<T, N>, ContactOnset<T>) -> Option<R>,
    {
        self.law
            .contact_onset()
            .and_then(|o| map(&self.coordinate, o))
    }
}

impl<T: Real, const N: usize, E: Elements<T, N>, const K: usize> Elements<T, N> for [E; K] {
    #[inline(always)]
    fn add_forces(&self, q: &[T], qd: &[T], out: &mut SVector<T, N>) {
        for e in self {
            e.add_forces(q, qd, out);
        }
    }
    fn add_tangent(&self, q: &[T], qd: &[T], k: &mut SMatrix<T, N, N>, c: &mut SMatrix<T, N, N>) {
        for e in self {
            e.add_tangent(q, qd, k, c);
        }
    }
    fn velocity_exponent_on<Map>(&self, map: &Map) -> Option<T>
    where
        Map: Fn(&Coordinate<T, N>, T) -> Option<T>,
    {
        self.iter()
            .fold(None, |q, e| min_exponent(q, e.velocity_exponent_on(map)))
    }
    fn contact_onset_on<R, Map>(&self, map: &Map) -> Option<R>
    where
        Map: Fn(&Coordinate<T, N>, ContactOnset<T>) -> Option<R>,
    {
        self.iter().find_map(|e| e.contact_onset_on(map))
    }
}

macro_rules! element_tuple {
    ($($name:ident $idx:tt),+) => {
        impl<T: Real, const N: usize, $($name: Elements<T, N>),+> Elements<T, N> for ($($name,)+) {
            #[inline(always)]
            fn add_forces(&self, q: &[T], qd: &[T], out: &mut SVector<T, N>) {
                $(self.$idx.add_forces(q, qd, out);)+
            }
            fn add_tangent(&self, q: &[T], qd: &[T], k: &mut SMatrix<T, N, N>, c: &mut SMatrix<T, N, N>) {
                $(self.$idx.add_tangent(q, qd, k, c);)+
            }
            fn velocity_exponent_on<Map>(&self, map: &Map) -> Option<T>
            where
                Map: Fn(&Coordinate<T, N>, T) -> Option<T>,
            {
                let mut q = None;
                $(q = min_exponent(q, self.$idx.velocity_exponent_on(map));)+
                q
            }
            fn contact_onset_on<R, Map>(&self, map: &Map) -> Option<R>
            where
                Map: Fn(&Coordinate<T, N>, ContactOnset<T>) -> Option<R>,
            {
                let mut o = None;
                $(o = o.or_else(|| self.$idx.contact_onset_on(map));)+
                o
            }
        }
    };
}

element_tuple!(A 0);
element_tuple!(A 0, B 1);
element_tuple!(A 0, B 1, C 2);
element_tuple!(A 0, B 1, C 2, D 3);
element_tuple!(A 0, B 1, C 2, D 3, E 4);
element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5);
element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);
element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8);
element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9);
element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9, K 10);
element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9, K 10, L 11);

/// An excitation `f(t)` applied through a [`Coordinate`]: generalized forces `w·f(t)` on
/// the right-hand side (for a DOF, the force on that mass; for `q_i − q_j`, equal and
/// opposite forces on the two masses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Load<T: Real, const N: usize, E> {
    /// Where the load acts.
    pub coordinate: Coordinate<T, N>,
    /// The excitation.
    pub excitation: E,
}

impl<T: Real, const N: usize, E: Excitation<T>> Load<T, N, E> {
    /// The excitation acting on DOF `i`.
    ///
    /// # Errors
    /// [`ModelError::DofOutOfRange`] unless `i < N`.
    pub fn on_dof(i: usize, excitation: E) -> Result<Self, ModelError> {
        Ok(Self {
            coordinate: Coordinate::dof(i)?,
            excitation,
        })
    }
}

/// A set of loads: a [`Load`], `()`, tuples of up to eight sets and arrays `[E; K]`.
pub trait Loads<T: Real, const N: usize> {
    /// Adds the generalized forces `Σ w·f(t)` to `out`.
    fn add_forces(&self, t: T, out: &mut SVector<T, N>);
    /// Adds `Σ w·ḟ(t)` to `out`.
    fn add_rates(&self, t: T, out: &mut SVector<T, N>);
    /// The phase of the first periodic load (for stroboscopic sections), if any.
    fn phase(&self, _t: T) -> Option<T> {
        None
    }
    /// The shortest [`time_scale`](Excitation::time_scale) of the loads near `t`, if any
    /// load declares one.
    fn time_scale(&self, _t: T) -> Option<T> {
        None
    }
}

/// The smaller of two optional time scales.
pub(crate) fn shorter<T: Real>(a: Option<T>, b: Option<T>) -> Option<T> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

impl<T: Real, const N: usize> Loads<T, N> for () {
    #[inline(always)]
    fn add_forces(&self, _t: T, _out: &mut SVector<T, N>) {}
    #[inline(always)]
    fn add_rates(&self, _t: T, _out: &mut SVector<T, N>) {}
}

impl<T: Real, const N: usize, E: Excitation<T>> Loads<T, N> for Load<T, N, E> {
    #[inline(always)]
    fn add_forces(&self, t: T, out: &mut SVector<T, N>) {
        let f = self.excitation.force(t);
        self.coordinate.distribute(f, out);
    }
    #[inline(always)]
    fn add_rates(&self, t: T, out: &mut SVector<T, N>) {
        let f = self.excitation.force_rate(t);
        self.coordinate.distribute(f, out);
    }
    fn phase(&self, t: T) -> Option<T> {
        self.excitation.phase(t)
    }
    fn time_scale(&self, t: T) -> Option<T> {
        self.excitation.time_scale(t)
    }
}

impl<T: Real, const N: usize, E: Loads<T, N>, const K: usize> Loads<T, N> for [E; K] {
    #[inline(always)]
    fn add_forces(&self, t: T, out: &mut SVector<T, N>) {
        for e in self {
            e.add_forces(t, out);
        }
    }
    #[inline(always)]
    fn add_rates(&self, t: T, out: &mut SVector<T, N>) {
        for e in self {
            e.add_rates(t, out);
        }
    }
    fn phase(&self, t: T) -> Option<T> {
        self.iter().find_map(|e| e.phase(t))
    }
    fn time_scale(&self, t: T) -> Option<T> {
        self.iter().fold(None, |m, e| shorter(m, e.time_scale(t)))
    }
}

macro_rules! load_tuple {
    ($($name:ident $idx:tt),+) => {
        impl<T: Real, const N: usize, $($name: Loads<T, N>),+> Loads<T, N> for ($($name,)+) {
            #[inline(always)]
            fn add_forces(&self, t: T, out: &mut SVector<T, N>) {
                $(self.$idx.add_forces(t, out);)+
            }
            #[inline(always)]
            fn add_rates(&self, t: T, out: &mut SVector<T, N>) {
                $(self.$idx.add_rates(t, out);)+
            }
            fn phase(&self, t: T) -> Option<T> {
                None $(.or_else(|| self.$idx.phase(t)))+
            }
            fn time_scale(&self, t: T) -> Option<T> {
                let m = None;
                $(let m = shorter(m, self.$idx.time_scale(t));)+
                m
            }
        }
    };
}

load_tuple!(A 0);
load_tuple!(A 0, B 1);
load_tuple!(A 0, B 1, C 2);
load_tuple!(A 0, B 1, C 2, D 3);
load_tuple!(A 0, B 1, C 2, D 3, E 4);
load_tuple!(A 0, B 1, C 2, D 3, E 4, F 5);
load_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
load_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);

/// An `N`-DOF mechanical system with state `y = (q, q̇)` of dimension `M = 2N`:
/// $$\mathbf M\ddot q + \mathbf C\dot q + \mathbf K q + \sum_e w_e\,F_e(w_e\cdot q + o_e,\;
///   w_e\cdot\dot q) = \sum_l w_l f_l(t).$$
///
/// The mass matrix `M` is symmetric positive definite (diagonal for lumped masses), `K` and
/// `C` are optional linear stiffness and damping matrices, the elements are any
/// [`ForceLaw`]s acting on [`Coordinate`]s (springs between masses, contacts on either
/// side, friction pairs) and the loads are [`Excitation`]s acting on coordinates.
///
/// # Model
/// The first-order form is `ẏ = (q̇, M⁻¹(f(t) − Kq − Cq̇ − Σ w F))`. The Jacobian is
/// assembled from the laws' analytic partials:
/// $$J = \begin{pmatrix} 0 & I \\ -\mathbf M^{-1}\mathbf K_t & -\mathbf M^{-1}\mathbf C_t
///   \end{pmatrix},\quad \mathbf K_t = \mathbf K + \sum_e \partial_g F_e\, w_e w_e^{\mathsf T},
///   \quad \mathbf C_t = \mathbf C + \sum_e \partial_{\dot g} F_e\, w_e w_e^{\mathsf T}.$$
///
/// # Dimensions
/// `N` is inferred from the masses, and `M` from the state the system is used with; the
/// constructor checks `M = 2N` at compile time, so a mismatch is a compile error, not a
/// run-time panic. The 1-DOF [`Oscillator`](crate::model::Oscillator) is the same model for
/// `N = 1` with scalar arithmetic (the two give bit-identical right-hand sides, tested).
///
/// # Size limit
/// `1 ≤ N ≤ 64` ([`MAX_DOFS`](Self::MAX_DOFS)), checked at compile time like `M = 2N`.
/// The matrices are `nalgebra` static matrices stored inline: the model holds six `N×N`
/// blocks and a run with an implicit stepper several `2N×2N` Jacobians, all on the stack.
/// With 64 degrees of freedom a run with [`Rosenbrock23`](crate::integrate::Rosenbrock23)
/// fits the 2 MiB stack of a spawned thread (a test, a rayon worker); a chain of 100 masses
/// does not, and 400 masses overflow even the 8 MiB main thread.
/// ```compile_fail
/// # use nonsmooth::model::Mechanical;
/// let none = Mechanical::<f64, 0>::with_masses([]); // no degrees of freedom
/// ```
/// ```compile_fail
/// # use nonsmooth::model::Mechanical;
/// let chain = Mechanical::<f64, 400>::with_masses([1.0; 400]); // beyond MAX_DOFS
/// ```
///
/// # Examples
/// A primary mass on a spring, forced, with a secondary mass attached to it hitting a Hertz
/// stop 1 mm above its rest position:
/// ```
/// use nonsmooth::Dynamics;
/// use nonsmooth::excite::Harmonic;
/// use nonsmooth::force::{HertzContact, LinearSpring, ViscousDamper};
/// use nonsmooth::model::{Element, Load, Mechanical};
/// use nalgebra::SVector;
///
/// let model = Mechanical::with_masses([1.0, 0.2])?
///     .with_elements((
///         Element::on_dof(0, (LinearSpring::new(100.0)?, ViscousDamper::new(0.1)?))?,
///         Element::between(1, 0, (LinearSpring::new(20.0)?, ViscousDamper::new(0.02)?))?,
///         Element::on_dof(1, HertzContact::new(1e-3, 1e7)?)?,
///     ))
///     .with_loads(Load::on_dof(0, Harmonic::new(1.0, 9.0, 0.0)?)?);
/// let y = SVector::<f64, 4>::new(0.0, 2e-3, 0.0, 0.0); // secondary mass 1 mm into the stop
/// let mut dy = SVector::zeros();
/// model.rhs(0.0, &y, &mut dy);
/// let contact = 1e7 * (1e-3f64).powf(1.5);
/// assert!((dy[3] - (-20.0 * 2e-3 - contact) / 0.2).abs() < 1e-9);
/// assert!((dy[2] - 20.0 * 2e-3 / 1.0).abs() < 1e-12); // sin(0) = 0: no load yet
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanical<T: Real, const N: usize, El = (), Ld = ()> {
    mass: SMatrix<T, N, N>,
    inv_mass: SMatrix<T, N, N>,
    diagonal: bool,
    stiffness: Option<SMatrix<T, N, N>>,
    damping: Option<SMatrix<T, N, N>>,
    /// `[K, C]` (an absent matrix as zeros) if either is given: one test on the hot path.
    linear: Option<[SMatrix<T, N, N>; 2]>,
    elements: El,
    loads: Ld,
}

/// The state of `N` degrees of freedom is `(q, q̇)`, `M = 2N` components: checked when the
/// code is compiled (a mismatch does not build), so the type names `N` only and `M` is
/// inferred from the state a run starts from.
#[inline(always)]
pub(crate) const fn state_size<const N: usize, const M: usize>() {
    const {
        assert!(
            M == 2 * N,
            "the state of a Mechanical system of N DOFs has M = 2N components"
        )
    };
}

/// The largest number of degrees of freedom of a [`Mechanical`] system (see its size limit).
const MAX_DOFS: usize = 64;

impl<T: Real, const N: usize, El, Ld> Mechanical<T, N, El, Ld> {
    /// The largest number of degrees of freedom `N` (64): the constructors do not compile
    /// for larger `N`, nor for `N = 0` (see the type's size limit).
    pub const MAX_DOFS: usize = MAX_DOFS;
}

impl<T: Real, const N: usize> Mechanical<T, N, (), ()> {
    /// A system of `N` lumped masses (diagonal mass matrix), no elements, no loads.
    ///
    /// # Errors
    /// [`ParameterError`] unless every mass is finite and > 0 with a finite inverse
    /// (`mass ≥ 5.6·10⁻³⁰⁹` for `f64`).
    pub fn with_masses(masses: [T; N]) -> Result<Self, ParameterError> {
        const {
            assert!(
                N >= 1 && N <= MAX_DOFS,
                "Mechanical needs 1 ≤ N ≤ 64 degrees of freedom (its matrices are on the stack)"
            )
        };
        let mut mass = SMatrix::zeros();
        let mut inv_mass = SMatrix::zeros();
        for (i, &m) in masses.iter().enumerate() {
            let m = crate::validate::positive("mass", m)?;
            let inv = T::one() / m;
            if !inv.is_finite() {
                return Err(ParameterError::new(
                    "mass",
                    to_f64(m),
                    "large enough that 1/mass is finite",
                ));
            }
            mass[(i, i)] = m;
            inv_mass[(i, i)] = inv;
        }
        Ok(Self {
            mass,
            inv_mass,
            diagonal: true,
            stiffness: None,
            damping: None,
            linear: None,
            elements: (),
            loads: (),
        })
    }

    /// A system with a full symmetric positive-definite mass matrix.
    ///
    /// The factorization and the inverse are computed for the matrix divided by the power
    /// of two nearest below its largest entry (exactly, so the result is that of the matrix
    /// itself), and scaled back: a well-conditioned matrix of any magnitude is accepted as
    /// long as its inverse is finite.
    ///
    /// # Errors
    /// [`ModelError`] if an entry is not finite, the matrix is not symmetric (to 8 ulps of
    /// its largest entry) or not positive definite (Cholesky fails), and
    /// [`ModelError::MassInverseOverflow`] if its inverse is not finite.
    pub fn with_mass_matrix(mass: SMatrix<T, N, N>) -> Result<Self, ModelError> {
        const {
            assert!(
                N >= 1 && N <= MAX_DOFS,
                "Mechanical needs 1 ≤ N ≤ 64 degrees of freedom (its matrices are on the stack)"
            )
        };
        check_finite("mass", &mass)?;
        let scale = mass.amax();
        for i in 0..N {
            for j in 0..i {
                if (mass[(i, j)] - mass[(j, i)]).abs()
                    > lit::<T>(8.0) * T::default_epsilon() * scale
                {
                    return Err(ModelError::MassMatrix {
                        reason: "not symmetric",
                    });
                }
            }
        }
        // Dividing by a power of two is exact: the factorization and the inverse of the
        // unit-scale matrix are those of `mass`, without the overflow or underflow of the
        // products (a determinant of 10⁶⁰⁰ or 10⁻³⁴⁰) at extreme magnitudes.
        let s = power_of_two_below(scale);
        let unit = mass.map(|m| m / s);
        if unit.cholesky().is_none() {
            return Err(ModelError::MassMatrix {
                reason: "Cholesky factorization failed",
            });
        }
        let inv_mass = unit
            .try_inverse()
            .ok_or(ModelError::MassMatrix { reason: "singular" })?
            .map(|m| m / s);
        if inv_mass.iter().any(|m| !m.is_finite()) {
            let smallest = (0..N).fold(f64::INFINITY, |a, i| a.min(to_f64(mass[(i, i)])));
            return Err(ModelError::MassInverseOverflow {
                smallest_mass: smallest,
            });
        }
        let diagonal = (0..N).all(|i| (0..N).all(|j| i == j || mass[(i, j)] == T::zero()));
        Ok(Self {
            mass,
            inv_mass,
            diagonal,
            stiffness: None,
            damping: None,
            linear: None,
            elements: (),
            loads: (),
        })
    }
}

/// The largest power of two `≤ x` for a positive normal `x` (1 for 0, the smallest normal
/// `f64` for smaller `x`), in `T`.
fn power_of_two_below<T: Real>(x: T) -> T {
    let f = to_f64(x);
    if f == 0.0 {
        return T::one();
    }
    let f = f.max(f64::MIN_POSITIVE);
    lit(f64::from_bits(f.to_bits() & 0x7ff0_0000_0000_0000))
}

fn check_finite<T: Real, const N: usize>(
    name: &'static str,
    m: &SMatrix<T, N, N>,
) -> Result<(), ModelError> {
    for i in 0..N {
        for j in 0..N {
            if !m[(i, j)].is_finite() {
                return Err(ModelError::NonFiniteMatrix {
                    name,
                    row: i,
                    col: j,
                });
            }
        }
    }
    Ok(())
}

impl<T: Real, const N: usize, El, Ld> Mechanical<T, N, El, Ld> {
    /// Replaces the elements (a tuple or array of [`Element`]s).
    pub fn with_elements<El2: Elements<T, N>>(self, elements: El2) -> Mechanical<T, N, El2, Ld> {
        Mechanical {
            mass: self.mass,
            inv_mass: self.inv_mass,
            diagonal: self.diagonal,
            stiffness: self.stiffness,
            damping: self.damping,
            linear: self.linear,
            elements,
            loads: self.loads,
        }
    }

    /// Replaces the loads (a tuple or array of [`Load`]s).
    pub fn with_loads<Ld2: Loads<T, N>>(self, loads: Ld2) -> Mechanical<T, N, El, Ld2> {
        Mechanical {
            mass: self.mass,
            inv_mass: self.inv_mass,
            diagonal: self.diagonal,
            stiffness: self.stiffness,
            damping: self.damping,
            linear: self.linear,
            elements: self.elements,
            loads,
        }
    }

    /// `[K, C]`, an absent matrix as zeros.
    fn linear_part(&self) -> [SMatrix<T, N, N>; 2] {
        [
            self.stiffness.unwrap_or_else(SMatrix::zeros),
            self.damping.unwrap_or_else(SMatrix::zeros),
        ]
    }

    /// Sets the linear stiffness matrix `K` (not required to be symmetric: follower forces
    /// and gyroscopic couplings are allowed).
    ///
    /// # Errors
    /// [`ModelError::NonFiniteMatrix`] if an entry is not finite.
    pub fn with_stiffness(mut self, k: SMatrix<T, N, N>) -> Result<Self, ModelError> {
        check_finite("stiffness", &k)?;
        self.stiffness = Some(k);
        self.linear = Some(self.linear_part());
        Ok(self)
    }

    /// Sets the linear damping matrix `C`.
    ///
    /// # Errors
    /// [`ModelError::NonFiniteMatrix`] if an entry is not finite.
    pub fn with_damping(mut self, c: SMatrix<T, N, N>) -> Result<Self, ModelError> {
        check_finite("damping", &c)?;
        self.damping = Some(c);
        self.linear = Some(self.linear_part());
        Ok(self)
    }

    /// The mass matrix.
    pub fn mass_matrix(&self) -> &SMatrix<T, N, N> {
        &self.mass
    }

    /// The inverse mass matrix `M⁻¹`.
    pub fn inverse_mass_matrix(&self) -> &SMatrix<T, N, N> {
        &self.inv_mass
    }

    /// The elements.
    pub fn elements(&self) -> &El {
        &self.elements
    }

    /// The loads.
    pub fn loads(&self) -> &Ld {
        &self.loads
    }
}

impl<T: Real, const N: usize, El: Elements<T, N>, Ld: Loads<T, N>> Mechanical<T, N, El, Ld> {
    /// The generalized force `f(t) − Kq − Cq̇ − Σ w F` (the right-hand side before `M⁻¹`).
    #[inline(always)]
    pub fn generalized_force(&self, t: T, q: &[T], qd: &[T]) -> SVector<T, N> {
        // Accumulators start at −0, the identity of floating-point addition (−0 + x = x
        // for every x), so the first term of each sum costs nothing once inlined: for one
        // DOF without `K`, `C` this is `f(t) − ΣF` as in the scalar oscillator, to the bit.
        // Loads first: their sines overlap with the laws' arithmetic (as in the scalar
        // oscillator's `f(t) − F(x, ẋ)`).
        let mut load = SVector::<T, N>::repeat(-T::zero());
        self.loads.add_forces(t, &mut load);
        let mut r = SVector::<T, N>::repeat(-T::zero());
        self.elements.add_forces(q, qd, &mut r);
        // K q then C q̇, each summed in index order (an absent matrix adds zeros).
        if let Some([k, c]) = &self.linear {
            for i in 0..N {
                for j in 0..N {
                    r[i] += k[(i, j)] * q[j];
                }
                for j in 0..N {
                    r[i] += c[(i, j)] * qd[j];
                }
            }
        }
        load - r
    }

    /// The unconstrained acceleration `q̈ = M⁻¹ f(t, q, q̇)` at the state `y = (q, q̇)`
    /// (`M = 2N`, checked at compile time).
    pub fn acceleration<const M: usize>(&self, t: T, y: &SVector<T, M>) -> SVector<T, N> {
        state_size::<N, M>();
        let (q, qd) = y.as_slice().split_at(N);
        self.inv_mass * self.generalized_force(t, q, qd)
    }

    /// The shortest [`time_scale`](Excitation::time_scale) of the loads near `t`, if any
    /// declares one: the bound on the step of a mode in which the state can stay constant
    /// while the loads change (sticking, stick–slip).
    pub fn forcing_time_scale(&self, t: T) -> Option<T> {
        self.loads.time_scale(t)
    }

    /// `(M⁻¹w, wᵀM⁻¹w)` for a direction `w` (a coordinate's weights): the accelerations a
    /// unit generalized force along `w` causes, and their component along `w` (the inverse
    /// effective mass of the coordinate).
    pub fn mobility(&self, w: &SVector<T, N>) -> (SVector<T, N>, T) {
        let m_w = self.inv_mass * w;
        let w_m_w = w.dot(&m_w);
        (m_w, w_m_w)
    }

    /// The tangent stiffness `K_t` and damping `C_t` at `(q, q̇)`.
    pub fn tangent(&self, q: &[T], qd: &[T]) -> (SMatrix<T, N, N>, SMatrix<T, N, N>) {
        let mut k = self.stiffness.unwrap_or_else(SMatrix::zeros);
        let mut c = self.damping.unwrap_or_else(SMatrix::zeros);
        self.elements.add_tangent(q, qd, &mut k, &mut c);
        (k, c)
    }

    /// The static restoring force `R(q) = Kq + Σ w F(g, 0)` (no loads).
    pub fn restoring_force(&self, q: &SVector<T, N>) -> SVector<T, N> {
        let zero = SVector::<T, N>::zeros();
        let mut r = SVector::<T, N>::zeros();
        self.elements
            .add_forces(q.as_slice(), zero.as_slice(), &mut r);
        if let Some(k) = &self.stiffness {
            r += k * q;
        }
        r
    }

    /// The static equilibrium `R(q) = load` by Newton's method with the assembled tangent
    /// stiffness and a backtracking line search on `‖R − load‖₂`, from the guess `q0`
    /// (`load` is a constant generalized force, e.g. weights; zero for none). Converged when
    /// the Newton step is at most `4·ε_mach·‖q‖∞` (or the residual is exactly zero).
    ///
    /// # Errors
    /// [`ModelError::SingularStiffness`] if the tangent stiffness is singular at an iterate,
    /// [`ModelError::EquilibriumNotConverged`] after 100 iterations or if the residual is
    /// not finite.
    pub fn static_equilibrium(
        &self,
        q0: SVector<T, N>,
        load: SVector<T, N>,
    ) -> Result<SVector<T, N>, ModelError> {
        let zero = SVector::<T, N>::zeros();
        let residual = |q: &SVector<T, N>| self.restoring_force(q) - load;
        let mut q = q0;
        let mut r = residual(&q);
        let max_iter = 100;
        for it in 0..max_iter {
            let rn = r.amax();
            if !rn.is_finite() {
                return Err(ModelError::EquilibriumNotConverged {
                    iterations: it,
                    residual: to_f64(rn),
                });
            }
            let (k, _) = self.tangent(q.as_slice(), zero.as_slice());
            let lu = Lu::new(k).ok_or(ModelError::SingularStiffness { iteration: it })?;
            let dq = lu.solve(&(-r));
            // Backtracking on the residual norm.
            let mut lambda = T::one();
            let mut q_new = q + dq;
            let mut r_new = residual(&q_new);
            let mut tries = 0;
            while !(r_new.norm() < r.norm()) && tries < 30 {
                lambda *= lit(0.5);
                q_new = q + dq * lambda;
                r_new = residual(&q_new);
                tries += 1;
            }
            let step = (q_new - q).amax();
            q = q_new;
            r = r_new;
            let scale = q.amax();
            if step <= lit::<T>(4.0) * T::default_epsilon() * scale || r.amax() == T::zero() {
                return Ok(q);
            }
        }
        Err(ModelError::EquilibriumNotConverged {
            iterations: max_iter,
            residual: to_f64(r.amax()),
        })
    }
}

impl<T: Real, const N: usize, const M: usize, El: Elements<T, N>, Ld: Loads<T, N>> Dynamics<T, M>
    for Mechanical<T, N, El, Ld>
{
    #[inline(always)]
    fn rhs(&self, t: T, y: &SVector<T, M>, dy: &mut SVector<T, M>) {
        state_size::<N, M>();
        let (q, qd) = y.as_slice().split_at(N);
        let f = self.generalized_force(t, q, qd);
        for i in 0..N {
            dy[i] = qd[i];
        }
        if N == 1 || self.diagonal {
            for i in 0..N {
                dy[N + i] = f[i] * self.inv_mass[(i, i)];
            }
        } else {
            let a = self.inv_mass * f;
            for i in 0..N {
                dy[N + i] = a[i];
            }
        }
    }

    fn jacobian(&self, _t: T, y: &SVector<T, M>) -> Option<SMatrix<T, M, M>> {
        state_size::<N, M>();
        let (q, qd) = y.as_slice().split_at(N);
        let (k, c) = self.tangent(q, qd);
        let ak = -(self.inv_mass * k);
        let ac = -(self.inv_mass * c);
        let mut j = SMatrix::<T, M, M>::zeros();
        for i in 0..N {
            j[(i, N + i)] = T::one();
            for l in 0..N {
                j[(N + i, l)] = ak[(i, l)];
                j[(N + i, N + l)] = ac[(i, l)];
            }
        }
        Some(j)
    }

    fn time_derivative(&self, t: T, _y: &SVector<T, M>) -> Option<SVector<T, M>> {
        state_size::<N, M>();
        let mut fd = SVector::<T, N>::zeros();
        self.loads.add_rates(t, &mut fd);
        let a = self.inv_mass * fd;
        let mut out = SVector::<T, M>::zeros();
        for i in 0..N {
            out[N + i] = a[i];
        }
        Some(out)
    }

    /// For one degree of freedom (state `(x, ẋ)`): the smallest velocity exponent that the
    /// elements' laws declare ([`Elements::velocity_exponent_on`]). A law on the coordinate
    /// `g = w·x + o` has its cusp in `ġ = w·ẋ`, so at `ẋ = 0` with the same exponent
    /// (`|ġ|^q = |w|^q·|ẋ|^q`): every coordinate of one degree of freedom counts, the
    /// degree of freedom itself, reversed (`w = −1`), offset or scaled. Loads do not
    /// matter.
    ///
    /// `None` for `N > 1`: [`TurningPoints`](crate::integrate::TurningPoints) crosses
    /// `ẋ = 0` of a one-degree-of-freedom system with state `(x, ẋ)`; a cusp in the rate of
    /// one coordinate of several degrees of freedom is no turning point of the state's
    /// second component (read the declarations per coordinate with
    /// [`Elements::velocity_exponent_on`]).
    fn velocity_exponent(&self) -> Option<T> {
        state_size::<N, M>();
        if N != 1 {
            return None;
        }
        self.elements
            .velocity_exponent_on(&|c: &Coordinate<T, N>, q| {
                let w = c.weights()[0];
                (w != T::zero() && w.is_finite()).then_some(q)
            })
    }

    /// For any number of degrees of freedom (state `(q, q̇)`): the smallest velocity
    /// exponent that the elements' laws declare on any coordinate with finite weights
    /// (a cusp in `ġ = w·q̇` is a cusp in the velocities).
    fn cusp_exponent(&self) -> Option<T> {
        state_size::<N, M>();
        self.elements
            .velocity_exponent_on(&|c: &Coordinate<T, N>, q| {
                c.weights().iter().all(|w| w.is_finite()).then_some(q)
            })
    }

    /// For one degree of freedom (state `(x, ẋ)`): the first contact onset that the
    /// elements' laws declare ([`Elements::contact_onset_on`]), mapped from the law's
    /// coordinate `g = w·x + o` to `x`. A stop `g_I` on the side `Upper` (`δ_g = g − g_I`)
    /// is the stop `x_I = (g_I − o)/w` in `x`, on the same side for `w > 0` and on the other
    /// side for `w < 0`: a law on the reversed degree of freedom (`w = −1`, e.g. a stop put
    /// on the other side with [`Coordinate::reversed`]) or with an offset is crossed as
    /// well. The exponent is the law's; the penetration is measured in `x`,
    /// `δ = δ_g/|w|` (exactly `δ_g` for `w = ±1`, up to the rounding of `g_I − o` with an
    /// offset), so the stepper's onset band is a band in `x`. For `w = 1`, `o = 0` (a law
    /// on the degree of freedom itself) the onset is the law's unchanged. An onset whose
    /// mapped stop is not finite is skipped. Loads do not matter.
    ///
    /// `None` for `N > 1` (as [`velocity_exponent`](Dynamics::velocity_exponent); read the
    /// declarations per coordinate with [`Elements::contact_onset_on`]).
    fn contact_onset(&self) -> Option<ContactOnset<T>> {
        state_size::<N, M>();
        if N != 1 {
            return None;
        }
        self.elements
            .contact_onset_on(&|c: &Coordinate<T, N>, onset: ContactOnset<T>| {
                one_dof_onset(c.weights()[0], c.offset(), onset)
            })
    }
}

/// The onset of a contact on the coordinate `g = w·x + o` of one degree of freedom, as an
/// onset in `x` (see [`Mechanical`]'s `contact_onset`); `None` if `w` is zero or not
/// finite, or the stop in `x` is not finite.
fn one_dof_onset<T: Real>(w: T, o: T, onset: ContactOnset<T>) -> Option<ContactOnset<T>> {
    if !(w != T::zero() && w.is_finite()) {
        return None;
    }
    if w == T::one() && o == T::zero() {
        return Some(onset);
    }
    let position = (onset.position - o) / w;
    let side = match (onset.side, w > T::zero()) {
        (side, true) => side,
        (Side::Upper, false) => Side::Lower,
        (Side::Lower, false) => Side::Upper,
    };
    position.is_finite().then_some(ContactOnset {
        position,
        side,
        exponent: onset.exponent,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::excite::Harmonic;
    use crate::force::{HertzContact, LinearSpring, ViscousDamper};

    #[test]
    fn coordinates_validate_and_evaluate() {
        assert!(Coordinate::<f64, 2>::dof(2).is_err());
        assert!(Coordinate::<f64, 2>::relative(1, 1).is_err());
        assert!(Coordinate::<f64, 2>::linear([0.0, 0.0]).is_err());
        assert!(Coordinate::<f64, 2>::linear([f64::NAN, 1.0]).is_err());
        let g = Coordinate::<f64, 3>::relative(2, 0)
            .unwrap()
            .with_offset(0.5)
            .unwrap();
        assert_eq!(g.value(&[1.0, 7.0, 4.0]), 3.5);
        assert_eq!(g.rate(&[1.0, 7.0, 4.0]), 3.0);
        assert_eq!(g.reversed().value(&[1.0, 7.0, 4.0]), -3.5);
    }

    #[test]
    fn sparse_shapes_equal_the_general_linear_form_to_the_bit() {
        // The shortcuts for e_i, e_i − e_j (and offsets, reversal) must give exactly
        // o + Σ w_k q_k summed in index order, and distribute exactly w·F.
        let general = |c: &Coordinate<f64, 3>, start: f64, x: &[f64]| {
            let mut g = start;
            for (w, v) in c.weights().iter().zip(x) {
                g += *w * *v;
            }
            g
        };
        let coords = [
            Coordinate::<f64, 3>::dof(1).unwrap(),
            Coordinate::dof(2).unwrap().with_offset(0.3).unwrap(),
            Coordinate::dof(0).unwrap().reversed(),
            Coordinate::relative(0, 2).unwrap(),
            Coordinate::relative(2, 0)
                .unwrap()
                .with_offset(-1e-3)
                .unwrap(),
            Coordinate::relative(1, 2)
                .unwrap()
                .with_offset(0.7)
                .unwrap()
                .reversed(),
            Coordinate::linear([0.5, 0.0, -2.0]).unwrap(),
        ];
        let shapes: Vec<Shape> = coords.iter().map(|c| c.shape).collect();
        assert!(matches!(shapes[0], Shape::Dof(1)));
        assert!(matches!(shapes[1], Shape::DofOffset(2)));
        assert!(matches!(shapes[2], Shape::General));
        assert!(matches!(shapes[3], Shape::Pair { plus: 0, minus: 2 }));
        assert!(matches!(shapes[4], Shape::Pair { plus: 2, minus: 0 }));
        assert!(matches!(shapes[5], Shape::Pair { plus: 2, minus: 1 }));
        assert!(matches!(shapes[6], Shape::General));
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..1000 {
            let x = [next() * 1e-3, next(), next() * 1e3];
            let f = next() * 50.0;
            for c in &coords {
                assert_eq!(c.value(&x).to_bits(), general(c, c.offset(), &x).to_bits());
                assert_eq!(c.rate(&x).to_bits(), general(c, 0.0, &x).to_bits());
                let mut out = SVector::<f64, 3>::from([0.25, -1.0, 2.0]);
                let mut want = out;
                for k in 0..3 {
                    want[k] += c.weights()[k] * f;
                }
                c.distribute(f, &mut out);
                assert_eq!(out, want);
            }
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let model = Mechanical::with_masses([1.5, 0.5])
            .unwrap()
            .with_elements((
                Element::on_dof(
                    0,
                    (
                        LinearSpring::new(100.0).unwrap(),
                        ViscousDamper::new(0.3).unwrap(),
                    ),
                )
                .unwrap(),
                Element::between(1, 0, LinearSpring::new(40.0).unwrap()).unwrap(),
                Element::on_dof(
                    1,
                    HertzContact::new(1e-3, 1e6)
                        .unwrap()
                        .with_damping(0.5, 1.5, 1.0)
                        .unwrap(),
                )
                .unwrap(),
            ))
            .with_loads(Load::on_dof(0, Harmonic::new(1.0, 3.0, 0.2).unwrap()).unwrap());
        let y = SVector::<f64, 4>::new(1e-4, 1.8e-3, 0.02, -0.05);
        let j = model.jacobian(0.3, &y).unwrap();
        for col in 0..4 {
            let h = 1e-7 * y[col].abs().max(1e-6);
            let (mut yp, mut ym) = (y, y);
            yp[col] += h;
            ym[col] -= h;
            let (mut fp, mut fm) = (SVector::zeros(), SVector::zeros());
            model.rhs(0.3, &yp, &mut fp);
            model.rhs(0.3, &ym, &mut fm);
            let fd = (fp - fm) / (2.0 * h);
            for row in 0..4 {
                let scale = j[(row, col)].abs().max(1.0);
                assert!(
                    (fd[row] - j[(row, col)]).abs() < 1e-5 * scale,
                    "J[{row},{col}] = {} vs FD {}",
                    j[(row, col)],
                    fd[row]
                );
            }
        }
        // ∂f/∂t from the loads.
        let dt = model.time_derivative(0.3, &y).unwrap();
        let (mut fp, mut fm) = (SVector::zeros(), SVector::zeros());
        model.rhs(0.3 + 1e-6, &y, &mut fp);
        model.rhs(0.3 - 1e-6, &y, &mut fm);
        assert!(((fp[2] - fm[2]) / 2e-6 - dt[2]).abs() < 1e-6);
    }

    #[test]
    fn full_mass_matrix_equals_lumped_when_diagonal() {
        let lumped = Mechanical::with_masses([2.0, 3.0])
            .unwrap()
            .with_elements(Element::between(0, 1, LinearSpring::new(5.0).unwrap()).unwrap());
        let full =
            Mechanical::<f64, 2>::with_mass_matrix(SMatrix::<f64, 2, 2>::new(2.0, 0.0, 0.0, 3.0))
                .unwrap()
                .with_elements(Element::between(0, 1, LinearSpring::new(5.0).unwrap()).unwrap());
        let y = SVector::<f64, 4>::new(0.1, -0.2, 0.3, 0.4);
        let (mut a, mut b) = (SVector::zeros(), SVector::zeros());
        lumped.rhs(0.0, &y, &mut a);
        full.rhs(0.0, &y, &mut b);
        assert_eq!(a, b);
        // Coupled mass matrix: M·ÿ must equal the force.
        let m = SMatrix::<f64, 2, 2>::new(2.0, 0.5, 0.5, 3.0);
        let coupled = Mechanical::<f64, 2>::with_mass_matrix(m)
            .unwrap()
            .with_elements(Element::between(0, 1, LinearSpring::new(5.0).unwrap()).unwrap());
        coupled.rhs(0.0, &y, &mut b);
        let acc = nalgebra::Vector2::new(b[2], b[3]);
        let force = nalgebra::Vector2::new(-5.0 * 0.3, 5.0 * 0.3);
        assert!((m * acc - force).amax() < 1e-15);
        assert!(
            Mechanical::<f64, 2>::with_mass_matrix(SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 1.0))
                .is_err()
        );
        assert!(
            Mechanical::<f64, 2>::with_mass_matrix(SMatrix::<f64, 2, 2>::new(1.0, 0.1, 0.0, 1.0))
                .is_err()
        );
        assert!(Mechanical::with_masses([1.0, 0.0]).is_err());
    }

    #[test]
    fn static_equilibrium_of_a_two_mass_chain() {
        // Wall — k1 — m1 — k2 — m2, weights w1, w2 pulling along +q: exact q1 = (w1+w2)/k1,
        // q2 = q1 + w2/k2.
        let (k1, k2, w1, w2) = (100.0, 50.0, 3.0, 2.0);
        let model = Mechanical::with_masses([1.0, 1.0]).unwrap().with_elements((
            Element::on_dof(0, LinearSpring::new(k1).unwrap()).unwrap(),
            Element::between(1, 0, LinearSpring::new(k2).unwrap()).unwrap(),
        ));
        let q = model
            .static_equilibrium(SVector::zeros(), SVector::<f64, 2>::new(w1, w2))
            .unwrap();
        let q1 = (w1 + w2) / k1;
        assert!((q[0] - q1).abs() < 1e-15);
        assert!((q[1] - (q1 + w2 / k2)).abs() < 1e-15);
        // Nonlinear: a Hertz stop pressed by a weight: k_c·δ^{3/2} = w.
        let stop = Mechanical::with_masses([1.0])
            .unwrap()
            .with_elements(Element::on_dof(0, HertzContact::new(0.0, 1e6).unwrap()).unwrap());
        let q = stop
            .static_equilibrium(SVector::from([1e-4]), SVector::from([10.0]))
            .unwrap();
        assert!((q[0] - (10.0f64 / 1e6).powf(2.0 / 3.0)).abs() < 1e-15);
        // A free mass has no equilibrium under a load: singular stiffness.
        let free = Mechanical::with_masses([1.0]).unwrap();
        assert!(matches!(
            free.static_equilibrium(SVector::zeros(), SVector::from([1.0])),
            Err(ModelError::SingularStiffness { .. })
        ));
    }
}
