//! The paper's approximate solutions about the static equilibrium (Sect. 5, eqs. 4–6) and
//! their grazing estimates, written for any 1-DOF [`Oscillator`].

use super::AnalysisError;
use crate::excite::{Excitation, UnbalancedRotor};
use crate::model::Oscillator;
use crate::roots::{brent, golden_max};
use crate::scalar::{lit, to_f64};
use crate::validate::{finite, non_negative, positive};
use crate::{ForceLaw, Real};

/// The amplitude `F0(ω)` of a harmonic forcing `F0(ω)·sin ωt` as a function of its frequency.
///
/// The approximations evaluate the forcing at frequencies other than the one an
/// oscillator was built with (grazing searches), so they need this function rather than
/// `f(t)`. Implement it for your own excitation:
/// ```
/// use nonsmooth::analysis::ForcingAmplitude;
/// /// A shaker whose force amplitude falls off as 1/ω.
/// struct Shaker { c: f64 }
/// impl ForcingAmplitude<f64> for Shaker {
///     fn amplitude_at(&self, omega: f64) -> f64 { self.c / omega }
/// }
/// assert_eq!(Shaker { c: 2.0 }.amplitude_at(4.0), 0.5);
/// ```
pub trait ForcingAmplitude<T: Real> {
    /// `F0(ω)` (N).
    fn amplitude_at(&self, omega: T) -> T;
}

/// `F0(ω) = m0·e·ω²`: the paper's unbalanced rotor, whatever speed it was built with.
impl<T: Real> ForcingAmplitude<T> for UnbalancedRotor<T> {
    #[inline]
    fn amplitude_at(&self, omega: T) -> T {
        self.unbalance() * omega * omega
    }
}

impl<T: Real, F: ForcingAmplitude<T> + ?Sized> ForcingAmplitude<T> for &F {
    #[inline]
    fn amplitude_at(&self, omega: T) -> T {
        (**self).amplitude_at(omega)
    }
}

/// AmplitudeLaw amplitude laws for [`LinearizedResponse::from_parts`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum AmplitudeLaw<T> {
    /// `F0(ω) = F0`, independent of the frequency (N).
    Constant(T),
    /// `F0(ω) = m0e·ω²`, an unbalanced rotor with unbalance `m0e` (kg·m).
    Unbalance(T),
}

impl<T: Real> ForcingAmplitude<T> for AmplitudeLaw<T> {
    #[inline]
    fn amplitude_at(&self, omega: T) -> T {
        match *self {
            AmplitudeLaw::Constant(f0) => f0,
            AmplitudeLaw::Unbalance(m0e) => m0e * omega * omega,
        }
    }
}

/// Absolute abscissa tolerance for Brent on `[lo, hi]`: a few ulps of the larger end.
fn xtol<T: Real>(lo: T, hi: T) -> T {
    lit::<T>(4.0) * T::default_epsilon() * lo.abs().max(hi.abs())
}

fn check_bracket<T: Real>(lo: T, hi: T) -> Result<(), AnalysisError> {
    if lo.is_finite() && hi.is_finite() && lo > T::zero() && hi > lo {
        Ok(())
    } else {
        Err(AnalysisError::InvalidBracket {
            lo: to_f64(lo),
            hi: to_f64(hi),
        })
    }
}

fn check_omega<T: Real>(omega: T) -> Result<(), AnalysisError> {
    if omega.is_finite() && omega > T::zero() {
        Ok(())
    } else {
        Err(AnalysisError::InvalidFrequency {
            omega: to_f64(omega),
        })
    }
}

/// Solves `f(ω) = 0` on `[lo, hi]` by Brent, reporting the lack of a sign change as
/// [`AnalysisError::NoGrazingBracket`].
fn grazing_root<T: Real, G: FnMut(T) -> T>(
    mut g: G,
    x_stop: T,
    lo: T,
    hi: T,
) -> Result<T, AnalysisError> {
    check_bracket(lo, hi)?;
    let (glo, ghi) = (g(lo), g(hi));
    let same_sign = (glo > T::zero()) == (ghi > T::zero());
    let no_root = same_sign && glo != T::zero() && ghi != T::zero();
    if !(glo.is_finite() && ghi.is_finite()) || no_root {
        return Err(AnalysisError::NoGrazingBracket {
            x_stop: to_f64(x_stop),
            lo: to_f64(lo),
            hi: to_f64(hi),
            gap_lo: to_f64(glo),
            gap_hi: to_f64(ghi),
        });
    }
    Ok(brent(g, lo, hi, glo, ghi, xtol(lo, hi), 200)?)
}

