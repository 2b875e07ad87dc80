//! A relay load on a [`Mechanical`] model: a generalized force `u = −U·sgn(σ(q, q̇))` along a
//! direction, switched by a linear function of the state.

use nalgebra::{SMatrix, SVector};

use super::system::{Filippov, Region};
use crate::model::{Elements, Loads, Mechanical};
use crate::scalar::to_f64;
use crate::validate::ParameterError;
use crate::{Dynamics, Real};

/// A [`Mechanical`] model with a relay load, as a Filippov system of state `(q, q̇)`
/// (`M = 2N`) with one surface:
/// $$ \sigma = s_q\cdot q + s_v\cdot\dot q, \qquad
///    M\ddot q = f(t, q, \dot q) + b\,u, \qquad u = -U\operatorname{sgn}\sigma . $$
/// Where both fields push into `σ = 0` the state slides on it with the equivalent control
/// `u_eq = U(1 − 2α)` (e.g. sliding-mode control: on `σ = q̇ + λq = 0` the coordinate
/// decays as `e^{−λt}` whatever the rest of the model).
///
/// # Example
/// A mass on a spring, `q̈ + q = u`, `u = −2 sgn(q̇ + q)`: from `q = 1` it reaches
/// `q̇ = −q` and slides there, `q` decaying as `e^{−t}`.
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::filippov::{FilippovSimulation, RelayLoad};
/// use nonsmooth::force::LinearSpring;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::model::{Element, Mechanical};
///
/// let model = Mechanical::with_masses([1.0_f64])?
///     .with_elements(Element::on_dof(0, LinearSpring::new(1.0)?)?);
/// let relay = RelayLoad::new(&model, SVector::from([1.0]), SVector::from([1.0]), SVector::from([1.0]), 2.0)?;
/// let mut sim = FilippovSimulation::new(relay, Dopri5::new(Tolerances::new(1e-10, 1e-12)?));
/// let run = sim.run(0.0, SVector::from([1.0, 0.0]), 6.0, &mut ())?;
/// let entry = run.transitions[0];
/// assert!(run.mode.is_sliding());
/// assert!((run.x[0] - entry.x[0] * (entry.t - 6.0).exp()).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct RelayLoad<'a, T: Real, const N: usize, El, Ld> {
    model: &'a Mechanical<T, N, El, Ld>,
    sigma_q: SVector<T, N>,
    sigma_v: SVector<T, N>,
    amplitude: T,
    /// `M⁻¹b·U`.
    m_b: SVector<T, N>,
}

impl<'a, T, const N: usize, El, Ld> RelayLoad<'a, T, N, El, Ld>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
{
    /// `model` with the load `b·u`, `u = −amplitude·sgn(σ)`, `σ = sigma_q·q + sigma_v·q̇`.
    ///
    /// # Errors
    /// [`ParameterError`] naming the first non-finite entry of `sigma_q`, `sigma_v` or `b`,
    /// a switching function that is zero (no surface), or an amplitude that is not finite
    /// and > 0.
    pub fn new(
        model: &'a Mechanical<T, N, El, Ld>,
        sigma_q: SVector<T, N>,
        sigma_v: SVector<T, N>,
        b: SVector<T, N>,
        amplitude: T,
    ) -> Result<Self, ParameterError> {
        for (name, v) in sigma_q
            .iter()
            .map(|v| ("sigma_q", *v))
            .chain(sigma_v.iter().map(|v| ("sigma_v", *v)))
            .chain(b.iter().map(|v| ("b", *v)))
        {
            if !v.is_finite() {
                return Err(ParameterError::new(name, to_f64(v), "finite entries"));
            }
        }
        if sigma_q.amax() == T::zero() && sigma_v.amax() == T::zero() {
            return Err(ParameterError::new(
                "sigma",
                0.0,
                "non-zero (the switching surface σ = 0)",
            ));
        }
        crate::validate::positive("relay amplitude", amplitude)?;
        let (m_b, _) = model.mobility(&b);
        Ok(Self {
            model,
            sigma_q,
            sigma_v,
            amplitude,
            m_b: m_b * amplitude,
        })
    }

    /// The relay's amplitude `U`.
    pub fn amplitude(&self) -> T {
        self.amplitude
    }
}

impl<T, const N: usize, const M: usize, El, Ld> Filippov<T, M, 1> for RelayLoad<'_, T, N, El, Ld>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
{
    #[inline(always)]
    fn surface(&self, _i: usize, _t: T, y: &SVector<T, M>) -> T {
        let mut s = T::zero();
        for k in 0..N {
            s += self.sigma_q[k] * y[k] + self.sigma_v[k] * y[N + k];
        }
        s
    }

    fn gradient(&self, _i: usize, _t: T, _y: &SVector<T, M>) -> SVector<T, M> {
        let mut g = SVector::<T, M>::zeros();
        for k in 0..N {
            g[k] = self.sigma_q[k];
            g[N + k] = self.sigma_v[k];
        }
        g
    }

    #[inline(always)]
    fn field(&self, sides: &[Region; 1], t: T, y: &SVector<T, M>, dy: &mut SVector<T, M>) {
        // u = −U sgn σ: +U below the surface, −U above.
        sided_field(self.model, &self.m_b, -sides[0].sign::<T>(), t, y, dy);
    }

    fn field_jacobian(
        &self,
        _sides: &[Region; 1],
        t: T,
        y: &SVector<T, M>,
    ) -> Option<SMatrix<T, M, M>> {
        // The load is constant in each region.
        self.model.jacobian(t, y)
    }

    fn time_scale(&self, t: T) -> Option<T> {
        self.model.forcing_time_scale(t)
    }
}

/// The field `q̇ = v`, `v̇ = a(t, y) + s·d` of `model` with a constant generalized force
/// whose acceleration is `d` (`M⁻¹` applied), of sign `s` on the current side.
#[inline(always)]
pub(crate) fn sided_field<T, const N: usize, const M: usize, El, Ld>(
    model: &Mechanical<T, N, El, Ld>,
    d: &SVector<T, N>,
    s: T,
    t: T,
    y: &SVector<T, M>,
    dy: &mut SVector<T, M>,
) where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
{
    let a = model.acceleration(t, y);
    for k in 0..N {
        dy[k] = y[N + k];
        dy[N + k] = a[k] + d[k] * s;
    }
}
