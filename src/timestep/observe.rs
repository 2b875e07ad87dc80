//! What a time-stepping run reports: per-step records (state, energies, the active contacts
//! with their impulses), observers of them, and an impact log built from the impulses.

use nalgebra::SVector;

use crate::Real;
use crate::drive::{Control, EventRecord, Observer, Outcome, RunError, StepView, Termination};
use crate::event::Direction;
use crate::integrate::{DenseOutput, Stats};
use crate::scalar::to_f64;

use super::lcp::LcpReport;

/// One active contact of a step (its predicted gap was ≤ 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRecord<T> {
    /// The contact's index in the contact set.
    pub index: usize,
    /// The gap at the step's start.
    pub gap: T,
    /// The normal relative velocity `ġ⁻` at the step's start.
    pub pre: T,
    /// The normal relative velocity `ġ⁺` at the step's end.
    pub post: T,
    /// The normal relative velocity the step would end with without contact impulses.
    pub free: T,
    /// The tangential relative velocity at the step's end.
    pub slip: T,
    /// The tangential relative velocity without contact impulses.
    pub free_slip: T,
    /// The normal impulse `p_n ≥ 0` over the step.
    pub normal_impulse: T,
    /// The tangential (friction) impulse `p_t`, `|p_t| ≤ μ p_n`.
    pub tangent_impulse: T,
}

impl<T: Real> ContactRecord<T> {
    /// `true` if the contact was struck in this step: a positive normal impulse with the
    /// contact approaching faster than `speed` at the step's start (`ġ⁻ < −speed`). A
    /// persistent (resting) contact carries an impulse with `ġ⁻ ≈ 0`.
    pub fn is_impact(&self, speed: T) -> bool {
        self.normal_impulse > T::zero() && self.pre < -speed
    }
}

/// The energies at a step's end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy<T> {
    /// `½ q̇ᵀ M q̇`.
    pub kinetic: T,
    /// [`Lagrangian::potential`](super::Lagrangian::potential).
    pub potential: T,
    /// The work of the step's contact impulses on the kinetic energy,
    /// `½ pᵀ H (q̇⁺ + q̇_free)` (≤ 0: dissipated by impacts and friction; 0 for elastic
    /// impacts, for which `ġ⁺ = −ġ_free`).
    pub impulse_work: T,
}

impl<T: Real> Energy<T> {
    /// Kinetic plus potential energy.
    pub fn total(&self) -> T {
        self.kinetic + self.potential
    }
}

/// One completed step `[t0, t1]`.
#[derive(Debug, Clone, Copy)]
pub struct StepRecord<'a, T> {
    /// The step's index (from 0).
    pub step: usize,
    /// Start time.
    pub t0: T,
    /// End time.
    pub t1: T,
    /// Positions at `t1`.
    pub q: &'a [T],
    /// Velocities at `t1`.
    pub v: &'a [T],
    /// Energies at `t1`.
    pub energy: Energy<T>,
    /// The active contacts of the step, with their impulses.
    pub contacts: &'a [ContactRecord<T>],
    /// The contact solver's iterations and residual (0 and 0 without active contacts).
    pub solver: LcpReport,
}

/// A run's totals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Steps completed.
    pub steps: usize,
    /// The final time.
    pub t: f64,
    /// `true` if an observer stopped the run.
    pub stopped: bool,
    /// The largest complementarity residual of the steps.
    pub max_residual: f64,
    /// The solver's iterations (pivots or sweeps) summed over the steps.
    pub solver_iterations: usize,
    /// The largest number of simultaneously active contacts.
    pub max_active: usize,
}

