//! The paper's approximate solutions about the static equilibrium (Sect. 5, eqs. 4–6) and
//! their grazing estimates, side by side with the paper's printed values.
//!
//! Run with `cargo run --example approximations`.

use nonsmooth::analysis::{AmplitudePhase, LinearizedResponse, TurningPoint};
use nonsmooth::systems::paper::PAPER;
use nonsmooth::util::brent;

fn row(name: &str, paper: Option<f64>, ours: f64) {
    match paper {
        Some(p) => println!(
            "{name:<44} {p:>14.5e} {ours:>16.8e} {:>+11.2e}",
            (ours - p) / p.abs()
        ),
        None => println!("{name:<44} {:>14} {ours:>16.8e} {:>11}", "—", "—"),
    }
}

fn main() -> Result<(), nonsmooth::Error> {
    let omega = 14.0;
    let osc = PAPER.oscillator::<f64>(omega)?;
    let x0 = PAPER.static_equilibrium()?;
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c)?;
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c)?;

    println!(
        "{:<44} {:>14} {:>16} {:>11}",
        "quantity", "paper", "ours", "rel. diff"
    );
    println!("{}", "-".repeat(88));
    row("X0 (m)", Some(-2.0807e-3), x0);
    row("k_eff = ∂ΣF/∂x at X0 (N/m)", None, lin.stiffness());

    let (a1, a2) = lin.coefficients(omega);
    row(
        "eq. (4), ω = 14: sin ωt coefficient A1 (m)",
        Some(4.2606e-6),
        a1,
    );
    row(
        "eq. (4), ω = 14: cos ωt coefficient A2 (m)",
        Some(-4.7779e-10),
        a2,
    );
    let w_lin = lin.grazing_omega(PAPER.x_i, 10.0, 30.0)?;
    row("grazing, linearized (rad/s)", Some(15.657), w_lin);

    let up = ap.solve(omega, TurningPoint::Upper)?;
    row(
        "eq. (6), ω = 14: sin ωt coefficient (m)",
        Some(3.6833e-6),
        up.sin_coefficient(),
    );
    row(
        "eq. (6), ω = 14: cos ωt coefficient (m)",
        Some(-3.5707e-10),
        up.cos_coefficient(),
    );
    let w_low = ap.grazing_omega(PAPER.x_i, TurningPoint::Lower, 10.0, 14.0)?;
    row(
        "grazing, amplitude–phase, lower point (rad/s)",
        Some(12.789),
        w_low,
    );

    println!();
    println!("other branches and readings (not in the paper):");
    // The upper amplitude mirrored to the lower side: X0 − a_upper(ω) = x_I.
    let gap = x0 - PAPER.x_i;
    let f = |w: f64| {
        ap.solve(w, TurningPoint::Upper)
            .map(|s| s.amplitude - gap)
            .unwrap_or(f64::NAN)
    };
    let w_mirror = brent(f, 10.0, 30.0, f(10.0), f(30.0), 1e-12, 200)?;
    row("grazing, upper amplitude mirrored (rad/s)", None, w_mirror);
    match ap.solve(omega, TurningPoint::Lower) {
        Ok(s) => {
            row(
                "lower balance at ω = 14: amplitude a (m)",
                None,
                s.amplitude,
            );
            row("lower balance at ω = 14: lag ψ (rad)", None, s.lag);
        }
        Err(e) => println!("lower balance at ω = 14: {e}"),
    }
    let low12 = ap.solve(12.0, TurningPoint::Lower)?;
    row(
        "lower balance at ω = 12: amplitude a (m)",
        None,
        low12.amplitude,
    );
    row("upper balance at ω = 14: lag ψ = α (rad)", None, up.lag);
    row(
        "upper balance at ω = 14: amplitude a (m)",
        None,
        up.amplitude,
    );
    row(
        "linearized amplitude at ω = 14 (m)",
        None,
        lin.amplitude(omega),
    );
    println!();
    println!(
        "eq. (3) (Fourier fit of the simulated orbit at ω = 14) needs the integrator: \
         paper a0 = -2.0813e-3, a1 = -1.3136e-6, b1 = 3.9328e-6, a2 = 6.6538e-7, b2 = 2.915e-7"
    );
    Ok(())
}
