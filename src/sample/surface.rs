//! Contact surfaces as the samplers see them.

use nalgebra::SVector;

use crate::Real;
use crate::drive::StepView;
use crate::event::{EventFunction, Gap, Stop};
use crate::excite::Excitation;
use crate::integrate::DenseOutput;
use crate::roots::golden_max;
use crate::scalar::lit;

/// A contact surface for the impact samplers: the penetration `g(t, y)` (negative while
/// free, `≥ 0` in contact) and its rate `ġ(t, y)` computed from the state alone (for a
/// mechanical system the velocities are part of the state), so that impact velocities are
/// exact and interior extrema of `g` inside a step can be found.
///
/// Impacts are the rising crossings of `g` reported by an event of the simulation built on
/// the same surface. Implemented for [`Stop`] (a level of one component) and [`Gap`] (any
/// coordinate of an `N`-DOF system against a fixed or moving surface).
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::event::EventFunction;
/// use nonsmooth::sample::Surface;
/// /// The unit circle as a wall around a point in the plane: state (x, y, ẋ, ẏ).
/// struct Circle;
/// impl EventFunction<f64, 4> for Circle {
///     fn value(&self, _t: f64, s: &SVector<f64, 4>) -> f64 { s[0].hypot(s[1]) - 1.0 }
/// }
/// impl Surface<f64, 4> for Circle {
///     fn gap_rate(&self, _t: f64, s: &SVector<f64, 4>) -> f64 {
///         (s[0] * s[2] + s[1] * s[3]) / s[0].hypot(s[1])
///     }
/// }
/// ```
pub trait Surface<T: Real, const N: usize>: EventFunction<T, N> {
    /// The penetration `g(t, y)` (default: the event function's value).
    #[inline(always)]
    fn gap(&self, t: T, y: &SVector<T, N>) -> T {
        self.value(t, y)
    }

    /// `ġ(t, y)`: the normal velocity towards the surface (positive approaching).
    fn gap_rate(&self, t: T, y: &SVector<T, N>) -> T;

    /// The maximum of `g` over a step view: the larger end value and, when `ġ` changes
    /// sign from + to − inside, the interior maximum of the interpolated `g` (golden
    /// section to `10⁻¹⁰` of the view).
    fn max_gap<D: DenseOutput<T, N>>(&self, s: &StepView<'_, T, N, D>) -> T {
        let mut m = self.gap(s.t0, &s.y0).max(self.gap(s.t1, &s.y1));
        if self.gap_rate(s.t0, &s.y0) > T::zero() && self.gap_rate(s.t1, &s.y1) < T::zero() {
            let tol = (s.t1 - s.t0) * lit(1e-10);
            let (_, v) = golden_max(
                |t| {
                    let mut y = SVector::zeros();
                    s.dense.interpolate_unchecked(t, &mut y);
                    self.gap(t, &y)
                },
                s.t0,
                s.t1,
                tol,
            );
            m = m.max(v);
        }
        m
    }
}

impl<T: Real, const N: usize> Surface<T, N> for Stop<T> {
    #[inline(always)]
    fn gap_rate(&self, _t: T, y: &SVector<T, N>) -> T {
        match y.get(self.velocity) {
            Some(&v) => v,
            None => T::zero() / T::zero(),
        }
    }

    fn max_gap<D: DenseOutput<T, N>>(&self, s: &StepView<'_, T, N, D>) -> T {
        // Extremum of the component itself, then shifted (bit-identical to the first
        // stage's grazing margins).
        component_max(s, self.position, self.velocity) - self.level
    }
}

impl<T: Real, const N: usize, const M: usize, S: Excitation<T>> Surface<T, M> for Gap<T, N, S> {
    #[inline(always)]
    fn gap_rate(&self, t: T, y: &SVector<T, M>) -> T {
        if M != 2 * N {
            return T::zero() / T::zero();
        }
        self.penetration_rate(t, &y.as_slice()[N..])
    }
}

/// The maximum of `y[pos]` over a step view, using the ends and, when `y[vel]` changes sign
/// from + to −, the interior maximum of the interpolant (golden section).
#[inline]
pub(super) fn component_max<T: Real, const N: usize, D: DenseOutput<T, N>>(
    s: &StepView<'_, T, N, D>,
    pos: usize,
    vel: usize,
) -> T {
    let mut m = s.y0[pos].max(s.y1[pos]);
    if s.y0[vel] > T::zero() && s.y1[vel] < T::zero() {
        let tol = (s.t1 - s.t0) * lit(1e-10);
        let (_, v) = golden_max(
            |t| {
                let mut y = SVector::zeros();
                s.dense.interpolate_unchecked(t, &mut y);
                y[pos]
            },
            s.t0,
            s.t1,
            tol,
        );
        m = m.max(v);
    }
    m
}

/// The minimum of `y[pos]` over a step view (see [`component_max`]).
#[inline]
pub(super) fn component_min<T: Real, const N: usize, D: DenseOutput<T, N>>(
    s: &StepView<'_, T, N, D>,
    pos: usize,
    vel: usize,
) -> T {
    let mut m = s.y0[pos].min(s.y1[pos]);
    if s.y0[vel] < T::zero() && s.y1[vel] > T::zero() {
        let tol = (s.t1 - s.t0) * lit(1e-10);
        let (_, v) = golden_max(
            |t| {
                let mut y = SVector::zeros();
                s.dense.interpolate_unchecked(t, &mut y);
                -y[pos]
            },
            s.t0,
            s.t1,
            tol,
        );
        m = m.min(-v);
    }
    m
}
