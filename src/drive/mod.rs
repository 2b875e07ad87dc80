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
//! use nonsmooth::systems::paper::PAPER;
//! use nalgebra::Vector2;
//!
//! // The paper's oscillator at ω = 20.465 rad/s from rest, impacts = upward crossings of x_I.
//! let osc = PAPER.oscillator::<f64>(20.465)?;
//! let impact = Event::new(Level::new(0, PAPER.x_i)?, Direction::Rising);
//! let tol = Tolerances::per_component(1e-8, [1e-12, 1e-10])?;
//! let mut sim = Simulation::new(osc, Dopri5::new(tol)).with_events(impact);
//! let x0 = PAPER.static_equilibrium()?;
//! let out = sim.run(0.0, Vector2::new(x0, 0.0), 3.0, &mut ())?;
//! assert_eq!(out.termination, Termination::ReachedEnd);
//! # Ok::<(), nonsmooth::Error>(())
//! ```

use nalgebra::SVector;

mod error;
pub mod modes;
pub mod stick_slip;
pub mod sticking;

pub(crate) use error::from_engine_errors;
pub use error::{ModeError, RunError};
pub use modes::{ModeRun, ModeSystem, Segment, run_modes};
pub use stick_slip::{Coulomb, SlipMode, StickSlip};
pub use sticking::{Constrained, ContactMode, ModeLog, RigidContact, run_with_sticking};

use crate::event::{Direction, EventError, EventHistory, EventSet, MAX_EVENTS, ZenoGuard, locate};
use crate::integrate::{DenseOutput, IntegrateError, Stats, Stepper, check_state};
use crate::scalar::{lit, to_f64};
use crate::validate::ParameterError;
use crate::{Dynamics, Real};
use error::Result;

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

impl<T: Real, const N: usize, D: DenseOutput<T, N>> StepView<'_, T, N, D> {
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
    /// Whatever the observer finds wrong (typically [`EventError::IndexOutOfRange`]).
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

