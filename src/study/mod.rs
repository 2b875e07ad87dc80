//! Studies that outgrow one machine: regime maps over one or two parameters and basins of
//! attraction over an initial-condition plane, run whole or in shards (Slurm job arrays),
//! merged with a verified, deterministic merge (feature `cli`).
//!
//! A study is a TOML file ([`StudySpec`], validated with errors that name the field): a model
//! of the catalogue (`paper`, `duffing_ueda`, `two_dof_impact`, `bouncing_ball`; see
//! [`SystemSpec::model`]) and its parameters, or a mechanical system described in the file
//! ([below](#a-system-described-in-the-study-file)); a grid over one or two named
//! parameters (`omega`, `amplitude_factor`, any model parameter) or initial-condition
//! components (`x0`, `v0` for one degree of freedom; `x1_0`, …, `v2_0` for several),
//! integration settings, transient and recorded forcing periods, and what to record.
//! At each grid point ([`compute_point`]) the system runs `transient` periods from the
//! initial state and records `record` periods with the sweep machinery
//! ([`run_point`](crate::sweep::run_point)): the stroboscopic points, the regime (period
//! detection), impacts per forcing period, optionally the top Lyapunov exponent (two
//! trajectories from the end of the window) and the entropy index `q*` of the inter-impact
//! intervals; and the attractor's fingerprint. Records hold whole states (`(x, v)` for one
//! degree of freedom, `(x1 … xN, v1 … vN)` for `N`) and, for a system with two or more
//! impact surfaces, the impacts per period on each. A shard runs the points of a system with
//! a lane form — the paper's model, Duffing–Ueda, the 2-DOF impact oscillator — in SIMD
//! lanes ([`sweep_starts`](crate::sweep::sweep_starts) or an [`Ensemble`](crate::ensemble::Ensemble)
//! with the scalar run's events and observers, exact math), 64 points per task, which
//! reproduces [`compute_point`]'s scalar run to the bit (tested field by field, failures
//! included); the Lyapunov exponent stays a scalar run. Every other system runs point by
//! point on the scalar path: one [`Simulation`](crate::drive::Simulation) with its impact
//! surfaces as events, or, for a rigid stop with Newton restitution (the ball on the
//! table), [`run_with_sticking`](crate::drive::run_with_sticking) through chattering and
//! sticking; its exponent by two trajectories
//! ([`TwoTrajectory`](crate::lyapunov::TwoTrajectory), or
//! [`HybridTwoTrajectory`](crate::lyapunov::HybridTwoTrajectory) across the resets of a
//! rigid stop).
//!
//! # Sharding and determinism
//! Point `i = ix + nx·iy` belongs to shard `I` of `N` when `i ≡ I − 1 (mod N)`
//! ([`shard_indices`]; round-robin, so the expensive chaotic regions are spread over every
//! task). A point's record depends only on the spec and `i` — every point starts from its
//! own initial state, with its own stepper, no shared random state and no accumulation
//! across points — so it is the same bits on any shard, in any thread. The merge
//! ([`read_shards`]) refuses anything short of every shard `1..=N` of one spec (each shard's
//! embedded spec verified against its hash) with every point exactly once, and labels attractors in index order; the merged table is
//! therefore bit-identical whether the study ran whole, in 3 shards or in 7, with any number
//! of threads (`tests/study.rs` checks it).
//!
//! # Attractor identification
//! Points are compared only with points of the same system parameters (a *group*: the
//! whole plane of a basin picture; a single point of a parameter map, whose label is then
//! 0). Within a group, in index order, a point gets the label of the first representative
//! it matches, or opens a new label. With section points `P = {p_k}` (whole states) scaled
//! component-wise by `s = (s_x, s_v)` (one scale per state component: `attractors.scales`,
//! default the model's Lyapunov scales):
//!
//! * **periodic orbits** (period `p ≥ 1` detected) match when they have the same period
//!   and impacts per period and their orbits' section points `P, Q` (the last `p` points)
//!   are within `tol` in the symmetric Hausdorff distance
//!   $$d_H(P, Q) = \max\Bigl(\max_{p\in P}\min_{q\in Q}\|p-q\|_s,\;
//!   \max_{q\in Q}\min_{p\in P}\|p-q\|_s\Bigr),\qquad
//!   \|p - q\|_s = \max_c |p_c - q_c|/s_c .$$
//!   Section points of a stable periodic orbit are exact to the integration tolerance, so a
//!   point-wise test is sharp, independent of the cyclic order, and does not depend on
//!   where a cell boundary happens to fall (rounding to a grid would split an orbit that
//!   sits on a cell edge).
//! * **non-periodic attractors** (chaotic or quasi-periodic) are compared by recurrence,
//!   the criterion of Attractors.jl's recurrence method (Datseris & Wagemakers 2022): the
//!   section is tessellated into cells of side `cell·s_c`, and the attractor's fingerprint
//!   is the set `C` of cells its recorded section points visit (at most the 256 most
//!   visited, which bounds the shard files). An attractor is a recurrent set: after the
//!   transient, a long enough sample of it visits the same cells from any initial condition
//!   in its basin, while disjoint attractors (further apart than a cell) visit disjoint
//!   cells. Two points match when the Jaccard overlap
//!   $$J(C_1, C_2) = \frac{|C_1\cap C_2|}{|C_1\cup C_2|} \ge \text{overlap}$$
//!   (default 0.3: two samples of one chaotic attractor share most of their frequently
//!   visited cells, and the threshold leaves room for the rarely visited ones). The choice
//!   is recurrence rather than a Lyapunov-sign test because coexisting chaotic attractors
//!   have the same sign; the exponent is reported per label, not used to match.
//!
//! Points of different periods are compared by their cells too: a long-period orbit, or one
//! that has not settled to the period-detection tolerance within the window, is recorded
//! with another period (or none) from different starts, yet visits the same cells (at
//! ω = 22.71 the paper's model gives period 8, 16 or none for one attractor). Fingerprints
//! are recorded only on grids with an initial-condition axis: on a pure parameter map no two
//! points share their parameters, and every label is 0. The per-label summary
//! ([`AttractorSummary`]) gives each attractor's basin fraction, period, impacts per period,
//! mean exponent and centroid.
//!
//! # A system described in the study file
//! `model = "mechanical"` describes a [`Mechanical`](crate::model::Mechanical) system of one
//! to [`MAX_DESCRIBED_DOFS`] degrees of freedom (numbered from 0) in the `system` table:
//!
//! ```toml
//! [system]
//! model = "mechanical"
//! masses = [1.0, 0.05]                     # one per degree of freedom
//! parameters = { gap = 0.1 }               # omega: the forcing frequency, here an axis
//!
//! [[system.elements]]                      # a force law on a coordinate
//! law = "linear_spring"
//! dof = 0                                  # q0; or between = [1, 0]: q1 − q0
//! k = 1.0
//!
//! [[system.elements]]                      # a Hertz stop: just an element
//! law = "hertz"
//! between = [1, 0]
//! position = "gap"                         # a number or a parameter ("-gap": its negative)
//! k = 1e4
//! b = 2.0
//!
//! [[system.loads]]                         # amplitude·cos(ω t + phase) on a degree of freedom
//! dof = 0
//! amplitude = 0.05
//!
//! [[system.surfaces]]                      # impacts are counted on each surface
//! between = [1, 0]
//! position = "gap"                         # side = "upper" (default) or "lower"
//! ```
//!
//! The laws ([`ElementSpec`]; defaults after `=`): `linear_spring` (`k`, `x0 = 0`),
//! `viscous_damper` (`c`), `cubic_spring` (`k1`, `k3`), `hertz` (`position`, `k`,
//! `n1 = 1.5`, `b = 0`, `n2 = 1.5`, `n3 = 1`; `side = "upper"`: contact where the
//! coordinate exceeds `position`, `"lower"` where it falls below) and `dry_friction` (`t`,
//! `eps`: the regularized sign `v/√(v²+ε²)`). Every number may instead name a parameter
//! ([`SpecValue`]): `omega` (required: the forcing frequency and the section period) and
//! `amplitude_factor` (a factor on every load's amplitude, default 1) always exist; any
//! other name becomes a parameter without a default, to be given in `system.parameters` or
//! as a grid axis.
//! A surface ([`SurfaceSpec`]) without `restitution` counts the impacts of a compliant
//! contact; with `restitution = e` it is a rigid stop with Newton's impact law, run through
//! chattering and sticking — the drive runs one rigid contact, so it must be the only
//! surface. The state is `(x1, …, xN, v1, …, vN)` (`(x, v)` for one mass), the rest state
//! the origin, the scales and absolute tolerances per `rtol` 1. A bad description is
//! rejected naming the field, e.g. `system.elements[2].law`. Example:
//! `examples/studies/impact_damper_2dof.toml`, a primary mass with a free mass rattling in
//! a cavity (two walls, impacts counted on each).
//!
//! # The shard files
//! Shard `I` of `N` writes three files into the output directory:
//! `shard-IIIII-of-NNNNN.csv` (one row per point; columns `impacts_per_period_K` per
//! surface for a system with two or more, cells as `a:b:…`, one integer per state
//! component), `shard-IIIII-of-NNNNN.sections.csv` (the kept stroboscopic points, one row
//! each: `index, k` and the state components by name, `x, v` for one degree of freedom) and
//! `shard-IIIII-of-NNNNN.json`, the
//! manifest: format version, crate version, the spec itself (so a directory of shards is
//! self-describing), its hash, `I`, `N`, the number of points and the FNV-1a hash of each
//! CSV file. CSV and JSON rather than Parquet: `csv` is already a dependency of the crate,
//! the files open in any tool (pandas, a text editor), a shard holds at most a few MB, and
//! the Arrow/Parquet stack would add a large build to a feature that must build on a login
//! node in minutes. Floats are written in the shortest form that reads back to the same
//! bits.
//!
//! Each file is written to a temporary name in the same directory and renamed into place
//! (atomic on POSIX file systems), the manifest last: a killed task leaves either no shard
//! or a complete one, and a re-run of a failed or stale shard replaces it. A manifest whose
//! CSV files do not hash to the recorded values (a task killed between the renames, a
//! truncated copy) is reported at merge as corrupt; so is one whose embedded spec does not
//! hash to its spec hash or differs from another shard's (the error names the field), and
//! one that lists other data files than its shard's own.
//!
//! [`Merged::write`] writes the merged table (one row per point in index order), the kept
//! section points, the attractor summary and the PNG figure ([`Merged::figure`]).

