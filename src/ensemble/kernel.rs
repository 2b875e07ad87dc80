//! One trial step of DOPRI5 in every lane: the vector part of the ensemble's loop.
//!
//! The step is the scalar [`Dopri5`](crate::integrate::Dopri5)'s, operation for operation
//! (the tableau of [`dopri5::tableau`](crate::integrate::dopri5::tableau), the error norm of
//! [`Tolerances::error_norm`], the PI controller), written over the components of a state
//! of any size `M` and evaluated with the model's lane form
//! ([`LaneDynamics`](crate::LaneDynamics)). It is compiled for the instruction set chosen at
//! run time ([`Simd`](crate::lanes::Simd)): the body is handed to `pulp`, which runs it under the AVX2 or
//! AVX-512 target features where the CPU has them.

use crate::LaneDynamics;
use crate::drive::QuietEnds;
use crate::event::{EventSet, MAX_EVENTS};
use crate::integrate::dopri5::tableau;
use crate::integrate::{StepOptions, Tolerances};
use crate::lanes::math::{exp, ln};
use crate::lanes::{F64x4, LaneMath, Lanes, TRUE};
#[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
use crate::lanes::{F64x8, F64x16};

/// An instruction set the lane loop is compiled for, with its lane width: a run takes
/// [`Wide`](Self::Wide) lanes and moves its last trajectories to [`Narrow`](Self::Narrow)
/// ones (the engine's compaction), stepped by [`Tail`](Self::Tail). Each (instruction set,
/// model, event set) compiles the lane loop for these two widths only.
///
/// The entry points [`step`](Self::step) and [`event_ends`](Self::event_ends) are methods
/// of the marker: the compiler places a generic method's code with its `Self` type, and
/// each marker is declared in a module of its own (below), so each instruction set's and
/// tail's lane loops (every model and event set) form a codegen unit of their own, which an
/// optimized build compiles in parallel with the others. As free functions of this module
/// they were all one unit (11 of the 15 minutes of `cargo build --release --all-features`).
pub(crate) trait Isa: Copy + Send + Sync + 'static {
    /// The lanes of a run (sixteen with AVX2 or AVX-512: the fastest width measured for the
    /// catalogue's models, `docs/performance.md`).
    type Wide: Lanes;
    /// The lanes the tail of a run compacts into (half of `Wide`).
    type Narrow: Lanes;
    /// The marker that steps the tail's `Narrow` lanes (the same instruction set; itself
    /// for a tail, which compacts no further).
    type Tail: Isa;
    /// Runs `f` compiled with this instruction set's target features.
    fn vectorize<F: pulp::WithSimd>(f: F) -> F::Output;

    /// One pass of the lane loop, compiled for this instruction set.
    #[inline(never)]
    fn step<V: Lanes, D: LaneDynamics<M>, const M: usize>(
        st: &mut LaneState<V, D, M>,
        k: &StepConsts<M>,
        out: &mut StepOut,
    ) {
        Self::vectorize(Pass { st, k, out })
    }

    /// Every event's value and rate at both ends of the accepted steps of a pass (from the
    /// rows `T0, T1, X0, X1, F0, F1` of `out`; at the start from `cache` where the lane is
    /// not fresh), from its lane form, and what they say about a quiet step
    /// ([`QuietEnds::lanes`], into `out.quiet`); `out.events` tells whether every event has
    /// a lane form. The accepted lanes' ends become their cached starts. Compiled, like
    /// [`step`](Self::step), for this instruction set (and apart from it, so that the step
    /// is not compiled again for each event set).
    #[inline(never)]
    fn event_ends<V: Lanes, E: EventSet<f64, M>, const M: usize>(
        events: &E,
        (cache, accepted): (&mut EndsCache<V>, V),
        out: &mut StepOut,
    ) {
        Self::vectorize(Ends::<V, E, M> {
            events,
            cache,
            accepted,
            out,
        })
    }
}

