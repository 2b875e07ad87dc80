//! `timestep`: Moreau–Jean time-stepping of rigid contacts (the ball on the vibrating
//! table, the woodpecker toy), with the state, the energies and every active contact's
//! record per step.

use nonsmooth::drive::Control;
use nonsmooth::timestep::{
    ContactSet, ImpactLog, Lagrangian, MoreauJean, StepObserver, StepRecord,
};

use crate::errors::{Fail, Result, value};
use crate::interrupt::Cancel;
use crate::record::Rec;
use crate::system::Kind;

/// Time-stepping settings.
#[derive(Debug, Clone)]
pub struct StepSpec {
    pub t0: f64,
    pub t_end: f64,
    pub h: f64,
    pub theta: f64,
    pub q0: Option<Vec<f64>>,
    pub v0: Option<Vec<f64>>,
    pub every: usize,
    pub max_records: usize,
    pub impact_speed: f64,
    pub cancel: Cancel,
}

/// Every `every`-th step's state and energies, every step's active contacts.
struct Log {
    n: usize,
    every: usize,
    max: usize,
    t: Vec<f64>,
    q: Vec<f64>,
    v: Vec<f64>,
    energy: Vec<f64>,
    contacts: [Vec<f64>; 7],
    cancel: Cancel,
}

impl StepObserver<f64> for Log {
    fn on_step(&mut self, s: &StepRecord<'_, f64>) -> Control {
        if self.cancel.is_set() {
            return Control::Stop;
        }
        if s.step % self.every == 0 && self.t.len() < self.max {
            self.t.push(s.t1);
            self.q.extend_from_slice(s.q);
            self.v.extend_from_slice(s.v);
            self.energy.extend_from_slice(&[
                s.energy.kinetic,
                s.energy.potential,
                s.energy.impulse_work,
            ]);
        }
        if self.contacts[0].len() < self.max {
            for c in s.contacts {
                for (col, x) in self.contacts.iter_mut().zip([
                    s.t1,
                    c.index as f64,
                    c.gap,
                    c.pre,
                    c.post,
                    c.normal_impulse,
                    c.tangent_impulse,
                ]) {
                    col.push(x);
                }
            }
        }
        Control::Continue
    }
}

fn run<S, C>(scheme: MoreauJean<f64, S, C>, q0: Vec<f64>, v0: Vec<f64>, s: &StepSpec) -> Result<Rec>
where
    S: Lagrangian<f64>,
    C: ContactSet<f64>,
{
    let mut scheme = scheme;
    let n = q0.len();
    let mut log = Log {
        n,
        every: s.every,
        max: s.max_records,
        t: vec![s.t0],
        q: q0.clone(),
        v: v0.clone(),
        energy: vec![f64::NAN; 3],
        contacts: Default::default(),
        cancel: s.cancel.clone(),
    };
    let mut impacts = ImpactLog::new(s.impact_speed)?;
    let (mut q, mut v) = (q0, v0);
    let summary = scheme.run(s.t0, &mut q, &mut v, s.t_end, &mut (&mut log, &mut impacts))?;
    if summary.stopped && s.cancel.is_set() {
        return Err(Fail::Interrupted);
    }
    let k = log.t.len();
    let c = &log.contacts;
    let m = c[0].len();
    let imp = &impacts.impacts;
    Ok(Rec::new()
        .a1("t", log.t)
        .shaped("q", log.q, vec![k, log.n])
        .shaped("v", log.v, vec![k, log.n])
        .shaped("energy", log.energy, vec![k, 3])
        .shaped(
            "contacts",
            (0..m)
                .flat_map(|i| c.iter().map(move |col| col[i]))
                .collect(),
            vec![m, 7],
        )
        .a1("impact_t", imp.iter().map(|i| i.t1).collect())
        .a1(
            "impact_contact",
            imp.iter().map(|i| i.contact as f64).collect(),
        )
        .a1("impact_pre", imp.iter().map(|i| i.pre).collect())
        .a1("impact_post", imp.iter().map(|i| i.post).collect())
        .a1("impact_impulse", imp.iter().map(|i| i.impulse).collect())
        .i("steps", summary.steps as i64)
        .f("t_final", summary.t)
        .f("max_residual", summary.max_residual)
        .i("max_active", summary.max_active as i64)
        .a1("q_final", q)
        .a1("v_final", v))
}

fn start(given: &Option<Vec<f64>>, default: &[f64], what: &str) -> Result<Vec<f64>> {
    let x = given.clone().unwrap_or_else(|| default.to_vec());
    if x.len() != default.len() {
        return Err(value(format!(
            "{what} has {} components; the system has {}",
            x.len(),
            default.len()
        )));
    }
    Ok(x)
}

/// A Moreau–Jean run of `kind` (the ball on the table, the woodpecker).
pub fn timestep(kind: &Kind, s: StepSpec) -> Result<Rec> {
    match kind {
        Kind::Ball(b) => {
            let scheme =
                MoreauJean::new(b.model::<f64>()?, [b.contact()?], s.h)?.with_theta(s.theta)?;
            let rest = kind.rest_state()?;
            let q0 = start(&s.q0, &rest[..1], "q0")?;
            let v0 = start(&s.v0, &rest[1..], "v0")?;
            run(scheme, q0, v0, &s)
        }
        Kind::Woodpecker => {
            use nonsmooth::systems::Woodpecker;
            let scheme =
                MoreauJean::new(Woodpecker, Woodpecker::contacts()?, s.h)?.with_theta(s.theta)?;
            let q0 = start(&s.q0, &Woodpecker::Q0, "q0")?;
            let v0 = start(&s.v0, &Woodpecker::V0, "v0")?;
            run(scheme, q0, v0, &s)
        }
        _ => Err(value(format!(
            "timestep runs rigid-contact systems (bouncing_ball, woodpecker), not {}",
            kind.name()
        ))),
    }
}
