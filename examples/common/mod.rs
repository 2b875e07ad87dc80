//! Helpers shared by the figure examples (`mod common;` in each).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use nalgebra::Vector2;
use nonsmooth::drive::Simulation;
use nonsmooth::event::{Direction, Event, Level};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::output::csv::{SweepColumns, write_sweep_files};
use nonsmooth::sample::{
    Impact, ImpactSequence, Regime, SectionPoint, Stroboscopic, Trajectory, detect_period,
};
use nonsmooth::sweep::{
    Stop, SweepBranch, SweepConfig, SweepDirection, SweepPoint, SweepResult, SweepSystem,
    Transition, hysteresis, run_point, transitions,
};
use nonsmooth::systems::paper::{PAPER, PaperOscillator};

/// Command-line arguments: `[--quick] [--out DIR | DIR]`.
#[derive(Debug, Clone)]
pub struct Args {
    /// Output directory (default `out/<figure>`).
    pub out: PathBuf,
    /// Coarse, fast version.
    pub quick: bool,
}

/// Parses the command line; prints usage and exits on `--help` or unknown flags.
pub fn args(figure: &str) -> Args {
    let mut out = None;
    let mut quick = false;
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--quick" | "-q" => quick = true,
            "--out" | "-o" => out = it.next().map(PathBuf::from),
            "--help" | "-h" => usage(figure, 0),
            s if s.starts_with('-') => {
                eprintln!("unknown option {s}");
                usage(figure, 2)
            }
            s => out = Some(PathBuf::from(s)),
        }
    }
    Args {
        out: out.unwrap_or_else(|| Path::new("out").join(figure)),
        quick,
    }
}

fn usage(figure: &str, code: i32) -> ! {
    eprintln!(
        "usage: cargo run --release [--features plot] --example {figure} -- [--quick] [--out DIR | DIR]\n\
         writes CSV files (and PNG figures with --features plot) into DIR (default out/{figure})"
    );
    std::process::exit(code)
}

/// The stop of the paper's oscillator: upward crossings of `x = x_I` are impacts.
pub fn stop() -> Stop {
    Stop {
        position: 0,
        velocity: 1,
        level: PAPER.x_i,
    }
}

/// The paper's oscillator at `omega` as a sweep needs it.
pub fn system(omega: f64) -> nonsmooth::Result<SweepSystem<PaperOscillator<f64>>> {
    Ok(SweepSystem {
        system: PAPER.oscillator::<f64>(omega)?,
        period: std::f64::consts::TAU / omega,
        stop: Some(stop()),
    })
}

/// DOPRI5 with rtol 1e-8, atol 1e-12 m and 1e-10 m/s.
pub fn stepper() -> Dopri5<f64, 2> {
    Dopri5::new(Tolerances::per_component(1e-8, [1e-12, 1e-10]).expect("valid tolerances"))
}

/// Rest at the static equilibrium (pressed into the stop).
pub fn rest() -> nonsmooth::Result<Vector2<f64>> {
    Ok(Vector2::new(PAPER.static_equilibrium()?, 0.0))
}

/// The transients of a sweep (the config's own are not readable back).
#[derive(Debug, Clone, Copy)]
pub struct Transients {
    /// Periods discarded at the first value.
    pub first: u32,
    /// Periods discarded after each step.
    pub step: u32,
}

/// The paper's transients: 100 periods at the first value, 50 after each step.
pub const PAPER_TRANSIENTS: Transients = Transients {
    first: 100,
    step: 50,
};

/// A sweep config over `[start, end]` with the given step, transients and recorded periods.
pub fn config(
    start: f64,
    end: f64,
    step: f64,
    tr: Transients,
    record: u32,
    direction: SweepDirection,
) -> nonsmooth::Result<SweepConfig> {
    Ok(SweepConfig::grid(start, end, step)?
        .direction(direction)
        .transients(tr.first, tr.step)
        .record(record)?)
}

fn bar(multi: &MultiProgress, len: usize, name: &str) -> ProgressBar {
    let pb = multi.add(ProgressBar::new(len as u64));
    pb.set_style(
        ProgressStyle::with_template(
            "{prefix:>5} [{elapsed_precise}] {bar:40.cyan/blue} {pos:>5}/{len:5} {msg} (eta {eta})",
        )
        .expect("valid template")
        .progress_chars("##-"),
    );
    pb.set_prefix(name.to_string());
    pb
}

