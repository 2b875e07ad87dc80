//! Excitations `f(t)`: the right-hand side of `m·ẍ + ΣF(x, ẋ) = f(t)`.
//!
//! Each excitation also exposes its *phase* `φ(t)`, so that stroboscopic Poincaré sections
//! can be taken at `φ = 2πi` exactly — for constant `ω` that is `t = 2πi/ω`, for a ramped
//! frequency it is the root of a quadratic, never an accumulated sum.

use crate::Real;
use crate::fastmath;
use crate::lanes::{LaneMath, Lanes};
use crate::scalar::{lit, to_f64};
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative, positive};

/// `x` clamped to the finite range: `±∞ → ±MAX` (NaN stays NaN; a type without a largest
/// value is returned unchanged).
///
/// The excitations evaluate a phase `ω·t` that overflows for finite but extreme `ω` and `t`;
/// there the floating-point phase is spaced far more than `2π` apart and carries no angle, so
/// any phase is as good as the exact one, and the saturated one keeps `sin`/`cos` finite.
#[inline(always)]
fn saturate<T: Real>(x: T) -> T {
    if x.is_finite() {
        return x;
    }
    match T::max_value() {
        Some(max) if x > T::zero() => max,
        Some(max) if x < T::zero() => -max,
        _ => x,
    }
}

/// A time-dependent force `f(t)`.
///
/// Implement [`force`](Excitation::force); override [`force_rate`](Excitation::force_rate)
/// with the analytic `df/dt` (used by the implicit stepper), and
/// [`phase`](Excitation::phase) / [`time_of_phase`](Excitation::time_of_phase) for periodic
/// forcing so that stroboscopic sections can be taken.
///
/// ```
/// use nonsmooth::{Real, excite::Excitation};
/// /// A constant force.
/// struct Gravity(f64);
/// impl Excitation<f64> for Gravity {
///     fn force(&self, _t: f64) -> f64 { self.0 }
///     fn force_rate(&self, _t: f64) -> f64 { 0.0 }
/// }
/// assert_eq!(Gravity(9.81).force(3.0), 9.81);
/// ```
pub trait Excitation<T: Real> {
    /// The force at time `t`.
    fn force(&self, t: T) -> T;

    /// `df/dt` at `t` (default: a central difference whose step is set by the
    /// [`time_scale`](Excitation::time_scale), not by `|t|`, so it stays accurate late in a
    /// long run).
    fn force_rate(&self, t: T) -> T {
        central_difference(|s| self.force(s), t, self.time_scale(t))
    }

    /// `d²f/dt²` at `t` (default: a central difference of
    /// [`force_rate`](Excitation::force_rate), as there). Used where an excitation is the
    /// position of a surface that a body rides on (the surface's acceleration).
    fn force_acceleration(&self, t: T) -> T {
        central_difference(|s| self.force_rate(s), t, self.time_scale(t))
    }

    /// The forcing phase `φ(t)` in radians, if the forcing is periodic in a phase.
    fn phase(&self, _t: T) -> Option<T> {
        None
    }

    /// The first time `t ≥ 0` at which `φ(t) = phase` (for stroboscopic sections).
    fn time_of_phase(&self, _phase: T) -> Option<T> {
        None
    }

    /// The instantaneous angular frequency `dφ/dt`, if defined.
    fn angular_frequency(&self, _t: T) -> Option<T> {
        None
    }

    /// The shortest time over which `f` can turn around near `t`, if it varies in time:
    /// no step of a run is longer than this while the excitation drives a quantity that
    /// the error estimate cannot see (a sticking or release condition, a moving surface;
    /// see the event contract in [`event`](crate::event)). Default: a sixteenth of the
    /// period `2π/|ω(t)|` when [`angular_frequency`](Excitation::angular_frequency) is
    /// declared, else `None` (constant in time, or nothing declared: override it for an
    /// excitation of your own that varies in time).
    fn time_scale(&self, t: T) -> Option<T> {
        self.angular_frequency(t).and_then(|w| {
            let h = T::two_pi() / (lit::<T>(16.0) * w.abs());
            (h.is_finite() && h > T::zero()).then_some(h)
        })
    }

