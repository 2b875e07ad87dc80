//! An implicit step for a velocity cusp: extrapolated backward Euler on the velocities of a
//! mechanical system ([`CuspImplicit`]), and the switch between it and an explicit stepper
//! where the cusp makes the explicit stepper stiffness-bound ([`CuspSwitch`]).
//!
//! # Why
//! A force term `∝ sgn(ẋ)|ẋ|^q` with `0 < q < 1` (a Hertz contact's damping, `q = n3`)
//! has the slope `q|ẋ|^{q−1}`, unbounded at `ẋ = 0`. Where the body *creeps* in contact —
//! at rest on a stop, its velocity following the slowly changing balance of the other
//! forces, `ẍ = A − C·g(ẋ)` with `A ≈ C·g(ẋ)` — the relaxation rate `C·q|ẋ|^{q−1}` is huge
//! and an explicit method's step is bounded by its inverse. [`TurningPoints`](super::TurningPoints)
//! crosses *transversal* reversals (`A ≠ 0`); it cannot help where the velocity lingers
//! near zero. A linearly implicit method (Rosenbrock) linearizes at the step's start, where
//! the partial derivative is infinite ([`IntegrateError::InfiniteJacobian`]).
//!
//! # The step
//! For a system in mechanical form, state `y = (q, v)` of `N = 2n` components with
//! `q̇ = v` and `v̇ = a(t, q, v)`, backward Euler over `h` eliminates the positions,
//! `q₊ = q + h·v₊`, and leaves an equation in the velocities alone:
//! $$\varphi(v_+) = v_+ - v - h\,a(t+h,\; q + h\,v_+,\; v_+) = 0 .$$
//! For one degree of freedom it is scalar, and monotone when `a` does not increase with
//! the velocity nor (through `h·v₊`) with the position — a damping, a cusp
//! `−C·sgn(v₊)|v₊|^q`, a spring: then `φ' ≥ 1`, one root, and the explicit-Euler point
//! `v_a − φ(v_a)` lies across the root from any `v_a`, so the bracket is found in one
//! evaluation (it is widened geometrically where `φ' ≥ 1` fails). The root is found by
//! Brent's method ([`brent`]) in the variable `u` with `v₊ = sgn(u)|u|^p`, `p = ⌈1/q⌉`
//! (the scale of [`TurningPoints`](super::TurningPoints)), where `φ` is smooth through
//! `v₊ = 0` (`|v₊|^q = |u|^{pq}`, `pq ≥ 1`), so the bracketing solve converges
//! superlinearly even when the root is `0` or next to it. It is solved to
//! `10⁻³` of the step's tolerance on `v₊` (and on `h·v₊` in `q₊`). For `n > 1` the
//! velocities are solved one at a time (nonlinear Gauss–Seidel: each a scalar monotone
//! equation with the others held), sweeping until no velocity moves by more than that
//! accuracy (at most 50 sweeps; it converges where the coupling through `h·∂a/∂v` and
//! `h²·∂a/∂q` is diagonally dominant, a failed sweep rejects the step).
//!
//! The order is raised by extrapolation (the implicit Euler extrapolation of Deuflhard
//! and of Hairer–Wanner's SEULEX, with a fixed table): `T_{j1}` is `j` backward Euler
//! steps of `h/j`, `j = 1, 2, 3`, and the Aitken–Neville table for an error expansion in
//! powers of `h`,
//! $$T_{j,k+1} = T_{j,k} + \frac{T_{j,k} - T_{j-1,k}}{n_j/n_{j-k} - 1},$$
//! gives `T₃₃`, of order 3, which is propagated (local extrapolation), and the error
//! estimate `T₃₃ − T₃₂` (the local error of the order-2 `T₃₂`, `O(h³)`). Six backward Euler
//! solves and one evaluation at the new state per step. Its stability function
//! `½R(z) − 4R(z/2)² + (9/2)R(z/3)³`, `R(z) = 1/(1 − z)`, vanishes as `z → −∞`: the fast
//! relaxation to the creeping state is damped in one step, whatever `h`.
//!
//! Why not a mode of [`TurningPoints`](super::TurningPoints): that stepper changes the
//! independent variable for one degree of freedom and a transversal crossing; this one is
//! an ordinary adaptive method in time ([`Adaptive`] over
//! [`CuspMethod`]), for any number of degrees of freedom, usable alone or inside
//! [`CuspSwitch`].
//!
//! # Dense output
//! The cubic Hermite interpolant of the step's ends and derivatives (third order), with the
//! end slopes `h·f` of a component limited to `3|Δy| + s` (`Δy` the step's change, `s`
//! the component's error scale): where a step starts in a fast transient (the derivative
//! at its start far larger than the change over the step), the unlimited cubic would
//! overshoot by `O(h·f₀)`; limited, it stays within `O(|Δy| + s)` of the ends. The
//! driver's event location and sections use it unchanged.
//!
//! # The switch
//! [`CuspSwitch`] steps with an explicit stepper (DOPRI5 by default) and hands over to the
//! implicit step where the declared cusp is active and the explicit stepper is
//! stiffness-bound, detected from the declared cusp and the step-size history:
//! - a system declares the cusp ([`Dynamics::cusp_exponent`]); without it the switch is
//!   the explicit stepper alone, which stops with [`IntegrateError::UndeclaredCusp`] where
//!   an undeclared cusp holds it stiffness-bound for 50 steps in a row (its rate, probed
//!   as below at `v` and `v/2`, grows as the velocity shrinks) instead of creeping to the
//!   step cap;
//! - after an accepted step of size `h` that ends with a velocity `|v_i| < v_band`, the
//!   cusp's relaxation rate is estimated by a secant in that velocity at the step's end,
//!   `ρ_i = |a_i(v_i) − a_i(v_i/2)|/|v_i/2|` (one extra evaluation; the secant of
//!   `|v|^q` over `[v/2, v]` is `2(1 − 2^{−q})/q` times its tangent slope at `v`, 1.3 for
//!   `q ≈ 0.19`); at `v_i = 0`, `ρ_i = ∞`;
//! - three explicit steps in a row with `h·ρ > 1/2` hand over to the implicit step. An
//!   explicit Runge–Kutta method is stable to `h·ρ ≈ 3` on the negative real axis, but in
//!   the creep its error estimate, dominated by the fast relaxation, holds the step
//!   lower: in `examples/exact_law.rs` DOPRI5 creeps at `h·ρ ≈ 0.7` (secant), with steps
//!   of `4·10⁻⁹` s at rtol 10⁻¹⁰ (ω = 17 rad/s). Away from the creep `h·ρ ≪ 1/2`; a
//!   transversal reversal gives one or two such steps, not three;
//! - the implicit step hands back after two steps with `h·ρ < 0.15` (the explicit method
//!   would be far from that regime at the same step), or as soon as no velocity is in the
//!   band.
//!
//! Each side keeps its own step-size history; a hand-over to the implicit step passes on
//! the explicit stepper's last step.

