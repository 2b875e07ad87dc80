//! Crossing `ẋ = 0` in a power scale of the velocity: the [`TurningPoints`] stepper.
//!
//! # Why
//! A force term `∝ sgn(ẋ)|ẋ|^q` with `0 < q < 1` (the paper's contact damping, `q = n3 =
//! 0.18667`) has an infinite slope at `ẋ = 0`. Where the trajectory turns round with an
//! acceleration `a ≠ 0`, `ẋ ≈ a·τ`, so the velocity has a `|τ|^{1+q}` term: a method that
//! steps in time must shrink its steps to ~10⁻⁸ s there and grow them back (≈ 40 attempts per
//! turning point at rtol 10⁻⁸ on the paper's model). A regularized friction
//! `T·ẋ/√(ẋ² + ε²)` adds a layer of width `ε/|a|` in time at every `ẋ = 0`.
//!
//! # How
//! Both are explicit functions of `ẋ`, and `ẋ` is monotone across the turning point. Inside
//! the band `|ẋ| < V*` the stepper integrates with the velocity as the independent variable,
//! in a power scale chosen from the exponent `q` the system declares
//! ([`Dynamics::velocity_exponent`]), `p = ⌈1/q⌉`:
//!
//! ```text
//! ẋ = sgn(u)|u|^p,   ẋ'(u) = p|u|^{p−1},
//! dτ/du = ẋ'(u)/a(t, x, ẋ),   dx/du = ẋ·ẋ'(u)/a(t, x, ẋ).
//! ```
//!
//! The cusp `|ẋ|^q = |u|^{pq}` (`pq ≥ 1`) enters `dτ/du` multiplied by `u^{p−1}`, so the
//! segment's right-hand side has `p − 1` more continuous derivatives than the cusp (`p = 6`
//! for the paper's `n3`: enough for a fifth-order method), and the friction layer is
//! stretched from `ε` to `≈ ε^{1/p}`. An integer `p` keeps the map `u ↦ ẋ` to a few
//! multiplications: `p = 1/q` itself (5.36 for the paper) took 6 % fewer steps per segment
//! (14.7 against 15.6 at rtol 10⁻⁸) but a `powf` per evaluation, and more time per period.
//!
//! The state of a *segment* is `(θ, x)`: the time since the segment began in units of its
//! natural duration, `θ = τ·|a₀|/V*` (`a₀` the acceleration at entry; a segment lasts
//! `θ ≈ 2`), and the position. A second stepper of the user's choice integrates it in
//! `s = σu` (`σ = sgn(a₀)`, so that `s` grows) from the band's edge on the near side (or from
//! `u = 0` for a body at rest) to its edge on the far side, `s = V*^{1/p}`.
//!
//! Every step of a segment is an accepted step of this stepper in time: its span is
//! `[t₀ + τ(s_a), t₀ + τ(s_b)]`, its dense output inverts `τ(s)` (`τ` is monotone: `dτ/ds =
//! ẋ'(u)/|a| ≥ 0`) and returns `(x(s), ẋ(s))`, so the driver's event location, sections and
//! observers work inside segments unchanged. A step never passes the driver's `t_limit`: a
//! segment step that would is cut at `τ(s) = t_limit − t₀` and the segment goes on from there.
//!
//! # When a segment is not used, or is left
//! - The system declares no exponent, or its `f₀ ≠ ẋ` (not a one-degree-of-freedom system in
//!   `(x, ẋ)`): the time stepper alone (the generic path).
//! - Entry needs `a·ẋ < 0` (the velocity heads to zero) or `ẋ = 0` with `a ≠ 0` after a reset.
//! - If the acceleration vanishes or changes sign inside a segment (sticking, a grazing exit),
//!   the segment step fails or `dτ/ds` turns non-positive: the segment is abandoned at its
//!   last accepted point and the time stepper goes on from there; no new segment starts until
//!   `|ẋ|` has left the band. Nothing is stepped over: the abandoned step was never reported.
//!
//! # Accuracy
//! A segment's accuracy is set by the segment stepper's tolerances on `(θ, x)`. The error
//! in `θ` is a phase error: `δτ = δθ·V*/|a₀|` shifts the state by `(ẋ, ẍ)·δτ` at the exit.
//! [`TurningPoints::dopri5`] uses `rtol` for both, an absolute tolerance of `100·rtol` on
//! `θ` and the time stepper's on `x`, chosen by work–precision measurements on the paper's
//! model (`examples/turning_points.rs`): on a stable period-2 orbit (ω = 19 rad/s, where
//! errors do not grow from period to period), time stepping needs 1.0–1.5× (median 1.3×)
//! the evaluations to reach the segments' error at rtol 10⁻⁶…10⁻¹²; `θ` to `rtol` gains
//! nothing (0.85–1.13×: the segment then takes as many steps as time stepping spent), and
//! to `1000·rtol` 0.94–1.35×.

