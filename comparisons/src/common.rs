//! What every runner shares: the job description, the result of a run, the hand-written
//! right-hand side used for the peers, and the stroboscopic/impact recorder with its root
//! locator (used by the peers; `nonsmooth` uses its own samplers and event engine).

use std::cell::Cell;
use std::rc::Rc;
use std::time::Instant;

use nonsmooth::systems::paper::PAPER;

/// CPU time of the calling thread (s). Timings use it rather than wall time: the machine
/// is shared with other jobs, which inflate wall time by descheduling.
pub fn cpu_now() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes into the timespec we own.
    unsafe {
        libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts);
    }
    ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
}

/// One integration task: from `(t0, y0)` over `n_periods` forcing periods.
#[derive(Debug, Clone, Copy)]
pub struct Job {
    pub omega: f64,
    pub t0: f64,
    pub y0: [f64; 2],
    pub n_periods: u64,
    pub rtol: f64,
    /// Wall-clock budget (s); a run that exceeds it stops and reports the fraction done.
    pub budget_s: f64,
}

impl Job {
    pub fn period(&self) -> f64 {
        std::f64::consts::TAU / self.omega
    }
    pub fn t_end(&self) -> f64 {
        self.t0 + self.n_periods as f64 * self.period()
    }
    /// Per-component absolute tolerances: x in m (~1e-3), v in m/s (~1e-2).
    pub fn atol(&self) -> [f64; 2] {
        [self.rtol * 1e-4, self.rtol * 1e-2]
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    Ok,
    /// The wall-clock budget ran out at this fraction of the span.
    Timeout(f64),
    /// The solver returned an error (message) at this fraction of the span.
    Failed(String, f64),
    /// The method cannot do this workload through its API (explanation).
    Unsupported(String),
}

impl Status {
    pub fn is_ok(&self) -> bool {
        matches!(self, Status::Ok)
    }
    pub fn short(&self) -> String {
        match self {
            Status::Ok => "ok".into(),
            Status::Timeout(f) => format!("timeout at {:.1}%", 100.0 * f),
            Status::Failed(m, f) => format!("failed at {:.1}%: {}", 100.0 * f, m),
            Status::Unsupported(m) => format!("unsupported: {m}"),
        }
    }
}

/// The result of one run.
#[derive(Debug, Clone)]
pub struct RunResult {
    pub status: Status,
    /// CPU time of the run (s, [`cpu_now`]), construction of the solver included.
    pub elapsed: f64,
    /// Right-hand-side evaluations, counted inside the right-hand side itself (a [`Counter`]
    /// bumped on every call, for every library).
    pub rhs_evals: u64,
    /// The library's own count of its right-hand-side evaluations, where it reports one
    /// (`nonsmooth`: `Stats::rhs_evals`; `differential-equations`: `Solution::evals.function`),
    /// for the check that it agrees with [`rhs_evals`](Self::rhs_evals).
    pub lib_rhs_evals: Option<u64>,
    /// Jacobian(-vector) evaluations, if any.
    pub jac_evals: u64,
    /// Impact times (upward crossings of x = x_I).
    pub impacts: Vec<f64>,
    /// `(t, x, v)` at `t0 + i·P`, `i = 1..=n`.
    pub strobe: Vec<[f64; 3]>,
    /// Final `(t, x, v)`.
    pub end: [f64; 3],
}

impl RunResult {
    pub fn unsupported(msg: &str) -> Self {
        Self {
            status: Status::Unsupported(msg.into()),
            elapsed: f64::NAN,
            rhs_evals: 0,
            lib_rhs_evals: None,
            jac_evals: 0,
            impacts: vec![],
            strobe: vec![],
            end: [f64::NAN; 3],
        }
    }
}

/// The paper's right-hand side written out by hand for the peers, operation for operation as
/// `nonsmooth` evaluates it (`PAPER.oscillator(ω)`: spring + viscous + regularized friction +
/// Hertz contact with the rate regularization `v(v²+η²)^((n3−1)/2)`, `d^{3/2} = d·√d`, the
/// power as `exp(((n3−1)/2)·ln(v²+η²))`), so that all solvers integrate the same function.
#[derive(Debug, Clone, Copy)]
pub struct Paper {
    inv_m: f64,
    k: f64,
    c: f64,
    t_fr: f64,
    eps: f64,
    x_i: f64,
    k_i: f64,
    b: f64,
    n3: f64,
    half_n3_m1: f64,
    eta: f64,
    amp: f64,
    omega: f64,
}

impl Paper {
    pub fn new(omega: f64) -> Self {
        let p = PAPER;
        Self {
            inv_m: 1.0 / p.m,
            k: p.k,
            c: p.c,
            t_fr: p.t,
            eps: p.eps,
            x_i: p.x_i,
            k_i: p.k_i,
            b: p.b,
            n3: p.n3,
            half_n3_m1: (p.n3 - 1.0) * 0.5,
            eta: p.eta,
            amp: p.m0e * omega * omega,
            omega,
        }
    }

