//! Parameter sweeps: bifurcation diagrams of stroboscopic points and inter-impact
//! intervals, up and down with continuation, hysteresis, and the experiment's continuous
//! frequency ramp.
//!
//! A sweep runs a system at each value `p` of a parameter grid (built by a closure
//! `make(p)`): `transient` forcing periods are discarded (by default 100 at the first value,
//! 50 after each step) and `record` periods are recorded — the stroboscopic points
//! `y(t_i)`, the impacts and their intervals `T_j`, the per-period grazing margin. With
//! continuation each value starts from the end state of the previous one (at forcing phase
//! 0, so the phase is continuous), which follows one attractor until it disappears; with
//! independent starts every value starts from the same state. The up and down branches of
//! a [`SweepDirection::Both`] sweep run concurrently, and independent-start sweeps run in
//! parallel over values (feature `parallel`); the results do not depend on the number of
//! threads, bit for bit, because every value is computed from the same inputs in the same
//! order whatever the scheduling.
//!
//! [`hysteresis`] compares the two branches and reports where they differ (coexisting
//! attractors); [`transitions`] lists the parameter steps where the number of impacts per
//! period or the period changes (grazing and period-doubling points).
//!
//! [`sweep_filippov`] sweeps a forced Filippov system (crossings and sliding, see
//! [`filippov`](crate::filippov)): stroboscopic points, regime and the time spent sliding
//! per value.

mod filippov;
mod lanes;
mod ramp;

pub use filippov::{SlidingSweepPoint, sweep_filippov};
#[cfg(feature = "parallel")]
pub use lanes::sweep_independent_parallel;
pub use lanes::{IndependentSweep, LaneStart, sweep_independent, sweep_starts};
pub use ramp::{RampImpact, RampRecord, RampSection, ramp, ramp_with_capacity};

use nalgebra::SVector;
use thiserror::Error;

use crate::Dynamics;
use crate::drive::{RunError, Simulation};
use crate::event::{Direction, Event, EventFunction};
use crate::integrate::Stepper;
use crate::sample::{
    ImpactSequence, PeriodSummary, Periodic, Regime, Stroboscopic, Surface, detect_period,
};

/// Sweep errors.
#[derive(Debug, Clone, Error)]
#[non_exhaustive]
pub enum SweepError {
    /// The parameter range has no values.
    #[error("empty parameter range")]
    EmptyRange,
    /// A parameter value is NaN or infinite.
    #[error("parameter value {index} is not finite ({value})")]
    NonFiniteValue {
        /// Position in the grid.
        index: usize,
        /// The value.
        value: f64,
    },
    /// The grid is not strictly increasing.
    #[error("parameter values must be strictly increasing (value {index} = {value} is not)")]
    NotIncreasing {
        /// Position.
        index: usize,
        /// Value.
        value: f64,
    },
    /// A grid step that does not lead from the start to the end.
    #[error("step {step} does not lead from {start} to {end} (wrong sign or zero)")]
    WrongStep {
        /// Start.
        start: f64,
        /// End.
        end: f64,
        /// Step.
        step: f64,
    },
    /// No recorded periods.
    #[error("the number of recorded periods must be > 0")]
    NoRecordedPeriods,
    /// More parameter values than a sweep takes.
    #[error("{count} parameter values requested; at most {max} (a step too small for the range?)")]
    TooManyValues {
        /// The requested number of values.
        count: f64,
        /// The limit.
        max: usize,
    },
    /// Period detection settings that cannot detect anything.
    #[error(
        "invalid period detection: tolerance {tol} must be finite and > 0, max period {max_period} >= 1"
    )]
    InvalidPeriodDetection {
        /// The tolerance.
        tol: f64,
        /// The largest period.
        max_period: usize,
    },
    /// The forcing period returned by the system builder is not finite and positive.
    #[error("invalid forcing period {period} at parameter {param}")]
    InvalidPeriod {
        /// Parameter value.
        param: f64,
        /// The period.
        period: f64,
    },
    /// A run failed at a parameter value.
    #[error("at parameter {param}: {source}")]
    Failed {
        /// Parameter value.
        param: f64,
        /// What failed.
        source: RunFailure,
    },
}

