//! The simulation driver: a system, a stepper, events and observers in one stepping loop.
//!
//! [`Simulation::run`] integrates from `(t0, y0)` to `t_end`; after each accepted step it
//! looks for events on the step's dense output (see [`event`](crate::event) for the
//! semantics), and streams the step — split at every located event — and the events to an
//! [`Observer`]. Observers cannot change the trajectory; they can stop the run.
//!
//! ```
//! use nonsmooth::drive::{Simulation, Termination};
//! use nonsmooth::event::{Direction, Event, Level};
//! use nonsmooth::integrate::{Dopri5, Tolerances};
//! use nonsmooth::systems::TwoDofImpact;
//! use nalgebra::SVector;
//!
//! // The 2-DOF impact oscillator at ω = 0.6 from rest, state (q₁, q₂, q̇₁, q̇₂); impacts =
//! // upward crossings of the stop by the secondary mass, q₂ = d.
//! let p = TwoDofImpact::default();
//! let model = p.model::<f64>(0.6)?;
//! let impact = Event::new(Level::new(1, p.gap)?, Direction::Rising);
//! let tol = Tolerances::<f64, 4>::new(1e-8, 1e-10)?;
//! let mut sim = Simulation::new(model, Dopri5::new(tol)).with_events(impact);
//! let out = sim.run(0.0, SVector::zeros(), 50.0, &mut ())?;
//! assert_eq!(out.termination, Termination::ReachedEnd);
//! # Ok::<(), nonsmooth::Error>(())
//! ```

use nalgebra::SVector;

mod constraint;
mod error;
pub mod modes;
mod scan;
pub mod stick_slip;
pub mod sticking;

pub(crate) use error::from_engine_errors;
pub use error::{ModeError, RunError};
pub use modes::{ModeRun, ModeSystem, Segment, run_modes};
pub use stick_slip::{Coulomb, SlipMode, StickSlip};
pub use sticking::{Constrained, ContactMode, ModeLog, RigidContact, run_with_sticking};

use crate::event::{Direction, EventHistory, EventSet, MAX_EVENTS, ZenoGuard};
use crate::integrate::{DenseOutput, IntegrateError, Stats, Stepper, check_state};
use crate::scalar::{lit, to_f64};
use crate::validate::ParameterError;
use crate::{Dynamics, Real};
use error::Result;
pub(crate) use scan::{LaneSides, QuietEnds, Scan, Sides, initial_sides};

/// Whether a run goes on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop the run after this callback.
    Stop,
}

/// A view of (part of) an accepted step: `[t0, t1]` with the states at both ends and the
/// step's dense output, valid on `[t0, t1]`.
#[derive(Debug, Clone, Copy)]
pub struct StepView<'a, T: Real, const N: usize, D> {
    /// Start of the view.
    pub t0: T,
    /// End of the view.
    pub t1: T,
    /// State at `t0`.
    pub y0: SVector<T, N>,
    /// State at `t1`.
    pub y1: SVector<T, N>,
    /// The dense output of the underlying step (which may extend beyond the view).
    pub dense: &'a D,
}

impl<'a, T: Real, const N: usize, D: DenseOutput<T, N>> StepView<'a, T, N, D> {
    /// The view of the whole step of `dense` (its span and end states): what a quiet step
    /// shows, in the driver and in the ensemble's lanes.
    #[inline(always)]
    pub(crate) fn whole(dense: &'a D) -> Self {
        let ((t0, t1), (y0, y1)) = (dense.span(), dense.endpoints());
        Self {
            t0,
            t1,
            y0: *y0,
            y1: *y1,
            dense,
        }
    }

    /// The interpolated state at `t ∈ [t0, t1]` (ends are returned exactly).
    #[inline(always)]
    pub fn state_at(&self, t: T, out: &mut SVector<T, N>) {
        if t == self.t0 {
            *out = self.y0;
        } else if t == self.t1 {
            *out = self.y1;
        } else {
            self.dense.interpolate_unchecked(t, out);
        }
    }
}

