//! Crossing the turning points in the velocity's power scale ([`TurningPoints`]) against
//! time stepping alone, on the paper's model.
//!
//! For starts on the attractor at ω = 20.465 rad/s (every 5 periods after 100), x after 5
//! periods is compared with DOP853 at rtol 1e-13; printed per rtol: the RMS error of x,
//! right-hand-side evaluations and trial steps per forcing period, segments per period,
//! trial steps per segment, abandoned segments and CPU time per 1000 periods.
//!
//! Measured (one run, shared machine; band 3e-3 m/s, segment tolerances τ to rtol seconds and
//! x as in time):
//!
//! | rtol | RHS/period time → segments | attempts/period | attempts/segment | RMS err x time → segments | CPU |
//! |---|---|---|---|---|---|
//! | 1e-6 | 1014 → 750 (−26 %) | 169 → 123 | 7.6 | 4.6e-6 → 3.8e-6 | −21 % |
//! | 1e-8 | 1928 → 1447 (−25 %) | 321 → 239 | 15.6 | 7.1e-8 → 5.1e-8 | −20 % |
//! | 1e-10 | 3933 → 3013 (−23 %) | 655 → 500 | 30.6 | 2.6e-9 → 7.6e-10 | −21 % |
//!
//! Four segments per period (two turning points in contact, two friction reversals in free
//! flight), none abandoned. Tightening the segments' τ tolerance (1e-3·rtol s, 1e-6·rtol s)
//! doubled their steps without a measurable gain in this error.
//!
//! The second table runs the exact law (η = 0) from rest: the first period creeps out of
//! resting contact with `a ≈ 0` (the damping term balances the forcing), which is not a
//! turning point, and segments save only 1–8 % there (280 850 → 276 834 evaluations at
//! rtol 1e-8).
//!
//! `cargo run --release --example turning_points -- [--quick] [--band V] [--tau-atol F]`
//! (`F`: the segments' absolute τ tolerance in units of rtol seconds, default 1).

use std::f64::consts::TAU;
use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::drive::Simulation;
use nonsmooth::integrate::{Dop853, Dopri5, Stepper, Tolerances, TurningPoints};
use nonsmooth::model::paper::PAPER;

const OMEGA: f64 = 20.465;

fn time_tolerances(rtol: f64) -> nonsmooth::Result<Tolerances<f64, 2>> {
    Ok(Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?)
}

