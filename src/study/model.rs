//! The models a study can run, by name, and their parameters by name.

use std::collections::BTreeMap;

use super::StudyError;
use crate::systems::DuffingUeda;
use crate::systems::paper::{PAPER, PaperParameters};

/// A model of the catalogue.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ModelKind {
    /// The paper's cart ([`PaperParameters`]).
    Paper,
    /// The Duffing–Ueda oscillator ([`DuffingUeda`]).
    DuffingUeda,
}

const PAPER_NAMES: &[&str] = &[
    "omega",
    "amplitude_factor",
    "m",
    "m0e",
    "k",
    "c",
    "t",
    "eps",
    "k_i",
    "b",
    "n1",
    "n2",
    "n3",
    "x_i",
    "eta",
];
const DUFFING_NAMES: &[&str] = &["omega", "amplitude_factor", "k", "b"];

impl ModelKind {
    /// The model called `name`.
    pub(crate) fn parse(name: &str) -> Result<Self, StudyError> {
        match name {
            "paper" => Ok(Self::Paper),
            "duffing_ueda" => Ok(Self::DuffingUeda),
            other => Err(StudyError::InvalidSpec {
                field: "system.model".into(),
                message: format!("unknown model {other:?}; known: paper, duffing_ueda"),
            }),
        }
    }

    /// The parameter names a spec may set or sweep.
    pub(crate) fn parameter_names(self) -> &'static [&'static str] {
        match self {
            Self::Paper => PAPER_NAMES,
            Self::DuffingUeda => DUFFING_NAMES,
        }
    }

    /// Whether `omega` has no default.
    pub(crate) fn requires_omega(self) -> bool {
        self == Self::Paper
    }

    /// Characteristic scales of `(x, v)`: the Lyapunov norm, attractor cells, period
    /// detection.
    pub(crate) fn scales(self) -> [f64; 2] {
        match self {
            Self::Paper => crate::systems::paper::lyapunov::NORM_SCALES,
            Self::DuffingUeda => [1.0, 1.0],
        }
    }

    /// Absolute tolerances per unit of `rtol`.
    pub(crate) fn atol_per_rtol(self) -> [f64; 2] {
        match self {
            Self::Paper => [1e-4, 1e-2],
            Self::DuffingUeda => [1.0, 1.0],
        }
    }

    /// Default Lyapunov separation (in the scaled norm).
    pub(crate) fn d0(self) -> f64 {
        match self {
            Self::Paper => crate::systems::paper::lyapunov::D0,
            Self::DuffingUeda => 1e-6,
        }
    }
}

/// The parameters of one point.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ParameterSet {
    /// The paper's cart at `omega` with the unbalance scaled by `factor`.
    Paper {
        /// Parameters.
        p: PaperParameters,
        /// Forcing frequency (NaN until set).
        omega: f64,
        /// Factor on `m0e`.
        factor: f64,
    },
    /// Duffing–Ueda with the amplitude scaled by `factor`.
    DuffingUeda {
        /// Parameters.
        p: DuffingUeda,
        /// Factor on `b`.
        factor: f64,
    },
}

impl ParameterSet {
    /// The model's defaults overridden by `values` (names checked by the spec).
    pub(crate) fn new(kind: ModelKind, values: &BTreeMap<String, f64>) -> Self {
        let mut s = match kind {
            ModelKind::Paper => Self::Paper {
                p: PAPER,
                omega: f64::NAN,
                factor: 1.0,
            },
            ModelKind::DuffingUeda => Self::DuffingUeda {
                p: DuffingUeda::default(),
                factor: 1.0,
            },
        };
        for (k, &v) in values {
            s.set(k, v);
        }
        s
    }

    /// Sets a parameter by name (unknown names are rejected earlier, by the spec).
    pub(crate) fn set(&mut self, name: &str, v: f64) {
        match self {
            Self::Paper { p, omega, factor } => match name {
                "omega" => *omega = v,
                "amplitude_factor" => *factor = v,
                "m" => p.m = v,
                "m0e" => p.m0e = v,
                "k" => p.k = v,
                "c" => p.c = v,
                "t" => p.t = v,
                "eps" => p.eps = v,
                "k_i" => p.k_i = v,
                "b" => p.b = v,
                "n1" => p.n1 = v,
                "n2" => p.n2 = v,
                "n3" => p.n3 = v,
                "x_i" => p.x_i = v,
                "eta" => p.eta = v,
                _ => {}
            },
            Self::DuffingUeda { p, factor } => match name {
                "omega" => p.omega = v,
                "amplitude_factor" => *factor = v,
                "k" => p.k = v,
                "b" => p.b = v,
                _ => {}
            },
        }
    }

    /// The paper's parameters with the factor applied.
    pub(crate) fn paper(&self) -> Option<(PaperParameters, f64)> {
        match self {
            Self::Paper { p, omega, factor } => {
                let mut q = *p;
                q.m0e *= *factor;
                Some((q, *omega))
            }
            Self::DuffingUeda { .. } => None,
        }
    }

    /// Duffing–Ueda's parameters with the factor applied.
    pub(crate) fn duffing(&self) -> Option<DuffingUeda> {
        match self {
            Self::DuffingUeda { p, factor } => {
                let mut q = *p;
                q.b *= *factor;
                Some(q)
            }
            Self::Paper { .. } => None,
        }
    }

    /// Builds the model to check the parameters.
    pub(crate) fn check(&self) -> Result<(), crate::Error> {
        if let Some((p, omega)) = self.paper() {
            p.oscillator::<f64>(omega)?;
            if !(p.m0e > 0.0) {
                return Err(crate::ParameterError::new(
                    "amplitude_factor",
                    p.m0e,
                    "such that m0e·amplitude_factor > 0",
                )
                .into());
            }
        }
        if let Some(d) = self.duffing() {
            d.model::<f64>()?;
        }
        Ok(())
    }
}