fn equilibrium<T: Real, L: ForceLaw<T>, E: Excitation<T>>(
    osc: &Oscillator<T, L, E>,
    lo: T,
    hi: T,
) -> Result<T, AnalysisError> {
    osc.static_equilibrium(lo, hi)
        .map_err(|_| AnalysisError::NoEquilibrium {
            lo: to_f64(lo),
            hi: to_f64(hi),
        })
}

/// The linearized steady response about the static equilibrium `X0` (the paper's eq. 4).
///
/// Deserialization (feature `serde`) applies the checks of
/// [`from_parts`](Self::from_parts).
///
/// # Model
/// Linearizing `m ẍ + ΣF(x, ẋ) = F0(ω) sin ωt` about `(X0, 0)`, keeping the static stiffness
/// and the viscous coefficient only,
/// $$m\ddot y + c\dot y + k_\mathrm{eff}\,y = F_0 \sin\omega t,\qquad
///   k_\mathrm{eff} = \left.\frac{\partial \Sigma F}{\partial x}\right|_{(X_0,0)},$$
/// has the steady solution $x = X_0 + A_1\sin\omega t + A_2\cos\omega t$ with
/// $$A_1 = \frac{F_0\,\Delta}{(\omega c)^2 + \Delta^2},\qquad
///   A_2 = -\frac{c\,F_0\,\omega}{(\omega c)^2 + \Delta^2},\qquad
///   \Delta = k_\mathrm{eff} - m\omega^2,$$
/// and amplitude $F_0/\sqrt{(\omega c)^2+\Delta^2}$. For an unbalanced rotor and a Hertz stop
/// of exponent 3/2 pressed at rest, $F_0 = m_0 e\,\omega^2$ and
/// $k_\mathrm{eff} = k + 1.5\,k_I\sqrt{X_0 - x_I}$; here
/// $k_\mathrm{eff}$ comes from the force laws' partials
/// ([`Oscillator::static_stiffness`]), so any oscillator works.
///
/// `c` is passed explicitly: it is the viscous coefficient. The other velocity-dependent
/// terms are dropped, as the method's source does (its `ε`-terms): the regularized dry
/// friction has the slope `T/ε` at `ẋ = 0` (`5·10⁵ N·s/m` for `T = 0.5 N`,
/// `ε = 10⁻⁶ m/s`) and the contact damping
/// `|ẋ|^{n3}` an infinite one, so `∂ΣF/∂ẋ` at rest is no useful damping coefficient for a
/// finite-amplitude oscillation.
///
/// # Examples
/// ```
/// use nonsmooth::analysis::{AmplitudeLaw, LinearizedResponse};
/// // ÿ + 0.2ẏ + 4y = sin ωt about X0 = 0: at ω = 1, Δ = k − mω² = 3 and
/// // A1 = FΔ/((ωc)² + Δ²), A2 = −cFω/((ωc)² + Δ²).
/// let lin = LinearizedResponse::from_parts(1.0, 4.0, 0.2, 0.0, AmplitudeLaw::Constant(1.0))?;
/// let (a1, a2) = lin.coefficients(1.0);
/// let d = 0.2_f64.powi(2) + 9.0;
/// assert!((a1 - 3.0 / d).abs() < 1e-15 && (a2 + 0.2 / d).abs() < 1e-15);
/// // The lower turning point X0 − A(ω) grazes a stop at −0.4 where A(ω) = 0.4.
/// let w = lin.grazing_omega(-0.4, 0.5, 1.9)?;
/// assert!((lin.amplitude(w) - 0.4).abs() < 1e-9);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
///
/// The paper's numbers (its eq. (4) and the grazing at ω = 15.657 rad/s) are in
/// [`systems::paper`](crate::systems::paper), "Results".
///
/// # References
/// The paper's Sect. 5, eq. (4) and the grazing estimate that follows it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LinearizedResponse<T, F = AmplitudeLaw<T>> {
    mass: T,
    stiffness: T,
    damping: T,
    x0: T,
    forcing: F,
}

