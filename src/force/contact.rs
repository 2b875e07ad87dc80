//! Compliant contact: the generalized Hertz law with nonlinear damping.

use crate::lanes::math::pow_masked;
use crate::lanes::{LaneMath, Lanes, mask};
use crate::scalar::{Exponent, lit};
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative, positive};
use crate::{ForceLaw, Real};

/// Which side of the stop the body penetrates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Side {
    /// The stop limits motion from above: contact when `x ≥ x_I`, the force pushes towards
    /// smaller `x` (positive on the left-hand side).
    Upper,
    /// The stop limits motion from below: contact when `x ≤ x_I`, the force pushes towards
    /// larger `x`.
    Lower,
}

/// The generalized Hertz contact law with nonlinear damping.
///
/// Deserialization (feature `serde`) applies the constructor's and the builders' checks
/// (the value is rebuilt from its parameters).
///
/// # Model
/// With the penetration `δ = x − x_I` and its rate `δ̇ = ẋ` (for [`Side::Upper`]; mirrored for
/// [`Side::Lower`]):
/// $$f(\delta, \dot\delta) = \delta^{n_1} + b\,\delta^{n_2}\,\mathrm{sgn}(\dot\delta)\,|\dot\delta|^{n_3},
///   \qquad F = \begin{cases} k_I\,f & \delta \ge 0 \text{ and } f \ge 0,\\ 0 & \text{otherwise.}\end{cases}$$
/// The force is zero when separated, never adhesive (`f < 0` during fast separation gives
/// zero force rather than a pull) and continuous at contact onset (`f(0, ·) = 0`).
///
/// ## The `|δ̇|^{n3}` singularity and its regularization
/// For `n3 < 1` the damping term is not Lipschitz at `δ̇ = 0`: its slope is infinite there.
/// A body resting in contact (for instance at rest on a preloaded stop) then obeys `m·v̇ ≈ −C·|v|^{n3}`
/// near `v = 0`, which relaxes in finite time and forces an explicit integrator to crawl.
/// [`with_rate_regularization`](Self::with_rate_regularization) replaces
/// `sgn(δ̇)|δ̇|^{n3}` by
/// $$\dot\delta\,(\dot\delta^2+\eta^2)^{(n_3-1)/2},$$
/// equal to the exact term for `|δ̇| ≫ η` and linear with slope `η^{n3−1}` inside `|δ̇| ≲ η`.
/// With `η = 0` (the default) the law is exact.
///
/// With `n3 = 1` (damping linear in the rate, as in Hunt and Crossley's model) the term is
/// `δ̇` itself, evaluated without a power.
///
/// # References
/// The impact force `F_I` of the impact oscillator of
/// [`systems::paper`](crate::systems::paper) (its eq. (1); its parameters are there).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct HertzContact<T> {
    x_i: T,
    side: Side,
    k_i: T,
    b: T,
    n1: Exponent<T>,
    n2: Exponent<T>,
    n3: T,
    eta: T,
    /// `(n3 − 1)/2`, cached for the regularized rate term.
    half_n3_minus_1: T,
}

crate::serde_check::deserialize_checked! {
    "HertzContact",
    HertzContact<T: Real> {
        x_i: T,
        side: Side,
        k_i: T,
        b: T,
        n1: Exponent<T>,
        n2: Exponent<T>,
        n3: T,
        eta: T,
        half_n3_minus_1: T,
    },
    // The cached `(n3 − 1)/2` is recomputed by `with_damping`.
    |raw| -> ParameterError {
        HertzContact::new(raw.x_i, raw.k_i)?
            .with_side(raw.side)
            .with_stiffness_exponent(raw.n1.value())?
            .with_damping(raw.b, raw.n2.value(), raw.n3)?
            .with_rate_regularization(raw.eta)?
    }
}

