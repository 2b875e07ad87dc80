//! The instruments over runs: Poincaré sections, sweeps, Lyapunov exponents, periodic
//! orbits and their continuation, the entropy index.

use nonsmooth::event::{Direction, Event, EventSet};
use nonsmooth::integrate::Dopri5;
use nonsmooth::lyapunov::{
    Dims, HybridTwoTrajectory, Norm, TangentDimension, TangentSpace, TwoTrajectory,
    tangent_tolerances,
};
use nonsmooth::orbit::{
    BifurcationKind, BranchEnd, ContinuationSettings, Extremum, Grazing, Shooting, follow,
};
use nonsmooth::sample::{Regime, Surface};
use nonsmooth::sweep::{
    RunFailure, SweepConfig, SweepDirection, SweepPoint, SweepSystem, hysteresis, run_point, sweep,
    transitions,
};
use nonsmooth::{Dynamics, LaneDynamics};

use crate::errors::{Fail, Result, value};
use crate::family::{Family, Visit, visit};
use crate::interrupt::{Cancel, state};
use crate::record::Rec;
use crate::runs::tolerances;
use crate::system::Kind;

/// Period detection and step cap of the sweep machinery.
#[derive(Debug, Clone)]
pub struct Detect {
    pub period_tol: f64,
    pub max_period: usize,
    pub max_steps: usize,
}

fn regime(r: Regime) -> i64 {
    r.period().map_or(0, |p| p as i64)
}

pub fn point_rec<const M: usize>(p: &SweepPoint<M>) -> Rec {
    Rec::new()
        .f("param", p.param)
        .rows("poincare", &p.poincare)
        .a1("intervals", p.intervals.clone())
        .a1("impact_velocities", p.impact_velocities.clone())
        .i("impacts", p.impacts as i64)
        .f("impacts_per_period", p.impacts_per_period)
        .i("period", regime(p.regime))
        .f("grazing_margin", p.grazing_margin)
        .vec("end_state", &p.end_state)
}

struct Poincare {
    y0: Vec<f64>,
    transient: u32,
    record: u32,
    rtol: f64,
    atol: Option<Vec<f64>>,
    detect: Detect,
}

impl Visit for Poincare {
    type Out = Rec;
    fn smooth<const M: usize, const M2: usize, const MT: usize, S, E, G>(
        self,
        f: Family<S, E, G>,
    ) -> Result<Rec>
    where
        S: Dynamics<f64, M> + LaneDynamics<M> + Clone + Send + Sync + 'static,
        E: EventSet<f64, M> + Clone + Send + Sync + 'static,
        G: Surface<f64, M> + Clone + Send + Sync + 'static,
        Dims<M>: TangentDimension<M, MT>,
    {
        let p = f.parts()?;
        let tol = f.tolerances::<M>(self.rtol, self.atol.as_deref())?;
        let param = f.base.parameter("omega").unwrap_or(0.0);
        let cfg = SweepConfig::new(vec![param])?
            .record(self.record)?
            .period_detection(self.detect.period_tol, self.detect.max_period)?
            .max_steps(self.detect.max_steps);
        let pt = run_point(
            &cfg,
            param,
            SweepSystem {
                system: p.model,
                period: p.period,
                stop: p.surface,
            },
            Dopri5::new(tol),
            state::<M>(&self.y0),
            self.transient,
        )?;
        Ok(point_rec(&pt).f("forcing_period", p.period))
    }
}

/// Stroboscopic points and impacts of one run (`transient` then `record` forcing periods).
#[allow(clippy::too_many_arguments)]
pub fn poincare(
    kind: &Kind,
    surface: usize,
    y0: Vec<f64>,
    transient: u32,
    record: u32,
    rtol: f64,
    atol: Option<Vec<f64>>,
    detect: Detect,
) -> Result<Rec> {
    visit(
        kind,
        surface,
        "poincare",
        Poincare {
            y0,
            transient,
            record,
            rtol,
            atol,
            detect,
        },
    )
}

