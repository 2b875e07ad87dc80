//! The lane DOPRI5 engine: `L` trajectories stepped together, each with its own step.

use nalgebra::SVector;

use super::kernel::{ALL, LaneState, StepConsts, StepOut, row};
use super::math::LaneMath;
use super::model::{Member, Packed, scalar_rhs};
use super::{Lanes, Simd};
use crate::drive::{Control, EventRecord, Observer, Outcome, StepView, Termination, landing_limit};
use crate::error::Result;
use crate::event::{Direction, Event, EventError, EventFunction, EventHistory, ZenoGuard, locate};
use crate::integrate::{DenseOutput, IntegrateError, Stats, StepOptions, Tolerances};
use crate::validate::ParameterError;

/// One trajectory of an ensemble: a [`Member`], its start and end, and an optional landing
/// grid `origin + i·dt` that every step lands on (the sweeps' sections at `t = i·2π/ω`).
///
/// The constructors validate; values set through the public fields are validated when a
/// run starts ([`check`](Self::check)), and an invalid trajectory is an error in its own
/// result slot of [`Ensemble::run`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemberRun {
    /// The model.
    pub member: Member,
    /// Start time.
    pub t0: f64,
    /// Initial state `(x, ẋ)`.
    pub y0: SVector<f64, 2>,
    /// End time.
    pub t_end: f64,
    /// Landing grid `(origin, dt)`.
    pub grid: Option<(f64, f64)>,
}

impl MemberRun {
    /// From `(t0, y0)` to `t_end`, without a landing grid.
    ///
    /// # Errors
    /// [`IntegrateError::InvalidTimeSpan`] unless `t0 < t_end`, both finite;
    /// [`IntegrateError::NonFiniteState`] for a non-finite `y0`.
    pub fn new(member: Member, t0: f64, y0: SVector<f64, 2>, t_end: f64) -> Result<Self> {
        if !(t0.is_finite() && t_end.is_finite() && t_end > t0) {
            return Err(IntegrateError::InvalidTimeSpan { t0, t_end }.into());
        }
        crate::integrate::check_state(&y0)?;
        Ok(Self {
            member,
            t0,
            y0,
            t_end,
            grid: None,
        })
    }

    /// `periods` forcing periods from `(0, y0)`, every step landing on `t = i·2π/ω` (the
    /// sweeps' setting).
    ///
    /// # Errors
    /// As [`new`](Self::new); [`ParameterError`] unless `periods` is finite and > 0.
    pub fn periods(member: Member, y0: SVector<f64, 2>, periods: f64) -> Result<Self> {
        crate::validate::positive("periods", periods)?;
        let tau = member.period();
        Self::new(member, 0.0, y0, periods * tau)?.with_grid(0.0, tau)
    }

    /// Checks what the constructors check, for a trajectory whose public fields were set
    /// directly: the time span, the initial state and the landing grid.
    ///
    /// # Errors
    /// [`IntegrateError::InvalidTimeSpan`] unless `t0 < t_end`, both finite;
    /// [`IntegrateError::NonFiniteState`] for a non-finite `y0`; [`ParameterError`] naming
    /// `grid origin` unless it is finite, `grid dt` unless it is finite and > 0.
    pub fn check(&self) -> Result<()> {
        let (t0, t_end) = (self.t0, self.t_end);
        if !(t0.is_finite() && t_end.is_finite() && t_end > t0) {
            return Err(IntegrateError::InvalidTimeSpan { t0, t_end }.into());
        }
        crate::integrate::check_state(&self.y0)?;
        if let Some((origin, dt)) = self.grid {
            crate::validate::finite("grid origin", origin)?;
            crate::validate::positive("grid dt", dt)?;
        }
        Ok(())
    }

    /// Makes every step land on `origin + i·dt` (computed from `i`, never accumulated).
    ///
    /// # Errors
    /// [`ParameterError`] unless `origin` is finite and `dt` finite and > 0.
    pub fn with_grid(mut self, origin: f64, dt: f64) -> Result<Self> {
        crate::validate::finite("origin", origin)?;
        crate::validate::positive("dt", dt)?;
        self.grid = Some((origin, dt));
        Ok(self)
    }
}

