//! The vector field and the event set of one mode: a region's field, or the sliding field
//! by Utkin's equivalent control; the surfaces' events, the exit event `min(α, 1 − α)`;
//! the normal rates, the tangency test, the projection onto a surface and the Jacobians.

use nalgebra::{SMatrix, SVector};

use super::error::{FilippovError, Result};
use super::system::{Filippov, Mode, Region};
use crate::drive::modes::rate_along_flow;
use crate::event::{Direction, EventSet};
use crate::scalar::{lit, to_f64};
use crate::{Dynamics, Real};

/// The largest `|H|`, relative to the surface's [`scale`], that counts as on the surface
/// (the event value is zero there, so that the side comes from the rate): a few ulps.
pub(crate) fn band<T: Real>() -> T {
    lit::<T>(16.0) * T::default_epsilon()
}

/// The scale of `H_i` at `x`: `max(1, ‖∇H‖∞·‖x‖∞)`, the size of the rounding in `H`
/// relative to which drift and coincidence are measured.
pub(crate) fn scale<T: Real, const N: usize>(grad: &SVector<T, N>, x: &SVector<T, N>) -> T {
    (grad.amax() * x.amax()).max(T::one())
}

/// The field and the events of one mode of a Filippov system.
#[derive(Debug)]
pub(crate) struct ModeField<'a, Sys, const S: usize> {
    pub(crate) sys: &'a Sys,
    pub(crate) mode: Mode<S>,
    /// Interior samples of the exit event per step.
    pub(crate) exit_samples: usize,
}

impl<Sys, const S: usize> Clone for ModeField<'_, Sys, S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<Sys, const S: usize> Copy for ModeField<'_, Sys, S> {}

/// What both fields do at a point of surface `i`: the normal rates
/// `h± = ∇H·F± + ∂H/∂t` and the fields.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rates<T: Real, const N: usize> {
    pub(crate) grad: SVector<T, N>,
    /// `∂H/∂t`.
    pub(crate) h_t: T,
    pub(crate) f_minus: SVector<T, N>,
    pub(crate) f_plus: SVector<T, N>,
    pub(crate) h_minus: T,
    pub(crate) h_plus: T,
}

impl<T: Real, const N: usize> Rates<T, N> {
    /// Utkin's equivalent control `α = h₋/(h₋ − h₊)`, for which
    /// `∇H·((1−α)F₋ + αF₊) + ∂H/∂t = 0`; `−1` (outside `[0, 1]`, so that the exit event
    /// fires) where the fields do not bracket the surface (`h₋ ≤ h₊`).
    pub(crate) fn alpha(&self) -> T {
        let den = self.h_minus - self.h_plus;
        if den > T::zero() {
            self.h_minus / den
        } else {
            -T::one()
        }
    }

    /// The field of `side`.
    pub(crate) fn field(&self, side: Region) -> &SVector<T, N> {
        match side {
            Region::Minus => &self.f_minus,
            Region::Plus => &self.f_plus,
        }
    }

    /// The normal rate of `side`.
    pub(crate) fn rate(&self, side: Region) -> T {
        match side {
            Region::Minus => self.h_minus,
            Region::Plus => self.h_plus,
        }
    }
}

/// `sides` with surface `i` on `side`.
pub(crate) fn with_side<const S: usize>(
    sides: &[Region; S],
    i: usize,
    side: Region,
) -> [Region; S] {
    let mut s = *sides;
    s[i] = side;
    s
}

/// The normal rates of both fields at `(t, x)` on surface `i`, the other surfaces on
/// `sides`.
pub(crate) fn rates<T, const N: usize, const S: usize, Sys>(
    sys: &Sys,
    i: usize,
    sides: &[Region; S],
    t: T,
    x: &SVector<T, N>,
) -> Rates<T, N>
where
    T: Real,
    Sys: Filippov<T, N, S>,
{
    let grad = sys.gradient(i, t, x);
    let h_t = sys.surface_time_rate(i, t, x);
    let mut f_minus = SVector::zeros();
    let mut f_plus = SVector::zeros();
    sys.field(&with_side(sides, i, Region::Minus), t, x, &mut f_minus);
    sys.field(&with_side(sides, i, Region::Plus), t, x, &mut f_plus);
    Rates {
        grad,
        h_t,
        h_minus: grad.dot(&f_minus) + h_t,
        h_plus: grad.dot(&f_plus) + h_t,
        f_minus,
        f_plus,
    }
}