use nalgebra::SVector;

use super::adaptive::sealed::Sealed;
use super::adaptive::{Adaptive, Interpolant, Method, MethodDense, StepParts};
use super::{DenseOutput, HermiteDense, IntegrateError, Stats, Stepper, Tolerances, Trial};
use crate::roots::brent;
use crate::scalar::{lit, to_f64};
use crate::validate::{ParameterError, positive};
use crate::{Dynamics, Real};

/// The most Gauss–Seidel sweeps of one backward Euler solve (`n > 1` velocities).
const MAX_SWEEPS: usize = 50;
/// The most doublings of the bracket of a scalar solve.
const MAX_WIDEN: usize = 60;
/// The most Brent iterations of a scalar solve.
const MAX_BRENT: usize = 100;
/// The accuracy of a solve relative to the step's error scale.
const SOLVE_FRACTION: f64 = 1e-3;

/// The extrapolated backward Euler method of [`CuspImplicit`] (see the [module
/// docs](self)): order 3, error estimate of order 2 (`O(h³)` locally).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CuspMethod;

impl Sealed for CuspMethod {}

/// The implicit cusp step: extrapolated backward Euler on the velocities of a system in
/// mechanical form `(q, v)`, `N = 2n` (see the [module docs](self)), with the crate's
/// step-size control and a limited cubic Hermite dense output.
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::integrate::{CuspImplicit, Stepper, Tolerances};
/// use nonsmooth::Dynamics;
///
/// /// ẍ = −sgn(ẋ)|ẋ|^{1/4}: comes to rest at t* = |v₀|^{3/4}/(3/4).
/// struct Creep;
/// impl Dynamics<f64, 2> for Creep {
///     fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
///         dy[0] = y[1];
///         dy[1] = -y[1].signum() * y[1].abs().powf(0.25);
///     }
///     fn velocity_exponent(&self) -> Option<f64> { Some(0.25) }
/// }
/// let mut st = CuspImplicit::new(Tolerances::new(1e-8, 1e-12)?);
/// st.reset_state(0.0, SVector::<f64, 2>::new(0.0, 1.0));
/// while st.current().0 < 2.0 {
///     st.step(&Creep, 2.0)?;
/// }
/// assert!(st.current().1[1].abs() < 1e-12);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
pub type CuspImplicit<T, const N: usize> = Adaptive<T, N, CuspMethod>;

