//! The scalar path of a study point for any system: one [`Simulation`] (or a run through
//! rigid contact with sticking, [`run_with_sticking`]) with a stroboscopic sampler and the
//! impacts on each surface, then the top Lyapunov exponent by two trajectories
//! ([`TwoTrajectory`] in one augmented state for smooth systems; [`HybridTwoTrajectory`],
//! which carries the resets, for rigid impacts).
//!
//! The paper's model does not come here: its points run in lanes, and its scalar reference
//! is [`sweep::run_point`](crate::sweep::run_point) (see `catalogue::Paper`).

use nalgebra::SVector;

use super::system::{PointRun, RunSettings};
use crate::Dynamics;
use crate::drive::{Control, EventRecord, Observer, RunError, Simulation, run_with_sticking};
use crate::event::{Direction, Event, EventError, EventFunction, EventSet, NewtonImpact};
use crate::excite::Excitation;
use crate::integrate::{Dopri5, Tolerances};
use crate::lyapunov::{HybridTwoTrajectory, Norm, TwoTrajectory};
use crate::model::{Elements, Loads, Mechanical};
use crate::sample::{Regime, Stroboscopic, detect_period};

/// The most impact surfaces of one system on the scalar path (each is an event of the run).
pub const MAX_SURFACES: usize = 4;

/// Impact surfaces as events of one run: surface `k` is event `k` (rising crossings of its
/// penetration, no reset); unused slots never fire. At most [`MAX_SURFACES`] surfaces
/// (the set always has that many events).
#[derive(Debug, Clone)]
pub struct SurfaceEvents<G>(pub Vec<G>);

impl<const M: usize, G: EventFunction<f64, M>> EventSet<f64, M> for SurfaceEvents<G> {
    const LEN: usize = MAX_SURFACES;
    #[inline(always)]
    fn value(&self, i: usize, t: f64, y: &SVector<f64, M>) -> f64 {
        self.0.get(i).map_or(-1.0, |g| g.value(t, y))
    }
    #[inline(always)]
    fn rate(&self, i: usize, t: f64, y: &SVector<f64, M>, dy: &SVector<f64, M>) -> Option<f64> {
        self.0.get(i).map_or(Some(0.0), |g| g.rate(t, y, dy))
    }
    fn direction(&self, _i: usize) -> Direction {
        Direction::Rising
    }
    fn is_terminal(&self, _i: usize) -> bool {
        false
    }
    fn resets(&self, _i: usize) -> bool {
        false
    }
    fn apply_reset(&self, _i: usize, _t: f64, _y: &mut SVector<f64, M>) {}
    fn interior_samples(&self, _i: usize) -> usize {
        0
    }
    fn check(&self) -> Result<(), EventError> {
        self.0.iter().try_for_each(|g| g.check())
    }
    fn chord_bounds(
        &self,
        i: usize,
        t0: f64,
        t1: f64,
        dev: &SVector<f64, M>,
        mag: &SVector<f64, M>,
    ) -> Option<(f64, f64)> {
        self.0
            .get(i)
            .map_or(Some((0.0, 1.0)), |g| g.chord_bounds(t0, t1, dev, mag))
    }
    fn max_step(&self, t: f64) -> Option<f64> {
        self.0
            .iter()
            .filter_map(|g| g.time_scale(t))
            .fold(None, |m: Option<f64>, h| Some(m.map_or(h, |m| m.min(h))))
    }
    fn constant_max_step(&self) -> bool {
        self.0.iter().all(|g| g.constant_time_scale())
    }
}

/// The impacts of a run: rising crossings of surface `k` (event `k`) from `record_from` on,
/// with the interval since the surface's previous impact.
#[derive(Debug, Clone)]
pub(super) struct ImpactLog {
    record_from: f64,
    last: Vec<Option<f64>>,
    /// `(t, surface)` in time order.
    impacts: Vec<(f64, usize)>,
    intervals: Vec<f64>,
}

impl<const M: usize> Observer<f64, M> for ImpactLog {
    fn wants_steps(&self) -> bool {
        false
    }
    fn on_event(&mut self, e: &EventRecord<f64, M>) -> Control {
        if e.direction != Direction::Rising {
            return Control::Continue;
        }
        let Some(last) = self.last.get_mut(e.index) else {
            return Control::Continue;
        };
        let interval = last.map(|l| e.t - l);
        *last = Some(e.t);
        if e.t >= self.record_from {
            self.impacts.push((e.t, e.index));
            if let Some(i) = interval {
                self.intervals.push(i);
            }
        }
        Control::Continue
    }
}

/// Impacts per forcing period from per-period counts: for a period-`p` orbit over the
/// largest whole number of orbit periods in the window, otherwise over the window (as
/// [`sweep::run_point`](crate::sweep::run_point) counts them).
fn per_period(counts: &[u64], period: usize) -> f64 {
    let n = counts.len();
    let whole = n.checked_div(period).map_or(0, |k| k * period);
    let window = if whole > 0 { whole } else { n.max(1) };
    let sum: u64 = counts[n - window.min(n)..].iter().sum();
    sum as f64 / window as f64
}

