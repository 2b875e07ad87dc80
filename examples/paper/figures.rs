//! PNG figures (feature `plot`); without the feature every function is a no-op and the
//! CSVs alone are written.

#![allow(unused_variables)]

use std::path::Path;

use nonsmooth::sweep::SweepResult;

use crate::reproduce::{Entropy, Steady};

/// Whether figures are drawn.
pub const ENABLED: bool = cfg!(feature = "plot");

#[cfg(feature = "plot")]
use nonsmooth::output::plot::{Layout, Panel, Quantity, Rgb, Series, bifurcation_panel, render};

type Res = Result<(), nonsmooth::Error>;

/// Figs. 3 and 4: Poincaré x and T_j against ω, up (red) and down (green).
pub fn bifurcation(dir: &Path, fig: &str, r: &SweepResult<2>) -> Res {
    #[cfg(feature = "plot")]
    {
        let a = bifurcation_panel(r, Quantity::POSITION_MM)?
            .x_label("ω [rad/s]")
            .title("(a)");
        let b = bifurcation_panel(r, Quantity::Intervals)?
            .x_label("ω [rad/s]")
            .title("(b)");
        render(
            dir.join(format!("{fig}.png")),
            &[a, b],
            &Layout::grid(1, 1100, 900),
        )?;
    }
    Ok(())
}

/// Fig. 5: the TLE against ω for both directions.
pub fn tle(dir: &Path, up: &[(f64, f64)], down: &[(f64, f64)]) -> Res {
    #[cfg(feature = "plot")]
    {
        let p = Panel::new("ω [rad/s]", "λ₁ [1/s]")
            .with(
                Series::line(up.iter().copied())
                    .color(Rgb::RED)
                    .label("increasing"),
            )
            .with(
                Series::line(down.iter().copied())
                    .color(Rgb::GREEN)
                    .label("decreasing"),
            )
            .hline(0.0, Rgb::BLACK);
        render(dir.join("fig5.png"), &[p], &Layout::grid(1, 1100, 500))?;
    }
    Ok(())
}

/// Fig. 6: the histogram of T_j and the redundancy R(q).
pub fn entropy(dir: &Path, e: &Entropy) -> Res {
    #[cfg(feature = "plot")]
    {
        let bars: Vec<(f64, f64)> = e
            .estimate
            .bins
            .iter()
            .map(|b| (b.centre, b.probability))
            .collect();
        let a = Panel::new("Tⱼ [s]", "p")
            .title("(a)")
            .with(Series::bars(bars, 0.001).color(Rgb::BLUE));
        let mut b = Panel::new("q", "R(q)")
            .title("(b)")
            .with(Series::line(e.curve.iter().copied()).color(Rgb::BLACK));
        if let Some(i) = e.index {
            b = b.vline(i.q, Rgb::RED);
        }
        render(dir.join("fig6.png"), &[a, b], &Layout::grid(2, 1200, 450))?;
    }
    Ok(())
}

/// Fig. 7: q against ω.
pub fn q_omega(dir: &Path, pts: &[(f64, f64)]) -> Res {
    #[cfg(feature = "plot")]
    {
        let p = Panel::new("ω [rad/s]", "q")
            .with(Series::line(pts.iter().copied()).color(Rgb::BLACK))
            .with(Series::dots(pts.iter().copied()).color(Rgb::RED))
            .hline(1.0, Rgb::GREEN);
        render(dir.join("fig7.png"), &[p], &Layout::grid(1, 900, 500))?;
    }
    Ok(())
}

/// Fig. 9: the solution at ω = 14 against the fit (3), eq. (4) and eq. (6); its spectrum.
pub fn solution(dir: &Path, st: &Steady, eq4: &[f64], eq6: &[f64]) -> Res {
    #[cfg(feature = "plot")]
    {
        let n = st.t.len() / 4; // one period
        let mm = |v: f64| v * 1e3;
        let f = st.fit;
        let w = st.omega;
        let fit = |t: f64| {
            f[0] + f[1] * (w * t).cos()
                + f[2] * (w * t).sin()
                + f[3] * (2.0 * w * t).cos()
                + f[4] * (2.0 * w * t).sin()
        };
        let a = Panel::new("t [s]", "x [mm]")
            .title("(a)")
            .with(
                Series::dots((0..n).step_by(8).map(|i| (st.t[i], mm(st.x[i]))))
                    .color(Rgb::BLACK)
                    .label("numerical"),
            )
            .with(
                Series::line((0..n).map(|i| (st.t[i], mm(fit(st.t[i])))))
                    .color(Rgb::GREEN)
                    .label("fit (3)"),
            )
            .with(
                Series::line((0..n).map(|i| (st.t[i], mm(eq4[i]))))
                    .color(Rgb::BLUE)
                    .label("eq. (4)"),
            )
            .with(
                Series::line((0..n).map(|i| (st.t[i], mm(eq6[i]))))
                    .color(Rgb::RED)
                    .label("eq. (6)"),
            );
        let b = Panel::new("frequency [rad/s]", "amplitude [m]")
            .title("(b)")
            .with(
                Series::stems(
                    st.harmonics
                        .iter()
                        .enumerate()
                        .map(|(j, &a)| (w * (j + 1) as f64, a)),
                )
                .color(Rgb::BLACK),
            );
        render(dir.join("fig9.png"), &[a, b], &Layout::grid(2, 1200, 450))?;
    }
    Ok(())
}
