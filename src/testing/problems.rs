//! Smooth reference problems with closed-form solutions, and the Lorenz system.

use nalgebra::{SMatrix, SVector};

use crate::scalar::lit;
use crate::validate::ParameterError;
use crate::validate::{finite, positive};
use crate::{Dynamics, Real};

/// A reference problem whose solution is known in closed form.
///
/// `exact(t, y0)` is the state at time `t` of the solution that starts from `y0` at `t = 0`
/// (for non-autonomous problems the time origin matters: it is `t = 0`).
///
/// ```
/// use nalgebra::Vector2;
/// use nonsmooth::testing::{ExactSolution, HarmonicOscillator};
///
/// let osc = HarmonicOscillator::new(2.0)?;
/// let y = osc.exact(std::f64::consts::PI, &Vector2::new(1.0, 0.0)); // one full period
/// assert!((y[0] - 1.0).abs() < 1e-14 && y[1].abs() < 1e-14);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
pub trait ExactSolution<T: Real, const N: usize>: Dynamics<T, N> {
    /// The state at `t` of the solution through `y0` at `t = 0`.
    fn exact(&self, t: T, y0: &SVector<T, N>) -> SVector<T, N>;
}

/// The harmonic oscillator `ẍ + ω²x = 0`, state `(x, ẋ)`.
///
/// # Model
/// $$x(t) = x_0\cos\omega t + \frac{v_0}{\omega}\sin\omega t .$$
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicOscillator<T> {
    pub(super) omega: T,
}

impl<T: Real> HarmonicOscillator<T> {
    /// The oscillator with angular frequency `omega` (rad/s).
    ///
    /// # Errors
    /// [`ParameterError`] unless `omega` is finite and > 0.
    pub fn new(omega: T) -> Result<Self, ParameterError> {
        Ok(Self {
            omega: positive("omega", omega)?,
        })
    }

    /// The angular frequency `ω`.
    pub fn omega(&self) -> T {
        self.omega
    }

    /// The conserved energy `(ẋ² + ω²x²)/2`.
    pub fn energy(&self, y: &SVector<T, 2>) -> T {
        (y[1] * y[1] + self.omega * self.omega * y[0] * y[0]) * lit(0.5)
    }
}

impl<T: Real> Dynamics<T, 2> for HarmonicOscillator<T> {
    #[inline(always)]
    fn rhs(&self, _t: T, y: &SVector<T, 2>, dy: &mut SVector<T, 2>) {
        dy[0] = y[1];
        dy[1] = -self.omega * self.omega * y[0];
    }
    fn jacobian(&self, _t: T, _y: &SVector<T, 2>) -> Option<SMatrix<T, 2, 2>> {
        Some(SMatrix::<T, 2, 2>::new(
            T::zero(),
            T::one(),
            -self.omega * self.omega,
            T::zero(),
        ))
    }
    fn time_derivative(&self, _t: T, _y: &SVector<T, 2>) -> Option<SVector<T, 2>> {
        Some(SVector::zeros())
    }
}

impl<T: Real> ExactSolution<T, 2> for HarmonicOscillator<T> {
    fn exact(&self, t: T, y0: &SVector<T, 2>) -> SVector<T, 2> {
        let w = self.omega;
        let (s, c) = (w * t).sin_cos();
        SVector::<T, 2>::new(y0[0] * c + y0[1] / w * s, -y0[0] * w * s + y0[1] * c)
    }
}

/// The underdamped oscillator `ẍ + 2ζω₀ẋ + ω₀²x = 0` (`0 ≤ ζ < 1`), state `(x, ẋ)`.
///
/// # Model
/// With `a = ζω₀` and `ω_d = ω₀√(1−ζ²)`:
/// $$x(t) = e^{-at}\Big(x_0\cos\omega_d t + \frac{v_0 + a x_0}{\omega_d}\sin\omega_d t\Big),\quad
///   \dot x(t) = e^{-at}\Big(v_0\cos\omega_d t - \frac{a v_0 + \omega_0^2 x_0}{\omega_d}\sin\omega_d t\Big).$$
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DampedOscillator<T> {
    omega0: T,
    zeta: T,
}