    /// Whether [`time_scale`](Excitation::time_scale) has the same value at every `t`
    /// (`None` everywhere included): an excitation of constant frequency, or one constant
    /// in time. The ensemble then bounds each lane's steps with the value at its start,
    /// computed in the lanes, instead of asking at every step. Default `false`;
    /// implemented by `()`, [`Constant`], [`Harmonic`] and [`UnbalancedRotor`].
    fn constant_time_scale(&self) -> bool {
        false
    }

    /// Bounds on `[t0, t1]`, if known: `(d, a)` with `|f(t) − ℓ(t)| ≤ d`, where `ℓ` is the
    /// chord between `f(t0)` and `f(t1)`, and `a` the scale of the rounding of `f`'s
    /// computed values (`|f(t)| ≤ a`, and for `A·sin(ωt + φ)` also `|A|·|ωt + φ|`: the
    /// rounding of the phase; the rounding allowance is relative to it). The event search uses them
    /// for a surface that moves as this excitation ([`Gap`](crate::event::Gap)) to rule
    /// out a crossing inside a step without searching it (a bound that holds only
    /// approximately would let a crossing be missed). For `|f̈| ≤ K` on the interval,
    /// `d = K·(t1 − t0)²/8`. Default `None`; implemented by `()`, [`Constant`],
    /// [`Harmonic`] and [`UnbalancedRotor`].
    fn chord_bounds(&self, _t0: T, _t1: T) -> Option<(T, T)> {
        None
    }

    /// The force and its rate `(f(t), ḟ(t))` at `L` times at once, one per lane, if the
    /// excitation has a lane form (`None`, the default, if not). Each lane must be
    /// [`force`](Excitation::force) and [`force_rate`](Excitation::force_rate) at that
    /// lane's time to the bit. The ensemble uses it for an event surface that moves as
    /// this excitation (a [`Gap`](crate::event::Gap) on a vibrating table), shared by all
    /// lanes: with it, the events of a step are evaluated in the lanes, and a lane goes to
    /// the scalar event search only when its step may hold an event; without it, every
    /// step is searched lane by lane (the same results, more time). Implemented by `()`,
    /// [`Constant`], [`Harmonic`] and [`UnbalancedRotor`] in `f64`.
    #[inline(always)]
    fn motion_lanes<V: Lanes>(&self, _t: V) -> Option<(V, V)>
    where
        Self: Sized,
    {
        None
    }
}

/// The central difference `(f(t₊) − f(t₋))/(t₊ − t₋)` at `t± = t ± h`, `h = ε^{1/3}·s`, where
/// `s` is the excitation's own time unit `16·scale/2π = 1/ω` when it declares one, else one
/// second, and at least `ε^{1/3}·|t|` so that `t ± h` stay distinct: the step does not
/// grow with `|t|` (the difference is taken between the representable neighbours used).
fn central_difference<T: Real>(f: impl Fn(T) -> T, t: T, scale: Option<T>) -> T {
    let (up, down) = difference_points(t, scale);
    (f(up) - f(down)) / (up - down)
}

/// The points `t ± h` of a central difference in time, `h` as in [`central_difference`]
/// (also used for the rates of mode conditions along the flow).
pub(crate) fn difference_points<T: Real>(t: T, scale: Option<T>) -> (T, T) {
    let cbrt_eps = crate::scalar::epsilon::<T>().powf(lit(1.0 / 3.0));
    let unit = scale.map_or(T::one(), |h| lit::<T>(16.0) * h / T::two_pi());
    let h = cbrt_eps * unit.max(cbrt_eps * t.abs());
    (t + h, t - h)
}

impl<T: Real, E: Excitation<T> + ?Sized> Excitation<T> for &E {
    #[inline(always)]
    fn force(&self, t: T) -> T {
        (**self).force(t)
    }
    #[inline(always)]
    fn force_rate(&self, t: T) -> T {
        (**self).force_rate(t)
    }
    fn phase(&self, t: T) -> Option<T> {
        (**self).phase(t)
    }
    fn time_of_phase(&self, phase: T) -> Option<T> {
        (**self).time_of_phase(phase)
    }
    fn angular_frequency(&self, t: T) -> Option<T> {
        (**self).angular_frequency(t)
    }
    fn force_acceleration(&self, t: T) -> T {
        (**self).force_acceleration(t)
    }
    fn time_scale(&self, t: T) -> Option<T> {
        (**self).time_scale(t)
    }
    fn constant_time_scale(&self) -> bool {
        (**self).constant_time_scale()
    }
    fn chord_bounds(&self, t0: T, t1: T) -> Option<(T, T)> {
        (**self).chord_bounds(t0, t1)
    }
}