/// The dense output of a [`CuspImplicit`] step.
pub type CuspDense<T, const N: usize> = MethodDense<T, N, CuspInterpolant<T, N>>;

/// The limited cubic Hermite interpolant of a [`CuspImplicit`] step: the end slopes `h·f`
/// after limiting (see the [module docs](self#dense-output)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuspInterpolant<T: Real, const N: usize> {
    h: T,
    s0: SVector<T, N>,
    s1: SVector<T, N>,
}

impl<T: Real, const N: usize> Sealed for CuspInterpolant<T, N> {}

impl<T: Real, const N: usize> Interpolant<T, N> for CuspInterpolant<T, N> {
    fn empty() -> Self {
        Self {
            h: T::one(),
            s0: SVector::zeros(),
            s1: SVector::zeros(),
        }
    }

    #[inline(always)]
    fn eval(&self, ends: &HermiteDense<T, N>, t: T, out: &mut SVector<T, N>) {
        // The cubic Hermite interpolant with the limited slopes as derivatives.
        let (t0, t1) = ends.span();
        let (y0, y1) = ends.endpoints();
        HermiteDense::new(t0, t1, *y0, *y1, self.s0 / self.h, self.s1 / self.h)
            .interpolate_unchecked(t, out);
    }
}

impl<T: Real, const N: usize> Method<T, N> for CuspMethod {
    const ORDER: u8 = 3;
    const ERROR_ORDER: f64 = 3.0;
    type Poly = CuspInterpolant<T, N>;

    fn advance<S: Dynamics<T, N>>(
        parts: StepParts<'_, T, N>,
        dense: &mut CuspDense<T, N>,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        let StepParts { tol, ctrl, core } = parts;
        core.begin(sys, t_limit)?;
        let (t, y, f0) = (core.t, core.y, core.f);
        check_mechanical(t, &y, &f0)?;
        let p = sys
            .cusp_exponent()
            .and_then(super::turning::velocity_power)
            .unwrap_or(1);
        let h = core.proposed(sys, 3, tol, ctrl.opts.h_max, t_limit);
        let a = core.adapt(ctrl, t_limit, h, |stats, hs, t_new| {
            let mut evals = 0u64;
            let table = extrapolate(sys, t, &y, hs, t_new, p, tol, &mut evals);
            let mut f = SVector::zeros();
            let trial = match table {
                Some((y33, y32)) => {
                    sys.rhs(t_new, &y33, &mut f);
                    evals += 1;
                    Trial::new(y33, f, || tol.error_norm(&(y33 - y32), &y, &y33))
                }
                None => Trial {
                    y,
                    f: f0,
                    err: None,
                },
            };
            stats.rhs_evals += evals;
            Ok(trial)
        })?;
        let (hs, y1, f1) = (a.hs, a.y, a.f);
        let mut s0 = f0 * hs;
        let mut s1 = f1 * hs;
        for i in 0..N {
            let cap = lit::<T>(3.0) * (y1[i] - y[i]).abs()
                + tol.atol[i]
                + tol.rtol[i] * y[i].abs().max(y1[i].abs());
            s0[i] = s0[i].max(-cap).min(cap);
            s1[i] = s1[i].max(-cap).min(cap);
        }
        *dense = MethodDense {
            ends: HermiteDense::new(t, a.t_new, y, y1, f0, f1),
            poly: CuspInterpolant { h: hs, s0, s1 },
        };
        core.accept(&a);
        Ok(())
    }
}

