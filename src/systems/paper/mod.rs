//! The paper's impact oscillator, assembled from the generic parts.
//!
//! A harmonically forced cart (mass `m`) on springs (`k`), with viscous (`c`) and
//! regularized dry friction (`T`, `ε`), hitting a one-sided compliant stop at `x_I` with the
//! generalized Hertz law and nonlinear damping, forced by an unbalanced rotor:
//! $$m\ddot x + kx + c\dot x + T\frac{\dot x}{\sqrt{\dot x^2+\varepsilon^2}} + F_I(x,\dot x)
//!   = m_0 e\,\omega^2\sin\omega t .$$
//! Nothing here is special-cased: [`PaperParameters::oscillator`] is an
//! [`Oscillator`] over the tuple of laws
//! `(LinearSpring, ViscousDamper, DryFriction, HertzContact)` and an [`UnbalancedRotor`].
//!
//! Everything else that exists only for the paper is here too, as configurations of the
//! generic instruments:
//!
//! - the experiment's processing: the smoothing filter ([`low_pass`], `θ =`
//!   [`FILTER_THETA`]) and the impact detector ([`impact_detector`], `x_I −`
//!   [`IMPACT_OFFSET`]) of [`signal`](crate::signal);
//! - the synthetic experiment ([`SyntheticExperiment`] under a [`Forcing`]), a
//!   configuration of [`ModelExperiment`](crate::signal::ModelExperiment);
//! - the identification ([`PaperFit`] over [`PAPER_FIT_PARAMETERS`]), a configuration of
//!   [`ModelFit`](crate::identify::ModelFit);
//! - the Lyapunov settings ([`lyapunov`]: the norm, `d0` and the diagram schedule).
//!
//! # Results
//! The paper's statistical analysis (Sect. 4, Figs. 6–7) histograms the inter-impact
//! intervals on `(0.05, 0.3)` s with bins of `0.001` s, drops empty bins and takes the
//! Tsallis entropy index `q*` that maximizes the redundancy
//! ([`entropy_index`](crate::entropy::entropy_index)): `q* = 0.62` at `ω = 20.465 rad/s`,
//! and `q* < 1`, varying weakly, over the chaotic window `ω ∈ (20.433, 20.515)`, growing
//! abruptly towards 1 at its edges where the attractor becomes almost periodic. The example
//! `examples/paper/` reproduces it.
//!
//! The approximate solutions of its Sect. 5 ([`analysis`](crate::analysis)) at ω = 14 rad/s
//! and the grazing frequencies they predict:
//!
//! ```
//! use nonsmooth::analysis::{AmplitudePhase, LinearizedResponse, TurningPoint};
//! use nonsmooth::systems::paper::PAPER;
//! let osc = PAPER.oscillator::<f64>(14.0)?;
//! let x0 = PAPER.static_equilibrium()?;
//! let lin = LinearizedResponse::new(&osc, x0, PAPER.c)?;
//! let (a1, a2) = lin.coefficients(14.0);
//! assert!((a1 - 4.2606e-6).abs() < 1e-10);   // eq. (4)
//! assert!((a2 + 4.7779e-10).abs() < 1e-14);  // eq. (4)
//! let w = lin.grazing_omega(PAPER.x_i, 10.0, 30.0)?;
//! assert!((w - 15.657).abs() < 1e-3);        // ω = 15.657 rad/s
//! let ap = AmplitudePhase::new(&osc, x0, PAPER.c)?;
//! let s = ap.solve(14.0, TurningPoint::Upper)?;
//! assert!((s.sin_coefficient() - 3.6833e-6).abs() < 1e-10);   // eq. (6)
//! assert!((s.cos_coefficient() + 3.5707e-10).abs() < 1e-14);  // eq. (6)
//! let w = ap.grazing_omega(PAPER.x_i, TurningPoint::Lower, 10.0, 14.0)?;
//! assert!((w - 12.789).abs() < 1e-3);                        // ω = 12.789 rad/s
//! # Ok::<(), nonsmooth::Error>(())
//! ```
//!
//! Builders and single-layer helpers return that layer's error
//! ([`SignalError`], [`IdentifyError`](crate::identify::IdentifyError)); what builds the
//! model and runs it returns the crate's [`Result`].
//!
//! # References
//! The paper's eq. (1) and the parameter set of its Sect. 2 ([`PAPER`]); the processing and
//! identification of its Sect. 2–3.