crate::serde_check::deserialize_checked! {
    "LinearizedResponse",
    LinearizedResponse<T: Real, F> { mass: T, stiffness: T, damping: T, x0: T, forcing: F },
    |raw| -> AnalysisError {
        LinearizedResponse::checked(raw.mass, raw.stiffness, raw.damping, raw.x0, raw.forcing)?
    }
}

impl<T: Real, F> LinearizedResponse<T, F> {
    /// The checks of [`from_parts`](Self::from_parts), shared with deserialization.
    fn checked(
        mass: T,
        stiffness: T,
        damping: T,
        x0: T,
        forcing: F,
    ) -> Result<Self, AnalysisError> {
        Ok(Self {
            mass: positive("mass", mass)?,
            stiffness: finite("stiffness", stiffness)?,
            damping: non_negative("damping", damping)?,
            x0: finite("x0", x0)?,
            forcing,
        })
    }
}

impl<T: Real, F: ForcingAmplitude<T>> LinearizedResponse<T, F> {
    /// The linearization of `osc` about `x0` (its static equilibrium) with viscous
    /// coefficient `damping`; the forcing amplitude law is the oscillator's excitation.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] if `x0` or the static stiffness is not finite or
    /// `damping` is negative or not finite.
    pub fn new<L: ForceLaw<T>>(
        osc: &Oscillator<T, L, F>,
        x0: T,
        damping: T,
    ) -> Result<Self, AnalysisError>
    where
        F: Excitation<T> + Clone,
    {
        let x0 = finite("x0", x0)?;
        Self::from_parts(
            osc.mass(),
            osc.static_stiffness(x0),
            damping,
            x0,
            osc.excitation().clone(),
        )
    }

    /// As [`new`](Self::new), with `X0` solved from the restoring force on `[lo, hi]`.
    ///
    /// # Errors
    /// [`AnalysisError::NoEquilibrium`] if the restoring force does not change sign on
    /// `[lo, hi]`; otherwise as [`new`](Self::new).
    pub fn at_equilibrium<L: ForceLaw<T>>(
        osc: &Oscillator<T, L, F>,
        lo: T,
        hi: T,
        damping: T,
    ) -> Result<Self, AnalysisError>
    where
        F: Excitation<T> + Clone,
    {
        let x0 = equilibrium(osc, lo, hi)?;
        Self::new(osc, x0, damping)
    }

    /// The linear oscillator `m ÿ + c ẏ + k_eff y = F0(ω) sin ωt` about `x0`, from its numbers.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] unless `mass > 0`, `damping ≥ 0`, and `stiffness`, `x0`
    /// are finite.
    pub fn from_parts(
        mass: T,
        stiffness: T,
        damping: T,
        x0: T,
        forcing: F,
    ) -> Result<Self, AnalysisError> {
        Self::checked(mass, stiffness, damping, x0, forcing)
    }

    /// The equilibrium `X0`.
    pub fn equilibrium(&self) -> T {
        self.x0
    }

    /// The static stiffness `k_eff`.
    pub fn stiffness(&self) -> T {
        self.stiffness
    }

    /// The viscous coefficient `c`.
    pub fn damping(&self) -> T {
        self.damping
    }

    /// The mass `m`.
    pub fn mass(&self) -> T {
        self.mass
    }

    /// The forcing amplitude law.
    pub fn forcing(&self) -> &F {
        &self.forcing
    }

    /// `Δ = k_eff − m ω²`.
    pub fn detuning(&self, omega: T) -> T {
        self.stiffness - self.mass * omega * omega
    }

