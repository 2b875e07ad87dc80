//! The computation at one grid point, and a shard's share of them.

use std::collections::BTreeMap;

use nalgebra::{SVector, Vector2};

use super::model::{ModelKind, ParameterSet};
use super::record::PointRecord;
use super::shard::{Shard, shard_indices};
use super::spec::{Study, apply_axis};
use crate::Dynamics;
use crate::ensemble::{Ensemble, F64x8, F64x16, IndependentSweep, Member, Simd, sweep_starts};
use crate::entropy::{Histogram, QRange, entropy_index};
use crate::integrate::{Dopri5, Tolerances};
use crate::lyapunov::{Norm, TwoTrajectory};
use crate::sample::Regime;
use crate::sweep::{Stop, SweepError, SweepPoint, SweepSystem, run_point};
use crate::systems::paper::PaperParameters;

/// Computes grid point `index` of `study` (a failure is recorded in the point's `status`,
/// never lost).
pub fn compute_point(study: &Study, index: usize) -> PointRecord {
    match try_point(study, index) {
        Ok(r) => r,
        Err(m) => PointRecord::failed(index, m),
    }
}

fn try_point(study: &Study, index: usize) -> Result<PointRecord, String> {
    let (set, y0) = point_setup(study, index)?;
    match study.kind() {
        ModelKind::Paper => {
            let (p, omega, y0) = paper_start(&set, y0)?;
            run_model(
                study,
                index,
                || Ok(p.oscillator::<f64>(omega)?),
                std::f64::consts::TAU / omega,
                Some(impact_stop(&p)),
                y0,
            )
        }
        ModelKind::DuffingUeda => {
            let d = set.duffing().ok_or("internal: not Duffing–Ueda")?;
            run_model(
                study,
                index,
                || d.model::<f64>(),
                d.period(),
                None,
                fill(y0, [0.0, 0.0]),
            )
        }
    }
}

/// The parameters and the given initial components of point `index`.
fn point_setup(study: &Study, index: usize) -> Result<(ParameterSet, Option<[f64; 2]>), String> {
    let spec = study.spec();
    if index >= study.points() {
        return Err(format!(
            "point {index} outside the grid of {} points",
            study.points()
        ));
    }
    let mut set = ParameterSet::new(study.kind(), &spec.system.parameters);
    let mut y0 = spec.initial.state;
    let (xv, yv) = study.values(index);
    apply_axis(&mut set, &mut y0, &spec.grid.x.parameter, xv);
    if let Some(y) = &spec.grid.y {
        apply_axis(&mut set, &mut y0, &y.parameter, yv);
    }
    Ok((set, y0))
}

/// The paper model's parameters, ω and initial state (the rest state where not given).
fn paper_start(
    set: &ParameterSet,
    y0: Option<[f64; 2]>,
) -> Result<(PaperParameters, f64, Vector2<f64>), String> {
    let (p, omega) = set.paper().ok_or("internal: not the paper's model")?;
    let rest = [p.static_equilibrium().map_err(|e| e.to_string())?, 0.0];
    Ok((p, omega, fill(y0, rest)))
}

/// Impacts: rising crossings of `x = x_I`.
fn impact_stop(p: &PaperParameters) -> Stop {
    Stop {
        position: 0,
        velocity: 1,
        level: p.x_i,
    }
}

/// The initial state: given components, the rest state for the others.
fn fill(y0: Option<[f64; 2]>, rest: [f64; 2]) -> Vector2<f64> {
    let s = y0.unwrap_or(rest);
    let pick = |k: usize| if s[k].is_nan() { rest[k] } else { s[k] };
    Vector2::new(pick(0), pick(1))
}

/// The integration tolerances and the sweep settings of every point.
fn integration(study: &Study) -> Result<(Tolerances<f64, 2>, IndependentSweep), String> {
    let spec = study.spec();
    let s = |e: &dyn std::fmt::Display| e.to_string();
    let rtol = spec.integration.rtol;
    let atol = spec.integration.atol.unwrap_or({
        let a = study.kind().atol_per_rtol();
        [a[0] * rtol, a[1] * rtol]
    });
    let tol = Tolerances::per_component(rtol, atol).map_err(|e| s(&e))?;
    let settings = IndependentSweep::new(spec.periods.transient, spec.periods.record)
        .and_then(|c| c.period_detection(spec.record.period_tol, spec.record.max_period))
        .map_err(|e| s(&e))?
        .max_steps(spec.integration.max_steps);
    Ok((tol, settings))
}

