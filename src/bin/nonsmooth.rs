//! The `nonsmooth` command-line tool (feature `cli`): studies on a laptop or a Slurm cluster.
//!
//! ```sh
//! nonsmooth study run SPEC --out DIR [--shard I/N] [--threads T] [--quiet]
//! nonsmooth study merge DIR [--out FILE]
//! nonsmooth study plan SPEC --shards N [--out DIR] [--cpus C] [--time HH:MM:SS] [--partition P]
//! nonsmooth study check SPEC
//! ```
//!
//! `run` without `--shard` runs the whole study (shard 1/1) unless it runs inside a Slurm
//! array task, where it takes its shard from `SLURM_ARRAY_TASK_*`.
//!
//! Exit status: 0 on success; 1 for an error, and also when every point of the shard
//! (`run`) or of the study (`merge`) failed — the files are written all the same, and
//! their `status` column says why. Some failed points among others are a warning only.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use nonsmooth::study::{
    Merged, PlanSettings, Shard, ShardManifest, Study, run_to_dir, sbatch_script,
};

const USAGE: &str = "\
usage:
  nonsmooth study run SPEC --out DIR [--shard I/N] [--threads T] [--quiet]
      Runs the study (or shard I of N; inside a Slurm array task the shard comes from
      SLURM_ARRAY_TASK_ID/_MIN/_MAX/_COUNT) and writes its shard files into DIR.
  nonsmooth study merge DIR [--out FILE]
      Checks that every shard of one study is in DIR and writes the merged table FILE
      (default DIR/merged.csv) with FILE's stem + .sections.csv, .attractors.csv, .png.
  run and merge exit non-zero when every point failed (the files are still written: their
  status column says why); some failed points are a warning.
  nonsmooth study plan SPEC --shards N [--out DIR] [--cpus C] [--time HH:MM:SS] [--partition P]
      Prints an sbatch script running the study as a job array of N tasks.
  nonsmooth study check SPEC
      Validates SPEC and prints its size and hash.";

type Res<T> = Result<T, String>;

/// The arguments of a command: positionals, `--name value` pairs and flags, in any order.
struct Opts {
    positional: Vec<String>,
    pairs: Vec<(String, String)>,
    flags: Vec<String>,
}

impl Opts {
    fn parse(args: &[String], with_value: &[&str], flags: &[&str]) -> Res<Self> {
        let mut positional = Vec::new();
        let mut pairs = Vec::new();
        let mut fl = Vec::new();
        let mut i = 0;
        while i < args.len() {
            let a = &args[i];
            if with_value.contains(&a.as_str()) {
                let v = args
                    .get(i + 1)
                    .ok_or_else(|| format!("{a} needs a value"))?;
                if pairs.iter().any(|(k, _)| k == a) {
                    return Err(format!("{a} given twice"));
                }
                pairs.push((a.clone(), v.clone()));
                i += 2;
            } else if flags.contains(&a.as_str()) {
                fl.push(a.clone());
                i += 1;
            } else if a.starts_with("--") {
                return Err(format!("unknown option {a:?}"));
            } else {
                positional.push(a.clone());
                i += 1;
            }
        }
        Ok(Self {
            positional,
            pairs,
            flags: fl,
        })
    }

    /// The single positional argument `what`.
    fn one(&self, cmd: &str, what: &str) -> Res<&str> {
        match self.positional.as_slice() {
            [one] => Ok(one),
            [] => Err(format!("study {cmd}: {what} is missing")),
            more => Err(format!(
                "study {cmd}: expected one {what}, got {}: {more:?}",
                more.len()
            )),
        }
    }