impl SweepError {
    /// A run at `param` failed with `error`.
    pub fn failed(param: f64, error: impl Into<RunFailure>) -> Self {
        Self::Failed {
            param,
            source: error.into(),
        }
    }
}

/// Why a run inside a sweep failed: the module error that stopped it (not the crate
/// [`Error`](crate::Error), which contains [`SweepError`]: the error types stay
/// non-recursive).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RunFailure {
    /// A constructor rejected a parameter.
    #[error(transparent)]
    Parameter(#[from] crate::ParameterError),
    /// A model could not be assembled.
    #[error(transparent)]
    Model(#[from] crate::model::ModelError),
    /// A root search failed.
    #[error(transparent)]
    Root(#[from] crate::roots::RootError),
    /// Time integration failed.
    #[error(transparent)]
    Integrate(#[from] crate::integrate::IntegrateError),
    /// Event handling failed (e.g. an accumulation of events).
    #[error(transparent)]
    Event(#[from] crate::event::EventError),
    /// A run through modes was started inconsistently or left its constraint.
    #[error(transparent)]
    Mode(#[from] crate::drive::ModeError),
    /// A Filippov run failed where only sliding motion can fail (two surfaces met at
    /// once, a repelling surface, …).
    #[error(transparent)]
    Filippov(crate::filippov::FilippovError),
    /// Any other error, by its message.
    #[error("{0}")]
    Other(String),
}

impl From<crate::filippov::FilippovError> for RunFailure {
    /// The engine's errors as themselves, the rest as [`Filippov`](RunFailure::Filippov).
    fn from(e: crate::filippov::FilippovError) -> Self {
        match e {
            crate::filippov::FilippovError::Run(e) => e.into(),
            e => Self::Filippov(e),
        }
    }
}

impl From<RunError> for RunFailure {
    fn from(e: RunError) -> Self {
        match e {
            RunError::Parameter(e) => Self::Parameter(e),
            RunError::Model(e) => Self::Model(e),
            RunError::Root(e) => Self::Root(e),
            RunError::Integrate(e) => Self::Integrate(e),
            RunError::Event(e) => Self::Event(e),
            RunError::Mode(e) => Self::Mode(e),
        }
    }
}

/// Which way a sweep goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum SweepDirection {
    /// Increasing parameter.
    Up,
    /// Decreasing parameter.
    Down,
    /// Both, concurrently.
    Both,
}

/// The most parameter values of one sweep (10⁷: far beyond any diagram, well below an
/// allocation that would abort the process).
pub const MAX_VALUES: usize = 10_000_000;

/// How a sweep is run.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepConfig {
    values: Vec<f64>,
    direction: SweepDirection,
    continuation: bool,
    transient_first: u32,
    transient_step: u32,
    record: u32,
    period_tol: f64,
    max_period: usize,
    max_steps: usize,
}

impl SweepConfig {
    /// A sweep over the given strictly increasing values; defaults: both directions,
    /// continuation, transients of 100 periods first and 50 per step, 50 recorded periods,
    /// period detection to `10⁻⁴` of the points' scale up to period 16, `10⁷` steps per
    /// value.
    ///
    /// The period tolerance must sit above the scatter of the stroboscopic points on a
    /// periodic orbit, which is the integration error amplified at the impacts: on the
    /// impact oscillator of `examples/paper.rs` at `rtol = 10⁻⁸` that scatter is ~`5·10⁻⁶`
    /// of the scale (e.g. the period-2 orbit at ω = 19 rad/s), at `rtol = 10⁻¹⁰` ~`10⁻⁶`.
    ///
    /// # Errors
    /// [`SweepError`] for an empty, non-finite or non-increasing grid.
    pub fn new(values: Vec<f64>) -> Result<Self, SweepError> {
        if values.is_empty() {
            return Err(SweepError::EmptyRange);
        }
        if values.len() > MAX_VALUES {
            return Err(SweepError::TooManyValues {
                count: values.len() as f64,
                max: MAX_VALUES,
            });
        }
        for (i, &v) in values.iter().enumerate() {
            if !v.is_finite() {
                return Err(SweepError::NonFiniteValue { index: i, value: v });
            }
            if i > 0 && v <= values[i - 1] {
                return Err(SweepError::NotIncreasing { index: i, value: v });
            }
        }
        Ok(Self {
            values,
            direction: SweepDirection::Both,
            continuation: true,
            transient_first: 100,
            transient_step: 50,
            record: 50,
            period_tol: 1e-4,
            max_period: 16,
            max_steps: 10_000_000,
        })
    }

    /// The grid `start + i·step` for `i = 0..` while within `[start, end]` (plus a rounding
    /// margin of `10⁻⁹·step`); values are computed from `i`, never accumulated.
    ///
    /// # Errors
    /// [`SweepError::WrongStep`] if `step` is zero or does not lead from `start` to `end`;
    /// [`SweepError::NonFiniteValue`] for non-finite ends.
    pub fn grid(start: f64, end: f64, step: f64) -> Result<Self, SweepError> {
        if !start.is_finite() {
            return Err(SweepError::NonFiniteValue {
                index: 0,
                value: start,
            });
        }
        if !end.is_finite() {
            return Err(SweepError::NonFiniteValue {
                index: 1,
                value: end,
            });
        }
        if !(step.is_finite() && step > 0.0 && end >= start) {
            return Err(SweepError::WrongStep { start, end, step });
        }
        let n = ((end - start) / step + 1e-9).floor() + 1.0;
        if !(n <= MAX_VALUES as f64) {
            return Err(SweepError::TooManyValues {
                count: n,
                max: MAX_VALUES,
            });
        }
        let n = n as usize;
        Self::new((0..n).map(|i| start + i as f64 * step).collect())
    }

    /// Sets the direction.
    pub fn direction(mut self, d: SweepDirection) -> Self {
        self.direction = d;
        self
    }

    /// Continuation (`true`) or independent starts from the initial state (`false`).
    pub fn continuation(mut self, on: bool) -> Self {
        self.continuation = on;
        self
    }

    /// Transient periods at the first value and after each step.
    pub fn transients(mut self, first: u32, step: u32) -> Self {
        self.transient_first = first;
        self.transient_step = step;
        self
    }

    /// Recorded periods per value.
    ///
    /// # Errors
    /// [`SweepError::NoRecordedPeriods`] if `periods == 0`.
    pub fn record(mut self, periods: u32) -> Result<Self, SweepError> {
        if periods == 0 {
            return Err(SweepError::NoRecordedPeriods);
        }
        self.record = periods;
        Ok(self)
    }

    /// Period detection: relative tolerance and largest period tested.
    ///
    /// # Errors
    /// [`SweepError::InvalidPeriodDetection`] unless `tol` is finite and > 0 and
    /// `max_period ≥ 1` (a NaN or negative tolerance would call every orbit not periodic).
    pub fn period_detection(mut self, tol: f64, max_period: usize) -> Result<Self, SweepError> {
        if !(tol.is_finite() && tol > 0.0) || max_period == 0 {
            return Err(SweepError::InvalidPeriodDetection { tol, max_period });
        }
        self.period_tol = tol;
        self.max_period = max_period;
        Ok(self)
    }

    /// Step cap per parameter value.
    pub fn max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps.max(1);
        self
    }

    /// The parameter values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
}

/// A system at one parameter value, as the sweep needs it.
#[derive(Debug, Clone)]
pub struct SweepSystem<S, G = Stop> {
    /// The system.
    pub system: S,
    /// Its forcing period (sections at `t = i·period`).
    pub period: f64,
    /// The contact surface whose impacts are recorded (rising crossings of its penetration:
    /// a [`Stop`] `y[position] = level`, a [`Gap`](crate::event::Gap) of an `N`-DOF system,
    /// fixed or moving, or any [`Surface`]); `None` for a system without impacts.
    pub stop: Option<G>,
}

/// An impact surface `y[position] = level` (the first stage's sweep stop, now the generic
/// [`event::Stop`](crate::event::Stop) in `f64`).
pub type Stop = crate::event::Stop<f64>;

/// What was recorded at one parameter value.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPoint<const N: usize> {
    /// Parameter value.
    pub param: f64,
    /// Stroboscopic points (one per recorded period).
    pub poincare: Vec<SVector<f64, N>>,
    /// Inter-impact intervals `T_j` of the impacts in the recording window.
    pub intervals: Vec<f64>,
    /// Impact velocities.
    pub impact_velocities: Vec<f64>,
    /// Impacts in the recording window.
    pub impacts: u64,
    /// Impacts per forcing period (average over the window).
    pub impacts_per_period: f64,
    /// The regime from the stroboscopic points.
    pub regime: Regime,
    /// The smallest per-period grazing margin `level − max x` (negative: penetration).
    pub grazing_margin: f64,
    /// The state at the end of the run (phase 0).
    pub end_state: SVector<f64, N>,
}

/// One direction of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepBranch<const N: usize> {
    /// [`SweepDirection::Up`] or [`SweepDirection::Down`] (or `Both`'s parts); for
    /// independent starts, `Up`.
    pub direction: SweepDirection,
    /// Points in the order computed.
    pub points: Vec<SweepPoint<N>>,
}