/// Fails unless the state is `(q, v)` with `q̇ = v` (`N` even, `f₀..ₙ = y_{n..2n}`).
fn check_mechanical<T: Real, const N: usize>(
    t: T,
    y: &SVector<T, N>,
    f: &SVector<T, N>,
) -> Result<(), IntegrateError> {
    let n = N / 2;
    if N % 2 != 0 {
        return Err(IntegrateError::NotMechanical {
            t: to_f64(t),
            index: N - 1,
        });
    }
    match (0..n).find(|&i| f[i] != y[n + i]) {
        Some(i) => Err(IntegrateError::NotMechanical {
            t: to_f64(t),
            index: i,
        }),
        None => Ok(()),
    }
}

/// The extrapolation table of one step of size `hs` from `(t, y)` (ending at `t_new`):
/// `(T₃₃, T₃₂)`, or `None` if a solve failed.
#[allow(clippy::too_many_arguments)]
fn extrapolate<T: Real, const N: usize, S: Dynamics<T, N>>(
    sys: &S,
    t: T,
    y: &SVector<T, N>,
    hs: T,
    t_new: T,
    p: i32,
    tol: &Tolerances<T, N>,
    evals: &mut u64,
) -> Option<(SVector<T, N>, SVector<T, N>)> {
    let mut sub = |m: usize| -> Option<SVector<T, N>> {
        let hm = hs / lit::<T>(m as f64);
        let mut yk = *y;
        for k in 1..=m {
            let tk = if k == m {
                t_new
            } else {
                t + hs * lit::<T>(k as f64 / m as f64)
            };
            yk = backward_euler(sys, tk, &yk, hm, p, tol, evals)?;
        }
        Some(yk)
    };
    let t11 = sub(1)?;
    let t21 = sub(2)?;
    let t31 = sub(3)?;
    let t22 = t21 * lit::<T>(2.0) - t11;
    let t32 = t31 * lit::<T>(3.0) - t21 * lit::<T>(2.0);
    let t33 = t32 + (t32 - t22) * lit::<T>(0.5);
    Some((t33, t32))
}

/// One backward Euler step of size `h` ending at `t_new` from `y = (q, v)`: solves
/// `v₊ = v + h·a(t_new, q + h·v₊, v₊)` (see the [module docs](self#the-step)).
fn backward_euler<T: Real, const N: usize, S: Dynamics<T, N>>(
    sys: &S,
    t_new: T,
    y: &SVector<T, N>,
    h: T,
    p: i32,
    tol: &Tolerances<T, N>,
    evals: &mut u64,
) -> Option<SVector<T, N>> {
    let n = N / 2;
    let mut z = *y;
    for i in 0..n {
        z[i] = y[i] + h * y[n + i];
    }
    let mut dz = SVector::<T, N>::zeros();
    let frac = lit::<T>(SOLVE_FRACTION);
    for _ in 0..MAX_SWEEPS {
        let mut converged = true;
        for i in 0..n {
            let (j, vi) = (n + i, y[n + i]);
            // The accuracy of v₊ᵢ: on vᵢ itself and through h·v₊ᵢ on qᵢ.
            let sc_v = tol.atol[j] + tol.rtol[j] * vi.abs();
            let sc_q = (tol.atol[i] + tol.rtol[i] * y[i].abs()) / h;
            let wtol = frac * sc_v.min(sc_q);
            let w0 = z[j];
            let mut phi = |w: T| -> T {
                z[j] = w;
                z[i] = y[i] + h * w;
                sys.rhs(t_new, &z, &mut dz);
                *evals += 1;
                w - vi - h * dz[j]
            };
            let w = solve_monotone(&mut phi, w0, p, wtol)?;
            z[j] = w;
            z[i] = y[i] + h * w;
            if (w - w0).abs() > wtol {
                converged = false;
            }
        }
        if n <= 1 || converged {
            return Some(z);
        }
    }
    None
}

