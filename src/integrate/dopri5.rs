//! Dormand–Prince 5(4) with Hairer's 4th-order continuous extension.

use nalgebra::SVector;

use super::adaptive::{Adaptive, Interpolant, Method, MethodDense, StepParts, sealed};
use super::{HermiteDense, IntegrateError, Trial};
use crate::scalar::lit;
use crate::{Dynamics, Real};

/// The Dormand–Prince 5(4) tableau and Hairer's dense-output coefficients (shared with the
/// ensemble's lane step, which must evaluate the same numbers).
pub(crate) mod tableau {
    /// Nodes `c₂…c₅` (`c₆ = c₇ = 1`).
    pub const C: [f64; 4] = [0.2, 0.3, 0.8, 8.0 / 9.0];
    /// Row 3 of `A`.
    pub const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
    /// Row 4 of `A`.
    pub const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
    /// Row 5 of `A`.
    pub const A5: [f64; 4] = [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
    ];
    /// Row 6 of `A`.
    pub const A6: [f64; 5] = [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
    ];
    /// The weights `b₁, b₃…b₆` (`b₂ = b₇ = 0`; row 7 of `A`).
    pub const B: [f64; 5] = [
        35.0 / 384.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ];
    /// The error weights `b − b̂` for stages 1, 3…7.
    pub const E: [f64; 6] = [
        71.0 / 57600.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ];
    /// Hairer's dense-output coefficients for stages 1, 3…7.
    pub const D: [f64; 6] = [
        -12715105075.0 / 11282082432.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ];
}

/// The explicit Runge–Kutta method of Dormand and Prince, order 5 with an embedded order-4
/// error estimate, first-same-as-last (6 evaluations per accepted step), and Hairer's
/// 4th-order dense output: the [`Adaptive`] stepper of [`Dopri5Method`].
///
/// # References
/// J. R. Dormand, P. J. Prince, *A family of embedded Runge–Kutta formulae*, J. Comput.
/// Appl. Math. 6 (1980); E. Hairer, S. P. Nørsett, G. Wanner, *Solving ODEs I*, II.5–II.6.
pub type Dopri5<T, const N: usize> = Adaptive<T, N, Dopri5Method>;

/// Dense output of a [`Dopri5`] step.
pub type Dopri5Dense<T, const N: usize> = MethodDense<T, N, Dopri5Interpolant<T, N>>;

impl<T: Real, const N: usize> Dopri5Dense<T, N> {
    /// A step's dense output from its parts: the ends, the step `h` and Hairer's
    /// coefficients `[r2, r3, r4, r5]` (the ensemble builds each lane's step from its rows:
    /// the same interpolation as the scalar stepper's, to the bit).
    pub(crate) fn from_parts(
        ends: HermiteDense<T, N>,
        h: T,
        [r2, r3, r4, r5]: [SVector<T, N>; 4],
    ) -> Self {
        MethodDense {
            ends,
            poly: Dopri5Interpolant { h, r2, r3, r4, r5 },
        }
    }
}

/// The Dormand–Prince 5(4) method (see [`Dopri5`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Dopri5Method;

/// Hairer's 4th-order continuous extension of a [`Dopri5`] step:
/// `y(t0 + θh) = y0 + θ(r2 + (1−θ)(r3 + θ(r4 + (1−θ)r5)))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dopri5Interpolant<T: Real, const N: usize> {
    h: T,
    r2: SVector<T, N>,
    r3: SVector<T, N>,
    r4: SVector<T, N>,
    r5: SVector<T, N>,
}

impl sealed::Sealed for Dopri5Method {}
impl<T: Real, const N: usize> sealed::Sealed for Dopri5Interpolant<T, N> {}

impl<T: Real, const N: usize> Interpolant<T, N> for Dopri5Interpolant<T, N> {
    fn empty() -> Self {
        let z = SVector::zeros();
        Self {
            h: T::zero(),
            r2: z,
            r3: z,
            r4: z,
            r5: z,
        }
    }

    #[inline(always)]
    fn eval(&self, ends: &HermiteDense<T, N>, t: T, out: &mut SVector<T, N>) {
        let (t0, y0) = (ends.t0, &ends.y0);
        let th = (t - t0) / self.h;
        let th1 = T::one() - th;
        for i in 0..N {
            out[i] = y0[i]
                + th * (self.r2[i] + th1 * (self.r3[i] + th * (self.r4[i] + th1 * self.r5[i])));
        }
    }

