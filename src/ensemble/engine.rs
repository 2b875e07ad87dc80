//! The lane DOPRI5 engine: `L` trajectories stepped together, each with its own step.

use nalgebra::SVector;

use super::kernel::{Counts, EndsCache, LaneState, StepConsts, StepOut, row};
use crate::LaneDynamics;
use crate::drive::{Control, Observer, Outcome, RunError, StepView, Termination};
use crate::drive::{LaneSides, Scan, check_work, landing_limit, scaled_limit, time_scale};
use crate::event::{Event, EventFunction, EventHistory, EventSet, MAX_EVENTS, ZenoGuard};
use crate::integrate::{
    DenseOutput, Dopri5Dense, HermiteDense, IntegrateError, Stats, StepOptions, Tolerances,
};
use crate::lanes::{LaneMath, Lanes, Simd, TRUE};

#[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
use super::kernel::{Avx2, Avx512};
use super::kernel::{Baseline, Isa};
use crate::validate::ParameterError;

/// `Result` with the driver's [`RunError`]: the ensemble's runs fail as the scalar
/// [`Simulation`](crate::drive::Simulation)'s do.
type Result<T, E = RunError> = std::result::Result<T, E>;

/// One trajectory of an ensemble: its model (any [`LaneDynamics`] of state size `M`),
/// its start and end, and an optional landing grid
/// `origin + i·dt` that every step lands on (the sweeps' sections at `t = i·2π/ω`).
///
/// The constructors validate; values set through the public fields are validated when a
/// run starts ([`check`](Self::check)), and an invalid trajectory is an error in its own
/// result slot of [`Ensemble::run`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MemberRun<D, const M: usize = 2> {
    /// The model.
    pub member: D,
    /// Start time.
    pub t0: f64,
    /// Initial state.
    pub y0: SVector<f64, M>,
    /// End time.
    pub t_end: f64,
    /// Landing grid `(origin, dt)`.
    pub grid: Option<(f64, f64)>,
}

