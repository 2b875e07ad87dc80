//! Higher-order explicit pairs against DOPRI5: Tsitouras 5(4) (`Tsit5`) and Verner 6(5)
//! (`Vern6`) beside DOPRI5 and DOP853, on the paper's model and on Duffing–Ueda, at rtol
//! 1e-8, 1e-10 and 1e-12.
//!
//! # Workloads
//! - **W2** (`comparisons/`): the paper's oscillator at ω = 20.465 rad/s (chaotic), 1000
//!   forcing periods from the state after 100 periods (DOP853 at rtol 1e-12 from rest);
//!   every impact (upward crossing of `x_I`) located, steps landing on the sections
//!   `t = 2πk/ω`; `atol = [rtol·10⁻⁴ m, rtol·10⁻² m/s]`. Each method plain, and with
//!   [`TurningPoints`] over it (the same method in time and in the segments `|ẋ| < 3 mm/s`,
//!   with the segment tolerances of [`TurningPoints::dopri5`]).
//! - **Duffing–Ueda** (smooth; Ueda's chaotic attractor, `k = 0.05`, `B = 7.5`, ω = 1):
//!   200 periods from `(3, 0)`, steps landing on `t = 2πk`, `atol = rtol`.
//!
//! # Columns
//! RHS evaluations, accepted and rejected steps, CPU seconds (this thread's CPU time where
//! `/proc/thread-self/schedstat` exists, wall time otherwise; the smallest of `--reps`
//! turns, 3 by default), the ratios of evaluations and time to DOPRI5 in the same mode
//! (plain or turning points), and the accuracy: from 10 states on the attractor (W2: the
//! sections 100, 110, …, 190 from rest; Duffing–Ueda: 10, 20, …, 100 from `(3, 0)`), the
//! largest `|Δx|` over the sections `k = 1..K` against a DOP853 run at rtol 1e-13 from the
//! same state (`K = 3` on W2, where differences grow ~10× in 3 periods; `K = 3` on
//! Duffing–Ueda), its RMS over the 10 states in m, and in units of `rtol·X` with `X` the
//! largest `|x|` of the reference sections (the tolerance's scale). Chaos amplifies every
//! error over the `K` periods, so this is 10–10³, alike for all methods; what matters is
//! the comparison at equal error: the second table of each mode interpolates each
//! method's evaluations and time (log–log between its rows) at DOPRI5's error.
//!
//! # Measured (two runs on 2 shared cores, 3 turns each, at commit 59aaa33)
//! The evaluation counts are deterministic; the CPU ratios moved by up to ±20 % between the
//! two runs (both given). Ratios to DOPRI5 at DOPRI5's error, for rtol 1e-8 / 1e-10 / 1e-12:
//! - **W2, plain**: Tsit5 1.17 / 1.10 / 0.96 the evaluations (CPU 1.25–1.34 / 1.12–1.30 /
//!   0.98–1.18), Vern6 1.40 / 1.23 / 1.36 (CPU 1.41–1.48 / 1.18–1.39 / 1.14–1.47), DOP853
//!   2.02 / 1.58 / 1.10 (CPU 1.77–1.88 / 1.49–1.62 / 1.03–1.18).
//! - **W2, turning points**: Tsit5 0.91 / 0.92 / 1.01 (CPU 0.96 / 1.02–1.18 / 1.01–1.03),
//!   Vern6 1.31 / 1.13 / 1.23 (CPU 1.21–1.56 / 1.29–1.31 / 1.07–1.11), DOP853 1.57 / 1.22 /
//!   0.91 (CPU 1.20–1.68 / 1.23–1.32 / 0.79–0.99). At equal *rtol* 1e-12, DOP853 with
//!   turning points takes 0.79× the evaluations and 0.70–0.81× the time of DOPRI5 with
//!   them, at 3.4× its error. No new pair wins the paper's workload: its steps are bounded
//!   by the contact onsets and exits and the reversals, not by the smooth flow between them.
//! - **Duffing–Ueda** (smooth): DOP853 0.49 / 0.39 / 0.28 (CPU 0.36–0.73 / 0.44–0.46 /
//!   0.34–0.37), Vern6 0.71 / 0.59 / 1.53 (CPU 0.72–0.97 / 0.62–0.65 / 1.66–1.73), Tsit5
//!   0.85 / 0.84 / 0.82 (CPU 1.04–1.15 / 1.02–1.07 / 0.95–1.05: its step costs more per
//!   evaluation than the hand-written DOPRI5 on this cheap right-hand side). Vern6 at
//!   1e-12 rejects 10 % of its steps over 2000 periods (192 708): the rounding of the stage
//!   times to the spacing of `t` (up to `1.3·10⁴` here), multiplied by its large weights
//!   (see [`Vern6`]). The last table runs the same 200 periods with the clock started at
//!   `t₀ = 0`, `1.2·10⁴` and `1.2·10⁵`: Vern6 takes 91 750 / 271 717 / 1 955 997 accepted
//!   and 1 481 / 35 049 / 277 096 rejected steps, DOPRI5 214 178 / 212 252 / 214 008 and
//!   23 / 26 / 32.
//!
//! [`Vern6`]: nonsmooth::integrate::Vern6
//!
//! ```sh
//! cargo run --release --example rk_pairs             # ≈ 1–2 min
//! cargo run --release --example rk_pairs -- --quick  # 200 W2 periods, 1 turn
//! ```