mod attractor;
mod catalogue;
mod compute;
mod lanes;
mod mechanical;
mod merge;
mod plan;
mod record;
mod scalar;
mod shard;
mod spec;
mod system;

pub use attractor::{AttractorSummary, identify, regime_class};
pub use compute::{MAX_CELLS, compute_point, run_shard};
pub use mechanical::{
    DescribedElements, DescribedLoads, DescribedModel, DescribedSystem, ElementSpec, LoadSpec,
    MAX_DESCRIBED_DOFS, SpecValue, SurfaceSpec,
};
pub use merge::Merged;
pub use plan::{PlanSettings, sbatch_script};
pub use record::PointRecord;
pub use scalar::{MAX_SURFACES, SurfaceEvents};
pub use shard::{
    SHARD_FORMAT, Shard, ShardManifest, check_output_dir, read_shards, shard_indices, write_shard,
};
pub use spec::{
    AttractorSpec, Axis, GridSpec, InitialSpec, IntegrationSpec, LyapunovSpec, MAX_PERIODS,
    MAX_POINTS, PeriodsSpec, QSpec, RecordSpec, Study, StudySpec, SystemSpec,
};

use thiserror::Error;

/// Study errors: each names what to fix.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum StudyError {
    /// The TOML text could not be read into a spec (syntax, unknown or missing key, wrong
    /// type); the message names the key.
    #[error("study spec: {0}")]
    Toml(String),
    /// A field of the spec is invalid.
    #[error("study spec: `{field}` {message}")]
    InvalidSpec {
        /// The field, e.g. `grid.x.points`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A setting of the sbatch script (`study plan`) is invalid: a value that is not a plain
    /// Slurm token, or a path that cannot be written into the script safely.
    #[error("study plan: `{field}` {message}")]
    InvalidPlan {
        /// The setting, e.g. `--partition`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A shard out of range or unreadable.
    #[error("shard: {0}")]
    Shard(String),
    /// Shards are missing.
    #[error("incomplete study: {0}")]
    MissingShards(String),
    /// Shards of different studies, versions or shard counts.
    #[error("inconsistent shards: {0}")]
    Mismatch(String),
    /// A shard file is damaged.
    #[error("corrupt shard: {0}")]
    Corrupt(String),
    /// Reading or writing a file failed.
    #[error("i/o: {0}")]
    Io(String),
}

/// Runs `shard` of `study` and writes its shard files into `dir` (checking first that `dir`
/// holds no shards of another study); `progress` is called after each point. Returns the
/// manifest's path.
///
/// # Errors
/// [`StudyError::Shard`] if the shard has more tasks than the study has points;
/// as [`check_output_dir`] and [`write_shard`].
pub fn run_to_dir<F: Fn() + Sync>(
    study: &Study,
    shard: Shard,
    dir: &std::path::Path,
    progress: F,
) -> Result<std::path::PathBuf, StudyError> {
    if shard.count() > study.points() {
        return Err(StudyError::Shard(format!(
            "{} shards for {} points: use at most one shard per point",
            shard.count(),
            study.points()
        )));
    }
    check_output_dir(dir, study)?;
    let records = run_shard(study, shard, progress);
    write_shard(dir, study, shard, &records)
}
