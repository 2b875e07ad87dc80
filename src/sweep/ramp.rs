//! The experiment's continuous sweep: the forcing frequency ramps linearly in time.

use nalgebra::SVector;

use super::{Stop, StopEvent, SweepError};
use crate::Dynamics;
use crate::drive::{RunError, Simulation};
use crate::event::{Direction, Event};
use crate::excite::Excitation;
use crate::integrate::Stepper;
use crate::sample::{ImpactSequence, PhaseClock, Stroboscopic};

/// A stroboscopic point of a ramped run (forcing phase `2πi`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampSection<const N: usize> {
    /// Section index `i`.
    pub index: u64,
    /// Time.
    pub t: f64,
    /// The forcing frequency `ω(t)` there.
    pub omega: f64,
    /// State.
    pub y: SVector<f64, N>,
}

/// An impact of a ramped run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampImpact {
    /// Time.
    pub t: f64,
    /// `ω(t)`.
    pub omega: f64,
    /// Interval since the previous impact.
    pub interval: Option<f64>,
    /// Impact velocity.
    pub velocity: f64,
}

/// The records of a ramped run.
///
/// Memory: `24 + 8N` bytes per section (48 B for `N = 2`) and 40 B per impact;
/// the run keeps them while it lasts, so the peak is about twice that. Bound it with
/// [`ramp_with_capacity`].
#[derive(Debug, Clone, PartialEq)]
pub struct RampRecord<const N: usize> {
    /// Stroboscopic points.
    pub sections: Vec<RampSection<N>>,
    /// Impacts.
    pub impacts: Vec<RampImpact>,
    /// Sections passed but not stored because the capacity was reached.
    pub dropped_sections: u64,
    /// Impacts seen but not stored because the capacity was reached.
    pub dropped_impacts: u64,
}

/// Runs `system` (whose forcing is `excitation`, e.g. a
/// [`RampedRotor`](crate::excite::RampedRotor)) from `y0` at `t = 0` to `t_end`, taking
/// stroboscopic points where the forcing phase passes `2πi` (computed exactly from the
/// phase, never accumulated) and impacts as upward crossings of `stop`.
///
/// Every section and impact is kept (see [`RampRecord`] for the memory per record); use
/// [`ramp_with_capacity`] to bound it.
///
/// # Errors
/// [`SweepError::Failed`] if the run fails.
pub fn ramp<const N: usize, S, St, E>(
    system: S,
    excitation: E,
    stop: Stop,
    stepper: St,
    y0: SVector<f64, N>,
    t_end: f64,
) -> Result<RampRecord<N>, SweepError>
where
    S: Dynamics<f64, N>,
    St: Stepper<f64, N>,
    E: Excitation<f64> + Clone,
{
    ramp_with_capacity(system, excitation, stop, stepper, y0, t_end, usize::MAX)
}

/// [`ramp`] keeping at most `capacity` sections and `capacity` impacts (the first ones);
/// the rest are counted in [`RampRecord::dropped_sections`] and
/// [`RampRecord::dropped_impacts`]. Memory is then bounded by `capacity` whatever `t_end`.
///
/// # Errors
/// [`SweepError::Failed`] if the run fails.
pub fn ramp_with_capacity<const N: usize, S, St, E>(
    system: S,
    excitation: E,
    stop: Stop,
    stepper: St,
    y0: SVector<f64, N>,
    t_end: f64,
    capacity: usize,
) -> Result<RampRecord<N>, SweepError>
where
    S: Dynamics<f64, N>,
    St: Stepper<f64, N>,
    E: Excitation<f64> + Clone,
{
    let fail = |e: RunError| SweepError::failed(f64::NAN, e);
    let ev = Event::new(StopEvent(Some(stop)), Direction::Rising);
    let mut sim = Simulation::new(system, stepper)
        .with_events(ev)
        .max_steps(usize::MAX)
        .map_err(|e| fail(e.into()))?;
    let cap = capacity;
    let mut strobe = Stroboscopic::<f64, N, _>::new(PhaseClock(excitation.clone()), 0.0, cap)
        .map_err(|e| fail(e.into()))?;
    let mut impacts = ImpactSequence::new(0, stop.position, stop.velocity, stop.level, 0.0, cap)
        .map_err(|e| fail(e.into()))?;
    sim.run(0.0, y0, t_end, &mut (&mut strobe, &mut impacts))
        .map_err(fail)?;
    let omega = |t: f64| excitation.angular_frequency(t).unwrap_or(f64::NAN);
    Ok(RampRecord {
        sections: strobe
            .points()
            .iter()
            .map(|p| RampSection {
                index: p.index,
                t: p.t,
                omega: omega(p.t),
                y: p.y,
            })
            .collect(),
        impacts: impacts
            .impacts()
            .iter()
            .map(|i| RampImpact {
                t: i.t,
                omega: omega(i.t),
                interval: i.interval,
                velocity: i.velocity,
            })
            .collect(),
        dropped_sections: strobe.dropped(),
        dropped_impacts: impacts.dropped(),
    })
}
