//! A linearly implicit (Rosenbrock) method for stiff phases.

use nalgebra::{SMatrix, SVector};

use super::adaptive::{Adaptive, Interpolant, Method, MethodDense, StepParts, sealed};
use super::{Core, HermiteDense, IntegrateError, Tolerances, Trial};
use crate::linalg::Lu;
use crate::scalar::{epsilon, lit, to_f64};
use crate::{Dynamics, Real};

/// The L-stable Rosenbrock method of Shampine and Reichelt (MATLAB's `ode23s`): order 2
/// with a 3rd-order error estimate, first-same-as-last, and its own quadratic dense output.
///
/// # Model
/// With `W = I − h·d·J`, `d = 1/(2+√2)`, `J = ∂f/∂y` and `T = ∂f/∂t` at the step start:
/// $$\begin{aligned}
/// W k_1 &= f(t, y) + h d T,\\
/// W (k_2 - k_1) &= f(t + h/2, y + h k_1/2) - k_1,\qquad y_{n+1} = y + h k_2,\\
/// W k_3 &= f(t+h, y_{n+1}) - e_{32}(k_2 - f_1) - 2(k_1 - f_0) + h d T,\\
/// \mathrm{err} &= \tfrac{h}{6}(k_1 - 2k_2 + k_3).
/// \end{aligned}$$
/// One Jacobian and one LU decomposition per step attempt (`N×N`, on the stack). The
/// Jacobian is the system's [`Dynamics::jacobian`] or, if absent, a forward difference.
///
/// The [`Adaptive`] stepper of [`Rosenbrock23Method`].
///
/// # References
/// L. F. Shampine, M. W. Reichelt, *The MATLAB ODE Suite*, SIAM J. Sci. Comput. 18 (1997).
pub type Rosenbrock23<T, const N: usize> = Adaptive<T, N, Rosenbrock23Method>;

/// Dense output of a [`Rosenbrock23`] step.
pub type Rosenbrock23Dense<T, const N: usize> = MethodDense<T, N, Rosenbrock23Interpolant<T, N>>;

/// The Rosenbrock method of Shampine and Reichelt (see [`Rosenbrock23`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Rosenbrock23Method;

/// The quadratic continuous extension of a [`Rosenbrock23`] step:
/// `y(t0 + s·h) = y0 + h·(s(1−s)/(1−2d)·k1 + s(s−2d)/(1−2d)·k2)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rosenbrock23Interpolant<T: Real, const N: usize> {
    h: T,
    k1: SVector<T, N>,
    k2: SVector<T, N>,
}

impl sealed::Sealed for Rosenbrock23Method {}
impl<T: Real, const N: usize> sealed::Sealed for Rosenbrock23Interpolant<T, N> {}

impl<T: Real, const N: usize> Interpolant<T, N> for Rosenbrock23Interpolant<T, N> {
    fn empty() -> Self {
        Self {
            h: T::one(),
            k1: SVector::zeros(),
            k2: SVector::zeros(),
        }
    }

    #[inline(always)]
    fn eval(&self, ends: &HermiteDense<T, N>, t: T, out: &mut SVector<T, N>) {
        let d = d_const::<T>();
        let (t0, y0) = (ends.t0, &ends.y0);
        let s = (t - t0) / self.h;
        let den = T::one() - lit::<T>(2.0) * d;
        let c1 = s * (T::one() - s) / den;
        let c2 = s * (s - lit::<T>(2.0) * d) / den;
        for i in 0..N {
            out[i] = y0[i] + self.h * (c1 * self.k1[i] + c2 * self.k2[i]);
        }
    }
}

#[inline(always)]
fn d_const<T: Real>() -> T {
    T::one() / (lit::<T>(2.0) + lit::<T>(2.0).sqrt())
}

