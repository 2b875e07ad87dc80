//! The closest approach of an orbit to a switching surface: the test function of a
//! grazing-sliding bifurcation.

use nalgebra::SVector;

use super::run::SlidingObserver;
use super::system::{Filippov, Mode};
use crate::Real;
use crate::drive::{Control, StepView};
use crate::integrate::DenseOutput;
use crate::roots::golden_max;
use crate::scalar::lit;

/// Records the closest approach of the orbit to surface `i` after a time `t_from`: the
/// smallest `s·H_i` over the region steps (`s = ±1` the side's sign, so `s·H_i > 0` inside
/// the region), located on the dense output (samples, then a golden-section search around
/// the smallest), and 0 once the orbit slides on the surface.
///
/// As the test function of a grazing-sliding bifurcation it is positive while the orbit
/// stays off the surface, smooth in the parameters there, and reaches zero where the orbit
/// touches the surface tangentially; past it the orbit slides ([`sliding`](Self::sliding)).
#[derive(Debug, Clone)]
pub struct Approach<'a, T: Real, Sys> {
    system: &'a Sys,
    surface: usize,
    t_from: T,
    samples: usize,
    /// The smallest `s·H_i` and where (time), if a region step was seen after `t_from`.
    pub closest: Option<(T, T)>,
    /// Whether the orbit slid on surface `i` after `t_from`.
    pub sliding: bool,
    /// The smallest *interior* local minimum of `s·H_i` over the region steps after
    /// `t_from` (inside a step, not at its ends: an arc that leaves the surface
    /// tangentially has its minimum, zero, where it starts) and where, if one was seen: the
    /// near miss of an arc of an orbit that may slide elsewhere (the local grazing-sliding
    /// test; a touch within rounding that the run did not report as a transition may be
    /// `≤ 0`).
    pub near_miss: Option<(T, T)>,
}

impl<'a, T: Real, Sys> Approach<'a, T, Sys> {
    /// The approach to surface `surface` of `system` after `t_from`, with `samples` interior
    /// samples per step before the refinement (at least 2 are used).
    pub fn new(system: &'a Sys, surface: usize, t_from: T, samples: usize) -> Self {
        Self {
            system,
            surface,
            t_from,
            samples: samples.max(2),
            closest: None,
            sliding: false,
            near_miss: None,
        }
    }

    /// The test function: the closest approach, 0 if the orbit slid, `None` before any
    /// step after `t_from`.
    pub fn value(&self) -> Option<T> {
        if self.sliding {
            Some(T::zero())
        } else {
            self.closest.map(|c| c.0)
        }
    }
}

impl<T: Real, const N: usize, const S: usize, Sys: Filippov<T, N, S>> SlidingObserver<T, N, S>
    for Approach<'_, T, Sys>
{
    fn on_step<D: DenseOutput<T, N>>(
        &mut self,
        mode: &Mode<S>,
        step: &StepView<'_, T, N, D>,
    ) -> Control {
        if step.t1 <= self.t_from || self.surface >= S {
            return Control::Continue;
        }
        if mode.sliding == Some(self.surface) {
            self.sliding = true;
            return Control::Continue;
        }
        if mode.sliding.is_some() {
            return Control::Continue;
        }
        let s = mode.sides[self.surface].sign::<T>();
        let (ta, tb) = (step.t0.max(self.t_from), step.t1);
        let gap = |t: T| {
            let mut y = SVector::zeros();
            step.state_at(t, &mut y);
            s * self.system.surface(self.surface, t, &y)
        };
        let n = self.samples + 1;
        let at = |k: usize| ta + (tb - ta) * lit::<T>(k as f64) / lit::<T>(n as f64);
        let (mut kmin, mut gmin) = (0, gap(ta));
        for k in 1..=n {
            let g = gap(at(k));
            if g < gmin {
                kmin = k;
                gmin = g;
            }
        }
        let (lo, hi) = (at(kmin.saturating_sub(1)), at((kmin + 1).min(n)));
        let (tm, neg) = golden_max(
            |t| -gap(t),
            lo,
            hi,
            T::default_epsilon() * tb.abs().max(T::one()),
        );
        let (tmin, gmin) = if -neg < gmin {
            (tm, -neg)
        } else {
            (at(kmin), gmin)
        };
        if self.closest.is_none_or(|c| gmin < c.0) {
            self.closest = Some((gmin, tmin));
        }
        let margin = lit::<T>(1e-9) * (tb - ta);
        if tmin > ta + margin && tmin < tb - margin && self.near_miss.is_none_or(|c| gmin < c.0) {
            self.near_miss = Some((gmin, tmin));
        }
        Control::Continue
    }
}