/// A sweep's result.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepResult<const N: usize> {
    /// The branches (one, or up then down).
    pub branches: Vec<SweepBranch<N>>,
}

/// An event function that is either a surface's penetration or never zero.
#[derive(Debug, Clone, Copy)]
struct SurfaceEvent<G>(Option<G>);

impl<const N: usize, G: Surface<f64, N>> EventFunction<f64, N> for SurfaceEvent<G> {
    #[inline(always)]
    fn value(&self, t: f64, y: &SVector<f64, N>) -> f64 {
        match &self.0 {
            Some(s) => s.value(t, y),
            None => -1.0,
        }
    }
    #[inline(always)]
    fn rate(&self, t: f64, y: &SVector<f64, N>, dy: &SVector<f64, N>) -> Option<f64> {
        match &self.0 {
            Some(s) => s.rate(t, y, dy),
            None => Some(0.0),
        }
    }
    fn check(&self) -> Result<(), crate::event::EventError> {
        self.0.as_ref().map_or(Ok(()), |s| s.check())
    }
    /// No time scale (the default `None`).
    fn constant_time_scale(&self) -> bool {
        true
    }
}

/// An event function that is either a level or never zero.
#[derive(Debug, Clone, Copy)]
struct StopEvent(Option<Stop>);

impl<const N: usize> EventFunction<f64, N> for StopEvent {
    #[inline(always)]
    fn value(&self, _t: f64, y: &SVector<f64, N>) -> f64 {
        match self.0 {
            Some(s) => y[s.position] - s.level,
            None => -1.0,
        }
    }
    #[inline(always)]
    fn rate(&self, _t: f64, _y: &SVector<f64, N>, dy: &SVector<f64, N>) -> Option<f64> {
        match self.0 {
            Some(s) => Some(dy[s.position]),
            None => Some(0.0),
        }
    }
    /// The stop's (a constant has no deviation from its chord).
    fn chord_bounds(
        &self,
        t0: f64,
        t1: f64,
        dev: &SVector<f64, N>,
        mag: &SVector<f64, N>,
    ) -> Option<(f64, f64)> {
        match &self.0 {
            Some(s) => s.chord_bounds(t0, t1, dev, mag),
            None => Some((0.0, 1.0)),
        }
    }
    /// No time scale (the default `None`).
    fn constant_time_scale(&self) -> bool {
        true
    }
}

