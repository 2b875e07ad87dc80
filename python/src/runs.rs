//! `simulate` and `impacts`: one run of a system with dense samples, event records and
//! modes (smooth systems with their impact surfaces, rigid stops through chattering and
//! sticking, Filippov systems through sliding).

use nalgebra::SVector;
use nonsmooth::drive::{
    Control, EventRecord, Observer, Simulation, StepView, Termination, run_with_sticking,
};
use nonsmooth::event::{EventSet, NewtonImpact};
use nonsmooth::excite::Excitation;
use nonsmooth::integrate::{DenseOutput, Dopri5, Tolerances};
use nonsmooth::lyapunov::{Dims, TangentDimension};
use nonsmooth::model::{Elements, Loads, Mechanical};
use nonsmooth::sample::{ImpactSequence, Surface};
use nonsmooth::{Dynamics, LaneDynamics};

use crate::errors::{Fail, Result, value};
use crate::family::{Family, Visit, visit};
use crate::interrupt::{Cancel, Watch, state};
use crate::record::Rec;
use crate::system::Kind;

/// Dense samples at given times (sorted), interpolated on each step's dense output.
pub struct Samples<const M: usize> {
    t: Vec<f64>,
    next: usize,
    y: Vec<SVector<f64, M>>,
}

impl<const M: usize> Samples<M> {
    pub fn new(t: Vec<f64>) -> Self {
        let y = Vec::with_capacity(t.len());
        Self { t, next: 0, y }
    }
    /// The number of samples taken.
    pub fn len(&self) -> usize {
        self.y.len()
    }
    /// The samples taken.
    pub fn rows(&self) -> &[SVector<f64, M>] {
        &self.y
    }
}

