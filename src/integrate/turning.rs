//! Crossing `ẋ = 0` in a power scale of the velocity: the [`TurningPoints`] stepper.
//!
//! # Why
//! A force term `∝ sgn(ẋ)|ẋ|^q` with `0 < q < 1` (a Hertz contact's damping, `q = n3`) has
//! an infinite slope at `ẋ = 0`. Where the trajectory turns round with an
//! acceleration `a ≠ 0`, `ẋ ≈ a·τ`, so the velocity has a `|τ|^{1+q}` term: a method that
//! steps in time must shrink its steps to ~10⁻⁸ s there and grow them back (the attempts per
//! turning point are counted by `examples/turning_points.rs`; figures in
//! `docs/performance.md`). A regularized friction
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
//! for `q ≈ 0.19`: enough for a fifth-order method), and the friction layer is
//! stretched from `ε` to `≈ ε^{1/p}`. An integer `p` keeps the map `u ↦ ẋ` to a few
//! multiplications; `p = 1/q` itself would cost a `powf` per evaluation.
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
//! # Contact onset and exit
//! A contact force `∝ δ^n` (`n = 3/2` for Hertz) switched on at `δ = 0` gives the
//! acceleration a `|τ|^n` term where the body enters or leaves contact with `ẋ ≠ 0`. With
//! [`TurningPoints::with_onset_band`] and a contact the system declares
//! ([`Dynamics::contact_onset`]), the first `δ*` of each contact is crossed with the
//! penetration's power scale as the independent variable, `δ = w^m` (`m` the smallest
//! integer with `m·n` integral, `m = 2` for Hertz: `δ^{3/2} = w³`), state `(θ, ẋ)`:
//!
//! ```text
//! dτ/dw = δ'(w)/ẋ,   dẋ/dw = ẍ·δ'(w)/ẋ,
//! ```
//!
//! from `w = 0` (the crossing of the stop, located on the time step's dense output) to
//! `w = δ*^{1/m}` entering, and back from `δ = δ*` to exactly `δ = 0` leaving. It needs
//! `ẋ ≠ 0` across the band; a contact shallower than `δ*` (the body turns round inside
//! it) abandons the segment and is stepped in time. It is off by default: on the paper's
//! model the time stepper crosses the first micrometres of a contact in a few attempts, and
//! the segment's restarts cost as much (`examples/turning_points.rs -- --onset 1e-5`;
//! figures in `docs/performance.md`).
//!
//! # Which systems declare
//! The one-degree-of-freedom models declare what their force laws declare
//! ([`ForceLaw::velocity_exponent`](crate::ForceLaw::velocity_exponent),
//! [`ForceLaw::contact_onset`](crate::ForceLaw::contact_onset)):
//! [`Oscillator`](crate::model::Oscillator) and
//! [`Mechanical`](crate::model::Mechanical) with `N = 1` (state `(x, ẋ)`), the smallest
//! exponent and the first stop of their laws. A `Mechanical` law on another coordinate of
//! its one degree of freedom, `g = w·x + o` (reversed, offset or scaled), has its cusp at
//! `ẋ = 0` too, and its stop `g_I` is mapped to `x_I = (g_I − o)/w` (the other side for
//! `w < 0`). A `Mechanical` system of `N > 1` degrees of freedom declares nothing: its
//! state is not `(x, ẋ)`, and this stepper steps two components. Its elements report their
//! declarations per coordinate ([`Elements`](crate::model::Elements)) for a stepper that
//! crosses `ġ = 0` of one coordinate among several. A system of one's own declares with
//! [`Dynamics::velocity_exponent`] and [`Dynamics::contact_onset`] (a reference `&S`
//! forwards them).
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
//! `θ` and the time stepper's on `x`, chosen by work–precision measurements on a stable
//! periodic orbit, where errors do not grow from period to period
//! (`examples/turning_points.rs`; figures in `docs/performance.md`).

use nalgebra::{SVector, Vector2};

use super::{DenseOutput, HermiteDense, IntegrateError, Stats, Stepper};
use crate::force::ContactOnset;
use crate::roots::brent;
use crate::scalar::lit;
use crate::validate::ParameterError;
use crate::validate::positive;
use crate::{Dynamics, Real};

/// The most accepted steps a segment may take before it is abandoned (a guard against a
/// segment that crawls because `a → 0` or `ẋ → 0`; typical segments take 3–40).
const MAX_SEGMENT_STEPS: u32 = 10_000;