fn run_model<S, F>(
    study: &Study,
    index: usize,
    make: F,
    period: f64,
    stop: Option<Stop>,
    y0: Vector2<f64>,
) -> Result<PointRecord, String>
where
    S: Dynamics<f64, 2>,
    F: Fn() -> crate::Result<S>,
{
    let s = |e: &dyn std::fmt::Display| e.to_string();
    let (tol, settings) = integration(study)?;
    let cfg = settings.config(vec![0.0]).map_err(|e| s(&e))?;
    let system = make().map_err(|e| s(&e))?;
    let pt = run_point(
        &cfg,
        0.0,
        SweepSystem {
            system,
            period,
            stop,
        },
        Dopri5::new(tol),
        y0,
        settings.transient,
    )
    .map_err(|e| s(&e))?;
    Ok(record(study, index, make, period, &tol, &pt))
}

/// The point's record from its run: period, sections, fingerprint, `q` and (a second,
/// scalar run from the end state) the top Lyapunov exponent.
fn record<S, F>(
    study: &Study,
    index: usize,
    make: F,
    period: f64,
    tol: &Tolerances<f64, 2>,
    pt: &SweepPoint<2>,
) -> PointRecord
where
    S: Dynamics<f64, 2>,
    F: Fn() -> crate::Result<S>,
{
    let spec = study.spec();
    let kind = study.kind();
    let period_n = match pt.regime {
        Regime::Periodic(p) => p,
        Regime::NotPeriodic => 0,
    };
    let keep = spec.record.poincare.max(period_n).min(pt.poincare.len());
    let sections: Vec<[f64; 2]> = pt.poincare[pt.poincare.len() - keep..]
        .iter()
        .map(|p| [p[0], p[1]])
        .collect();
    let scales = spec.attractors.scales.unwrap_or(kind.scales());
    // Fingerprints are compared only between points of the same system parameters, which
    // exist only on a grid with an initial-condition axis.
    let cells = if study.has_initial_condition_axis() {
        fingerprint(&pt.poincare, scales, spec.attractors.cell)
    } else {
        Vec::new()
    };
    let mut rec = PointRecord {
        index,
        status: "ok".into(),
        period: period_n,
        impacts_per_period: pt.impacts_per_period,
        tle: f64::NAN,
        tle_spread: f64::NAN,
        q: f64::NAN,
        sections,
        cells,
    };
    if let Some(q) = &spec.record.q {
        rec.q = Histogram::new(q.lo, q.hi, q.step)
            .ok()
            .and_then(|h| h.estimate(&pt.intervals).ok())
            .and_then(|est| entropy_index(&est.probabilities, &QRange::default()).ok())
            .map_or(f64::NAN, |i| i.q);
    }
    if let Some(l) = &spec.record.lyapunov {
        let tle = (|| -> crate::Result<(f64, f64)> {
            let norm = Norm::weighted(scales)?;
            let d0 = l.d0.unwrap_or(kind.d0());
            let mut est = TwoTrajectory::<f64, 2, 4, _, _>::with_tolerances(
                make()?,
                Dopri5::new,
                tol,
                d0,
                norm,
            )?;
            // The run ended after a whole number of periods: t = 0 has the same phase.
            est.start(0.0, pt.end_state)?;
            let e = est.estimate(period, l.periods)?;
            Ok((e.exponent, e.spread))
        })();
        match tle {
            Ok((l, sp)) => {
                rec.tle = l;
                rec.tle_spread = sp;
            }
            Err(e) => rec.status = format!("lyapunov: {e}"),
        }
    }
    rec
}

/// The most cells kept in a fingerprint.
pub const MAX_CELLS: usize = 256;

/// The cells of side `cell·scale` visited by the section points, at most [`MAX_CELLS`] of
/// them (the most visited; ties by cell), sorted.
fn fingerprint(points: &[SVector<f64, 2>], scales: [f64; 2], cell: f64) -> Vec<(i64, i64)> {
    let mut all: Vec<(i64, i64)> = points
        .iter()
        .map(|p| {
            // `as` saturates: a far-out point lands in an edge cell instead of wrapping.
            (
                (p[0] / (scales[0] * cell)).floor() as i64,
                (p[1] / (scales[1] * cell)).floor() as i64,
            )
        })
        .collect();
    all.sort_unstable();
    let mut counted: Vec<((i64, i64), usize)> = Vec::new();
    for c in all {
        match counted.last_mut() {
            Some((last, n)) if *last == c => *n += 1,
            _ => counted.push((c, 1)),
        }
    }
    if counted.len() > MAX_CELLS {
        counted.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        counted.truncate(MAX_CELLS);
    }
    let mut cells: Vec<(i64, i64)> = counted.into_iter().map(|(c, _)| c).collect();
    cells.sort_unstable();
    cells
}

