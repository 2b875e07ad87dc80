//! `ode_solvers` (0.6): `Dopri5` / `Dop853` with a `System` whose `solout(x, y, dy)` is
//! called after every accepted step.
//!
//! What its API allows, and what it does not:
//! - No event location. `solout` sees only the step end `(x, y, dy)`, and only with
//!   `OutputType::Sparse`: in `Dense` mode it is handed the last *dense-output* point instead of
//!   the step's state. So impacts are found from the sign change of `x − x_I` between step
//!   ends and located (Illinois, 1e-12 s) on the cubic Hermite interpolant built from the two
//!   ends' `(y, dy)` — 3rd-order, whatever the method's order.
//! - No dense output inside `solout`. Sections are therefore hit exactly: the run is split
//!   into one `integrate()` per forcing period (`x_end = t0 + (i+1)·P`), the next period
//!   starting with the last full step size of the previous one.
//! - Scalar `atol` only. The state is integrated in scaled units `u = x/10⁻⁴`, `w = v/10⁻²`
//!   with `atol = rtol`, which is exactly the per-component tolerance `[rtol·10⁻⁴, rtol·10⁻²]`
//!   of the other solvers in the same (RMS) error norm.
//! - Stiffness detection (which aborts the run) is pushed out of reach (`n_stiff` = 2³¹).

use ode_solvers::{Dop853, Dopri5, OutputType, System, Vector2};

use crate::common::{Counter, Job, Paper, Recorder, RunResult, Status, hermite};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OsMethod {
    Dopri5,
    Dop853,
}

const SX: f64 = 1e-4;
const SV: f64 = 1e-2;

/// What the step callback updates (borrowed by the system, read back after each period).
struct OsState {
    rec: Recorder,
    /// Previous step end in physical units: (t, y, dy).
    prev: (f64, [f64; 2], [f64; 2]),
    stop: bool,
}

struct Sys<'a> {
    p: Paper,
    evals: Counter,
    st: &'a mut OsState,
}

impl System<f64, Vector2<f64>> for Sys<'_> {
    #[inline(always)]
    fn system(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        self.evals.bump();
        let x = y[0] * SX;
        let v = y[1] * SV;
        dy[0] = v / SX;
        dy[1] = self.p.accel(t, x, v) / SV;
    }

    fn solout(&mut self, t: f64, y: &Vector2<f64>, dy: &Vector2<f64>) -> bool {
        let yb = [y[0] * SX, y[1] * SV];
        let fb = [dy[0] * SX, dy[1] * SV];
        let st = &mut *self.st;
        let (ta, ya, fa) = st.prev;
        if t > ta {
            let ok = st
                .rec
                .step(ta, t, ya, yb, |s| hermite(ta, t, ya, yb, fa, fb, s));
            if !ok {
                st.stop = true;
            }
        }
        st.prev = (t, yb, fb);
        st.stop
    }
}

pub fn run(m: OsMethod, job: &Job) -> RunResult {
    let cpu0 = crate::common::cpu_now();
    let p = Paper::new(job.omega);
    let evals = Counter::default();
    let period = job.period();
    let f0 = [job.y0[1], p.accel(job.t0, job.y0[0], job.y0[1])];
    let mut st = OsState {
        rec: Recorder::new(job, p.x_i()),
        prev: (job.t0, job.y0, f0),
        stop: false,
    };
    let mut y = Vector2::new(job.y0[0] / SX, job.y0[1] / SV);
    let mut h = 0.0; // 0: the solver picks the first step
    let mut status = Status::Ok;
    // ode_solvers' own count (`Stats::num_eval`, summed over the per-period calls).
    let (mut lib_evals, mut lib_ok) = (0u64, true);
    let (rtol, atol) = (job.rtol, job.rtol);
    for i in 0..job.n_periods {
        let ta = job.t0 + i as f64 * period;
        let tb = job.t0 + (i + 1) as f64 * period;
        let sys = Sys {
            p,
            evals: evals.clone(),
            st: &mut st,
        };
        let (res, h_last, y_last) = match m {
            OsMethod::Dopri5 => {
                let mut s = Dopri5::from_param(
                    sys,
                    ta,
                    tb,
                    period,
                    y,
                    rtol,
                    atol,
                    0.9,
                    0.04,
                    0.2,
                    10.0,
                    period,
                    h,
                    u32::MAX,
                    u32::MAX,
                    OutputType::Sparse,
                );
                let r = s.integrate();
                (
                    r.map(|st| st.num_eval),
                    tail2(s.x_out()),
                    s.y_out().last().copied(),
                )
            }
            OsMethod::Dop853 => {
                let mut s = Dop853::from_param(
                    sys,
                    ta,
                    tb,
                    period,
                    y,
                    rtol,
                    atol,
                    0.9,
                    0.0,
                    0.333,
                    6.0,
                    period,
                    h,
                    u32::MAX,
                    u32::MAX,
                    OutputType::Sparse,
                );
                let r = s.integrate();
                (
                    r.map(|st| st.num_eval),
                    tail2(s.x_out()),
                    s.y_out().last().copied(),
                )
            }
        };
        match res {
            Ok(n) => lib_evals += u64::from(n),
            Err(e) => {
                status = Status::Failed(format!("{e:?}"), st.rec.fraction(job));
                lib_ok = false;
                break;
            }
        }
        if st.stop {
            status = Status::Timeout(st.rec.fraction(job));
            break;
        }
        if let Some(ly) = y_last {
            y = ly;
        }
        // The next period starts with the last unclipped step of this one.
        if let Some(hh) = h_last {
            h = hh;
        }
    }
    let elapsed = crate::common::cpu_now() - cpu0;
    let end = st.rec.finish_last();
    RunResult {
        status,
        elapsed,
        rhs_evals: evals.get(),
        lib_rhs_evals: lib_ok.then_some(lib_evals),
        jac_evals: 0,
        impacts: std::mem::take(&mut st.rec.impacts),
        strobe: std::mem::take(&mut st.rec.strobe),
        end,
    }
}

/// The step before the last (the last one is clipped to the period's end).
fn tail2(x: &[f64]) -> Option<f64> {
    let n = x.len();
    if n >= 3 {
        Some(x[n - 2] - x[n - 3])
    } else {
        None
    }
}
