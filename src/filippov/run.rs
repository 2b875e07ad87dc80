//! The event-driven run through regions and sliding: [`FilippovSimulation`], its
//! [`Settings`], the mode-aware observer ([`SlidingObserver`], [`Plain`]) and the records
//! ([`ModeTransition`], [`FilippovRun`]).

use nalgebra::SVector;

use super::error::{FilippovError, Result};
use super::field::{ModeField, band, departure, project, rates, rates_checked, scale, with_side};
use super::system::{Filippov, Mode, Region};
use crate::Real;
use crate::drive::{Control, EventRecord, Observer, Scan, StepView, Termination};
use crate::event::{EventHistory, ZenoGuard};
use crate::integrate::{DenseOutput, IntegrateError, Stats, Stepper, check_state};
use crate::scalar::{lit, to_f64};
use crate::validate::{ParameterError, positive};

/// What happened at a transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TransitionKind {
    /// The state crossed the surface into the other region (both fields point the same
    /// way through it).
    Crossing,
    /// The state reached the surface where both fields point into it and slides on it.
    SlidingEntry,
    /// The equivalent control reached a bound (`α = 0`: into `H < 0`, `α = 1`: into
    /// `H > 0`) and the state left the surface.
    SlidingExit,
    /// The state touched the surface tangentially and stays in its region (a grazing,
    /// decided by the second-order test), or the equivalent control touched a bound and
    /// sliding goes on.
    Graze,
}

/// One transition of a Filippov run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeTransition<T: Real, const N: usize, const S: usize> {
    /// Time.
    pub t: T,
    /// The state the next mode starts from (on the surface for sliding entries and exits).
    pub x: SVector<T, N>,
    /// The surface.
    pub surface: usize,
    /// What happened.
    pub kind: TransitionKind,
    /// The mode before.
    pub from: Mode<S>,
    /// The mode after.
    pub to: Mode<S>,
}

/// The result of [`FilippovSimulation::run`].
#[derive(Debug, Clone, PartialEq)]
pub struct FilippovRun<T: Real, const N: usize, const S: usize> {
    /// Final time.
    pub t: T,
    /// Final state.
    pub x: SVector<T, N>,
    /// Final mode.
    pub mode: Mode<S>,
    /// The start mode (decided from the start state, see [`FilippovSimulation::mode_at`]).
    pub start_mode: Mode<S>,
    /// Every transition, in time order.
    pub transitions: Vec<ModeTransition<T, N, S>>,
    /// Whether an observer stopped the run.
    pub stopped: bool,
    /// The largest `|H|/scale` seen while sliding, at step ends and at the interior
    /// samples of the dense output (`scale = max(1, ‖∇H‖∞·‖x‖∞)`).
    pub max_drift: T,
    /// Work done (a sliding field evaluation counts once, though it evaluates both fields).
    pub stats: Stats,
}

/// Receives the steps of a Filippov run with the mode they belong to, and its transitions.
/// All hooks have defaults; `()` observes nothing, `&mut O` is an observer, and
/// [`Plain`] adapts any [`Observer`] of the driver.
pub trait SlidingObserver<T: Real, const N: usize, const S: usize> {
    /// Called once before the first step, with the start mode.
    fn on_start(&mut self, _t0: T, _x0: &SVector<T, N>, _mode: &Mode<S>) {}
    /// Called for each accepted step (or its part up to a transition), with its mode.
    fn on_step<D: DenseOutput<T, N>>(
        &mut self,
        _mode: &Mode<S>,
        _step: &StepView<'_, T, N, D>,
    ) -> Control {
        Control::Continue
    }
    /// Called at each transition, after the step part that leads to it.
    fn on_transition(&mut self, _transition: &ModeTransition<T, N, S>) -> Control {
        Control::Continue
    }
    /// Called once at the end of a successful run.
    fn on_finish(&mut self, _run: &FilippovRun<T, N, S>) {}
}

impl<T: Real, const N: usize, const S: usize> SlidingObserver<T, N, S> for () {}

