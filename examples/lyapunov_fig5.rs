//! The paper's Fig. 5: the top Lyapunov exponent of the impact oscillator against the
//! forcing frequency ω, for increasing and decreasing ω with continuation.
//!
//! ```text
//! cargo run --release --example lyapunov_fig5 -- [--from 17.5] [--to 25] [--step 0.005]
//!     [--periods 1000] [--transient 100] [--step-transient 50] [--out out/fig5_tle.csv]
//! ```
//! The defaults are the paper's settings (Sect. 4): ω ∈ [17.5, 25] rad/s in steps of
//! 0.005 rad/s, 100 transient periods from rest, 50 after each step, 10³ periods for the
//! exponent, renormalization every forcing period. For a quick look use e.g.
//! `--step 0.05 --periods 200`. Writes a tidy CSV with the columns
//! `omega_rad_s,direction,tle_per_s,spread_per_s` and prints a summary with timings.

use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{
    DiagramDirection, DiagramPoint, DiagramSettings, IntervalRule, pair_tolerances, tle_diagram,
};
use nonsmooth::systems::paper::PAPER;
use nonsmooth::systems::paper::lyapunov::{D0 as PAPER_D0, norm as paper_norm};

struct Args {
    from: f64,
    to: f64,
    step: f64,
    periods: usize,
    transient: usize,
    step_transient: usize,
    out: String,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        from: 17.5,
        to: 25.0,
        step: 0.005,
        periods: 1000,
        transient: 100,
        step_transient: 50,
        out: "out/fig5_tle.csv".to_string(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let val = it
            .next()
            .ok_or_else(|| format!("missing value after {flag}"))?;
        let num = || val.parse::<f64>().map_err(|e| format!("{flag} {val}: {e}"));
        let int = || {
            val.parse::<usize>()
                .map_err(|e| format!("{flag} {val}: {e}"))
        };
        match flag.as_str() {
            "--from" => a.from = num()?,
            "--to" => a.to = num()?,
            "--step" => a.step = num()?,
            "--periods" => a.periods = int()?,
            "--transient" => a.transient = int()?,
            "--step-transient" => a.step_transient = int()?,
            "--out" => a.out = val.clone(),
            _ => return Err(format!("unknown argument {flag}")),
        }
    }
    if !(a.step > 0.0 && a.to >= a.from && a.from > 0.0) {
        return Err("need 0 < from <= to and step > 0".into());
    }
    Ok(a)
}

/// The ω-intervals (of consecutive grid values) where the exponent is positive.
fn chaotic_windows(points: &[DiagramPoint<f64>]) -> Vec<(f64, f64)> {
    let mut sorted: Vec<_> = points.to_vec();
    sorted.sort_by(|a, b| a.parameter.total_cmp(&b.parameter));
    let mut out = Vec::new();
    let mut open: Option<(f64, f64)> = None;
    for p in &sorted {
        if p.exponent > 0.0 {
            open = Some(match open {
                Some((lo, _)) => (lo, p.parameter),
                None => (p.parameter, p.parameter),
            });
        } else if let Some(w) = open.take() {
            out.push(w);
        }
    }
    out.extend(open);
    out
}

fn main() -> nonsmooth::Result<()> {
    let args = parse_args().unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let n = ((args.to - args.from) / args.step).round() as usize + 1;
    // The grid from the index, never accumulated.
    let omegas: Vec<f64> = (0..n).map(|i| args.from + i as f64 * args.step).collect();
    let settings = DiagramSettings::new(
        IntervalRule::ForcingPeriod,
        args.transient,
        args.step_transient,
        args.periods,
    )?;
    let tol = pair_tolerances(&Tolerances::per_component(1e-8, [1e-12, 1e-10])?)?;
    let y0 = Vector2::new(PAPER.static_equilibrium()?, 0.0);
    println!(
        "TLE diagram: {n} values of ω in [{}, {}] rad/s (step {}), {} + {}/step transient and {} \
         recorded periods, d0 = {PAPER_D0:e}, both directions{}",
        args.from,
        args.to,
        args.step,
        args.transient,
        args.step_transient,
        args.periods,
        if cfg!(feature = "parallel") {
            " (concurrently)"
        } else {
            ""
        }
    );
    let t = Instant::now();
    let d = tle_diagram(
        |w: f64| Ok(PAPER.oscillator::<f64>(w)?),
        &Dopri5::new(tol),
        y0,
        &omegas,
        PAPER_D0,
        paper_norm(),
        &settings,
    )?;
    let wall = t.elapsed().as_secs_f64();

    if let Some(dir) = std::path::Path::new(&args.out).parent() {
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir)?;
        }
    }
    let mut w = csv::Writer::from_path(&args.out)?;
    w.write_record(["omega_rad_s", "direction", "tle_per_s", "spread_per_s"])?;
    for branch in [DiagramDirection::Increasing, DiagramDirection::Decreasing] {
        for p in d.branch(branch) {
            w.write_record([
                format!("{:.6}", p.parameter),
                branch.as_str().to_string(),
                format!("{:.6e}", p.exponent),
                format!("{:.6e}", p.spread),
            ])?;
        }
    }
    w.flush()?;

    for branch in [DiagramDirection::Increasing, DiagramDirection::Decreasing] {
        let pts = d.branch(branch);
        let pos = pts.iter().filter(|p| p.exponent > 0.0).count();
        let max = pts
            .iter()
            .max_by(|a, b| a.exponent.total_cmp(&b.exponent))
            .expect("non-empty branch");
        let evals: u64 = pts.iter().map(|p| p.stats.rhs_evals).sum();
        println!(
            "{:>10}: {pos}/{} values with λ₁ > 0; max λ₁ = {:.3} /s at ω = {:.3}; {:.2e} evaluations",
            branch.as_str(),
            pts.len(),
            max.exponent,
            max.parameter,
            evals as f64
        );
        let windows = chaotic_windows(pts);
        let shown: Vec<String> = windows
            .iter()
            .take(12)
            .map(|(a, b)| format!("[{a:.3}, {b:.3}]"))
            .collect();
        println!(
            "            λ₁ > 0 on {} windows: {}{}",
            windows.len(),
            shown.join(" "),
            if windows.len() > 12 { " …" } else { "" }
        );
    }
    // Hysteresis: values where the branches disagree on the sign.
    let mut down: Vec<_> = d.decreasing.clone();
    down.reverse();
    let differ: Vec<f64> = d
        .increasing
        .iter()
        .zip(&down)
        .filter(|(a, b)| (a.exponent > 0.0) != (b.exponent > 0.0))
        .map(|(a, _)| a.parameter)
        .collect();
    println!(
        "branches disagree on the sign at {} values{}",
        differ.len(),
        differ
            .first()
            .map(|f| format!(" (first at ω = {f:.3})"))
            .unwrap_or_default()
    );
    let periods_total = 2 * (args.transient + (n - 1) * args.step_transient + n * args.periods);
    println!(
        "wall time {wall:.1} s for {n} × 2 values ({:.3} s per value and branch, {:.3} ms per \
         period per branch); wrote {}",
        wall / n as f64,
        wall * 1e3 / periods_total as f64 * if cfg!(feature = "parallel") { 2.0 } else { 1.0 },
        args.out
    );
    Ok(())
}