impl<T: Real> HertzContact<T> {
    /// A purely elastic Hertz contact `k_I·(x − x_I)^{3/2}` with the stop at `x_i`, on
    /// [`Side::Upper`]. Add damping with [`with_damping`](Self::with_damping).
    ///
    /// # Errors
    /// [`ParameterError`] if `x_i` is not finite or `k_i` is not finite and > 0.
    pub fn new(x_i: T, k_i: T) -> Result<Self, ParameterError> {
        let n3: T = T::one();
        Ok(Self {
            x_i: finite("x_i", x_i)?,
            side: Side::Upper,
            k_i: positive("k_i", k_i)?,
            b: T::zero(),
            n1: Exponent::ThreeHalves,
            n2: Exponent::ThreeHalves,
            n3,
            eta: T::zero(),
            half_n3_minus_1: T::zero(),
        })
    }

    /// Sets the side of the stop.
    pub fn with_side(mut self, side: Side) -> Self {
        self.side = side;
        self
    }

    /// Sets the stiffness exponent `n1` (Hertz: 3/2).
    ///
    /// # Errors
    /// [`ParameterError`] unless `n1` is finite and > 0.
    pub fn with_stiffness_exponent(mut self, n1: T) -> Result<Self, ParameterError> {
        self.n1 = Exponent::new(positive("n1", n1)?);
        Ok(self)
    }

    /// Sets the nonlinear damping `b·δ^{n2}·sgn(δ̇)|δ̇|^{n3}`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `b ≥ 0` and `n2`, `n3` are > 0, all finite, and (with a
    /// rate regularization `η > 0`) `η^{n3−1}` is finite.
    pub fn with_damping(mut self, b: T, n2: T, n3: T) -> Result<Self, ParameterError> {
        self.b = non_negative("b", b)?;
        self.n2 = Exponent::new(positive("n2", n2)?);
        self.n3 = positive("n3", n3)?;
        self.half_n3_minus_1 = (self.n3 - T::one()) * lit(0.5);
        self.check_rate_scale()
    }

    /// With `η > 0`, the regularized rate term's factor at `δ̇ = 0`, `η^{n3−1}`, must be
    /// finite (and `η²` must not underflow): otherwise `δ̇·(δ̇²+η²)^{(n3−1)/2}` is `0·∞`.
    fn check_rate_scale(self) -> Result<Self, ParameterError> {
        if self.eta > T::zero() {
            crate::validate::normal_square("eta", self.eta)?;
            let s = self.eta * self.eta;
            if !(self.half_n3_minus_1 * s.ln()).exp().is_finite() {
                return Err(ParameterError::new(
                    "eta",
                    crate::scalar::to_f64(self.eta),
                    "with eta^(n3-1) finite",
                ));
            }
        }
        Ok(self)
    }

    /// Regularizes `sgn(δ̇)|δ̇|^{n3}` as `δ̇(δ̇²+η²)^{(n3−1)/2}` (see the type's docs);
    /// `eta = 0` restores the exact law.
    ///
    /// # Errors
    /// [`ParameterError`] unless `eta` is finite and ≥ 0, and `eta²` does not underflow
    /// when `eta > 0` (`eta ≥ 1.5·10⁻¹⁵⁴` for `f64`) and `eta^{n3−1}` is finite (the rate
    /// term would be `0·∞` at `δ̇ = 0`).
    pub fn with_rate_regularization(mut self, eta: T) -> Result<Self, ParameterError> {
        self.eta = non_negative("eta", eta)?;
        self.check_rate_scale()
    }

    /// The stop position `x_I`.
    pub fn stop(&self) -> T {
        self.x_i
    }

    /// The side of the stop.
    pub fn side(&self) -> Side {
        self.side
    }

    /// The contact stiffness `k_I`.
    pub fn stiffness(&self) -> T {
        self.k_i
    }

    /// The rate regularization `η` (0 = exact).
    pub fn rate_regularization(&self) -> T {
        self.eta
    }

    /// Penetration `δ` and its rate for the configured side.
    #[inline(always)]
    fn penetration(&self, x: T, v: T) -> (T, T) {
        match self.side {
            Side::Upper => (x - self.x_i, v),
            Side::Lower => (self.x_i - x, -v),
        }
    }