impl<T: Real, const N: usize, const S: usize, O: SlidingObserver<T, N, S> + ?Sized>
    SlidingObserver<T, N, S> for &mut O
{
    fn on_start(&mut self, t0: T, x0: &SVector<T, N>, mode: &Mode<S>) {
        (**self).on_start(t0, x0, mode)
    }
    fn on_step<D: DenseOutput<T, N>>(
        &mut self,
        mode: &Mode<S>,
        step: &StepView<'_, T, N, D>,
    ) -> Control {
        (**self).on_step(mode, step)
    }
    fn on_transition(&mut self, transition: &ModeTransition<T, N, S>) -> Control {
        (**self).on_transition(transition)
    }
    fn on_finish(&mut self, run: &FilippovRun<T, N, S>) {
        (**self).on_finish(run)
    }
}

/// Any driver [`Observer`] as a [`SlidingObserver`]: it gets the steps, `on_mode` with the
/// mode's [`name`](Mode::name) at the start and at each transition, and each transition as
/// an event (`index` = the surface, `y_after` = the state the next mode starts from).
#[derive(Debug, Clone, Default)]
pub struct Plain<O>(pub O);

impl<T: Real, const N: usize, const S: usize, O: Observer<T, N>> SlidingObserver<T, N, S>
    for Plain<O>
{
    fn on_start(&mut self, t0: T, x0: &SVector<T, N>, mode: &Mode<S>) {
        self.0.on_start(t0, x0);
        self.0.on_mode(t0, mode.name());
    }
    fn on_step<D: DenseOutput<T, N>>(
        &mut self,
        _mode: &Mode<S>,
        step: &StepView<'_, T, N, D>,
    ) -> Control {
        self.0.on_step(step)
    }
    fn on_transition(&mut self, tr: &ModeTransition<T, N, S>) -> Control {
        let record = EventRecord {
            index: tr.surface,
            t: tr.t,
            y: tr.x,
            y_after: Some(tr.x),
            direction: crate::event::Direction::Either,
        };
        let c = self.0.on_event(&record);
        if tr.from != tr.to {
            self.0.on_mode(tr.t, tr.to.name());
        }
        c
    }
    fn on_finish(&mut self, run: &FilippovRun<T, N, S>) {
        self.0.on_finish(&crate::drive::Outcome {
            t: run.t,
            y: run.x,
            termination: if run.stopped {
                Termination::ObserverStopped
            } else {
                Termination::ReachedEnd
            },
            stats: run.stats,
        });
    }
}

/// The driver's view of a [`SlidingObserver`] during one mode: steps go through with the
/// mode; surface events are reported as transitions by the run once decided.
struct WithMode<'a, O, const S: usize> {
    inner: &'a mut O,
    mode: Mode<S>,
}

impl<T: Real, const N: usize, const S: usize, O: SlidingObserver<T, N, S>> Observer<T, N>
    for WithMode<'_, O, S>
{
    #[inline(always)]
    fn on_step<D: DenseOutput<T, N>>(&mut self, step: &StepView<'_, T, N, D>) -> Control {
        self.inner.on_step(&self.mode, step)
    }
}