/// A stepper that crosses `ẋ = 0` of a one-degree-of-freedom system in the power scale of
/// the velocity that the system declares, and optionally the first `δ*` of a declared
/// contact in a power scale of the penetration (see the [module docs](self) for the method).
///
/// `St` steps in time; `Sg` steps the segments in `s`. Both keep their step-size history
/// between uses. Without a declaration it is the time stepper alone.
///
/// ```
/// use nonsmooth::drive::Simulation;
/// use nonsmooth::integrate::{Tolerances, TurningPoints};
/// use nonsmooth::excite::Harmonic;
/// use nonsmooth::force::{HertzContact, LinearSpring, ViscousDamper};
/// use nonsmooth::model::Oscillator;
/// use nalgebra::Vector2;
///
/// // A forced oscillator hitting a stop at x = 0.01 whose damping term is
/// // b·δ^{3/2}·sgn(ẋ)|ẋ|^{1/4}: it declares the velocity exponent 1/4.
/// let contact = HertzContact::new(0.01, 1e6)?.with_damping(1.0, 1.5, 0.25)?;
/// let laws = (LinearSpring::new(100.0)?, ViscousDamper::new(0.1)?, contact);
/// let osc = Oscillator::new(1.0, laws, Harmonic::sine(2.0, 8.0)?)?;
/// let rtol = 1e-8;
/// let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?;
/// // DOPRI5 in time and in the segments, |ẋ| < 0.01.
/// let stepper = TurningPoints::dopri5(tol, 1e-2)?;
/// let mut sim = Simulation::new(osc, stepper);
/// let out = sim.run(0.0, Vector2::zeros(), 1.0, &mut ())?;
/// assert!(sim.stepper().segments() > 0);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TurningPoints<T: Real, St: Stepper<T, 2>, Sg: Stepper<T, 2>> {
    time: St,
    seg: Sg,
    band: T,
    onset_band: Option<T>,
    mode: Mode<T>,
    /// The rest of a velocity segment step after `ẋ = 0`, to report next.
    pending: Option<SegmentEnd<T>>,
    t: T,
    y: SVector<T, 2>,
    dense: TurningDense<T, St::Dense, Sg::Dense>,
    stats: Stats,
    /// Right-hand-side evaluations of this stepper itself (entry and cut points).
    own_evals: u64,
    /// Set by `reset_state`: the next step may start a segment at once.
    fresh: bool,
    /// After an abandoned velocity segment: no new one until `|ẋ|` has left the band.
    cooldown: bool,
    /// After an abandoned contact segment: no new one until `δ` has left `[0, δ*]`.
    cooldown_onset: bool,
    counts: SegmentCounts,
}

/// What the segments did (cumulative since construction).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SegmentCounts {
    /// Velocity segments completed (crossed to the far edge of the band).
    pub completed: u64,
    /// Velocity segments abandoned (the acceleration vanished or changed sign, or a step
    /// failed).
    pub abandoned: u64,
    /// Accepted plus rejected steps of the segment stepper in velocity segments.
    pub attempts: u64,
    /// Contact segments completed (entering or leaving contact).
    pub contact_completed: u64,
    /// Contact segments abandoned (the velocity vanished inside `[0, δ*]`, or a step
    /// failed).
    pub contact_abandoned: u64,
    /// Accepted plus rejected steps of the segment stepper in contact segments.
    pub contact_attempts: u64,
}

#[derive(Debug, Clone, Copy)]
enum Mode<T> {
    Time,
    Segment(Segment<T>),
}

/// The independent variable of a segment and how the state follows from it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind<T> {
    /// Across `ẋ = 0`: `ẋ = sgn(u)|u|^p`, `u = σs`; segment state `(θ, x)`.
    Velocity { sigma: T, p: i32 },
    /// Across `δ ∈ [0, δ*]`: `δ = w^m`, `w = σs` (`σ = +1` entering, `−1` leaving);
    /// segment state `(θ, ẋ)`.
    Contact {
        onset: ContactOnset<T>,
        sigma: T,
        m: i32,
    },
}

impl<T: Real> Kind<T> {
    /// `(x, ẋ)` at `s` for the segment state `z`.
    #[inline(always)]
    fn state(&self, s: T, z: &SVector<T, 2>) -> Vector2<T> {
        match *self {
            Kind::Velocity { sigma, p } => Vector2::new(z[1], velocity(sigma * s, p)),
            Kind::Contact { onset, sigma, m } => {
                let w = (sigma * s).max(T::zero());
                Vector2::new(onset.position + onset.direction() * w.powi(m), z[1])
            }
        }
    }

