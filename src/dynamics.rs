//! The [`Dynamics`] trait: all an integrator knows about a system.

use nalgebra::{SMatrix, SVector};

use crate::Real;
use crate::lanes::{LaneMath, Lanes};

/// A first-order system `ẏ = f(t, y)` of dimension `N`.
///
/// Only [`rhs`](Dynamics::rhs) is required; it is infallible and must not allocate — the
/// steppers check its output for NaN/∞ and report an
/// [`IntegrateError`](crate::integrate::IntegrateError). Provide
/// [`jacobian`](Dynamics::jacobian) (and [`time_derivative`](Dynamics::time_derivative) for
/// non-autonomous systems) to enable the implicit stepper without finite differences and
/// the tangent-space Lyapunov method.
///
/// ```
/// use nalgebra::{SMatrix, SVector};
/// use nonsmooth::Dynamics;
///
/// /// Exponential decay ẏ = −λ·y.
/// struct Decay(f64);
/// impl Dynamics<f64, 1> for Decay {
///     fn rhs(&self, _t: f64, y: &SVector<f64, 1>, dy: &mut SVector<f64, 1>) {
///         dy[0] = -self.0 * y[0];
///     }
///     fn jacobian(&self, _t: f64, _y: &SVector<f64, 1>) -> Option<SMatrix<f64, 1, 1>> {
///         Some(SMatrix::<f64, 1, 1>::new(-self.0))
///     }
/// }
/// let mut dy = SVector::<f64, 1>::zeros();
/// Decay(2.0).rhs(0.0, &SVector::<f64, 1>::new(3.0), &mut dy);
/// assert_eq!(dy[0], -6.0);
/// ```
pub trait Dynamics<T: Real, const N: usize> {
    /// Writes `f(t, y)` into `dy`.
    fn rhs(&self, t: T, y: &SVector<T, N>, dy: &mut SVector<T, N>);

    /// The Jacobian `∂f/∂y`, if known.
    fn jacobian(&self, _t: T, _y: &SVector<T, N>) -> Option<SMatrix<T, N, N>> {
        None
    }

    /// The explicit time derivative `∂f/∂t`, if known (zero for autonomous systems).
    fn time_derivative(&self, _t: T, _y: &SVector<T, N>) -> Option<SVector<T, N>> {
        None
    }

    /// The shortest time over which the system's explicit dependence on `t` can turn
    /// around near `t`, if it must bound the step. The driver takes no step longer than
    /// this. A system whose error estimate sees its forcing need not declare it (the
    /// default, `None`); one whose state can stay constant while its forcing changes — a
    /// constrained mode, a sticking contact — must, or a long step hides a change of mode
    /// (see the event contract in [`event`](crate::event)).
    fn time_scale(&self, _t: T) -> Option<T> {
        None
    }

    /// For a one-degree-of-freedom system with state `(x, ẋ)` and `f = (ẋ, ẍ)`: the
    /// exponent `q ∈ (0, 1)` of a term `∝ sgn(ẋ)|ẋ|^q` in `ẍ`, if it has one (see
    /// [`ForceLaw::velocity_exponent`](crate::ForceLaw::velocity_exponent)). A
    /// [`TurningPoints`](crate::integrate::TurningPoints) stepper crosses `ẋ = 0` in the
    /// variable `u = sgn(ẋ)|ẋ|^q` when it is declared. Default `None`.
    ///
    /// [`Oscillator`](crate::model::Oscillator) and the one-degree-of-freedom
    /// [`Mechanical`](crate::model::Mechanical) system return their laws' smallest; a
    /// `Mechanical` system of several degrees of freedom returns `None` (its state is not
    /// `(x, ẋ)`; see [`Elements`](crate::model::Elements) for its laws' declarations per
    /// coordinate). Declare it only where it holds for the state's second component: the
    /// stepper trusts it.
    fn velocity_exponent(&self) -> Option<T> {
        None
    }

    /// For a system in mechanical form, state `(q, q̇)` of `N = 2n` components with `n ≥ 1`
    /// degrees of freedom: the smallest exponent `q ∈ (0, 1)` of a term `∝ sgn(ġ)|ġ|^q` in
    /// the rate of any coordinate, if there is one. The implicit cusp step
    /// ([`CuspSwitch`](crate::integrate::CuspSwitch)) probes the velocities for the cusp's
    /// stiffness when it is declared, and solves in the power scale it sets. Default:
    /// [`velocity_exponent`](Self::velocity_exponent) (one degree of freedom);
    /// [`Mechanical`](crate::model::Mechanical) declares it for any number of degrees of
    /// freedom.
    fn cusp_exponent(&self) -> Option<T> {
        self.velocity_exponent()
    }

