//! Filippov systems: vector fields that are discontinuous across switching surfaces, with
//! crossing, sliding on a surface and exit from it, by the event-driven method of
//! Piiroinen & Kuznetsov.
//!
//! # Model
//! A [`Filippov`] system has codimension-1 surfaces `H_i(t, x) = 0`, `i < S`, and a smooth
//! field in each region, the region given by the side of every surface ([`Region`]: which side of one surface):
//! $$ \dot x = F_\sigma(t, x), \qquad \sigma = (\operatorname{sgn} H_0, \dots, \operatorname{sgn} H_{S-1}). $$
//! On surface `i`, with the other surfaces' sides fixed, let `F₋`, `F₊` be the fields of the
//! two regions it separates and
//! $$ h_\pm = \nabla H \cdot F_\pm + \partial_t H $$
//! the rates at which they move `H`.
//! - **Crossing** (`h₋ h₊ > 0`): both fields move the state through the surface.
//! - **Sliding** (`h₋ > 0 > h₊`, both push into the surface): the state moves on the
//!   surface with Filippov's convex combination given by Utkin's equivalent control,
//!   $$ F_s = (1-\alpha) F_- + \alpha F_+, \qquad \alpha = \frac{h_-}{h_- - h_+} \in [0, 1], $$
//!   the `α` for which `∇H·F_s + ∂_t H = 0`.
//! - **Exit**: sliding ends where `α` leaves `[0, 1]` (`α = 0`: `h₋ = 0`, the state leaves
//!   into `H < 0` along `F₋`; `α = 1`: into `H > 0`), located as a zero of the event
//!   `min(α, 1 − α)` on the dense output.
//! - **Repelling** (`h₋ < 0 < h₊`): the forward solution is not unique; the run stops
//!   with [`FilippovError::Repelling`].
//!
//! # Method
//! Each mode ([`Mode`]: a region, or sliding on surface `i`) is integrated by the crate's
//! steppers with the driver's crossing search ([`drive`](crate::drive)): the surfaces and
//! the exit are terminal events, located on the interpolant of the step. At an event the
//! next mode is chosen from the signs of `h±`. Where a rate is within the tangency
//! tolerance of zero ([`Settings::tangency`]) its sign is taken from the **second-order
//! test**, the sign of
//! $$ L_F^2 H = \frac{d}{dt}\left(\nabla H\cdot F + \partial_t H\right) \text{ along } F , $$
//! so a grazing arrival (`h₋ = 0`, `L²H < 0`) stays in its region, a field tangent on the
//! far side that turns back into the surface (`h₊ = 0`, `L²_{F₊}H < 0`) makes the state
//! slide, and an exit where `α` only touches a bound (`L²H` pointing back) goes on sliding.
//! Where the second-order test is inconclusive (`L²H` zero, or within the rounding of the
//! central difference it is computed by) the first-order sign decides: a state that reached
//! the surface at a rate below the tolerance but not zero, with nothing of second order to
//! turn it back (a constant field), crosses, as the flow does.
//!
//! Every quantity a decision reads (`H`, `∇H`, `∂_t H`, `h±`, `L²H`) must be finite; one
//! that is not stops the run with [`FilippovError::NonFinite`] naming it.
//!
//! **Drift**: `∇H·F_s = −∂_t H` holds at every stage of a step, so for a linear surface a
//! Runge–Kutta step keeps `H` constant to rounding; for a curved one the state is projected
//! back onto `H = 0` (Newton steps along `∇H`) at every step end. `|H|` is checked on the
//! dense output between step ends ([`Settings::drift`]) and its largest value is reported
//! ([`FilippovRun::max_drift`]).
//!
//! **Codimension 2**: an event on one surface with another within the coincidence
//! tolerance of zero, or any surface met while sliding, stops the run with
//! [`FilippovError::Codimension2`] (time and both surfaces) instead of a wrong answer.
//!
//! **Observers** ([`SlidingObserver`]) get every step with its mode and every
//! [`ModeTransition`]; [`Plain`] passes them to any [`Observer`](crate::drive::Observer) of
//! the driver (modes by [`Observer::on_mode`](crate::drive::Observer::on_mode)).
//!
//! # Tangent dynamics
//! [`FilippovSimulation::monodromy`] integrates `Φ̇ = JΦ` along each mode and multiplies by
//! the saltation matrix ([`saltation`]) at each transition:
//! - crossing from `a` to `b`: `S = I + (F_b − F_a)∇Hᵀ/h_a`;
//! - sliding entry from `a`: `S = I + (F_s − F_a)∇Hᵀ/h_a`, which maps every perturbation
//!   into the surface's tangent space (`∇H·S = 0` for a linear surface): a multiplier 0;
//! - sliding exit: `S = I` (`F_s = F_b` where `α` reaches its bound).
//!
//! [`FilippovSimulation::find_orbit`] finds periodic orbits with sliding segments by
//! Newton's method on the period map with this monodromy as its Jacobian (a forced system's
//! period, or an autonomous orbit's unknown period with a phase section), and
//! [`FilippovSimulation::exponents`] the Lyapunov spectrum by re-orthonormalizing the
//! monodromy of successive intervals. A sliding entry collapses the direction normal to
//! the surface: a Floquet multiplier 0, a Lyapunov exponent `−∞`.
//!
//! While sliding, `J` is the Jacobian of the sliding field,
//! $$ J_s = J_- + \alpha (J_+ - J_-) + (F_+ - F_-)\nabla\alpha^{\mathsf T}, \qquad
//!    \nabla\alpha = \frac{h_-\nabla h_+ - h_+\nabla h_-}{(h_- - h_+)^2}, $$
//! `∇h± = J±ᵀ∇H + ∇²H F± + ∂_t∇H`.
//!
//! # Test functions
//! The transitions carry what sliding bifurcations are located by: `α` at an exit (an exit
//! at `α = 0` versus `1`), `h±` at an arrival (a crossing turning into a sliding entry where
//! `h₊` changes sign: crossing- or switching-sliding, told apart by the sign of the far
//! field's second-order rate [`second_rate`] there), and a [`TransitionKind::Graze`] (the
//! minimum of `H` along a region's orbit reaching zero: grazing-sliding).
//! [`FilippovSimulation::control_extrema`] finds the local extrema of the equivalent
//! control `α` along the sliding flow (continued past the exit when asked for a longer
//! span): where one touches its bound, a sliding segment splits in two (adding-sliding).
//! The branches and their test functions are in [`orbit::sliding`](crate::orbit::sliding).
//!
//! # Dry friction: `StickSlip` is this path
//! A mass whose coordinate rubs on a surface of velocity `u` with Coulomb friction of
//! static limit equal to the kinetic force `F_k` is the Filippov system with the surface
//! `H = w·q̇ − u` and the fields of slip with the friction force `∓F_k`: sticking is
//! sliding on `H = 0`, the stick force is the equivalent control
//! (`F = F_k(1 − 2α)`), and a stick ends where `α` reaches 0 or 1, i.e. where the force
//! needed to hold reaches `F_k`. [`CoulombFriction`] builds this system from a
//! [`Mechanical`](crate::model::Mechanical) model and a
//! [`Coulomb`](crate::drive::Coulomb) contact. [`StickSlip`](crate::drive::StickSlip) with
//! `F_s = F_k` gives the same modes at the same times (checked in the tests on a forced
//! oscillator on a belt); with `F_s > F_k` (a static limit above the kinetic force) the
//! law is not a Filippov convexification and `StickSlip` is the model.
//!
//! # Relay loads
//! [`RelayLoad`] builds the Filippov system of a [`Mechanical`](crate::model::Mechanical)
//! model with a relay load `u = −U·sgn(σ)` along a direction `b` of the generalized forces,
//! switched by a linear function `σ = s_q·q + s_v·q̇` of the state; with a linear model it
//! is [`LinearRelay`] (checked in the tests to round-off).
//!
//! # Time dependence
//! Fields and surfaces may depend on `t`. While the state slides (or sticks), it can stay
//! nearly constant while the forcing changes, so a system with forcing declares its
//! [`time_scale`](Filippov::time_scale) (e.g. a sixteenth of the forcing period): no step
//! is longer, and the exit event cannot be stepped over.
//!
//! # Example
//! ```
//! use nalgebra::SVector;
//! use nonsmooth::filippov::{FilippovSimulation, Switched, TransitionKind};
//! use nonsmooth::integrate::{Dopri5, Tolerances};
//!
//! // ẋ = y, ẏ = −x − sgn(y − 0.5) (a mass on a spring, on a belt at speed 0.5):
//! // sliding (sticking to the belt) on y = 0.5 while |x| ≤ 1.
//! let belt = Switched::new(
//!     |x: &SVector<f64, 2>| x[1] - 0.5,
//!     |_x: &SVector<f64, 2>| SVector::from([0.0, 1.0]),
//!     |_t, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] + 1.0]),
//!     |_t, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] - 1.0]),
//! );
//! let mut sim = FilippovSimulation::new(belt, Dopri5::new(Tolerances::new(1e-10, 1e-12)?));
//! let run = sim.run(0.0, SVector::from([0.0, 0.5]), 5.0, &mut ())?;
//! // Stuck from x = 0 until the spring force reaches the friction limit, x = 1, at t = 2.
//! let exit = run.transitions[0];
//! assert_eq!(exit.kind, TransitionKind::SlidingExit);
//! assert!((exit.t - 2.0).abs() < 1e-10);
//! # Ok::<(), nonsmooth::filippov::FilippovError>(())
//! ```
//!
//! # References
//! P. T. Piiroinen, Yu. A. Kuznetsov, *An event-driven method to simulate Filippov systems
//! with accurate computing of sliding motions*, ACM TOMS 34(3), 2008. A. F. Filippov,
//! *Differential Equations with Discontinuous Righthand Sides*, Kluwer, 1988.
//! V. I. Utkin, *Sliding Modes in Control and Optimization*, Springer, 1992.
//! M. di Bernardo, C. J. Budd, A. R. Champneys, P. Kowalczyk, *Piecewise-smooth Dynamical
//! Systems*, Springer, 2008 (saltation matrices, sliding bifurcations).

mod approach;
mod error;
mod extrema;
mod field;
mod friction;
mod load;
mod relay;
mod run;
mod system;
mod tangent;

pub use approach::Approach;
pub use error::FilippovError;
pub use extrema::{ControlExtremum, second_rate};
pub use friction::CoulombFriction;
pub use load::RelayLoad;
pub use relay::LinearRelay;
pub use run::{
    FilippovRun, FilippovSimulation, MAX_SAMPLES, ModeTransition, Plain, Settings, SlidingObserver,
    TransitionKind,
};
pub use system::{Filippov, Mode, Region, Switched};
pub use tangent::{Exponents, Monodromy, SlidingOrbit, saltation};