    pub fn x_i(&self) -> f64 {
        self.x_i
    }

    /// `ẍ = (m0·e·ω²·sin ωt − ΣF(x, v)) / m`.
    #[inline(always)]
    pub fn accel(&self, t: f64, x: f64, v: f64) -> f64 {
        let spring = self.k * (x - 0.0);
        let visc = self.c * v;
        let fric = self.t_fr * v / (v * v + self.eps * self.eps).sqrt();
        let d = x - self.x_i;
        let contact = if d <= 0.0 {
            0.0
        } else {
            let p1 = d * d.sqrt();
            let s = v * v + self.eta * self.eta;
            let p = (self.half_n3_m1 * s.ln()).exp();
            let f = p1 + self.b * p1 * (v * p);
            if f <= 0.0 { 0.0 } else { self.k_i * f }
        };
        let total = 0.0 + spring + visc + fric + contact;
        // The crate's `sin` (fdlibm kernels, ≤ 1 ulp against libm): the peers evaluate the
        // same function, so the right-hand sides agree to the bit (`rhs_agreement`).
        (self.amp * nonsmooth::util::sin_f64(self.omega * t) - total) * self.inv_m
    }

    /// `(∂ẍ/∂x, ∂ẍ/∂v)` (analytic, as `nonsmooth`'s `Oscillator::jacobian`).
    #[inline(always)]
    pub fn accel_partials(&self, x: f64, v: f64) -> (f64, f64) {
        let e2 = self.eps * self.eps;
        let s = v * v + e2;
        let mut fx = self.k;
        let mut fv = self.c + self.t_fr * e2 / (s * s.sqrt());
        let d = x - self.x_i;
        if d > 0.0 {
            let sd = d.sqrt();
            let (p1, dp1) = (d * sd, 1.5 * sd);
            let s = v * v + self.eta * self.eta;
            let p = (self.half_n3_m1 * s.ln()).exp();
            let g = v * p;
            let dg = p * (self.n3 * v * v + self.eta * self.eta) / s;
            let f = p1 + self.b * p1 * g;
            if f > 0.0 {
                fx += self.k_i * (dp1 + self.b * dp1 * g);
                fv += self.k_i * (self.b * p1 * dg);
            }
        }
        (-fx * self.inv_m, -fv * self.inv_m)
    }
}

/// A shared evaluation counter (cheap: one non-atomic increment per evaluation).
#[derive(Debug, Clone, Default)]
pub struct Counter(pub Rc<Cell<u64>>);

impl Counter {
    #[inline(always)]
    pub fn bump(&self) {
        self.0.set(self.0.get() + 1);
    }
    pub fn get(&self) -> u64 {
        self.0.get()
    }
}

/// The absolute event-time tolerance (the same as `nonsmooth`'s default, 1e-12 s).
pub const EVENT_TOL: f64 = 1e-12;

/// Locates the crossing of `g` in `[a, b]` (`ga`, `gb` of opposite signs) by the Illinois
/// variant of regula falsi, to `|Δt| ≤ EVENT_TOL` (what `nonsmooth` uses too).
pub fn illinois(mut g: impl FnMut(f64) -> f64, a: f64, b: f64, ga: f64, gb: f64) -> f64 {
    let (mut a, mut b, mut ga, mut gb) = (a, b, ga, gb);
    let tol = EVENT_TOL.max(4.0 * f64::EPSILON * b.abs());
    let mut side = 0i8;
    for _ in 0..200 {
        if (b - a).abs() <= tol {
            break;
        }
        let mut c = if gb != ga {
            (a * gb - b * ga) / (gb - ga)
        } else {
            0.5 * (a + b)
        };
        let lo = a + 0.5 * tol;
        let hi = b - 0.5 * tol;
        if c.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
            c = lo;
        }
        if c.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
            c = hi;
        }
        let gc = g(c);
        if (gc >= 0.0) == (gb >= 0.0) {
            b = c;
            gb = gc;
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        } else {
            a = c;
            ga = gc;
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        }
    }
    b
}

