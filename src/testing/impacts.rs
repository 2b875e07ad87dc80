//! Reference problems for events: a bouncing ball, zero crossings of a harmonic signal and
//! a constructed near-grazing crossing pair.

use nalgebra::{SMatrix, SVector};

use crate::scalar::{lit, to_f64};
use crate::testing::HarmonicOscillator;
use crate::validate::ParameterError;
use crate::validate::{finite, positive};
use crate::{Dynamics, Real};

/// A ball in free flight above a wall at height 0, state `(h, v)`, with Newton restitution
/// `r` at the wall.
///
/// The [`Dynamics`] are the free flight `ḣ = v`, `v̇ = −g`; the wall is an event `h = 0`
/// (falling) with the reset `v⁺ = −r·v⁻` ([`reset`](Self::reset)), supplied by the
/// integrator's event machinery. [`drop_from`](Self::drop_from) gives the analytic impact
/// sequence of a ball released at rest.
///
/// # Model
/// Released from rest at height `h₀` at `t = 0`, the ball first hits the wall at
/// `t₀ = √(2h₀/g)` with speed `u₀ = √(2gh₀)`; impact `k` (counted from 0) comes at speed
/// `u_k = r^k u₀` and at
/// $$t_k = t_0 + \frac{2u_0}{g}\sum_{j=1}^{k} r^j
///   = t_0 + \frac{2u_0}{g}\,\frac{r(1-r^k)}{1-r}\quad(r<1),$$
/// so the impacts accumulate (Zeno) at `t_∞ = t₀(1+r)/(1−r)` for `r < 1`. Each bounce keeps
/// the fraction `r²` of the energy.
///
/// ```
/// use nonsmooth::testing::BouncingBall;
///
/// let ball = BouncingBall::new(9.81, 0.5)?;
/// let drop = ball.drop_from(1.0)?;
/// let t0 = (2.0 / 9.81_f64).sqrt();
/// assert!((drop.impact_time(0) - t0).abs() < 1e-15);
/// assert!((drop.zeno_time().unwrap() - 3.0 * t0).abs() < 1e-14);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BouncingBall<T> {
    g: T,
    r: T,
}

impl<T: Real> BouncingBall<T> {
    /// A ball under gravity `g` with restitution `r`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `g > 0` and `0 ≤ r ≤ 1`, both finite.
    pub fn new(g: T, r: T) -> Result<Self, ParameterError> {
        let g = positive("g", g)?;
        if !(r >= T::zero() && r <= T::one()) {
            return Err(ParameterError::new("r", to_f64(r), "in [0, 1]"));
        }
        Ok(Self { g, r })
    }

    /// Gravity `g`.
    pub fn gravity(&self) -> T {
        self.g
    }

    /// The restitution coefficient `r`.
    pub fn restitution(&self) -> T {
        self.r
    }

    /// The impact reset `v ← −r·v` (height unchanged).
    pub fn reset(&self, y: &mut SVector<T, 2>) {
        y[1] = -self.r * y[1];
    }

    /// The energy per unit mass `v²/2 + g·h`.
    pub fn energy(&self, y: &SVector<T, 2>) -> T {
        y[1] * y[1] * lit(0.5) + self.g * y[0]
    }

    /// The analytic motion of the ball released at rest from height `h0` at `t = 0`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `h0` is finite and > 0.
    pub fn drop_from(&self, h0: T) -> Result<BallDrop<T>, ParameterError> {
        let h0 = positive("h0", h0)?;
        let two: T = lit(2.0);
        Ok(BallDrop {
            ball: *self,
            h0,
            t0: (two * h0 / self.g).sqrt(),
            u0: (two * self.g * h0).sqrt(),
        })
    }
}

impl<T: Real> Dynamics<T, 2> for BouncingBall<T> {
    #[inline(always)]
    fn rhs(&self, _t: T, y: &SVector<T, 2>, dy: &mut SVector<T, 2>) {
        dy[0] = y[1];
        dy[1] = -self.g;
    }
    fn jacobian(&self, _t: T, _y: &SVector<T, 2>) -> Option<SMatrix<T, 2, 2>> {
        Some(SMatrix::<T, 2, 2>::new(
            T::zero(),
            T::one(),
            T::zero(),
            T::zero(),
        ))
    }
    fn time_derivative(&self, _t: T, _y: &SVector<T, 2>) -> Option<SVector<T, 2>> {
        Some(SVector::zeros())
    }
}

/// The analytic impact sequence of a [`BouncingBall`] released at rest (see its docs).
/// Impacts are counted from `k = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallDrop<T> {
    ball: BouncingBall<T>,
    h0: T,
    t0: T,
    u0: T,
}

