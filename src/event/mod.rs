//! Events: functions `g(t, y)` whose zero crossings are located on the dense output,
//! optional reset maps applied at the crossing, terminal events and the chatter guard.
//!
//! # Semantics
//! - A crossing of `g` in the configured [`Direction`] is located on the step's dense
//!   interpolant by a bracketing (Illinois regula falsi) iteration to `|Δt| ≤ max(tol_t,
//!   4·ε_mach·|t|)`. The reported time is the end of the final bracket on the *far* side of
//!   the crossing, so the event never re-fires at the same instant.
//! - **Grazing**: when `g` has the same sign at both ends of a step but its time derivative
//!   ([`EventFunction::rate`], e.g. `ẋ` for the surface `x − x_I`) shows an interior
//!   extremum approaching zero, the extremum of the interpolated `g` is found by golden-section
//!   search and, if it lies beyond zero, both crossings of the pair are located. Any
//!   excursion of the interpolant past zero is therefore found, however shallow — down to
//!   the interpolant's own accuracy (about the absolute tolerance of the component
//!   involved). Without a rate, `k` interior samples per step can be requested
//!   ([`Event::with_interior_samples`]).
//! - With a [`ResetMap`] the stepper is rewound to the event (its state set to the
//!   interpolated state, mapped by the reset), its caches are dropped, and the rest of the
//!   step is discarded. After a reset the fired event's side is taken from the sign of its
//!   rate at the new state (moving away from the surface counts as having left it), so it is
//!   not re-triggered at the same instant.
//! - Without a reset (a pure detection, e.g. an impact with compliant contact) nothing is
//!   rewound: the step is split at the event for the observers, and integration goes on
//!   unchanged.
//!
//! # The contract, stated once
//! - **What is found.** Every sign change of `g` between the ends of a step, and every
//!   excursion past zero inside a step while `g` has at most one interior extremum there
//!   (grazing pairs; from the rate, or from `k` interior samples without one). Events are
//!   located to `max(tol_t, 4·ε_mach·|t|)` on the dense output.
//! - **Moving surfaces.** An event function with explicit time dependence declares its
//!   [`time_scale`](EventFunction::time_scale) (a [`Gap`] on a harmonically moving surface:
//!   `T_surface/16`), or the event a [`max_step`](Event::with_max_step); no step is longer
//!   while the event is in the set. So a step never spans more than a sixteenth of the
//!   surface's period, however smooth the free flight (where an error estimate alone lets
//!   the step grow without bound).
//! - **Start on the surface.** A trajectory that starts exactly on a surface (`g(t₀) = 0`)
//!   has not crossed it: no event at `t₀` in either direction; the side is the one it moves
//!   to (from the rate, or from the end of the first step).
//! - **Non-finite values.** `g` = NaN or ±∞ at a step end stops the run with
//!   [`EventError::NonFinite`]; interior samples that are not finite are not crossings.
//! - **Indices.** Event functions, resets and observers check their component indices
//!   against the state before the first step ([`EventError::IndexOutOfRange`]).
//! - **Sticking.** After a reset, an event is disarmed until the trajectory leaves the far
//!   side; if it turns back deeper instead (the reset cannot separate it from the surface),
//!   the run stops with [`EventError::Sticking`] and its state, never silently.
//! - **Accumulation.** The [`ZenoGuard`] stops a geometric accumulation of events below its
//!   time floor, whatever the run's span, and leaves the simulation at the last event.

use nalgebra::SVector;
use thiserror::Error;

use crate::Real;
use crate::model::Coordinate;
use crate::scalar::lit;
use crate::validate::ParameterError;
use crate::validate::non_negative;