/// The ensemble integrator: DOPRI5 with the scalar [`Dopri5`](crate::integrate::Dopri5)'s
/// tableau, error norm, PI controller and first-step heuristic, one trajectory per lane,
/// with the driver's event location and observers per lane (see the
/// [module docs](super)).
#[derive(Debug, Clone)]
pub struct Ensemble<G = crate::event::Level<f64>> {
    tol: Tolerances<f64, 2>,
    opts: StepOptions<f64>,
    math: LaneMath,
    simd: Simd,
    max_steps: usize,
    event_tol: f64,
    zeno: ZenoGuard<f64>,
    event: Option<Event<G>>,
}

impl Ensemble {
    /// An ensemble with the given tolerances, default [`StepOptions`], no event,
    /// [`LaneMath::Exact`], the driver's defaults (step cap 10⁸ per trajectory, event time
    /// tolerance 10⁻¹², the default [`ZenoGuard`]).
    ///
    /// # Errors
    /// [`ParameterError`] for invalid tolerances (set through the public fields).
    pub fn new(tol: Tolerances<f64, 2>) -> Result<Self> {
        tol.validate()?;
        Ok(Self {
            tol,
            opts: StepOptions::default(),
            math: LaneMath::Exact,
            simd: Simd::Auto,
            max_steps: 100_000_000,
            event_tol: 1e-12,
            zeno: ZenoGuard::default(),
            event: None,
        })
    }
}

