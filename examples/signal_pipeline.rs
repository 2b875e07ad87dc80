//! The measured-data pipeline on a synthetic record: generate, write CSV, read back,
//! filter with the paper's `(θs + 1)^{-1}`, detect impacts as upward crossings of
//! `x_I − 0.01 mm`, print the inter-impact intervals and the Poincaré section from the
//! (wrapped) rotor phase.
//!
//! ```text
//! cargo run --example signal_pipeline [-- out/signal_pipeline]
//! ```

use std::f64::consts::PI;
use std::path::PathBuf;

use nonsmooth::signal::{CsvOptions, PhaseSection, TimeSeries, intervals, section_frequencies};
use nonsmooth::systems::paper::{PAPER, impact_detector, low_pass};

/// SplitMix64 (Steele, Lea & Flood 2014): a tiny deterministic generator for pseudo-noise.
struct SplitMix64(u64);

impl SplitMix64 {
    /// Uniform in [−1, 1).
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

fn main() -> nonsmooth::Result<()> {
    let dir = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("out/signal_pipeline"), PathBuf::from);
    std::fs::create_dir_all(&dir)?;

    // 1. Synthetic record: 20 s at 5 kHz. The rotor accelerates like the paper's ramp,
    //    ω(t) = 20 + 8.0905e-3·t rad/s; the cart position is a sum of sines around the
    //    static equilibrium with sensor noise of ±2 µm.
    let (fs, duration) = (5000.0, 20.0);
    let (omega0, alpha) = (20.0, 8.0905e-3);
    let x_stop = PAPER.x_i; // the stop position x_I = −2.086 mm
    let n = (duration * fs) as usize;
    let mut rng = SplitMix64(2024);
    let mut t = Vec::with_capacity(n);
    let mut x = Vec::with_capacity(n);
    let mut phase = Vec::with_capacity(n);
    for i in 0..n {
        let ti = i as f64 / fs;
        let phi = omega0 * ti + 0.5 * alpha * ti * ti;
        t.push(ti);
        x.push(
            x_stop - 0.35e-3
                + 0.40e-3 * (phi - 0.4).sin()
                + 0.05e-3 * (2.0 * phi + 1.0).sin()
                + 0.02e-3 * (3.0 * phi).cos()
                + 2e-6 * rng.next_f64(),
        );
        phase.push(phi.rem_euclid(2.0 * PI));
    }
    let record = TimeSeries::new(t, x, Some(phase))?;

    // 2. Write and read back (tidy CSV, SI units in the header).
    let path = dir.join("synthetic_record.csv");
    record.write_csv_path(&path)?;
    let series = TimeSeries::from_csv_path(&path, &CsvOptions::default())?;
    assert_eq!(series, record, "CSV round trip must be exact");
    println!(
        "wrote and re-read {} samples: {}",
        series.len(),
        path.display()
    );

    // 3. Smooth with the paper's filter, θ = 1 ms.
    let smooth = series.filtered(&low_pass()?)?;

    // 4. Impacts: upward crossings of x_I − 0.01 mm, debounced by a 2 µm hysteresis.
    let detector = impact_detector(x_stop)?.with_hysteresis(2e-6)?;
    let raw_impacts = series.crossings(&impact_detector(x_stop)?)?;
    let impacts = smooth.crossings(&detector)?;
    let intervals = intervals(&impacts);
    println!(
        "impacts: {} in the raw record (noise chatter), {} after filtering + hysteresis",
        raw_impacts.len(),
        impacts.len()
    );
    println!("first inter-impact intervals T_j (s):");
    for (j, dt) in intervals.iter().take(8).enumerate() {
        println!("  T_{j} = {dt:.6}");
    }
    let mean = intervals.iter().sum::<f64>() / intervals.len().max(1) as f64;
    println!(
        "  … mean {mean:.6} s (forcing period at mid-record {:.6} s)",
        2.0 * PI / (omega0 + alpha * duration / 2.0)
    );

    // 5. Poincaré section φ = 2πi and the forcing frequency at each point.
    let points = smooth.poincare(&PhaseSection::new())?;
    let omega = section_frequencies(&points)?;
    println!("Poincaré points: {} (first five):", points.len());
    for (p, w) in points.iter().zip(&omega).take(5) {
        println!(
            "  i = {:3}  t = {:.6} s  ω = {:.5} rad/s  x = {:.6} mm",
            p.i,
            p.t,
            w,
            p.x * 1e3
        );
    }

    // Tidy CSV of the impact sequence.
    let mut csv = String::from("j,t_s,interval_s\n");
    for (j, (t, dt)) in impacts.iter().zip(&intervals).enumerate() {
        csv.push_str(&format!("{j},{t},{dt}\n"));
    }
    let path = dir.join("impact_intervals.csv");
    std::fs::write(&path, csv)?;
    println!("wrote {}", path.display());
    Ok(())
}
