//! Independent-start sweeps in lanes: the records of
//! [`sweep`](crate::sweep::sweep) without continuation, one parameter value per lane.

use nalgebra::SVector;

use super::{Ensemble, Lanes, Member, MemberRun};
use crate::drive::Outcome;
use crate::event::{Direction, Event, Stop};
use crate::sample::{ImpactSequence, PeriodSummary, Periodic, Stroboscopic, detect_period};
use crate::sweep::{SweepConfig, SweepDirection, SweepError, SweepPoint};

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
    /// starts, one branch): [`sweep`](crate::sweep::sweep) with it returns the records
    /// of [`sweep_independent`] (bit for bit with [`LaneMath::Exact`](super::LaneMath)).
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

/// The most stored samples per value (the scalar sweep's capacity).
const CAP: usize = 1 << 20;

/// The observers of one value: the scalar [`run_point`](crate::sweep::run_point)'s.
type PointObserver = (
    Stroboscopic<f64, 2>,
    Option<ImpactSequence<f64, Stop>>,
    Option<PeriodSummary<f64, Periodic<f64>, Stop>>,
);

/// Builds the observers of one value.
fn observers(
    member: &Member,
    settings: &IndependentSweep,
    stop: Stop,
) -> Result<PointObserver, SweepError> {
    let param = member.omega();
    let fail = |e: crate::Error| SweepError::failed(param, e);
    let period = member.period();
    if !(period.is_finite() && period > 0.0) {
        return Err(SweepError::InvalidPeriod { param, period });
    }
    let t_rec = settings.transient as f64 * period;
    let strobe = Stroboscopic::<f64, 2>::periodic(0.0, period, t_rec + 0.5 * period, CAP)
        .map_err(|e| fail(e.into()))?;
    let impacts = ImpactSequence::on_surface(0, stop, t_rec, CAP).map_err(|e| fail(e.into()))?;
    let periods = PeriodSummary::periodic(0.0, period, 0, 0, 1, 0.0, t_rec, CAP)
        .map_err(|e| fail(e.into()))?
        .with_surface(stop);
    Ok((strobe, Some(impacts), Some(periods)))
}

/// The sweep's record of one value from its observers and outcome.
fn point(
    settings: &IndependentSweep,
    param: f64,
    obs: &PointObserver,
    outcome: &Outcome<f64, 2>,
) -> SweepPoint<2> {
    let (strobe, impacts, periods) = obs;
    let impact_list = impacts.as_ref().map_or(&[][..], |i| i.impacts());
    let period_list = periods.as_ref().map_or(&[][..], |p| p.periods());
    let impact_count = impacts.as_ref().map_or(0, |i| i.count());
    let poincare: Vec<SVector<f64, 2>> = strobe.points().iter().map(|p| p.y).collect();
    let mut scale = SVector::<f64, 2>::zeros();
    for p in &poincare {
        for c in 0..2 {
            scale[c] = scale[c].max(p[c].abs());
        }
    }
    let regime = detect_period(&poincare, &scale, settings.period_tol, settings.max_period);
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
        impacts_per_period: crate::sweep::impacts_per_period(
            period_list,
            regime,
            impact_count,
            settings.record,
        ),
        regime,
        grazing_margin,
        end_state: outcome.y,
    }
}

/// An independent-start sweep in lanes of `V`: every member runs from `y0` at `t = 0`,
/// `settings.transient` periods, then `settings.record` recorded periods, with steps
/// landing on the sections `t = i·2π/ω` and impacts the rising crossings of `stop` —
/// the records of [`sweep`](crate::sweep::sweep) with [`IndependentSweep::config`], in
/// the order of `members`.
///
/// `ensemble` gives the tolerances, step options, math mode and instruction set; its
/// event (if any) is replaced by `stop`'s impacts and its step cap by
/// `settings.max_steps`. With [`LaneMath::Exact`](super::LaneMath::Exact) every record is
/// the scalar sweep's to the bit (tested); on the calling thread (see
/// [`sweep_independent_parallel`] for the thread pool; the records are the same).
///
/// # Examples
/// ```
/// use nalgebra::Vector2;
/// use nonsmooth::ensemble::{Ensemble, F64x4, IndependentSweep, Member, sweep_independent};
/// use nonsmooth::event::Stop;
/// use nonsmooth::integrate::Tolerances;
/// use nonsmooth::systems::paper::PAPER;
///
/// let tol = Tolerances::per_component(1e-8, [1e-12, 1e-10])?;
/// let members = [19.0, 19.1, 19.2].map(|w| Member::paper(w)).into_iter().collect::<Result<Vec<_>, _>>()?;
/// let stop = Stop { position: 0, velocity: 1, level: PAPER.x_i };
/// let y0 = Vector2::new(PAPER.static_equilibrium()?, 0.0);
/// let settings = IndependentSweep::new(40, 10)?;
/// let points = sweep_independent::<F64x4>(&Ensemble::new(tol)?, &settings, &members, y0, stop)?;
/// assert_eq!(points.len(), 3);
/// assert_eq!(points[1].param, 19.1);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
///
/// # Errors
/// [`SweepError`]: invalid settings; [`SweepError::Failed`] with the parameter of the
/// first member (in order) whose run failed.
pub fn sweep_independent<V: Lanes>(
    ensemble: &Ensemble,
    settings: &IndependentSweep,
    members: &[Member],
    y0: SVector<f64, 2>,
    stop: Stop,
) -> Result<Vec<SweepPoint<2>>, SweepError> {
    let starts: Vec<_> = members.iter().map(|m| (*m, y0)).collect();
    first_failure(
        &starts,
        run_starts::<V>(ensemble, settings, &starts, stop, None)?,
    )
}

