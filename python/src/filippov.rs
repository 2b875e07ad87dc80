//! Filippov systems (the relay feedback system, the belt oscillator): runs through
//! crossings and sliding, Lyapunov exponents by two trajectories through sliding, periodic
//! orbits with their monodromy (saltation at every transition), and continuation with the
//! sliding bifurcations located. Each instrument is written once over the system and
//! dispatched to the two concrete systems.

use std::f64::consts::TAU;

use nalgebra::SVector;
use nonsmooth::filippov::{Filippov, FilippovSimulation, Plain, Switched, TransitionKind};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{FilippovTwoTrajectory, Norm};
use nonsmooth::orbit::BranchEnd;
use nonsmooth::orbit::sliding::{SlidingBifurcationKind, SlidingContinuation, follow_sliding};

use crate::analysis::{ContinuationSpec, LyapunovSpec, OrbitSpec};
use crate::errors::{Fail, Result, value};
use crate::interrupt::{Watch, state};
use crate::record::Rec;
use crate::runs::{EventLog, RunSpec, Samples, tolerances};
use crate::system::Kind;

/// The belt oscillator `ẍ + x = F₀ cos ωt − F_k sgn(ẋ − u)`: a unit mass on a unit spring
/// rubbing on a belt of speed `u` (sticking is sliding on `ẋ = u`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Belt {
    pub f0: f64,
    pub omega: f64,
    pub u: f64,
    pub fk: f64,
}

impl Default for Belt {
    /// `F₀ = 0.6`, `ω = 2`, `u = 0.5`, `F_k = 1` (the crate's sliding example).
    fn default() -> Self {
        Self {
            f0: 0.6,
            omega: 2.0,
            u: 0.5,
            fk: 1.0,
        }
    }
}

impl Belt {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("f0", self.f0), ("u", self.u)] {
            if !v.is_finite() {
                return Err(value(format!("{name} must be finite (got {v})")));
            }
        }
        for (name, v) in [("omega", self.omega), ("fk", self.fk)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(value(format!("{name} must be finite and > 0 (got {v})")));
            }
        }
        Ok(())
    }
}

/// The belt oscillator as a Filippov system (surface `ẋ − u = 0`).
fn belt(b: Belt) -> impl Filippov<f64, 2, 1> + Clone + Send + Sync + 'static {
    let Belt { f0, omega, u, fk } = b;
    Switched::new(
        move |x: &SVector<f64, 2>| x[1] - u,
        |_x: &SVector<f64, 2>| SVector::from([0.0, 1.0]),
        move |t: f64, x: &SVector<f64, 2>| {
            SVector::from([x[1], -x[0] + f0 * (omega * t).cos() + fk])
        },
        move |t: f64, x: &SVector<f64, 2>| {
            SVector::from([x[1], -x[0] + f0 * (omega * t).cos() - fk])
        },
    )
}

/// A Filippov system and how to build it at other parameter values; `forced`: its
/// forcing period (none for an autonomous system).
pub struct FFamily<Sys> {
    base: Kind,
    build: fn(&Kind) -> Result<Sys>,
}

impl<Sys> FFamily<Sys> {
    fn system(&self) -> Result<Sys> {
        (self.build)(&self.base)
    }
    fn at(&self, name: &str, v: f64) -> Result<Sys> {
        (self.build)(&self.base.with_parameter(name, v)?)
    }
}

/// An instrument over a Filippov system of `N` states and `S` surfaces (`M = N + N²`).
pub trait FVisit {
    type Out;
    fn filippov<const N: usize, const S: usize, const M: usize, Sys>(
        self,
        f: FFamily<Sys>,
    ) -> Result<Self::Out>
    where
        Sys: Filippov<f64, N, S> + Clone + Send + Sync + 'static;
}

fn relay(k: &Kind) -> Result<nonsmooth::filippov::LinearRelay<f64, 3>> {
    let Kind::Relay(r) = k else { unreachable!() };
    Ok(r.system()?)
}

fn belt_of(k: &Kind) -> Result<impl Filippov<f64, 2, 1> + Clone + Send + Sync + use<>> {
    let Kind::Belt(b) = k else { unreachable!() };
    b.validate()?;
    Ok(belt(*b))
}

/// Runs `v` on the Filippov system `kind`.
pub fn visit<V: FVisit>(kind: &Kind, v: V) -> Result<V::Out> {
    let base = kind.clone();
    match kind {
        Kind::Relay(_) => v.filippov::<3, 1, 12, _>(FFamily { base, build: relay }),
        Kind::Belt(_) => v.filippov::<2, 1, 6, _>(FFamily {
            base,
            build: belt_of,
        }),
        _ => Err(value(format!("{} is not a Filippov system", kind.name()))),
    }
}

fn weights<const N: usize>(kind: &Kind) -> Result<Norm<f64, N>> {
    let s = kind.scales();
    let mut arr = [0.0; N];
    arr.copy_from_slice(&s[..N]);
    Ok(Norm::weighted(arr)?)
}