/// Receives the steps of a time-stepping run. Every hook has a default; `()` is the no-op
/// observer, and `&mut O` and pairs `(A, B)` are observers.
///
/// # Examples
/// The lowest kinetic energy seen:
/// ```
/// use nonsmooth::drive::Control;
/// use nonsmooth::timestep::{StepObserver, StepRecord};
/// struct Lowest(f64);
/// impl StepObserver<f64> for Lowest {
///     fn on_step(&mut self, s: &StepRecord<'_, f64>) -> Control {
///         self.0 = self.0.min(s.energy.kinetic);
///         Control::Continue
///     }
/// }
/// ```
pub trait StepObserver<T: Real> {
    /// Before the first step, with the initial state.
    fn on_start(&mut self, _t0: T, _q: &[T], _v: &[T]) {}
    /// After each step; [`Control::Stop`] ends the run.
    fn on_step(&mut self, _step: &StepRecord<'_, T>) -> Control {
        Control::Continue
    }
    /// After the last step of a run that did not fail.
    fn on_finish(&mut self, _summary: &Summary) {}
}

impl<T: Real> StepObserver<T> for () {}

impl<T: Real, O: StepObserver<T> + ?Sized> StepObserver<T> for &mut O {
    fn on_start(&mut self, t0: T, q: &[T], v: &[T]) {
        (**self).on_start(t0, q, v)
    }
    fn on_step(&mut self, step: &StepRecord<'_, T>) -> Control {
        (**self).on_step(step)
    }
    fn on_finish(&mut self, summary: &Summary) {
        (**self).on_finish(summary)
    }
}

impl<T: Real, A: StepObserver<T>, B: StepObserver<T>> StepObserver<T> for (A, B) {
    fn on_start(&mut self, t0: T, q: &[T], v: &[T]) {
        self.0.on_start(t0, q, v);
        self.1.on_start(t0, q, v);
    }
    fn on_step(&mut self, step: &StepRecord<'_, T>) -> Control {
        let a = self.0.on_step(step);
        let b = self.1.on_step(step);
        if a == Control::Stop || b == Control::Stop {
            Control::Stop
        } else {
            Control::Continue
        }
    }
    fn on_finish(&mut self, summary: &Summary) {
        self.0.on_finish(summary);
        self.1.on_finish(summary);
    }
}

/// An impact found from the impulses: contact `contact` struck during the step `[t0, t1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepImpact {
    /// The step's start.
    pub t0: f64,
    /// The step's end.
    pub t1: f64,
    /// The contact.
    pub contact: usize,
    /// The normal relative velocity before (`ġ⁻ < 0`).
    pub pre: f64,
    /// The normal relative velocity after.
    pub post: f64,
    /// The normal impulse.
    pub impulse: f64,
}

/// Records every [`StepImpact`] (a step in which a contact carries an impulse while approaching
/// faster than `speed`, see [`ContactRecord::is_impact`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactLog<T> {
    speed: T,
    /// The impacts in time order.
    pub impacts: Vec<StepImpact>,
}

impl<T: Real> ImpactLog<T> {
    /// A log of impacts faster than `speed ≥ 0`.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `speed` is finite and ≥ 0.
    pub fn new(speed: T) -> Result<Self, crate::ParameterError> {
        Ok(Self {
            speed: crate::validate::non_negative("speed", speed)?,
            impacts: Vec::new(),
        })
    }
}

impl<T: Real> StepObserver<T> for ImpactLog<T> {
    fn on_step(&mut self, s: &StepRecord<'_, T>) -> Control {
        for c in s.contacts {
            if c.is_impact(self.speed) {
                self.impacts.push(StepImpact {
                    t0: to_f64(s.t0),
                    t1: to_f64(s.t1),
                    contact: c.index,
                    pre: to_f64(c.pre),
                    post: to_f64(c.post),
                    impulse: to_f64(c.normal_impulse),
                });
            }
        }
        Control::Continue
    }
}

/// Records the episodes of sustained contact: runs of consecutive steps in which some contact
/// carries an impulse without being struck (`normal_impulse > 0` and not
/// [`ContactRecord::is_impact`] at `speed`): a body riding or resting on a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct RidingLog<T> {
    speed: T,
    open: Option<f64>,
    /// The finished episodes `(start, end)`: the start of an episode's first step and the
    /// start of the first step after it, in time order.
    pub episodes: Vec<(f64, f64)>,
}

