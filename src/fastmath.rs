//! `sin` and `cos` for the right-hand side's hot path.
//!
//! A forced oscillator evaluates `sin ωt` at every stage; with the platform's `libm` that
//! call is a large part of a right-hand-side evaluation (`comparisons/results/profile.md`). The `f64` kernels here are a short, branch-light
//! polynomial evaluation with the accuracy of a good `libm` on the arguments a simulation
//! produces:
//!
//! * Cody–Waite reduction `x = k·π/2 + r`, `|r| ≤ π/4`, with `π/2` split into a 33-bit head
//!   (so `k·head` is exact for `|k| < 2²⁰`) and a 53-bit tail; `k` is rounded with the
//!   `1.5·2⁵²` trick (no `round` call);
//! * the degree-13 (sine) and degree-14 (cosine) minimax kernels of fdlibm (Sun
//!   Microsystems, 1993) on `[−π/4, π/4]`, with fdlibm's exact evaluation of `1 − r²/2`.
//!
//! They are used for `2⁻²⁷ ≤ |x| ≤ 2¹⁹` (up to about 5·10⁵ rad, i.e. 8·10⁴ periods of a
//! 20 rad/s forcing); smaller arguments return `x` (sine) or 1 (cosine) exactly, larger
//! ones, where a two-part reduction would lose digits, and non-finite ones fall back to
//! `libm`. Measured against `libm` (tests below, 6·10⁵ arguments): at most 1 ulp where
//! `|sin x|, |cos x| > 10⁻³`, and an absolute error below `2.2·10⁻¹⁶` near the zeros. The
//! kernels are plain arithmetic, so results do not depend on the platform's `libm`.
//!
//! The same approach for the contact law's `exp`/`ln` pair (fdlibm-style `ln` with a
//! division, Taylor `exp`) was slower than glibc's table-driven functions and is not used
//! (`comparisons/`, `rhs-bench`; the figures are in `docs/performance.md`).
//!
//! Both functions are generic over [`Real`]: the kernels are taken only when `T` *is* `f64`
//! (a `TypeId` test the compiler folds away); `f32` and user scalar types (dual numbers,
//! intervals) keep their own implementations.

// The constants are printed with the digits of their published sources (fdlibm); each
// rounds to the intended f64.
#![allow(clippy::excessive_precision)]

use core::any::TypeId;

use crate::Real;
use crate::scalar::{lit, to_f64};

/// Whether `T` is `f64` (the fast kernels and the lane forms apply).
#[inline(always)]
pub(crate) fn is_f64<T: Real>() -> bool {
    TypeId::of::<T>() == TypeId::of::<f64>()
}

/// `sin x`.
#[inline(always)]
pub fn sin<T: Real>(x: T) -> T {
    if is_f64::<T>() {
        lit(sin_f64(to_f64(x)))
    } else {
        x.sin()
    }
}

/// `(sin x, cos x)` with one argument reduction.
#[inline(always)]
pub fn sin_cos<T: Real>(x: T) -> (T, T) {
    if is_f64::<T>() {
        let (s, c) = sin_cos_f64(to_f64(x));
        (lit(s), lit(c))
    } else {
        x.sin_cos()
    }
}

/// `cos x`.
#[inline(always)]
pub fn cos<T: Real>(x: T) -> T {
    if is_f64::<T>() {
        lit(cos_f64(to_f64(x)))
    } else {
        x.cos()
    }
}

// π/2 = PIO2_HI + PIO2_LO: the head has 33 significant bits, so k·PIO2_HI is exact for
// |k| < 2²⁰; the tail is π/2 − PIO2_HI rounded to 53 bits.
const PIO2_HI: f64 = 1.570_796_326_734_125_614_17;
const PIO2_LO: f64 = 6.077_100_506_506_192_249_32e-11;
/// 1.5·2⁵²: adding and subtracting it rounds to the nearest integer (|y| < 2⁵¹).
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;
const TRIG_LIMIT: f64 = 524_288.0;
/// 2⁻²⁷: below it `sin x` rounds to `x` and `cos x` to 1 (keeps the sign of `−0`).
const TINY: f64 = 7.450_580_596_923_828e-9;

/// `x = k·π/2 + r`: returns `(r, k mod 4)`.
#[inline(always)]
fn reduce_pio2(x: f64) -> (f64, u64) {
    let y = x * core::f64::consts::FRAC_2_PI + ROUND_MAGIC;
    let q = y.to_bits();
    let k = y - ROUND_MAGIC;
    let r = (x - k * PIO2_HI) - k * PIO2_LO;
    (r, q & 3)
}

/// `sin r` for `|r| ≤ π/4` (fdlibm's `__kernel_sin` coefficients).
#[inline(always)]
fn ksin(r: f64) -> f64 {
    const S1: f64 = -1.666_666_666_666_663_243_48e-01;
    const S2: f64 = 8.333_333_333_322_489_461_24e-03;
    const S3: f64 = -1.984_126_982_985_794_931_34e-04;
    const S4: f64 = 2.755_731_370_707_006_767_89e-06;
    const S5: f64 = -2.505_076_025_340_686_341_95e-08;
    const S6: f64 = 1.589_690_995_211_550_102_21e-10;
    let z = r * r;
    let p = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    r + (r * z) * (S1 + z * p)
}

