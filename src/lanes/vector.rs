//! The lane vector: `L` values of `f64` in one SIMD register (or a few).

use core::fmt::Debug;
use core::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

pub(crate) mod sealed {
    /// What only the crate's lane types provide: bit operations the vector math relies on
    /// (and the seal: every operation of a lane type must be lane-wise and IEEE-exact).
    pub trait Sealed: Sized {
        /// `2^k` from `y = k + 1.5·2⁵²` (`k` an integer in `[−1022, 1023]`, held in the low
        /// bits of `y`): the bits `(bits(y) + 1023) << 52`, lane-wise.
        fn pow2_from_rounded(self) -> Self;
        /// The biased exponent field `bits(x) >> 52` as an `f64` (exact; the sign bit must
        /// be clear), lane-wise.
        fn exponent_field(self) -> Self;
        /// The bits plus `c` (wrapping), as an `f64`, lane-wise.
        fn add_bits(self, c: u64) -> Self;
        /// Lane `i` set to `x` in place (nothing if `i ≥ L`): the engine's per-lane writes
        /// into its boxed state, without moving the whole vector through registers as
        /// [`with_lane`](super::Lanes::with_lane) does.
        fn set_lane(&mut self, i: usize, x: f64);
        /// Lane `i` read in place (`0` if `i ≥ L`), like [`set_lane`](Self::set_lane).
        fn get_lane(&self, i: usize) -> f64;
    }
}

/// `L` lanes of `f64`: [`F64x2`], [`F64x4`], [`F64x8`] and [`F64x16`].
///
/// Every operation acts lane by lane; comparisons return a *mask* of the same type (all
/// bits set where true, zero where false), which [`Lanes::select`] consumes. The types
/// compile to one register per vector where the instruction set in use has one (`F64x4`
/// on AVX2, `F64x8` on AVX-512F), and to pairs of narrower registers otherwise; the
/// ensemble picks the instruction set at run time ([`Simd`](super::Simd)). The trait is
/// sealed: the engine relies on each operation being lane-wise and IEEE-exact. Lane forms
/// of force laws, excitations and models ([`LaneLaw`](crate::force::LaneLaw),
/// [`LaneExcitation`](crate::excite::LaneExcitation),
/// [`LaneDynamics`](crate::LaneDynamics)) are written with these operations.
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
    /// The type with half the lanes (itself for two lanes): the ensemble moves its last
    /// trajectories there when at most half the lanes are busy.
    type Half: Lanes;
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
    /// `mask ? a : b`, lane-wise (`self` is the mask: every bit of a lane set or clear, as
    /// the comparisons, [`TRUE`](super::TRUE) and [`mask`](super::mask) give it; the sign
    /// bit decides).
    fn select(self, a: Self, b: Self) -> Self;
    /// Bit `i` set where lane `i` of the mask is set.
    fn bits(self) -> u32;
}

