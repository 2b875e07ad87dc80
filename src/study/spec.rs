//! The study specification: a TOML file read with serde, validated into a [`Study`].
//!
//! The format is described on [`StudySpec`].

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use std::sync::Arc;

use super::StudyError;
use super::catalogue;
use super::mechanical::{
    DescribedSystem, Description, ElementSpec, LoadSpec, SpecValue, SurfaceSpec,
};
use super::system::{ParameterPoint, StudySystem, is_initial_name};

/// The most grid points of one study (10⁸: a 10⁴ × 10⁴ plane).
pub const MAX_POINTS: usize = 100_000_000;

/// The most forcing periods (`transient + record`) of one point: a point's run visits a
/// section at every forcing period, and one run visits at most
/// [`MAX_SECTIONS_PER_RUN`](crate::sample::MAX_SECTIONS_PER_RUN) sections (one less here,
/// for the rounding of the last section time).
pub const MAX_PERIODS: u64 = crate::sample::MAX_SECTIONS_PER_RUN - 1;

/// A study as written in its TOML file (after defaults are filled in).
///
/// Read it with [`StudySpec::from_toml`], which also validates it; [`Study::new`] turns a
/// spec into the runnable study.
///
/// ```toml
/// name = "smoke"
///
/// [system]
/// model = "paper"                 # or "duffing_ueda"
/// parameters = { omega = 20.0 }   # any parameter of the model, `amplitude_factor`
///
/// [grid]                          # one axis (x) or two (x, y); x varies fastest
/// x = { parameter = "omega", start = 17.5, end = 25.0, points = 16 }
/// y = { parameter = "amplitude_factor", start = 0.5, end = 1.5, points = 5 }
///
/// [periods]
/// transient = 100                 # forcing periods discarded
/// record = 50                     # forcing periods recorded
/// ```
///
/// Optional tables: `[initial] state = [x, v]` (the whole state: `[x1, …, xN, v1, …, vN]`
/// for `N` degrees of freedom; default the model's rest state), `[integration] rtol, atol =
/// [a_x, a_v] (one per state component), max_steps`, `[record] poincare, period_tol,
/// max_period, lyapunov = { periods, d0 }, q = { lo, hi, step }`, `[attractors] scales,
/// tol, cell, overlap` (see [`AttractorSpec`]). Unknown keys are errors, so a misspelt
/// field is never silently ignored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// A name for the study (used in file names and job names).
    pub name: String,
    /// The system and its fixed parameters.
    pub system: SystemSpec,
    /// The grid over one or two parameters or initial-condition components.
    pub grid: GridSpec,
    /// The initial state (of every point not on an initial-condition axis).
    #[serde(default)]
    pub initial: InitialSpec,
    /// Integration settings.
    #[serde(default)]
    pub integration: IntegrationSpec,
    /// Transient and recorded forcing periods.
    pub periods: PeriodsSpec,
    /// What is recorded per point.
    #[serde(default)]
    pub record: RecordSpec,
    /// How attractors are identified.
    #[serde(default)]
    pub attractors: AttractorSpec,
}

/// The system: a model of the catalogue and its parameters, or a mechanical system
/// described here.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SystemSpec {
    /// A model of the catalogue:
    /// - `"paper"`: the paper's cart; parameters as in
    ///   [`PaperParameters`](crate::systems::paper::PaperParameters) plus `omega` (no
    ///   default) and `amplitude_factor`, a factor on the unbalance `m0e`;
    /// - `"duffing_ueda"`: [`DuffingUeda`](crate::systems::DuffingUeda), `k`, `b`, `omega`,
    ///   `amplitude_factor` on `b`;
    /// - `"two_dof_impact"`: [`TwoDofImpact`](crate::systems::TwoDofImpact), `m1`, `m2`,
    ///   `k1`, `k2`, `c1`, `c2`, `force`, `gap`, `k_contact`, `b_contact`, `omega` (default
    ///   0.7), `amplitude_factor` on `force`; state `(x1, x2, v1, v2)`, one surface;
    /// - `"bouncing_ball"`: [`BouncingBallTable`](crate::systems::BouncingBallTable),
    ///   `gamma = Aω²/g` (default 1.5), `e` (0.9), `omega` (2π), `g` (9.81),
    ///   `amplitude_factor` on the table's amplitude; rigid impacts with chattering and
    ///   sticking, starting 2 m/s above the table's velocity;
    ///
    /// or `"mechanical"`, the system of `masses`, `elements`, `loads` and `surfaces` (see
    /// the [module docs](super#a-system-described-in-the-study-file)).
    pub model: String,
    /// Parameters that differ from the model's defaults.
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
    /// `mechanical`: the masses, one per degree of freedom.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub masses: Vec<SpecValue>,
    /// `mechanical`: the elements (force laws on coordinates).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub elements: Vec<ElementSpec>,
    /// `mechanical`: the harmonic loads.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub loads: Vec<LoadSpec>,
    /// `mechanical`: the impact surfaces.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub surfaces: Vec<SurfaceSpec>,
}