/// An instruction set's marker and its tail's, each in a module of its own (so that each
/// marker's lane loops are a codegen unit of their own, see [`Isa`]): `Wide` lanes and the
/// tail's `Narrow` ones, `vectorize` for both.
macro_rules! isa {
    (
        $(#[$doc:meta])* $module:ident::$name:ident($wide:ty, $narrow:ty),
        $(#[$tail_doc:meta])* $tail:ident,
        |$f:ident| $vectorize:expr
    ) => {
        mod $module {
            use super::*;

            $(#[$doc])*
            #[derive(Debug, Clone, Copy)]
            pub(crate) struct $name;

            impl Isa for $name {
                type Wide = $wide;
                type Narrow = $narrow;
                type Tail = tail::$tail;
                #[inline(always)]
                fn vectorize<F: pulp::WithSimd>($f: F) -> F::Output {
                    $vectorize
                }
            }

            mod tail {
                use super::*;

                $(#[$tail_doc])*
                #[derive(Debug, Clone, Copy)]
                pub(crate) struct $tail;

                impl Isa for $tail {
                    type Wide = $narrow;
                    type Narrow = $narrow;
                    type Tail = Self;
                    #[inline(always)]
                    fn vectorize<F: pulp::WithSimd>(f: F) -> F::Output {
                        $name::vectorize(f)
                    }
                }
            }
        }
    };
}

pub(crate) use baseline::Baseline;
isa! {
    /// The build's target features (SSE2 on a default x86-64 build): four lanes (two SSE2
    /// registers per value), two in the tail.
    baseline::Baseline(F64x4, crate::lanes::F64x2),
    /// The baseline's tail: two lanes.
    BaselineTail,
    |f| pulp::Simd::vectorize(pulp::Scalar::new(), f)
}

#[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
pub(crate) use avx2::Avx2;
#[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
isa! {
    /// AVX2 and FMA: sixteen lanes (four registers of four per value), eight in the tail.
    avx2::Avx2(F64x16, F64x8),
    /// AVX2's tail: eight lanes.
    Avx2Tail,
    |f| match pulp::x86::V3::try_new() {
        Some(v3) => pulp::Simd::vectorize(v3, f),
        None => pulp::Simd::vectorize(pulp::Scalar::new(), f),
    }
}

#[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
pub(crate) use avx512::Avx512;
#[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
isa! {
    /// AVX-512F with AVX2 and FMA: sixteen lanes (two registers of eight per value), eight
    /// in the tail.
    avx512::Avx512(F64x16, F64x8),
    /// AVX-512's tail: eight lanes.
    Avx512Tail,
    |f| match pulp::x86::V4::try_new() {
        Some(v4) => pulp::Simd::vectorize(v4, f),
        None => Avx2::vectorize(f),
    }
}

/// The vector state of all lanes.
#[derive(Debug, Clone)]
pub(crate) struct LaneState<V: Lanes, D: LaneDynamics<M>, const M: usize> {
    pub(crate) packed: D::Packed<V>,
    pub(crate) t: V,
    /// Each trajectory's start, the origin of its clock (`Stepper::start`): `t = origin + tau`.
    pub(crate) origin: V,
    /// The time elapsed since `origin`, advanced by the steps.
    pub(crate) tau: V,
    pub(crate) y: [V; M],
    pub(crate) f: [V; M],
    pub(crate) h: V,
    pub(crate) limit: V,
    /// The next landing point ([`landing_limit`](crate::drive::landing_limit)), which
    /// `limit` does not pass.
    pub(crate) landing: V,
    /// `|origin| + dt` of the landing grid (0 without one): the scale of the rounding of
    /// the landing point's computation.
    pub(crate) grid_scale: V,
    /// The time scale that bounds every step where it is the same at every `t` (the
    /// events' and the model's, [`EventSet::constant_max_step`]); `+∞` where there is
    /// none, or where it varies and the engine computes each limit lane by lane.
    pub(crate) scale: V,
    pub(crate) t_end: V,
    pub(crate) ln_err_old: V,
    pub(crate) rej_last: V,
    pub(crate) active: V,
    /// The seven stages of the last trial step (scratch of [`stages`]).
    pub(crate) kk: [[V; M]; 7],
    /// The lanes whose last trial step was accepted.
    pub(crate) accepted: V,
    /// Each trajectory's accepted and rejected steps so far, and its non-finite trial steps
    /// since the last accepted one (counts, exact as `f64`).
    pub(crate) counts: Counts<V>,
    /// The events at each lane's start ([`event_ends`]).
    pub(crate) ends: EndsCache<V>,
}

/// Each event's value and rate at each lane's current start, kept from the end of the
/// lane's last accepted step: [`event_ends`] then evaluates an event once per point of a
/// trajectory instead of twice (at both ends of every step). The start of a step is
/// exactly the end of the last accepted one (`t`, the state and its derivative, to the
/// bit) except after a new start or a restart at an event, which mark the lane fresh.
#[derive(Debug, Clone)]
pub(crate) struct EndsCache<V> {
    /// The lanes whose start is not kept (every lane of a new cache).
    pub(crate) fresh: V,
    g: [V; MAX_EVENTS],
    r: [V; MAX_EVENTS],
    /// Bit `e`: event `e` had a rate at the last update.
    has_rate: u32,
}

impl<V: Lanes> EndsCache<V> {
    /// A cache with every lane fresh.
    pub(crate) fn new() -> Self {
        let z = V::splat(0.0);
        Self {
            fresh: V::splat(TRUE),
            g: [z; MAX_EVENTS],
            r: [z; MAX_EVENTS],
            has_rate: 0,
        }
    }
}

/// The step counters of each lane ([`LaneState::counts`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Counts<V> {
    pub(crate) accepted: V,
    pub(crate) rejected: V,
    pub(crate) non_finite: V,
}

impl<V: Lanes> Counts<V> {
    /// Every count zero.
    pub(crate) fn zero() -> Self {
        let z = V::splat(0.0);
        Self {
            accepted: z,
            rejected: z,
            non_finite: z,
        }
    }

    /// Lane `i`'s counts set to zero (a new trajectory).
    pub(crate) fn clear_lane(&mut self, i: usize) {
        for c in [&mut self.accepted, &mut self.rejected, &mut self.non_finite] {
            c.set_lane(i, 0.0);
        }
    }
}

/// The scalar settings of a step: tolerances, controller constants and the math mode.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepConsts<const M: usize> {
    atol: [f64; M],
    rtol: [f64; M],
    expo: f64,
    beta: f64,
    safety: f64,
    inv_fac_max: f64,
    inv_fac_min: f64,
    h_max: f64,
    h_min: f64,
    max_steps: f64,
    math: LaneMath,
}

impl<const M: usize> StepConsts<M> {
    pub(crate) fn new(
        tol: &Tolerances<f64, M>,
        opts: &StepOptions<f64>,
        (max_steps, math): (usize, LaneMath),
    ) -> Self {
        Self {
            atol: core::array::from_fn(|i| tol.atol[i]),
            rtol: core::array::from_fn(|i| tol.rtol[i]),
            expo: 1.0 / 5.0 - 0.75 * opts.beta,
            beta: opts.beta,
            safety: opts.safety,
            inv_fac_max: 1.0 / opts.fac_max,
            inv_fac_min: 1.0 / opts.fac_min,
            h_max: opts.h_max,
            h_min: opts.h_min,
            max_steps: max_steps as f64,
            math,
        }
    }
}

/// The rows of [`StepOut::buf`]: lane `i` of each vector is `buf[row][i]`; a vector
/// quantity of the state takes `M` rows, component by component.
pub(crate) mod row {
    pub const T0: usize = 0;
    pub const T1: usize = 1;
    pub const H: usize = 2;
    /// The first row of the `q`-th vector quantity: `y₀, y₁, f₀, f₁, r₂, r₃, r₄, r₅`.
    pub const fn vector(q: usize, m: usize) -> usize {
        3 + q * m
    }
    pub const X0: usize = 0;
    pub const X1: usize = 1;
    pub const F0: usize = 2;
    pub const F1: usize = 3;
    pub const R2: usize = 4;
    pub const R3: usize = 5;
    pub const R4: usize = 6;
    pub const R5: usize = 7;
    /// The number of rows for a state of `m` components.
    pub const fn count(m: usize) -> usize {
        3 + 8 * m
    }
}

/// What one pass did (bit `i` for lane `i`) and the data of the accepted steps.
#[derive(Debug, Clone)]
pub(crate) struct StepOut {
    /// Lanes whose step fell below the minimum: no step was taken in any lane, and
    /// `buf[T0]`, `buf[H]` hold those lanes' `t` and step.
    pub(crate) too_small: u32,
    /// Lanes whose trial step was rejected (they keep their state, with a smaller step).
    pub(crate) rejected: u32,
    /// Lanes whose trial step was accepted (their step data are in `buf`).
    pub(crate) accepted: u32,
    /// Lanes whose trial steps were not finite more than 20 times in a row (rejected;
    /// `buf[T0]` holds their `t`): their trajectory fails.
    pub(crate) failing: u32,
    /// Accepted lanes whose step ends their trajectory: at its end time, or its step cap.
    pub(crate) ends: u32,
    /// Accepted lanes whose step ends on or near (within rounding of) their landing point,
    /// where the next one is computed again.
    pub(crate) near_landing: u32,
    /// Whether every event has a lane form and `quiet` holds what the ends of this
    /// pass's steps say about each ([`event_ends`]).
    pub(crate) events: bool,
    /// Per event, the masks of [`QuietEnds::lanes`] (bit `i` for lane `i`): the lanes
    /// whose step ends allow a quiet step, their side, and their rate into it.
    pub(crate) quiet: [[u32; 3]; MAX_EVENTS],
    /// For accepted lanes: `t₀, t₁, h`, then `y₀, y₁, f₀, f₁` and the dense output's
    /// `r₂…r₅`, `M` rows each. Allocated once per run.
    pub(crate) buf: Vec<[f64; 16]>,
}

impl StepOut {
    /// The output of a state of `m` components.
    pub(crate) fn new(m: usize) -> Self {
        Self {
            too_small: 0,
            rejected: 0,
            accepted: 0,
            failing: 0,
            ends: 0,
            near_landing: 0,
            events: false,
            quiet: [[0; 3]; MAX_EVENTS],
            buf: vec![[0.0; 16]; row::count(m)],
        }
    }
}

/// One pass, handed to `pulp` to be compiled with the instruction set's target features.
struct Pass<'a, V: Lanes, D: LaneDynamics<M>, const M: usize> {
    st: &'a mut LaneState<V, D, M>,
    k: &'a StepConsts<M>,
    out: &'a mut StepOut,
}

impl<V: Lanes, D: LaneDynamics<M>, const M: usize> pulp::WithSimd for Pass<'_, V, D, M> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        body(self.st, self.k, self.out)
    }
}

