//! The computation at one grid point, and a shard's share of them.

use std::collections::BTreeMap;

use nalgebra::Vector2;

use super::catalogue::Paper;
use super::record::PointRecord;
use super::shard::{Shard, shard_indices};
use super::spec::{Study, apply_axis};
use super::system::{ParameterPoint, PointRun, RunSettings, fill};
use crate::ensemble::{Ensemble, F64x8, F64x16, Member, Simd, sweep_starts};
use crate::entropy::{Histogram, QRange, entropy_index};
use crate::sweep::SweepError;
use crate::systems::paper::PaperParameters;

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
    let spec = study.spec();
    if index >= study.points() {
        return Err(format!(
            "point {index} outside the grid of {} points",
            study.points()
        ));
    }
    let system = study.system();
    let mut point = system
        .point(&spec.system.parameters)
        .map_err(|e| e.to_string())?;
    let mut y0 = spec.initial.state.clone();
    let (xv, yv) = study.values(index);
    apply_axis(system, &mut point, &mut y0, &spec.grid.x.parameter, xv);
    if let Some(y) = &spec.grid.y {
        apply_axis(system, &mut point, &mut y0, &y.parameter, yv);
    }
    Ok((point, y0))
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

/// The paper model's parameters, ω and initial state (the rest state where not given).
fn paper_start(
    point: &ParameterPoint,
    given: Option<Vec<f64>>,
) -> Result<(PaperParameters, f64, Vector2<f64>), String> {
    let (p, omega) = Paper::at(point);
    let rest = [p.static_equilibrium().map_err(|e| e.to_string())?, 0.0];
    let y = fill(given.as_deref(), &rest);
    Ok((p, omega, Vector2::new(y[0], y[1])))
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

/// Points per batch of the paper model's lanes (a batch runs on one thread).
const BATCH: usize = 64;

/// THE DISPATCH TO LANES: the system of `study` if its points run in SIMD lanes — today the
/// paper's model only ([`sweep_starts`] over [`Member`], the paper's oscillator family);
/// every other system runs point by point on the scalar path ([`compute_point`]). Lanes
/// for other systems are added here.
fn lanes(study: &Study) -> Option<&Paper> {
    study.system().as_any().downcast_ref::<Paper>()
}

/// Computes the points of `shard` in parallel (rayon, in the current pool), calling
/// `progress` after each point; returned in index order. The result does not depend on the
/// number of threads: each point depends only on the spec and its index.
///
/// The paper model's points run in SIMD lanes ([`sweep_starts`] with
/// [`LaneMath::Exact`](crate::ensemble::LaneMath::Exact), batches of 64 points per
/// task), which gives each point's run to the bit as [`compute_point`] does (tested); the
/// Lyapunov exponent, where recorded, is the scalar two-trajectory estimate from the run's
/// end state. The points of every other system run on the scalar path.
pub fn run_shard<F: Fn() + Sync>(study: &Study, shard: Shard, progress: F) -> Vec<PointRecord> {
    use rayon::prelude::*;
    let idx: Vec<usize> = shard_indices(study.points(), shard).collect();
    match lanes(study) {
        Some(_) => idx
            .par_chunks(BATCH)
            .flat_map_iter(|batch| {
                let recs = paper_batch(study, batch);
                batch.iter().for_each(|_| progress());
                recs
            })
            .collect(),
        None => idx
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
    let run_settings = run_settings(study);
    let (tol, settings) = match Paper::integration(&run_settings) {
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
        let start = point_setup(study, i).and_then(|(point, y0)| paper_start(&point, y0));
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
        let stop = Paper::impact_stop(group[0].1.params());
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
                        Ok(pt) => record(
                            study,
                            i,
                            Paper::point_run(
                                &run_settings,
                                || Ok(*m.scalar()),
                                m.period(),
                                &tol,
                                &pt,
                            ),
                        ),
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
