//! Hybrid runs through discrete modes: rigid contact (free flight ↔ sticking to a surface),
//! dry friction (slip ↔ stick), or any mode logic of your own.
//!
//! A [`ModeSystem`] runs one continuous segment in a given mode and says how it ended: at
//! `t_end`, or at a mode change with the mode to continue in. [`run_modes`] chains the
//! segments, streams them to one observer (which sees `on_start` at every mode change) and
//! logs the transitions. Two mode systems are built in:
//! [`RigidContact`](super::sticking::RigidContact) (chattering → sticking → release on a
//! rigid surface) and [`StickSlip`](super::stick_slip::StickSlip) (a set-valued Coulomb law
//! with static and kinetic friction).
//!
//! # Implementing a mode system
//! ```
//! use nalgebra::SVector;
//! use nonsmooth::drive::{Observer, Outcome, RunError, Simulation, Termination};
//! use nonsmooth::drive::modes::{ModeSystem, Segment, run_modes};
//! use nonsmooth::integrate::{Dopri5, Tolerances};
//! use nonsmooth::testing::HarmonicOscillator;
//!
//! /// Two modes that alternate every second (a stand-in for real switching logic).
//! struct Alternate(HarmonicOscillator<f64>);
//! impl ModeSystem<f64, 2> for Alternate {
//!     type Mode = bool;
//!     fn segment<O: Observer<f64, 2>>(
//!         &mut self, mode: bool, t: f64, y: SVector<f64, 2>, t_end: f64, observer: &mut O,
//!     ) -> Result<Segment<f64, 2, bool>, RunError> {
//!         let stop = (t + 1.0).min(t_end);
//!         let mut sim = Simulation::new(self.0, Dopri5::new(Tolerances::new(1e-9, 1e-12)?));
//!         let outcome = sim.run(t, y, stop, observer)?;
//!         let next = (outcome.t < t_end).then_some(!mode);
//!         Ok(Segment { outcome, next })
//!     }
//! }
//! let mut system = Alternate(HarmonicOscillator::new(1.0)?);
//! let run = run_modes(&mut system, true, 0.0, SVector::from([1.0, 0.0]), 3.5, 10, &mut ())?;
//! assert_eq!(run.transitions.len(), 3); // at t = 1, 2, 3
//! assert!((run.outcome.y[0] - 3.5_f64.cos()).abs() < 1e-7);
//! # Ok::<(), nonsmooth::Error>(())
//! ```

use std::fmt::Debug;

use nalgebra::SVector;

pub use super::error::ModeError;
use super::error::Result;
use super::{Observer, Outcome};
use crate::Real;
use crate::event::EventError;
use crate::scalar::to_f64;
use crate::validate::ParameterError;

impl ModeError {
    /// [`ModeError::InconsistentStart`] with its diagnostics as `f64`.
    pub(crate) fn inconsistent_start<T: Real>(
        mode: &'static str,
        t: T,
        quantity: &'static str,
        value: T,
        requirement: String,
    ) -> Self {
        ModeError::InconsistentStart {
            mode,
            t: to_f64(t),
            quantity,
            value: to_f64(value),
            requirement,
        }
    }
}

/// `dg/dt` along the flow `ẏ = dy` at `(t, y)` by a central difference
/// `(g(t+h, y+h·dy) − g(t−h, y−h·dy))/2h`, `h = ε^{1/3}·s` with `s` the time unit
/// `16·scale/2π` of a declared time scale (else one second). For the rates of mode
/// conditions (a release, a static limit) whose exact derivative needs the derivative of
/// the acceleration: the rate only has to show the sign of `ġ` at step ends, so that an
/// excursion of `g` past zero inside a step (a release and a re-stick between two step
/// ends) is found by the driver's grazing search.
pub(crate) fn rate_along_flow<T: Real, const M: usize>(
    g: impl Fn(T, &SVector<T, M>) -> T,
    t: T,
    y: &SVector<T, M>,
    dy: &SVector<T, M>,
    scale: Option<T>,
) -> T {
    let (up, down) = crate::excite::difference_points(t, scale);
    let (hu, hd) = (up - t, t - down);
    (g(up, &(y + dy * hu)) - g(down, &(y - dy * hd))) / (hu + hd)
}

