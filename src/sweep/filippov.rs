//! Sweeps of forced Filippov systems: stroboscopic points and the time spent sliding per
//! parameter value, through crossings and sliding.
//!
//! Each value is one event-driven [`FilippovSimulation`] run (transient periods, then
//! recorded ones) observed by the crate's [`Stroboscopic`] sampler through
//! [`Plain`](crate::filippov::Plain) — the samplers of smooth and impacting runs work
//! unchanged on Filippov runs — and by a count of the sliding segments and their time.

use nalgebra::SVector;

use super::{SweepConfig, SweepError};
use crate::drive::{Control, StepView};
use crate::filippov::{Filippov, FilippovSimulation, Mode, ModeTransition, Plain, SlidingObserver};
use crate::integrate::{DenseOutput, Stepper};
use crate::sample::{Regime, Stroboscopic, detect_period};

/// What was recorded at one parameter value of [`sweep_filippov`].
#[derive(Debug, Clone, PartialEq)]
pub struct SlidingSweepPoint<const N: usize> {
    /// Parameter value.
    pub param: f64,
    /// Stroboscopic points (one per recorded period, at `t = k·T`).
    pub poincare: Vec<SVector<f64, N>>,
    /// The regime from the stroboscopic points.
    pub regime: Regime,
    /// Sliding entries in the recording window.
    pub sliding_entries: usize,
    /// The fraction of the recording window spent sliding (on any surface).
    pub sliding_fraction: f64,
    /// The state at the end of the run (phase 0).
    pub end_state: SVector<f64, N>,
}

/// The stroboscopic sampler (through [`Plain`]) and the sliding time from `record_from` on.
struct Recorder<const N: usize> {
    strobe: Plain<Stroboscopic<f64, N>>,
    record_from: f64,
    entries: usize,
    sliding: f64,
}

impl<const N: usize, const S: usize> SlidingObserver<f64, N, S> for Recorder<N> {
    fn on_start(&mut self, t0: f64, x0: &SVector<f64, N>, mode: &Mode<S>) {
        SlidingObserver::<f64, N, S>::on_start(&mut self.strobe, t0, x0, mode);
    }
    fn on_step<D: DenseOutput<f64, N>>(
        &mut self,
        mode: &Mode<S>,
        step: &StepView<'_, f64, N, D>,
    ) -> Control {
        if mode.is_sliding() {
            let from = step.t0.max(self.record_from);
            if step.t1 > from {
                self.sliding += step.t1 - from;
            }
        }
        SlidingObserver::<f64, N, S>::on_step(&mut self.strobe, mode, step)
    }
    fn on_transition(&mut self, tr: &ModeTransition<f64, N, S>) -> Control {
        if tr.t >= self.record_from && tr.to.is_sliding() && !tr.from.is_sliding() {
            self.entries += 1;
        }
        SlidingObserver::<f64, N, S>::on_transition(&mut self.strobe, tr)
    }
}

/// Sweeps a forced Filippov system over `config`'s values in increasing order:
/// `build(p)` is the simulation at `p`, `period(p)` its forcing period. The first value
/// starts from `x0` with `config`'s first transient; with continuation, each next value
/// starts from the previous end state (at phase 0) with the per-step transient, else from
/// `x0` with the first transient. The stroboscopic points of the recorded periods give the
/// [`Regime`] (period detection as in [`sweep`](super::sweep), each component relative to
/// its magnitude over the points, floored at `10⁻³` of the largest).
///
/// # Errors
/// [`SweepError::InvalidPeriod`] for a period that is not finite and > 0;
/// [`SweepError::Failed`] with the builder's or the run's error at that value.
pub fn sweep_filippov<Sys, St, B, P, const N: usize, const S: usize>(
    config: &SweepConfig,
    build: B,
    period: P,
    x0: SVector<f64, N>,
) -> Result<Vec<SlidingSweepPoint<N>>, SweepError>
where
    B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>, SweepError>,
    P: Fn(f64) -> f64,
    Sys: Filippov<f64, N, S>,
    St: Stepper<f64, N>,
{
    let mut out: Vec<SlidingSweepPoint<N>> = Vec::with_capacity(config.values.len());
    for &param in &config.values {
        let t_period = period(param);
        if !(t_period.is_finite() && t_period > 0.0) {
            return Err(SweepError::InvalidPeriod {
                param,
                period: t_period,
            });
        }
        let (start, transient) = match out.last() {
            Some(prev) if config.continuation => (prev.end_state, config.transient_step),
            _ => (x0, config.transient_first),
        };
        let record_from = f64::from(transient) * t_period;
        let t_end = (f64::from(transient) + f64::from(config.record)) * t_period;
        let strobe = Stroboscopic::periodic(0.0, t_period, record_from, config.record as usize + 1)
            .map_err(|e| SweepError::failed(param, e))?;
        let mut rec = Recorder {
            strobe: Plain(strobe),
            record_from,
            entries: 0,
            sliding: 0.0,
        };
        let mut sim = build(param)?;
        let run = sim
            .run::<N, S, _>(0.0, start, t_end, &mut rec)
            .map_err(|e| SweepError::failed(param, e))?;
        let poincare: Vec<SVector<f64, N>> = rec.strobe.0.points().iter().map(|p| p.y).collect();
        // Each component on its own magnitude, floored at 10⁻³ of the largest (a
        // component that stays near 0 — a velocity at phase 0 — is not measured relative
        // to its own rounding).
        let mut scale = SVector::<f64, N>::zeros();
        for p in &poincare {
            for c in 0..N {
                scale[c] = scale[c].max(p[c].abs());
            }
        }
        let floor = (1e-3 * scale.amax()).max(f64::MIN_POSITIVE);
        scale.apply(|v| *v = v.max(floor));
        let regime = detect_period(&poincare, &scale, config.period_tol, config.max_period);
        out.push(SlidingSweepPoint {
            param,
            poincare,
            regime,
            sliding_entries: rec.entries,
            sliding_fraction: rec.sliding / (t_end - record_from),
            end_state: run.x,
        });
    }
    Ok(out)
}
