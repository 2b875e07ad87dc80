//! The smooth part of a Lagrangian system, `M(q) q̈ = f(t, q, q̇)`, and its contacts.

use crate::Real;
use crate::model::{Elements, Loads, Mechanical};
use crate::scalar::to_f64;
use crate::validate::ParameterError;

use super::error::TimeStepError;

/// The smooth dynamics `M(q) q̈ = f(t, q, q̇)` of a Lagrangian system with `dofs()`
/// generalized coordinates; the time-stepping scheme adds the contact impulses.
///
/// Slices passed to the methods have length `dofs()` (`mass`: `dofs()²`, row-major); the
/// outputs are overwritten.
///
/// # Examples
/// A point mass in a plane under gravity:
/// ```
/// use nonsmooth::timestep::Lagrangian;
/// struct Particle { m: f64, g: f64 }
/// impl Lagrangian<f64> for Particle {
///     fn dofs(&self) -> usize { 2 }
///     fn mass(&self, _q: &[f64], m: &mut [f64]) {
///         m.copy_from_slice(&[self.m, 0.0, 0.0, self.m]);
///     }
///     fn diagonal_mass(&self) -> bool { true }
///     fn forces(&self, _t: f64, _q: &[f64], _v: &[f64], f: &mut [f64]) {
///         f[0] = 0.0;
///         f[1] = -self.m * self.g;
///     }
///     fn potential(&self, _t: f64, q: &[f64]) -> f64 { self.m * self.g * q[1] }
/// }
/// ```
pub trait Lagrangian<T: Real> {
    /// The number of generalized coordinates.
    fn dofs(&self) -> usize;
    /// Writes the mass matrix `M(q)` (symmetric positive definite, row-major).
    fn mass(&self, q: &[T], m: &mut [T]);
    /// `true` if `M` does not depend on `q` (it is then factorized once per run).
    /// Default: `true`.
    fn constant_mass(&self) -> bool {
        true
    }
    /// `true` if `M` is diagonal (cheaper Delassus matrices). Default: `false`.
    fn diagonal_mass(&self) -> bool {
        false
    }
    /// Writes the generalized force `f(t, q, q̇)` (everything but the contacts).
    fn forces(&self, t: T, q: &[T], v: &[T], f: &mut [T]);
    /// The potential energy of the conservative forces, for the energy records.
    /// Default: 0 (then the records' total is the kinetic energy alone).
    fn potential(&self, _t: T, _q: &[T]) -> T {
        T::zero()
    }
    /// Writes the force Jacobians `K = −∂f/∂q` and `C = −∂f/∂q̇` at `(t, q, q̇)`
    /// (row-major, `dofs()²` each) and returns `true`; needed for
    /// [`MoreauJean::with_implicit_forces`](super::MoreauJean::with_implicit_forces).
    /// Default: `false` (not provided).
    fn force_jacobians(&self, _t: T, _q: &[T], _v: &[T], _k: &mut [T], _c: &mut [T]) -> bool {
        false
    }
}

/// A [`Mechanical`] system as the smooth part: its constant mass matrix and its generalized
/// force `f(t) − Kq − Cq̇ − Σ w F` (elements and loads), with its tangent stiffness and
/// damping as the force Jacobians. The potential energy is not known to it (reported as 0).
impl<T: Real, const N: usize, El: Elements<T, N>, Ld: Loads<T, N>> Lagrangian<T>
    for Mechanical<T, N, El, Ld>
{
    fn dofs(&self) -> usize {
        N
    }
    fn mass(&self, _q: &[T], m: &mut [T]) {
        let mm = self.mass_matrix();
        for i in 0..N {
            for j in 0..N {
                m[i * N + j] = mm[(i, j)];
            }
        }
    }
    fn diagonal_mass(&self) -> bool {
        let mm = self.mass_matrix();
        (0..N).all(|i| (0..N).all(|j| i == j || mm[(i, j)] == T::zero()))
    }
    fn forces(&self, t: T, q: &[T], v: &[T], f: &mut [T]) {
        let g = self.generalized_force(t, q, v);
        f[..N].copy_from_slice(g.as_slice());
    }
    /// The tangent stiffness and damping of the elements with `K` and `C`
    /// ([`Mechanical::tangent`]); the loads depend on time only.
    fn force_jacobians(&self, _t: T, q: &[T], v: &[T], k: &mut [T], c: &mut [T]) -> bool {
        let (kt, ct) = self.tangent(q, v);
        for i in 0..N {
            for j in 0..N {
                k[i * N + j] = kt[(i, j)];
                c[i * N + j] = ct[(i, j)];
            }
        }
        true
    }
}

/// The local geometry of a contact at `(t, q)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry<T> {
    /// The gap `g(q, t)` (≥ 0 when separated).
    pub gap: T,
}

