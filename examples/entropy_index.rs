//! The paper's entropy-index pipeline (Sect. 4, Figs. 6–7) on a synthetic sample.
//!
//! The "inter-impact intervals" here are a deterministic chaotic sequence, so that the
//! estimator can be looked at alone: the logistic map `x ← r·x·(1 − x)` mapped to
//! `T_j = 0.08 + 0.2·x_j` seconds, inside the paper's histogram range `(0.05, 0.3)` with
//! step `0.001`. The integrated model's intervals (Figs. 6, 7 at ω = 20.465) are in
//! `examples/paper`; a scan of `q*` over a parameter grid is a study recording `q`
//! (`nonsmooth study run`, whose points run in SIMD lanes).
//!
//! Run with `cargo run --release --example entropy_index`.

use nonsmooth::entropy::{EntropyError, Histogram, QRange, entropy_index, redundancy_curve};

/// `n` intervals from the logistic map with parameter `r`, after 1000 transient iterations.
fn logistic_intervals(r: f64, n: usize) -> Vec<f64> {
    let mut x = 0.3;
    for _ in 0..1000 {
        x = r * x * (1.0 - x);
    }
    (0..n)
        .map(|_| {
            x = r * x * (1.0 - x);
            0.08 + 0.2 * x
        })
        .collect()
}

fn main() -> Result<(), EntropyError> {
    let histogram = Histogram::new(0.05, 0.3, 0.001)?;
    let range = QRange::default();

    // Fig. 6 analogue: one sample, its histogram and its redundancy curve.
    let intervals = logistic_intervals(3.9, 100_000);
    let est = histogram.estimate(&intervals)?;
    println!(
        "{} intervals, {} bins: {} occupied, {} empty (dropped), {} below / {} above the range",
        est.tally.total(),
        histogram.bins(),
        est.occupied(),
        est.probabilities.dropped_zeros(),
        est.tally.below,
        est.tally.above
    );
    let index = entropy_index(&est.probabilities, &range)?;
    println!(
        "entropy index q* = {:.6}, R(q*) = {:.6} ({} evaluations of R, {} scan maxima, at range end: {:?})",
        index.q, index.redundancy, index.evaluations, index.scan_maxima, index.at_bound
    );
    println!(
        "q* {} 1: {}",
        if index.q < 1.0 { "<" } else { ">=" },
        if index.q < 1.0 {
            "rare events weigh in the distribution"
        } else {
            "frequent events dominate"
        }
    );
    println!("\n   q      R(q)");
    for pt in redundancy_curve(&est.probabilities, 0.1, 3.0, 30)? {
        let bar = "#".repeat((pt.redundancy * 600.0).round().max(0.0) as usize);
        println!("{:5.2}  {:.5}  {bar}", pt.q, pt.redundancy);
    }

    // Fig. 7 analogue: q* along the parameter, with the regimes where it is undefined.
    println!("\n    r     N      q*       R(q*)");
    for k in 0..=15 {
        let r = 3.80 + 0.01 * k as f64;
        let est = histogram.estimate(&logistic_intervals(r, 30_000))?;
        match entropy_index(&est.probabilities, &range) {
            Ok(i) => println!("{r:.3}  {:4}  {:.4}  {:.5}", i.states, i.q, i.redundancy),
            Err(e) => println!("{r:.3}  {:4}  --      ({e})", est.occupied()),
        }
    }
    Ok(())
}
