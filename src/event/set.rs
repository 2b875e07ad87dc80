//! Events (a function, a direction, a reset) and fixed sets of them dispatched by index:
//! `()`, one event and tuples.

use nalgebra::SVector;

use super::direction::Direction;
use super::error::EventError;
use super::function::EventFunction;
use super::reset::ResetMap;
use crate::Real;
use crate::lanes::Lanes;
use crate::scalar::lit;
use crate::validate::ParameterError;

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
    /// Whether [`max_step`](EventSet::max_step) has the same value at every `t`: every
    /// event's function has a [constant time scale](EventFunction::constant_time_scale).
    /// Default `false`.
    fn constant_max_step(&self) -> bool {
        false
    }
    /// Event `i`'s [`EventFunction::chord_bounds`].
    fn chord_bounds(
        &self,
        _i: usize,
        _t0: T,
        _t1: T,
        _dev: &SVector<T, N>,
        _mag: &SVector<T, N>,
    ) -> Option<(T, T)> {
        None
    }
    /// Event `i`'s value and rate at `L` points at once, one per lane (its function's
    /// [`EventFunction::lanes`]), or `None` if its function has no lane form.
    #[inline(always)]
    fn lanes<V: Lanes>(&self, _i: usize, _t: V, _y: &[V; N], _dy: &[V; N]) -> Option<(V, Option<V>)>
    where
        Self: Sized,
    {
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
    fn constant_max_step(&self) -> bool {
        true
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
    fn constant_max_step(&self) -> bool {
        self.function.constant_time_scale()
    }
    fn chord_bounds(
        &self,
        _i: usize,
        t0: T,
        t1: T,
        dev: &SVector<T, N>,
        mag: &SVector<T, N>,
    ) -> Option<(T, T)> {
        self.function.chord_bounds(t0, t1, dev, mag)
    }
    #[inline(always)]
    fn lanes<V: Lanes>(&self, _i: usize, t: V, y: &[V; N], dy: &[V; N]) -> Option<(V, Option<V>)> {
        self.function.lanes(t, y, dy)
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
            fn chord_bounds(
                &self,
                i: usize,
                t0: T,
                t1: T,
                dev: &SVector<T, N>,
                mag: &SVector<T, N>,
            ) -> Option<(T, T)> {
                dispatch!(self, i, None, |m, j| m.chord_bounds(j, t0, t1, dev, mag); $($name $idx),+)
            }
            #[inline(always)]
            fn lanes<V: Lanes>(
                &self,
                i: usize,
                t: V,
                y: &[V; N],
                dy: &[V; N],
            ) -> Option<(V, Option<V>)> {
                dispatch!(self, i, None, |m, j| m.lanes(j, t, y, dy); $($name $idx),+)
            }
            #[inline(always)]
            fn max_step(&self, t: T) -> Option<T> {
                let m = None;
                $(let m = min_option(m, self.$idx.max_step(t));)+
                m
            }
            fn constant_max_step(&self) -> bool {
                true $(&& self.$idx.constant_max_step())+
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