    /// `dτ/ds` at `s` with `ẋ = v`, and `ds`-derivative factor of the second component
    /// (`d(z₁)/ds = factor·dτ/ds`): `ẋ` for a velocity segment, `ẍ` for a contact one.
    /// `a` is `ẍ` at the point.
    #[inline(always)]
    fn rates(&self, s: T, v: T, a: T) -> (T, T) {
        match *self {
            Kind::Velocity { sigma, p } => {
                let au = (sigma * s).abs();
                // ẋ'(u) = p|u|^{p−1} = p|ẋ|/|u|: 0 at u = 0 (p ≥ 2).
                let dv = if au > T::zero() {
                    lit::<T>(f64::from(p)) * v.abs() / au
                } else {
                    T::zero()
                };
                (sigma * dv / a, v)
            }
            Kind::Contact { onset, sigma, m } => {
                let w = (sigma * s).max(T::zero());
                let dx = onset.direction() * lit::<T>(f64::from(m)) * w.powi(m - 1) * sigma;
                (dx / v, a)
            }
        }
    }

    /// `ẍ` at `s` from the segment's rates where `dτ/ds ≠ 0`: `ẋ = v`, `dz₁/ds = dz1` and
    /// `dτ/ds = dtau` (the inverse of [`rates`](Self::rates): `ẍ = σ·ẋ'(u)/(dτ/ds)` for a
    /// velocity segment, `(dẋ/ds)/(dτ/ds)` for a contact one).
    #[inline(always)]
    fn acceleration(&self, s: T, v: T, dz1: T, dtau: T) -> T {
        match *self {
            Kind::Velocity { sigma, p } => {
                let au = (sigma * s).abs();
                lit::<T>(f64::from(p)) * v.abs() / au * sigma / dtau
            }
            Kind::Contact { .. } => dz1 / dtau,
        }
    }

    fn is_contact(&self) -> bool {
        matches!(self, Kind::Contact { .. })
    }
}

/// A segment under way.
#[derive(Debug, Clone, Copy)]
struct Segment<T> {
    t0: T,
    /// The segment's time unit (`V*/|a|` or `δ*/|ẋ|` at entry): its state holds
    /// `θ = τ/scale`.
    scale: T,
    s_end: T,
    steps: u32,
    /// The segment stepper's attempts when the segment began.
    attempts0: u64,
    kind: Kind<T>,
}

/// The end of a segment step: `s`, the segment state `z` and `dz/ds` there. Kept for a step
/// across `ẋ = 0` whose part after `ẋ = 0` is still to be reported (the step itself is
/// accepted and its dense output kept).
#[derive(Debug, Clone, Copy)]
struct SegmentEnd<T> {
    s: T,
    z: Vector2<T>,
    dz: Vector2<T>,
}

/// A place in a time step where a segment may begin.
#[derive(Debug, Clone, Copy)]
enum Entry {
    Velocity,
    Contact { leaving: bool },
}