mod experiment;
mod fit;
pub mod lyapunov;
mod member;

pub use experiment::{Forcing, SyntheticExperiment, SyntheticRecord};
pub use fit::{
    PAPER_FIT_PARAMETERS, PaperFit, PaperFitReport, paper_parameter, set_paper_parameter,
};
pub use member::Member;

use crate::Real;
use crate::error::Result;
use crate::excite::{Excitation, RampedRotor, UnbalancedRotor};
use crate::force::{DryFriction, HertzContact, LinearSpring, ViscousDamper};
use crate::model::{Element, Load, Mechanical, Oscillator};
use crate::scalar::lit;
use crate::signal::{LowPass, SignalError, ThresholdCrossing};
use crate::validate::{ParameterError, finite};

/// The time constant `θ = 1 ms` (s) of the paper's smoothing filter `1/(θs + 1)` (Sect. 3).
pub const FILTER_THETA: f64 = 1.0e-3;

/// How far below the stop the paper puts its impact threshold (m): impacts are upward
/// crossings of `x_I − 0.01 mm` (Sect. 3), i.e. `x_I − IMPACT_OFFSET`.
pub const IMPACT_OFFSET: f64 = 1.0e-5;

/// The paper's smoothing filter: [`LowPass`] with `θ =` [`FILTER_THETA`], starting at the
/// first sample.
///
/// # Errors
/// None for the scalar types of the crate (`θ` is positive and finite in `f32` and `f64`);
/// the [`LowPass::new`] check is kept rather than assumed.
///
/// # Examples
/// ```
/// use nonsmooth::systems::paper::low_pass;
/// assert_eq!(low_pass::<f64>()?.theta(), 1e-3);
/// # Ok::<(), nonsmooth::signal::SignalError>(())
/// ```
pub fn low_pass<T: Real>() -> Result<LowPass<T>, SignalError> {
    LowPass::new(lit(FILTER_THETA))
}

/// The paper's impact detector: rising crossings of `x_I − 0.01 mm` ([`IMPACT_OFFSET`]),
/// `x_i` in metres (no hysteresis, no minimum separation: add them with the
/// [`ThresholdCrossing`] builders).
///
/// # Errors
/// [`SignalError::Parameter`] if `x_i` is not finite.
///
/// # Examples
/// ```
/// use nonsmooth::systems::paper::{PAPER, impact_detector};
/// let detector = impact_detector(PAPER.x_i)?.with_hysteresis(1e-6)?;
/// assert!((detector.level() - (-2.096e-3)).abs() < 1e-15);
/// # Ok::<(), nonsmooth::signal::SignalError>(())
/// ```
pub fn impact_detector<T: Real>(x_i: T) -> Result<ThresholdCrossing<T>, SignalError> {
    ThresholdCrossing::new(finite("x_i", x_i)? - lit(IMPACT_OFFSET))
}

/// The force laws of the paper's model, summed as a tuple.
pub type PaperLaws<T> = (
    LinearSpring<T>,
    ViscousDamper<T>,
    DryFriction<T>,
    HertzContact<T>,
);

/// The paper's oscillator at a fixed forcing frequency.
pub type PaperOscillator<T> = Oscillator<T, PaperLaws<T>, UnbalancedRotor<T>>;

/// The paper's model as a 1-DOF [`Mechanical`] system (the same right-hand side as
/// [`PaperOscillator`], bit for bit; the form to extend with further degrees of freedom).
pub type PaperMechanical<T> =
    Mechanical<T, 1, Element<T, 1, PaperLaws<T>>, Load<T, 1, UnbalancedRotor<T>>>;

/// The paper's oscillator with a linearly ramped forcing frequency (the experiment's sweep).
pub type RampedPaperOscillator<T> = Oscillator<T, PaperLaws<T>, RampedRotor<T>>;