impl<G: EventFunction<f64, 2>> Ensemble<G> {
    /// Adds a detection event, located per lane on the step's dense output exactly as
    /// [`Simulation`](crate::drive::Simulation) does (sign changes, grazing pairs from the
    /// event's rate, the same bracketing solver and tolerance).
    ///
    /// # Errors
    /// [`ParameterError`] for what the lanes do not support: resets, terminal events,
    /// restarts, interior samples and step bounds (use the scalar driver for those).
    pub fn with_event<G2: EventFunction<f64, 2>>(self, event: Event<G2>) -> Result<Ensemble<G2>> {
        let unsupported = |requirement: &'static str| -> Result<Ensemble<G2>> {
            Err(ParameterError::new("event", 0.0, requirement).into())
        };
        if event.terminal {
            return unsupported("not terminal (terminal events are not supported in lanes)");
        }
        if event.restart {
            return unsupported("without restart (not supported in lanes)");
        }
        if event.interior_samples > 0 {
            return unsupported("without interior samples (not supported in lanes)");
        }
        if event.max_step.is_some() {
            return unsupported("without a step bound (not supported in lanes)");
        }
        event.function.check()?;
        Ok(Ensemble {
            tol: self.tol,
            opts: self.opts,
            math: self.math,
            simd: self.simd,
            max_steps: self.max_steps,
            event_tol: self.event_tol,
            zeno: self.zeno,
            event: Some(event),
        })
    }

    /// Sets how `exp` and `ln` are evaluated.
    pub fn with_math(mut self, math: LaneMath) -> Self {
        self.math = math;
        self
    }

    /// Sets the instruction set of the lane loop (default [`Simd::Auto`]; the results do
    /// not depend on it, bit for bit).
    pub fn with_simd(mut self, simd: Simd) -> Self {
        self.simd = simd;
        self
    }

    /// The requested instruction set ([`Simd::resolve`] gives the one that runs).
    pub fn simd(&self) -> Simd {
        self.simd
    }

    /// Sets the step options.
    ///
    /// # Errors
    /// [`ParameterError`] for invalid options, or the predictive correction (not in lanes).
    pub fn with_options(mut self, opts: StepOptions<f64>) -> Result<Self> {
        opts.validate()?;
        if opts.predictive {
            return Err(ParameterError::new("predictive", 1.0, "false in lanes").into());
        }
        self.opts = opts;
        Ok(self)
    }

    /// Caps the accepted steps per trajectory.
    ///
    /// # Errors
    /// [`ParameterError`] if `max_steps == 0`.
    pub fn max_steps(mut self, max_steps: usize) -> Result<Self> {
        if max_steps == 0 {
            return Err(ParameterError::new("max_steps", 0.0, "> 0").into());
        }
        self.max_steps = max_steps;
        Ok(self)
    }

    /// The tolerances.
    pub fn tolerances(&self) -> &Tolerances<f64, 2> {
        &self.tol
    }

    /// The math mode.
    pub fn math(&self) -> LaneMath {
        self.math
    }

    /// Integrates every trajectory in lanes of `V`, streaming trajectory `j` to
    /// `observers[j]`, on the calling thread. A lane whose trajectory ends (or fails) takes
    /// the next one in order; the result of each trajectory does not depend on `V`, on the
    /// order of the slice or on what runs in the other lanes.
    ///
    /// Every trajectory is checked ([`MemberRun::check`]) before the lanes start: an
    /// invalid one (fields set directly to a reversed time span, a non-finite state, a
    /// landing grid with `dt ≤ 0`) never enters a lane; its result is the error, and the
    /// others run as they would without it.
    ///
    /// # Errors
    /// The outer error: [`ParameterError`] if `observers` and `trajectories` differ in
    /// length. Each trajectory's own result is an element of the vector: its
    /// [`Outcome`], or the error that stopped it (the scalar driver's errors, or that of
    /// [`MemberRun::check`]).
    pub fn run<V: Lanes, O: Observer<f64, 2>>(
        &self,
        trajectories: &[MemberRun],
        observers: &mut [O],
    ) -> Result<Vec<Result<Outcome<f64, 2>>>> {
        if observers.len() != trajectories.len() {
            return Err(ParameterError::new(
                "observers",
                observers.len() as f64,
                "one per trajectory",
            )
            .into());
        }
        let mut out: Vec<Option<Result<Outcome<f64, 2>>>> = Vec::with_capacity(trajectories.len());
        out.resize_with(trajectories.len(), || None);
        // The valid trajectories, in order: the lanes' queue.
        let mut queue = Vec::with_capacity(trajectories.len());
        for (j, job) in trajectories.iter().enumerate() {
            match job.check() {
                Ok(()) => queue.push(j),
                Err(e) => out[j] = Some(Err(e)),
            }
        }
        if let Some(&first) = queue.first() {
            Engine::<V, G>::new(self, trajectories, &queue, &trajectories[first])
                .run(observers, &mut out);
        }
        Ok(out
            .into_iter()
            .map(|r| r.unwrap_or_else(|| Err(IntegrateError::NotInitialized.into())))
            .collect())
    }

    /// [`run`](Self::run) over the threads of the current rayon pool, `chunk` trajectories
    /// per task (each task fills its own lanes): the results are the same, bit for bit, as
    /// on one thread.
    ///
    /// # Errors
    /// As [`run`](Self::run); [`ParameterError`] if `chunk == 0`.
    #[cfg(feature = "parallel")]
    pub fn run_parallel<V: Lanes, O: Observer<f64, 2> + Send>(
        &self,
        trajectories: &[MemberRun],
        observers: &mut [O],
        chunk: usize,
    ) -> Result<Vec<Result<Outcome<f64, 2>>>>
    where
        G: Sync,
    {
        use rayon::prelude::*;
        if chunk == 0 {
            return Err(ParameterError::new("chunk", 0.0, "> 0").into());
        }
        if observers.len() != trajectories.len() {
            return Err(ParameterError::new(
                "observers",
                observers.len() as f64,
                "one per trajectory",
            )
            .into());
        }
        let parts: Vec<Vec<Result<Outcome<f64, 2>>>> = trajectories
            .par_chunks(chunk)
            .zip(observers.par_chunks_mut(chunk))
            .map(|(t, o)| self.run::<V, O>(t, o))
            .collect::<Result<_>>()?;
        Ok(parts.into_iter().flatten().collect())
    }
}

/// The dense output of one lane's accepted step (Hairer's continuous extension of
/// DOPRI5, the same formula as [`Dopri5Dense`](crate::integrate::Dopri5Dense)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneDense {
    t0: f64,
    t1: f64,
    h: f64,
    y0: SVector<f64, 2>,
    y1: SVector<f64, 2>,
    f0: SVector<f64, 2>,
    f1: SVector<f64, 2>,
    r2: SVector<f64, 2>,
    r3: SVector<f64, 2>,
    r4: SVector<f64, 2>,
    r5: SVector<f64, 2>,
}