/// Points per batch of the paper model's lanes (a batch runs on one thread).
const BATCH: usize = 64;

/// Computes the points of `shard` in parallel (rayon, in the current pool), calling
/// `progress` after each point; returned in index order. The result does not depend on the
/// number of threads: each point depends only on the spec and its index.
///
/// The paper model's points run in SIMD lanes ([`sweep_starts`] with
/// [`LaneMath::Exact`](crate::ensemble::LaneMath::Exact), batches of 64 points per
/// task), which gives each point's run to the bit as [`compute_point`] does (tested); the
/// Lyapunov exponent, where recorded, is the scalar two-trajectory estimate from the run's
/// end state. Duffing–Ueda points run on the scalar path.
pub fn run_shard<F: Fn() + Sync>(study: &Study, shard: Shard, progress: F) -> Vec<PointRecord> {
    use rayon::prelude::*;
    let idx: Vec<usize> = shard_indices(study.points(), shard).collect();
    match study.kind() {
        ModelKind::Paper => idx
            .par_chunks(BATCH)
            .flat_map_iter(|batch| {
                let recs = paper_batch(study, batch);
                batch.iter().for_each(|_| progress());
                recs
            })
            .collect(),
        ModelKind::DuffingUeda => idx
            .par_iter()
            .map(|&i| {
                let r = compute_point(study, i);
                progress();
                r
            })
            .collect(),
    }
}

/// The paper model's points `indices` in lanes: the records of [`compute_point`], to the
/// bit, with the same messages for what fails.
fn paper_batch(study: &Study, indices: &[usize]) -> Vec<PointRecord> {
    let (tol, settings) = match integration(study) {
        Ok(v) => v,
        Err(m) => {
            return indices
                .iter()
                .map(|&i| PointRecord::failed(i, m.clone()))
                .collect();
        }
    };
    let mut recs: Vec<Option<PointRecord>> = vec![None; indices.len()];
    // One impact surface per batch of lanes: points are grouped by x_I (a grid axis may
    // move it).
    let mut groups: BTreeMap<u64, Vec<(usize, Member, Vector2<f64>)>> = BTreeMap::new();
    for (k, &i) in indices.iter().enumerate() {
        let start = point_setup(study, i).and_then(|(set, y0)| paper_start(&set, y0));
        match start {
            Err(m) => recs[k] = Some(PointRecord::failed(i, m)),
            Ok((p, omega, y0)) => match Member::new(p, omega) {
                Err(e) => recs[k] = Some(PointRecord::failed(i, crate::Error::from(e).to_string())),
                Ok(m) => groups.entry(p.x_i.to_bits()).or_default().push((k, m, y0)),
            },
        }
    }
    // Sixteen lanes pay on AVX-512, eight on AVX2 (the `ensemble` module docs); the
    // records are the same either way.
    let run_lanes = if Simd::Auto.resolve() == Simd::Avx512 {
        sweep_starts::<F64x16>
    } else {
        sweep_starts::<F64x8>
    };
    for group in groups.values() {
        let stop = impact_stop(group[0].1.params());
        let starts: Vec<(Member, Vector2<f64>)> = group.iter().map(|(_, m, y)| (*m, *y)).collect();
        let run = Ensemble::new(tol)
            .map_err(|e| SweepError::failed(0.0, e))
            .and_then(|e| run_lanes(&e, &settings, &starts, stop));
        match run {
            Err(e) => {
                for (k, _, _) in group {
                    recs[*k] = Some(PointRecord::failed(indices[*k], e.to_string()));
                }
            }
            Ok(points) => {
                for ((k, m, _), r) in group.iter().zip(points) {
                    let i = indices[*k];
                    recs[*k] = Some(match r {
                        Err(e) => PointRecord::failed(i, SweepError::failed(0.0, e).to_string()),
                        Ok(pt) => record(study, i, || Ok(*m.scalar()), m.period(), &tol, &pt),
                    });
                }
            }
        }
    }
    recs.into_iter()
        .zip(indices)
        .map(|(r, &i)| r.unwrap_or_else(|| PointRecord::failed(i, "internal: not computed".into())))
        .collect()
}
