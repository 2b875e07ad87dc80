//! Lane forms of the math functions of the built-in parts: `sin` and `cos` of the forcing and
//! of moving surfaces, `exp` and
//! `ln` of the contact law's exponents and of the step-size controller.
//!
//! # `sin`
//! [`sin`] is the lane form of [`fastmath::sin_f64`](crate::fastmath::sin_f64) — the
//! same Cody–Waite reduction, the same fdlibm kernels, the same operations in the same
//! order — so each lane returns the scalar function's value **to the bit** (tested). The
//! quadrant `k mod 4` is taken as `k − 4·round(k/4)` on the exact integer `k` instead of
//! from the bits of `k + 1.5·2⁵²`, which is the same number. Lanes outside the kernels' range
//! (`|x| > 2¹⁹` or not finite) are passed to the platform's `sin` one by one, like the
//! scalar function does; lanes with `|x| < 2⁻²⁷` return `x`. Against `libm` this is at
//! most 1 ulp where `|sin x| > 10⁻³` and within `2.2·10⁻¹⁶` absolute near the zeros (the
//! scalar function's figures, `fastmath`'s tests).
//!
//! # `exp` and `ln`
//! [`LaneMath`] chooses how they are evaluated:
//! * [`LaneMath::Exact`] calls the platform's `exp`/`ln` lane by lane, for the lanes that
//!   need them (in contact): the values are those of the scalar path to the bit, so a lane
//!   follows the scalar trajectory step for step.
//! * [`LaneMath::Vector`] evaluates them in the lanes, without leaving the vector
//!   registers, by fdlibm's algorithms ([`exp_vector`]: reduction by `ln 2` in two parts,
//!   the rational form `1 + 2r/(2 − c(r))` with a degree-5 polynomial in `r²`, the scale
//!   `2^k` written into the exponent bits; [`ln_vector`]: exponent and mantissa from the
//!   bits, `s = f/(2 + f)` and a degree-7 polynomial in `s²`). Lanes outside their fast
//!   ranges (`|x| > 708` for `exp`; zero, subnormal, negative, infinite or NaN for `ln`)
//!   are passed to the platform's functions one by one. Measured against `libm` in
//!   `tests/ensemble.rs` (`exp` on `[−745, 710]`, `ln` on `[10⁻³⁰⁰, 10³⁰⁰]` and near 1,
//!   special values): at most 1 ulp for `exp` and for `ln` away from `x = 1`, where
//!   `ln x → 0` and the error is below `2⁻⁵⁴` absolute. Results then differ from the
//!   scalar path by rounding, and a lane's trajectory agrees with the scalar one within
//!   the integration tolerance instead of to the bit.

// The fdlibm constants are printed with the digits of their source.
#![allow(clippy::excessive_precision)]

use super::Lanes;

/// How the ensemble evaluates `exp` and `ln` (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LaneMath {
    /// The platform's `exp`/`ln`, lane by lane: bit-identical to the scalar path.
    #[default]
    Exact,
    /// fdlibm's algorithms in the lanes ([`exp_vector`], [`ln_vector`]): equal to the
    /// scalar path within rounding (≤ 1 ulp per call).
    Vector,
}

const PIO2_HI: f64 = 1.570_796_326_734_125_614_17;
const PIO2_LO: f64 = 6.077_100_506_506_192_249_32e-11;
const ROUND_MAGIC: f64 = 6_755_399_441_055_744.0;
const TRIG_LIMIT: f64 = 524_288.0;
const TINY: f64 = 7.450_580_596_923_828e-9;

#[inline(always)]
fn ksin<V: Lanes>(r: V) -> V {
    let s = V::splat;
    let z = r * r;
    let p = s(8.333_333_333_322_489_461_24e-03)
        + z * (s(-1.984_126_982_985_794_931_34e-04)
            + z * (s(2.755_731_370_707_006_767_89e-06)
                + z * (s(-2.505_076_025_340_686_341_95e-08)
                    + z * s(1.589_690_995_211_550_102_21e-10))));
    r + (r * z) * (s(-1.666_666_666_666_663_243_48e-01) + z * p)
}