impl SystemSpec {
    /// The description of a mechanical system (empty for a model of the catalogue).
    pub(crate) fn description(&self) -> Description<'_> {
        Description {
            masses: &self.masses,
            elements: &self.elements,
            loads: &self.loads,
            surfaces: &self.surfaces,
        }
    }
}

impl DescribedSystem {
    /// Checks the description in `system` (`model = "mechanical"`) and its parameters
    /// (`system.parameters` must give every parameter without a default, `omega` among
    /// them) and builds it once.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] naming the field: another model than `"mechanical"`, an
    /// invalid description, an unknown or missing parameter, a value a law rejects.
    pub fn new(system: &SystemSpec) -> Result<Self, StudyError> {
        if system.model != "mechanical" {
            return Err(invalid(
                "system.model",
                format!(
                    "{:?}: a described system has model = \"mechanical\"",
                    system.model
                ),
            ));
        }
        Self::from_description(&system.description(), &system.parameters)
    }
}

/// The grid: axis `x`, optionally axis `y`; point `i = ix + nx·iy`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// The first axis (varies fastest).
    pub x: Axis,
    /// The second axis.
    #[serde(default)]
    pub y: Option<Axis>,
}

/// One grid axis: `points` values `start + (end − start)·s` with `s = k/(points − 1)`,
/// computed from `k` (never accumulated); where `end − start` overflows (an axis across
/// most of the `f64` range), as `start·(1 − s) + end·s`, which stays finite.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    /// A model parameter (e.g. `omega`, `amplitude_factor`, `x_i`) or an initial-condition
    /// component: `x0` (position), `v0` (velocity).
    pub parameter: String,
    /// First value.
    pub start: f64,
    /// Last value (equal to `start` if `points == 1`).
    pub end: f64,
    /// Number of values (≥ 1).
    pub points: usize,
}

impl Axis {
    /// The `k`-th value (finite for finite `start` and `end`).
    pub fn value(&self, k: usize) -> f64 {
        if self.points <= 1 {
            return self.start;
        }
        let s = k as f64 / (self.points - 1) as f64;
        let span = self.end - self.start;
        if span.is_finite() {
            // The form of every existing study: its values stay the same bits.
            self.start + span * s
        } else {
            // `start < 0 < end` here: two terms of opposite sign, each at most the larger
            // of |start|, |end|, cannot overflow.
            self.start * (1.0 - s) + self.end * s
        }
    }

    /// Whether the axis is an initial-condition component: `x0`, `v0` (one degree of
    /// freedom) or `xK_0`, `vK_0` (degree of freedom `K ≥ 1` of several).
    pub fn is_initial_condition(&self) -> bool {
        is_initial_name(&self.parameter)
    }
}

/// The initial state.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// The state `[x, v]` (`[x1, …, xN, v1, …, vN]` for `N` degrees of freedom); default
    /// the model's rest state (the paper: the static equilibrium against the stop;
    /// Duffing–Ueda: the origin).
    #[serde(default)]
    pub state: Option<Vec<f64>>,
}

/// Integration settings (DOPRI5 with event location).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegrationSpec {
    /// Relative tolerance.
    #[serde(default = "default_rtol")]
    pub rtol: f64,
    /// Absolute tolerances, one per state component (`[position, velocity]` for one degree
    /// of freedom); default the model's scale × `rtol`.
    #[serde(default)]
    pub atol: Option<Vec<f64>>,
    /// Step cap per run.
    #[serde(default = "default_max_steps")]
    pub max_steps: usize,
}

fn default_rtol() -> f64 {
    1e-8
}
fn default_max_steps() -> usize {
    10_000_000
}

impl Default for IntegrationSpec {
    fn default() -> Self {
        Self {
            rtol: default_rtol(),
            atol: None,
            max_steps: default_max_steps(),
        }
    }
}

/// Forcing periods per point: `transient + record` at most [`MAX_PERIODS`], and no more
/// than `integration.max_steps` (a point takes at least one step per period).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodsSpec {
    /// Discarded periods.
    pub transient: u32,
    /// Recorded periods (≥ 1).
    pub record: u32,
}

/// What is recorded per point. Always: the regime (period), impacts per period, the
/// attractor fingerprint; optionally the top Lyapunov exponent and the entropy index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSpec {
    /// The most stroboscopic points kept per point (the last ones; at least the orbit's
    /// period are always kept).
    #[serde(default = "default_poincare")]
    pub poincare: usize,
    /// Relative tolerance of period detection.
    #[serde(default = "default_period_tol")]
    pub period_tol: f64,
    /// Largest period tested.
    #[serde(default = "default_max_period")]
    pub max_period: usize,
    /// The top Lyapunov exponent (two trajectories), if given.
    #[serde(default)]
    pub lyapunov: Option<LyapunovSpec>,
    /// The entropy index `q*` of the inter-impact intervals, if given.
    #[serde(default)]
    pub q: Option<QSpec>,
}

fn default_poincare() -> usize {
    16
}
fn default_period_tol() -> f64 {
    1e-4
}
fn default_max_period() -> usize {
    16
}

