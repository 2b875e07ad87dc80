//! `nonsmooth` itself: `Simulation` + `Event(Level(0, x_I), Rising)` + `Stroboscopic`.

use std::time::Instant;

use nalgebra::{Matrix2, Vector2};
use nonsmooth::Dynamics;
use nonsmooth::drive::{Control, EventRecord, Observer, Simulation, StepView, Termination};
use nonsmooth::event::{Direction, Event, Level};
use nonsmooth::integrate::{
    CuspImplicit, CuspSwitch, DenseOutput, Dop853, Dopri5, Rosenbrock23, StepOptions, Stepper,
    Tolerances, TurningPoints,
};
use nonsmooth::sample::Stroboscopic;
use nonsmooth::systems::paper::{PAPER, PaperOscillator, PaperParameters};

use crate::common::{Counter, Job, RunResult, Status};

/// Which stepper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ours {
    Dopri5,
    Dop853,
    Rosenbrock23,
    /// DOPRI5 with every step cut at the section times (`landing_grid`) instead of
    /// interpolating them.
    Dopri5Grid,
    /// DOPRI5 with the predictive controller correction on.
    Dopri5Pred,
    /// DOPRI5 in time, and DOPRI5 across the turning points (`|ẋ| < 3e-3 m/s`) with the
    /// velocity's power scale as the independent variable (`TurningPoints::dopri5`).
    Dopri5Turning,
    /// The paper's exact contact law (`η = 0`) with DOPRI5 alone.
    Dopri5Exact,
    /// The exact law with `CuspSwitch::dopri5(tol, 1e-6)`: DOPRI5, and the extrapolated
    /// backward Euler cusp step where the creep in contact makes DOPRI5 stiffness-bound.
    CuspExact,
    /// The exact law with `CuspSwitch` over `TurningPoints::dopri5(tol, 3e-3)` (the
    /// fastest regularized configuration as the explicit side).
    TurningCuspExact,
    /// The exact law with DOP853 (a cross-check of the `η = 0` reference; not a table row).
    Dop853Exact,
    /// DOP853 with `η = 1e-11 m/s` (the `η = 0` accuracy reference; not a table row): the
    /// exact law itself does not run at the reference tolerance, and `η = 1e-11` differs
    /// from it by `(10⁻³)^{1+2n3} ≈ 8·10⁻⁵` of the distance between `η = 1e-8` and `η = 0`
    /// (order `1 + 2n3` in `η`, `examples/exact_law.rs`).
    Dop853Eta11,
}

/// The band `|ẋ| < CUSP_BAND` (m/s) in which `CuspSwitch` probes the cusp's stiffness (the
/// value of `examples/exact_law.rs`).
pub const CUSP_BAND: f64 = 1e-6;

/// The band `|ẋ| < TURNING_BAND` (m/s) of `TurningPoints`.
const TURNING_BAND: f64 = 3e-3;

impl Ours {
    /// Whether the configuration runs the exact contact law (`η = 0`) instead of the
    /// crate's default regularization `η = 1e-8 m/s`.
    pub fn exact_law(self) -> bool {
        matches!(
            self,
            Ours::Dopri5Exact | Ours::CuspExact | Ours::TurningCuspExact | Ours::Dop853Exact
        )
    }
}

/// The paper's parameters, with `η = 0` for the exact-law configurations.
fn parameters(kind: Ours) -> PaperParameters {
    let mut p = PAPER;
    if kind.exact_law() {
        p.eta = 0.0;
    } else if kind == Ours::Dop853Eta11 {
        p.eta = 1e-11;
    }
    p
}

/// Impact times.
#[derive(Default)]
struct Impacts(Vec<f64>);

impl Observer<f64, 2> for Impacts {
    fn on_event(&mut self, e: &EventRecord<f64, 2>) -> Control {
        self.0.push(e.t);
        Control::Continue
    }
}

/// Stops the run when the wall-clock budget is spent (checked every 64 steps).
struct Budget {
    start: Instant,
    limit: f64,
    calls: u32,
    timed_out: bool,
    t: f64,
}

impl Observer<f64, 2> for Budget {
    #[inline]
    fn on_step<D: DenseOutput<f64, 2>>(&mut self, s: &StepView<'_, f64, 2, D>) -> Control {
        self.t = s.t1;
        self.calls += 1;
        if self.calls.is_multiple_of(64) && self.start.elapsed().as_secs_f64() > self.limit {
            self.timed_out = true;
            return Control::Stop;
        }
        Control::Continue
    }
}

/// The model behind a never-inlined `rhs` (profiling only: callgrind then attributes the
/// right-hand side's cost exactly, as the inclusive cost of `NoInline::rhs`).
struct NoInline(PaperOscillator<f64>);

impl Dynamics<f64, 2> for NoInline {
    #[inline(never)]
    fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        self.0.rhs(t, y, dy)
    }
    fn jacobian(&self, t: f64, y: &Vector2<f64>) -> Option<Matrix2<f64>> {
        self.0.jacobian(t, y)
    }
    fn time_derivative(&self, t: f64, y: &Vector2<f64>) -> Option<Vector2<f64>> {
        self.0.time_derivative(t, y)
    }
    fn velocity_exponent(&self) -> Option<f64> {
        self.0.velocity_exponent()
    }
    fn cusp_exponent(&self) -> Option<f64> {
        self.0.cusp_exponent()
    }
}

/// The system as `Simulation` sees it: every right-hand-side (and Jacobian) evaluation bumps
/// the same [`Counter`] the peers bump inside their right-hand sides (one non-atomic increment
/// through an `Rc<Cell<u64>>`), so the RHS figures of all libraries are counted the same way
/// and cost the same. `Stats::rhs_evals`, the stepper's own bookkeeping, is reported next to
/// it ([`RunResult::lib_rhs_evals`]).
struct Counted<S> {
    sys: S,
    evals: Counter,
    jacs: Counter,
}