/// The settings of a [`FilippovSimulation`] (all relative tolerances are relative to a
/// surface's scale `max(1, ‖∇H‖∞·‖x‖∞)`, or, for the tangency, to `‖∇H‖·‖F‖`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Settings<T> {
    /// Absolute event-time tolerance (default 10⁻¹², plus 4·ε·|t|).
    pub event_tol: T,
    /// A normal rate `|∇H·F + ∂H/∂t|` below this times `‖∇H‖·‖F‖` is a tangency, decided
    /// by the second-order test where that is conclusive, else by the rate's sign (see the
    /// [module docs](super); default 10⁻⁹, at least `1000·ε`; in `(0, 1)`).
    pub tangency: T,
    /// Another surface within this (relative) of zero at an event is met at once: a
    /// codimension-2 point (default 10⁻⁹, at least `1000·ε`; in `(0, 1)`).
    pub coincidence: T,
    /// The largest relative `|H|` allowed while sliding, checked at step ends and at
    /// [`drift_samples`](Self::drift_samples) interior points of each step (default 10⁻⁹,
    /// at least `1000·ε`; in `(0, 1)`;
    /// a linear surface is held to rounding, a curved one to the local error between the
    /// projections at step ends).
    pub drift: T,
    /// Interior points per sliding step at which the drift is checked (default 3, at most
    /// [`MAX_SAMPLES`]).
    pub drift_samples: usize,
    /// Interior samples per sliding step of the exit event `min(α, 1−α)` (default 3), so
    /// that an excursion of `α` out of `[0, 1]` and back inside one step is found (at most
    /// [`MAX_SAMPLES`]).
    pub exit_samples: usize,
    /// The step cap per run (default 10⁸).
    pub max_steps: usize,
    /// The largest number of transitions at one instant before the run stops with
    /// [`FilippovError::NoProgress`] (default 16).
    pub max_stalls: usize,
}

impl<T: Real> Default for Settings<T> {
    fn default() -> Self {
        // 10⁻⁹, but not below a thousand roundings (f32).
        let rel = lit::<T>(1e-9).max(lit::<T>(1e3) * T::default_epsilon());
        Self {
            event_tol: lit(1e-12),
            tangency: rel,
            coincidence: rel,
            drift: rel,
            drift_samples: 3,
            exit_samples: 3,
            max_steps: 100_000_000,
            max_stalls: 16,
        }
    }
}

/// The largest [`Settings::drift_samples`] and [`Settings::exit_samples`]: a million
/// samples per step is far beyond any use, and the bound keeps the sample loops' counts
/// (`samples + 1` intervals) from overflowing.
pub const MAX_SAMPLES: usize = 1_000_000;

impl<T: Real> Settings<T> {
    /// Checks every setting.
    ///
    /// - `event_tol` is finite and `> 0`.
    /// - The relative tolerances `tangency`, `coincidence` and `drift` are in `(0, 1)`. At 1
    ///   and above they no longer tell anything apart: by Cauchy–Schwarz
    ///   `|∇H·F| ≤ ‖∇H‖·‖F‖`, so `tangency ≥ 1` makes every crossing of a fixed surface a
    ///   tangency (decided by the second-order test alone); `coincidence ≥ 1` or
    ///   `drift ≥ 1` accept `|H|` as large as the surface's scale
    ///   `max(1, ‖∇H‖∞·‖x‖∞)` (the size of `H` over the state itself) as "on the surface".
    /// - `drift_samples` and `exit_samples` are at most [`MAX_SAMPLES`]; `max_steps` and
    ///   `max_stalls` are `> 0`.
    ///
    /// # Errors
    /// [`ParameterError`] naming the first setting that breaks its rule, with its value.
    pub fn validate(&self) -> std::result::Result<(), ParameterError> {
        positive("event_tol", self.event_tol)?;
        for (name, value) in [
            ("tangency", self.tangency),
            ("coincidence", self.coincidence),
            ("drift", self.drift),
        ] {
            if !(value > T::zero() && value < T::one()) {
                return Err(ParameterError::new(
                    name,
                    to_f64(value),
                    "in (0, 1) (a relative tolerance)",
                ));
            }
        }
        for (name, count) in [
            ("drift_samples", self.drift_samples),
            ("exit_samples", self.exit_samples),
        ] {
            if count > MAX_SAMPLES {
                return Err(ParameterError::new(
                    name,
                    count as f64,
                    "at most MAX_SAMPLES = 10⁶",
                ));
            }
        }
        if self.max_steps == 0 {
            return Err(ParameterError::new("max_steps", 0.0, "> 0"));
        }
        if self.max_stalls == 0 {
            return Err(ParameterError::new("max_stalls", 0.0, "> 0"));
        }
        Ok(())
    }
}