impl<T: Real> DampedOscillator<T> {
    /// The oscillator with natural frequency `omega0` and damping ratio `zeta`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `omega0 > 0` and `0 ≤ zeta < 1` (underdamped), both finite.
    pub fn new(omega0: T, zeta: T) -> Result<Self, ParameterError> {
        let omega0 = positive("omega0", omega0)?;
        if !(zeta.is_finite() && zeta >= T::zero() && zeta < T::one()) {
            return Err(ParameterError::new(
                "zeta",
                crate::scalar::to_f64(zeta),
                "in [0, 1) (underdamped)",
            ));
        }
        Ok(Self { omega0, zeta })
    }

    /// The natural frequency `ω₀`.
    pub fn omega0(&self) -> T {
        self.omega0
    }

    /// The damping ratio `ζ`.
    pub fn zeta(&self) -> T {
        self.zeta
    }

    /// The damped frequency `ω_d = ω₀√(1−ζ²)`.
    pub fn damped_frequency(&self) -> T {
        self.omega0 * (T::one() - self.zeta * self.zeta).sqrt()
    }
}

impl<T: Real> Dynamics<T, 2> for DampedOscillator<T> {
    #[inline(always)]
    fn rhs(&self, _t: T, y: &SVector<T, 2>, dy: &mut SVector<T, 2>) {
        dy[0] = y[1];
        dy[1] = -lit::<T>(2.0) * self.zeta * self.omega0 * y[1] - self.omega0 * self.omega0 * y[0];
    }
    fn jacobian(&self, _t: T, _y: &SVector<T, 2>) -> Option<SMatrix<T, 2, 2>> {
        Some(SMatrix::<T, 2, 2>::new(
            T::zero(),
            T::one(),
            -self.omega0 * self.omega0,
            -lit::<T>(2.0) * self.zeta * self.omega0,
        ))
    }
    fn time_derivative(&self, _t: T, _y: &SVector<T, 2>) -> Option<SVector<T, 2>> {
        Some(SVector::zeros())
    }
}

impl<T: Real> ExactSolution<T, 2> for DampedOscillator<T> {
    fn exact(&self, t: T, y0: &SVector<T, 2>) -> SVector<T, 2> {
        let a = self.zeta * self.omega0;
        let wd = self.damped_frequency();
        let (s, c) = (wd * t).sin_cos();
        let e = (-a * t).exp();
        let (x0, v0) = (y0[0], y0[1]);
        SVector::<T, 2>::new(
            e * (x0 * c + (v0 + a * x0) / wd * s),
            e * (v0 * c - (a * v0 + self.omega0 * self.omega0 * x0) / wd * s),
        )
    }
}

/// Exponential decay `ẏ = −λy`, `y(t) = y₀e^{−λt}`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExponentialDecay<T> {
    lambda: T,
}

impl<T: Real> ExponentialDecay<T> {
    /// Decay with rate `lambda` (negative values give growth).
    ///
    /// # Errors
    /// [`ParameterError`] unless `lambda` is finite.
    pub fn new(lambda: T) -> Result<Self, ParameterError> {
        Ok(Self {
            lambda: finite("lambda", lambda)?,
        })
    }

    /// The rate `λ`.
    pub fn lambda(&self) -> T {
        self.lambda
    }
}

impl<T: Real> Dynamics<T, 1> for ExponentialDecay<T> {
    #[inline(always)]
    fn rhs(&self, _t: T, y: &SVector<T, 1>, dy: &mut SVector<T, 1>) {
        dy[0] = -self.lambda * y[0];
    }
    fn jacobian(&self, _t: T, _y: &SVector<T, 1>) -> Option<SMatrix<T, 1, 1>> {
        Some(SMatrix::<T, 1, 1>::new(-self.lambda))
    }
    fn time_derivative(&self, _t: T, _y: &SVector<T, 1>) -> Option<SVector<T, 1>> {
        Some(SVector::zeros())
    }
}