/// Event errors.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum EventError {
    /// Events accumulate (Zeno/chatter): their intervals shrank geometrically below the
    /// guard's time floor. The simulation is left at the last event, so a caller can switch
    /// model (e.g. to sticking) and continue from `t`, `state`.
    #[error(
        "{count} events with geometrically shrinking intervals, the last {last_interval} s, at t = {t}: accumulation of events (Zeno/chatter); the run was stopped there"
    )]
    Zeno {
        /// Time of the last event.
        t: f64,
        /// Number of consecutive shrinking intervals (or events in the guard's window).
        count: usize,
        /// The last inter-event interval.
        last_interval: f64,
        /// The state after the last event (after its reset, if any), to restart from.
        state: Vec<f64>,
    },
    /// After a reset the trajectory stayed on the far side of the surface and turned
    /// deeper again instead of leaving it: the reset cannot separate it (the body sticks to
    /// the surface, e.g. a ball caught by a table accelerating upwards). The simulation is
    /// left at `t`, `state`; continue with a constrained (sticking) model.
    #[error(
        "event {index}: after its reset the trajectory turned back into the surface at t = {t} (depth {depth}): sticking; continue with a constrained model from this state"
    )]
    Sticking {
        /// The event's index.
        index: usize,
        /// Time (a step end).
        t: f64,
        /// `|g|` there.
        depth: f64,
        /// The state there.
        state: Vec<f64>,
    },
    /// An event or reset index outside the state vector.
    #[error("event or reset index {index} out of range (state dimension {len})")]
    IndexOutOfRange {
        /// Index.
        index: usize,
        /// The state dimension.
        len: usize,
    },
    /// An event function returned NaN or ±∞.
    #[error("event function {index} is not finite (g = {value}) at t = {t}")]
    NonFinite {
        /// The event's index in the set.
        index: usize,
        /// Time.
        t: f64,
        /// The value.
        value: f64,
    },
}

/// The direction of a zero crossing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Direction {
    /// `g` goes from negative to positive.
    Rising,
    /// `g` goes from positive to negative.
    Falling,
    /// Either.
    Either,
}

impl Direction {
    /// Whether a crossing towards `sign` (+1 rising, −1 falling) is wanted.
    #[inline(always)]
    pub fn accepts(self, rising: bool) -> bool {
        match self {
            Direction::Rising => rising,
            Direction::Falling => !rising,
            Direction::Either => true,
        }
    }
}

/// A scalar function `g(t, y)` whose zeros are events.
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::event::EventFunction;
/// /// The energy surface E(y) = E0 of an oscillator.
/// struct Energy(f64);
/// impl EventFunction<f64, 2> for Energy {
///     fn value(&self, _t: f64, y: &SVector<f64, 2>) -> f64 { 0.5 * (y[0] * y[0] + y[1] * y[1]) - self.0 }
/// }
/// ```
pub trait EventFunction<T: Real, const N: usize> {
    /// `g(t, y)`; must not mutate anything.
    fn value(&self, t: T, y: &SVector<T, N>) -> T;

    /// `dg/dt` along the trajectory, given `dy = f(t, y)`, if known. Enables grazing
    /// detection from the step's end derivatives.
    fn rate(&self, _t: T, _y: &SVector<T, N>, _dy: &SVector<T, N>) -> Option<T> {
        None
    }

    /// The shortest time over which the function's explicit dependence on `t` can turn
    /// around near `t` (e.g. a fraction of a moving surface's period), if it has one. While
    /// the event is in a simulation, no step is longer than this, so that a moving surface
    /// cannot be stepped over (see the module docs). Default: `None` (no explicit time
    /// dependence).
    fn time_scale(&self, _t: T) -> Option<T> {
        None
    }

    /// Checks that the function can be evaluated on states of dimension `N` (e.g. that a
    /// component index is in range); the driver calls it before a run starts. Default: `Ok`.
    ///
    /// # Errors
    /// [`EventError::IndexOutOfRange`] for an index `≥ N`.
    fn check(&self) -> Result<(), EventError> {
        Ok(())
    }
}

/// `Err(IndexOutOfRange)` unless `index < n` (for implementations of the `check` hooks).
pub fn check_index(index: usize, n: usize) -> Result<(), EventError> {
    if index < n {
        Ok(())
    } else {
        Err(EventError::IndexOutOfRange { index, len: n })
    }
}

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
}

/// A one-sided stop `y[position] = level` with `y[velocity]` the position's rate: the
/// penetration `g = y[position] − level` is negative while the body is free (the paper's
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

/// An event function from a closure `g(t, y)` (no rate: use interior samples for grazing).
#[derive(Debug, Clone, Copy)]
pub struct FnEvent<F>(pub F);