/// No forcing.
impl<T: Real> Excitation<T> for () {
    #[inline(always)]
    fn force(&self, _t: T) -> T {
        T::zero()
    }
    #[inline(always)]
    fn motion_lanes<V: Lanes>(&self, _t: V) -> Option<(V, V)> {
        Some((V::splat(0.0), V::splat(0.0)))
    }
    fn constant_time_scale(&self) -> bool {
        true
    }
    #[inline(always)]
    fn force_rate(&self, _t: T) -> T {
        T::zero()
    }
    fn force_acceleration(&self, _t: T) -> T {
        T::zero()
    }
    fn chord_bounds(&self, _t0: T, _t1: T) -> Option<(T, T)> {
        Some((T::zero(), T::zero()))
    }
}

/// A constant `f(t) = c`: a weight or a static preload as a [`Load`](crate::model::Load), a
/// belt's constant velocity for a friction contact.
///
/// ```
/// use nonsmooth::excite::{Constant, Excitation};
/// let g = Constant::new(-9.81_f64)?;
/// assert_eq!((g.force(3.0), g.force_rate(3.0)), (-9.81, 0.0));
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constant<T> {
    value: T,
}

impl<T: Real> Constant<T> {
    /// The constant `value`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `value` is finite.
    pub fn new(value: T) -> Result<Self, ParameterError> {
        Ok(Self {
            value: finite("value", value)?,
        })
    }

    /// The value.
    pub fn value(&self) -> T {
        self.value
    }
}

impl<T: Real> Excitation<T> for Constant<T> {
    #[inline(always)]
    fn force(&self, _t: T) -> T {
        self.value
    }
    #[inline(always)]
    fn motion_lanes<V: Lanes>(&self, _t: V) -> Option<(V, V)> {
        fastmath::is_f64::<T>().then(|| (V::splat(to_f64(self.value)), V::splat(0.0)))
    }
    fn constant_time_scale(&self) -> bool {
        true
    }
    #[inline(always)]
    fn force_rate(&self, _t: T) -> T {
        T::zero()
    }
    fn force_acceleration(&self, _t: T) -> T {
        T::zero()
    }
    fn chord_bounds(&self, _t0: T, _t1: T) -> Option<(T, T)> {
        Some((T::zero(), self.value.abs()))
    }
}

/// Harmonic forcing `F0·sin(ωt + φ0)`.
///
/// Deserialization (feature `serde`) applies the constructor's checks.
///
/// # Model
/// $$f(t) = F_0 \sin(\omega t + \varphi_0), \qquad \varphi(t) = \omega t + \varphi_0 .$$
/// Where `ωt + φ0` overflows, [`force`](Excitation::force) and
/// [`force_rate`](Excitation::force_rate) take the phase as `±MAX` (the floating-point
/// phase there carries no angle): for finite `t` both are finite.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Harmonic<T> {
    amplitude: T,
    omega: T,
    phase0: T,
}

crate::serde_check::deserialize_checked! {
    "Harmonic", Harmonic<T: Real> { amplitude: T, omega: T, phase0: T },
    |raw| -> ParameterError { Harmonic::new(raw.amplitude, raw.omega, raw.phase0)? }
}

impl<T: Real> Harmonic<T> {
    /// `amplitude·sin(omega·t + phase0)`.
    ///
    /// # Errors
    /// [`ParameterError`] unless all are finite and `omega > 0`, with the amplitude of the
    /// force rate `amplitude·ω` finite.
    pub fn new(amplitude: T, omega: T, phase0: T) -> Result<Self, ParameterError> {
        let amplitude = finite("amplitude", amplitude)?;
        let omega = positive("omega", omega)?;
        let phase0 = finite("phase0", phase0)?;
        if !(amplitude * omega).is_finite() {
            return Err(ParameterError::new(
                "omega",
                crate::scalar::to_f64(omega),
                "small enough that amplitude·ω is finite",
            ));
        }
        Ok(Self {
            amplitude,
            omega,
            phase0,
        })
    }