/// [`rates`] where a mode is decided (an arrival, an exit, a start on the surface): every
/// quantity the decision reads must be finite. The sliding field evaluates the rates in
/// every stage without this check; a non-finite value there reaches the stepper, or the
/// next decision.
///
/// # Errors
/// [`FilippovError::NonFinite`] naming the first non-finite one of `∇H` (its first such
/// component), `∂H/∂t`, `h₋` and `h₊` (the last two, with `∇H` and `∂H/∂t` finite: a
/// field that is not).
pub(crate) fn rates_checked<T, const N: usize, const S: usize, Sys>(
    sys: &Sys,
    i: usize,
    sides: &[Region; S],
    t: T,
    x: &SVector<T, N>,
) -> Result<Rates<T, N>>
where
    T: Real,
    Sys: Filippov<T, N, S>,
{
    let r = rates(sys, i, sides, t, x);
    let bad = |quantity, value: T| FilippovError::NonFinite {
        t: to_f64(t),
        surface: i,
        quantity,
        value: to_f64(value),
    };
    if let Some(g) = r.grad.iter().find(|g| !g.is_finite()) {
        return Err(bad("the gradient ∇H", *g));
    }
    if !r.h_t.is_finite() {
        return Err(bad("the time rate ∂H/∂t", r.h_t));
    }
    if !r.h_minus.is_finite() {
        return Err(bad("the normal rate ∇H·F₋ + ∂H/∂t", r.h_minus));
    }
    if !r.h_plus.is_finite() {
        return Err(bad("the normal rate ∇H·F₊ + ∂H/∂t", r.h_plus));
    }
    Ok(r)
}

/// The sign with which the field `F` of `side` moves the state off surface `i` from
/// `(t, x)`, with `h = ∇H·F + ∂H/∂t` its normal rate (`rates`, finite):
/// 1. **transversal**: `sgn h` where `|h| > tangency·‖∇H‖·‖F‖`;
/// 2. **tangency** (`|h|` within that band): the sign of the second-order rate
///    `L²_F H = d/dt (∇H·F + ∂H/∂t)` along `F` (a central difference over `t₊ − t₋`), where
///    `|L²_F H| > ρ`, its rounding (below);
/// 3. **inconclusive** second order (zero, or within its rounding): `sgn h` — a state that
///    reached the surface at the rate `h ≠ 0` goes on that way, as the flow of `F` does
///    when nothing of second order turns it back (a slow crossing, not a graze); 0 only if
///    `h = 0` as well.
///
/// The rounding of the central difference is that of the two rates it is the difference
/// of, over its span:
/// $$ \rho = \frac{64\,\varepsilon\,(\lVert\nabla H\rVert\lVert F\rVert
///    + |\partial_t H|)}{t_+ - t_-}. $$
///
/// A second-order rate above its rounding that opposes `h` decides (rule 2): inside the
/// tangency band the flow of `F` goes past the surface by at most `h²/(2|L²_F H|)` before
/// it turns back, and the tangency setting is the size of rate below which that touch is
/// taken for a graze. One within its rounding says nothing about the turn, and with it the
/// state would be held on the wrong side of the surface for as long as `F` takes to bring
/// it back (forever for a constant field), so it does not decide (rule 3).
///
/// # Errors
/// [`FilippovError::NonFinite`] if the second-order rate is not finite (a field or
/// gradient that is not, next to the point).
pub(crate) fn departure<T, const N: usize, const S: usize, Sys>(
    sys: &Sys,
    i: usize,
    sides: &[Region; S],
    side: Region,
    (t, x): (T, &SVector<T, N>),
    rates: &Rates<T, N>,
    tangency: T,
) -> Result<i8>
where
    T: Real,
    Sys: Filippov<T, N, S>,
{
    let sign = |v: T| -> i8 {
        if v > T::zero() {
            1
        } else if v < T::zero() {
            -1
        } else {
            0
        }
    };
    let h = rates.rate(side);
    let f = rates.field(side);
    let size = rates.grad.norm() * f.norm();
    if h.abs() > tangency * size {
        return Ok(sign(h));
    }
    let region = with_side(sides, i, side);
    let g = |t: T, y: &SVector<T, N>| {
        let mut fy = SVector::zeros();
        sys.field(&region, t, y, &mut fy);
        sys.gradient(i, t, y).dot(&fy) + sys.surface_time_rate(i, t, y)
    };
    let scale = sys.time_scale(t);
    let second = rate_along_flow(g, t, x, f, scale);
    if !second.is_finite() {
        return Err(FilippovError::NonFinite {
            t: to_f64(t),
            surface: i,
            quantity: "the second-order rate L²H (along the field, by central differences)",
            value: to_f64(second),
        });
    }
    let (up, down) = crate::excite::difference_points(t, scale);
    let rounding = lit::<T>(64.0) * T::default_epsilon() * (size + rates.h_t.abs()) / (up - down);
    Ok(if second.abs() > rounding {
        sign(second)
    } else {
        sign(h)
    })
}

