//! A 2-DOF impact oscillator from the catalogue (`systems::TwoDofImpact`): bifurcation
//! diagram of the secondary mass's stroboscopic position and of its impacts on the stop,
//! forcing frequency swept up and down with continuation; checked against a hand-written
//! right-hand side integrated independently.
//!
//! `cargo run --release [--features plot] --example two_dof_impact -- [--quick] [--out DIR]`
//!
//! Writes `two_dof_{poincare,intervals,summary}.csv` (and `two_dof.png` with `plot`) into
//! `out/two_dof_impact`. Exits non-zero if the assembled model and the hand-written one
//! disagree.

use std::path::PathBuf;
use std::time::Instant;

use nalgebra::SVector;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::output::csv::{
    SweepColumns, write_sweep_intervals_path, write_sweep_poincare_path, write_sweep_summary_path,
};
use nonsmooth::sweep::{SweepConfig, SweepDirection, SweepResult, SweepSystem, sweep};
use nonsmooth::systems::TwoDofImpact;
use nonsmooth::testing::TwoDofImpactByHand;

fn tolerances() -> nonsmooth::Result<Tolerances<f64, 4>> {
    Ok(Tolerances::per_component(1e-9, [1e-11; 4])?)
}

fn main() -> nonsmooth::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out/two_dof_impact"));
    std::fs::create_dir_all(&out).map_err(|e| nonsmooth::Error::Output(e.to_string()))?;

    let p = TwoDofImpact::default();
    let (lo, hi, step) = if quick {
        (0.3, 1.3, 0.01)
    } else {
        (0.3, 1.3, 0.0025)
    };
    let config = SweepConfig::grid(lo, hi, step)?
        .direction(SweepDirection::Both)
        .transients(200, 100)
        .record(40)?;
    let start = Instant::now();
    let make = |w: f64| -> nonsmooth::Result<SweepSystem<_, _>> {
        Ok(SweepSystem {
            system: p.model::<f64>(w)?,
            period: TwoDofImpact::period(w),
            stop: Some(p.stop::<f64>()?),
        })
    };
    let tol = tolerances()?;
    let result = sweep(&config, make, || Dopri5::new(tol), SVector::zeros())?;
    println!(
        "2-DOF impact oscillator: ω ∈ [{lo}, {hi}], step {step}, both directions: {:.1} s",
        start.elapsed().as_secs_f64()
    );

    // Summary: impacts per period and regime, up branch.
    let up = &result.branches[0];
    let mut last = (f64::NAN, String::new());
    for pt in &up.points {
        let regime = format!("{:?}", pt.regime);
        if pt.impacts_per_period != last.0 || regime != last.1 {
            println!(
                "  from ω = {:.4}: {:.2} impacts/period, {regime}",
                pt.param, pt.impacts_per_period
            );
            last = (pt.impacts_per_period, regime);
        }
    }

    // Independent check: the hand-written right-hand side at values with periodic
    // response gives the same stroboscopic points and impact counts.
    let check_values: Vec<f64> = up
        .points
        .iter()
        .filter(|pt| pt.regime.period() == Some(1) && pt.impacts > 0)
        .map(|pt| pt.param)
        .step_by(4)
        .take(6)
        .collect();
    let check = SweepConfig::new(check_values.clone())?
        .direction(SweepDirection::Up)
        .continuation(false)
        .transients(300, 0)
        .record(20)?;
    // Tight tolerances, so that the comparison measures the assembly, not the integration
    // error (a wrong sign or factor in the assembly moves the points by ≳ 1e-3).
    let tight = Tolerances::per_component(1e-12, [1e-14; 4])?;
    let assembled = sweep(&check, make, || Dopri5::new(tight), SVector::zeros())?;
    let hand = sweep(
        &check,
        |w: f64| -> nonsmooth::Result<SweepSystem<_, _>> {
            Ok(SweepSystem {
                system: TwoDofImpactByHand {
                    params: p,
                    omega: w,
                },
                period: TwoDofImpact::period(w),
                stop: Some(p.stop::<f64>()?),
            })
        },
        || Dopri5::new(tight),
        SVector::zeros(),
    )?;
    let mut worst: f64 = 0.0;
    let mut ok = !check_values.is_empty();
    for (a, b) in assembled.branches[0]
        .points
        .iter()
        .zip(&hand.branches[0].points)
    {
        let d = a
            .poincare
            .iter()
            .zip(&b.poincare)
            .map(|(x, y)| (x - y).amax())
            .fold(0.0, f64::max);
        worst = worst.max(d);
        if a.impacts != b.impacts || d > 1e-8 {
            ok = false;
            println!(
                "  MISMATCH at ω = {}: impacts {} vs {}, max |Δy| = {d:.2e}",
                a.param, a.impacts, b.impacts
            );
        }
    }
    println!(
        "check against the hand-written right-hand side at {} values of ω: max |Δy| = {worst:.2e} ({})",
        check_values.len(),
        if ok { "ok" } else { "FAILED" }
    );

    write(&out, &result)?;
    println!("wrote {}", out.display());
    if !ok {
        std::process::exit(1);
    }
    Ok(())
}

fn write(out: &std::path::Path, result: &SweepResult<4>) -> nonsmooth::Result<()> {
    let columns = SweepColumns::new("omega", ["q1", "q2", "v1", "v2"]);
    write_sweep_poincare_path(out.join("two_dof_poincare.csv"), result, &columns)?;
    write_sweep_intervals_path(out.join("two_dof_intervals.csv"), result, &columns)?;
    write_sweep_summary_path(out.join("two_dof_summary.csv"), result, &columns)?;
    #[cfg(feature = "plot")]
    {
        use nonsmooth::output::plot::{Layout, Quantity, bifurcation_panel, render};
        let panels = [
            bifurcation_panel(
                result,
                Quantity::Poincare {
                    component: 1,
                    factor: 1.0,
                },
            )?
            .x_label("ω")
            .y_label("q₂(2πi/ω)"),
            bifurcation_panel(result, Quantity::ImpactVelocities { factor: 1.0 })?
                .x_label("ω")
                .y_label("impact velocity of m₂"),
        ];
        render(
            out.join("two_dof.png"),
            &panels,
            &Layout::grid(1, 900, 900).title("2-DOF impact oscillator: up (red), down (green)"),
        )?;
    }
    Ok(())
}