/// A located event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventRecord<T: Real, const N: usize> {
    /// Index of the event in the simulation's event set.
    pub index: usize,
    /// Located time.
    pub t: T,
    /// State at the event (before any reset).
    pub y: SVector<T, N>,
    /// State after the reset, if the event has one.
    pub y_after: Option<SVector<T, N>>,
    /// The actual crossing direction ([`Direction::Rising`] or [`Direction::Falling`]).
    pub direction: Direction,
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Termination {
    /// `t_end` was reached.
    ReachedEnd,
    /// An observer returned [`Control::Stop`].
    ObserverStopped,
    /// A terminal event (its index) fired.
    TerminalEvent(usize),
}

/// The result of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome<T: Real, const N: usize> {
    /// Final time.
    pub t: T,
    /// Final state.
    pub y: SVector<T, N>,
    /// Why the run ended.
    pub termination: Termination,
    /// Work done in this run (difference of the stepper's counters).
    pub stats: Stats,
}

/// Receives the accepted steps and located events of a run, in time order.
///
/// All hooks have defaults; `()` is the no-op observer, `&mut O` and tuples of observers are
/// observers.
///
/// ```
/// use nonsmooth::drive::{Control, EventRecord, Observer, StepView};
/// use nonsmooth::integrate::DenseOutput;
/// /// Counts events.
/// #[derive(Default)]
/// struct Counter(usize);
/// impl Observer<f64, 2> for Counter {
///     fn on_event(&mut self, _e: &EventRecord<f64, 2>) -> Control {
///         self.0 += 1;
///         Control::Continue
///     }
/// }
/// ```
pub trait Observer<T: Real, const N: usize> {
    /// Checks the observer's configuration against the state dimension `N` (e.g. component
    /// indices) before a run starts; an error stops the run before its first step.
    /// Default: `Ok`.
    ///
    /// # Errors
    /// Whatever the observer finds wrong (typically [`EventError::IndexOutOfRange`](crate::event::EventError::IndexOutOfRange)).
    fn check(&self) -> Result<()> {
        Ok(())
    }

    /// Checks that the run over `[t0, t_end]` is within the observer's bounds (e.g. a
    /// section clock whose sections over the span are countable); an error stops the run
    /// before its first step. Default: `Ok`.
    ///
    /// # Errors
    /// Whatever the observer finds wrong for this span.
    fn check_span(&self, _t0: T, _t_end: T) -> Result<()> {
        Ok(())
    }

    /// Called once before the first step.
    fn on_start(&mut self, _t0: T, _y0: &SVector<T, N>) {}

    /// Called for each accepted step (or the part of it between events).
    fn on_step<D: DenseOutput<T, N>>(&mut self, _step: &StepView<'_, T, N, D>) -> Control {
        Control::Continue
    }

    /// Whether [`on_step`](Observer::on_step) does anything (default `true`). An observer
    /// that only reads events and the outcome may return `false`; the ensemble
    /// ([`Ensemble`](crate::ensemble::Ensemble)) then need not build a lane's step for it
    /// where the step holds no event. `on_step` must then be a no-op returning
    /// [`Control::Continue`]: the drivers may still call it. The answer must not change
    /// during a run (the ensemble reads it once, when the trajectory starts).
    fn wants_steps(&self) -> bool {
        true
    }

    /// Called for each located event, after the step part that leads to it.
    fn on_event(&mut self, _event: &EventRecord<T, N>) -> Control {
        Control::Continue
    }

    /// Called by [`run_modes`] before each segment of a run through modes, with the
    /// segment's start time and its mode's name
    /// ([`ModeSystem::mode_name`]): every step and event
    /// until the next call belongs to that mode.
    fn on_mode(&mut self, _t: T, _mode: &'static str) {}

    /// Called once at the end of a successful run.
    fn on_finish(&mut self, _outcome: &Outcome<T, N>) {}
}

impl<T: Real, const N: usize> Observer<T, N> for () {
    fn wants_steps(&self) -> bool {
        false
    }
}

impl<T: Real, const N: usize, O: Observer<T, N> + ?Sized> Observer<T, N> for &mut O {
    fn check(&self) -> Result<()> {
        (**self).check()
    }
    fn check_span(&self, t0: T, t_end: T) -> Result<()> {
        (**self).check_span(t0, t_end)
    }
    fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
        (**self).on_start(t0, y0)
    }
    #[inline(always)]
    fn on_step<D: DenseOutput<T, N>>(&mut self, step: &StepView<'_, T, N, D>) -> Control {
        (**self).on_step(step)
    }
    fn wants_steps(&self) -> bool {
        (**self).wants_steps()
    }
    fn on_event(&mut self, event: &EventRecord<T, N>) -> Control {
        (**self).on_event(event)
    }
    fn on_mode(&mut self, t: T, mode: &'static str) {
        (**self).on_mode(t, mode)
    }
    fn on_finish(&mut self, outcome: &Outcome<T, N>) {
        (**self).on_finish(outcome)
    }
}