    /// For a one-degree-of-freedom system with state `(x, ẋ)`: where a contact force starts
    /// as a power of the penetration, if it does (see
    /// [`ForceLaw::contact_onset`](crate::ForceLaw::contact_onset)), with the stop and the
    /// penetration in `x`. Default `None`.
    ///
    /// [`Oscillator`](crate::model::Oscillator) and the one-degree-of-freedom
    /// [`Mechanical`](crate::model::Mechanical) system return their laws' first stop (for a
    /// `Mechanical` law on the coordinate `g = w·x + o`, mapped to `x`); a `Mechanical`
    /// system of several degrees of freedom returns `None`.
    fn contact_onset(&self) -> Option<crate::force::ContactOnset<T>> {
        None
    }
}

impl<T: Real, const N: usize, D: Dynamics<T, N> + ?Sized> Dynamics<T, N> for &D {
    #[inline(always)]
    fn rhs(&self, t: T, y: &SVector<T, N>, dy: &mut SVector<T, N>) {
        (**self).rhs(t, y, dy)
    }
    #[inline(always)]
    fn jacobian(&self, t: T, y: &SVector<T, N>) -> Option<SMatrix<T, N, N>> {
        (**self).jacobian(t, y)
    }
    #[inline(always)]
    fn time_derivative(&self, t: T, y: &SVector<T, N>) -> Option<SVector<T, N>> {
        (**self).time_derivative(t, y)
    }
    #[inline(always)]
    fn time_scale(&self, t: T) -> Option<T> {
        (**self).time_scale(t)
    }
    #[inline(always)]
    fn velocity_exponent(&self) -> Option<T> {
        (**self).velocity_exponent()
    }
    #[inline(always)]
    fn cusp_exponent(&self) -> Option<T> {
        (**self).cusp_exponent()
    }
    #[inline(always)]
    fn contact_onset(&self) -> Option<crate::force::ContactOnset<T>> {
        (**self).contact_onset()
    }
}

/// The lane form of a system: its right-hand side evaluated for `L` trajectories at once,
/// one per lane of a [`Lanes`] vector, each with its own parameters. The ensemble
/// ([`ensemble`](crate::ensemble)) steps a `LaneDynamics` model in SIMD lanes.
///
/// The crate's models implement it when their parts have lane forms:
/// [`Oscillator`](crate::model::Oscillator) with laws implementing
/// [`LaneLaw`](crate::force::LaneLaw) and an excitation implementing
/// [`LaneExcitation`](crate::excite::LaneExcitation), and
/// [`Mechanical`](crate::model::Mechanical) with such elements and loads. Any other
/// system runs in lanes through [`LaneByLane`], which evaluates its scalar `rhs` lane by
/// lane.
///
/// # Contract
/// [`rhs_lanes`](Self::rhs_lanes) must compute in every lane `i` the value of
/// [`rhs`](Dynamics::rhs) for the model packed into lane `i`
/// ([`pack_lane`](Self::pack_lane)), and may depend on nothing else (not on the other lanes,
/// not on the lane count). With [`LaneMath::Exact`] the crate's lane forms perform the
/// scalar operations in the scalar order, so each lane's value is the scalar value to the
/// bit; the ensemble then reproduces the scalar driver step for step.
///
/// The evaluation is split in two: [`time_lanes`](Self::time_lanes) computes what depends
/// on `t` alone (the loads), [`rhs_lanes`](Self::rhs_lanes) the rest, so two stages of a
/// step at the same time (the last two of DOPRI5) share the loads.
///
/// [`LaneMath::Exact`]: crate::lanes::LaneMath::Exact
pub trait LaneDynamics<const M: usize>: Dynamics<f64, M> + Clone {
    /// The parameters of `L` models, one per lane.
    type Packed<V: Lanes>: Clone + core::fmt::Debug + Send + Sync;
    /// What [`time_lanes`](Self::time_lanes) computes.
    type Time<V: Lanes>: Copy;

    /// Every lane set to this model.
    fn pack<V: Lanes>(&self) -> Self::Packed<V>;

    /// Lane `lane` of `packed` set to this model (the other lanes unchanged).
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize);

    /// Whether `other` can share lanes with `self`: the parts of a model that its lane
    /// form takes from the model packed first (the structure, e.g. the coordinates of a
    /// [`Mechanical`](crate::model::Mechanical) system) are the same. The ensemble runs
    /// a trajectory whose model differs in structure from the first one's as an error in
    /// its result slot. Default `true` (every part is per lane).
    fn same_structure(&self, _other: &Self) -> bool {
        true
    }

    /// Whether [`time_scale`](Dynamics::time_scale) has the same value at every `t`
    /// (`None` everywhere included, as for every model that does not declare one). The
    /// ensemble then bounds each lane's steps with the value at its start, computed in the
    /// lanes, instead of asking at every step. Default `false`; `true` for
    /// [`Oscillator`](crate::model::Oscillator) and
    /// [`Mechanical`](crate::model::Mechanical), which declare none.
    fn constant_time_scale(&self) -> bool {
        false
    }

    /// The terms of the right-hand side that depend on the time only, in every lane.
    fn time_lanes<V: Lanes>(packed: &Self::Packed<V>, math: LaneMath, t: V) -> Self::Time<V>;

    /// `ẏ = f(t, y)` in every lane, with the time terms of `t` given.
    fn rhs_lanes<V: Lanes>(
        packed: &Self::Packed<V>,
        math: LaneMath,
        t: V,
        time: &Self::Time<V>,
        y: &[V; M],
        dy: &mut [V; M],
    );
}

