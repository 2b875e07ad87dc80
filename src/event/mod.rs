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
//! - **Simultaneous contacts at the start.** Two or more impact events (resetting, with a
//!   direction) closed at `t₀` (`g = 0`, or `g` on the far side: bodies touching) with the
//!   state moving into one of them is a simultaneous impact, which one located impact at
//!   a time cannot resolve: the run stops with [`EventError::SimultaneousContacts`], which
//!   names the time-stepper ([`MoreauJean`](crate::timestep::MoreauJean)). Contacts closed
//!   at rest start as before.
//! - **Non-finite values.** `g` = NaN or ±∞ at a step end stops the run with
//!   [`EventError::NonFinite`]; interior samples that are not finite are not crossings.
//! - **Indices.** Event functions, resets and observers check their component indices
//!   against the state before the first step ([`EventError::IndexOutOfRange`]).
//! - **Sticking.** After a reset, an event is disarmed until the trajectory leaves the far
//!   side; if it turns back deeper instead (the reset cannot separate it from the surface),
//!   the run stops with [`EventError::Sticking`] and its state, never silently.
//! - **Accumulation.** The [`ZenoGuard`] stops a geometric accumulation of events below its
//!   time floor, whatever the run's span, and leaves the simulation at the last event.

mod direction;
mod error;
mod function;
mod locate;
mod reset;
mod set;
mod surface;
mod zeno;

pub use direction::Direction;
pub use error::EventError;
pub use function::{EventFunction, FnEvent, check_index};
pub(crate) use locate::locate;
pub use reset::{NewtonImpact, ResetMap, Restitution};
pub use set::{Event, EventSet, MAX_EVENTS};
pub use surface::{Gap, Level, Stop};
pub(crate) use zeno::EventHistory;
pub use zeno::ZenoGuard;
