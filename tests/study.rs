//! Studies (feature `cli`): determinism over shard and thread counts, the verified merge,
//! attractor labels, bad inputs, the command-line tool.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

use nonsmooth::study::{
    Merged, PlanSettings, Shard, Study, StudyError, compute_point, read_shards, regime_class,
    run_shard, run_to_dir, sbatch_script, write_shard,
};

/// A fresh scratch directory for one test, removed when dropped.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("nonsmooth-study-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

/// A small regime map with every recorded quantity.
const MAP: &str = r#"
name = "map"
[system]
model = "paper"
[grid]
x = { parameter = "omega", start = 18.0, end = 24.0, points = 5 }
y = { parameter = "amplitude_factor", start = 0.8, end = 1.2, points = 3 }
[periods]
transient = 40
record = 20
[record]
poincare = 4
lyapunov = { periods = 10 }
q = { lo = 0.05, hi = 0.3, step = 0.001 }
"#;

/// A small basin picture where two attractors coexist (period 3 and the 3-impacts-per-2-
/// periods family, see `examples/studies/paper_basin_22_73.toml`).
const BASIN: &str = r#"
name = "basin"
[system]
model = "paper"
parameters = { omega = 22.73 }
[grid]
x = { parameter = "x0", start = -0.01, end = -0.0021, points = 5 }
y = { parameter = "v0", start = -0.1, end = 0.1, points = 5 }
[periods]
transient = 300
record = 40
"#;

/// The impact surface moves along the grid (lanes are grouped by it) and the last rows of
/// the amplitude axis are cut short by a step cap (failed points).
const MOVING_STOP: &str = r#"
name = "stop"
[system]
model = "paper"
parameters = { omega = 20.5 }
[grid]
x = { parameter = "x_i", start = -3e-3, end = -1.5e-3, points = 4 }
y = { parameter = "omega", start = 19.0, end = 23.0, points = 3 }
[periods]
transient = 30
record = 10
[record]
q = { lo = 0.05, hi = 0.3, step = 0.001 }
"#;

/// Duffing–Ueda's initial-condition plane (no impact surface), with the exponent.
const DUFFING: &str = r#"
name = "duffing"
[system]
model = "duffing_ueda"
[grid]
x = { parameter = "x0", start = -3.0, end = 3.0, points = 4 }
y = { parameter = "v0", start = -3.0, end = 3.0, points = 3 }
[periods]
transient = 30
record = 10
[record]
lyapunov = { periods = 10 }
"#;

/// The 2-DOF impact oscillator with its stop moving along the grid (lanes are grouped by
/// the surface), impacts on it counted, the exponent recorded.
const TWO_DOF_GAPS: &str = r#"
name = "two_dof_gaps"
[system]
model = "two_dof_impact"
[grid]
x = { parameter = "gap", start = 0.02, end = 0.2, points = 3 }
y = { parameter = "omega", start = 0.5, end = 0.9, points = 3 }
[periods]
transient = 40
record = 10
[record]
lyapunov = { periods = 10 }
q = { lo = 0.5, hi = 20.0, step = 0.01 }
"#;

#[test]
fn lanes_of_any_system_give_the_scalar_records_to_the_bit() {
    // Duffing–Ueda and the 2-DOF impact oscillator run in lanes like the paper's model
    // (`StudySystem::run_batch`); `compute_point` is their scalar path.
    let capped = TWO_DOF_GAPS.replace(
        "name = \"two_dof_gaps\"",
        "name = \"capped\"\n[integration]\nmax_steps = 2500",
    );
    for text in [DUFFING, TWO_DOF_GAPS, capped.as_str()] {
        let study = Study::from_toml(text).unwrap();
        let lanes = run_shard(&study, Shard::WHOLE, || {});
        assert_eq!(lanes.len(), study.points());
        let mut failed = 0;
        let mut impacts = 0.0;
        for (i, got) in lanes.iter().enumerate() {
            let want = compute_point(&study, i);
            assert_eq!(
                format!("{got:?}"),
                format!("{want:?}"),
                "point {i} of\n{text}"
            );
            failed += usize::from(!got.is_ok());
            impacts += got.impacts_per_period.max(0.0);
        }
        if text == capped {
            assert!(failed > 0, "the step cap must fail some points");
        } else {
            assert_eq!(failed, 0, "{text}");
        }
        if text == TWO_DOF_GAPS {
            assert!(impacts > 0.0, "the stop must be hit somewhere on the grid");
        }
    }
}

#[test]
fn lanes_give_the_scalar_records_to_the_bit() {
    // `run_shard` runs the paper model's points in SIMD lanes; `compute_point` is the
    // scalar path, point by point. Every field, and every failure message, must agree.
    let capped = MOVING_STOP.replace(
        "name = \"stop\"",
        "name = \"capped\"\n[integration]\nmax_steps = 3000",
    );
    for text in [MAP, BASIN, MOVING_STOP, capped.as_str()] {
        let study = Study::from_toml(text).unwrap();
        let lanes = run_shard(&study, Shard::WHOLE, || {});
        assert_eq!(lanes.len(), study.points());
        let mut failed = 0;
        for (i, got) in lanes.iter().enumerate() {
            let want = compute_point(&study, i);
            // Debug prints every f64 exactly (and NaN as NaN).
            assert_eq!(
                format!("{got:?}"),
                format!("{want:?}"),
                "point {i} of\n{text}"
            );
            failed += usize::from(!got.is_ok());
        }
        if text == capped {
            assert!(failed > 0, "the step cap must fail some points");
        } else {
            assert_eq!(failed, 0, "{text}");
        }
    }
}

fn run_in_shards(study: &Study, dir: &Path, n: usize) {
    for i in 1..=n {
        run_to_dir(study, Shard::new(i, n).unwrap(), dir, || {}).unwrap();
    }
}

/// The merged files' bytes, in a fixed order.
fn merged_bytes(dir: &Path) -> Vec<Vec<u8>> {
    let out = dir.join("merged.csv");
    let m = Merged::from_dir(dir).unwrap();
    let files = m.write(&out).unwrap();
    files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "csv"))
        .map(|f| fs::read(f).unwrap())
        .collect()
}

#[test]
fn merged_result_is_identical_for_1_3_and_7_shards_and_any_thread_count() {
    for (name, text) in [("map", MAP), ("basin", BASIN)] {
        let study = Study::from_toml(text).unwrap();
        let mut results = Vec::new();
        for n in [1, 3, 7] {
            let d = scratch(&format!("det-{name}-{n}"));
            run_in_shards(&study, &d, n);
            results.push(merged_bytes(&d));
        }
        assert_eq!(results[0].len(), 3);
        assert_eq!(results[0], results[1], "{name}: 1 vs 3 shards");
        assert_eq!(results[0], results[2], "{name}: 1 vs 7 shards");
        // Thread counts: the whole study in pools of 1 and 2 threads.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let two = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let r1 = one.install(|| run_shard(&study, Shard::WHOLE, || {}));
        let r2 = two.install(|| run_shard(&study, Shard::WHOLE, || {}));
        let d1 = scratch(&format!("thr1-{name}"));
        let d2 = scratch(&format!("thr2-{name}"));
        write_shard(&d1, &study, Shard::WHOLE, &r1).unwrap();
        write_shard(&d2, &study, Shard::WHOLE, &r2).unwrap();
        assert_eq!(
            fs::read(d1.join("shard-00001-of-00001.csv")).unwrap(),
            fs::read(d2.join("shard-00001-of-00001.csv")).unwrap(),
            "{name}: 1 vs 2 threads"
        );
        assert_eq!(merged_bytes(&d1), results[0], "{name}: threads vs shards");
    }
}