    /// `g(w) = sgn(w)|w|^{n3}` or its regularization, and `g'(w)`.
    #[inline(always)]
    fn rate_term(&self, w: T) -> (T, T) {
        if self.eta > T::zero() {
            let s = w * w + self.eta * self.eta;
            // (w²+η²)^{(n3−1)/2}: the one transcendental pair of the evaluation.
            let p = (self.half_n3_minus_1 * s.ln()).exp();
            // p ≤ η^{n3−1} < ∞ near w = 0 (checked at construction): never 0·∞.
            let g = w * p;
            let dg = p * (self.n3 * w * w + self.eta * self.eta) / s;
            (g, dg)
        } else if w == T::zero() {
            (
                T::zero(),
                if self.n3 < T::one() {
                    T::max_value().unwrap_or(T::zero())
                } else if self.n3 == T::one() {
                    T::one()
                } else {
                    T::zero()
                },
            )
        } else if self.n3 == T::one() {
            // Linear in the rate (Hunt–Crossley): `g = w` exactly, without `exp(ln|w|)`.
            (w, T::one())
        } else {
            let a = w.abs();
            let m = (self.n3 * a.ln()).exp();
            let g = if w > T::zero() { m } else { -m };
            (g, self.n3 * m / a)
        }
    }

    /// The scalar `f(δ, δ̇)` of the model and its partials, for `δ > 0`.
    #[inline(always)]
    fn f_and_partials(&self, d: T, w: T) -> (T, T, T) {
        let (p1, dp1) = self.n1.pow_and_derivative(d);
        if self.b == T::zero() {
            return (p1, dp1, T::zero());
        }
        let (p2, dp2) = if self.n2 == self.n1 {
            (p1, dp1)
        } else {
            self.n2.pow_and_derivative(d)
        };
        let (g, dg) = self.rate_term(w);
        (
            p1 + self.b * p2 * g,
            dp1 + self.b * dp2 * g,
            self.b * p2 * dg,
        )
    }
}

impl<T: Real> ForceLaw<T> for HertzContact<T> {
    #[inline(always)]
    fn force(&self, x: T, v: T) -> T {
        let (d, w) = self.penetration(x, v);
        if d <= T::zero() {
            return T::zero();
        }
        let p1 = self.n1.pow(d);
        let f = if self.b == T::zero() {
            p1
        } else {
            let p2 = if self.n2 == self.n1 {
                p1
            } else {
                self.n2.pow(d)
            };
            p1 + self.b * p2 * self.rate_term(w).0
        };
        if f <= T::zero() {
            return T::zero();
        }
        match self.side {
            Side::Upper => self.k_i * f,
            Side::Lower => -self.k_i * f,
        }
    }

    /// The stop, its side and the smaller of `n1` and (with damping) `n2`.
    fn contact_onset(&self) -> Option<crate::force::ContactOnset<T>> {
        let n1 = self.n1.value();
        let n = if self.b > T::zero() && self.n2.value() < n1 {
            self.n2.value()
        } else {
            n1
        };
        Some(crate::force::ContactOnset {
            position: self.x_i,
            side: self.side,
            exponent: n,
        })
    }

    /// `n3` when the damping term has a cusp (`b > 0`, `n3 < 1`), with or without the rate
    /// regularization: with `η > 0` the cusp is rounded off inside `|δ̇| ≲ η`, and the
    /// power scale `u = sgn(δ̇)|δ̇|^{n3}` still straightens the term outside that layer.
    fn velocity_exponent(&self) -> Option<T> {
        (self.b > T::zero() && self.n3 < T::one()).then_some(self.n3)
    }

    /// Analytic partials. With `η = 0` and `n3 < 1`, `∂F/∂v` is infinite at `v = 0` in
    /// contact; it is reported as the largest finite value of `T`.
    #[inline(always)]
    fn partials(&self, x: T, v: T) -> (T, T) {
        let (d, w) = self.penetration(x, v);
        if d <= T::zero() {
            return (T::zero(), T::zero());
        }
        let (f, fd, fw) = self.f_and_partials(d, w);
        if f <= T::zero() {
            return (T::zero(), T::zero());
        }
        // For Side::Lower both δ = x_I − x and δ̇ = −v flip sign, and so does F.
        let big = T::max_value().unwrap_or(T::zero());
        let clamp = |p: T| {
            if p.is_finite() {
                p
            } else if p > T::zero() {
                big
            } else {
                -big
            }
        };
        (clamp(self.k_i * fd), clamp(self.k_i * fw))
    }
}