/// `cos r` for `|r| ≤ π/4` (fdlibm's `__kernel_cos` coefficients and its exact `1 − z/2`).
#[inline(always)]
fn kcos(r: f64) -> f64 {
    const C1: f64 = 4.166_666_666_666_660_190_37e-02;
    const C2: f64 = -1.388_888_888_887_410_957_49e-03;
    const C3: f64 = 2.480_158_728_947_672_941_78e-05;
    const C4: f64 = -2.755_731_435_139_066_330_35e-07;
    const C5: f64 = 2.087_572_321_298_174_827_90e-09;
    const C6: f64 = -1.135_964_755_778_819_482_65e-11;
    let z = r * r;
    let p = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + z * p)
}

/// `sin x` in `f64` (see the module docs).
#[inline(always)]
pub fn sin_f64(x: f64) -> f64 {
    if !(x.abs() <= TRIG_LIMIT) {
        return x.sin();
    }
    if x.abs() < TINY {
        return x;
    }
    let (r, q) = reduce_pio2(x);
    match q {
        0 => ksin(r),
        1 => kcos(r),
        2 => -ksin(r),
        _ => -kcos(r),
    }
}

/// `(sin x, cos x)` in `f64` with one reduction (see the module docs).
#[inline(always)]
pub fn sin_cos_f64(x: f64) -> (f64, f64) {
    if !(x.abs() <= TRIG_LIMIT) {
        return x.sin_cos();
    }
    if x.abs() < TINY {
        return (x, 1.0);
    }
    let (r, q) = reduce_pio2(x);
    let (s, c) = (ksin(r), kcos(r));
    match q {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `cos x` in `f64` (see the module docs).
#[inline(always)]
pub fn cos_f64(x: f64) -> f64 {
    if !(x.abs() <= TRIG_LIMIT) {
        return x.cos();
    }
    if x.abs() < TINY {
        return 1.0;
    }
    let (r, q) = reduce_pio2(x);
    match q {
        0 => kcos(r),
        1 => -ksin(r),
        2 => -kcos(r),
        _ => ksin(r),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place (of the reference).
    fn ulps(a: f64, b: f64) -> f64 {
        if a == b {
            return 0.0;
        }
        let ulp = f64::from_bits(b.abs().to_bits() + 1) - b.abs();
        ((a - b) / ulp).abs()
    }

    /// A deterministic pseudo-random sequence in [0, 1).
    fn lcg(n: usize) -> impl Iterator<Item = f64> {
        let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
        (0..n).map(move |_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        })
    }

    #[test]
    fn sin_cos_match_libm_within_one_ulp() {
        let mut worst: f64 = 0.0;
        for u in lcg(200_000) {
            // Arguments over the whole fast range, denser near zero.
            for x in [u * 8.0 - 4.0, (u - 0.5) * 2.0 * TRIG_LIMIT, u * 1e4] {
                let (s, c) = x.sin_cos();
                // Absolute error relative to 1 where the value is tiny (near the zeros the
                // reduction's absolute accuracy is what matters).
                let es = if s.abs() > 1e-3 {
                    ulps(sin_f64(x), s)
                } else {
                    (sin_f64(x) - s).abs() / f64::EPSILON
                };
                let ec = if c.abs() > 1e-3 {
                    ulps(cos_f64(x), c)
                } else {
                    (cos_f64(x) - c).abs() / f64::EPSILON
                };
                worst = worst.max(es).max(ec);
            }
        }
        assert!(worst <= 1.0, "worst sin/cos error {worst} ulp");
        // The fallback range and special values.
        for x in [1e7, -3e9, f64::INFINITY, f64::NAN, 0.0, -0.0, 1e-300] {
            assert_eq!(sin_f64(x).to_bits(), x.sin().to_bits(), "sin({x})");
            assert_eq!(cos_f64(x).to_bits(), x.cos().to_bits(), "cos({x})");
        }
    }

    #[test]
    fn generic_entry_points_dispatch_by_type() {
        // f64 takes the kernels, f32 its own functions: both agree with libm.
        assert_eq!(sin(1.25_f64), sin_f64(1.25));
        assert_eq!(sin(1.25_f32), 1.25_f32.sin());
        assert_eq!(cos(0.5_f32), 0.5_f32.cos());
        assert_eq!(sin_cos(0.5_f32), 0.5_f32.sin_cos());
        // One reduction for both: the same values as the separate calls.
        for x in [-7.3e4, -2.0, -1e-12, 0.0, 0.7, 3.0, 5.5, 1e5, 1e7, f64::NAN] {
            let (s, c) = sin_cos(x);
            assert!(
                s.to_bits() == sin(x).to_bits() || (s.is_nan() && x.is_nan()),
                "{x}"
            );
            assert!(
                c.to_bits() == cos(x).to_bits() || (c.is_nan() && x.is_nan()),
                "{x}"
            );
        }
    }
}