    /// `amplitude·sin(omega·t)`.
    ///
    /// # Errors
    /// As [`new`](Harmonic::new).
    pub fn sine(amplitude: T, omega: T) -> Result<Self, ParameterError> {
        Self::new(amplitude, omega, T::zero())
    }

    /// `amplitude·cos(omega·t)`, i.e. `φ0 = π/2`: the forcing phase is `φ(t) = ωt + π/2`,
    /// so sections at `φ = 2πi` fall a quarter period before `t = 2πi/ω`; take sections at
    /// `t = 2πi/ω` with [`Stroboscopic::periodic`](crate::sample::Stroboscopic::periodic).
    ///
    /// # Errors
    /// As [`new`](Harmonic::new).
    ///
    /// ```
    /// use nonsmooth::excite::{Excitation, Harmonic};
    /// let f = Harmonic::cosine(7.5, 1.0).unwrap();
    /// assert_eq!(f.force(0.0), 7.5);
    /// assert!((f.force(2.0) - 7.5 * 2.0_f64.cos()).abs() < 1e-14);
    /// ```
    pub fn cosine(amplitude: T, omega: T) -> Result<Self, ParameterError> {
        Self::new(amplitude, omega, T::frac_pi_2())
    }

    /// The angular frequency `ω`.
    pub fn omega(&self) -> T {
        self.omega
    }

    /// The amplitude `F0`.
    pub fn amplitude(&self) -> T {
        self.amplitude
    }

    /// The phase offset `φ0`.
    pub fn phase_offset(&self) -> T {
        self.phase0
    }

    /// The forcing period `2π/ω`.
    pub fn period(&self) -> T {
        T::two_pi() / self.omega
    }
}

/// [`Excitation::chord_bounds`] of `A·sin(ωt + φ)` on `[t0, t1]`: `|A|·ω²·(t1 − t0)²/8`
/// (`|f̈| ≤ |A|·ω²`) and the rounding scale `|A|·(1 + |ω|·max|t| + |φ|)`.
fn sine_chord_bounds<T: Real>(amplitude: T, omega: T, phase0: T, t0: T, t1: T) -> (T, T) {
    let (a, h) = (amplitude.abs(), t1 - t0);
    let phase = omega.abs() * t0.abs().max(t1.abs()) + phase0.abs();
    (a * omega * omega * h * h / lit(8.0), a * (T::one() + phase))
}

impl<T: Real> Excitation<T> for Harmonic<T> {
    #[inline(always)]
    fn force(&self, t: T) -> T {
        self.amplitude * fastmath::sin(saturate(self.omega * t + self.phase0))
    }
    #[inline(always)]
    fn force_rate(&self, t: T) -> T {
        self.amplitude * self.omega * fastmath::cos(saturate(self.omega * t + self.phase0))
    }
    #[inline(always)]
    fn motion_lanes<V: Lanes>(&self, t: V) -> Option<(V, V)> {
        if !fastmath::is_f64::<T>() {
            return None;
        }
        let [a, w, p] = [self.amplitude, self.omega, self.phase0].map(|x| V::splat(to_f64(x)));
        let (sin, cos) = crate::lanes::math::sin_cos(saturate_lanes(w * t + p));
        Some((a * sin, a * w * cos))
    }
    fn force_acceleration(&self, t: T) -> T {
        -self.amplitude * self.omega * self.omega * fastmath::sin(self.omega * t + self.phase0)
    }
    fn phase(&self, t: T) -> Option<T> {
        Some(self.omega * t + self.phase0)
    }
    fn time_of_phase(&self, phase: T) -> Option<T> {
        Some((phase - self.phase0) / self.omega)
    }
    fn angular_frequency(&self, _t: T) -> Option<T> {
        Some(self.omega)
    }
    fn constant_time_scale(&self) -> bool {
        true
    }
    /// `|F0|·ω²·(t1 − t0)²/8` (`|f̈| ≤ |F0|·ω²`) and `|F0|·(1 + |ω|·max|t| + |φ0|)`.
    fn chord_bounds(&self, t0: T, t1: T) -> Option<(T, T)> {
        Some(sine_chord_bounds(
            self.amplitude,
            self.omega,
            self.phase0,
            t0,
            t1,
        ))
    }
}