/// The parameters of the paper's model (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PaperParameters {
    /// Total mass of the cart `m` (kg).
    pub m: f64,
    /// Unbalance `m0·e` (kg·m).
    pub m0e: f64,
    /// Spring stiffness `k` (N/m).
    pub k: f64,
    /// Viscous damping `c` (N·s/m).
    pub c: f64,
    /// Dry friction magnitude `T` (N).
    pub t: f64,
    /// Friction regularization `ε` (m/s).
    pub eps: f64,
    /// Contact stiffness `k_I` (N/m^{n1}).
    pub k_i: f64,
    /// Contact damping `b` (m^{−n3}·s^{n3}).
    pub b: f64,
    /// Stiffness exponent `n1`.
    pub n1: f64,
    /// Damping penetration exponent `n2`.
    pub n2: f64,
    /// Damping rate exponent `n3`.
    pub n3: f64,
    /// Stop position `x_I` (m).
    pub x_i: f64,
    /// Numerical, *not* from the paper: the rate regularization `η` (m/s) of the contact
    /// damping term `sgn(ẋ)|ẋ|^{n3}` (see [`HertzContact`]); 0 is the exact law.
    ///
    /// The default `10⁻⁸ m/s` is a hundred times below the friction's `ε`: inside
    /// `|ẋ| < ε` the regularized friction already dominates the dynamics, and the tests
    /// (`tests/integrate_paper.rs`) show that results do not move at the paper's printed
    /// precision when `η` changes by two decades.
    pub eta: f64,
}

crate::serde_check::deserialize_checked! {
    "PaperParameters",
    PaperParameters {
        m: f64, m0e: f64, k: f64, c: f64, t: f64, eps: f64, k_i: f64, b: f64, n1: f64,
        n2: f64, n3: f64, x_i: f64, eta: f64,
    },
    |raw| -> ParameterError {
        // Every law and the mass are checked by assembling the model (ω = 1 is valid).
        raw.oscillator::<f64>(1.0)?;
        raw
    }
}

/// The paper's identified parameter set (Sect. 2), with the obstacle at
/// `x_I = −2.086·10⁻³ m` used throughout its analysis.
pub const PAPER: PaperParameters = PaperParameters {
    m: 8.735,
    m0e: 0.01805,
    k: 1418.9,
    c: 6.6511,
    t: 0.63133,
    eps: 1e-6,
    k_i: 2.3983e8,
    b: 0.8485,
    n1: 1.5,
    n2: 1.5,
    n3: 0.18667,
    x_i: -2.086e-3,
    eta: 1e-8,
};

impl Default for PaperParameters {
    fn default() -> Self {
        PAPER
    }
}

impl PaperParameters {
    /// The force laws `(k·x, c·ẋ, T·ẋ/√(ẋ²+ε²), F_I)`.
    ///
    /// # Errors
    /// [`ParameterError`] if any parameter is invalid.
    pub fn laws<T: Real>(&self) -> Result<PaperLaws<T>, ParameterError> {
        Ok((
            LinearSpring::new(lit(self.k))?,
            ViscousDamper::new(lit(self.c))?,
            DryFriction::sqrt(lit(self.t), lit(self.eps))?,
            HertzContact::new(lit(self.x_i), lit(self.k_i))?
                .with_stiffness_exponent(lit(self.n1))?
                .with_damping(lit(self.b), lit(self.n2), lit(self.n3))?
                .with_rate_regularization(lit(self.eta))?,
        ))
    }

    /// The oscillator forced at `omega` (rad/s).
    ///
    /// # Errors
    /// [`ParameterError`] if any parameter or `omega` is invalid.
    pub fn oscillator<T: Real>(&self, omega: T) -> Result<PaperOscillator<T>, ParameterError> {
        Oscillator::new(
            lit(self.m),
            self.laws()?,
            UnbalancedRotor::new(lit(self.m0e), omega)?,
        )
    }

    /// The stop as a grazing test for [`crate::orbit`] continuation: the orbit's smallest
    /// `x` against `x_I` (where it drops below `x_I` the cart leaves the stop once more per
    /// period and hits it again).
    pub fn grazing(&self) -> crate::orbit::Grazing {
        crate::orbit::Grazing {
            component: 0,
            level: self.x_i,
            extremum: crate::orbit::Extremum::Min,
        }
    }