impl DenseOutput<f64, 2> for LaneDense {
    fn span(&self) -> (f64, f64) {
        (self.t0, self.t1)
    }
    fn endpoints(&self) -> (&SVector<f64, 2>, &SVector<f64, 2>) {
        (&self.y0, &self.y1)
    }
    fn end_derivatives(&self) -> (&SVector<f64, 2>, &SVector<f64, 2>) {
        (&self.f0, &self.f1)
    }
    #[inline(always)]
    fn interpolate_unchecked(&self, t: f64, out: &mut SVector<f64, 2>) {
        let th = (t - self.t0) / self.h;
        let th1 = 1.0 - th;
        for i in 0..2 {
            out[i] = self.y0[i]
                + th * (self.r2[i] + th1 * (self.r3[i] + th * (self.r4[i] + th1 * self.r5[i])));
        }
    }
}

/// Per-lane bookkeeping (scalar).
struct Slot {
    job: Option<usize>,
    member: Option<Member>,
    t_end: f64,
    grid: Option<(f64, f64)>,
    steps: usize,
    nonfinite: u32,
    side: i8,
    history: EventHistory<f64>,
    stats: Stats,
}

impl Slot {
    fn idle() -> Self {
        Self {
            job: None,
            member: None,
            t_end: 0.0,
            grid: None,
            steps: 0,
            nonfinite: 0,
            side: 0,
            history: EventHistory::new(),
            stats: Stats::default(),
        }
    }
}

/// The lanes and their scalar bookkeeping.
struct Engine<'a, V: Lanes, G> {
    cfg: &'a Ensemble<G>,
    jobs: &'a [MemberRun],
    /// The indices of the valid trajectories, in order ([`MemberRun::check`]).
    queue: &'a [usize],
    /// The next position in `queue`.
    next: usize,
    slots: Vec<Slot>,
    /// On the heap, like the step's output: on the stack, the speed of the vector step
    /// depended on where the stack began (the program's path and environment) by up to
    /// 30 % (measured with AVX2, 16 lanes: 0.38–0.50 s for the same binary); boxed, it
    /// stays at the fast end.
    st: Box<LaneState<V>>,
    consts: StepConsts,
}

