//! The paper's model with the scalar right-hand side `(f(t) − ΣF(x, ẋ))/m` written out, as
//! the oscillator had it before it became a layer over the one-DOF `Mechanical` system:
//! the reference for the layer's cost (same values to the bit).

use nalgebra::SVector;
use nonsmooth::excite::Excitation;
use nonsmooth::{Dynamics, ForceLaw};

/// `ẍ = (f(t) − F(x, ẋ))/m`.
#[derive(Debug, Clone, Copy)]
pub struct ScalarOscillator<L, E> {
    pub laws: L,
    pub excitation: E,
    pub inv_mass: f64,
}

impl<L: ForceLaw<f64>, E: Excitation<f64>> Dynamics<f64, 2> for ScalarOscillator<L, E> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
        dy[0] = y[1];
        dy[1] = (self.excitation.force(t) - self.laws.force(y[0], y[1])) * self.inv_mass;
    }
}

/// The paper's model at `omega` in the scalar form.
pub fn paper(
    omega: f64,
) -> ScalarOscillator<
    nonsmooth::systems::paper::PaperLaws<f64>,
    nonsmooth::excite::UnbalancedRotor<f64>,
> {
    use nonsmooth::systems::paper::PAPER;
    let osc = PAPER.oscillator::<f64>(omega).unwrap();
    ScalarOscillator {
        laws: *osc.laws(),
        excitation: *osc.excitation(),
        inv_mass: 1.0 / osc.mass(),
    }
}
