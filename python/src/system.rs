//! Systems: the catalogue's entries and systems described with the study files' schema, as
//! one Python class. A system holds its parameters; instruments build the crate's model
//! from them (every law runs compiled, no Python in the right-hand side).

use std::collections::BTreeMap;

use nonsmooth::study::{DescribedSystem, SystemSpec};
use nonsmooth::systems::paper::{PAPER, PaperParameters};
use nonsmooth::systems::{BouncingBallTable, DuffingUeda, RelayFeedback, TwoDofImpact};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{Fail, Result, value};
use crate::filippov::Belt;

/// A system of the catalogue or a described one, with its parameter values.
#[derive(Debug, Clone)]
pub enum Kind {
    /// The paper's cart against a compliant stop, forced by an unbalanced rotor at `omega`.
    Paper(PaperParameters, f64),
    /// The Duffing–Ueda oscillator.
    Duffing(DuffingUeda),
    /// The 2-DOF impact oscillator forced at `omega`.
    TwoDof(TwoDofImpact, f64),
    /// The ball on a vibrating table (rigid impacts, chattering and sticking).
    Ball(BouncingBallTable),
    /// The relay feedback system (Filippov, sliding).
    Relay(RelayFeedback),
    /// A mechanical system described with the study files' schema.
    Described(DescribedSystem),
    /// The woodpecker toy (time-stepping only).
    Woodpecker,
    /// The belt oscillator (Filippov, sticking as sliding).
    Belt(Belt),
}