impl Default for RecordSpec {
    fn default() -> Self {
        Self {
            poincare: default_poincare(),
            period_tol: default_period_tol(),
            max_period: default_max_period(),
            lyapunov: None,
            q: None,
        }
    }
}

/// Top Lyapunov exponent settings: two trajectories renormalized every forcing period,
/// started from the end of the recorded window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LyapunovSpec {
    /// Forcing periods averaged (≥ 10: the spread needs 10 blocks).
    pub periods: usize,
    /// Initial separation in the model's norm; default the model's (the paper:
    /// [`systems::paper::lyapunov::D0`](crate::systems::paper::lyapunov::D0)).
    #[serde(default)]
    pub d0: Option<f64>,
}

/// Entropy index settings: the histogram of the inter-impact intervals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QSpec {
    /// Lower edge of the histogram (s).
    pub lo: f64,
    /// Upper edge (s).
    pub hi: f64,
    /// Bin width (s).
    pub step: f64,
}

/// Attractor identification (see the [module docs](super) for the criterion).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttractorSpec {
    /// Scales of the section coordinates, one per state component (`[x, v]` for one
    /// degree of freedom); default the model's.
    #[serde(default)]
    pub scales: Option<Vec<f64>>,
    /// Periodic orbits coincide when their section points are within `tol` (scaled, max
    /// norm) of each other.
    #[serde(default = "default_attractor_tol")]
    pub tol: f64,
    /// Cell size (scaled) of the tessellation of the section for non-periodic attractors.
    #[serde(default = "default_cell")]
    pub cell: f64,
    /// Non-periodic attractors coincide when the Jaccard overlap of their occupied cells
    /// is at least this.
    #[serde(default = "default_overlap")]
    pub overlap: f64,
}

fn default_attractor_tol() -> f64 {
    1e-3
}
fn default_cell() -> f64 {
    0.05
}
fn default_overlap() -> f64 {
    0.3
}

impl Default for AttractorSpec {
    fn default() -> Self {
        Self {
            scales: None,
            tol: default_attractor_tol(),
            cell: default_cell(),
            overlap: default_overlap(),
        }
    }
}

fn invalid(field: impl Into<String>, message: impl Into<String>) -> StudyError {
    StudyError::InvalidSpec {
        field: field.into(),
        message: message.into(),
    }
}

fn positive_finite(field: &str, v: f64) -> Result<(), StudyError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(field, format!("must be finite and > 0 (got {v})")))
    }
}

impl StudySpec {
    /// Reads and validates a spec from TOML text.
    ///
    /// # Errors
    /// [`StudyError::Toml`] for malformed TOML, an unknown or missing key, or a value of the
    /// wrong type (the message names the key); [`StudyError::InvalidSpec`] naming the field
    /// that fails validation.
    pub fn from_toml(text: &str) -> Result<Self, StudyError> {
        let spec = Self::parse(text)?;
        spec.validate()?;
        Ok(spec)
    }

    /// Reads a spec from TOML text without validating it.
    ///
    /// # Errors
    /// [`StudyError::Toml`] as [`from_toml`](Self::from_toml).
    fn parse(text: &str) -> Result<Self, StudyError> {
        toml::from_str(text).map_err(|e| StudyError::Toml(e.to_string()))
    }

    /// Checks every field; the error names the first invalid one.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`].
    pub fn validate(&self) -> Result<(), StudyError> {
        self.checked().map(|_| ())
    }

    /// Checks every field and returns the system.
    fn checked(&self) -> Result<Arc<dyn StudySystem>, StudyError> {
        self.validate_name()?;
        let system = catalogue::system(&self.system.model, &self.system.description())?;
        self.validate_with(&*system)?;
        Ok(system)
    }

    /// Checks every field but the name and the model against `sys`, the spec's system.
    fn validate_with(&self, sys: &dyn StudySystem) -> Result<(), StudyError> {
        self.validate_system(sys)?;
        let axes = self.axes();
        self.validate_grid(sys, &axes)?;
        let axes = self.resolve(sys, &axes)?;
        self.validate_fixed(sys, &axes)?;
        self.validate_initial(sys)?;
        self.validate_integration(sys)?;
        self.validate_periods()?;
        self.validate_record()?;
        self.validate_attractors(sys)?;
        self.validate_axis_models(sys, &axes)
    }

    /// The number of grid points.
    pub fn points(&self) -> usize {
        self.grid.x.points * self.grid.y.as_ref().map_or(1, |y| y.points)
    }

    /// The canonical text of the spec (JSON with every default filled in and parameters
    /// sorted by name): two specs with the same canonical text describe the same study,
    /// whatever their TOML layout.
    ///
    /// # Errors
    /// [`StudyError::Io`] if serialization fails (it does not for a validated spec).
    pub fn canonical(&self) -> Result<String, StudyError> {
        serde_json::to_string(self).map_err(|e| StudyError::Io(e.to_string()))
    }

    /// The spec hash: 64-bit FNV-1a of the canonical text and the crate version, as 16 hex
    /// digits. Stable across runs, machines and thread counts (unlike std's `DefaultHasher`,
    /// which is randomly keyed per process).
    ///
    /// # Errors
    /// As [`canonical`](Self::canonical).
    pub fn hash(&self) -> Result<String, StudyError> {
        let text = format!(
            "nonsmooth {}\n{}",
            env!("CARGO_PKG_VERSION"),
            self.canonical()?
        );
        Ok(format!("{:016x}", fnv1a(text.as_bytes())))
    }
}

