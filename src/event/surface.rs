//! Surfaces as event functions: a level of one component, a one-sided stop and the contact
//! gap of a mechanical system against a fixed or moving surface.

use nalgebra::SVector;

use super::error::EventError;
use super::function::{EventFunction, check_index};
use crate::Real;
use crate::lanes::Lanes;
use crate::model::Coordinate;
use crate::scalar::to_f64;
use crate::validate::ParameterError;

/// The hyperplane `g = y[index] − level` (e.g. the stop `x = x_I`), with rate `ẏ[index]`.
///
/// Deserialization (feature `serde`) applies the constructor's check of the level (the index
/// is checked against the state when a run starts). Called directly on a state without
/// component `index`, [`value`](EventFunction::value) is NaN (which the driver reports) and
/// [`rate`](EventFunction::rate) is `None`; neither panics.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Level<T> {
    index: usize,
    level: T,
}

crate::serde_check::deserialize_checked! {
    "Level", Level<T: Real> { index: usize, level: T },
    |raw| -> ParameterError { Level::new(raw.index, raw.level)? }
}

impl<T: Real> Level<T> {
    /// `g = y[index] − level`.
    ///
    /// # Errors
    /// [`ParameterError`] if `level` is not finite.
    pub fn new(index: usize, level: T) -> Result<Self, ParameterError> {
        Ok(Self {
            index,
            level: crate::validate::finite("level", level)?,
        })
    }

    /// The component index.
    pub fn index(&self) -> usize {
        self.index
    }

    /// The level.
    pub fn level(&self) -> T {
        self.level
    }
}

impl<T: Real, const N: usize> EventFunction<T, N> for Level<T> {
    #[inline(always)]
    fn value(&self, _t: T, y: &SVector<T, N>) -> T {
        // An index outside the state gives NaN (reported by the driver), never a panic.
        match y.get(self.index) {
            Some(&x) => x - self.level,
            None => T::zero() / T::zero(),
        }
    }
    #[inline(always)]
    fn rate(&self, _t: T, _y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T> {
        dy.get(self.index).copied()
    }
    fn check(&self) -> Result<(), EventError> {
        check_index(self.index, N)
    }
    fn chord_bounds(
        &self,
        _t0: T,
        _t1: T,
        dev: &SVector<T, N>,
        mag: &SVector<T, N>,
    ) -> Option<(T, T)> {
        component_bounds(self.index, self.level, dev, mag)
    }
    #[inline(always)]
    fn lanes<V: Lanes>(&self, _t: V, y: &[V; N], dy: &[V; N]) -> Option<(V, Option<V>)> {
        component_lanes::<T, V, N>(self.index, self.level, y, dy)
    }
    fn constant_time_scale(&self) -> bool {
        true
    }
}

/// A one-sided stop `y[position] = level` with `y[velocity]` the position's rate: the
/// penetration `g = y[position] − level` is negative while the body is free (an upper
/// stop at `x_I`). Its event rate is `ẏ[position]`.
///
/// The fields are public for struct-literal use; a non-finite level or an index outside
/// the state is reported when a run starts ([`EventError`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Stop<T = f64> {
    /// Position component.
    pub position: usize,
    /// Velocity component (the rate of `position`).
    pub velocity: usize,
    /// Level.
    pub level: T,
}

impl<T: Real, const N: usize> EventFunction<T, N> for Stop<T> {
    #[inline(always)]
    fn value(&self, _t: T, y: &SVector<T, N>) -> T {
        // An index outside the state gives NaN (reported by the driver), never a panic.
        match y.get(self.position) {
            Some(&x) => x - self.level,
            None => T::zero() / T::zero(),
        }
    }
    #[inline(always)]
    fn rate(&self, _t: T, _y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T> {
        dy.get(self.position).copied()
    }
    #[inline(always)]
    fn lanes<V: Lanes>(&self, _t: V, y: &[V; N], dy: &[V; N]) -> Option<(V, Option<V>)> {
        component_lanes::<T, V, N>(self.position, self.level, y, dy)
    }
    fn chord_bounds(
        &self,
        _t0: T,
        _t1: T,
        dev: &SVector<T, N>,
        mag: &SVector<T, N>,
    ) -> Option<(T, T)> {
        component_bounds(self.position, self.level, dev, mag)
    }
    fn check(&self) -> Result<(), EventError> {
        check_index(self.position, N)?;
        check_index(self.velocity, N)?;
        if !self.level.is_finite() {
            return Err(EventError::NonFinite {
                index: 0,
                t: 0.0,
                value: crate::scalar::to_f64(self.level),
            });
        }
        Ok(())
    }
    fn constant_time_scale(&self) -> bool {
        true
    }
}

/// The lane form of `g = y[index] − level`, `ġ = ẏ[index]` (`T = f64` only; `None` for an
/// index outside the state, where the scalar value is NaN).
#[inline(always)]
fn component_lanes<T: Real, V: Lanes, const N: usize>(
    index: usize,
    level: T,
    y: &[V; N],
    dy: &[V; N],
) -> Option<(V, Option<V>)> {
    if !crate::fastmath::is_f64::<T>() {
        return None;
    }
    Some((
        *y.get(index)? - V::splat(to_f64(level)),
        Some(*dy.get(index)?),
    ))
}

/// [`EventFunction::chord_bounds`] of `g = y[index] − level`: component `index`'s bounds
/// (`None` for an index outside the state).
fn component_bounds<T: Real, const N: usize>(
    index: usize,
    level: T,
    dev: &SVector<T, N>,
    mag: &SVector<T, N>,
) -> Option<(T, T)> {
    Some((*dev.get(index)?, *mag.get(index)? + level.abs()))
}

/// A contact surface of an `N`-DOF mechanical system with state `y = (q, q̇)` (dimension
/// `M = 2N`): the penetration of a [`Coordinate`] `c(q) = w·q + o` past a surface that
/// moves as `s(t)` (any [`Excitation`](crate::excite::Excitation) read as a position;
/// `()` for a fixed one at 0 — put a fixed level into the coordinate's offset):
/// $$g = \sigma\,\bigl(c(q) - s(t)\bigr),\qquad \dot g = \sigma\,\bigl(w\cdot\dot q -
///   \dot s(t)\bigr),$$
/// with `σ = +1` for a body that must stay *below* the surface ([`Gap::below`]) and `σ = −1`
/// for one that must stay *above* it ([`Gap::above`], e.g. a ball on a vibrating table).
/// `g < 0` while free, `g ≥ 0` in contact, as for [`Stop`]; impacts are rising crossings.
/// Its event rate is `ġ` computed from the state (exact, no finite differences).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gap<T: Real, const N: usize, S = ()> {
    coordinate: Coordinate<T, N>,
    motion: S,
    sign: T,
}