/// The root of `φ`, increasing (see the [module docs](self#the-step)), from the guess `w0`,
/// to `wtol`: bracket from the explicit-Euler point, then Brent's method in `u`,
/// `w = sgn(u)|u|^p`.
fn solve_monotone<T: Real>(phi: &mut impl FnMut(T) -> T, w0: T, p: i32, wtol: T) -> Option<T> {
    let fa = phi(w0);
    if !fa.is_finite() {
        return None;
    }
    if fa == T::zero() {
        return Some(w0);
    }
    let mut step = -fa;
    let mut found = None;
    for _ in 0..MAX_WIDEN {
        let wb = w0 + step;
        let fb = phi(wb);
        if !fb.is_finite() {
            return None;
        }
        if fb == T::zero() {
            return Some(wb);
        }
        if (fb > T::zero()) != (fa > T::zero()) {
            found = Some((wb, fb));
            break;
        }
        step *= lit::<T>(4.0);
    }
    let (wb, fb) = found?;
    let (ua, ub) = (to_u(w0, p), to_u(wb, p));
    // |dw/du| = p|u|^{p−1} ≤ p·max(|ua|, |ub|)^{p−1} on the bracket.
    let umax = ua.abs().max(ub.abs());
    let slope = lit::<T>(f64::from(p)) * umax.powi(p - 1);
    let xtol = if slope > T::zero() {
        (wtol / slope).min(umax)
    } else {
        T::zero()
    };
    let u = brent(|u| phi(from_u(u, p)), ua, ub, fa, fb, xtol, MAX_BRENT).ok()?;
    Some(from_u(u, p))
}

/// `u = sgn(w)|w|^{1/p}`.
#[inline(always)]
fn to_u<T: Real>(w: T, p: i32) -> T {
    if p == 1 {
        w
    } else {
        w.signum() * w.abs().powf(T::one() / lit::<T>(f64::from(p)))
    }
}

/// `w = sgn(u)|u|^p`.
#[inline(always)]
fn from_u<T: Real>(u: T, p: i32) -> T {
    if p == 1 {
        u
    } else {
        u.signum() * u.abs().powi(p)
    }
}

/// Hand-overs of a [`CuspSwitch`] (cumulative since construction).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SwitchCounts {
    /// Hand-overs from the explicit stepper to the implicit step.
    pub to_implicit: u64,
    /// Hand-overs back.
    pub to_explicit: u64,
    /// Accepted steps of the implicit step.
    pub implicit_steps: u64,
    /// Stiffness probes (one evaluation each).
    pub probes: u64,
}

/// An explicit stepper `E` with the implicit cusp step ([`CuspImplicit`]) where the
/// declared cusp makes `E` stiffness-bound (see the [module docs](self#the-switch) for the
/// detection).
///
/// ```
/// use nonsmooth::drive::Simulation;
/// use nonsmooth::excite::Harmonic;
/// use nonsmooth::force::{HertzContact, LinearSpring};
/// use nonsmooth::integrate::{CuspSwitch, Tolerances};
/// use nonsmooth::model::Oscillator;
/// use nalgebra::Vector2;
///
/// // A spring pressing the body onto a stop at x = −0.01 (rest position 0), the contact
/// // damped by b·δ^{3/2}·sgn(ẋ)|ẋ|^{1/4} (exact, no regularization: a cusp at ẋ = 0).
/// let contact = HertzContact::new(-0.01, 1e6)?.with_damping(1.0, 1.5, 0.25)?;
/// let osc = Oscillator::new(1.0, (LinearSpring::new(100.0)?, contact), Harmonic::sine(0.5, 8.0)?)?;
/// let x0 = osc.static_equilibrium(-0.01, 0.0)?; // pressed about 1e-4 into the stop
/// let rtol = 1e-8;
/// let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?;
/// let mut sim = Simulation::new(osc, CuspSwitch::dopri5(tol, 1e-6)?);
/// // From rest on the stop: the forcing is too weak to lift the body off, and its creep is
/// // stepped implicitly.
/// let out = sim.run(0.0, Vector2::new(x0, 0.0), 0.3, &mut ())?;
/// assert!(sim.stepper().counts().implicit_steps > 0);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct CuspSwitch<T: Real, const N: usize, E: Stepper<T, N>> {
    explicit: E,
    implicit: CuspImplicit<T, N>,
    band: T,
    on_implicit: bool,
    stiff_run: u32,
    soft_run: u32,
    /// Explicit steps in a row that an undeclared cusp holds stiffness-bound.
    stall_run: u32,
    t: T,
    y: SVector<T, N>,
    dense: CuspSwitchDense<T, N, E::Dense>,
    stats: Stats,
    own_evals: u64,
    counts: SwitchCounts,
}

/// Explicit steps in a row, on a system that declares no cusp, held stiffness-bound by one
/// before the run stops with [`IntegrateError::UndeclaredCusp`].
const STALL_RUN: u32 = 50;

/// Explicit steps in a row with `h·ρ > 1/2` before the hand-over to the implicit step.
const ENTER_RUN: u32 = 3;
/// Implicit steps in a row with `h·ρ < 0.15` before the hand-over back.
const LEAVE_RUN: u32 = 2;
const ENTER_HRHO: f64 = 0.5;
const LEAVE_HRHO: f64 = 0.15;

