//! One trial step of DOPRI5 in every lane: the vector part of the ensemble's loop.
//!
//! The step is compiled inside this crate, once per lane type ([`F64x2`], [`F64x4`],
//! [`F64x8`], [`F64x16`]) and instruction set ([`Simd`]), and reached through the sealed
//! [`Lanes`] trait by a non-generic function per lane type. Code that runs an ensemble with
//! its own observer or event type therefore instantiates only the scalar bookkeeping
//! (events, observers, the work queue), not the inlined vector step: the step is compiled
//! once for the library instead of once per observer, event type and dependent crate.
//!
//! [`F64x2`]: super::F64x2
//! [`F64x4`]: super::F64x4
//! [`F64x8`]: super::F64x8
//! [`F64x16`]: super::F64x16

use super::math::{LaneMath, exp, ln};
use super::model::Packed;
use super::{Lanes, Simd};
use crate::integrate::dopri5::tableau;
use crate::integrate::{StepOptions, Tolerances};

/// All bits set: the `true` of a lane mask.
pub(crate) const ALL: f64 = f64::from_bits(u64::MAX);

/// The vector state of all lanes.
#[derive(Debug, Clone, Copy)]
pub struct LaneState<V> {
    pub(crate) packed: Packed<V>,
    pub(crate) t: V,
    pub(crate) x: V,
    pub(crate) v: V,
    pub(crate) fx: V,
    pub(crate) fv: V,
    pub(crate) h: V,
    pub(crate) limit: V,
    pub(crate) ln_err_old: V,
    pub(crate) rej_last: V,
    pub(crate) active: V,
}

/// The scalar settings of a step: tolerances, controller constants, math mode and the
/// instruction set (already resolved for this CPU).
#[derive(Debug, Clone, Copy)]
pub struct StepConsts {
    atol: [f64; 2],
    rtol: [f64; 2],
    expo: f64,
    beta: f64,
    safety: f64,
    inv_fac_max: f64,
    inv_fac_min: f64,
    h_max: f64,
    h_min: f64,
    math: LaneMath,
    simd: Simd,
}

impl StepConsts {
    pub(crate) fn new(
        tol: &Tolerances<f64, 2>,
        opts: &StepOptions<f64>,
        math: LaneMath,
        simd: Simd,
    ) -> Self {
        Self {
            atol: [tol.atol[0], tol.atol[1]],
            rtol: [tol.rtol[0], tol.rtol[1]],
            expo: 1.0 / 5.0 - 0.75 * opts.beta,
            beta: opts.beta,
            safety: opts.safety,
            inv_fac_max: 1.0 / opts.fac_max,
            inv_fac_min: 1.0 / opts.fac_min,
            h_max: opts.h_max,
            h_min: opts.h_min,
            math,
            simd: simd.resolve(),
        }
    }
}

/// The rows of [`StepOut::buf`]: lane `i` of each vector is `buf[row][i]`.
pub(crate) mod row {
    pub const T0: usize = 0;
    pub const T1: usize = 1;
    pub const H: usize = 2;
    pub const X0: usize = 3;
    pub const X1: usize = 5;
    pub const F0: usize = 7;
    pub const F1: usize = 9;
    pub const R2: usize = 11;
    pub const R3: usize = 13;
    pub const R4: usize = 15;
    pub const R5: usize = 17;
    pub const COUNT: usize = 19;
}

/// What one pass did (bit `i` for lane `i`) and the data of the accepted steps.
#[derive(Debug, Clone)]
pub struct StepOut {
    /// Lanes whose step fell below the minimum: no step was taken in any lane, and
    /// `buf[T0]`, `buf[H]` hold those lanes' `t` and step.
    pub(crate) too_small: u32,
    /// Lanes whose trial step was rejected (they keep their state, with a smaller step).
    pub(crate) rejected: u32,
    /// Lanes whose trial step was accepted (their step data are in `buf`).
    pub(crate) accepted: u32,
    /// Lanes whose trial step was not finite (rejected; `buf[T0]` holds their `t`).
    pub(crate) non_finite: u32,
    /// For accepted lanes: `t₀, t₁, h, y₀, y₁, f₀, f₁` and the dense output's `r₂…r₅`
    /// (two rows per vector quantity: `x`, then `ẋ`; see [`row`]).
    pub(crate) buf: [[f64; 16]; row::COUNT],
}

impl StepOut {
    pub(crate) fn new() -> Self {
        Self {
            too_small: 0,
            rejected: 0,
            accepted: 0,
            non_finite: 0,
            buf: [[0.0; 16]; row::COUNT],
        }
    }
}

