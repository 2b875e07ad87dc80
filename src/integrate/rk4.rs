//! The classical fixed-step Runge–Kutta method with cubic Hermite dense output.

use nalgebra::SVector;

use super::{Accepted, Core, DenseOutput, IntegrateError, Stats, Stepper, all_finite};
use crate::scalar::{lit, to_f64};
use crate::validate::ParameterError;
use crate::validate::positive;
use crate::{Dynamics, Real};

/// The classical 4th-order Runge–Kutta method with a fixed step `h` (the last step of a
/// run is shortened to land on the limit). A reference for tests; no error control.
///
/// The end-point derivative of each step is kept for the next step (so 4 evaluations per
/// step in a steady run) and gives the cubic Hermite dense output ([`HermiteDense`],
/// 3rd order).
#[derive(Debug, Clone)]
pub struct Rk4<T: Real, const N: usize> {
    h: T,
    core: Core<T, N>,
    dense: HermiteDense<T, N>,
}

/// Cubic Hermite interpolation between two states and their derivatives.
///
/// Also the step ends `(t0, t1, y0, y1, f0, f1)` that every method's dense output keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HermiteDense<T: Real, const N: usize> {
    pub(crate) t0: T,
    t1: T,
    pub(crate) y0: SVector<T, N>,
    y1: SVector<T, N>,
    f0: SVector<T, N>,
    f1: SVector<T, N>,
}

impl<T: Real, const N: usize> HermiteDense<T, N> {
    /// Builds the interpolant on `[t0, t1]`.
    pub fn new(
        t0: T,
        t1: T,
        y0: SVector<T, N>,
        y1: SVector<T, N>,
        f0: SVector<T, N>,
        f1: SVector<T, N>,
    ) -> Self {
        Self {
            t0,
            t1,
            y0,
            y1,
            f0,
            f1,
        }
    }

    /// All zero (before the first step).
    pub(crate) fn zeros() -> Self {
        let z = SVector::zeros();
        Self::new(T::zero(), T::zero(), z, z, z, z)
    }
}

impl<T: Real, const N: usize> DenseOutput<T, N> for HermiteDense<T, N> {
    #[inline(always)]
    fn span(&self) -> (T, T) {
        (self.t0, self.t1)
    }

    #[inline(always)]
    fn endpoints(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        (&self.y0, &self.y1)
    }

    #[inline(always)]
    fn end_derivatives(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        (&self.f0, &self.f1)
    }

    #[inline(always)]
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, N>) {
        let h = self.t1 - self.t0;
        let s = (t - self.t0) / h;
        let s2 = s * s;
        let s3 = s2 * s;
        let two = lit::<T>(2.0);
        let three = lit::<T>(3.0);
        let h00 = two * s3 - three * s2 + T::one();
        let h10 = s3 - two * s2 + s;
        let h01 = -two * s3 + three * s2;
        let h11 = s3 - s2;
        for i in 0..N {
            out[i] =
                h00 * self.y0[i] + h10 * h * self.f0[i] + h01 * self.y1[i] + h11 * h * self.f1[i];
        }
    }
}

impl<T: Real, const N: usize> Rk4<T, N> {
    /// A fixed-step RK4 with step `h`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `h` is finite and > 0.
    pub fn new(h: T) -> Result<Self, ParameterError> {
        Ok(Self {
            h: positive("h", h)?,
            core: Core::new(None),
            dense: HermiteDense::zeros(),
        })
    }
}

impl<T: Real, const N: usize> Stepper<T, N> for Rk4<T, N> {
    type Dense = HermiteDense<T, N>;

    fn reset_state(&mut self, t: T, y: SVector<T, N>) {
        self.core.reset(t, y);
    }

    fn start(&mut self, t: T, y: SVector<T, N>) {
        self.core.start(t, y);
    }

    fn current(&self) -> (T, &SVector<T, N>) {
        (self.core.t, &self.core.y)
    }

    fn dense(&self) -> &Self::Dense {
        &self.dense
    }

    fn stats(&self) -> &Stats {
        &self.core.stats
    }

    fn stats_mut(&mut self) -> &mut Stats {
        &mut self.core.stats
    }

    fn step<S: Dynamics<T, N>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError> {
        self.core.begin(sys, t_limit)?;
        let (t, y) = (self.core.t, self.core.y);
        // Land exactly on the limit when the remaining span is within 1e-9 of a step.
        let (h, t_new, tau_new) = self.core.fixed_step(self.h, t_limit);
        if !(t_new > t) {
            // A step below the time resolution at t: no progress is possible.
            return Err(IntegrateError::StepSizeTooSmall {
                t: to_f64(t),
                h: to_f64(self.h),
            });
        }
        let half = lit::<T>(0.5);
        let k1 = self.core.f;
        let mut k2 = SVector::zeros();
        let mut k3 = SVector::zeros();
        let mut k4 = SVector::zeros();
        sys.rhs(t + half * h, &(y + k1 * (half * h)), &mut k2);
        sys.rhs(t + half * h, &(y + k2 * (half * h)), &mut k3);
        sys.rhs(t_new, &(y + k3 * h), &mut k4);
        let y_new = y + (k1 + (k2 + k3) * lit::<T>(2.0) + k4) * (h / lit::<T>(6.0));
        let mut f_new = SVector::zeros();
        sys.rhs(t_new, &y_new, &mut f_new);
        self.core.stats.rhs_evals += 4;
        if !all_finite(&y_new) || !all_finite(&f_new) {
            return Err(IntegrateError::NonFiniteRhs { t: to_f64(t) });
        }
        self.dense = HermiteDense::new(t, t_new, y, y_new, k1, f_new);
        self.core.accept(&Accepted {
            hs: self.h,
            t_new,
            tau_new,
            lands: false,
            h: self.h,
            h_next: self.h,
            y: y_new,
            f: f_new,
        });
        Ok(())
    }

    fn order(&self) -> u8 {
        4
    }

    fn max_step(&self) -> Option<T> {
        Some(self.h)
    }
}