fn kind_name(k: TransitionKind) -> &'static str {
    match k {
        TransitionKind::Crossing => "crossing",
        TransitionKind::SlidingEntry => "sliding_entry",
        TransitionKind::SlidingExit => "sliding_exit",
        TransitionKind::Graze => "graze",
    }
}

/// `simulate`.
pub struct Run(pub RunSpec);

impl FVisit for Run {
    type Out = Rec;
    fn filippov<const N: usize, const S: usize, const M: usize, Sys>(
        self,
        f: FFamily<Sys>,
    ) -> Result<Rec>
    where
        Sys: Filippov<f64, N, S> + Clone + Send + Sync + 'static,
    {
        let r = self.0;
        let tol = tolerances::<N>(&f.base, r.rtol, r.atol.as_deref())?;
        let mut sim = FilippovSimulation::new(f.system()?, Dopri5::new(tol));
        let mut samples = Samples::<N>::new(r.t_eval.clone());
        let mut log = EventLog::<N>::new(r.max_events);
        let mut watch = Watch(r.cancel.clone());
        let mut obs = Plain((&mut samples, &mut log, &mut watch));
        let run = sim.run::<N, S, _>(r.t0, state::<N>(&r.y0), r.t_end, &mut obs)?;
        if run.stopped && r.cancel.is_set() {
            return Err(Fail::Interrupted);
        }
        let transitions = run
            .transitions
            .iter()
            .map(|tr| {
                Rec::new()
                    .f("t", tr.t)
                    .i("surface", tr.surface as i64)
                    .s("kind", kind_name(tr.kind))
                    .s("from", tr.from.name())
                    .s("to", tr.to.name())
                    .vec("x", &tr.x)
            })
            .collect();
        let n = samples.len();
        Ok(log
            .rec()
            .a1("t", r.t_eval[..n].to_vec())
            .rows("y", samples.rows())
            .vec("y_final", &run.x)
            .list("transitions", transitions)
            .f("max_drift", run.max_drift)
            .stats(&run.stats)
            .f("t_final", run.t)
            .s(
                "termination",
                if run.stopped {
                    "stopped"
                } else {
                    "reached_end"
                },
            ))
    }
}

/// `lyapunov` (two trajectories through sliding).
pub struct Lyapunov(pub LyapunovSpec);

impl FVisit for Lyapunov {
    type Out = Rec;
    fn filippov<const N: usize, const S: usize, const M: usize, Sys>(
        self,
        f: FFamily<Sys>,
    ) -> Result<Rec>
    where
        Sys: Filippov<f64, N, S> + Clone + Send + Sync + 'static,
    {
        let l = self.0;
        if l.spectrum {
            return Err(value(format!(
                "method='spectrum' is not available for the {} system (Filippov); use \
                 method='two_trajectory'",
                f.base.name()
            )));
        }
        let tol = tolerances::<N>(&f.base, l.rtol, l.atol.as_deref())?;
        let mut est = FilippovTwoTrajectory::new(
            f.system()?,
            Dopri5::new(tol),
            l.d0.unwrap_or(f.base.d0()),
            weights::<N>(&f.base)?,
        )?;
        est.start(l.t0, state::<N>(&l.y0))?;
        let tau = match (l.tau, f.base.period()) {
            (Some(t), _) | (None, Some(t)) => t,
            (None, None) => return Err(value("tau is required for an autonomous system")),
        };
        if l.transient > 0 {
            est.transient::<S>(tau, l.transient)?;
        }
        l.cancel.check()?;
        let e = est.estimate::<S>(tau, l.intervals)?;
        l.cancel.check()?;
        Ok(crate::analysis::estimate_rec(&e))
    }
}

/// `periodic_orbit` (Newton on the period map, the monodromy with saltation).
pub struct Orbit(pub OrbitSpec);

impl FVisit for Orbit {
    type Out = Rec;
    fn filippov<const N: usize, const S: usize, const M: usize, Sys>(
        self,
        f: FFamily<Sys>,
    ) -> Result<Rec>
    where
        Sys: Filippov<f64, N, S> + Clone + Send + Sync + 'static,
    {
        let o = self.0;
        let tol = tolerances::<N>(&f.base, o.rtol, o.atol.as_deref())?;
        let mut sim = FilippovSimulation::new(f.system()?, Dopri5::new(tol));
        let forced = f.base.period();
        let (period, autonomous) = match (o.period, forced) {
            (Some(p), None) => (p, true),
            (None, Some(t)) => (f64::from(o.multiple) * t, false),
            (Some(p), Some(_)) => (p, false),
            (None, None) => {
                return Err(value(
                    "period (a guess) is required for an autonomous system",
                ));
            }
        };
        let tol_m = Tolerances::<f64, M>::new(o.rtol, o.rtol * 1e-2)?;
        let orbit = sim.find_orbit::<N, S, M>(
            o.t0,
            state::<N>(&o.y0),
            period,
            autonomous,
            tol_m,
            o.xtol,
            o.max_iterations,
        )?;
        let mus = orbit.monodromy.multipliers();
        // An autonomous orbit's multiplier 1 (the flow's direction) is not a stability one.
        let stable = mus
            .iter()
            .filter(|m| !(autonomous && (m.re - 1.0).hypot(m.im) <= 1e-6))
            .all(|m| m.norm() < 1.0);
        Ok(Rec::new()
            .vec("state", &orbit.state)
            .f("period", orbit.period)
            .matrix("monodromy", &orbit.monodromy.matrix)
            .complex("multipliers", mus)
            .i("iterations", orbit.iterations as i64)
            .f("residual", f64::NAN)
            .b("stable", stable))
    }
}