/// Sweep settings.
#[derive(Debug, Clone)]
pub struct SweepSpec {
    pub parameter: String,
    pub values: Vec<f64>,
    pub direction: SweepDirection,
    pub continuation: bool,
    pub transient_first: u32,
    pub transient_step: u32,
    pub record: u32,
    pub y0: Vec<f64>,
    pub rtol: f64,
    pub atol: Option<Vec<f64>>,
    pub detect: Detect,
    pub hysteresis_tol: f64,
    pub cancel: Cancel,
}

struct Sweep(SweepSpec);

impl Visit for Sweep {
    type Out = Rec;
    fn smooth<const M: usize, const M2: usize, const MT: usize, S, E, G>(
        self,
        f: Family<S, E, G>,
    ) -> Result<Rec>
    where
        S: Dynamics<f64, M> + LaneDynamics<M> + Clone + Send + Sync + 'static,
        E: EventSet<f64, M> + Clone + Send + Sync + 'static,
        G: Surface<f64, M> + Clone + Send + Sync + 'static,
        Dims<M>: TangentDimension<M, MT>,
    {
        let s = self.0;
        let tol = f.tolerances::<M>(s.rtol, s.atol.as_deref())?;
        let cfg = SweepConfig::new(s.values.clone())?
            .direction(s.direction)
            .continuation(s.continuation)
            .transients(s.transient_first, s.transient_step)
            .record(s.record)?
            .period_detection(s.detect.period_tol, s.detect.max_period)?
            .max_steps(s.detect.max_steps);
        let cancel = s.cancel.clone();
        let name = s.parameter.clone();
        // The builder is the sweep's hook per value: it stops the sweep on Ctrl-C.
        let make = |v: f64| -> std::result::Result<SweepSystem<S, G>, RunFailure> {
            if cancel.is_set() {
                return Err(RunFailure::Other("interrupted".into()));
            }
            let p = f
                .at(&name, v)
                .map_err(|e| RunFailure::Other(fail_message(e)))?;
            Ok(SweepSystem {
                system: p.model,
                period: p.period,
                stop: p.surface,
            })
        };
        let res = sweep(&cfg, make, || Dopri5::new(tol), state::<M>(&s.y0));
        s.cancel.check()?;
        let res = res?;
        let hy = hysteresis(&res, s.hysteresis_tol);
        let branches = res
            .branches
            .iter()
            .map(|b| {
                let tr = transitions(b)
                    .iter()
                    .map(|t| {
                        Rec::new()
                            .f("before", t.before)
                            .f("after", t.after)
                            .f("impacts_before", t.impacts_before)
                            .f("impacts_after", t.impacts_after)
                            .i("period_before", regime(t.regime_before))
                            .i("period_after", regime(t.regime_after))
                    })
                    .collect();
                Rec::new()
                    .s(
                        "direction",
                        match b.direction {
                            SweepDirection::Down => "down",
                            _ => "up",
                        },
                    )
                    .list("points", b.points.iter().map(point_rec).collect())
                    .list("transitions", tr)
            })
            .collect();
        Ok(Rec::new()
            .s("parameter", s.parameter)
            .list("branches", branches)
            .a1("hysteresis_lo", hy.iter().map(|h| h.0).collect())
            .a1("hysteresis_hi", hy.iter().map(|h| h.1).collect()))
    }
}

fn fail_message(f: Fail) -> String {
    match f {
        Fail::Value(m)
        | Fail::Run(m)
        | Fail::Zeno(m)
        | Fail::Work(m)
        | Fail::Convergence(m)
        | Fail::Integration(m)
        | Fail::Study(m) => m,
        Fail::Interrupted => "interrupted".into(),
    }
}

/// An up/down (or independent) sweep over a parameter.
pub fn run_sweep(kind: &Kind, surface: usize, s: SweepSpec) -> Result<Rec> {
    visit(kind, surface, "sweep", Sweep(s))
}

/// Lyapunov settings.
#[derive(Debug, Clone)]
pub struct LyapunovSpec {
    pub spectrum: bool,
    pub y0: Vec<f64>,
    pub t0: f64,
    pub tau: Option<f64>,
    pub transient: usize,
    pub intervals: usize,
    pub d0: Option<f64>,
    pub rtol: f64,
    pub atol: Option<Vec<f64>>,
    pub cancel: Cancel,
}