#[test]
fn regime_map_records_what_the_spec_asks_for() {
    let study = Study::from_toml(MAP).unwrap();
    let d = scratch("records");
    run_to_dir(&study, Shard::WHOLE, &d, || {}).unwrap();
    let (_, recs) = read_shards(&d).unwrap();
    assert_eq!(recs.len(), 15);
    for r in &recs {
        assert!(r.is_ok(), "point {}: {}", r.index, r.status);
        assert!(
            r.tle.is_finite() && r.tle_spread.is_finite(),
            "point {}",
            r.index
        );
        assert_eq!(r.sections.len(), r.period.clamp(4, 20), "point {}", r.index);
        // A parameter map needs no fingerprints (no two points share their parameters).
        assert!(r.cells.is_empty());
        assert!(r.impacts_per_period >= 0.0);
    }
    // Above the first grazing (ω ≈ 14) every point of this map hits the stop.
    assert!(recs.iter().all(|r| r.impacts_per_period > 0.0));
    // Periodic points have a negative top exponent.
    for r in recs.iter().filter(|r| r.period > 0) {
        assert!(
            r.tle < 0.0,
            "point {} period {}: λ = {}",
            r.index,
            r.period,
            r.tle
        );
    }
}

#[test]
fn coexisting_attractors_get_different_labels() {
    let study = Study::from_toml(BASIN).unwrap();
    let recs = run_shard(&study, Shard::WHOLE, || {});
    let m = Merged::new(study, recs).unwrap();
    assert!(
        m.attractors.len() >= 2,
        "attractors: {:?}",
        m.attractors
            .iter()
            .map(|a| (a.period, a.impacts_per_period, a.points))
            .collect::<Vec<_>>()
    );
    for r in &m.records {
        assert!(!r.cells.is_empty() && r.cells.len() <= nonsmooth::study::MAX_CELLS);
        assert!(r.cells.windows(2).all(|w| w[0] < w[1]), "sorted, unique");
    }
    // Every point is labelled; the fractions add up to one.
    assert!(m.labels.iter().all(Option::is_some));
    let total: f64 = m.attractors.iter().map(|a| a.fraction).sum();
    assert!((total - 1.0).abs() < 1e-12);
    // Points with the same label have the same impacts per period (same attractor), and
    // the period-3 orbit with 4 impacts is among them.
    for (r, l) in m.records.iter().zip(&m.labels) {
        let a = &m.attractors[l.unwrap()];
        if r.period > 0 && a.period == r.period {
            assert!((r.impacts_per_period - a.impacts_per_period).abs() < 1e-9);
        }
    }
    assert!(
        m.attractors
            .iter()
            .any(|a| a.period == 3 && (a.impacts_per_period * 3.0 - 4.0).abs() < 1e-9)
    );
}

fn expect_spec_error(text: &str, field: &str) {
    match Study::from_toml(text) {
        Err(StudyError::InvalidSpec { field: f, .. }) => assert_eq!(f, field, "{text}"),
        Err(StudyError::Toml(m)) => assert!(m.contains(field), "{m} does not name {field}"),
        other => panic!("expected an error naming {field}, got {other:?}"),
    }
}

#[test]
fn bad_specs_name_the_field() {
    expect_spec_error(
        &MAP.replace("parameter = \"omega\"", "parameter = \"omegaa\""),
        "grid.x.parameter",
    );
    expect_spec_error(
        &BASIN.replace("omega = 22.73", "omega = 22.73, stiffness = 3.0"),
        "system.parameters.stiffness",
    );
    expect_spec_error(&MAP.replace("points = 5", "points = 0"), "grid.x.points");
    expect_spec_error(&MAP.replace("record = 20", "record = 0"), "periods.record");
    expect_spec_error(&MAP.replace("record = 20", "recrd = 20"), "recrd");
    expect_spec_error(
        &MAP.replace("model = \"paper\"", "model = \"cart\""),
        "system.model",
    );
    expect_spec_error(&MAP.replace("end = 24.0", "end = 17.0"), "grid.x.end");
    expect_spec_error(
        &MAP.replace("parameter = \"amplitude_factor\"", "parameter = \"omega\""),
        "grid.y.parameter",
    );
    expect_spec_error(&MAP.replace("start = 0.8", "start = -2.0"), "grid.y");
    expect_spec_error(
        &MAP.replace("lyapunov = { periods = 10 }", "lyapunov = { periods = 3 }"),
        "record.lyapunov.periods",
    );
    expect_spec_error(
        &BASIN.replace("parameters = { omega = 22.73 }", ""),
        "system.parameters.omega",
    );
    expect_spec_error("name = \"x\"", "system");
}

#[test]
fn bad_shards_are_rejected() {
    for bad in ["0/3", "4/3", "1/0", "x/3", "3", "1/2/3", "-1/3"] {
        assert!(
            matches!(Shard::parse(bad), Err(StudyError::Shard(_))),
            "{bad}"
        );
    }
    assert_eq!(Shard::parse("2/7").unwrap(), Shard::new(2, 7).unwrap());
    // More shards than points.
    let study = Study::from_toml(MAP).unwrap();
    let d = scratch("too-many");
    assert!(matches!(
        run_to_dir(&study, Shard::new(1, 16).unwrap(), &d, || {}),
        Err(StudyError::Shard(_))
    ));
    // Slurm array variables.
    let env = |id: &'static str, min: &'static str, max: &'static str, count: &'static str| {
        move |k: &str| -> Option<String> {
            match k {
                "SLURM_ARRAY_TASK_ID" => Some(id.into()),
                "SLURM_ARRAY_TASK_MIN" => Some(min.into()),
                "SLURM_ARRAY_TASK_MAX" => Some(max.into()),
                "SLURM_ARRAY_TASK_COUNT" => Some(count.into()),
                _ => None,
            }
        }
    };
    assert_eq!(
        Shard::from_slurm(env("0", "0", "2", "3")).unwrap(),
        Some(Shard::new(1, 3).unwrap())
    );
    assert_eq!(
        Shard::from_slurm(env("7", "5", "7", "3")).unwrap(),
        Some(Shard::new(3, 3).unwrap())
    );
    assert!(Shard::from_slurm(env("4", "0", "8", "3")).is_err()); // a stepped array
    assert!(Shard::from_slurm(env("a", "0", "2", "3")).is_err());
    assert_eq!(Shard::from_slurm(|_| None).unwrap(), None);
}