use nalgebra::{SVector, Vector2};

use super::{DenseOutput, IntegrateError, Stats, Stepper};
use crate::error::ParameterError;
use crate::roots::brent;
use crate::scalar::lit;
use crate::validate::positive;
use crate::{Dynamics, Real};

/// The most accepted steps a segment may take before it is abandoned (a guard against a
/// segment that crawls because `a → 0`; typical segments take 5–30).
const MAX_SEGMENT_STEPS: u32 = 10_000;

/// A stepper that crosses `ẋ = 0` of a one-degree-of-freedom system in the power scale of
/// the velocity that the system declares (see the [module docs](self) for the method).
///
/// `St` steps in time; `Sg` steps the segments' `(τ, x)` in `s`. Both keep their step-size
/// history between uses. Without a declared exponent it is the time stepper alone.
///
/// ```
/// use nonsmooth::drive::Simulation;
/// use nonsmooth::integrate::{Tolerances, TurningPoints};
/// use nonsmooth::model::paper::PAPER;
/// use nalgebra::Vector2;
///
/// let osc = PAPER.oscillator::<f64>(20.465)?;
/// let rtol = 1e-8;
/// let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?;
/// // DOPRI5 in time and in the segments, |ẋ| < 3 mm/s.
/// let stepper = TurningPoints::dopri5(tol, 3e-3)?;
/// let mut sim = Simulation::new(osc, stepper);
/// let out = sim.run(0.0, Vector2::new(PAPER.static_equilibrium()?, 0.0), 3.0, &mut ())?;
/// assert!(sim.stepper().segments() > 0);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TurningPoints<T: Real, St: Stepper<T, 2>, Sg: Stepper<T, 2>> {
    time: St,
    seg: Sg,
    band: T,
    mode: Mode<T>,
    t: T,
    y: SVector<T, 2>,
    dense: TurningDense<T, St::Dense, Sg::Dense>,
    stats: Stats,
    /// Right-hand-side evaluations of this stepper itself (entry and cut points).
    own_evals: u64,
    /// Set by `reset_state`: the next step may start a segment at once.
    fresh: bool,
    /// After an abandoned segment: no new one until `|ẋ|` has left the band.
    cooldown: bool,
    counts: SegmentCounts,
}

/// What the segments did (cumulative since construction).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SegmentCounts {
    /// Segments completed (crossed to the far edge of the band).
    pub completed: u64,
    /// Segments abandoned (the acceleration vanished or changed sign, or a step failed).
    pub abandoned: u64,
    /// Accepted plus rejected steps of the segment stepper.
    pub attempts: u64,
}

#[derive(Debug, Clone, Copy)]
enum Mode<T> {
    Time,
    Segment(Segment<T>),
}