impl<T: Real> ExactSolution<T, 1> for ExponentialDecay<T> {
    fn exact(&self, t: T, y0: &SVector<T, 1>) -> SVector<T, 1> {
        SVector::<T, 1>::new(y0[0] * (-self.lambda * t).exp())
    }
}

/// The Prothero–Robinson problem `ẏ = −λ(y − sin t) + cos t`: non-autonomous, smooth, stiff
/// for large `λ`.
///
/// # Model
/// $$y(t) = \sin t + y_0\,e^{-\lambda t}.$$
/// With `λ = 1` it is `ẏ = −y + sin t + cos t`. Because the forcing enters through `t`, a
/// Runge–Kutta tableau with wrong nodes `c_i` loses its order here while staying exact on
/// autonomous problems: use it (and [`ForcedOscillator`]) for order tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProtheroRobinson<T> {
    lambda: T,
}

impl<T: Real> ProtheroRobinson<T> {
    /// The problem with stiffness `lambda`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `lambda` is finite.
    pub fn new(lambda: T) -> Result<Self, ParameterError> {
        Ok(Self {
            lambda: finite("lambda", lambda)?,
        })
    }

    /// The stiffness `λ`.
    pub fn lambda(&self) -> T {
        self.lambda
    }
}

impl<T: Real> Dynamics<T, 1> for ProtheroRobinson<T> {
    #[inline(always)]
    fn rhs(&self, t: T, y: &SVector<T, 1>, dy: &mut SVector<T, 1>) {
        let (s, c) = t.sin_cos();
        dy[0] = -self.lambda * (y[0] - s) + c;
    }
    fn jacobian(&self, _t: T, _y: &SVector<T, 1>) -> Option<SMatrix<T, 1, 1>> {
        Some(SMatrix::<T, 1, 1>::new(-self.lambda))
    }
    fn time_derivative(&self, t: T, _y: &SVector<T, 1>) -> Option<SVector<T, 1>> {
        let (s, c) = t.sin_cos();
        Some(SVector::<T, 1>::new(self.lambda * c - s))
    }
}

impl<T: Real> ExactSolution<T, 1> for ProtheroRobinson<T> {
    fn exact(&self, t: T, y0: &SVector<T, 1>) -> SVector<T, 1> {
        SVector::<T, 1>::new(t.sin() + y0[0] * (-self.lambda * t).exp())
    }
}

/// The harmonically forced undamped oscillator `ẍ + ω²x = a·cos Ωt` (`Ω ≠ ω`), state
/// `(x, ẋ)`; [`canonical`](Self::canonical) is `ẍ + x = cos 2t`.
///
/// # Model
/// With `P = a/(ω² − Ω²)`:
/// $$x(t) = (x_0 - P)\cos\omega t + \frac{v_0}{\omega}\sin\omega t + P\cos\Omega t .$$
/// Non-autonomous: see [`ProtheroRobinson`] for why order tests need that.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForcedOscillator<T> {
    omega: T,
    amplitude: T,
    forcing_frequency: T,
}

impl<T: Real> ForcedOscillator<T> {
    /// `ẍ + ω²x = a·cos Ωt` with `omega = ω`, `amplitude = a`, `forcing_frequency = Ω`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `omega > 0`, `amplitude` and `forcing_frequency` are finite,
    /// and the forcing is away from resonance: `|ω² − Ω²| > 10⁻⁶·max(ω², Ω²)`.
    pub fn new(omega: T, amplitude: T, forcing_frequency: T) -> Result<Self, ParameterError> {
        let omega = positive("omega", omega)?;
        let amplitude = finite("amplitude", amplitude)?;
        let forcing_frequency = finite("forcing_frequency", forcing_frequency)?;
        let (w2, f2) = (omega * omega, forcing_frequency * forcing_frequency);
        if (w2 - f2).abs() <= lit::<T>(1e-6) * w2.max(f2) {
            return Err(ParameterError::new(
                "forcing_frequency",
                crate::scalar::to_f64(forcing_frequency),
                "away from resonance: |omega^2 - forcing_frequency^2| > 1e-6 max(..)",
            ));
        }
        Ok(Self {
            omega,
            amplitude,
            forcing_frequency,
        })
    }