#[test]
fn merge_refuses_missing_mismatched_and_corrupt_shards() {
    let study = Study::from_toml(MAP).unwrap();
    let d = scratch("merge-errors");
    // Nothing there.
    assert!(matches!(
        Merged::from_dir(&d),
        Err(StudyError::MissingShards(_))
    ));
    run_to_dir(&study, Shard::new(1, 3).unwrap(), &d, || {}).unwrap();
    run_to_dir(&study, Shard::new(3, 3).unwrap(), &d, || {}).unwrap();
    match Merged::from_dir(&d) {
        Err(StudyError::MissingShards(m)) => assert!(m.contains(": 2 "), "{m}"),
        other => panic!("{other:?}"),
    }
    run_to_dir(&study, Shard::new(2, 3).unwrap(), &d, || {}).unwrap();
    let good = merged_bytes(&d);
    // A re-run replaces its shard: nothing lost or counted twice.
    run_to_dir(&study, Shard::new(2, 3).unwrap(), &d, || {}).unwrap();
    assert_eq!(merged_bytes(&d), good);

    // A corrupt points file (one byte changed) and a truncated sections file.
    let p = d.join("shard-00002-of-00003.csv");
    let orig = fs::read(&p).unwrap();
    let mut bad = orig.clone();
    let k = bad.iter().rposition(|&b| b == b'.').unwrap();
    bad[k + 1] = if bad[k + 1] == b'1' { b'2' } else { b'1' };
    fs::write(&p, &bad).unwrap();
    assert!(matches!(Merged::from_dir(&d), Err(StudyError::Corrupt(_))));
    fs::write(&p, &orig).unwrap();
    let s = d.join("shard-00001-of-00003.sections.csv");
    let orig_s = fs::read(&s).unwrap();
    fs::write(&s, &orig_s[..orig_s.len() / 2]).unwrap();
    assert!(matches!(Merged::from_dir(&d), Err(StudyError::Corrupt(_))));
    fs::write(&s, &orig_s).unwrap();
    // A corrupt manifest.
    let j = d.join("shard-00003-of-00003.json");
    let orig_j = fs::read(&j).unwrap();
    fs::write(&j, b"{ not json").unwrap();
    assert!(matches!(Merged::from_dir(&d), Err(StudyError::Corrupt(_))));
    fs::write(&j, &orig_j).unwrap();
    // A missing data file.
    fs::remove_file(&s).unwrap();
    assert!(matches!(
        Merged::from_dir(&d),
        Err(StudyError::MissingShards(_))
    ));
    fs::write(&s, &orig_s).unwrap();
    assert_eq!(merged_bytes(&d), good);

    // A shard of another run (other shard count) in the same directory.
    run_to_dir(&study, Shard::new(1, 2).unwrap(), &d, || {}).unwrap();
    assert!(matches!(Merged::from_dir(&d), Err(StudyError::Mismatch(_))));
    fs::remove_file(d.join("shard-00001-of-00002.json")).unwrap();
    assert_eq!(merged_bytes(&d), good);

    // A shard of another study: refused when running into the directory, and at merge.
    let other = Study::from_toml(&MAP.replace("record = 20", "record = 21")).unwrap();
    assert_ne!(other.hash(), study.hash());
    assert!(matches!(
        run_to_dir(&other, Shard::new(1, 3).unwrap(), &d, || {}),
        Err(StudyError::Mismatch(_))
    ));
    let e = scratch("merge-other");
    run_to_dir(&other, Shard::new(1, 3).unwrap(), &e, || {}).unwrap();
    fs::copy(
        e.join("shard-00001-of-00003.json"),
        d.join("shard-00001-of-00003.json"),
    )
    .unwrap();
    assert!(matches!(Merged::from_dir(&d), Err(StudyError::Mismatch(_))));
}

#[test]
fn spec_hash_is_stable_and_layout_independent() {
    let a = Study::from_toml(MAP).unwrap();
    // Same study, other layout and explicit defaults.
    let b = Study::from_toml(&MAP.replace(
        "[periods]",
        "[integration]\nrtol = 1e-8\nmax_steps = 10000000\n[periods]",
    ))
    .unwrap();
    assert_eq!(a.hash(), b.hash());
    assert_eq!(a.hash().len(), 16);
    // Any change of substance changes it.
    let c = Study::from_toml(&MAP.replace("end = 24.0", "end = 24.5")).unwrap();
    assert_ne!(a.hash(), c.hash());
}

#[test]
fn plan_prints_an_array_script() {
    let study = Study::from_toml(MAP).unwrap();
    let s = sbatch_script(
        &study,
        Path::new("/data/map.toml"),
        &PlanSettings::new(5, "/data/out", "/opt/nonsmooth").cpus(4),
    )
    .unwrap();
    assert!(s.starts_with("#!/bin/bash\n"));
    assert!(s.contains("#SBATCH --array=1-5\n"));
    assert!(s.contains("#SBATCH --cpus-per-task=4\n"));
    assert!(s.contains("--shard \"${SLURM_ARRAY_TASK_ID}/5\""));
    assert!(s.contains("'/data/map.toml'"));
    assert!(
        sbatch_script(
            &study,
            Path::new("m.toml"),
            &PlanSettings::new(16, "o", "p")
        )
        .is_err()
    );
    assert!(sbatch_script(&study, Path::new("m.toml"), &PlanSettings::new(0, "o", "p")).is_err());
}