/// The six new stages of the trial step `hs` from `(t, y)` (ending at `t_new`), in one
/// loop so that the right-hand side is inlined once instead of six times: the stage
/// inputs are the scalar stepper's expressions, term for term. Fills the seven stages
/// `kk` (the first is `f`) and returns the new state. `kk` is the lane state's scratch,
/// written stage by stage before it is read: a fresh array here would be zeroed on every
/// pass (a `memset` of up to 3.5 KB at 16 lanes and a state of 4).
#[inline(always)]
fn stages<V: Lanes, D: LaneDynamics<M>, const M: usize>(
    (p, y, f): (&D::Packed<V>, &[V; M], &[V; M]),
    k: &StepConsts<M>,
    (t, hs, t_new): (V, V, V),
    kk: &mut [[V; M]; 7],
) -> [V; M] {
    let s = V::splat;
    let a21 = s(1.0 / 5.0);
    let [a31, a32] = splats::<V, _>(tableau::A3);
    let [a41, a42, a43] = splats::<V, _>(tableau::A4);
    let [a51, a52, a53, a54] = splats::<V, _>(tableau::A5);
    let [a61, a62, a63, a64, a65] = splats::<V, _>(tableau::A6);
    let [a71, a73, a74, a75, a76] = splats::<V, _>(tableau::B);
    let [c2, c3, c4, c5] = splats::<V, _>(tableau::C);
    let math = k.math;
    kk[0] = *f;
    let mut yn = *y;
    // Stage 2's time terms; stages 3 to 6 compute theirs in the loop, stage 7 shares
    // stage 6's (both at t_new).
    let mut time = D::time_lanes(p, math, t + c2 * hs);
    // The stage input, overwritten whole by every stage (not zeroed per stage).
    let mut ys = *y;
    for stage in 1..7 {
        let ts = match stage {
            1 => {
                for c in 0..M {
                    ys[c] = y[c] + kk[0][c] * (a21 * hs);
                }
                t + c2 * hs
            }
            2 => {
                for c in 0..M {
                    ys[c] = y[c] + combo(kk, &[(0, a31), (1, a32)], c) * hs;
                }
                t + c3 * hs
            }
            3 => {
                for c in 0..M {
                    ys[c] = y[c] + combo(kk, &[(0, a41), (1, a42), (2, a43)], c) * hs;
                }
                t + c4 * hs
            }
            4 => {
                for c in 0..M {
                    ys[c] = y[c] + combo(kk, &[(0, a51), (1, a52), (2, a53), (3, a54)], c) * hs;
                }
                t + c5 * hs
            }
            5 => {
                let terms = [(0, a61), (1, a62), (2, a63), (3, a64), (4, a65)];
                for c in 0..M {
                    ys[c] = y[c] + combo(kk, &terms, c) * hs;
                }
                t_new
            }
            _ => {
                let terms = [(0, a71), (2, a73), (3, a74), (4, a75), (5, a76)];
                for c in 0..M {
                    yn[c] = y[c] + combo(kk, &terms, c) * hs;
                }
                ys = yn;
                t_new
            }
        };
        if stage != 1 && stage != 6 {
            time = D::time_lanes(p, math, ts);
        }
        D::rhs_lanes(p, math, ts, &time, &ys, &mut kk[stage]);
    }
    yn
}