impl<T: Real> RidingLog<T> {
    /// A log in which impulses of contacts approaching faster than `speed ≥ 0` are impacts,
    /// slower ones sustained contact.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `speed` is finite and ≥ 0.
    pub fn new(speed: T) -> Result<Self, crate::ParameterError> {
        Ok(Self {
            speed: crate::validate::non_negative("speed", speed)?,
            open: None,
            episodes: Vec::new(),
        })
    }

    /// The start of an episode still going on at the last step seen, if any.
    pub fn open(&self) -> Option<f64> {
        self.open
    }
}

impl<T: Real> StepObserver<T> for RidingLog<T> {
    fn on_step(&mut self, s: &StepRecord<'_, T>) -> Control {
        let riding = s
            .contacts
            .iter()
            .any(|c| c.normal_impulse > T::zero() && !c.is_impact(self.speed));
        match (riding, self.open) {
            (true, None) => self.open = Some(to_f64(s.t0)),
            (false, Some(t)) => {
                self.episodes.push((t, to_f64(s.t0)));
                self.open = None;
            }
            _ => {}
        }
        Control::Continue
    }
}

/// A state on a stroboscopic section.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionSample {
    /// The section time `t₀ + i·period`.
    pub t: f64,
    /// Positions (interpolated linearly between the step ends around `t`).
    pub q: Vec<f64>,
    /// Velocities (likewise).
    pub v: Vec<f64>,
}

/// Samples the state at `t = t₀ + i·period` (`i = 0, 1, …`; a grid, never accumulated),
/// interpolating linearly between the ends of the step that contains each section time:
/// first-order accurate, as the scheme.
#[derive(Debug, Clone, PartialEq)]
pub struct StroboscopicSection {
    t0: f64,
    period: f64,
    next: u64,
    last_t: f64,
    last_q: Vec<f64>,
    last_v: Vec<f64>,
    /// The samples in time order.
    pub samples: Vec<SectionSample>,
}

impl StroboscopicSection {
    /// Sections at `t0 + i·period`.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `t0` is finite and `period` finite
    /// and > 0.
    pub fn new(t0: f64, period: f64) -> Result<Self, crate::ParameterError> {
        Ok(Self {
            t0: crate::validate::finite("t0", t0)?,
            period: crate::validate::positive("period", period)?,
            next: 0,
            last_t: f64::NAN,
            last_q: Vec::new(),
            last_v: Vec::new(),
            samples: Vec::new(),
        })
    }

    fn section_time(&self) -> f64 {
        self.t0 + self.next as f64 * self.period
    }
}

impl<T: Real> StepObserver<T> for StroboscopicSection {
    fn on_start(&mut self, t0: T, q: &[T], v: &[T]) {
        self.last_t = to_f64(t0);
        self.last_q = q.iter().map(|&x| to_f64(x)).collect();
        self.last_v = v.iter().map(|&x| to_f64(x)).collect();
        // Skip the section times before the run.
        while self.section_time() < self.last_t {
            self.next += 1;
        }
    }
    fn on_step(&mut self, s: &StepRecord<'_, T>) -> Control {
        let t1 = to_f64(s.t1);
        while self.section_time() <= t1 {
            let t = self.section_time();
            let span = t1 - self.last_t;
            let w = if span > 0.0 {
                (t - self.last_t) / span
            } else {
                1.0
            };
            let lerp = |a: &[f64], b: &[T]| -> Vec<f64> {
                a.iter()
                    .zip(b)
                    .map(|(&x, &y)| x + w * (to_f64(y) - x))
                    .collect()
            };
            self.samples.push(SectionSample {
                t,
                q: lerp(&self.last_q, s.q),
                v: lerp(&self.last_v, s.v),
            });
            self.next += 1;
        }
        self.last_t = t1;
        for (a, &b) in self.last_q.iter_mut().zip(s.q) {
            *a = to_f64(b);
        }
        for (a, &b) in self.last_v.iter_mut().zip(s.v) {
            *a = to_f64(b);
        }
        Control::Continue
    }
}