/// Moves `x` onto `H_i = 0` along `∇H` (Newton steps `x ← x − H ∇H/‖∇H‖²`) until `|H|` is
/// within the rounding [`band`] of its scale. Returns the final `|H|`.
pub(crate) fn project<T, const N: usize, const S: usize, Sys>(
    sys: &Sys,
    i: usize,
    t: T,
    x: &mut SVector<T, N>,
) -> T
where
    T: Real,
    Sys: Filippov<T, N, S>,
{
    let mut h = sys.surface(i, t, x);
    for _ in 0..4 {
        let grad = sys.gradient(i, t, x);
        let gg = grad.norm_squared();
        if !(h.abs() > band::<T>() * scale(&grad, x)) || !(gg > T::zero()) {
            break;
        }
        *x -= grad * (h / gg);
        h = sys.surface(i, t, x);
    }
    h.abs()
}

impl<Sys, const S: usize> ModeField<'_, Sys, S> {
    /// The field of the mode at `(t, x)`.
    #[inline(always)]
    pub(crate) fn eval<T: Real, const N: usize>(
        &self,
        t: T,
        x: &SVector<T, N>,
        dx: &mut SVector<T, N>,
    ) where
        Sys: Filippov<T, N, S>,
    {
        match self.mode.sliding {
            None => self.sys.field(&self.mode.sides, t, x, dx),
            Some(i) => {
                let r = rates(self.sys, i, &self.mode.sides, t, x);
                let a = r.alpha();
                *dx = r.f_minus + (r.f_plus - r.f_minus) * a;
            }
        }
    }

    /// `∂F/∂x` of the mode: the region's (given or by central differences), or, sliding,
    /// `J₋ + α(J₊ − J₋) + (F₊ − F₋)∇αᵀ` with
    /// `∇α = (h₋∇h₊ − h₊∇h₋)/(h₋ − h₊)²`, `∇h± = J±ᵀ∇H + (∇²H F± + ∂_t∇H)` (the last term
    /// by a central difference of the gradient along `(1, F±)`; zero for a linear `H`).
    pub(crate) fn jacobian<T: Real, const N: usize>(
        &self,
        t: T,
        x: &SVector<T, N>,
    ) -> SMatrix<T, N, N>
    where
        Sys: Filippov<T, N, S>,
    {
        match self.mode.sliding {
            None => region_jacobian(self.sys, &self.mode.sides, t, x),
            Some(i) => {
                let sides = &self.mode.sides;
                let r = rates(self.sys, i, sides, t, x);
                let jm = region_jacobian(self.sys, &with_side(sides, i, Region::Minus), t, x);
                let jp = region_jacobian(self.sys, &with_side(sides, i, Region::Plus), t, x);
                let curv = |f: &SVector<T, N>| {
                    let (up, down) = crate::excite::difference_points(t, self.sys.time_scale(t));
                    let (hu, hd) = (up - t, t - down);
                    (self.sys.gradient(i, up, &(x + f * hu))
                        - self.sys.gradient(i, down, &(x - f * hd)))
                        / (hu + hd)
                };
                let dh_m = jm.transpose() * r.grad + curv(&r.f_minus);
                let dh_p = jp.transpose() * r.grad + curv(&r.f_plus);
                let den = r.h_minus - r.h_plus;
                let a = r.alpha();
                let grad_a = (dh_p * r.h_minus - dh_m * r.h_plus) / (den * den);
                jm + (jp - jm) * a + (r.f_plus - r.f_minus) * grad_a.transpose()
            }
        }
    }
}

