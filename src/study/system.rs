//! What a study needs of a system: the [`StudySystem`] trait, and the parameter point and
//! the run settings and results it exchanges with the study, in any state size.
//!
//! The systems themselves (the catalogue and the mechanical system described in a study
//! file) are in [`catalogue`](super::catalogue); adding one is an impl of the trait and a
//! line in its registry.

use std::collections::BTreeMap;

use super::StudyError;

/// A parameter of a study system: its name and default (`None`: no default, the spec must
/// give it, in `system.parameters` or as a grid axis — the paper's `omega`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ParameterDef {
    /// The name a spec uses.
    pub name: String,
    /// The default value.
    pub default: Option<f64>,
}

impl ParameterDef {
    /// A parameter with a default.
    pub fn new(name: &str, default: f64) -> Self {
        Self {
            name: name.into(),
            default: Some(default),
        }
    }

    /// A parameter without a default.
    pub fn required(name: &str) -> Self {
        Self {
            name: name.into(),
            default: None,
        }
    }
}

/// The values of every parameter of a system at one grid point, in the order of the
/// system's [`parameters`](StudySystem::parameters) (NaN for a parameter without a default
/// that is not given). Names are resolved to indices once
/// ([`parameter_index`](StudySystem::parameter_index)), not at every point.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ParameterPoint {
    values: Vec<f64>,
}

impl ParameterPoint {
    /// The value of parameter `index` (NaN beyond the system's parameters).
    pub fn value(&self, index: usize) -> f64 {
        self.values.get(index).copied().unwrap_or(f64::NAN)
    }

    /// Every parameter's value, in the order of the system's parameters.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The values of a system of `K` parameters, in order; all NaN for a point of another
    /// number of parameters (not a point of that system: every check then fails).
    pub fn array<const K: usize>(&self) -> [f64; K] {
        debug_assert_eq!(self.values.len(), K, "a point of another system");
        self.values.as_slice().try_into().unwrap_or([f64::NAN; K])
    }

    /// Sets parameter `index` (nothing beyond the system's parameters).
    pub fn set(&mut self, index: usize, value: f64) {
        if let Some(v) = self.values.get_mut(index) {
            *v = value;
        }
    }
}

/// The settings of one point's run, from the spec, in the system's state size.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RunSettings {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerances, one per state component.
    pub atol: Vec<f64>,
    /// Step cap per run.
    pub max_steps: usize,
    /// Discarded forcing periods.
    pub transient: u32,
    /// Recorded forcing periods.
    pub record: u32,
    /// Relative tolerance of period detection.
    pub period_tol: f64,
    /// Largest period tested.
    pub max_period: usize,
    /// The top Lyapunov exponent: forcing periods averaged and the initial separation.
    pub lyapunov: Option<(usize, f64)>,
    /// Characteristic scales of the state components (the Lyapunov norm).
    pub scales: Vec<f64>,
}

/// What one point's run gave, in any state size.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PointRun {
    /// The detected period in forcing periods (0: none).
    pub period: usize,
    /// The stroboscopic points of the recorded window.
    pub poincare: Vec<Vec<f64>>,
    /// Impacts per forcing period on all surfaces.
    pub impacts_per_period: f64,
    /// Impacts per forcing period on each surface.
    pub impacts_per_surface: Vec<f64>,
    /// Inter-impact intervals of the recorded window.
    pub intervals: Vec<f64>,
    /// The top Lyapunov exponent and its spread, or why it failed (`None`: not recorded).
    pub lyapunov: Option<Result<(f64, f64), String>>,
}

/// The start of one point: its parameters and initial state, or why it has none.
pub(crate) type PointStart = Result<(ParameterPoint, Vec<f64>), String>;

/// `points` run one by one through `system`'s [`run`](StudySystem::run) (the default
/// [`run_batch`](StudySystem::run_batch)).
pub(crate) fn one_by_one<S: StudySystem + ?Sized>(
    system: &S,
    points: &[PointStart],
    s: &RunSettings,
) -> Vec<Result<PointRun, String>> {
    points
        .iter()
        .map(|p| match p {
            Ok((p, y0)) => system.run(p, y0, s),
            Err(m) => Err(m.clone()),
        })
        .collect()
}

/// A system a study can run: a model of the catalogue or one described in the study file.
///
/// The study asks it for its parameters (names and defaults), builds a [`ParameterPoint`]
/// per grid point, and runs the point from an initial state with [`run`](Self::run), which
/// builds the model at the point and drives it on the scalar path
/// ([`scalar`](super::scalar)). A system with a lane form runs a shard's points together
/// in SIMD lanes ([`run_batch`](Self::run_batch), [`lanes`](super::lanes)).
pub(crate) trait StudySystem: std::fmt::Debug + Send + Sync {
    /// The name in `system.model`.
    fn name(&self) -> &str;

    /// The parameters a spec may set or sweep, with their defaults.
    fn parameters(&self) -> &[ParameterDef];

    /// The state dimension (`2N` for `N` degrees of freedom).
    fn dimension(&self) -> usize;

    /// The number of impact surfaces (impacts are counted on each).
    fn surfaces(&self) -> usize;

    /// Characteristic scales of the state components: the Lyapunov norm, attractor cells.
    fn scales(&self) -> Vec<f64>;

    /// Absolute tolerances per unit of `rtol`, per state component.
    fn atol_per_rtol(&self) -> Vec<f64>;

