//! `study plan`: the sbatch script of a Slurm job array.

use std::path::Path;

use super::StudyError;
use super::spec::Study;

/// Settings of the sbatch script.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PlanSettings {
    /// Number of shards (array tasks).
    pub shards: usize,
    /// The output directory of the shards.
    pub out: String,
    /// The `nonsmooth` executable.
    pub program: String,
    /// CPUs per task (`--cpus-per-task`; the task runs that many threads).
    pub cpus: usize,
    /// Wall time per task (`--time`), e.g. `01:00:00`.
    pub time: String,
    /// Partition (`--partition`), if any.
    pub partition: Option<String>,
}

impl PlanSettings {
    /// Defaults: 1 CPU per task, 1 h, no partition.
    pub fn new(shards: usize, out: impl Into<String>, program: impl Into<String>) -> Self {
        Self {
            shards,
            out: out.into(),
            program: program.into(),
            cpus: 1,
            time: "01:00:00".into(),
            partition: None,
        }
    }

    /// Sets CPUs per task.
    pub fn cpus(mut self, cpus: usize) -> Self {
        self.cpus = cpus;
        self
    }

    /// Sets the wall time per task.
    pub fn time(mut self, time: impl Into<String>) -> Self {
        self.time = time.into();
        self
    }

    /// Sets the partition.
    pub fn partition(mut self, partition: Option<String>) -> Self {
        self.partition = partition;
        self
    }
}

/// A shell word: `s` in single quotes (a quote inside as `'\''`); nothing in it is
/// expanded. Values reach it only through [`shell_value`], which refuses control characters.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

fn bad(field: &str, message: String) -> StudyError {
    StudyError::InvalidPlan {
        field: field.into(),
        message,
    }
}

/// A value of an `#SBATCH` line: a plain token of `allowed` characters. sbatch reads these
/// lines itself (the shell sees comments), so nothing may be quoted there and nothing may
/// end the line.
fn token<'a>(
    field: &str,
    value: &'a str,
    allowed: fn(char) -> bool,
    what: &str,
) -> Result<&'a str, StudyError> {
    if value.is_empty() || !value.chars().all(allowed) {
        return Err(bad(
            field,
            format!("{value:?} is not a plain Slurm value: use only {what}"),
        ));
    }
    Ok(value)
}

/// A value written into the script's shell lines (single-quoted) and comments: anything but
/// control characters (a newline would end the comment line it is also written into) and a
/// leading `-`.
fn shell_value<'a>(field: &str, value: &'a str) -> Result<&'a str, StudyError> {
    if value.is_empty() {
        return Err(bad(field, "must not be empty".into()));
    }
    if let Some(c) = value.chars().find(|c| c.is_control()) {
        return Err(bad(
            field,
            format!("{value:?} contains the control character {c:?}"),
        ));
    }
    if value.starts_with('-') {
        return Err(bad(
            field,
            format!("{value:?} starts with '-' (it would be read as an option)"),
        ));
    }
    Ok(value)
}

fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.')
}

fn is_partition_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | ',')
}

fn is_time_char(c: char) -> bool {
    c.is_ascii_digit() || matches!(c, ':' | '-')
}

/// A directory path that is also a plain `#SBATCH --output` value (no spaces, quotes, `%`
/// patterns or shell characters).
fn is_path_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | ',' | '/' | '+' | '=' | '@')
}