fn main() -> nonsmooth::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let band = args
        .iter()
        .position(|a| a == "--band")
        .and_then(|i| args.get(i + 1))
        .map_or(3e-3, |s| s.parse::<f64>().unwrap_or(f64::NAN));
    // Absolute tolerance of a segment's τ, in units of rtol seconds.
    let tau_atol = args
        .iter()
        .position(|a| a == "--tau-atol")
        .and_then(|i| args.get(i + 1))
        .map_or(1.0, |s| s.parse::<f64>().unwrap_or(f64::NAN));
    let osc = PAPER.oscillator::<f64>(OMEGA)?;
    let period = TAU / OMEGA;
    let (n_starts, span) = if quick { (5, 5.0) } else { (20, 5.0) };
    let rtols: &[f64] = if quick { &[1e-8] } else { &[1e-6, 1e-8, 1e-10] };
    let reference = |t0: f64, y0: Vector2<f64>, t1: f64| -> nonsmooth::Result<Vector2<f64>> {
        Ok(Simulation::new(osc, Dop853::new(time_tolerances(1e-13)?))
            .run(t0, y0, t1, &mut ())?
            .y)
    };
    let mut starts = Vec::new();
    let x0 = PAPER.static_equilibrium()?;
    let mut y = reference(0.0, Vector2::new(x0, 0.0), 100.0 * period)?;
    let mut t = 100.0 * period;
    for _ in 0..n_starts {
        let y1 = reference(t, y, t + span * period)?;
        starts.push((t, y, y1[0]));
        (t, y) = (t + span * period, y1);
    }
    println!(
        "ω = {OMEGA}, {n_starts} starts on the attractor, x after {span} periods against DOP853 at rtol 1e-13, band {band:e} m/s"
    );
    println!(
        "| rtol | method | RMS err x (m) | RHS/period | trial steps/period | segments/period | trial steps/segment | abandoned | CPU s/1000 periods |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let periods = n_starts as f64 * span;
    for &rtol in rtols {
        // Time stepping alone.
        let mut sq = 0.0;
        let (mut evals, mut attempts) = (0u64, 0u64);
        let clock = Instant::now();
        for &(t0, y0, x_ref) in &starts {
            let mut sim = Simulation::new(osc, Dopri5::new(time_tolerances(rtol)?));
            let out = sim.run(t0, y0, t0 + span * period, &mut ())?;
            sq += (out.y[0] - x_ref).powi(2);
            evals += out.stats.rhs_evals;
            attempts += out.stats.accepted + out.stats.rejected;
        }
        let cpu = clock.elapsed().as_secs_f64();
        println!(
            "| {rtol:e} | DOPRI5 in time | {:.2e} | {:.0} | {:.0} | – | – | – | {:.3} |",
            (sq / n_starts as f64).sqrt(),
            evals as f64 / periods,
            attempts as f64 / periods,
            1000.0 * cpu / periods
        );
        // With segments.
        let mut sq = 0.0;
        let (mut evals, mut attempts, mut segs, mut seg_attempts, mut abandoned) =
            (0u64, 0u64, 0u64, 0u64, 0u64);
        let clock = Instant::now();
        for &(t0, y0, x_ref) in &starts {
            let seg_tol = Tolerances::per_component(rtol, [rtol * tau_atol, rtol * 1e-4])?;
            let stepper = TurningPoints::new(
                Dopri5::new(time_tolerances(rtol)?),
                Dopri5::new(seg_tol),
                band,
            )?;
            let mut sim = Simulation::new(osc, stepper);
            let out = sim.run(t0, y0, t0 + span * period, &mut ())?;
            sq += (out.y[0] - x_ref).powi(2);
            evals += out.stats.rhs_evals;
            let st = sim.stepper();
            let c = st.segment_counts();
            let ts = st.time_stepper().stats();
            attempts += ts.accepted + ts.rejected + c.attempts;
            segs += c.completed;
            seg_attempts += c.attempts;
            abandoned += c.abandoned;
        }
        let cpu = clock.elapsed().as_secs_f64();
        println!(
            "| {rtol:e} | DOPRI5 + segments | {:.2e} | {:.0} | {:.0} | {:.2} | {:.1} | {abandoned} | {:.3} |",
            (sq / n_starts as f64).sqrt(),
            evals as f64 / periods,
            attempts as f64 / periods,
            segs as f64 / periods,
            seg_attempts as f64 / segs.max(1) as f64,
            1000.0 * cpu / periods
        );
    }
    // The exact law (η = 0) from rest in contact: the first period creeps out of resting
    // contact, where the law's rate term has its cusp.
    let mut exact = PAPER;
    exact.eta = 0.0;
    let osc0 = exact.oscillator::<f64>(OMEGA)?;
    println!();
    println!(
        "exact law (η = 0), from rest at the static equilibrium, {n_exact} periods",
        n_exact = 10
    );
    println!("| rtol | method | RHS evaluations | x at the end (m) |");
    println!("|---|---|---|---|");
    for &rtol in rtols {
        let y0 = Vector2::new(x0, 0.0);
        let t1 = 10.0 * period;
        let plain =
            Simulation::new(osc0, Dopri5::new(time_tolerances(rtol)?)).run(0.0, y0, t1, &mut ());
        match plain {
            Ok(o) => println!(
                "| {rtol:e} | DOPRI5 in time | {} | {:.10e} |",
                o.stats.rhs_evals, o.y[0]
            ),
            Err(e) => println!("| {rtol:e} | DOPRI5 in time | failed: {e} | – |"),
        }
        let seg_tol = Tolerances::per_component(rtol, [rtol * tau_atol, rtol * 1e-4])?;
        let stepper = TurningPoints::new(
            Dopri5::new(time_tolerances(rtol)?),
            Dopri5::new(seg_tol),
            band,
        )?;
        let mut sim = Simulation::new(osc0, stepper);
        match sim.run(0.0, y0, t1, &mut ()) {
            Ok(o) => println!(
                "| {rtol:e} | DOPRI5 + segments | {} | {:.10e} |",
                o.stats.rhs_evals, o.y[0]
            ),
            Err(e) => println!("| {rtol:e} | DOPRI5 + segments | failed: {e} | – |"),
        }
    }
    Ok(())
}