impl<T: Real> BallDrop<T> {
    /// The initial state `(h₀, 0)` at `t = 0`.
    pub fn initial_state(&self) -> SVector<T, 2> {
        SVector::<T, 2>::new(self.h0, T::zero())
    }

    /// `r^k` (saturating `k` at `i32::MAX`).
    fn rpow(&self, k: usize) -> T {
        self.ball.r.powi(k.min(i32::MAX as usize) as i32)
    }

    /// `Σ_{j=1}^{k} r^j`.
    fn geometric(&self, k: usize) -> T {
        let r = self.ball.r;
        if r == T::one() {
            lit(k as f64)
        } else {
            r * (T::one() - self.rpow(k)) / (T::one() - r)
        }
    }

    /// The time of impact `k`.
    pub fn impact_time(&self, k: usize) -> T {
        self.t0 + lit::<T>(2.0) * self.u0 / self.ball.g * self.geometric(k)
    }

    /// The speed `u_k = r^k·√(2gh₀)` at impact `k` (the velocity just before is `−u_k`, just
    /// after `r·u_k`).
    pub fn impact_speed(&self, k: usize) -> T {
        self.u0 * self.rpow(k)
    }

    /// The height of the apex after impact `k`: `r^{2(k+1)}·h₀`.
    pub fn apex_height(&self, k: usize) -> T {
        let u = self.ball.r * self.impact_speed(k);
        u * u / (lit::<T>(2.0) * self.ball.g)
    }

    /// The accumulation time `t_∞ = t₀(1+r)/(1−r)` of the impacts, `None` for `r = 1`.
    pub fn zeno_time(&self) -> Option<T> {
        let r = self.ball.r;
        (r < T::one()).then(|| self.t0 * (T::one() + r) / (T::one() - r))
    }

    /// The number of impacts at times `≤ t`; `None` if infinitely many (`t ≥ t_∞`).
    ///
    /// Close to `t_∞` the impact times stop being distinct in floating point; the count is
    /// then that of the distinct ones.
    pub fn impacts_until(&self, t: T) -> Option<usize> {
        if t < self.t0 {
            return Some(0);
        }
        if let Some(tz) = self.zeno_time() {
            if t >= tz {
                return None;
            }
        }
        let r = self.ball.r;
        let period0 = lit::<T>(2.0) * self.u0 / self.ball.g;
        // Estimate the last impact index, then correct it against the exact times.
        let guess = if r == T::one() {
            to_f64((t - self.t0) / period0)
        } else if r == T::zero() {
            0.0
        } else {
            // t_∞ − t_k = period0·r^{k+1}/(1−r).
            let tz = self.zeno_time().unwrap_or(t);
            to_f64(((tz - t) * (T::one() - r) / period0).ln() / r.ln()) - 1.0
        };
        let mut k = if guess.is_finite() && guess > 0.0 {
            guess.floor().min(1e15) as usize
        } else {
            0
        };
        while k > 0 && self.impact_time(k) > t {
            k -= 1;
        }
        while self.impact_time(k + 1) <= t && self.impact_time(k + 1) > self.impact_time(k) {
            k += 1;
        }
        Some(k + 1)
    }

    /// The state `(h, v)` at time `t ≥ 0` (the post-impact velocity at an impact instant;
    /// `(0, 0)` from `t_∞` on).
    pub fn state_at(&self, t: T) -> SVector<T, 2> {
        let g = self.ball.g;
        let half: T = lit(0.5);
        match self.impacts_until(t) {
            None => SVector::zeros(),
            Some(0) => SVector::<T, 2>::new(self.h0 - half * g * t * t, -g * t),
            Some(n) => {
                let k = n - 1;
                let u = self.ball.r * self.impact_speed(k);
                let tau = t - self.impact_time(k);
                SVector::<T, 2>::new(u * tau - half * g * tau * tau, u - g * tau)
            }
        }
    }
}

/// A zero crossing of a signal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroCrossing<T> {
    /// The crossing time.
    pub t: T,
    /// `true` if the signal goes from negative to positive.
    pub rising: bool,
}

/// The zero crossings of `x(t) = A·cos(ωt + φ)`, the position of a
/// [`HarmonicOscillator`].
///
/// # Model
/// $$x(t_k) = 0 \iff t_k = \frac{\pi/2 + k\pi - \varphi}{\omega},\quad k\in\mathbb Z,$$
/// rising for odd `k` (for `A > 0`).
///
/// ```
/// use nonsmooth::testing::HarmonicZeroCrossings;
///
/// let z = HarmonicZeroCrossings::new(1.0, 2.0, 0.0)?; // x = cos 2t
/// let c = z.crossings_in(0.0, 3.0);
/// assert_eq!(c.len(), 2);
/// assert!((c[0].t - std::f64::consts::FRAC_PI_4).abs() < 1e-15 && !c[0].rising);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicZeroCrossings<T> {
    amplitude: T,
    omega: T,
    phase: T,
}

