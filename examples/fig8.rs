//! The paper's Fig. 8: phase portraits (x, ẋ) along the impact-adding sequence, ω = 14,
//! 14.1, 15, 16, 17, 17.5, 18 and 19 rad/s, after transients from rest at the static
//! equilibrium. The stop x = x_I is the red line, the stroboscopic points t = 2πi/ω are red
//! dots and the impacts (upward crossings of x_I) blue dots.
//!
//! `cargo run --release [--features plot] --example fig8 -- [--quick] [--out DIR]`
//!
//! Transients 300 periods (quick: 100), then 10 recorded periods (quick: 4) sampled 2000
//! times per period (quick: 500). Writes one tidy CSV per ω, `fig8_omega_<ω>.csv` with
//! columns `kind, t_s, x_m, v_m_s` (`kind` = `orbit`, `section` or `impact`), and, with
//! `--features plot`, `fig8.png` / `fig8.svg` with eight panels.

mod common;

use common::{Orbit, orbit, regime, secs};
use indicatif::{ProgressBar, ProgressStyle};
use nonsmooth::output::csv::{Cell, write_table_path};
use nonsmooth::systems::paper::PAPER;

const OMEGAS: [f64; 8] = [14.0, 14.1, 15.0, 16.0, 17.0, 17.5, 18.0, 19.0];

fn write_csv(dir: &std::path::Path, o: &Orbit) -> nonsmooth::Result<std::path::PathBuf> {
    let path = dir.join(format!("fig8_omega_{:.3}.csv", o.omega));
    let rows = o
        .curve
        .iter()
        .map(|p| ("orbit", p.t, p.y[0], p.y[1]))
        .chain(o.strobe.iter().map(|p| ("section", p.t, p.y[0], p.y[1])))
        .chain(
            o.impacts
                .iter()
                .map(|i| ("impact", i.t, PAPER.x_i, i.velocity)),
        )
        .map(|(k, t, x, v)| [Cell::Text(k), Cell::from(t), Cell::from(x), Cell::from(v)]);
    write_table_path(&path, &["kind", "t_s", "x_m", "v_m_s"], rows)?;
    Ok(path)
}

fn main() -> nonsmooth::Result<()> {
    let a = common::args("fig8");
    let (transient, record, samples) = if a.quick {
        (100, 4, 500)
    } else {
        (300, 10, 2000)
    };
    println!(
        "fig8: phase portraits from rest, {transient} transient + {record} recorded periods, {samples} samples per period{}",
        if a.quick { " (quick)" } else { "" }
    );
    let pb = ProgressBar::new(OMEGAS.len() as u64);
    pb.set_style(
        ProgressStyle::with_template("[{elapsed_precise}] {bar:40.cyan/blue} {pos}/{len} {msg}")
            .expect("valid template"),
    );
    let mut orbits = Vec::new();
    for w in OMEGAS {
        pb.set_message(format!("ω = {w}"));
        orbits.push(orbit(w, transient, record, samples)?);
        pb.inc(1);
    }
    pb.finish_and_clear();
    for o in &orbits {
        let path = write_csv(&a.out, o)?;
        let max_pen = o
            .impacts
            .iter()
            .filter_map(|i| i.max_penetration)
            .fold(0.0, f64::max);
        let x_max = o.curve.iter().map(|p| p.y[0]).fold(f64::MIN, f64::max);
        println!(
            "ω = {:>5.2}: {:>5.2} impacts/T, {:>3}, max x − x_I = {:+7.2} µm, max penetration per impact {:5.2} µm, {:.2} s  → {}",
            o.omega,
            o.impacts_per_period(),
            regime(o.regime),
            (x_max - PAPER.x_i) * 1e6,
            max_pen * 1e6,
            secs(o.time),
            path.display()
        );
    }
    #[cfg(feature = "plot")]
    {
        use nonsmooth::output::plot::{Layout, phase_portrait_panel, render};
        let panels: Vec<_> = orbits
            .iter()
            .map(|o| {
                phase_portrait_panel(&o.curve, &o.strobe, &o.impacts, Some(PAPER.x_i))
                    .title(format!("ω = {} rad/s", o.omega))
            })
            .collect();
        for ext in ["png", "svg"] {
            let path = a.out.join(format!("fig8.{ext}"));
            render(
                &path,
                &panels,
                &Layout::grid(4, 600, 480).title(
                    "Fig. 8: phase portraits from rest (stop red line, t = 2πi/ω red dots, impacts blue dots)",
                ),
            )?;
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}
