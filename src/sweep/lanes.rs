//! Independent-start sweeps in the lanes of an [`Ensemble`]: the records of
//! [`sweep`](super::sweep) without continuation, one start per lane, for any model with a
//! lane form.

use nalgebra::SVector;

use super::{
    PointObservers, SurfaceEvent, SweepConfig, SweepDirection, SweepError, SweepPoint,
    point_observers, point_record,
};
use crate::LaneDynamics;
use crate::drive::{Outcome, RunError};
use crate::ensemble::{Ensemble, MemberRun};
use crate::event::{Direction, Event};
use crate::sample::Surface;

/// The schedule of an independent-start sweep: every value runs `transient` forcing
/// periods from the same initial state, then `record` recorded periods.
///
/// The same settings as a [`SweepConfig`] with `continuation(false)`, whose fields are
/// private; [`config`](Self::config) gives that scalar configuration, so both paths are
/// spelled once.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct IndependentSweep {
    /// Transient periods (discarded) at every value.
    pub transient: u32,
    /// Recorded periods per value (> 0).
    pub record: u32,
    /// Relative tolerance of the period detection.
    pub period_tol: f64,
    /// Largest period tested.
    pub max_period: usize,
    /// Step cap per value.
    pub max_steps: usize,
}

impl Default for IndependentSweep {
    /// [`SweepConfig::new`]'s defaults: 100 transient and 50 recorded periods, period
    /// detection to `10⁻⁴` up to period 16, `10⁷` steps per value.
    fn default() -> Self {
        Self {
            transient: 100,
            record: 50,
            period_tol: 1e-4,
            max_period: 16,
            max_steps: 10_000_000,
        }
    }
}

impl IndependentSweep {
    /// `transient` then `record` periods per value; the other settings as
    /// [`Default`].
    ///
    /// # Errors
    /// [`SweepError::NoRecordedPeriods`] if `record == 0`.
    pub fn new(transient: u32, record: u32) -> Result<Self, SweepError> {
        let s = Self {
            transient,
            record,
            ..Self::default()
        };
        s.check()?;
        Ok(s)
    }

    /// Period detection: relative tolerance and largest period tested.
    ///
    /// # Errors
    /// [`SweepError::InvalidPeriodDetection`] unless `tol` is finite and > 0 and
    /// `max_period ≥ 1`.
    pub fn period_detection(mut self, tol: f64, max_period: usize) -> Result<Self, SweepError> {
        self.period_tol = tol;
        self.max_period = max_period;
        self.check()?;
        Ok(self)
    }

    /// Step cap per value (at least 1).
    pub fn max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps.max(1);
        self
    }

    /// The scalar [`SweepConfig`] with the same settings over `values` (independent
    /// starts, one branch): [`sweep`](super::sweep) with it returns the records
    /// of [`sweep_independent`] (bit for bit with [`LaneMath::Exact`](crate::lanes::LaneMath::Exact)).
    ///
    /// # Errors
    /// [`SweepError`] for an empty, non-finite or non-increasing grid, or invalid settings.
    pub fn config(&self, values: Vec<f64>) -> Result<SweepConfig, SweepError> {
        SweepConfig::new(values)?
            .direction(SweepDirection::Up)
            .continuation(false)
            .transients(self.transient, self.transient)
            .record(self.record)?
            .period_detection(self.period_tol, self.max_period)
            .map(|c| c.max_steps(self.max_steps))
    }

    /// The settings checked by [`SweepConfig`]'s own rules (one place for them).
    fn check(&self) -> Result<(), SweepError> {
        self.config(vec![0.0]).map(|_| ())
    }
}

/// One start of a lane sweep: the system at parameter value `param`, its forcing period
/// (sections at `t = i·period`, every step landing on them) and its initial state at
/// `t = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneStart<D, const M: usize> {
    /// The parameter value (the record's `param`).
    pub param: f64,
    /// The system at that value.
    pub system: D,
    /// Its forcing period (finite, > 0).
    pub period: f64,
    /// The initial state at `t = 0`.
    pub y0: SVector<f64, M>,
}