/// Any [`Dynamics`] in lanes: [`LaneDynamics::rhs_lanes`] calls the system's scalar
/// [`rhs`](Dynamics::rhs) once per lane.
///
/// This is the fallback for a system whose parts have no lane form (a user's own force law
/// or right-hand side): the ensemble's stepping, error control and event handling still
/// run in lanes, the right-hand side does not, so it is correct (each lane is the scalar
/// path to the bit, whatever the math mode) and slower than a lane form — by how much
/// depends on the share of the right-hand side in a step.
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::lanes::{F64x4, LaneMath, Lanes};
/// use nonsmooth::{Dynamics, LaneByLane, LaneDynamics};
///
/// #[derive(Clone, Debug)]
/// struct Decay(f64);
/// impl Dynamics<f64, 1> for Decay {
///     fn rhs(&self, _t: f64, y: &SVector<f64, 1>, dy: &mut SVector<f64, 1>) {
///         dy[0] = -self.0 * y[0];
///     }
/// }
/// let m = LaneByLane(Decay(2.0));
/// let p = m.pack::<F64x4>();
/// let t = F64x4::splat(0.0);
/// let time = LaneByLane::<Decay>::time_lanes(&p, LaneMath::Exact, t);
/// let mut dy = [F64x4::splat(0.0)];
/// LaneByLane::<Decay>::rhs_lanes(&p, LaneMath::Exact, t, &time, &[F64x4::splat(3.0)], &mut dy);
/// assert_eq!(dy[0].lane(2), -6.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneByLane<D>(pub D);

impl<const M: usize, D: Dynamics<f64, M>> Dynamics<f64, M> for LaneByLane<D> {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &SVector<f64, M>, dy: &mut SVector<f64, M>) {
        self.0.rhs(t, y, dy)
    }
    fn jacobian(&self, t: f64, y: &SVector<f64, M>) -> Option<SMatrix<f64, M, M>> {
        self.0.jacobian(t, y)
    }
    fn time_derivative(&self, t: f64, y: &SVector<f64, M>) -> Option<SVector<f64, M>> {
        self.0.time_derivative(t, y)
    }
    fn time_scale(&self, t: f64) -> Option<f64> {
        self.0.time_scale(t)
    }
    fn velocity_exponent(&self) -> Option<f64> {
        self.0.velocity_exponent()
    }
    fn cusp_exponent(&self) -> Option<f64> {
        self.0.cusp_exponent()
    }
    fn contact_onset(&self) -> Option<crate::force::ContactOnset<f64>> {
        self.0.contact_onset()
    }
}

impl<const M: usize, D> LaneDynamics<M> for LaneByLane<D>
where
    D: Dynamics<f64, M> + Clone + core::fmt::Debug + Send + Sync,
{
    /// One model per lane.
    type Packed<V: Lanes> = Vec<D>;
    type Time<V: Lanes> = ();

    fn pack<V: Lanes>(&self) -> Vec<D> {
        vec![self.0.clone(); V::LANES]
    }

    fn pack_lane<V: Lanes>(&self, packed: &mut Vec<D>, lane: usize) {
        if let Some(m) = packed.get_mut(lane) {
            *m = self.0.clone();
        }
    }

    #[inline(always)]
    fn time_lanes<V: Lanes>(_packed: &Vec<D>, _math: LaneMath, _t: V) {}

    #[inline(always)]
    fn rhs_lanes<V: Lanes>(
        packed: &Vec<D>,
        _math: LaneMath,
        t: V,
        _time: &(),
        y: &[V; M],
        dy: &mut [V; M],
    ) {
        let mut out = [[0.0f64; 16]; M];
        for (i, model) in packed.iter().enumerate().take(V::LANES) {
            let yi = SVector::<f64, M>::from_fn(|k, _| y[k].lane(i));
            let mut di = SVector::<f64, M>::zeros();
            model.rhs(t.lane(i), &yi, &mut di);
            for k in 0..M {
                out[k][i] = di[k];
            }
        }
        for k in 0..M {
            dy[k] = V::load(&out[k]);
        }
    }
}
