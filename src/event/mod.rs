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

use nalgebra::SVector;
use thiserror::Error;

use crate::Real;
use crate::error::ParameterError;
use crate::scalar::lit;
use crate::validate::non_negative;

/// Event errors.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum EventError {
    /// Too many events in too short a time (chatter, Zeno accumulation).
    #[error(
        "{count} events within {window} s ending at t = {t}: accumulation of events (Zeno/chatter); the run was stopped"
    )]
    Zeno {
        /// Time of the last event.
        t: f64,
        /// Number of events in the window.
        count: usize,
        /// The window length.
        window: f64,
    },
    /// An event index outside the configured events.
    #[error("event index {index} out of range ({len} events)")]
    IndexOutOfRange {
        /// Index.
        index: usize,
        /// Number of events.
        len: usize,
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
}

/// The hyperplane `g = y[index] − level` (e.g. the stop `x = x_I`), with rate `ẏ[index]`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Level<T> {
    index: usize,
    level: T,
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
        y[self.index] - self.level
    }
    #[inline(always)]
    fn rate(&self, _t: T, _y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T> {
        Some(dy[self.index])
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
}

/// No reset.
impl<T: Real, const N: usize> ResetMap<T, N> for () {
    const RESETS: bool = false;
    #[inline(always)]
    fn apply(&self, _t: T, _y: &mut SVector<T, N>) {}
}

/// Newton's restitution law `ẏ[velocity]⁺ = −r·ẏ[velocity]⁻`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Restitution<T> {
    velocity: usize,
    r: T,
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
        y[self.velocity] = -self.r * y[self.velocity];
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

    /// Restarts the stepper at the event (for a switching surface where the right-hand side
    /// loses smoothness, e.g. contact onset): the step is cut there and the next one starts
    /// exactly on the surface, with the derivative cache refreshed. Observers see the same
    /// time-ordered views; the trajectory changes only within the integration tolerance.
    pub fn restart(mut self) -> Self {
        self.restart = true;
        self
    }
}

/// A fixed set of events, dispatched by index without `dyn` (implemented for `()`, a single
/// [`Event`] and tuples of up to four).
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
}

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
}

macro_rules! event_tuple {
    ($len:expr; $($name:ident $idx:tt),+) => {
        impl<T: Real, const N: usize, $($name: EventSet<T, N>),+> EventSet<T, N> for ($($name,)+) {
            const LEN: usize = $len;
            #[inline(always)]
            fn value(&self, i: usize, t: T, y: &SVector<T, N>) -> T {
                match i { $($idx => self.$idx.value(0, t, y),)+ _ => T::one() }
            }
            #[inline(always)]
            fn rate(&self, i: usize, t: T, y: &SVector<T, N>, dy: &SVector<T, N>) -> Option<T> {
                match i { $($idx => self.$idx.rate(0, t, y, dy),)+ _ => None }
            }
            fn direction(&self, i: usize) -> Direction {
                match i { $($idx => self.$idx.direction(0),)+ _ => Direction::Either }
            }
            fn is_terminal(&self, i: usize) -> bool {
                match i { $($idx => self.$idx.is_terminal(0),)+ _ => false }
            }
            fn resets(&self, i: usize) -> bool {
                match i { $($idx => self.$idx.resets(0),)+ _ => false }
            }
            fn apply_reset(&self, i: usize, t: T, y: &mut SVector<T, N>) {
                match i { $($idx => self.$idx.apply_reset(0, t, y),)+ _ => {} }
            }
            fn interior_samples(&self, i: usize) -> usize {
                match i { $($idx => self.$idx.interior_samples(0),)+ _ => 0 }
            }
            fn restarts(&self, i: usize) -> bool {
                match i { $($idx => self.$idx.restarts(0),)+ _ => false }
            }
        }
    };
}

event_tuple!(1; A 0);
event_tuple!(2; A 0, B 1);
event_tuple!(3; A 0, B 1, C 2);
event_tuple!(4; A 0, B 1, C 2, D 3);

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

/// Chatter/Zeno guard: more than `max_events` events within any time window of length
/// `window` stops the run with [`EventError::Zeno`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZenoGuard<T> {
    /// Events allowed within the window (at most [`ZenoGuard::CAPACITY`]).
    pub max_events: usize,
    /// The window length.
    pub window: T,
}

impl<T: Real> ZenoGuard<T> {
    /// The largest `max_events` supported (the guard keeps a fixed ring buffer).
    pub const CAPACITY: usize = 256;

    /// A guard allowing `max_events` events per `window`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `1 ≤ max_events ≤ 256` and `window` is finite and > 0.
    pub fn new(max_events: usize, window: T) -> Result<Self, ParameterError> {
        if max_events == 0 || max_events > Self::CAPACITY {
            return Err(ParameterError::new(
                "max_events",
                max_events as f64,
                "in 1..=256",
            ));
        }
        Ok(Self {
            max_events,
            window: crate::validate::positive("window", window)?,
        })
    }
}

/// Ring buffer of recent event times for the guard.
#[derive(Debug, Clone)]
pub(crate) struct EventHistory<T> {
    times: [T; 256],
    next: usize,
    len: usize,
}

impl<T: Real> EventHistory<T> {
    pub(crate) fn new() -> Self {
        Self {
            times: [T::zero(); 256],
            next: 0,
            len: 0,
        }
    }

    pub(crate) fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
    }

    /// Records `t`; returns the count in the window if the guard is exceeded.
    pub(crate) fn push(&mut self, t: T, guard: &ZenoGuard<T>) -> Option<usize> {
        self.times[self.next] = t;
        self.next = (self.next + 1) % 256;
        self.len = (self.len + 1).min(256);
        if self.len > guard.max_events {
            // The (max_events+1)-th most recent event.
            let idx = (self.next + 256 - 1 - guard.max_events) % 256;
            if t - self.times[idx] <= guard.window {
                return Some(guard.max_events + 1);
            }
        }
        None
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
        let g = ZenoGuard::new(3, 1.0).unwrap();
        let mut h = EventHistory::new();
        assert!(h.push(0.0, &g).is_none());
        assert!(h.push(0.5, &g).is_none());
        assert!(h.push(2.0, &g).is_none());
        assert!(h.push(2.1, &g).is_none());
        assert!(h.push(2.2, &g).is_none());
        assert_eq!(h.push(2.3, &g), Some(4));
        assert!(ZenoGuard::new(0, 1.0).is_err());
        assert!(ZenoGuard::new(3, 0.0).is_err());
    }
}