/// Runs one parameter value: `transient` periods from `y0`, then `record` periods.
///
/// # Errors
/// [`SweepError::Failed`] wrapping the simulation's error, [`SweepError::InvalidPeriod`].
pub fn run_point<const N: usize, S, St, G>(
    config: &SweepConfig,
    param: f64,
    sys: SweepSystem<S, G>,
    stepper: St,
    y0: SVector<f64, N>,
    transient: u32,
) -> Result<SweepPoint<N>, SweepError>
where
    S: Dynamics<f64, N>,
    St: Stepper<f64, N>,
    G: Surface<f64, N> + Clone,
{
    let fail = |e: RunError| SweepError::failed(param, e);
    let period = sys.period;
    if !(period.is_finite() && period > 0.0) {
        return Err(SweepError::InvalidPeriod { param, period });
    }
    let stop = sys.stop;
    // In f64: `transient + record` may not fit a u32.
    let t_end = (f64::from(transient) + f64::from(config.record)) * period;
    let ev = Event::new(SurfaceEvent(stop.clone()), Direction::Rising);
    let mut sim = Simulation::new(sys.system, stepper)
        .with_events(ev)
        .landing_grid(Some((0.0, period)))
        .map_err(|e| fail(e.into()))?
        .max_steps(config.max_steps)
        .map_err(|e| fail(e.into()))?;
    let mut obs = point_observers::<N, G>(param, period, transient, stop)?;
    let out = sim.run(0.0, y0, t_end, &mut obs).map_err(fail)?;
    Ok(point_record(
        (config.record, config.period_tol, config.max_period),
        param,
        &obs,
        out.y,
    ))
}

