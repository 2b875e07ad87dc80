//! The paper's Fig. 10: time profiles x(t) over a few forcing periods at ω = 15, 16.7 and
//! 18 rad/s, after transients from rest — the micro-oscillations near the stop ("incomplete
//! chattering") between the first grazing and the chaotic mode.
//!
//! `cargo run --release [--features plot] --example fig10 -- [--quick] [--out DIR]`
//!
//! Transients 300 periods (quick: 100), then 4 recorded periods sampled 4000 times per
//! period (quick: 1000). Writes `fig10_omega_<ω>.csv` (`t_s, x_m, v_m_s`) per ω and, with
//! `--features plot`, `fig10.png` / `fig10.svg` (profiles, and the same zoomed to the
//! stop).

mod common;

use common::{Orbit, orbit, regime, secs};
use nonsmooth::output::csv::{STATE_XV, write_section_points_path};
use nonsmooth::systems::paper::PAPER;

const OMEGAS: [f64; 3] = [15.0, 16.7, 18.0];

/// Local maxima of x within `band` (m) below or above the stop, per forcing period.
fn peaks_near_stop(o: &Orbit, band: f64) -> f64 {
    let n = o
        .curve
        .windows(3)
        .filter(|w| w[1].y[0] > w[0].y[0] && w[1].y[0] >= w[2].y[0])
        .filter(|w| w[1].y[0] > PAPER.x_i - band)
        .count();
    n as f64 / o.periods as f64
}

fn main() -> nonsmooth::Result<()> {
    let a = common::args("fig10");
    let (transient, record, samples) = if a.quick {
        (100, 4, 1000)
    } else {
        (300, 4, 4000)
    };
    println!(
        "fig10: time profiles from rest, {transient} transient + {record} recorded periods, {samples} samples per period{}",
        if a.quick { " (quick)" } else { "" }
    );
    let mut orbits = Vec::new();
    for w in OMEGAS {
        let o = orbit(w, transient, record, samples)?;
        let path = a.out.join(format!("fig10_omega_{w:.3}.csv"));
        write_section_points_path(&path, &o.curve, STATE_XV)?;
        let x_min = o.curve.iter().map(|p| p.y[0]).fold(f64::MAX, f64::min);
        let x_max = o.curve.iter().map(|p| p.y[0]).fold(f64::MIN, f64::max);
        println!(
            "ω = {w:>5.2}: {:>5.2} impacts/T, {:>3}, x ∈ [{:.4}, {:.4}] mm, local maxima within 50 µm of the stop: {:.2} per period, {:.2} s → {}",
            o.impacts_per_period(),
            regime(o.regime),
            x_min * 1e3,
            x_max * 1e3,
            peaks_near_stop(&o, 50e-6),
            secs(o.time),
            path.display()
        );
        orbits.push(o);
    }
    #[cfg(feature = "plot")]
    {
        use nonsmooth::output::plot::{Layout, render, time_profile_panel};
        let mut panels = Vec::new();
        for (o, tag) in orbits.iter().zip(["a", "b", "c"]) {
            let p = time_profile_panel(&o.curve, Some(PAPER.x_i))
                .title(format!("({tag}) ω = {} rad/s", o.omega));
            let x_max = o.curve.iter().map(|p| p.y[0]).fold(f64::MIN, f64::max);
            let zoom = p
                .clone()
                .title(format!("({tag}) ω = {} rad/s, near the stop", o.omega))
                .y_range(
                    (PAPER.x_i - 0.6 * (x_max - PAPER.x_i)) * 1e3,
                    (x_max + 0.1 * (x_max - PAPER.x_i)) * 1e3,
                );
            panels.push(p);
            panels.push(zoom);
        }
        for ext in ["png", "svg"] {
            let path = a.out.join(format!("fig10.{ext}"));
            render(
                &path,
                &panels,
                &Layout::grid(2, 800, 420).title("Fig. 10: profiles x(t) (stop: red line)"),
            )?;
            println!("wrote {}", path.display());
        }
    }
    #[cfg(not(feature = "plot"))]
    let _ = orbits;
    Ok(())
}