/// An independent-start sweep in lanes of `V`: every start runs from its `y0` at `t = 0`,
/// `settings.transient` periods, then `settings.record` recorded periods, with steps
/// landing on the sections `t = i·period` and impacts the rising crossings of `stop`
/// (none for `None`) — the records of [`sweep`](super::sweep) with
/// [`IndependentSweep::config`] and [`Dopri5`](crate::integrate::Dopri5), in the order
/// of `starts`.
///
/// Any model with a lane form runs ([`LaneDynamics`]: an
/// [`Oscillator`](crate::model::Oscillator), a [`Mechanical`](crate::model::Mechanical)
/// of any size, any [`Dynamics`](crate::Dynamics) through
/// [`LaneByLane`](crate::LaneByLane)); `stop` is any impact [`Surface`] (a
/// [`Stop`](crate::event::Stop), a [`Gap`](crate::event::Gap), fixed or moving).
/// `ensemble` gives the tolerances, step options, math mode and instruction set; the step
/// cap is `settings.max_steps`. With [`LaneMath::Exact`](crate::lanes::LaneMath::Exact)
/// every record is the scalar sweep's to the bit (tested); on the calling thread (see
/// [`sweep_independent_parallel`] for the thread pool; the records are the same).
///
/// # Examples
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::ensemble::Ensemble;
/// use nonsmooth::event::Stop;
/// use nonsmooth::integrate::Tolerances;
/// use nonsmooth::sweep::{IndependentSweep, LaneStart, sweep_independent};
/// use nonsmooth::systems::TwoDofImpact;
///
/// let p = TwoDofImpact::default();
/// let tol = Tolerances::<f64, 4>::new(1e-6, 1e-8)?;
/// let starts = [0.6, 0.7, 0.8]
///     .map(|w| -> nonsmooth::Result<_> {
///         Ok(LaneStart { param: w, system: p.model(w)?, period: TwoDofImpact::period(w), y0: SVector::zeros() })
///     })
///     .into_iter()
///     .collect::<nonsmooth::Result<Vec<_>>>()?;
/// // State (q₁, q₂, q̇₁, q̇₂): impacts of the secondary mass on the stop q₂ = d.
/// let stop = Stop { position: 1, velocity: 3, level: p.gap };
/// let settings = IndependentSweep::new(20, 5)?;
/// let points = sweep_independent(&Ensemble::new(tol)?, &settings, &starts, Some(stop))?;
/// assert_eq!(points.len(), 3);
/// assert_eq!(points[1].param, 0.7);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
///
/// # Errors
/// [`SweepError`]: invalid settings or no starts; [`SweepError::Failed`] with the
/// parameter of the first start (in order) whose run failed.
pub fn sweep_independent<D, G, const M: usize>(
    ensemble: &Ensemble<(), M>,
    settings: &IndependentSweep,
    starts: &[LaneStart<D, M>],
    stop: Option<G>,
) -> Result<Vec<SweepPoint<M>>, SweepError>
where
    D: LaneDynamics<M> + Clone,
    G: Surface<f64, M> + Clone,
{
    run_starts(ensemble, settings, starts, stop, |e, j, o| e.run(j, o))?
        .into_iter()
        .collect()
}

/// [`sweep_independent`] over the threads of the current rayon pool, `chunk` starts per
/// task: the same records, bit for bit, for any number of threads.
///
/// # Errors
/// As [`sweep_independent`]; [`SweepError::Failed`] (a parameter error) if `chunk == 0`.
#[cfg(feature = "parallel")]
pub fn sweep_independent_parallel<D, G, const M: usize>(
    ensemble: &Ensemble<(), M>,
    settings: &IndependentSweep,
    starts: &[LaneStart<D, M>],
    stop: Option<G>,
    chunk: usize,
) -> Result<Vec<SweepPoint<M>>, SweepError>
where
    D: LaneDynamics<M> + Clone + Sync,
    G: Surface<f64, M> + Clone + Send + Sync,
{
    run_starts(ensemble, settings, starts, stop, |e, j, o| {
        e.run_parallel(j, o, chunk)
    })?
    .into_iter()
    .collect()
}