#[inline(always)]
fn kcos<V: Lanes>(r: V) -> V {
    let s = V::splat;
    let z = r * r;
    let p = z
        * (s(4.166_666_666_666_660_190_37e-02)
            + z * (s(-1.388_888_888_887_410_957_49e-03)
                + z * (s(2.480_158_728_947_672_941_78e-05)
                    + z * (s(-2.755_731_435_139_066_330_35e-07)
                        + z * (s(2.087_572_321_298_174_827_90e-09)
                            + z * s(-1.135_964_755_778_819_482_65e-11))))));
    let hz = s(0.5) * z;
    let w = s(1.0) - hz;
    w + (((s(1.0) - w) - hz) + z * p)
}

/// `x = k·π/2 + r` in every lane: `(r, q)` with `q = k − 4·round(k/4) ∈ {−2, …, 2}`
/// (the scalar reduction's `k mod 4`, as an exact integer: `k/4` is exact and rounded with
/// the same 1.5·2⁵² trick; quadrant 1 is `q = 1`, quadrant 2 is `q = ±2`, quadrant 3 is
/// `q = −1`).
#[inline(always)]
fn reduce_pio2<V: Lanes>(x: V) -> (V, V) {
    let s = V::splat;
    let y = x * s(core::f64::consts::FRAC_2_PI) + s(ROUND_MAGIC);
    let k = y - s(ROUND_MAGIC);
    let r = (x - k * s(PIO2_HI)) - k * s(PIO2_LO);
    let q = k - s(4.0) * ((k * s(0.25) + s(ROUND_MAGIC)) - s(ROUND_MAGIC));
    (r, q)
}

/// `sin x` in every lane, bit-identical to
/// [`fastmath::sin_f64`](crate::fastmath::sin_f64) (see the [module docs](self)).
#[inline(always)]
pub fn sin<V: Lanes>(x: V) -> V {
    sin_of(x, quadrant(x))
}

/// `cos x` in every lane, bit-identical to
/// [`fastmath::cos_f64`](crate::fastmath::cos_f64) (the reduction and kernels of [`sin`];
/// `1` for `|x| < 2⁻²⁷`, the platform's `cos` lane by lane outside the kernels' range).
#[inline(always)]
pub fn cos<V: Lanes>(x: V) -> V {
    cos_of(x, quadrant(x))
}

/// `(sin x, cos x)` in every lane with one reduction: each bit-identical to [`sin`] and
/// [`cos`] (and so to [`fastmath::sin_cos_f64`](crate::fastmath::sin_cos_f64)).
#[inline(always)]
pub fn sin_cos<V: Lanes>(x: V) -> (V, V) {
    let k = quadrant(x);
    (sin_of(x, k), cos_of(x, k))
}

/// The quadrant `q` of `x` ([`reduce_pio2`]) and both kernels at its remainder.
#[inline(always)]
fn quadrant<V: Lanes>(x: V) -> (V, V, V) {
    let (r, q) = reduce_pio2(x);
    (q, ksin(r), kcos(r))
}

/// `sin x` from its quadrant and kernels ([`quadrant`]).
#[inline(always)]
fn sin_of<V: Lanes>(x: V, (q, sn, cs): (V, V, V)) -> V {
    let s = V::splat;
    // Quadrants 1, 3 take the cosine kernel; quadrants 2, 3 change the sign.
    let odd = q.eq(s(1.0)) | q.eq(s(-1.0));
    let neg = q.ge(s(2.0)) | q.lt(s(0.0));
    let v = odd.select(cs, sn);
    let mut v = neg.select(-v, v);
    let a = x.abs();
    v = a.lt(s(TINY)).select(x, v);
    let slow = !a.le(s(TRIG_LIMIT));
    patch(v, slow, x, f64::sin)
}