/// A Filippov system and a stepper: event-driven runs through regions and sliding (see the
/// [module docs](super)).
#[derive(Debug, Clone)]
pub struct FilippovSimulation<T: Real, Sys, St> {
    system: Sys,
    stepper: St,
    settings: Settings<T>,
    zeno: ZenoGuard<T>,
}

impl<T: Real, Sys, St> FilippovSimulation<T, Sys, St> {
    /// `system` stepped by `stepper`, default [`Settings`] and [`ZenoGuard`].
    pub fn new(system: Sys, stepper: St) -> Self {
        Self {
            system,
            stepper,
            settings: Settings::default(),
            zeno: ZenoGuard::default(),
        }
    }

    /// Replaces the settings.
    ///
    /// # Errors
    /// [`ParameterError`] for an invalid setting (see [`Settings::validate`]).
    pub fn with_settings(
        mut self,
        settings: Settings<T>,
    ) -> std::result::Result<Self, ParameterError> {
        settings.validate()?;
        self.settings = settings;
        Ok(self)
    }

    /// Replaces the guard against an accumulation of transitions (Zeno).
    pub fn zeno_guard(mut self, guard: ZenoGuard<T>) -> Self {
        self.zeno = guard;
        self
    }

    /// The settings.
    pub fn settings(&self) -> &Settings<T> {
        &self.settings
    }

    /// The system.
    pub fn system(&self) -> &Sys {
        &self.system
    }

    /// The stepper.
    pub fn stepper(&self) -> &St {
        &self.stepper
    }
}

/// What to do at a surface reached from one side.
enum Arrival {
    Cross,
    Slide,
    Stay,
}

impl<T: Real, Sys, St> FilippovSimulation<T, Sys, St> {
    /// The normal rates at surface `i` and the decision there for a state arriving from
    /// `from` (`None`: a start on the surface).
    fn arrival<const N: usize, const S: usize>(
        &self,
        i: usize,
        sides: &[Region; S],
        from: Option<Region>,
        t: T,
        x: &SVector<T, N>,
    ) -> Result<Arrival>
    where
        Sys: Filippov<T, N, S>,
    {
        let r = rates_checked(&self.system, i, sides, t, x)?;
        let tang = self.settings.tangency;
        let sm = departure(&self.system, i, sides, Region::Minus, (t, x), &r, tang)?;
        let sp = departure(&self.system, i, sides, Region::Plus, (t, x), &r, tang)?;
        let repelling = || FilippovError::Repelling {
            t: to_f64(t),
            surface: i,
            rate_minus: to_f64(r.h_minus),
            rate_plus: to_f64(r.h_plus),
        };
        Ok(match from {
            // Arriving from H < 0: the minus field moves the state up (else it only
            // touched the surface and stays), the plus field decides cross or slide.
            Some(Region::Minus) => match (sm, sp) {
                (s, _) if s <= 0 => Arrival::Stay,
                (_, p) if p >= 0 => Arrival::Cross,
                _ => Arrival::Slide,
            },
            Some(Region::Plus) => match (sp, sm) {
                (s, _) if s >= 0 => Arrival::Stay,
                (_, m) if m <= 0 => Arrival::Cross,
                _ => Arrival::Slide,
            },
            None => match (sm, sp) {
                (1, -1) => Arrival::Slide,
                (-1, 1) => return Err(repelling()),
                (0, 0) => {
                    return Err(FilippovError::Degenerate {
                        t: to_f64(t),
                        surface: i,
                    });
                }
                // Both move the state the same way (or one is tangent): the side it goes.
                (m, p) if m + p > 0 => Arrival::Cross, // to Plus
                _ => Arrival::Stay,                    // to Minus
            },
        })
    }