#[inline(always)]
fn sign_of(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// The lanes whose bit is set in `mask`, in increasing order.
#[inline(always)]
fn lanes_of(mut mask: u32) -> impl Iterator<Item = usize> {
    core::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

impl<'a, V: Lanes, G: EventFunction<f64, 2>> Engine<'a, V, G> {
    fn new(
        cfg: &'a Ensemble<G>,
        jobs: &'a [MemberRun],
        queue: &'a [usize],
        first: &MemberRun,
    ) -> Self {
        let z = V::splat(0.0);
        let packed = Packed::splat(&first.member);
        // Idle lanes step from a benign state (the first valid job's start, h = 1e-6):
        // their results are never used and their state never changes.
        let (t, x, v) = (first.t0, first.y0[0], first.y0[1]);
        Self {
            cfg,
            jobs,
            queue,
            next: 0,
            slots: (0..V::LANES).map(|_| Slot::idle()).collect(),
            st: Box::new(LaneState {
                packed,
                t: V::splat(t),
                x: V::splat(x),
                v: V::splat(v),
                fx: z,
                fv: z,
                h: V::splat(1e-6),
                limit: V::splat(t + 1.0),
                ln_err_old: V::splat(1e-4f64.ln()),
                rej_last: z,
                active: z,
            }),
            consts: StepConsts::new(&cfg.tol, &cfg.opts, cfg.math, cfg.simd),
        }
    }

    /// Starts the next trajectory of the queue in lane `i` (skipping those that fail at
    /// once); leaves the lane idle when the queue is empty.
    fn fill<O: Observer<f64, 2>>(
        &mut self,
        i: usize,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, 2>>>],
    ) {
        self.st.active = self.st.active.with_lane(i, 0.0);
        self.slots[i].job = None;
        while let Some(&j) = self.queue.get(self.next) {
            self.next += 1;
            match self.start(i, j, &mut observers[j]) {
                Ok(()) => {
                    self.st.active = self.st.active.with_lane(i, ALL);
                    return;
                }
                Err(e) => out[j] = Some(Err(e)),
            }
        }
    }

    fn start<O: Observer<f64, 2>>(&mut self, i: usize, j: usize, obs: &mut O) -> Result<()> {
        let job = &self.jobs[j];
        let cfg = self.cfg;
        // The time span, state and grid were checked before the run (`MemberRun::check`).
        let (t0, y0, t_end) = (job.t0, job.y0, job.t_end);
        cfg.opts
            .validate()
            .map_err(IntegrateError::InvalidSettings)?;
        obs.check()?;
        obs.check_span(t0, t_end)?;
        // The work bound (the driver's check_work).
        let mut hb = (cfg.opts.h_max.is_finite() && cfg.opts.h_max > 0.0).then_some(cfg.opts.h_max);
        if let Some((_, dt)) = job.grid {
            hb = Some(hb.map_or(dt, |h| h.min(dt)));
        }
        if let Some(hb) = hb {
            let needed = (t_end - t0) / hb;
            if !(needed <= cfg.max_steps as f64 + 1.0) {
                return Err(IntegrateError::WorkExceedsCap {
                    needed,
                    span: t_end - t0,
                    h: hb,
                    max_steps: cfg.max_steps,
                }
                .into());
            }
        }
        let m = job.member;
        let mut stats = Stats::default();
        obs.on_start(t0, &y0);
        // The event's side at the start (the driver's rule).
        let mut side = 0i8;
        if let Some(ev) = &cfg.event {
            let g = ev.function.value(t0, &y0);
            if !g.is_finite() {
                return Err(non_finite(t0, g));
            }
            side = sign_of(g);
            if side == 0 {
                let f = scalar_rhs(&m, t0, &y0);
                if let Some(r) = ev.function.rate(t0, &y0, &f) {
                    side = sign_of(r);
                }
            }
        }
        // The stepper's first derivative and first step.
        let f0 = scalar_rhs(&m, t0, &y0);
        stats.rhs_evals += 1;
        if !(f0[0].is_finite() && f0[1].is_finite()) {
            return Err(IntegrateError::NonFiniteRhs { t: t0 }.into());
        }
        let limit = landing_limit(t0, t_end, job.grid);
        let h = match cfg.opts.h_init {
            Some(h) => h,
            None => crate::integrate::initial_step(
                m.scalar(),
                t0,
                &y0,
                &f0,
                5,
                &cfg.tol,
                cfg.opts.h_max,
                limit - t0,
                &mut stats.rhs_evals,
            ),
        };
        self.st.packed.set(i, &m);
        self.st.t = self.st.t.with_lane(i, t0);
        self.st.x = self.st.x.with_lane(i, y0[0]);
        self.st.v = self.st.v.with_lane(i, y0[1]);
        self.st.fx = self.st.fx.with_lane(i, f0[0]);
        self.st.fv = self.st.fv.with_lane(i, f0[1]);
        self.st.h = self.st.h.with_lane(i, h);
        self.st.limit = self.st.limit.with_lane(i, limit);
        self.st.ln_err_old = self.st.ln_err_old.with_lane(i, 1e-4f64.ln());
        self.st.rej_last = self.st.rej_last.with_lane(i, 0.0);
        let s = &mut self.slots[i];
        *s = Slot::idle();
        s.job = Some(j);
        s.member = Some(m);
        s.t_end = t_end;
        s.grid = job.grid;
        s.side = side;
        s.stats = stats;
        Ok(())
    }

    fn finish<O: Observer<f64, 2>>(
        &mut self,
        i: usize,
        result: Result<(f64, SVector<f64, 2>, Termination)>,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, 2>>>],
    ) {
        if let Some(j) = self.slots[i].job {
            out[j] = Some(result.map(|(t, y, termination)| {
                let o = Outcome {
                    t,
                    y,
                    termination,
                    stats: self.slots[i].stats,
                };
                observers[j].on_finish(&o);
                o
            }));
        }
        self.fill(i, observers, out);
    }

    /// The lane loop: a vector step in every lane ([`kernel`](super::kernel), compiled in
    /// this crate for the instruction set chosen at run time), then the scalar work of each
    /// lane: a failed start or step ends its trajectory, an accepted step goes to the
    /// lane's event search and observer.
    fn run<O: Observer<f64, 2>>(
        &mut self,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, 2>>>],
    ) {
        for i in 0..V::LANES {
            self.fill(i, observers, out);
        }
        self.drive(observers, out);
    }

    /// The lanes' passes until every trajectory has ended. Once the queue is empty and at
    /// most half the lanes are busy, the busy ones move to a vector of half the width
    /// ([`compact`](Self::compact)): a pass there costs about half, and each lane computes
    /// what it would have computed here (every operation is lane-wise).
    fn drive<O: Observer<f64, 2>>(
        &mut self,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, 2>>>],
    ) {
        let mut step = Box::new(StepOut::new());
        while self.st.active.bits() != 0 {
            if self.next >= self.queue.len()
                && <V::Half as Lanes>::LANES < V::LANES
                && self.st.active.bits().count_ones() as usize <= <V::Half as Lanes>::LANES
            {
                self.compact().drive(observers, out);
                return;
            }
            V::step_lanes(&mut self.st, &self.consts, &mut step);
            if step.too_small != 0 {
                for i in lanes_of(step.too_small) {
                    let e = IntegrateError::StepSizeTooSmall {
                        t: step.buf[row::T0][i],
                        h: step.buf[row::H][i],
                    };
                    self.finish(i, Err(e.into()), observers, out);
                }
                continue;
            }
            // Every active lane made one trial step (six evaluations): rejected here,
            // accepted in after_step. Only the lanes named by the masks are visited.
            for i in lanes_of(step.rejected) {
                let slot = &mut self.slots[i];
                slot.stats.rhs_evals += 6;
                slot.stats.rejected += 1;
                if step.non_finite & (1 << i) != 0 {
                    slot.nonfinite += 1;
                    if slot.nonfinite > 20 {
                        let e = IntegrateError::NonFiniteRhs {
                            t: step.buf[row::T0][i],
                        };
                        self.finish(i, Err(e.into()), observers, out);
                    }
                }
            }
            for i in lanes_of(step.accepted) {
                let g = |k: usize| step.buf[k][i];
                let sv = |k: usize| SVector::<f64, 2>::new(g(k), g(k + 1));
                let dense = LaneDense {
                    t0: g(row::T0),
                    t1: g(row::T1),
                    h: g(row::H),
                    y0: sv(row::X0),
                    y1: sv(row::X1),
                    f0: sv(row::F0),
                    f1: sv(row::F1),
                    r2: sv(row::R2),
                    r3: sv(row::R3),
                    r4: sv(row::R4),
                    r5: sv(row::R5),
                };
                self.after_step(i, &dense, observers, out);
            }
        }
    }

    /// The busy lanes moved, in order, to an engine with half the lanes (the queue is
    /// empty). Idle lanes there step from the first busy lane's state, never used.
    fn compact(&mut self) -> Engine<'a, V::Half, G> {
        type H<V> = <V as Lanes>::Half;
        let busy: Vec<usize> = lanes_of(self.st.active.bits()).collect();
        let st = &self.st;
        let first = busy[0];
        let splat = |x: V| <H<V> as Lanes>::splat(x.lane(first));
        let member = self.slots[first].member.unwrap_or(self.jobs[0].member);
        let mut half = Box::new(LaneState {
            packed: Packed::splat(&member),
            t: splat(st.t),
            x: splat(st.x),
            v: splat(st.v),
            fx: splat(st.fx),
            fv: splat(st.fv),
            h: splat(st.h),
            limit: splat(st.limit),
            ln_err_old: splat(st.ln_err_old),
            rej_last: splat(st.rej_last),
            active: <H<V> as Lanes>::splat(0.0),
        });
        let mut slots: Vec<Slot> = (0..<H<V> as Lanes>::LANES).map(|_| Slot::idle()).collect();
        for (k, &i) in busy.iter().enumerate() {
            let mv = |dst: H<V>, src: V| dst.with_lane(k, src.lane(i));
            half.t = mv(half.t, st.t);
            half.x = mv(half.x, st.x);
            half.v = mv(half.v, st.v);
            half.fx = mv(half.fx, st.fx);
            half.fv = mv(half.fv, st.fv);
            half.h = mv(half.h, st.h);
            half.limit = mv(half.limit, st.limit);
            half.ln_err_old = mv(half.ln_err_old, st.ln_err_old);
            half.rej_last = mv(half.rej_last, st.rej_last);
            half.active = half.active.with_lane(k, ALL);
            slots[k] = core::mem::replace(&mut self.slots[i], Slot::idle());
            if let Some(m) = &slots[k].member {
                half.packed.set(k, m);
            }
        }
        Engine {
            cfg: self.cfg,
            jobs: self.jobs,
            queue: self.queue,
            next: self.next,
            slots,
            st: half,
            consts: self.consts,
        }
    }

    /// A lane's accepted step: events and observers, then the end or the next limit.
    fn after_step<O: Observer<f64, 2>>(
        &mut self,
        i: usize,
        dense: &LaneDense,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, 2>>>],
    ) {
        let Some(j) = self.slots[i].job else { return };
        let slot = &mut self.slots[i];
        slot.stats.rhs_evals += 6;
        slot.stats.accepted += 1;
        slot.steps += 1;
        slot.nonfinite = 0;
        let obs = &mut observers[j];
        let res = scan(self.cfg, slot, dense, obs);
        match res {
            Err(e) => self.finish(i, Err(e), observers, out),
            Ok(Some((t, y))) => {
                self.finish(i, Ok((t, y, Termination::ObserverStopped)), observers, out)
            }
            Ok(None) => {
                let slot = &self.slots[i];
                let (t1, y1) = (dense.t1, dense.y1);
                if t1 >= slot.t_end {
                    self.finish(i, Ok((t1, y1, Termination::ReachedEnd)), observers, out);
                } else if slot.steps >= self.cfg.max_steps {
                    let e = IntegrateError::MaxSteps {
                        t: t1,
                        max_steps: self.cfg.max_steps,
                    };
                    self.finish(i, Err(e.into()), observers, out);
                } else {
                    // The driver computes the next landing point after every step. Short of
                    // the current one (by more than the rounding of that computation) it
                    // is the current one again, so it is only recomputed near or on it.
                    let limit = self.st.limit.lane(i);
                    let scale = t1.abs() + slot.grid.map_or(0.0, |(o, dt)| o.abs() + dt);
                    if limit - t1 <= 64.0 * f64::EPSILON * scale {
                        let l = landing_limit(t1, slot.t_end, slot.grid);
                        self.st.limit = self.st.limit.with_lane(i, l);
                    }
                }
            }
        }
    }
}

