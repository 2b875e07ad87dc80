//! Chattering → sticking → release for rigid contact on a [`Gap`] of a [`Mechanical`]
//! system: a two-mode run (free flight with impacts; motion constrained to the surface).
//!
//! # Modes
//! - **Free**: the model with the impact event (`Gap`, rising) and its [`NewtonImpact`]
//!   reset. When impacts accumulate (the [`ZenoGuard`](crate::event::ZenoGuard) trips: a
//!   geometric sequence of flight times below its floor, so the accumulation point is at
//!   most `floor·r/(1−r)` ahead) or the surface catches the body after a reset
//!   ([`EventError::Sticking`]), the state is projected onto the surface (`g = 0`, `ġ = 0`,
//!   along `M⁻¹w`) and the run goes on in the sticking mode.
//! - **Sticking** ([`Constrained`]): the body moves with the surface, `w·q̈ = s̈(t)`, by the
//!   constraint force `λ·w` with
//!   $$\lambda = \frac{\ddot s - w\cdot \mathbf M^{-1} f}{w^{\mathsf T}\mathbf M^{-1}w},$$
//!   (`f` the model's generalized force) while it is compressive (`σλ ≤ 0`, `σ` the gap's
//!   sign); the release is the event `−σλ = 0` (falling), located on the dense output like
//!   any other, after which the free mode resumes from the surface.
//!
//! The result does not depend on `t_end`: a run to `t_end` passes through the same modes at
//! the same times as a longer one.
//!
//! # References
//! C. Budd, F. Dux, *Phil. Trans. R. Soc. A* 347 (1994) 365–389 (chattering and sticking in
//! impact oscillators); A. B. Nordmark, P. T. Piiroinen, *Nonlinear Dyn.* 58 (2009) 85–106.

use nalgebra::SVector;

use super::constraint::ScalarConstraint;
use super::error::Result;
use super::modes::{ModeError, ModeSystem, Segment, rate_along_flow, run_modes};
use super::{Observer, Outcome, Simulation, Termination};
use crate::event::{Direction, Event, EventError, EventFunction, Gap, NewtonImpact};
use crate::excite::Excitation;
use crate::integrate::Stepper;
use crate::model::{Elements, Loads, Mechanical, shorter};
use crate::scalar::lit;
use crate::{Dynamics, Real};

/// The motion of a [`Mechanical`] system constrained to a [`Gap`] surface (`g = 0`).
#[derive(Debug)]
pub struct Constrained<'a, T: Real, const N: usize, const M: usize, El, Ld, S> {
    model: &'a Mechanical<T, N, El, Ld>,
    gap: &'a Gap<T, N, S>,
    /// The constraint along the gap's coordinate.
    constraint: ScalarConstraint<T, N>,
    /// Baumgarte rate `α` (1/s).
    alpha: T,
}

