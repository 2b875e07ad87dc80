//! The computation at one grid point, and a shard's share of them.

use super::record::PointRecord;
use super::shard::{Shard, shard_indices};
use super::spec::Study;
use super::system::{ParameterPoint, PointRun, PointStart, RunSettings, fill};
use crate::entropy::{Histogram, QRange, entropy_index};

/// Computes grid point `index` of `study` (a failure is recorded in the point's `status`,
/// never lost).
pub fn compute_point(study: &Study, index: usize) -> PointRecord {
    match try_point(study, index) {
        Ok(r) => r,
        Err(m) => failed(study, index, m),
    }
}

fn try_point(study: &Study, index: usize) -> Result<PointRecord, String> {
    let (point, given) = point_setup(study, index)?;
    let system = study.system();
    let rest = system.rest_state(&point)?;
    let y0 = fill(given.as_deref(), &rest);
    let run = system.run(&point, &y0, &run_settings(study))?;
    Ok(record(study, index, run))
}

/// The parameters and the given initial components (NaN: not given) of point `index`.
fn point_setup(study: &Study, index: usize) -> Result<(ParameterPoint, Option<Vec<f64>>), String> {
    if index >= study.points() {
        return Err(format!(
            "point {index} outside the grid of {} points",
            study.points()
        ));
    }
    Ok(study.point(index))
}

/// The run settings of every point of `study`.
pub(crate) fn run_settings(study: &Study) -> RunSettings {
    let spec = study.spec();
    let system = study.system();
    let rtol = spec.integration.rtol;
    let atol = match &spec.integration.atol {
        Some(a) => a.to_vec(),
        None => system.atol_per_rtol().iter().map(|a| a * rtol).collect(),
    };
    RunSettings {
        rtol,
        atol,
        max_steps: spec.integration.max_steps,
        transient: spec.periods.transient,
        record: spec.periods.record,
        period_tol: spec.record.period_tol,
        max_period: spec.record.max_period,
        lyapunov: spec
            .record
            .lyapunov
            .as_ref()
            .map(|l| (l.periods, l.d0.unwrap_or(system.d0()))),
        scales: study.scales(),
    }
}

/// The point's record from its run: period, sections, fingerprint, `q` and the top
/// Lyapunov exponent.
fn record(study: &Study, index: usize, run: PointRun) -> PointRecord {
    let spec = study.spec();
    let period_n = run.period;
    let keep = spec.record.poincare.max(period_n).min(run.poincare.len());
    let sections: Vec<Vec<f64>> = run.poincare[run.poincare.len() - keep..].to_vec();
    // Fingerprints are compared only between points of the same system parameters, which
    // exist only on a grid with an initial-condition axis.
    let cells = if study.has_initial_condition_axis() {
        fingerprint(&run.poincare, &study.scales(), spec.attractors.cell)
    } else {
        Vec::new()
    };
    let impacts_per_surface = if study.system().surfaces() >= 2 {
        run.impacts_per_surface
    } else {
        Vec::new()
    };
    let mut rec = PointRecord {
        index,
        status: "ok".into(),
        period: period_n,
        impacts_per_period: run.impacts_per_period,
        impacts_per_surface,
        tle: f64::NAN,
        tle_spread: f64::NAN,
        q: f64::NAN,
        sections,
        cells,
    };
    if let Some(q) = &spec.record.q {
        rec.q = Histogram::new(q.lo, q.hi, q.step)
            .ok()
            .and_then(|h| h.estimate(&run.intervals).ok())
            .and_then(|est| entropy_index(&est.probabilities, &QRange::default()).ok())
            .map_or(f64::NAN, |i| i.q);
    }
    match run.lyapunov {
        Some(Ok((l, sp))) => {
            rec.tle = l;
            rec.tle_spread = sp;
        }
        Some(Err(e)) => rec.status = format!("lyapunov: {e}"),
        None => {}
    }
    rec
}

/// The most cells kept in a fingerprint.
pub const MAX_CELLS: usize = 256;

/// The cells of side `cell·scale` visited by the section points, at most [`MAX_CELLS`] of
/// them (the most visited; ties by cell), sorted.
fn fingerprint(points: &[Vec<f64>], scales: &[f64], cell: f64) -> Vec<Vec<i64>> {
    let mut all: Vec<Vec<i64>> = points
        .iter()
        .map(|p| {
            // `as` saturates: a far-out point lands in an edge cell instead of wrapping.
            p.iter()
                .zip(scales)
                .map(|(x, s)| (x / (s * cell)).floor() as i64)
                .collect()
        })
        .collect();
    all.sort_unstable();
    let mut counted: Vec<(Vec<i64>, usize)> = Vec::new();
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
    let mut cells: Vec<Vec<i64>> = counted.into_iter().map(|(c, _)| c).collect();
    cells.sort_unstable();
    cells
}

/// A point whose run failed: with NaN impacts on each surface of a system with two or more.
fn failed(study: &Study, index: usize, message: String) -> PointRecord {
    let mut r = PointRecord::failed(index, message);
    let n = study.system().surfaces();
    if n >= 2 {
        r.impacts_per_surface = vec![f64::NAN; n];
    }
    r
}

/// Points per batch of a system that runs in lanes (a batch runs on one thread).
const BATCH: usize = 64;

/// Computes the points of `shard` in parallel (rayon, in the current pool), calling
/// `progress` after each point; returned in index order. The result does not depend on the
/// number of threads: each point depends only on the spec and its index.
///
/// The points of a system with a lane form (the paper's model, Duffing–Ueda, the 2-DOF
/// impact oscillator, a described system without a rigid surface) run in SIMD lanes, 64
/// points per task, with
/// [`LaneMath::Exact`](crate::lanes::LaneMath::Exact): each point's record is
/// [`compute_point`]'s to the bit (tested), failure messages included; the Lyapunov
/// exponent, where recorded, is the scalar two-trajectory estimate from the run's end
/// state. The points of every other system run one by one on the scalar path.
pub fn run_shard<F: Fn() + Sync>(study: &Study, shard: Shard, progress: F) -> Vec<PointRecord> {
    use rayon::prelude::*;
    let idx: Vec<usize> = shard_indices(study.points(), shard).collect();
    if study.system().in_lanes() {
        idx.par_chunks(BATCH)
            .flat_map_iter(|batch| {
                let recs = batch_records(study, batch);
                batch.iter().for_each(|_| progress());
                recs
            })
            .collect()
    } else {
        idx.par_iter()
            .map(|&i| {
                let r = compute_point(study, i);
                progress();
                r
            })
            .collect()
    }
}

/// The points `indices` run together ([`StudySystem::run_batch`](super::system::StudySystem::run_batch)):
/// the records of [`compute_point`], to the bit.
fn batch_records(study: &Study, indices: &[usize]) -> Vec<PointRecord> {
    let system = study.system();
    let starts: Vec<PointStart> = indices
        .iter()
        .map(|&i| {
            let (point, given) = point_setup(study, i)?;
            let rest = system.rest_state(&point)?;
            let y0 = fill(given.as_deref(), &rest);
            Ok((point, y0))
        })
        .collect();
    let runs = system.run_batch(&starts, &run_settings(study));
    indices
        .iter()
        .zip(runs)
        .map(|(&i, r)| match r {
            Ok(run) => record(study, i, run),
            Err(m) => failed(study, i, m),
        })
        .collect()
}