    /// `(A1, A2)`: the coefficients of `sin ωt` and `cos ωt` (∞/NaN at an undamped
    /// resonance `c = 0, Δ = 0`).
    pub fn coefficients(&self, omega: T) -> (T, T) {
        let d = self.detuning(omega);
        let wc = omega * self.damping;
        let f0 = self.forcing.amplitude_at(omega);
        let den = wc * wc + d * d;
        (f0 * d / den, -f0 * wc / den)
    }

    /// The amplitude `F0/√((ωc)² + Δ²)`.
    pub fn amplitude(&self, omega: T) -> T {
        let d = self.detuning(omega);
        let wc = omega * self.damping;
        self.forcing.amplitude_at(omega).abs() / wc.hypot(d)
    }

    /// The approximate displacement `X0 + A1 sin ωt + A2 cos ωt`.
    pub fn displacement(&self, omega: T, t: T) -> T {
        let (a1, a2) = self.coefficients(omega);
        let (s, c) = (omega * t).sin_cos();
        self.x0 + a1 * s + a2 * c
    }

    /// The frequency in `[lo, hi]` at which the turning point on the stop's side reaches the
    /// stop: `|x_stop − X0| = F0/√((ωc)²+Δ²)` — for a stop below the equilibrium, the
    /// paper's `x_I = X0 − m0e ω²/√((ωc)²+Δ²)`. The bracket must hold one crossing; the first
    /// grazing is the smallest root.
    ///
    /// # Errors
    /// [`AnalysisError::InvalidBracket`] unless `0 < lo < hi`;
    /// [`AnalysisError::NoGrazingBracket`] if the amplitude does not cross `|x_stop − X0|`
    /// on the bracket; [`AnalysisError::Root`] if Brent fails.
    pub fn grazing_omega(&self, x_stop: T, lo: T, hi: T) -> Result<T, AnalysisError> {
        let x_stop = finite("x_stop", x_stop)?;
        let gap = (x_stop - self.x0).abs();
        grazing_root(|w| gap - self.amplitude(w), x_stop, lo, hi)
    }
}

/// Which turning point of the orbit the amplitude–phase balance is written at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum TurningPoint {
    /// The maximum `x = X0 + a` (the paper's `ωt = π/2` with `A > 0`; its eq. 6).
    Upper,
    /// The minimum `x = X0 − a` (the paper's equations with `A < 0`, `cos α < 0`; its grazing
    /// estimate `ω = 12.789`).
    Lower,
}

impl TurningPoint {
    /// `"upper"` or `"lower"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            TurningPoint::Upper => "upper",
            TurningPoint::Lower => "lower",
        }
    }
}