/// [`sweep_independent`] over the threads of the current rayon pool, `chunk` members per
/// task: the same records, bit for bit, for any number of threads.
///
/// # Errors
/// As [`sweep_independent`]; [`SweepError::Failed`] (a parameter error) if `chunk == 0`.
#[cfg(feature = "parallel")]
pub fn sweep_independent_parallel<V: Lanes>(
    ensemble: &Ensemble,
    settings: &IndependentSweep,
    members: &[Member],
    y0: SVector<f64, 2>,
    stop: Stop,
    chunk: usize,
) -> Result<Vec<SweepPoint<2>>, SweepError> {
    let starts: Vec<_> = members.iter().map(|m| (*m, y0)).collect();
    first_failure(
        &starts,
        run_starts::<V>(ensemble, settings, &starts, stop, Some(chunk))?,
    )
}

/// The records, or the first failure in start order (reported at its member's ω).
fn first_failure(
    starts: &[(Member, SVector<f64, 2>)],
    results: Vec<crate::Result<SweepPoint<2>>>,
) -> Result<Vec<SweepPoint<2>>, SweepError> {
    starts
        .iter()
        .zip(results)
        .map(|((m, _), r)| r.map_err(|e| SweepError::failed(m.omega(), e)))
        .collect()
}

/// Independent starts, each from its own initial state, with a result per start: the
/// lane form of calling [`run_point`](crate::sweep::run_point) once per start with
/// [`IndependentSweep::config`]'s settings and `Dopri5` (to the bit with
/// [`LaneMath::Exact`](super::LaneMath::Exact); the record's `param` is the member's ω).
/// A start that fails does not stop the others: its entry is the integration error
/// (what [`run_point`](crate::sweep::run_point) wraps in [`SweepError::Failed`]). This is
/// what a basin or parameter-plane study runs (`study` feature `cli`).
///
/// # Errors
/// The outer error: [`SweepError`] for invalid settings or no starts.
pub fn sweep_starts<V: Lanes>(
    ensemble: &Ensemble,
    settings: &IndependentSweep,
    starts: &[(Member, SVector<f64, 2>)],
    stop: Stop,
) -> Result<Vec<crate::Result<SweepPoint<2>>>, SweepError> {
    run_starts::<V>(ensemble, settings, starts, stop, None)
}

/// The lane runs of every start: on the calling thread, or over the rayon pool with
/// `chunk` starts per task.
fn run_starts<V: Lanes>(
    ensemble: &Ensemble,
    settings: &IndependentSweep,
    starts: &[(Member, SVector<f64, 2>)],
    stop: Stop,
    chunk: Option<usize>,
) -> Result<Vec<crate::Result<SweepPoint<2>>>, SweepError> {
    settings.check()?;
    if starts.is_empty() {
        return Err(SweepError::EmptyRange);
    }
    let omega0 = starts[0].0.omega();
    let batch_error = |e| SweepError::failed(omega0, e);
    let e = ensemble
        .clone()
        .with_event(Event::new(stop, Direction::Rising))
        .and_then(|e| e.max_steps(settings.max_steps))
        .map_err(batch_error)?;
    let periods = f64::from(settings.transient) + f64::from(settings.record);
    // Starts that cannot begin (a non-finite state) fail alone; the others run.
    let mut results: Vec<Option<crate::Result<SweepPoint<2>>>> = Vec::with_capacity(starts.len());
    let (mut jobs, mut obs, mut slot) = (Vec::new(), Vec::new(), Vec::new());
    for (k, (m, y0)) in starts.iter().enumerate() {
        match MemberRun::periods(*m, *y0, periods) {
            Ok(j) => {
                obs.push(observers(m, settings, stop)?);
                jobs.push(j);
                slot.push(k);
                results.push(None);
            }
            Err(err) => results.push(Some(Err(err))),
        }
    }
    if !jobs.is_empty() {
        let out = match chunk {
            None => e.run::<V, _, _>(&jobs, &mut obs),
            #[cfg(feature = "parallel")]
            Some(c) => e.run_parallel::<V, _, _>(&jobs, &mut obs, c),
            #[cfg(not(feature = "parallel"))]
            Some(_) => e.run::<V, _, _>(&jobs, &mut obs),
        }
        .map_err(batch_error)?;
        for ((k, o), r) in slot.into_iter().zip(&obs).zip(out) {
            let m = &starts[k].0;
            results[k] = Some(r.map(|outcome| point(settings, m.omega(), o, &outcome)));
        }
    }
    Ok(results.into_iter().flatten().collect())
}