/// One continuation branch, as [`nonsmooth::sweep::sweep`] runs it (same transients, same
/// seeding from the previous end state), with a progress bar.
fn branch(
    config: &SweepConfig,
    tr: Transients,
    dir: SweepDirection,
    y0: Vector2<f64>,
    pb: &ProgressBar,
) -> nonsmooth::Result<SweepBranch<2>> {
    let mut vals = config.values().to_vec();
    if dir == SweepDirection::Down {
        vals.reverse();
    }
    let mut y = y0;
    let mut points: Vec<SweepPoint<2>> = Vec::with_capacity(vals.len());
    for (k, &w) in vals.iter().enumerate() {
        let transient = if k == 0 { tr.first } else { tr.step };
        let p = run_point(config, w, system(w)?, stepper(), y, transient)?;
        y = p.end_state;
        pb.set_message(format!("ω = {w:.3}, {:.2} impacts/T", p.impacts_per_period));
        pb.inc(1);
        points.push(p);
    }
    pb.finish();
    Ok(SweepBranch {
        direction: dir,
        points,
    })
}

/// Runs the continuation sweep of the paper's oscillator from rest, up and/or down (the two
/// branches concurrently), with progress bars; returns the result and the wall time.
pub fn run_sweep(
    config: &SweepConfig,
    tr: Transients,
    directions: &[SweepDirection],
) -> nonsmooth::Result<(SweepResult<2>, Duration)> {
    let y0 = rest()?;
    let multi = MultiProgress::new();
    let n = config.values().len();
    let start = Instant::now();
    let branches: Vec<nonsmooth::Result<SweepBranch<2>>> = std::thread::scope(|s| {
        let handles: Vec<_> = directions
            .iter()
            .map(|&d| {
                let pb = bar(
                    &multi,
                    n,
                    if d == SweepDirection::Down {
                        "down"
                    } else {
                        "up"
                    },
                );
                s.spawn(move || branch(config, tr, d, y0, &pb))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("sweep thread panicked"))
            .collect()
    });
    let branches = branches
        .into_iter()
        .collect::<nonsmooth::Result<Vec<_>>>()?;
    Ok((SweepResult { branches }, start.elapsed()))
}

/// Writes the sweep's three CSV tables; prints their paths.
pub fn write_sweep(out: &Path, stem: &str, result: &SweepResult<2>) -> nonsmooth::Result<()> {
    let paths = write_sweep_files(out, stem, result, &SweepColumns::OSCILLATOR_OMEGA)?;
    for p in paths {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// Writes the two-panel bifurcation diagram (Poincaré x above, T_j below).
#[cfg(feature = "plot")]
pub fn plot_sweep(
    out: &Path,
    stem: &str,
    result: &SweepResult<2>,
    title: &str,
) -> nonsmooth::Result<()> {
    use nonsmooth::output::plot::{Layout, Quantity, bifurcation_panel, render};
    let a = bifurcation_panel(result, Quantity::POSITION_MM)?
        .x_label("ω [rad/s]")
        .title("(a) stroboscopic points t = 2πi/ω");
    let b = bifurcation_panel(result, Quantity::Intervals)?
        .x_label("ω [rad/s]")
        .title("(b) inter-impact intervals");
    for ext in ["png", "svg"] {
        let path = out.join(format!("{stem}.{ext}"));
        render(
            &path,
            &[a.clone(), b.clone()],
            &Layout::grid(1, 1200, 560).title(title),
        )?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// Short text for a regime.
pub fn regime(r: Regime) -> String {
    match r {
        Regime::Periodic(p) => format!("P{p}"),
        Regime::NotPeriodic => "NP".into(),
    }
}

/// A copy of `result` with two corrections of the per-value classification, so that the
/// printed transitions, the hysteresis intervals and the CSV summary show the dynamics and
/// not artefacts of the window (both leave a clean point as it is):
///
/// * the period is detected again with each state component scaled by its largest
///   magnitude over the whole branch (the size of the diagram), not over the value's own
///   points as the sweep does. The per-value scale is tiny for a component that is near
///   zero at the section (the velocity of the cart resting against the stop at
///   ω ≈ 14.1–14.5 rad/s is ~3·10⁻⁷ m/s there), so that the 10⁻⁴ relative tolerance falls
///   below the integration error, and sporadic kicks of ~10⁻⁷ m/s in single section points
///   (seen at any tolerance, also with DOP853) then make a period-1 orbit read as not
///   periodic. 10⁻⁴ of the diagram's size is still ten times finer than a pixel of the
///   figure;
/// * the impacts per period of a periodic point (period `p`) are counted per orbit period,
///   `round(p·n̄)/p`: a 50-period window does not hold a whole number of periods of a P3,
///   P4, P6, P7 … orbit, so the window average `n̄` wobbles by up to `p/50` between
///   neighbouring values (1.66 / 1.68 for 5 impacts per 3 periods), which `transitions`
///   and `hysteresis` would report as changes. Non-periodic points keep `n̄`.
pub fn normalize(result: &SweepResult<2>) -> SweepResult<2> {
    let mut r = result.clone();
    for b in &mut r.branches {
        let mut wide = Vector2::<f64>::zeros();
        for p in &b.points {
            for y in &p.poincare {
                wide[0] = wide[0].max(y[0].abs());
                wide[1] = wide[1].max(y[1].abs());
            }
        }
        for p in &mut b.points {
            p.regime = detect_period(&p.poincare, &wide, 1e-4, 16);
            if let Regime::Periodic(k) = p.regime {
                let k = k as f64;
                p.impacts_per_period = (p.impacts_per_period * k).round() / k;
            }
        }
    }
    r
}

/// Prints the transitions of a branch (steps where the impacts per orbit period or the
/// period change), leaving out changes of the window average between two non-periodic
/// (chaotic) points, which are noise; returns the transitions printed.
pub fn print_transitions(branch: &SweepBranch<2>) -> Vec<Transition> {
    let all = transitions(branch);
    let (kept, noise): (Vec<Transition>, Vec<Transition>) = all.into_iter().partition(|t| {
        !(t.regime_before == Regime::NotPeriodic && t.regime_after == Regime::NotPeriodic)
    });
    println!(
        "transitions along the {} branch ({}; {} changes between chaotic points not shown):",
        if branch.direction == SweepDirection::Down {
            "decreasing"
        } else {
            "increasing"
        },
        kept.len(),
        noise.len()
    );
    for t in &kept {
        println!(
            "  ω {:>8.4} → {:>8.4}: impacts/T {:>5.3} → {:>5.3}, {} → {}",
            t.before,
            t.after,
            t.impacts_before,
            t.impacts_after,
            regime(t.regime_before),
            regime(t.regime_after)
        );
    }
    kept
}

/// Prints the hysteresis intervals (where the branches reached different attractors):
/// those spanning at least three grid values in full, the narrower ones (a thin periodic
/// window on one branch only, two chaotic samples of a different kind, a single kicked
/// section point) on one line.
pub fn print_hysteresis(result: &SweepResult<2>, tol: f64) -> Vec<(f64, f64)> {
    let h = hysteresis(result, tol);
    let step = result
        .branches
        .first()
        .and_then(|b| b.points.get(..2))
        .map_or(1.0, |p| (p[1].param - p[0].param).abs());
    let values = |(a, b): &(f64, f64)| ((b - a) / step).round() as usize + 1;
    let wide: Vec<&(f64, f64)> = h.iter().filter(|iv| values(iv) >= 3).collect();
    let narrow: Vec<&(f64, f64)> = h.iter().filter(|iv| values(iv) < 3).collect();
    println!(
        "hysteresis (up and down branches differ, tol {tol:e}): {} intervals of ≥ 3 values",
        wide.len()
    );
    for iv in wide {
        println!("  ω ∈ [{:.4}, {:.4}] ({} values)", iv.0, iv.1, values(iv));
    }
    let list: Vec<String> = narrow
        .iter()
        .map(|&&(a, b)| {
            if a == b {
                format!("{a:.3}")
            } else {
                format!("{a:.3}–{b:.3}")
            }
        })
        .collect();
    println!("  and {} of 1–2 values: {}", narrow.len(), list.join(", "));
    h
}

/// The point of a branch nearest to `w`.
pub fn nearest(branch: &SweepBranch<2>, w: f64) -> Option<&SweepPoint<2>> {
    branch.points.iter().min_by(|a, b| {
        (a.param - w)
            .abs()
            .partial_cmp(&(b.param - w).abs())
            .unwrap_or(std::cmp::Ordering::Equal)
    })
}

/// An orbit on the attractor reached from rest.
#[derive(Debug, Clone)]
pub struct Orbit {
    /// Forcing frequency.
    pub omega: f64,
    /// Samples on a fine grid over the recorded window.
    pub curve: Vec<SectionPoint<f64, 2>>,
    /// Stroboscopic points `t = 2πi/ω` in the window.
    pub strobe: Vec<SectionPoint<f64, 2>>,
    /// Impacts in the window.
    pub impacts: Vec<Impact<f64>>,
    /// Period of the stroboscopic points.
    pub regime: Regime,
    /// Recorded forcing periods.
    pub periods: u32,
    /// Wall time.
    pub time: Duration,
}

impl Orbit {
    /// Impacts per forcing period.
    pub fn impacts_per_period(&self) -> f64 {
        self.impacts.len() as f64 / self.periods as f64
    }
}

/// Runs the paper's oscillator at `omega` from rest for `transient` periods, then records
/// `record` periods: the state every `T/samples` (never accumulated), the stroboscopic
/// points and the impacts.
pub fn orbit(omega: f64, transient: u32, record: u32, samples: u32) -> nonsmooth::Result<Orbit> {
    let start = Instant::now();
    let period = std::f64::consts::TAU / omega;
    let t_rec = transient as f64 * period;
    let t_end = (transient + record) as f64 * period;
    let cap = 1 << 24;
    let mut traj = Trajectory::new(0.0, period / samples as f64, t_rec, cap)?;
    // Sections at i·T for i = transient ..= transient + record − 1 (a half period of margin
    // on both sides keeps rounding out of the choice).
    let mut strobe = Stroboscopic::periodic(0.0, period, t_rec - 0.5 * period, cap)?;
    let mut impacts = ImpactSequence::new(0, 0, 1, PAPER.x_i, t_rec, cap)?;
    let impact = Event::new(Level::new(0, PAPER.x_i)?, Direction::Rising);
    let mut sim = Simulation::new(PAPER.oscillator::<f64>(omega)?, stepper())
        .with_events(impact)
        .landing_grid(Some((0.0, period)))?;
    sim.run(
        0.0,
        rest()?,
        t_end,
        &mut (&mut traj, &mut strobe, &mut impacts),
    )?;
    let mut strobe = strobe.points().to_vec();
    strobe.retain(|p| p.t < t_end - 0.5 * period);
    let pts: Vec<_> = strobe.iter().map(|p| p.y).collect();
    // Scales floored at 0.1 mm and 1 mm/s: the velocity at the section can be ~0 (the cart
    // resting against the stop), and a scale of ~0 would make the tolerance meaningless.
    let mut scale = Vector2::new(1e-4, 1e-3);
    for p in &pts {
        scale[0] = f64::max(scale[0], p[0].abs());
        scale[1] = f64::max(scale[1], p[1].abs());
    }
    let regime = detect_period(&pts, &scale, 1e-4, 16);
    Ok(Orbit {
        omega,
        curve: traj.samples().to_vec(),
        strobe,
        impacts: impacts.impacts().to_vec(),
        regime,
        periods: record,
        time: start.elapsed(),
    })
}

/// Seconds, for printing.
pub fn secs(d: Duration) -> f64 {
    d.as_secs_f64()
}

/// What the paper reports for an up/down sweep figure.
pub struct PaperReport<'a> {
    /// The paper's transition/grazing values.
    pub transitions: &'a str,
    /// The paper's hysteresis locations.
    pub hysteresis: &'a str,
}

/// The up/down continuation sweep figures (Figs. 3 and 4): runs, writes CSV (and PNG/SVG
/// with `--features plot`), prints transitions and hysteresis.
pub fn updown_figure(
    figure: &str,
    (start, end): (f64, f64),
    (step_full, step_quick): (f64, f64),
    title: &str,
    paper: PaperReport<'_>,
) -> nonsmooth::Result<SweepResult<2>> {
    let a = args(figure);
    let step = if a.quick { step_quick } else { step_full };
    let cfg = config(start, end, step, PAPER_TRANSIENTS, 50, SweepDirection::Both)?;
    println!(
        "{figure}: ω ∈ [{start}, {end}] step {step} ({} values), up and down, transients 100/50, 50 recorded periods{}",
        cfg.values().len(),
        if a.quick { " (quick)" } else { "" }
    );
    let (res, time) = run_sweep(
        &cfg,
        PAPER_TRANSIENTS,
        &[SweepDirection::Up, SweepDirection::Down],
    )?;
    println!("sweep: {:.1} s wall", secs(time));
    let norm = normalize(&res);
    write_sweep(&a.out, figure, &norm)?;
    #[cfg(feature = "plot")]
    plot_sweep(&a.out, figure, &norm, title)?;
    #[cfg(not(feature = "plot"))]
    let _ = title;
    for b in &norm.branches {
        print_transitions(b);
    }
    println!("paper: {}", paper.transitions);
    print_hysteresis(&norm, 1e-3);
    println!("paper: {}", paper.hysteresis);
    Ok(res)
}