/// The amplitude–phase (one-point harmonic balance) approximation of the paper's eqs. (5)–(6).
///
/// # Model
/// Seek $x = X_0 + a\sin(\omega t - \psi)$ with $a > 0$, $\psi\in[0,\pi]$, and require the
/// equation of motion $m\ddot x + R(x) + c\dot x = F_0\sin\omega t$ — with the *full
/// nonlinear* restoring force $R(x) = \Sigma F(x, 0)$
/// ([`Oscillator::restoring_force`]; for the paper $kx + k_I(x-x_I)^{n_1}_+$) and the viscous
/// coefficient `c` only, the friction and contact damping dropped as in the paper — at two
/// phases: at a turning point ($\dot x = 0$) and a quarter period away ($x = X_0$).
/// At the **upper** turning point ($\omega t - \psi = \pi/2$):
/// $$-m a\omega^2 + R(X_0 + a) = F_0\cos\psi,\qquad c\,a\,\omega = F_0\sin\psi;$$
/// at the **lower** one ($\omega t - \psi = -\pi/2$):
/// $$m a\omega^2 + R(X_0 - a) = -F_0\cos\psi,\qquad c\,a\,\omega = F_0\sin\psi.$$
/// Eliminating $\psi$ leaves one equation for $a$, e.g. for the upper point
/// $\bigl(R(X_0+a) - m a\omega^2\bigr)^2 + (c a\omega)^2 = F_0^2$, solved for its smallest
/// root $a > 0$ (the branch continued from the static state); $\psi$ follows from
/// $\sin\psi$ and $\cos\psi$. For a linear restoring force both points give the exact
/// linear response, i.e. [`LinearizedResponse`].
///
/// # The paper's convention
/// The paper writes $-mA\omega^2 + k(A+X_0) + k_I(A+X_0-x_I)^{n_1} = m_0e\omega^2\cos\alpha$,
/// $cA\omega = m_0e\omega^2\sin\alpha$, $x = X_0 + A\sin(\omega t-\alpha)$, and does not say
/// which root it takes. Its numbers are reproduced as follows (see `tests/analysis.rs`):
/// - eq. (6) at ω = 14, $-3.5707\cdot10^{-10}\cos\omega t + 3.6833\cdot10^{-6}\sin\omega t$, is
///   the **upper** balance: $A = a > 0$, $\alpha = \psi \approx 10^{-4}$;
/// - the grazing estimate "$x_I = X_0 + A(\omega)$ ⇒ ω = 12.789" is the **lower** balance:
///   the same equations with $A = -a < 0$ and $\alpha = \psi - \pi$ ($\cos\alpha < 0$),
///   which is the balance at $\omega t - \psi = -\pi/2$ rewritten; it reaches the stop
///   $a = X_0 - x_I$ at ω = 12.78895. The other readings give other numbers or none: the
///   upper amplitude mirrored, $x_I = X_0 - a_\text{upper}(\omega)$, grazes at
///   ω ≈ 17.283; $A = x_I - X_0 < 0$ with $\cos\alpha > 0$ has no solution at any ω
///   (the lower residual at $a = X_0 - x_I$ changes sign once on ω ∈ [10⁻³, 10³] rad/s, at
///   12.789, where $\cos\alpha = -\cos\psi < 0$); and at ω = 14 the lower
///   balance has no root near the contact any more, only a far one
///   ($a \approx 2.03\cdot10^{-2}$ m, $\psi \approx 2.58$, the free spring's resonance
///   $\sqrt{k/m} = 12.745$ rad/s passed).
/// - At the lower-balance grazing the small root merges with a second one exactly at the
///   contact boundary (a fold): just below ω = 12.789 the lower amplitude tends to
///   $X_0 - x_I$, just above it jumps to the far root.
/// - Measuring the restoring force from the equilibrium, $R(X_0+A) - R(X_0)$, changes
///   nothing since $R(X_0) = 0$; linearizing it, $k_\mathrm{eff}A$, gives back eq. (4).
///
/// Because $R$ stiffens strongly in contact and softens to $k$ out of contact, the two
/// balances differ: the lower turning point sees the soft side, whence the earlier grazing.
///
/// The paper's numbers (its eq. (6) and the grazing at ω = 12.789 rad/s), computed with this
/// type, are in [`systems::paper`](crate::systems::paper), "Results".
///
/// # References
/// The paper's Sect. 5, eqs. (5)–(6) and the grazing estimate after them; the method after
/// its refs. [34, 35].
#[derive(Debug, Clone, PartialEq)]
pub struct AmplitudePhase<T: Real, L, E> {
    osc: Oscillator<T, L, E>,
    x0: T,
    damping: T,
}

/// A solution of the amplitude–phase balance: `x = X0 + a·sin(ωt − ψ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AmplitudePhaseSolution<T> {
    /// The forcing frequency `ω`.
    pub omega: T,
    /// The equilibrium `X0`.
    pub x0: T,
    /// The amplitude `a > 0`.
    pub amplitude: T,
    /// The phase lag `ψ ∈ [0, π]` of the response behind the forcing.
    pub lag: T,
    /// The turning point the balance was written at.
    pub turning_point: TurningPoint,
}

impl<T: Real> AmplitudePhaseSolution<T> {
    /// The coefficient of `sin ωt`: `a·cos ψ`.
    pub fn sin_coefficient(&self) -> T {
        self.amplitude * self.lag.cos()
    }

    /// The coefficient of `cos ωt`: `−a·sin ψ`.
    pub fn cos_coefficient(&self) -> T {
        -self.amplitude * self.lag.sin()
    }

    /// `X0 + a sin(ωt − ψ)`.
    pub fn displacement(&self, t: T) -> T {
        self.x0 + self.amplitude * (self.omega * t - self.lag).sin()
    }