    /// The mode a run from `(t, x)` starts in: the side of each surface from the sign of
    /// `H_i`; on a surface (within rounding), sliding if both fields point into it, else
    /// the side both move the state to (the second-order test at a tangency).
    ///
    /// # Errors
    /// [`FilippovError::NonFinite`] for a non-finite `H_i` or `∇H_i`, or, on a surface, a
    /// non-finite rate the decision reads; [`FilippovError::Codimension2`]
    /// on two surfaces at once; [`FilippovError::Repelling`] on a surface both fields leave;
    /// [`FilippovError::Degenerate`] where both are tangent to second order.
    pub fn mode_at<const N: usize, const S: usize>(
        &self,
        t: T,
        x: &SVector<T, N>,
    ) -> Result<Mode<S>>
    where
        Sys: Filippov<T, N, S>,
    {
        let mut sides = [Region::Plus; S];
        let mut on: Option<usize> = None;
        for (i, side) in sides.iter_mut().enumerate() {
            let (h, grad) = self.surface_checked(i, t, x)?;
            let tol = band::<T>() * scale(&grad, x);
            if h.abs() <= tol {
                if let Some(first) = on {
                    return Err(FilippovError::Codimension2 {
                        t: to_f64(t),
                        first,
                        second: i,
                        value: to_f64(h),
                        tolerance: to_f64(tol),
                    });
                }
                on = Some(i);
            } else {
                *side = Region::of(h);
            }
        }
        let Some(i) = on else {
            return Ok(Mode::region(sides));
        };
        Ok(match self.arrival(i, &sides, None, t, x)? {
            Arrival::Slide => Mode::sliding_on(i, with_side(&sides, i, Region::Minus)),
            Arrival::Cross => Mode::region(with_side(&sides, i, Region::Plus)),
            Arrival::Stay => Mode::region(with_side(&sides, i, Region::Minus)),
        })
    }

    /// `H_i` and `∇H_i` at `(t, x)`.
    ///
    /// # Errors
    /// [`FilippovError::NonFinite`] unless both are finite.
    fn surface_checked<const N: usize, const S: usize>(
        &self,
        i: usize,
        t: T,
        x: &SVector<T, N>,
    ) -> Result<(T, SVector<T, N>)>
    where
        Sys: Filippov<T, N, S>,
    {
        let h = self.system.surface(i, t, x);
        let grad = self.system.gradient(i, t, x);
        let bad = |quantity, value: T| FilippovError::NonFinite {
            t: to_f64(t),
            surface: i,
            quantity,
            value: to_f64(value),
        };
        if !h.is_finite() {
            return Err(bad("the value H", h));
        }
        if let Some(g) = grad.iter().find(|g| !g.is_finite()) {
            return Err(bad("the gradient ∇H", *g));
        }
        Ok((h, grad))
    }