macro_rules! lanes_type {
    ($name:ident, $n:expr, $align:literal, $half:ident, $doc:literal) => {
        #[doc = $doc]
        ///
        /// A plain array of `f64` whose operations are lane-wise loops: the compiler turns
        /// them into the vector instructions of the code they are inlined into, so the
        /// ensemble's lane loop, compiled once per instruction set
        /// ([`Simd`](super::Simd)), runs on SSE2, AVX2 or AVX-512 registers from the
        /// same source. Every operation is the IEEE operation of each lane.
        #[derive(Clone, Copy, Debug, PartialEq, Default)]
        #[repr(C, align($align))]
        pub struct $name([f64; $n]);

        impl $name {
            #[inline(always)]
            fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
                let mut r = [0.0; $n];
                for i in 0..$n {
                    r[i] = f(self.0[i], o.0[i]);
                }
                Self(r)
            }
            #[inline(always)]
            fn map(self, f: impl Fn(f64) -> f64) -> Self {
                let mut r = [0.0; $n];
                for i in 0..$n {
                    r[i] = f(self.0[i]);
                }
                Self(r)
            }
            #[inline(always)]
            fn bitwise(self, o: Self, f: impl Fn(u64, u64) -> u64) -> Self {
                self.zip(o, |a, b| f64::from_bits(f(a.to_bits(), b.to_bits())))
            }
            #[inline(always)]
            fn cmp(self, o: Self, f: impl Fn(f64, f64) -> bool) -> Self {
                self.zip(o, |a, b| f64::from_bits((f(a, b) as u64).wrapping_neg()))
            }
        }

        impl Add for $name {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                self.zip(o, |a, b| a + b)
            }
        }
        impl Sub for $name {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                self.zip(o, |a, b| a - b)
            }
        }
        impl Mul for $name {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: Self) -> Self {
                self.zip(o, |a, b| a * b)
            }
        }
        impl Div for $name {
            type Output = Self;
            #[inline(always)]
            fn div(self, o: Self) -> Self {
                self.zip(o, |a, b| a / b)
            }
        }
        impl Neg for $name {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                self.map(|a| -a)
            }
        }
        impl BitAnd for $name {
            type Output = Self;
            #[inline(always)]
            fn bitand(self, o: Self) -> Self {
                self.bitwise(o, |a, b| a & b)
            }
        }
        impl BitOr for $name {
            type Output = Self;
            #[inline(always)]
            fn bitor(self, o: Self) -> Self {
                self.bitwise(o, |a, b| a | b)
            }
        }
        impl Not for $name {
            type Output = Self;
            #[inline(always)]
            fn not(self) -> Self {
                self.map(|a| f64::from_bits(!a.to_bits()))
            }
        }

        impl sealed::Sealed for $name {
            #[inline(always)]
            fn pow2_from_rounded(self) -> Self {
                self.map(|y| f64::from_bits(y.to_bits().wrapping_add(1023) << 52))
            }
            #[inline(always)]
            fn set_lane(&mut self, i: usize, x: f64) {
                if let Some(v) = self.0.get_mut(i) {
                    *v = x;
                }
            }
            #[inline(always)]
            fn get_lane(&self, i: usize) -> f64 {
                self.0.get(i).copied().unwrap_or(0.0)
            }
            #[inline(always)]
            fn add_bits(self, c: u64) -> Self {
                self.map(|x| f64::from_bits(x.to_bits().wrapping_add(c)))
            }
            #[inline(always)]
            fn exponent_field(self) -> Self {
                // (e | bits of 2⁵²) − 2⁵² = e exactly, for e < 2¹²: no integer conversion,
                // which AVX2 lacks for 64-bit lanes.
                self.map(|x| {
                    f64::from_bits((x.to_bits() >> 52) | 0x4330_0000_0000_0000)
                        - 4_503_599_627_370_496.0
                })
            }
        }
        impl Lanes for $name {
            const LANES: usize = $n;
            type Half = $half;
            #[inline(always)]
            fn splat(x: f64) -> Self {
                Self([x; $n])
            }
            #[inline(always)]
            fn load(src: &[f64]) -> Self {
                let mut a = [0.0; $n];
                for (d, s) in a.iter_mut().zip(src) {
                    *d = *s;
                }
                Self(a)
            }
            #[inline(always)]
            fn store(self, dst: &mut [f64]) {
                for (d, s) in dst.iter_mut().zip(self.0) {
                    *d = s;
                }
            }
            #[inline(always)]
            fn lane(self, i: usize) -> f64 {
                sealed::Sealed::get_lane(&self, i)
            }
            #[inline(always)]
            fn with_lane(mut self, i: usize, x: f64) -> Self {
                sealed::Sealed::set_lane(&mut self, i, x);
                self
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                self.map(f64::sqrt)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                self.map(f64::abs)
            }
            #[inline(always)]
            fn max(self, o: Self) -> Self {
                // x86's `maxpd`: `a > b ? a : b`, and `a` where `b` is NaN (`wide`'s rule).
                self.zip(o, |a, b| if b.is_nan() || a > b { a } else { b })
            }
            #[inline(always)]
            fn min(self, o: Self) -> Self {
                self.zip(o, |a, b| if b.is_nan() || a < b { a } else { b })
            }
            #[inline(always)]
            fn gt(self, o: Self) -> Self {
                self.cmp(o, |a, b| a > b)
            }
            #[inline(always)]
            fn ge(self, o: Self) -> Self {
                self.cmp(o, |a, b| a >= b)
            }
            #[inline(always)]
            fn lt(self, o: Self) -> Self {
                self.cmp(o, |a, b| a < b)
            }
            #[inline(always)]
            fn le(self, o: Self) -> Self {
                self.cmp(o, |a, b| a <= b)
            }
            #[inline(always)]
            fn eq(self, o: Self) -> Self {
                self.cmp(o, |a, b| a == b)
            }
            #[inline(always)]
            fn finite(self) -> Self {
                self.cmp(self, |a, _| a.is_finite())
            }
            #[inline(always)]
            fn select(self, a: Self, b: Self) -> Self {
                (self & a) | (!self & b)
            }
            #[inline(always)]
            fn bits(self) -> u32 {
                let mut r = 0u32;
                for i in 0..$n {
                    r |= ((self.0[i].to_bits() >> 63) as u32) << i;
                }
                r
            }
        }
    };
}

lanes_type!(F64x2, 2, 16, F64x2, "Two lanes (one SSE2 register).");
lanes_type!(
    F64x4,
    4,
    32,
    F64x2,
    "Four lanes: the default width (one AVX register, two SSE2 registers)."
);
lanes_type!(
    F64x8,
    8,
    64,
    F64x4,
    "Eight lanes (one AVX-512 register, two AVX or four SSE2 registers)."
);
lanes_type!(
    F64x16,
    16,
    64,
    F64x8,
    "Sixteen lanes (two AVX-512, four AVX or eight SSE2 registers): more independent \
     work per instruction stream, which hides the latency of the polynomial chains in \
     `sin`, `exp` and `ln`."
);
