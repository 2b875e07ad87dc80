//! Force laws: the terms `F(x, ẋ)` on the left-hand side of
//! `m·ẍ + Σ F_i(x, ẋ) = f(t)`.
//!
//! A [`ForceLaw`] is a pure function of a coordinate `x` and its rate `v = ẋ`, with its
//! partial derivatives `(∂F/∂x, ∂F/∂v)` (analytic where known; central finite differences by
//! default). Laws compose *by value*: a tuple `(A, B, …)` of laws is a law (their sum), and
//! so is [`Sum`]; nothing in the hot path goes through `dyn`.
//!
//! | law | force | module |
//! |---|---|---|
//! | [`LinearSpring`] | `k·x` | linear |
//! | [`ViscousDamper`] | `c·ẋ` | linear |
//! | [`CubicSpring`] | `k₁u + k₃u³`, `u = x − x₀` (Duffing) | polynomial |
//! | [`Polynomial`] | `Σ c_i u^i` | polynomial |
//! | [`Bilinear`] | `k_in·x + k_out[(x−hi)⁺ − (lo−x)⁺]` (backlash, bilinear stop) | piecewise |
//! | [`DryFriction`] | `T·ẋ/√(ẋ²+ε²)` or `T·tanh(ẋ/ε)` | friction |
//! | [`HertzContact`] | `k_I·[(x−x_I)^{n1} + b·(x−x_I)^{n2}·sgn ẋ·|ẋ|^{n3}]⁺` | contact |
//!
//! # Implementing a law
//! ```
//! use nonsmooth::{ForceLaw, Real};
//!
//! /// A cubic (Duffing) spring `k3·x³`.
//! struct Cubic { k3: f64 }
//!
//! impl ForceLaw<f64> for Cubic {
//!     fn force(&self, x: f64, _v: f64) -> f64 { self.k3 * x * x * x }
//!     // Optional: analytic partials (the default uses finite differences).
//!     fn partials(&self, x: f64, _v: f64) -> (f64, f64) { (3.0 * self.k3 * x * x, 0.0) }
//! }
//!
//! let law = (Cubic { k3: 2.0 }, nonsmooth::force::ViscousDamper::new(0.5).unwrap());
//! assert_eq!(law.force(1.0, 2.0), 2.0 + 1.0);
//! ```

mod contact;
mod friction;
mod linear;
mod piecewise;
mod polynomial;

pub use contact::{ExponentLanes, HertzContact, HertzLanes, Side};
pub use friction::{DryFriction, DryFrictionLanes, Regularization};
pub use linear::{LinearSpring, ViscousDamper};
pub use piecewise::Bilinear;
pub use polynomial::{CubicSpring, Polynomial};

use crate::Real;
use crate::lanes::{LaneMath, Lanes};
use crate::scalar::{epsilon, lit};

/// A force term `F(x, ẋ)` on the left-hand side of `m·ẍ + ΣF = f(t)`.
///
/// Only [`force`](ForceLaw::force) is required. Override [`partials`](ForceLaw::partials)
/// with the analytic derivatives where they are known: the tangent-space Lyapunov method, the
/// implicit stepper and the linearizations use them. The checker in `nonsmooth::testing`
/// (feature `testing`) compares analytic partials with finite differences.
pub trait ForceLaw<T: Real> {
    /// The force at position `x` and velocity `v`.
    fn force(&self, x: T, v: T) -> T;

    /// `(∂F/∂x, ∂F/∂v)` at `(x, v)`.
    ///
    /// The default is a central finite difference with relative steps `∛ε_mach·max(|·|, s)`,
    /// where `s = √ε_mach`; it is inaccurate across kinks, so override it where possible.
    fn partials(&self, x: T, v: T) -> (T, T) {
        finite_difference_partials(self, x, v)
    }

    /// The exponent `q ∈ (0, 1)` of a term `∝ sgn(v)|v|^q` in the law, if it has one: the
    /// force then has an infinite slope in `v` at `v = 0` (a cusp), and a trajectory that
    /// turns round with acceleration `a ≠ 0` has a `|τ|^{1+q}` term in its velocity. Steppers
    /// that know it cross `v = 0` in the variable `u = sgn(v)|v|^q`, in which the term is
    /// linear ([`TurningPoints`](crate::integrate::TurningPoints)). Default `None`: no
    /// cusp in `v` (smooth laws, and smooth layers such as a regularized friction).
    fn velocity_exponent(&self) -> Option<T> {
        None
    }

