//! The `differential-equations` crate (0.7): `IVP::ode(..).solout(..).method(..).solve()`.
//!
//! Events and sections: a custom `Solout`, the crate's hook that sees every accepted step
//! with the method's own interpolant (`interpolator.interpolate(t)`). Impacts: sign change of
//! `x − x_I` between step ends (rising), located on the interpolant by Illinois to 1e-12 s —
//! the same rule as the crate's own `EventSolout` (Brent on the interpolant, sign changes at
//! step ends only). Per-component tolerances are passed as `[atol_x, atol_v]`.

use differential_equations::linalg::Matrix;
use differential_equations::prelude::*;

use crate::common::{Counter, Job, Paper, Recorder, RunResult, Status};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeMethod {
    Dopri5,
    Dop853,
    /// Verner 9(8) with its own 9th-order interpolant.
    Rkv988e,
    /// Radau IIA order 5 (implicit), analytic Jacobian.
    Radau5,
    /// Kvaerno 7-stage ESDIRK 5(4) (implicit), analytic Jacobian.
    Kvaerno745,
    /// Variable-order BDF (implicit), analytic Jacobian.
    Bdf,
}

struct Sys {
    p: Paper,
    evals: Counter,
    jacs: Counter,
}

impl ODE<f64, [f64; 2]> for Sys {
    #[inline(always)]
    fn diff(&self, t: f64, y: &[f64; 2], dydt: &mut [f64; 2]) {
        self.evals.bump();
        dydt[0] = y[1];
        dydt[1] = self.p.accel(t, y[0], y[1]);
    }

    fn jacobian(&self, _t: f64, y: &[f64; 2], j: &mut Matrix<f64>) {
        self.jacs.bump();
        let (ax, av) = self.p.accel_partials(y[0], y[1]);
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = ax;
        j[(1, 1)] = av;
    }
}

struct Obs<'a> {
    rec: &'a mut Recorder,
}

impl Solout<f64, [f64; 2]> for Obs<'_> {
    #[inline]
    fn solout<I>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &[f64; 2],
        y_prev: &[f64; 2],
        interpolator: &mut I,
        _solution: &mut Solution<f64, [f64; 2]>,
    ) -> ControlFlag<f64, [f64; 2]>
    where
        I: Interpolation<f64, [f64; 2]> + ?Sized,
    {
        if t_curr <= t_prev {
            // The initial call (t_prev == t_curr == t0).
            return ControlFlag::Continue;
        }
        let ok = self.rec.step(t_prev, t_curr, *y_prev, *y_curr, |t| {
            interpolator.interpolate(t).unwrap_or([f64::NAN; 2])
        });
        if ok {
            ControlFlag::Continue
        } else {
            ControlFlag::Terminate
        }
    }
}

pub fn run(m: DeMethod, job: &Job) -> RunResult {
    let cpu0 = crate::common::cpu_now();
    let sys = Sys {
        p: Paper::new(job.omega),
        evals: Counter::default(),
        jacs: Counter::default(),
    };
    let mut rec = Recorder::new(job, sys.p.x_i());
    let (t0, tf, y0) = (job.t0, job.t_end(), job.y0);
    let rtol = job.rtol;
    let atol = job.atol();
    const MAX: usize = 2_000_000_000;
    let res = {
        let ivp = IVP::ode(&sys, t0, tf, y0).solout(Obs { rec: &mut rec });
        // The same settings on every method: rtol, per-component atol, run-wide step and
        // rejection limits raised (BDF has no rejection limit).
        macro_rules! solve {
            ($builder:expr) => {
                ivp.method($builder.rtol(rtol).atol(atol).max_steps(MAX))
                    .solve()
                    .map(|s| (s.status.clone(), s.evals.function))
            };
            ($builder:expr, rejects) => {
                solve!($builder.max_rejects(MAX))
            };
        }
        match m {
            DeMethod::Dopri5 => solve!(ExplicitRungeKutta::dopri5(), rejects),
            DeMethod::Dop853 => solve!(ExplicitRungeKutta::dop853(), rejects),
            DeMethod::Rkv988e => solve!(ExplicitRungeKutta::rkv988e(), rejects),
            DeMethod::Radau5 => solve!(ImplicitRungeKutta::radau5(), rejects),
            DeMethod::Kvaerno745 => solve!(DiagonallyImplicitRungeKutta::kvaerno745(), rejects),
            DeMethod::Bdf => solve!(BackwardDifferentiationFormula::adaptive()),
        }
    };
    let elapsed = crate::common::cpu_now() - cpu0;
    let frac = rec.fraction(job);
    let lib_rhs_evals = res.as_ref().ok().map(|(_, n)| *n as u64);
    let status = match res {
        Ok((st, _)) => {
            if rec.timed_out {
                Status::Timeout(frac)
            } else {
                match st {
                    differential_equations::status::Status::Complete => Status::Ok,
                    other => Status::Failed(format!("{other:?}"), frac),
                }
            }
        }
        Err(e) => Status::Failed(format!("{e:?}"), frac),
    };
    let end = rec.finish_last();
    RunResult {
        status,
        elapsed,
        rhs_evals: sys.evals.get(),
        lib_rhs_evals,
        jac_evals: sys.jacs.get(),
        impacts: std::mem::take(&mut rec.impacts),
        strobe: std::mem::take(&mut rec.strobe),
        end,
    }
}