/// How one segment of a [`ModeSystem`] ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment<T: Real, const M: usize, Mode> {
    /// The segment's run (its end time and state are where the next segment starts).
    pub outcome: Outcome<T, M>,
    /// The mode to continue in, or `None` if the run is over (`t_end` reached, or an
    /// observer stopped it).
    pub next: Option<Mode>,
}

/// A hybrid system with discrete modes, each run as one continuous segment.
pub trait ModeSystem<T: Real, const M: usize> {
    /// The discrete mode (e.g. free/stuck, slip direction/stick).
    type Mode: Copy + PartialEq + Debug;

    /// The mode's name, passed to the observer's [`on_mode`](Observer::on_mode) before each
    /// segment. Default: `"mode"`.
    fn mode_name(&self, _mode: Self::Mode) -> &'static str {
        "mode"
    }

    /// Runs `mode` from `(t, y)` towards `t_end`, streaming to `observer`, until `t_end` or
    /// a mode change.
    ///
    /// # Errors
    /// Whatever the segment's integration or event handling reports.
    fn segment<O: Observer<T, M>>(
        &mut self,
        mode: Self::Mode,
        t: T,
        y: SVector<T, M>,
        t_end: T,
        observer: &mut O,
    ) -> Result<Segment<T, M, Self::Mode>>;
}

/// The result of [`run_modes`].
#[derive(Debug, Clone, PartialEq)]
pub struct ModeRun<T: Real, const M: usize, Mode> {
    /// The last segment's outcome (end time and state; its statistics are the last
    /// segment's).
    pub outcome: Outcome<T, M>,
    /// Every mode change: the time and the mode entered.
    pub transitions: Vec<(T, Mode)>,
}

/// Runs `system` from `(t0, y0)` in `mode` to `t_end` through its mode changes, at most
/// `max_segments` segments.
///
/// # Errors
/// [`ParameterError`] if `max_segments` is zero; the segments' errors (a start mode that
/// contradicts the start state is [`ModeError::InconsistentStart`]); [`EventError::Zeno`]
/// if `max_segments` segments do not reach `t_end` (mode changes accumulating), with the
/// state to continue from.
pub fn run_modes<T, const M: usize, Sys, O>(
    system: &mut Sys,
    mode: Sys::Mode,
    t0: T,
    y0: SVector<T, M>,
    t_end: T,
    max_segments: usize,
    observer: &mut O,
) -> Result<ModeRun<T, M, Sys::Mode>>
where
    T: Real,
    Sys: ModeSystem<T, M>,
    O: Observer<T, M>,
{
    if max_segments == 0 {
        return Err(ParameterError::new("max_segments", 0.0, "> 0").into());
    }
    let (mut mode, mut t, mut y) = (mode, t0, y0);
    let mut transitions = Vec::new();
    for _ in 0..max_segments {
        observer.on_mode(t, system.mode_name(mode));
        let segment = system.segment(mode, t, y, t_end, observer)?;
        match segment.next {
            None => {
                return Ok(ModeRun {
                    outcome: segment.outcome,
                    transitions,
                });
            }
            Some(_) if segment.outcome.t >= t_end => {
                return Ok(ModeRun {
                    outcome: segment.outcome,
                    transitions,
                });
            }
            Some(next) => {
                t = segment.outcome.t;
                y = segment.outcome.y;
                if next != mode {
                    transitions.push((t, next));
                }
                mode = next;
            }
        }
    }
    Err(EventError::Zeno {
        t: to_f64(t),
        count: max_segments,
        last_interval: 0.0,
        state: y.iter().map(|&v| to_f64(v)).collect(),
    }
    .into())
}
