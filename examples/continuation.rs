//! Periodic orbits followed in a parameter, their bifurcations located — and checked
//! against independent calculations:
//! - the hardening Duffing oscillator `ẍ + 0.1ẋ + x + x³ = 0.5 cos ωt`: the frequency
//!   response through its two folds (unstable middle branch), against one-harmonic balance
//!   and against brute-force sweeps up and down (their jumps);
//! - the double-well Duffing oscillator `ẍ + 0.3ẋ − x + x³ = γ cos 1.2t`: the
//!   period-doubling cascade to period 8 by branch switching, and Feigenbaum's ratio;
//! - the paper's cart: the first grazing of its period-1 orbit, against the steady-state
//!   simulation estimate (`analysis::first_grazing`); and every impact adding along it
//!   (a local minimum of x reaching the stop), each checked by simulation on both sides.
//!
//! `cargo run --release [--features plot] --example continuation -- [--quick] [--out DIR]`
//!
//! Writes `duffing_branch.csv`, `duffing_bifurcations.csv`, `duffing_sweep.csv`,
//! `cascade.csv`, `paper_branch.csv`, `paper_impact_adding.csv` (and `continuation.png` with
//! `plot`) into
//! `out/continuation`. Exits non-zero if a check fails.

mod common;

use std::f64::consts::TAU;
use std::time::Instant;

use nalgebra::SVector;
use nonsmooth::analysis::first_grazing;
use nonsmooth::drive::Simulation;
use nonsmooth::excite::Harmonic;
use nonsmooth::force::{CubicSpring, ViscousDamper};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::tangent_tolerances;
use nonsmooth::model::{Element, Load, Mechanical};
use nonsmooth::orbit::{
    BifurcationKind, Branch, ContinuationSettings, Shooting, follow, period_doubled,
};
use nonsmooth::output::csv::{
    Cell, SweepColumns, write_bifurcations, write_branch, write_table_path,
};
use nonsmooth::sample::Stroboscopic;
use nonsmooth::systems::paper::PAPER;

type Duffing = Mechanical<
    f64,
    1,
    Element<f64, 1, (CubicSpring<f64>, ViscousDamper<f64>)>,
    Load<f64, 1, Harmonic<f64>>,
>;

/// `ẍ + cẋ + k₁x + x³ = F cos ωt`.
fn duffing(k1: f64, c: f64, force: f64, omega: f64) -> nonsmooth::Result<Duffing> {
    Ok(Mechanical::with_masses([1.0])?
        .with_elements(Element::on_dof(
            0,
            (CubicSpring::new(k1, 1.0)?, ViscousDamper::new(c)?),
        )?)
        .with_loads(Load::on_dof(0, Harmonic::cosine(force, omega)?)?))
}

/// The folds of the one-harmonic balance of the hardening oscillator (`k₁ = 1`): where the
/// cubic `(9/16)u³ + (3/2)a u² + (a² + c²ω²)u − F² = 0` in `u = A²`, `a = 1 − ω²`, gains or
/// loses two real roots.
fn harmonic_balance_folds(c: f64, force: f64, lo: f64, hi: f64) -> Vec<f64> {
    let disc = |w: f64| {
        let a = 1.0 - w * w;
        let (p, q, r, s) = (0.5625, 1.5 * a, a * a + (c * w).powi(2), -force * force);
        18.0 * p * q * r * s - 4.0 * q.powi(3) * s + q * q * r * r
            - 4.0 * p * r.powi(3)
            - 27.0 * p * p * s * s
    };
    let mut folds = Vec::new();
    let mut w = lo;
    while w < hi {
        let (mut a, mut b) = (w, w + 1e-3);
        if disc(a).signum() != disc(b).signum() {
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if disc(a).signum() == disc(m).signum() {
                    a = m;
                } else {
                    b = m;
                }
            }
            folds.push(0.5 * (a + b));
        }
        w += 1e-3;
    }
    folds
}

