//! Shards: which points a task runs, the self-describing shard files, and the verified
//! merge.
//!
//! See the [study module docs](super#the-shard-files) for the file formats.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::StudyError;
use super::record::PointRecord;
use super::spec::{Study, StudySpec, fnv1a};

/// The manifest format written and accepted.
pub const SHARD_FORMAT: &str = "nonsmooth-study-shard/1";

/// Shard `index` of `count` (1-based: `1 ≤ index ≤ count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Shard {
    index: usize,
    count: usize,
}

impl Shard {
    /// The whole study as one shard (1/1).
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Shard `index` of `count`.
    ///
    /// # Errors
    /// [`StudyError::Shard`] unless `1 ≤ index ≤ count`.
    pub fn new(index: usize, count: usize) -> Result<Self, StudyError> {
        if count == 0 || index == 0 || index > count {
            return Err(StudyError::Shard(format!(
                "shard {index}/{count} out of range: need 1 <= I <= N"
            )));
        }
        Ok(Self { index, count })
    }

    /// Parses `"I/N"`.
    ///
    /// # Errors
    /// [`StudyError::Shard`] for another form or an out-of-range shard.
    pub fn parse(text: &str) -> Result<Self, StudyError> {
        let bad = || {
            StudyError::Shard(format!(
                "--shard {text:?}: expected I/N with integers 1 <= I <= N, e.g. 2/7"
            ))
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let i: usize = i.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        Self::new(i, n)
    }

    /// The shard of a Slurm array task, from `SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_MIN`,
    /// `SLURM_ARRAY_TASK_MAX` and `SLURM_ARRAY_TASK_COUNT` (read through `var`): the task
    /// at offset `ID − MIN` is shard `ID − MIN + 1` of `COUNT`. `None` outside an array.
    /// The array must be contiguous (`MAX − MIN + 1 = COUNT`); to re-run single tasks, pass
    /// `--shard I/N` explicitly (the script of `study plan` does).
    ///
    /// # Errors
    /// [`StudyError::Shard`] for unreadable values or an array with gaps or a step.
    pub fn from_slurm(var: impl Fn(&str) -> Option<String>) -> Result<Option<Self>, StudyError> {
        let Some(id) = var("SLURM_ARRAY_TASK_ID") else {
            return Ok(None);
        };
        let num = |name: &str| -> Result<usize, StudyError> {
            let v = var(name).ok_or_else(|| {
                StudyError::Shard(format!("SLURM_ARRAY_TASK_ID is set but {name} is not"))
            })?;
            v.trim()
                .parse()
                .map_err(|_| StudyError::Shard(format!("{name}={v:?} is not a number")))
        };
        let id: usize = id.trim().parse().map_err(|_| {
            StudyError::Shard(format!("SLURM_ARRAY_TASK_ID={id:?} is not a number"))
        })?;
        let (min, max, count) = (
            num("SLURM_ARRAY_TASK_MIN")?,
            num("SLURM_ARRAY_TASK_MAX")?,
            num("SLURM_ARRAY_TASK_COUNT")?,
        );
        if max < min || max - min + 1 != count || id < min || id > max {
            return Err(StudyError::Shard(format!(
                "the Slurm array {min}-{max} ({count} tasks, this one {id}) is not contiguous: \
                 pass --shard I/N explicitly"
            )));
        }
        Self::new(id - min + 1, count).map(Some)
    }

    /// `I` (1-based).
    pub fn index(&self) -> usize {
        self.index
    }

    /// `N`.
    pub fn count(&self) -> usize {
        self.count
    }

    /// The file stem `shard-IIIII-of-NNNNN`.
    pub fn stem(&self) -> String {
        format!("shard-{:05}-of-{:05}", self.index, self.count)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// A shard's manifest (`shard-…json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardManifest {
    /// [`SHARD_FORMAT`].
    pub format: String,
    /// The crate version that computed the shard.
    pub crate_version: String,
    /// The spec hash ([`StudySpec::hash`]).
    pub spec_hash: String,
    /// The spec.
    pub spec: StudySpec,
    /// `I`.
    pub shard: usize,
    /// `N`.
    pub shards: usize,
    /// Points in the whole study.
    pub total_points: usize,
    /// Points in this shard.
    pub points: usize,
    /// Points whose status is not `ok`.
    pub failed_points: usize,
    /// The points file name.
    pub points_file: String,
    /// Its FNV-1a hash (hex).
    pub points_fnv: String,
    /// The sections file name.
    pub sections_file: String,
    /// Its FNV-1a hash (hex).
    pub sections_fnv: String,
}

impl ShardManifest {
    /// Reads a manifest file (e.g. the one [`write_shard`] returns).
    ///
    /// # Errors
    /// [`StudyError::Io`] naming the file if it cannot be read; [`StudyError::Corrupt`] if
    /// it is not a manifest.
    pub fn read(path: &Path) -> Result<Self, StudyError> {
        let text = fs::read_to_string(path).map_err(|e| io(path, e))?;
        serde_json::from_str(&text).map_err(|e| corrupt(path, format!("unreadable manifest: {e}")))
    }
}

/// A float in the shortest form that reads back to the same bits.
pub(crate) fn fmt_f64(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-4..1e7).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn io(path: &Path, e: impl std::fmt::Display) -> StudyError {
    StudyError::Io(format!("{}: {e}", path.display()))
}

/// Writes `bytes` to `path` through a temporary file and a rename.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), StudyError> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| io(path, "not a file name"))?;
    let tmp = path.with_file_name(format!(".{name}.tmp.{}", std::process::id()));
    fs::write(&tmp, bytes).map_err(|e| io(&tmp, e))?;
    fs::rename(&tmp, path).map_err(|e| io(path, e))
}

/// The columns of the points file: the per-surface impacts only for a system with two or
/// more impact surfaces (`impacts_per_period_0`, …, after `impacts_per_period`).
fn point_header(study: &Study) -> Vec<String> {
    let mut h: Vec<String> = ["index", "status", "period", "impacts_per_period"]
        .map(String::from)
        .to_vec();
    h.extend((0..surface_columns(study)).map(|k| format!("impacts_per_period_{k}")));
    h.extend(
        [
            "tle",
            "tle_spread",
            "q",
            "kept_sections",
            "cells",
            "spec_hash",
        ]
        .map(String::from),
    );
    h
}

/// The number of per-surface impact columns: the surfaces of a system with two or more.
pub(crate) fn surface_columns(study: &Study) -> usize {
    let n = study.system().surfaces();
    if n >= 2 { n } else { 0 }
}

/// The per-surface impacts of `r` for its `n` columns (NaN where the record has none).
pub(crate) fn surface_values(r: &PointRecord, n: usize) -> impl Iterator<Item = String> + '_ {
    (0..n).map(|k| fmt_f64(r.impacts_per_surface.get(k).copied().unwrap_or(f64::NAN)))
}