    /// `ẍ + x = cos 2t`, with `x(t) = (x₀ + ⅓)cos t + v₀ sin t − ⅓cos 2t`.
    pub fn canonical() -> Self {
        Self {
            omega: T::one(),
            amplitude: T::one(),
            forcing_frequency: lit(2.0),
        }
    }

    /// The particular amplitude `P = a/(ω² − Ω²)`.
    pub fn particular_amplitude(&self) -> T {
        self.amplitude / (self.omega * self.omega - self.forcing_frequency * self.forcing_frequency)
    }
}

impl<T: Real> Dynamics<T, 2> for ForcedOscillator<T> {
    #[inline(always)]
    fn rhs(&self, t: T, y: &SVector<T, 2>, dy: &mut SVector<T, 2>) {
        dy[0] = y[1];
        dy[1] =
            self.amplitude * (self.forcing_frequency * t).cos() - self.omega * self.omega * y[0];
    }
    fn jacobian(&self, _t: T, _y: &SVector<T, 2>) -> Option<SMatrix<T, 2, 2>> {
        Some(SMatrix::<T, 2, 2>::new(
            T::zero(),
            T::one(),
            -self.omega * self.omega,
            T::zero(),
        ))
    }
    fn time_derivative(&self, t: T, _y: &SVector<T, 2>) -> Option<SVector<T, 2>> {
        let f = self.forcing_frequency;
        Some(SVector::<T, 2>::new(
            T::zero(),
            -self.amplitude * f * (f * t).sin(),
        ))
    }
}

impl<T: Real> ExactSolution<T, 2> for ForcedOscillator<T> {
    fn exact(&self, t: T, y0: &SVector<T, 2>) -> SVector<T, 2> {
        let (w, f) = (self.omega, self.forcing_frequency);
        let p = self.particular_amplitude();
        let (s, c) = (w * t).sin_cos();
        let (sf, cf) = (f * t).sin_cos();
        let a0 = y0[0] - p;
        SVector::<T, 2>::new(
            a0 * c + y0[1] / w * s + p * cf,
            -a0 * w * s + y0[1] * c - p * f * sf,
        )
    }
}

/// The Lorenz system `ẋ = σ(y − x)`, `ẏ = x(ρ − z) − y`, `ż = xy − βz`.
///
/// # Model
/// $$J = \begin{pmatrix} -\sigma & \sigma & 0\\ \rho - z & -1 & -x\\ y & x & -\beta\end{pmatrix},
///   \qquad \operatorname{tr} J = -(\sigma + 1 + \beta),$$
/// so the Lyapunov spectrum sums to `−(σ+1+β)` ([`lyapunov_sum`](Self::lyapunov_sum)). For
/// the classic parameters (10, 28, 8/3) the top exponent is
/// [`TOP_LYAPUNOV_CLASSIC`](Self::TOP_LYAPUNOV_CLASSIC) ≈ 0.9056, the second is 0 and the
/// sum is −41/3.
///
/// # References
/// E. N. Lorenz, *Deterministic nonperiodic flow*, J. Atmos. Sci. 20 (1963); the spectrum
/// (0.9056, 0, −14.5723) from J. C. Sprott, *Chaos and Time-Series Analysis* (2003).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lorenz<T> {
    sigma: T,
    rho: T,
    beta: T,
}

impl<T: Real> Lorenz<T> {
    /// The largest Lyapunov exponent for `σ = 10, ρ = 28, β = 8/3` (Sprott 2003).
    pub const TOP_LYAPUNOV_CLASSIC: f64 = 0.9056;