/// The dense output of a [`CuspSwitch`] step: the explicit stepper's or the implicit
/// step's, whichever took it.
#[derive(Debug, Clone)]
pub struct CuspSwitchDense<T: Real, const N: usize, ED> {
    on_implicit: bool,
    explicit: ED,
    implicit: CuspDense<T, N>,
}

impl<T: Real, const N: usize, ED: DenseOutput<T, N>> DenseOutput<T, N>
    for CuspSwitchDense<T, N, ED>
{
    fn span(&self) -> (T, T) {
        if self.on_implicit {
            self.implicit.span()
        } else {
            self.explicit.span()
        }
    }

    fn endpoints(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        if self.on_implicit {
            self.implicit.endpoints()
        } else {
            self.explicit.endpoints()
        }
    }

    fn end_derivatives(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        if self.on_implicit {
            self.implicit.end_derivatives()
        } else {
            self.explicit.end_derivatives()
        }
    }

    #[inline]
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, N>) {
        if self.on_implicit {
            self.implicit.interpolate_unchecked(t, out)
        } else {
            self.explicit.interpolate_unchecked(t, out)
        }
    }
}

impl<T: Real, const N: usize, E: Stepper<T, N>> CuspSwitch<T, N, E>
where
    E::Dense: Clone,
{
    /// The explicit stepper `explicit`, the implicit step `implicit`, and the band
    /// `|v| < v_band` in which a velocity's cusp is probed for stiffness (10⁻⁶ m/s in
    /// `examples/exact_law.rs`, where the creep in contact runs at `|ẋ| ≪ 10⁻⁸` m/s).
    ///
    /// # Errors
    /// [`ParameterError`] unless `v_band` is finite and > 0.
    pub fn new(
        explicit: E,
        implicit: CuspImplicit<T, N>,
        v_band: T,
    ) -> Result<Self, ParameterError> {
        positive("v_band", v_band)?;
        let dense = CuspSwitchDense {
            on_implicit: false,
            explicit: explicit.dense().clone(),
            implicit: *implicit.dense(),
        };
        Ok(Self {
            explicit,
            implicit,
            band: v_band,
            on_implicit: false,
            stiff_run: 0,
            soft_run: 0,
            stall_run: 0,
            t: T::zero(),
            y: SVector::zeros(),
            dense,
            stats: Stats::default(),
            own_evals: 0,
            counts: SwitchCounts::default(),
        })
    }

    /// The explicit stepper.
    pub fn explicit(&self) -> &E {
        &self.explicit
    }

    /// The implicit step.
    pub fn implicit(&self) -> &CuspImplicit<T, N> {
        &self.implicit
    }

    /// Hand-overs and implicit steps so far.
    pub fn counts(&self) -> SwitchCounts {
        self.counts
    }

    /// Whether the next step is the implicit step's.
    pub fn is_implicit(&self) -> bool {
        self.on_implicit
    }

    fn sync_stats(&mut self) {
        let events = self.stats.events;
        let mut s = *self.explicit.stats();
        s += self.implicit.stats();
        s.rhs_evals += self.own_evals;
        s.events = events;
        self.stats = s;
    }

    /// `h·ρ` at the end of the step just taken (the largest over the velocities in the
    /// band, `∞` at `v = 0`), or `None` if no velocity is in the band or the system
    /// declares no cusp.
    fn stiffness<S: Dynamics<T, N>, D: DenseOutput<T, N>>(
        &mut self,
        sys: &S,
        dense: &D,
    ) -> Option<T> {
        sys.cusp_exponent()?;
        let n = N / 2;
        let (t0, t1) = dense.span();
        let h = t1 - t0;
        let y = *dense.endpoints().1;
        let f = *dense.end_derivatives().1;
        let mut worst: Option<T> = None;
        for i in 0..n {
            let v = y[n + i];
            if !(v.abs() < self.band) {
                continue;
            }
            let hrho = if v == T::zero() {
                T::max_value().unwrap_or(lit(1e300))
            } else {
                let mut probe = y;
                let dv = v * lit(0.5);
                probe[n + i] = v - dv;
                let mut fp = SVector::zeros();
                sys.rhs(t1, &probe, &mut fp);
                self.own_evals += 1;
                self.counts.probes += 1;
                h * ((f[n + i] - fp[n + i]) / dv).abs()
            };
            if hrho >= T::zero() {
                worst = Some(worst.map_or(hrho, |w: T| w.max(hrho)));
            }
        }
        worst
    }
}