fn non_finite(t: f64, g: f64) -> crate::Error {
    EventError::NonFinite {
        index: 0,
        t,
        value: g,
    }
    .into()
}

/// The driver's event scan and observer calls for one lane's step (one detection event,
/// no reset). Returns the state to stop at if an observer stopped the run.
fn scan<G: EventFunction<f64, 2>, O: Observer<f64, 2>>(
    cfg: &Ensemble<G>,
    slot: &mut Slot,
    dense: &LaneDense,
    obs: &mut O,
) -> Result<Option<(f64, SVector<f64, 2>)>> {
    let (ts0, ts1) = (dense.t0, dense.t1);
    let (y_start, y_end) = (dense.y0, dense.y1);
    let mut t_lo = ts0;
    let mut y_lo = y_start;
    let mut g_end = None;
    if let (Some(ev), Some(m)) = (&cfg.event, &slot.member) {
        let fun = &ev.function;
        let g0 = fun.value(ts0, &y_start);
        let ge = fun.value(ts1, &y_end);
        if !(g0.is_finite() && ge.is_finite()) {
            let (t, g) = if g0.is_finite() { (ts1, ge) } else { (ts0, g0) };
            return Err(non_finite(t, g));
        }
        g_end = Some(ge);
        if slot.side == 0 {
            slot.side = if ge != 0.0 { sign_of(ge) } else { 1 };
        }
        let st_g = if g0 == 0.0 {
            let tiny = f64::EPSILON * f64::EPSILON;
            if slot.side < 0 { -tiny } else { tiny }
        } else {
            g0
        };
        let st_r = fun.rate(ts0, &y_start, &dense.f0);
        let r_end = fun.rate(ts1, &y_end, &dense.f1);
        let tol = cfg.event_tol.max(4.0 * f64::EPSILON * ts1.abs());
        let mut found = find_crossing(fun, m, dense, tol, ts0, st_g, st_r, ts1, ge, r_end);
        while let Some(c) = found {
            found = match c.resume {
                Some((tr, gr)) => find_crossing(fun, m, dense, tol, tr, gr, None, ts1, ge, r_end),
                None => None,
            };
            slot.side = if c.rising { 1 } else { -1 };
            if !ev.direction.accepts(c.rising) {
                continue;
            }
            let tc = c.t;
            let mut yc = SVector::zeros();
            dense.interpolate_unchecked(tc, &mut yc);
            let view = StepView {
                t0: t_lo,
                t1: tc,
                y0: y_lo,
                y1: yc,
                dense,
            };
            let stop_obs = obs.on_step(&view) == Control::Stop;
            slot.stats.events += 1;
            if let Some((count, last)) = slot.history.push(tc, &cfg.zeno) {
                return Err(EventError::Zeno {
                    t: tc,
                    count,
                    last_interval: last,
                    state: yc.iter().copied().collect(),
                }
                .into());
            }
            let rec = EventRecord {
                index: 0,
                t: tc,
                y: yc,
                y_after: None,
                direction: if c.rising {
                    Direction::Rising
                } else {
                    Direction::Falling
                },
            };
            let stop_ev = obs.on_event(&rec) == Control::Stop;
            if stop_obs || stop_ev {
                return Ok(Some((tc, yc)));
            }
            t_lo = tc;
            y_lo = yc;
        }
    }
    let view = StepView {
        t0: t_lo,
        t1: ts1,
        y0: y_lo,
        y1: y_end,
        dense,
    };
    let stop = obs.on_step(&view) == Control::Stop;
    if let Some(ge) = g_end {
        if ge != 0.0 {
            slot.side = sign_of(ge);
        }
    }
    Ok(stop.then_some((ts1, y_end)))
}