impl<T: Real, const N: usize, F: Fn(T, &SVector<T, N>) -> T> EventFunction<T, N> for FnEvent<F> {
    #[inline(always)]
    fn value(&self, t: T, y: &SVector<T, N>) -> T {
        (self.0)(t, y)
    }
}

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

/// An event: a function, a direction, an optional reset, terminal or not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event<G, R = ()> {
    /// The event function.
    pub function: G,
    /// Which crossings count.
    pub direction: Direction,
    /// The reset map (`()` for none).
    pub reset: R,
    /// Whether the run stops at this event.
    pub terminal: bool,
    /// Interior samples of `g` per step (grazing safety without a rate).
    pub interior_samples: usize,
    /// Whether the stepper restarts at the event (a switching point of the dynamics).
    pub restart: bool,
    /// The longest step the driver takes while this event is in the set (s), besides the
    /// function's own [`time_scale`](EventFunction::time_scale); `None` for no bound.
    pub max_step: Option<f64>,
}

impl<G> Event<G, ()> {
    /// A detection event without reset.
    pub fn new(function: G, direction: Direction) -> Self {
        Self {
            function,
            direction,
            reset: (),
            terminal: false,
            interior_samples: 0,
            restart: false,
            max_step: None,
        }
    }
}

impl<G, R> Event<G, R> {
    /// Adds a reset map.
    pub fn with_reset<R2>(self, reset: R2) -> Event<G, R2> {
        Event {
            function: self.function,
            direction: self.direction,
            reset,
            terminal: self.terminal,
            interior_samples: self.interior_samples,
            restart: self.restart,
            max_step: self.max_step,
        }
    }

    /// Makes the event terminal (the run stops there).
    pub fn terminal(mut self) -> Self {
        self.terminal = true;
        self
    }

    /// Samples `g` at `k` interior points of each step (for functions without a rate).
    pub fn with_interior_samples(mut self, k: usize) -> Self {
        self.interior_samples = k;
        self
    }

    /// Bounds the step length while this event is in the set (for an event function with
    /// fast explicit time dependence that does not declare its
    /// [`time_scale`](EventFunction::time_scale)).
    ///
    /// # Errors
    /// [`ParameterError`] unless `h` is finite and > 0.
    pub fn with_max_step(mut self, h: f64) -> Result<Self, ParameterError> {
        self.max_step = Some(crate::validate::positive("max_step", h)?);
        Ok(self)
    }

    /// Restarts the stepper at the event (for a switching surface where the right-hand side
    /// loses smoothness, e.g. contact onset): the step is cut there and the next one starts
    /// exactly on the surface, with the derivative cache refreshed. Observers see the same
    /// time-ordered views; the trajectory changes only within the integration tolerance.
    pub fn restart(mut self) -> Self {
        self.restart = true;
        self
    }
}