impl<T: Real, St: Stepper<T, 2>, Sg: Stepper<T, 2>> TurningPoints<T, St, Sg>
where
    St::Dense: Clone,
    Sg::Dense: Clone,
{
    /// A time stepper, a segment stepper and the band `|ẋ| < v_band` in which velocity
    /// segments run.
    ///
    /// The band should hold the turning point's cusp and friction layer (3·10⁻³ m/s in
    /// `examples/turning_points.rs`, where the acceleration is 10²–10⁴ m/s²) and be thin enough for the
    /// acceleration not to change sign inside it.
    ///
    /// # Errors
    /// [`ParameterError`] unless `v_band` is finite and > 0.
    pub fn new(time: St, segment: Sg, v_band: T) -> Result<Self, ParameterError> {
        positive("v_band", v_band)?;
        let dense = TurningDense {
            ends: HermiteDense::zeros(),
            time: time.dense().clone(),
            seg: segment.dense().clone(),
            kind: None,
            t_seg: T::zero(),
            scale: T::one(),
            s0: T::zero(),
            s1: T::zero(),
        };
        Ok(Self {
            time,
            seg: segment,
            band: v_band,
            onset_band: None,
            mode: Mode::Time,
            pending: None,
            t: T::zero(),
            y: SVector::zeros(),
            dense,
            stats: Stats::default(),
            own_evals: 0,
            fresh: false,
            cooldown: false,
            cooldown_onset: false,
            counts: SegmentCounts::default(),
        })
    }

    /// Also crosses the first `delta_band` of a contact that the system declares
    /// ([`Dynamics::contact_onset`]) in the penetration's power scale, entering and leaving
    /// (see the [module docs](self#contact-onset-and-exit)).
    ///
    /// # Errors
    /// [`ParameterError`] unless `delta_band` is finite and > 0.
    pub fn with_onset_band(mut self, delta_band: T) -> Result<Self, ParameterError> {
        self.onset_band = Some(positive("delta_band", delta_band)?);
        Ok(self)
    }

    /// The time stepper.
    pub fn time_stepper(&self) -> &St {
        &self.time
    }

    /// The segment stepper.
    pub fn segment_stepper(&self) -> &Sg {
        &self.seg
    }

    /// Velocity segments completed so far.
    pub fn segments(&self) -> u64 {
        self.counts.completed
    }

    /// What the segments did so far (a segment under way counts its attempts so far).
    pub fn segment_counts(&self) -> SegmentCounts {
        let mut c = self.counts;
        if let Mode::Segment(g) = self.mode {
            let n = self.seg_attempts() - g.attempts0;
            if g.kind.is_contact() {
                c.contact_attempts += n;
            } else {
                c.attempts += n;
            }
        }
        c
    }

    fn seg_attempts(&self) -> u64 {
        let s = self.seg.stats();
        s.accepted + s.rejected
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

    fn begin(&mut self, t: T, s0: T, z0: Vector2<T>, scale: T, s_end: T, kind: Kind<T>) {
        self.seg.reset_state(s0, z0);
        self.mode = Mode::Segment(Segment {
            t0: t,
            scale,
            s_end,
            steps: 0,
            attempts0: self.seg_attempts(),
            kind,
        });
    }

    /// Starts a velocity segment at `(t, y)` with `f = f(t, y)` if the velocity is in the
    /// band and heads to zero (or is zero with `a ≠ 0`) and the system is `(x, ẋ)` with a
    /// declared exponent.
    ///
    /// `v_max` bounds `|ẋ|`: the band for a fresh state, a little more at a located edge
    /// (the crossing is located to the rounding of `t`, so `|ẋ|` may exceed the band by a
    /// few ulps there).
    fn enter_velocity(
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
        let Some(p) = velocity_power(q) else {
            return false;
        };
        let r = T::one() / lit::<T>(f64::from(p));
        let sigma = if a > T::zero() { T::one() } else { -T::one() };
        let s0 = if v == T::zero() {
            T::zero()
        } else {
            sigma * v.signum() * v.abs().powf(r)
        };
        let kind = Kind::Velocity { sigma, p };
        let z0 = Vector2::new(T::zero(), y[0]);
        self.begin(t, s0, z0, self.band / a.abs(), self.band.powf(r), kind);
        true
    }

    /// Starts a contact segment at `(t, y)`: entering at `δ ≈ 0` with `ẋ` into the contact,
    /// or leaving at `δ ≈ δ*` with `ẋ` out of it.
    fn enter_contact(
        &mut self,
        onset: ContactOnset<T>,
        t: T,
        y: &SVector<T, 2>,
        f: &SVector<T, 2>,
        leaving: bool,
    ) -> bool {
        let Some(band) = self.onset_band else {
            return false;
        };
        let Some(m) = contact_power(onset.exponent) else {
            return false;
        };
        let v = y[1];
        let inward = v * onset.direction();
        let moving = if leaving {
            inward < T::zero()
        } else {
            inward > T::zero()
        };
        let delta = onset.penetration(y[0]).max(T::zero());
        if !(moving && f[0] == v && f[1].is_finite() && delta <= band * lit(2.0)) {
            return false;
        }
        let r = T::one() / lit::<T>(f64::from(m));
        let w0 = delta.powf(r);
        let (sigma, s0, s_end) = if leaving {
            (-T::one(), -w0, T::zero())
        } else {
            (T::one(), w0, band.powf(r))
        };
        if !(s0 < s_end) {
            return false;
        }
        let kind = Kind::Contact { onset, sigma, m };
        self.begin(
            t,
            s0,
            Vector2::new(T::zero(), v),
            band / v.abs(),
            s_end,
            kind,
        );
        true
    }

    /// Leaves a segment at `(t, y)`: the time stepper goes on from there.
    fn leave(&mut self, g: &Segment<T>, t: T, y: SVector<T, 2>, abandoned: bool) {
        self.mode = Mode::Time;
        self.pending = None;
        self.time.reset_state(t, y);
        let n = self.seg_attempts() - g.attempts0;
        let c = &mut self.counts;
        match (g.kind.is_contact(), abandoned) {
            (false, false) => c.completed += 1,
            (false, true) => c.abandoned += 1,
            (true, false) => c.contact_completed += 1,
            (true, true) => c.contact_abandoned += 1,
        }
        if g.kind.is_contact() {
            c.contact_attempts += n;
            self.cooldown_onset |= abandoned;
        } else {
            c.attempts += n;
            self.cooldown |= abandoned;
        }
    }

    /// Where in the time step just taken a segment may begin: the earliest of `|ẋ|`
    /// entering the band heading to zero, the penetration crossing 0 inward and the
    /// penetration crossing `δ*` outward.
    fn entries<S: Dynamics<T, 2>>(
        &self,
        sys: &S,
        onset: Option<(T, ContactOnset<T>)>,
        t0: T,
        y0: &SVector<T, 2>,
    ) -> [Option<(T, Entry)>; 2] {
        let (t1, y1) = (self.dense.ends.span().1, *self.dense.ends.endpoints().1);
        let d = &self.dense.time;
        let mut out = [None, None];
        let (v0, v1) = (y0[1], y1[1]);
        if sys.velocity_exponent().is_some() && !self.cooldown && v0.abs() >= self.band {
            let edge = if v0 > T::zero() {
                self.band
            } else {
                -self.band
            };
            if (v1 - edge) * (v0 - edge) < T::zero() || v1 == edge {
                let tc = if v1 == edge {
                    t1
                } else {
                    crossing(d, t0, v0 - edge, t1, v1 - edge, |y| y[1] - edge)
                };
                out[0] = Some((tc, Entry::Velocity));
            }
        }
        if let (Some((band, onset)), false) = (onset, self.cooldown_onset) {
            let (d0, d1) = (onset.penetration(y0[0]), onset.penetration(y1[0]));
            if d0 < T::zero() && d1 >= T::zero() {
                let tc = if d1 == T::zero() {
                    t1
                } else {
                    crossing(d, t0, d0, t1, d1, |y| onset.penetration(y[0]))
                };
                out[1] = Some((tc, Entry::Contact { leaving: false }));
            } else if d0 > band && d1 <= band {
                let tc = if d1 == band {
                    t1
                } else {
                    crossing(d, t0, d0 - band, t1, d1 - band, |y| {
                        onset.penetration(y[0]) - band
                    })
                };
                out[1] = Some((tc, Entry::Contact { leaving: true }));
            }
        }
        out
    }

    /// One time step; cut where a segment begins (see [`entries`](Self::entries)).
    fn time_step<S: Dynamics<T, 2>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError> {
        let (t0, y0) = (self.t, self.y);
        self.time.step(sys, t_limit)?;
        let d = self.time.dense();
        let (t1, y1) = (self.time.current().0, *self.time.current().1);
        let (f0, f1) = d.end_derivatives();
        let (f0, f1) = (*f0, *f1);
        self.dense.time = d.clone();
        self.dense.kind = None;
        self.dense.ends = HermiteDense::new(t0, t1, y0, y1, f0, f1);
        self.t = t1;
        self.y = y1;
        if y1[1].abs() >= self.band {
            self.cooldown = false;
        }
        // The contact band and the declared onset, read once per step.
        let onset = self
            .onset_band
            .and_then(|band| sys.contact_onset().map(|o| (band, o)));
        if let Some((band, onset)) = onset {
            let d1 = onset.penetration(y1[0]);
            if d1 < T::zero() || d1 > band {
                self.cooldown_onset = false;
            }
        }
        let mut found = self.entries(sys, onset, t0, &y0);
        // Earliest first.
        if let [Some(a), Some(b)] = found
            && b.0 < a.0
        {
            found = [Some(b), Some(a)];
        }
        for (tc, entry) in found.into_iter().flatten() {
            if !(tc > t0) {
                continue;
            }
            let yc = if tc == t1 {
                y1
            } else {
                let mut yc = SVector::zeros();
                self.dense.time.interpolate_unchecked(tc, &mut yc);
                yc
            };
            let fc = if tc == t1 {
                f1
            } else {
                self.eval(sys, tc, &yc)
            };
            let entered = match entry {
                Entry::Velocity => {
                    self.enter_velocity(sys.velocity_exponent(), tc, &yc, &fc, self.band * lit(2.0))
                }
                Entry::Contact { leaving } => match onset {
                    Some((_, onset)) => self.enter_contact(onset, tc, &yc, &fc, leaving),
                    None => false,
                },
            };
            if entered {
                // The time step ends where the segment begins.
                self.dense.ends = HermiteDense::new(t0, tc, y0, yc, f0, fc);
                self.t = tc;
                self.y = yc;
                break;
            }
        }
        Ok(())
    }

    /// `f(t, y)` at the current point: the reported step's end derivative if that step ended
    /// here, else an evaluation.
    fn current_derivative<S: Dynamics<T, 2>>(&mut self, sys: &S) -> SVector<T, 2> {
        let (t, y) = (self.t, self.y);
        let ends = &self.dense.ends;
        if ends.span().1 == t && *ends.endpoints().1 == y {
            *ends.end_derivatives().1
        } else {
            self.eval(sys, t, &y)
        }
    }

    /// Steps segment `g` in `s` until its time passes `t_a` (a step below the resolution of
    /// `t` is followed by the next): the step's start `s_a` and its end, the segment
    /// stepper's dense output kept. `None` if the segment was left at `(t_a, y_a)` instead:
    /// abandoned (a failed step, too many steps, `τ(s)` not monotone, a non-finite state),
    /// or finished below the resolution of `t`.
    fn next_segment_step<S: Dynamics<T, 2>>(
        &mut self,
        sys: &S,
        g: &mut Segment<T>,
        t_a: T,
        y_a: SVector<T, 2>,
    ) -> Option<(T, SegmentEnd<T>)> {
        loop {
            let (s_a, z_a) = (self.seg.current().0, *self.seg.current().1);
            let r = Reparam {
                sys,
                t0: g.t0,
                scale: g.scale,
                kind: g.kind,
            };
            g.steps += 1;
            if g.steps > MAX_SEGMENT_STEPS || self.seg.step(&r, g.s_end).is_err() {
                self.leave(g, t_a, y_a, true);
                return None;
            }
            let (s_b, z_b) = (self.seg.current().0, *self.seg.current().1);
            let dz_b = *self.seg.dense().end_derivatives().1;
            let y_end = g.kind.state(s_b, &z_b);
            // dτ/ds > 0 except where the scale's derivative vanishes (u = 0, w = 0);
            // a sign change means that a (or ẋ) changed sign. θ may stand still in
            // floating point next to u = 0 (it grows like |u|^p there).
            let monotone = z_b[0] >= z_a[0] && dz_b[0] >= T::zero();
            if !(monotone && y_end[0].is_finite() && y_end[1].is_finite()) {
                self.leave(g, t_a, y_a, true);
                return None;
            }
            if !(g.t0 + g.scale * z_b[0] > t_a) {
                // Below the resolution of t: step on in s.
                if s_b >= g.s_end {
                    self.leave(g, t_a, y_a, false);
                    return None;
                }
                continue;
            }
            self.dense.seg = self.seg.dense().clone();
            return Some((
                s_a,
                SegmentEnd {
                    s: s_b,
                    z: z_b,
                    dz: dz_b,
                },
            ));
        }
    }

    /// The end of the part to report of a velocity step of segment `g` from `s_a < 0` (time
    /// `t_a`) to `end` (`s > 0`): `ẋ = 0` (`s = 0`), keeping `end` to report next, unless
    /// `ẋ = 0` falls on the step's ends in `t`; else `end`.
    ///
    /// A velocity step across `ẋ = 0` is reported in two parts, so that no reported step
    /// has `ẋ` changing sign inside it: observers that look for an interior extremum of `x`
    /// (inverting `τ(s)` at every trial point) find it at the end of the first part.
    fn split_at_turn(&mut self, g: &Segment<T>, t_a: T, end: SegmentEnd<T>) -> SegmentEnd<T> {
        let mut z0 = SVector::zeros();
        self.dense.seg.interpolate_unchecked(T::zero(), &mut z0);
        let t0 = g.t0 + g.scale * z0[0];
        if !(t0 > t_a && t0 < g.t0 + g.scale * end.z[0]) {
            return end;
        }
        self.pending = Some(end);
        SegmentEnd {
            s: T::zero(),
            z: z0,
            // dτ/ds = 0 at u = 0: ẍ comes from an evaluation below.
            dz: SVector::zeros(),
        }
    }

    /// Cuts the step of segment `g` being reported at `τ = t_limit − t₀`: the state there.
    /// The segment goes on from there (its stepper restarts at the cut, nothing is pending).
    fn cut_at(&mut self, g: &Segment<T>, t_limit: T) -> Vector2<T> {
        let target = (t_limit - g.t0) / g.scale;
        let s_c = self.dense.invert(target);
        let mut z_c = SVector::zeros();
        self.dense.seg.interpolate_unchecked(s_c, &mut z_c);
        z_c[0] = target;
        let y_c = g.kind.state(s_c, &z_c);
        self.dense.s1 = s_c;
        self.seg.reset_state(s_c, z_c);
        self.pending = None;
        y_c
    }

    /// One accepted step of the segment, or the part of it after `ẋ = 0` (see
    /// [`split_at_turn`](Self::split_at_turn)). Returns `false` if the segment was left
    /// before a step was reported (abandoned, or finished below the resolution of `t`).
    fn segment_step<S: Dynamics<T, 2>>(
        &mut self,
        sys: &S,
        t_limit: T,
        mut g: Segment<T>,
    ) -> Result<bool, IntegrateError> {
        let (t_a, y_a) = (self.t, self.y);
        let f_a = self.current_derivative(sys);
        let (s_a, mut end) = match self.pending.take() {
            // The rest of the step already taken, from ẋ = 0 on.
            Some(p) => (T::zero(), p),
            None => match self.next_segment_step(sys, &mut g, t_a, y_a) {
                Some(step) => step,
                None => return Ok(false),
            },
        };
        self.dense.kind = Some(g.kind);
        self.dense.t_seg = g.t0;
        self.dense.scale = g.scale;
        self.dense.s0 = s_a;
        if let Kind::Velocity { .. } = g.kind
            && s_a < T::zero()
            && end.s > T::zero()
        {
            end = self.split_at_turn(&g, t_a, end);
        }
        let SegmentEnd {
            s: s_b,
            z: z_b,
            dz: dz_b,
        } = end;
        let dtau_b = dz_b[0] * g.scale;
        let mut t_b = g.t0 + g.scale * z_b[0];
        let mut y_b = g.kind.state(s_b, &z_b);
        self.dense.s1 = s_b;
        let cut = t_b > t_limit;
        if cut {
            y_b = self.cut_at(&g, t_limit);
            t_b = t_limit;
        }
        // ẍ from the step's last stage where dτ/ds ≠ 0.
        let f_b = if !cut && dtau_b != T::zero() {
            Vector2::new(y_b[1], g.kind.acceleration(s_b, y_b[1], dz_b[1], dtau_b))
        } else {
            self.eval(sys, t_b, &y_b)
        };
        self.dense.ends = HermiteDense::new(t_a, t_b, y_a, y_b, f_a, f_b);
        self.t = t_b;
        self.y = y_b;
        if !cut && self.pending.is_none() && s_b >= g.s_end {
            self.leave(&g, t_b, y_b, false);
        } else {
            self.mode = Mode::Segment(g);
        }
        Ok(true)
    }
}

impl<T: Real> TurningPoints<T, super::Dopri5<T, 2>, super::Dopri5<T, 2>> {
    /// DOPRI5 in time with the tolerances `tol` and DOPRI5 in the segments with the
    /// recommended tolerances (see [Accuracy](self#accuracy)): `rtol` of `tol`'s first
    /// component for both, absolute `100·rtol` on `θ` and `tol`'s on the second component
    /// (`x` in velocity segments, `ẋ` in contact segments: the larger of the two).
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
        self.pending = None;
        self.time.reset_state(t, y);
        self.fresh = true;
        self.cooldown = false;
        self.cooldown_onset = false;
    }

    fn start(&mut self, t: T, y: SVector<T, 2>) {
        self.reset_state(t, y);
        self.time.start(t, y);
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
                // The current point as a step of zero length: its f is reused.
                self.dense.ends = HermiteDense::new(t, t, y, y, f, f);
                self.enter_velocity(q, t, &y, &f, self.band);
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

/// The system in `s`: state `(θ, x)` (velocity segment) or `(θ, ẋ)` (contact segment),
/// `τ = scale·θ`.
struct Reparam<'a, T, S> {
    sys: &'a S,
    t0: T,
    scale: T,
    kind: Kind<T>,
}

impl<T: Real, S: Dynamics<T, 2>> Dynamics<T, 2> for Reparam<'_, T, S> {
    #[inline(always)]
    fn rhs(&self, s: T, z: &SVector<T, 2>, dz: &mut SVector<T, 2>) {
        let y = self.kind.state(s, z);
        let mut f = SVector::zeros();
        self.sys.rhs(self.t0 + self.scale * z[0], &y, &mut f);
        let (dtau, factor) = self.kind.rates(s, y[1], f[1]);
        dz[0] = dtau / self.scale;
        dz[1] = factor * dtau;
    }
}

