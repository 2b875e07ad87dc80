//! The two-trajectory (Benettin) top exponent in the lanes of an
//! [`Ensemble`], for many parameter values at once, of any model with a lane form.

use nalgebra::SVector;

use super::{DiagramPoint, DiagramSettings, LyapunovError, Norm, block_standard_error, grid_time};
use crate::LaneDynamics;
use crate::drive::{Outcome, RunError};
use crate::ensemble::{Ensemble, MemberRun};
use crate::integrate::Stats;

/// `Result` with [`LyapunovError`].
type Result<T, E = LyapunovError> = std::result::Result<T, E>;

/// The ensemble's outcomes of a batch (outer error: the batch could not run).
type Outcomes<const M: usize> =
    std::result::Result<Vec<std::result::Result<Outcome<f64, M>, RunError>>, RunError>;

/// The top Lyapunov exponent of every `(p, system)` of `systems` from the same initial
/// state (independent starts), by the two-trajectory method with the renormalization rule of
/// [`TwoTrajectory`](crate::lyapunov::TwoTrajectory), both trajectories of every pair in
/// lanes of `V`.
///
/// Any model with a lane form runs ([`LaneDynamics`]: an
/// [`Oscillator`](crate::model::Oscillator), a [`Mechanical`](crate::model::Mechanical),
/// any [`Dynamics`](crate::Dynamics) through [`LaneByLane`](crate::LaneByLane)); `p` is
/// the parameter value the record carries and gives the interval `τ =
/// settings.interval.interval(p)`.
///
/// For each system: the reference starts at `(settings.t0, y0)`, the perturbed copy at
/// `y0 + d0·e` with `e` the unit vector along the norm's scales; `settings.first_transient`
/// intervals of `τ` are run and renormalized without being
/// recorded (a separation lost to rounding there is re-seeded along `e`), then
/// `settings.intervals` recorded ones: after each, `d = ‖ỹ − y‖`, the local rate
/// `ln(d/d_start)/τ` is recorded and `ỹ ← y + (ỹ − y)·d0/d`. The estimate is the mean of
/// the rates, its spread the block standard error over `settings.blocks` blocks — the
/// scalar estimator's formulas. `settings.step_transient` is not used (there is no
/// continuation).
///
/// # Agreement with the scalar estimator
/// The scalar estimator integrates the pair as one system of dimension 4 with one step
/// size (its error norm covers both copies); here each copy has its own step and each
/// interval restarts both lanes (Hairer's first-step guess). The step sequences differ, so
/// the estimates agree with the scalar ones within the estimator's spread, not to the bit
/// (tested on the paper's model: periodic and chaotic values).
///
/// # Errors
/// [`LyapunovError`] for empty `systems`, a bad `d0`, norm, interval or block count, a
/// separation lost in a recorded interval; the first integration error in the order of
/// `systems` ([`LyapunovError::Run`]).
pub fn tle_independent<D: LaneDynamics<M> + Clone, const M: usize>(
    ensemble: &Ensemble<(), M>,
    systems: &[(f64, D)],
    y0: SVector<f64, M>,
    d0: f64,
    norm: Norm<f64, M>,
    settings: &DiagramSettings<f64>,
) -> Result<Vec<DiagramPoint<f64>>> {
    estimate(systems, y0, d0, norm, settings, |jobs| {
        let mut obs = vec![(); jobs.len()];
        ensemble.run(jobs, &mut obs)
    })
}

/// [`tle_independent`] over the threads of the current rayon pool, `chunk` trajectories
/// per task: the same results, bit for bit, for any number of threads.
///
/// # Errors
/// As [`tle_independent`]; a parameter error if `chunk == 0`.
#[cfg(feature = "parallel")]
pub fn tle_independent_parallel<D: LaneDynamics<M> + Clone + Sync, const M: usize>(
    ensemble: &Ensemble<(), M>,
    systems: &[(f64, D)],
    y0: SVector<f64, M>,
    d0: f64,
    norm: Norm<f64, M>,
    settings: &DiagramSettings<f64>,
    chunk: usize,
) -> Result<Vec<DiagramPoint<f64>>> {
    estimate(systems, y0, d0, norm, settings, |jobs| {
        let mut obs = vec![(); jobs.len()];
        ensemble.run_parallel(jobs, &mut obs, chunk)
    })
}

/// One pair's state between intervals.
struct Pair<D, const M: usize> {
    param: f64,
    system: D,
    tau: f64,
    a: SVector<f64, M>,
    b: SVector<f64, M>,
    d_start: f64,
    local: Vec<f64>,
    stats: Stats,
}