// The checks of `StudySpec::validate`, one per section of the spec, in the order it runs them
// (so that the error names the first invalid field).
impl StudySpec {
    fn validate_name(&self) -> Result<(), StudyError> {
        if self.name.is_empty()
            || !self
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.')
        {
            return Err(invalid(
                "name",
                format!(
                    "must be non-empty and use only letters, digits, '_', '-', '.' (got {:?})",
                    self.name
                ),
            ));
        }
        Ok(())
    }

    /// The fixed parameters: known to the model and finite.
    fn validate_system(&self, system: &dyn StudySystem) -> Result<(), StudyError> {
        for (name, &v) in &self.system.parameters {
            if !system.has_parameter(name) {
                return Err(invalid(
                    format!("system.parameters.{name}"),
                    format!(
                        "unknown parameter of model {:?}; known: {}",
                        self.system.model,
                        system.parameter_list()
                    ),
                ));
            }
            if !v.is_finite() {
                return Err(invalid(
                    format!("system.parameters.{name}"),
                    format!("must be finite (got {v})"),
                ));
            }
        }
        Ok(())
    }

    /// The grid's axes with their field names: `grid.x`, then `grid.y` if present.
    fn axes(&self) -> Vec<(&'static str, &Axis)> {
        let mut axes = vec![("grid.x", &self.grid.x)];
        if let Some(y) = &self.grid.y {
            axes.push(("grid.y", y));
        }
        axes
    }