    fn get(&self, name: &str) -> Option<&str> {
        self.pairs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    fn flag(&self, name: &str) -> bool {
        self.flags.iter().any(|f| f == name)
    }

    fn usize(&self, name: &str) -> Res<Option<usize>> {
        self.get(name)
            .map(|v| {
                v.parse::<usize>()
                    .map_err(|_| format!("{name} {v:?}: expected a non-negative integer"))
            })
            .transpose()
    }
}

fn load(spec: &str) -> Res<Study> {
    Study::from_file(Path::new(spec)).map_err(|e| format!("{spec}: {e}"))
}

fn run(args: &[String]) -> Res<()> {
    let o = Opts::parse(args, &["--out", "--shard", "--threads"], &["--quiet"])?;
    let spec = o.one("run", "SPEC")?;
    let out = PathBuf::from(o.get("--out").ok_or("study run: --out DIR is required")?);
    let study = load(spec)?;
    let shard = match o.get("--shard") {
        Some(s) => Shard::parse(s).map_err(|e| e.to_string())?,
        None => Shard::from_slurm(|k| std::env::var(k).ok())
            .map_err(|e| e.to_string())?
            .unwrap_or(Shard::WHOLE),
    };
    let threads = o.usize("--threads")?;
    if threads == Some(0) {
        return Err("--threads must be >= 1".into());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| format!("thread pool: {e}"))?;
    let n_points = nonsmooth::study::shard_indices(study.points(), shard).count();
    let quiet = o.flag("--quiet");
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        let b = indicatif::ProgressBar::new(n_points as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} points, eta {eta}",
        ) {
            b.set_style(style.progress_chars("=> "));
        }
        b
    };
    eprintln!(
        "study {:?} (hash {}): shard {shard}, {n_points} of {} points, {} threads",
        study.spec().name,
        study.hash(),
        study.points(),
        pool.current_num_threads()
    );
    let t0 = Instant::now();
    let manifest = pool
        .install(|| run_to_dir(&study, shard, &out, || bar.inc(1)))
        .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    eprintln!(
        "wrote {} ({:.1} s)",
        manifest.display(),
        t0.elapsed().as_secs_f64()
    );
    let m = ShardManifest::read(&manifest).map_err(|e| e.to_string())?;
    if m.points > 0 && m.failed_points == m.points {
        return Err(format!(
            "every point of shard {shard} failed ({} of {}); the status column of {} says why",
            m.failed_points,
            m.points,
            out.join(&m.points_file).display()
        ));
    }
    if m.failed_points > 0 {
        eprintln!(
            "warning: {} of {} points failed (their status column says which)",
            m.failed_points, m.points
        );
    }
    Ok(())
}

fn merge(args: &[String]) -> Res<()> {
    let o = Opts::parse(args, &["--out"], &[])?;
    let dir = o.one("merge", "DIR")?;
    let dir = PathBuf::from(dir);
    let out = o
        .get("--out")
        .map_or_else(|| dir.join("merged.csv"), PathBuf::from);
    let m = Merged::from_dir(&dir).map_err(|e| e.to_string())?;
    let files = m.write(&out).map_err(|e| e.to_string())?;
    let failed = m.failed();
    let groups = {
        let mut g: Vec<_> = m.attractors.iter().map(|a| a.group).collect();
        g.dedup();
        g.len()
    };
    eprintln!(
        "merged {} points of study {:?} (hash {}); {} attractors in {groups} group(s) of \
         equal parameters; {failed} points with a failure",
        m.records.len(),
        m.study.spec().name,
        m.study.hash(),
        m.attractors.len()
    );
    for f in files {
        println!("{}", f.display());
    }
    if failed > 0 && failed == m.records.len() {
        let first = &m.records[0];
        return Err(format!(
            "every point of the study failed ({failed} of {failed}; point 0: {}); the merged \
             files are written, their status column says why",
            first.status
        ));
    }
    if failed > 0 {
        eprintln!("warning: {failed} points have a failure (their status column says which)");
    }
    Ok(())
}

fn plan(args: &[String]) -> Res<()> {
    let o = Opts::parse(
        args,
        &["--shards", "--out", "--cpus", "--time", "--partition"],
        &[],
    )?;
    let spec = o.one("plan", "SPEC")?;
    let study = load(spec)?;
    let shards = o
        .usize("--shards")?
        .ok_or("study plan: --shards N is required")?;
    let abs = |p: &str| -> String {
        std::path::absolute(p).map_or_else(|_| p.to_string(), |a| a.display().to_string())
    };
    let out = abs(o
        .get("--out")
        .unwrap_or(&format!("study-{}", study.spec().name)));
    let program = std::env::current_exe()
        .map_or_else(|_| "nonsmooth".to_string(), |p| p.display().to_string());
    let settings = PlanSettings::new(shards, out.clone(), program)
        .cpus(o.usize("--cpus")?.unwrap_or(1))
        .time(o.get("--time").unwrap_or("01:00:00"))
        .partition(o.get("--partition").map(str::to_string));
    let script =
        sbatch_script(&study, Path::new(&abs(spec)), &settings).map_err(|e| e.to_string())?;
    // Slurm opens the task logs in the output directory before the task starts.
    std::fs::create_dir_all(&out).map_err(|e| format!("{out}: {e}"))?;
    print!("{script}");
    Ok(())
}

fn check(args: &[String]) -> Res<()> {
    let o = Opts::parse(args, &[], &[])?;
    let spec = o.one("check", "SPEC")?;
    let study = load(spec)?;
    println!(
        "{}: study {:?}, {} points, spec hash {}",
        spec,
        study.spec().name,
        study.points(),
        study.hash()
    );
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "-h" || a == "--help") || args.is_empty() {
        println!("{USAGE}");
        return ExitCode::SUCCESS;
    }
    let result = match args.as_slice() {
        [study, cmd, rest @ ..] if study == "study" => match cmd.as_str() {
            "run" => run(rest),
            "merge" => merge(rest),
            "plan" => plan(rest),
            "check" => check(rest),
            other => Err(format!("unknown command `study {other}`\n{USAGE}")),
        },
        _ => Err(format!("unknown command\n{USAGE}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