impl<T: Real, const N: usize, const M: usize, El, Ld, S> Clone
    for Constrained<'_, T, N, M, El, Ld, S>
{
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Real, const N: usize, const M: usize, El, Ld, S> Copy
    for Constrained<'_, T, N, M, El, Ld, S>
{
}

impl<'a, T, const N: usize, const M: usize, El, Ld, S> Constrained<'a, T, N, M, El, Ld, S>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    S: Excitation<T>,
{
    /// The constrained motion of `model` on `gap`.
    pub fn new(model: &'a Mechanical<T, N, El, Ld>, gap: &'a Gap<T, N, S>) -> Self {
        let constraint = ScalarConstraint::new(model, gap.coordinate().weights());
        // Drift of the constraint (integration error) decays at rate α: four surface
        // radians per radian, or 1/s for a fixed surface.
        let alpha = EventFunction::<T, M>::time_scale(gap, T::zero()).map_or(T::one(), |h| {
            lit::<T>(4.0) * T::two_pi() / (lit::<T>(16.0) * h)
        });
        Self {
            model,
            gap,
            constraint,
            alpha,
        }
    }

    /// The shortest time scale of the model's loads and the surface's motion near `t`: the
    /// longest step of the sticking mode, whose state moves with the surface while the
    /// release condition changes with the loads.
    pub fn time_scale(&self, t: T) -> Option<T> {
        shorter(
            self.model.forcing_time_scale(t),
            EventFunction::<T, M>::time_scale(self.gap, t),
        )
    }

    /// The free acceleration `M⁻¹f` and the constraint multiplier `λ` at `(t, y)`.
    pub fn multiplier(&self, t: T, y: &SVector<T, M>) -> (SVector<T, N>, T) {
        let a = self.model.acceleration(t, y);
        let w = self.gap.coordinate().weights();
        let (q, qd) = y.as_slice().split_at(N);
        // Baumgarte stabilization: w·q̈ = s̈ − 2α(ċ − ṡ) − α²(c − s).
        let (s, sd) = self.gap.surface(t);
        let e = self.gap.coordinate().value(q) - s;
        let ed = self.gap.coordinate().rate(qd) - sd;
        let two = lit::<T>(2.0);
        let target =
            self.gap.surface_acceleration(t) - two * self.alpha * ed - self.alpha * self.alpha * e;
        let lambda = self.constraint.multiplier(w, &a, target);
        (a, lambda)
    }

    /// Projects `y` onto the surface: `g = 0` and `ġ = 0`, along `M⁻¹w`.
    pub fn project(&self, t: T, y: &mut SVector<T, M>) {
        let (s, sd) = self.gap.surface(t);
        let (q, qd) = y.as_slice().split_at(N);
        let c = self.gap.coordinate().value(q);
        let cd = self.gap.coordinate().rate(qd);
        self.constraint.shift_positions(y, s - c);
        self.constraint.shift_velocities(y, sd - cd);
    }
}

impl<T, const N: usize, const M: usize, El, Ld, S> Dynamics<T, M>
    for Constrained<'_, T, N, M, El, Ld, S>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    S: Excitation<T>,
{
    fn rhs(&self, t: T, y: &SVector<T, M>, dy: &mut SVector<T, M>) {
        let (a, lambda) = self.multiplier(t, y);
        self.constraint.rhs(y, &a, lambda, dy);
    }
    fn time_scale(&self, t: T) -> Option<T> {
        Constrained::time_scale(self, t)
    }
}

/// The release condition `−σλ` of the sticking mode (positive while the constraint force is
/// compressive; the release is its falling zero).
#[derive(Debug, Clone, Copy)]
struct Release<'a, T: Real, const N: usize, const M: usize, El, Ld, S>(
    Constrained<'a, T, N, M, El, Ld, S>,
);

impl<T, const N: usize, const M: usize, El, Ld, S> EventFunction<T, M>
    for Release<'_, T, N, M, El, Ld, S>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    S: Excitation<T>,
{
    fn value(&self, t: T, y: &SVector<T, M>) -> T {
        -self.0.gap.sign() * self.0.multiplier(t, y).1
    }
    /// Along the flow by a central difference: it shows a release and a re-catch between
    /// two step ends to the driver's grazing search.
    fn rate(&self, t: T, y: &SVector<T, M>, dy: &SVector<T, M>) -> Option<T> {
        Some(rate_along_flow(
            |s, z| self.value(s, z),
            t,
            y,
            dy,
            self.0.time_scale(t),
        ))
    }
    /// The loads' and the surface's: the release depends on time through both.
    fn time_scale(&self, t: T) -> Option<T> {
        self.0.time_scale(t)
    }
}

/// What a [`run_with_sticking`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeLog<T> {
    /// Times at which sticking began.
    pub stick: Vec<T>,
    /// Times at which the body was released.
    pub release: Vec<T>,
}