fn points_csv(study: &Study, records: &[PointRecord], hash: &str) -> Result<Vec<u8>, StudyError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let e = |e: csv::Error| StudyError::Io(e.to_string());
    w.write_record(point_header(study)).map_err(e)?;
    let n = surface_columns(study);
    for r in records {
        let cells: Vec<String> = r
            .cells
            .iter()
            .map(|c| {
                c.iter()
                    .map(|k| k.to_string())
                    .collect::<Vec<_>>()
                    .join(":")
            })
            .collect();
        let mut row = vec![
            r.index.to_string(),
            r.status.clone(),
            r.period.to_string(),
            fmt_f64(r.impacts_per_period),
        ];
        row.extend(surface_values(r, n));
        row.extend([
            fmt_f64(r.tle),
            fmt_f64(r.tle_spread),
            fmt_f64(r.q),
            r.sections.len().to_string(),
            cells.join(" "),
            hash.to_string(),
        ]);
        w.write_record(row).map_err(e)?;
    }
    w.into_inner().map_err(|e| StudyError::Io(e.to_string()))
}

/// The kept section points, one row each: `index, k` and the state components by name
/// (`x, v` for one degree of freedom).
pub(super) fn sections_csv(study: &Study, records: &[PointRecord]) -> Result<Vec<u8>, StudyError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let e = |e: csv::Error| StudyError::Io(e.to_string());
    let mut header = vec!["index".to_string(), "k".to_string()];
    header.extend(study.system().state_names());
    w.write_record(&header).map_err(e)?;
    for r in records {
        for (k, s) in r.sections.iter().enumerate() {
            let mut row = vec![r.index.to_string(), k.to_string()];
            row.extend(s.iter().map(|&x| fmt_f64(x)));
            w.write_record(row).map_err(e)?;
        }
    }
    w.into_inner().map_err(|e| StudyError::Io(e.to_string()))
}