    /// With `u = θ`, `v = 1 − θ` the interpolant less its chord `y0 + θ·r2` is
    /// `uv·r3 + u²v·r4 + u²v²·r5`, and on `[0, 1]` `uv ≤ 1/4`, `u²v ≤ 4/27 < 0.15`,
    /// `u²v² ≤ 1/16`: `dev = |r3|/4 + 0.15·|r4| + |r5|/16`; `mag = |y0| + Σ|r_j|`.
    fn chord_bounds(&self, ends: &HermiteDense<T, N>) -> Option<(SVector<T, N>, SVector<T, N>)> {
        let (q, e, s) = (lit::<T>(0.25), lit::<T>(0.15), lit::<T>(0.0625));
        let mut dev = SVector::zeros();
        let mut mag = SVector::zeros();
        for i in 0..N {
            let (a3, a4, a5) = (self.r3[i].abs(), self.r4[i].abs(), self.r5[i].abs());
            dev[i] = q * a3 + e * a4 + s * a5;
            mag[i] = ends.y0[i].abs() + self.r2[i].abs() + a3 + a4 + a5;
        }
        Some((dev, mag))
    }
}

impl<T: Real, const N: usize> Method<T, N> for Dopri5Method {
    const ORDER: u8 = 5;
    const ERROR_ORDER: f64 = 5.0;
    type Poly = Dopri5Interpolant<T, N>;

    fn advance<S: Dynamics<T, N>>(
        parts: StepParts<'_, T, N>,
        dense: &mut Dopri5Dense<T, N>,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        let StepParts { tol, ctrl, core } = parts;
        core.begin(sys, t_limit)?;
        let (t, y, k1) = (core.t, core.y, core.f);
        let h = core.proposed(sys, 5, tol, ctrl.opts.h_max, t_limit);
        let c = |x: f64| lit::<T>(x);
        let a21 = c(1.0 / 5.0);
        let [a31, a32] = tableau::A3.map(c);
        let [a41, a42, a43] = tableau::A4.map(c);
        let [a51, a52, a53, a54] = tableau::A5.map(c);
        let [a61, a62, a63, a64, a65] = tableau::A6.map(c);
        let [a71, a73, a74, a75, a76] = tableau::B.map(c);
        let [e1, e3, e4, e5, e6, e7] = tableau::E.map(c);
        let [c2, c3, c4, c5] = tableau::C.map(c);
        let mut k2 = SVector::zeros();
        let mut k3 = SVector::zeros();
        let mut k4 = SVector::zeros();
        let mut k5 = SVector::zeros();
        let mut k6 = SVector::zeros();
        let mut k7 = SVector::zeros();
        let a = core.adapt(ctrl, t_limit, h, |stats, hs, t_new| {
            let yt = y + k1 * (a21 * hs);
            sys.rhs(t + c2 * hs, &yt, &mut k2);
            let yt = y + (k1 * a31 + k2 * a32) * hs;
            sys.rhs(t + c3 * hs, &yt, &mut k3);
            let yt = y + (k1 * a41 + k2 * a42 + k3 * a43) * hs;
            sys.rhs(t + c4 * hs, &yt, &mut k4);
            let yt = y + (k1 * a51 + k2 * a52 + k3 * a53 + k4 * a54) * hs;
            sys.rhs(t + c5 * hs, &yt, &mut k5);
            let yt = y + (k1 * a61 + k2 * a62 + k3 * a63 + k4 * a64 + k5 * a65) * hs;
            sys.rhs(t_new, &yt, &mut k6);
            let y_new = y + (k1 * a71 + k3 * a73 + k4 * a74 + k5 * a75 + k6 * a76) * hs;
            sys.rhs(t_new, &y_new, &mut k7);
            stats.rhs_evals += 6;
            Ok(Trial::new(y_new, k7, || {
                let errv = (k1 * e1 + k3 * e3 + k4 * e4 + k5 * e5 + k6 * e6 + k7 * e7) * hs;
                tol.error_norm(&errv, &y, &y_new)
            }))
        })?;
        let (hs, y_new) = (a.hs, a.y);
        let ydiff = y_new - y;
        let bspl = k1 * hs - ydiff;
        let [d1, d3, d4, d5, d6, d7] = tableau::D.map(c);
        *dense = MethodDense {
            ends: HermiteDense::new(t, a.t_new, y, y_new, k1, k7),
            poly: Dopri5Interpolant {
                h: hs,
                r2: ydiff,
                r3: bspl,
                r4: ydiff - k7 * hs - bspl,
                r5: (k1 * d1 + k3 * d3 + k4 * d4 + k5 * d5 + k6 * d6 + k7 * d7) * hs,
            },
        };
        core.accept(&a);
        Ok(())
    }
}