/// A fixed set of events, dispatched by index without `dyn`: `()`, a single [`Event`], and
/// tuples of up to eight sets — nested tuples too. Indices are flat: in `((a, b), c)`, `a`
/// is 0, `b` is 1 and `c` is 2 (a tuple's [`LEN`](EventSet::LEN) is the sum of its
/// members'). A simulation takes at most [`MAX_EVENTS`] events; a larger set is a compile
/// error at the `Simulation::with_events` call, never a silently unchecked event:
///
/// ```compile_fail
/// use nonsmooth::drive::Simulation;
/// use nonsmooth::event::{Direction, Event, Level};
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::testing::HarmonicOscillator;
///
/// let e = Event::new(Level::new(0, 0.0).unwrap(), Direction::Rising);
/// let tol = Tolerances::<f64, 2>::new(1e-8, 1e-10).unwrap();
/// // Nine events: does not compile.
/// let sim = Simulation::new(HarmonicOscillator::new(1.0).unwrap(), Dopri5::new(tol))
///     .with_events(((e, e, e, e, e, e, e, e), e));
/// ```
pub trait EventSet<T: Real, const N: usize> {
    /// The number of events.
    const LEN: usize;
    /// `g_i(t, y)`.
    fn value(&self, i: usize, t: T, y: &SVector<T, N>) -> T;
    /// `dg_i/dt` if known.
    fn rate(&self, i: usize, t: T, y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T>;
    /// Direction of event `i`.
    fn direction(&self, i: usize) -> Direction;
    /// Whether event `i` is terminal.
    fn is_terminal(&self, i: usize) -> bool;
    /// Whether event `i` resets the state.
    fn resets(&self, i: usize) -> bool;
    /// Applies the reset of event `i`.
    fn apply_reset(&self, i: usize, t: T, y: &mut SVector<T, N>);
    /// Interior samples of event `i`.
    fn interior_samples(&self, i: usize) -> usize;
    /// Whether the stepper restarts at event `i`.
    fn restarts(&self, _i: usize) -> bool {
        false
    }
    /// Checks every event function and reset against the state dimension.
    ///
    /// # Errors
    /// [`EventError::IndexOutOfRange`] for an index `≥ N`.
    fn check(&self) -> Result<(), EventError> {
        Ok(())
    }
    /// The longest step the set allows near `t` (the smallest declared time scale or
    /// `max_step` of its events), if any.
    #[inline(always)]
    fn max_step(&self, _t: T) -> Option<T> {
        None
    }
}

#[inline(always)]
fn min_option<T: Real>(a: Option<T>, b: Option<T>) -> Option<T> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, None) => a,
        (None, b) => b,
    }
}

/// The most events one simulation takes (the driver keeps per-event state in fixed arrays
/// on the stack; a larger set does not compile).
pub const MAX_EVENTS: usize = 8;

impl<T: Real, const N: usize> EventSet<T, N> for () {
    const LEN: usize = 0;
    fn value(&self, _i: usize, _t: T, _y: &SVector<T, N>) -> T {
        T::one()
    }
    fn rate(&self, _i: usize, _t: T, _y: &SVector<T, N>, _dy: &SVector<T, N>) -> Option<T> {
        None
    }
    fn direction(&self, _i: usize) -> Direction {
        Direction::Either
    }
    fn is_terminal(&self, _i: usize) -> bool {
        false
    }
    fn resets(&self, _i: usize) -> bool {
        false
    }
    fn apply_reset(&self, _i: usize, _t: T, _y: &mut SVector<T, N>) {}
    fn interior_samples(&self, _i: usize) -> usize {
        0
    }
}