impl<S: Dynamics<f64, 2>> Dynamics<f64, 2> for Counted<S> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        self.evals.bump();
        self.sys.rhs(t, y, dy)
    }
    #[inline(always)]
    fn jacobian(&self, t: f64, y: &Vector2<f64>) -> Option<Matrix2<f64>> {
        self.jacs.bump();
        self.sys.jacobian(t, y)
    }
    #[inline(always)]
    fn time_derivative(&self, t: f64, y: &Vector2<f64>) -> Option<Vector2<f64>> {
        self.sys.time_derivative(t, y)
    }
    fn velocity_exponent(&self) -> Option<f64> {
        self.sys.velocity_exponent()
    }
    fn cusp_exponent(&self) -> Option<f64> {
        self.sys.cusp_exponent()
    }
}

pub fn run(kind: Ours, job: &Job) -> RunResult {
    let osc = parameters(kind)
        .oscillator::<f64>(job.omega)
        .expect("model");
    if std::env::var_os("NONSMOOTH_RHS_NOINLINE").is_some() {
        run_with(NoInline(osc), kind, job)
    } else {
        run_with(osc, kind, job)
    }
}

fn run_with<S: Dynamics<f64, 2>>(sys: S, kind: Ours, job: &Job) -> RunResult {
    let start = Instant::now();
    let cpu0 = crate::common::cpu_now();
    let tol = Tolerances::per_component(job.rtol, job.atol()).expect("tolerances");
    match kind {
        Ours::Dopri5 => go(sys, Dopri5::new(tol), job, false, start, cpu0),
        Ours::Dopri5Grid => go(sys, Dopri5::new(tol), job, true, start, cpu0),
        Ours::Dopri5Pred => go(
            sys,
            Dopri5::with_options(tol, StepOptions::default().with_predictive(true)),
            job,
            false,
            start,
            cpu0,
        ),
        Ours::Dopri5Turning => {
            let st = TurningPoints::dopri5(tol, TURNING_BAND).expect("band");
            go(sys, st, job, false, start, cpu0)
        }
        Ours::Dopri5Exact => go(sys, Dopri5::new(tol), job, false, start, cpu0),
        Ours::CuspExact => {
            let st = CuspSwitch::dopri5(tol, CUSP_BAND).expect("band");
            go(sys, st, job, false, start, cpu0)
        }
        Ours::TurningCuspExact => {
            let st = CuspSwitch::new(
                TurningPoints::dopri5(tol, TURNING_BAND).expect("band"),
                CuspImplicit::new(tol),
                CUSP_BAND,
            )
            .expect("band");
            go(sys, st, job, false, start, cpu0)
        }
        Ours::Dop853 | Ours::Dop853Exact | Ours::Dop853Eta11 => {
            go(sys, Dop853::new(tol), job, false, start, cpu0)
        }
        Ours::Rosenbrock23 => go(sys, Rosenbrock23::new(tol), job, false, start, cpu0),
    }
}

fn go<S: Dynamics<f64, 2>, St: Stepper<f64, 2>>(
    sys: S,
    stepper: St,
    job: &Job,
    grid: bool,
    start: Instant,
    cpu0: f64,
) -> RunResult {
    let impact = Event::new(Level::new(0, PAPER.x_i).expect("level"), Direction::Rising);
    let period = job.period();
    let (evals, jacs) = (Counter::default(), Counter::default());
    let osc = Counted {
        sys,
        evals: evals.clone(),
        jacs: jacs.clone(),
    };
    let mut sim = Simulation::new(osc, stepper).with_events(impact);
    if grid {
        sim = sim.landing_grid(Some((job.t0, period))).expect("grid");
    }
    let mut strobe = Stroboscopic::periodic(
        job.t0,
        period,
        job.t0 + 0.5 * period,
        job.n_periods as usize + 1,
    )
    .expect("strobe");
    let mut impacts = Impacts(Vec::with_capacity(4 * job.n_periods as usize));
    let mut budget = Budget {
        start,
        limit: job.budget_s,
        calls: 0,
        timed_out: false,
        t: job.t0,
    };
    let res = sim.run(
        job.t0,
        Vector2::new(job.y0[0], job.y0[1]),
        job.t_end(),
        &mut (&mut strobe, &mut impacts, &mut budget),
    );
    let elapsed = crate::common::cpu_now() - cpu0;
    let stats = *sim.stepper().stats();
    let frac = ((budget.t - job.t0) / (job.t_end() - job.t0)).clamp(0.0, 1.0);
    let strobe: Vec<[f64; 3]> = strobe
        .points()
        .iter()
        .map(|p| [p.t, p.y[0], p.y[1]])
        .collect();
    match res {
        Ok(out) => {
            let status = match out.termination {
                Termination::ReachedEnd => Status::Ok,
                _ if budget.timed_out => Status::Timeout(frac),
                t => Status::Failed(format!("{t:?}"), frac),
            };
            RunResult {
                status,
                elapsed,
                rhs_evals: evals.get(),
                lib_rhs_evals: Some(stats.rhs_evals),
                jac_evals: jacs.get(),
                impacts: impacts.0,
                strobe,
                end: [out.t, out.y[0], out.y[1]],
            }
        }
        Err(e) => RunResult {
            status: Status::Failed(e.to_string(), frac),
            elapsed,
            rhs_evals: evals.get(),
            lib_rhs_evals: Some(stats.rhs_evals),
            jac_evals: jacs.get(),
            impacts: impacts.0,
            strobe,
            end: [f64::NAN; 3],
        },
    }
}