/// One pass of the lane loop in the instruction set `k.simd` (the entry point of each lane
/// type's [`Sealed::step_lanes`](super::lanes::Sealed)).
#[inline(always)]
pub(crate) fn step<V: Lanes>(st: &mut LaneState<V>, k: &StepConsts, out: &mut StepOut) {
    #[cfg(target_arch = "x86_64")]
    match k.simd {
        Simd::Avx512 => {
            if let Some(v4) = pulp::x86::V4::try_new() {
                return pulp::Simd::vectorize(v4, Pass { st, k, out });
            }
        }
        Simd::Avx2 => {
            if let Some(v3) = pulp::x86::V3::try_new() {
                return pulp::Simd::vectorize(v3, Pass { st, k, out });
            }
        }
        _ => {}
    }
    body(st, k, out)
}

/// One pass, handed to `pulp` to be compiled with the instruction set's target features.
#[cfg(target_arch = "x86_64")]
struct Pass<'a, V> {
    st: &'a mut LaneState<V>,
    k: &'a StepConsts,
    out: &'a mut StepOut,
}

#[cfg(target_arch = "x86_64")]
impl<V: Lanes> pulp::WithSimd for Pass<'_, V> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        body(self.st, self.k, self.out)
    }
}

/// The trial step of every lane (the same operations in the same order as the scalar
/// [`Dopri5`](crate::integrate::Dopri5) and its controller), the masked update of the
/// accepted and rejected lanes, and the accepted lanes' step data in `out.buf`.
#[inline(always)]
fn body<V: Lanes>(st: &mut LaneState<V>, k: &StepConsts, out: &mut StepOut) {
    let s = V::splat;
    let a21 = s(1.0 / 5.0);
    let [a31, a32] = tableau::A3.map(s);
    let [a41, a42, a43] = tableau::A4.map(s);
    let [a51, a52, a53, a54] = tableau::A5.map(s);
    let [a61, a62, a63, a64, a65] = tableau::A6.map(s);
    let [a71, a73, a74, a75, a76] = tableau::B.map(s);
    let [e1, e3, e4, e5, e6, e7] = tableau::E.map(s);
    let [d1, d3, d4, d5, d6, d7] = tableau::D.map(s);
    let [c2, c3, c4, c5] = tableau::C.map(s);
    let (atx, atv) = (s(k.atol[0]), s(k.atol[1]));
    let (rtx, rtv) = (s(k.rtol[0]), s(k.rtol[1]));
    let (expo_v, beta_v) = (s(k.expo), s(k.beta));
    let (safety, inv_fac_max, inv_fac_min) = (s(k.safety), s(k.inv_fac_max), s(k.inv_fac_min));
    let h_max = s(k.h_max);
    let ln_floor = s(1e-4f64.ln());
    let min_step_rel = s(16.0 * f64::EPSILON);
    let h_min = s(k.h_min);
    let math = k.math;
    let one = s(1.0);
    let zero = s(0.0);

    out.too_small = 0;
    out.rejected = 0;
    out.accepted = 0;
    out.non_finite = 0;
    let p = &st.packed;
    let (t, x, v, k1x, k1v, h) = (st.t, st.x, st.v, st.fx, st.fv, st.h);
    // The trial step, cut to land on the lane's limit (clamp_to_limit).
    let rest = st.limit - t;
    let lands = h.ge(rest * s(0.99));
    let hs = lands.select(rest, h);
    let too_small =
        (hs.lt((min_step_rel * t.abs()).max(h_min)) | !(t + hs).gt(t)) & !lands & st.active;
    if too_small.bits() != 0 {
        out.too_small = too_small.bits();
        t.store(&mut out.buf[row::T0]);
        hs.store(&mut out.buf[row::H]);
        return;
    }
    let t_new = lands.select(st.limit, t + hs);
    // The six new stages in one loop, so that the right-hand side (sin, the contact law's
    // powers) is inlined once instead of six times: the stage inputs are the scalar
    // stepper's expressions, term for term.
    let mut kx = [zero; 7];
    let mut kv = [zero; 7];
    kx[0] = k1x;
    kv[0] = k1v;
    let (mut xn, mut vn) = (x, v);
    let mut forcing = zero;
    for stage in 1..7 {
        let (ts, xs, vs) = match stage {
            1 => (t + c2 * hs, x + k1x * (a21 * hs), v + k1v * (a21 * hs)),
            2 => (
                t + c3 * hs,
                x + (k1x * a31 + kx[1] * a32) * hs,
                v + (k1v * a31 + kv[1] * a32) * hs,
            ),
            3 => (
                t + c4 * hs,
                x + (k1x * a41 + kx[1] * a42 + kx[2] * a43) * hs,
                v + (k1v * a41 + kv[1] * a42 + kv[2] * a43) * hs,
            ),
            4 => (
                t + c5 * hs,
                x + (k1x * a51 + kx[1] * a52 + kx[2] * a53 + kx[3] * a54) * hs,
                v + (k1v * a51 + kv[1] * a52 + kv[2] * a53 + kv[3] * a54) * hs,
            ),
            5 => (
                t_new,
                x + (k1x * a61 + kx[1] * a62 + kx[2] * a63 + kx[3] * a64 + kx[4] * a65) * hs,
                v + (k1v * a61 + kv[1] * a62 + kv[2] * a63 + kv[3] * a64 + kv[4] * a65) * hs,
            ),
            _ => {
                xn = x + (k1x * a71 + kx[2] * a73 + kx[3] * a74 + kx[4] * a75 + kx[5] * a76) * hs;
                vn = v + (k1v * a71 + kv[2] * a73 + kv[3] * a74 + kv[4] * a75 + kv[5] * a76) * hs;
                (t_new, xn, vn)
            }
        };
        // Stages 6 and 7 are both at t_new: one sin for the two.
        if stage != 6 {
            forcing = p.excitation(ts);
        }
        let (fx, fv) = p.rhs_forced(math, forcing, xs, vs);
        kx[stage] = fx;
        kv[stage] = fv;
    }
    let [_, _, k3x, k4x, k5x, k6x, k7x] = kx;
    let [_, _, k3v, k4v, k5v, k6v, k7v] = kv;
    let ex = (k1x * e1 + k3x * e3 + k4x * e4 + k5x * e5 + k6x * e6 + k7x * e7) * hs;
    let ev = (k1v * e1 + k3v * e3 + k4v * e4 + k5v * e5 + k6v * e6 + k7v * e7) * hs;
    let qx = ex / (atx + rtx * x.abs().max(xn.abs()));
    let qv = ev / (atv + rtv * v.abs().max(vn.abs()));
    let err = (((zero + qx * qx) + qv * qv) / s(2.0)).sqrt();
    let finite = xn.finite() & vn.finite() & k7x.finite() & k7v.finite();
    let err = finite.select(err, s(f64::NAN));
    // The PI controller (Controller::propose), lane-wise.
    let err_ok = err.finite();
    let pos = err.gt(zero) & err_ok;
    let ln_err = pos.select(ln(math, pos.select(err, one)), s(-700.0));
    let acc = err_ok & err.le(one);
    // One exp per lane: err^α/err_old^β where accepted, err^α where rejected.
    let arg = acc.select(expo_v * ln_err - beta_v * st.ln_err_old, expo_v * ln_err);
    let fac_any = exp(math, arg);
    let fac = (fac_any / safety).max(inv_fac_max).min(inv_fac_min);
    let h_acc = hs / fac;
    let h_acc = st.rej_last.select(h_acc.min(hs), h_acc).min(h_max);
    let h_rej = hs / (fac_any / safety).min(inv_fac_min);
    let h_next = acc.select(h_acc, err_ok.select(h_rej, hs * s(0.1)));
    let acc = acc & st.active;
    let rejected = !acc & st.active;
    // Rejected lanes retry with the smaller step.
    st.h = rejected.select(h_next, st.h);
    st.rej_last = rejected.select(s(ALL), acc.select(zero, st.rej_last));
    st.ln_err_old = acc.select(ln_err.max(ln_floor), st.ln_err_old);
    out.rejected = rejected.bits();
    out.accepted = acc.bits();
    out.non_finite = (!finite & st.active).bits();
    if out.non_finite != 0 {
        t.store(&mut out.buf[row::T0]);
    }
    if out.accepted == 0 {
        return;
    }
    // Accepted lanes: the new state, the next step, the dense output.
    st.t = acc.select(t_new, st.t);
    st.x = acc.select(xn, st.x);
    st.v = acc.select(vn, st.v);
    st.fx = acc.select(k7x, st.fx);
    st.fv = acc.select(k7v, st.fv);
    st.h = acc.select(lands.select(h_next.max(h), h_next), st.h);
    let dxd = xn - x;
    let dvd = vn - v;
    let bx = k1x * hs - dxd;
    let bv = k1v * hs - dvd;
    let r4x = dxd - k7x * hs - bx;
    let r4v = dvd - k7v * hs - bv;
    let r5x = (k1x * d1 + k3x * d3 + k4x * d4 + k5x * d5 + k6x * d6 + k7x * d7) * hs;
    let r5v = (k1v * d1 + k3v * d3 + k4v * d4 + k5v * d5 + k6v * d6 + k7v * d7) * hs;
    for (b, w) in out.buf.iter_mut().zip([
        t, t_new, hs, x, v, xn, vn, k1x, k1v, k7x, k7v, dxd, dvd, bx, bv, r4x, r4v, r5x, r5v,
    ]) {
        w.store(b);
    }
}