/// `continuation` with the sliding bifurcations located.
pub struct Continue {
    pub spec: ContinuationSpec,
    pub period: Option<f64>,
}

impl FVisit for Continue {
    type Out = Rec;
    fn filippov<const N: usize, const S: usize, const M: usize, Sys>(
        self,
        f: FFamily<Sys>,
    ) -> Result<Rec>
    where
        Sys: Filippov<f64, N, S> + Clone + Send + Sync + 'static,
    {
        let c = self.spec;
        let tol = tolerances::<N>(&f.base, c.rtol, c.atol.as_deref())?;
        let p0 = f.base.parameter(&c.parameter)?;
        let autonomous = f.base.period().is_none();
        let guess = match (self.period, autonomous) {
            (Some(p), _) => p,
            (None, false) => f64::NAN,
            (None, true) => {
                return Err(value(
                    "period (a guess) is required for an autonomous system",
                ));
            }
        };
        let step = if c.downward { -c.step } else { c.step };
        let mut settings = SlidingContinuation::new(c.lo, c.hi, step, 0)?;
        if let Some(m) = c.max_points {
            settings = settings.with_max_points(m)?;
        }
        if autonomous {
            settings = settings.autonomous();
        }
        let name = c.parameter.clone();
        let build = |p: f64| -> std::result::Result<_, nonsmooth::orbit::OrbitError> {
            let sys = f
                .at(&name, p)
                .map_err(|e| nonsmooth::orbit::OrbitError::Build(format!("{e:?}")))?;
            Ok(FilippovSimulation::new(sys, Dopri5::new(tol)))
        };
        let multiple = f64::from(c.multiple);
        let base = f.base.clone();
        let period = |p: f64| -> f64 {
            if autonomous {
                guess
            } else {
                base.with_parameter(&name, p)
                    .ok()
                    .and_then(|k| k.period())
                    .map_or(f64::NAN, |t| multiple * t)
            }
        };
        let tol_m = Tolerances::<f64, M>::new(c.rtol, c.rtol * 1e-2)?;
        let branch = follow_sliding::<Sys, _, _, _, N, S, M>(
            build,
            period,
            c.t0,
            p0,
            state::<N>(&c.y0),
            tol_m,
            &settings,
        )?;
        let points = branch
            .points
            .iter()
            .map(|q| {
                let stable = q
                    .multipliers
                    .iter()
                    .filter(|m| !(autonomous && (m.re - 1.0).hypot(m.im) <= 1e-6))
                    .all(|m| m.norm() < 1.0);
                Rec::new()
                    .f("p", q.p)
                    .f("arclength", f64::NAN)
                    .vec("state", &q.state)
                    .f("period", q.period)
                    .complex("multipliers", q.multipliers.clone())
                    .b("stable", stable)
                    .opt("grazing_margin", Some(q.tests.grazing_sliding))
            })
            .collect();
        let bifurcations = branch
            .bifurcations
            .iter()
            .map(|b| {
                Rec::new()
                    .s(
                        "kind",
                        match b.kind {
                            SlidingBifurcationKind::GrazingSliding => "grazing_sliding",
                            SlidingBifurcationKind::CrossingSliding => "crossing_sliding",
                            SlidingBifurcationKind::SwitchingSliding => "switching_sliding",
                            SlidingBifurcationKind::AddingSliding => "adding_sliding",
                        },
                    )
                    .f("p", b.p)
                    .f("arclength", f64::NAN)
                    .vec("state", &b.state)
                    .complex("multipliers", Vec::new())
            })
            .collect();
        let (end, end_p) = match branch.end {
            BranchEnd::ParameterRange => ("parameter_range", None),
            BranchEnd::MaxPoints => ("max_points", None),
            BranchEnd::StepTooSmall { p } => ("step_too_small", Some(p)),
        };
        Ok(Rec::new()
            .s("parameter", c.parameter)
            .list("points", points)
            .list("bifurcations", bifurcations)
            .s("end", end)
            .opt("end_p", end_p))
    }
}

/// The belt's forcing period.
pub fn belt_period(b: &Belt) -> f64 {
    TAU / b.omega
}