impl<T: Real, const N: usize> CuspSwitch<T, N, super::Dopri5<T, N>> {
    /// DOPRI5 and the implicit step with the same tolerances `tol`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `v_band` is finite and > 0, or if a tolerance is invalid.
    pub fn dopri5(tol: Tolerances<T, N>, v_band: T) -> Result<Self, ParameterError> {
        tol.validate()?;
        Self::new(super::Dopri5::new(tol), CuspImplicit::new(tol), v_band)
    }
}

impl<T: Real, const N: usize, E: Stepper<T, N>> Stepper<T, N> for CuspSwitch<T, N, E>
where
    E::Dense: Clone,
{
    type Dense = CuspSwitchDense<T, N, E::Dense>;

    fn reset_state(&mut self, t: T, y: SVector<T, N>) {
        self.t = t;
        self.y = y;
        self.explicit.reset_state(t, y);
        self.implicit.reset_state(t, y);
    }

    fn start(&mut self, t: T, y: SVector<T, N>) {
        self.t = t;
        self.y = y;
        self.explicit.start(t, y);
        self.implicit.start(t, y);
    }

    fn step<S: Dynamics<T, N>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError> {
        let r = if self.on_implicit {
            self.implicit_step(sys, t_limit)
        } else {
            self.explicit_step(sys, t_limit)
        };
        self.sync_stats();
        r
    }

    fn current(&self) -> (T, &SVector<T, N>) {
        (self.t, &self.y)
    }

    fn dense(&self) -> &Self::Dense {
        &self.dense
    }

    fn stats(&self) -> &Stats {
        &self.stats
    }

    fn stats_mut(&mut self) -> &mut Stats {
        &mut self.stats
    }

    fn order(&self) -> u8 {
        self.explicit.order()
    }

    fn check(&self) -> Result<(), IntegrateError> {
        self.explicit.check()?;
        self.implicit.check()
    }

    fn max_step(&self) -> Option<T> {
        self.explicit.max_step()
    }
}

impl<T: Real, const N: usize, E: Stepper<T, N>> CuspSwitch<T, N, E>
where
    E::Dense: Clone,
{
    fn explicit_step<S: Dynamics<T, N>>(
        &mut self,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        self.explicit.step(sys, t_limit)?;
        let (t, y) = self.explicit.current();
        (self.t, self.y) = (t, *y);
        self.dense.explicit = self.explicit.dense().clone();
        self.dense.on_implicit = false;
        let dense = self.dense.explicit.clone();
        if sys.cusp_exponent().is_none() {
            return self.undeclared_cusp(sys, &dense);
        }
        let stiff = self
            .stiffness(sys, &dense)
            .is_some_and(|hr| hr > lit(ENTER_HRHO));
        self.stiff_run = if stiff { self.stiff_run + 1 } else { 0 };
        if self.stiff_run >= ENTER_RUN {
            let (t0, t1) = dense.span();
            self.stiff_run = 0;
            self.soft_run = 0;
            self.on_implicit = true;
            self.counts.to_implicit += 1;
            self.implicit.reset_state(self.t, self.y);
            self.implicit.set_proposed_step(t1 - t0);
        }
        Ok(())
    }

    fn implicit_step<S: Dynamics<T, N>>(
        &mut self,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        if let Err(e) = self.implicit.step(sys, t_limit) {
            // Not a system the implicit step can take (or a failed step): the explicit
            // stepper goes on from the same state.
            if !(t_limit > self.t) {
                return Err(e);
            }
            self.on_implicit = false;
            self.stiff_run = 0;
            self.counts.to_explicit += 1;
            self.explicit.reset_state(self.t, self.y);
            return self.explicit_step(sys, t_limit);
        }
        self.counts.implicit_steps += 1;
        let (t, y) = self.implicit.current();
        (self.t, self.y) = (t, *y);
        self.dense.implicit = *self.implicit.dense();
        self.dense.on_implicit = true;
        let dense = self.dense.implicit;
        let soft = self
            .stiffness(sys, &dense)
            .is_none_or(|hr| hr < lit(LEAVE_HRHO));
        self.soft_run = if soft { self.soft_run + 1 } else { 0 };
        let outside = dense_outside_band(&dense, self.band);
        if outside || self.soft_run >= LEAVE_RUN {
            self.soft_run = 0;
            self.on_implicit = false;
            self.counts.to_explicit += 1;
            self.explicit.reset_state(self.t, self.y);
        }
        Ok(())
    }
}

