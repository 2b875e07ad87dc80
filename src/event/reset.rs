//! Reset maps applied at an event: the identity, Newton's restitution on one component and
//! the impact law on a contact gap.

use nalgebra::SVector;

use super::error::EventError;
use super::function::check_index;
use super::surface::Gap;
use crate::Real;
use crate::validate::{ParameterError, non_negative};

/// A map `y⁺ = R(y⁻)` applied at an event (e.g. a rigid impact law).
pub trait ResetMap<T: Real, const N: usize> {
    /// `false` only for the identity (no reset), which lets the driver skip the rewind.
    const RESETS: bool = true;
    /// Applies the reset in place.
    fn apply(&self, t: T, y: &mut SVector<T, N>);
    /// Checks indices against the state dimension `N` (called before a run). Default: `Ok`.
    ///
    /// # Errors
    /// [`EventError::IndexOutOfRange`] for an index `≥ N`.
    fn check(&self) -> Result<(), EventError> {
        Ok(())
    }
}

/// No reset.
impl<T: Real, const N: usize> ResetMap<T, N> for () {
    const RESETS: bool = false;
    #[inline(always)]
    fn apply(&self, _t: T, _y: &mut SVector<T, N>) {}
}

/// Newton's restitution law `ẏ[velocity]⁺ = −r·ẏ[velocity]⁻`.
///
/// Deserialization (feature `serde`) applies the constructor's check of `r` (the index is
/// checked against the state when a run starts). Applied directly to a state without
/// component `velocity`, [`apply`](ResetMap::apply) leaves the state unchanged (no panic);
/// [`check`](ResetMap::check) reports such an index.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Restitution<T> {
    velocity: usize,
    r: T,
}

crate::serde_check::deserialize_checked! {
    "Restitution", Restitution<T: Real> { velocity: usize, r: T },
    |raw| -> ParameterError { Restitution::new(raw.velocity, raw.r)? }
}

impl<T: Real> Restitution<T> {
    /// Restitution coefficient `r ≥ 0` acting on component `velocity`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `r` is finite and ≥ 0.
    pub fn new(velocity: usize, r: T) -> Result<Self, ParameterError> {
        Ok(Self {
            velocity,
            r: non_negative("r", r)?,
        })
    }
}

impl<T: Real, const N: usize> ResetMap<T, N> for Restitution<T> {
    #[inline(always)]
    fn apply(&self, _t: T, y: &mut SVector<T, N>) {
        // An index outside the state leaves it unchanged (`check` reports it), never a panic.
        if let Some(v) = y.get_mut(self.velocity) {
            *v = -self.r * *v;
        }
    }
    fn check(&self) -> Result<(), EventError> {
        check_index(self.velocity, N)
    }
}

/// Newton's restitution law on a contact [`Gap`] of an `N`-DOF mechanical system, fixed or
/// moving: the normal relative velocity reverses, scaled by `e`,
/// $$\dot g^+ = -e\,\dot g^-,\qquad \dot q^+ = \dot q^- - (1+e)\,
///   \frac{w\cdot\dot q^- - \dot s(t)}{w^{\mathsf T}\mathbf M^{-1}w}\,\mathbf M^{-1}w,$$
/// an impulse along the surface's gradient `w` (the coordinate's weights) that leaves the
/// positions and every velocity component orthogonal (in the mass metric) unchanged. For a
/// single mass against a surface moving with velocity `ṡ` this is `v⁺ = ṡ − e·(v⁻ − ṡ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonImpact<T: Real, const N: usize, S = ()> {
    gap: Gap<T, N, S>,
    e: T,
    /// `M⁻¹w / (wᵀM⁻¹w)`.
    direction: SVector<T, N>,
}

impl<T: Real, const N: usize, S: crate::excite::Excitation<T>> NewtonImpact<T, N, S> {
    /// Restitution `e ∈ [0, 1]` on `gap` for a system with mass matrix `mass` (e.g.
    /// [`Mechanical::mass_matrix`](crate::model::Mechanical::mass_matrix)).
    ///
    /// # Errors
    /// [`ParameterError`] unless `0 ≤ e ≤ 1`, or if `mass` is singular or not positive along
    /// the gap's gradient (`wᵀM⁻¹w ≤ 0`).
    pub fn new(
        gap: Gap<T, N, S>,
        e: T,
        mass: &nalgebra::SMatrix<T, N, N>,
    ) -> Result<Self, ParameterError> {
        if !(e >= T::zero() && e <= T::one()) {
            return Err(ParameterError::new(
                "e",
                crate::scalar::to_f64(e),
                "in [0, 1]",
            ));
        }
        let inv = mass
            .try_inverse()
            .ok_or(ParameterError::new("mass", f64::NAN, "invertible"))?;
        let w = gap.coordinate().weights();
        let m_w = inv * w;
        let denom = w.dot(&m_w);
        if !(denom > T::zero() && denom.is_finite()) {
            return Err(ParameterError::new(
                "mass",
                crate::scalar::to_f64(denom),
                "positive definite along the gap (wᵀM⁻¹w > 0)",
            ));
        }
        Ok(Self {
            gap,
            e,
            direction: m_w / denom,
        })
    }

    /// For unit masses (`M = I`): `q̇⁺ = q̇⁻ − (1+e)(w·q̇⁻ − ṡ)·w/|w|²`.
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn unit_mass(gap: Gap<T, N, S>, e: T) -> Result<Self, ParameterError> {
        Self::new(gap, e, &nalgebra::SMatrix::identity())
    }

    /// The gap.
    pub fn gap(&self) -> &Gap<T, N, S> {
        &self.gap
    }

    /// The restitution coefficient.
    pub fn restitution(&self) -> T {
        self.e
    }
}

impl<T: Real, const N: usize, const M: usize, S: crate::excite::Excitation<T>> ResetMap<T, M>
    for NewtonImpact<T, N, S>
{
    fn apply(&self, t: T, y: &mut SVector<T, M>) {
        if M != 2 * N {
            return;
        }
        let w = self.gap.coordinate().weights();
        let (_, sdot) = self.gap.surface(t);
        let mut vn = -sdot;
        for k in 0..N {
            vn += w[k] * y[N + k];
        }
        let scale = (T::one() + self.e) * vn;
        for k in 0..N {
            y[N + k] -= scale * self.direction[k];
        }
    }
    fn check(&self) -> Result<(), EventError> {
        if M != 2 * N {
            return Err(EventError::IndexOutOfRange {
                index: 2 * N - 1,
                len: M,
            });
        }
        Ok(())
    }
}
