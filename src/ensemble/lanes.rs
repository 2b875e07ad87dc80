//! The lane vector: `L` values of `f64` in one SIMD register (or a few), from the `wide`
//! crate.

use core::fmt::Debug;
use core::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

mod sealed {
    pub trait Sealed {}
}

/// `L` lanes of `f64`: [`wide::f64x2`], [`wide::f64x4`] (the default, [`F64x4`]) and
/// [`wide::f64x8`].
///
/// Every operation acts lane by lane; comparisons return a *mask* of the same type (all
/// bits set where true, zero where false), which [`Lanes::select`] consumes. The `wide`
/// types compile to one register per vector where the target has one (`f64x4` on AVX,
/// `f64x8` on AVX-512F), and to pairs of narrower registers (SSE2 on any x86-64)
/// otherwise: `RUSTFLAGS="-C target-cpu=native"` picks the widest the machine has. The
/// trait is sealed: the engine relies on each operation being lane-wise and IEEE-exact.
pub trait Lanes:
    Copy
    + Send
    + Sync
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Not<Output = Self>
    + sealed::Sealed
{
    /// The number of lanes `L`.
    const LANES: usize;
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// Lanes `src[0..L]` (`src` must hold at least `L` values; missing ones read as 0).
    fn load(src: &[f64]) -> Self;
    /// Writes the lanes to `dst[0..L]` (as many as fit).
    fn store(self, dst: &mut [f64]);
    /// Lane `i` (0 if `i ≥ L`).
    fn lane(self, i: usize) -> f64;
    /// This vector with lane `i` replaced by `x` (unchanged if `i ≥ L`).
    fn with_lane(self, i: usize, x: f64) -> Self;
    /// Correctly rounded square root (IEEE `sqrt`), lane-wise.
    fn sqrt(self) -> Self;
    /// `|x|`.
    fn abs(self) -> Self;
    /// `max(a, b)` (for non-NaN lanes, the same as `f64::max`).
    fn max(self, o: Self) -> Self;
    /// `min(a, b)` (for non-NaN lanes, the same as `f64::min`).
    fn min(self, o: Self) -> Self;
    /// Mask of `a > b`.
    fn gt(self, o: Self) -> Self;
    /// Mask of `a ≥ b`.
    fn ge(self, o: Self) -> Self;
    /// Mask of `a < b`.
    fn lt(self, o: Self) -> Self;
    /// Mask of `a ≤ b`.
    fn le(self, o: Self) -> Self;
    /// Mask of `a == b`.
    fn eq(self, o: Self) -> Self;
    /// Mask of the finite lanes.
    fn finite(self) -> Self;
    /// `mask ? a : b`, lane-wise (`self` is the mask).
    fn select(self, a: Self, b: Self) -> Self;
    /// Bit `i` set where lane `i` of the mask is set.
    fn bits(self) -> u32;
    /// `e^x` by `wide`'s polynomial (see [`math`](super::math) for its accuracy).
    fn exp_poly(self) -> Self;
    /// `ln x` by `wide`'s rational approximation (see [`math`](super::math)).
    fn ln_poly(self) -> Self;
}

macro_rules! lanes_impl {
    ($t:ty, $n:expr) => {
        impl sealed::Sealed for $t {}
        impl Lanes for $t {
            const LANES: usize = $n;
            #[inline(always)]
            fn splat(x: f64) -> Self {
                <$t>::splat(x)
            }
            #[inline(always)]
            fn load(src: &[f64]) -> Self {
                let mut a = [0.0; $n];
                for (d, s) in a.iter_mut().zip(src) {
                    *d = *s;
                }
                <$t>::new(a)
            }
            #[inline(always)]
            fn store(self, dst: &mut [f64]) {
                for (d, s) in dst.iter_mut().zip(self.to_array()) {
                    *d = s;
                }
            }
            #[inline(always)]
            fn lane(self, i: usize) -> f64 {
                self.to_array().get(i).copied().unwrap_or(0.0)
            }
            #[inline(always)]
            fn with_lane(self, i: usize, x: f64) -> Self {
                let mut a = self.to_array();
                if let Some(v) = a.get_mut(i) {
                    *v = x;
                }
                <$t>::new(a)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline(always)]
            fn max(self, o: Self) -> Self {
                <$t>::max(self, o)
            }
            #[inline(always)]
            fn min(self, o: Self) -> Self {
                <$t>::min(self, o)
            }
            #[inline(always)]
            fn gt(self, o: Self) -> Self {
                self.simd_gt(o)
            }
            #[inline(always)]
            fn ge(self, o: Self) -> Self {
                self.simd_ge(o)
            }
            #[inline(always)]
            fn lt(self, o: Self) -> Self {
                self.simd_lt(o)
            }
            #[inline(always)]
            fn le(self, o: Self) -> Self {
                self.simd_le(o)
            }
            #[inline(always)]
            fn eq(self, o: Self) -> Self {
                self.simd_eq(o)
            }
            #[inline(always)]
            fn finite(self) -> Self {
                self.is_finite()
            }
            #[inline(always)]
            fn select(self, a: Self, b: Self) -> Self {
                <$t>::select(self, a, b)
            }
            #[inline(always)]
            fn bits(self) -> u32 {
                self.to_bitmask()
            }
            #[inline(always)]
            fn exp_poly(self) -> Self {
                <$t>::exp(self)
            }
            #[inline(always)]
            fn ln_poly(self) -> Self {
                <$t>::ln(self)
            }
        }
    };
}

lanes_impl!(wide::f64x2, 2);
lanes_impl!(wide::f64x4, 4);
lanes_impl!(wide::f64x8, 8);

/// Four lanes: the default width (one AVX register, two SSE2 registers).
pub type F64x4 = wide::f64x4;
/// Two lanes (one SSE2 register).
pub type F64x2 = wide::f64x2;
/// Eight lanes (one AVX-512 register with `target-cpu` support, else two or four).
pub type F64x8 = wide::f64x8;
