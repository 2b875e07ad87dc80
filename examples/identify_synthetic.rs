//! Parameter identification on a synthetic experiment: the paper's procedure (Sect. 2) end
//! to end, with a known answer.
//!
//! 1. "Measure" the paper's model with its identified parameters: from rest in the static
//!    equilibrium, forced at constant ω, sampled at 1 kHz, with 2 µm Gaussian noise and an
//!    unmodelled 1 µm, 60 Hz oscillation; write `measured.csv` (`t_s,x_m,phase_rad`).
//! 2. Read the CSV back and fit all seven parameters `(k, c, T, k_I, b, n₂, n₃)` by
//!    minimizing `F0` with Nelder–Mead, from a guess 20 % off (every parameter × 1.2,
//!    or alternately × 1.2 and × 0.8 with `--alternate`), in stages (see the comments in
//!    `main`: growing window, (k, c, T) first, bounded parameters).
//! 3. Print the table (parameter, true, guess, fitted, relative error), `F0` in mm² beside
//!    the noise floor `F0(true parameters)`, the number of simulations and the wall time;
//!    write `fit.csv` and `history.csv`.
//!
//! ```text
//! cargo run --release --example identify_synthetic -- [--omega 17] [--duration 2]
//!     [--noise 2e-6] [--hum 1e-6] [--hum-frequency 60] [--seed 1] [--guess 1.2]
//!     [--alternate] [--restarts 4] [--max-iterations 5000] [--stages 0.5,1]
//!     [--out out/identify]
//! ```
//!
//! The default frequency is ω = 17 rad/s, a periodic impacting regime (8 impacts in the
//! first second). At the paper's ω = 20.465 rad/s the start from rest is an irregular
//! transient in which `F0` is a rough function of the parameters (`F0(k)` has local minima
//! every ~2.5 % of `k` over one second of data), so a guess 20 % off does not lead
//! Nelder–Mead to the answer there; `--omega 20.465 --guess 1.02` reaches the noise floor.
//!
//! Measured (dev profile, default arguments): 6147 simulations, 34 s; `k, c, T, k_I`
//! recovered within their linearized 3σ, F0 = 4.3616e-6 mm² below the 4.3724e-6 mm² of
//! the true parameters; `b, n₂, n₃` land elsewhere on the curved valley of the contact
//! damping `b·δ^{n₂}·|v|^{n₃}` (Δχ² of the truth 4.9: the data cannot tell them apart).
//! Noise-free (`--noise 0 --hum 0`): all seven within 8·10⁻⁴, 6750 simulations, 31 s.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use nonsmooth::identify::{M2_TO_MM2, NelderMeadOptions};
use nonsmooth::signal::{CsvOptions, TimeSeries};
use nonsmooth::systems::paper::{
    Forcing, PAPER, PAPER_FIT_PARAMETERS, PaperFit, SyntheticExperiment, paper_parameter,
    set_paper_parameter,
};

struct Args {
    omega: f64,
    duration: f64,
    noise: f64,
    hum: f64,
    hum_frequency: f64,
    seed: u64,
    guess: f64,
    alternate: bool,
    restarts: usize,
    max_iterations: u64,
    stages: Vec<f64>,
    out: PathBuf,
}

