//! The Duffing–Ueda oscillator from the catalogue (`systems::DuffingUeda`,
//! `ẍ + 0.05ẋ + x³ = 7.5 cos t`): its stroboscopic section (Ueda's chaotic attractor) and
//! top Lyapunov exponent two ways, with three independent checks:
//! - the assembled model against a hand-written right-hand side integrated with a second
//!   integrator (DOP853 instead of DOPRI5), section by section over the first periods;
//! - the two-trajectory and the QR (tangent-space) estimates of `λ₁` agree with each other
//!   and with the published value ≈ 0.10 per unit time;
//! - the QR spectrum sums to `tr J = −k` exactly.
//!
//! `cargo run --release [--features plot] --example duffing_ueda -- [--quick] [--out DIR]`
//!
//! Writes `duffing_ueda_section.csv` and `duffing_ueda_lyapunov.csv` (and `duffing_ueda.png`
//! with `plot`) into `out/duffing_ueda`. Exits non-zero if a check fails.

use std::f64::consts::TAU;
use std::path::PathBuf;
use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::drive::Simulation;
use nonsmooth::integrate::{Dop853, Dopri5, Tolerances};
use nonsmooth::lyapunov::{Norm, TangentSpace, TwoTrajectory};
use nonsmooth::output::csv::{Cell, write_table_path};
use nonsmooth::sample::Stroboscopic;
use nonsmooth::systems::DuffingUeda;
use nonsmooth::testing::DuffingUedaByHand;

/// Stroboscopic points `(x, ẋ)(2πi)`, `i = 1..=periods`, after `transient` periods.
fn section<S: nonsmooth::Dynamics<f64, 2>, St: nonsmooth::integrate::Stepper<f64, 2>>(
    system: S,
    stepper: St,
    y0: Vector2<f64>,
    transient: usize,
    periods: usize,
) -> nonsmooth::Result<Vec<(f64, f64)>> {
    let t_rec = transient as f64 * TAU;
    let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, TAU, t_rec + 0.5 * TAU, periods + 1)?;
    let t_end = (transient + periods) as f64 * TAU + 0.25 * TAU;
    let mut sim = Simulation::new(system, stepper).max_steps(usize::MAX)?;
    sim.run(0.0, y0, t_end, &mut strobe)?;
    Ok(strobe.points().iter().map(|p| (p.y[0], p.y[1])).collect())
}