    /// Where the law's force starts as a power of a penetration, if it does: a contact law
    /// `F ∝ δ^n` for `δ = ±(x − x_I) > 0` and zero on the other side (see
    /// [`ContactOnset`]). A trajectory that enters or leaves contact with `ẋ ≠ 0` then has
    /// a `|τ|^{n}` term in its acceleration; [`TurningPoints`](crate::integrate::TurningPoints)
    /// (with [`with_onset_band`](crate::integrate::TurningPoints::with_onset_band)) crosses
    /// the first `δ*` of the contact with `δ = w^m` as the independent variable. Default
    /// `None`.
    fn contact_onset(&self) -> Option<ContactOnset<T>> {
        None
    }
}

/// The lane form of a [`ForceLaw`]: the force of `L` laws of the same type at once, one
/// per lane of a [`Lanes`] vector, each lane with its own parameters (what lets a model
/// built from the law run in the ensemble's SIMD lanes,
/// [`ensemble`](crate::ensemble)).
///
/// Every built-in law implements it, and so do `()`, [`Sum`] and tuples of lane laws. The
/// parameters are *packed*: [`pack`](Self::pack) sets every lane to `self`,
/// [`pack_lane`](Self::pack_lane) one lane; [`force_lanes`](Self::force_lanes) evaluates
/// them. A branch of the scalar law becomes a mask and [`Lanes::select`] (see
/// [`lanes`](crate::lanes)).
///
/// # Contract
/// In every lane `i`, `force_lanes` returns [`force`](ForceLaw::force) of the law packed
/// into lane `i` at that lane's `(x, v)`. With [`LaneMath::Exact`] the built-in laws
/// perform the scalar operations in the scalar order: the value is the scalar one to the
/// bit (tested per law over free, contact and sticking states). A law of one's own that
/// cannot promise that still runs in lanes through [`LaneByLane`](crate::LaneByLane).
///
/// ```
/// use nonsmooth::force::{LaneLaw, LinearSpring, ViscousDamper};
/// use nonsmooth::lanes::{F64x4, LaneMath, Lanes};
/// use nonsmooth::ForceLaw;
///
/// let law = (LinearSpring::new(2.0)?, ViscousDamper::new(0.5)?);
/// let mut p = law.pack::<F64x4>();
/// (LinearSpring::new(3.0)?, ViscousDamper::new(0.5)?).pack_lane(&mut p, 1);
/// let x = F64x4::splat(1.0);
/// let v = F64x4::splat(2.0);
/// let f = <(LinearSpring<f64>, ViscousDamper<f64>)>::force_lanes(&p, LaneMath::Exact, x, v);
/// assert_eq!(f.lane(0), law.force(1.0, 2.0));
/// assert_eq!(f.lane(1), 3.0 + 1.0);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
pub trait LaneLaw: ForceLaw<f64> {
    /// The law's parameters in `L` lanes.
    type Packed<V: Lanes>: Copy + core::fmt::Debug + Send + Sync;

    /// Every lane set to this law.
    fn pack<V: Lanes>(&self) -> Self::Packed<V>;

    /// Lane `lane` of `packed` set to this law (the other lanes unchanged).
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize);

    /// The force in every lane at `(x, v)`.
    fn force_lanes<V: Lanes>(packed: &Self::Packed<V>, math: LaneMath, x: V, v: V) -> V;
}

impl LaneLaw for () {
    type Packed<V: Lanes> = ();
    fn pack<V: Lanes>(&self) {}
    fn pack_lane<V: Lanes>(&self, _packed: &mut (), _lane: usize) {}
    #[inline(always)]
    fn force_lanes<V: Lanes>(_packed: &(), _math: LaneMath, _x: V, _v: V) -> V {
        V::splat(0.0)
    }
}