/// The amplitude `√(x² + (ẋ/ω)²)` at the section after each ω of a sweep, each value
/// started from the previous end state.
fn sweep(omegas: &[f64], tol: Tolerances<f64, 2>) -> nonsmooth::Result<Vec<f64>> {
    let mut y = SVector::<f64, 2>::zeros();
    let mut amplitude = Vec::new();
    for &w in omegas {
        let mut sim = Simulation::new(duffing(1.0, 0.1, 0.5, w)?, Dopri5::new(tol));
        let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, TAU / w, 0.0, 1000)?;
        y = sim.run(0.0, y, 150.0 * TAU / w, &mut strobe)?.y;
        amplitude.push(y[0].hypot(y[1] / w));
    }
    Ok(amplitude)
}

fn check(ok: &mut bool, pass: bool, what: &str) {
    println!("  {what}: {}", if pass { "ok" } else { "FAILED" });
    *ok &= pass;
}

fn main() -> nonsmooth::Result<()> {
    let args = common::args("continuation");
    let out = args.out;
    std::fs::create_dir_all(&out).map_err(|e| nonsmooth::Error::Output(e.to_string()))?;
    let mut ok = true;
    let tol = Tolerances::new(1e-10, 1e-12)?;
    let tangent = tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12)?;
    let columns = SweepColumns::new("omega_rad_s", ["x_m", "v_m_s"]);

    // 1. Hardening Duffing: frequency response through two folds.
    let start = Instant::now();
    let build = |w: f64| Ok(Shooting::new(duffing(1.0, 0.1, 0.5, w)?, (), tangent));
    let settings = ContinuationSettings::new(1.0, 2.5, 0.02)?;
    let duffing_branch = follow(build, |w| TAU / w, 0.0, 1.0, SVector::zeros(), &settings)?;
    write_branch(file(&out, "duffing_branch.csv")?, &duffing_branch, &columns)?;
    write_bifurcations(
        file(&out, "duffing_bifurcations.csv")?,
        &duffing_branch,
        &columns,
    )?;
    let folds: Vec<f64> = kinds(&duffing_branch, BifurcationKind::Fold);
    let hb = harmonic_balance_folds(0.1, 0.5, 1.0, 2.5);
    let step: f64 = if args.quick { 0.02 } else { 0.005 };
    let up: Vec<f64> = (0..=(1.5 / step).round() as usize)
        .map(|i| 1.0 + step * i as f64)
        .collect();
    let down: Vec<f64> = up.iter().rev().copied().collect();
    let (a_up, a_down) = (sweep(&up, tol)?, sweep(&down, tol)?);
    let jump = |ws: &[f64], a: &[f64], sign: f64| {
        let i = (1..ws.len())
            .max_by(|&i, &j| (sign * (a[i - 1] - a[i])).total_cmp(&(sign * (a[j - 1] - a[j]))))
            .unwrap_or(1);
        (ws[i - 1], ws[i])
    };
    let (jump_up, jump_down) = (jump(&up, &a_up, 1.0), jump(&down, &a_down, -1.0));
    write_table_path(
        out.join("duffing_sweep.csv"),
        &["omega_rad_s", "direction", "amplitude_m"],
        up.iter()
            .zip(&a_up)
            .map(|(&w, &a)| [Cell::from(w), Cell::from("up"), Cell::from(a)])
            .chain(
                down.iter()
                    .zip(&a_down)
                    .map(|(&w, &a)| [Cell::from(w), Cell::from("down"), Cell::from(a)]),
            ),
    )?;
    println!(
        "Duffing: {} points, folds at ω = {folds:?} ({:.2} s); harmonic balance {hb:?}; sweeps \
         jump in {jump_up:?} (up), {jump_down:?} (down)",
        duffing_branch.points.len(),
        start.elapsed().as_secs_f64()
    );
    let two = folds.len() == 2 && hb.len() == 2;
    check(
        &mut ok,
        two,
        "two folds on the branch, two in harmonic balance",
    );
    if two {
        let (upper, lower) = (folds[0], folds[1]);
        check(
            &mut ok,
            (upper - hb[1]).abs() < 0.02 * hb[1] && (lower - hb[0]).abs() < 0.02 * hb[0],
            "folds within 2 % of harmonic balance",
        );
        check(
            &mut ok,
            jump_up.0 <= upper + 1e-9
                && upper <= jump_up.1 + 1e-9
                && jump_down.1 <= lower + 1e-9
                && lower <= jump_down.0 + 1e-9,
            "sweeps jump at the folds",
        );
    }

    // 2. Double-well Duffing: the period-doubling cascade by branch switching.
    let start = Instant::now();
    let build = |g: f64| Ok(Shooting::new(duffing(-1.0, 0.3, g, 1.2)?, (), tangent));
    let t = TAU / 1.2;
    let (mut p, mut y, mut k, mut hi) = (0.2, SVector::from([1.0, 0.0]), 1.0, 0.4);
    let mut doublings = Vec::new();
    for _ in 0..4 {
        let period = move |_g: f64| k * t;
        let settings = ContinuationSettings::new(0.1, hi, 0.01)?.with_max_points(400)?;
        let branch = follow(build, period, 0.0, p, y, &settings)?;
        let Some(pd) = branch
            .bifurcations
            .iter()
            .find(|b| b.kind == BifurcationKind::PeriodDoubling)
        else {
            break;
        };
        doublings.push(pd.p);
        let (p2, orbit) = period_doubled(build, period, 0.0, pd, 1e-5, 1.0)?;
        if let [.., a, b] = doublings[..] {
            hi = b + 0.5 * (b - a);
        }
        (p, y, k) = (p2, orbit.state, 2.0 * k);
    }
    write_table_path(
        out.join("cascade.csv"),
        &["period", "gamma"],
        doublings
            .iter()
            .enumerate()
            .map(|(i, &g)| [Cell::from(f64::powi(2.0, i as i32)), Cell::from(g)]),
    )?;
    let ratios: Vec<f64> = doublings
        .windows(3)
        .map(|w| (w[1] - w[0]) / (w[2] - w[1]))
        .collect();
    println!(
        "double well: period doublings at γ = {doublings:?}, ratios {ratios:?} (Feigenbaum \
         4.6692; {:.2} s)",
        start.elapsed().as_secs_f64()
    );
    check(
        &mut ok,
        ratios.len() == 2 && (ratios[1] - 4.6692).abs() < 0.05,
        "second ratio within 0.05 of Feigenbaum's δ",
    );

    // 3. The paper's cart: the first grazing of the period-1 orbit.
    let start = Instant::now();
    let ptol = Tolerances::per_component(1e-10, [1e-14, 1e-12])?;
    let ptangent = tangent_tolerances::<f64, 2, 2, 6>(&ptol, 1e-10, 1e-12)?;
    let build = |w: f64| Ok(Shooting::new(PAPER.oscillator::<f64>(w)?, (), ptangent));
    let settings = ContinuationSettings::new(13.0, 14.3, 0.005)?
        .with_max_step(0.2)?
        .with_grazing(PAPER.grazing());
    let rest = SVector::from([PAPER.static_equilibrium()?, 0.0]);
    let branch = follow(build, |w| TAU / w, 0.0, 13.0, rest, &settings)?;
    write_branch(file(&out, "paper_branch.csv")?, &branch, &columns)?;
    let grazing = kinds(&branch, BifurcationKind::Grazing);
    let by_simulation = first_grazing(
        |w: f64| Ok((PAPER.oscillator::<f64>(w)?, TAU / w, rest)),
        || Dopri5::new(ptol),
        0,
        PAPER.x_i,
        14.0,
        14.1,
        1e-9,
        100,
        2,
    )?;
    println!(
        "paper: first grazing by continuation {grazing:?}, by simulation {by_simulation:.10} \
         ({:.2} s)",
        start.elapsed().as_secs_f64()
    );
    check(
        &mut ok,
        grazing.len() == 1 && (grazing[0] - by_simulation).abs() < 1e-6,
        "grazing by continuation within 1e-6 rad/s of the simulation estimate",
    );

    // 4. The paper's cart: impact adding along the period-1 orbit. Each local minimum of x
    //    that reaches x_I adds a contact per period; located by following that minimum.
    let start = Instant::now();
    let hi = if args.quick { 15.0 } else { 17.6 };
    let g = PAPER.grazing();
    let settings = ContinuationSettings::new(13.5, hi, 0.005)?
        .with_max_step(0.2)?
        .with_contact_changes(g);
    let adding = follow(build, |w| TAU / w, 0.0, 13.5, rest, &settings)?;
    let added = kinds(&adding, BifurcationKind::Grazing);
    write_bifurcations(file(&out, "paper_impact_adding.csv")?, &adding, &columns)?;
    println!(
        "paper: contacts added at ω = {added:?} ({} points, {:.2} s)",
        adding.points.len(),
        start.elapsed().as_secs_f64()
    );
    // Independent check: steady impacts per period by simulation just below and above each
    // located point differ by one.
    let impacts_per_period = |w: f64| -> nonsmooth::Result<f64> {
        use nonsmooth::event::{Direction, Event, Level};
        use nonsmooth::sample::ImpactSequence;
        let period = TAU / w;
        let ev = Event::new(Level::new(0, PAPER.x_i)?, Direction::Rising);
        let mut sim =
            Simulation::new(PAPER.oscillator::<f64>(w)?, Dopri5::new(ptol)).with_events(ev);
        let mut imp = ImpactSequence::new(0, 0, 1, PAPER.x_i, 100.0 * period, 10_000)?;
        sim.run(0.0, rest, 120.0 * period, &mut imp)?;
        Ok(imp.count() as f64 / 20.0)
    };
    let mut adding_ok = added.len() == if args.quick { 2 } else { 5 };
    for &w in &added {
        let (below, above) = (impacts_per_period(w - 2e-3)?, impacts_per_period(w + 2e-3)?);
        println!("    ω = {w:.9}: {below} impacts per period at −0.002, {above} at +0.002");
        adding_ok &= above == below + 1.0;
    }
    check(
        &mut ok,
        adding_ok,
        "each located contact adds one impact per period in simulation",
    );

    #[cfg(feature = "plot")]
    {
        use nonsmooth::output::plot::{Layout, Panel, Rgb, Series, branch_series, render};
        // The branch's section state x(0) (stable solid, saddle dashed, folds as dots) and,
        // on its own panel, the sweeps' amplitudes with their jumps at the folds.
        let mut duffing_panel = Panel::new("ω (rad/s)", "x at the section (m)")
            .title("Duffing: frequency response through two folds");
        for s in branch_series(&duffing_branch, 0, Rgb::BLUE) {
            duffing_panel = duffing_panel.with(s);
        }
        let mut sweep_panel =
            Panel::new("ω (rad/s)", "amplitude (m)").title("sweeps up (red) and down (blue)");
        sweep_panel = sweep_panel
            .with(Series::dots(up.iter().copied().zip(a_up.iter().copied())).color(Rgb::RED))
            .with(Series::dots(down.iter().copied().zip(a_down.iter().copied())).color(Rgb::BLUE));
        let mut paper_panel = Panel::new("ω (rad/s)", "x at the section (m)")
            .title("the paper's cart: period 1 up to its first grazing");
        for s in branch_series(&branch, 0, Rgb::BLACK) {
            paper_panel = paper_panel.with(s);
        }
        render(
            out.join("continuation.png"),
            &[duffing_panel, sweep_panel, paper_panel],
            &Layout::grid(3, 1800, 600).title("periodic orbits: stable solid, unstable dashed"),
        )?;
    }

    if !ok {
        eprintln!("a check FAILED");
        std::process::exit(1);
    }
    println!("all checks ok; wrote {}", out.display());
    Ok(())
}

/// The parameters of the bifurcations of one kind.
fn kinds<const N: usize>(branch: &Branch<N>, kind: BifurcationKind) -> Vec<f64> {
    branch
        .bifurcations
        .iter()
        .filter(|b| b.kind == kind)
        .map(|b| b.p)
        .collect()
}

fn file(dir: &std::path::Path, name: &str) -> nonsmooth::Result<std::fs::File> {
    std::fs::File::create(dir.join(name))
        .map_err(|e| nonsmooth::Error::Output(format!("{name}: {e}")))
}