impl<T: Real> HarmonicZeroCrossings<T> {
    /// `x(t) = amplitude·cos(omega·t + phase)`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `amplitude > 0`, `omega > 0` and `phase` finite.
    pub fn new(amplitude: T, omega: T, phase: T) -> Result<Self, ParameterError> {
        Ok(Self {
            amplitude: positive("amplitude", amplitude)?,
            omega: positive("omega", omega)?,
            phase: finite("phase", phase)?,
        })
    }

    /// The signal of the oscillator with frequency `omega` started at `(x0, v0)` at `t = 0`:
    /// `A = √(x₀² + (v₀/ω)²)`, `φ = atan2(−v₀/ω, x₀)`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `omega > 0` and the state is finite and not `(0, 0)`.
    pub fn from_state(omega: T, x0: T, v0: T) -> Result<Self, ParameterError> {
        let omega = positive("omega", omega)?;
        let (x0, v0) = (finite("x0", x0)?, finite("v0", v0)?);
        let s = v0 / omega;
        let amplitude = (x0 * x0 + s * s).sqrt();
        Self::new(amplitude, omega, (-s).atan2(x0))
    }

    /// The oscillator whose position this is.
    pub fn oscillator(&self) -> HarmonicOscillator<T> {
        HarmonicOscillator { omega: self.omega }
    }

    /// The state `(x, ẋ)` at `t = 0`.
    pub fn initial_state(&self) -> SVector<T, 2> {
        self.state_at(T::zero())
    }

    /// The state `(x, ẋ)` at `t`.
    pub fn state_at(&self, t: T) -> SVector<T, 2> {
        let (s, c) = (self.omega * t + self.phase).sin_cos();
        SVector::<T, 2>::new(self.amplitude * c, -self.amplitude * self.omega * s)
    }

    /// The crossing with index `k` (see the model).
    pub fn crossing(&self, k: i64) -> ZeroCrossing<T> {
        let pi = T::pi();
        ZeroCrossing {
            t: (pi * lit::<T>(0.5) + lit::<T>(k as f64) * pi - self.phase) / self.omega,
            rising: k.rem_euclid(2) == 1,
        }
    }

    /// All crossings with `t0 ≤ t ≤ t1`, in order (empty unless `t0 ≤ t1`, both finite).
    pub fn crossings_in(&self, t0: T, t1: T) -> Vec<ZeroCrossing<T>> {
        let mut out = Vec::new();
        if !(t0.is_finite() && t1.is_finite() && t0 <= t1) {
            return out;
        }
        let pi = T::pi();
        // Smallest k with t_k ≥ t0.
        let k0 = to_f64((self.omega * t0 + self.phase - pi * lit::<T>(0.5)) / pi).ceil() as i64;
        let mut k = k0 - 1;
        while self.crossing(k).t < t0 {
            k += 1;
        }
        loop {
            let c = self.crossing(k);
            if c.t > t1 {
                break;
            }
            out.push(c);
            k += 1;
        }
        out
    }
}

/// A harmonic oscillation whose maximum exceeds a level by a tiny `δ`: the level is crossed
/// twice within a short interval, the classic grazing case an event locator checking signs
/// only at step ends misses.
///
/// # Model
/// `x(t) = A·cos(ω(t − t_p))` with `A = L + δ`; the crossings of `x = L` around the peak
/// `t_p` are `t_p ∓ θ/ω` with
/// $$\theta = \arccos\frac{L}{L+\delta} = 2\arcsin\sqrt{\frac{\delta}{2(L+\delta)}}
///   \approx \sqrt{2\delta/L},$$
/// the second form being accurate for tiny `δ`. Further pairs repeat every `2π/ω`.
///
/// ```
/// use nonsmooth::testing::NearGrazing;
///
/// let g = NearGrazing::new(1.0, 1.0, 1e-8, 0.5)?;
/// let (up, down) = g.crossing_pair();
/// // Twice θ/ω ≈ √(2δ/L), up to a relative O(δ).
/// assert!(((down - up) / (2.0 * (2e-8_f64).sqrt()) - 1.0).abs() < 1e-7);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearGrazing<T> {
    omega: T,
    level: T,
    delta: T,
    t_peak: T,
}

