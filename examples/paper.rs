//! The main job: reproduce the paper (work in progress — grows as capabilities land).
//!
//! `cargo run --release --example paper [OUT_DIR]`

use nalgebra::Vector2;
use nonsmooth::Dynamics;
use nonsmooth::model::paper::PAPER;

fn main() -> Result<(), nonsmooth::Error> {
    let x0 = PAPER.static_equilibrium()?;
    println!("static equilibrium X0 = {x0:.6e} m (paper: -2.0807e-3 m)");
    let osc = PAPER.oscillator::<f64>(14.0)?;
    let mut dy = Vector2::zeros();
    osc.rhs(0.0, &Vector2::new(x0, 0.0), &mut dy);
    println!("acceleration at rest in equilibrium: {:.3e} m/s^2", dy[1]);
    Ok(())
}