/// The sparse rows `∂g/∂q` (normal) and the tangent direction of one contact, written by
/// [`Contact::evaluate`]: `(dof, value)` pairs, a repeated `dof` adds up.
#[derive(Debug)]
pub struct Jacobian<'a, T> {
    pub(crate) normal: &'a mut Vec<(usize, T)>,
    pub(crate) tangent: &'a mut Vec<(usize, T)>,
    pub(crate) dofs: usize,
    pub(crate) out_of_range: Option<usize>,
}

impl<T: Real> Jacobian<'_, T> {
    /// Adds `value` to `∂g/∂q_dof` (the normal row). An index `≥ dofs` is recorded and
    /// reported as an error by the scheme (never a panic).
    #[inline]
    pub fn normal(&mut self, dof: usize, value: T) {
        if dof < self.dofs {
            self.normal.push((dof, value));
        } else {
            self.out_of_range = Some(dof);
        }
    }

    /// Adds `value` to the tangent row (the relative tangential velocity is
    /// `Σ tangent·q̇ + drift`), used by frictional contacts.
    #[inline]
    pub fn tangent(&mut self, dof: usize, value: T) {
        if dof < self.dofs {
            self.tangent.push((dof, value));
        } else {
            self.out_of_range = Some(dof);
        }
    }

    /// The number of generalized coordinates of the system.
    pub fn dofs(&self) -> usize {
        self.dofs
    }
}

/// One unilateral contact `g(q, t) ≥ 0` with its impact and friction laws.
///
/// The relative normal velocity is `ġ = ∇g·q̇ + ∂g/∂t`, the tangential one
/// `u_t = t·q̇ + (explicit time term)`: [`evaluate`](Self::evaluate) writes the rows,
/// [`drift`](Self::drift) the time terms (moving surfaces).
///
/// # Examples
/// A point mass `(x, y)` above a table moving as `s(t) = A sin ωt`:
/// ```
/// use nonsmooth::timestep::{Contact, Geometry, Jacobian};
/// struct Table { a: f64, omega: f64, e: f64 }
/// impl Contact<f64> for Table {
///     fn evaluate(&self, t: f64, q: &[f64], jac: &mut Jacobian<'_, f64>) -> Geometry<f64> {
///         jac.normal(1, 1.0);
///         jac.tangent(0, 1.0);
///         Geometry { gap: q[1] - self.a * (self.omega * t).sin() }
///     }
///     fn drift(&self, t: f64, _q: &[f64]) -> [f64; 2] {
///         [-self.a * self.omega * (self.omega * t).cos(), 0.0]
///     }
///     fn restitution(&self) -> f64 { self.e }
/// }
/// ```
pub trait Contact<T: Real> {
    /// The gap at `(t, q)`, with the rows written into `jac`.
    fn evaluate(&self, t: T, q: &[T], jac: &mut Jacobian<'_, T>) -> Geometry<T>;
    /// The explicit time terms `[∂g/∂t, tangential]` of the relative velocities (moving
    /// surfaces). Default: `[0, 0]`.
    fn drift(&self, _t: T, _q: &[T]) -> [T; 2] {
        [T::zero(), T::zero()]
    }
    /// Newton's restitution coefficient `e ∈ [0, 1]`.
    fn restitution(&self) -> T;
    /// Coulomb's friction coefficient `μ ≥ 0`. Default: 0 (frictionless).
    fn friction(&self) -> T {
        T::zero()
    }
    /// Checks the contact against a system of `dofs` coordinates (e.g. body indices).
    /// Default: `Ok`.
    ///
    /// # Errors
    /// [`TimeStepError::Dimension`] for an index out of range.
    fn check(&self, _dofs: usize) -> Result<(), TimeStepError> {
        Ok(())
    }
}

/// A contact with constant rows over the first `K` coordinates: the gap
/// `g = normal·q + offset`, the tangential velocity `tangent·q̇` (a point on a fixed plane
/// in coordinates where both are linear, or a linearized contact such as the woodpecker's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearContact<T, const K: usize> {
    normal: [T; K],
    offset: T,
    tangent: [T; K],
    restitution: T,
    friction: T,
}

impl<T: Real, const K: usize> LinearContact<T, K> {
    /// The contact `g = normal·q + offset` with tangent row `tangent`, Newton's coefficient
    /// `restitution` and Coulomb's `friction`.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) naming a non-finite row entry or offset,
    /// a restitution outside `[0, 1]` or a negative friction coefficient.
    pub fn new(
        normal: [T; K],
        offset: T,
        tangent: [T; K],
        restitution: T,
        friction: T,
    ) -> Result<Self, TimeStepError> {
        use crate::validate::finite;
        for &n in &normal {
            finite("normal", n)?;
        }
        for &t in &tangent {
            finite("tangent", t)?;
        }
        finite("offset", offset)?;
        if !(restitution >= T::zero() && restitution <= T::one()) {
            return Err(
                ParameterError::new("restitution", to_f64(restitution), "in [0, 1]").into(),
            );
        }
        if !(friction >= T::zero() && friction.is_finite()) {
            return Err(
                ParameterError::new("friction", to_f64(friction), "finite and >= 0").into(),
            );
        }
        Ok(Self {
            normal,
            offset,
            tangent,
            restitution,
            friction,
        })
    }
}