/// A segment under way: its start time, direction and exponent.
#[derive(Debug, Clone, Copy)]
struct Segment<T> {
    t0: T,
    /// The segment's time unit `V*/|a|` at entry: its state holds `θ = τ/scale`.
    scale: T,
    sigma: T,
    p: i32,
    s_end: T,
    steps: u32,
}

impl<T: Real, St: Stepper<T, 2>, Sg: Stepper<T, 2>> TurningPoints<T, St, Sg>
where
    St::Dense: Clone,
    Sg::Dense: Clone,
{
    /// A time stepper, a segment stepper and the band `|ẋ| < v_band` in which segments run.
    ///
    /// The band should hold the turning point's cusp and friction layer (for the paper's
    /// model 3·10⁻³ m/s, where the acceleration is 10²–10⁴ m/s²) and be thin enough for the
    /// acceleration not to change sign inside it.
    ///
    /// # Errors
    /// [`ParameterError`] unless `v_band` is finite and > 0.
    pub fn new(time: St, segment: Sg, v_band: T) -> Result<Self, ParameterError> {
        positive("v_band", v_band)?;
        let dense = TurningDense {
            t0: T::zero(),
            t1: T::zero(),
            y0: SVector::zeros(),
            y1: SVector::zeros(),
            f0: SVector::zeros(),
            f1: SVector::zeros(),
            time: time.dense().clone(),
            seg: segment.dense().clone(),
            in_segment: false,
            t_seg: T::zero(),
            scale: T::one(),
            sigma: T::one(),
            p: 1,
            s0: T::zero(),
            s1: T::zero(),
        };
        Ok(Self {
            time,
            seg: segment,
            band: v_band,
            mode: Mode::Time,
            t: T::zero(),
            y: SVector::zeros(),
            dense,
            stats: Stats::default(),
            own_evals: 0,
            fresh: false,
            cooldown: false,
            counts: SegmentCounts::default(),
        })
    }

    /// The time stepper.
    pub fn time_stepper(&self) -> &St {
        &self.time
    }

    /// The segment stepper.
    pub fn segment_stepper(&self) -> &Sg {
        &self.seg
    }

    /// Segments completed so far.
    pub fn segments(&self) -> u64 {
        self.counts.completed
    }

    /// What the segments did so far.
    pub fn segment_counts(&self) -> SegmentCounts {
        let mut c = self.counts;
        let s = self.seg.stats();
        c.attempts = s.accepted + s.rejected;
        c
    }

    fn sync_stats(&mut self) {
        let events = self.stats.events;
        let mut s = *self.time.stats();
        s += self.seg.stats();
        s.rhs_evals += self.own_evals;
        s.events = events;
        self.stats = s;
    }

    /// `f(t, y)` counted as this stepper's own evaluation.
    fn eval<S: Dynamics<T, 2>>(&mut self, sys: &S, t: T, y: &SVector<T, 2>) -> SVector<T, 2> {
        let mut f = SVector::zeros();
        sys.rhs(t, y, &mut f);
        self.own_evals += 1;
        f
    }

    /// Starts a segment at `(t, y)` with `f = f(t, y)` if the velocity is in the band and
    /// heads to zero (or is zero with `a ≠ 0`) and the system is `(x, ẋ)` with a declared
    /// exponent.
    ///
    /// `v_max` bounds `|ẋ|`: the band for a fresh state, a little more at a located edge
    /// (the crossing is located to the rounding of `t`, so `|ẋ|` may exceed the band by a
    /// few ulps there).
    fn try_enter(
        &mut self,
        q: Option<T>,
        t: T,
        y: &SVector<T, 2>,
        f: &SVector<T, 2>,
        v_max: T,
    ) -> bool {
        let Some(q) = q else { return false };
        let (v, a) = (y[1], f[1]);
        let heads_to_zero = (v == T::zero() && a != T::zero()) || a * v < T::zero();
        let usable = q > T::zero()
            && q < T::one()
            && f[0] == v
            && heads_to_zero
            && v.abs() < v_max
            && a.is_finite();
        if !usable {
            return false;
        }
        let Some(p) = power_of(q) else { return false };
        let r = T::one() / lit::<T>(f64::from(p));
        let sigma = if a > T::zero() { T::one() } else { -T::one() };
        let u0 = v.signum() * v.abs().powf(r);
        let s0 = if v == T::zero() {
            T::zero()
        } else {
            sigma * u0
        };
        self.seg.reset_state(s0, Vector2::new(T::zero(), y[0]));
        self.mode = Mode::Segment(Segment {
            t0: t,
            scale: self.band / a.abs(),
            sigma,
            p,
            s_end: self.band.powf(r),
            steps: 0,
        });
        true
    }

    /// Leaves a segment at `(t, y)`: the time stepper goes on from there.
    fn leave(&mut self, t: T, y: SVector<T, 2>, abandoned: bool) {
        self.mode = Mode::Time;
        self.time.reset_state(t, y);
        if abandoned {
            self.counts.abandoned += 1;
            self.cooldown = true;
        } else {
            self.counts.completed += 1;
        }
    }

    /// One time step; cut where `|ẋ|` enters the band heading to zero, and a segment is
    /// started there.
    fn time_step<S: Dynamics<T, 2>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError> {
        let (t0, y0) = (self.t, self.y);
        self.time.step(sys, t_limit)?;
        let d = self.time.dense();
        let (t1, y1) = (self.time.current().0, *self.time.current().1);
        let (f0, f1) = d.end_derivatives();
        let (f0, f1) = (*f0, *f1);
        self.dense.time = d.clone();
        self.dense.in_segment = false;
        self.dense.t0 = t0;
        self.dense.y0 = y0;
        self.dense.f0 = f0;
        self.dense.t1 = t1;
        self.dense.y1 = y1;
        self.dense.f1 = f1;
        self.t = t1;
        self.y = y1;
        let (v0, v1) = (y0[1], y1[1]);
        if v1.abs() >= self.band {
            self.cooldown = false;
        }
        let q = sys.velocity_exponent();
        if q.is_none() || self.cooldown || !(v0.abs() >= self.band) {
            return Ok(());
        }
        let edge = if v0 > T::zero() {
            self.band
        } else {
            -self.band
        };
        // Entered the band (or crossed it) in this step?
        if !((v1 - edge) * (v0 - edge) < T::zero() || v1 == edge) {
            return Ok(());
        }
        let (tc, yc) = if v1 == edge {
            (t1, y1)
        } else {
            let tc = velocity_crossing(&self.dense.time, t0, v0 - edge, t1, v1 - edge, edge);
            let mut yc = SVector::zeros();
            self.dense.time.interpolate_unchecked(tc, &mut yc);
            (tc, yc)
        };
        if !(tc > t0) {
            return Ok(());
        }
        let fc = if tc == t1 {
            f1
        } else {
            self.eval(sys, tc, &yc)
        };
        if self.try_enter(q, tc, &yc, &fc, self.band * lit(2.0)) {
            // The time step ends at the band's edge.
            self.dense.t1 = tc;
            self.dense.y1 = yc;
            self.dense.f1 = fc;
            self.t = tc;
            self.y = yc;
        }
        Ok(())
    }

    /// One accepted step of the segment (or, if it is abandoned, a time step from its last
    /// point). Returns `false` if the segment was abandoned before a step was reported.
    fn segment_step<S: Dynamics<T, 2>>(
        &mut self,
        sys: &S,
        t_limit: T,
        mut g: Segment<T>,
    ) -> Result<bool, IntegrateError> {
        let (t_a, y_a) = (self.t, self.y);
        let f_a = if self.dense.t1 == t_a && self.dense.y1 == y_a {
            self.dense.f1
        } else {
            self.eval(sys, t_a, &y_a)
        };
        loop {
            let (s_a, z_a) = (self.seg.current().0, *self.seg.current().1);
            let r = Reparam {
                sys,
                t0: g.t0,
                scale: g.scale,
                p: g.p,
                sigma: g.sigma,
            };
            g.steps += 1;
            if g.steps > MAX_SEGMENT_STEPS || self.seg.step(&r, g.s_end).is_err() {
                self.leave(t_a, y_a, true);
                return Ok(false);
            }
            let (s_b, z_b) = (self.seg.current().0, *self.seg.current().1);
            let (_, dz_b) = self.seg.dense().end_derivatives();
            let dtau_b = dz_b[0] * g.scale;
            let u_b = g.sigma * s_b;
            let v_b = velocity(u_b, g.p);
            // dτ/ds > 0 except at u = 0; a sign change means a changed sign.
            let monotone = z_b[0] > z_a[0] && (dtau_b > T::zero() || u_b == T::zero());
            if !(monotone && z_b[1].is_finite() && v_b.is_finite()) {
                self.leave(t_a, y_a, true);
                return Ok(false);
            }
            let mut t_b = g.t0 + g.scale * z_b[0];
            if !(t_b > t_a) {
                // Below the resolution of t: step on in s.
                if s_b >= g.s_end {
                    self.leave(t_a, y_a, false);
                    return Ok(false);
                }
                continue;
            }
            self.dense.seg = self.seg.dense().clone();
            self.dense.in_segment = true;
            self.dense.t_seg = g.t0;
            self.dense.scale = g.scale;
            self.dense.sigma = g.sigma;
            self.dense.p = g.p;
            self.dense.s0 = s_a;
            self.dense.s1 = s_b;
            self.dense.t0 = t_a;
            self.dense.y0 = y_a;
            self.dense.f0 = f_a;
            let mut y_b = Vector2::new(z_b[1], v_b);
            let mut cut = false;
            if t_b > t_limit {
                // Cut at τ = t_limit − t₀; the segment goes on from there.
                let target = (t_limit - g.t0) / g.scale;
                let s_c = self.dense.invert(target);
                let mut z_c = SVector::zeros();
                self.dense.seg.interpolate_unchecked(s_c, &mut z_c);
                let u_c = g.sigma * s_c;
                y_b = Vector2::new(z_c[1], velocity(u_c, g.p));
                t_b = t_limit;
                self.dense.s1 = s_c;
                self.seg.reset_state(s_c, Vector2::new(target, z_c[1]));
                cut = true;
            }
            let f_b = if !cut && u_b != T::zero() {
                // a = σ·ẋ'(u)/(dτ/ds) from the step's last stage.
                let dv = lit::<T>(f64::from(g.p)) * v_b.abs() / u_b.abs();
                Vector2::new(v_b, g.sigma * dv / dtau_b)
            } else {
                self.eval(sys, t_b, &y_b)
            };
            self.dense.t1 = t_b;
            self.dense.y1 = y_b;
            self.dense.f1 = f_b;
            self.t = t_b;
            self.y = y_b;
            if !cut && s_b >= g.s_end {
                self.leave(t_b, y_b, false);
            } else {
                self.mode = Mode::Segment(g);
            }
            return Ok(true);
        }
    }
}