macro_rules! observer_tuple {
    ($($name:ident $idx:tt),+) => {
        impl<T: Real, const N: usize, $($name: Observer<T, N>),+> Observer<T, N> for ($($name,)+) {
            fn check(&self) -> Result<()> {
                $(self.$idx.check()?;)+
                Ok(())
            }
            fn check_span(&self, t0: T, t_end: T) -> Result<()> {
                $(self.$idx.check_span(t0, t_end)?;)+
                Ok(())
            }
            fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
                $(self.$idx.on_start(t0, y0);)+
            }
            #[inline(always)]
            fn on_step<DD: DenseOutput<T, N>>(&mut self, step: &StepView<'_, T, N, DD>) -> Control {
                let mut c = Control::Continue;
                $(if self.$idx.on_step(step) == Control::Stop { c = Control::Stop; })+
                c
            }
            fn wants_steps(&self) -> bool {
                false $(|| self.$idx.wants_steps())+
            }
            fn on_event(&mut self, event: &EventRecord<T, N>) -> Control {
                let mut c = Control::Continue;
                $(if self.$idx.on_event(event) == Control::Stop { c = Control::Stop; })+
                c
            }
            fn on_mode(&mut self, t: T, mode: &'static str) {
                $(self.$idx.on_mode(t, mode);)+
            }
            fn on_finish(&mut self, outcome: &Outcome<T, N>) {
                $(self.$idx.on_finish(outcome);)+
            }
        }
    };
}

/// An optional observer: `None` observes nothing.
impl<T: Real, const N: usize, O: Observer<T, N>> Observer<T, N> for Option<O> {
    fn check(&self) -> Result<()> {
        self.as_ref().map_or(Ok(()), |o| o.check())
    }
    fn check_span(&self, t0: T, t_end: T) -> Result<()> {
        self.as_ref().map_or(Ok(()), |o| o.check_span(t0, t_end))
    }
    fn on_mode(&mut self, t: T, mode: &'static str) {
        if let Some(o) = self {
            o.on_mode(t, mode)
        }
    }
    fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
        if let Some(o) = self {
            o.on_start(t0, y0)
        }
    }
    #[inline(always)]
    fn on_step<D: DenseOutput<T, N>>(&mut self, step: &StepView<'_, T, N, D>) -> Control {
        match self {
            Some(o) => o.on_step(step),
            None => Control::Continue,
        }
    }
    fn wants_steps(&self) -> bool {
        self.as_ref().is_some_and(|o| o.wants_steps())
    }
    fn on_event(&mut self, event: &EventRecord<T, N>) -> Control {
        match self {
            Some(o) => o.on_event(event),
            None => Control::Continue,
        }
    }
    fn on_finish(&mut self, outcome: &Outcome<T, N>) {
        if let Some(o) = self {
            o.on_finish(outcome)
        }
    }
}

observer_tuple!(A 0);
observer_tuple!(A 0, B 1);
observer_tuple!(A 0, B 1, C 2);
observer_tuple!(A 0, B 1, C 2, D 3);
observer_tuple!(A 0, B 1, C 2, D 3, E 4);
observer_tuple!(A 0, B 1, C 2, D 3, E 4, F 5);

/// A system, a stepper and a set of events.
#[derive(Debug, Clone)]
pub struct Simulation<T: Real, const N: usize, S, St, E = ()> {
    system: S,
    stepper: St,
    events: E,
    max_steps: usize,
    event_tol: T,
    zeno: ZenoGuard<T>,
    history: EventHistory<T>,
    grid: Option<(T, T)>,
}

