//! The systems a study runs, by name: the catalogue of [`systems`](crate::systems) behind
//! [`StudySystem`], and the registry ([`CATALOGUE`]).
//!
//! Adding a system is an impl of [`StudySystem`] (usually a few lines over the system's own
//! parameters and [`scalar::run_smooth`] or [`scalar::run_rigid`]) and a line in
//! [`CATALOGUE`].

use std::collections::BTreeMap;
use std::sync::Arc;

use nalgebra::Vector2;

use super::StudyError;
use super::mechanical::{Described, Description};
use super::system::{ParameterDef, ParameterPoint, PointRun, PointStart, RunSettings, StudySystem};
use super::{lanes, scalar};
use crate::ensemble::Ensemble;
use crate::event::Stop;
use crate::integrate::{Dopri5, Tolerances};
use crate::lyapunov::{Norm, TwoTrajectory};
use crate::sample::Regime;
use crate::sweep::{
    IndependentSweep, LaneStart, SweepError, SweepPoint, SweepSystem, run_point, sweep_starts,
};
use crate::systems::paper::{Member, PAPER, PaperParameters};
use crate::systems::{BouncingBallTable, DuffingUeda, TwoDofImpact};
use crate::{Dynamics, ParameterError};

/// A system of the catalogue, made on demand.
type Make = fn() -> Arc<dyn StudySystem>;

/// The registry: each catalogue system by its name in `system.model`.
const CATALOGUE: &[(&str, Make)] = &[
    ("paper", || Arc::new(Paper::new())),
    ("duffing_ueda", || Arc::new(Duffing::new())),
    ("two_dof_impact", || Arc::new(TwoDof::new())),
    ("bouncing_ball", || Arc::new(Ball::new())),
];

/// The model of a system described in the study file.
const MECHANICAL: &str = "mechanical";

/// The names of the systems a spec may name in `system.model`.
pub(crate) fn model_names() -> Vec<&'static str> {
    let mut names: Vec<&str> = CATALOGUE.iter().map(|(n, _)| *n).collect();
    names.push(MECHANICAL);
    names
}

/// The system called `name`: a model of the catalogue, or `"mechanical"`, the system of
/// `description`.
///
/// # Errors
/// [`StudyError::InvalidSpec`] naming `system.model` for an unknown name, a field of the
/// description if it is invalid, or given for a model of the catalogue.
pub(crate) fn system(
    name: &str,
    description: &Description<'_>,
) -> Result<Arc<dyn StudySystem>, StudyError> {
    if name == MECHANICAL {
        return Ok(Arc::new(Described::new(description)?));
    }
    if let Some(field) = description.first_field() {
        return Err(StudyError::InvalidSpec {
            field: field.into(),
            message: format!("describes a system of model = \"{MECHANICAL}\", not of {name:?}"),
        });
    }
    CATALOGUE
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, make)| make())
        .ok_or_else(|| StudyError::InvalidSpec {
            field: "system.model".into(),
            message: format!(
                "unknown model {name:?}; known: {}",
                model_names().join(", ")
            ),
        })
}

