//! `diffsol` (0.18): `OdeBuilder` with `rhs_implicit` (right-hand side + analytic
//! Jacobian-vector product), `init`, `root` (g = x − x_I), then `solver.step()` in a loop.
//!
//! Events: diffsol's own root finder (sign change of `g` between step ends, located on the
//! interpolant; `step()` returns `RootFound(t)` and the state stays at the step end, so the
//! integration simply goes on); only rising crossings (g < 0 at the previous step end) count.
//! Sections: `interpolate_inplace(t_i)` for every `t_i` inside an accepted step (what
//! diffsol's `solve_dense` does). `set_stop_time(t_end)` lands on the end exactly.

use diffsol::{
    NalgebraLU, NalgebraMat, NalgebraVec, OdeBuilder, OdeSolverMethod, OdeSolverStopReason,
};

use crate::common::{Counter, Job, Paper, Recorder, RunResult, Status};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DsMethod {
    /// Tsitouras 5(4), explicit.
    Tsit45,
    /// Variable-order BDF/NDF (ode15s-like).
    Bdf,
    /// TR-BDF2 (SDIRK).
    TrBdf2,
    /// ESDIRK3(4).
    Esdirk34,
}

type M = NalgebraMat<f64>;
type LS = NalgebraLU<f64>;

pub fn run(m: DsMethod, job: &Job) -> RunResult {
    let cpu0 = crate::common::cpu_now();
    let p = Paper::new(job.omega);
    let evals = Counter::default();
    let jacs = Counter::default();
    let (e1, j1) = (evals.clone(), jacs.clone());
    let y0 = job.y0;
    let x_i = p.x_i();
    let problem = OdeBuilder::<M>::new()
        .t0(job.t0)
        .rtol(job.rtol)
        .atol(job.atol())
        .rhs_implicit(
            move |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| {
                e1.bump();
                y[0] = x[1];
                y[1] = p.accel(t, x[0], x[1]);
            },
            move |x: &[f64], _p: &[f64], _t: f64, v: &[f64], y: &mut [f64]| {
                j1.bump();
                let (ax, av) = p.accel_partials(x[0], x[1]);
                y[0] = v[1];
                y[1] = ax * v[0] + av * v[1];
            },
        )
        .init(
            move |_p: &[f64], _t: f64, y: &mut [f64]| {
                y[0] = y0[0];
                y[1] = y0[1];
            },
            2,
        )
        .root(
            move |x: &[f64], _p: &[f64], _t: f64, y: &mut [f64]| {
                y[0] = x[0] - x_i;
            },
            1,
        )
        .build();
    let mut problem = match problem {
        Ok(p) => p,
        Err(e) => {
            let mut r = RunResult::unsupported(&format!("build: {e}"));
            r.status = Status::Failed(format!("build: {e}"), 0.0);
            return r;
        }
    };
    // diffsol counts Newton failures over the whole run (not per step) and aborts at 50 by
    // default: raised, like the other peers' run-wide failure caps, so that long runs do not
    // stop for bookkeeping reasons. The per-step limits are left as they are.
    problem.ode_options.max_nonlinear_solver_failures = usize::MAX / 2;
    let mut rec = Recorder::new(job, x_i);
    let res = match m {
        DsMethod::Tsit45 => problem
            .tsit45()
            .map_err(|e| e.to_string())
            .and_then(|s| drive(s, job, &mut rec)),
        DsMethod::Bdf => problem
            .bdf::<LS>()
            .map_err(|e| e.to_string())
            .and_then(|s| drive(s, job, &mut rec)),
        DsMethod::TrBdf2 => problem
            .tr_bdf2::<LS>()
            .map_err(|e| e.to_string())
            .and_then(|s| drive(s, job, &mut rec)),
        DsMethod::Esdirk34 => problem
            .esdirk34::<LS>()
            .map_err(|e| e.to_string())
            .and_then(|s| drive(s, job, &mut rec)),
    };
    let elapsed = crate::common::cpu_now() - cpu0;
    let frac = rec.fraction(job);
    let status = match res {
        Ok(()) if rec.timed_out => Status::Timeout(frac),
        Ok(()) => Status::Ok,
        Err(e) => Status::Failed(e, frac),
    };
    let end = rec.finish_last();
    RunResult {
        status,
        elapsed,
        rhs_evals: evals.get(),
        lib_rhs_evals: None,
        jac_evals: jacs.get(),
        impacts: std::mem::take(&mut rec.impacts),
        strobe: std::mem::take(&mut rec.strobe),
        end,
    }
}

fn drive<'a, Eqn, S>(mut solver: S, job: &Job, rec: &mut Recorder) -> Result<(), String>
where
    Eqn: diffsol::OdeEquations<T = f64, V = NalgebraVec<f64>> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    let t_end = job.t_end();
    solver.set_stop_time(t_end).map_err(|e| e.to_string())?;
    let mut ta = solver.state().t;
    let mut ya = {
        let y = solver.state().y;
        [y[0], y[1]]
    };
    let mut buf = solver.state().y.clone();
    loop {
        let reason = solver.step().map_err(|e| e.to_string())?;
        let (tb, yb) = {
            let st = solver.state();
            (st.t, [st.y[0], st.y[1]])
        };
        if let OdeSolverStopReason::RootFound(tr, _) = reason {
            // diffsol located the crossing; count rising ones only.
            if ya[0] - job_x_i(rec) < 0.0 {
                rec.impacts.push(tr);
            }
        }
        // Sections (and the budget) through the shared recorder, with events switched off
        // there (diffsol found them already).
        let ok = rec.step_sections_only(ta, tb, ya, yb, |t| {
            let _ = solver.interpolate_inplace(t, &mut buf);
            [buf[0], buf[1]]
        });
        ta = tb;
        ya = yb;
        if !ok {
            return Ok(());
        }
        if matches!(reason, OdeSolverStopReason::TstopReached) || tb >= t_end {
            return Ok(());
        }
    }
}

fn job_x_i(rec: &Recorder) -> f64 {
    rec.x_i()
}