impl<T: Real, const N: usize> Observer<T, N> for () {}

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
    /// steps, [`EventError::Zeno`] for an accumulation of events.
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
        self.stepper.reset_state(t0, y0);
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
        match (self.events.max_step(t), self.system.time_scale(t)) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Fails at once when the run provably needs more steps than the cap: its span over the
    /// largest step it may take (the stepper's `h_max` or fixed step, the landing grid's
    /// spacing, the time scale of the events and the system).
    fn check_work(&self, t0: T, t_end: T) -> Result<()> {
        let mut h = self.stepper.max_step();
        if let Some((_, dt)) = self.grid {
            h = Some(h.map_or(dt, |h| h.min(dt)));
        }
        // The time scale bounds every step; the larger of its values at the two ends bounds
        // it over the run when it changes monotonically (a ramp).
        if let (Some(a), Some(b)) = (self.time_scale(t0), self.time_scale(t_end)) {
            let s = a.max(b);
            h = Some(h.map_or(s, |h| h.min(s)));
        }
        let Some(h) = h else { return Ok(()) };
        let span = to_f64(t_end - t0);
        let needed = span / to_f64(h);
        // A margin of one step for the rounding of the last one.
        if !(needed <= self.max_steps as f64 + 1.0) {
            return Err(IntegrateError::WorkExceedsCap {
                needed,
                span,
                h: to_f64(h),
                max_steps: self.max_steps,
            }
            .into());
        }
        Ok(())
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
            let limit = landing_limit(t_now, t_end, self.grid);
            // The time scales of the events (moving surfaces, mode conditions) and of the
            // system (constrained modes) bound the step.
            let limit = match self.time_scale(t_now) {
                Some(h) => limit.min(t_now + h),
                None => limit,
            };
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

    /// Each event's side at the current state, every event armed.
    fn initial_sides(&self) -> Result<Sides> {
        let mut sides = Sides {
            side: [0; MAX_EVENTS],
            armed: [true; MAX_EVENTS],
        };
        let (t, y) = self.stepper.current();
        let mut f = SVector::zeros();
        let mut have_f = false;
        for (i, s) in sides.side.iter_mut().enumerate().take(E::LEN) {
            let g = self.events.value(i, t, y);
            if !g.is_finite() {
                return Err(non_finite(i, t, g));
            }
            *s = sign_of(g);
            if *s == 0 {
                // Start on the surface: it has not been crossed; the side is the one
                // the trajectory moves to (from the rate, else from the first step).
                if !have_f {
                    self.system.rhs(t, y, &mut f);
                    have_f = true;
                }
                if let Some(r) = self.events.rate(i, t, y, &f) {
                    *s = sign_of(r);
                }
            }
        }
        Ok(sides)
    }

    /// The events and observer calls of the step just taken: its crossings in time order
    /// ([`crossings`](Self::crossings)), the sticking check, then the observer's view of
    /// the rest of the step. Returns how the run ends, if it ends here.
    fn scan_step<O: Observer<T, N>>(
        &mut self,
        sides: &mut Sides,
        observer: &mut O,
    ) -> Result<Option<Termination>> {
        let mut scan = self.start_scan(sides)?;
        let (t_lo, y_lo) = match self.crossings(&mut scan, sides, observer)? {
            Crossings::Through(t_lo, y_lo) => (t_lo, y_lo),
            // The state was reset or cut at an event: the next step starts there.
            Crossings::Cut => return Ok(None),
            Crossings::End(t) => return Ok(Some(t)),
        };
        self.check_sticking(&scan, sides, t_lo, y_lo, observer)?;
        let dense = self.stepper.dense();
        let view = StepView {
            t0: t_lo,
            t1: scan.t1,
            y0: y_lo,
            y1: scan.y1,
            dense,
        };
        let stop = observer.on_step(&view) == Control::Stop;
        for (i, s) in sides.side.iter_mut().enumerate().take(E::LEN) {
            if scan.g_end[i] != T::zero() {
                *s = sign_of(scan.g_end[i]);
            }
        }
        Ok(stop.then_some(Termination::ObserverStopped))
    }

    /// Every event's values and rates at both ends of the step and its first crossing.
    fn start_scan(&self, sides: &mut Sides) -> Result<StepScan<T, N>> {
        let dense = self.stepper.dense();
        let (ts0, ts1) = dense.span();
        let (y_start, y_end) = dense.endpoints();
        let (f_start, f_end) = dense.end_derivatives();
        let (y_start, y_end, f_start, f_end) = (*y_start, *y_end, *f_start, *f_end);
        let mut scan = StepScan {
            t0: ts0,
            t1: ts1,
            y0: y_start,
            y1: y_end,
            g_end: [T::zero(); MAX_EVENTS],
            r_end: [None; MAX_EVENTS],
            found: [None; MAX_EVENTS],
        };
        for i in 0..E::LEN {
            let g0 = self.events.value(i, ts0, &y_start);
            let ge = self.events.value(i, ts1, &y_end);
            scan.g_end[i] = ge;
            if !(g0.is_finite() && ge.is_finite()) {
                let (t, g) = if g0.is_finite() { (ts1, ge) } else { (ts0, g0) };
                return Err(non_finite(i, t, g));
            }
            if sides.side[i] == 0 {
                // Started on the surface with no rate: the side is where it goes.
                sides.side[i] = if ge != T::zero() { sign_of(ge) } else { 1 };
            }
            let st_g = if g0 == T::zero() {
                signed_tiny(sides.side[i])
            } else {
                g0
            };
            let st_r = self.events.rate(i, ts0, &y_start, &f_start);
            scan.r_end[i] = self.events.rate(i, ts1, &y_end, &f_end);
            scan.found[i] = self.find_crossing(i, ts0, st_g, st_r, ts1, ge, scan.r_end[i]);
        }
        Ok(scan)
    }

    /// The step's crossings, earliest first: the observer's view up to each accepted one,
    /// its record, its reset (which ends the step there), a restart, a terminal event or
    /// an observer's stop. Returns where the step's last piece starts if it goes on to the
    /// step's end.
    fn crossings<O: Observer<T, N>>(
        &mut self,
        scan: &mut StepScan<T, N>,
        sides: &mut Sides,
        observer: &mut O,
    ) -> Result<Crossings<T, N>> {
        let n_ev = E::LEN;
        let mut t_lo = scan.t0;
        let mut y_lo = scan.y0;
        loop {
            let mut best: Option<(usize, Crossing<T>)> = None;
            for (i, f) in scan.found.iter().enumerate().take(n_ev) {
                if let Some(c) = f {
                    if best.is_none_or(|(_, b)| c.t < b.t) {
                        best = Some((i, *c));
                    }
                }
            }
            let Some((i, c)) = best else {
                return Ok(Crossings::Through(t_lo, y_lo));
            };
            // Where the scan of event i resumes (None: no further crossing this step).
            scan.found[i] = match c.resume {
                Some((tr, gr)) => {
                    self.find_crossing(i, tr, gr, None, scan.t1, scan.g_end[i], scan.r_end[i])
                }
                None => None,
            };
            let was_armed = sides.armed[i];
            sides.armed[i] = true;
            sides.side[i] = if c.rising { 1 } else { -1 };
            if !was_armed || !self.events.direction(i).accepts(c.rising) {
                // Re-arming crossing (the exit after a reset) or an unwanted direction.
                continue;
            }
            let tc = c.t;
            let dense = self.stepper.dense();
            let mut yc = SVector::zeros();
            dense.interpolate_unchecked(tc, &mut yc);
            let view = StepView {
                t0: t_lo,
                t1: tc,
                y0: y_lo,
                y1: yc,
                dense,
            };
            let stop_obs = observer.on_step(&view) == Control::Stop;
            let direction = if c.rising {
                Direction::Rising
            } else {
                Direction::Falling
            };
            self.stepper.stats_mut().events += 1;
            if let Some((count, last)) = self.history.push(tc, &self.zeno) {
                // Leave the simulation at the event (after its reset) so that the
                // caller can change the model and continue from there.
                let mut ya = yc;
                if self.events.resets(i) {
                    self.events.apply_reset(i, tc, &mut ya);
                }
                self.stepper.reset_state(tc, ya);
                return Err(EventError::Zeno {
                    t: to_f64(tc),
                    count,
                    last_interval: to_f64(last),
                    state: ya.iter().map(|&v| to_f64(v)).collect(),
                }
                .into());
            }
            let terminal = self.events.is_terminal(i);
            if self.events.resets(i) {
                // An impact moves into the surface. A located crossing where the rate does
                // not (the far end of a bracket past the top of a graze of zero normal
                // velocity: the arrival of a chattering sequence) is no impact: the body
                // stays on the surface, reported as sticking, not as an event.
                let mut fc = SVector::zeros();
                self.system.rhs(tc, &yc, &mut fc);
                self.stepper.stats_mut().rhs_evals += 1;
                let into = if c.rising { T::one() } else { -T::one() };
                if let Some(r) = self.events.rate(i, tc, &yc, &fc) {
                    if !(into * r > T::zero()) {
                        self.stepper.stats_mut().events -= 1;
                        self.stepper.reset_state(tc, yc);
                        return Err(EventError::Sticking {
                            index: i,
                            t: to_f64(tc),
                            depth: to_f64(self.events.value(i, tc, &yc).abs()),
                            state: yc.iter().map(|&v| to_f64(v)).collect(),
                        }
                        .into());
                    }
                }
                let mut ya = yc;
                self.events.apply_reset(i, tc, &mut ya);
                let rec = EventRecord {
                    index: i,
                    t: tc,
                    y: yc,
                    y_after: Some(ya),
                    direction,
                };
                let stop_ev = observer.on_event(&rec) == Control::Stop;
                self.stepper.reset_state(tc, ya);
                self.after_reset(i, tc, &ya, sides);
                return Ok(if terminal {
                    Crossings::End(Termination::TerminalEvent(i))
                } else if stop_obs || stop_ev {
                    Crossings::End(Termination::ObserverStopped)
                } else {
                    Crossings::Cut
                });
            }
            let rec = EventRecord {
                index: i,
                t: tc,
                y: yc,
                y_after: None,
                direction,
            };
            let stop_ev = observer.on_event(&rec) == Control::Stop;
            if self.events.restarts(i) && !(terminal || stop_obs || stop_ev) {
                // A switching point: cut the step here and start the next one on it.
                self.stepper.reset_state(tc, yc);
                return Ok(Crossings::Cut);
            }
            if terminal || stop_obs || stop_ev {
                // Rewind the stepper to the event.
                self.stepper.reset_state(tc, yc);
                return Ok(Crossings::End(if terminal {
                    Termination::TerminalEvent(i)
                } else {
                    Termination::ObserverStopped
                }));
            }
            t_lo = tc;
            y_lo = yc;
        }
    }

    /// The sides after event `i`'s reset to `ya` at `tc`; event `i` is disarmed if the
    /// reset left the state on the far side while moving back out.
    fn after_reset(&mut self, i: usize, tc: T, ya: &SVector<T, N>, sides: &mut Sides) {
        let mut fa = SVector::zeros();
        self.system.rhs(tc, ya, &mut fa);
        self.stepper.stats_mut().rhs_evals += 1;
        for (j, s) in sides.side.iter_mut().enumerate().take(E::LEN) {
            let g = self.events.value(j, tc, ya);
            if g != T::zero() {
                *s = sign_of(g);
            }
            if j == i {
                // Left on the far side but moving back out: disarmed until it has
                // crossed back.
                let r = self.events.rate(j, tc, ya, &fa).unwrap_or(T::zero());
                sides.armed[j] = !(g != T::zero() && r != T::zero() && sign_of(g) != sign_of(r));
                if g == T::zero() && r != T::zero() {
                    *s = sign_of(r);
                }
            }
        }
    }

    /// Sticking: an event disarmed after a reset (or an impact event on its far side),
    /// still on the far side at the step end and moving deeper again, never left the
    /// surface: the reset could not separate the trajectory from it. Never silent: stops
    /// where it turned (the extremum of g on the dense output), with the state to go on
    /// from, and an [`EventError::Sticking`].
    fn check_sticking<O: Observer<T, N>>(
        &mut self,
        scan: &StepScan<T, N>,
        sides: &Sides,
        t_lo: T,
        y_lo: SVector<T, N>,
        observer: &mut O,
    ) -> Result<()> {
        for i in 0..E::LEN {
            // For an impact (a resetting event with a direction) the far side is the
            // wrong side at any step end: its crossings are reset away from it.
            let wrong_side = match self.events.direction(i) {
                Direction::Rising => 1,
                Direction::Falling => -1,
                Direction::Either => 0,
            };
            let (ge, re) = (scan.g_end[i], scan.r_end[i]);
            let stuck = !sides.armed[i] || (self.events.resets(i) && sign_of(ge) == wrong_side);
            if !(stuck
                && ge != T::zero()
                && re.is_some_and(|r| r != T::zero() && sign_of(r) == sign_of(ge)))
            {
                continue;
            }
            let dense = self.stepper.dense();
            let tol = self
                .event_tol
                .max(lit::<T>(4.0) * T::default_epsilon() * scan.t1.abs());
            let sg = if ge > T::zero() { T::one() } else { -T::one() };
            let events = &self.events;
            let (te, _) = crate::roots::golden_max(
                |t| {
                    let mut y = SVector::<T, N>::zeros();
                    dense.interpolate_unchecked(t, &mut y);
                    -sg * events.value(i, t, &y)
                },
                t_lo,
                scan.t1,
                tol,
            );
            let mut ye = SVector::zeros();
            dense.interpolate_unchecked(te, &mut ye);
            let view = StepView {
                t0: t_lo,
                t1: te,
                y0: y_lo,
                y1: ye,
                dense,
            };
            observer.on_step(&view);
            let depth = self.events.value(i, te, &ye).abs();
            self.stepper.reset_state(te, ye);
            return Err(EventError::Sticking {
                index: i,
                t: to_f64(te),
                depth: to_f64(depth),
                state: ye.iter().map(|&v| to_f64(v)).collect(),
            }
            .into());
        }
        Ok(())
    }

    /// The earliest crossing (any direction) of event `i` in `(t_lo, t1]`, starting from
    /// `g_lo ≠ 0` (rate `r_lo` if known) and ending at `g1` (rate `r1`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn find_crossing(
        &self,
        i: usize,
        t_lo: T,
        g_lo: T,
        r_lo: Option<T>,
        t1: T,
        g1: T,
        r1: Option<T>,
    ) -> Option<Crossing<T>> {
        let ev = &self.events;
        let dense = self.stepper.dense();
        let tol = self
            .event_tol
            .max(lit::<T>(4.0) * T::default_epsilon() * t1.abs());
        let g_at = |t: T| {
            let mut y = SVector::<T, N>::zeros();
            dense.interpolate_unchecked(t, &mut y);
            ev.value(i, t, &y)
        };
        // Interior samples (grazing safety for functions without a rate).
        let k = ev.interior_samples(i);
        if k > 0 {
            let mut ta = t_lo;
            let mut ga = g_lo;
            for m in 1..=(k + 1) {
                let (tb, gb) = if m == k + 1 {
                    (t1, g1)
                } else {
                    let tb = t_lo + (t1 - t_lo) * lit::<T>(m as f64 / (k as f64 + 1.0));
                    (tb, g_at(tb))
                };
                if !gb.is_finite() {
                    // Not a crossing (the step ends are checked to be finite).
                    continue;
                }
                if gb != T::zero() && sign_of(gb) != sign_of(ga) {
                    let (tc, _) = locate(g_at, ta, tb, ga, gb, tol);
                    let resume = if m == k + 1 { None } else { Some((tb, gb)) };
                    return Some(Crossing {
                        t: tc,
                        rising: gb > T::zero(),
                        resume,
                    });
                }
                if gb != T::zero() {
                    ta = tb;
                    ga = gb;
                }
            }
            return None;
        }
        let rate_lo = || {
            r_lo.or_else(|| {
                let mut y = SVector::zeros();
                dense.interpolate_unchecked(t_lo, &mut y);
                let mut f = SVector::zeros();
                self.system.rhs(t_lo, &y, &mut f);
                ev.rate(i, t_lo, &y, &f)
            })
        };
        crossing_between(g_at, rate_lo, tol, t_lo, g_lo, t1, g1, r1)
    }
}

