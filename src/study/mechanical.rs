//! A mechanical system described in the study file (`[system] model = "mechanical"`):
//! masses, elements (a force law on a degree of freedom or a relative coordinate), harmonic
//! loads and impact surfaces, built at each grid point as a [`model::Mechanical`] system.
//!
//! ```toml
//! [system]
//! model = "mechanical"
//! masses = [1.0, 0.05]                    # one per degree of freedom (1 to 4)
//! parameters = { omega = 1.0, gap = 0.05 } # omega: the forcing frequency (required)
//!
//! [[system.elements]]                     # a law on q0: spring and damper
//! law = "linear_spring"
//! dof = 0
//! k = 1.0
//!
//! [[system.elements]]                     # a Hertz stop on q1 − q0 at +gap
//! law = "hertz"
//! between = [1, 0]
//! position = "gap"                        # a number, or the name of a parameter
//! k = 1e4
//!
//! [[system.loads]]                        # amplitude·cos(ω t + phase) on q0
//! dof = 0
//! amplitude = 0.1
//!
//! [[system.surfaces]]                     # impacts are counted on each surface
//! between = [1, 0]
//! position = "gap"
//! side = "upper"
//! ```
//!
//! Every number may instead name a parameter (`"-name"` for its negative): `omega` and
//! `amplitude_factor` (a factor on every load's amplitude, default 1) are always
//! parameters; any other name becomes one, without a default (it must be given in
//! `system.parameters` or as a grid axis). The laws
//! and their parameters (with their defaults):
//!
//! | law | parameters |
//! |---|---|
//! | `linear_spring` | `k`, `x0 = 0` |
//! | `viscous_damper` | `c` |
//! | `cubic_spring` | `k1`, `k3` |
//! | `hertz` | `position`, `k`, `n1 = 1.5`, `b = 0`, `n2 = 1.5`, `n3 = 1`; `side = "upper"` |
//! | `dry_friction` | `t`, `eps` (the friction's `v/√(v²+ε²)` sign) |
//!
//! A surface is a stop `position` on its coordinate: `side = "upper"` (the default) for a
//! contact where the coordinate reaches it from below, `"lower"` from above. Without
//! `restitution` it only counts impacts (the contact force is an element, e.g. `hertz`);
//! with `restitution = e` it is a rigid stop with Newton's impact law, run with chattering
//! and sticking ([`run_with_sticking`](crate::drive::run_with_sticking)), which drives one
//! rigid contact: such a surface must be the only one.
//!
//! A shard runs the points of a system without a rigid surface (and with at most 16
//! elements and 8 loads) together in SIMD lanes, as it runs the catalogue's: each law's
//! lane form, chosen by the law's kind once per stage for all lanes; every point's record
//! is the one-by-one run's to the bit. A system with a rigid surface runs its points one by
//! one.
//!
//! [`model::Mechanical`]: crate::model::Mechanical

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::StudyError;
use super::scalar::{self, MAX_SURFACES};
use super::system::{
    ParameterDef, ParameterPoint, PointRun, PointStart, RunSettings, StudySystem, is_initial_name,
};
use crate::event::{Gap, NewtonImpact};
use crate::excite::Harmonic;
use crate::force::{
    ContactOnset, CubicSpring, DryFriction, HertzContact, LinearSpring, Side, ViscousDamper,
};
use crate::model::{Coordinate, Element, Elements, Load, Loads, Mechanical};
use crate::{Dynamics, ForceLaw, ParameterError};

mod lanes;

/// The most degrees of freedom of a described system.
pub const MAX_DESCRIBED_DOFS: usize = 4;

/// A number of a described system, or the name of a parameter (`system.parameters` or a
/// grid axis; `"-name"` for its negative).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum SpecValue {
    /// A number.
    Number(f64),
    /// A parameter's name.
    Parameter(String),
}

/// An element of a described system: a force law on a coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElementSpec {
    /// The law: `linear_spring`, `viscous_damper`, `cubic_spring`, `hertz`, `dry_friction`
    /// (see the [table](super#a-system-described-in-the-study-file)).
    pub law: String,
    /// The degree of freedom `i` (from 0) the law acts on, or
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dof: Option<usize>,
    /// the pair `[i, j]` of the relative coordinate `q_i − q_j` (read as a list: any other
    /// length is an error of the spec naming the field, not an index dropped or missing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub between: Option<Vec<usize>>,
    /// `"upper"` or `"lower"`: the side of a `hertz` stop (default `"upper"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<String>,
    /// The law's parameters by name.
    #[serde(flatten)]
    pub parameters: BTreeMap<String, SpecValue>,
}

/// A harmonic load `amplitude·amplitude_factor·cos(ω t + phase)` on a degree of freedom.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// The degree of freedom (from 0).
    pub dof: usize,
    /// The amplitude.
    pub amplitude: SpecValue,
    /// The phase (rad; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<SpecValue>,
}

/// An impact surface: a stop at `position` on a coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    /// The degree of freedom (from 0), or
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dof: Option<usize>,
    /// the pair `[i, j]` of the relative coordinate `q_i − q_j` (as on an element: exactly
    /// two indices).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub between: Option<Vec<usize>>,
    /// The stop's position on the coordinate.
    pub position: SpecValue,
    /// `"upper"` (the coordinate reaches the stop from below; the default) or `"lower"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<String>,
    /// Newton's restitution coefficient `e ∈ [0, 1]` of a rigid stop; none: the surface
    /// counts the impacts of a compliant contact (an element).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub restitution: Option<SpecValue>,
}

/// The description of a mechanical system in a spec (the `system` table's fields).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Description<'a> {
    pub masses: &'a [SpecValue],
    pub elements: &'a [ElementSpec],
    pub loads: &'a [LoadSpec],
    pub surfaces: &'a [SurfaceSpec],
}