impl<T: Real> NearGrazing<T> {
    /// The oscillation with frequency `omega` peaking at `level + delta` at `t_peak`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `omega`, `level` and `delta` are finite and > 0, and
    /// `t_peak` is finite.
    pub fn new(omega: T, level: T, delta: T, t_peak: T) -> Result<Self, ParameterError> {
        Ok(Self {
            omega: positive("omega", omega)?,
            level: positive("level", level)?,
            delta: positive("delta", delta)?,
            t_peak: finite("t_peak", t_peak)?,
        })
    }

    /// The oscillator to integrate.
    pub fn oscillator(&self) -> HarmonicOscillator<T> {
        HarmonicOscillator { omega: self.omega }
    }

    /// The amplitude `A = L + δ`.
    pub fn amplitude(&self) -> T {
        self.level + self.delta
    }

    /// The level `L`.
    pub fn level(&self) -> T {
        self.level
    }

    /// The peak time `t_p`.
    pub fn peak_time(&self) -> T {
        self.t_peak
    }

    /// The state `(x, ẋ)` at `t`.
    pub fn state_at(&self, t: T) -> SVector<T, 2> {
        let a = self.amplitude();
        let (s, c) = (self.omega * (t - self.t_peak)).sin_cos();
        SVector::<T, 2>::new(a * c, -a * self.omega * s)
    }

    /// The state at `t = 0`.
    pub fn initial_state(&self) -> SVector<T, 2> {
        self.state_at(T::zero())
    }

    /// The event function `x − L` (positive above the level).
    pub fn event_value(&self, y: &SVector<T, 2>) -> T {
        y[0] - self.level
    }

    /// The upward and the downward crossing of `x = L` around `t_p`.
    pub fn crossing_pair(&self) -> (T, T) {
        let half = self.half_width();
        (self.t_peak - half, self.t_peak + half)
    }

    /// `θ/ω`: half the time spent above the level.
    pub fn half_width(&self) -> T {
        let q = (self.delta / (lit::<T>(2.0) * self.amplitude())).sqrt();
        lit::<T>(2.0) * q.asin() / self.omega
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert!(BouncingBall::new(0.0, 0.5).is_err());
        assert!(BouncingBall::new(9.81, 1.5).is_err());
        assert!(BouncingBall::new(9.81, f64::NAN).is_err());
        assert!(
            BouncingBall::new(9.81, 0.5)
                .unwrap()
                .drop_from(0.0)
                .is_err()
        );
        assert!(HarmonicZeroCrossings::from_state(1.0, 0.0, 0.0).is_err());
        assert!(NearGrazing::new(1.0, 1.0, 0.0, 0.0).is_err());
    }

    #[test]
    fn ball_impact_counting() {
        let d = BouncingBall::new(9.81, 0.8)
            .unwrap()
            .drop_from(2.0)
            .unwrap();
        assert_eq!(d.impacts_until(0.0), Some(0));
        // (Beyond k ≈ 150 the times t_k of r = 0.8 are no longer distinct in f64.)
        for k in [0usize, 1, 5, 40, 100] {
            let tk = d.impact_time(k);
            assert_eq!(d.impacts_until(tk), Some(k + 1), "k = {k}");
            let before = if k == 0 {
                0.5 * tk
            } else {
                0.5 * (tk + d.impact_time(k - 1))
            };
            assert_eq!(d.impacts_until(before), Some(k), "k = {k}");
        }
        assert_eq!(d.impacts_until(d.zeno_time().unwrap()), None);
        let elastic = BouncingBall::new(9.81, 1.0)
            .unwrap()
            .drop_from(2.0)
            .unwrap();
        assert_eq!(elastic.zeno_time(), None);
        assert_eq!(elastic.impacts_until(elastic.impact_time(1000)), Some(1001));
        let dead = BouncingBall::new(9.81, 0.0)
            .unwrap()
            .drop_from(2.0)
            .unwrap();
        assert_eq!(dead.zeno_time(), Some(dead.impact_time(0)));
        assert_eq!(dead.state_at(10.0), SVector::<f64, 2>::zeros());
    }

    #[test]
    fn crossings_from_state() {
        let z = HarmonicZeroCrossings::<f64>::from_state(3.0, 0.4, -1.2).unwrap();
        let y = z.initial_state();
        assert!((y[0] - 0.4).abs() < 1e-15 && (y[1] + 1.2).abs() < 1e-15);
        for c in z.crossings_in(-2.0, 5.0) {
            let s = z.state_at(c.t);
            assert!(s[0].abs() < 1e-14);
            assert_eq!(s[1] > 0.0, c.rising);
        }
        assert!(z.crossings_in(1.0, 0.0).is_empty());
    }
}