/// The linear dense output of one time-stepping step, over the state `y = (q, v)` of
/// `N = 2·dofs` entries: both halves interpolated linearly between the step's ends (the
/// scheme's own first-order picture: its position update is a straight line in `t`, its
/// velocity jumps inside the step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearStep<T: Real, const N: usize> {
    t0: T,
    t1: T,
    y0: SVector<T, N>,
    y1: SVector<T, N>,
    slope: SVector<T, N>,
}

impl<T: Real, const N: usize> DenseOutput<T, N> for LinearStep<T, N> {
    fn span(&self) -> (T, T) {
        (self.t0, self.t1)
    }
    fn endpoints(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        (&self.y0, &self.y1)
    }
    /// The chord's slope at both ends.
    fn end_derivatives(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        (&self.slope, &self.slope)
    }
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, N>) {
        let s = t - self.t0;
        for i in 0..N {
            out[i] = self.y0[i] + s * self.slope[i];
        }
    }
}

/// Lets any [`drive::Observer`](crate::drive::Observer) — the samplers of
/// [`sample`](crate::sample) among them — watch a time-stepping run: the state is
/// `y = (q, v)` (`N = 2·dofs` entries), each step is an observer step with a
/// [`LinearStep`] dense output, and each impact (a step whose contact
/// [`is_impact`](ContactRecord::is_impact) at the given speed) is an event whose `index` is
/// the contact's, reported after its step at the step's end `t1` with the state there (the
/// impulse is already in it: the scheme has no pre-impact state at one instant; `y_after`
/// is `None`, the direction [`Direction::Falling`](crate::event::Direction::Falling), the
/// gap closing).
///
/// A run whose system does not have `N/2` coordinates is not forwarded: the adapter stops it
/// at its first step and [`mismatch`](Self::mismatch) reports the number of coordinates seen.
/// [`Observer::check`](crate::drive::Observer::check) and
/// [`check_span`](crate::drive::Observer::check_span) are the caller's to call (as
/// [`check`](Self::check) does) before the run.
///
/// # Examples
/// ```
/// use nonsmooth::sample::Stroboscopic;
/// use nonsmooth::timestep::{DriveObserver, MoreauJean, PlanarBodies, PlanarContact, Plane, RigidBody};
/// let ball = PlanarBodies::new(vec![RigidBody::disc(1.0, 0.1)?], 9.81)?;
/// let floor = vec![PlanarContact::disc_plane(0, 0.1, Plane::floor(0.0)?, 0.5, 0.0)?];
/// let mut scheme = MoreauJean::new(ball, floor, 1e-3)?;
/// let strobe = Stroboscopic::<f64, 6>::periodic(0.0, 0.25, 0.0, 100)?;
/// let mut adapter = DriveObserver::new(strobe, 1e-3)?;
/// adapter.check(0.0, 1.0)?;
/// let (mut q, mut v) = ([0.0, 1.1, 0.0], [0.0; 3]);
/// scheme.run(0.0, &mut q, &mut v, 1.0, &mut adapter)?;
/// assert_eq!(adapter.observer().points().len(), 5); // t = 0, 0.25, …, 1
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct DriveObserver<T: Real, const N: usize, O> {
    observer: O,
    speed: T,
    last_t: T,
    last: SVector<T, N>,
    mismatch: Option<usize>,
    steps: u64,
    events: u64,
}