/// The step's Jacobian: the system's, or a forward difference.
fn jacobian<T: Real, const N: usize, S: Dynamics<T, N>>(
    core: &mut Core<T, N>,
    tol: &Tolerances<T, N>,
    sys: &S,
    t: T,
    y: &SVector<T, N>,
    f0: &SVector<T, N>,
) -> SMatrix<T, N, N> {
    core.stats.jacobian_evals += 1;
    if let Some(j) = sys.jacobian(t, y) {
        return j;
    }
    let mut j = SMatrix::<T, N, N>::zeros();
    let sq = epsilon::<T>().sqrt();
    let mut f1 = SVector::zeros();
    for c in 0..N {
        let dy = sq * (y[c].abs().max(tol.atol[c] / tol.rtol[c].max(epsilon())));
        let mut yp = *y;
        yp[c] += dy;
        sys.rhs(t, &yp, &mut f1);
        core.stats.rhs_evals += 1;
        j.set_column(c, &((f1 - f0) / dy));
    }
    j
}

/// The step's time derivative `∂f/∂t`: the system's, or a forward difference.
fn dfdt<T: Real, const N: usize, S: Dynamics<T, N>>(
    core: &mut Core<T, N>,
    sys: &S,
    t: T,
    y: &SVector<T, N>,
    f0: &SVector<T, N>,
) -> SVector<T, N> {
    if let Some(d) = sys.time_derivative(t, y) {
        return d;
    }
    let dt = epsilon::<T>().sqrt() * t.abs().max(T::one());
    let mut f1 = SVector::zeros();
    sys.rhs(t + dt, y, &mut f1);
    core.stats.rhs_evals += 1;
    (f1 - f0) / dt
}

impl<T: Real, const N: usize> Method<T, N> for Rosenbrock23Method {
    const ORDER: u8 = 2;
    const ERROR_ORDER: f64 = 3.0;
    type Poly = Rosenbrock23Interpolant<T, N>;

    fn advance<S: Dynamics<T, N>>(
        parts: StepParts<'_, T, N>,
        dense: &mut Rosenbrock23Dense<T, N>,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        let StepParts { tol, ctrl, core } = parts;
        core.begin(sys, t_limit)?;
        let (t, y) = (core.t, core.y);
        let f0 = core.f;
        let h = core.proposed(sys, 2, tol, ctrl.opts.h_max, t_limit);
        let jac = jacobian(core, tol, sys, t, &y, &f0);
        // A law reports an infinite partial as the largest finite value; the system's
        // Jacobian scales it (by the inverse mass, …), so anything beyond √MAX ≈ 1.3e154,
        // far from any physical partial, is taken for one.
        let big = T::max_value().unwrap_or(T::zero()).sqrt();
        if let Some(k) = jac.iter().position(|v| !v.is_finite() || v.abs() >= big) {
            return Err(IntegrateError::InfiniteJacobian {
                t: to_f64(t),
                row: k % N,
                col: k / N,
            });
        }
        let tdot = dfdt(core, sys, t, &y, &f0);
        let d = d_const::<T>();
        let e32 = lit::<T>(6.0) + lit::<T>(2.0).sqrt();
        let half = lit::<T>(0.5);
        let two = lit::<T>(2.0);
        let mut f1 = SVector::zeros();
        let mut f2 = SVector::zeros();
        let (mut k1, mut k2) = (SVector::zeros(), SVector::zeros());
        let a = core.adapt(ctrl, t_limit, h, |stats, hs, t_new| {
            let w = SMatrix::<T, N, N>::identity() - jac * (hs * d);
            let Some(lu) = Lu::new(w) else {
                return Err(IntegrateError::SingularMatrix { t: to_f64(t) });
            };
            stats.decompositions += 1;
            let hdt = tdot * (hs * d);
            k1 = lu.solve(&(f0 + hdt));
            sys.rhs(t + half * hs, &(y + k1 * (half * hs)), &mut f1);
            let k2m = lu.solve(&(f1 - k1));
            k2 = k2m + k1;
            let y_new = y + k2 * hs;
            sys.rhs(t_new, &y_new, &mut f2);
            stats.rhs_evals += 2;
            let k3 = lu.solve(&(f2 - (k2 - f1) * e32 - (k1 - f0) * two + hdt));
            Ok(Trial::new(y_new, f2, || {
                let errv = (k1 - k2 * two + k3) * (hs / lit::<T>(6.0));
                tol.error_norm(&errv, &y, &y_new)
            }))
        })?;
        *dense = MethodDense {
            ends: HermiteDense::new(t, a.t_new, y, a.y, f0, a.f),
            poly: Rosenbrock23Interpolant { h: a.hs, k1, k2 },
        };
        core.accept(&a);
        Ok(())
    }
}