/// The earliest crossing of `g` (its value on the step's dense output: `g_at`) in
/// `(t_lo, t1]`, from `g_lo ≠ 0` to `g1` with the rate `r1` at `t1`: a sign change of the
/// ends, located by the bracketing solver; else, with the same sign at both ends (or
/// `g1 = 0`), a grazing pair when the rates show an interior extremum that reaches the
/// other side (`rate_lo`, the rate at `t_lo`, is evaluated only then): the extremum by
/// golden-section search, the crossing before it, and the extremum as where the scan
/// resumes. The ensemble's lanes run the same search written for `f64`
/// (`ensemble::engine::find_crossing`): through this generic function their throughput
/// was 3–4 % lower (same machine, alternating runs), and their events are tested equal to
/// the driver's bit for bit.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn crossing_between<T: Real>(
    g_at: impl Fn(T) -> T + Copy,
    rate_lo: impl FnOnce() -> Option<T>,
    tol: T,
    t_lo: T,
    g_lo: T,
    t1: T,
    g1: T,
    r1: Option<T>,
) -> Option<Crossing<T>> {
    let s = sign_of(g_lo);
    if g1 != T::zero() && sign_of(g1) != s {
        let (tc, _) = locate(g_at, t_lo, t1, g_lo, g1, tol);
        return Some(Crossing {
            t: tc,
            rising: g1 > T::zero(),
            resume: None,
        });
    }
    let (Some(r_lo), Some(r1)) = (rate_lo(), r1) else {
        return None;
    };
    let towards = if s > 0 {
        r_lo < T::zero()
    } else {
        r_lo > T::zero()
    };
    let away = if s > 0 {
        r1 > T::zero()
    } else {
        r1 < T::zero()
    };
    if !(towards && (away || g1 == T::zero())) {
        return None;
    }
    let sg = if s > 0 { T::one() } else { -T::one() };
    let (te, neg) = crate::roots::golden_max(|t| -sg * g_at(t), t_lo, t1, tol);
    let ge = -neg * sg;
    if ge == T::zero() || sign_of(ge) == s {
        return None;
    }
    let (tc, _) = locate(g_at, t_lo, te, g_lo, ge, tol);
    Some(Crossing {
        t: tc,
        rising: ge > T::zero(),
        resume: Some((te, ge)),
    })
}