fn parse() -> Result<Args, String> {
    let mut a = Args {
        omega: 17.0,
        duration: 2.0,
        noise: 2e-6,
        hum: 1e-6,
        hum_frequency: 60.0,
        seed: 1,
        guess: 1.2,
        alternate: false,
        restarts: 4,
        max_iterations: 5_000,
        stages: vec![0.5, 1.0],
        out: PathBuf::from("out/identify"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        if flag == "--alternate" {
            a.alternate = true;
            continue;
        }
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        let num = || value.parse::<f64>().map_err(|e| format!("{flag}: {e}"));
        match flag.as_str() {
            "--omega" => a.omega = num()?,
            "--duration" => a.duration = num()?,
            "--noise" => a.noise = num()?,
            "--hum" => a.hum = num()?,
            "--hum-frequency" => a.hum_frequency = num()?,
            "--seed" => a.seed = value.parse().map_err(|e| format!("{flag}: {e}"))?,
            "--guess" => a.guess = num()?,
            "--restarts" => a.restarts = value.parse().map_err(|e| format!("{flag}: {e}"))?,
            "--max-iterations" => {
                a.max_iterations = value.parse().map_err(|e| format!("{flag}: {e}"))?
            }
            "--out" => a.out = PathBuf::from(value),
            "--stages" => {
                a.stages = value
                    .split(',')
                    .map(|v| v.parse::<f64>().map_err(|e| format!("{flag}: {e}")))
                    .collect::<Result<_, _>>()?
            }
            other => return Err(format!("unknown option {other}")),
        }
    }
    Ok(a)
}

fn main() -> nonsmooth::Result<()> {
    let args = parse().unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    std::fs::create_dir_all(&args.out)?;
    let forcing = Forcing::constant(args.omega);

    // 1. The synthetic experiment.
    let t0 = Instant::now();
    let record = SyntheticExperiment::new(PAPER, forcing, args.duration)?
        .with_noise(args.noise, args.seed)?
        .with_disturbance(args.hum, args.hum_frequency)?
        .with_phase_column(true)
        .generate()?;
    let csv = args.out.join("measured.csv");
    record.measured.write_csv_path(&csv)?;
    println!(
        "synthetic experiment: ω = {} rad/s, {} s at 1 kHz, noise σ = {:.1} µm, {:.1} µm at {} Hz, {} impacts ({:.2?}) -> {}",
        args.omega,
        args.duration,
        args.noise * 1e6,
        args.hum * 1e6,
        args.hum_frequency,
        record.impacts.len(),
        t0.elapsed(),
        csv.display()
    );

    // 2. The fit, on the record as read back from the CSV file. Nelder–Mead from a guess
    //    20 % off in all seven parameters does not reach the answer on the whole record at
    //    once: over two seconds a 10 % error in the natural frequency (k 20 % off) slips the
    //    free transient by more than a radian, F0 has local minima, and an unbounded
    //    exponent can run away (n₂ → 100 switches the contact damping off, which a huge c
    //    then imitates). So the fit is staged:
    //    - the window grows (0.5 s, 1 s, the whole record), each stage starting from the
    //      previous one's result — a continuation in the horizon;
    //    - the first stage fits only (k, c, T), the contact parameters held at their guess
    //      (three impacts in 0.5 s say little about them);
    //    - every parameter is boxed: within a factor 3 of its guess, the exponents within
    //      physically sensible ranges, n₂ ∈ [1, 2.5], n₃ ∈ [0.05, 1].
    let measured = TimeSeries::from_csv_path(&csv, &CsvOptions::default())?;
    let floor_fit = PaperFit::new(measured.clone(), (0.0, args.duration), forcing, PAPER)?;
    let floor = floor_fit.objective(&PAPER)? * M2_TO_MM2;
    let mut guesses = Vec::new();
    for (i, name) in PAPER_FIT_PARAMETERS.iter().enumerate() {
        let factor = if args.alternate && i % 2 == 1 {
            2.0 - args.guess
        } else {
            args.guess
        };
        guesses.push(factor * paper_parameter(&PAPER, name)?);
    }
    let bounds: Vec<(f64, f64)> = PAPER_FIT_PARAMETERS
        .iter()
        .zip(&guesses)
        .map(|(&name, &g)| match name {
            "n2" => (1.0, 2.5),
            "n3" => (0.05, 1.0),
            _ => (g / 3.0, 3.0 * g),
        })
        .collect();
    let mut stages: Vec<f64> = args
        .stages
        .iter()
        .copied()
        .filter(|&t| t < args.duration)
        .collect();
    stages.push(args.duration);
    let mut current = guesses.clone();
    let (mut simulations, mut failed) = (0, 0);
    let mut history = Vec::new();
    let mut report = None;
    let wall = Instant::now();
    for (stage, &t2) in stages.iter().enumerate() {
        let subset: &[&str] = if stage == 0 && stages.len() > 1 {
            &["k", "c", "t"]
        } else {
            &PAPER_FIT_PARAMETERS
        };
        // The parameters not fitted in this stage stay at their current values.
        let mut base = PAPER;
        for (name, &v) in PAPER_FIT_PARAMETERS.iter().zip(&current) {
            set_paper_parameter(&mut base, name, v)?;
        }
        let mut fit = PaperFit::new(measured.clone(), (0.0, t2), forcing, base)?.with_options(
            NelderMeadOptions::default()
                .with_tolerances(1e-4, 1e-6)
                .with_restarts(args.restarts)
                .with_max_iterations(args.max_iterations),
        );
        for ((name, &v), &(lo, hi)) in PAPER_FIT_PARAMETERS.iter().zip(&current).zip(&bounds) {
            if subset.contains(name) {
                fit = fit.fit_bounded(name, v, lo, hi)?;
            }
        }
        let r = fit.run()?;
        println!(
            "stage {} [0, {t2}] s, {subset:?}: F0 {:.3e} -> {:.6e} mm², {} simulations, {} iterations, {}, {:.2?}",
            stage + 1,
            r.initial_f0_mm2,
            r.f0_mm2,
            r.simulations,
            r.fit.iterations,
            r.fit.termination,
            r.wall_time
        );
        current = PAPER_FIT_PARAMETERS
            .iter()
            .map(|n| paper_parameter(&r.parameters, n))
            .collect::<Result<_, _>>()?;
        simulations += r.simulations;
        failed += r.failed_simulations;
        history.extend(r.fit.history.iter().map(|f| (t2, f * M2_TO_MM2)));
        report = Some(r);
    }
    let wall = wall.elapsed();
    let report = report.ok_or_else(|| nonsmooth::Error::Output("no stage ran".into()))?;

    // 3. The table, with the linearized standard deviations at the fit: J = ∂x_sim/∂ln p
    //    by central differences (step 1e-2, large against the integrator's error),
    //    cov(ln p) = s²(JᵀJ)⁻¹ with s² = N·F0/(N − 7) the residual variance.
    let last = PaperFit::new(measured.clone(), (0.0, args.duration), forcing, PAPER)?;
    let h: f64 = 1e-2;
    let mut cols = Vec::new();
    for name in PAPER_FIT_PARAMETERS {
        let v = paper_parameter(&report.parameters, name)?;
        let (mut up, mut down) = (report.parameters, report.parameters);
        set_paper_parameter(&mut up, name, v * h.exp())?;
        set_paper_parameter(&mut down, name, v * (-h).exp())?;
        let (xu, xd) = (last.simulate(&up)?, last.simulate(&down)?);
        cols.push(
            xu.iter()
                .zip(&xd)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect::<Vec<f64>>(),
        );
    }
    let p = cols.len();
    let n = last.nodes().len() as f64;
    let jtj = nalgebra::DMatrix::from_fn(p, p, |i, j| {
        cols[i]
            .iter()
            .zip(&cols[j])
            .map(|(a, b)| a * b)
            .sum::<f64>()
    });
    let s2 = report.fit.objective * n / (n - p as f64);
    let sd: Vec<f64> = match jtj.try_inverse() {
        Some(inv) => (0..p).map(|j| (s2 * inv[(j, j)]).sqrt()).collect(),
        None => vec![f64::NAN; p],
    };
    println!(
        "\n{:<5} {:>14} {:>14} {:>14} {:>11} {:>11}",
        "param", "true", "guess", "fitted", "rel. error", "3σ (rel.)"
    );
    let mut table = std::fs::File::create(args.out.join("fit.csv"))?;
    writeln!(
        table,
        "parameter,true,guess,fitted,relative_error,three_sigma_relative"
    )?;
    for ((name, guess), sd) in PAPER_FIT_PARAMETERS.iter().zip(&guesses).zip(&sd) {
        let truth = paper_parameter(&PAPER, name)?;
        let fitted = report.value(name)?;
        let rel = fitted / truth - 1.0;
        let three = 3.0 * sd;
        println!(
            "{name:<5} {truth:>14.6e} {guess:>14.6e} {fitted:>14.6e} {rel:>+11.2e} {three:>11.2e}"
        );
        writeln!(
            table,
            "{name},{truth:e},{guess:e},{fitted:e},{rel:e},{three:e}"
        )?;
    }
    println!(
        "\nF0 = {:.6e} mm² (initial guess {:.3e} mm²; at the true parameters {:.6e} mm², expected ≈ σ² + A²/2 = {:.3e} mm²)",
        report.f0_mm2,
        report.initial_f0_mm2,
        floor,
        (args.noise.powi(2) + 0.5 * args.hum.powi(2)) * M2_TO_MM2
    );
    // Where the truth lies in the likelihood: Δχ² = N·(F0(true) − F0(fit))/s². The
    // linearized 3σ above is an ellipsoid; the contact damping b·δ^{n₂}·|v|^{n₃} makes the
    // real confidence region a curved valley, and a fit can sit far from the truth along
    // it while fitting the data as well (Δχ² within the χ²₇ range, 99.7 % quantile 21.7).
    println!(
        "Δχ² of the true parameters relative to the fit: {:.2} (N = {n}, s = {:.3} µm)",
        n * (floor / M2_TO_MM2 - report.fit.objective) / s2,
        s2.sqrt() * 1e6
    );
    println!(
        "{simulations} simulations ({failed} failed) in {} stages; last stage: {} iterations, {} runs, {}; wall time {wall:.2?}",
        stages.len(),
        report.fit.iterations,
        report.fit.runs,
        report.fit.termination,
    );
    let mut file = std::fs::File::create(args.out.join("history.csv"))?;
    writeln!(file, "step,window_end_s,f0_mm2")?;
    for (i, (t2, f)) in history.iter().enumerate() {
        writeln!(file, "{i},{t2},{f:e}")?;
    }
    println!("wrote {}", args.out.display());
    Ok(())
}