/// The observers of one parameter value: its sections, and the impacts and per-period
/// margins on its surface (none without one).
pub(crate) type PointObservers<const N: usize, G> = (
    Stroboscopic<f64, N>,
    Option<ImpactSequence<f64, G>>,
    Option<PeriodSummary<f64, Periodic<f64>, G>>,
);

/// The observers of one value with forcing period `period`: sections at `i·period` for
/// `i = transient+1 ..= transient+record`, impacts and per-period margins on `stop` from
/// `t = transient·period` (extrema are kept of component 0, the first position of a
/// mechanical state; only the margins are used).
pub(crate) fn point_observers<const N: usize, G: Surface<f64, N> + Clone>(
    param: f64,
    period: f64,
    transient: u32,
    stop: Option<G>,
) -> Result<PointObservers<N, G>, SweepError> {
    let fail = |e: RunError| SweepError::failed(param, e);
    if !(period.is_finite() && period > 0.0) {
        return Err(SweepError::InvalidPeriod { param, period });
    }
    let cap = 1 << 20;
    let t_rec = transient as f64 * period;
    let strobe = Stroboscopic::<f64, N>::periodic(0.0, period, t_rec + 0.5 * period, cap)
        .map_err(|e| fail(e.into()))?;
    let (impacts, periods) = match stop {
        Some(g) => (
            Some(ImpactSequence::on_surface(0, g.clone(), t_rec, cap).map_err(|e| fail(e.into()))?),
            Some(
                PeriodSummary::periodic(0.0, period, 0, 0, N / 2, 0.0, t_rec, cap)
                    .map_err(|e| fail(e.into()))?
                    .with_surface(g),
            ),
        ),
        None => (None, None),
    };
    Ok((strobe, impacts, periods))
}