/// Dense output of a [`TurningPoints`] step: the time stepper's, or a segment step's with
/// `τ(s)` inverted.
#[derive(Debug, Clone)]
pub struct TurningDense<T: Real, TD, SD> {
    /// The reported step's ends: span, states and derivatives.
    ends: HermiteDense<T, 2>,
    time: TD,
    seg: SD,
    /// The segment's kind (`None`: a time step).
    kind: Option<Kind<T>>,
    t_seg: T,
    scale: T,
    s0: T,
    s1: T,
}

impl<T: Real, TD: DenseOutput<T, 2>, SD: DenseOutput<T, 2>> TurningDense<T, TD, SD> {
    /// The `s ∈ [s0, s1]` where the segment's `θ(s) = target` (Brent's method on the
    /// segment step's dense output; `θ` is monotone on the step).
    fn invert(&self, target: T) -> T {
        let mut z = SVector::zeros();
        let mut theta = |s: T| {
            self.seg.interpolate_unchecked(s, &mut z);
            z[0] - target
        };
        let (a, b) = (self.s0, self.s1);
        let (fa, fb) = (theta(a), theta(b));
        if !(fa < T::zero()) {
            return a;
        }
        if !(fb > T::zero()) {
            return b;
        }
        brent(theta, a, b, fa, fb, T::zero(), 200).unwrap_or(a + (b - a) * lit(0.5))
    }
}