    /// The same model as a 1-DOF [`Mechanical`] system forced at `omega`.
    ///
    /// # Errors
    /// [`Error::Parameter`](crate::Error::Parameter) if any parameter or `omega` is invalid.
    pub fn mechanical<T: Real>(&self, omega: T) -> Result<PaperMechanical<T>> {
        Ok(Mechanical::with_masses([lit(self.m)])?
            .with_elements(Element::on_dof(0, self.laws()?)?)
            .with_loads(Load::on_dof(
                0,
                UnbalancedRotor::new(lit(self.m0e), omega)?,
            )?))
    }

    /// The oscillator with `ω(t) = omega0 + rate·t` (the experiment's continuous sweep).
    ///
    /// # Errors
    /// [`ParameterError`] if any parameter is invalid.
    pub fn ramped<T: Real>(
        &self,
        omega0: T,
        rate: T,
    ) -> Result<RampedPaperOscillator<T>, ParameterError> {
        Oscillator::new(
            lit(self.m),
            self.laws()?,
            RampedRotor::new(lit(self.m0e), omega0, rate)?,
        )
    }

    /// The static equilibrium `X0`: `k·X0 + k_I·(X0 − x_I)^{n1} = 0` (generic over the
    /// laws' restoring force; the paper prints `X0 = −2.0807·10⁻³ m`).
    ///
    /// # Errors
    /// If the parameters are invalid or no equilibrium lies between the stop and the spring's
    /// rest position.
    pub fn static_equilibrium(&self) -> Result<f64> {
        let osc = self.oscillator::<f64>(1.0)?;
        let (lo, hi) = if self.x_i < 0.0 {
            (self.x_i, 0.0)
        } else {
            (0.0, self.x_i.max(f64::MIN_POSITIVE))
        };
        if self.x_i >= 0.0 {
            // The spring's rest position is free of contact: it is the equilibrium.
            return Ok(0.0);
        }
        Ok(osc.static_equilibrium(lo, hi)?)
    }

    /// The forcing period `2π/ω`.
    pub fn period(omega: f64) -> f64 {
        std::f64::consts::TAU / omega
    }
}

/// The excitation's frequency, for systems built from the paper's parameters.
pub fn omega_of<T: Real, E: Excitation<T>>(e: &E) -> Option<T> {
    e.angular_frequency(T::zero())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn processing_constants() {
        assert_eq!(low_pass::<f64>().unwrap().theta(), 1e-3);
        assert_eq!(low_pass::<f32>().unwrap().theta(), 1e-3_f32);
        let c = impact_detector(-2.0e-3_f64).unwrap();
        assert!((c.level() + 2.01e-3).abs() < 1e-18);
        assert!(impact_detector(f64::NAN).is_err());
    }

    #[test]
    fn static_equilibrium_golden() {
        // Paper, Sect. 5: X0 = −2.0807·10⁻³ m.
        let x0 = PAPER.static_equilibrium().unwrap();
        assert!((x0 - (-2.0807e-3)).abs() < 0.5e-7, "X0 = {x0:e}");
        let osc = PAPER.oscillator::<f64>(14.0).unwrap();
        assert!(osc.restoring_force(x0).abs() < 1e-12);
    }

    #[test]
    fn f32_model_builds_and_agrees() {
        let o32 = PAPER.oscillator::<f32>(14.0).unwrap();
        let x0 = PAPER.static_equilibrium().unwrap();
        assert!(o32.restoring_force(x0 as f32).abs() < 1e-3);
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let mut p = PAPER;
        p.m = -1.0;
        assert!(p.oscillator::<f64>(14.0).is_err());
        let mut p = PAPER;
        p.eps = 0.0;
        assert!(p.laws::<f64>().is_err());
        let mut p = PAPER;
        p.n3 = 0.0;
        assert!(p.laws::<f64>().is_err());
        let mut p = PAPER;
        p.k_i = f64::NAN;
        assert!(p.laws::<f64>().is_err());
        assert!(PAPER.oscillator::<f64>(-3.0).is_err());
    }
}