/// A contact exponent per lane: masks of its kind and its value.
#[derive(Debug, Clone, Copy)]
pub struct ExponentLanes<V> {
    one: V,
    three_halves: V,
    two: V,
    general: V,
    p: V,
}

impl<V: Lanes> ExponentLanes<V> {
    fn zero() -> Self {
        let z = V::splat(0.0);
        Self {
            one: z,
            three_halves: z,
            two: z,
            general: z,
            p: z,
        }
    }

    fn set(&mut self, i: usize, e: Exponent<f64>) {
        self.one = self.one.with_lane(i, mask(e == Exponent::One));
        self.three_halves = self
            .three_halves
            .with_lane(i, mask(e == Exponent::ThreeHalves));
        self.two = self.two.with_lane(i, mask(e == Exponent::Two));
        self.general = self
            .general
            .with_lane(i, mask(matches!(e, Exponent::General(_))));
        self.p = self.p.with_lane(i, e.value());
    }

    /// `d^p` where `inside` (`d > 0`), 0 elsewhere: [`Exponent::pow`] lane by lane (the
    /// general power only if some lane needs it).
    #[inline(always)]
    fn pow(&self, math: LaneMath, inside: V, d: V) -> V {
        let z = V::splat(0.0);
        let ds = inside.select(d, V::splat(1.0));
        let mut v = self.three_halves.select(d * ds.sqrt(), z);
        v = self.one.select(d, v);
        v = self.two.select(d * d, v);
        let g = self.general & inside;
        if g.bits() != 0 {
            v = g.select(pow_masked(math, g, ds, self.p), v);
        }
        inside.select(v, z)
    }
}

/// The parameters of [`HertzContact`] per lane.
#[derive(Debug, Clone, Copy)]
pub struct HertzLanes<V> {
    x_i: V,
    lower: V,
    k_i: V,
    b: V,
    b_zero: V,
    n1: ExponentLanes<V>,
    n2: ExponentLanes<V>,
    n2_is_n1: V,
    n3: V,
    n3_one: V,
    half_n3m1: V,
    eta2: V,
    eta_pos: V,
    /// Every lane a damped Hertz stop above (`n1 = n2 = 3/2`, `b > 0`, `η = 0`, upper
    /// side): the shape most models use, evaluated without the other shapes' selects.
    hertz: bool,
}