use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::Dynamics;
use nonsmooth::drive::{Control, EventRecord, Observer, Simulation, StepView};
use nonsmooth::event::{Direction, Event, Stop};
use nonsmooth::integrate::{
    Adaptive, DenseOutput, Dop853Method, Dopri5Method, Method, Stats, Stepper, Tolerances,
    Tsit5Method, TurningPoints, Vern6Method,
};
use nonsmooth::systems::DuffingUeda;
use nonsmooth::systems::paper::{PAPER, PaperParameters};

const OMEGA_W2: f64 = 20.465;
const RTOLS: [f64; 3] = [1e-8, 1e-10, 1e-12];
const RTOL_REF: f64 = 1e-13;

/// Section points at `t = t0 + k·period` (steps land there) and the impacts.
struct Record {
    t0: f64,
    period: f64,
    sections: Vec<Vector2<f64>>,
    impacts: u64,
}

impl Observer<f64, 2> for Record {
    fn on_step<D: DenseOutput<f64, 2>>(&mut self, s: &StepView<'_, f64, 2, D>) -> Control {
        let k = ((s.t1 - self.t0) / self.period).round();
        if k >= 1.0 && s.t1 == self.t0 + k * self.period {
            self.sections.push(s.y1);
        }
        Control::Continue
    }
    fn on_event(&mut self, _e: &EventRecord<f64, 2>) -> Control {
        self.impacts += 1;
        Control::Continue
    }
}

/// A workload: the system, its start, its section period and length, its tolerances.
trait Workload {
    type System: Dynamics<f64, 2>;
    fn name(&self) -> &str;
    fn system(&self) -> nonsmooth::Result<Self::System>;
    fn period(&self) -> f64;
    /// `(t0, y0)`, with `t0` a section time.
    fn start(&self) -> (f64, Vector2<f64>);
    fn tolerances(&self, rtol: f64) -> nonsmooth::Result<Tolerances<f64, 2>>;
    /// The impact stop, if any.
    fn stop(&self) -> Option<f64>;
}

struct W2 {
    t0: f64,
    y0: Vector2<f64>,
}

impl Workload for W2 {
    type System = nonsmooth::systems::paper::PaperOscillator<f64>;
    fn name(&self) -> &str {
        "W2"
    }
    fn system(&self) -> nonsmooth::Result<Self::System> {
        Ok(PAPER.oscillator(OMEGA_W2)?)
    }
    fn period(&self) -> f64 {
        PaperParameters::period(OMEGA_W2)
    }
    fn start(&self) -> (f64, Vector2<f64>) {
        (self.t0, self.y0)
    }
    fn tolerances(&self, rtol: f64) -> nonsmooth::Result<Tolerances<f64, 2>> {
        Ok(Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?)
    }
    fn stop(&self) -> Option<f64> {
        Some(PAPER.x_i)
    }
}

struct Ueda(nonsmooth::systems::duffing_ueda::DuffingUedaModel<f64>);

impl Workload for Ueda {
    type System = nonsmooth::systems::duffing_ueda::DuffingUedaModel<f64>;
    fn name(&self) -> &str {
        "Duffing–Ueda"
    }
    fn system(&self) -> nonsmooth::Result<Self::System> {
        Ok(self.0)
    }
    fn period(&self) -> f64 {
        std::f64::consts::TAU
    }
    fn start(&self) -> (f64, Vector2<f64>) {
        (0.0, Vector2::new(3.0, 0.0))
    }
    fn tolerances(&self, rtol: f64) -> nonsmooth::Result<Tolerances<f64, 2>> {
        Ok(Tolerances::new(rtol, rtol)?)
    }
    fn stop(&self) -> Option<f64> {
        None
    }
}