impl<A: LaneLaw, B: LaneLaw> LaneLaw for Sum<A, B> {
    type Packed<V: Lanes> = (A::Packed<V>, B::Packed<V>);
    fn pack<V: Lanes>(&self) -> Self::Packed<V> {
        (self.0.pack(), self.1.pack())
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
        self.0.pack_lane(&mut packed.0, lane);
        self.1.pack_lane(&mut packed.1, lane);
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(packed: &Self::Packed<V>, math: LaneMath, x: V, v: V) -> V {
        A::force_lanes(&packed.0, math, x, v) + B::force_lanes(&packed.1, math, x, v)
    }
}

macro_rules! tuple_lane_law {
    ($($name:ident $idx:tt),+) => {
        impl<$($name: LaneLaw),+> LaneLaw for ($($name,)+) {
            type Packed<V: Lanes> = ($($name::Packed<V>,)+);
            fn pack<V: Lanes>(&self) -> Self::Packed<V> {
                ($(self.$idx.pack(),)+)
            }
            fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
                $(self.$idx.pack_lane(&mut packed.$idx, lane);)+
            }
            /// The terms summed from `0` in order, as [`ForceLaw::force`] of the tuple.
            #[inline(always)]
            fn force_lanes<V: Lanes>(packed: &Self::Packed<V>, math: LaneMath, x: V, v: V) -> V {
                V::splat(0.0) $(+ $name::force_lanes(&packed.$idx, math, x, v))+
            }
        }
    };
}

tuple_lane_law!(A 0);
tuple_lane_law!(A 0, B 1);
tuple_lane_law!(A 0, B 1, C 2);
tuple_lane_law!(A 0, B 1, C 2, D 3);
tuple_lane_law!(A 0, B 1, C 2, D 3, E 4);
tuple_lane_law!(A 0, B 1, C 2, D 3, E 4, F 5);
tuple_lane_law!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
tuple_lane_law!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);

/// The onset of a contact force: `F ∝ δ^n` near `δ = 0⁺`, with the penetration
/// `δ = x − x_I` ([`Side::Upper`]) or `δ = x_I − x` ([`Side::Lower`]), and no force for
/// `δ < 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactOnset<T> {
    /// The stop `x_I`.
    pub position: T,
    /// Which side of the stop is in contact.
    pub side: Side,
    /// The smallest exponent of `δ` in the force near `δ = 0⁺` (`n > 0`).
    pub exponent: T,
}

impl<T: Real> ContactOnset<T> {
    /// The penetration `δ` at `x` (negative when separated).
    #[inline(always)]
    pub fn penetration(&self, x: T) -> T {
        match self.side {
            Side::Upper => x - self.position,
            Side::Lower => self.position - x,
        }
    }

    /// `+1` if the penetration grows with `x` ([`Side::Upper`]), else `−1`.
    #[inline(always)]
    pub fn direction(&self) -> T {
        match self.side {
            Side::Upper => T::one(),
            Side::Lower => -T::one(),
        }
    }
}

/// The smaller of two declared exponents (a sum of laws has the strongest cusp of its terms).
#[inline]
pub(crate) fn min_exponent<T: Real>(a: Option<T>, b: Option<T>) -> Option<T> {
    match (a, b) {
        (Some(a), Some(b)) => Some(if b < a { b } else { a }),
        (a, None) => a,
        (None, b) => b,
    }
}

/// Central finite-difference partials of any law (the default of [`ForceLaw::partials`]).
pub fn finite_difference_partials<T: Real, F: ForceLaw<T> + ?Sized>(law: &F, x: T, v: T) -> (T, T) {
    let cbrt_eps = epsilon::<T>().powf(lit(1.0 / 3.0));
    let floor = epsilon::<T>().sqrt();
    let hx = cbrt_eps * x.abs().max(floor);
    let hv = cbrt_eps * v.abs().max(floor);
    let two = lit::<T>(2.0);
    let dx = (law.force(x + hx, v) - law.force(x - hx, v)) / (two * hx);
    let dv = (law.force(x, v + hv) - law.force(x, v - hv)) / (two * hv);
    (dx, dv)
}