fn main() -> nonsmooth::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out/duffing_ueda"));
    std::fs::create_dir_all(&out).map_err(|e| nonsmooth::Error::Output(e.to_string()))?;

    let p = DuffingUeda::default();
    let y0 = Vector2::new(3.0, 0.0);
    let tol = Tolerances::new(1e-10, 1e-12)?;
    let mut ok = true;

    // 1. Ueda's attractor on the section t = 2πi.
    let start = Instant::now();
    let points = if quick { 3000 } else { 20_000 };
    let attractor = section(p.model::<f64>()?, Dopri5::new(tol), y0, 100, points)?;
    println!(
        "section: {} points after 100 periods in {:.2} s",
        attractor.len(),
        start.elapsed().as_secs_f64()
    );

    // 2. The assembled model against the hand-written one on a second integrator. Chaos
    // amplifies differences by e^{λ₁t}: over 12 periods (t ≈ 75) that is e^{7.5} ≈ 2·10³,
    // so at tolerances 10⁻¹³ the sections agree to ≈ 10⁻⁹ unless the assembly is wrong.
    let tight = Tolerances::new(1e-13, 1e-13)?;
    let a = section(p.model::<f64>()?, Dopri5::new(tight), y0, 0, 12)?;
    let b = section(
        DuffingUedaByHand { params: p },
        Dop853::new(tight),
        y0,
        0,
        12,
    )?;
    let worst = a
        .iter()
        .zip(&b)
        .map(|(u, v)| (u.0 - v.0).abs().max((u.1 - v.1).abs()))
        .fold(0.0, f64::max);
    let agree = a.len() == 12 && b.len() == 12 && worst < 1e-7;
    ok &= agree;
    println!(
        "assembled (DOPRI5) vs hand-written (DOP853), 12 sections: max |Δ| = {worst:.2e} ({})",
        if agree { "ok" } else { "FAILED" }
    );

    // 3. λ₁ two ways and the QR sum.
    let intervals = if quick { 600 } else { 5000 };
    let start = Instant::now();
    let mut pair = TwoTrajectory::from_tolerances(
        p.model::<f64>()?,
        &tol,
        Dopri5::new,
        1e-8,
        Norm::Euclidean,
    )?;
    pair.start(0.0, y0)?;
    pair.transient(TAU, 50)?;
    let two = pair.estimate(TAU, intervals)?;
    let mut qr = TangentSpace::from_tolerances(
        p.model::<f64>()?,
        &tol,
        Dopri5::new,
        (1e-10, 1e-12),
        Norm::Euclidean,
    )?;
    qr.start(0.0, y0)?;
    qr.transient(TAU, 50)?;
    let spec = qr.estimate(TAU, intervals)?;
    println!(
        "λ₁ over {intervals} periods: two trajectories {:.4} ± {:.4}, QR {:.4} ± {:.4} (λ₂ {:.4}); {:.2} s",
        two.exponent,
        two.spread,
        spec.exponents[0],
        spec.spread[0],
        spec.exponents[1],
        start.elapsed().as_secs_f64()
    );
    // Published: λ₁ ≈ 0.10; the two estimators must agree within their spreads.
    let near = |x: f64, s: f64| (x - 0.10).abs() < 3.0 * s + 0.02;
    let lyap_ok = near(two.exponent, two.spread)
        && near(spec.top(), spec.spread[0])
        && (two.exponent - spec.top()).abs() < 3.0 * (two.spread + spec.spread[0]) + 0.01;
    ok &= lyap_ok;
    let sum_err = (spec.sum() + p.k).abs();
    let sum_ok = sum_err < 1e-6;
    ok &= sum_ok;
    println!(
        "λ₁ vs 0.10: {}; λ₁ + λ₂ = {:.9} vs −k = {} (|Δ| = {sum_err:.1e}, {})",
        if lyap_ok { "ok" } else { "FAILED" },
        spec.sum(),
        -p.k,
        if sum_ok { "ok" } else { "FAILED" }
    );

    write_table_path(
        out.join("duffing_ueda_section.csv"),
        &["x", "v"],
        attractor
            .iter()
            .map(|&(x, v)| [Cell::Number(x), Cell::Number(v)]),
    )?;
    let blocks = two.history.len().min(spec.history.len());
    write_table_path(
        out.join("duffing_ueda_lyapunov.csv"),
        &["t", "two_trajectories", "qr_top", "qr_second"],
        (0..blocks).map(|i| {
            [
                Cell::Number((i + 1) as f64 * TAU),
                Cell::Number(two.history[i]),
                Cell::Number(spec.history[i][0]),
                Cell::Number(spec.history[i][1]),
            ]
        }),
    )?;
    #[cfg(feature = "plot")]
    {
        use nonsmooth::output::plot::{Layout, Panel, Rgb, Series, render};
        let sec = Panel::new("x(2πi)", "ẋ(2πi)")
            .with(Series::dots(attractor.iter().copied()).color(Rgb::BLACK))
            .legend(None);
        let conv = Panel::new("t", "running λ")
            .hline(0.10, Rgb::BLACK)
            .with(
                Series::line(
                    two.history
                        .iter()
                        .enumerate()
                        .map(|(i, &h)| ((i + 1) as f64 * TAU, h)),
                )
                .color(Rgb::RED)
                .label("two trajectories"),
            )
            .with(
                Series::line(
                    spec.history
                        .iter()
                        .enumerate()
                        .map(|(i, h)| ((i + 1) as f64 * TAU, h[0])),
                )
                .color(Rgb::GREEN)
                .label("QR λ₁"),
            );
        render(
            out.join("duffing_ueda.png"),
            &[sec, conv],
            &Layout::grid(2, 1400, 650).title("Duffing–Ueda: ẍ + 0.05ẋ + x³ = 7.5 cos t"),
        )?;
    }
    println!("wrote {}", out.display());
    if !ok {
        std::process::exit(1);
    }
    Ok(())
}
