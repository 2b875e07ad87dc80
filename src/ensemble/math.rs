//! Lane forms of the math functions of the built-in laws: `sin` of the forcing, `exp` and
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
//! * [`LaneMath::Vector`] evaluates them in the lanes with `wide`'s polynomials (`exp`: a
//!   Cody–Waite reduction by `ln 2` and a degree-13 Taylor polynomial; `ln`: a rational
//!   approximation of degree 5/5 on `[√½, √2]` with `ln 2` split in two). Measured against
//!   `libm` in `tests/ensemble.rs` over the arguments the model produces (`exp` on
//!   `[−40, 40]`, `ln` on `[10⁻³⁰⁰, 10³⁰⁰]`): at most 1 ulp for `exp` and 1 ulp for `ln`
//!   away from `x = 1`, where `ln x → 0` and the error is below `2⁻⁵³` absolute. Results
//!   then differ from the scalar path by rounding, and a lane's trajectory agrees with the
//!   scalar one within the integration tolerance instead of to the bit.

// The fdlibm constants are printed with the digits of their source.
#![allow(clippy::excessive_precision)]

use super::Lanes;

/// How the ensemble evaluates `exp` and `ln` (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LaneMath {
    /// The platform's `exp`/`ln`, lane by lane: bit-identical to the scalar path.
    #[default]
    Exact,
    /// `wide`'s vector polynomials: faster in contact, equal to the scalar path within
    /// rounding (≤ 1 ulp per call).
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

/// `sin x` in every lane, bit-identical to
/// [`fastmath::sin_f64`](crate::fastmath::sin_f64) (see the [module docs](self)).
#[inline(always)]
pub fn sin<V: Lanes>(x: V) -> V {
    let s = V::splat;
    let y = x * s(core::f64::consts::FRAC_2_PI) + s(ROUND_MAGIC);
    let k = y - s(ROUND_MAGIC);
    let r = (x - k * s(PIO2_HI)) - k * s(PIO2_LO);
    // k mod 4 from q = k − 4·round(k/4) ∈ {−2, …, 2} (exact: k/4 is exact and rounded
    // with the same 1.5·2⁵² trick): quadrants 1, 3 are q = ±1, quadrants 2, 3 are
    // q ∈ {2, −2, −1}.
    let q = k - s(4.0) * ((k * s(0.25) + s(ROUND_MAGIC)) - s(ROUND_MAGIC));
    let (sn, cs) = (ksin(r), kcos(r));
    let odd = q.eq(s(1.0)) | q.eq(s(-1.0));
    let neg = q.ge(s(2.0)) | q.lt(s(0.0));
    let v = odd.select(cs, sn);
    let mut v = neg.select(-v, v);
    let a = x.abs();
    v = a.lt(s(TINY)).select(x, v);
    let slow = !a.le(s(TRIG_LIMIT));
    let bits = slow.bits();
    if bits != 0 {
        for i in 0..V::LANES {
            if bits & (1 << i) != 0 {
                v = v.with_lane(i, x.lane(i).sin());
            }
        }
    }
    v
}

/// `e^x` in every lane.
#[inline(always)]
pub fn exp<V: Lanes>(math: LaneMath, x: V) -> V {
    match math {
        LaneMath::Exact => map(x, f64::exp),
        LaneMath::Vector => x.exp_poly(),
    }
}

/// `ln x` in every lane.
#[inline(always)]
pub fn ln<V: Lanes>(math: LaneMath, x: V) -> V {
    match math {
        LaneMath::Exact => map(x, f64::ln),
        LaneMath::Vector => x.ln_poly(),
    }
}

/// `e^{c·ln x}` in the lanes of `mask` (others: 0); `Exact` calls the platform's
/// functions only for those lanes.
#[inline(always)]
pub(crate) fn pow_masked<V: Lanes>(math: LaneMath, mask: V, x: V, c: V) -> V {
    match math {
        LaneMath::Exact => {
            let bits = mask.bits();
            if bits == 0 {
                return V::splat(0.0);
            }
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
        LaneMath::Vector => {
            if mask.bits() == 0 {
                V::splat(0.0)
            } else {
                let xs = mask.select(x, V::splat(1.0));
                mask.select((c * xs.ln_poly()).exp_poly(), V::splat(0.0))
            }
        }
    }
}

#[inline(always)]
fn map<V: Lanes>(x: V, f: fn(f64) -> f64) -> V {
    let mut a = [0.0f64; 16];
    x.store(&mut a);
    for v in a.iter_mut().take(V::LANES) {
        *v = f(*v);
    }
    V::load(&a)
}
