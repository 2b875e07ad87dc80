//! The two-trajectory (Benettin) top exponent in lanes, for many parameter values at once.

use nalgebra::SVector;

use super::{Ensemble, Lanes, Member, MemberRun};
use crate::drive::Outcome;
use crate::error::Result;
use crate::integrate::Stats;
use crate::lyapunov::{DiagramPoint, DiagramSettings, LyapunovError, Norm};

/// The top Lyapunov exponent of every member from the same initial state (independent
/// starts), by the two-trajectory method with the renormalization rule of
/// [`TwoTrajectory`](crate::lyapunov::TwoTrajectory), both trajectories of every pair in
/// lanes of `V`.
///
/// For each member: the reference starts at `(settings.t0, y0)`, the perturbed copy at
/// `y0 + d0·e` with `e` the unit vector along the norm's scales; `settings.first_transient`
/// intervals of `τ = settings.interval.interval(ω)` are run and renormalized without being
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
/// [`LyapunovError`] for empty `members`, a bad `d0`, norm, interval or block count, a
/// separation lost in a recorded interval; the first integration error in member order.
pub fn tle_independent<V: Lanes>(
    ensemble: &Ensemble,
    members: &[Member],
    y0: SVector<f64, 2>,
    d0: f64,
    norm: Norm<f64, 2>,
    settings: &DiagramSettings<f64>,
) -> Result<Vec<DiagramPoint<f64>>> {
    estimate(members, y0, d0, norm, settings, |jobs| {
        let mut obs = vec![(); jobs.len()];
        ensemble.run::<V, _, _>(jobs, &mut obs)
    })
}

/// [`tle_independent`] over the threads of the current rayon pool, `chunk` trajectories
/// per task: the same results, bit for bit, for any number of threads.
///
/// # Errors
/// As [`tle_independent`]; a parameter error if `chunk == 0`.
#[cfg(feature = "parallel")]
pub fn tle_independent_parallel<V: Lanes>(
    ensemble: &Ensemble,
    members: &[Member],
    y0: SVector<f64, 2>,
    d0: f64,
    norm: Norm<f64, 2>,
    settings: &DiagramSettings<f64>,
    chunk: usize,
) -> Result<Vec<DiagramPoint<f64>>> {
    estimate(members, y0, d0, norm, settings, |jobs| {
        let mut obs = vec![(); jobs.len()];
        ensemble.run_parallel::<V, _, _>(jobs, &mut obs, chunk)
    })
}

/// One pair's state between intervals.
struct Pair {
    member: Member,
    tau: f64,
    a: SVector<f64, 2>,
    b: SVector<f64, 2>,
    d_start: f64,
    local: Vec<f64>,
    stats: Stats,
}

fn estimate(
    members: &[Member],
    y0: SVector<f64, 2>,
    d0: f64,
    norm: Norm<f64, 2>,
    settings: &DiagramSettings<f64>,
    run: impl Fn(&[MemberRun]) -> Result<Vec<Result<Outcome<f64, 2>>>>,
) -> Result<Vec<DiagramPoint<f64>>> {
    if members.is_empty() {
        return Err(LyapunovError::NoParameters.into());
    }
    if !(d0.is_finite() && d0 > 0.0) {
        return Err(LyapunovError::InvalidSeparation { d0 }.into());
    }
    norm.validate()?;
    let n = settings.intervals;
    if n < 2 {
        return Err(LyapunovError::TooFewIntervals {
            intervals: n,
            minimum: 2,
        }
        .into());
    }
    if settings.blocks < 2 {
        return Err(LyapunovError::InvalidBlocks {
            blocks: settings.blocks,
        }
        .into());
    }
    let t0 = settings.t0;
    if !(t0.is_finite() && y0.iter().all(|v| v.is_finite())) {
        return Err(LyapunovError::NonFinite {
            what: "t0 or y0",
            value: t0,
        }
        .into());
    }
    let w = norm.scales();
    let dir = w / norm.norm(&w);
    let y1 = y0 + dir * d0;
    let realized = norm.norm(&(y1 - y0));
    if !((realized - d0).abs() <= 1e-3 * d0) {
        return Err(LyapunovError::UnresolvedSeparation { d0, realized }.into());
    }
    let mut pairs = Vec::with_capacity(members.len());
    for m in members {
        pairs.push(Pair {
            member: *m,
            tau: settings.interval.interval(m.omega())?,
            a: y0,
            b: y1,
            d_start: realized,
            local: Vec::with_capacity(n),
            stats: Stats::default(),
        });
    }
    let transient = settings.first_transient;
    let mut jobs = Vec::with_capacity(2 * members.len());
    for k in 0..transient + n {
        let recording = k >= transient;
        // The scalar estimator's clock: `t_s + τ·j` from the start `t_s` of each stage.
        let j = if recording { k - transient } else { k };
        jobs.clear();
        for p in &pairs {
            let start = if recording {
                grid(t0, p.tau, transient)
            } else {
                t0
            };
            let (t_a, t_b) = (grid(start, p.tau, j), grid(start, p.tau, j + 1));
            jobs.push(MemberRun::new(p.member, t_a, p.a, t_b)?);
            jobs.push(MemberRun::new(p.member, t_a, p.b, t_b)?);
        }
        let out = run(&jobs)?;
        let mut out = out.into_iter();
        for p in &mut pairs {
            let (Some(ra), Some(rb)) = (out.next(), out.next()) else {
                break;
            };
            let (oa, ob) = (ra?, rb?);
            if recording {
                p.stats += &oa.stats;
                p.stats += &ob.stats;
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
                }
                .into());
            }
            if recording {
                p.local.push((d / p.d_start).ln() / p.tau);
            }
            let b_new = a + delta * (d0 / d);
            p.d_start = norm.norm(&(b_new - a));
            if !(p.d_start > 0.0) {
                return Err(LyapunovError::UnresolvedSeparation {
                    d0,
                    realized: p.d_start,
                }
                .into());
            }
            p.a = a;
            p.b = b_new;
        }
    }
    Ok(pairs
        .iter()
        .map(|p| {
            let sum: f64 = p.local.iter().fold(0.0, |s, &x| s + x);
            DiagramPoint {
                parameter: p.member.omega(),
                exponent: sum / n as f64,
                spread: block_standard_error(&p.local, settings.blocks.min(n)),
                stats: p.stats,
            }
        })
        .collect())
}

/// `t0 + τ·k` (never accumulated).
fn grid(t0: f64, tau: f64, k: usize) -> f64 {
    t0 + tau * k as f64
}

/// The scalar estimator's block standard error (`2 ≤ blocks ≤ x.len()`).
fn block_standard_error(x: &[f64], blocks: usize) -> f64 {
    let n = x.len();
    let block_mean = |b: usize| {
        let (lo, hi) = (b * n / blocks, (b + 1) * n / blocks);
        x[lo..hi].iter().fold(0.0, |s, &v| s + v) / (hi - lo) as f64
    };
    let bf = blocks as f64;
    let mut mean = 0.0;
    for b in 0..blocks {
        mean += block_mean(b);
    }
    mean /= bf;
    let mut ss = 0.0;
    for b in 0..blocks {
        let d = block_mean(b) - mean;
        ss += d * d;
    }
    (ss / (bf * (bf - 1.0))).sqrt()
}