/// A manifest file and what reading it gave.
type Found = (PathBuf, Result<ShardManifest, String>);

/// Manifests already in `dir`, by file.
fn manifests(dir: &Path) -> Result<Vec<Found>, StudyError> {
    let mut out = Vec::new();
    let rd = match fs::read_dir(dir) {
        Ok(rd) => rd,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(out),
        Err(e) => return Err(io(dir, e)),
    };
    for entry in rd {
        let p = entry.map_err(|e| io(dir, e))?.path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with("shard-") && name.ends_with(".json") {
            let m = fs::read_to_string(&p)
                .map_err(|e| e.to_string())
                .and_then(|t| serde_json::from_str::<ShardManifest>(&t).map_err(|e| e.to_string()));
            out.push((p, m));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// Checks that `dir` holds no shards of another study (call before a long run).
///
/// # Errors
/// [`StudyError::Mismatch`] naming a shard file of another spec or crate version.
pub fn check_output_dir(dir: &Path, study: &Study) -> Result<(), StudyError> {
    for (p, m) in manifests(dir)? {
        if let Ok(m) = m {
            if m.spec_hash != study.hash() {
                return Err(StudyError::Mismatch(format!(
                    "{} belongs to another study (spec hash {} here, {} in the file): \
                     use another output directory",
                    p.display(),
                    study.hash(),
                    m.spec_hash
                )));
            }
        }
    }
    Ok(())
}

/// Writes the shard files of `records` (the points of `shard`, in index order) into `dir`,
/// atomically; returns the manifest's path.
///
/// # Errors
/// [`StudyError::Shard`] if `records` are not exactly the points of `shard`;
/// [`StudyError::Io`] if a file cannot be written.
pub fn write_shard(
    dir: &Path,
    study: &Study,
    shard: Shard,
    records: &[PointRecord],
) -> Result<PathBuf, StudyError> {
    let expected: Vec<usize> = shard_indices(study.points(), shard).collect();
    if records.len() != expected.len() || records.iter().zip(&expected).any(|(r, &i)| r.index != i)
    {
        return Err(StudyError::Shard(format!(
            "records are not the {} points of shard {shard}",
            expected.len()
        )));
    }
    fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let stem = shard.stem();
    let points = points_csv(study, records, study.hash())?;
    let sections = sections_csv(study, records)?;
    let points_file = format!("{stem}.csv");
    let sections_file = format!("{stem}.sections.csv");
    let manifest = ShardManifest {
        format: SHARD_FORMAT.into(),
        crate_version: env!("CARGO_PKG_VERSION").into(),
        spec_hash: study.hash().into(),
        spec: study.spec().clone(),
        shard: shard.index(),
        shards: shard.count(),
        total_points: study.points(),
        points: records.len(),
        failed_points: records.iter().filter(|r| !r.is_ok()).count(),
        points_fnv: format!("{:016x}", fnv1a(&points)),
        sections_fnv: format!("{:016x}", fnv1a(&sections)),
        points_file,
        sections_file,
    };
    write_atomic(&dir.join(&manifest.points_file), &points)?;
    write_atomic(&dir.join(&manifest.sections_file), &sections)?;
    let json =
        serde_json::to_string_pretty(&manifest).map_err(|e| StudyError::Io(e.to_string()))?;
    let path = dir.join(format!("{stem}.json"));
    write_atomic(&path, json.as_bytes())?;
    Ok(path)
}

fn corrupt(path: &Path, what: impl std::fmt::Display) -> StudyError {
    StudyError::Corrupt(format!("{}: {what}", path.display()))
}

fn parse_f64(path: &Path, row: usize, col: &str, s: &str) -> Result<f64, StudyError> {
    s.parse()
        .map_err(|_| corrupt(path, format!("row {row}: {col} = {s:?} is not a number")))
}

fn parse_usize(path: &Path, row: usize, col: &str, s: &str) -> Result<usize, StudyError> {
    s.parse()
        .map_err(|_| corrupt(path, format!("row {row}: {col} = {s:?} is not an integer")))
}

/// Reads one shard's points after checking its hashes.
fn read_shard(
    study: &Study,
    dir: &Path,
    m: &ShardManifest,
    manifest_path: &Path,
) -> Result<Vec<PointRecord>, StudyError> {
    let pp = dir.join(&m.points_file);
    let sp = dir.join(&m.sections_file);
    let points = read_listed(&pp, m, manifest_path)?;
    let sections = read_listed(&sp, m, manifest_path)?;
    for (p, bytes, want) in [
        (&pp, &points, &m.points_fnv),
        (&sp, &sections, &m.sections_fnv),
    ] {
        let got = format!("{:016x}", fnv1a(bytes));
        if &got != want {
            return Err(corrupt(
                p,
                format!(
                    "content hash {got} differs from {want} in its manifest (truncated or \
                     modified): re-run shard {}/{}",
                    m.shard, m.shards
                ),
            ));
        }
    }
    let records = parse_points(study, &pp, &points, &m.spec_hash)?;
    attach_sections(study, &sp, &sections, records)
}

/// The bytes of a file listed in the manifest `m` (at `manifest_path`).
fn read_listed(
    path: &Path,
    m: &ShardManifest,
    manifest_path: &Path,
) -> Result<Vec<u8>, StudyError> {
    fs::read(path).map_err(|e| {
        StudyError::MissingShards(format!(
            "{} (listed in {}): {e}; re-run shard {}/{}",
            path.display(),
            manifest_path.display(),
            m.shard,
            m.shards
        ))
    })
}

/// The points file `pp` (its bytes `points`): each point with its number of kept sections
/// (its `sections` still empty), every row of the study with hash `spec_hash`.
fn parse_points(
    study: &Study,
    pp: &Path,
    points: &[u8],
    spec_hash: &str,
) -> Result<Vec<(PointRecord, usize)>, StudyError> {
    let mut rd = csv::Reader::from_reader(points);
    let header = rd.headers().map_err(|e| corrupt(pp, e))?.clone();
    if header
        .iter()
        .ne(point_header(study).iter().map(String::as_str))
    {
        return Err(corrupt(pp, "unexpected header"));
    }
    let n = surface_columns(study);
    let dim = study.system().dimension();
    let mut records = Vec::new();
    for (row, rec) in rd.records().enumerate() {
        let rec = rec.map_err(|e| corrupt(pp, e))?;
        let f = |k: usize| rec.get(k).unwrap_or("");
        if f(9 + n) != spec_hash {
            return Err(corrupt(
                pp,
                format!("row {row}: spec hash {} differs", f(9 + n)),
            ));
        }
        let cells = parse_cells(pp, row, f(8 + n), dim)?;
        let kept = parse_usize(pp, row, "kept_sections", f(7 + n))?;
        let impacts_per_surface = (0..n)
            .map(|k| parse_f64(pp, row, &format!("impacts_per_period_{k}"), f(4 + k)))
            .collect::<Result<Vec<f64>, StudyError>>()?;
        records.push((
            PointRecord {
                index: parse_usize(pp, row, "index", f(0))?,
                status: f(1).to_string(),
                period: parse_usize(pp, row, "period", f(2))?,
                impacts_per_period: parse_f64(pp, row, "impacts_per_period", f(3))?,
                impacts_per_surface,
                tle: parse_f64(pp, row, "tle", f(4 + n))?,
                tle_spread: parse_f64(pp, row, "tle_spread", f(5 + n))?,
                q: parse_f64(pp, row, "q", f(6 + n))?,
                sections: Vec::with_capacity(kept),
                cells,
            },
            kept,
        ));
    }
    Ok(records)
}

/// The cells `a:b:…` (one integer per state component, `dim` of them; cells separated by
/// white space) of row `row` of the points file `pp`.
fn parse_cells(pp: &Path, row: usize, text: &str, dim: usize) -> Result<Vec<Vec<i64>>, StudyError> {
    let mut cells = Vec::new();
    for c in text.split_whitespace() {
        let bad = || corrupt(pp, format!("row {row}: cell {c:?}"));
        let cell = c
            .split(':')
            .map(|k| k.parse::<i64>().map_err(|_| bad()))
            .collect::<Result<Vec<i64>, StudyError>>()?;
        if cell.len() != dim {
            return Err(bad());
        }
        cells.push(cell);
    }
    Ok(cells)
}

/// Appends the sections file `sp` (its bytes `sections`) to the points of `records`; each
/// point must get exactly its number of kept sections.
fn attach_sections(
    study: &Study,
    sp: &Path,
    sections: &[u8],
    mut records: Vec<(PointRecord, usize)>,
) -> Result<Vec<PointRecord>, StudyError> {
    let mut pos: BTreeMap<usize, usize> = BTreeMap::new();
    for (k, (r, _)) in records.iter().enumerate() {
        pos.insert(r.index, k);
    }
    let names = study.system().state_names();
    let mut rd = csv::Reader::from_reader(sections);
    let header = rd.headers().map_err(|e| corrupt(sp, e))?.clone();
    let expected = ["index", "k"]
        .into_iter()
        .chain(names.iter().map(String::as_str));
    if header.iter().ne(expected) {
        return Err(corrupt(sp, "unexpected header"));
    }
    for (row, rec) in rd.records().enumerate() {
        let rec = rec.map_err(|e| corrupt(sp, e))?;
        let f = |k: usize| rec.get(k).unwrap_or("");
        let index = parse_usize(sp, row, "index", f(0))?;
        let k = *pos
            .get(&index)
            .ok_or_else(|| corrupt(sp, format!("row {row}: point {index} is not in the shard")))?;
        let point = names
            .iter()
            .enumerate()
            .map(|(c, name)| parse_f64(sp, row, name, f(2 + c)))
            .collect::<Result<Vec<f64>, StudyError>>()?;
        records[k].0.sections.push(point);
    }
    let mut out = Vec::with_capacity(records.len());
    for (r, kept) in records {
        if r.sections.len() != kept {
            return Err(corrupt(
                sp,
                format!(
                    "point {}: {} sections, {kept} expected",
                    r.index,
                    r.sections.len()
                ),
            ));
        }
        out.push(r);
    }
    Ok(out)
}

/// Reads every shard of the study in `dir`, checks that they are complete and consistent,
/// and returns the study and its points in index order.
///
/// # Errors
/// [`StudyError::MissingShards`] if no shard, or not every shard `1..=N`, is present
/// (naming the missing ones); [`StudyError::Mismatch`] for shards of different specs, crate
/// versions or shard counts; [`StudyError::Corrupt`] for an unreadable manifest, one whose
/// embedded spec does not hash to its spec hash or differs from another shard's (naming the
/// field), one that lists data files other than its shard's own, a file whose content hash
/// differs from its manifest, or a shard whose points are not exactly its share (every index
/// must appear exactly once).
pub fn read_shards(dir: &Path) -> Result<(Study, Vec<PointRecord>), StudyError> {
    let ms = read_manifests(dir)?;
    check_consistent(&ms)?;
    let (reference, study) = reference_study(&ms)?;
    for (p, m) in &ms {
        if p != reference {
            check_same_spec(p, m, reference, &study)?;
        }
    }
    let n = ms[0].1.shards;
    let by_index = index_shards(dir, ms, n)?;
    let total = study.points();
    let mut slots: Vec<Option<PointRecord>> = vec![None; total];
    for (i, (p, m)) in &by_index {
        let shard = Shard::new(*i, n)?;
        place_shard(&study, dir, p, m, shard, total, &mut slots)?;
    }
    let mut out = Vec::with_capacity(total);
    for (i, s) in slots.into_iter().enumerate() {
        out.push(s.ok_or_else(|| {
            StudyError::MissingShards(format!("point {i} is in no shard of {}", dir.display()))
        })?);
    }
    Ok((study, out))
}

/// The manifests in `dir` (at least one), each readable and of the format [`SHARD_FORMAT`].
fn read_manifests(dir: &Path) -> Result<Vec<(PathBuf, ShardManifest)>, StudyError> {
    let all = manifests(dir)?;
    if all.is_empty() {
        return Err(StudyError::MissingShards(format!(
            "no shard manifests (shard-*.json) in {}",
            dir.display()
        )));
    }
    let mut ms: Vec<(PathBuf, ShardManifest)> = Vec::new();
    for (p, m) in all {
        let m = m.map_err(|e| corrupt(&p, format!("unreadable manifest: {e}")))?;
        if m.format != SHARD_FORMAT {
            return Err(corrupt(
                &p,
                format!("format {:?}, expected {SHARD_FORMAT:?}", m.format),
            ));
        }
        ms.push((p, m));
    }
    Ok(ms)
}

/// Every manifest of the same crate version (this one), spec and shard count as the first.
fn check_consistent(ms: &[(PathBuf, ShardManifest)]) -> Result<(), StudyError> {
    let (p0, m0) = &ms[0];
    for (p, m) in &ms[1..] {
        if m.crate_version != m0.crate_version {
            return Err(StudyError::Mismatch(format!(
                "{} was computed by nonsmooth {}, {} by {}",
                p.display(),
                m.crate_version,
                p0.display(),
                m0.crate_version
            )));
        }
        if m.spec_hash != m0.spec_hash {
            return Err(StudyError::Mismatch(format!(
                "{} has spec hash {}, {} has {}: shards of different studies",
                p.display(),
                m.spec_hash,
                p0.display(),
                m0.spec_hash
            )));
        }
        if m.shards != m0.shards {
            return Err(StudyError::Mismatch(format!(
                "{} is a shard of {}, {} of {}: remove the shards of the other run",
                p.display(),
                m.shards,
                p0.display(),
                m0.shards
            )));
        }
    }
    if m0.crate_version != env!("CARGO_PKG_VERSION") {
        return Err(StudyError::Mismatch(format!(
            "the shards were computed by nonsmooth {}, this is {}",
            m0.crate_version,
            env!("CARGO_PKG_VERSION")
        )));
    }
    Ok(())
}

/// The study of the spec embedded in manifest `m` (at `p`), which must hash to the
/// manifest's spec hash.
fn embedded_study(p: &Path, m: &ShardManifest) -> Result<Study, StudyError> {
    let study = Study::new(m.spec.clone())?;
    if study.hash() != m.spec_hash {
        return Err(corrupt(
            p,
            format!(
                "the embedded spec hashes to {}, the manifest says {}",
                study.hash(),
                m.spec_hash
            ),
        ));
    }
    Ok(study)
}

/// The study of the first manifest of `ms` whose embedded spec hashes to its spec hash, and
/// that manifest's path.
///
/// # Errors
/// Where none does, the first manifest's: [`StudyError::Corrupt`] for its hash, or as
/// [`Study::new`] for its spec.
fn reference_study(ms: &[(PathBuf, ShardManifest)]) -> Result<(&Path, Study), StudyError> {
    for (p, m) in ms {
        if m.spec.hash()? == m.spec_hash {
            return Ok((p, embedded_study(p, m)?));
        }
    }
    let (p0, m0) = &ms[0];
    Err(embedded_study(p0, m0)
        .err()
        .unwrap_or_else(|| corrupt(p0, "the embedded spec does not hash to its spec hash")))
}

/// The spec embedded in manifest `m` (at `p`) against `study`, the spec of the manifest at
/// `p0`: it must hash to its manifest's spec hash and be the same spec.
///
/// # Errors
/// [`StudyError::Corrupt`] naming the file `p`, its hash if it differs from the manifest's,
/// and the first field where the spec differs.
fn check_same_spec(
    p: &Path,
    m: &ShardManifest,
    p0: &Path,
    study: &Study,
) -> Result<(), StudyError> {
    if m.spec.canonical()? == study.spec().canonical()? {
        return Ok(());
    }
    let hash = m.spec.hash()?;
    let hashed = if hash == m.spec_hash {
        String::new()
    } else {
        format!(
            "the embedded spec hashes to {hash}, the manifest says {}; ",
            m.spec_hash
        )
    };
    let differs = match spec_difference(&m.spec, study.spec())? {
        Some((field, here, there)) => format!("`{field}` is {here} here, {there} in"),
        None => "the embedded spec differs from the one in".to_string(),
    };
    Err(corrupt(
        p,
        format!(
            "{hashed}{differs} {} (the manifest was edited, or the shards are of different \
             studies): re-run shard {}/{}",
            p0.display(),
            m.shard,
            m.shards
        ),
    ))
}

/// The first field where specs `a` and `b` differ (as `grid.x.points`,
/// `system.masses[1]`), with its value in each (JSON; `absent` where a spec has none).
///
/// # Errors
/// [`StudyError::Io`] if a spec cannot be serialized.
fn spec_difference(
    a: &StudySpec,
    b: &StudySpec,
) -> Result<Option<(String, String, String)>, StudyError> {
    let json = |s: &StudySpec| serde_json::to_value(s).map_err(|e| StudyError::Io(e.to_string()));
    Ok(json_difference(String::new(), &json(a)?, &json(b)?))
}

/// The first path below `path` where `a` and `b` differ, with the two values there.
fn json_difference(
    path: String,
    a: &serde_json::Value,
    b: &serde_json::Value,
) -> Option<(String, String, String)> {
    use serde_json::Value;
    let show = |v: Option<&Value>| v.map_or("absent".to_string(), Value::to_string);
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            keys.into_iter().find_map(|k| {
                let at = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                match (x.get(k), y.get(k)) {
                    (Some(u), Some(v)) => json_difference(at, u, v),
                    (u, v) => Some((at, show(u), show(v))),
                }
            })
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(k, (u, v))| json_difference(format!("{path}[{k}]"), u, v)),
        _ if a == b => None,
        _ => Some((path, a.to_string(), b.to_string())),
    }
}

/// The manifests by shard index, each in the file named after its shard; every shard
/// `1..=n` must be present.
fn index_shards(
    dir: &Path,
    ms: Vec<(PathBuf, ShardManifest)>,
    n: usize,
) -> Result<BTreeMap<usize, (PathBuf, ShardManifest)>, StudyError> {
    let mut by_index: BTreeMap<usize, (PathBuf, ShardManifest)> = BTreeMap::new();
    for (p, m) in ms {
        let shard = Shard::new(m.shard, m.shards).map_err(|e| corrupt(&p, e))?;
        let expected_name = format!("{}.json", shard.stem());
        if p.file_name().and_then(|f| f.to_str()) != Some(expected_name.as_str()) {
            return Err(corrupt(
                &p,
                format!("describes shard {shard}, file name differs"),
            ));
        }
        check_listed_files(&p, &m, shard)?;
        by_index.insert(m.shard, (p, m));
    }
    let missing: Vec<String> = (1..=n)
        .filter(|i| !by_index.contains_key(i))
        .map(|i| i.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(StudyError::MissingShards(format!(
            "{} of {n} shards missing in {}: {} (run them with --shard I/{n})",
            missing.len(),
            dir.display(),
            missing.join(", ")
        )));
    }
    Ok(by_index)
}

/// The data files manifest `m` (at `p`) lists: its shard's own, `STEM.csv` and
/// `STEM.sections.csv` beside it, as [`write_shard`] names them.
///
/// # Errors
/// [`StudyError::Corrupt`] naming the manifest, the key and the file it lists.
fn check_listed_files(p: &Path, m: &ShardManifest, shard: Shard) -> Result<(), StudyError> {
    let stem = shard.stem();
    for (key, listed, expected) in [
        ("points_file", &m.points_file, format!("{stem}.csv")),
        (
            "sections_file",
            &m.sections_file,
            format!("{stem}.sections.csv"),
        ),
    ] {
        if *listed != expected {
            return Err(corrupt(
                p,
                format!(
                    "{key} is {listed:?}; the files of shard {shard} are {stem}.csv and \
                     {stem}.sections.csv beside its manifest"
                ),
            ));
        }
    }
    Ok(())
}

/// Reads the points of `shard` (manifest `m` at `p`) into their `slots`, after checking
/// the manifest's counts against the spec's `total` and the points file against both:
/// each message says which count is claimed and which was found.
fn place_shard(
    study: &Study,
    dir: &Path,
    p: &Path,
    m: &ShardManifest,
    shard: Shard,
    total: usize,
    slots: &mut [Option<PointRecord>],
) -> Result<(), StudyError> {
    let expected: Vec<usize> = shard_indices(total, shard).collect();
    check_manifest_counts(p, m, shard, total, expected.len())?;
    let recs = read_shard(study, dir, m, p)?;
    check_points_file(p, m, &recs)?;
    for (r, &e) in recs.into_iter().zip(&expected) {
        if r.index != e {
            return Err(corrupt(
                p,
                format!("point {} where point {e} was expected", r.index),
            ));
        }
        let slot = slots
            .get_mut(e)
            .ok_or_else(|| corrupt(p, format!("point {e} outside the grid")))?;
        if slot.is_some() {
            return Err(corrupt(p, format!("point {e} appears twice")));
        }
        *slot = Some(r);
    }
    Ok(())
}

/// The manifest's study size and point count against the spec's `total` and the shard's
/// share `expected` of it.
fn check_manifest_counts(
    p: &Path,
    m: &ShardManifest,
    shard: Shard,
    total: usize,
    expected: usize,
) -> Result<(), StudyError> {
    if m.total_points != total {
        return Err(corrupt(
            p,
            format!(
                "the manifest claims a study of {} points, its spec has {total}",
                m.total_points
            ),
        ));
    }
    if m.points != expected {
        return Err(corrupt(
            p,
            format!(
                "the manifest claims {} points, shard {shard} of a study of {total} points \
                 has {expected}",
                m.points
            ),
        ));
    }
    Ok(())
}

/// The points read from the points file against the manifest's point and failure counts.
fn check_points_file(p: &Path, m: &ShardManifest, recs: &[PointRecord]) -> Result<(), StudyError> {
    if recs.len() != m.points {
        return Err(corrupt(
            p,
            format!(
                "the manifest claims {} points, its points file {} holds {}",
                m.points,
                m.points_file,
                recs.len()
            ),
        ));
    }
    let failed = recs.iter().filter(|r| !r.is_ok()).count();
    if failed != m.failed_points {
        return Err(corrupt(
            p,
            format!(
                "the manifest claims {} failed points, its points file {} holds {failed}",
                m.failed_points, m.points_file
            ),
        ));
    }
    Ok(())
}

/// The indices of `shard`: `i ≡ shard.index() − 1 (mod shard.count())`, ascending
/// (round-robin spreads the costly regions of a map over all shards).
pub fn shard_indices(total: usize, shard: Shard) -> impl Iterator<Item = usize> {
    (shard.index() - 1..total).step_by(shard.count())
}