/// The record of one value from its observers after the run and its end state;
/// `(record, period_tol, max_period)` are the window length and the period detection.
pub(crate) fn point_record<const N: usize, G>(
    (record, period_tol, max_period): (u32, f64, usize),
    param: f64,
    obs: &PointObservers<N, G>,
    end_state: SVector<f64, N>,
) -> SweepPoint<N> {
    let (strobe, impacts, periods) = obs;
    let no_impacts: &[crate::sample::Impact<f64>] = &[];
    let no_periods: &[crate::sample::PeriodRecord<f64>] = &[];
    let impact_list = impacts.as_ref().map_or(no_impacts, |i| i.impacts());
    let period_list = periods.as_ref().map_or(no_periods, |p| p.periods());
    let impact_count = impacts.as_ref().map_or(0, |i| i.count());
    let poincare: Vec<SVector<f64, N>> = strobe.points().iter().map(|p| p.y).collect();
    let mut scale = SVector::<f64, N>::zeros();
    for p in &poincare {
        for c in 0..N {
            scale[c] = scale[c].max(p[c].abs());
        }
    }
    let regime = detect_period(&poincare, &scale, period_tol, max_period);
    let intervals: Vec<f64> = impact_list.iter().filter_map(|i| i.interval).collect();
    let impact_velocities = impact_list.iter().map(|i| i.velocity).collect();
    let grazing_margin = period_list
        .iter()
        .map(|p| p.margin)
        .fold(f64::INFINITY, f64::min);
    SweepPoint {
        param,
        poincare,
        intervals,
        impact_velocities,
        impacts: impact_count,
        impacts_per_period: impacts_per_period(period_list, regime, impact_count, record),
        regime,
        grazing_margin,
        end_state,
    }
}

/// Impacts per forcing period: for a period-`p` orbit counted over the largest whole number
/// of orbit periods in the window (a 50-period window holds no whole number of period-3
/// orbits, and the plain average would flicker between neighbouring values); otherwise the
/// average over the window.
fn impacts_per_period(
    periods: &[crate::sample::PeriodRecord<f64>],
    regime: Regime,
    total: u64,
    record: u32,
) -> f64 {
    if let Regime::Periodic(p) = regime {
        let whole = (periods.len() / p) * p;
        if whole > 0 {
            let n: u64 = periods[periods.len() - whole..]
                .iter()
                .map(|r| r.impacts as u64)
                .sum();
            return n as f64 / whole as f64;
        }
    }
    total as f64 / record as f64
}