/// The sbatch script that runs `study` (read from `spec_path`) as a job array of
/// `settings.shards` tasks; each task passes its shard explicitly (`--shard
/// $SLURM_ARRAY_TASK_ID/N`), so a single failed task can be re-run with
/// `sbatch --array=I script`.
///
/// Every value written into the script is checked first: the `#SBATCH` values (job name,
/// time, partition, output directory) must be plain tokens — the partition of
/// `[A-Za-z0-9_.,-]`, the time of digits, `:` and `-`, the output directory of
/// `[A-Za-z0-9_.,/+=@-]` — and the program and spec paths, written single-quoted into the
/// shell command, must hold no control characters (no newline can start a line of its
/// own) and not start with `-`.
///
/// # Errors
/// [`StudyError::Shard`] for zero shards or more shards than points;
/// [`StudyError::InvalidPlan`] naming the setting for zero CPUs or a value that fails its
/// check above (or a spec path that is not UTF-8).
pub fn sbatch_script(
    study: &Study,
    spec_path: &Path,
    settings: &PlanSettings,
) -> Result<String, StudyError> {
    let ScriptValues {
        name,
        time,
        partition,
        out,
        program,
        spec,
    } = ScriptValues::checked(study, spec_path, settings)?;
    let n = settings.shards;
    let mut s = String::new();
    s.push_str("#!/bin/bash\n");
    s.push_str(&format!("#SBATCH --job-name=nonsmooth-{name}\n"));
    s.push_str(&format!("#SBATCH --array=1-{n}\n"));
    s.push_str(&format!("#SBATCH --cpus-per-task={}\n", settings.cpus));
    s.push_str(&format!("#SBATCH --time={time}\n"));
    if let Some(p) = partition {
        s.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    s.push_str(&format!("#SBATCH --output={out}/slurm-%A_%a.out\n"));
    s.push_str(&format!(
        "# Study {name:?}: {} points in {n} shards, spec hash {}.\n",
        study.points(),
        study.hash()
    ));
    s.push_str(&format!(
        "# Submit: sbatch THIS_FILE; re-run task I alone: sbatch --array=I THIS_FILE\n\
         # Then merge: {} study merge {}\n",
        quote(program),
        quote(out)
    ));
    s.push_str("set -euo pipefail\n");
    s.push_str(&format!(
        "exec {} study run {} --out {} --shard \"${{SLURM_ARRAY_TASK_ID}}/{n}\" \
         --threads \"${{SLURM_CPUS_PER_TASK:-1}}\" --quiet\n",
        quote(program),
        quote(spec),
        quote(out)
    ));
    Ok(s)
}

/// Every value [`sbatch_script`] writes into the script, each checked against the
/// characters its place allows.
struct ScriptValues<'a> {
    name: &'a str,
    time: &'a str,
    partition: Option<&'a str>,
    out: &'a str,
    program: &'a str,
    spec: &'a str,
}

impl<'a> ScriptValues<'a> {
    fn checked(
        study: &'a Study,
        spec_path: &'a Path,
        settings: &'a PlanSettings,
    ) -> Result<Self, StudyError> {
        let n = settings.shards;
        if n == 0 || n > study.points() {
            return Err(StudyError::Shard(format!(
                "--shards {n}: need 1 <= N <= {} (the number of points)",
                study.points()
            )));
        }
        if settings.cpus == 0 {
            return Err(bad("--cpus", "must be >= 1".into()));
        }
        let name = token(
            "name",
            &study.spec().name,
            is_name_char,
            "letters, digits, '_', '-', '.'",
        )?;
        let time = token(
            "--time",
            &settings.time,
            is_time_char,
            "digits, ':' and '-' (a Slurm time, e.g. 01:00:00)",
        )?;
        let partition = settings
            .partition
            .as_deref()
            .map(|p| {
                token(
                    "--partition",
                    p,
                    is_partition_char,
                    "letters, digits, '_', '.', ',', '-' (partition names)",
                )
            })
            .transpose()?;
        let out = token(
            "--out",
            &settings.out,
            is_path_char,
            "letters, digits and '_', '-', '.', ',', '/', '+', '=', '@' (it is written into \
             #SBATCH --output)",
        )?;
        let program = shell_value("program", &settings.program)?;
        let spec = spec_path.to_str().ok_or_else(|| {
            bad(
                "spec path",
                format!("{} is not valid UTF-8", spec_path.display()),
            )
        })?;
        let spec = shell_value("spec path", spec)?;
        Ok(Self {
            name,
            time,
            partition,
            out,
            program,
            spec,
        })
    }
}
