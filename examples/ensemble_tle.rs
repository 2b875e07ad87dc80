//! W4 on the ensemble: the top Lyapunov exponent over the paper's Fig. 5 grid (ω ∈ [17.5,
//! 25], step 0.01, 751 values; 100 transient and 1000 recorded forcing periods, d0 =
//! `PAPER_D0`, the paper's norm, rtol 1e-8), both trajectories of every pair in lanes
//! (`lyapunov::tle_independent_parallel`, independent starts from rest), on the default
//! rayon pool. The scalar estimator from rest (`TwoTrajectory`) is timed on every
//! `--every`-th value (default 25) for the ratio and compared value by value.
//!
//! ```sh
//! cargo run --release --features timing --example ensemble_tle                 # full grid
//! cargo run --release --features timing --example ensemble_tle -- --quick      # step 0.1, 300 periods
//! ```

use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::ensemble::{Ensemble, LaneMath, Simd};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{
    DiagramSettings, IntervalRule, TwoTrajectory, pair_tolerances, tle_independent_parallel,
};
use nonsmooth::systems::paper::lyapunov::{D0 as PAPER_D0, norm as paper_norm};
use nonsmooth::systems::paper::{Member, PAPER};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let every: usize = args
        .iter()
        .position(|a| a == "--every")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(25);
    let (step, intervals) = if quick { (0.1, 300) } else { (0.01, 1000) };
    let n = ((25.0 - 17.5) / step + 1e-9f64).floor() as usize + 1;
    let omegas: Vec<f64> = (0..n).map(|i| 17.5 + i as f64 * step).collect();
    let rtol = 1e-8;
    let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?;
    let y0 = Vector2::new(PAPER.static_equilibrium()?, 0.0);
    let settings = DiagramSettings::new(IntervalRule::ForcingPeriod, 100, 50, intervals)?;
    println!(
        "{n} values × (100 + {intervals}) periods, {} threads, lane loop on {:?}",
        rayon::current_num_threads(),
        Simd::Auto.resolve()
    );

    let members: Vec<(f64, Member)> = omegas
        .iter()
        .map(|&w| Member::paper(w).map(|m| (w, m)))
        .collect::<Result<_, _>>()?;
    let start = Instant::now();
    // The lane pair is not the scalar pair to the bit anyway (each copy has its own step),
    // so the vector math costs nothing in agreement.
    let e = Ensemble::new(tol)?.with_math(LaneMath::Vector);
    let lanes = tle_independent_parallel(&e, &members, y0, PAPER_D0, paper_norm(), &settings, 64)?;
    let t_lanes = start.elapsed().as_secs_f64();
    println!("independent starts, ensemble (vector math): {t_lanes:7.2} s");

    let pair_tol = pair_tolerances(&tol)?;
    let sub: Vec<usize> = (0..n).step_by(every.max(1)).collect();
    let start = Instant::now();
    let scalar: Vec<(f64, f64)> = {
        use rayon::prelude::*;
        sub.par_iter()
            .map(|&i| -> nonsmooth::Result<(f64, f64)> {
                let w = omegas[i];
                let mut est = TwoTrajectory::new(
                    PAPER.oscillator::<f64>(w)?,
                    Dopri5::new(pair_tol),
                    PAPER_D0,
                    paper_norm(),
                )?;
                est.start(0.0, y0)?;
                let tau = std::f64::consts::TAU / w;
                est.transient(tau, 100)?;
                let e = est.estimate(tau, intervals)?;
                Ok((e.exponent, e.spread))
            })
            .collect::<nonsmooth::Result<_>>()?
    };
    let t_sub = start.elapsed().as_secs_f64();
    let t_scalar = t_sub * n as f64 / sub.len() as f64;
    let mut within = 0;
    let mut sign = 0;
    for (&i, &(l, se)) in sub.iter().zip(&scalar) {
        let p = &lanes[i];
        let band = 3.0 * (se * se + p.spread * p.spread).sqrt();
        within += usize::from((p.exponent - l).abs() <= band);
        sign += usize::from((p.exponent > 0.0) == (l > 0.0));
    }
    println!(
        "independent starts, scalar estimator: {t_sub:7.2} s on {} values → {t_scalar:7.2} s for all {n} (extrapolated)",
        sub.len()
    );
    println!(
        "agreement on those values: {within}/{} within 3 combined spreads, {sign}/{} same sign",
        sub.len(),
        sub.len()
    );
    println!(
        "independent-start TLE ratio scalar/ensemble: {:.2}",
        t_scalar / t_lanes
    );
    Ok(())
}