    /// The system with parameters `sigma`, `rho`, `beta`.
    ///
    /// # Errors
    /// [`ParameterError`] unless all three are finite.
    pub fn new(sigma: T, rho: T, beta: T) -> Result<Self, ParameterError> {
        Ok(Self {
            sigma: finite("sigma", sigma)?,
            rho: finite("rho", rho)?,
            beta: finite("beta", beta)?,
        })
    }

    /// The classic chaotic parameters `σ = 10, ρ = 28, β = 8/3`.
    pub fn classic() -> Self {
        Self {
            sigma: lit(10.0),
            rho: lit(28.0),
            beta: lit(8.0 / 3.0),
        }
    }

    /// The sum of the Lyapunov spectrum, `−(σ + 1 + β)` (the constant trace of `J`).
    pub fn lyapunov_sum(&self) -> T {
        -(self.sigma + T::one() + self.beta)
    }

    /// `(σ, ρ, β)`.
    pub fn parameters(&self) -> (T, T, T) {
        (self.sigma, self.rho, self.beta)
    }
}

impl<T: Real> Dynamics<T, 3> for Lorenz<T> {
    #[inline(always)]
    fn rhs(&self, _t: T, y: &SVector<T, 3>, dy: &mut SVector<T, 3>) {
        dy[0] = self.sigma * (y[1] - y[0]);
        dy[1] = y[0] * (self.rho - y[2]) - y[1];
        dy[2] = y[0] * y[1] - self.beta * y[2];
    }
    fn jacobian(&self, _t: T, y: &SVector<T, 3>) -> Option<SMatrix<T, 3, 3>> {
        Some(SMatrix::<T, 3, 3>::new(
            -self.sigma,
            self.sigma,
            T::zero(),
            self.rho - y[2],
            -T::one(),
            -y[0],
            y[1],
            y[0],
            -self.beta,
        ))
    }
    fn time_derivative(&self, _t: T, _y: &SVector<T, 3>) -> Option<SVector<T, 3>> {
        Some(SVector::zeros())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, Vector2};

    #[test]
    fn validation() {
        assert!(HarmonicOscillator::new(0.0).is_err());
        assert!(DampedOscillator::new(1.0, 1.0).is_err());
        assert!(DampedOscillator::new(1.0, -0.1).is_err());
        assert!(ExponentialDecay::new(f64::NAN).is_err());
        assert!(ProtheroRobinson::new(f64::INFINITY).is_err());
        assert!(ForcedOscillator::new(1.0, 1.0, 1.0).is_err());
        assert!(ForcedOscillator::new(1.0, 1.0, -1.0).is_err());
        assert!(Lorenz::new(10.0, f64::NAN, 1.0).is_err());
    }

    #[test]
    fn initial_values_and_f32() {
        let y0 = Vector2::new(0.3, -0.7);
        assert_eq!(HarmonicOscillator::new(3.0).unwrap().exact(0.0, &y0), y0);
        let d = DampedOscillator::new(3.0, 0.2).unwrap().exact(0.0, &y0);
        assert!((d - y0).norm() < 1e-15);
        let f = ForcedOscillator::canonical().exact(0.0, &y0);
        assert!((f - y0).norm() < 1e-15);
        let p = ProtheroRobinson::new(5.0)
            .unwrap()
            .exact(0.0, &Vector1::new(2.0));
        assert_eq!(p[0], 2.0);
        let o = HarmonicOscillator::new(2.0_f32).unwrap();
        let y = o.exact(core::f32::consts::PI, &Vector2::new(1.0_f32, 0.0));
        assert!((y[0] - 1.0).abs() < 1e-5);
        let mut dy = Vector2::zeros();
        o.rhs(0.0, &Vector2::new(1.0, 2.0), &mut dy);
        assert_eq!(dy, Vector2::new(2.0, -4.0));
    }
}