/// One run: work, sections, impacts, CPU (or wall) seconds.
struct Run {
    stats: Stats,
    sections: Vec<Vector2<f64>>,
    impacts: u64,
    seconds: f64,
}

/// This thread's CPU seconds, if the kernel reports them.
fn thread_cpu() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace()
        .next()?
        .parse::<f64>()
        .ok()
        .map(|ns| ns * 1e-9)
}

fn simulate<W: Workload, St>(
    w: &W,
    (t0, y0): (f64, Vector2<f64>),
    stepper: St,
    periods: u32,
) -> nonsmooth::Result<Run>
where
    St: Stepper<f64, 2>,
{
    let mut rec = Record {
        t0,
        period: w.period(),
        sections: Vec::new(),
        impacts: 0,
    };
    let sim = Simulation::new(w.system()?, stepper)
        .landing_grid(Some((t0, w.period())))?
        .max_steps(usize::MAX)?;
    let t_end = t0 + f64::from(periods) * w.period();
    let (wall, cpu) = (Instant::now(), thread_cpu());
    let out = match w.stop() {
        Some(level) => {
            let stop = Stop {
                position: 0,
                velocity: 1,
                level,
            };
            let mut sim = sim.with_events(Event::new(stop, Direction::Rising));
            sim.run(t0, y0, t_end, &mut rec)?
        }
        None => {
            let mut sim = sim;
            sim.run(t0, y0, t_end, &mut rec)?
        }
    };
    let seconds = match (cpu, thread_cpu()) {
        (Some(a), Some(b)) => b - a,
        _ => wall.elapsed().as_secs_f64(),
    };
    Ok(Run {
        stats: out.stats,
        sections: rec.sections,
        impacts: rec.impacts,
        seconds,
    })
}

/// The plain stepper of method `M`.
fn plain<M: Method<f64, 2>>(tol: Tolerances<f64, 2>) -> Adaptive<f64, 2, M> {
    Adaptive::new(tol)
}

/// Turning points with method `M` in time and in the segments.
type Turning<M> = TurningPoints<f64, Adaptive<f64, 2, M>, Adaptive<f64, 2, M>>;

/// [`TurningPoints`] with method `M` in time and in the segments (the segment tolerances
/// of [`TurningPoints::dopri5`]).
fn turning<M: Method<f64, 2>>(tol: Tolerances<f64, 2>) -> nonsmooth::Result<Turning<M>> {
    let rtol = tol.rtol[0];
    let segment = Tolerances::per_component(rtol, [100.0 * rtol, tol.atol[0]])?;
    Ok(TurningPoints::new(
        Adaptive::new(tol),
        Adaptive::new(segment),
        3e-3,
    )?)
}

/// The accuracy check: starts on the attractor and the reference sections from each.
struct Accuracy {
    starts: Vec<(f64, Vector2<f64>)>,
    references: Vec<Vec<Vector2<f64>>>,
    /// Sections compared per start.
    k: usize,
    /// The largest `|x|` over the reference sections.
    scale: f64,
}

impl Accuracy {
    /// DOP853 at [`RTOL_REF`] from every start.
    fn new<W: Workload>(
        w: &W,
        starts: Vec<(f64, Vector2<f64>)>,
        k: usize,
    ) -> nonsmooth::Result<Self> {
        let mut references = Vec::new();
        for &s in &starts {
            let tol = w.tolerances(RTOL_REF)?;
            references.push(simulate(w, s, plain::<Dop853Method>(tol), k as u32)?.sections);
        }
        let scale = references
            .iter()
            .flatten()
            .fold(0.0f64, |m, p| m.max(p[0].abs()));
        Ok(Self {
            starts,
            references,
            k,
            scale,
        })
    }
}

/// `reps` runs of the workload with the steppers `make` gives (the counts are
/// deterministic: the smallest time is kept), and the RMS over the accuracy starts of the
/// largest `|Δx|` over their sections.
fn measure<W: Workload, St: Stepper<f64, 2>>(
    w: &W,
    make: impl Fn() -> nonsmooth::Result<St>,
    periods: u32,
    reps: usize,
    acc: &Accuracy,
) -> nonsmooth::Result<(Run, f64)> {
    let mut best = simulate(w, w.start(), make()?, periods)?;
    for _ in 1..reps {
        let r = simulate(w, w.start(), make()?, periods)?;
        best.seconds = best.seconds.min(r.seconds);
    }
    let mut sq = 0.0;
    for (&start, reference) in acc.starts.iter().zip(&acc.references) {
        let r = simulate(w, start, make()?, acc.k as u32)?;
        let e = r
            .sections
            .iter()
            .zip(reference)
            .fold(0.0f64, |m, (a, b)| m.max((a[0] - b[0]).abs()));
        sq += e * e;
    }
    Ok((best, (sq / acc.starts.len() as f64).sqrt()))
}