impl<T: Real, const N: usize, S: crate::excite::Excitation<T>> Gap<T, N, S> {
    /// The body's coordinate must stay below the surface: `g = c(q) − s(t)`.
    pub fn below(coordinate: Coordinate<T, N>, motion: S) -> Self {
        Self {
            coordinate,
            motion,
            sign: T::one(),
        }
    }

    /// The body's coordinate must stay above the surface: `g = s(t) − c(q)`.
    pub fn above(coordinate: Coordinate<T, N>, motion: S) -> Self {
        Self {
            coordinate,
            motion,
            sign: -T::one(),
        }
    }

    /// The coordinate.
    pub fn coordinate(&self) -> &Coordinate<T, N> {
        &self.coordinate
    }

    /// `σ = ±1`.
    pub fn sign(&self) -> T {
        self.sign
    }

    /// The surface's position and velocity `(s(t), ṡ(t))`.
    #[inline(always)]
    pub fn surface(&self, t: T) -> (T, T) {
        (self.motion.force(t), self.motion.force_rate(t))
    }

    /// The surface's acceleration `s̈(t)` (the motion's
    /// [`force_acceleration`](crate::excite::Excitation::force_acceleration)).
    #[inline(always)]
    pub fn surface_acceleration(&self, t: T) -> T {
        self.motion.force_acceleration(t)
    }

    /// The penetration `g(t, q)` from the positions `q`.
    #[inline(always)]
    pub fn penetration(&self, t: T, q: &[T]) -> T {
        self.sign * (self.coordinate.value(q) - self.motion.force(t))
    }

    /// The rate `ġ(t, q̇)` from the velocities `q̇`.
    #[inline(always)]
    pub fn penetration_rate(&self, t: T, qd: &[T]) -> T {
        self.sign * (self.coordinate.rate(qd) - self.motion.force_rate(t))
    }
}

impl<T: Real, const N: usize, const M: usize, S: crate::excite::Excitation<T>> EventFunction<T, M>
    for Gap<T, N, S>
{
    #[inline(always)]
    fn value(&self, t: T, y: &SVector<T, M>) -> T {
        // A state of the wrong dimension gives NaN (reported by the driver), never a panic.
        if M != 2 * N {
            return T::zero() / T::zero();
        }
        self.penetration(t, &y.as_slice()[..N])
    }
    #[inline(always)]
    fn rate(&self, t: T, y: &SVector<T, M>, _dy: &SVector<T, M>) -> Option<T> {
        if M != 2 * N {
            return None;
        }
        Some(self.penetration_rate(t, &y.as_slice()[N..]))
    }
    /// The motion's [`time_scale`](crate::excite::Excitation::time_scale) (`2π/(16ω)` for a
    /// harmonic surface: sixteen steps per surface period at least).
    fn time_scale(&self, t: T) -> Option<T> {
        self.motion.time_scale(t)
    }
    fn constant_time_scale(&self) -> bool {
        self.motion.constant_time_scale()
    }
    /// `Σ|w_k|·dev_k` over the positions plus the motion's
    /// [`chord_bounds`](crate::excite::Excitation::chord_bounds) (`None` without them).
    fn chord_bounds(
        &self,
        t0: T,
        t1: T,
        dev: &SVector<T, M>,
        mag: &SVector<T, M>,
    ) -> Option<(T, T)> {
        if M != 2 * N {
            return None;
        }
        let (ds, s) = self.motion.chord_bounds(t0, t1)?;
        let c = &self.coordinate;
        Some((
            c.weighted_bound(&dev.as_slice()[..N]) + ds,
            c.weighted_bound(&mag.as_slice()[..N]) + c.offset().abs() + s,
        ))
    }
    #[inline(always)]
    fn lanes<V: Lanes>(&self, t: V, y: &[V; M], _dy: &[V; M]) -> Option<(V, Option<V>)> {
        if M != 2 * N || !crate::fastmath::is_f64::<T>() {
            return None;
        }
        let (s, ds) = self.motion.motion_lanes(t)?;
        let sign = V::splat(to_f64(self.sign));
        let (c, w) = self.coordinate.lanes(&y[..N], &y[N..]);
        Some((sign * (c - s), Some(sign * (w - ds))))
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