    /// The balanced turning point: `X0 + a` (upper) or `X0 − a` (lower).
    pub fn turning_position(&self) -> T {
        match self.turning_point {
            TurningPoint::Upper => self.x0 + self.amplitude,
            TurningPoint::Lower => self.x0 - self.amplitude,
        }
    }

    /// The signed form `(A, α)` with `x = X0 + A sin(ωt − α)` and the sign of `A` naming
    /// the turning point: `(a, ψ)` for the upper point, `(−a, ψ − π)` for the lower one.
    pub fn signed_amplitude_lag(&self) -> (T, T) {
        match self.turning_point {
            TurningPoint::Upper => (self.amplitude, self.lag),
            TurningPoint::Lower => (-self.amplitude, self.lag - T::pi()),
        }
    }
}

/// Geometric step of the outward search for the smallest amplitude root.
const SEARCH_RATIO: f64 = 1.01;
/// The search spans `[10⁻⁶, 10⁶]` times the amplitude scale `F0/(|k_eff| + mω² + cω)`.
const SEARCH_DECADES: f64 = 6.0;

impl<T: Real, L: ForceLaw<T>, E: Excitation<T> + ForcingAmplitude<T>> AmplitudePhase<T, L, E> {
    /// The approximation for `osc` about `x0` (its static equilibrium) with viscous
    /// coefficient `damping`; the forcing amplitude law is the oscillator's excitation.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] if `x0` is not finite or `damping` is negative or not
    /// finite.
    pub fn new(osc: &Oscillator<T, L, E>, x0: T, damping: T) -> Result<Self, AnalysisError>
    where
        L: Clone,
        E: Clone,
    {
        Ok(Self {
            osc: osc.clone(),
            x0: finite("x0", x0)?,
            damping: non_negative("damping", damping)?,
        })
    }

    /// As [`new`](Self::new), with `X0` solved from the restoring force on `[lo, hi]`.
    ///
    /// # Errors
    /// [`AnalysisError::NoEquilibrium`] if the restoring force does not change sign on
    /// `[lo, hi]`; otherwise as [`new`](Self::new).
    pub fn at_equilibrium(
        osc: &Oscillator<T, L, E>,
        lo: T,
        hi: T,
        damping: T,
    ) -> Result<Self, AnalysisError>
    where
        L: Clone,
        E: Clone,
    {
        let x0 = equilibrium(osc, lo, hi)?;
        Self::new(osc, x0, damping)
    }

    /// The equilibrium `X0`.
    pub fn equilibrium(&self) -> T {
        self.x0
    }

    /// The viscous coefficient `c`.
    pub fn damping(&self) -> T {
        self.damping
    }

    /// The balance residual `(R(X0 ± a) ∓ m a ω²)² + (c a ω)² − F0²` at amplitude `a`
    /// (zero at a solution; negative at `a = 0`).
    pub fn residual(&self, omega: T, a: T, point: TurningPoint) -> T {
        let f0 = self.osc.excitation().amplitude_at(omega);
        let r = self.balance(omega, a, point);
        let v = self.damping * a * omega;
        r * r + v * v - f0 * f0
    }

    /// `R(X0 + a) − m a ω²` for the upper point and `−R(X0 − a) − m a ω²` for the lower
    /// one: in both cases the quantity that equals `F0 cos ψ`.
    fn balance(&self, omega: T, a: T, point: TurningPoint) -> T {
        let inertia = self.osc.mass() * a * omega * omega;
        match point {
            TurningPoint::Upper => self.osc.restoring_force(self.x0 + a) - inertia,
            TurningPoint::Lower => -(self.osc.restoring_force(self.x0 - a) + inertia),
        }
    }

