//! Samplers: observers that turn a run into records.
//!
//! | sampler | records | paper |
//! |---|---|---|
//! | [`Stroboscopic`] | states at the section times `t_i` (`2πi/ω`, or phase `2πi` of a ramped rotor) | Figs. 2a, 2c, 3a, 4a |
//! | [`ImpactSequence`] | impacts on any contact [`Surface`] (fixed or moving, any coordinate): times, intervals `T_j`, velocities, maximum penetration | Figs. 2b, 2d, 3b, 4b, 6 |
//! | [`PeriodSummary`] | per forcing period: impacts, extrema of `x`, grazing margin | Fig. 8 |
//! | [`Section`] | crossings of a general event function (a Poincaré section) | |
//! | [`Trajectory`] | the state on a uniform grid `t0 + i·dt` | Figs. 8, 9, 10 |
//!
//! Samplers are [`Observer`](crate::drive::Observer)s: they see every accepted step with its
//! dense output and every located event, and never change the trajectory. Each records only
//! from `record_from` on (to skip transients) and keeps at most `capacity` records (bounded
//! memory; the count of dropped records is kept).
//!
//! [`detect_period`] finds the period of a recorded sequence of section points
//! ([`try_detect_period`] rejects an invalid tolerance).

mod period;
mod samplers;
mod surface;

pub use period::{Regime, detect_period, try_detect_period};
pub use samplers::{
    Impact, ImpactSequence, MAX_SECTIONS_PER_RUN, PeriodRecord, PeriodSummary, Periodic,
    PhaseClock, Section, SectionClock, SectionPoint, Stroboscopic, Trajectory,
};
pub use surface::Surface;
