//! The [`Dynamics`] trait: all an integrator knows about a system.

use nalgebra::{SMatrix, SVector};

use crate::Real;

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
    fn contact_onset(&self) -> Option<crate::force::ContactOnset<T>> {
        (**self).contact_onset()
    }
}