impl Description<'_> {
    /// The first field given, for an error on a model of the catalogue.
    pub fn first_field(&self) -> Option<&'static str> {
        [
            ("system.masses", self.masses.is_empty()),
            ("system.elements", self.elements.is_empty()),
            ("system.loads", self.loads.is_empty()),
            ("system.surfaces", self.surfaces.is_empty()),
        ]
        .into_iter()
        .find(|(_, empty)| !empty)
        .map(|(f, _)| f)
    }
}

/// A law's parameters: each name with its default (`None`: required).
type LawParameters = &'static [(&'static str, Option<f64>)];

/// The built-in laws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LawKind {
    Linear,
    Damper,
    Cubic,
    Hertz,
    Friction,
}

/// The laws, their kinds and their parameters (in the order [`Described::law`] reads them).
const LAWS: &[(&str, LawKind, LawParameters)] = &[
    (
        "linear_spring",
        LawKind::Linear,
        &[("k", None), ("x0", Some(0.0))],
    ),
    ("viscous_damper", LawKind::Damper, &[("c", None)]),
    (
        "cubic_spring",
        LawKind::Cubic,
        &[("k1", None), ("k3", None)],
    ),
    (
        "hertz",
        LawKind::Hertz,
        &[
            ("position", None),
            ("k", None),
            ("n1", Some(1.5)),
            ("b", Some(0.0)),
            ("n2", Some(1.5)),
            ("n3", Some(1.0)),
        ],
    ),
    (
        "dry_friction",
        LawKind::Friction,
        &[("t", None), ("eps", None)],
    ),
];

/// The most parameters of a law (the Hertz stop's).
const MAX_LAW_PARAMETERS: usize = 6;