/// `∂F_σ/∂x` of a region: given by the system, else by central differences.
pub(crate) fn region_jacobian<T, const N: usize, const S: usize, Sys>(
    sys: &Sys,
    sides: &[Region; S],
    t: T,
    x: &SVector<T, N>,
) -> SMatrix<T, N, N>
where
    T: Real,
    Sys: Filippov<T, N, S>,
{
    if let Some(j) = sys.field_jacobian(sides, t, x) {
        return j;
    }
    let cbrt_eps = crate::scalar::epsilon::<T>().powf(lit(1.0 / 3.0));
    let mut j = SMatrix::<T, N, N>::zeros();
    let (mut fu, mut fd) = (SVector::zeros(), SVector::zeros());
    for k in 0..N {
        let h = cbrt_eps * x[k].abs().max(T::one());
        let mut xu = *x;
        let mut xd = *x;
        xu[k] += h;
        xd[k] -= h;
        sys.field(sides, t, &xu, &mut fu);
        sys.field(sides, t, &xd, &mut fd);
        let col = (fu - fd) / (xu[k] - xd[k]);
        j.set_column(k, &col);
    }
    j
}

impl<T: Real, const N: usize, const S: usize, Sys: Filippov<T, N, S>> Dynamics<T, N>
    for ModeField<'_, Sys, S>
{
    #[inline(always)]
    fn rhs(&self, t: T, x: &SVector<T, N>, dx: &mut SVector<T, N>) {
        self.eval(t, x, dx)
    }

    fn time_scale(&self, t: T) -> Option<T> {
        self.sys.time_scale(t)
    }
}

/// Events `0..S`: the surfaces (a crossing towards the far side of the mode's side; the
/// surface slid on never fires); event `S`: the sliding exit `min(α, 1 − α)` falling
/// through zero (never fires in a region). Every event is terminal: the run decides the
/// next mode there.
impl<T: Real, const N: usize, const S: usize, Sys: Filippov<T, N, S>> EventSet<T, N>
    for ModeField<'_, Sys, S>
{
    const LEN: usize = S + 1;

    #[inline(always)]
    fn value(&self, i: usize, t: T, y: &SVector<T, N>) -> T {
        if i == S {
            return match self.mode.sliding {
                Some(k) => {
                    let a = rates(self.sys, k, &self.mode.sides, t, y).alpha();
                    a.min(T::one() - a)
                }
                None => T::one(),
            };
        }
        if self.mode.sliding == Some(i) {
            return T::one();
        }
        let h = self.sys.surface(i, t, y);
        // Within rounding of the surface: on the mode's own side (not on the side of the
        // rounding error of a projected state). A tiny value of the mode's sign rather
        // than zero, so that a state that leaves the surface into its region and comes
        // back within one step (a crossing close to a tangency of the far field) is
        // located where it returns through the band, not at the start of the mode.
        if h.abs() <= band::<T>() * scale(&self.sys.gradient(i, t, y), y) {
            self.mode.sides[i].sign::<T>() * T::default_epsilon() * T::default_epsilon()
        } else {
            h
        }
    }

    #[inline(always)]
    fn rate(&self, i: usize, t: T, y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T> {
        if i == S || self.mode.sliding == Some(i) {
            return None;
        }
        Some(self.sys.gradient(i, t, y).dot(dy) + self.sys.surface_time_rate(i, t, y))
    }

    fn direction(&self, i: usize) -> Direction {
        if i == S {
            Direction::Falling
        } else {
            match self.mode.sides[i] {
                Region::Minus => Direction::Rising,
                Region::Plus => Direction::Falling,
            }
        }
    }

    fn is_terminal(&self, _i: usize) -> bool {
        true
    }

    fn resets(&self, _i: usize) -> bool {
        false
    }

    fn apply_reset(&self, _i: usize, _t: T, _y: &mut SVector<T, N>) {}

    fn interior_samples(&self, i: usize) -> usize {
        if i == S && self.mode.sliding.is_some() {
            self.exit_samples
        } else {
            0
        }
    }
}