const METHODS: [&str; 4] = ["DOPRI5", "Tsit5", "Vern6", "DOP853"];

/// Runs method number `i` of [`METHODS`], plain or with turning points.
fn run_method<W: Workload>(
    w: &W,
    (i, turn): (usize, bool),
    rtol: f64,
    periods: u32,
    reps: usize,
    acc: &Accuracy,
) -> nonsmooth::Result<(Run, f64)> {
    let tol = w.tolerances(rtol)?;
    match (i, turn) {
        (0, false) => measure(w, || Ok(plain::<Dopri5Method>(tol)), periods, reps, acc),
        (1, false) => measure(w, || Ok(plain::<Tsit5Method>(tol)), periods, reps, acc),
        (2, false) => measure(w, || Ok(plain::<Vern6Method>(tol)), periods, reps, acc),
        (3, false) => measure(w, || Ok(plain::<Dop853Method>(tol)), periods, reps, acc),
        (0, true) => measure(w, || turning::<Dopri5Method>(tol), periods, reps, acc),
        (1, true) => measure(w, || turning::<Tsit5Method>(tol), periods, reps, acc),
        (2, true) => measure(w, || turning::<Vern6Method>(tol), periods, reps, acc),
        _ => measure(w, || turning::<Dop853Method>(tol), periods, reps, acc),
    }
}

/// One measured row: `(evaluations, seconds, error)`.
type Point = (f64, f64, f64);

/// The cost (`0`: evaluations, `1`: seconds) of a method at the error `target`, by linear
/// interpolation of `ln cost` against `ln err` between its two rows that bracket `target`
/// (extrapolated from the two nearest, and marked `~`, when none do).
fn at_error(rows: &[Point], target: f64, cost: usize) -> Option<(f64, bool)> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.2.ln(), if cost == 0 { r.0 } else { r.1 }.ln()))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    let lt = target.ln();
    let pair = pts
        .windows(2)
        .find(|p| (p[0].0 - lt) * (p[1].0 - lt) <= 0.0 && p[0].0 != p[1].0)
        .map(|p| (p[0], p[1], true))
        .or_else(|| {
            let mut by: Vec<(f64, f64)> = pts.clone();
            by.sort_by(|a, b| (a.0 - lt).abs().total_cmp(&(b.0 - lt).abs()));
            (by.len() >= 2 && by[0].0 != by[1].0).then(|| (by[0], by[1], false))
        })?;
    let (a, b, inside) = pair;
    let y = a.1 + (lt - a.0) * (b.1 - a.1) / (b.0 - a.0);
    Some((y.exp(), inside))
}

/// The table of one workload, then the costs at equal accuracy.
fn table<W: Workload>(
    w: &W,
    periods: u32,
    modes: &[bool],
    reps: usize,
    acc: &Accuracy,
) -> nonsmooth::Result<()> {
    println!(
        "\n### {}: {periods} periods; accuracy: RMS over {} starts of max |Δx| over sections 1..{} against DOP853 at rtol {RTOL_REF:.0e} (X = {:.3e})\n",
        w.name(),
        acc.starts.len(),
        acc.k,
        acc.scale
    );
    println!(
        "| mode | rtol | method | RHS | accepted | rejected | impacts | CPU s | RHS / DOPRI5 | CPU / DOPRI5 | RMS Δx | Δx / (rtol·X) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for &turn in modes {
        let mode = if turn { "turning points" } else { "plain" };
        let mut points: Vec<Vec<Point>> = vec![Vec::new(); METHODS.len()];
        for rtol in RTOLS {
            let mut base: Option<(f64, f64)> = None;
            for (i, name) in METHODS.iter().enumerate() {
                match run_method(w, (i, turn), rtol, periods, reps, acc) {
                    Ok((r, err)) => {
                        let rhs = r.stats.rhs_evals as f64;
                        let (b_rhs, b_cpu) = *base.get_or_insert((rhs, r.seconds));
                        points[i].push((rhs, r.seconds, err));
                        println!(
                            "| {mode} | {rtol:.0e} | {name} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {err:.1e} | {:.1} |",
                            r.stats.rhs_evals,
                            r.stats.accepted,
                            r.stats.rejected,
                            r.impacts,
                            r.seconds,
                            rhs / b_rhs,
                            r.seconds / b_cpu,
                            err / (rtol * acc.scale)
                        );
                    }
                    Err(e) => {
                        points[i].push((f64::NAN, f64::NAN, f64::NAN));
                        println!("| {mode} | {rtol:.0e} | {name} | failed: {e} |");
                    }
                }
            }
        }
        println!(
            "\n{mode}, at equal accuracy: each method's evaluations and CPU time at DOPRI5's error (interpolated in log–log between its rows; `~` extrapolated), over DOPRI5's\n"
        );
        println!("| DOPRI5 rtol | DOPRI5 RMS Δx | method | RHS ratio | CPU ratio |");
        println!("|---|---|---|---|---|");
        for (j, rtol) in RTOLS.iter().enumerate() {
            let (d_rhs, d_cpu, d_err) = points[0][j];
            for (i, name) in METHODS.iter().enumerate().skip(1) {
                let cell = |cost: usize, base: f64| match at_error(&points[i], d_err, cost) {
                    Some((v, inside)) => {
                        format!("{}{:.2}", if inside { "" } else { "~" }, v / base)
                    }
                    None => "—".into(),
                };
                println!(
                    "| {rtol:.0e} | {d_err:.1e} | {name} | {} | {} |",
                    cell(0, d_rhs),
                    cell(1, d_cpu)
                );
            }
        }
    }
    Ok(())
}