impl<T: Real> TurningPoints<T, super::Dopri5<T, 2>, super::Dopri5<T, 2>> {
    /// DOPRI5 in time with the tolerances `tol` and DOPRI5 in the segments with the
    /// recommended tolerances (see [Accuracy](self#accuracy)): `rtol` of `tol`'s first
    /// component for both, absolute `100·rtol` on `θ` and `tol`'s on `x`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `v_band` is finite and > 0, or if a tolerance is invalid.
    pub fn dopri5(tol: super::Tolerances<T, 2>, v_band: T) -> Result<Self, ParameterError> {
        tol.validate()?;
        let rtol = tol.rtol[0];
        let segment = super::Tolerances {
            rtol: SVector::repeat(rtol),
            atol: Vector2::new(rtol * lit(100.0), tol.atol[0]),
        };
        segment.validate()?;
        Self::new(super::Dopri5::new(tol), super::Dopri5::new(segment), v_band)
    }
}

impl<T: Real, St: Stepper<T, 2>, Sg: Stepper<T, 2>> Stepper<T, 2> for TurningPoints<T, St, Sg>
where
    St::Dense: Clone,
    Sg::Dense: Clone,
{
    type Dense = TurningDense<T, St::Dense, Sg::Dense>;

    fn reset_state(&mut self, t: T, y: SVector<T, 2>) {
        self.t = t;
        self.y = y;
        self.mode = Mode::Time;
        self.time.reset_state(t, y);
        self.fresh = true;
        self.cooldown = false;
    }

    fn step<S: Dynamics<T, 2>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError> {
        if !(t_limit > self.t) {
            // The time stepper reports the span error (or that it has no state).
            let r = self.time.step(sys, t_limit);
            self.sync_stats();
            return r;
        }
        if self.fresh {
            self.fresh = false;
            let q = sys.velocity_exponent();
            if q.is_some() && self.y[1].abs() < self.band {
                let (t, y) = (self.t, self.y);
                let f = self.eval(sys, t, &y);
                // At ẋ = 0 the check `f₀ = ẋ` cannot tell (x, ẋ) from another system:
                // probe a moving state.
                let probe = Vector2::new(y[0], self.band);
                let mechanical = y[1] != T::zero() || self.eval(sys, t, &probe)[0] == probe[1];
                let q = if mechanical { q } else { None };
                self.dense.t1 = t;
                self.dense.y1 = y;
                self.dense.f1 = f;
                self.try_enter(q, t, &y, &f, self.band);
            }
        }
        let r = match self.mode {
            Mode::Segment(g) => match self.segment_step(sys, t_limit, g) {
                Ok(true) => Ok(()),
                Ok(false) => self.time_step(sys, t_limit),
                Err(e) => Err(e),
            },
            Mode::Time => self.time_step(sys, t_limit),
        };
        self.sync_stats();
        r
    }

    fn current(&self) -> (T, &SVector<T, 2>) {
        (self.t, &self.y)
    }

    fn dense(&self) -> &Self::Dense {
        &self.dense
    }

    fn stats(&self) -> &Stats {
        &self.stats
    }

    fn stats_mut(&mut self) -> &mut Stats {
        &mut self.stats
    }

    fn order(&self) -> u8 {
        self.time.order()
    }

    fn check(&self) -> Result<(), IntegrateError> {
        self.time.check()?;
        self.seg.check()
    }

    fn max_step(&self) -> Option<T> {
        self.time.max_step()
    }
}