/// Independent starts with a result per start: the lane form of calling
/// [`run_point`](super::run_point) once per start with [`IndependentSweep::config`]'s
/// settings and `Dopri5` (to the bit with
/// [`LaneMath::Exact`](crate::lanes::LaneMath::Exact)). A start that fails does not stop
/// the others: its entry is [`SweepError::Failed`] at its parameter. This is what a basin
/// or parameter-plane study runs (`study`, feature `cli`).
///
/// # Errors
/// The outer error: [`SweepError`] for invalid settings or no starts.
pub fn sweep_starts<D, G, const M: usize>(
    ensemble: &Ensemble<(), M>,
    settings: &IndependentSweep,
    starts: &[LaneStart<D, M>],
    stop: Option<G>,
) -> Result<Vec<Result<SweepPoint<M>, SweepError>>, SweepError>
where
    D: LaneDynamics<M> + Clone,
    G: Surface<f64, M> + Clone,
{
    run_starts(ensemble, settings, starts, stop, |e, j, o| e.run(j, o))
}

/// The lane runs of every start, the batch run by `run` (on the calling thread or over
/// the rayon pool).
fn run_starts<D, G, const M: usize>(
    ensemble: &Ensemble<(), M>,
    settings: &IndependentSweep,
    starts: &[LaneStart<D, M>],
    stop: Option<G>,
    run: impl FnOnce(
        &SweepEnsemble<G, M>,
        &[MemberRun<D, M>],
        &mut [PointObservers<M, G>],
    ) -> Outcomes<M>,
) -> Result<Vec<Result<SweepPoint<M>, SweepError>>, SweepError>
where
    D: LaneDynamics<M> + Clone,
    G: Surface<f64, M> + Clone,
{
    settings.check()?;
    let Some(first) = starts.first() else {
        return Err(SweepError::EmptyRange);
    };
    let batch_error = |e| SweepError::failed(first.param, e);
    let e = ensemble
        .clone()
        .with_event(Event::new(SurfaceEvent(stop.clone()), Direction::Rising))
        .and_then(|e| e.max_steps(settings.max_steps))
        .map_err(batch_error)?;
    let periods = f64::from(settings.transient) + f64::from(settings.record);
    // Starts that cannot begin (a bad period or a non-finite state) fail alone; the
    // others run.
    let mut results: Vec<Option<Result<SweepPoint<M>, SweepError>>> =
        Vec::with_capacity(starts.len());
    let (mut jobs, mut obs, mut slot) = (Vec::new(), Vec::new(), Vec::new());
    for (k, s) in starts.iter().enumerate() {
        let begin = point_observers::<M, G>(s.param, s.period, settings.transient, stop.clone())
            .and_then(|o| {
                MemberRun::periods_of(s.system.clone(), s.y0, s.period, periods)
                    .map(|j| (o, j))
                    .map_err(|e| SweepError::failed(s.param, e))
            });
        match begin {
            Ok((o, j)) => {
                obs.push(o);
                jobs.push(j);
                slot.push(k);
                results.push(None);
            }
            Err(err) => results.push(Some(Err(err))),
        }
    }
    if !jobs.is_empty() {
        let out = run(&e, &jobs, &mut obs).map_err(batch_error)?;
        for ((k, o), r) in slot.into_iter().zip(&obs).zip(out) {
            let s = &starts[k];
            let record = (settings.record, settings.period_tol, settings.max_period);
            results[k] = Some(
                r.map(|outcome| point_record(record, s.param, o, outcome.y))
                    .map_err(|e| SweepError::failed(s.param, e)),
            );
        }
    }
    Ok(results.into_iter().flatten().collect())
}

/// The lane ensemble with the sweep's impact event.
type SweepEnsemble<G, const M: usize> = Ensemble<Event<SurfaceEvent<G>>, M>;

/// The ensemble's outcomes of a batch (outer error: the batch could not run).
type Outcomes<const M: usize> = Result<Vec<Result<Outcome<f64, M>, RunError>>, RunError>;