/// An unbalanced rotor at constant speed: `m0·e·ω²·sin(ωt)` (the paper's forcing).
///
/// Deserialization (feature `serde`) applies the constructor's checks; the amplitude
/// `m0e·ω²` is recomputed.
///
/// # Model
/// $$f(t) = m_0 e\,\omega^2 \sin\omega t .$$
/// Where `ωt` overflows, the phase is taken as `±MAX` (as for [`Harmonic`]): for finite `t`
/// the force and its rate are finite.
/// # References
/// The forcing of the impact oscillator of [`systems::paper`](crate::systems::paper) (its
/// eq. (1), right-hand side; its parameters are there).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct UnbalancedRotor<T> {
    m0e: T,
    omega: T,
    amp: T,
}

crate::serde_check::deserialize_checked! {
    "UnbalancedRotor", UnbalancedRotor<T: Real> { m0e: T, omega: T, amp: T },
    |raw| -> ParameterError { UnbalancedRotor::new(raw.m0e, raw.omega)? }
}

impl<T: Real> UnbalancedRotor<T> {
    /// A rotor with unbalance `m0e` (kg·m) turning at `omega` (rad/s).
    ///
    /// # Errors
    /// [`ParameterError`] unless `m0e ≥ 0` and `omega > 0`, both finite, with the force
    /// amplitude `m0e·ω²` and its rate `m0e·ω³` finite.
    pub fn new(m0e: T, omega: T) -> Result<Self, ParameterError> {
        let m0e = non_negative("m0e", m0e)?;
        let omega = positive("omega", omega)?;
        let amp = m0e * omega * omega;
        // The force m0e·ω² and its rate m0e·ω³ must be finite.
        if !(amp * omega).is_finite() {
            return Err(ParameterError::new(
                "omega",
                crate::scalar::to_f64(omega),
                "small enough that m0e·ω³ is finite",
            ));
        }
        Ok(Self { m0e, omega, amp })
    }

    /// The angular speed `ω`.
    pub fn omega(&self) -> T {
        self.omega
    }

    /// The unbalance `m0·e`.
    pub fn unbalance(&self) -> T {
        self.m0e
    }

    /// The force amplitude `m0·e·ω²`.
    pub fn amplitude(&self) -> T {
        self.amp
    }

    /// The forcing period `2π/ω`.
    pub fn period(&self) -> T {
        T::two_pi() / self.omega
    }
}

impl<T: Real> Excitation<T> for UnbalancedRotor<T> {
    #[inline(always)]
    fn force(&self, t: T) -> T {
        self.amp * fastmath::sin(saturate(self.omega * t))
    }
    #[inline(always)]
    fn force_rate(&self, t: T) -> T {
        self.amp * self.omega * fastmath::cos(saturate(self.omega * t))
    }
    #[inline(always)]
    fn motion_lanes<V: Lanes>(&self, t: V) -> Option<(V, V)> {
        if !fastmath::is_f64::<T>() {
            return None;
        }
        let [a, w] = [self.amp, self.omega].map(|x| V::splat(to_f64(x)));
        let (sin, cos) = crate::lanes::math::sin_cos(saturate_lanes(w * t));
        Some((a * sin, a * w * cos))
    }
    fn force_acceleration(&self, t: T) -> T {
        -self.amp * self.omega * self.omega * fastmath::sin(self.omega * t)
    }
    fn phase(&self, t: T) -> Option<T> {
        Some(self.omega * t)
    }
    fn time_of_phase(&self, phase: T) -> Option<T> {
        Some(phase / self.omega)
    }
    fn angular_frequency(&self, _t: T) -> Option<T> {
        Some(self.omega)
    }
    fn constant_time_scale(&self) -> bool {
        true
    }
    /// `|m0·e·ω²|·ω²·(t1 − t0)²/8` and `|m0·e·ω²|·(1 + |ω|·max|t|)`.
    fn chord_bounds(&self, t0: T, t1: T) -> Option<(T, T)> {
        Some(sine_chord_bounds(self.amp, self.omega, T::zero(), t0, t1))
    }
}