impl<D, const M: usize> MemberRun<D, M> {
    /// From `(t0, y0)` to `t_end`, without a landing grid.
    ///
    /// # Errors
    /// [`IntegrateError::InvalidTimeSpan`] unless `t0 < t_end`, both finite;
    /// [`IntegrateError::NonFiniteState`] for a non-finite `y0`.
    pub fn new(member: D, t0: f64, y0: SVector<f64, M>, t_end: f64) -> Result<Self> {
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

    /// `periods` periods of length `period` from `(0, y0)`, every step landing on
    /// `t = i·period` (the sweeps' setting: `period` the forcing period).
    ///
    /// # Errors
    /// As [`new`](Self::new); [`ParameterError`] unless `periods` and `period` are finite
    /// and > 0.
    pub fn periods_of(member: D, y0: SVector<f64, M>, period: f64, periods: f64) -> Result<Self> {
        crate::validate::positive("periods", periods)?;
        crate::validate::positive("period", period)?;
        Self::new(member, 0.0, y0, periods * period)?.with_grid(0.0, period)
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
pub struct Ensemble<E = (), const M: usize = 2> {
    tol: Tolerances<f64, M>,
    opts: StepOptions<f64>,
    math: LaneMath,
    simd: Simd,
    max_steps: usize,
    event_tol: f64,
    zeno: ZenoGuard<f64>,
    events: E,
}

impl<const M: usize> Ensemble<(), M> {
    /// An ensemble of state size `M` with the given tolerances, default [`StepOptions`], no event,
    /// [`LaneMath::Exact`], the driver's defaults (step cap 10⁸ per trajectory, event time
    /// tolerance 10⁻¹², the default [`ZenoGuard`]).
    ///
    /// # Errors
    /// [`ParameterError`] for invalid tolerances (set through the public fields).
    pub fn new(tol: Tolerances<f64, M>) -> Result<Self> {
        tol.validate()?;
        Ok(Self {
            tol,
            opts: StepOptions::default(),
            math: LaneMath::Exact,
            simd: Simd::Auto,
            max_steps: 100_000_000,
            event_tol: 1e-12,
            zeno: ZenoGuard::default(),
            events: (),
        })
    }
}

impl<E: EventSet<f64, M>, const M: usize> Ensemble<E, M> {
    /// Sets the events: any [`EventSet`] of the crate's events ([`Event`] with any event
    /// function, reset and flags, and tuples of them), handled per lane exactly as
    /// [`Simulation`](crate::drive::Simulation) handles them — the same code: crossings
    /// and grazing pairs located on each lane's dense output, records, resets (a lane
    /// restarts from the reset state), restarts, terminal events, the sticking check, the
    /// Zeno guard, and the events' step bounds.
    ///
    /// # Errors
    /// [`EventError`](crate::event::EventError) for invalid event settings (the events'
    /// own [`check`](EventSet::check)).
    pub fn with_events<E2: EventSet<f64, M>>(self, events: E2) -> Result<Ensemble<E2, M>> {
        const {
            assert!(
                E2::LEN <= MAX_EVENTS,
                "an ensemble handles at most MAX_EVENTS events"
            )
        };
        events.check()?;
        Ok(Ensemble {
            tol: self.tol,
            opts: self.opts,
            math: self.math,
            simd: self.simd,
            max_steps: self.max_steps,
            event_tol: self.event_tol,
            zeno: self.zeno,
            events,
        })
    }

    /// Sets one detection event ([`with_events`](Self::with_events) of one [`Event`]).
    ///
    /// # Errors
    /// As [`with_events`](Self::with_events).
    pub fn with_event<G2: EventFunction<f64, M>, R2: crate::event::ResetMap<f64, M>>(
        self,
        event: Event<G2, R2>,
    ) -> Result<Ensemble<Event<G2, R2>, M>> {
        self.with_events(event)
    }

    /// The events.
    pub fn events(&self) -> &E {
        &self.events
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
    pub fn tolerances(&self) -> &Tolerances<f64, M> {
        &self.tol
    }

    /// The math mode.
    pub fn math(&self) -> LaneMath {
        self.math
    }

    /// Integrates every trajectory in SIMD lanes, streaming trajectory `j` to
    /// `observers[j]`, on the calling thread. The instruction set is chosen at run time
    /// ([`with_simd`](Self::with_simd), default the widest the CPU has), and with it the
    /// lanes: sixteen with AVX2 or AVX-512, four on the baseline, half that for the last
    /// trajectories of a run. A lane whose trajectory ends (or fails) takes the next one
    /// in order; the result of each trajectory does not depend on the instruction set or
    /// the width, on the order of the slice or on what runs in the other lanes.
    ///
    /// Every trajectory is checked ([`MemberRun::check`]) before the lanes start: an
    /// invalid one (fields set directly to a reversed time span, a non-finite state, a
    /// landing grid with `dt ≤ 0`, a model whose structure differs from the first valid
    /// one's, [`LaneDynamics::same_structure`]) never enters a lane; its result is the
    /// error, and the others run as they would without it.
    ///
    /// # Errors
    /// The outer error: [`ParameterError`] if `observers` and `trajectories` differ in
    /// length. Each trajectory's own result is an element of the vector: its
    /// [`Outcome`], or the error that stopped it (the scalar driver's errors, or that of
    /// [`MemberRun::check`]).
    pub fn run<D: LaneDynamics<M>, O: Observer<f64, M>>(
        &self,
        trajectories: &[MemberRun<D, M>],
        observers: &mut [O],
    ) -> Result<Vec<Result<Outcome<f64, M>>>> {
        if observers.len() != trajectories.len() {
            return Err(ParameterError::new(
                "observers",
                observers.len() as f64,
                "one per trajectory",
            )
            .into());
        }
        let mut out: Vec<Option<Result<Outcome<f64, M>>>> = Vec::with_capacity(trajectories.len());
        out.resize_with(trajectories.len(), || None);
        // The valid trajectories, in order: the lanes' queue.
        let mut queue = Vec::with_capacity(trajectories.len());
        let mut first: Option<&D> = None;
        for (j, job) in trajectories.iter().enumerate() {
            let shared = first.is_none_or(|f| f.same_structure(&job.member));
            match job.check() {
                Ok(()) if shared => {
                    first.get_or_insert(&job.member);
                    queue.push(j);
                }
                Ok(()) => {
                    let e = ParameterError::new(
                        "member",
                        j as f64,
                        "of the same structure as the first valid member (coordinates, mass \
                         shape, linear matrices)",
                    );
                    out[j] = Some(Err(e.into()));
                }
                Err(e) => out[j] = Some(Err(e)),
            }
        }
        if let Some(&first) = queue.first() {
            let first = &trajectories[first];
            match self.simd.resolve() {
                #[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
                Simd::Avx512 => {
                    self.lanes::<Avx512, _, _>(trajectories, &queue, first, observers, &mut out)
                }
                #[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
                Simd::Avx2 => {
                    self.lanes::<Avx2, _, _>(trajectories, &queue, first, observers, &mut out)
                }
                _ => self.lanes::<Baseline, _, _>(trajectories, &queue, first, observers, &mut out),
            }
        }
        Ok(out
            .into_iter()
            .map(|r| r.unwrap_or_else(|| Err(IntegrateError::NotInitialized.into())))
            .collect())
    }

    /// The lanes of the instruction set `I` over the valid trajectories `queue`.
    fn lanes<I: Isa, D: LaneDynamics<M>, O: Observer<f64, M>>(
        &self,
        trajectories: &[MemberRun<D, M>],
        queue: &[usize],
        first: &MemberRun<D, M>,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, M>>>],
    ) {
        Engine::<I, I::Wide, I::Narrow, E, D, M>::new(self, trajectories, queue, first)
            .run(observers, out);
    }

    /// [`run`](Self::run) over the threads of the current rayon pool, `chunk` trajectories
    /// per task (each task fills its own lanes): the results are the same, bit for bit, as
    /// on one thread.
    ///
    /// # Errors
    /// As [`run`](Self::run); [`ParameterError`] if `chunk == 0`.
    #[cfg(feature = "parallel")]
    pub fn run_parallel<D: LaneDynamics<M> + Sync, O: Observer<f64, M> + Send>(
        &self,
        trajectories: &[MemberRun<D, M>],
        observers: &mut [O],
        chunk: usize,
    ) -> Result<Vec<Result<Outcome<f64, M>>>>
    where
        E: Sync,
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
        let parts: Vec<Vec<Result<Outcome<f64, M>>>> = trajectories
            .par_chunks(chunk)
            .zip(observers.par_chunks_mut(chunk))
            .map(|(t, o)| self.run::<D, O>(t, o))
            .collect::<Result<_>>()?;
        Ok(parts.into_iter().flatten().collect())
    }
}

/// The dense output of one lane's accepted step: the scalar stepper's own
/// [`Dopri5Dense`] (Hairer's continuous extension of DOPRI5), built from the lane's rows.
pub type LaneDense<const M: usize = 2> = Dopri5Dense<f64, M>;

/// Lane `i`'s step from the rows of a pass's output.
#[inline(always)]
fn dense_of<const M: usize>(buf: &[[f64; 16]], i: usize) -> Dopri5Dense<f64, M> {
    let v = |q: usize| SVector::<f64, M>::from_fn(|c, _| buf[row::vector(q, M) + c][i]);
    let ends = HermiteDense::new(
        buf[row::T0][i],
        buf[row::T1][i],
        v(row::X0),
        v(row::X1),
        v(row::F0),
        v(row::F1),
    );
    let r = [v(row::R2), v(row::R3), v(row::R4), v(row::R5)];
    Dopri5Dense::from_parts(ends, buf[row::H][i], r)
}

/// Per-lane bookkeeping (scalar). The step counts are lanes of the vector state
/// ([`Counts`]), added to `stats` when the trajectory ends.
struct Slot<D> {
    job: Option<usize>,
    member: Option<D>,
    grid: Option<(f64, f64)>,
    history: EventHistory<f64>,
    stats: Stats,
}

impl<D> Slot<D> {
    fn idle() -> Self {
        Self {
            job: None,
            member: None,
            grid: None,
            history: EventHistory::new(),
            stats: Stats::default(),
        }
    }
}

/// The lanes whose bit is set in `mask` as a mask of the lanes they move to: bit
/// `from[k]` of `mask` becomes bit `k`.
fn gather_bits(mask: u32, from: &[usize]) -> u32 {
    from.iter()
        .enumerate()
        .fold(0, |acc, (k, &l)| acc | ((mask >> l & 1) << k))
}

/// The lanes and their scalar bookkeeping.
///
/// `I` is the instruction set the lane loop is compiled for, `V` the lanes of this engine
/// and `H` those its tail compacts into (`H = V`: no further compaction).
struct Engine<'a, I: Isa, V: Lanes, H: Lanes, E, D: LaneDynamics<M>, const M: usize> {
    cfg: &'a Ensemble<E, M>,
    jobs: &'a [MemberRun<D, M>],
    /// The indices of the valid trajectories, in order ([`MemberRun::check`]).
    queue: &'a [usize],
    /// The next position in `queue`.
    next: usize,
    slots: Vec<Slot<D>>,
    /// Each lane's events' sides (the driver's [`Sides`](crate::drive::Sides), as masks).
    sides: LaneSides,
    /// The lanes whose step bound (the events' and the model's time scale) may change with
    /// `t`: their limit is computed after every step by the driver's rule, lane by lane.
    /// The kernel computes the others' (`LaneState::scale`).
    varying: u32,
    /// The lanes whose observer [wants steps](Observer::wants_steps).
    watch: u32,
    /// On the heap, like the step's output: on the stack, the speed of the vector step
    /// depended on where the stack began (the program's path and environment) by up to
    /// 30 % (measured with AVX2, 16 lanes: 0.38–0.50 s for the same binary); boxed, it
    /// stays at the fast end.
    st: Box<LaneState<V, D, M>>,
    consts: StepConsts<M>,
    isa: core::marker::PhantomData<(I, H)>,
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

impl<'a, I: Isa, V: Lanes, H: Lanes, E: EventSet<f64, M>, D: LaneDynamics<M>, const M: usize>
    Engine<'a, I, V, H, E, D, M>
{
    fn new(
        cfg: &'a Ensemble<E, M>,
        jobs: &'a [MemberRun<D, M>],
        queue: &'a [usize],
        first: &MemberRun<D, M>,
    ) -> Self {
        let z = V::splat(0.0);
        let packed = first.member.pack::<V>();
        // Idle lanes step from a benign state (the first valid job's start, h = 1e-6):
        // their results are never used and their state never changes.
        let t = first.t0;
        Self {
            cfg,
            jobs,
            queue,
            next: 0,
            slots: (0..V::LANES).map(|_| Slot::idle()).collect(),
            sides: LaneSides::default(),
            varying: 0,
            watch: 0,
            st: Box::new(LaneState {
                packed,
                t: V::splat(t),
                origin: V::splat(t),
                tau: z,
                y: core::array::from_fn(|c| V::splat(first.y0[c])),
                f: [z; M],
                h: V::splat(1e-6),
                limit: V::splat(t + 1.0),
                landing: V::splat(t + 1.0),
                grid_scale: z,
                scale: V::splat(f64::INFINITY),
                t_end: V::splat(t + 1.0),
                ln_err_old: V::splat(1e-4f64.ln()),
                rej_last: z,
                active: z,
                kk: [[z; M]; 7],
                accepted: z,
                counts: Counts::zero(),
                ends: EndsCache::new(),
            }),
            consts: StepConsts::new(&cfg.tol, &cfg.opts, (cfg.max_steps, cfg.math)),
            isa: core::marker::PhantomData,
        }
    }

    /// Starts the next trajectory of the queue in lane `i` (skipping those that fail at
    /// once); leaves the lane idle when the queue is empty.
    fn fill<O: Observer<f64, M>>(
        &mut self,
        i: usize,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, M>>>],
    ) {
        self.st.active.set_lane(i, 0.0);
        self.slots[i].job = None;
        while let Some(&j) = self.queue.get(self.next) {
            self.next += 1;
            match self.start(i, j, &mut observers[j]) {
                Ok(()) => {
                    self.st.active.set_lane(i, TRUE);
                    return;
                }
                Err(e) => out[j] = Some(Err(e)),
            }
        }
    }

    fn start<O: Observer<f64, M>>(&mut self, i: usize, j: usize, obs: &mut O) -> Result<()> {
        let job = &self.jobs[j];
        let cfg = self.cfg;
        // The time span, state and grid were checked before the run (`MemberRun::check`).
        let (t0, y0, t_end) = (job.t0, job.y0, job.t_end);
        cfg.opts
            .validate()
            .map_err(IntegrateError::InvalidSettings)?;
        obs.check()?;
        obs.check_span(t0, t_end)?;
        let m = &job.member;
        cfg.events.check()?;
        let scale = |t: f64| time_scale(m, &cfg.events, t);
        let h_max = (cfg.opts.h_max.is_finite() && cfg.opts.h_max > 0.0).then_some(cfg.opts.h_max);
        check_work(t0, t_end, h_max, job.grid, scale, cfg.max_steps)?;
        let mut stats = Stats::default();
        obs.on_start(t0, &y0);
        // The events' sides at the start (the driver's rule).
        let sides = crate::drive::initial_sides(m, &cfg.events, t0, &y0)?;
        // The stepper's first derivative and first step.
        let f0 = scalar_rhs(m, t0, &y0);
        stats.rhs_evals += 1;
        if !f0.iter().all(|v| v.is_finite()) {
            return Err(IntegrateError::NonFiniteRhs { t: t0 }.into());
        }
        let varying = !(cfg.events.constant_max_step() && m.constant_time_scale());
        let landing = landing_limit(t0, t_end, job.grid);
        let limit = scaled_limit(landing, t0, scale(t0));
        let h = match cfg.opts.h_init {
            Some(h) => h,
            None => crate::integrate::initial_step(
                m,
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
        m.pack_lane(&mut self.st.packed, i);
        self.st.t.set_lane(i, t0);
        self.st.origin.set_lane(i, t0);
        self.st.tau.set_lane(i, 0.0);
        for c in 0..M {
            self.st.y[c].set_lane(i, y0[c]);
            self.st.f[c].set_lane(i, f0[c]);
        }
        self.st.h.set_lane(i, h);
        self.st.limit.set_lane(i, limit);
        self.st.landing.set_lane(i, landing);
        let grid_scale = job.grid.map_or(0.0, |(o, dt)| o.abs() + dt);
        self.st.grid_scale.set_lane(i, grid_scale);
        let fixed = if varying { None } else { scale(t0) };
        self.st.scale.set_lane(i, fixed.unwrap_or(f64::INFINITY));
        self.st.t_end.set_lane(i, t_end);
        self.st.ln_err_old.set_lane(i, 1e-4f64.ln());
        self.st.rej_last.set_lane(i, 0.0);
        self.st.ends.fresh.set_lane(i, TRUE);
        self.st.counts.clear_lane(i);
        self.sides.set(i, &sides);
        let bit = 1u32 << i;
        self.varying = if varying {
            self.varying | bit
        } else {
            self.varying & !bit
        };
        self.watch = if obs.wants_steps() {
            self.watch | bit
        } else {
            self.watch & !bit
        };
        let s = &mut self.slots[i];
        *s = Slot::idle();
        s.job = Some(j);
        s.member = Some(m.clone());
        s.grid = job.grid;
        s.stats = stats;
        Ok(())
    }

    fn finish<O: Observer<f64, M>>(
        &mut self,
        i: usize,
        result: Result<(f64, SVector<f64, M>, Termination)>,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, M>>>],
    ) {
        if let Some(j) = self.slots[i].job {
            // The lane's step counts join the scalar statistics (six evaluations a trial).
            let mut stats = self.slots[i].stats;
            let n = &self.st.counts;
            let (accepted, rejected) = (n.accepted.get_lane(i), n.rejected.get_lane(i));
            stats.accepted += accepted as u64;
            stats.rejected += rejected as u64;
            stats.rhs_evals += 6 * (accepted as u64 + rejected as u64);
            out[j] = Some(result.map(|(t, y, termination)| {
                let o = Outcome {
                    t,
                    y,
                    termination,
                    stats,
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
    fn run<O: Observer<f64, M>>(
        &mut self,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, M>>>],
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
    fn drive<O: Observer<f64, M>>(
        &mut self,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, M>>>],
    ) {
        let mut step = Box::new(StepOut::new(M));
        // The events' ends tell which lanes' steps are quiet (quiet_lanes).
        let want_events = E::LEN > 0;
        while self.st.active.bits() != 0 {
            if self.next >= self.queue.len()
                && H::LANES < V::LANES
                && self.st.active.bits().count_ones() as usize <= H::LANES
            {
                self.compact().drive(observers, out);
                return;
            }
            super::kernel::step::<I, V, D, M>(&mut self.st, &self.consts, &mut step);
            step.events = false;
            if want_events && step.accepted != 0 {
                let st = &mut *self.st;
                super::kernel::event_ends::<I, V, E, M>(
                    &self.cfg.events,
                    (&mut st.ends, st.accepted),
                    &mut step,
                );
            }
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
            // Every active lane made one trial step, counted in the lanes. Only the lanes
            // named by the masks are visited.
            for i in lanes_of(step.failing) {
                let e = IntegrateError::NonFiniteRhs {
                    t: step.buf[row::T0][i],
                };
                self.finish(i, Err(e.into()), observers, out);
            }
            let quiet = self.quiet_lanes(&step);
            if quiet != 0 {
                self.after_quiet_steps(quiet, &step);
            }
            // The quiet lanes whose observer does not want steps are done.
            for i in lanes_of(step.accepted & !(quiet & !self.watch)) {
                if quiet & (1 << i) != 0 {
                    self.show_quiet_step(i, &step, observers, out);
                } else {
                    let dense = dense_of::<M>(&step.buf, i);
                    let near = step.near_landing & (1 << i) != 0;
                    self.after_step((i, near), &dense, observers, out);
                }
            }
        }
    }

    /// The busy lanes moved, in order, to an engine of the narrow width `H` (the queue is
    /// empty; at most `H::LANES` lanes are busy). Idle lanes there step from the first
    /// busy lane's state, never used.
    fn compact(&mut self) -> Engine<'a, I, H, H, E, D, M> {
        let busy: Vec<usize> = lanes_of(self.st.active.bits()).collect();
        let st = &self.st;
        let first = busy[0];
        let splat = |x: V| H::splat(x.lane(first));
        let member = self.slots[first]
            .member
            .as_ref()
            .unwrap_or(&self.jobs[self.queue[0]].member);
        let mut half = Box::new(LaneState {
            packed: member.pack::<H>(),
            t: splat(st.t),
            origin: splat(st.origin),
            tau: splat(st.tau),
            y: st.y.map(splat),
            f: st.f.map(splat),
            h: splat(st.h),
            limit: splat(st.limit),
            landing: splat(st.landing),
            grid_scale: splat(st.grid_scale),
            scale: splat(st.scale),
            t_end: splat(st.t_end),
            ln_err_old: splat(st.ln_err_old),
            rej_last: splat(st.rej_last),
            active: H::splat(0.0),
            kk: [[H::splat(0.0); M]; 7],
            accepted: H::splat(0.0),
            counts: Counts::zero(),
            ends: EndsCache::new(),
        });
        let mut slots: Vec<Slot<D>> = (0..H::LANES).map(|_| Slot::idle()).collect();
        for (k, &i) in busy.iter().enumerate() {
            let mv = |dst: H, src: V| dst.with_lane(k, src.lane(i));
            half.t = mv(half.t, st.t);
            half.origin = mv(half.origin, st.origin);
            half.tau = mv(half.tau, st.tau);
            for c in 0..M {
                half.y[c] = mv(half.y[c], st.y[c]);
                half.f[c] = mv(half.f[c], st.f[c]);
            }
            half.h = mv(half.h, st.h);
            half.limit = mv(half.limit, st.limit);
            half.landing = mv(half.landing, st.landing);
            half.grid_scale = mv(half.grid_scale, st.grid_scale);
            half.scale = mv(half.scale, st.scale);
            half.t_end = mv(half.t_end, st.t_end);
            let (n, m) = (&mut half.counts, &st.counts);
            n.accepted = mv(n.accepted, m.accepted);
            n.rejected = mv(n.rejected, m.rejected);
            n.non_finite = mv(n.non_finite, m.non_finite);
            half.ln_err_old = mv(half.ln_err_old, st.ln_err_old);
            half.rej_last = mv(half.rej_last, st.rej_last);
            half.active = half.active.with_lane(k, TRUE);
            slots[k] = core::mem::replace(&mut self.slots[i], Slot::idle());
            if let Some(m) = &slots[k].member {
                m.pack_lane(&mut half.packed, k);
            }
        }
        Engine {
            cfg: self.cfg,
            jobs: self.jobs,
            queue: self.queue,
            next: self.next,
            slots,
            sides: self.sides.map(|m| gather_bits(m, &busy)),
            varying: gather_bits(self.varying, &busy),
            watch: gather_bits(self.watch, &busy),
            st: half,
            consts: self.consts,
            isa: core::marker::PhantomData,
        }
    }

    /// A lane's accepted step: the driver's event handling and observer calls
    /// ([`Scan`]), then the end, a restart where an event reset or cut the step, or the
    /// next limit (`near_landing`: the kernel found the step's end near the landing point).
    fn after_step<O: Observer<f64, M>>(
        &mut self,
        (i, near_landing): (usize, bool),
        dense: &LaneDense<M>,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, M>>>],
    ) {
        let Some(j) = self.slots[i].job else { return };
        let cfg = self.cfg;
        let slot = &mut self.slots[i];
        let Some(m) = &slot.member else { return };
        let mut restart = None;
        let mut sides = self.sides.get(i);
        let res = Scan {
            system: m,
            events: &cfg.events,
            zeno: &cfg.zeno,
            event_tol: cfg.event_tol,
            history: &mut slot.history,
            dense,
            stats: &mut slot.stats,
            restart: &mut restart,
        }
        .scan_step(&mut sides, &mut observers[j]);
        self.sides.set(i, &sides);
        let (t, y) = restart.unwrap_or((dense.span().1, *dense.endpoints().1));
        match res {
            Err(e) => self.finish(i, Err(e), observers, out),
            Ok(Some(termination)) => self.finish(i, Ok((t, y, termination)), observers, out),
            Ok(None) => {
                if restart.is_some() {
                    // The driver's stepper restarts from the event's state: its derivative
                    // is evaluated again (one evaluation), the step and controller go on.
                    let f = scalar_rhs(m, t, &y);
                    slot.stats.rhs_evals += 1;
                    if !f.iter().all(|v| v.is_finite()) {
                        let e = IntegrateError::NonFiniteRhs { t };
                        self.finish(i, Err(e.into()), observers, out);
                        return;
                    }
                    self.st.t.set_lane(i, t);
                    let origin = self.st.origin.get_lane(i);
                    self.st.tau.set_lane(i, t - origin);
                    for c in 0..M {
                        self.st.y[c].set_lane(i, y[c]);
                        self.st.f[c].set_lane(i, f[c]);
                    }
                    self.st.ends.fresh.set_lane(i, TRUE);
                }
                let steps = self.st.counts.accepted.get_lane(i);
                if t >= self.st.t_end.get_lane(i) {
                    self.finish(i, Ok((t, y, Termination::ReachedEnd)), observers, out);
                } else if steps >= cfg.max_steps as f64 {
                    let e = IntegrateError::MaxSteps {
                        t,
                        max_steps: cfg.max_steps,
                    };
                    self.finish(i, Err(e.into()), observers, out);
                } else {
                    // Without a restart the lane is at its step's end, where the kernel
                    // told whether it is near its landing point.
                    let near = restart.is_some() || near_landing;
                    self.update_limit(i, t, near);
                }
            }
        }
    }

    /// The next step limit of lane `i`, now at `t`: the driver's
    /// [`step_limit`](crate::drive::step_limit), which it computes after every step. Its
    /// landing point is computed again only if `near` (on or near the current one, or
    /// after a restart): short of it by more than the rounding of that computation it is
    /// the current one again. With a time scale that does not vary, the kernel has then
    /// computed the limit of the step's end already, and nothing changes.
    #[inline(always)]
    fn update_limit(&mut self, i: usize, t: f64, near: bool) {
        if !(near || self.varying & (1 << i) != 0) {
            return;
        }
        let slot = &self.slots[i];
        let mut landing = self.st.landing.get_lane(i);
        if near {
            landing = landing_limit(t, self.st.t_end.get_lane(i), slot.grid);
            self.st.landing.set_lane(i, landing);
        }
        let bound = slot
            .member
            .as_ref()
            .and_then(|m| time_scale(m, &self.cfg.events, t));
        self.st.limit.set_lane(i, scaled_limit(landing, t, bound));
    }

    /// The accepted lanes whose step the driver's event handling would pass through
    /// without doing anything but moving the events' sides and showing the whole step to
    /// the observer: the trajectory does not end with this step, and every event's step is
    /// quiet ([`LaneSides::quiet`], with the ends' part [`QuietEnds::lanes`] from the
    /// events' lane forms, which the kernel evaluates at the ends of every lane's step at
    /// once, under the run's instruction set, keeping each end as the next step's start).
    /// Empty if an event has no lane form.
    ///
    /// [`QuietEnds::lanes`]: crate::drive::QuietEnds::lanes
    fn quiet_lanes(&self, step: &StepOut) -> u32 {
        let mut quiet = step.accepted & !step.ends;
        if quiet == 0 || E::LEN == 0 {
            return quiet;
        }
        if !step.events {
            return 0;
        }
        for (e, &q) in step.quiet.iter().enumerate().take(E::LEN) {
            quiet = self.sides.quiet(&self.cfg.events, e, quiet, q);
            if quiet == 0 {
                return 0;
            }
        }
        quiet
    }

    /// What [`after_step`](Self::after_step) does for the lanes of `quiet`
    /// ([`quiet_lanes`](Self::quiet_lanes)) besides showing the step to an observer that
    /// [wants steps](Observer::wants_steps) ([`show_quiet_step`](Self::show_quiet_step)):
    /// the events' sides move to those of the steps' ends, and the next limit is computed
    /// where it changes.
    fn after_quiet_steps(&mut self, quiet: u32, step: &StepOut) {
        for (e, &[_, positive, _]) in step.quiet.iter().enumerate().take(E::LEN) {
            self.sides.quiet_step(e, quiet, positive);
        }
        for i in lanes_of(quiet & (self.varying | step.near_landing)) {
            let near = step.near_landing & (1 << i) != 0;
            self.update_limit(i, step.buf[row::T1][i], near);
        }
    }

    /// A quiet step shown to lane `i`'s observer as the whole step.
    fn show_quiet_step<O: Observer<f64, M>>(
        &mut self,
        i: usize,
        step: &StepOut,
        observers: &mut [O],
        out: &mut [Option<Result<Outcome<f64, M>>>],
    ) {
        let Some(j) = self.slots[i].job else { return };
        let dense = dense_of::<M>(&step.buf, i);
        let view = StepView::whole(&dense);
        if observers[j].on_step(&view) == Control::Stop {
            let end = Ok((view.t1, view.y1, Termination::ObserverStopped));
            self.finish(i, end, observers, out);
        }
    }
}

/// The scalar right-hand side of a lane's model (used where one lane is handled alone: its
/// first derivative, the initial step, the event rates).
#[inline(always)]
fn scalar_rhs<D: LaneDynamics<M>, const M: usize>(
    m: &D,
    t: f64,
    y: &SVector<f64, M>,
) -> SVector<f64, M> {
    let mut dy = SVector::zeros();
    m.rhs(t, y, &mut dy);
    dy
}