/// The tolerances of a state of dimension `M`.
pub(super) fn tolerances<const M: usize>(s: &RunSettings) -> Result<Tolerances<f64, M>, String> {
    let atol: [f64; M] = s.atol.as_slice().try_into().map_err(|_| {
        format!(
            "internal: {} absolute tolerances for {M} state components",
            s.atol.len()
        )
    })?;
    Tolerances::per_component(s.rtol, atol).map_err(|e| e.to_string())
}

pub(super) fn state<const M: usize>(y: &[f64]) -> Result<SVector<f64, M>, String> {
    if y.len() != M {
        return Err(format!(
            "internal: initial state of {} components for {M}",
            y.len()
        ));
    }
    Ok(SVector::from_column_slice(y))
}

/// The observers of a run: the sections and the impacts on each surface.
pub(super) type Observers<const M: usize> = (Stroboscopic<f64, M>, ImpactLog);

/// The observers of a run and the window they record.
pub(super) struct Recording<const M: usize> {
    pub obs: Observers<M>,
    t_rec: f64,
    pub t_end: f64,
}

impl<const M: usize> Recording<M> {
    pub fn new(s: &RunSettings, period: f64, surfaces: usize) -> Result<Self, String> {
        if !(period.is_finite() && period > 0.0) {
            return Err(format!("invalid forcing period {period}"));
        }
        let t_rec = f64::from(s.transient) * period;
        let t_end = (f64::from(s.transient) + f64::from(s.record)) * period;
        // Sections at i·period for i = transient+1 ..= transient+record.
        let strobe = Stroboscopic::<f64, M>::periodic(0.0, period, t_rec + 0.5 * period, 1 << 20)
            .map_err(|e| e.to_string())?;
        let impacts = ImpactLog {
            record_from: t_rec,
            last: vec![None; surfaces],
            impacts: Vec::new(),
            intervals: Vec::new(),
        };
        Ok(Self {
            obs: (strobe, impacts),
            t_rec,
            t_end,
        })
    }

    /// The record of the window (without the exponent).
    pub fn finish(self, s: &RunSettings, period: f64) -> PointRun {
        let (strobe, impacts) = self.obs;
        // A run through modes restarts its observers at each mode change: a section at the
        // change is seen twice.
        let mut points = strobe.points().to_vec();
        points.dedup_by_key(|p| p.index);
        let poincare: Vec<SVector<f64, M>> = points.iter().map(|p| p.y).collect();
        let mut scale = SVector::<f64, M>::zeros();
        for p in &poincare {
            for c in 0..M {
                scale[c] = scale[c].max(p[c].abs());
            }
        }
        let regime = detect_period(&poincare, &scale, s.period_tol, s.max_period);
        let period_n = match regime {
            Regime::Periodic(p) => p,
            Regime::NotPeriodic => 0,
        };
        // At least one recorded period (the spec's check; one bucket all the same).
        let n = (s.record as usize).max(1);
        let surfaces = impacts.last.len();
        let mut counts = vec![vec![0u64; n]; surfaces];
        let mut total = vec![0u64; n];
        for &(t, k) in &impacts.impacts {
            // `as` saturates (NaN to 0): every impact lands in a bucket of the window.
            let i = (((t - self.t_rec) / period).floor().max(0.0) as usize).min(n - 1);
            if let Some(c) = counts.get_mut(k) {
                c[i] += 1;
            }
            total[i] += 1;
        }
        PointRun {
            period: period_n,
            poincare: poincare.iter().map(|p| p.as_slice().to_vec()).collect(),
            impacts_per_period: per_period(&total, period_n),
            impacts_per_surface: counts.iter().map(|c| per_period(c, period_n)).collect(),
            intervals: impacts.intervals,
            lyapunov: None,
        }
    }
}

/// An estimator of the top Lyapunov exponent and its spread from the tolerances, the norm,
/// `d0` and the number of periods.
trait Estimate<const M: usize>:
    FnOnce(Tolerances<f64, M>, Norm<f64, M>, f64, usize) -> crate::Result<(f64, f64)>
{
}

impl<const M: usize, F> Estimate<M> for F where
    F: FnOnce(Tolerances<f64, M>, Norm<f64, M>, f64, usize) -> crate::Result<(f64, f64)>
{
}

/// The top Lyapunov exponent from the end state of a run (phase 0): `estimate(tol, norm,
/// d0, periods)` runs the estimator.
fn lyapunov<const M: usize>(
    s: &RunSettings,
    estimate: impl Estimate<M>,
) -> Option<Result<(f64, f64), String>> {
    let (periods, d0) = s.lyapunov?;
    let run = || -> crate::Result<(f64, f64)> {
        let scales: [f64; M] = s.scales.as_slice().try_into().map_err(|_| {
            crate::ParameterError::new("scales", s.scales.len() as f64, "one per component")
        })?;
        let atol: [f64; M] = s.atol.as_slice().try_into().map_err(|_| {
            crate::ParameterError::new("atol", s.atol.len() as f64, "one per component")
        })?;
        let tol = Tolerances::per_component(s.rtol, atol)?;
        estimate(tol, Norm::weighted(scales)?, d0, periods)
    };
    Some(run().map_err(|e| e.to_string()))
}

