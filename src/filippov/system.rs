//! The description of a Filippov system ([`Filippov`]): switching surfaces, their
//! gradients and the vector field in each region; the discrete state ([`Region`], [`Mode`]);
//! a closure adapter for one surface ([`Switched`]).

use nalgebra::{SMatrix, SVector};

use crate::Real;

/// The side of a switching surface `H(x) = 0`: `Minus` where `H < 0`, `Plus` where `H > 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Region {
    /// `H < 0`: the field `F₋`.
    Minus,
    /// `H > 0`: the field `F₊`.
    Plus,
}

impl Region {
    /// The side of a value's sign (`Plus` for `h ≥ 0`).
    pub fn of<T: Real>(h: T) -> Self {
        if h < T::zero() {
            Region::Minus
        } else {
            Region::Plus
        }
    }

    /// The other side.
    pub fn flip(self) -> Self {
        match self {
            Region::Minus => Region::Plus,
            Region::Plus => Region::Minus,
        }
    }

    /// `−1` or `+1`.
    pub fn sign<T: Real>(self) -> T {
        match self {
            Region::Minus => -T::one(),
            Region::Plus => T::one(),
        }
    }
}

/// The discrete state of a Filippov run: the side of every surface, and the surface the
/// state slides on, if any (its entry in `sides` is then the side it came from).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Mode<const S: usize> {
    /// The side of each surface.
    pub sides: [Region; S],
    /// `Some(i)` while sliding on surface `i`.
    pub sliding: Option<usize>,
}

impl<const S: usize> Mode<S> {
    /// The region given by `sides` (no sliding).
    pub fn region(sides: [Region; S]) -> Self {
        Self {
            sides,
            sliding: None,
        }
    }

    /// Sliding on surface `i`, the other surfaces on `sides`.
    pub fn sliding_on(i: usize, sides: [Region; S]) -> Self {
        Self {
            sides,
            sliding: Some(i),
        }
    }

    /// Whether the state slides.
    pub fn is_sliding(&self) -> bool {
        self.sliding.is_some()
    }

    /// `"sliding"` or `"region"`, as [`Observer::on_mode`](crate::drive::Observer::on_mode)
    /// sees it through [`Plain`](super::Plain).
    pub fn name(&self) -> &'static str {
        if self.sliding.is_some() {
            "sliding"
        } else {
            "region"
        }
    }
}

/// A piecewise-smooth system `ẋ = F_σ(t, x)` with codimension-1 switching surfaces
/// `H_i(t, x) = 0`, `i < S`: the region `σ` is the side of every surface.
///
/// Each region's field must be defined (as a smooth extension) a little beyond its region:
/// the equivalent control evaluates both fields on the surface, and the tangency test
/// evaluates a field on the surface along its own flow. Surfaces and fields must not
/// allocate; they are evaluated in the stepping loop.
///
/// # Implementing
/// A relay `ẍ = −x − sgn(ẋ)` (dry friction on a fixed surface) as one surface `H = ẋ`:
/// ```
/// use nalgebra::{SMatrix, SVector};
/// use nonsmooth::filippov::{Filippov, Region};
///
/// struct Relay;
/// impl Filippov<f64, 2, 1> for Relay {
///     fn surface(&self, _i: usize, _t: f64, x: &SVector<f64, 2>) -> f64 {
///         x[1]
///     }
///     fn gradient(&self, _i: usize, _t: f64, _x: &SVector<f64, 2>) -> SVector<f64, 2> {
///         SVector::from([0.0, 1.0])
///     }
///     fn field(&self, sides: &[Region; 1], _t: f64, x: &SVector<f64, 2>, dx: &mut SVector<f64, 2>) {
///         // Friction opposes the velocity: −1 for ẋ > 0 (Plus), +1 for ẋ < 0 (Minus).
///         let friction = -sides[0].sign::<f64>();
///         *dx = SVector::from([x[1], -x[0] + friction]);
///     }
///     fn field_jacobian(&self, _s: &[Region; 1], _t: f64, _x: &SVector<f64, 2>) -> Option<SMatrix<f64, 2, 2>> {
///         Some(SMatrix::<f64, 2, 2>::new(0.0, 1.0, -1.0, 0.0))
///     }
/// }
/// ```
pub trait Filippov<T: Real, const N: usize, const S: usize> {
    /// `H_i(t, x)`.
    fn surface(&self, i: usize, t: T, x: &SVector<T, N>) -> T;

    /// `∇_x H_i(t, x)`.
    fn gradient(&self, i: usize, t: T, x: &SVector<T, N>) -> SVector<T, N>;

    /// `∂H_i/∂t` (a moving surface). Default: 0.
    fn surface_time_rate(&self, _i: usize, _t: T, _x: &SVector<T, N>) -> T {
        T::zero()
    }