/// The modes of [`RigidContact`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactMode {
    /// Free flight with impacts.
    Free,
    /// Moving with the surface under a compressive constraint force.
    Stuck,
}

impl ContactMode {
    /// The mode's name (`"free"`, `"stuck"`), as observers see it in
    /// [`Observer::on_mode`].
    pub fn name(self) -> &'static str {
        match self {
            ContactMode::Free => "free",
            ContactMode::Stuck => "stuck",
        }
    }
}

/// The largest penetration `g` into the rigid surface a [`RigidContact`] run accepts, at a
/// start, at any step end and at [`DRIFT_SAMPLES`] interior points of each sticking step,
/// unless set with [`RigidContact::with_drift_tolerance`] (in the gap's units).
pub const DRIFT_TOLERANCE: f64 = 1e-8;

/// Interior points of each sticking step at which the penetration is checked.
pub const DRIFT_SAMPLES: usize = 4;

/// Forwards everything to the caller's observer and watches the penetration of a sticking
/// step at its end and at [`DRIFT_SAMPLES`] interior points; stops the run at the first
/// violation (kept in `violation`).
struct DriftWatch<'o, 'g, T: Real, const N: usize, const M: usize, S, O> {
    gap: &'g Gap<T, N, S>,
    tolerance: T,
    violation: Option<(T, T)>,
    inner: &'o mut O,
}

impl<T, const N: usize, const M: usize, S, O> Observer<T, M> for DriftWatch<'_, '_, T, N, M, S, O>
where
    T: Real,
    S: Excitation<T>,
    O: Observer<T, M>,
{
    fn on_start(&mut self, t0: T, y0: &SVector<T, M>) {
        self.inner.on_start(t0, y0)
    }
    fn on_step<D: crate::integrate::DenseOutput<T, M>>(
        &mut self,
        step: &super::StepView<'_, T, M, D>,
    ) -> super::Control {
        let mut y = step.y1;
        for k in 1..=DRIFT_SAMPLES + 1 {
            let t = if k == DRIFT_SAMPLES + 1 {
                step.t1
            } else {
                step.t0 + (step.t1 - step.t0) * lit::<T>(k as f64 / (DRIFT_SAMPLES + 1) as f64)
            };
            step.state_at(t, &mut y);
            let g = self.gap.penetration(t, &y.as_slice()[..N]);
            if !(g.abs() <= self.tolerance) {
                self.violation = Some((t, g));
                return super::Control::Stop;
            }
        }
        self.inner.on_step(step)
    }
    fn on_event(&mut self, event: &super::EventRecord<T, M>) -> super::Control {
        self.inner.on_event(event)
    }
}

/// Rigid contact on a [`Gap`] as a [`ModeSystem`]: free flight with Newton impacts ↔
/// sticking to the surface (see the [module docs](self)).
pub struct RigidContact<'a, T, const N: usize, const M: usize, El, Ld, S, St>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    S: Excitation<T>,
{
    constrained: Constrained<'a, T, N, M, El, Ld, S>,
    free: FreeFlight<T, N, M, El, Ld, S, St>,
    stuck: Sticking<'a, T, N, M, El, Ld, S, St>,
    tolerance: T,
}

/// The free mode's simulation: the model with its impact event.
type FreeFlight<T, const N: usize, const M: usize, El, Ld, S, St> =
    Simulation<T, M, Mechanical<T, N, El, Ld>, St, Event<Gap<T, N, S>, NewtonImpact<T, N, S>>>;

/// The sticking mode's simulation: the constrained motion with its release event.
type Sticking<'a, T, const N: usize, const M: usize, El, Ld, S, St> = Simulation<
    T,
    M,
    Constrained<'a, T, N, M, El, Ld, S>,
    St,
    Event<Release<'a, T, N, M, El, Ld, S>>,
>;