/// A crossing found on a step.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    t: f64,
    rising: bool,
    resume: Option<(f64, f64)>,
}

/// The earliest crossing of the event in `(t_lo, t1]`: [`Simulation`]'s search without
/// interior samples (`drive::crossing_between`) written for `f64` — through the generic
/// function the ensemble's throughput was 3–4 % lower.
///
/// [`Simulation`]: crate::drive::Simulation
#[allow(clippy::too_many_arguments)]
fn find_crossing<G: EventFunction<f64, 2>>(
    ev: &G,
    m: &Member,
    dense: &LaneDense,
    tol: f64,
    t_lo: f64,
    g_lo: f64,
    r_lo: Option<f64>,
    t1: f64,
    g1: f64,
    r1: Option<f64>,
) -> Option<Crossing> {
    let g_at = |t: f64| {
        let mut y = SVector::<f64, 2>::zeros();
        dense.interpolate_unchecked(t, &mut y);
        ev.value(t, &y)
    };
    let s = sign_of(g_lo);
    if g1 != 0.0 && sign_of(g1) != s {
        let (tc, _) = locate(g_at, t_lo, t1, g_lo, g1, tol);
        return Some(Crossing {
            t: tc,
            rising: g1 > 0.0,
            resume: None,
        });
    }
    let r_lo = match r_lo {
        Some(r) => Some(r),
        None => {
            let mut y = SVector::zeros();
            dense.interpolate_unchecked(t_lo, &mut y);
            let f = scalar_rhs(m, t_lo, &y);
            ev.rate(t_lo, &y, &f)
        }
    };
    let (Some(r_lo), Some(r1)) = (r_lo, r1) else {
        return None;
    };
    let towards = if s > 0 { r_lo < 0.0 } else { r_lo > 0.0 };
    let away = if s > 0 { r1 > 0.0 } else { r1 < 0.0 };
    if !(towards && (away || g1 == 0.0)) {
        return None;
    }
    let sg = if s > 0 { 1.0 } else { -1.0 };
    let (te, neg) = crate::roots::golden_max(|t| -sg * g_at(t), t_lo, t1, tol);
    let ge = -neg * sg;
    if ge == 0.0 || sign_of(ge) == s {
        return None;
    }
    let (tc, _) = locate(g_at, t_lo, te, g_lo, ge, tol);
    Some(Crossing {
        t: tc,
        rising: ge > 0.0,
        resume: Some((te, ge)),
    })
}