    /// The field `F_σ(t, x)` of the region `σ = sides` into `dx`.
    fn field(&self, sides: &[Region; S], t: T, x: &SVector<T, N>, dx: &mut SVector<T, N>);

    /// `∂F_σ/∂x`, if known (else central differences are used for tangent dynamics).
    fn field_jacobian(
        &self,
        _sides: &[Region; S],
        _t: T,
        _x: &SVector<T, N>,
    ) -> Option<SMatrix<T, N, N>> {
        None
    }

    /// The shortest time over which the explicit time dependence (forcing, moving
    /// surfaces) can turn around near `t`, if it must bound the step (see
    /// [`Dynamics::time_scale`](crate::Dynamics::time_scale)). Default: `None`.
    fn time_scale(&self, _t: T) -> Option<T> {
        None
    }
}

impl<T: Real, const N: usize, const S: usize, F: Filippov<T, N, S> + ?Sized> Filippov<T, N, S>
    for &F
{
    #[inline(always)]
    fn surface(&self, i: usize, t: T, x: &SVector<T, N>) -> T {
        (**self).surface(i, t, x)
    }
    #[inline(always)]
    fn gradient(&self, i: usize, t: T, x: &SVector<T, N>) -> SVector<T, N> {
        (**self).gradient(i, t, x)
    }
    #[inline(always)]
    fn surface_time_rate(&self, i: usize, t: T, x: &SVector<T, N>) -> T {
        (**self).surface_time_rate(i, t, x)
    }
    #[inline(always)]
    fn field(&self, sides: &[Region; S], t: T, x: &SVector<T, N>, dx: &mut SVector<T, N>) {
        (**self).field(sides, t, x, dx)
    }
    fn field_jacobian(
        &self,
        sides: &[Region; S],
        t: T,
        x: &SVector<T, N>,
    ) -> Option<SMatrix<T, N, N>> {
        (**self).field_jacobian(sides, t, x)
    }
    fn time_scale(&self, t: T) -> Option<T> {
        (**self).time_scale(t)
    }
}

/// One autonomous switching surface from closures: `H(x)`, `∇H(x)` and the fields
/// `F₋(t, x)`, `F₊(t, x)` (returning the derivative).
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::filippov::{FilippovSimulation, Switched};
/// use nonsmooth::integrate::{Dopri5, Tolerances};
///
/// // ẋ = −sgn(x) + 0.5: both sides push into x = 0, sliding holds x = 0.
/// let relay = Switched::new(
///     |x: &SVector<f64, 1>| x[0],
///     |_x: &SVector<f64, 1>| SVector::from([1.0]),
///     |_t, _x: &SVector<f64, 1>| SVector::from([1.5]),
///     |_t, _x: &SVector<f64, 1>| SVector::from([-0.5]),
/// );
/// let mut sim = FilippovSimulation::new(relay, Dopri5::new(Tolerances::new(1e-10, 1e-12)?));
/// let run = sim.run(0.0, SVector::from([-1.0]), 2.0, &mut ())?;
/// // Reaches x = 0 at t = 1/1.5 and slides there.
/// assert!((run.transitions[0].t - 1.0 / 1.5).abs() < 1e-10);
/// assert!(run.mode.is_sliding() && run.x[0].abs() < 1e-15);
/// # Ok::<(), nonsmooth::filippov::FilippovError>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Switched<H, G, Fm, Fp> {
    h: H,
    grad: G,
    minus: Fm,
    plus: Fp,
}

impl<H, G, Fm, Fp> Switched<H, G, Fm, Fp> {
    /// The surface `h(x) = 0` with gradient `grad(x)`, the field `minus` where `h < 0` and
    /// `plus` where `h > 0`.
    pub fn new(h: H, grad: G, minus: Fm, plus: Fp) -> Self {
        Self {
            h,
            grad,
            minus,
            plus,
        }
    }
}

impl<T, const N: usize, H, G, Fm, Fp> Filippov<T, N, 1> for Switched<H, G, Fm, Fp>
where
    T: Real,
    H: Fn(&SVector<T, N>) -> T,
    G: Fn(&SVector<T, N>) -> SVector<T, N>,
    Fm: Fn(T, &SVector<T, N>) -> SVector<T, N>,
    Fp: Fn(T, &SVector<T, N>) -> SVector<T, N>,
{
    #[inline(always)]
    fn surface(&self, _i: usize, _t: T, x: &SVector<T, N>) -> T {
        (self.h)(x)
    }
    #[inline(always)]
    fn gradient(&self, _i: usize, _t: T, x: &SVector<T, N>) -> SVector<T, N> {
        (self.grad)(x)
    }
    #[inline(always)]
    fn field(&self, sides: &[Region; 1], t: T, x: &SVector<T, N>, dx: &mut SVector<T, N>) {
        *dx = match sides[0] {
            Region::Minus => (self.minus)(t, x),
            Region::Plus => (self.plus)(t, x),
        };
    }
}
