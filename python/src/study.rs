//! The study tool over the same files as the command line: run a study (or one shard of
//! it) into a directory, merge the shards into the table, the attractor summary and the
//! figure.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use nonsmooth::study::{Merged, Shard, Study, check_output_dir, run_shard, write_shard};

use crate::errors::Result;
use crate::interrupt::Cancel;
use crate::record::Rec;

/// Runs shard `index` of `count` of the study in `spec` (a TOML file) into `out`, counting
/// finished points in `done`. Nothing is written if the run was interrupted.
pub fn run(
    spec: PathBuf,
    out: PathBuf,
    (index, count): (usize, usize),
    done: Arc<AtomicUsize>,
    cancel: &Cancel,
) -> Result<Rec> {
    let study = Study::from_file(&spec)?;
    let shard = Shard::new(index, count)?;
    if shard.count() > study.points() {
        return Err(crate::errors::value(format!(
            "{count} shards for {} points: use at most one shard per point",
            study.points()
        )));
    }
    std::fs::create_dir_all(&out)
        .map_err(|e| crate::errors::Fail::Study(format!("i/o: {}: {e}", out.display())))?;
    check_output_dir(&out, &study)?;
    let records = run_shard(&study, shard, || {
        done.fetch_add(1, Ordering::Relaxed);
    });
    cancel.check()?;
    let manifest = write_shard(&out, &study, shard, &records)?;
    let failed = records.iter().filter(|r| r.status != "ok").count();
    Ok(Rec::new()
        .s("manifest", manifest.display().to_string())
        .i("points", records.len() as i64)
        .i("failed", failed as i64)
        .s("hash", study.hash()))
}

/// The number of points of the study in `spec`.
pub fn points(spec: &std::path::Path) -> Result<usize> {
    Ok(Study::from_file(spec)?.points())
}

/// Merges the shards in `dir`; writes the merged files next to `out` if given.
pub fn merge(dir: PathBuf, out: Option<PathBuf>) -> Result<Rec> {
    let m = Merged::from_dir(&dir)?;
    let written = match &out {
        Some(o) => m.write(o)?,
        None => Vec::new(),
    };
    let spec = m.study.spec();
    let nx = spec.grid.x.points;
    let ny = spec.grid.y.as_ref().map_or(1, |y| y.points);
    let n = m.records.len();
    let (xs, ys): (Vec<f64>, Vec<f64>) = (0..n).map(|i| m.study.values(i)).unzip();
    let r = &m.records;
    let attractors = m
        .attractors
        .iter()
        .map(|a| {
            Rec::new()
                .i("label", a.label as i64)
                .i("points", a.points as i64)
                .f("fraction", a.fraction)
                .i("period", a.period as i64)
                .f("impacts_per_period", a.impacts_per_period)
                .f("tle_mean", a.tle_mean)
                .a1("centroid", a.centroid.clone())
        })
        .collect();
    Ok(Rec::new()
        .s("name", spec.name.clone())
        .s("x_parameter", spec.grid.x.parameter.clone())
        .s(
            "y_parameter",
            spec.grid
                .y
                .as_ref()
                .map_or(String::new(), |y| y.parameter.clone()),
        )
        .i("nx", nx as i64)
        .i("ny", ny as i64)
        .a1("x", xs)
        .a1("y", ys)
        .a1("period", r.iter().map(|p| p.period as f64).collect())
        .a1(
            "impacts_per_period",
            r.iter().map(|p| p.impacts_per_period).collect(),
        )
        .a1("tle", r.iter().map(|p| p.tle).collect())
        .a1("q", r.iter().map(|p| p.q).collect())
        .a1(
            "label",
            m.labels
                .iter()
                .map(|l| l.map_or(-1.0, |l| l as f64))
                .collect(),
        )
        .a1(
            "ok",
            r.iter()
                .map(|p| if p.status == "ok" { 1.0 } else { 0.0 })
                .collect(),
        )
        .list("attractors", attractors)
        .list(
            "files",
            written
                .iter()
                .map(|p| Rec::new().s("path", p.display().to_string()))
                .collect(),
        )
        .i("failed", m.failed() as i64))
}