pub fn estimate_rec(e: &nonsmooth::lyapunov::Estimate<f64>) -> Rec {
    Rec::new()
        .a1("exponents", vec![e.exponent])
        .a1("spread", vec![e.spread])
        .a1("history", e.history.clone())
        .f("interval", e.interval)
        .i("intervals", e.history.len() as i64)
        .s("method", "two_trajectory")
}

struct Lyapunov(LyapunovSpec);

impl Visit for Lyapunov {
    type Out = Rec;
    fn smooth<const M: usize, const M2: usize, const MT: usize, S, E, G>(
        self,
        f: Family<S, E, G>,
    ) -> Result<Rec>
    where
        S: Dynamics<f64, M> + LaneDynamics<M> + Clone + Send + Sync + 'static,
        E: EventSet<f64, M> + Clone + Send + Sync + 'static,
        G: Surface<f64, M> + Clone + Send + Sync + 'static,
        Dims<M>: TangentDimension<M, MT>,
    {
        let l = self.0;
        let p = f.parts()?;
        let tol = f.tolerances::<M>(l.rtol, l.atol.as_deref())?;
        let norm = f.norm::<M>()?;
        let tau = l.tau.unwrap_or(p.period);
        let y0 = state::<M>(&l.y0);
        if l.spectrum {
            let mut est = TangentSpace::<f64, M, M, MT, _, _>::from_tolerances(
                p.model,
                &tol,
                Dopri5::new,
                (l.rtol, l.rtol),
                norm,
            )?;
            est.start(l.t0, y0)?;
            if l.transient > 0 {
                est.transient(tau, l.transient)?;
            }
            l.cancel.check()?;
            let s = est.estimate(tau, l.intervals)?;
            l.cancel.check()?;
            return Ok(Rec::new()
                .a1("exponents", s.exponents.to_vec())
                .a1("spread", s.spread.to_vec())
                .a1("history", s.history.iter().map(|h| h[0]).collect())
                .f("interval", s.interval)
                .i("intervals", s.history.len() as i64)
                .s("method", "spectrum"));
        }
        let d0 = l.d0.unwrap_or(f.base.d0());
        let mut est = TwoTrajectory::<f64, M, M2, _, _>::with_tolerances(
            p.model,
            Dopri5::new,
            &tol,
            d0,
            norm,
        )?;
        est.start(l.t0, y0)?;
        if l.transient > 0 {
            est.transient(tau, l.transient)?;
        }
        l.cancel.check()?;
        let e = est.estimate(tau, l.intervals)?;
        l.cancel.check()?;
        Ok(estimate_rec(&e))
    }
}

fn weights<const M: usize>(kind: &Kind) -> Result<Norm<f64, M>> {
    let s = kind.scales();
    let mut arr = [0.0; M];
    arr.copy_from_slice(&s[..M]);
    Ok(Norm::weighted(arr)?)
}

/// Lyapunov exponents: two trajectories (through resets and sliding) or the spectrum.
pub fn lyapunov(kind: &Kind, l: LyapunovSpec) -> Result<Rec> {
    match kind {
        Kind::Ball(b) => {
            if l.spectrum {
                return Err(value(
                    "method='spectrum' is not available for the bouncing ball; use \
                     method='two_trajectory'",
                ));
            }
            let tol = tolerances::<2>(kind, l.rtol, l.atol.as_deref())?;
            let events =
                Event::new(b.table::<f64>()?, Direction::Rising).with_reset(b.impact::<f64>()?);
            let mut est = HybridTwoTrajectory::new(
                b.model::<f64>()?,
                Dopri5::new(tol),
                events,
                l.d0.unwrap_or(kind.d0()),
                weights::<2>(kind)?,
            )?;
            est.start(l.t0, state::<2>(&l.y0))?;
            let tau = l.tau.unwrap_or(b.period());
            if l.transient > 0 {
                est.transient(tau, l.transient)?;
            }
            l.cancel.check()?;
            let e = est.estimate(tau, l.intervals)?;
            l.cancel.check()?;
            Ok(estimate_rec(&e))
        }
        Kind::Relay(_) | Kind::Belt(_) => {
            crate::filippov::visit(kind, crate::filippov::Lyapunov(l))
        }
        _ => visit(kind, 0, "lyapunov", Lyapunov(l)),
    }
}

