//! What a time-stepping run reports: per-step records (state, energies, the active contacts
//! with their impulses), observers of them, and an impact log built from the impulses.

use crate::Real;
use crate::drive::Control;
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
pub struct Impact {
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

/// Records every [`Impact`] (a step in which a contact carries an impulse while approaching
/// faster than `speed`, see [`ContactRecord::is_impact`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ImpactLog<T> {
    speed: T,
    /// The impacts in time order.
    pub impacts: Vec<Impact>,
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
                self.impacts.push(Impact {
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