impl<T: Real, const N: usize, G: EventFunction<T, N>, R: ResetMap<T, N>> EventSet<T, N>
    for Event<G, R>
{
    const LEN: usize = 1;
    #[inline(always)]
    fn value(&self, _i: usize, t: T, y: &SVector<T, N>) -> T {
        self.function.value(t, y)
    }
    #[inline(always)]
    fn rate(&self, _i: usize, t: T, y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T> {
        self.function.rate(t, y, dy)
    }
    fn direction(&self, _i: usize) -> Direction {
        self.direction
    }
    fn is_terminal(&self, _i: usize) -> bool {
        self.terminal
    }
    fn resets(&self, _i: usize) -> bool {
        R::RESETS
    }
    fn apply_reset(&self, _i: usize, t: T, y: &mut SVector<T, N>) {
        self.reset.apply(t, y)
    }
    fn interior_samples(&self, _i: usize) -> usize {
        self.interior_samples
    }
    fn restarts(&self, _i: usize) -> bool {
        self.restart
    }
    fn check(&self) -> Result<(), EventError> {
        self.function.check()?;
        self.reset.check()
    }
    #[inline(always)]
    fn max_step(&self, t: T) -> Option<T> {
        min_option(self.function.time_scale(t), self.max_step.map(lit))
    }
}

/// Dispatches flat index `$i` to the member that holds it (members are visited in order;
/// each takes `LEN` consecutive indices).
macro_rules! dispatch {
    ($self:ident, $i:ident, $default:expr, |$m:ident, $j:ident| $call:expr; $($name:ident $idx:tt),+) => {{
        let mut $j = $i;
        $(
            if $j < <$name as EventSet<T, N>>::LEN {
                let $m = &$self.$idx;
                return $call;
            }
            $j -= <$name as EventSet<T, N>>::LEN;
        )+
        let _ = $j;
        $default
    }};
}

macro_rules! event_tuple {
    ($($name:ident $idx:tt),+) => {
        impl<T: Real, const N: usize, $($name: EventSet<T, N>),+> EventSet<T, N> for ($($name,)+) {
            const LEN: usize = 0 $(+ <$name as EventSet<T, N>>::LEN)+;
            #[inline(always)]
            fn value(&self, i: usize, t: T, y: &SVector<T, N>) -> T {
                dispatch!(self, i, T::one(), |m, j| m.value(j, t, y); $($name $idx),+)
            }
            #[inline(always)]
            fn rate(&self, i: usize, t: T, y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T> {
                dispatch!(self, i, None, |m, j| m.rate(j, t, y, dy); $($name $idx),+)
            }
            fn direction(&self, i: usize) -> Direction {
                dispatch!(self, i, Direction::Either, |m, j| m.direction(j); $($name $idx),+)
            }
            fn is_terminal(&self, i: usize) -> bool {
                dispatch!(self, i, false, |m, j| m.is_terminal(j); $($name $idx),+)
            }
            fn resets(&self, i: usize) -> bool {
                dispatch!(self, i, false, |m, j| m.resets(j); $($name $idx),+)
            }
            fn apply_reset(&self, i: usize, t: T, y: &mut SVector<T, N>) {
                dispatch!(self, i, (), |m, j| m.apply_reset(j, t, y); $($name $idx),+)
            }
            fn interior_samples(&self, i: usize) -> usize {
                dispatch!(self, i, 0, |m, j| m.interior_samples(j); $($name $idx),+)
            }
            fn restarts(&self, i: usize) -> bool {
                dispatch!(self, i, false, |m, j| m.restarts(j); $($name $idx),+)
            }
            fn check(&self) -> Result<(), EventError> {
                $(self.$idx.check()?;)+
                Ok(())
            }
            #[inline(always)]
            fn max_step(&self, t: T) -> Option<T> {
                let m = None;
                $(let m = min_option(m, self.$idx.max_step(t));)+
                m
            }
        }
    };
}

event_tuple!(A 0);
event_tuple!(A 0, B 1);
event_tuple!(A 0, B 1, C 2);
event_tuple!(A 0, B 1, C 2, D 3);
event_tuple!(A 0, B 1, C 2, D 3, E 4);
event_tuple!(A 0, B 1, C 2, D 3, E 4, F 5);
event_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
event_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);

/// Locates a crossing of `g` in `[a, b]` (with `ga`, `gb` of opposite signs, `gb` on the
/// far side) by the Illinois variant of regula falsi, which keeps a bracket at all times.
/// Returns `(t, g(t))` with `t` the end of the final bracket on the far side, within `tol`
/// of the crossing.
pub(crate) fn locate<T: Real, F: FnMut(T) -> T>(
    mut g: F,
    a: T,
    b: T,
    ga: T,
    gb: T,
    tol: T,
) -> (T, T) {
    let (mut a, mut b, mut ga, mut gb) = (a, b, ga, gb);
    let far_positive = gb > T::zero() || (gb == T::zero() && ga < T::zero());
    let mut side = 0i8;
    let half = lit::<T>(0.5);
    for _ in 0..200 {
        let w = b - a;
        if w.abs() <= tol {
            break;
        }
        let mut c = if gb != ga {
            (a * gb - b * ga) / (gb - ga)
        } else {
            (a + b) * half
        };
        // Keep c strictly inside, at least tol/2 from either end, so the bracket shrinks.
        let lo = a.min(b) + tol * half;
        let hi = a.max(b) - tol * half;
        // (NaN-safe: a NaN c falls through both tests to the clamp.)
        if c.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
            c = lo;
        }
        if c.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
            c = hi;
        }
        let gc = g(c);
        let on_far = if far_positive {
            gc >= T::zero()
        } else {
            gc <= T::zero()
        };
        if on_far {
            b = c;
            gb = gc;
            if side == 1 {
                ga *= half;
            }
            side = 1;
        } else {
            a = c;
            ga = gc;
            if side == -1 {
                gb *= half;
            }
            side = -1;
        }
    }
    (b, gb)
}