/// Checks the inputs of [`estimate`]; returns the separation direction `dir`, the second
/// start `y0 + d0·dir` and the separation realized after rounding.
fn start_pair<const M: usize>(
    n_systems: usize,
    y0: SVector<f64, M>,
    d0: f64,
    norm: &Norm<f64, M>,
    settings: &DiagramSettings<f64>,
) -> Result<(SVector<f64, M>, SVector<f64, M>, f64)> {
    if n_systems == 0 {
        return Err(LyapunovError::NoParameters);
    }
    if !(d0.is_finite() && d0 > 0.0) {
        return Err(LyapunovError::InvalidSeparation { d0 });
    }
    norm.validate()?;
    if settings.intervals < 2 {
        return Err(LyapunovError::TooFewIntervals {
            intervals: settings.intervals,
            minimum: 2,
        });
    }
    if settings.blocks < 2 {
        return Err(LyapunovError::InvalidBlocks {
            blocks: settings.blocks,
        });
    }
    let t0 = settings.t0;
    if !(t0.is_finite() && y0.iter().all(|v| v.is_finite())) {
        return Err(LyapunovError::NonFinite {
            what: "t0 or y0",
            value: t0,
        });
    }
    let w = norm.scales();
    let dir = w / norm.norm(&w);
    let y1 = y0 + dir * d0;
    let realized = norm.norm(&(y1 - y0));
    if !((realized - d0).abs() <= 1e-3 * d0) {
        return Err(LyapunovError::UnresolvedSeparation { d0, realized });
    }
    Ok((dir, y1, realized))
}

fn estimate<D: LaneDynamics<M> + Clone, const M: usize>(
    systems: &[(f64, D)],
    y0: SVector<f64, M>,
    d0: f64,
    norm: Norm<f64, M>,
    settings: &DiagramSettings<f64>,
    run: impl Fn(&[MemberRun<D, M>]) -> Outcomes<M>,
) -> Result<Vec<DiagramPoint<f64>>> {
    let (dir, y1, realized) = start_pair(systems.len(), y0, d0, &norm, settings)?;
    let (n, t0) = (settings.intervals, settings.t0);
    let mut pairs = Vec::with_capacity(systems.len());
    for (p, system) in systems {
        pairs.push(Pair {
            param: *p,
            system: system.clone(),
            tau: settings.interval.interval(*p)?,
            a: y0,
            b: y1,
            d_start: realized,
            local: Vec::with_capacity(n),
            stats: Stats::default(),
        });
    }
    let transient = settings.first_transient;
    let mut jobs = Vec::with_capacity(2 * systems.len());
    for k in 0..transient + n {
        let recording = k >= transient;
        // The scalar estimator's clock: `t_s + τ·j` from the start `t_s` of each stage.
        let j = if recording { k - transient } else { k };
        jobs.clear();
        for p in &pairs {
            let start = if recording {
                grid_time(t0, p.tau, transient)
            } else {
                t0
            };
            let (t_a, t_b) = (grid_time(start, p.tau, j), grid_time(start, p.tau, j + 1));
            jobs.push(MemberRun::new(p.system.clone(), t_a, p.a, t_b)?);
            jobs.push(MemberRun::new(p.system.clone(), t_a, p.b, t_b)?);
        }
        let out = run(&jobs)?;
        let mut out = out.into_iter();
        for p in &mut pairs {
            let (Some(ra), Some(rb)) = (out.next(), out.next()) else {
                break;
            };
            p.renormalize(&ra?, &rb?, recording, (dir, d0), &norm)?;
        }
    }
    Ok(pairs.iter().map(|p| p.point(settings.blocks)).collect())
}

impl<D, const M: usize> Pair<D, M> {
    /// The pair after an interval whose runs ended in `oa` (reference) and `ob`
    /// (perturbed): the local exponent (if `recording`), and the perturbed state back at
    /// distance `d0` along the separation (along `dir` if it vanished in the transient).
    fn renormalize(
        &mut self,
        oa: &crate::drive::Outcome<f64, M>,
        ob: &crate::drive::Outcome<f64, M>,
        recording: bool,
        (dir, d0): (SVector<f64, M>, f64),
        norm: &Norm<f64, M>,
    ) -> Result<()> {
        if recording {
            self.stats += &oa.stats;
            self.stats += &ob.stats;
        }
        let a = oa.y;
        let mut delta = ob.y - a;
        let mut d = norm.norm(&delta);
        if !recording && d == 0.0 {
            delta = dir * d0;
            d = norm.norm(&delta);
        }
        if !(d.is_finite() && d > 0.0) {
            return Err(LyapunovError::SeparationLost {
                t: oa.t,
                separation: d,
            });
        }
        if recording {
            self.local.push((d / self.d_start).ln() / self.tau);
        }
        let b_new = a + delta * (d0 / d);
        self.d_start = norm.norm(&(b_new - a));
        if !(self.d_start > 0.0) {
            return Err(LyapunovError::UnresolvedSeparation {
                d0,
                realized: self.d_start,
            });
        }
        self.a = a;
        self.b = b_new;
        Ok(())
    }

    /// The pair's diagram point: the mean of its local exponents and their block
    /// standard error over `blocks` blocks.
    fn point(&self, blocks: usize) -> DiagramPoint<f64> {
        let n = self.local.len();
        let sum: f64 = self.local.iter().fold(0.0, |s, &x| s + x);
        DiagramPoint {
            parameter: self.param,
            exponent: sum / n as f64,
            spread: block_standard_error(n, blocks.min(n), |k| self.local[k]),
            stats: self.stats,
        }
    }
}
