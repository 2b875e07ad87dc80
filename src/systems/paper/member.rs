//! The paper's oscillator family as an ensemble member.

use nalgebra::{SMatrix, SVector};

use super::{PaperOscillator, PaperParameters};
use crate::drive::RunError;
use crate::ensemble::MemberRun;
use crate::lanes::{LaneMath, Lanes};
use crate::sweep::LaneStart;
use crate::validate::ParameterError;
use crate::{Dynamics, LaneDynamics};

/// One member of an ensemble: the paper's oscillator (any [`PaperParameters`], not only
/// the paper's set) forced at `ω`, with its scalar model kept beside it.
///
/// # Model
/// $$m\ddot x + kx + c\dot x + T\frac{\dot x}{\sqrt{\dot x^2+\varepsilon^2}} + F_I(x,\dot x)
///   = m_0 e\,\omega^2\sin\omega t,$$
/// with the generalized Hertz law `F_I` of [`HertzContact`](crate::force::HertzContact)
/// (exponents `n1`, `n2`, damping `b·δ^{n2}·ẋ(ẋ²+η²)^{(n3−1)/2}`, or the exact
/// `sgn(ẋ)|ẋ|^{n3}` for `η = 0`). The lane form evaluates the same terms in the same
/// order as the scalar [`PaperOscillator`] — it *is* that oscillator's lane form
/// ([`Oscillator`](crate::model::Oscillator)'s, from the lane forms of its laws and its
/// rotor); with [`LaneMath::Exact`] each lane's value is the scalar one to the bit.
///
/// A linear forced oscillator is the member with `T = 0` and a stop out of reach
/// (`x_I` far above the motion): the smooth reference problem of the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Member {
    params: PaperParameters,
    omega: f64,
    scalar: PaperOscillator<f64>,
}

impl Member {
    /// The oscillator with `params` forced at `omega` (rad/s).
    ///
    /// # Errors
    /// [`ParameterError`] for any invalid parameter (the checks of
    /// [`PaperParameters::oscillator`]).
    pub fn new(params: PaperParameters, omega: f64) -> Result<Self, ParameterError> {
        let scalar = params.oscillator::<f64>(omega)?;
        Ok(Self {
            params,
            omega,
            scalar,
        })
    }

    /// The paper's parameter set forced at `omega`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `omega` is finite and > 0 (with `m0e·ω³` finite).
    pub fn paper(omega: f64) -> Result<Self, ParameterError> {
        Self::new(super::PAPER, omega)
    }

    /// The parameters.
    pub fn params(&self) -> &PaperParameters {
        &self.params
    }

    /// The forcing frequency `ω`.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The forcing period `2π/ω`.
    pub fn period(&self) -> f64 {
        core::f64::consts::TAU / self.omega
    }

    /// This member from `y0` at `t = 0` as a start of a lane sweep
    /// ([`sweep_independent`](crate::sweep::sweep_independent)): the record's parameter is
    /// `ω`, the sections are at `t = i·2π/ω`.
    pub fn start(&self, y0: SVector<f64, 2>) -> LaneStart<Self, 2> {
        LaneStart {
            param: self.omega,
            system: *self,
            period: self.period(),
            y0,
        }
    }

    /// The same model on the scalar path.
    pub fn scalar(&self) -> &PaperOscillator<f64> {
        &self.scalar
    }
}

impl Dynamics<f64, 2> for Member {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
        self.scalar.rhs(t, y, dy)
    }
    fn jacobian(&self, t: f64, y: &SVector<f64, 2>) -> Option<SMatrix<f64, 2, 2>> {
        self.scalar.jacobian(t, y)
    }
    fn time_derivative(&self, t: f64, y: &SVector<f64, 2>) -> Option<SVector<f64, 2>> {
        self.scalar.time_derivative(t, y)
    }
    fn velocity_exponent(&self) -> Option<f64> {
        self.scalar.velocity_exponent()
    }
    fn contact_onset(&self) -> Option<crate::force::ContactOnset<f64>> {
        self.scalar.contact_onset()
    }
}

/// The lane form of the paper's oscillator.
impl LaneDynamics<2> for Member {
    type Packed<V: Lanes> = <PaperOscillator<f64> as LaneDynamics<2>>::Packed<V>;
    type Time<V: Lanes> = <PaperOscillator<f64> as LaneDynamics<2>>::Time<V>;

    fn pack<V: Lanes>(&self) -> Self::Packed<V> {
        self.scalar.pack()
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
        self.scalar.pack_lane(packed, lane)
    }
    /// No time scale is declared (the driver's default `None`).
    fn constant_time_scale(&self) -> bool {
        true
    }
    fn same_structure(&self, other: &Self) -> bool {
        self.scalar.same_structure(&other.scalar)
    }
    #[inline(always)]
    fn time_lanes<V: Lanes>(packed: &Self::Packed<V>, math: LaneMath, t: V) -> Self::Time<V> {
        PaperOscillator::<f64>::time_lanes(packed, math, t)
    }
    #[inline(always)]
    fn rhs_lanes<V: Lanes>(
        packed: &Self::Packed<V>,
        math: LaneMath,
        t: V,
        time: &Self::Time<V>,
        y: &[V; 2],
        dy: &mut [V; 2],
    ) {
        PaperOscillator::<f64>::rhs_lanes(packed, math, t, time, y, dy)
    }
}

impl MemberRun<Member, 2> {
    /// `periods` forcing periods `2π/ω` of the paper's member from `(0, y0)`, every step
    /// landing on `t = i·2π/ω` (the sweeps' setting).
    ///
    /// # Errors
    /// As [`MemberRun::new`]; [`ParameterError`] unless `periods` is finite and > 0.
    pub fn periods(member: Member, y0: SVector<f64, 2>, periods: f64) -> Result<Self, RunError> {
        let tau = member.period();
        Self::periods_of(member, y0, tau, periods)
    }
}
