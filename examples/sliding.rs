//! Sliding motion in Filippov systems (`nonsmooth::filippov`):
//! - the relay feedback system of di Bernardo, Johansson & Vasca (the test problem of
//!   Piiroinen & Kuznetsov) from `x₀ = (0, −0.001, −0.02)`: its periodic orbit with sliding
//!   segments, `|H|` while sliding, the period and the Floquet multipliers;
//! - the dry-friction oscillator on a belt over the forcing amplitude: the bifurcation
//!   diagram (largest velocity, fraction of time stuck) with the grazing-sliding point
//!   located by a secant on its test function (the closest approach to the belt speed) and
//!   marked;
//! - the belt oscillator's periodic orbit followed in the forcing amplitude by shooting
//!   (`orbit::sliding::follow_sliding`), with its sliding bifurcations (grazing-sliding,
//!   switching-sliding, crossing-sliding) located on the branch as zeros of their test
//!   functions, and at forcing frequency 0.8 an adding-sliding (a stick split in two),
//!   checked against the closed form of the equivalent control along the stick.
//!
//! `cargo run --release [--features plot] --example sliding -- [--out DIR]`
//!
//! Writes `relay_orbit.csv`, `belt_diagram.csv`, `belt_bifurcation.csv` and
//! `belt_branch.csv` into `out/sliding`, and with feature `plot` `sliding.png` (the relay's
//! sliding orbit, the belt's bifurcation diagram with the sliding bifurcations marked, the
//! branch). Prints the checks; exits non-zero if one fails.

use std::f64::consts::PI;
use std::path::PathBuf;

use nalgebra::SVector;
use nonsmooth::drive::{Control, StepView};
use nonsmooth::filippov::{
    Approach, Filippov, FilippovSimulation, LinearRelay, Mode, SlidingObserver, Switched,
    TransitionKind,
};
use nonsmooth::integrate::{DenseOutput, Dopri5, Tolerances};
use nonsmooth::orbit::sliding::{SlidingBifurcationKind, SlidingContinuation, follow_sliding};
use nonsmooth::output::csv::write_table_path;
use nonsmooth::systems::RelayFeedback;

/// The relay feedback system `ẋ = A x − b sgn(x₁)` of the catalogue (ζ = 0.05, ω = 25,
/// σ = 1).
fn relay() -> LinearRelay<f64, 3> {
    RelayFeedback::default()
        .system()
        .expect("finite relay matrices")
}

/// Dense samples `(t, x, sliding)` after `t_from`, and the largest `|x₁|` while sliding.
struct Samples {
    t_from: f64,
    rows: Vec<[f64; 5]>,
    worst_h: f64,
}

impl SlidingObserver<f64, 3, 1> for Samples {
    fn on_step<D: DenseOutput<f64, 3>>(
        &mut self,
        mode: &Mode<1>,
        step: &StepView<'_, f64, 3, D>,
    ) -> Control {
        let mut y = SVector::zeros();
        for k in 0..8 {
            let t = step.t0 + (step.t1 - step.t0) * k as f64 / 8.0;
            step.state_at(t, &mut y);
            if mode.is_sliding() {
                self.worst_h = self.worst_h.max(y[0].abs());
            }
            if t >= self.t_from {
                let s = if mode.is_sliding() { 1.0 } else { 0.0 };
                self.rows.push([t, y[0], y[1], y[2], s]);
            }
        }
        Control::Continue
    }
}

/// The belt oscillator `ẍ + x = F₀ cos 2t − sgn(ẋ − 0.5)`.
fn belt(f0: f64) -> impl Filippov<f64, 2, 1> + Clone {
    belt_at(f0, 2.0)
}

/// The belt oscillator at forcing `f0` and frequency `w`.
fn belt_at(f0: f64, w: f64) -> impl Filippov<f64, 2, 1> + Clone {
    Switched::new(
        |x: &SVector<f64, 2>| x[1] - 0.5,
        |_x: &SVector<f64, 2>| SVector::from([0.0, 1.0]),
        move |t: f64, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] + f0 * (w * t).cos() + 1.0]),
        move |t: f64, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] + f0 * (w * t).cos() - 1.0]),
    )
}