/// Runs `system` with impacts counted on `surfaces` (compliant contacts: events without
/// resets), sections every `period`, and the exponent if asked for: two trajectories in one
/// augmented state of dimension `M2 = 2M` ([`TwoTrajectory`], which integrates both with
/// the same steps, as for the paper's model).
///
/// # Errors
/// The run's error, as the point's status.
pub(crate) fn run_smooth<const M: usize, const M2: usize, S, G>(
    s: &RunSettings,
    system: S,
    surfaces: Vec<G>,
    period: f64,
    y0: &[f64],
) -> Result<PointRun, String>
where
    S: Dynamics<f64, M> + Clone,
    G: EventFunction<f64, M> + Clone,
{
    if surfaces.len() > MAX_SURFACES {
        return Err(format!(
            "{} impact surfaces; at most {MAX_SURFACES}",
            surfaces.len()
        ));
    }
    let y0 = state::<M>(y0)?;
    let tol = tolerances::<M>(s)?;
    let mut rec = Recording::<M>::new(s, period, surfaces.len())?;
    let fail = |e: RunError| e.to_string();
    let mut sim = Simulation::new(system.clone(), Dopri5::new(tol))
        .with_events(SurfaceEvents(surfaces))
        .landing_grid(Some((0.0, period)))
        .map_err(|e| e.to_string())?
        .max_steps(s.max_steps)
        .map_err(|e| e.to_string())?;
    let out = sim.run(0.0, y0, rec.t_end, &mut rec.obs).map_err(fail)?;
    Ok(smooth_record::<M, M2, S>(s, rec, system, period, out.y))
}

/// The record of a smooth run from its observers and end state `y_end` (after a whole
/// number of periods), with the exponent if asked for: two trajectories in one augmented
/// state from `y_end` at phase 0.
pub(super) fn smooth_record<const M: usize, const M2: usize, S: Dynamics<f64, M> + Clone>(
    s: &RunSettings,
    rec: Recording<M>,
    system: S,
    period: f64,
    y_end: SVector<f64, M>,
) -> PointRun {
    let mut run = rec.finish(s, period);
    run.lyapunov = lyapunov::<M>(s, |tol, norm, d0, periods| {
        let mut est = TwoTrajectory::<f64, M, M2, _, _>::with_tolerances(
            system,
            Dopri5::new,
            &tol,
            d0,
            norm,
        )?;
        // The run ended after a whole number of periods: t = 0 has the same phase.
        est.start(0.0, y_end)?;
        let e = est.estimate(period, periods)?;
        Ok((e.exponent, e.spread))
    });
    run
}

/// Runs a mechanical system with one rigid impact surface (Newton restitution) through
/// chattering, sticking and release ([`run_with_sticking`], at most `max_steps` mode
/// segments); the exponent by two trajectories with the impact's reset (a point that
/// sticks has none: two trajectories cannot follow a sticking phase).
///
/// # Errors
/// The run's error, as the point's status.
pub(crate) fn run_rigid<const N: usize, const M: usize, El, Ld, Sm>(
    s: &RunSettings,
    model: Mechanical<f64, N, El, Ld>,
    impact: NewtonImpact<f64, N, Sm>,
    period: f64,
    y0: &[f64],
) -> Result<PointRun, String>
where
    El: Elements<f64, N> + Clone,
    Ld: Loads<f64, N> + Clone,
    Sm: Excitation<f64> + Clone,
    Mechanical<f64, N, El, Ld>: Dynamics<f64, M>,
{
    let y0 = state::<M>(y0)?;
    let tol = tolerances::<M>(s)?;
    let mut rec = Recording::<M>::new(s, period, 1)?;
    let (out, _) = run_with_sticking(
        &model,
        &impact,
        || Dopri5::new(tol),
        0.0,
        y0,
        rec.t_end,
        s.max_steps,
        &mut rec.obs,
    )
    .map_err(|e| e.to_string())?;
    let mut run = rec.finish(s, period);
    let events = Event::new(impact.gap().clone(), Direction::Rising).with_reset(impact);
    run.lyapunov = lyapunov::<M>(s, |tol, norm, d0, periods| {
        let mut est = HybridTwoTrajectory::new(model, Dopri5::new(tol), events, d0, norm)?;
        est.start(0.0, out.y)?;
        let e = est.estimate(period, periods)?;
        Ok((e.exponent, e.spread))
    });
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn impacts_per_period_over_whole_orbit_periods() {
        // Period 3 with 4 impacts per orbit in a 10-period window: the last 9 periods.
        let counts = [5, 2, 1, 1, 2, 1, 1, 2, 1, 1];
        assert_eq!(per_period(&counts, 3), 12.0 / 9.0);
        assert_eq!(per_period(&counts, 0), 17.0 / 10.0);
        assert_eq!(per_period(&counts, 20), 17.0 / 10.0);
        assert_eq!(per_period(&[], 0), 0.0);
    }
}