    /// Each axis on its own, two distinct axes, the number of points, and every parameter
    /// without a default (the paper's forcing frequency) given somewhere.
    fn validate_grid(
        &self,
        system: &dyn StudySystem,
        axes: &[(&str, &Axis)],
    ) -> Result<(), StudyError> {
        for (field, a) in axes {
            self.validate_axis(system, field, a)?;
        }
        if let Some(y) = &self.grid.y {
            if y.parameter == self.grid.x.parameter {
                return Err(invalid(
                    "grid.y.parameter",
                    format!("{:?} is already the x axis", y.parameter),
                ));
            }
        }
        let total =
            (self.grid.x.points as f64) * self.grid.y.as_ref().map_or(1.0, |y| y.points as f64);
        if total > MAX_POINTS as f64 {
            return Err(invalid(
                "grid",
                format!("{total} points; at most {MAX_POINTS}"),
            ));
        }
        for d in system.parameters() {
            if d.default.is_none() && !self.is_given(&d.name, axes) {
                return Err(invalid(
                    format!("system.parameters.{}", d.name),
                    format!(
                        "{} has no default: it must be given (here or as a grid axis)",
                        d.name
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Whether parameter `name` is given in `system.parameters` or as an axis.
    fn is_given(&self, name: &str, axes: &[(&str, &Axis)]) -> bool {
        self.system.parameters.contains_key(name) || axes.iter().any(|(_, a)| a.parameter == name)
    }

    /// Whether parameter `name` has no default and is not a fixed parameter of the spec.
    fn unset_required(&self, system: &dyn StudySystem, name: &str) -> bool {
        !self.system.parameters.contains_key(name)
            && system
                .parameters()
                .iter()
                .any(|d| d.name == name && d.default.is_none())
    }

    /// One axis: a known parameter, at least one point, finite and increasing ends.
    fn validate_axis(
        &self,
        system: &dyn StudySystem,
        field: &str,
        a: &Axis,
    ) -> Result<(), StudyError> {
        let initial = system.initial_names();
        let known = initial.contains(&a.parameter) || system.has_parameter(&a.parameter);
        if !known {
            return Err(invalid(
                format!("{field}.parameter"),
                format!(
                    "unknown parameter {:?} of model {:?}; known: {}, {}",
                    a.parameter,
                    self.system.model,
                    system.parameter_list(),
                    initial.join(", ")
                ),
            ));
        }
        if a.points == 0 {
            return Err(invalid(
                format!("{field}.points"),
                "the grid is empty: points must be >= 1",
            ));
        }
        if !a.start.is_finite() {
            return Err(invalid(format!("{field}.start"), "must be finite"));
        }
        if !a.end.is_finite() {
            return Err(invalid(format!("{field}.end"), "must be finite"));
        }
        if a.points > 1 && !(a.end > a.start) {
            return Err(invalid(
                format!("{field}.end"),
                format!(
                    "must be > start ({}) for {} points (got {})",
                    a.start, a.points, a.end
                ),
            ));
        }
        Ok(())
    }

    fn validate_initial(&self, system: &dyn StudySystem) -> Result<(), StudyError> {
        if let Some(s) = &self.initial.state {
            components("initial.state", s, system)?;
            for (k, v) in s.iter().enumerate() {
                if !v.is_finite() {
                    return Err(invalid(format!("initial.state[{k}]"), "must be finite"));
                }
            }
        }
        Ok(())
    }

    fn validate_integration(&self, system: &dyn StudySystem) -> Result<(), StudyError> {
        positive_finite("integration.rtol", self.integration.rtol)?;
        if let Some(a) = &self.integration.atol {
            components("integration.atol", a, system)?;
            for (k, &v) in a.iter().enumerate() {
                positive_finite(&format!("integration.atol[{k}]"), v)?;
            }
        }
        if self.integration.max_steps == 0 {
            return Err(invalid("integration.max_steps", "must be >= 1"));
        }
        Ok(())
    }

    /// The recorded periods, their total against [`MAX_PERIODS`], and the step cap against
    /// the total.
    fn validate_periods(&self) -> Result<(), StudyError> {
        if self.periods.record == 0 {
            return Err(invalid("periods.record", "must be >= 1"));
        }
        let periods = u64::from(self.periods.transient) + u64::from(self.periods.record);
        if periods > MAX_PERIODS {
            let field = if u64::from(self.periods.transient) > MAX_PERIODS {
                "periods.transient"
            } else {
                "periods"
            };
            return Err(invalid(
                field,
                format!(
                    "transient + record = {} + {} = {periods} forcing periods per point \
                     exceeds the limit of {MAX_PERIODS} (MAX_PERIODS: one run visits at most \
                     10^9 sections)",
                    self.periods.transient, self.periods.record
                ),
            ));
        }
        // Every step lands on the period grid: a point takes at least one step per period.
        if (self.integration.max_steps as u64) < periods {
            return Err(invalid(
                "integration.max_steps",
                format!(
                    "{} is below the {periods} forcing periods (transient + record) of a \
                     point: every step lands on the period grid, so every point would stop \
                     at the step cap; allow at least {periods} steps",
                    self.integration.max_steps
                ),
            ));
        }
        Ok(())
    }

    fn validate_record(&self) -> Result<(), StudyError> {
        positive_finite("record.period_tol", self.record.period_tol)?;
        if self.record.max_period == 0 {
            return Err(invalid("record.max_period", "must be >= 1"));
        }
        if let Some(l) = &self.record.lyapunov {
            validate_lyapunov(l)?;
        }
        if let Some(q) = &self.record.q {
            validate_q(q)?;
        }
        Ok(())
    }

    fn validate_attractors(&self, system: &dyn StudySystem) -> Result<(), StudyError> {
        if let Some(s) = &self.attractors.scales {
            components("attractors.scales", s, system)?;
            for (k, &v) in s.iter().enumerate() {
                positive_finite(&format!("attractors.scales[{k}]"), v)?;
            }
        }
        positive_finite("attractors.tol", self.attractors.tol)?;
        positive_finite("attractors.cell", self.attractors.cell)?;
        if !(self.attractors.overlap > 0.0 && self.attractors.overlap <= 1.0) {
            return Err(invalid(
                "attractors.overlap",
                format!("must be in (0, 1] (got {})", self.attractors.overlap),
            ));
        }
        Ok(())
    }

    /// The axes with their targets, resolved once (the names are known: checked by
    /// [`validate_grid`](Self::validate_grid)).
    ///
    /// # Errors
    /// As [`AxisTarget::of`].
    fn resolve<'a>(
        &self,
        system: &dyn StudySystem,
        axes: &[(&'static str, &'a Axis)],
    ) -> Result<Vec<ResolvedAxis<'a>>, StudyError> {
        axes.iter()
            .map(|&(field, axis)| {
                Ok(ResolvedAxis {
                    field,
                    axis,
                    target: AxisTarget::of(system, field, &axis.parameter)?,
                    required: self.unset_required(system, &axis.parameter),
                })
            })
            .collect()
    }

    /// The values the spec fixes, at the base point (the fixed parameters, the defaults,
    /// and the axis starts of parameters without a default), naming the field at fault.
    fn validate_fixed(
        &self,
        system: &dyn StudySystem,
        axes: &[ResolvedAxis<'_>],
    ) -> Result<(), StudyError> {
        let mut p = system.point(&self.system.parameters)?;
        for b in axes.iter().filter(|b| b.required) {
            b.set(&mut p, b.axis.start);
        }
        system.check_fixed(&p, &|name| axes.iter().any(|a| a.axis.parameter == name))
    }

    /// The axes of parameters without a default take their start while the other axis is
    /// checked: where that base point is invalid and another value of such an axis makes it
    /// valid, its start is at fault, and the error names that axis.
    fn blame_axis_start(
        &self,
        system: &dyn StudySystem,
        axes: &[ResolvedAxis<'_>],
        set: &ParameterPoint,
    ) -> Result<(), StudyError> {
        let mut base = set.clone();
        for b in axes.iter().filter(|b| b.required) {
            b.set(&mut base, b.axis.start);
        }
        let Err(e) = system.check(&base) else {
            return Ok(());
        };
        for b in axes.iter().filter(|b| b.required) {
            // Each value of this axis on the base point (one parameter set in turn).
            let mut p = base.clone();
            let frees = (1..b.axis.points).any(|k| {
                b.set(&mut p, b.axis.value(k));
                system.check(&p).is_ok()
            });
            if frees {
                return Err(invalid(
                    b.field,
                    format!(
                        "value {v} ({} = {v}) gives an invalid model: {e}",
                        b.axis.parameter,
                        v = b.axis.start
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Every axis value must give a valid model, with the other axis at the base value
    /// (the fixed parameters or the model's default), so that an error names the axis
    /// at fault; a parameter without a default (the paper's `omega`) takes its axis start.
    /// The point is built once per axis and each value sets its one parameter; the values
    /// of an initial-condition axis leave the model as it is, which is checked once.
    fn validate_axis_models(
        &self,
        system: &dyn StudySystem,
        axes: &[ResolvedAxis<'_>],
    ) -> Result<(), StudyError> {
        let set = system.point(&self.system.parameters)?;
        self.blame_axis_start(system, axes, &set)?;
        for a in axes {
            let mut p = set.clone();
            for b in axes {
                if b.axis.parameter != a.axis.parameter && b.required {
                    b.set(&mut p, b.axis.start);
                }
            }
            let mut checked = false;
            let axis = a.axis;
            for k in 0..axis.points {
                let v = axis.value(k);
                if !v.is_finite() {
                    return Err(invalid(
                        a.field,
                        format!(
                            "value {k} of {} ({} from {} to {} in {} points) is {v}: every \
                             axis value must be finite",
                            axis.parameter, axis.parameter, axis.start, axis.end, axis.points
                        ),
                    ));
                }
                match a.target {
                    AxisTarget::Parameter(i) => p.set(i, v),
                    AxisTarget::Initial(_) if checked => continue,
                    AxisTarget::Initial(_) => checked = true,
                }
                system.check(&p).map_err(|e| {
                    invalid(
                        a.field,
                        format!(
                            "value {v} ({} = {v}) gives an invalid model: {e}",
                            axis.parameter
                        ),
                    )
                })?;
            }
        }
        Ok(())
    }
}

/// An axis of the grid with its field (`grid.x`), where its values go, and whether it is
/// the axis of a parameter without a default that the spec does not fix.
struct ResolvedAxis<'a> {
    field: &'static str,
    axis: &'a Axis,
    target: AxisTarget,
    required: bool,
}

impl ResolvedAxis<'_> {
    /// Sets the axis value `v` in `p` (a value of an initial-condition axis sets no
    /// parameter).
    fn set(&self, p: &mut ParameterPoint, v: f64) {
        if let AxisTarget::Parameter(i) = self.target {
            p.set(i, v);
        }
    }
}

/// `values` (the field `field`) has one value per state component of `system`.
fn components(field: &str, values: &[f64], system: &dyn StudySystem) -> Result<(), StudyError> {
    let n = system.dimension();
    if values.len() != n {
        let names = system.state_names().join(", ");
        return Err(invalid(
            field,
            format!(
                "has {} values; model {:?} has {n} state components ({names})",
                values.len(),
                system.name()
            ),
        ));
    }
    Ok(())
}

/// `record.lyapunov`: enough periods for the spread's blocks, no more than one estimate takes.
fn validate_lyapunov(l: &LyapunovSpec) -> Result<(), StudyError> {
    if l.periods < 10 {
        return Err(invalid(
            "record.lyapunov.periods",
            format!(
                "must be >= 10 (the spread uses 10 blocks; got {})",
                l.periods
            ),
        ));
    }
    if l.periods > crate::lyapunov::MAX_INTERVALS {
        return Err(invalid(
            "record.lyapunov.periods",
            format!(
                "{} exceeds the limit of {} intervals of one estimate \
                 (lyapunov::MAX_INTERVALS)",
                l.periods,
                crate::lyapunov::MAX_INTERVALS
            ),
        ));
    }
    if let Some(d0) = l.d0 {
        positive_finite("record.lyapunov.d0", d0)?;
    }
    Ok(())
}

/// `record.q`: a finite increasing range and a histogram that can be built on it.
fn validate_q(q: &QSpec) -> Result<(), StudyError> {
    if !(q.lo.is_finite() && q.hi.is_finite() && q.hi > q.lo) {
        return Err(invalid(
            "record.q.hi",
            format!("must be finite and > lo (lo = {}, hi = {})", q.lo, q.hi),
        ));
    }
    positive_finite("record.q.step", q.step)?;
    // The histogram itself (bins at most `Histogram::MAX_BINS`, resolvable edges):
    // otherwise every point's `q` would be NaN without a word.
    crate::entropy::Histogram::<f64>::new(q.lo, q.hi, q.step)
        .map_err(|e| invalid("record.q.step", e.to_string()))?;
    Ok(())
}

/// 64-bit FNV-1a.
pub(crate) fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Where the values of an axis go: a parameter of the system or a component of the initial
/// state, by index (the axis's name resolved once).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum AxisTarget {
    /// The parameter of this index in a point's values.
    Parameter(usize),
    /// The initial-state component of this index.
    Initial(usize),
}

impl AxisTarget {
    /// The target of the axis `field` over `name`: an initial-condition component of
    /// `system`, or else its parameter.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] naming `FIELD.parameter` if `name` is neither.
    fn of(system: &dyn StudySystem, field: &str, name: &str) -> Result<Self, StudyError> {
        match system.initial_names().iter().position(|n| n == name) {
            Some(k) => Ok(Self::Initial(k)),
            None => system
                .parameter_index(name)
                .map(Self::Parameter)
                .ok_or_else(|| {
                    invalid(
                        format!("{field}.parameter"),
                        format!("unknown parameter {name:?} of model {:?}", system.name()),
                    )
                }),
        }
    }

    /// Sets the axis value `value`: in `p`, or in `y0` (the given components of an initial
    /// state of `dimension` components, NaN for the others).
    fn apply(
        self,
        dimension: usize,
        p: &mut ParameterPoint,
        y0: &mut Option<Vec<f64>>,
        value: f64,
    ) {
        match self {
            Self::Parameter(i) => p.set(i, value),
            Self::Initial(k) => {
                let s = y0.get_or_insert_with(|| vec![f64::NAN; dimension]);
                if let Some(c) = s.get_mut(k) {
                    *c = value;
                }
            }
        }
    }
}

/// A validated study: the spec, its hash, its system and its grid.
#[derive(Debug, Clone)]
pub struct Study {
    spec: StudySpec,
    hash: String,
    system: Arc<dyn StudySystem>,
    /// The parameters of every point before the axes set theirs.
    base: ParameterPoint,
    /// Where the values of the axes go: `x`, then `y` if the grid has it.
    targets: (AxisTarget, Option<AxisTarget>),
}

impl PartialEq for Study {
    fn eq(&self, other: &Self) -> bool {
        self.spec == other.spec && self.hash == other.hash
    }
}

impl Study {
    /// Validates the spec and computes its hash.
    ///
    /// # Errors
    /// As [`StudySpec::validate`].
    pub fn new(spec: StudySpec) -> Result<Self, StudyError> {
        let system = spec.checked()?;
        let hash = spec.hash()?;
        let base = system.point(&spec.system.parameters)?;
        let x = AxisTarget::of(&*system, "grid.x", &spec.grid.x.parameter)?;
        let y = match &spec.grid.y {
            Some(a) => Some(AxisTarget::of(&*system, "grid.y", &a.parameter)?),
            None => None,
        };
        Ok(Self {
            spec,
            hash,
            system,
            base,
            targets: (x, y),
        })
    }

    /// Reads a study from TOML text (validated once, by [`Study::new`]).
    ///
    /// # Errors
    /// As [`StudySpec::from_toml`].
    pub fn from_toml(text: &str) -> Result<Self, StudyError> {
        Self::new(StudySpec::parse(text)?)
    }

    /// Reads a study from a TOML file.
    ///
    /// # Errors
    /// [`StudyError::Io`] naming the file; as [`StudySpec::from_toml`].
    pub fn from_file(path: &std::path::Path) -> Result<Self, StudyError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| StudyError::Io(format!("{}: {e}", path.display())))?;
        Self::from_toml(&text)
    }

    /// The spec.
    pub fn spec(&self) -> &StudySpec {
        &self.spec
    }

    /// The spec hash (see [`StudySpec::hash`]).
    pub fn hash(&self) -> &str {
        &self.hash
    }

    /// The system.
    pub(crate) fn system(&self) -> &dyn StudySystem {
        &*self.system
    }

    /// The scales of the state components: `attractors.scales`, or the system's.
    pub(crate) fn scales(&self) -> Vec<f64> {
        match &self.spec.attractors.scales {
            Some(s) => s.to_vec(),
            None => self.system.scales(),
        }
    }

    /// The number of grid points.
    pub fn points(&self) -> usize {
        self.spec.points()
    }

    /// Whether an axis of the grid is an initial-condition component.
    pub fn has_initial_condition_axis(&self) -> bool {
        let g = &self.spec.grid;
        g.x.is_initial_condition() || g.y.as_ref().is_some_and(Axis::is_initial_condition)
    }

    /// Grid coordinates `(ix, iy)` of point `index`.
    pub fn coordinates(&self, index: usize) -> (usize, usize) {
        let nx = self.spec.grid.x.points;
        (index % nx, index / nx)
    }

    /// The parameters of point `index` and its given initial components (`None`, or NaN
    /// where not given: the rest state's).
    pub(crate) fn point(&self, index: usize) -> (ParameterPoint, Option<Vec<f64>>) {
        let mut p = self.base.clone();
        let mut y0 = self.spec.initial.state.clone();
        let (xv, yv) = self.values(index);
        let dimension = self.system.dimension();
        let (x, y) = self.targets;
        x.apply(dimension, &mut p, &mut y0, xv);
        if let Some(y) = y {
            y.apply(dimension, &mut p, &mut y0, yv);
        }
        (p, y0)
    }

    /// Axis values `(x, y)` of point `index` (`y` is NaN for a one-axis grid).
    pub fn values(&self, index: usize) -> (f64, f64) {
        let (ix, iy) = self.coordinates(index);
        (
            self.spec.grid.x.value(ix),
            self.spec.grid.y.as_ref().map_or(f64::NAN, |y| y.value(iy)),
        )
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use super::super::system::{ParameterDef, PointRun, RunSettings, state_names};
    use super::*;

    #[test]
    fn fnv1a_matches_the_reference_vectors() {
        // The published FNV-1a 64-bit test vectors.
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn axis_values_are_computed_from_the_index() {
        let a = Axis {
            parameter: "omega".into(),
            start: 17.5,
            end: 25.0,
            points: 61,
        };
        assert_eq!(a.value(0), 17.5);
        assert_eq!(a.value(60), 25.0);
        assert_eq!(a.value(30), 21.25);
    }

    #[test]
    fn an_axis_across_the_f64_range_has_finite_values() {
        let a = Axis {
            parameter: "x0".into(),
            start: -1e308,
            end: 1e308,
            points: 3,
        };
        assert_eq!([a.value(0), a.value(1), a.value(2)], [-1e308, 0.0, 1e308]);
        let b = Axis {
            parameter: "x0".into(),
            start: -f64::MAX,
            end: f64::MAX,
            points: 7,
        };
        assert!((0..7).all(|k| b.value(k).is_finite()));
        assert!((0..6).all(|k| b.value(k) < b.value(k + 1)));
        assert_eq!((b.value(0), b.value(6)), (-f64::MAX, f64::MAX));
    }

    /// A system that counts its model checks and the look-ups of its parameter and state
    /// names, and runs nothing.
    #[derive(Debug)]
    struct Counting {
        params: Vec<ParameterDef>,
        checks: AtomicUsize,
        lookups: AtomicUsize,
    }

    impl Counting {
        fn new() -> Self {
            Self {
                params: vec![ParameterDef::new("omega", 1.0), ParameterDef::new("k", 1.0)],
                checks: 0.into(),
                lookups: 0.into(),
            }
        }
        fn count(c: &AtomicUsize) -> usize {
            c.load(Ordering::Relaxed)
        }
        fn add(c: &AtomicUsize) {
            c.fetch_add(1, Ordering::Relaxed);
        }
    }

    impl StudySystem for Counting {
        fn name(&self) -> &str {
            "counting"
        }
        fn parameters(&self) -> &[ParameterDef] {
            Self::add(&self.lookups);
            &self.params
        }
        fn dimension(&self) -> usize {
            2
        }
        fn surfaces(&self) -> usize {
            0
        }
        fn scales(&self) -> Vec<f64> {
            vec![1.0; 2]
        }
        fn atol_per_rtol(&self) -> Vec<f64> {
            vec![1.0; 2]
        }
        fn d0(&self) -> f64 {
            1e-6
        }
        fn check(&self, _p: &ParameterPoint) -> Result<(), String> {
            Self::add(&self.checks);
            Ok(())
        }
        fn rest_state(&self, _p: &ParameterPoint) -> Result<Vec<f64>, String> {
            Ok(vec![0.0; 2])
        }
        fn run(
            &self,
            _p: &ParameterPoint,
            _y0: &[f64],
            _s: &RunSettings,
        ) -> Result<PointRun, String> {
            Err("not run".into())
        }
        fn state_names(&self) -> Vec<String> {
            Self::add(&self.lookups);
            state_names(2)
        }
    }

    /// Issue 49: checking a spec looked up the axes' names, and copied the parameters, at
    /// every axis value (30 s for 10⁷ points). The names are resolved once per axis: per
    /// value of a parameter axis there is one model check and no look-up, and an
    /// initial-condition axis, whose values leave the model as it is, checks it once.
    #[test]
    fn checking_a_spec_resolves_the_axes_once() {
        let n = 10_000;
        let text = format!(
            r#"
name = "count"
[system]
model = "counting"
[grid]
x = {{ parameter = "k", start = 1.0, end = 2.0, points = {n} }}
y = {{ parameter = "x0", start = -1.0, end = 1.0, points = {n} }}
[periods]
transient = 10
record = 10
"#
        );
        let spec: StudySpec = toml::from_str(&text).unwrap();
        let sys = Counting::new();
        spec.validate_with(&sys).unwrap();
        let (checks, lookups) = (Counting::count(&sys.checks), Counting::count(&sys.lookups));
        assert!(
            (n..n + 10).contains(&checks),
            "{checks} model checks for {n} values of k and {n} of x0"
        );
        assert!(lookups < 100, "{lookups} look-ups of the names");
    }

    #[test]
    fn max_periods_is_within_the_section_limit_of_a_run() {
        use crate::drive::Observer;
        use crate::sample::Stroboscopic;
        for omega in [20.0, 17.3, 1.0, 1e-3, 123.456, 22.73] {
            let period = std::f64::consts::TAU / omega;
            let s = Stroboscopic::<f64, 2>::periodic(0.0, period, 0.0, 16).unwrap();
            // The end of a point's run as `sweep::run_point` computes it.
            let t_end = (MAX_PERIODS as f64) * period;
            assert!(s.check_span(0.0, t_end).is_ok(), "ω = {omega}");
            let over = (MAX_PERIODS as f64 + 2.0) * period;
            assert!(s.check_span(0.0, over).is_err(), "ω = {omega}");
        }
    }
}
