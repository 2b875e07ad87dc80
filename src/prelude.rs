//! The types a new user needs to build a system, run it and record what happens, in one
//! import (no two of them share a name):
//!
//! ```
//! use nalgebra::SVector;
//! use nonsmooth::prelude::*;
//!
//! // A forced oscillator hitting a compliant stop at x = 0.2, impacts recorded.
//! let model = Mechanical::with_masses([1.0])?
//!     .with_elements((
//!         Element::on_dof(0, (LinearSpring::new(1.0)?, ViscousDamper::new(0.05)?))?,
//!         Element::on_dof(0, HertzContact::new(0.2, 1e3)?)?,
//!     ))
//!     .with_loads(Load::on_dof(0, Harmonic::cosine(0.5, 0.8)?)?);
//! let stop = Gap::below(Coordinate::<f64, 1>::dof(0)?.with_offset(-0.2)?, ());
//! let mut impacts = ImpactSequence::on_surface(0, stop, 50.0, 1000)?;
//! let tol = Tolerances::<f64, 2>::new(1e-9, 1e-11)?; // the state (x, ẋ)
//! let out = Simulation::new(model, Dopri5::new(tol))
//!     .with_events(Event::new(stop, Direction::Rising))
//!     .run(0.0, SVector::zeros(), 200.0, &mut impacts)?;
//! assert_eq!(out.termination, Termination::ReachedEnd);
//! assert!(impacts.count() > 5);
//! # Ok::<(), nonsmooth::Error>(())
//! ```
//!
//! Instruments (sweeps, Lyapunov exponents, periodic orbits, entropy, analysis) and the
//! catalogue of systems are imported from their modules.

pub use crate::drive::{
    Control, EventRecord, Observer, Outcome, RunError, Simulation, StepView, Termination,
};
pub use crate::event::{
    Direction, Event, EventFunction, Gap, Level, NewtonImpact, Restitution, Stop,
};
pub use crate::excite::{Constant, Excitation, Harmonic, UnbalancedRotor};
pub use crate::force::{
    Bilinear, CubicSpring, DryFriction, HertzContact, LinearSpring, ViscousDamper,
};
pub use crate::integrate::{Dop853, Dopri5, Rk4, Rosenbrock23, Stepper, Tolerances, TurningPoints};
pub use crate::model::{Coordinate, Element, Load, Mechanical, Oscillator};
pub use crate::sample::{ImpactSequence, PeriodSummary, Stroboscopic, Trajectory};
pub use crate::{Dynamics, Error, ForceLaw, ParameterError, Real};