    /// The smallest-amplitude solution of the balance at `point` and frequency `omega`.
    ///
    /// The root is bracketed by marching outward from `a = 0` on a geometric grid (ratio
    /// 1.01) over `[10⁻⁶, 10⁶]` times the scale `F0/(|k_eff| + mω² + cω)` (and not beyond
    /// `F0/(cω)`, where `sin ψ` would exceed 1), then refined by Brent to a few ulps. Where
    /// the sampled residual has a local maximum below zero, a golden-section search looks
    /// for a pair of close roots inside the cell (near a fold, e.g. just below a grazing
    /// frequency, the two roots are closer than the grid spacing).
    ///
    /// # Errors
    /// [`AnalysisError::InvalidFrequency`] for a bad `omega`;
    /// [`AnalysisError::Parameter`] if the forcing amplitude is not finite and > 0;
    /// [`AnalysisError::NoSolution`] if no root is found.
    pub fn solve(
        &self,
        omega: T,
        point: TurningPoint,
    ) -> Result<AmplitudePhaseSolution<T>, AnalysisError> {
        check_omega(omega)?;
        let f0 = self.osc.excitation().amplitude_at(omega);
        positive("forcing amplitude", f0)?;
        let m = self.osc.mass();
        let c = self.damping;
        let scale = f0 / (self.osc.static_stiffness(self.x0).abs() + m * omega * omega + c * omega);
        let ten = lit::<T>(10.0);
        let decades = lit::<T>(SEARCH_DECADES);
        let mut cap = scale * ten.powf(decades);
        if c > T::zero() {
            cap = cap.min(f0 / (c * omega));
        }
        // q < 0 at a = 0 (normally H(0) = R(X0)² − F0² = −F0²); the first a with q ≥ 0 is
        // the root sought.
        let sign = if self.residual(omega, T::zero(), point) > T::zero() {
            -T::one()
        } else {
            T::one()
        };
        let q = |a: T| sign * self.residual(omega, a, point);
        let ratio = lit::<T>(SEARCH_RATIO);
        let no_solution = AnalysisError::NoSolution {
            omega: to_f64(omega),
            branch: point.as_str(),
        };
        // The last three grid points (a, q(a)), oldest first.
        let mut p0 = (T::zero(), q(T::zero()));
        let mut p1 = p0;
        let mut a = scale * ten.powf(-decades);
        loop {
            let last = a >= cap;
            if last {
                a = cap;
            }
            let qa = q(a);
            if !qa.is_finite() {
                return Err(no_solution);
            }
            let bracket = if qa >= T::zero() {
                Some((p1, (a, qa)))
            } else if p1.1 > p0.1 && p1.1 >= qa && p0.0 < p1.0 {
                // A sampled local maximum below zero: two close roots (a fold, e.g. the
                // contact boundary at grazing) may hide inside one grid cell. Look.
                let (am, qm) = golden_max(q, p0.0, a, T::default_epsilon().sqrt() * a);
                (qm >= T::zero()).then_some((p0, (am, qm)))
            } else {
                None
            };
            if let Some(((lo, qlo), (hi, qhi))) = bracket {
                let root = brent(q, lo, hi, qlo, qhi, xtol(lo, hi), 200)?;
                return Ok(self.solution(omega, root, point));
            }
            if last {
                return Err(no_solution);
            }
            p0 = p1;
            p1 = (a, qa);
            a *= ratio;
        }
    }

    fn solution(&self, omega: T, a: T, point: TurningPoint) -> AmplitudePhaseSolution<T> {
        // F0·cos ψ and F0·sin ψ; at the root their squares sum to F0² up to rounding, and
        // atan2 normalizes the pair. sin ψ ≥ 0, so ψ ∈ [0, π].
        let cos_f0 = self.balance(omega, a, point);
        let sin_f0 = self.damping * a * omega;
        AmplitudePhaseSolution {
            omega,
            x0: self.x0,
            amplitude: a,
            lag: sin_f0.atan2(cos_f0),
            turning_point: point,
        }
    }