/// The system in `s = σu`, state `(θ, x)` with `τ = scale·θ`.
struct Reparam<'a, T, S> {
    sys: &'a S,
    t0: T,
    scale: T,
    p: i32,
    sigma: T,
}

impl<T: Real, S: Dynamics<T, 2>> Dynamics<T, 2> for Reparam<'_, T, S> {
    #[inline(always)]
    fn rhs(&self, s: T, z: &SVector<T, 2>, dz: &mut SVector<T, 2>) {
        let u = self.sigma * s;
        let au = u.abs();
        let mag = au.powi(self.p);
        let v = u.signum() * mag;
        // ẋ'(u) = p|u|^{p−1} = p|ẋ|/|u|: 0 at u = 0 (p ≥ 2).
        let dv = if au > T::zero() {
            lit::<T>(f64::from(self.p)) * mag / au
        } else {
            T::zero()
        };
        let mut f = SVector::zeros();
        self.sys
            .rhs(self.t0 + self.scale * z[0], &Vector2::new(z[1], v), &mut f);
        let dtau = self.sigma * dv / f[1];
        dz[0] = dtau / self.scale;
        dz[1] = v * dtau;
    }
}

/// Dense output of a [`TurningPoints`] step: the time stepper's, or a segment step's with
/// `τ(s)` inverted.
#[derive(Debug, Clone)]
pub struct TurningDense<T: Real, TD, SD> {
    t0: T,
    t1: T,
    y0: SVector<T, 2>,
    y1: SVector<T, 2>,
    f0: SVector<T, 2>,
    f1: SVector<T, 2>,
    time: TD,
    seg: SD,
    in_segment: bool,
    t_seg: T,
    scale: T,
    sigma: T,
    p: i32,
    s0: T,
    s1: T,
}