/// An unbalanced rotor whose speed ramps linearly, `ω(t) = ω0 + r·t` (the experiment's
/// continuous sweep, `r = 8.0905·10⁻³ rad/s²`).
///
/// Deserialization (feature `serde`) applies the constructor's checks.
///
/// # Model
/// The rotor angle is integrated exactly, `φ(t) = ω0·t + r·t²/2`, and the force is that of
/// an unbalance `m0e` at angle `φ`, including the tangential term of the angular
/// acceleration:
/// $$f(t) = m_0 e\,\bigl(\dot\varphi^2 \sin\varphi - \ddot\varphi\cos\varphi\bigr).$$
/// For `r = 0` it is [`UnbalancedRotor`]. Stroboscopic sections are at `φ = 2πi`, found
/// from the quadratic for `t` (no accumulated time).
///
/// For finite `t` the force and its rate are finite: where the ramp takes `ω(t)`, `φ(t)` or
/// the force beyond the floating-point range (far outside any simulated horizon), every
/// intermediate saturates at `±MAX` and the phase is taken as `±MAX`, as for [`Harmonic`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RampedRotor<T> {
    m0e: T,
    omega0: T,
    rate: T,
}

crate::serde_check::deserialize_checked! {
    "RampedRotor", RampedRotor<T: Real> { m0e: T, omega0: T, rate: T },
    |raw| -> ParameterError { RampedRotor::new(raw.m0e, raw.omega0, raw.rate)? }
}

impl<T: Real> RampedRotor<T> {
    /// A rotor starting at `omega0` (rad/s) and accelerating at `rate` (rad/s², any sign).
    ///
    /// # Errors
    /// [`ParameterError`] unless `m0e ≥ 0`, `omega0 > 0` and `rate` are finite and the
    /// force and its rate at `t = 0` (`−m0e·rate`, `m0e·ω0³`) and `m0e·ω0·rate` are finite.
    pub fn new(m0e: T, omega0: T, rate: T) -> Result<Self, ParameterError> {
        let m0e = non_negative("m0e", m0e)?;
        let omega0 = positive("omega0", omega0)?;
        let rate = finite("rate", rate)?;
        // The rate at t = 0 is m0e·ω0³; the force at t = 0 is −m0e·r.
        if !(m0e * omega0 * omega0 * omega0).is_finite() {
            return Err(ParameterError::new(
                "omega0",
                crate::scalar::to_f64(omega0),
                "small enough that m0e·ω0³ is finite",
            ));
        }
        if !(m0e * rate).is_finite() || !(m0e * omega0 * rate).is_finite() {
            return Err(ParameterError::new(
                "rate",
                crate::scalar::to_f64(rate),
                "small enough that m0e·rate and m0e·ω0·rate are finite",
            ));
        }
        Ok(Self { m0e, omega0, rate })
    }

    /// [`force`](Excitation::force) where its direct evaluation is not finite: every
    /// intermediate saturated at `±MAX` (finite operands, so never NaN), the unbalance
    /// multiplied in first so that a small `m0e` keeps a large `ω²` in range.
    #[cold]
    fn saturated_force(&self, t: T) -> T {
        let (w, s, c) = self.saturated_state(t);
        let m = self.m0e;
        let centrifugal = saturate(saturate(saturate(m * w) * w) * s);
        let tangential = saturate(saturate(m * self.rate) * c);
        saturate(centrifugal - tangential)
    }

    /// [`force_rate`](Excitation::force_rate) where its direct evaluation is not finite,
    /// as [`saturated_force`](Self::saturated_force): `m0e·(w³·cos φ + 3·r·w·sin φ)`.
    #[cold]
    fn saturated_force_rate(&self, t: T) -> T {
        let (w, s, c) = self.saturated_state(t);
        let m = self.m0e;
        let cubic = saturate(saturate(saturate(saturate(m * w) * w) * w) * c);
        let mixed = saturate(saturate(saturate(saturate(m * self.rate) * w) * s) * lit(3.0));
        saturate(cubic + mixed)
    }

    /// `(ω(t), sin φ(t), cos φ(t))` with `ω` and `φ` saturated at `±MAX`.
    fn saturated_state(&self, t: T) -> (T, T, T) {
        let w = saturate(self.omega0 + saturate(self.rate * t));
        let half_rate_t = saturate(lit::<T>(0.5) * self.rate * t);
        let phi = saturate(saturate(self.omega0 + half_rate_t) * t);
        let (s, c) = fastmath::sin_cos(phi);
        (w, s, c)
    }