impl super::LaneLaw for HertzContact<f64> {
    type Packed<V: Lanes> = HertzLanes<V>;
    fn pack<V: Lanes>(&self) -> HertzLanes<V> {
        let z = V::splat(0.0);
        let mut p = HertzLanes {
            x_i: z,
            lower: z,
            k_i: z,
            b: z,
            b_zero: z,
            n1: ExponentLanes::zero(),
            n2: ExponentLanes::zero(),
            n2_is_n1: z,
            n3: z,
            n3_one: z,
            half_n3m1: z,
            eta2: z,
            eta_pos: z,
            hertz: false,
        };
        for i in 0..V::LANES {
            self.pack_lane(&mut p, i);
        }
        p
    }
    fn pack_lane<V: Lanes>(&self, p: &mut HertzLanes<V>, i: usize) {
        p.x_i = p.x_i.with_lane(i, self.x_i);
        p.lower = p.lower.with_lane(i, mask(self.side == Side::Lower));
        p.k_i = p.k_i.with_lane(i, self.k_i);
        p.b = p.b.with_lane(i, self.b);
        p.b_zero = p.b_zero.with_lane(i, mask(self.b == 0.0));
        p.n1.set(i, self.n1);
        p.n2.set(i, self.n2);
        p.n2_is_n1 = p.n2_is_n1.with_lane(i, mask(self.n1 == self.n2));
        p.n3 = p.n3.with_lane(i, self.n3);
        p.n3_one = p.n3_one.with_lane(i, mask(self.n3 == 1.0));
        p.half_n3m1 = p.half_n3m1.with_lane(i, self.half_n3_minus_1);
        p.eta2 = p.eta2.with_lane(i, self.eta * self.eta);
        p.eta_pos = p.eta_pos.with_lane(i, mask(self.eta > 0.0));
        let all = V::splat(crate::lanes::TRUE).bits();
        p.hertz = p.lower.bits() == 0
            && p.n1.three_halves.bits() == all
            && p.n2_is_n1.bits() == all
            && (p.b_zero | p.eta_pos).bits() == 0;
    }
    /// The scalar law's terms in its order; lanes out of contact cost a compare (and
    /// nothing more when no lane is in contact).
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &HertzLanes<V>, math: LaneMath, x: V, v: V) -> V {
        let z = V::splat(0.0);
        if p.hertz {
            return hertz_force_lanes(p, math, x, v);
        }
        // The penetration and its rate: (x − x_I, v) above, (x_I − x, −v) below.
        let d = p.lower.select(p.x_i - x, x - p.x_i);
        let inside = !d.le(z);
        if inside.bits() == 0 {
            return z;
        }
        let w = p.lower.select(-v, v);
        let p1 = p.n1.pow(math, inside, d);
        let p2 = if (p.n2_is_n1 & inside).bits() == inside.bits() {
            p1
        } else {
            p.n2_is_n1.select(p1, p.n2.pow(math, inside, d))
        };
        // g(w): w·(w²+η²)^{(n3−1)/2} for η > 0, sgn(w)|w|^{n3} for η = 0.
        let damped = inside & !p.b_zero;
        let s = w * w + p.eta2;
        let reg = damped & p.eta_pos;
        let g_reg = w * pow_masked(math, reg, s, p.half_n3m1);
        let exact = damped & !p.eta_pos & !w.eq(z);
        let g = if exact.bits() == 0 {
            g_reg
        } else {
            exact.select(p.rate_power(math, exact, w), p.eta_pos.select(g_reg, z))
        };
        let f = p.b_zero.select(p1, p1 + p.b * p2 * g);
        let kf = p.k_i * f;
        (inside & !f.le(z)).select(p.lower.select(-p.k_i * f, kf), z)
    }
}

impl<V: Lanes> HertzLanes<V> {
    /// `sgn(w)|w|^{n3}` in the lanes of `exact` (`w ≠ 0`, no regularization): `w` itself
    /// where `n3 = 1` (the scalar law's fast path), the power only where some lane has
    /// another exponent.
    #[inline(always)]
    fn rate_power(&self, math: LaneMath, exact: V, w: V) -> V {
        let general = exact & !self.n3_one;
        if general.bits() == 0 {
            return w;
        }
        let m = pow_masked(math, general, w.abs(), self.n3);
        self.n3_one.select(w, w.gt(V::splat(0.0)).select(m, -m))
    }
}