impl<T: Real, const N: usize, O: Observer<T, N>> DriveObserver<T, N, O> {
    /// Wraps `observer`; contacts approaching faster than `speed ≥ 0` when struck are
    /// reported as events.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `speed` is finite and ≥ 0, or if
    /// `N` is odd (`N` must be `2·dofs`).
    pub fn new(observer: O, speed: T) -> Result<Self, crate::ParameterError> {
        if N % 2 != 0 {
            return Err(crate::ParameterError::new(
                "N",
                N as f64,
                "even: the state (q, v) has 2·dofs entries",
            ));
        }
        Ok(Self {
            observer,
            speed: crate::validate::non_negative("speed", speed)?,
            last_t: T::zero(),
            last: SVector::zeros(),
            mismatch: None,
            steps: 0,
            events: 0,
        })
    }

    /// Runs the wrapped observer's [`check`](Observer::check) and
    /// [`check_span`](Observer::check_span) for a run over `[t0, t_end]`.
    ///
    /// # Errors
    /// The wrapped observer's.
    pub fn check(&self, t0: T, t_end: T) -> Result<(), RunError> {
        self.observer.check()?;
        self.observer.check_span(t0, t_end)
    }

    /// The wrapped observer.
    pub fn observer(&self) -> &O {
        &self.observer
    }

    /// The wrapped observer, mutably.
    pub fn observer_mut(&mut self) -> &mut O {
        &mut self.observer
    }

    /// Unwraps the observer.
    pub fn into_inner(self) -> O {
        self.observer
    }

    /// The number of coordinates of the last run's system if it was not `N/2` (that run
    /// was stopped at its first step, unobserved).
    pub fn mismatch(&self) -> Option<usize> {
        self.mismatch
    }

    fn stack(q: &[T], v: &[T], y: &mut SVector<T, N>) {
        let n = N / 2;
        for i in 0..n {
            y[i] = q[i];
            y[n + i] = v[i];
        }
    }
}

impl<T: Real, const N: usize, O: Observer<T, N>> StepObserver<T> for DriveObserver<T, N, O> {
    fn on_start(&mut self, t0: T, q: &[T], v: &[T]) {
        self.steps = 0;
        self.events = 0;
        self.mismatch = (2 * q.len() != N || 2 * v.len() != N).then_some(q.len());
        if self.mismatch.is_some() {
            return;
        }
        self.last_t = t0;
        Self::stack(q, v, &mut self.last);
        self.observer.on_start(t0, &self.last);
    }

    fn on_step(&mut self, s: &StepRecord<'_, T>) -> Control {
        if self.mismatch.is_some() {
            return Control::Stop;
        }
        let mut y1 = SVector::<T, N>::zeros();
        Self::stack(s.q, s.v, &mut y1);
        let span = s.t1 - s.t0;
        let slope = if span > T::zero() {
            (y1 - self.last) / span
        } else {
            SVector::zeros()
        };
        let dense = LinearStep {
            t0: s.t0,
            t1: s.t1,
            y0: self.last,
            y1,
            slope,
        };
        let view = StepView {
            t0: s.t0,
            t1: s.t1,
            y0: self.last,
            y1,
            dense: &dense,
        };
        let mut control = self.observer.on_step(&view);
        for c in s.contacts {
            if c.is_impact(self.speed) {
                let event = EventRecord {
                    index: c.index,
                    t: s.t1,
                    y: y1,
                    y_after: None,
                    direction: Direction::Falling,
                };
                self.events += 1;
                if self.observer.on_event(&event) == Control::Stop {
                    control = Control::Stop;
                }
            }
        }
        self.last_t = s.t1;
        self.last = y1;
        self.steps += 1;
        control
    }

    fn on_finish(&mut self, summary: &Summary) {
        if self.mismatch.is_some() {
            return;
        }
        let outcome = Outcome {
            t: self.last_t,
            y: self.last,
            termination: if summary.stopped {
                Termination::ObserverStopped
            } else {
                Termination::ReachedEnd
            },
            stats: Stats {
                accepted: self.steps,
                events: self.events,
                ..Stats::default()
            },
        };
        self.observer.on_finish(&outcome);
    }
}