impl<T: Real, TD: DenseOutput<T, 2>, SD: DenseOutput<T, 2>> DenseOutput<T, 2>
    for TurningDense<T, TD, SD>
{
    fn span(&self) -> (T, T) {
        self.ends.span()
    }

    fn endpoints(&self) -> (&SVector<T, 2>, &SVector<T, 2>) {
        self.ends.endpoints()
    }

    fn end_derivatives(&self) -> (&SVector<T, 2>, &SVector<T, 2>) {
        self.ends.end_derivatives()
    }

    #[inline]
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, 2>) {
        let Some(kind) = self.kind else {
            self.time.interpolate_unchecked(t, out);
            return;
        };
        let (t0, t1) = self.ends.span();
        if t <= t0 {
            *out = *self.ends.endpoints().0;
            return;
        }
        if t >= t1 {
            *out = *self.ends.endpoints().1;
            return;
        }
        let s = self.invert((t - self.t_seg) / self.scale);
        let mut z = SVector::zeros();
        self.seg.interpolate_unchecked(s, &mut z);
        *out = kind.state(s, &z);
    }
}

/// The integer power `p = ⌈1/q⌉` of the scale `ẋ = sgn(u)|u|^p` for a declared exponent
/// `q ∈ (0, 1)`; `None` beyond `p = 64` (a cusp too strong for the scale to be worth it).
pub(crate) fn velocity_power<T: Real>(q: T) -> Option<i32> {
    // The margin keeps 1/q = 3 + 1 ulp (q = 1/3 rounded) at p = 3.
    let inv = (crate::scalar::to_f64(T::one() / q) - 1e-9).ceil();
    (2.0..=64.0).contains(&inv).then_some(inv as i32)
}