impl<'a, T, const N: usize, const M: usize, El, Ld, S, St> RigidContact<'a, T, N, M, El, Ld, S, St>
where
    T: Real,
    El: Elements<T, N> + Clone,
    Ld: Loads<T, N> + Clone,
    S: Excitation<T> + Clone,
    St: Stepper<T, M>,
{
    /// `model` with rigid impacts `impact` on `gap` (the impact's gap), each mode with a
    /// stepper made by `stepper()`.
    pub fn new<F: Fn() -> St>(
        model: &'a Mechanical<T, N, El, Ld>,
        gap: &'a Gap<T, N, S>,
        impact: &NewtonImpact<T, N, S>,
        stepper: F,
    ) -> Self {
        let constrained = Constrained::new(model, gap);
        Self {
            constrained,
            free: Simulation::new(model.clone(), stepper())
                .with_events(Event::new(gap.clone(), Direction::Rising).with_reset(impact.clone())),
            stuck: Simulation::new(constrained, stepper())
                .with_events(Event::new(Release(constrained), Direction::Falling).terminal()),
            tolerance: lit(DRIFT_TOLERANCE),
        }
    }

    /// Sets the largest penetration accepted at a start and in the sticking mode (default
    /// [`DRIFT_TOLERANCE`]).
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `tolerance` is finite and `> 0`.
    pub fn with_drift_tolerance(mut self, tolerance: T) -> Result<Self> {
        self.tolerance = crate::validate::positive("drift tolerance", tolerance)?;
        Ok(self)
    }

    /// [`ModeError::InconsistentStart`] unless `mode` can start at `(t, y)`: outside the
    /// surface (or on it to the drift tolerance) in free flight; on it, with the surface's
    /// velocity and a compressive constraint force, when stuck.
    fn check_start(&self, mode: ContactMode, t: T, y: &SVector<T, M>) -> Result<()> {
        let gap = self.constrained.gap;
        let (q, qd) = y.as_slice().split_at(N);
        let g = gap.penetration(t, q);
        let err = |quantity, value: T, requirement: String| -> Result<()> {
            Err(ModeError::inconsistent_start(mode.name(), t, quantity, value, requirement).into())
        };
        let tol = crate::scalar::to_f64(self.tolerance);
        match mode {
            ContactMode::Free if !(g <= self.tolerance) => err(
                "penetration",
                g,
                format!("at most the drift tolerance {tol:e}"),
            ),
            ContactMode::Stuck if !(g.abs() <= self.tolerance) => err(
                "penetration",
                g,
                format!("within the drift tolerance {tol:e} of 0"),
            ),
            ContactMode::Stuck if !(gap.penetration_rate(t, qd).abs() <= self.tolerance) => err(
                "penetration rate",
                gap.penetration_rate(t, qd),
                format!("within {tol:e} of 0"),
            ),
            ContactMode::Stuck if !self.compressive(t, y) => err(
                "constraint force (compressive > 0)",
                -gap.sign() * self.constrained.multiplier(t, y).1,
                "> 0".into(),
            ),
            _ => Ok(()),
        }
    }

    /// Whether the constraint force at `(t, y)` (on the surface) is compressive.
    fn compressive(&self, t: T, y: &SVector<T, M>) -> bool {
        -self.constrained.gap.sign() * self.constrained.multiplier(t, y).1 > T::zero()
    }
}

impl<T, const N: usize, const M: usize, El, Ld, S, St> ModeSystem<T, M>
    for RigidContact<'_, T, N, M, El, Ld, S, St>