/// Runs a sweep.
///
/// `make(p)` builds the system at parameter `p`; `stepper()` builds a fresh stepper for
/// each run; `y0` is the initial state (of the first value with continuation, of every
/// value without).
///
/// # Errors
/// The first [`SweepError`] met (in parameter order within each branch).
///
/// # Examples
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::systems::TwoDofImpact;
/// use nonsmooth::sweep::{SweepConfig, SweepSystem, Stop, SweepDirection, sweep};
///
/// let p = TwoDofImpact::default();
/// let config = SweepConfig::grid(0.6, 0.8, 0.1)?.direction(SweepDirection::Up).transients(20, 10).record(5)?;
/// let make = |w: f64| -> nonsmooth::Result<SweepSystem<_>> {
///     Ok(SweepSystem {
///         system: p.model::<f64>(w)?,
///         period: TwoDofImpact::period(w),
///         // State (q₁, q₂, q̇₁, q̇₂): impacts of the secondary mass on the stop q₂ = d.
///         stop: Some(Stop { position: 1, velocity: 3, level: p.gap }),
///     })
/// };
/// let tol = Tolerances::<f64, 4>::new(1e-6, 1e-8)?;
/// let res = sweep(&config, make, || nonsmooth::integrate::Dopri5::new(tol), SVector::zeros())?;
/// assert_eq!(res.branches[0].points.len(), 3);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
pub fn sweep<const N: usize, S, St, F, G, Sf, Fe>(
    config: &SweepConfig,
    make: F,
    stepper: G,
    y0: SVector<f64, N>,
) -> Result<SweepResult<N>, SweepError>
where
    S: Dynamics<f64, N> + Send,
    St: Stepper<f64, N>,
    F: Fn(f64) -> Result<SweepSystem<S, Sf>, Fe> + Sync,
    Fe: Into<RunFailure>,
    G: Fn() -> St + Sync,
    Sf: Surface<f64, N> + Clone + Send,
{
    let branch = |dir: SweepDirection| -> Result<SweepBranch<N>, SweepError> {
        let mut vals: Vec<f64> = config.values.clone();
        if dir == SweepDirection::Down {
            vals.reverse();
        }
        if config.continuation {
            let mut y = y0;
            let mut points = Vec::with_capacity(vals.len());
            for (k, &p) in vals.iter().enumerate() {
                let sys = make(p).map_err(|e| SweepError::failed(p, e))?;
                let tr = if k == 0 {
                    config.transient_first
                } else {
                    config.transient_step
                };
                let pt = run_point(config, p, sys, stepper(), y, tr)?;
                y = pt.end_state;
                points.push(pt);
            }
            Ok(SweepBranch {
                direction: dir,
                points,
            })
        } else {
            let one = |&p: &f64| -> Result<SweepPoint<N>, SweepError> {
                let sys = make(p).map_err(|e| SweepError::failed(p, e))?;
                run_point(config, p, sys, stepper(), y0, config.transient_first)
            };
            #[cfg(feature = "parallel")]
            let points: Result<Vec<_>, _> = {
                use rayon::prelude::*;
                vals.par_iter().map(one).collect()
            };
            #[cfg(not(feature = "parallel"))]
            let points: Result<Vec<_>, _> = vals.iter().map(one).collect();
            Ok(SweepBranch {
                direction: dir,
                points: points?,
            })
        }
    };
    let branches = match config.direction {
        SweepDirection::Up => vec![branch(SweepDirection::Up)?],
        SweepDirection::Down => vec![branch(SweepDirection::Down)?],
        SweepDirection::Both if !config.continuation => {
            // Independent starts do not depend on the direction: one branch serves both.
            let b = branch(SweepDirection::Up)?;
            vec![b]
        }
        SweepDirection::Both => {
            #[cfg(feature = "parallel")]
            let (up, down) = rayon::join(
                || branch(SweepDirection::Up),
                || branch(SweepDirection::Down),
            );
            #[cfg(not(feature = "parallel"))]
            let (up, down) = (branch(SweepDirection::Up), branch(SweepDirection::Down));
            vec![up?, down?]
        }
    };
    Ok(SweepResult { branches })
}