impl<const M: usize> Observer<f64, M> for Samples<M> {
    fn on_step<D: DenseOutput<f64, M>>(&mut self, s: &StepView<'_, f64, M, D>) -> Control {
        while self.next < self.t.len() && self.t[self.next] <= s.t1 {
            let mut y = SVector::zeros();
            s.state_at(self.t[self.next].max(s.t0), &mut y);
            self.y.push(y);
            self.next += 1;
        }
        Control::Continue
    }
    fn on_mode(&mut self, _t: f64, _mode: &'static str) {}
}

/// Every event: surface index, time, state before and after.
#[derive(Default)]
pub struct EventLog<const M: usize> {
    index: Vec<f64>,
    t: Vec<f64>,
    y: Vec<SVector<f64, M>>,
    after: Vec<SVector<f64, M>>,
    modes: Vec<(f64, &'static str)>,
    cap: usize,
}

impl<const M: usize> EventLog<M> {
    pub fn new(cap: usize) -> Self {
        Self {
            cap,
            ..Default::default()
        }
    }
    pub fn rec(self) -> Rec {
        let modes = self
            .modes
            .iter()
            .map(|&(t, m)| Rec::new().f("t", t).s("mode", m))
            .collect();
        Rec::new()
            .a1("event_t", self.t)
            .a1("event_surface", self.index)
            .rows("event_y", &self.y)
            .rows("event_y_after", &self.after)
            .list("modes", modes)
    }
}

impl<const M: usize> Observer<f64, M> for EventLog<M> {
    fn on_event(&mut self, e: &EventRecord<f64, M>) -> Control {
        if self.t.len() < self.cap {
            self.index.push(e.index as f64);
            self.t.push(e.t);
            self.y.push(e.y);
            self.after
                .push(e.y_after.unwrap_or_else(|| SVector::repeat(f64::NAN)));
        }
        Control::Continue
    }
    fn on_mode(&mut self, t: f64, mode: &'static str) {
        self.modes.push((t, mode));
    }
}

/// The settings of one run.
#[derive(Debug, Clone)]
pub struct RunSpec {
    pub t0: f64,
    pub t_end: f64,
    pub y0: Vec<f64>,
    pub t_eval: Vec<f64>,
    pub rtol: f64,
    pub atol: Option<Vec<f64>>,
    pub max_steps: usize,
    pub max_events: usize,
    pub cancel: Cancel,
}

fn outcome(rec: Rec, t: f64, termination: Termination, cancel: &Cancel) -> Result<Rec> {
    if termination == Termination::ObserverStopped && cancel.is_set() {
        return Err(Fail::Interrupted);
    }
    let term = match termination {
        Termination::ReachedEnd => "reached_end",
        Termination::ObserverStopped => "stopped",
        Termination::TerminalEvent(_) => "terminal_event",
    };
    Ok(rec.f("t_final", t).s("termination", term))
}

struct Simulate(RunSpec);

impl Visit for Simulate {
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
        let r = self.0;
        let p = f.parts()?;
        let tol = f.tolerances::<M>(r.rtol, r.atol.as_deref())?;
        let mut sim = Simulation::new(p.model, Dopri5::new(tol))
            .with_events(p.events)
            .max_steps(r.max_steps)?;
        let mut samples = Samples::<M>::new(r.t_eval.clone());
        let mut log = EventLog::<M>::new(r.max_events);
        let mut watch = Watch(r.cancel.clone());
        let out = sim.run(
            r.t0,
            state::<M>(&r.y0),
            r.t_end,
            &mut (&mut samples, &mut log, &mut watch),
        )?;
        let n = samples.y.len();
        let rec = log
            .rec()
            .a1("t", r.t_eval[..n].to_vec())
            .rows("y", &samples.y)
            .vec("y_final", &out.y)
            .stats(&out.stats);
        outcome(rec, out.t, out.termination, &r.cancel)
    }
}

/// A rigid stop on a mechanical model: Newton impacts, chattering, sticking and release.
#[allow(clippy::type_complexity)]
fn rigid<const N: usize, const M: usize, El, Ld, Sx>(
    r: RunSpec,
    model: &Mechanical<f64, N, El, Ld>,
    impact: &NewtonImpact<f64, N, Sx>,
    tol: Tolerances<f64, M>,
) -> Result<Rec>
where
    El: Elements<f64, N> + Clone,
    Ld: Loads<f64, N> + Clone,
    Sx: Excitation<f64> + Clone,
    Mechanical<f64, N, El, Ld>: Dynamics<f64, M>,
{
    let mut samples = Samples::<M>::new(r.t_eval.clone());
    let mut log = EventLog::<M>::new(r.max_events);
    let mut watch = Watch(r.cancel.clone());
    let (out, modes) = run_with_sticking(
        model,
        impact,
        || Dopri5::new(tol),
        r.t0,
        state::<M>(&r.y0),
        r.t_end,
        r.max_steps,
        &mut (&mut samples, &mut log, &mut watch),
    )?;
    let n = samples.y.len();
    let rec = log
        .rec()
        .a1("t", r.t_eval[..n].to_vec())
        .rows("y", &samples.y)
        .vec("y_final", &out.y)
        .a1("stick_t", modes.stick)
        .a1("release_t", modes.release)
        .stats(&out.stats);
    outcome(rec, out.t, out.termination, &r.cancel)
}

/// Tolerances for a system outside the smooth family.
pub fn tolerances<const M: usize>(
    kind: &Kind,
    rtol: f64,
    atol: Option<&[f64]>,
) -> Result<Tolerances<f64, M>> {
    let a: Vec<f64> = match atol {
        Some(a) => a.to_vec(),
        None => kind.atol_per_rtol().iter().map(|s| rtol * s).collect(),
    };
    let mut arr = [0.0; M];
    arr.copy_from_slice(&a[..M]);
    Ok(Tolerances::per_component(rtol, arr)?)
}

fn described_rigid<const N: usize, const M: usize>(
    r: RunSpec,
    kind: &Kind,
    d: &nonsmooth::study::DescribedSystem,
) -> Result<Rec>
where
    nonsmooth::study::DescribedModel<N>: Dynamics<f64, M>,
{
    let model = d.model::<N>()?;
    let impact = d
        .rigid_stop::<N>()?
        .ok_or_else(|| value("the system has no rigid stop"))?;
    let tol = tolerances::<M>(kind, r.rtol, r.atol.as_deref())?;
    rigid::<N, M, _, _, _>(r, &model, &impact, tol)
}

/// One run of any system.
pub fn simulate(kind: &Kind, r: RunSpec) -> Result<Rec> {
    match kind {
        Kind::Ball(b) => {
            let tol = tolerances::<2>(kind, r.rtol, r.atol.as_deref())?;
            rigid::<1, 2, _, _, _>(r, &b.model::<f64>()?, &b.impact::<f64>()?, tol)
        }
        Kind::Relay(_) | Kind::Belt(_) => crate::filippov::visit(kind, crate::filippov::Run(r)),
        Kind::Described(d) if d.is_rigid() => match d.dofs() {
            1 => described_rigid::<1, 2>(r, kind, d),
            2 => described_rigid::<2, 4>(r, kind, d),
            3 => described_rigid::<3, 6>(r, kind, d),
            4 => described_rigid::<4, 8>(r, kind, d),
            n => Err(value(format!("{n} degrees of freedom; at most 4"))),
        },
        _ => visit(kind, 0, "simulate", Simulate(r)),
    }
}

struct Impacts {
    run: RunSpec,
    record_from: f64,
    capacity: usize,
}

impl Visit for Impacts {
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
        let r = self.run;
        let p = f.parts()?;
        let surface = p.surface.ok_or_else(|| {
            value(format!(
                "the {} system has no impact surface",
                f.base.name()
            ))
        })?;
        let tol = f.tolerances::<M>(r.rtol, r.atol.as_deref())?;
        // The selected surface alone, as the sweep records impacts (its event is index 0).
        let ev = nonsmooth::event::Event::new(surface.clone(), nonsmooth::event::Direction::Rising);
        let mut sim = Simulation::new(p.model, Dopri5::new(tol))
            .with_events(ev)
            .max_steps(r.max_steps)?;
        let mut seq = ImpactSequence::on_surface(0, surface, self.record_from, self.capacity)?;
        let mut watch = Watch(r.cancel.clone());
        let out = sim.run(
            r.t0,
            state::<M>(&r.y0),
            r.t_end,
            &mut (&mut seq, &mut watch),
        )?;
        let imp = seq.impacts();
        let rec = Rec::new()
            .a1("t", imp.iter().map(|i| i.t).collect())
            .a1("velocity", imp.iter().map(|i| i.velocity).collect())
            .a1(
                "interval",
                imp.iter().map(|i| i.interval.unwrap_or(f64::NAN)).collect(),
            )
            .a1(
                "max_penetration",
                imp.iter()
                    .map(|i| i.max_penetration.unwrap_or(f64::NAN))
                    .collect(),
            )
            .i("count", seq.count() as i64)
            .i("dropped", seq.dropped() as i64)
            .vec("y_final", &out.y)
            .stats(&out.stats);
        outcome(rec, out.t, out.termination, &r.cancel)
    }
}

/// The impact sequence on `surface` of a smooth system from `record_from` on.
pub fn impacts(
    kind: &Kind,
    surface: usize,
    r: RunSpec,
    record_from: f64,
    capacity: usize,
) -> Result<Rec> {
    visit(
        kind,
        surface,
        "impacts",
        Impacts {
            run: r,
            record_from,
            capacity,
        },
    )
}