/// Largest velocity and fraction of time stuck over the last `keep` of `periods` forcing
/// periods from the pure-slip steady state, and the closest approach to the belt speed.
fn belt_point(f0: f64, periods: f64, keep: f64) -> Result<(f64, f64, f64), String> {
    struct Stats {
        t_from: f64,
        vmax: f64,
        stuck: f64,
    }
    impl SlidingObserver<f64, 2, 1> for Stats {
        fn on_step<D: DenseOutput<f64, 2>>(
            &mut self,
            mode: &Mode<1>,
            step: &StepView<'_, f64, 2, D>,
        ) -> Control {
            if step.t1 <= self.t_from {
                return Control::Continue;
            }
            let t0 = step.t0.max(self.t_from);
            if mode.is_sliding() {
                self.stuck += step.t1 - t0;
            }
            let mut y = SVector::zeros();
            for k in 0..=8 {
                step.state_at(t0 + (step.t1 - t0) * k as f64 / 8.0, &mut y);
                self.vmax = self.vmax.max(y[1]);
            }
            Control::Continue
        }
    }
    let system = belt(f0);
    let period = PI; // 2π/ω, ω = 2
    let t_from = (periods - keep) * period;
    let mut obs = Pair(
        Stats {
            t_from,
            vmax: f64::NEG_INFINITY,
            stuck: 0.0,
        },
        Approach::new(&system, 0, t_from, 8),
    );
    let tol = Tolerances::new(1e-12, 1e-14).map_err(|e| e.to_string())?;
    let mut sim = FilippovSimulation::new(&system, Dopri5::new(tol));
    let x0 = SVector::from([1.0 - f0 / 3.0, 0.0]);
    sim.run(0.0, x0, periods * period, &mut obs)
        .map_err(|e| e.to_string())?;
    let g = obs.1.value().ok_or("no approach recorded")?;
    Ok((obs.0.vmax, obs.0.stuck / (keep * period), g))
}

/// Two observers in one.
impl<A: SlidingObserver<f64, 2, 1>, B: SlidingObserver<f64, 2, 1>> SlidingObserver<f64, 2, 1>
    for Pair<A, B>
{
    fn on_step<D: DenseOutput<f64, 2>>(
        &mut self,
        mode: &Mode<1>,
        step: &StepView<'_, f64, 2, D>,
    ) -> Control {
        self.0.on_step(mode, step);
        self.1.on_step(mode, step)
    }
}
struct Pair<A, B>(A, B);