/// The error norm of the trial step ([`Tolerances::error_norm`](crate::integrate::Tolerances),
/// lane-wise) and the mask of lanes whose new state and last stage are finite (the norm
/// is NaN elsewhere).
#[inline(always)]
fn error_norm<V: Lanes, const M: usize>(
    k: &StepConsts<M>,
    kk: &[[V; M]; 7],
    y: &[V; M],
    yn: &[V; M],
    hs: V,
) -> (V, V) {
    let s = V::splat;
    let [e1, e3, e4, e5, e6, e7] = splats::<V, _>(tableau::E);
    let mut acc = s(0.0);
    let mut finite = s(TRUE);
    for c in 0..M {
        let e = combo(
            kk,
            &[(0, e1), (2, e3), (3, e4), (4, e5), (5, e6), (6, e7)],
            c,
        ) * hs;
        let q = e / (s(k.atol[c]) + s(k.rtol[c]) * y[c].abs().max(yn[c].abs()));
        acc = acc + q * q;
        finite = finite & yn[c].finite() & kk[6][c].finite();
    }
    let err = (acc / s(M as f64)).sqrt();
    (finite.select(err, s(f64::NAN)), finite)
}

/// Every constant of `a` in every lane. A loop the compiler unrolls in place: an array's
/// `map` of six constants was left out of line, a call in the middle of each pass.
#[inline(always)]
fn splats<V: Lanes, const K: usize>(a: [f64; K]) -> [V; K] {
    let mut r = [V::splat(0.0); K];
    for (v, x) in r.iter_mut().zip(a) {
        *v = V::splat(x);
    }
    r
}