/// The chatter/Zeno guard.
///
/// # Rule (default, [`ZenoGuard::accumulation`])
/// The guard trips when `count` consecutive inter-event intervals each shrink by at least
/// the factor `ratio` (`Δ_{k+1} ≤ ratio·Δ_k`, a geometric accumulation of events) **and**
/// the last interval is below the time floor `floor + 64·ε_mach·|t|`. Both conditions are
/// about the events themselves, never about the length of the run:
/// - an orbit whose events are at least `floor` apart never trips, however long the run;
/// - a periodic orbit with at most `count` events per period never trips at all (its
///   intervals repeat, so no run of `count` strictly shrinking intervals exists);
/// - a true accumulation (a ball coming to rest by a geometric sequence of bounces) trips
///   after the same number of events whatever `t_end` is.
///
/// The default is `count = 16`, `ratio = 0.999`, `floor = 1e-9 s`. A fixed window
/// ([`ZenoGuard::window`]: more than `max_events` events within `window`) is available for
/// callers who know their time scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZenoGuard<T> {
    rule: ZenoRule<T>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum ZenoRule<T> {
    Accumulation { count: usize, ratio: T, floor: T },
    Window { max_events: usize, window: T },
}

impl<T: Real> Default for ZenoGuard<T> {
    fn default() -> Self {
        Self {
            rule: ZenoRule::Accumulation {
                count: 16,
                ratio: lit(0.999),
                floor: lit(1e-9),
            },
        }
    }
}

impl<T: Real> ZenoGuard<T> {
    /// The largest `max_events` supported by [`window`](Self::window) (the guard keeps a
    /// fixed ring buffer).
    pub const CAPACITY: usize = 256;

    /// Trips after `count` consecutive intervals each at most `ratio` times the previous,
    /// the last below `floor` seconds (plus `64·ε_mach·|t|`).
    ///
    /// # Errors
    /// [`ParameterError`] unless `count ≥ 2`, `0 < ratio < 1` and `floor` is finite and > 0.
    pub fn accumulation(count: usize, ratio: T, floor: T) -> Result<Self, ParameterError> {
        if count < 2 {
            return Err(ParameterError::new("count", count as f64, ">= 2"));
        }
        if !(ratio > T::zero() && ratio < T::one()) {
            return Err(ParameterError::new(
                "ratio",
                crate::scalar::to_f64(ratio),
                "in (0, 1)",
            ));
        }
        Ok(Self {
            rule: ZenoRule::Accumulation {
                count,
                ratio,
                floor: crate::validate::positive("floor", floor)?,
            },
        })
    }

    /// Trips when more than `max_events` events fall within any time window of length
    /// `window`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `1 ≤ max_events ≤ 256` and `window` is finite and > 0.
    pub fn window(max_events: usize, window: T) -> Result<Self, ParameterError> {
        if max_events == 0 || max_events > Self::CAPACITY {
            return Err(ParameterError::new(
                "max_events",
                max_events as f64,
                "in 1..=256",
            ));
        }
        Ok(Self {
            rule: ZenoRule::Window {
                max_events,
                window: crate::validate::positive("window", window)?,
            },
        })
    }

    /// Same as [`window`](Self::window) (the first-stage name).
    ///
    /// # Errors
    /// As [`window`](Self::window).
    pub fn new(max_events: usize, window: T) -> Result<Self, ParameterError> {
        Self::window(max_events, window)
    }
}

/// What the guard remembers of recent events.
#[derive(Debug, Clone)]
pub(crate) struct EventHistory<T> {
    times: [T; 256],
    next: usize,
    len: usize,
    last_interval: Option<T>,
    shrinking: usize,
}

impl<T: Real> EventHistory<T> {
    pub(crate) fn new() -> Self {
        Self {
            times: [T::zero(); 256],
            next: 0,
            len: 0,
            last_interval: None,
            shrinking: 0,
        }
    }