/// Shooting settings.
#[derive(Debug, Clone)]
pub struct OrbitSpec {
    pub y0: Vec<f64>,
    pub t0: f64,
    pub multiple: u32,
    pub period: Option<f64>,
    pub rtol: f64,
    pub atol: Option<Vec<f64>>,
    pub xtol: f64,
    pub max_iterations: usize,
}

struct Orbit(OrbitSpec);

fn orbit_rec<const M: usize>(o: &nonsmooth::orbit::PeriodicOrbit<f64, M>) -> Rec {
    Rec::new()
        .vec("state", &o.state)
        .f("period", o.period)
        .matrix("monodromy", &o.monodromy)
        .complex("multipliers", o.multipliers.clone())
        .i("iterations", o.iterations as i64)
        .f("residual", o.residual)
        .b("stable", o.is_stable())
}

impl Visit for Orbit {
    type Out = Rec;
    fn smooth<const M: usize, const M2: usize, const MT: usize, S, E, G>(
        self,
        f: Family<S, E, G>,
    ) -> Result<Rec>
    where
        S: Dynamics<f64, M> + LaneDynamics<M> + Clone + Send + Sync + 'static,
        E: EventSet<f64, M> + Clone + Send + Sync + 'static,
        G: Surface<f64, M> + Clone + Send + Sync + 'static,
        Dims<M>: TangentDimension<M, MT>,
    {
        let o = self.0;
        let p = f.parts()?;
        let tol = f.tolerances::<M>(o.rtol, o.atol.as_deref())?;
        let tangent = tangent_tolerances::<f64, M, M, MT>(&tol, o.rtol, o.rtol * 1e-2)?;
        let shooting = Shooting::new(p.model, (), tangent).with_max_iterations(o.max_iterations)?;
        let period = o.period.unwrap_or(f64::from(o.multiple) * p.period);
        let orbit = shooting.find(o.t0, period, state::<M>(&o.y0))?;
        Ok(orbit_rec(&orbit))
    }
}

/// A periodic orbit by shooting, with its monodromy matrix and Floquet multipliers.
pub fn periodic_orbit(kind: &Kind, o: OrbitSpec) -> Result<Rec> {
    match kind {
        Kind::Relay(_) | Kind::Belt(_) => crate::filippov::visit(kind, crate::filippov::Orbit(o)),
        _ => visit(kind, 0, "periodic_orbit", Orbit(o)),
    }
}

/// Continuation settings.
#[derive(Debug, Clone)]
pub struct ContinuationSpec {
    pub parameter: String,
    pub lo: f64,
    pub hi: f64,
    pub step: f64,
    pub max_step: Option<f64>,
    pub max_points: Option<usize>,
    pub downward: bool,
    pub multiple: u32,
    pub y0: Vec<f64>,
    pub t0: f64,
    pub rtol: f64,
    pub atol: Option<Vec<f64>>,
    /// Grazing test: component, level, extremum (`true`: max).
    pub grazing: Option<(usize, f64, bool)>,
    /// Contact changes of local extrema at the level instead of the global extremum.
    pub contact_changes: bool,
}

struct Continue(ContinuationSpec);