    /// The frequency in `[lo, hi]` at which the balance at `point` has the stop as its turning
    /// point: `a = |x_stop − X0|` solves the balance. With the lower point this is the
    /// paper's "`x_I = X0 + A(ω)` ⇒ ω = 12.789" (see the type's docs).
    ///
    /// The function solved is [`residual`](Self::residual) at `a = |x_stop − X0|` as a
    /// function of `ω`; the bracket must hold one sign change.
    ///
    /// # Errors
    /// [`AnalysisError::WrongSide`] if the stop is above `X0` for the lower point or below it
    /// for the upper one; [`AnalysisError::InvalidBracket`] unless `0 < lo < hi`;
    /// [`AnalysisError::NoGrazingBracket`] if the residual does not change sign on the
    /// bracket; [`AnalysisError::Root`] if Brent fails.
    pub fn grazing_omega(
        &self,
        x_stop: T,
        point: TurningPoint,
        lo: T,
        hi: T,
    ) -> Result<T, AnalysisError> {
        let x_stop = finite("x_stop", x_stop)?;
        let a = match point {
            TurningPoint::Upper => x_stop - self.x0,
            TurningPoint::Lower => self.x0 - x_stop,
        };
        if a <= T::zero() {
            return Err(AnalysisError::WrongSide {
                x_stop: to_f64(x_stop),
                x0: to_f64(self.x0),
                branch: point.as_str(),
            });
        }
        grazing_root(|w| self.residual(w, a, point), x_stop, lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::excite::Harmonic;
    use crate::force::{LinearSpring, ViscousDamper};

    #[test]
    fn linear_oscillator_amplitude_phase_equals_linearization() {
        // For a linear spring both balances are exact: they must agree with eq. (4), on
        // both sides of the resonance sqrt(k/m) = 2.
        let k = 4.0_f64;
        let osc = Oscillator::new(
            1.0,
            LinearSpring::new(k).unwrap(),
            UnbalancedRotor::new(0.1, 1.0).unwrap(),
        )
        .unwrap();
        let lin = LinearizedResponse::new(&osc, 0.0, 0.3).unwrap();
        let ap = AmplitudePhase::new(&osc, 0.0, 0.3).unwrap();
        for &w in &[0.5, 1.9, 2.0, 2.2, 5.0] {
            let (a1, a2) = lin.coefficients(w);
            for p in [TurningPoint::Upper, TurningPoint::Lower] {
                let s = ap.solve(w, p).unwrap();
                assert!((s.amplitude - lin.amplitude(w)).abs() < 1e-13 * lin.amplitude(w));
                assert!(
                    (s.sin_coefficient() - a1).abs() < 1e-12 * lin.amplitude(w),
                    "{w} {p:?}"
                );
                assert!(
                    (s.cos_coefficient() - a2).abs() < 1e-12 * lin.amplitude(w),
                    "{w} {p:?}"
                );
            }
        }
        // The damper in the laws is ignored by the static quantities.
        let osc2 = Oscillator::new(
            1.0,
            (
                LinearSpring::new(k).unwrap(),
                ViscousDamper::new(9.0).unwrap(),
            ),
            UnbalancedRotor::new(0.1, 1.0).unwrap(),
        )
        .unwrap();
        assert_eq!(
            LinearizedResponse::new(&osc2, 0.0, 0.3)
                .unwrap()
                .stiffness(),
            k
        );
    }

    #[test]
    fn from_parts_validation_and_forcing_laws() {
        assert!(
            LinearizedResponse::from_parts(0.0, 1.0, 0.1, 0.0, AmplitudeLaw::Constant(1.0))
                .is_err()
        );
        assert!(
            LinearizedResponse::from_parts(1.0, 1.0, -0.1, 0.0, AmplitudeLaw::Constant(1.0))
                .is_err()
        );
        assert!(
            LinearizedResponse::from_parts(1.0, f64::NAN, 0.1, 0.0, AmplitudeLaw::Constant(1.0))
                .is_err()
        );
        let l = LinearizedResponse::from_parts(1.0_f64, 1.0, 0.0, 0.0, AmplitudeLaw::Constant(2.0))
            .unwrap();
        // Static limit: amplitude F0/k.
        assert!((l.amplitude(1e-9) - 2.0).abs() < 1e-12);
        assert_eq!(AmplitudeLaw::Unbalance(0.5).amplitude_at(2.0), 2.0);
        // A Harmonic excitation has no amplitude law: use from_parts.
        let _ = Harmonic::new(1.0, 1.0, 0.0).unwrap();
    }
}