fn non_finite<T: Real>(index: usize, t: T, g: T) -> RunError {
    EventError::NonFinite {
        index,
        t: to_f64(t),
        value: to_f64(g),
    }
    .into()
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

/// Each event's side of its surface (+1/−1; 0 = not known yet, for a start exactly on it,
/// used when g is exactly zero at a step boundary) and whether it is armed (false right
/// after a reset that left the state on the far side while moving back out). Carried
/// from step to step.
#[derive(Debug, Clone, Copy)]
struct Sides {
    side: [i8; MAX_EVENTS],
    armed: [bool; MAX_EVENTS],
}

/// One step's event data: its ends, each event's value and rate at the end, and the next
/// crossing found for each (cached while earlier crossings are handled).
#[derive(Debug, Clone, Copy)]
struct StepScan<T: Real, const N: usize> {
    t0: T,
    t1: T,
    y0: SVector<T, N>,
    y1: SVector<T, N>,
    g_end: [T; MAX_EVENTS],
    r_end: [Option<T>; MAX_EVENTS],
    found: [Option<Crossing<T>>; MAX_EVENTS],
}

/// How a step's crossings ended.
enum Crossings<T: Real, const N: usize> {
    /// No crossing stopped the step: its last piece starts at this time and state.
    Through(T, SVector<T, N>),
    /// The state was reset or restarted at an event: the next step starts there.
    Cut,
    /// The run ends.
    End(Termination),
}

/// A crossing found on a step.
#[derive(Debug, Clone, Copy)]
struct Crossing<T> {
    t: T,
    rising: bool,
    /// Where to resume scanning this event after it (`None`: nothing more this step).
    resume: Option<(T, T)>,
}

#[inline(always)]
fn signed_tiny<T: Real>(side: i8) -> T {
    let tiny = T::default_epsilon() * T::default_epsilon();
    if side < 0 { -tiny } else { tiny }
}

#[inline(always)]
fn sign_of<T: Real>(x: T) -> i8 {
    if x > T::zero() {
        1
    } else if x < T::zero() {
        -1
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