/// The integer power `m` of the scale `δ = w^m` for a contact force `∝ δ^n`: the smallest
/// `m ≤ 8` with `m·n` an integer (`m = 2` for the Hertz `n = 3/2`: `δ^{3/2} = w³`), else
/// `⌈6/n⌉` (six continuous derivatives in `w`, enough for a fifth-order method).
fn contact_power<T: Real>(n: T) -> Option<i32> {
    let n = crate::scalar::to_f64(n);
    if !(n > 0.0 && n.is_finite()) {
        return None;
    }
    (1..=8)
        .find(|&m| {
            let mn = f64::from(m) * n;
            (mn - mn.round()).abs() < 1e-12
        })
        .or_else(|| {
            let m = (6.0 / n).ceil();
            (1.0..=64.0).contains(&m).then_some(m as i32)
        })
}

/// `ẋ = sgn(u)|u|^p`.
#[inline(always)]
fn velocity<T: Real>(u: T, p: i32) -> T {
    u.signum() * u.abs().powi(p)
}

/// The time in `[t0, t1]` where `g(y(t))` changes sign (`g0`, `g1` at the ends), by
/// Brent's method on the time step's dense output.
fn crossing<T: Real, D: DenseOutput<T, 2>>(
    dense: &D,
    t0: T,
    g0: T,
    t1: T,
    g1: T,
    g: impl Fn(&SVector<T, 2>) -> T,
) -> T {
    let mut y = SVector::zeros();
    let h = |t: T| {
        dense.interpolate_unchecked(t, &mut y);
        g(&y)
    };
    brent(h, t0, t1, g0, g1, T::zero(), 200).unwrap_or(t0 + (t1 - t0) * lit(0.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn powers_of_the_scales() {
        assert_eq!(velocity_power(0.18667), Some(6));
        assert_eq!(velocity_power(0.5), Some(2));
        assert_eq!(velocity_power(1.0 / 3.0), Some(3));
        assert_eq!(velocity_power(0.01), None);
        assert_eq!(velocity_power(f64::NAN), None);
        assert_eq!(contact_power(1.5), Some(2));
        assert_eq!(contact_power(1.0), Some(1));
        assert_eq!(contact_power(1.25), Some(4));
        assert_eq!(contact_power(0.3), Some(20));
        assert_eq!(contact_power(0.0), None);
        assert_eq!(contact_power(f64::INFINITY), None);
    }
}