/// Whether two recorded points show different attractors: a different regime or number of
/// impacts per period, or stroboscopic point sets further apart than `tol` (relative to the
/// points' scale) in the set distance.
pub fn attractors_differ<const N: usize>(a: &SweepPoint<N>, b: &SweepPoint<N>, tol: f64) -> bool {
    if a.regime != b.regime || (a.impacts_per_period - b.impacts_per_period).abs() > 1e-9 {
        return true;
    }
    let mut scale = SVector::<f64, N>::zeros();
    for p in a.poincare.iter().chain(&b.poincare) {
        for c in 0..N {
            scale[c] = scale[c].max(p[c].abs());
        }
    }
    let dist = |p: &SVector<f64, N>, set: &[SVector<f64, N>]| {
        set.iter()
            .map(|q| {
                (0..N)
                    .map(|c| ((p[c] - q[c]) / scale[c].max(f64::MIN_POSITIVE)).abs())
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min)
    };
    a.poincare.iter().any(|p| dist(p, &b.poincare) > tol)
        || b.poincare.iter().any(|p| dist(p, &a.poincare) > tol)
}

/// Intervals `[p_a, p_b]` of consecutive parameter values where the up and down branches
/// reached different attractors (coexistence, hysteresis). `tol` as in
/// [`attractors_differ`]; chaotic points (not periodic) on both branches are compared by
/// regime and impacts per period only.
pub fn hysteresis<const N: usize>(result: &SweepResult<N>, tol: f64) -> Vec<(f64, f64)> {
    let (Some(up), Some(down)) = (
        result
            .branches
            .iter()
            .find(|b| b.direction == SweepDirection::Up),
        result
            .branches
            .iter()
            .find(|b| b.direction == SweepDirection::Down),
    ) else {
        return Vec::new();
    };
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut open: Option<(f64, f64)> = None;
    for a in &up.points {
        let Some(b) = down.points.iter().find(|b| b.param == a.param) else {
            continue;
        };
        let differ = if a.regime == Regime::NotPeriodic && b.regime == Regime::NotPeriodic {
            false
        } else {
            attractors_differ(a, b, tol)
        };
        match (differ, open) {
            (true, None) => open = Some((a.param, a.param)),
            (true, Some((s, _))) => open = Some((s, a.param)),
            (false, Some(iv)) => {
                out.push(iv);
                open = None;
            }
            (false, None) => {}
        }
    }
    if let Some(iv) = open {
        out.push(iv);
    }
    out
}

/// A change between consecutive points of a branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// Parameter before the change.
    pub before: f64,
    /// Parameter after the change.
    pub after: f64,
    /// Impacts per period before.
    pub impacts_before: f64,
    /// Impacts per period after.
    pub impacts_after: f64,
    /// Regime before.
    pub regime_before: Regime,
    /// Regime after.
    pub regime_after: Regime,
}

/// The steps along a branch where the number of impacts per period (rounded to 1/100) or
/// the regime changes: grazing bifurcations add or remove impacts; period doublings and
/// transitions to chaos change the regime.
pub fn transitions<const N: usize>(branch: &SweepBranch<N>) -> Vec<Transition> {
    branch
        .points
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let ia = (a.impacts_per_period * 100.0).round();
            let ib = (b.impacts_per_period * 100.0).round();
            if ia != ib || a.regime != b.regime {
                Some(Transition {
                    before: a.param,
                    after: b.param,
                    impacts_before: a.impacts_per_period,
                    impacts_after: b.impacts_per_period,
                    regime_before: a.regime,
                    regime_after: b.regime,
                })
            } else {
                None
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn config_validation() {
        assert!(matches!(
            SweepConfig::new(vec![]),
            Err(SweepError::EmptyRange)
        ));
        assert!(matches!(
            SweepConfig::new(vec![1.0, f64::NAN]),
            Err(SweepError::NonFiniteValue { index: 1, .. })
        ));
        assert!(matches!(
            SweepConfig::new(vec![1.0, 1.0]),
            Err(SweepError::NotIncreasing { index: 1, .. })
        ));
        assert!(matches!(
            SweepConfig::grid(1.0, 2.0, -0.1),
            Err(SweepError::WrongStep { .. })
        ));
        assert!(matches!(
            SweepConfig::grid(2.0, 1.0, 0.1),
            Err(SweepError::WrongStep { .. })
        ));
        assert!(matches!(
            SweepConfig::grid(1.0, 2.0, 0.0),
            Err(SweepError::WrongStep { .. })
        ));
        assert!(matches!(
            SweepConfig::grid(1.0, f64::INFINITY, 0.1),
            Err(SweepError::NonFiniteValue { .. })
        ));
        assert!(matches!(
            SweepConfig::grid(1.0, 2.0, 0.5).unwrap().record(0),
            Err(SweepError::NoRecordedPeriods)
        ));
        let g = SweepConfig::grid(17.5, 25.0, 0.005).unwrap();
        assert_eq!(g.values().len(), 1501);
        assert_eq!(*g.values().last().unwrap(), 17.5 + 1500.0 * 0.005);
    }
}