    /// The default Lyapunov separation (in the scaled norm).
    fn d0(&self) -> f64;

    /// Builds the model at `p` to check the parameters.
    ///
    /// # Errors
    /// The model's constructor's error, naming the parameter.
    fn check(&self, p: &ParameterPoint) -> Result<(), String>;

    /// Checks the values the spec fixes (not those of the grid axes: `on_axes(name)` says
    /// whether parameter `name` is an axis), naming the field of the spec at fault. Default:
    /// nothing to check beyond [`check`](Self::check) at every axis value.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] naming the field.
    fn check_fixed(
        &self,
        _p: &ParameterPoint,
        _on_axes: &dyn Fn(&str) -> bool,
    ) -> Result<(), StudyError> {
        Ok(())
    }

    /// The default initial state at `p` (the components the spec does not give).
    ///
    /// # Errors
    /// Why there is none (e.g. no static equilibrium).
    fn rest_state(&self, p: &ParameterPoint) -> Result<Vec<f64>, String>;

    /// Runs the point `p` from `y0` (of [`dimension`](Self::dimension) components):
    /// `transient` forcing periods, then `record` recorded ones, and the top Lyapunov
    /// exponent from the end state if asked for.
    ///
    /// # Errors
    /// What failed, as the point's status.
    fn run(&self, p: &ParameterPoint, y0: &[f64], s: &RunSettings) -> Result<PointRun, String>;

    /// Whether a shard runs this system's points together in SIMD lanes
    /// ([`run_batch`](Self::run_batch)) rather than one by one. Default: no.
    fn in_lanes(&self) -> bool {
        false
    }

    /// Runs `points` together (each its parameter point and initial state, or why it has
    /// none): a result per point, what [`run`](Self::run) gives for it, to the bit and with
    /// the same messages. Default: one by one through [`run`](Self::run); a system with a
    /// lane form runs them in SIMD lanes (and says so in [`in_lanes`](Self::in_lanes)).
    fn run_batch(&self, points: &[PointStart], s: &RunSettings) -> Vec<Result<PointRun, String>> {
        one_by_one(self, points, s)
    }

    /// The names of the state components: `x, v` for one degree of freedom, `x1 … xN,
    /// v1 … vN` for `N` (section columns, attractor centroids).
    fn state_names(&self) -> Vec<String> {
        state_names(self.dimension())
    }

    /// The names of the initial-condition axes: the state names with `0` (`x0`, `v0`) for
    /// one degree of freedom, with `_0` (`x1_0`, `v2_0`) for more.
    fn initial_names(&self) -> Vec<String> {
        let sep = if self.dimension() == 2 { "" } else { "_" };
        self.state_names()
            .iter()
            .map(|n| format!("{n}{sep}0"))
            .collect()
    }

    /// The parameter point with the defaults, overridden by `values`.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] naming `system.parameters.NAME` for an unknown name.
    fn point(&self, values: &BTreeMap<String, f64>) -> Result<ParameterPoint, StudyError> {
        let mut p = ParameterPoint {
            values: self
                .parameters()
                .iter()
                .map(|d| d.default.unwrap_or(f64::NAN))
                .collect(),
        };
        for (name, &v) in values {
            let index = self
                .parameter_index(name)
                .ok_or_else(|| StudyError::InvalidSpec {
                    field: format!("system.parameters.{name}"),
                    message: format!(
                        "unknown parameter of model {:?}; known: {}",
                        self.name(),
                        self.parameter_list()
                    ),
                })?;
            p.set(index, v);
        }
        Ok(p)
    }

    /// The index of parameter `name` in [`parameters`](Self::parameters) and in a point's
    /// values.
    fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameters().iter().position(|d| d.name == name)
    }

    /// The parameter names, comma-separated.
    fn parameter_list(&self) -> String {
        self.parameters()
            .iter()
            .map(|d| d.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether `name` is a parameter.
    fn has_parameter(&self, name: &str) -> bool {
        self.parameter_index(name).is_some()
    }
}

/// `x, v` for a state of dimension 2; `x1 … xN, v1 … vN` for `2N`.
pub(crate) fn state_names(dimension: usize) -> Vec<String> {
    let n = dimension / 2;
    if n == 1 {
        return vec!["x".into(), "v".into()];
    }
    (1..=n)
        .map(|k| format!("x{k}"))
        .chain((1..=n).map(|k| format!("v{k}")))
        .collect()
}

/// The initial state: the given components (NaN: not given), the rest state for the others.
pub(crate) fn fill(given: Option<&[f64]>, rest: &[f64]) -> Vec<f64> {
    rest.iter()
        .enumerate()
        .map(|(k, &r)| match given.and_then(|g| g.get(k)) {
            Some(&v) if !v.is_nan() => v,
            _ => r,
        })
        .collect()
}

/// Whether `name` has the form of an initial-condition component: `x0`, `v0`, `xK_0`,
/// `vK_0` (`K` a positive integer without leading zeros).
pub(crate) fn is_initial_name(name: &str) -> bool {
    if name == "x0" || name == "v0" {
        return true;
    }
    let Some(rest) = name.strip_prefix('x').or_else(|| name.strip_prefix('v')) else {
        return false;
    };
    let Some(k) = rest.strip_suffix("_0") else {
        return false;
    };
    !k.is_empty() && !k.starts_with('0') && k.bytes().all(|b| b.is_ascii_digit())
}