impl<T: Real, const N: usize, E: Stepper<T, N>> CuspSwitch<T, N, E>
where
    E::Dense: Clone,
{
    /// On a system that declares no cusp: whether the explicit step just taken was held
    /// stiffness-bound by a cusp in a velocity of the band, and after [`STALL_RUN`] such
    /// steps in a row, [`IntegrateError::UndeclaredCusp`]. A step counts when, for some
    /// `0 < |v_i| < v_band`, the secant rates `ρ₁` over `[v/2, v]` and `ρ₂` over
    /// `[v/4, v/2]` give `h·ρ₁ > 1/2` (stiffness-bound, as the hand-over's test) and
    /// `ρ₂ > 1.1·ρ₁`: the rate grows as the velocity shrinks, `ρ₂/ρ₁ = 2^{1−q}` for a power
    /// `|v|^q` (`q < 0.86`), where a linear damping (`q = 1`) or a smooth law keeps it
    /// (two extra evaluations per step in the band).
    fn undeclared_cusp<S: Dynamics<T, N>, D: DenseOutput<T, N>>(
        &mut self,
        sys: &S,
        dense: &D,
    ) -> Result<(), IntegrateError> {
        let n = N / 2;
        let (t0, t1) = dense.span();
        let h = t1 - t0;
        let y = *dense.endpoints().1;
        let f = *dense.end_derivatives().1;
        let mut found = None;
        for i in 0..n {
            let v = y[n + i];
            if !(v.abs() < self.band) || v == T::zero() {
                continue;
            }
            let mut at = |w: T| {
                let mut probe = y;
                probe[n + i] = w;
                let mut fp = SVector::zeros();
                sys.rhs(t1, &probe, &mut fp);
                self.own_evals += 1;
                self.counts.probes += 1;
                fp[n + i]
            };
            let (half, quarter) = (v * lit(0.5), v * lit(0.25));
            let (a2, a4) = (at(half), at(quarter));
            let rho1 = ((f[n + i] - a2) / half).abs();
            let rho2 = ((a2 - a4) / quarter).abs();
            if h * rho1 > lit(ENTER_HRHO) && rho2 > lit::<T>(1.1) * rho1 {
                let q = T::one() - (rho2 / rho1).log2();
                found = Some((i, v, q));
                break;
            }
        }
        self.stall_run = if found.is_some() {
            self.stall_run + 1
        } else {
            0
        };
        match found {
            Some((index, v, q)) if self.stall_run >= STALL_RUN => {
                Err(IntegrateError::UndeclaredCusp {
                    t: to_f64(t1),
                    index,
                    velocity: to_f64(v),
                    exponent: to_f64(q),
                })
            }
            _ => Ok(()),
        }
    }
}

/// `true` if no velocity of the step's end is in the band.
fn dense_outside_band<T: Real, const N: usize, D: DenseOutput<T, N>>(d: &D, band: T) -> bool {
    let n = N / 2;
    let y = d.endpoints().1;
    (0..n).all(|i| !(y[n + i].abs() < band))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_scale_round_trip() {
        for &w in &[0.0, 1e-300, -3.5e-17, 2.0, -7.25] {
            let u = to_u(w, 6);
            let back: f64 = from_u(u, 6);
            // powf(1/p) then powi(p): p roundings of the root, and the rounding `δ` of
            // the exponent 1/p, which moves the result by `δ·|ln w|` relatively.
            let bound = (w.abs().ln().abs() + 16.0 * 6.0) * f64::EPSILON * w.abs();
            assert!(
                w == 0.0 && back == 0.0 || (back - w).abs() <= bound,
                "{w:e} -> {back:e}"
            );
        }
    }

    #[test]
    fn monotone_solve_finds_zero_root() {
        // φ(w) = w + sgn(w)|w|^{0.2} has its root at 0.
        let mut phi = |w: f64| w + w.signum() * w.abs().powf(0.2);
        let r = solve_monotone(&mut phi, 1.0, 5, 1e-30).unwrap();
        assert!(r.abs() < 1e-30, "{r}");
    }
}
