//! The paper's Fig. 4: bifurcation diagrams for ω ∈ [17.5, 20.5] rad/s, increasing (red)
//! and decreasing (green) with continuation — stroboscopic points x(2πi/ω) and inter-impact
//! intervals T_j — with the transitions and the hysteresis intervals.
//!
//! `cargo run --release [--features plot] --example fig4 -- [--quick] [--out DIR]`
//!
//! Step 0.005 rad/s (quick: 0.02), transients 100 periods at the first value and 50 after
//! each step, 50 recorded periods. Writes `fig4_{poincare,intervals,summary}.csv` (and
//! `fig4.png`, `fig4.svg`) into `out/fig4`. The regimes and impacts per period in the summary
//! and the printout are re-read by `common::normalize` (period detection at the diagram's
//! scale, impacts counted per orbit period).

mod common;

fn main() -> nonsmooth::Result<()> {
    common::updown_figure(
        "fig4",
        (17.5, 20.5),
        (0.005, 0.02),
        "Fig. 4: ω ∈ [17.5, 20.5] rad/s, increasing (red) and decreasing (green)",
        common::PaperReport {
            transitions: "self-similar windows (17.6931; 17.8200), (17.9024; 18.2418), (18.3233; 19.2300) (lengths 0.1269, 0.3394, 0.9067; ratios 2.6745, 2.6714); period doubling in (20, 20.5)",
            hysteresis: "hysteresis near ω = 17.9, 18.5 and 19.7 rad/s",
        },
    )?;
    Ok(())
}