impl<T: Real, TD: DenseOutput<T, 2>, SD: DenseOutput<T, 2>> TurningDense<T, TD, SD> {
    /// The `s ∈ [s0, s1]` where the segment's `θ(s) = target` (Brent's method on the
    /// segment step's dense output; `τ` is monotone on the step).
    fn invert(&self, target: T) -> T {
        let mut z = SVector::zeros();
        let mut tau = |s: T| {
            self.seg.interpolate_unchecked(s, &mut z);
            z[0] - target
        };
        let (a, b) = (self.s0, self.s1);
        let (fa, fb) = (tau(a), tau(b));
        if !(fa < T::zero()) {
            return a;
        }
        if !(fb > T::zero()) {
            return b;
        }
        brent(tau, a, b, fa, fb, T::zero(), 200).unwrap_or(a + (b - a) * lit(0.5))
    }
}

impl<T: Real, TD: DenseOutput<T, 2>, SD: DenseOutput<T, 2>> DenseOutput<T, 2>
    for TurningDense<T, TD, SD>
{
    fn span(&self) -> (T, T) {
        (self.t0, self.t1)
    }

    fn endpoints(&self) -> (&SVector<T, 2>, &SVector<T, 2>) {
        (&self.y0, &self.y1)
    }

    fn end_derivatives(&self) -> (&SVector<T, 2>, &SVector<T, 2>) {
        (&self.f0, &self.f1)
    }

    #[inline]
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, 2>) {
        if !self.in_segment {
            self.time.interpolate_unchecked(t, out);
            return;
        }
        if t <= self.t0 {
            *out = self.y0;
            return;
        }
        if t >= self.t1 {
            *out = self.y1;
            return;
        }
        let s = self.invert((t - self.t_seg) / self.scale);
        let mut z = SVector::zeros();
        self.seg.interpolate_unchecked(s, &mut z);
        let u = self.sigma * s;
        *out = Vector2::new(z[1], velocity(u, self.p));
    }
}