impl<T: Real, F: ForceLaw<T> + ?Sized> ForceLaw<T> for &F {
    #[inline(always)]
    fn force(&self, x: T, v: T) -> T {
        (**self).force(x, v)
    }
    #[inline(always)]
    fn partials(&self, x: T, v: T) -> (T, T) {
        (**self).partials(x, v)
    }
    fn velocity_exponent(&self) -> Option<T> {
        (**self).velocity_exponent()
    }
    fn contact_onset(&self) -> Option<ContactOnset<T>> {
        (**self).contact_onset()
    }
}

/// The sum of two laws, `A + B`, itself a law. Tuples of up to eight laws are laws too.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Sum<A, B>(pub A, pub B);

impl<T: Real, A: ForceLaw<T>, B: ForceLaw<T>> ForceLaw<T> for Sum<A, B> {
    #[inline(always)]
    fn force(&self, x: T, v: T) -> T {
        self.0.force(x, v) + self.1.force(x, v)
    }
    #[inline(always)]
    fn partials(&self, x: T, v: T) -> (T, T) {
        let (a, b) = self.0.partials(x, v);
        let (c, d) = self.1.partials(x, v);
        (a + c, b + d)
    }
    fn velocity_exponent(&self) -> Option<T> {
        min_exponent(self.0.velocity_exponent(), self.1.velocity_exponent())
    }
    /// The first term's onset, else the second's (one stop is used).
    fn contact_onset(&self) -> Option<ContactOnset<T>> {
        self.0.contact_onset().or_else(|| self.1.contact_onset())
    }
}

/// The zero force (the empty sum).
impl<T: Real> ForceLaw<T> for () {
    #[inline(always)]
    fn force(&self, _x: T, _v: T) -> T {
        T::zero()
    }
    #[inline(always)]
    fn partials(&self, _x: T, _v: T) -> (T, T) {
        (T::zero(), T::zero())
    }
}

macro_rules! tuple_law {
    ($($name:ident $idx:tt),+) => {
        impl<T: Real, $($name: ForceLaw<T>),+> ForceLaw<T> for ($($name,)+) {
            #[inline(always)]
            fn force(&self, x: T, v: T) -> T {
                T::zero() $(+ self.$idx.force(x, v))+
            }
            #[inline(always)]
            fn partials(&self, x: T, v: T) -> (T, T) {
                let mut dx = T::zero();
                let mut dv = T::zero();
                $(
                    let (a, b) = self.$idx.partials(x, v);
                    dx += a;
                    dv += b;
                )+
                (dx, dv)
            }
            fn velocity_exponent(&self) -> Option<T> {
                let mut q = None;
                $(q = min_exponent(q, self.$idx.velocity_exponent());)+
                q
            }
            fn contact_onset(&self) -> Option<ContactOnset<T>> {
                let mut o = None;
                $(o = o.or_else(|| self.$idx.contact_onset());)+
                o
            }
        }
    };
}

tuple_law!(A 0);
tuple_law!(A 0, B 1);
tuple_law!(A 0, B 1, C 2);
tuple_law!(A 0, B 1, C 2, D 3);
tuple_law!(A 0, B 1, C 2, D 3, E 4);
tuple_law!(A 0, B 1, C 2, D 3, E 4, F 5);
tuple_law!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
tuple_law!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tuples_and_sum_add_up() {
        let k = LinearSpring::new(2.0).unwrap();
        let c = ViscousDamper::new(0.5).unwrap();
        let t = (k, c);
        assert_eq!(t.force(1.5, -2.0), 3.0 - 1.0);
        assert_eq!(Sum(k, c).force(1.5, -2.0), t.force(1.5, -2.0));
        assert_eq!(t.partials(1.5, -2.0), (2.0, 0.5));
        assert_eq!(ForceLaw::<f64>::force(&(), 1.0, 1.0), 0.0);
        assert_eq!(ForceLaw::force(&&t, 1.0, 0.0), 2.0);
    }

    #[test]
    fn finite_differences_of_a_smooth_law() {
        struct Cubic;
        impl ForceLaw<f64> for Cubic {
            fn force(&self, x: f64, v: f64) -> f64 {
                x * x * x + v * v
            }
        }
        let (dx, dv) = Cubic.partials(0.7, -0.3);
        assert!((dx - 3.0 * 0.49).abs() < 1e-8);
        assert!((dv + 0.6).abs() < 1e-8);
    }
}
