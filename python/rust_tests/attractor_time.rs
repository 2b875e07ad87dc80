//! The Rust side of the Python package's overhead measurement (`examples/overhead.py`): the
//! paper's cart on its attractor at ω = 20.465 rad/s, 1000 forcing periods from the static
//! equilibrium at rtol = 1e-8, 64 dense samples per period and every impact recorded; the
//! wall time of each of several runs.
//!
//! `cargo run --release -p nonsmooth-python --example attractor_time -- [RUNS]`

use std::f64::consts::TAU;
use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::drive::Simulation;
use nonsmooth::event::{Direction, Event, Stop};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::sample::{ImpactSequence, Trajectory};
use nonsmooth::systems::paper::PAPER;

fn main() -> Result<(), nonsmooth::Error> {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(7);
    let omega = 20.465;
    let period = TAU / omega;
    let rtol = 1e-8;
    let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?;
    let stop = Stop {
        position: 0,
        velocity: 1,
        level: PAPER.x_i,
    };
    let y0 = Vector2::new(PAPER.static_equilibrium()?, 0.0);
    let mut times = Vec::new();
    for _ in 0..runs {
        let start = Instant::now();
        let mut sim = Simulation::new(PAPER.oscillator::<f64>(omega)?, Dopri5::new(tol))
            .with_events(Event::new(stop, Direction::Rising));
        let mut samples = Trajectory::<f64, 2>::new(0.0, period / 64.0, 0.0, 64_001)?;
        let mut impacts = ImpactSequence::on_surface(0, stop, 0.0, 1 << 20)?;
        let out = sim.run(0.0, y0, 1000.0 * period, &mut (&mut samples, &mut impacts))?;
        let s = start.elapsed().as_secs_f64();
        times.push(s);
        println!(
            "rust: {s:.4} s ({} samples, {} impacts, {} steps)",
            samples.samples().len(),
            impacts.count(),
            out.stats.accepted
        );
    }
    times.sort_by(f64::total_cmp);
    println!("rust median: {:.4} s", times[times.len() / 2]);
    Ok(())
}