    /// The next mode after the terminal event `k` of `mode` at `(t, x)`, with the
    /// transition's surface and kind; `x` is projected onto the surface when the next mode
    /// slides or has just left sliding.
    fn next_mode<const N: usize, const S: usize>(
        &self,
        mode: Mode<S>,
        k: usize,
        t: T,
        x: &mut SVector<T, N>,
    ) -> Result<(Mode<S>, usize, TransitionKind)>
    where
        Sys: Filippov<T, N, S>,
    {
        if let Some(i) = mode.sliding {
            if k < S {
                // Another surface met while sliding: a codimension-2 point.
                return Err(FilippovError::Codimension2 {
                    t: to_f64(t),
                    first: i,
                    second: k,
                    value: to_f64(self.system.surface(k, t, x)),
                    tolerance: to_f64(self.settings.coincidence),
                });
            }
            // α left [0, 1]: exit to the side of the bound reached, if that field moves
            // the state off the surface (second-order test at the tangency).
            let a = rates_checked(&self.system, i, &mode.sides, t, x)?.alpha();
            let slack = lit::<T>(1e3) * self.settings.tangency;
            let clearly_out = a < -slack || a > T::one() + slack;
            let target = if a < lit(0.5) {
                Region::Minus
            } else {
                Region::Plus
            };
            project(&self.system, i, t, x);
            let r2 = rates_checked(&self.system, i, &mode.sides, t, x)?;
            let s = departure(
                &self.system,
                i,
                &mode.sides,
                target,
                (t, x),
                &r2,
                self.settings.tangency,
            )?;
            if !clearly_out && (s == 0 || (s > 0) != (target == Region::Plus)) {
                return Ok((mode, i, TransitionKind::Graze));
            }
            return Ok((
                Mode::region(with_side(&mode.sides, i, target)),
                i,
                TransitionKind::SlidingExit,
            ));
        }
        // A surface reached from the mode's side: first, no other surface there.
        for j in (0..S).filter(|&j| j != k) {
            let (h, grad) = self.surface_checked(j, t, x)?;
            let tol = self.settings.coincidence * scale(&grad, x);
            if h.abs() <= tol {
                return Err(FilippovError::Codimension2 {
                    t: to_f64(t),
                    first: k,
                    second: j,
                    value: to_f64(h),
                    tolerance: to_f64(tol),
                });
            }
        }
        let from = mode.sides[k];
        Ok(match self.arrival(k, &mode.sides, Some(from), t, x)? {
            Arrival::Cross => (
                Mode::region(with_side(&mode.sides, k, from.flip())),
                k,
                TransitionKind::Crossing,
            ),
            Arrival::Slide => {
                project(&self.system, k, t, x);
                (
                    Mode::sliding_on(k, mode.sides),
                    k,
                    TransitionKind::SlidingEntry,
                )
            }
            Arrival::Stay => (mode, k, TransitionKind::Graze),
        })
    }
}

/// The bookkeeping of one [`FilippovSimulation::run`].
struct RunState<T: Real, const N: usize, const S: usize> {
    mode: Mode<S>,
    history: EventHistory<T>,
    transitions: Vec<ModeTransition<T, N, S>>,
    max_drift: T,
    steps: usize,
    stalls: usize,
}

/// How a step in a mode ended.
enum StepEnd {
    /// The mode goes on.
    Next,
    /// The run reached its end.
    End,
    /// The observer stopped the run.
    Stopped,
    /// The mode ends at surface `k` (`S`: the sliding mode's exit).
    Transition(usize),
}