fn defs(list: &[(&str, Option<f64>)]) -> Vec<ParameterDef> {
    list.iter()
        .map(|&(n, d)| match d {
            Some(v) => ParameterDef::new(n, v),
            None => ParameterDef::required(n),
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// The paper's cart.

/// The paper's cart ([`PaperParameters`]; `omega` without default, `amplitude_factor` a
/// factor on the unbalance `m0e`). A shard runs its points in SIMD lanes; [`run`] is the
/// scalar reference they reproduce to the bit.
///
/// [`run`]: StudySystem::run
#[derive(Debug)]
pub(crate) struct Paper {
    params: Vec<ParameterDef>,
}

impl Paper {
    fn new() -> Self {
        let p = PAPER;
        Self {
            params: defs(&[
                ("omega", None),
                ("amplitude_factor", Some(1.0)),
                ("m", Some(p.m)),
                ("m0e", Some(p.m0e)),
                ("k", Some(p.k)),
                ("c", Some(p.c)),
                ("t", Some(p.t)),
                ("eps", Some(p.eps)),
                ("k_i", Some(p.k_i)),
                ("b", Some(p.b)),
                ("n1", Some(p.n1)),
                ("n2", Some(p.n2)),
                ("n3", Some(p.n3)),
                ("x_i", Some(p.x_i)),
                ("eta", Some(p.eta)),
            ]),
        }
    }

    /// The parameters at `p` with the factor applied, and `ω`.
    pub(crate) fn at(p: &ParameterPoint) -> (PaperParameters, f64) {
        // The values in the order of `Paper::new`'s list.
        let [
            omega,
            factor,
            m,
            m0e,
            k,
            c,
            t,
            eps,
            k_i,
            b,
            n1,
            n2,
            n3,
            x_i,
            eta,
        ] = p.array();
        let q = PaperParameters {
            m,
            m0e: m0e * factor,
            k,
            c,
            t,
            eps,
            k_i,
            b,
            n1,
            n2,
            n3,
            x_i,
            eta,
        };
        (q, omega)
    }

    /// Impacts: rising crossings of `x = x_I`.
    pub(crate) fn impact_stop(p: &PaperParameters) -> Stop {
        Stop {
            position: 0,
            velocity: 1,
            level: p.x_i,
        }
    }

    /// The integration tolerances and the sweep settings of every point.
    ///
    /// # Errors
    /// The constructors' messages.
    pub(crate) fn integration(
        s: &RunSettings,
    ) -> Result<(Tolerances<f64, 2>, IndependentSweep), String> {
        let e = |e: &dyn std::fmt::Display| e.to_string();
        let atol: [f64; 2] = s
            .atol
            .as_slice()
            .try_into()
            .map_err(|_| "internal: the paper's state has two components".to_string())?;
        let tol = Tolerances::per_component(s.rtol, atol).map_err(|x| e(&x))?;
        let settings = IndependentSweep::new(s.transient, s.record)
            .and_then(|c| c.period_detection(s.period_tol, s.max_period))
            .map_err(|x| e(&x))?
            .max_steps(s.max_steps);
        Ok((tol, settings))
    }

    /// The run of a point from its sweep record (scalar or lanes): the sweep's quantities
    /// and (a second, scalar run from the end state) the top Lyapunov exponent.
    pub(crate) fn point_run<S, F>(
        s: &RunSettings,
        make: F,
        period: f64,
        tol: &Tolerances<f64, 2>,
        pt: &SweepPoint<2>,
    ) -> PointRun
    where
        S: Dynamics<f64, 2>,
        F: Fn() -> crate::Result<S>,
    {
        let lyapunov = s.lyapunov.map(|(periods, d0)| {
            (|| -> crate::Result<(f64, f64)> {
                let scales: [f64; 2] = s.scales.as_slice().try_into().map_err(|_| {
                    ParameterError::new("scales", s.scales.len() as f64, "two components")
                })?;
                let norm = Norm::weighted(scales)?;
                let mut est = TwoTrajectory::<f64, 2, 4, _, _>::with_tolerances(
                    make()?,
                    Dopri5::new,
                    tol,
                    d0,
                    norm,
                )?;
                // The run ended after a whole number of periods: t = 0 has the same phase.
                est.start(0.0, pt.end_state)?;
                let e = est.estimate(period, periods)?;
                Ok((e.exponent, e.spread))
            })()
            .map_err(|e| e.to_string())
        });
        PointRun {
            period: match pt.regime {
                Regime::Periodic(p) => p,
                Regime::NotPeriodic => 0,
            },
            poincare: pt.poincare.iter().map(|p| vec![p[0], p[1]]).collect(),
            impacts_per_period: pt.impacts_per_period,
            impacts_per_surface: vec![pt.impacts_per_period],
            intervals: pt.intervals.clone(),
            lyapunov,
        }
    }
}

impl Paper {
    /// The points in SIMD lanes ([`sweep_starts`] over [`Member`]s, grouped by the impact
    /// surface `x_I`): the results of [`run`](StudySystem::run), to the bit, with the same
    /// messages for what fails.
    fn batch(points: &[PointStart], s: &RunSettings) -> Vec<Result<PointRun, String>> {
        let (tol, settings) = match Self::integration(s) {
            Ok(v) => v,
            Err(m) => return vec![Err(m); points.len()],
        };
        let mut out: Vec<Option<Result<PointRun, String>>> = vec![None; points.len()];
        // One impact surface per ensemble: points are grouped by x_I (a grid axis may move
        // it). The record's parameter is 0, as in the scalar run.
        let mut groups: BTreeMap<u64, Vec<(usize, LaneStart<Member, 2>)>> = BTreeMap::new();
        for (k, p) in points.iter().enumerate() {
            let start = p.as_ref().map_err(Clone::clone).and_then(|(p, y0)| {
                let (q, omega) = Self::at(p);
                let y0 = match y0[..] {
                    [x, v] => Vector2::new(x, v),
                    _ => return Err("internal: the paper's state has two components".into()),
                };
                let m = Member::new(q, omega).map_err(|e| crate::Error::from(e).to_string())?;
                Ok((q.x_i, m.start(y0)))
            });
            match start {
                Err(m) => out[k] = Some(Err(m)),
                Ok((x_i, st)) => groups
                    .entry(x_i.to_bits())
                    .or_default()
                    .push((k, LaneStart { param: 0.0, ..st })),
            }
        }
        for group in groups.values() {
            let stop = Self::impact_stop(group[0].1.system.params());
            let starts: Vec<LaneStart<Member, 2>> = group.iter().map(|(_, st)| *st).collect();
            let run = Ensemble::new(tol)
                .map_err(|e| SweepError::failed(0.0, e))
                .and_then(|e| sweep_starts(&e, &settings, &starts, Some(stop)));
            match run {
                Err(e) => {
                    for (k, _) in group {
                        out[*k] = Some(Err(e.to_string()));
                    }
                }
                Ok(results) => {
                    for ((k, st), r) in group.iter().zip(results) {
                        let m = st.system;
                        out[*k] = Some(r.map_err(|e| e.to_string()).map(|pt| {
                            Self::point_run(s, || Ok(*m.scalar()), m.period(), &tol, &pt)
                        }));
                    }
                }
            }
        }
        out.into_iter()
            .map(|r| r.unwrap_or_else(|| Err("internal: not computed".into())))
            .collect()
    }
}

impl StudySystem for Paper {
    fn name(&self) -> &str {
        "paper"
    }
    fn parameters(&self) -> &[ParameterDef] {
        &self.params
    }
    fn dimension(&self) -> usize {
        2
    }
    fn surfaces(&self) -> usize {
        1
    }
    fn scales(&self) -> Vec<f64> {
        crate::systems::paper::lyapunov::NORM_SCALES.to_vec()
    }
    fn atol_per_rtol(&self) -> Vec<f64> {
        vec![1e-4, 1e-2]
    }
    fn d0(&self) -> f64 {
        crate::systems::paper::lyapunov::D0
    }
    fn check(&self, p: &ParameterPoint) -> Result<(), String> {
        let (q, omega) = Self::at(p);
        q.oscillator::<f64>(omega)
            .map_err(|e| crate::Error::from(e).to_string())?;
        if !(q.m0e > 0.0) {
            let e = ParameterError::new(
                "amplitude_factor",
                q.m0e,
                "such that m0e·amplitude_factor > 0",
            );
            return Err(crate::Error::from(e).to_string());
        }
        Ok(())
    }
    fn rest_state(&self, p: &ParameterPoint) -> Result<Vec<f64>, String> {
        let (q, _) = Self::at(p);
        Ok(vec![
            q.static_equilibrium().map_err(|e| e.to_string())?,
            0.0,
        ])
    }
    fn run(&self, p: &ParameterPoint, y0: &[f64], s: &RunSettings) -> Result<PointRun, String> {
        let e = |e: &dyn std::fmt::Display| e.to_string();
        let (q, omega) = Self::at(p);
        let y0 = match y0 {
            &[x, v] => Vector2::new(x, v),
            _ => return Err("internal: the paper's state has two components".into()),
        };
        let make = || Ok(q.oscillator::<f64>(omega)?);
        let period = std::f64::consts::TAU / omega;
        let (tol, settings) = Self::integration(s)?;
        let cfg = settings.config(vec![0.0]).map_err(|x| e(&x))?;
        let system = make().map_err(|x: crate::Error| e(&x))?;
        let pt = run_point(
            &cfg,
            0.0,
            SweepSystem {
                system,
                period,
                stop: Some(Self::impact_stop(&q)),
            },
            Dopri5::new(tol),
            y0,
            settings.transient,
        )
        .map_err(|x| e(&x))?;
        Ok(Self::point_run(s, make, period, &tol, &pt))
    }
    fn in_lanes(&self) -> bool {
        true
    }
    fn run_batch(&self, points: &[PointStart], s: &RunSettings) -> Vec<Result<PointRun, String>> {
        Self::batch(points, s)
    }
}

// ---------------------------------------------------------------------------------------
// Duffing–Ueda.

/// The Duffing–Ueda oscillator ([`DuffingUeda`]; `amplitude_factor` a factor on `b`).
#[derive(Debug)]
struct Duffing {
    params: Vec<ParameterDef>,
}

impl Duffing {
    fn new() -> Self {
        let d = DuffingUeda::default();
        Self {
            params: defs(&[
                ("omega", Some(d.omega)),
                ("amplitude_factor", Some(1.0)),
                ("k", Some(d.k)),
                ("b", Some(d.b)),
            ]),
        }
    }

    fn at(p: &ParameterPoint) -> DuffingUeda {
        // The values in the order of `Duffing::new`'s list.
        let [omega, factor, k, b] = p.array();
        DuffingUeda {
            k,
            b: b * factor,
            omega,
        }
    }
}

impl StudySystem for Duffing {
    fn name(&self) -> &str {
        "duffing_ueda"
    }
    fn parameters(&self) -> &[ParameterDef] {
        &self.params
    }
    fn dimension(&self) -> usize {
        2
    }
    fn surfaces(&self) -> usize {
        0
    }
    fn scales(&self) -> Vec<f64> {
        vec![1.0, 1.0]
    }
    fn atol_per_rtol(&self) -> Vec<f64> {
        vec![1.0, 1.0]
    }
    fn d0(&self) -> f64 {
        1e-6
    }
    fn check(&self, p: &ParameterPoint) -> Result<(), String> {
        Self::at(p)
            .model::<f64>()
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
    fn rest_state(&self, _p: &ParameterPoint) -> Result<Vec<f64>, String> {
        Ok(vec![0.0, 0.0])
    }
    fn run(&self, p: &ParameterPoint, y0: &[f64], s: &RunSettings) -> Result<PointRun, String> {
        let d = Self::at(p);
        let model = d.model::<f64>().map_err(|e| e.to_string())?;
        scalar::run_smooth::<2, 4, _, Stop>(s, model, Vec::new(), d.period(), y0)
    }
    fn in_lanes(&self) -> bool {
        true
    }
    fn run_batch(&self, points: &[PointStart], s: &RunSettings) -> Vec<Result<PointRun, String>> {
        let starts = points.iter().map(|p| {
            let (p, y0) = p.as_ref().map_err(Clone::clone)?;
            let d = Self::at(p);
            let model = d.model::<f64>().map_err(|e| e.to_string())?;
            Ok((model, Vec::<Stop>::new(), d.period(), y0.clone()))
        });
        lanes::run_smooth_batch::<2, 4, _, _>(s, starts.collect())
    }
}

// ---------------------------------------------------------------------------------------
// The 2-DOF impact oscillator.

/// The 2-DOF impact oscillator ([`TwoDofImpact`]; `omega` the forcing frequency, default
/// 0.7 near the primary resonance; `amplitude_factor` a factor on `force`). One surface:
/// the stop of the secondary mass.
#[derive(Debug)]
struct TwoDof {
    params: Vec<ParameterDef>,
}

impl TwoDof {
    fn new() -> Self {
        let d = TwoDofImpact::default();
        Self {
            params: defs(&[
                ("omega", Some(0.7)),
                ("amplitude_factor", Some(1.0)),
                ("m1", Some(d.m1)),
                ("m2", Some(d.m2)),
                ("k1", Some(d.k1)),
                ("k2", Some(d.k2)),
                ("c1", Some(d.c1)),
                ("c2", Some(d.c2)),
                ("force", Some(d.force)),
                ("gap", Some(d.gap)),
                ("k_contact", Some(d.k_contact)),
                ("b_contact", Some(d.b_contact)),
            ]),
        }
    }

    fn at(p: &ParameterPoint) -> (TwoDofImpact, f64) {
        // The values in the order of `TwoDof::new`'s list.
        let [
            omega,
            factor,
            m1,
            m2,
            k1,
            k2,
            c1,
            c2,
            force,
            gap,
            k_contact,
            b_contact,
        ] = p.array();
        (
            TwoDofImpact {
                m1,
                m2,
                k1,
                k2,
                c1,
                c2,
                force: force * factor,
                gap,
                k_contact,
                b_contact,
            },
            omega,
        )
    }
}

impl StudySystem for TwoDof {
    fn name(&self) -> &str {
        "two_dof_impact"
    }
    fn parameters(&self) -> &[ParameterDef] {
        &self.params
    }
    fn dimension(&self) -> usize {
        4
    }
    fn surfaces(&self) -> usize {
        1
    }
    fn scales(&self) -> Vec<f64> {
        vec![0.1; 4]
    }
    fn atol_per_rtol(&self) -> Vec<f64> {
        vec![0.01; 4]
    }
    fn d0(&self) -> f64 {
        1e-6
    }
    fn check(&self, p: &ParameterPoint) -> Result<(), String> {
        let (d, omega) = Self::at(p);
        let e = |e: crate::Error| e.to_string();
        d.model::<f64>(omega).map_err(e)?;
        d.stop::<f64>().map(|_| ()).map_err(e)
    }
    fn rest_state(&self, _p: &ParameterPoint) -> Result<Vec<f64>, String> {
        Ok(vec![0.0; 4])
    }
    fn run(&self, p: &ParameterPoint, y0: &[f64], s: &RunSettings) -> Result<PointRun, String> {
        let (d, omega) = Self::at(p);
        let e = |e: crate::Error| e.to_string();
        let model = d.model::<f64>(omega).map_err(e)?;
        let stop = d.stop::<f64>().map_err(e)?;
        scalar::run_smooth::<4, 8, _, _>(s, model, vec![stop], TwoDofImpact::period(omega), y0)
    }
    fn in_lanes(&self) -> bool {
        true
    }
    fn run_batch(&self, points: &[PointStart], s: &RunSettings) -> Vec<Result<PointRun, String>> {
        let starts = points.iter().map(|p| {
            let (p, y0) = p.as_ref().map_err(Clone::clone)?;
            let (d, omega) = Self::at(p);
            let e = |e: crate::Error| e.to_string();
            let model = d.model::<f64>(omega).map_err(e)?;
            let stop = d.stop::<f64>().map_err(e)?;
            Ok((model, vec![stop], TwoDofImpact::period(omega), y0.clone()))
        });
        lanes::run_smooth_batch::<4, 8, _, _>(s, starts.collect())
    }
}

// ---------------------------------------------------------------------------------------
// The ball on a vibrating table.

/// The ball on a vibrating table ([`BouncingBallTable`]): `gamma = Aω²/g`, `e`, `omega`,
/// `g`, `amplitude_factor` a factor on the table's amplitude. Rigid impacts with Newton
/// restitution, chattering and sticking ([`scalar::run_rigid`]). The default start leaves
/// the table at `t = 0` at 2 m/s relative to it (as the example `bouncing_ball` does).
#[derive(Debug)]
struct Ball {
    params: Vec<ParameterDef>,
}

impl Ball {
    fn new() -> Self {
        Self {
            params: defs(&[
                ("omega", Some(std::f64::consts::TAU)),
                ("amplitude_factor", Some(1.0)),
                ("gamma", Some(1.5)),
                ("e", Some(0.9)),
                ("g", Some(9.81)),
            ]),
        }
    }

    fn at(p: &ParameterPoint) -> BouncingBallTable {
        // The values in the order of `Ball::new`'s list.
        let [omega, factor, gamma, e, g] = p.array();
        BouncingBallTable {
            g,
            amplitude: gamma * g / (omega * omega) * factor,
            omega,
            e,
        }
    }
}

impl StudySystem for Ball {
    fn name(&self) -> &str {
        "bouncing_ball"
    }
    fn parameters(&self) -> &[ParameterDef] {
        &self.params
    }
    fn dimension(&self) -> usize {
        2
    }
    fn surfaces(&self) -> usize {
        1
    }
    fn scales(&self) -> Vec<f64> {
        vec![0.1, 1.0]
    }
    fn atol_per_rtol(&self) -> Vec<f64> {
        vec![0.01, 0.1]
    }
    fn d0(&self) -> f64 {
        1e-6
    }
    fn check(&self, p: &ParameterPoint) -> Result<(), String> {
        let b = Self::at(p);
        let e = |e: crate::Error| e.to_string();
        b.model::<f64>().map_err(e)?;
        b.impact::<f64>().map(|_| ()).map_err(e)
    }
    fn rest_state(&self, p: &ParameterPoint) -> Result<Vec<f64>, String> {
        Ok(vec![0.0, Self::at(p).table_motion(0.0).1 + 2.0])
    }
    fn run(&self, p: &ParameterPoint, y0: &[f64], s: &RunSettings) -> Result<PointRun, String> {
        let b = Self::at(p);
        let e = |e: crate::Error| e.to_string();
        let model = b.model::<f64>().map_err(e)?;
        let impact = b.impact::<f64>().map_err(e)?;
        scalar::run_rigid::<1, 2, _, _, _>(s, model, impact, b.period(), y0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each parameter set by name to a value of its own (2, 3, 4, … in the system's order):
    /// the point and the values by name.
    fn distinct(system: &dyn StudySystem) -> (ParameterPoint, BTreeMap<String, f64>) {
        let values: BTreeMap<String, f64> = system
            .parameters()
            .iter()
            .enumerate()
            .map(|(k, d)| (d.name.clone(), 2.0 + k as f64))
            .collect();
        (system.point(&values).unwrap(), values)
    }

    /// The `at` of each system of the catalogue reads every parameter at its index: a point
    /// whose parameters are set by name gives each field the value of its own name.
    #[test]
    fn each_system_reads_its_parameters_by_their_names() {
        let (p, v) = distinct(&Paper::new());
        let (q, omega) = Paper::at(&p);
        assert_eq!(omega, v["omega"]);
        let fields = [
            (q.m, "m"),
            (q.k, "k"),
            (q.c, "c"),
            (q.t, "t"),
            (q.eps, "eps"),
            (q.k_i, "k_i"),
            (q.b, "b"),
            (q.n1, "n1"),
            (q.n2, "n2"),
            (q.n3, "n3"),
            (q.x_i, "x_i"),
            (q.eta, "eta"),
        ];
        for (got, name) in fields {
            assert_eq!(got, v[name], "{name}");
        }
        assert_eq!(q.m0e, v["m0e"] * v["amplitude_factor"]);

        let (p, v) = distinct(&Duffing::new());
        let d = Duffing::at(&p);
        assert_eq!([d.k, d.omega], [v["k"], v["omega"]]);
        assert_eq!(d.b, v["b"] * v["amplitude_factor"]);

        let (p, v) = distinct(&TwoDof::new());
        let (d, omega) = TwoDof::at(&p);
        let fields = [
            (omega, "omega"),
            (d.m1, "m1"),
            (d.m2, "m2"),
            (d.k1, "k1"),
            (d.k2, "k2"),
            (d.c1, "c1"),
            (d.c2, "c2"),
            (d.gap, "gap"),
            (d.k_contact, "k_contact"),
            (d.b_contact, "b_contact"),
        ];
        for (got, name) in fields {
            assert_eq!(got, v[name], "{name}");
        }
        assert_eq!(d.force, v["force"] * v["amplitude_factor"]);

        let (p, v) = distinct(&Ball::new());
        let b = Ball::at(&p);
        assert_eq!([b.g, b.omega, b.e], [v["g"], v["omega"], v["e"]]);
        let (omega, g) = (v["omega"], v["g"]);
        assert_eq!(
            b.amplitude,
            v["gamma"] * g / (omega * omega) * v["amplitude_factor"]
        );
    }
}