/// `Σ_j k_j·a_j` over the given stages, component `c`, in the scalar stepper's order.
#[inline(always)]
fn combo<V: Lanes, const M: usize>(k: &[[V; M]; 7], terms: &[(usize, V)], c: usize) -> V {
    let (j0, a0) = terms[0];
    let mut s = k[j0][c] * a0;
    for &(j, a) in &terms[1..] {
        s = s + k[j][c] * a;
    }
    s
}

/// The trial step of every lane (the same operations in the same order as the scalar
/// [`Dopri5`](crate::integrate::Dopri5) and its controller), the masked update of the
/// accepted and rejected lanes, and the accepted lanes' step data in `out.buf`.
#[inline(always)]
fn body<V: Lanes, D: LaneDynamics<M>, const M: usize>(
    st: &mut LaneState<V, D, M>,
    k: &StepConsts<M>,
    out: &mut StepOut,
) {
    let s = V::splat;
    let [d1, d3, d4, d5, d6, d7] = splats::<V, _>(tableau::D);
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
    out.failing = 0;
    out.ends = 0;
    out.near_landing = 0;
    let (t, y, h) = (st.t, st.y, st.h);
    // The trial step on the elapsed time, cut to land on the lane's limit
    // (Core::trial_step).
    let rest = (st.limit - st.origin) - st.tau;
    let lands = h.ge(rest * s(0.99));
    let hs = lands.select(rest, h);
    let tau_try = st.tau + hs;
    let t_new = lands.select(st.limit, st.origin + tau_try);
    let tau_new = lands.select(st.limit - st.origin, tau_try);
    let too_small =
        (hs.lt((min_step_rel * t.abs()).max(h_min)) | !t_new.gt(t)) & !lands & st.active;
    if too_small.bits() != 0 {
        out.too_small = too_small.bits();
        t.store(&mut out.buf[row::T0]);
        hs.store(&mut out.buf[row::H]);
        return;
    }
    let yn = stages::<V, D, M>((&st.packed, &st.y, &st.f), k, (t, hs, t_new), &mut st.kk);
    let kk = &st.kk;
    let k1 = kk[0];
    let k7 = kk[6];
    let (err, finite) = error_norm(k, kk, &y, &yn, hs);
    // The PI controller (Controller::propose), lane-wise.
    let err_ok = err.finite();
    let pos = err.gt(zero) & err_ok;
    let ln_err = pos.select(ln(math, pos.select(err, one)), s(-700.0));
    let acc_mask = err_ok & err.le(one);
    // One exp per lane: err^α/err_old^β where accepted, err^α where rejected.
    let arg = acc_mask.select(expo_v * ln_err - beta_v * st.ln_err_old, expo_v * ln_err);
    let fac_any = exp(math, arg);
    let fac = (fac_any / safety).max(inv_fac_max).min(inv_fac_min);
    let h_acc = hs / fac;
    let h_acc = st.rej_last.select(h_acc.min(hs), h_acc).min(h_max);
    let h_rej = hs / (fac_any / safety).min(inv_fac_min);
    let h_next = acc_mask.select(h_acc, err_ok.select(h_rej, hs * s(0.1)));
    let accepted = acc_mask & st.active;
    st.accepted = accepted;
    let rejected = !accepted & st.active;
    // Rejected lanes retry with the smaller step.
    st.h = rejected.select(h_next, st.h);
    st.rej_last = rejected.select(s(TRUE), accepted.select(zero, st.rej_last));
    st.ln_err_old = accepted.select(ln_err.max(ln_floor), st.ln_err_old);
    out.rejected = rejected.bits();
    out.accepted = accepted.bits();
    // The counts (a non-finite trial step is never accepted: its norm is NaN).
    let n = &mut st.counts;
    n.accepted = n.accepted + accepted.select(one, zero);
    n.rejected = n.rejected + rejected.select(one, zero);
    let bad = !finite & rejected;
    n.non_finite = accepted.select(zero, n.non_finite + bad.select(one, zero));
    out.failing = (n.non_finite.gt(s(20.0)) & bad).bits();
    if out.failing != 0 {
        t.store(&mut out.buf[row::T0]);
    }
    if out.accepted == 0 {
        return;
    }
    let at_cap = n.accepted.ge(s(k.max_steps));
    out.ends = ((t_new.ge(st.t_end) | at_cap) & accepted).bits();
    let rounding = s(64.0 * f64::EPSILON) * (t_new.abs() + st.grid_scale);
    out.near_landing = ((st.landing - t_new).le(rounding) & accepted).bits();
    // The next limit (`scaled_limit`; the engine computes it again where the landing
    // point or the scale changes).
    st.limit = accepted.select(st.landing.min(t_new + st.scale), st.limit);
    // Accepted lanes: the new state, the next step, the dense output.
    st.t = accepted.select(t_new, st.t);
    st.tau = accepted.select(tau_new, st.tau);
    st.h = accepted.select(lands.select(h_next.max(h), h_next), st.h);
    t.store(&mut out.buf[row::T0]);
    t_new.store(&mut out.buf[row::T1]);
    hs.store(&mut out.buf[row::H]);
    let dterms = [(0, d1), (2, d3), (3, d4), (4, d5), (5, d6), (6, d7)];
    for c in 0..M {
        st.y[c] = accepted.select(yn[c], st.y[c]);
        st.f[c] = accepted.select(k7[c], st.f[c]);
        let dy = yn[c] - y[c];
        let b = k1[c] * hs - dy;
        let r4 = dy - k7[c] * hs - b;
        let r5 = combo(kk, &dterms, c) * hs;
        for (q, w) in [y[c], yn[c], k1[c], k7[c], dy, b, r4, r5]
            .into_iter()
            .enumerate()
        {
            w.store(&mut out.buf[row::vector(q, M) + c]);
        }
    }
}