    pub(crate) fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
        self.last_interval = None;
        self.shrinking = 0;
    }

    /// Records `t`; returns `(count, last interval)` if the guard trips.
    pub(crate) fn push(&mut self, t: T, guard: &ZenoGuard<T>) -> Option<(usize, T)> {
        let prev = if self.len > 0 {
            Some(self.times[(self.next + 255) % 256])
        } else {
            None
        };
        self.times[self.next] = t;
        self.next = (self.next + 1) % 256;
        self.len = (self.len + 1).min(256);
        let interval = prev.map(|p| t - p);
        match guard.rule {
            ZenoRule::Accumulation {
                count,
                ratio,
                floor,
            } => {
                let d = interval?;
                if let Some(last) = self.last_interval {
                    if d <= ratio * last {
                        self.shrinking += 1;
                    } else {
                        self.shrinking = 0;
                    }
                }
                self.last_interval = Some(d);
                let floor_t = floor + lit::<T>(64.0) * T::default_epsilon() * t.abs();
                (self.shrinking >= count && d <= floor_t).then_some((self.shrinking, d))
            }
            ZenoRule::Window { max_events, window } => {
                if self.len > max_events {
                    // The (max_events+1)-th most recent event.
                    let idx = (self.next + 256 - 1 - max_events) % 256;
                    if t - self.times[idx] <= window {
                        return Some((max_events + 1, interval.unwrap_or(T::zero())));
                    }
                }
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locate_keeps_far_side() {
        let (t, g) = locate(|t: f64| t * t - 2.0, 0.0, 2.0, -2.0, 2.0, 1e-13);
        assert!(g >= 0.0);
        assert!(
            t - 2.0_f64.sqrt() >= 0.0 && t - 2.0_f64.sqrt() < 1e-12,
            "{t}"
        );
        let (t, g) = locate(|t: f64| 1.0 - t, 0.0, 3.0, 1.0, -2.0, 1e-13);
        assert!(g <= 0.0 && (t - 1.0).abs() < 1e-12);
    }

    #[test]
    fn zeno_guard_counts_in_window() {
        let g = ZenoGuard::window(3, 1.0).unwrap();
        let mut h = EventHistory::new();
        assert!(h.push(0.0, &g).is_none());
        assert!(h.push(0.5, &g).is_none());
        assert!(h.push(2.0, &g).is_none());
        assert!(h.push(2.1, &g).is_none());
        assert!(h.push(2.2, &g).is_none());
        assert_eq!(h.push(2.3, &g).map(|c| c.0), Some(4));
        assert!(ZenoGuard::new(0, 1.0).is_err());
        assert!(ZenoGuard::new(3, 0.0).is_err());
    }

    #[test]
    fn accumulation_guard_trips_on_geometric_sequences_only() {
        let g = ZenoGuard::<f64>::default();
        // A geometric sequence of intervals 0.5^k from 0.1 s: trips once 16 consecutive
        // intervals have shrunk and the last is below 1e-9 s.
        let mut h = EventHistory::new();
        let mut t = 0.0;
        let mut tripped = None;
        for k in 0..200 {
            t += 0.1 * 0.5f64.powi(k);
            if let Some(c) = h.push(t, &g) {
                tripped = Some((k, c));
                break;
            }
        }
        let (k, (count, d)) = tripped.expect("geometric accumulation must trip");
        assert!(d <= 1e-9 && count >= 16, "{k} {count} {d}");
        assert_eq!(k, 27, "first k with 0.1·0.5^k ≤ 1e-9");
        // A periodic pattern of 16 distinct intervals per period, some tiny, repeated 10⁵
        // times: never trips, whatever the run length.
        let mut h = EventHistory::new();
        let pattern: Vec<f64> = (0..16).map(|k| 1e-12 * 2f64.powi(16 - k)).collect();
        let mut t = 0.0;
        for _ in 0..100_000 {
            for &d in &pattern {
                t += d + 1.0e-3 * (d == pattern[15]) as i32 as f64;
                assert!(h.push(t, &g).is_none());
            }
        }
        assert!(ZenoGuard::<f64>::accumulation(1, 0.5, 1e-9).is_err());
        assert!(ZenoGuard::<f64>::accumulation(4, 1.0, 1e-9).is_err());
        assert!(ZenoGuard::<f64>::accumulation(4, 0.5, 0.0).is_err());
    }
}