impl<T: Real, const K: usize> Contact<T> for LinearContact<T, K> {
    fn evaluate(&self, _t: T, q: &[T], jac: &mut Jacobian<'_, T>) -> Geometry<T> {
        let mut gap = self.offset;
        let rows = self.normal.iter().zip(&self.tangent).zip(q);
        for (j, ((&n, &t), &x)) in rows.enumerate() {
            if n != T::zero() {
                jac.normal(j, n);
                gap += n * x;
            }
            if t != T::zero() {
                jac.tangent(j, t);
            }
        }
        Geometry { gap }
    }
    fn restitution(&self) -> T {
        self.restitution
    }
    fn friction(&self) -> T {
        self.friction
    }
    fn check(&self, dofs: usize) -> Result<(), TimeStepError> {
        if K > dofs {
            return Err(TimeStepError::Dimension {
                what: "linear contact rows",
                got: K,
                expected: dofs,
            });
        }
        Ok(())
    }
}

/// A collection of contacts, indexed `0..len()`: `Vec<C>`, `[C; K]` and pairs of sets
/// (`(A, B)`: `A`'s contacts first) — statically dispatched.
pub trait ContactSet<T: Real> {
    /// The number of contacts.
    fn len(&self) -> usize;
    /// `true` if there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Contact `i` (`i < len()`): [`Contact::evaluate`].
    fn evaluate(&self, i: usize, t: T, q: &[T], jac: &mut Jacobian<'_, T>) -> Geometry<T>;
    /// Contact `i`'s [`Contact::drift`].
    fn drift(&self, i: usize, t: T, q: &[T]) -> [T; 2];
    /// Contact `i`'s restitution.
    fn restitution(&self, i: usize) -> T;
    /// Contact `i`'s friction coefficient.
    fn friction(&self, i: usize) -> T;
    /// Contact `i`'s [`Contact::check`].
    ///
    /// # Errors
    /// As [`Contact::check`].
    fn check(&self, i: usize, dofs: usize) -> Result<(), TimeStepError>;
}

macro_rules! slice_set {
    () => {
        fn len(&self) -> usize {
            self[..].len()
        }
        fn evaluate(&self, i: usize, t: T, q: &[T], jac: &mut Jacobian<'_, T>) -> Geometry<T> {
            self[i].evaluate(t, q, jac)
        }
        fn drift(&self, i: usize, t: T, q: &[T]) -> [T; 2] {
            self[i].drift(t, q)
        }
        fn restitution(&self, i: usize) -> T {
            self[i].restitution()
        }
        fn friction(&self, i: usize) -> T {
            self[i].friction()
        }
        fn check(&self, i: usize, dofs: usize) -> Result<(), TimeStepError> {
            self[i].check(dofs)
        }
    };
}

impl<T: Real, C: Contact<T>> ContactSet<T> for Vec<C> {
    slice_set!();
}

impl<T: Real, C: Contact<T>, const K: usize> ContactSet<T> for [C; K] {
    slice_set!();
}

impl<T: Real, A: ContactSet<T>, B: ContactSet<T>> ContactSet<T> for (A, B) {
    fn len(&self) -> usize {
        self.0.len() + self.1.len()
    }
    fn evaluate(&self, i: usize, t: T, q: &[T], jac: &mut Jacobian<'_, T>) -> Geometry<T> {
        let n = self.0.len();
        if i < n {
            self.0.evaluate(i, t, q, jac)
        } else {
            self.1.evaluate(i - n, t, q, jac)
        }
    }
    fn drift(&self, i: usize, t: T, q: &[T]) -> [T; 2] {
        let n = self.0.len();
        if i < n {
            self.0.drift(i, t, q)
        } else {
            self.1.drift(i - n, t, q)
        }
    }
    fn restitution(&self, i: usize) -> T {
        let n = self.0.len();
        if i < n {
            self.0.restitution(i)
        } else {
            self.1.restitution(i - n)
        }
    }
    fn friction(&self, i: usize) -> T {
        let n = self.0.len();
        if i < n {
            self.0.friction(i)
        } else {
            self.1.friction(i - n)
        }
    }
    fn check(&self, i: usize, dofs: usize) -> Result<(), TimeStepError> {
        let n = self.0.len();
        if i < n {
            self.0.check(i, dofs)
        } else {
            self.1.check(i - n, dofs)
        }
    }
}