fn main() {
    if let Err(e) = run() {
        eprintln!("sliding: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let mut out = PathBuf::from("out/sliding");
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--out") {
        out = PathBuf::from(args.get(i + 1).ok_or("--out needs a directory")?);
    }
    std::fs::create_dir_all(&out).map_err(|e| e.to_string())?;
    let mut failures = Vec::new();

    // The relay feedback system.
    let tol = Tolerances::new(1e-12, 1e-14).map_err(|e| e.to_string())?;
    let mut sim = FilippovSimulation::new(relay(), Dopri5::new(tol));
    let x0 = SVector::from([0.0, -0.001, -0.02]);
    let mut samples = Samples {
        t_from: 34.0,
        rows: Vec::new(),
        worst_h: 0.0,
    };
    let run = sim
        .run(0.0, x0, 40.0, &mut samples)
        .map_err(|e| e.to_string())?;
    let entries: Vec<f64> = run
        .transitions
        .iter()
        .filter(|tr| tr.kind == TransitionKind::SlidingEntry)
        .map(|tr| tr.t)
        .collect();
    // Each half period (the orbit is symmetric under x → −x) starts after a long region
    // piece; the period spans two.
    let marks: Vec<f64> = entries
        .windows(2)
        .filter(|w| w[1] - w[0] > 1.0)
        .map(|w| w[1])
        .collect();
    let n = marks.len();
    if n < 4 {
        return Err(format!("relay: {n} half periods"));
    }
    let period = marks[n - 1] - marks[n - 3];
    let drift = (period - (marks[n - 2] - marks[n - 4])).abs();
    let per_period = entries
        .iter()
        .filter(|&&t| t >= marks[n - 3] && t < marks[n - 1])
        .count();
    println!(
        "relay: period {period:.12} (change over the last period {drift:.1e}), {per_period} sliding segments per period, |H| while sliding ≤ {:.1e}",
        samples.worst_h
    );
    let tol12 = Tolerances::<f64, 12>::new(1e-12, 1e-14).map_err(|e| e.to_string())?;
    let start = run
        .transitions
        .iter()
        .rev()
        .find(|tr| tr.kind == TransitionKind::SlidingExit)
        .ok_or("no sliding exit")?;
    let mono = sim
        .monodromy(start.t, start.x, start.t + period, tol12)
        .map_err(|e| e.to_string())?;
    let mus = mono.multipliers();
    println!("relay: Floquet multipliers {mus:?}");
    if samples.worst_h > 1e-12 {
        failures.push(format!("|H| while sliding {:e} > 1e-12", samples.worst_h));
    }
    if drift > 1e-9 {
        failures.push(format!("period not converged: {drift:e}"));
    }
    if !mus.iter().any(|m| (m - 1.0).norm() < 1e-6) || !mus.iter().any(|m| m.norm() < 1e-6) {
        failures.push(format!(
            "multipliers {mus:?} miss the trivial 1 and the sliding 0"
        ));
    }
    write_table_path(
        out.join("relay_orbit.csv"),
        &["t", "x1", "x2", "x3", "sliding"],
        samples.rows.iter().map(|r| r.iter().copied()),
    )
    .map_err(|e| e.to_string())?;

    // The belt oscillator over F₀: the diagram and the grazing-sliding point.
    let mut rows = Vec::new();
    for k in 0..=90 {
        let f0 = 0.3 + 0.01 * k as f64;
        let (vmax, stuck, g) = belt_point(f0, 24.0, 4.0)?;
        rows.push([f0, vmax, stuck, g]);
    }
    let (mut a, mut b) = (0.5, 0.6);
    let (mut ga, mut gb) = (belt_point(a, 2.0, 2.0)?.2, belt_point(b, 2.0, 2.0)?.2);
    for _ in 0..30 {
        let c = b - gb * (b - a) / (gb - ga);
        if (c - b).abs() < 1e-14 {
            break;
        }
        (a, ga) = (b, gb);
        b = c;
        gb = belt_point(b, 2.0, 2.0)?.2;
    }
    let closed = 0.5 * 3.0 / 2.0; // u|1 − ω²|/ω
    let below = belt_point(b * (1.0 - 1e-6), 2.0, 2.0)?;
    let above = belt_point(b * (1.0 + 1e-6), 2.0, 2.0)?;
    println!(
        "belt: grazing-sliding at F₀ = {b:.13} (closed form {closed}), stuck fraction {:.1e} below, {:.1e} above",
        below.1, above.1
    );
    if (b - closed).abs() > 1e-9 {
        failures.push(format!("grazing-sliding at {b}, closed form {closed}"));
    }
    if below.1 != 0.0 || above.1 <= 0.0 {
        failures.push("the sliding segment does not appear at the bifurcation".into());
    }
    write_table_path(
        out.join("belt_diagram.csv"),
        &["f0", "max_velocity", "stuck_fraction", "closest_approach"],
        rows.iter().map(|r| r.iter().copied()),
    )
    .map_err(|e| e.to_string())?;
    write_table_path(
        out.join("belt_bifurcation.csv"),
        &["kind", "f0", "closed_form"],
        [[
            nonsmooth::output::csv::Cell::Text("grazing-sliding"),
            b.into(),
            closed.into(),
        ]],
    )
    .map_err(|e| e.to_string())?;

    // The belt oscillator's orbit of period π followed in F₀ by shooting, with the sliding
    // bifurcations located on the branch.
    let tol2 = Tolerances::<f64, 2>::new(1e-12, 1e-14).map_err(|e| e.to_string())?;
    let build = |f0: f64| Ok(FilippovSimulation::new(belt(f0), Dopri5::new(tol2)));
    let tol6 = Tolerances::<f64, 6>::new(1e-12, 1e-14).map_err(|e| e.to_string())?;
    let settings = SlidingContinuation::new(0.5, 2.2, 0.05, 0)
        .and_then(|s| s.with_locate_tolerance(1e-12))
        .map_err(|e| e.to_string())?;
    let branch = follow_sliding(
        build,
        |_| PI,
        0.0,
        0.6,
        SVector::from([1.0 - 0.6 / 3.0, 0.0]),
        tol6,
        &settings,
    )
    .map_err(|e| e.to_string())?;
    for bif in &branch.bifurcations {
        println!("belt branch: {:?} at F₀ = {:.12}", bif.kind, bif.p);
    }
    let graze = branch
        .bifurcations
        .iter()
        .find(|bif| bif.kind == SlidingBifurcationKind::GrazingSliding)
        .ok_or("no grazing-sliding on the branch")?;
    if (graze.p - closed).abs() > 1e-9 {
        failures.push(format!(
            "grazing-sliding on the branch at {}, closed form {closed}",
            graze.p
        ));
    }
    // At ω = 0.8 the stick-slip orbit's stick splits in two (adding-sliding) where the
    // spring and forcing q = −x + F₀ cos ωt, along the stick x = x_s + u(t − t_s), touch
    // the friction limit at an extremum (sin ωt = −u/(F₀ω)).
    let w = 0.8;
    let period = 2.0 * PI / w;
    let build_w = |f0: f64| Ok(FilippovSimulation::new(belt_at(f0, w), Dopri5::new(tol2)));
    let settings_w = SlidingContinuation::new(0.7, 0.95, 0.05, 0)
        .and_then(|s| s.with_locate_tolerance(1e-12))
        .map_err(|e| e.to_string())?;
    let mut warm = build_w(0.75).map_err(|e: nonsmooth::orbit::OrbitError| e.to_string())?;
    let x_w = warm
        .run(0.0, SVector::from([0.5, 0.0]), 80.0 * period, &mut ())
        .map_err(|e| e.to_string())?
        .x;
    let branch_w = follow_sliding(build_w, |_| period, 0.0, 0.75, x_w, tol6, &settings_w)
        .map_err(|e| e.to_string())?;
    let adding = branch_w
        .bifurcations
        .iter()
        .find(|bif| bif.kind == SlidingBifurcationKind::AddingSliding)
        .ok_or("no adding-sliding on the ω = 0.8 branch")?;
    let mut sim = build_w(adding.p).map_err(|e| e.to_string())?;
    let run = sim
        .run(0.0, adding.state, period, &mut ())
        .map_err(|e| e.to_string())?;
    let r = -0.5 / (adding.p * w);
    let mut touch = f64::INFINITY;
    for entry in run
        .transitions
        .iter()
        .filter(|tr| tr.kind == TransitionKind::SlidingEntry)
    {
        let q = |t: f64| -entry.x[0] - 0.5 * (t - entry.t) + adding.p * (w * t).cos();
        for k in -1..3 {
            for base in [r.asin(), PI - r.asin()] {
                let t = (base + 2.0 * PI * f64::from(k)) / w;
                if t > entry.t && t < entry.t + period {
                    touch = touch.min((1.0 - q(t).abs()).abs());
                }
            }
        }
    }
    println!(
        "belt branch at ω = 0.8: AddingSliding at F₀ = {:.12}, 1 − |q| at the stick's extremum {touch:.1e}",
        adding.p
    );
    if touch > 1e-8 {
        failures.push(format!(
            "adding-sliding: 1 − |q| = {touch:e} at the located orbit"
        ));
    }
    write_table_path(
        out.join("belt_branch.csv"),
        &["f0", "x0", "v0", "sliding_time", "mu1"],
        branch.points.iter().map(|q| {
            [
                q.p,
                q.state[0],
                q.state[1],
                q.tests.sliding_time,
                q.multipliers[0].norm(),
            ]
        }),
    )
    .map_err(|e| e.to_string())?;

    #[cfg(feature = "plot")]
    {
        use nonsmooth::output::plot::{Layout, Panel, Rgb, Series, render};
        let (slide, region): (Vec<&[f64; 5]>, Vec<&[f64; 5]>) =
            samples.rows.iter().partition(|r| r[4] > 0.5);
        let orbit = Panel::new("x₁", "x₂")
            .title("relay feedback: sliding orbit (sliding red)")
            .with(Series::dots(region.iter().map(|r| (r[1], r[2]))).color(Rgb::BLUE))
            .with(Series::dots(slide.iter().map(|r| (r[1], r[2]))).color(Rgb::RED));
        let mut diagram = Panel::new("F₀", "largest ẋ")
            .title("belt oscillator: grazing- (red), switching- (green), crossing-sliding (orange)")
            .with(Series::dots(rows.iter().map(|r| (r[0], r[1]))).color(Rgb::BLACK))
            .hline(0.5, Rgb::GRAY)
            .vline(b, Rgb::RED);
        let mut along = Panel::new("F₀", "x at t = 0")
            .title("the branch by shooting, time stuck per period (gray)")
            .with(Series::line(branch.points.iter().map(|q| (q.p, q.state[0]))).color(Rgb::BLUE))
            .with(
                Series::dots(branch.points.iter().map(|q| (q.p, q.tests.sliding_time)))
                    .color(Rgb::GRAY),
            );
        for bif in &branch.bifurcations {
            let color = match bif.kind {
                SlidingBifurcationKind::GrazingSliding => Rgb::RED,
                SlidingBifurcationKind::SwitchingSliding => Rgb::GREEN,
                SlidingBifurcationKind::AddingSliding => Rgb::PURPLE,
                _ => Rgb::ORANGE,
            };
            along = along.vline(bif.p, color);
            if bif.p <= rows.last().map_or(0.0, |r| r[0]) {
                diagram = diagram.vline(bif.p, color);
            }
        }
        render(
            out.join("sliding.png"),
            &[orbit, diagram, along],
            &Layout::grid(3, 700, 560).title("sliding (Filippov systems)"),
        )
        .map_err(|e| e.to_string())?;
    }

    println!("wrote {}", out.display());
    if failures.is_empty() {
        println!("all checks passed");
        Ok(())
    } else {
        Err(failures.join("; "))
    }
}