impl<T: Real, const N: usize, S: Dynamics<T, N>, St: Stepper<T, N>> Simulation<T, N, S, St, ()> {
    /// A simulation without events; default step cap 10⁸, event time tolerance 10⁻¹²
    /// (absolute, plus 4·ε_mach·|t|), the default [`ZenoGuard`] (a geometric accumulation
    /// of events below 10⁻⁹ s; it does not depend on the run's span).
    pub fn new(system: S, stepper: St) -> Self {
        Self {
            system,
            stepper,
            events: (),
            max_steps: 100_000_000,
            event_tol: lit(1e-12),
            zeno: ZenoGuard::default(),
            history: EventHistory::new(),
            grid: None,
        }
    }
}

impl<T: Real, const N: usize, S: Dynamics<T, N>, St: Stepper<T, N>, E: EventSet<T, N>>
    Simulation<T, N, S, St, E>
{
    /// Replaces the event set (at most [`MAX_EVENTS`] events: a larger set does not
    /// compile). Event and reset indices are checked against the state dimension when a run
    /// starts.
    pub fn with_events<E2: EventSet<T, N>>(self, events: E2) -> Simulation<T, N, S, St, E2> {
        const {
            assert!(
                E2::LEN <= MAX_EVENTS,
                "a simulation takes at most MAX_EVENTS (8) events"
            )
        };
        Simulation {
            system: self.system,
            stepper: self.stepper,
            events,
            max_steps: self.max_steps,
            event_tol: self.event_tol,
            zeno: self.zeno,
            history: self.history,
            grid: self.grid,
        }
    }

    /// Caps the number of accepted steps per run.
    ///
    /// # Errors
    /// [`ParameterError`] if `max_steps == 0`.
    pub fn max_steps(mut self, max_steps: usize) -> Result<Self, ParameterError> {
        if max_steps == 0 {
            return Err(ParameterError::new("max_steps", 0.0, "> 0"));
        }
        self.max_steps = max_steps;
        Ok(self)
    }

    /// Sets the absolute event-time tolerance.
    ///
    /// # Errors
    /// [`ParameterError`] unless `tol` is finite and > 0.
    pub fn event_tolerance(mut self, tol: T) -> Result<Self, ParameterError> {
        self.event_tol = crate::validate::positive("event_tol", tol)?;
        Ok(self)
    }

    /// Sets the chatter/Zeno guard (default: [`ZenoGuard::default`]).
    pub fn zeno_guard(mut self, guard: ZenoGuard<T>) -> Self {
        self.zeno = guard;
        self
    }

    /// Makes every step land exactly on the grid `origin + i·dt` (steps are cut there;
    /// the grid is computed from `i`, never accumulated). `None` removes the grid.
    ///
    /// # Errors
    /// [`ParameterError`] unless `dt` is finite and > 0.
    pub fn landing_grid(mut self, grid: Option<(T, T)>) -> Result<Self, ParameterError> {
        if let Some((o, dt)) = grid {
            crate::validate::finite("origin", o)?;
            crate::validate::positive("dt", dt)?;
        }
        self.grid = grid;
        Ok(self)
    }

    /// The system.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// Replaces the system (e.g. another parameter value). The stepper keeps its state but
    /// drops its cached derivative.
    pub fn set_system(&mut self, system: S) {
        self.system = system;
        let (t, y) = self.stepper.current();
        let y = *y;
        self.stepper.reset_state(t, y);
    }

    /// The stepper.
    pub fn stepper(&self) -> &St {
        &self.stepper
    }

    /// The events.
    pub fn events(&self) -> &E {
        &self.events
    }

    /// Integrates from `(t0, y0)` to `t_end`, streaming to `observer`.
    ///
    /// # Errors
    /// [`IntegrateError`] for invalid inputs (non-finite state, `t_end ≤ t0`) or failed
    /// steps, [`EventError::Zeno`](crate::event::EventError::Zeno) for an accumulation of events.
    pub fn run<O: Observer<T, N>>(
        &mut self,
        t0: T,
        y0: SVector<T, N>,
        t_end: T,
        observer: &mut O,
    ) -> Result<Outcome<T, N>> {
        if !t0.is_finite() || !t_end.is_finite() || t_end <= t0 {
            return Err(IntegrateError::InvalidTimeSpan {
                t0: to_f64(t0),
                t_end: to_f64(t_end),
            }
            .into());
        }
        check_state(&y0)?;
        self.preflight(t0, t_end, observer)?;
        self.stepper.start(t0, y0);
        self.history.clear();
        observer.on_start(t0, &y0);
        self.advance(t_end, observer)
    }

    /// Continues from the stepper's current state to `t_end` (for continuation: the state and
    /// step size carry over; observers get `on_start` again).
    ///
    /// # Errors
    /// As [`run`](Self::run).
    pub fn run_on<O: Observer<T, N>>(
        &mut self,
        t_end: T,
        observer: &mut O,
    ) -> Result<Outcome<T, N>> {
        let (t0, y0) = self.stepper.current();
        let (t0, y0) = (t0, *y0);
        if !t_end.is_finite() || t_end <= t0 {
            return Err(IntegrateError::InvalidTimeSpan {
                t0: to_f64(t0),
                t_end: to_f64(t_end),
            }
            .into());
        }
        self.preflight(t0, t_end, observer)?;
        observer.on_start(t0, &y0);
        self.advance(t_end, observer)
    }

    /// The checks before a run over `[t0, t_end]`: the stepper's settings, the events' and
    /// the observer's indices and span, and the work bound.
    fn preflight<O: Observer<T, N>>(&self, t0: T, t_end: T, observer: &O) -> Result<()> {
        self.stepper.check()?;
        self.events.check()?;
        observer.check()?;
        observer.check_span(t0, t_end)?;
        self.check_work(t0, t_end)
    }

    /// The longest step the events and the system allow near `t`, if they bound it (see
    /// [`EventFunction::time_scale`](crate::event::EventFunction::time_scale) and
    /// [`Dynamics::time_scale`]).
    #[inline(always)]
    fn time_scale(&self, t: T) -> Option<T> {
        time_scale(&self.system, &self.events, t)
    }

    /// Fails at once when the run provably needs more steps than the cap: its span over the
    /// largest step it may take (the stepper's `h_max` or fixed step, the landing grid's
    /// spacing, the time scale of the events and the system).
    fn check_work(&self, t0: T, t_end: T) -> Result<()> {
        check_work(
            t0,
            t_end,
            self.stepper.max_step(),
            self.grid,
            |t| self.time_scale(t),
            self.max_steps,
        )
    }

    /// Each event's side at the current state, every event armed.
    fn initial_sides(&self) -> Result<Sides> {
        let (t, y) = self.stepper.current();
        scan::initial_sides(&self.system, &self.events, t, y)
    }

    /// The events and observer calls of the step just taken ([`scan::Scan`]): the stepper
    /// moves to where a reset, restart or stop at an event leaves the trajectory, and
    /// counts the scan's work. Returns how the run ends, if it ends here.
    fn scan_step<O: Observer<T, N>>(
        &mut self,
        sides: &mut Sides,
        observer: &mut O,
    ) -> Result<Option<Termination>> {
        let mut work = Stats::default();
        let mut restart = None;
        let out = Scan {
            system: &self.system,
            events: &self.events,
            zeno: &self.zeno,
            event_tol: self.event_tol,
            history: &mut self.history,
            dense: self.stepper.dense(),
            stats: &mut work,
            restart: &mut restart,
        }
        .scan_step(sides, observer);
        let stats = self.stepper.stats_mut();
        stats.events += work.events;
        stats.rhs_evals += work.rhs_evals;
        if let Some((t, y)) = restart {
            self.stepper.reset_state(t, y);
        }
        out
    }

    /// The driver's loop: a step to the next landing point, then the step's events and
    /// observer ([`scan_step`](Self::scan_step)), until the end, a stop or an error.
    fn advance<O: Observer<T, N>>(&mut self, t_end: T, observer: &mut O) -> Result<Outcome<T, N>> {
        let stats0 = *self.stepper.stats();
        let mut sides = self.initial_sides()?;
        let mut steps = 0usize;
        let mut termination = Termination::ReachedEnd;
        loop {
            let t_now = self.stepper.current().0;
            if t_now >= t_end {
                break;
            }
            if steps >= self.max_steps {
                return Err(IntegrateError::MaxSteps {
                    t: to_f64(t_now),
                    max_steps: self.max_steps,
                }
                .into());
            }
            let limit = step_limit(t_now, t_end, self.grid, self.time_scale(t_now));
            self.stepper.step(&self.system, limit)?;
            steps += 1;
            if let Some(t) = self.scan_step(&mut sides, observer)? {
                termination = t;
                break;
            }
        }
        let (t, y) = self.stepper.current();
        let stats = self.stepper.stats().since(&stats0);
        let out = Outcome {
            t,
            y: *y,
            termination,
            stats,
        };
        observer.on_finish(&out);
        Ok(out)
    }
}

