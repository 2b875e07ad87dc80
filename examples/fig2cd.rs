//! The paper's Fig. 2c–d: bifurcation diagrams for increasing ω ∈ [10, 25] rad/s, from rest
//! at the static equilibrium (pressed into the stop) with continuation — stroboscopic
//! points x(2πi/ω) (c) and inter-impact intervals T_j (d) — and the impacts per period
//! along the impact-adding sequence ω ∈ [14, 17.5].
//!
//! `cargo run --release [--features plot] --example fig2cd -- [--quick] [--out DIR]`
//!
//! Step 0.01 rad/s (quick: 0.05), transients 100 periods at the first value and 50 after
//! each step, 50 recorded periods. Writes `fig2cd_{poincare,intervals,summary}.csv` (and
//! `fig2cd.png`, `fig2cd.svg`) into `out/fig2cd`. The regimes and impacts per period in the
//! summary and the printout are re-read by `common::normalize` (period detection at the
//! diagram's scale, impacts counted per orbit period).

mod common;

use common::{PAPER_TRANSIENTS, config, nearest, regime, run_sweep, secs, write_sweep};
use nonsmooth::sweep::SweepDirection;

fn main() -> nonsmooth::Result<()> {
    let a = common::args("fig2cd");
    let step = if a.quick { 0.05 } else { 0.01 };
    let cfg = config(10.0, 25.0, step, PAPER_TRANSIENTS, 50, SweepDirection::Up)?;
    println!(
        "fig2cd: ω ∈ [10, 25] step {step} ({} values), increasing, from rest, transients 100/50, 50 recorded periods{}",
        cfg.values().len(),
        if a.quick { " (quick)" } else { "" }
    );
    let (res, time) = run_sweep(&cfg, PAPER_TRANSIENTS, &[SweepDirection::Up])?;
    println!("sweep: {:.1} s wall", secs(time));
    let norm = common::normalize(&res);
    write_sweep(&a.out, "fig2cd", &norm)?;
    #[cfg(feature = "plot")]
    common::plot_sweep(
        &a.out,
        "fig2cd",
        &norm,
        "Fig. 2c–d: increasing ω ∈ [10, 25] rad/s from rest",
    )?;
    let up = &norm.branches[0];
    println!("impact-adding sequence (impacts per forcing period, per orbit period if periodic):");
    for w in [14.0, 14.1, 15.0, 16.0, 17.0, 17.5] {
        if let Some(p) = nearest(up, w) {
            println!(
                "  ω = {:>6.3}: {:>5.3} impacts/T, {}, grazing margin {:+.3} µm",
                p.param,
                p.impacts_per_period,
                regime(p.regime),
                p.grazing_margin * 1e6
            );
        }
    }
    let first = up.points.iter().find(|p| p.impacts > 0);
    if let Some(p) = first {
        println!(
            "first value with impacts: ω = {:.3} rad/s (paper: ≈ 14)",
            p.param
        );
    }
    common::print_transitions(up);
    Ok(())
}