/// `cos x` from its quadrant and kernels ([`quadrant`]).
#[inline(always)]
fn cos_of<V: Lanes>(x: V, (q, sn, cs): (V, V, V)) -> V {
    let s = V::splat;
    // Quadrants 1, 3 take the sine kernel; quadrants 1, 2 change the sign.
    let odd = q.eq(s(1.0)) | q.eq(s(-1.0));
    let neg = q.eq(s(1.0)) | q.eq(s(2.0)) | q.eq(s(-2.0));
    let v = odd.select(sn, cs);
    let mut v = neg.select(-v, v);
    let a = x.abs();
    v = a.lt(s(TINY)).select(s(1.0), v);
    let slow = !a.le(s(TRIG_LIMIT));
    patch(v, slow, x, f64::cos)
}

/// `e^x` in every lane.
#[inline(always)]
pub fn exp<V: Lanes>(math: LaneMath, x: V) -> V {
    match math {
        LaneMath::Exact => map(x, f64::exp),
        LaneMath::Vector => exp_vector(x),
    }
}

/// `ln x` in every lane.
#[inline(always)]
pub fn ln<V: Lanes>(math: LaneMath, x: V) -> V {
    match math {
        LaneMath::Exact => map(x, f64::ln),
        LaneMath::Vector => ln_vector(x),
    }
}

/// `e^{c·ln x}` in the lanes of `mask` (others: 0); `Exact` calls the platform's
/// functions only for those lanes.
#[inline(always)]
pub fn pow_masked<V: Lanes>(math: LaneMath, mask: V, x: V, c: V) -> V {
    match math {
        LaneMath::Exact => {
            let bits = mask.bits();
            if bits == 0 {
                return V::splat(0.0);
            }
            pow_lanes(bits, x, c)
        }
        LaneMath::Vector => {
            if mask.bits() == 0 {
                V::splat(0.0)
            } else {
                let xs = mask.select(x, V::splat(1.0));
                mask.select(exp_vector(c * ln_vector(xs)), V::splat(0.0))
            }
        }
    }
}

/// `e^{c·ln x}` in the lanes of `bits` (others: 0), by the platform's functions one lane
/// at a time. Inlined, like [`map`], so that the calls are direct: out of line, the
/// functions came in as pointers and every lane's call was an indirect one, which costs
/// most at narrow widths, where these calls are a larger part of a pass.
#[inline(always)]
fn pow_lanes<V: Lanes>(bits: u32, x: V, c: V) -> V {
    let (mut xa, mut ca) = ([0.0f64; 16], [0.0f64; 16]);
    x.store(&mut xa);
    c.store(&mut ca);
    let mut out = [0.0f64; 16];
    for i in 0..V::LANES {
        if bits & (1 << i) != 0 {
            out[i] = (ca[i] * xa[i].ln()).exp();
        }
    }
    V::load(&out)
}

const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-01;
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;

/// `e^x` in every lane for [`LaneMath::Vector`]: fdlibm's `exp` (Cody–Waite reduction `x = k·ln 2 + r`,
/// `|r| ≤ ½ln 2`, with `ln 2` in two parts; the rational form
/// `e^r = 1 + 2r/(2 − c(r))`, `c(r) = r − r²P(r²)`, `P` of degree 4; scaling by `2^k`
/// built in the exponent bits). `k` is rounded with the `1.5·2⁵²` trick, so nothing
/// leaves the vector registers. Lanes with `|x| > 708` or NaN (where `2^k` would not be a
/// normal number) take the platform's `exp`, one by one.
#[inline(always)]
pub fn exp_vector<V: Lanes>(x: V) -> V {
    let s = V::splat;
    let y = x * s(core::f64::consts::LOG2_E) + s(ROUND_MAGIC);
    let k = y - s(ROUND_MAGIC);
    let hi = x - k * s(LN2_HI);
    let lo = k * s(LN2_LO);
    let r = hi - lo;
    let t = r * r;
    let c = r - t
        * (s(1.666_666_666_666_660_190_37e-01)
            + t * (s(-2.777_777_777_701_559_338_42e-03)
                + t * (s(6.613_756_321_437_934_361_17e-05)
                    + t * (s(-1.653_390_220_546_525_153_90e-06)
                        + t * s(4.138_136_797_057_238_460_39e-08)))));
    let e = s(1.0) - ((lo - (r * c) / (s(2.0) - c)) - hi);
    let v = e * y.pow2_from_rounded();
    let slow = !x.abs().le(s(708.0));
    patch(v, slow, x, f64::exp)
}