#[test]
fn command_line_runs_merges_and_reports_errors() {
    let exe = env!("CARGO_BIN_EXE_nonsmooth");
    let d = scratch("cli");
    let spec = d.join("map.toml");
    fs::write(&spec, MAP.replace("lyapunov = { periods = 10 }", "")).unwrap();
    let out = d.join("shards");
    for i in 1..=2 {
        let st = Command::new(exe)
            .args(["study", "run"])
            .arg(&spec)
            .arg("--out")
            .arg(&out)
            .args(["--shard", &format!("{i}/2"), "--threads", "1", "--quiet"])
            .env_remove("SLURM_ARRAY_TASK_ID")
            .status()
            .unwrap();
        assert!(st.success());
    }
    let table = d.join("merged/map.csv");
    let st = Command::new(exe)
        .args(["study", "merge"])
        .arg(&out)
        .arg("--out")
        .arg(&table)
        .status()
        .unwrap();
    assert!(st.success());
    let text = fs::read_to_string(&table).unwrap();
    assert_eq!(text.lines().count(), 16);
    assert!(text.starts_with("index,ix,iy,omega,amplitude_factor,"));
    assert!(d.join("merged/map.png").exists());
    assert!(d.join("merged/map.attractors.csv").exists());
    // Errors: a shard out of range, a missing shard, an unknown command.
    let o = Command::new(exe)
        .args(["study", "run"])
        .arg(&spec)
        .arg("--out")
        .arg(&out)
        .args(["--shard", "3/2"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("out of range"));
    fs::remove_file(out.join("shard-00002-of-00002.json")).unwrap();
    let o = Command::new(exe)
        .args(["study", "merge"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing"));
    let o = Command::new(exe)
        .args(["study", "frobnicate"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    // plan prints a script.
    let o = Command::new(exe)
        .args(["study", "plan"])
        .arg(&spec)
        .args(["--shards", "3", "--out"])
        .arg(d.join("planned"))
        .output()
        .unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("#SBATCH --array=1-3"));
}

#[test]
fn duffing_ueda_study_runs_without_a_stop() {
    let text = r#"
name = "ueda"
[system]
model = "duffing_ueda"
[grid]
x = { parameter = "x0", start = -2.0, end = 2.0, points = 3 }
[periods]
transient = 20
record = 20
[record]
lyapunov = { periods = 10 }
q = { lo = 0.1, hi = 1.0, step = 0.01 }
"#;
    let study = Study::from_toml(text).unwrap();
    let recs = run_shard(&study, Shard::WHOLE, || {});
    assert_eq!(recs.len(), 3);
    for r in &recs {
        assert!(r.is_ok(), "{}", r.status);
        // No stop: no impacts, no intervals, no entropy index.
        assert_eq!(r.impacts_per_period, 0.0);
        assert!(r.q.is_nan());
        assert!(r.tle.is_finite());
    }
    // The initial condition axis changes the start: the first sections differ.
    assert_ne!(recs[0].sections, recs[2].sections);
    // A parameter of the paper's model is unknown here.
    expect_spec_error(
        &text.replace("[periods]", "[system.parameters]\nx_i = 0.1\n[periods]"),
        "system.parameters.x_i",
    );
}

/// A small, quick map (no Lyapunov exponent, no entropy index).
const TINY: &str = r#"
name = "tiny"
[system]
model = "paper"
[grid]
x = { parameter = "omega", start = 18.0, end = 24.0, points = 5 }
[periods]
transient = 10
record = 10
"#;

/// Runs the command-line tool with `args`, killing it after `secs` seconds (a hang fails
/// the test instead of stalling the suite); returns its status and output.
fn run_cli(args: &[&std::ffi::OsStr], secs: u64) -> (bool, String, String) {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_nonsmooth"))
        .args(args)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(secs);
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if std::time::Instant::now() > deadline {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("nonsmooth {args:?} did not finish within {secs} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    let (mut out, mut err) = (String::new(), String::new());
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (status.success(), out, err)
}

fn os(s: &str) -> &std::ffi::OsStr {
    std::ffi::OsStr::new(s)
}

fn shard_manifests(dir: &Path) -> usize {
    fs::read_dir(dir).map_or(0, |rd| {
        rd.filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.file_name().to_string_lossy().ends_with(".json"))
        })
        .count()
    })
}

/// Issue 27: `transient = 4000000000` passed `study check`, and `study run` exited 0 with
/// every point failed on the 10⁹-section limit of a run. Work beyond a limit is an error of
/// the spec, naming the field and the limit, in `check` and in `run` before any point runs.
#[test]
fn work_beyond_a_limit_is_rejected_before_any_point_runs() {
    let limit_error = |text: &str, field: &str, limit: &str| match Study::from_toml(text) {
        Err(StudyError::InvalidSpec { field: f, message }) => {
            assert_eq!(f, field, "{message}");
            assert!(message.contains(limit), "{f} {message}: no limit {limit}");
        }
        other => panic!("expected an error naming {field}, got {other:?}"),
    };
    limit_error(
        &TINY.replace("transient = 10", "transient = 4000000000"),
        "periods.transient",
        "999999999",
    );
    limit_error(
        &TINY
            .replace("transient = 10", "transient = 999999990")
            .replace(
                "[periods]",
                "[integration]\nmax_steps = 2000000000\n[periods]",
            ),
        "periods",
        "999999999",
    );
    // Fewer steps than periods: steps land on every period, so every point would stop.
    limit_error(
        &TINY.replace("[periods]", "[integration]\nmax_steps = 19\n[periods]"),
        "integration.max_steps",
        "20",
    );
    limit_error(
        &TINY.replace(
            "[periods]",
            "[record]\nlyapunov = { periods = 100000001 }\n[periods]",
        ),
        "record.lyapunov.periods",
        "100000000",
    );
    limit_error(
        &TINY.replace(
            "[periods]",
            "[record]\nq = { lo = 0.0, hi = 1.0, step = 1e-9 }\n[periods]",
        ),
        "record.q.step",
        "16777216",
    );
    // At the limits the spec is valid.
    let at = TINY
        .replace("transient = 10", "transient = 999999989")
        .replace(
            "[periods]",
            "[integration]\nmax_steps = 999999999\n[periods]",
        );
    assert!(Study::from_toml(&at).is_ok());

    // The command line: `check` and `run` fail naming the field; `run` writes nothing.
    let d = scratch("limits");
    let spec = d.join("big.toml");
    fs::write(
        &spec,
        TINY.replace("transient = 10", "transient = 4000000000"),
    )
    .unwrap();
    let (ok, _, err) = run_cli(&[os("study"), os("check"), spec.as_os_str()], 60);
    assert!(!ok && err.contains("periods.transient"), "{err}");
    let out = d.join("out");
    let (ok, _, err) = run_cli(
        &[
            os("study"),
            os("run"),
            spec.as_os_str(),
            os("--out"),
            out.as_os_str(),
            os("--quiet"),
        ],
        60,
    );
    assert!(!ok && err.contains("periods.transient"), "{err}");
    assert_eq!(shard_manifests(&out), 0, "no point may run");
}

/// A `study run` whose every point failed exits non-zero (the shard files are written, with
/// the reasons in their status column); so does the merge of such a study.
#[test]
fn a_run_or_merge_where_every_point_failed_exits_non_zero() {
    let d = scratch("all-failed");
    let spec = d.join("capped.toml");
    // 20 steps for 20 periods: valid, but every point needs more.
    fs::write(
        &spec,
        TINY.replace("[periods]", "[integration]\nmax_steps = 20\n[periods]"),
    )
    .unwrap();
    let out = d.join("out");
    let (ok, _, err) = run_cli(
        &[
            os("study"),
            os("run"),
            spec.as_os_str(),
            os("--out"),
            out.as_os_str(),
            os("--quiet"),
        ],
        120,
    );
    assert!(!ok, "{err}");
    assert!(
        err.contains("every point of shard 1/1 failed (5 of 5)"),
        "{err}"
    );
    assert_eq!(shard_manifests(&out), 1, "the shard files are written");
    let (_, recs) = read_shards(&out).unwrap();
    assert!(recs.iter().all(|r| !r.is_ok()));
    let (ok, _, err) = run_cli(&[os("study"), os("merge"), out.as_os_str()], 120);
    assert!(!ok, "{err}");
    assert!(
        err.contains("every point of the study failed (5 of 5"),
        "{err}"
    );
    assert!(out.join("merged.csv").exists());
}

/// Issue 27: an `x0` axis from −1e308 to 1e308 gave the axis values NaN, inf, inf (the
/// linspace overflowed), the spec was accepted, the NaN point ran (from the rest state) and
/// was recorded `ok`, and `study merge` hung (plotters' tick loop on a range that is not
/// finite). The values are now −1e308, 0, 1e308, and the merge draws an axis whose range
/// overflows over its grid index.
#[test]
fn an_axis_across_the_f64_range_has_finite_values_and_merges() {
    let text = r#"
name = "huge"
[system]
model = "duffing_ueda"
[grid]
x = { parameter = "x0", start = -1e308, end = 1e308, points = 3 }
y = { parameter = "v0", start = -1e308, end = 1e308, points = 3 }
[periods]
transient = 20
record = 10
"#;
    let study = Study::from_toml(text).unwrap();
    let xs: Vec<f64> = (0..3).map(|i| study.values(i).0).collect();
    assert_eq!(xs, [-1e308, 0.0, 1e308]);
    for i in 0..study.points() {
        let (x, y) = study.values(i);
        assert!(x.is_finite() && y.is_finite(), "point {i}: {x}, {y}");
    }
    let d = scratch("huge-axis");
    let spec = d.join("huge.toml");
    fs::write(&spec, text).unwrap();
    let out = d.join("out");
    let (ok, _, err) = run_cli(
        &[
            os("study"),
            os("run"),
            spec.as_os_str(),
            os("--out"),
            out.as_os_str(),
            os("--quiet"),
        ],
        120,
    );
    assert!(ok, "{err}");
    let (_, recs) = read_shards(&out).unwrap();
    // The origin runs; a start at x0 = ±1e308 does not (its force overflows).
    assert!(recs[4].is_ok(), "{}", recs[4].status);
    for i in [0, 2, 3, 5, 6, 8] {
        assert!(!recs[i].is_ok(), "point {i}");
    }
    let (ok, _, err) = run_cli(&[os("study"), os("merge"), out.as_os_str()], 120);
    assert!(ok, "{err}");
    let table = fs::read_to_string(out.join("merged.csv")).unwrap();
    for line in table.lines().skip(1) {
        let xy: Vec<f64> = line
            .split(',')
            .skip(3)
            .take(2)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!(xy.iter().all(|v| v.is_finite()), "{line}");
    }
    assert!(out.join("merged.png").exists());
}

/// Issue 27: a manifest that claims one point more than its shard has gave "5 points,
/// shard 1/3 of 15 points has 5". Each count is now checked on its own, and the message
/// says which is claimed and which was found.
#[test]
fn a_manifest_with_a_wrong_count_says_which() {
    let study = Study::from_toml(TINY).unwrap();
    let d = scratch("claims");
    run_in_shards(&study, &d, 2);
    let j = d.join("shard-00001-of-00002.json");
    let orig = fs::read_to_string(&j).unwrap();
    let tamper = |key: &str, delta: i64| {
        let mut v: serde_json::Value = serde_json::from_str(&orig).unwrap();
        let n = v[key].as_i64().unwrap();
        v[key] = (n + delta).into();
        fs::write(&j, serde_json::to_string_pretty(&v).unwrap()).unwrap();
        match Merged::from_dir(&d) {
            Err(StudyError::Corrupt(m)) => m,
            other => panic!("{key}: {other:?}"),
        }
    };
    // Shard 1 of 2 of 5 points holds points 0, 2, 4.
    let m = tamper("points", 1);
    assert!(
        m.contains("the manifest claims 4 points, shard 1/2 of a study of 5 points has 3"),
        "{m}"
    );
    let m = tamper("total_points", 1);
    assert!(
        m.contains("the manifest claims a study of 6 points, its spec has 5"),
        "{m}"
    );
    let m = tamper("failed_points", 2);
    assert!(
        m.contains("the manifest claims 2 failed points, its points file"),
        "{m}"
    );
    assert!(m.ends_with("holds 0"), "{m}");
    fs::write(&j, &orig).unwrap();
    assert!(Merged::from_dir(&d).is_ok());
}

/// Issue 27 (security): `study plan --partition` was copied into the sbatch script
/// unchecked, so a newline put a command on its own line. Every value written into the
/// script is checked: `#SBATCH` values must be plain tokens, the shell's words are
/// single-quoted and hold no control characters. Each hostile value is rejected, or the
/// script — run by bash with `exec` replaced by a function that records its arguments —
/// executes nothing of it and passes it through unchanged.
#[test]
fn plan_rejects_or_quotes_every_hostile_value() {
    let study = Study::from_toml(MAP).unwrap();
    let d = scratch("plan-hostile");
    let pwned = d.join("pwned");
    let p = pwned.display().to_string();
    let payloads = [
        format!("x\ntouch {p}"),
        format!("x\r\ntouch {p}"),
        format!("x'; touch {p}; '"),
        format!("x\"; touch {p}; \""),
        format!("$(touch {p})"),
        format!("`touch {p}`"),
        format!("x; touch {p}"),
        format!("x && touch {p} #"),
        format!("${{IFS}}touch${{IFS}}{p}"),
    ];
    let base = || PlanSettings::new(3, "/data/out", "/opt/nonsmooth");
    let spec_path = PathBuf::from("/data/map.toml");
    // The values of `#SBATCH` lines: every payload is rejected, naming the setting.
    for v in &payloads {
        for (field, settings) in [
            ("--partition", base().partition(Some(v.clone()))),
            ("--time", base().time(v.clone())),
            ("--out", PlanSettings::new(3, v.clone(), "/opt/nonsmooth")),
        ] {
            match sbatch_script(&study, &spec_path, &settings) {
                Err(e) => assert!(e.to_string().contains(field), "{field}: {e}"),
                Ok(s) => panic!("{field} = {v:?} accepted:\n{s}"),
            }
        }
    }
    for bad in ["gpu normal", "gpu%x", "", "a/b"] {
        assert!(
            sbatch_script(&study, &spec_path, &base().partition(Some(bad.into()))).is_err(),
            "{bad:?}"
        );
    }
    assert!(
        sbatch_script(
            &study,
            &spec_path,
            &base().partition(Some("gpu,long-1.x_2".into()))
        )
        .is_ok()
    );
    // The study's name (the job name) is checked by the spec.
    for v in &payloads {
        let text = MAP.replace("name = \"map\"", &format!("name = {v:?}"));
        assert!(Study::from_toml(&text).is_err(), "name {v:?}");
    }
    // The program and spec paths are shell words: control characters and a leading '-'
    // are rejected, everything else is quoted and reaches the program unchanged.
    let script_file = d.join("job.sh");
    let args_file = d.join("args");
    for v in &payloads {
        for field in ["program", "spec path"] {
            let (settings, spec) = if field == "program" {
                (
                    PlanSettings::new(3, "/data/out", v.clone()),
                    spec_path.clone(),
                )
            } else {
                (base(), PathBuf::from(v))
            };
            let script = match sbatch_script(&study, &spec, &settings) {
                Err(e) => {
                    assert!(v.contains(['\n', '\r']), "{field} = {v:?}: {e}");
                    assert!(e.to_string().contains(field), "{e}");
                    continue;
                }
                Ok(s) => s,
            };
            // Only two lines execute: `set` and the `exec` of the program.
            let code: Vec<&str> = script
                .lines()
                .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
                .collect();
            assert_eq!(code.len(), 2, "{script}");
            assert_eq!(code[0], "set -euo pipefail");
            assert!(code[1].starts_with("exec '"), "{script}");
            for l in script.lines().filter(|l| l.starts_with("#SBATCH")) {
                let value = l.strip_prefix("#SBATCH ").unwrap();
                assert!(
                    value
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || "-=_.,/+@%:".contains(c)),
                    "{l}"
                );
            }
            fs::write(
                &script_file,
                format!(
                    "exec() {{ printf '%s\\0' \"$@\" > '{}'; }}\nsource '{}'\n",
                    args_file.display(),
                    script_file.with_extension("body").display()
                ),
            )
            .unwrap();
            fs::write(script_file.with_extension("body"), &script).unwrap();
            let _ = fs::remove_file(&args_file);
            let st = Command::new("bash")
                .arg(&script_file)
                .env("SLURM_ARRAY_TASK_ID", "2")
                .env_remove("SLURM_CPUS_PER_TASK")
                .status()
                .unwrap();
            assert!(st.success(), "{field} = {v:?}:\n{script}");
            assert!(!pwned.exists(), "{field} = {v:?} executed:\n{script}");
            let args = fs::read(&args_file).unwrap();
            let args: Vec<String> = args
                .split(|&b| b == 0)
                .filter(|a| !a.is_empty())
                .map(|a| String::from_utf8(a.to_vec()).unwrap())
                .collect();
            let (prog, spec) = if field == "program" {
                (v.as_str(), "/data/map.toml")
            } else {
                ("/opt/nonsmooth", v.as_str())
            };
            assert_eq!(
                args,
                [
                    prog,
                    "study",
                    "run",
                    spec,
                    "--out",
                    "/data/out",
                    "--shard",
                    "2/3",
                    "--threads",
                    "1",
                    "--quiet"
                ],
                "{field} = {v:?}"
            );
        }
    }
    assert!(sbatch_script(&study, &spec_path, &PlanSettings::new(3, "/data/out", "-x")).is_err());
    // The command line refuses a hostile partition and prints no script.
    let spec = d.join("map.toml");
    fs::write(&spec, MAP).unwrap();
    let (ok, out, err) = run_cli(
        &[
            os("study"),
            os("plan"),
            spec.as_os_str(),
            os("--shards"),
            os("3"),
            os("--out"),
            d.join("planned").as_os_str(),
            os("--partition"),
            os(&payloads[0]),
        ],
        60,
    );
    assert!(!ok && out.is_empty(), "{out}");
    assert!(err.contains("--partition"), "{err}");
    assert!(!pwned.exists());
}

/// A system of two degrees of freedom (the catalogue's 2-DOF impact oscillator: a state of
/// four components, one impact surface) over the forcing frequency and the initial position
/// of the secondary mass.
const TWO_DOF: &str = r#"
name = "two_dof"
[system]
model = "two_dof_impact"
[grid]
x = { parameter = "omega", start = 0.5, end = 0.9, points = 4 }
y = { parameter = "x2_0", start = -0.3, end = 0.3, points = 3 }
[periods]
transient = 40
record = 16
[record]
poincare = 4
lyapunov = { periods = 10 }
"#;

#[test]
fn a_two_dof_study_records_whole_states_and_merges_identically_in_shards() {
    let study = Study::from_toml(TWO_DOF).unwrap();
    let mut results = Vec::new();
    for n in [1, 3] {
        let d = scratch(&format!("two-dof-{n}"));
        run_in_shards(&study, &d, n);
        let (_, recs) = read_shards(&d).unwrap();
        // What the shard files hold is what the points computed.
        for r in &recs {
            assert_eq!(
                format!("{r:?}"),
                format!("{:?}", compute_point(&study, r.index))
            );
        }
        results.push(merged_bytes(&d));
        if n == 1 {
            let m = Merged::from_dir(&d).unwrap();
            m.write(&d.join("merged.csv")).unwrap();
            let sections = fs::read_to_string(d.join("merged.sections.csv")).unwrap();
            assert!(sections.starts_with("index,k,x1,x2,v1,v2\n"), "{sections}");
            let attractors = fs::read_to_string(d.join("merged.attractors.csv")).unwrap();
            assert!(
                attractors
                    .lines()
                    .next()
                    .unwrap()
                    .ends_with(",centroid_x1,centroid_x2,centroid_v1,centroid_v2"),
                "{attractors}"
            );
            assert!(d.join("merged.png").exists());
        }
        for r in &recs {
            assert!(r.is_ok(), "point {}: {}", r.index, r.status);
            assert!(!r.sections.is_empty());
            assert!(r.sections.iter().all(|s| s.len() == 4));
            // An initial-condition axis: fingerprints of four integers per cell.
            assert!(!r.cells.is_empty() && r.cells.iter().all(|c| c.len() == 4));
            // One surface: no per-surface columns.
            assert!(r.impacts_per_surface.is_empty());
        }
        // The secondary mass hits its stop at every frequency of the map.
        assert!(recs.iter().all(|r| r.impacts_per_period > 0.0));
        // The axis of the secondary mass's start moves it: its first sections differ.
        let (a, b) = (&recs[0].sections, &recs[8].sections);
        assert_eq!(study.values(8).1, 0.3);
        assert!(a != b || recs[0].period == 1);
    }
    assert_eq!(results[0], results[1], "1 vs 3 shards");
    // Settings of the wrong size are rejected, naming the field.
    expect_spec_error(
        &TWO_DOF.replace("[periods]", "[initial]\nstate = [0.0, 0.0]\n[periods]"),
        "initial.state",
    );
    expect_spec_error(
        &TWO_DOF.replace(
            "[periods]",
            "[attractors]\nscales = [1.0, 1.0, 1.0]\n[periods]",
        ),
        "attractors.scales",
    );
    expect_spec_error(
        &TWO_DOF.replace(
            "[periods]",
            "[integration]\natol = [1e-9, 1e-9, 1e-9, -1.0]\n[periods]",
        ),
        "integration.atol[3]",
    );
    // `x0` is the initial-condition axis of one degree of freedom, not of two.
    expect_spec_error(
        &TWO_DOF.replace("parameter = \"x2_0\"", "parameter = \"x0\""),
        "grid.y.parameter",
    );
}

/// The example `examples/studies/impact_damper_2dof.toml`: a system described in the study
/// file (two masses, four elements, a load, two impact surfaces).
const DAMPER: &str = include_str!("../examples/studies/impact_damper_2dof.toml");

#[test]
fn a_described_two_dof_impact_damper_runs_whole_and_in_shards_and_draws_its_map() {
    let study = Study::from_toml(DAMPER).unwrap();
    assert_eq!(study.points(), 15);
    assert!(
        sbatch_script(
            &study,
            Path::new("impact_damper_2dof.toml"),
            &PlanSettings::new(3, "out", "nonsmooth")
        )
        .is_ok()
    );
    let mut results = Vec::new();
    for n in [1, 3] {
        let d = scratch(&format!("damper-{n}"));
        run_in_shards(&study, &d, n);
        results.push(merged_bytes(&d));
        // The shards run the described system's points in lanes: each record is the
        // scalar path's, point by point, to the bit.
        let (_, recs) = read_shards(&d).unwrap();
        for r in &recs {
            assert_eq!(
                format!("{r:?}"),
                format!("{:?}", compute_point(&study, r.index))
            );
        }
        if n == 3 {
            let m = Merged::from_dir(&d).unwrap();
            let files = m.write(&d.join("map.csv")).unwrap();
            assert!(files.iter().any(|f| f.ends_with("map.png")));
            assert!(d.join("map.png").metadata().unwrap().len() > 1000);
            let table = fs::read_to_string(d.join("map.csv")).unwrap();
            assert!(
                table.starts_with(
                    "index,ix,iy,omega,amplitude_factor,period,impacts_per_period,\
                     impacts_per_period_0,impacts_per_period_1,tle,"
                ),
                "{table}"
            );
            for (r, l) in m.records.iter().zip(&m.labels) {
                assert!(r.is_ok(), "point {}: {}", r.index, r.status);
                assert_eq!(l, &Some(0));
                assert_eq!(r.impacts_per_surface.len(), 2);
                // The total is the sum of the walls' (exact: counts over one window).
                let sum: f64 = r.impacts_per_surface.iter().sum();
                assert!((sum - r.impacts_per_period).abs() < 1e-12, "{r:?}");
                assert!(r.sections.iter().all(|s| s.len() == 4));
                assert!(r.tle.is_finite());
            }
            // The free mass hits both walls everywhere; periodic and chaotic regimes.
            assert!(
                m.records
                    .iter()
                    .all(|r| r.impacts_per_surface.iter().all(|&i| i > 0.0))
            );
            let classes: Vec<String> = m.records.iter().map(regime_class).collect();
            assert!(classes.iter().any(|c| c == "P1, 2 imp."), "{classes:?}");
            assert!(classes.iter().any(|c| c == "chaotic"), "{classes:?}");
        }
    }
    assert_eq!(results[0], results[1], "1 vs 3 shards");
}

#[test]
fn a_described_rigid_stop_runs_with_restitution() {
    // A forced mass on a spring against a rigid stop: Newton restitution, chattering and
    // sticking through the drive.
    let text = r#"
name = "rigid"
[system]
model = "mechanical"
masses = [1.0]
[[system.elements]]
law = "linear_spring"
dof = 0
k = 1.0
[[system.elements]]
law = "viscous_damper"
dof = 0
c = 0.05
[[system.loads]]
dof = 0
amplitude = 0.5
[[system.surfaces]]
dof = 0
position = 0.2
restitution = "e"
[grid]
x = { parameter = "omega", start = 0.8, end = 1.6, points = 3 }
y = { parameter = "e", start = 0.5, end = 0.8, points = 2 }
[periods]
transient = 30
record = 10
"#;
    let study = Study::from_toml(text).unwrap();
    let recs = run_shard(&study, Shard::WHOLE, || {});
    for r in &recs {
        assert!(r.is_ok(), "point {}: {}", r.index, r.status);
        assert!(r.impacts_per_period > 0.0, "point {}", r.index);
        // The stop holds: no section beyond it.
        assert!(r.sections.iter().all(|s| s[0] <= 0.2 + 1e-9), "{r:?}");
    }
    expect_spec_error(
        &text.replace("start = 0.5, end = 0.8", "start = 0.5, end = 1.8"),
        "grid.y",
    );
}

#[test]
fn bad_descriptions_name_the_field() {
    let d = DAMPER;
    let cases: Vec<(String, &str)> = vec![
        (
            d.replacen("law = \"hertz\"", "law = \"herz\"", 1),
            "system.elements[2].law",
        ),
        (
            d.replacen("k = 1e4", "kk = 1e4", 1),
            "system.elements[2].kk",
        ),
        (d.replacen("k = 1e4\n", "", 1), "system.elements[2].k"),
        (d.replacen("k = 1.0", "k = -1.0", 1), "system.elements[0].k"),
        (
            d.replacen("dof = 0", "dof = 2", 1),
            "system.elements[0].dof",
        ),
        (
            d.replacen(
                "law = \"hertz\"\nbetween = [1, 0]",
                "law = \"hertz\"\nbetween = [1, 1]",
                1,
            ),
            "system.elements[2].between",
        ),
        (
            d.replacen("side = \"lower\"", "side = \"below\"", 1),
            "system.elements[3].side",
        ),
        (
            d.replace("masses = [1.0, 0.05]", "masses = []"),
            "system.masses",
        ),
        (
            d.replace("masses = [1.0, 0.05]", "masses = [1.0, -0.05]"),
            "system.masses[1]",
        ),
        (
            d.replace("masses = [1.0, 0.05]", "masses = [1.0, 1.0, 1.0, 1.0, 1.0]"),
            "system.masses",
        ),
        (
            d.replace("parameters = { gap = 0.1 }", ""),
            "system.parameters.gap",
        ),
        (
            d.replace("gap = 0.1 }", "gap = 0.1, gapp = 0.2 }"),
            "system.parameters.gapp",
        ),
        (
            d.replacen("amplitude = 0.05", "amplitude = \"x2_0\"", 1),
            "system.loads[0].amplitude",
        ),
        (
            d.replacen(
                "position = \"-gap\"\nside",
                "position = \"-gap\"\nrestitution = 0.5\nside",
                1,
            ),
            "system.surfaces[1].restitution",
        ),
        (
            d.replace("model = \"mechanical\"", "model = \"paper\""),
            "system.masses",
        ),
        (
            d.replacen("[[system.loads]]\ndof = 0", "[[system.loads]]\ndof = 5", 1),
            "system.loads[0].dof",
        ),
    ];
    for (text, field) in &cases {
        expect_spec_error(text, field);
    }
    // A parameter without a value; then on an axis whose values a law rejects.
    let ok = d.replace("k = 1e4\nb = 2.0", "k = \"kc\"\nb = 2.0");
    expect_spec_error(&ok, "system.parameters.kc");
    let axis = ok.replace(
        "y = { parameter = \"amplitude_factor\", start = 0.5, end = 1.5, points = 3 }",
        "y = { parameter = \"kc\", start = -1.0, end = 1e4, points = 3 }",
    );
    expect_spec_error(&axis, "grid.y");
}

/// Every spec in `examples/studies` reads and plans, the catalogue's models and a described
/// system among them; the small ones (at most 30 points) run whole and in two shards, every
/// point without failure, with the same merged files.
#[test]
fn every_example_spec_reads_plans_and_the_small_ones_run() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/studies");
    let mut specs: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    specs.sort();
    let mut models = std::collections::BTreeSet::new();
    let mut ran = 0;
    for path in &specs {
        let study = Study::from_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        models.insert(study.spec().system.model.clone());
        let shards = study.points().min(4);
        let script = sbatch_script(&study, path, &PlanSettings::new(shards, "out", "nonsmooth"))
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(script.contains(&format!("#SBATCH --array=1-{shards}\n")));
        if study.points() > 30 {
            continue;
        }
        let name = study.spec().name.clone();
        let whole = scratch(&format!("example-{name}-1"));
        let two = scratch(&format!("example-{name}-2"));
        run_in_shards(&study, &whole, 1);
        run_in_shards(&study, &two, 2);
        let (_, recs) = read_shards(&whole).unwrap();
        for r in &recs {
            assert!(r.is_ok(), "{name} point {}: {}", r.index, r.status);
        }
        assert_eq!(merged_bytes(&whole), merged_bytes(&two), "{name}");
        ran += 1;
    }
    for model in [
        "paper",
        "duffing_ueda",
        "two_dof_impact",
        "bouncing_ball",
        "mechanical",
    ] {
        assert!(
            models.contains(model),
            "no example spec of {model}: {models:?}"
        );
    }
    assert!(ran >= 5, "{ran} small examples ran");
}

/// Issue 49: `study merge` checked the spec embedded in a manifest against its hash for the
/// first shard only, so a shard whose manifest had another spec under the same hash
/// (`periods.transient`, a mass) merged with exit status 0. Every shard's spec must hash to
/// its manifest's hash and be the first shard's; the error names the shard file and the field
/// that differs. The data files a manifest lists must be its shard's own, in its directory.
#[test]
fn a_shard_whose_manifest_was_edited_is_refused() {
    let study = Study::from_toml(TINY).unwrap();
    let d = scratch("edited-manifest");
    run_in_shards(&study, &d, 3);
    let good = merged_bytes(&d);
    let j = d.join("shard-00002-of-00003.json");
    let orig = fs::read_to_string(&j).unwrap();
    let edited = |edit: &dyn Fn(&mut serde_json::Value)| -> String {
        let mut v: serde_json::Value = serde_json::from_str(&orig).unwrap();
        edit(&mut v);
        fs::write(&j, serde_json::to_string_pretty(&v).unwrap()).unwrap();
        v.to_string()
    };
    let refused = |what: &str| -> String {
        let r = Merged::from_dir(&d);
        fs::write(&j, &orig).unwrap();
        match r {
            Err(StudyError::Corrupt(m)) => {
                assert!(m.contains("shard-00002-of-00003.json"), "{what}: {m}");
                m
            }
            Ok(_) => panic!("{what}: the edited shard was merged"),
            Err(e) => panic!("{what}: expected a corrupt shard, got {e:?}"),
        }
    };
    edited(&|v| v["spec"]["periods"]["transient"] = 11.into());
    let m = refused("periods.transient");
    assert!(m.contains("periods.transient"), "{m}");
    edited(&|v| v["spec"]["system"]["parameters"]["m"] = 1.5.into());
    let m = refused("a mass");
    assert!(m.contains("system.parameters.m"), "{m}");
    // A points or sections file elsewhere: a copy of the shard's own, the same bytes.
    let elsewhere = scratch("edited-manifest-elsewhere");
    for (key, file) in [
        ("points_file", "shard-00002-of-00003.csv"),
        ("sections_file", "shard-00002-of-00003.sections.csv"),
    ] {
        let copy = elsewhere.join(file);
        fs::copy(d.join(file), &copy).unwrap();
        edited(&|v| v[key] = copy.to_str().unwrap().into());
        let m = refused(key);
        assert!(m.contains(key), "{m}");
    }
    // The first shard edited: the others' spec is the reference.
    let j1 = d.join("shard-00001-of-00003.json");
    let orig1 = fs::read_to_string(&j1).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&orig1).unwrap();
    v["spec"]["grid"]["x"]["end"] = 23.0.into();
    fs::write(&j1, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let r = Merged::from_dir(&d);
    fs::write(&j1, &orig1).unwrap();
    match r {
        Err(StudyError::Corrupt(m)) => assert!(
            m.contains("shard-00001-of-00003.json") && m.contains("grid.x.end"),
            "{m}"
        ),
        Ok(_) => panic!("the edited first shard was merged"),
        Err(e) => panic!("expected a corrupt first shard, got {e:?}"),
    }
    assert_eq!(merged_bytes(&d), good);
    // The command line exits non-zero, naming the shard and the field.
    edited(&|v| v["spec"]["periods"]["transient"] = 11.into());
    let (ok, _, err) = run_cli(&[os("study"), os("merge"), d.as_os_str()], 120);
    fs::write(&j, &orig).unwrap();
    assert!(!ok, "{err}");
    assert!(
        err.contains("shard-00002-of-00003.json") && err.contains("periods.transient"),
        "{err}"
    );
}

/// Issue 49: in a described system, `between = [0, 1, 1]` passed `study check` with the
/// third index dropped (`between = [0]` was refused). A `between` of any length other than
/// 2 is an error naming the field and the length, on an element and on a surface.
#[test]
fn a_between_of_another_length_than_two_is_refused() {
    let element = "law = \"hertz\"\nbetween = [1, 0]";
    let surface = "[[system.surfaces]]\nbetween = [1, 0]";
    for (from, to, field, len) in [
        (
            element,
            "law = \"hertz\"\nbetween = [1, 0, 1]",
            "system.elements[2].between",
            3,
        ),
        (
            element,
            "law = \"hertz\"\nbetween = [1]",
            "system.elements[2].between",
            1,
        ),
        (
            element,
            "law = \"hertz\"\nbetween = []",
            "system.elements[2].between",
            0,
        ),
        (
            surface,
            "[[system.surfaces]]\nbetween = [1, 0, 0, 1]",
            "system.surfaces[0].between",
            4,
        ),
    ] {
        let text = DAMPER.replacen(from, to, 1);
        assert_ne!(text, DAMPER, "{to}");
        match Study::from_toml(&text) {
            Err(StudyError::InvalidSpec { field: f, message }) => {
                assert_eq!(f, field, "{message}");
                assert!(message.contains(&format!("length {len}")), "{message}");
            }
            Ok(_) => panic!("{to}: accepted, expected an error naming {field}"),
            Err(e) => panic!("{to}: expected an error naming {field}, got {e:?}"),
        }
    }
}

/// Issue 49: `study check` of a spec with 10⁷ points on one axis took 30 s (a map of the
/// parameters cloned and searched by name at every axis value). Checking is still a check
/// of every axis value: an invalid value far along a long axis is reported, naming the axis
/// and the value.
#[test]
fn an_invalid_value_far_along_a_long_axis_is_reported() {
    let text = r#"
name = "long"
[system]
model = "bouncing_ball"
[grid]
x = { parameter = "e", start = 0.5, end = 1.5, points = 1000001 }
[periods]
transient = 10
record = 10
"#;
    match Study::from_toml(text) {
        Err(StudyError::InvalidSpec { field, message }) => {
            assert_eq!(field, "grid.x", "{message}");
            // The first value above 1 (restitution in [0, 1]): 0.5 + 500001·10⁻⁶.
            assert!(message.contains("(e = 1.00000"), "{message}");
        }
        Ok(_) => panic!("accepted, expected an error naming grid.x"),
        Err(e) => panic!("expected an error naming grid.x, got {e:?}"),
    }
    let valid = text.replace("end = 1.5", "end = 1.0");
    assert_eq!(Study::from_toml(&valid).unwrap().points(), 1_000_001);
}