where
    T: Real,
    El: Elements<T, N> + Clone,
    Ld: Loads<T, N> + Clone,
    S: Excitation<T> + Clone,
    St: Stepper<T, M>,
{
    type Mode = ContactMode;

    fn mode_name(&self, mode: ContactMode) -> &'static str {
        mode.name()
    }

    fn segment<O: Observer<T, M>>(
        &mut self,
        mode: ContactMode,
        t: T,
        y: SVector<T, M>,
        t_end: T,
        observer: &mut O,
    ) -> Result<Segment<T, M, ContactMode>> {
        self.check_start(mode, t, &y)?;
        match mode {
            ContactMode::Free => match self.free.run(t, y, t_end, observer) {
                // Free flight until t_end, an accumulation or a catch.
                Ok(outcome) => Ok(Segment {
                    outcome,
                    next: None,
                }),
                Err(super::RunError::Event(EventError::Zeno { .. }))
                | Err(super::RunError::Event(EventError::Sticking { .. })) => {
                    let (ts, ys) = self.free.stepper().current();
                    let (ts, mut ys) = (ts, *ys);
                    self.constrained.project(ts, &mut ys);
                    // Stick only while the constraint force is compressive; else fly on.
                    let next = if self.compressive(ts, &ys) {
                        ContactMode::Stuck
                    } else {
                        ContactMode::Free
                    };
                    Ok(Segment {
                        outcome: Outcome {
                            t: ts,
                            y: ys,
                            termination: Termination::TerminalEvent(0),
                            stats: *self.free.stepper().stats(),
                        },
                        next: Some(next),
                    })
                }
                Err(e) => Err(e),
            },
            ContactMode::Stuck => {
                let mut watch = DriftWatch {
                    gap: self.constrained.gap,
                    tolerance: self.tolerance,
                    violation: None,
                    inner: observer,
                };
                let outcome = self.stuck.run(t, y, t_end, &mut watch)?;
                if let Some((t, g)) = watch.violation {
                    return Err(ModeError::ConstraintDrift {
                        mode: ContactMode::Stuck.name(),
                        t: crate::scalar::to_f64(t),
                        quantity: "penetration",
                        value: crate::scalar::to_f64(g),
                        tolerance: crate::scalar::to_f64(self.tolerance),
                    }
                    .into());
                }
                let next = match outcome.termination {
                    Termination::TerminalEvent(_) => Some(ContactMode::Free),
                    _ => None,
                };
                Ok(Segment { outcome, next })
            }
        }
    }
}

/// Runs `model` with rigid impacts `impact` from `(t0, y0)` to `t_end` through chattering,
/// sticking and release (see the [module docs](self)), streaming both modes to `observer`
/// (it sees `on_start` at each mode change). `stepper()` makes a fresh stepper per mode;
/// at most `max_segments` mode segments. The same run as [`run_modes`] on a
/// [`RigidContact`] started in free flight, with the transitions split into stick and
/// release times.
///
/// # Errors
/// Integration and event errors other than the accumulation and sticking that this function
/// handles; [`EventError::Zeno`] if `max_segments` is exhausted.
#[allow(clippy::too_many_arguments)]
pub fn run_with_sticking<T, const N: usize, const M: usize, El, Ld, S, St, F, O>(
    model: &Mechanical<T, N, El, Ld>,
    impact: &NewtonImpact<T, N, S>,
    stepper: F,
    t0: T,
    y0: SVector<T, M>,
    t_end: T,
    max_segments: usize,
    observer: &mut O,
) -> Result<(Outcome<T, M>, ModeLog<T>)>
where
    T: Real,
    El: Elements<T, N> + Clone,
    Ld: Loads<T, N> + Clone,
    S: Excitation<T> + Clone,
    St: Stepper<T, M>,
    F: Fn() -> St,
    O: Observer<T, M>,
{
    let gap = impact.gap().clone();
    let mut system = RigidContact::new(model, &gap, impact, stepper);
    let run = run_modes(
        &mut system,
        ContactMode::Free,
        t0,
        y0,
        t_end,
        max_segments,
        observer,
    )?;
    let mut log = ModeLog {
        stick: Vec::new(),
        release: Vec::new(),
    };
    for (t, mode) in run.transitions {
        match mode {
            ContactMode::Stuck => log.stick.push(t),
            ContactMode::Free => log.release.push(t),
        }
    }
    Ok((run.outcome, log))
}
