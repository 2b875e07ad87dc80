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

fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The sbatch script that runs `study` (read from `spec_path`) as a job array of
/// `settings.shards` tasks; each task passes its shard explicitly (`--shard
/// $SLURM_ARRAY_TASK_ID/N`), so a single failed task can be re-run with
/// `sbatch --array=I script`.
///
/// # Errors
/// [`StudyError::Shard`] for zero shards or more shards than points;
/// [`StudyError::InvalidSpec`] for zero CPUs or a time with characters other than digits,
/// `:` and `-`.
pub fn sbatch_script(
    study: &Study,
    spec_path: &Path,
    settings: &PlanSettings,
) -> Result<String, StudyError> {
    let n = settings.shards;
    if n == 0 || n > study.points() {
        return Err(StudyError::Shard(format!(
            "--shards {n}: need 1 <= N <= {} (the number of points)",
            study.points()
        )));
    }
    if settings.cpus == 0 {
        return Err(StudyError::InvalidSpec {
            field: "--cpus".into(),
            message: "must be >= 1".into(),
        });
    }
    if settings.time.is_empty()
        || !settings
            .time
            .chars()
            .all(|c| c.is_ascii_digit() || c == ':' || c == '-')
    {
        return Err(StudyError::InvalidSpec {
            field: "--time".into(),
            message: format!("{:?} is not a Slurm time (e.g. 01:00:00)", settings.time),
        });
    }
    let name = &study.spec().name;
    let mut s = String::new();
    s.push_str("#!/bin/bash\n");
    s.push_str(&format!("#SBATCH --job-name=nonsmooth-{name}\n"));
    s.push_str(&format!("#SBATCH --array=1-{n}\n"));
    s.push_str(&format!("#SBATCH --cpus-per-task={}\n", settings.cpus));
    s.push_str(&format!("#SBATCH --time={}\n", settings.time));
    if let Some(p) = &settings.partition {
        s.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    s.push_str(&format!(
        "#SBATCH --output={}/slurm-%A_%a.out\n",
        settings.out
    ));
    s.push_str(&format!(
        "# Study {name:?}: {} points in {n} shards, spec hash {}.\n",
        study.points(),
        study.hash()
    ));
    s.push_str(&format!(
        "# Submit: sbatch THIS_FILE; re-run task I alone: sbatch --array=I THIS_FILE\n\
         # Then merge: {} study merge {}\n",
        quote(&settings.program),
        quote(&settings.out)
    ));
    s.push_str("set -euo pipefail\n");
    s.push_str(&format!(
        "exec {} study run {} --out {} --shard \"${{SLURM_ARRAY_TASK_ID}}/{n}\" \
         --threads \"${{SLURM_CPUS_PER_TASK:-1}}\" --quiet\n",
        quote(&settings.program),
        quote(&spec_path.display().to_string()),
        quote(&settings.out)
    ));
    Ok(s)
}
