//! The errors of event functions, resets and the event loop.

use thiserror::Error;

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
    /// The run starts with two or more impact surfaces closed (bodies touching: `g = 0`, or
    /// `g` on the side the impact's reset moves away from) and the state moving into one
    /// of them: a simultaneous impact at the start. Its outcome depends on how the impulses
    /// are shared among the contacts (for touching balls struck at one end, Moreau's
    /// complementarity problem of all contacts at once moves the struck balls as one body;
    /// impacts taken in sequence pass the momentum along), which the event-driven method,
    /// one located impact at a time, cannot decide. Use the time-stepper
    /// [`MoreauJean`](crate::timestep::MoreauJean), which solves all contacts at once, or
    /// start with the contacts apart.
    #[error(
        "events {moving} and {other} start closed at t = {t}, event {moving} moving into its surface (rate {rate}): a simultaneous impact, which the event-driven method (one impact at a time) cannot resolve; use the time-stepper nonsmooth::timestep::MoreauJean (all contacts at once), or start with the contacts apart"
    )]
    SimultaneousContacts {
        /// The start time.
        t: f64,
        /// The impact event whose state moves into its surface.
        moving: usize,
        /// Another impact event closed at the start.
        other: usize,
        /// The rate `ġ` of event `moving` (its sign points into the surface).
        rate: f64,
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