impl<T: Real, Sys, St> FilippovSimulation<T, Sys, St> {
    /// Runs from `(t0, x0)` to `t_end` through crossings, sliding and exits, streaming every
    /// step with its mode and every transition to `observer`.
    ///
    /// # Errors
    /// [`FilippovError::Run`] for invalid inputs (non-finite state, `t_end ≤ t0`, invalid
    /// settings), failed steps, an accumulation of transitions or the step cap;
    /// [`FilippovError::Codimension2`] where two surfaces are met at once;
    /// [`FilippovError::Repelling`] / [`FilippovError::Degenerate`] where no side can be
    /// chosen; [`FilippovError::Drift`] if sliding leaves its surface by more than the drift
    /// tolerance; [`FilippovError::NoProgress`] if transitions repeat at one instant;
    /// [`FilippovError::NonFinite`] where a surface's value, gradient or time rate, or a
    /// rate a decision reads, is not finite.
    pub fn run<const N: usize, const S: usize, O: SlidingObserver<T, N, S>>(
        &mut self,
        t0: T,
        x0: SVector<T, N>,
        t_end: T,
        observer: &mut O,
    ) -> Result<FilippovRun<T, N, S>>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        const {
            assert!(
                S < crate::event::MAX_EVENTS,
                "at most MAX_EVENTS − 1 (7) surfaces"
            )
        };
        if !t0.is_finite() || !t_end.is_finite() || t_end <= t0 {
            return Err(IntegrateError::InvalidTimeSpan {
                t0: to_f64(t0),
                t_end: to_f64(t_end),
            }
            .into());
        }
        check_state(&x0)?;
        self.settings.validate()?;
        self.stepper.check()?;
        let start_mode = self.mode_at(t0, &x0)?;
        let mut x = x0;
        if let Some(i) = start_mode.sliding {
            project(&self.system, i, t0, &mut x);
        }
        self.stepper.start(t0, x);
        let stats0 = *self.stepper.stats();
        let mut state = RunState {
            mode: start_mode,
            history: EventHistory::new(),
            transitions: Vec::new(),
            max_drift: T::zero(),
            steps: 0,
            stalls: 0,
        };
        let mut stopped = false;
        observer.on_start(t0, &x0, &start_mode);
        'modes: loop {
            let mut sides = {
                let field = ModeField {
                    sys: &self.system,
                    mode: state.mode,
                    exit_samples: self.settings.exit_samples,
                };
                let (t, y) = self.stepper.current();
                crate::drive::initial_sides(&field, &field, t, y)?
            };
            loop {
                match self.step_in_mode(&mut sides, &mut state, t_end, observer)? {
                    StepEnd::Next => {}
                    StepEnd::End => break 'modes,
                    StepEnd::Stopped => {
                        stopped = true;
                        break 'modes;
                    }
                    StepEnd::Transition(k) => {
                        if self.transition(k, &mut state, observer)? == Control::Stop {
                            stopped = true;
                            break 'modes;
                        }
                        continue 'modes;
                    }
                }
            }
        }
        let (t, y) = self.stepper.current();
        let run = FilippovRun {
            t,
            x: *y,
            mode: state.mode,
            start_mode,
            transitions: state.transitions,
            stopped,
            max_drift: state.max_drift,
            stats: self.stepper.stats().since(&stats0),
        };
        observer.on_finish(&run);
        Ok(run)
    }

    /// One step in the current mode (the events' sides `sides`): the
    /// step, the driver's event scan with the mode's observer view, the drift check and
    /// correction while sliding, and whether the mode ends here.
    fn step_in_mode<const N: usize, const S: usize, O: SlidingObserver<T, N, S>>(
        &mut self,
        sides: &mut crate::drive::Sides,
        state: &mut RunState<T, N, S>,
        t_end: T,
        observer: &mut O,
    ) -> Result<StepEnd>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let mode = state.mode;
        let field = &ModeField {
            sys: &self.system,
            mode,
            exit_samples: self.settings.exit_samples,
        };
        let t_now = self.stepper.current().0;
        if t_now >= t_end {
            return Ok(StepEnd::End);
        }
        if state.steps >= self.settings.max_steps {
            return Err(IntegrateError::MaxSteps {
                t: to_f64(t_now),
                max_steps: self.settings.max_steps,
            }
            .into());
        }
        let limit = crate::drive::step_limit(
            t_now,
            t_end,
            None,
            crate::drive::time_scale(field, field, t_now),
        );
        self.stepper.step(field, limit)?;
        state.steps += 1;
        let mut work = Stats::default();
        let mut restart = None;
        let out = Scan {
            system: field,
            events: field,
            zeno: &self.zeno,
            event_tol: self.settings.event_tol,
            history: &mut state.history,
            dense: self.stepper.dense(),
            stats: &mut work,
            restart: &mut restart,
        }
        .scan_step(
            sides,
            &mut WithMode {
                inner: &mut *observer,
                mode,
            },
        );
        if let Some(i) = mode.sliding {
            // The surface between step ends, on the part of the step that was kept.
            let (ta, tb) = self.stepper.dense().span();
            let tb = restart.map_or(tb, |(t, _)| t);
            let d = self.drift_on_step(i, ta, tb)?;
            state.max_drift = state.max_drift.max(d);
        }
        let stats = self.stepper.stats_mut();
        stats.events += work.events;
        stats.rhs_evals += work.rhs_evals;
        if let Some((t, y)) = restart {
            self.stepper.reset_state(t, y);
        }
        Ok(match out? {
            None => match mode.sliding {
                Some(i) => self.after_sliding_step(i, &mode),
                None => StepEnd::Next,
            },
            Some(Termination::TerminalEvent(k)) => StepEnd::Transition(k),
            Some(_) => StepEnd::Stopped,
        })
    }

    /// The end of a step sliding on surface `i` without an event: the drift correction
    /// (back onto the surface), and an exit here if the equivalent control is out of
    /// `[0, 1]` (after an exit was judged a touch).
    fn after_sliding_step<const N: usize, const S: usize>(
        &mut self,
        i: usize,
        mode: &Mode<S>,
    ) -> StepEnd
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let (t, y) = self.stepper.current();
        let mut y = *y;
        let grad = self.system.gradient(i, t, &y);
        if self.system.surface(i, t, &y).abs() > band::<T>() * scale(&grad, &y) {
            project(&self.system, i, t, &mut y);
            self.stepper.reset_state(t, y);
        }
        let a = rates(&self.system, i, &mode.sides, t, &y).alpha();
        let slack = lit::<T>(1e3) * self.settings.tangency;
        if a < -slack || a > T::one() + slack {
            StepEnd::Transition(S)
        } else {
            StepEnd::Next
        }
    }

    /// The transition at the current state through surface `k` (`S`: the sliding mode's
    /// exit): the next mode, the stall guard, the record and the observer's call.
    ///
    /// # Errors
    /// [`FilippovError::NoProgress`] after [`Settings::max_stalls`] transitions at one
    /// instant; the errors of choosing the next mode.
    fn transition<const N: usize, const S: usize, O: SlidingObserver<T, N, S>>(
        &mut self,
        k: usize,
        state: &mut RunState<T, N, S>,
        observer: &mut O,
    ) -> Result<Control>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let (t, y) = self.stepper.current();
        let mut y = *y;
        let (next, surface, kind) = self.next_mode(state.mode, k, t, &mut y)?;
        let last_t = state.transitions.last().map(|tr| tr.t);
        let stall_tol = self.settings.event_tol + lit::<T>(4.0) * T::default_epsilon() * t.abs();
        if last_t.is_some_and(|lt| (t - lt).abs() <= stall_tol) {
            state.stalls += 1;
            if state.stalls >= self.settings.max_stalls {
                return Err(FilippovError::NoProgress {
                    t: to_f64(t),
                    count: state.stalls,
                    mode: next.name(),
                });
            }
        } else {
            state.stalls = 0;
        }
        let tr = ModeTransition {
            t,
            x: y,
            surface,
            kind,
            from: state.mode,
            to: next,
        };
        state.transitions.push(tr);
        self.stepper.reset_state(t, y);
        state.mode = next;
        Ok(observer.on_transition(&tr))
    }

    /// The largest relative `|H_i|` on the stepper's dense output over `[ta, tb]` (its ends
    /// and [`Settings::drift_samples`] interior points).
    ///
    /// # Errors
    /// [`FilippovError::Drift`] if it exceeds [`Settings::drift`];
    /// [`FilippovError::NonFinite`] if `H_i` or `∇H_i` is not finite at a sample.
    fn drift_on_step<const N: usize, const S: usize>(&self, i: usize, ta: T, tb: T) -> Result<T>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let dense = self.stepper.dense();
        let n = self.settings.drift_samples + 1;
        let mut worst = T::zero();
        let mut y = SVector::zeros();
        for k in 0..=n {
            let t = ta + (tb - ta) * lit::<T>(k as f64) / lit::<T>(n as f64);
            dense.interpolate_unchecked(t, &mut y);
            let h = self.system.surface(i, t, &y);
            let rel = h.abs() / scale(&self.system.gradient(i, t, &y), &y);
            if !(rel <= self.settings.drift) {
                // Not finite is not a drift: check H and ∇H here, off the common path.
                self.surface_checked(i, t, &y)?;
                return Err(FilippovError::Drift {
                    t: to_f64(t),
                    surface: i,
                    value: to_f64(h.abs()),
                    tolerance: to_f64(
                        self.settings.drift * scale(&self.system.gradient(i, t, &y), &y),
                    ),
                });
            }
            worst = worst.max(rel);
        }
        Ok(worst)
    }
}