/// [`LaneLaw::force_lanes`](super::LaneLaw::force_lanes) where every lane is a damped
/// Hertz stop above ([`HertzLanes::hertz`]): the general lane form's operations with the
/// selects of the other shapes left out (each lane's value the same, to the bit).
#[inline(always)]
fn hertz_force_lanes<V: Lanes>(p: &HertzLanes<V>, math: LaneMath, x: V, v: V) -> V {
    let z = V::splat(0.0);
    let d = x - p.x_i;
    let inside = !d.le(z);
    if inside.bits() == 0 {
        return z;
    }
    let p1 = inside.select(d * inside.select(d, V::splat(1.0)).sqrt(), z);
    let exact = inside & !v.eq(z);
    let g = if exact.bits() == 0 {
        // The general form's regularized term where no lane has one: `w·0`.
        v * z
    } else {
        exact.select(p.rate_power(math, exact, v), z)
    };
    let f = p1 + p.b * p1 * g;
    (inside & !f.le(z)).select(p.k_i * f, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> HertzContact<f64> {
        HertzContact::new(-2.086e-3, 2.3983e8)
            .unwrap()
            .with_damping(0.8485, 1.5, 0.18667)
            .unwrap()
    }

    #[test]
    fn zero_when_separated_and_elastic_at_rest() {
        let c = paper();
        assert_eq!(c.force(-3e-3, 1.0), 0.0);
        let d: f64 = 5e-6;
        assert!((c.force(-2.086e-3 + d, 0.0) - 2.3983e8 * d.powf(1.5)).abs() < 1e-9);
    }

    #[test]
    fn no_adhesion_during_fast_separation() {
        let c = paper();
        // f = δ^{3/2}(1 + b·sgn(v)|v|^{n3}) < 0 when b|v|^{n3} > 1 and v < 0.
        let v = -(2.0_f64 / 0.8485).powf(1.0 / 0.18667);
        assert_eq!(c.force(-2.086e-3 + 1e-6, v), 0.0);
        assert_eq!(c.partials(-2.086e-3 + 1e-6, v), (0.0, 0.0));
    }

    #[test]
    fn lower_side_mirrors_upper() {
        let up = paper();
        let lo = HertzContact::new(2.086e-3, 2.3983e8)
            .unwrap()
            .with_side(Side::Lower)
            .with_damping(0.8485, 1.5, 0.18667)
            .unwrap();
        for &(x, v) in &[(-2.08e-3, 0.01), (-2.085e-3, -1e-3), (-2.07e-3, 0.3)] {
            assert_eq!(lo.force(-x, -v), -up.force(x, v));
            let (a, b) = up.partials(x, v);
            let (c, d) = lo.partials(-x, -v);
            assert_eq!((a, b), (c, d));
        }
    }

    #[test]
    fn regularization_vanishes_at_large_rates() {
        let exact = paper();
        let reg = paper().with_rate_regularization(1e-7).unwrap();
        let x = -2.086e-3 + 4e-6;
        let v = 1e-2;
        let rel = (exact.force(x, v) - reg.force(x, v)).abs() / exact.force(x, v);
        assert!(rel < 1e-9, "{rel}");
        // Lipschitz at v = 0: finite slope η^{n3−1}·b·k_I·δ^{n2}.
        let (_, dv) = reg.partials(x, 0.0);
        let expect = 2.3983e8 * 0.8485 * 4e-6_f64.powf(1.5) * 1e-7_f64.powf(0.18667 - 1.0);
        assert!((dv - expect).abs() < 1e-9 * expect);
    }

    #[test]
    fn linear_rate_term_is_the_rate_itself() {
        // n3 = 1 (Hunt–Crossley): F = k·(δ^{3/2} + b·δ^{3/2}·δ̇), the rate taken as it is.
        let c = HertzContact::new(0.0, 2.0)
            .unwrap()
            .with_damping(0.5, 1.5, 1.0)
            .unwrap();
        let (d, v) = (0.01_f64, -0.3_f64);
        let p = d * d.sqrt();
        assert_eq!(c.force(d, v), 2.0 * (p + 0.5 * p * v));
        // ∂F/∂v = k·b·δ^{3/2}, also at v = 0 (the slope of a linear term).
        for v in [0.0, 0.2] {
            assert_eq!(c.partials(d, v).1, 2.0 * (0.5 * p * 1.0));
        }
        // Below the stop the same law pulls the other way.
        let lower = c.with_side(Side::Lower);
        assert_eq!(lower.force(-d, -v), -2.0 * (p + 0.5 * p * v));
    }

    #[test]
    fn validation() {
        assert!(HertzContact::new(f64::NAN, 1.0).is_err());
        assert!(HertzContact::new(0.0, 0.0).is_err());
        assert!(HertzContact::new(0.0, -1.0).is_err());
        let c = HertzContact::new(0.0, 1.0).unwrap();
        assert!(c.with_stiffness_exponent(0.0).is_err());
        assert!(c.with_damping(-1.0, 1.5, 0.2).is_err());
        assert!(c.with_damping(1.0, 0.0, 0.2).is_err());
        assert!(c.with_damping(1.0, 1.5, -0.2).is_err());
        assert!(c.with_damping(1.0, 1.5, f64::NAN).is_err());
        assert!(c.with_rate_regularization(-1e-9).is_err());
    }
}