fn paper_fields(p: &mut PaperParameters) -> [(&'static str, &mut f64); 13] {
    [
        ("m", &mut p.m),
        ("m0e", &mut p.m0e),
        ("k", &mut p.k),
        ("c", &mut p.c),
        ("t", &mut p.t),
        ("eps", &mut p.eps),
        ("k_i", &mut p.k_i),
        ("b", &mut p.b),
        ("n1", &mut p.n1),
        ("n2", &mut p.n2),
        ("n3", &mut p.n3),
        ("x_i", &mut p.x_i),
        ("eta", &mut p.eta),
    ]
}

fn two_dof_fields(p: &mut TwoDofImpact) -> [(&'static str, &mut f64); 10] {
    [
        ("m1", &mut p.m1),
        ("m2", &mut p.m2),
        ("k1", &mut p.k1),
        ("k2", &mut p.k2),
        ("c1", &mut p.c1),
        ("c2", &mut p.c2),
        ("force", &mut p.force),
        ("gap", &mut p.gap),
        ("k_contact", &mut p.k_contact),
        ("b_contact", &mut p.b_contact),
    ]
}

fn ball_fields(p: &mut BouncingBallTable) -> [(&'static str, &mut f64); 4] {
    [
        ("g", &mut p.g),
        ("amplitude", &mut p.amplitude),
        ("omega", &mut p.omega),
        ("e", &mut p.e),
    ]
}

fn relay_fields(p: &mut RelayFeedback) -> [(&'static str, &mut f64); 3] {
    [
        ("zeta", &mut p.zeta),
        ("omega", &mut p.omega),
        ("sigma", &mut p.sigma),
    ]
}

fn belt_fields(p: &mut Belt) -> [(&'static str, &mut f64); 4] {
    [
        ("f0", &mut p.f0),
        ("omega", &mut p.omega),
        ("u", &mut p.u),
        ("fk", &mut p.fk),
    ]
}

fn duffing_fields(p: &mut DuffingUeda) -> [(&'static str, &mut f64); 3] {
    [("k", &mut p.k), ("b", &mut p.b), ("omega", &mut p.omega)]
}

/// Sets `name` among `fields`, or says which names there are.
fn set_field<const K: usize>(
    model: &str,
    fields: [(&'static str, &mut f64); K],
    name: &str,
    v: f64,
) -> Result<()> {
    let known: Vec<&str> = fields.iter().map(|(n, _)| *n).collect();
    let known = known.join(", ");
    match fields.into_iter().find(|(n, _)| *n == name) {
        Some((_, f)) => {
            *f = v;
            Ok(())
        }
        None => Err(value(format!(
            "unknown parameter {name:?} of {model}; known: {known}"
        ))),
    }
}

impl Kind {
    /// The model's name.
    pub fn name(&self) -> &'static str {
        match self {
            Kind::Paper(..) => "paper",
            Kind::Duffing(_) => "duffing_ueda",
            Kind::TwoDof(..) => "two_dof_impact",
            Kind::Ball(_) => "bouncing_ball",
            Kind::Relay(_) => "relay_feedback",
            Kind::Described(_) => "mechanical",
            Kind::Woodpecker => "woodpecker",
            Kind::Belt(_) => "belt_friction",
        }
    }

    /// The state dimension.
    pub fn dimension(&self) -> usize {
        match self {
            Kind::Paper(..) | Kind::Duffing(_) | Kind::Ball(_) | Kind::Belt(_) => 2,
            Kind::TwoDof(..) => 4,
            Kind::Relay(_) => 3,
            Kind::Described(d) => 2 * d.dofs(),
            Kind::Woodpecker => 6,
        }
    }

    /// The parameters and their values.
    pub fn parameters(&self) -> Vec<(String, f64)> {
        let list = |f: &mut dyn FnMut() -> Vec<(&'static str, f64)>| {
            f().into_iter().map(|(n, v)| (n.to_string(), v)).collect()
        };
        match self {
            Kind::Paper(p, omega) => {
                let mut p = *p;
                let mut v: Vec<(String, f64)> =
                    list(&mut || paper_fields(&mut p).map(|(n, v)| (n, *v)).to_vec());
                v.insert(0, ("omega".into(), *omega));
                v
            }
            Kind::Duffing(d) => {
                let mut d = *d;
                list(&mut || duffing_fields(&mut d).map(|(n, v)| (n, *v)).to_vec())
            }
            Kind::TwoDof(p, omega) => {
                let mut p = *p;
                let mut v: Vec<(String, f64)> =
                    list(&mut || two_dof_fields(&mut p).map(|(n, v)| (n, *v)).to_vec());
                v.insert(0, ("omega".into(), *omega));
                v
            }
            Kind::Ball(b) => {
                let mut b = *b;
                list(&mut || ball_fields(&mut b).map(|(n, v)| (n, *v)).to_vec())
            }
            Kind::Relay(r) => {
                let mut r = *r;
                list(&mut || relay_fields(&mut r).map(|(n, v)| (n, *v)).to_vec())
            }
            Kind::Described(d) => d.parameters(),
            Kind::Woodpecker => Vec::new(),
            Kind::Belt(b) => {
                let mut b = *b;
                list(&mut || belt_fields(&mut b).map(|(n, v)| (n, *v)).to_vec())
            }
        }
    }

    /// The value of parameter `name`.
    pub fn parameter(&self, name: &str) -> Result<f64> {
        self.parameters()
            .into_iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
            .ok_or_else(|| {
                let known: Vec<String> = self.parameters().into_iter().map(|(n, _)| n).collect();
                value(format!(
                    "unknown parameter {name:?} of {}; known: {}",
                    self.name(),
                    known.join(", ")
                ))
            })
    }

    /// The system with parameter `name` at `v`, validated (the model is built).
    ///
    /// # Errors
    /// `ValueError` for an unknown name or a value the model rejects, naming it.
    pub fn with_parameter(&self, name: &str, v: f64) -> Result<Kind> {
        let k = match self {
            Kind::Paper(p, omega) => {
                let (mut p, mut omega) = (*p, *omega);
                if name == "omega" {
                    omega = v;
                } else {
                    set_field("paper", paper_fields(&mut p), name, v)?;
                }
                Kind::Paper(p, omega)
            }
            Kind::Duffing(d) => {
                let mut d = *d;
                set_field("duffing_ueda", duffing_fields(&mut d), name, v)?;
                Kind::Duffing(d)
            }
            Kind::TwoDof(p, omega) => {
                let (mut p, mut omega) = (*p, *omega);
                if name == "omega" {
                    omega = v;
                } else {
                    set_field("two_dof_impact", two_dof_fields(&mut p), name, v)?;
                }
                Kind::TwoDof(p, omega)
            }
            Kind::Ball(b) => {
                let mut b = *b;
                set_field("bouncing_ball", ball_fields(&mut b), name, v)?;
                Kind::Ball(b)
            }
            Kind::Relay(r) => {
                let mut r = *r;
                set_field("relay_feedback", relay_fields(&mut r), name, v)?;
                Kind::Relay(r)
            }
            Kind::Described(d) => Kind::Described(d.with_parameter(name, v)?),
            Kind::Woodpecker => {
                return Err(value(format!(
                    "unknown parameter {name:?} of woodpecker; it has none"
                )));
            }
            Kind::Belt(b) => {
                let mut b = *b;
                set_field("belt_friction", belt_fields(&mut b), name, v)?;
                Kind::Belt(b)
            }
        };
        k.validate()?;
        Ok(k)
    }

    /// Builds the model once to check every parameter.
    pub fn validate(&self) -> Result<()> {
        match self {
            Kind::Paper(p, omega) => {
                p.oscillator::<f64>(*omega)?;
            }
            Kind::Duffing(d) => d.validate()?,
            Kind::TwoDof(p, omega) => {
                p.model::<f64>(*omega)?;
            }
            Kind::Ball(b) => b.validate()?,
            Kind::Relay(r) => {
                r.system()?;
            }
            Kind::Described(_) | Kind::Woodpecker => {}
            Kind::Belt(b) => b.validate()?,
        }
        Ok(())
    }

    /// The forcing period (`None` for the autonomous relay system).
    pub fn period(&self) -> Option<f64> {
        match self {
            Kind::Paper(_, omega) => {
                Some(nonsmooth::systems::paper::PaperParameters::period(*omega))
            }
            Kind::Duffing(d) => Some(d.period()),
            Kind::TwoDof(_, omega) => Some(TwoDofImpact::period(*omega)),
            Kind::Ball(b) => Some(b.period()),
            Kind::Relay(_) | Kind::Woodpecker => None,
            Kind::Described(d) => Some(d.period()),
            Kind::Belt(b) => Some(crate::filippov::belt_period(b)),
        }
    }

    /// The default initial state: the paper's static equilibrium against the stop; the
    /// ball 2 m/s above the table's velocity; the relay's test start; the origin otherwise.
    pub fn rest_state(&self) -> Result<Vec<f64>> {
        Ok(match self {
            Kind::Paper(p, _) => vec![p.static_equilibrium()?, 0.0],
            Kind::Ball(b) => vec![0.0, b.table_motion(0.0).1 + 2.0],
            Kind::Relay(_) => RelayFeedback::X0.to_vec(),
            Kind::Woodpecker => {
                use nonsmooth::systems::Woodpecker;
                Woodpecker::Q0
                    .iter()
                    .chain(&Woodpecker::V0)
                    .copied()
                    .collect()
            }
            k => vec![0.0; k.dimension()],
        })
    }

    /// Characteristic scales of the state components (the Lyapunov norm's weights), as the
    /// study tool uses them.
    pub fn scales(&self) -> Vec<f64> {
        match self {
            Kind::Paper(..) => nonsmooth::systems::paper::lyapunov::NORM_SCALES.to_vec(),
            Kind::TwoDof(..) => vec![0.1; 4],
            Kind::Ball(_) => vec![0.1, 1.0],
            k => vec![1.0; k.dimension()],
        }
    }

    /// Absolute tolerances per unit of `rtol`, as the study tool uses them.
    pub fn atol_per_rtol(&self) -> Vec<f64> {
        match self {
            Kind::Paper(..) => vec![1e-4, 1e-2],
            Kind::TwoDof(..) => vec![0.01; 4],
            Kind::Ball(_) => vec![0.01, 0.1],
            Kind::Relay(_) => vec![1e-2; 3],
            k => vec![1.0; k.dimension()],
        }
    }

    /// The default Lyapunov separation (scaled norm).
    pub fn d0(&self) -> f64 {
        match self {
            Kind::Paper(..) => nonsmooth::systems::paper::lyapunov::D0,
            Kind::Relay(_) => 1e-8,
            _ => 1e-6,
        }
    }

    /// The names of the state components.
    pub fn state_names(&self) -> Vec<String> {
        let n = self.dimension();
        match self {
            Kind::Relay(_) => vec!["x1".into(), "x2".into(), "x3".into()],
            Kind::Woodpecker => ["z", "phi_s", "phi_b", "dz", "dphi_s", "dphi_b"]
                .map(String::from)
                .to_vec(),
            _ if n == 2 => vec!["x".into(), "v".into()],
            _ => (1..=n / 2)
                .map(|k| format!("x{k}"))
                .chain((1..=n / 2).map(|k| format!("v{k}")))
                .collect(),
        }
    }
}

/// A dynamical system: a model of the catalogue or one described with the study files'
/// schema, with its parameter values. Build one with `nonsmooth.paper(...)`,
/// `nonsmooth.describe(...)` and the other constructors; pass it to the instruments.
#[pyclass(name = "System", module = "nonsmooth", frozen)]
#[derive(Debug, Clone)]
pub struct PySystem {
    pub kind: Kind,
}

impl PySystem {
    fn checked(kind: Kind) -> PyResult<Self> {
        kind.validate()?;
        Ok(Self { kind })
    }
}

/// `overrides` applied to `kind` one by one.
fn apply(mut kind: Kind, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Kind> {
    if let Some(o) = overrides {
        for (k, v) in o.iter() {
            let name: String = k.extract()?;
            let v: f64 = v
                .extract()
                .map_err(|_| Fail::Value(format!("parameter {name:?} must be a number")))?;
            kind = kind.with_parameter(&name, v)?;
        }
    }
    Ok(kind)
}

#[pymethods]
impl PySystem {
    /// The model's name (`"paper"`, `"duffing_ueda"`, `"two_dof_impact"`,
    /// `"bouncing_ball"`, `"relay_feedback"`, `"mechanical"`).
    #[getter]
    fn name(&self) -> &'static str {
        self.kind.name()
    }

    /// The state dimension (`2N` for `N` degrees of freedom).
    #[getter]
    fn dimension(&self) -> usize {
        self.kind.dimension()
    }

    /// The parameters and their values (SI units for the paper's cart).
    #[getter]
    fn parameters(&self) -> BTreeMap<String, f64> {
        self.kind.parameters().into_iter().collect()
    }

    /// The forcing period `2π/ω` in s (`ValueError` for an autonomous system).
    #[getter]
    fn period(&self) -> PyResult<f64> {
        self.kind.period().ok_or_else(|| {
            Fail::Value(format!(
                "the {} system is autonomous: it has no forcing period",
                self.kind.name()
            ))
            .into()
        })
    }

    /// The default initial state.
    #[getter]
    fn rest_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(py, self.kind.rest_state()?))
    }

    /// The names of the state components (`x, v`; `x1 … xN, v1 … vN`).
    #[getter]
    fn state_names(&self) -> Vec<String> {
        self.kind.state_names()
    }

    /// The characteristic scales of the state components (the Lyapunov norm's weights).
    #[getter]
    fn scales<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.kind.scales())
    }

    /// The same system with some parameters changed (validated).
    #[pyo3(signature = (**overrides))]
    fn with_parameters(&self, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Self::checked(apply(self.kind.clone(), overrides)?)
    }

    fn __repr__(&self) -> String {
        let p: Vec<String> = self
            .kind
            .parameters()
            .iter()
            .map(|(n, v)| format!("{n}={v}"))
            .collect();
        format!("System({}, {})", self.kind.name(), p.join(", "))
    }
}

/// The paper's cart (1 DOF, state `(x, ẋ)` in m, m/s) forced at `omega` rad/s, with the
/// paper's parameters unless overridden by keyword.
#[pyfunction]
#[pyo3(signature = (omega, **overrides))]
pub fn paper(omega: f64, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<PySystem> {
    PySystem::checked(apply(Kind::Paper(PAPER, omega), overrides)?)
}

/// The Duffing–Ueda oscillator `ẍ + kẋ + x³ = B cos ωt`.
#[pyfunction]
#[pyo3(signature = (k = 0.05, b = 7.5, omega = 1.0))]
pub fn duffing_ueda(k: f64, b: f64, omega: f64) -> PyResult<PySystem> {
    PySystem::checked(Kind::Duffing(DuffingUeda { k, b, omega }))
}

/// The 2-DOF impact oscillator forced at `omega`, default parameters unless overridden.
#[pyfunction]
#[pyo3(signature = (omega = 0.7, **overrides))]
pub fn two_dof_impact(omega: f64, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<PySystem> {
    PySystem::checked(apply(
        Kind::TwoDof(TwoDofImpact::default(), omega),
        overrides,
    )?)
}

/// The ball on a table shaken at `Γ = Aω²/g` (ω = 2π rad/s, g = 9.81 m/s²), restitution `e`.
#[pyfunction]
#[pyo3(signature = (gamma = 1.5, e = 0.9))]
pub fn bouncing_ball(gamma: f64, e: f64) -> PyResult<PySystem> {
    Ok(PySystem {
        kind: Kind::Ball(BouncingBallTable::with_gamma(gamma, e).map_err(Fail::from)?),
    })
}

/// The relay feedback system `ẋ = Ax − b sgn(x₁)`.
#[pyfunction]
#[pyo3(signature = (zeta = 0.05, omega = 25.0, sigma = 1.0))]
pub fn relay_feedback(zeta: f64, omega: f64, sigma: f64) -> PyResult<PySystem> {
    PySystem::checked(Kind::Relay(RelayFeedback { zeta, omega, sigma }))
}

/// The belt oscillator `ẍ + x = F₀ cos ωt − F_k sgn(ẋ − u)`: a unit mass on a unit spring
/// rubbing with Coulomb friction `F_k` on a belt moving at `u` (a Filippov system: sticking
/// to the belt is sliding on `ẋ = u`).
#[pyfunction]
#[pyo3(signature = (f0 = 0.6, omega = 2.0, u = 0.5, fk = 1.0))]
pub fn belt_friction(f0: f64, omega: f64, u: f64, fk: f64) -> PyResult<PySystem> {
    PySystem::checked(Kind::Belt(Belt { f0, omega, u, fk }))
}

/// The woodpecker toy of the catalogue (a sleeve and a bird on a pole, three frictional
/// impact contacts): state `(z, φ_S, φ_B)` and their rates; for `timestep` only.
#[pyfunction]
pub fn woodpecker() -> PySystem {
    PySystem {
        kind: Kind::Woodpecker,
    }
}

/// A mechanical system from the JSON text of a study file's `system` table
/// (`model = "mechanical"`); the Python layer converts dicts and TOML files.
#[pyfunction]
pub fn describe_json(text: &str, parameters: BTreeMap<String, f64>) -> PyResult<PySystem> {
    let mut spec: SystemSpec =
        serde_json::from_str(text).map_err(|e| Fail::Value(format!("system description: {e}")))?;
    spec.parameters.extend(parameters);
    Ok(PySystem {
        kind: Kind::Described(DescribedSystem::new(&spec).map_err(Fail::from)?),
    })
}

/// A mechanical system from TOML text: a `system` table, or a whole study file (its
/// `[system]` table is used).
#[pyfunction]
pub fn describe_toml(text: &str, parameters: BTreeMap<String, f64>) -> PyResult<PySystem> {
    let table: toml::Table =
        toml::from_str(text).map_err(|e| Fail::Value(format!("system description: {e}")))?;
    let system = match table.get("system") {
        Some(toml::Value::Table(t)) => t.clone(),
        _ => table,
    };
    let mut spec = SystemSpec::deserialize_from(system)?;
    spec.parameters.extend(parameters);
    Ok(PySystem {
        kind: Kind::Described(DescribedSystem::new(&spec).map_err(Fail::from)?),
    })
}

trait FromToml: Sized {
    fn deserialize_from(t: toml::Table) -> Result<Self>;
}

impl FromToml for SystemSpec {
    fn deserialize_from(t: toml::Table) -> Result<Self> {
        toml::Value::Table(t)
            .try_into()
            .map_err(|e: toml::de::Error| Fail::Value(format!("system description: {e}")))
    }
}

/// Checks a state vector of `n` components: finite values.
pub fn check_state(what: &str, y: &[f64], n: usize) -> Result<()> {
    if y.len() != n {
        return Err(value(format!(
            "{what} has {} components; the system's state has {n}",
            y.len()
        )));
    }
    if let Some((i, v)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(value(format!("{what}[{i}] = {v} is not finite")));
    }
    Ok(())
}