impl Visit for Continue {
    type Out = Rec;
    fn smooth<const M: usize, const M2: usize, const MT: usize, S, E, G>(
        self,
        f: Family<S, E, G>,
    ) -> Result<Rec>
    where
        S: Dynamics<f64, M> + LaneDynamics<M> + Clone + Send + Sync + 'static,
        E: EventSet<f64, M> + Clone + Send + Sync + 'static,
        G: Surface<f64, M> + Clone + Send + Sync + 'static,
        Dims<M>: TangentDimension<M, MT>,
    {
        let c = self.0;
        let tol = f.tolerances::<M>(c.rtol, c.atol.as_deref())?;
        let tangent = tangent_tolerances::<f64, M, M, MT>(&tol, c.rtol, c.rtol * 1e-2)?;
        let p0 = f.base.parameter(&c.parameter)?;
        let name = c.parameter.clone();
        let build = |p: f64| -> std::result::Result<
            Shooting<f64, S, (), M, MT>,
            nonsmooth::orbit::OrbitError,
        > {
            let parts = f
                .at(&name, p)
                .map_err(|e| nonsmooth::orbit::OrbitError::Build(fail_message(e)))?;
            Ok(Shooting::new(parts.model, (), tangent))
        };
        let multiple = f64::from(c.multiple);
        let period = |p: f64| f.at(&name, p).map_or(f64::NAN, |x| multiple * x.period);
        let mut settings = ContinuationSettings::new(c.lo, c.hi, c.step)?;
        if let Some(m) = c.max_step {
            settings = settings.with_max_step(m)?;
        }
        if let Some(m) = c.max_points {
            settings = settings.with_max_points(m)?;
        }
        if c.downward {
            settings = settings.downward();
        }
        if let Some((component, level, max)) = c.grazing {
            let g = Grazing {
                component,
                level,
                extremum: if max { Extremum::Max } else { Extremum::Min },
            };
            settings = if c.contact_changes {
                settings.with_contact_changes(g)
            } else {
                settings.with_grazing(g)
            };
        }
        let branch = follow(build, period, c.t0, p0, state::<M>(&c.y0), &settings)?;
        let points = branch
            .points
            .iter()
            .map(|q| {
                Rec::new()
                    .f("p", q.p)
                    .f("arclength", q.arclength)
                    .vec("state", &q.state)
                    .complex("multipliers", q.multipliers.clone())
                    .b("stable", q.stable)
                    .opt("grazing_margin", q.grazing_margin)
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
                            BifurcationKind::Fold => "fold",
                            BifurcationKind::PeriodDoubling => "period_doubling",
                            BifurcationKind::NeimarkSacker => "neimark_sacker",
                            BifurcationKind::Grazing => "grazing",
                        },
                    )
                    .f("p", b.p)
                    .f("arclength", b.arclength)
                    .vec("state", &b.state)
                    .complex("multipliers", b.multipliers.clone())
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

/// A branch of periodic orbits followed in a parameter, with bifurcations located (the
/// sliding bifurcations of a Filippov system; `period`: the guess of an autonomous
/// orbit's period).
pub fn continuation(kind: &Kind, c: ContinuationSpec, period: Option<f64>) -> Result<Rec> {
    match kind {
        Kind::Relay(_) | Kind::Belt(_) => {
            crate::filippov::visit(kind, crate::filippov::Continue { spec: c, period })
        }
        _ => visit(kind, 0, "continuation", Continue(c)),
    }
}

/// The entropy index `q*` of samples (histogram on `[lo, hi)` with bins of `step`).
pub fn tsallis_q(
    samples: &[f64],
    lo: f64,
    hi: f64,
    step: f64,
    q: Option<(f64, f64)>,
) -> Result<Rec> {
    use nonsmooth::entropy::{Histogram, QRange, entropy_index};
    let h = Histogram::new(lo, hi, step)?;
    let est = h.estimate(samples)?;
    let range = match q {
        None => QRange::default(),
        Some((a, b)) => QRange::new(a, b)?,
    };
    let index = entropy_index(&est.probabilities, &range)?;
    Ok(Rec::new()
        .f("q", index.q)
        .f("redundancy", index.redundancy)
        .i("states", index.states as i64)
        .b("at_bound", index.at_bound.is_some())
        .i("scan_maxima", index.scan_maxima as i64))
}

/// The unused-state check of a vector.
pub fn finite(what: &str, v: &[f64]) -> Result<()> {
    if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(value(format!("{what}[{i}] = {x} is not finite")));
    }
    Ok(())
}