/// Cubic Hermite interpolation on `[t0, t1]` from the states and derivatives at the ends
/// (for `ode_solvers`, whose step callback exposes no dense output).
#[inline]
pub fn hermite(
    t0: f64,
    t1: f64,
    y0: [f64; 2],
    y1: [f64; 2],
    f0: [f64; 2],
    f1: [f64; 2],
    t: f64,
) -> [f64; 2] {
    let h = t1 - t0;
    let s = (t - t0) / h;
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    let mut out = [0.0; 2];
    for i in 0..2 {
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
    }
    out
}

/// Stroboscopic samples and impact times from a stream of accepted steps with an interpolant
/// (the peers' side of the comparison). Checks the wall-clock budget every 64 steps.
pub struct Recorder {
    t0: f64,
    period: f64,
    n: u64,
    next_i: u64,
    x_i: f64,
    pub strobe: Vec<[f64; 3]>,
    pub impacts: Vec<f64>,
    start: Instant,
    budget_s: f64,
    calls: u32,
    pub timed_out: bool,
    pub t_reached: f64,
    pub y_reached: [f64; 2],
}

impl Recorder {
    pub fn new(job: &Job, x_i: f64) -> Self {
        Self {
            t0: job.t0,
            period: job.period(),
            n: job.n_periods,
            next_i: 1,
            x_i,
            strobe: Vec::with_capacity(job.n_periods as usize + 1),
            impacts: Vec::with_capacity(4 * job.n_periods as usize),
            start: Instant::now(),
            budget_s: job.budget_s,
            calls: 0,
            timed_out: false,
            t_reached: job.t0,
            y_reached: job.y0,
        }
    }

    #[inline]
    fn section_time(&self, i: u64) -> f64 {
        self.t0 + i as f64 * self.period
    }

    pub fn x_i(&self) -> f64 {
        self.x_i
    }

    /// [`step`](Self::step) without the impact search (for solvers that locate events
    /// themselves and push into `impacts`).
    #[inline]
    pub fn step_sections_only(
        &mut self,
        ta: f64,
        tb: f64,
        ya: [f64; 2],
        yb: [f64; 2],
        interp: impl FnMut(f64) -> [f64; 2],
    ) -> bool {
        let x_i = self.x_i;
        self.x_i = f64::INFINITY;
        let ok = self.step(ta, tb, ya, yb, interp);
        self.x_i = x_i;
        ok
    }

    /// One accepted step `[ta, tb]`; `interp(t)` evaluates the step's interpolant. Returns
    /// `false` when the budget is exhausted (the caller stops the solver).
    #[inline]
    pub fn step(
        &mut self,
        ta: f64,
        tb: f64,
        ya: [f64; 2],
        yb: [f64; 2],
        mut interp: impl FnMut(f64) -> [f64; 2],
    ) -> bool {
        let ga = ya[0] - self.x_i;
        let gb = yb[0] - self.x_i;
        if ga < 0.0 && gb >= 0.0 {
            let x_i = self.x_i;
            let tc = illinois(|t| interp(t)[0] - x_i, ta, tb, ga, gb);
            self.impacts.push(tc);
        }
        while self.next_i <= self.n {
            let ts = self.section_time(self.next_i);
            if ts > tb {
                break;
            }
            let y = if ts == tb { yb } else { interp(ts.max(ta)) };
            self.strobe.push([ts, y[0], y[1]]);
            self.next_i += 1;
        }
        self.t_reached = tb;
        self.y_reached = yb;
        self.calls += 1;
        if self.calls.is_multiple_of(64) && self.start.elapsed().as_secs_f64() > self.budget_s {
            self.timed_out = true;
            return false;
        }
        true
    }

    /// The final state; records a last section the steps ended on up to rounding.
    pub fn finish(&mut self, t: f64, y: [f64; 2]) {
        while self.next_i <= self.n {
            let ts = self.section_time(self.next_i);
            if (ts - t).abs() <= 1e-12 * t.abs().max(1.0) {
                self.strobe.push([ts, y[0], y[1]]);
                self.next_i += 1;
            } else {
                break;
            }
        }
    }

    /// [`finish`](Self::finish) with the last step's end; returns the final `(t, x, v)`.
    pub fn finish_last(&mut self) -> [f64; 3] {
        let (t, y) = (self.t_reached, self.y_reached);
        self.finish(t, y);
        [t, y[0], y[1]]
    }

    pub fn fraction(&self, job: &Job) -> f64 {
        ((self.t_reached - job.t0) / (job.t_end() - job.t0)).clamp(0.0, 1.0)
    }
}