/// The longest step the events and the system allow near `t`, if they bound it (see
/// [`EventFunction::time_scale`](crate::event::EventFunction::time_scale) and
/// [`Dynamics::time_scale`]).
#[inline(always)]
pub(crate) fn time_scale<T: Real, const N: usize, S: Dynamics<T, N>, E: EventSet<T, N>>(
    system: &S,
    events: &E,
    t: T,
) -> Option<T> {
    match (events.max_step(t), system.time_scale(t)) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// Where the step from `t` must end: the next landing point ([`landing_limit`]), sooner
/// if the time scale of the events (moving surfaces, mode conditions) or of the system
/// (constrained modes) bounds the step.
#[inline(always)]
pub(crate) fn step_limit<T: Real>(t: T, t_end: T, grid: Option<(T, T)>, scale: Option<T>) -> T {
    scaled_limit(landing_limit(t, t_end, grid), t, scale)
}

/// The step limit from `t` given the next landing point `landing` ([`step_limit`]).
#[inline(always)]
pub(crate) fn scaled_limit<T: Real>(landing: T, t: T, scale: Option<T>) -> T {
    match scale {
        Some(h) => landing.min(t + h),
        None => landing,
    }
}

/// Fails at once when a run provably needs more steps than the cap: its span over the
/// largest step it may take (the stepper's `h_max` or fixed step `h_stepper`, the landing
/// grid's spacing, the time `scale` of the events and the system at the two ends).
pub(crate) fn check_work<T: Real>(
    t0: T,
    t_end: T,
    h_stepper: Option<T>,
    grid: Option<(T, T)>,
    scale: impl Fn(T) -> Option<T>,
    max_steps: usize,
) -> Result<()> {
    let mut h = h_stepper;
    if let Some((_, dt)) = grid {
        h = Some(h.map_or(dt, |h| h.min(dt)));
    }
    // The time scale bounds every step; the larger of its values at the two ends bounds
    // it over the run when it changes monotonically (a ramp).
    if let (Some(a), Some(b)) = (scale(t0), scale(t_end)) {
        let s = a.max(b);
        h = Some(h.map_or(s, |h| h.min(s)));
    }
    let Some(h) = h else { return Ok(()) };
    let span = to_f64(t_end - t0);
    let needed = span / to_f64(h);
    // A margin of one step for the rounding of the last one.
    if !(needed <= max_steps as f64 + 1.0) {
        return Err(IntegrateError::WorkExceedsCap {
            needed,
            span,
            h: to_f64(h),
            max_steps,
        }
        .into());
    }
    Ok(())
}

/// The next landing point after `t` on the grid `origin + k·dt` (computed from `k`,
/// never accumulated; a point within rounding of `t` is skipped), capped at `t_end`;
/// `t_end` without a grid. The driver's rule, also used by the ensemble's lanes.
#[inline]
pub(crate) fn landing_limit<T: Real>(t: T, t_end: T, grid: Option<(T, T)>) -> T {
    match grid {
        Some((o, dt)) => {
            let k = ((t - o) / dt).floor() + T::one();
            let mut next = o + k * dt;
            if next
                <= t * (T::one() + lit::<T>(4.0) * T::default_epsilon()) + T::default_epsilon() * dt
            {
                next = o + (k + T::one()) * dt;
            }
            next.min(t_end)
        }
        None => t_end,
    }
}

#[cfg(test)]
mod tests {
    use super::scan::{sign_of, signed_tiny};
    use super::*;
    use crate::event::EventError;
    use crate::event::{Event, FnEvent, Level};
    use crate::integrate::{Dopri5, Rk4, Tolerances};
    use crate::testing::HarmonicOscillator;

    /// `ẍ = −x` (state `(x, ẋ)`).
    fn oscillator() -> HarmonicOscillator<f64> {
        HarmonicOscillator::new(1.0).unwrap()
    }

    fn adaptive() -> Dopri5<f64, 2> {
        Dopri5::new(Tolerances::new(1e-8, 1e-10).unwrap())
    }

    fn work_exceeds(needed: f64, span: f64, h: f64, max_steps: usize) -> RunError {
        IntegrateError::WorkExceedsCap {
            needed,
            span,
            h,
            max_steps,
        }
        .into()
    }

    #[test]
    fn landing_limit_is_t_end_without_a_grid() {
        assert_eq!(landing_limit(0.25, 7.0, None), 7.0);
    }

    #[test]
    fn landing_limit_computes_grid_points_from_their_index() {
        // The next point after t = 0.25 on 0 + k·0.1 is k = 3, computed as 3·0.1 (which
        // is 0.30000000000000004, not the accumulated 0.1 + 0.1 + 0.1).
        assert_eq!(landing_limit(0.25, 1.0, Some((0.0, 0.1))), 3.0 * 0.1);
        // Far along the grid: k = 10001, no drift.
        assert_eq!(
            landing_limit(1000.05, 2000.0, Some((0.0, 0.1))),
            10001.0 * 0.1
        );
        // An origin off zero: 1 + k·0.5.
        assert_eq!(landing_limit(1.2, 9.0, Some((1.0, 0.5))), 1.5);
        assert_eq!(landing_limit(-0.2, 9.0, Some((1.0, 0.5))), 0.0);
        // f32: the same rule.
        assert_eq!(
            landing_limit::<f32>(0.25, 1.0, Some((0.0, 0.1))),
            3.0f32 * 0.1
        );
    }

    #[test]
    fn landing_limit_skips_a_point_within_rounding_of_t() {
        // t = 0.3 lies just below 3·0.1 = 0.30000000000000004: that point is within
        // rounding of t, so the next one, 4·0.1, is the limit (no step of 4e-17 s).
        assert_eq!(landing_limit(0.3, 1.0, Some((0.0, 0.1))), 4.0 * 0.1);
        // Exactly on a grid point: the next one.
        assert_eq!(landing_limit(3.0 * 0.1, 1.0, Some((0.0, 0.1))), 4.0 * 0.1);
        assert_eq!(landing_limit(1.5, 9.0, Some((1.0, 0.5))), 2.0);
    }

    #[test]
    fn landing_limit_is_capped_at_t_end() {
        assert_eq!(landing_limit(0.25, 0.28, Some((0.0, 0.1))), 0.28);
        assert_eq!(landing_limit(0.25, 0.3, Some((0.0, 0.1))), 0.3);
    }

    #[test]
    fn sign_of_and_signed_tiny() {
        assert_eq!(sign_of(2.5), 1);
        assert_eq!(sign_of(-1e-300), -1);
        assert_eq!(sign_of(0.0), 0);
        assert_eq!(sign_of(-0.0), 0);
        assert_eq!(sign_of(f64::NAN), 0);
        assert_eq!(sign_of(f32::NEG_INFINITY), -1);
        let tiny = f64::EPSILON * f64::EPSILON;
        assert_eq!(signed_tiny::<f64>(-1), -tiny);
        assert_eq!(signed_tiny::<f64>(1), tiny);
        assert_eq!(signed_tiny::<f64>(0), tiny);
        assert_eq!(signed_tiny::<f32>(-1), -(f32::EPSILON * f32::EPSILON));
    }

    #[test]
    fn check_work_rejects_a_span_beyond_the_step_cap_of_a_fixed_step() {
        let sim = Simulation::new(oscillator(), Rk4::new(0.1).unwrap())
            .max_steps(10)
            .unwrap();
        // 2 s at h = 0.1 needs 20 steps; the cap is 10 (plus one for rounding).
        assert_eq!(
            sim.check_work(0.0, 2.0),
            Err(work_exceeds(20.0, 2.0, 0.1, 10))
        );
        // 1 s needs 10: accepted, and so is 11 (the margin of one step).
        assert_eq!(sim.check_work(0.0, 1.0), Ok(()));
        assert_eq!(sim.check_work(0.0, 1.0999999), Ok(()));
        // The same check runs before a run takes a step.
        let mut sim = sim;
        let err = sim.run(0.0, SVector::from([1.0, 0.0]), 2.0, &mut ());
        assert_eq!(err.unwrap_err(), work_exceeds(20.0, 2.0, 0.1, 10));
    }

    #[test]
    fn check_work_bounds_the_step_by_the_grid_and_the_events() {
        // An adaptive stepper without h_max is unbounded: any span passes.
        let sim = Simulation::new(oscillator(), adaptive())
            .max_steps(3)
            .unwrap();
        assert_eq!(sim.check_work(0.0, 1e9), Ok(()));
        // A landing grid bounds the step by its spacing.
        let sim = sim.landing_grid(Some((0.0, 0.5))).unwrap();
        assert_eq!(
            sim.check_work(0.0, 10.0),
            Err(work_exceeds(20.0, 10.0, 0.5, 3))
        );
        // An event's max_step bounds it too; the smaller bound counts.
        let e = Event::new(Level::new(0, 0.0).unwrap(), Direction::Either)
            .with_max_step(0.25)
            .unwrap();
        let sim = sim.with_events(e);
        assert_eq!(
            sim.check_work(0.0, 10.0),
            Err(work_exceeds(40.0, 10.0, 0.25, 3))
        );
        let sim = sim.landing_grid(None).unwrap();
        assert_eq!(sim.check_work(1.0, 1.5), Ok(()));
        assert_eq!(
            sim.check_work(0.0, 2.0),
            Err(work_exceeds(8.0, 2.0, 0.25, 3))
        );
    }

    #[test]
    fn initial_sides_of_a_start_on_a_surface_come_from_the_rate() {
        let on = |level| Event::new(Level::new(0, level).unwrap(), Direction::Either);
        let no_rate = Event::new(
            FnEvent(|_t: f64, y: &SVector<f64, 2>| y[0]),
            Direction::Either,
        );
        let mut sim = Simulation::new(oscillator(), adaptive()).with_events((
            on(0.0),
            on(1.0),
            on(-1.0),
            Event::new(Level::new(1, 0.0).unwrap(), Direction::Either),
            no_rate,
        ));
        // On x = 0 moving up (ẋ = 1): side +1, although g = 0.
        sim.stepper.reset_state(0.0, SVector::from([0.0, 1.0]));
        let sides = sim.initial_sides().unwrap();
        assert_eq!(sides.side, [1, -1, 1, 1, 0, 0, 0, 0]);
        assert_eq!(sides.armed, [true; MAX_EVENTS]);
        // On x = 0 moving down: side −1. The closure has no rate: unknown (0) until the
        // first step, whichever way the state moves.
        sim.stepper.reset_state(0.0, SVector::from([0.0, -1.0]));
        assert_eq!(
            sim.initial_sides().unwrap().side,
            [-1, -1, 1, -1, 0, 0, 0, 0]
        );
        // At rest on x = 0 and on ẋ = 0: both rates (ẋ, ẍ = −x) are 0, the sides unknown.
        sim.stepper.reset_state(0.0, SVector::from([0.0, 0.0]));
        assert_eq!(sim.initial_sides().unwrap().side, [0, -1, 1, 0, 0, 0, 0, 0]);
    }

    #[test]
    fn initial_sides_reject_a_non_finite_event_value() {
        let bad = Event::new(
            FnEvent(|_t: f64, _y: &SVector<f64, 2>| f64::NAN),
            Direction::Either,
        );
        let mut sim = Simulation::new(oscillator(), adaptive()).with_events((
            Event::new(Level::new(0, 0.0).unwrap(), Direction::Either),
            bad,
        ));
        sim.stepper.reset_state(0.5, SVector::from([1.0, 0.0]));
        match sim.initial_sides() {
            Err(RunError::Event(EventError::NonFinite { index, t, value })) => {
                assert_eq!((index, t), (1, 0.5));
                assert!(value.is_nan());
            }
            other => panic!("expected NonFinite, got {other:?}"),
        }
    }
}