/// The events' ends, handed to `pulp` like [`Pass`].
struct Ends<'a, V, E, const M: usize> {
    events: &'a E,
    cache: &'a mut EndsCache<V>,
    accepted: V,
    out: &'a mut StepOut,
}

impl<V: Lanes, E: EventSet<f64, M>, const M: usize> pulp::WithSimd for Ends<'_, V, E, M> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        ends_body::<V, E, M>(self.events, (self.cache, self.accepted), self.out)
    }
}

#[inline(always)]
fn ends_body<V: Lanes, E: EventSet<f64, M>, const M: usize>(
    events: &E,
    (cache, accepted): (&mut EndsCache<V>, V),
    out: &mut StepOut,
) {
    out.events = false;
    let buf = &out.buf;
    let load = |r: usize| V::load(&buf[r]);
    let vector = |q: usize| -> [V; M] { core::array::from_fn(|c| load(row::vector(q, M) + c)) };
    let (t1, y1, f1) = (load(row::T1), vector(row::X1), vector(row::F1));
    let fresh = cache.fresh & accepted;
    let any_fresh = fresh.bits() != 0;
    for e in 0..E::LEN {
        let Some((g1, r1)) = events.lanes(e, t1, &y1, &f1) else {
            return;
        };
        let kept_r = (cache.has_rate & (1 << e) != 0).then_some(cache.r[e]);
        // Lanes whose start values are not to be trusted: none, unless the event's rate
        // came and went between points (then only the fresh lanes are evaluated here).
        let mut trust = V::splat(TRUE);
        let (g0, r0) = if any_fresh {
            let (t0, y0, f0) = (load(row::T0), vector(row::X0), vector(row::F0));
            let Some((g, r)) = events.lanes(e, t0, &y0, &f0) else {
                return;
            };
            let r0 = match (r, kept_r) {
                (Some(n), Some(k)) => Some(fresh.select(n, k)),
                (r, k) => {
                    if r.is_some() != k.is_some() {
                        trust = fresh;
                    }
                    r
                }
            };
            (fresh.select(g, cache.g[e]), r0)
        } else {
            if r1.is_some() != kept_r.is_some() {
                trust = V::splat(0.0);
            }
            (cache.g[e], kept_r)
        };
        let [ends, positive, away] = QuietEnds::lanes((g0, g1), (r0, r1));
        out.quiet[e] = [ends & trust, positive, away].map(V::bits);
        cache.g[e] = accepted.select(g1, cache.g[e]);
        if let Some(r1) = r1 {
            cache.r[e] = accepted.select(r1, cache.r[e]);
            cache.has_rate |= 1 << e;
        } else {
            cache.has_rate &= !(1 << e);
        }
    }
    cache.fresh = cache.fresh & !accepted;
    out.events = true;
}