/// The integer power `p = ⌈1/q⌉` of the scale `ẋ = sgn(u)|u|^p` for a declared exponent
/// `q ∈ (0, 1)`; `None` beyond `p = 64` (a cusp too strong for the scale to be worth it).
fn power_of<T: Real>(q: T) -> Option<i32> {
    let inv = crate::scalar::to_f64(T::one() / q).ceil();
    (2.0..=64.0).contains(&inv).then_some(inv as i32)
}

/// `ẋ = sgn(u)|u|^p`.
#[inline(always)]
fn velocity<T: Real>(u: T, p: i32) -> T {
    u.signum() * u.abs().powi(p)
}

/// The time in `[t0, t1]` where the time step's velocity reaches `edge` (`g = ẋ − edge`
/// changes sign: `g0`, `g1`), by Brent's method on the dense output.
fn velocity_crossing<T: Real, D: DenseOutput<T, 2>>(
    dense: &D,
    t0: T,
    g0: T,
    t1: T,
    g1: T,
    edge: T,
) -> T {
    let mut y = SVector::zeros();
    let g = |t: T| {
        dense.interpolate_unchecked(t, &mut y);
        y[1] - edge
    };
    brent(g, t0, t1, g0, g1, T::zero(), 200).unwrap_or(t0 + (t1 - t0) * lit(0.5))
}