/// `ln x` in every lane for [`LaneMath::Vector`]: fdlibm's `log` (`x = 2^k(1 + f)` with `1 + f ∈ [√½, √2)`,
/// `s = f/(2 + f)`, `ln(1 + f) = f − ½f² + s(½f² + R(s²))`, `R` of degree 7, `k·ln 2`
/// in two parts). The exponent and mantissa come from the bits by lane-wise masks and
/// shifts. Lanes that are not positive normal numbers (0, subnormal, negative, infinite,
/// NaN) take the platform's `ln`, one by one.
#[inline(always)]
pub fn ln_vector<V: Lanes>(x: V) -> V {
    let s = V::splat;
    let mantissa = s(f64::from_bits(0x000f_ffff_ffff_ffff));
    // 1 + f in [1, 2), then halved (and k raised by one) above √2.
    let m = (x & mantissa) | s(1.0);
    let big = m.ge(s(core::f64::consts::SQRT_2));
    let m = big.select(m * s(0.5), m);
    let dk = x.exponent_field() - s(1023.0) + big.select(s(1.0), s(0.0));
    let f = m - s(1.0);
    let hfsq = s(0.5) * f * f;
    let sf = f / (s(2.0) + f);
    let z = sf * sf;
    let w = z * z;
    let t1 = w
        * (s(3.999_999_999_940_941_908e-01)
            + w * (s(2.222_219_843_214_978_396e-01) + w * s(1.531_383_769_920_937_332e-01)));
    let t2 = z
        * (s(6.666_666_666_666_735_130e-01)
            + w * (s(2.857_142_874_366_239_149e-01)
                + w * (s(1.818_357_216_161_805_012e-01) + w * s(1.479_819_860_511_658_591e-01))));
    let rr = t2 + t1;
    let v = sf * (hfsq + rr) + dk * s(LN2_LO) - hfsq + f + dk * s(LN2_HI);
    // The lanes that are not positive normal numbers, from two integer additions: with b
    // the bits of x and N those of MIN_POSITIVE, b − N (wrapping) has its sign bit set for
    // +0, the positive subnormals and the negative numbers from −MIN_POSITIVE down (with
    // −inf and negative NaNs); b + N for +inf, positive NaNs and every negative number (−0
    // and the negative subnormals among them). The union is everything outside
    // [MIN_POSITIVE, MAX]. The two float comparisons this replaces became a floating-point
    // class test that the compiler did not vectorize (ln: 0.72 → 0.36 ns per lane, AVX2).
    let n = f64::MIN_POSITIVE.to_bits();
    let slow = x.add_bits(n.wrapping_neg()) | x.add_bits(n);
    patch(v, slow, x, f64::ln)
}

/// `v` with the lanes of `mask` replaced by `f` of the same lanes of `x` (the slow lanes of
/// the vector functions, computed one by one).
#[inline(always)]
fn patch<V: Lanes>(v: V, mask: V, x: V, f: fn(f64) -> f64) -> V {
    let bits = mask.bits();
    if bits != 0 {
        patch_lanes(v, bits, x, f)
    } else {
        v
    }
}

/// [`patch`]'s rare path, out of line (cold: lanes outside the fast ranges).
#[cold]
#[inline(never)]
fn patch_lanes<V: Lanes>(mut v: V, bits: u32, x: V, f: fn(f64) -> f64) -> V {
    for i in 0..V::LANES {
        if bits & (1 << i) != 0 {
            v = v.with_lane(i, f(x.lane(i)));
        }
    }
    v
}

/// `f` in every lane, one lane at a time (inlined: a direct call per lane, see
/// [`pow_lanes`]).
#[inline(always)]
fn map<V: Lanes>(x: V, f: fn(f64) -> f64) -> V {
    let mut a = [0.0f64; 16];
    x.store(&mut a);
    for v in a.iter_mut().take(V::LANES) {
        *v = f(*v);
    }
    V::load(&a)
}