fn main() -> nonsmooth::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let reps = args
        .iter()
        .position(|a| a == "--reps")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(if quick { 1 } else { 3 });
    let (w2_periods, ueda_periods) = if quick { (200, 200) } else { (1000, 2000) };
    println!(
        "Explicit pairs against DOPRI5{}; times: {} of {reps} turn(s)",
        if quick { " (--quick)" } else { "" },
        if thread_cpu().is_some() {
            "thread CPU, smallest"
        } else {
            "wall, fastest"
        }
    );
    let rest = Vector2::new(PAPER.static_equilibrium()?, 0.0);
    let from_rest = W2 { t0: 0.0, y0: rest };
    // The attractor: sections 100, 110, …, 190 from rest (DOP853 at rtol 1e-12).
    let tol = from_rest.tolerances(1e-12)?;
    let warm = simulate(&from_rest, (0.0, rest), plain::<Dop853Method>(tol), 190)?;
    let on = |k: usize| (k as f64 * from_rest.period(), warm.sections[k - 1]);
    let w2 = W2 {
        t0: on(100).0,
        y0: on(100).1,
    };
    let acc = Accuracy::new(&w2, (0..10).map(|j| on(100 + 10 * j)).collect(), 3)?;
    table(&w2, w2_periods, &[false, true], reps, &acc)?;

    let ueda = Ueda(DuffingUeda::default().model()?);
    let tol = ueda.tolerances(1e-12)?;
    let warm = simulate(&ueda, ueda.start(), plain::<Dop853Method>(tol), 100)?;
    let starts = (1..=10)
        .map(|j| (10.0 * j as f64 * ueda.period(), warm.sections[10 * j - 1]))
        .collect();
    let acc = Accuracy::new(&ueda, starts, 3)?;
    table(&ueda, ueda_periods, &[false], reps, &acc)?;
    clock_rounding(&ueda)
}

/// The same 200 Duffing–Ueda periods from `(3, 0)` at rtol 1e-12, starting the clock at
/// `t₀ = 0`, `2π·1900` and `2π·19000` (the forcing is the same): Vern6's steps against the
/// size of `t`, DOPRI5's for reference.
fn clock_rounding(w: &Ueda) -> nonsmooth::Result<()> {
    println!("\n### Duffing–Ueda, 200 periods at rtol 1e-12 from (3, 0), by the clock's start\n");
    println!("| t0 | Vern6 accepted | Vern6 rejected | DOPRI5 accepted | DOPRI5 rejected |");
    println!("|---|---|---|---|---|");
    let tol = w.tolerances(1e-12)?;
    for k0 in [0.0, 1900.0, 19000.0] {
        let start = (k0 * w.period(), w.start().1);
        let a = simulate(w, start, plain::<Vern6Method>(tol), 200)?.stats;
        let b = simulate(w, start, plain::<Dopri5Method>(tol), 200)?.stats;
        println!(
            "| {:.0} | {} | {} | {} | {} |",
            start.0, a.accepted, a.rejected, b.accepted, b.rejected
        );
    }
    Ok(())
}
