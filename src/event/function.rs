//! Event functions `g(t, y)`: the trait, the index check of its implementations and the
//! closure adapter.

use nalgebra::SVector;

use super::error::EventError;
use crate::Real;
use crate::lanes::Lanes;

/// A scalar function `g(t, y)` whose zeros are events.
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::event::EventFunction;
/// /// The energy surface E(y) = E0 of an oscillator.
/// struct Energy(f64);
/// impl EventFunction<f64, 2> for Energy {
///     fn value(&self, _t: f64, y: &SVector<f64, 2>) -> f64 { 0.5 * (y[0] * y[0] + y[1] * y[1]) - self.0 }
/// }
/// ```
pub trait EventFunction<T: Real, const N: usize> {
    /// `g(t, y)`; must not mutate anything.
    fn value(&self, t: T, y: &SVector<T, N>) -> T;

    /// `dg/dt` along the trajectory, given `dy = f(t, y)`, if known. Enables grazing
    /// detection from the step's end derivatives.
    fn rate(&self, _t: T, _y: &SVector<T, N>, _dy: &SVector<T, N>) -> Option<T> {
        None
    }

    /// The shortest time over which the function's explicit dependence on `t` can turn
    /// around near `t` (e.g. a fraction of a moving surface's period), if it has one. While
    /// the event is in a simulation, no step is longer than this, so that a moving surface
    /// cannot be stepped over (see the module docs). Default: `None` (no explicit time
    /// dependence).
    fn time_scale(&self, _t: T) -> Option<T> {
        None
    }

    /// Whether [`time_scale`](EventFunction::time_scale) has the same value at every `t`
    /// (`None` everywhere included: no explicit time dependence, or a surface moving at a
    /// constant frequency). The ensemble then bounds each lane's steps with the value at
    /// its start, computed in the lanes, instead of asking at every step. Default `false`;
    /// implemented by [`Level`](super::Level), [`Stop`](super::Stop),
    /// [`FnEvent`] and [`Gap`](super::Gap) (as its motion's
    /// [`Excitation::constant_time_scale`](crate::excite::Excitation::constant_time_scale)).
    fn constant_time_scale(&self) -> bool {
        false
    }

    /// Bounds on `g` along a step's dense output `y(t)` on `[t0, t1]`, if the function can
    /// give them: `(d, a)` with `|g(t, y(t)) − ℓ(t)| ≤ d`, where `ℓ` is the chord between
    /// `g` at the step's ends, and `a` a bound on the magnitudes of the terms `g` is
    /// computed from (the rounding allowance is relative to it). `dev[k]` bounds
    /// `|y_k(t) − ℓ_k(t)|` (the chord of component `k`) and `mag[k]` the magnitudes of the
    /// terms of `y_k(t)` on the step
    /// ([`DenseOutput::chord_bounds`](crate::integrate::DenseOutput::chord_bounds)).
    ///
    /// The driver uses them where the rates at a step's ends show a grazing pair (both
    /// ends on one side, moving towards the surface and then away from it): when both
    /// ends are farther from the surface than `d` plus the allowance, no point of the step
    /// reaches it, and the search for the extremum is skipped; the result is the one the
    /// search would have given. A bound that holds only approximately would let a
    /// crossing be missed. For `g` affine in `y`, `g = w·y + c + s(t)`, it is
    /// `d = Σ|w_k|·dev_k + d_s` with `d_s` the surface's own chord deviation. Default
    /// `None` (the search always runs); implemented by [`Level`](super::Level),
    /// [`Stop`](super::Stop) and [`Gap`](super::Gap) (as its motion's
    /// [`Excitation::chord_bounds`](crate::excite::Excitation::chord_bounds)).
    fn chord_bounds(
        &self,
        _t0: T,
        _t1: T,
        _dev: &SVector<T, N>,
        _mag: &SVector<T, N>,
    ) -> Option<(T, T)> {
        None
    }

    /// Checks that the function can be evaluated on states of dimension `N` (e.g. that a
    /// component index is in range); the driver calls it before a run starts. Default: `Ok`.
    ///
    /// # Errors
    /// [`EventError::IndexOutOfRange`] for an index `≥ N`.
    fn check(&self) -> Result<(), EventError> {
        Ok(())
    }

    /// The lane form: [`value`](EventFunction::value) and [`rate`](EventFunction::rate) at
    /// `L` points `(t, y, dy)` at once, one per lane, each lane equal to the scalar
    /// functions at that lane's point to the bit (the rate `None` exactly where `rate` is
    /// `None`). `None` (the default) if the function has none. The ensemble
    /// ([`Ensemble`](crate::ensemble::Ensemble)) evaluates its events at the ends of every
    /// lane's step with it (once per point: a step's end is the next one's start) and
    /// searches a step lane by lane only where it may hold an event (the driver's own
    /// conditions); without it, every step is searched lane by lane: the same results,
    /// more time. Implemented by [`Level`](super::Level),
    /// [`Stop`](super::Stop) and [`Gap`](super::Gap) (on a surface whose motion has
    /// [`Excitation::motion_lanes`](crate::excite::Excitation::motion_lanes)) in `f64`.
    #[inline(always)]
    fn lanes<V: Lanes>(&self, _t: V, _y: &[V; N], _dy: &[V; N]) -> Option<(V, Option<V>)>
    where
        Self: Sized,
    {
        None
    }
}

/// `Err(IndexOutOfRange)` unless `index < n` (for implementations of the `check` hooks).
pub fn check_index(index: usize, n: usize) -> Result<(), EventError> {
    if index < n {
        Ok(())
    } else {
        Err(EventError::IndexOutOfRange { index, len: n })
    }
}

/// An event function from a closure `g(t, y)` (no rate: use interior samples for grazing).
#[derive(Debug, Clone, Copy)]
pub struct FnEvent<F>(pub F);

impl<T: Real, const N: usize, F: Fn(T, &SVector<T, N>) -> T> EventFunction<T, N> for FnEvent<F> {
    #[inline(always)]
    fn value(&self, t: T, y: &SVector<T, N>) -> T {
        (self.0)(t, y)
    }
    fn constant_time_scale(&self) -> bool {
        true
    }
}
