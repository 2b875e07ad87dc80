//! W3 on the ensemble: the paper's sweep grid (ω ∈ [17.5, 25], step 0.005, 1501 values;
//! 100 transient and 50 recorded periods; rtol 1e-8) with independent starts from rest, in
//! lanes (`sweep::sweep_independent_parallel`) against the scalar `sweep` with the same
//! independent starts, and the paper's continuation sweep (both directions, transients
//! 100/50) on the scalar path for reference. All on the default rayon pool.
//!
//! ```sh
//! cargo run --release --features timing --example ensemble_sweep              # full grid
//! cargo run --release --features timing --example ensemble_sweep -- --quick   # step 0.05
//! ```

use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::ensemble::{Ensemble, Simd};
use nonsmooth::event::Stop;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::sweep::{
    IndependentSweep, LaneStart, SweepConfig, SweepDirection, SweepSystem, sweep,
    sweep_independent_parallel,
};
use nonsmooth::systems::paper::{Member, PAPER, PaperOscillator};

fn make(w: f64) -> nonsmooth::Result<SweepSystem<PaperOscillator<f64>>> {
    Ok(SweepSystem {
        system: PAPER.oscillator::<f64>(w)?,
        period: std::f64::consts::TAU / w,
        stop: Some(stop()),
    })
}

fn stop() -> Stop {
    Stop {
        position: 0,
        velocity: 1,
        level: PAPER.x_i,
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let quick = std::env::args().any(|a| a == "--quick");
    let step = if quick { 0.05 } else { 0.005 };
    let rtol = 1e-8;
    let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?;
    let y0 = Vector2::new(PAPER.static_equilibrium()?, 0.0);
    let grid = SweepConfig::grid(17.5, 25.0, step)?;
    let values = grid.values().to_vec();
    let settings = IndependentSweep::new(100, 50)?;
    println!(
        "{} values, {} threads, lane loop on {:?}",
        values.len(),
        rayon::current_num_threads(),
        Simd::Auto.resolve()
    );

    let start = Instant::now();
    let starts: Vec<LaneStart<Member, 2>> = values
        .iter()
        .map(|&w| Member::paper(w).map(|m| m.start(y0)))
        .collect::<Result<_, _>>()?;
    let e = Ensemble::new(tol)?;
    // Two fills of the sixteen lanes per task.
    let lanes = sweep_independent_parallel(&e, &settings, &starts, Some(stop()), 32)?;
    let t_lanes = start.elapsed().as_secs_f64();
    println!("independent starts, ensemble (exact): {t_lanes:7.2} s");

    let start = Instant::now();
    let cfg = settings.config(values.clone())?;
    let scalar = sweep(&cfg, make, || Dopri5::new(tol), y0)?;
    let t_scalar = start.elapsed().as_secs_f64();
    let same = scalar.branches[0]
        .points
        .iter()
        .zip(&lanes)
        .filter(|(a, b)| a == b)
        .count();
    println!(
        "independent starts, scalar sweep:               {t_scalar:7.2} s  ({same}/{} records identical)",
        values.len()
    );

    let start = Instant::now();
    let cont = grid
        .direction(SweepDirection::Both)
        .transients(100, 50)
        .record(50)?;
    let r = sweep(&cont, make, || Dopri5::new(tol), y0)?;
    let t_cont = start.elapsed().as_secs_f64();
    println!(
        "continuation up and down (the paper's W3), scalar: {t_cont:7.2} s  ({} branches)",
        r.branches.len()
    );
    println!(
        "independent-start sweep ratio scalar/ensemble: {:.2}",
        t_scalar / t_lanes
    );
    Ok(())
}