/// The law's parameter named `name` by its constructor, as the spec names it.
fn spec_name(law: &str, name: &'static str) -> &'static str {
    match (law, name) {
        ("hertz", "x_i") => "position",
        ("hertz", "k_i") => "k",
        ("dry_friction", "T") => "t",
        _ => name,
    }
}

fn invalid(field: impl Into<String>, message: impl Into<String>) -> StudyError {
    StudyError::InvalidSpec {
        field: field.into(),
        message: message.into(),
    }
}

/// Whether `name` can name a parameter: a letter or `_`, then letters, digits, `_`.
fn is_identifier(name: &str) -> bool {
    let mut c = name.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

/// A built-in force law of a described system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Law {
    Linear(LinearSpring<f64>),
    Damper(ViscousDamper<f64>),
    Cubic(CubicSpring<f64>),
    Hertz(HertzContact<f64>),
    Friction(DryFriction<f64>),
}

macro_rules! each_law {
    ($self:expr, $l:ident => $e:expr) => {
        match $self {
            Law::Linear($l) => $e,
            Law::Damper($l) => $e,
            Law::Cubic($l) => $e,
            Law::Hertz($l) => $e,
            Law::Friction($l) => $e,
        }
    };
}

impl ForceLaw<f64> for Law {
    #[inline]
    fn force(&self, x: f64, v: f64) -> f64 {
        each_law!(self, l => l.force(x, v))
    }
    fn partials(&self, x: f64, v: f64) -> (f64, f64) {
        each_law!(self, l => l.partials(x, v))
    }
    fn velocity_exponent(&self) -> Option<f64> {
        each_law!(self, l => l.velocity_exponent())
    }
    fn contact_onset(&self) -> Option<ContactOnset<f64>> {
        each_law!(self, l => l.contact_onset())
    }
}

/// The elements of a described system (built by [`DescribedSystem::model`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DescribedElements<const N: usize>(Vec<Element<f64, N, Law>>);

impl<const N: usize> Elements<f64, N> for DescribedElements<N> {
    #[inline]
    fn add_forces(&self, q: &[f64], qd: &[f64], out: &mut nalgebra::SVector<f64, N>) {
        for e in &self.0 {
            e.add_forces(q, qd, out);
        }
    }
    fn add_tangent(
        &self,
        q: &[f64],
        qd: &[f64],
        k: &mut nalgebra::SMatrix<f64, N, N>,
        c: &mut nalgebra::SMatrix<f64, N, N>,
    ) {
        for e in &self.0 {
            e.add_tangent(q, qd, k, c);
        }
    }
}

/// The loads of a described system (built by [`DescribedSystem::model`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DescribedLoads<const N: usize>(Vec<Load<f64, N, Harmonic<f64>>>);

impl<const N: usize> Loads<f64, N> for DescribedLoads<N> {
    #[inline]
    fn add_forces(&self, t: f64, out: &mut nalgebra::SVector<f64, N>) {
        for l in &self.0 {
            l.add_forces(t, out);
        }
    }
    fn add_rates(&self, t: f64, out: &mut nalgebra::SVector<f64, N>) {
        for l in &self.0 {
            l.add_rates(t, out);
        }
    }
    fn phase(&self, t: f64) -> Option<f64> {
        self.0.iter().find_map(|l| l.phase(t))
    }
    fn time_scale(&self, t: f64) -> Option<f64> {
        self.0
            .iter()
            .fold(None, |m, l| crate::model::shorter(m, l.time_scale(t)))
    }
}

/// A model of `N` degrees of freedom built from a description.
type Model<const N: usize> = Mechanical<f64, N, DescribedElements<N>, DescribedLoads<N>>;

/// The [`Mechanical`] model of a described system of `N` degrees of freedom
/// ([`DescribedSystem::model`]).
pub type DescribedModel<const N: usize> = Model<N>;

/// Why a described system could not be built at a point: the field, what is wrong, and the
/// parameter the value came from (if it came from one).
#[derive(Debug, Clone, PartialEq)]
struct BuildError {
    field: String,
    message: String,
    parameter: Option<String>,
}

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` {}", self.field, self.message)
    }
}

/// A system described in the study file (validated).
#[derive(Debug, Clone)]
pub(crate) struct Described {
    masses: Vec<SpecValue>,
    elements: Vec<ElementSpec>,
    /// The elements' laws, resolved once.
    laws: Vec<ResolvedLaw>,
    loads: Vec<LoadSpec>,
    surfaces: Vec<SurfaceSpec>,
    params: Vec<ParameterDef>,
}

/// A number of the description resolved once against the system's parameters: a number,
/// or the index of a parameter in a point's values (negated: `"-name"`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Resolved {
    Number(f64),
    Parameter { index: usize, negated: bool },
}

impl Resolved {
    /// `v` against `params` (a name that is not among them: an index beyond a point's
    /// values, whose value is NaN).
    fn new(v: &SpecValue, params: &[ParameterDef]) -> Self {
        match v {
            SpecValue::Number(x) => Self::Number(*x),
            SpecValue::Parameter(name) => {
                let (negated, name) = match name.strip_prefix('-') {
                    Some(name) => (true, name),
                    None => (false, name.as_str()),
                };
                let index = params
                    .iter()
                    .position(|d| d.name == name)
                    .unwrap_or(usize::MAX);
                Self::Parameter { index, negated }
            }
        }
    }

    /// The value at `p`.
    fn at(self, p: &ParameterPoint) -> f64 {
        match self {
            Self::Number(x) => x,
            Self::Parameter {
                index,
                negated: false,
            } => p.value(index),
            Self::Parameter {
                index,
                negated: true,
            } => -p.value(index),
        }
    }
}

/// An element's law resolved once: its kind, its side (a Hertz stop's) and its parameters
/// in the order of [`LAWS`] (each the value given, or the default; NaN beyond the law's).
#[derive(Debug, Clone, Copy, PartialEq)]
struct ResolvedLaw {
    kind: LawKind,
    side: Side,
    values: [Resolved; MAX_LAW_PARAMETERS],
}

impl ResolvedLaw {
    /// The law of `e` (checked: a known law; `None` otherwise) against `params`.
    fn new(e: &ElementSpec, params: &[ParameterDef]) -> Option<Self> {
        let (_, kind, list) = LAWS.iter().find(|(l, _, _)| *l == e.law)?;
        let mut values = [Resolved::Number(f64::NAN); MAX_LAW_PARAMETERS];
        for (slot, (name, default)) in values.iter_mut().zip(list.iter()) {
            *slot = match e.parameters.get(*name) {
                Some(v) => Resolved::new(v, params),
                None => Resolved::Number(default.unwrap_or(f64::NAN)),
            };
        }
        let side = match e.side.as_deref() {
            Some("lower") => Side::Lower,
            _ => Side::Upper,
        };
        Some(Self {
            kind: *kind,
            side,
            values,
        })
    }
}

impl Described {
    /// Checks the description's structure (laws, coordinates, names), naming the field.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] naming the first invalid field.
    pub fn new(d: &Description<'_>) -> Result<Self, StudyError> {
        let n = d.masses.len();
        if n == 0 || n > MAX_DESCRIBED_DOFS {
            return Err(invalid(
                "system.masses",
                format!(
                    "a mechanical system needs 1 to {MAX_DESCRIBED_DOFS} masses (one per \
                     degree of freedom); got {n}"
                ),
            ));
        }
        let mut names = ParameterNames::default();
        for (k, m) in d.masses.iter().enumerate() {
            names.note(format!("system.masses[{k}]"), m)?;
        }
        for (i, e) in d.elements.iter().enumerate() {
            check_element(&format!("system.elements[{i}]"), e, n, &mut names)?;
        }
        for (i, l) in d.loads.iter().enumerate() {
            let f = format!("system.loads[{i}]");
            check_coordinate(&f, Some(l.dof), None, n)?;
            names.note(format!("{f}.amplitude"), &l.amplitude)?;
            if let Some(p) = &l.phase {
                names.note(format!("{f}.phase"), p)?;
            }
        }
        check_surfaces(d.surfaces, n, &mut names)?;
        let params = names.definitions();
        let laws = d
            .elements
            .iter()
            .enumerate()
            .map(|(i, e)| {
                ResolvedLaw::new(e, &params).ok_or_else(|| {
                    invalid(
                        format!("system.elements[{i}].law"),
                        format!("unknown law {:?}", e.law),
                    )
                })
            })
            .collect::<Result<Vec<_>, StudyError>>()?;
        Ok(Self {
            masses: d.masses.to_vec(),
            elements: d.elements.to_vec(),
            laws,
            loads: d.loads.to_vec(),
            surfaces: d.surfaces.to_vec(),
            params,
        })
    }

    /// The model at `p` (`N` must be the number of masses).
    fn model<const N: usize>(&self, p: &ParameterPoint) -> Result<Model<N>, BuildError> {
        let mut masses = [0.0; N];
        for (k, (m, v)) in masses.iter_mut().zip(&self.masses).enumerate() {
            *m = self.value(p, v);
            if !(m.is_finite() && *m > 0.0) {
                return Err(build_error(
                    format!("system.masses[{k}]"),
                    v,
                    format!("must be finite and > 0 (got {m})"),
                ));
            }
        }
        let mut elements = Vec::with_capacity(self.elements.len());
        for (i, (e, law)) in self.elements.iter().zip(&self.laws).enumerate() {
            let f = Item("system.elements", i);
            let c = coordinate::<N>(f, e.dof, e.between.as_deref())?;
            elements.push(Element::new(c, self.law(p, f, e, law)?));
        }
        let omega = p.value(OMEGA);
        let factor = p.value(AMPLITUDE_FACTOR);
        let mut loads = Vec::with_capacity(self.loads.len());
        for (i, l) in self.loads.iter().enumerate() {
            let f = Item("system.loads", i);
            let amplitude = self.value(p, &l.amplitude) * factor;
            let phase = l.phase.as_ref().map_or(0.0, |v| self.value(p, v));
            let h = Harmonic::new(amplitude, omega, std::f64::consts::FRAC_PI_2 + phase).map_err(
                |e| {
                    let (name, v) = match e.name {
                        "omega" => ("omega", None),
                        "phase" => ("phase", l.phase.as_ref()),
                        _ => ("amplitude", Some(&l.amplitude)),
                    };
                    let message = format!("must be {} (got {})", e.requirement, e.value);
                    match v {
                        Some(v) => build_error(format!("{f}.{name}"), v, message),
                        None => BuildError {
                            field: "system.parameters.omega".into(),
                            message,
                            parameter: Some("omega".into()),
                        },
                    }
                },
            )?;
            let load = Load::on_dof(l.dof, h).map_err(|e| BuildError {
                field: format!("{f}.dof"),
                message: e.to_string(),
                parameter: None,
            })?;
            loads.push(load);
        }
        let model = Mechanical::with_masses(masses).map_err(|e| BuildError {
            field: "system.masses".into(),
            message: e.to_string(),
            parameter: None,
        })?;
        Ok(model
            .with_elements(DescribedElements(elements))
            .with_loads(DescribedLoads(loads)))
    }

    /// The law of element `e` (field `f`; resolved: `law`) at `p`.
    fn law(
        &self,
        p: &ParameterPoint,
        f: Item,
        e: &ElementSpec,
        law: &ResolvedLaw,
    ) -> Result<Law, BuildError> {
        let fail = |err: ParameterError| {
            let name = spec_name(&e.law, err.name);
            let message = format!("must be {} (got {})", err.requirement, err.value);
            match e.parameters.get(name) {
                Some(v) => build_error(format!("{f}.{name}"), v, message),
                None => BuildError {
                    field: format!("{f}.{name}"),
                    message,
                    parameter: None,
                },
            }
        };
        // The values in the order of the law's parameters in `LAWS`.
        let v = law.values.map(|x| x.at(p));
        Ok(match law.kind {
            LawKind::Linear => {
                let [k, x0, ..] = v;
                Law::Linear(
                    LinearSpring::new(k)
                        .and_then(|l| l.with_rest_position(x0))
                        .map_err(fail)?,
                )
            }
            LawKind::Damper => {
                let [c, ..] = v;
                Law::Damper(ViscousDamper::new(c).map_err(fail)?)
            }
            LawKind::Cubic => {
                let [k1, k3, ..] = v;
                Law::Cubic(CubicSpring::new(k1, k3).map_err(fail)?)
            }
            LawKind::Hertz => {
                let [position, k, n1, b, n2, n3] = v;
                Law::Hertz(
                    HertzContact::new(position, k)
                        .map(|h| h.with_side(law.side))
                        .and_then(|h| h.with_stiffness_exponent(n1))
                        .and_then(|h| h.with_damping(b, n2, n3))
                        .map_err(fail)?,
                )
            }
            LawKind::Friction => {
                let [t, eps, ..] = v;
                Law::Friction(DryFriction::sqrt(t, eps).map_err(fail)?)
            }
        })
    }

    /// The surfaces at `p`.
    fn gaps<const N: usize>(&self, p: &ParameterPoint) -> Result<Vec<Gap<f64, N>>, BuildError> {
        let mut gaps = Vec::with_capacity(self.surfaces.len());
        for (i, s) in self.surfaces.iter().enumerate() {
            let f = Item("system.surfaces", i);
            let c = coordinate::<N>(f, s.dof, s.between.as_deref())?;
            let position = self.value(p, &s.position);
            let c = c.with_offset(-position).map_err(|_| {
                build_error(
                    format!("{f}.position"),
                    &s.position,
                    format!("must be finite (got {position})"),
                )
            })?;
            gaps.push(match s.side.as_deref() {
                Some("lower") => Gap::above(c, ()),
                _ => Gap::below(c, ()),
            });
        }
        Ok(gaps)
    }

    /// The rigid stop at `p`, if the description has one.
    fn rigid<const N: usize>(
        &self,
        p: &ParameterPoint,
        model: &Model<N>,
    ) -> Result<Option<NewtonImpact<f64, N>>, BuildError> {
        let Some((i, e)) = self
            .surfaces
            .iter()
            .enumerate()
            .find_map(|(i, s)| s.restitution.as_ref().map(|e| (i, e)))
        else {
            return Ok(None);
        };
        let gap = self
            .gaps::<N>(p)?
            .into_iter()
            .next()
            .ok_or_else(|| BuildError {
                field: "system.surfaces".into(),
                message: "internal: no surface".into(),
                parameter: None,
            })?;
        let r = self.value(p, e);
        NewtonImpact::new(gap, r, model.mass_matrix())
            .map(Some)
            .map_err(|err| {
                build_error(
                    format!("system.surfaces[{i}].restitution"),
                    e,
                    format!("must be {} (got {})", err.requirement, err.value),
                )
            })
    }

    /// Builds everything at `p` (with `N` degrees of freedom).
    fn check_n<const N: usize>(&self, p: &ParameterPoint) -> Result<(), BuildError> {
        let model = self.model::<N>(p)?;
        self.gaps::<N>(p)?;
        self.rigid::<N>(p, &model)?;
        let omega = p.value(OMEGA);
        if !(omega.is_finite() && omega > 0.0) {
            return Err(BuildError {
                field: "system.parameters.omega".into(),
                message: format!("the forcing frequency must be finite and > 0 (got {omega})"),
                parameter: Some("omega".into()),
            });
        }
        Ok(())
    }

    fn build_check(&self, p: &ParameterPoint) -> Result<(), BuildError> {
        match self.masses.len() {
            1 => self.check_n::<1>(p),
            2 => self.check_n::<2>(p),
            3 => self.check_n::<3>(p),
            4 => self.check_n::<4>(p),
            n => Err(BuildError {
                field: "system.masses".into(),
                message: format!("{n} masses; at most {MAX_DESCRIBED_DOFS}"),
                parameter: None,
            }),
        }
    }

    /// Runs `p` with `N` degrees of freedom (state `M = 2N`, `M2 = 2M`).
    fn run_n<const N: usize, const M: usize, const M2: usize>(
        &self,
        p: &ParameterPoint,
        y0: &[f64],
        s: &RunSettings,
    ) -> Result<PointRun, String>
    where
        Model<N>: Dynamics<f64, M>,
    {
        let e = |e: BuildError| e.to_string();
        let model = self.model::<N>(p).map_err(e)?;
        let period = std::f64::consts::TAU / p.value(OMEGA);
        match self.rigid::<N>(p, &model).map_err(e)? {
            Some(impact) => scalar::run_rigid::<N, M, _, _, _>(s, model, impact, period, y0),
            None => {
                let gaps = self.gaps::<N>(p).map_err(e)?;
                scalar::run_smooth::<M, M2, _, _>(s, model, gaps, period, y0)
            }
        }
    }
}

impl Described {
    /// The value of `v` at `p` (`"-name"`: the parameter's negative).
    fn value(&self, p: &ParameterPoint, v: &SpecValue) -> f64 {
        Resolved::new(v, &self.params).at(p)
    }
}

/// The index of `omega` in a point's values ([`ParameterNames::definitions`]).
const OMEGA: usize = 0;
/// The index of `amplitude_factor` in a point's values.
const AMPLITUDE_FACTOR: usize = 1;

/// The field of item `index` of a list of the description (`system.elements[2]`), formatted
/// only where an error names it.
#[derive(Debug, Clone, Copy)]
struct Item(&'static str, usize);

impl std::fmt::Display for Item {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}[{}]", self.0, self.1)
    }
}

/// The parameters a description names, in the order first met (`omega` and
/// `amplitude_factor` are always parameters and are not listed).
#[derive(Debug, Default)]
struct ParameterNames(Vec<String>);

impl ParameterNames {
    /// Checks the value `v` at `field`: a finite number, or the name of a parameter (then
    /// noted; `"-name"` names `name`).
    fn note(&mut self, field: String, v: &SpecValue) -> Result<(), StudyError> {
        match v {
            SpecValue::Number(x) if !x.is_finite() => {
                Err(invalid(field, format!("must be finite (got {x})")))
            }
            SpecValue::Number(_) => Ok(()),
            SpecValue::Parameter(p) => {
                let p = p.strip_prefix('-').unwrap_or(p);
                if !is_identifier(p) || is_initial_name(p) {
                    return Err(invalid(
                        field,
                        format!(
                            "{p:?} is neither a number nor a parameter name (letters, \
                             digits, '_'; not an initial-condition name such as x0)"
                        ),
                    ));
                }
                if p != "omega" && p != "amplitude_factor" && !self.0.iter().any(|n| n == p) {
                    self.0.push(p.to_string());
                }
                Ok(())
            }
        }
    }

    /// The system's parameters: `omega` (required; index [`OMEGA`]), `amplitude_factor`
    /// (default 1; index [`AMPLITUDE_FACTOR`]), then each name noted (required).
    fn definitions(self) -> Vec<ParameterDef> {
        let mut params = vec![
            ParameterDef::required("omega"),
            ParameterDef::new("amplitude_factor", 1.0),
        ];
        params.extend(self.0.iter().map(|p| ParameterDef::required(p)));
        params
    }
}

/// Checks element `e` (field `f`) of a system of `n` degrees of freedom: a known law on one
/// coordinate, a side only for a `hertz` stop, and the law's parameters.
fn check_element(
    f: &str,
    e: &ElementSpec,
    n: usize,
    names: &mut ParameterNames,
) -> Result<(), StudyError> {
    let Some((_, _, params)) = LAWS.iter().find(|(l, _, _)| *l == e.law) else {
        let known: Vec<&str> = LAWS.iter().map(|(l, _, _)| *l).collect();
        return Err(invalid(
            format!("{f}.law"),
            format!("unknown law {:?}; known: {}", e.law, known.join(", ")),
        ));
    };
    check_coordinate(f, e.dof, e.between.as_deref(), n)?;
    check_side(&format!("{f}.side"), e.side.as_deref())?;
    if e.side.is_some() && e.law != "hertz" {
        return Err(invalid(
            format!("{f}.side"),
            format!("only a hertz stop has a side, not {:?}", e.law),
        ));
    }
    check_law_parameters(f, e, params, names)
}

/// Checks the parameters of element `e` (field `f`) against its law's `params`: each one
/// given is the law's, each one without a default is given, and each value is valid.
fn check_law_parameters(
    f: &str,
    e: &ElementSpec,
    params: LawParameters,
    names: &mut ParameterNames,
) -> Result<(), StudyError> {
    for name in e.parameters.keys() {
        if !params.iter().any(|(p, _)| p == name) {
            let known: Vec<&str> = params.iter().map(|(p, _)| *p).collect();
            return Err(invalid(
                format!("{f}.{name}"),
                format!(
                    "unknown parameter of law {:?}; known: {}",
                    e.law,
                    known.join(", ")
                ),
            ));
        }
    }
    for (p, default) in params.iter() {
        match e.parameters.get(*p) {
            Some(v) => names.note(format!("{f}.{p}"), v)?,
            None if default.is_none() => {
                return Err(invalid(
                    format!("{f}.{p}"),
                    format!("is missing (law {:?})", e.law),
                ));
            }
            None => {}
        }
    }
    Ok(())
}

/// Checks the surfaces of a system of `n` degrees of freedom: at most [`MAX_SURFACES`],
/// each on one coordinate with a valid side and position, and a rigid stop (one with a
/// restitution) only as the only surface.
fn check_surfaces(
    surfaces: &[SurfaceSpec],
    n: usize,
    names: &mut ParameterNames,
) -> Result<(), StudyError> {
    if surfaces.len() > MAX_SURFACES {
        return Err(invalid(
            "system.surfaces",
            format!("{} surfaces; at most {MAX_SURFACES}", surfaces.len()),
        ));
    }
    for (i, s) in surfaces.iter().enumerate() {
        let f = format!("system.surfaces[{i}]");
        check_coordinate(&f, s.dof, s.between.as_deref(), n)?;
        check_side(&format!("{f}.side"), s.side.as_deref())?;
        names.note(format!("{f}.position"), &s.position)?;
        if let Some(e) = &s.restitution {
            names.note(format!("{f}.restitution"), e)?;
            if surfaces.len() > 1 {
                return Err(invalid(
                    format!("{f}.restitution"),
                    "a rigid stop must be the only surface (the drive runs one rigid \
                     contact, with chattering and sticking)",
                ));
            }
        }
    }
    Ok(())
}

/// A build error of the value `v` at `field`.
fn build_error(field: String, v: &SpecValue, message: String) -> BuildError {
    match v {
        SpecValue::Number(_) => BuildError {
            field,
            message,
            parameter: None,
        },
        SpecValue::Parameter(name) => BuildError {
            field,
            message: format!("{message}: parameter {name:?}"),
            parameter: Some(name.strip_prefix('-').unwrap_or(name).to_string()),
        },
    }
}

/// Exactly one of `dof` and `between` (a pair), within the `n` degrees of freedom.
fn check_coordinate(
    f: &str,
    dof: Option<usize>,
    between: Option<&[usize]>,
    n: usize,
) -> Result<(), StudyError> {
    match (dof, between) {
        (Some(i), None) if i < n => Ok(()),
        (Some(i), None) => Err(invalid(
            format!("{f}.dof"),
            format!("{i} is not a degree of freedom of {n} (0 to {})", n - 1),
        )),
        (None, Some(&[i, j])) if i < n && j < n && i != j => Ok(()),
        (None, Some(&[i, j])) => Err(invalid(
            format!("{f}.between"),
            format!(
                "[{i}, {j}] must be two different degrees of freedom of {n} (0 to {})",
                n - 1
            ),
        )),
        (None, Some(other)) => Err(invalid(
            format!("{f}.between"),
            format!(
                "{other:?} has length {}: expected a pair [i, j] of two different degrees of \
                 freedom of {n} (0 to {})",
                other.len(),
                n - 1
            ),
        )),
        (Some(_), Some(_)) => Err(invalid(
            format!("{f}.between"),
            "give either dof or between, not both",
        )),
        (None, None) => Err(invalid(
            format!("{f}.dof"),
            "is missing: give dof = i or between = [i, j]",
        )),
    }
}

/// `None`, `"upper"` or `"lower"`.
fn check_side(field: &str, side: Option<&str>) -> Result<(), StudyError> {
    match side {
        None | Some("upper") | Some("lower") => Ok(()),
        Some(other) => Err(invalid(
            field,
            format!("{other:?}: expected \"upper\" or \"lower\""),
        )),
    }
}

/// The coordinate `dof` or `between` (checked by [`check_coordinate`]).
fn coordinate<const N: usize>(
    f: Item,
    dof: Option<usize>,
    between: Option<&[usize]>,
) -> Result<Coordinate<f64, N>, BuildError> {
    let c = match (dof, between) {
        (Some(i), _) => Coordinate::dof(i),
        (None, Some(&[i, j])) => Coordinate::relative(i, j),
        // Neither, or not a pair: refused by the check; an index out of range here.
        (None, _) => Coordinate::dof(usize::MAX),
    };
    c.map_err(|e| BuildError {
        field: format!("{f}.{}", if dof.is_some() { "dof" } else { "between" }),
        message: e.to_string(),
        parameter: None,
    })
}

impl StudySystem for Described {
    fn name(&self) -> &str {
        "mechanical"
    }
    fn parameters(&self) -> &[ParameterDef] {
        &self.params
    }
    fn dimension(&self) -> usize {
        2 * self.masses.len()
    }
    fn surfaces(&self) -> usize {
        self.surfaces.len()
    }
    fn scales(&self) -> Vec<f64> {
        vec![1.0; self.dimension()]
    }
    fn atol_per_rtol(&self) -> Vec<f64> {
        vec![1.0; self.dimension()]
    }
    fn d0(&self) -> f64 {
        1e-6
    }
    fn check(&self, p: &ParameterPoint) -> Result<(), String> {
        self.build_check(p).map_err(|e| e.to_string())
    }
    fn check_fixed(
        &self,
        p: &ParameterPoint,
        on_axes: &dyn Fn(&str) -> bool,
    ) -> Result<(), StudyError> {
        match self.build_check(p) {
            Ok(()) => Ok(()),
            // A value from an axis parameter: the axis check names the axis.
            Err(e) if e.parameter.as_deref().is_some_and(on_axes) => Ok(()),
            Err(e) => Err(invalid(e.field, e.message)),
        }
    }
    fn rest_state(&self, _p: &ParameterPoint) -> Result<Vec<f64>, String> {
        Ok(vec![0.0; self.dimension()])
    }
    fn run(&self, p: &ParameterPoint, y0: &[f64], s: &RunSettings) -> Result<PointRun, String> {
        match self.masses.len() {
            1 => self.run_n::<1, 2, 4>(p, y0, s),
            2 => self.run_n::<2, 4, 8>(p, y0, s),
            3 => self.run_n::<3, 6, 12>(p, y0, s),
            4 => self.run_n::<4, 8, 16>(p, y0, s),
            n => Err(format!("{n} masses; at most {MAX_DESCRIBED_DOFS}")),
        }
    }
    /// A smooth system (no rigid surface) with at most
    /// [`MAX_LANE_ELEMENTS`](lanes::MAX_LANE_ELEMENTS) elements and
    /// [`MAX_LANE_LOADS`](lanes::MAX_LANE_LOADS) loads runs in lanes.
    fn in_lanes(&self) -> bool {
        self.surfaces.iter().all(|s| s.restitution.is_none())
            && self.elements.len() <= lanes::MAX_LANE_ELEMENTS
            && self.loads.len() <= lanes::MAX_LANE_LOADS
    }
    fn run_batch(&self, points: &[PointStart], s: &RunSettings) -> Vec<Result<PointRun, String>> {
        if !self.in_lanes() {
            // A rigid surface, or more elements or loads than the lane form holds.
            return super::system::one_by_one(self, points, s);
        }
        match self.masses.len() {
            1 => self.batch_n::<1, 2, 4>(points, s),
            2 => self.batch_n::<2, 4, 8>(points, s),
            3 => self.batch_n::<3, 6, 12>(points, s),
            4 => self.batch_n::<4, 8, 16>(points, s),
            n => vec![Err(format!("{n} masses; at most {MAX_DESCRIBED_DOFS}")); points.len()],
        }
    }
}

impl Described {
    /// The points of a smooth system in lanes ([`run_smooth_batch`](super::lanes)): what
    /// [`run_n`](Self::run_n) gives for each, to the bit.
    fn batch_n<const N: usize, const M: usize, const M2: usize>(
        &self,
        points: &[PointStart],
        s: &RunSettings,
    ) -> Vec<Result<PointRun, String>>
    where
        Model<N>: Dynamics<f64, M> + crate::LaneDynamics<M>,
        Gap<f64, N>: crate::event::EventFunction<f64, M>,
    {
        let starts = points.iter().map(|p| {
            let (p, y0) = p.as_ref().map_err(Clone::clone)?;
            let e = |e: BuildError| e.to_string();
            let model = self.model::<N>(p).map_err(e)?;
            let gaps = self.gaps::<N>(p).map_err(e)?;
            let period = std::f64::consts::TAU / p.value(OMEGA);
            Ok((model, gaps, period, y0.clone()))
        });
        super::lanes::run_smooth_batch::<M, M2, _, _>(s, starts.collect())
    }
}

/// A mechanical system described with the study files' schema (the `system` table with
/// `model = "mechanical"`), at fixed parameter values: what a study builds at each grid
/// point, for a caller that runs it with the crate's instruments (the Python package's
/// described systems).
///
/// ```
/// use nonsmooth::study::{DescribedSystem, SystemSpec};
/// let spec: SystemSpec = toml::from_str(r#"
///     model = "mechanical"
///     masses = [1.0]
///     parameters = { omega = 1.2 }
///     elements = [{ law = "linear_spring", dof = 0, k = 1.0 }]
///     loads = [{ dof = 0, amplitude = 0.1 }]
/// "#).unwrap();
/// let system = DescribedSystem::new(&spec)?;
/// assert_eq!((system.dofs(), system.parameter("omega")), (1, Some(1.2)));
/// let model = system.model::<1>()?;
/// # let _ = model;
/// # Ok::<(), nonsmooth::study::StudyError>(())
/// ```
#[derive(Debug, Clone)]
pub struct DescribedSystem {
    described: Described,
    point: ParameterPoint,
}

impl DescribedSystem {
    /// The system of description `d` with the parameter values `parameters` (the study's
    /// `system` table; [`DescribedSystem::new`] reads it from a [`SystemSpec`](super::SystemSpec)).
    pub(super) fn from_description(
        d: &Description<'_>,
        parameters: &BTreeMap<String, f64>,
    ) -> Result<Self, StudyError> {
        let described = Described::new(d)?;
        let point = described.point(parameters)?;
        Self::at(described, point)
    }

    fn at(described: Described, point: ParameterPoint) -> Result<Self, StudyError> {
        if let Some(d) = described
            .params
            .iter()
            .zip(point.values())
            .find_map(|(d, v)| (d.default.is_none() && v.is_nan()).then_some(d))
        {
            return Err(invalid(
                format!("system.parameters.{}", d.name),
                "is missing: the description uses this parameter and it has no default",
            ));
        }
        described
            .build_check(&point)
            .map_err(|e| invalid(e.field, e.message))?;
        Ok(Self { described, point })
    }

    /// The number of degrees of freedom (masses); the state has twice as many components.
    pub fn dofs(&self) -> usize {
        self.described.masses.len()
    }

    /// The number of impact surfaces.
    pub fn surfaces(&self) -> usize {
        self.described.surfaces.len()
    }

    /// Whether the (only) surface is a rigid stop with Newton's impact law.
    pub fn is_rigid(&self) -> bool {
        self.described
            .surfaces
            .iter()
            .any(|s| s.restitution.is_some())
    }

    /// The value of parameter `name`, if the system has one.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        self.described
            .parameter_index(name)
            .map(|i| self.point.value(i))
    }

    /// Every parameter and its value (`omega`, `amplitude_factor`, then the names the
    /// description uses), by name.
    pub fn parameters(&self) -> Vec<(String, f64)> {
        self.described
            .params
            .iter()
            .zip(self.point.values())
            .map(|(d, &v)| (d.name.clone(), v))
            .collect()
    }

    /// The system with parameter `name` set to `value`.
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] for an unknown name or a value the model rejects.
    pub fn with_parameter(&self, name: &str, value: f64) -> Result<Self, StudyError> {
        let index = self.described.parameter_index(name).ok_or_else(|| {
            invalid(
                format!("system.parameters.{name}"),
                format!(
                    "unknown parameter; known: {}",
                    self.described.parameter_list()
                ),
            )
        })?;
        let mut point = self.point.clone();
        point.set(index, value);
        Self::at(self.described.clone(), point)
    }

    /// The forcing period `2π/ω`.
    pub fn period(&self) -> f64 {
        std::f64::consts::TAU / self.point.value(OMEGA)
    }

    fn check_dofs<const N: usize>(&self) -> Result<(), StudyError> {
        if N == self.dofs() {
            Ok(())
        } else {
            Err(invalid(
                "system.masses",
                format!("{} degrees of freedom, built as {N}", self.dofs()),
            ))
        }
    }

    /// The model (`N` must be [`dofs`](Self::dofs)).
    ///
    /// # Errors
    /// [`StudyError::InvalidSpec`] if `N` is not the number of degrees of freedom.
    pub fn model<const N: usize>(&self) -> Result<DescribedModel<N>, StudyError> {
        self.check_dofs::<N>()?;
        self.described
            .model::<N>(&self.point)
            .map_err(|e| invalid(e.field, e.message))
    }

    /// The impact surfaces, surface `k` as [`Gap`] `k` (the penetration rises through 0 at
    /// an impact); as events of one run: [`SurfaceEvents`](super::SurfaceEvents).
    ///
    /// # Errors
    /// As [`model`](Self::model).
    pub fn gaps<const N: usize>(&self) -> Result<Vec<Gap<f64, N>>, StudyError> {
        self.check_dofs::<N>()?;
        self.described
            .gaps::<N>(&self.point)
            .map_err(|e| invalid(e.field, e.message))
    }

    /// The rigid stop's impact law, if the surface has a restitution.
    ///
    /// # Errors
    /// As [`model`](Self::model).
    pub fn rigid_stop<const N: usize>(&self) -> Result<Option<NewtonImpact<f64, N>>, StudyError> {
        let model = self.model::<N>()?;
        self.described
            .rigid::<N>(&self.point, &model)
            .map_err(|e| invalid(e.field, e.message))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_sides() {
        assert!(is_identifier("gap") && is_identifier("_k2") && is_identifier("K"));
        assert!(!is_identifier("") && !is_identifier("2k") && !is_identifier("a-b"));
        assert_eq!(spec_name("hertz", "x_i"), "position");
        assert_eq!(spec_name("linear_spring", "k"), "k");
        assert!(check_side("f", Some("sideways")).is_err());
        assert!(check_coordinate("f", Some(2), None, 2).is_err());
        assert!(check_coordinate("f", None, Some(&[1, 1]), 2).is_err());
        assert!(check_coordinate("f", None, None, 2).is_err());
        assert!(check_coordinate("f", None, Some(&[1, 0]), 2).is_ok());
        assert!(check_coordinate("f", None, Some(&[1, 0, 1]), 2).is_err());
        assert!(check_coordinate("f", None, Some(&[1]), 2).is_err());
    }

    /// Each law reads its parameters in the order of [`LAWS`]: the laws of a description,
    /// built at a point, are the laws built directly from the same numbers (the defaults
    /// and a parameter's negative among them).
    #[test]
    fn each_law_reads_its_parameters_by_their_names() {
        let el = |law: &str, ps: &[(&str, SpecValue)]| ElementSpec {
            law: law.into(),
            dof: Some(0),
            between: None,
            side: None,
            parameters: ps.iter().map(|(n, v)| (n.to_string(), v.clone())).collect(),
        };
        let num = SpecValue::Number;
        let elements = vec![
            el("linear_spring", &[("k", num(3.0)), ("x0", num(0.25))]),
            el("viscous_damper", &[("c", num(0.5))]),
            el("cubic_spring", &[("k1", num(2.0)), ("k3", num(7.0))]),
            ElementSpec {
                side: Some("lower".into()),
                ..el(
                    "hertz",
                    &[
                        ("position", num(-0.1)),
                        ("k", num(1e3)),
                        ("n1", num(1.25)),
                        ("b", num(0.3)),
                        ("n2", num(1.75)),
                        ("n3", num(0.5)),
                    ],
                )
            },
            el("dry_friction", &[("t", num(0.2)), ("eps", num(1e-3))]),
            el(
                "hertz",
                &[
                    ("position", SpecValue::Parameter("-gap".into())),
                    ("k", num(1e4)),
                ],
            ),
        ];
        let masses = [num(1.0)];
        let d = Described::new(&Description {
            masses: &masses,
            elements: &elements,
            loads: &[],
            surfaces: &[],
        })
        .unwrap();
        let values = BTreeMap::from([("omega".to_string(), 1.0), ("gap".to_string(), 0.2)]);
        let p = d.point(&values).unwrap();
        let want = [
            Law::Linear(
                LinearSpring::new(3.0)
                    .unwrap()
                    .with_rest_position(0.25)
                    .unwrap(),
            ),
            Law::Damper(ViscousDamper::new(0.5).unwrap()),
            Law::Cubic(CubicSpring::new(2.0, 7.0).unwrap()),
            Law::Hertz(
                HertzContact::new(-0.1, 1e3)
                    .unwrap()
                    .with_side(Side::Lower)
                    .with_stiffness_exponent(1.25)
                    .unwrap()
                    .with_damping(0.3, 1.75, 0.5)
                    .unwrap(),
            ),
            Law::Friction(DryFriction::sqrt(0.2, 1e-3).unwrap()),
            Law::Hertz(
                HertzContact::new(-0.2, 1e4)
                    .unwrap()
                    .with_side(Side::Upper)
                    .with_stiffness_exponent(1.5)
                    .unwrap()
                    .with_damping(0.0, 1.5, 1.0)
                    .unwrap(),
            ),
        ];
        for (i, (e, w)) in elements.iter().zip(want).enumerate() {
            let got = d
                .law(&p, Item("system.elements", i), e, &d.laws[i])
                .unwrap();
            assert_eq!(got, w, "{}", e.law);
        }
        assert!(LAWS.iter().all(|(_, _, ps)| ps.len() <= MAX_LAW_PARAMETERS));
    }

    #[test]
    fn the_law_enum_is_the_law() {
        let h = HertzContact::new(0.1, 1e3)
            .unwrap()
            .with_damping(0.2, 1.5, 1.0)
            .unwrap();
        let l = Law::Hertz(h);
        for (x, v) in [(0.05, 1.0), (0.15, -0.3), (0.2, 0.7)] {
            assert_eq!(l.force(x, v).to_bits(), h.force(x, v).to_bits());
            assert_eq!(l.partials(x, v), h.partials(x, v));
        }
        assert_eq!(l.contact_onset(), h.contact_onset());
    }
}