    /// `ω(t) = ω0 + r·t`.
    pub fn omega_at(&self, t: T) -> T {
        self.omega0 + self.rate * t
    }
}

impl<T: Real> Excitation<T> for RampedRotor<T> {
    #[inline(always)]
    fn force(&self, t: T) -> T {
        let w = self.omega0 + self.rate * t;
        let phi = (self.omega0 + lit::<T>(0.5) * self.rate * t) * t;
        let (s, c) = fastmath::sin_cos(phi);
        let f = self.m0e * (w * w * s - self.rate * c);
        if f.is_finite() {
            f
        } else {
            self.saturated_force(t)
        }
    }
    fn force_rate(&self, t: T) -> T {
        let w = self.omega0 + self.rate * t;
        let phi = (self.omega0 + lit::<T>(0.5) * self.rate * t) * t;
        let (s, c) = fastmath::sin_cos(phi);
        let r = self.rate;
        let rate = self.m0e * (lit::<T>(2.0) * w * r * s + w * w * w * c + r * w * s);
        if rate.is_finite() {
            rate
        } else {
            self.saturated_force_rate(t)
        }
    }
    fn phase(&self, t: T) -> Option<T> {
        Some((self.omega0 + lit::<T>(0.5) * self.rate * t) * t)
    }
    fn time_of_phase(&self, phase: T) -> Option<T> {
        // r/2·t² + ω0·t − φ = 0, smallest root t ≥ 0, in the cancellation-free form.
        if self.rate == T::zero() {
            return Some(phase / self.omega0);
        }
        let disc = self.omega0 * self.omega0 + lit::<T>(2.0) * self.rate * phase;
        if disc < T::zero() {
            return None;
        }
        Some(lit::<T>(2.0) * phase / (self.omega0 + disc.sqrt()))
    }
    fn angular_frequency(&self, t: T) -> Option<T> {
        Some(self.omega_at(t))
    }
}

/// The lane form of an [`Excitation`]: `f(t)` of `L` excitations of the same type at once,
/// one per lane, each with its own parameters (see [`LaneLaw`](crate::force::LaneLaw) for
/// packing; the same contract: each lane is the scalar [`force`](Excitation::force) of
/// the excitation packed into it, to the bit with
/// [`LaneMath::Exact`]).
///
/// Implemented by `()`, [`Constant`], [`Harmonic`], [`UnbalancedRotor`] (their `sin` is
/// the lane form of the scalar `fastmath` kernel, [`lanes::math::sin`](crate::lanes::math::sin))
/// and [`RampedRotor`] (evaluated lane by lane).
pub trait LaneExcitation: Excitation<f64> {
    /// The excitation's parameters in `L` lanes.
    type Packed<V: Lanes>: Copy + core::fmt::Debug + Send + Sync;

    /// Every lane set to this excitation.
    fn pack<V: Lanes>(&self) -> Self::Packed<V>;

    /// Lane `lane` of `packed` set to this excitation.
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize);

    /// The force at `t` in every lane.
    fn force_lanes<V: Lanes>(packed: &Self::Packed<V>, math: LaneMath, t: V) -> V;
}

/// [`saturate`] lane-wise.
#[inline(always)]
fn saturate_lanes<V: Lanes>(x: V) -> V {
    let z = V::splat(0.0);
    let max = V::splat(f64::MAX);
    let out = x.gt(z).select(max, x.lt(z).select(-max, x));
    x.finite().select(x, out)
}

impl LaneExcitation for () {
    type Packed<V: Lanes> = ();
    fn pack<V: Lanes>(&self) {}
    fn pack_lane<V: Lanes>(&self, _packed: &mut (), _lane: usize) {}
    #[inline(always)]
    fn force_lanes<V: Lanes>(_packed: &(), _math: LaneMath, _t: V) -> V {
        V::splat(0.0)
    }
}

impl LaneExcitation for Constant<f64> {
    type Packed<V: Lanes> = V;
    fn pack<V: Lanes>(&self) -> V {
        V::splat(self.value)
    }
    fn pack_lane<V: Lanes>(&self, p: &mut V, lane: usize) {
        *p = p.with_lane(lane, self.value);
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &V, _math: LaneMath, _t: V) -> V {
        *p
    }
}

impl LaneExcitation for Harmonic<f64> {
    /// `(F0, ω, φ0)` per lane.
    type Packed<V: Lanes> = [V; 3];
    fn pack<V: Lanes>(&self) -> [V; 3] {
        [self.amplitude, self.omega, self.phase0].map(V::splat)
    }
    fn pack_lane<V: Lanes>(&self, p: &mut [V; 3], lane: usize) {
        for (v, x) in p.iter_mut().zip([self.amplitude, self.omega, self.phase0]) {
            *v = v.with_lane(lane, x);
        }
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &[V; 3], _math: LaneMath, t: V) -> V {
        p[0] * crate::lanes::math::sin(saturate_lanes(p[1] * t + p[2]))
    }
}

impl LaneExcitation for UnbalancedRotor<f64> {
    /// `(m0e·ω², ω)` per lane.
    type Packed<V: Lanes> = [V; 2];
    fn pack<V: Lanes>(&self) -> [V; 2] {
        [self.amp, self.omega].map(V::splat)
    }
    fn pack_lane<V: Lanes>(&self, p: &mut [V; 2], lane: usize) {
        p[0] = p[0].with_lane(lane, self.amp);
        p[1] = p[1].with_lane(lane, self.omega);
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &[V; 2], _math: LaneMath, t: V) -> V {
        p[0] * crate::lanes::math::sin(saturate_lanes(p[1] * t))
    }
}

impl LaneExcitation for RampedRotor<f64> {
    /// One rotor per lane (evaluated lane by lane: the ramp's saturation guards are
    /// scalar code).
    type Packed<V: Lanes> = [RampedRotor<f64>; 16];
    fn pack<V: Lanes>(&self) -> [RampedRotor<f64>; 16] {
        [*self; 16]
    }
    fn pack_lane<V: Lanes>(&self, p: &mut [RampedRotor<f64>; 16], lane: usize) {
        if let Some(r) = p.get_mut(lane) {
            *r = *self;
        }
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(p: &[RampedRotor<f64>; 16], _math: LaneMath, t: V) -> V {
        let mut out = [0.0f64; 16];
        for (i, (o, r)) in out.iter_mut().zip(p).enumerate().take(V::LANES) {
            *o = r.force(t.lane(i));
        }
        V::load(&out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotor_matches_paper_form() {
        let r = UnbalancedRotor::new(0.01805, 20.0).unwrap();
        assert!((r.force(0.1) - 0.01805 * 400.0 * 2.0_f64.sin()).abs() < 1e-14);
        assert_eq!(
            r.time_of_phase(std::f64::consts::TAU * 3.0).unwrap(),
            3.0 * r.period()
        );
    }

    #[test]
    fn ramp_reduces_to_rotor_and_inverts_phase() {
        let ramp = RampedRotor::<f64>::new(0.01805, 14.0, 0.0).unwrap();
        let rot = UnbalancedRotor::new(0.01805, 14.0).unwrap();
        assert!((ramp.force(0.37) - rot.force(0.37)).abs() < 1e-14);
        let ramp = RampedRotor::new(0.01805, 14.0, 8.0905e-3).unwrap();
        for k in [1.0, 10.0, 1000.0] {
            let phi = std::f64::consts::TAU * k;
            let t = ramp.time_of_phase(phi).unwrap();
            assert!((ramp.phase(t).unwrap() - phi).abs() < 1e-10 * phi);
        }
        // df/dt against a central difference.
        let t: f64 = 12.3;
        let h = 1e-6;
        let fd = (ramp.force(t + h) - ramp.force(t - h)) / (2.0 * h);
        assert!((ramp.force_rate(t) - fd).abs() < 1e-6 * fd.abs().max(1.0));
    }

    #[test]
    fn validation() {
        assert!(UnbalancedRotor::new(0.01805, 0.0).is_err());
        assert!(UnbalancedRotor::new(-0.01805, 1.0).is_err());
        assert!(Harmonic::new(1.0, f64::NAN, 0.0).is_err());
        assert!(RampedRotor::new(0.01, 1.0, f64::INFINITY).is_err());
    }
}
