//! # nonsmooth
//!
//! Dynamics of nonsmooth mechanical systems — oscillators with impacts, compliant
//! (Hertz-type) contact, dry friction and harmonic forcing — from force laws to
//! bifurcation diagrams, Lyapunov exponents and entropy indices.
//!
//! ## A tour
//! | layer | what | start at |
//! |---|---|---|
//! | scalar, errors | `T: Real` (`f64`, `f32`), one crate [`Error`] | [`Real`], [`Error`] |
//! | force laws | `F(x, ẋ)` terms with partials, composable by value | [`ForceLaw`], [`force`] |
//! | excitation | harmonic, unbalanced rotor, ramped rotor | [`excite`] |
//! | models | `ẏ = f(t, y)`; N-DOF systems from elements, the 1-DOF oscillator | [`Dynamics`], [`model::Mechanical`], [`model::Oscillator`] |
//! | catalogue | ready systems: the paper's cart, Duffing–Ueda, a 2-DOF impact oscillator | [`systems`] |
//! | utilities | Brent's root bracketing, golden-section search, the fast `sin`/`cos` of the forcing | [`util`] |
//! | integrators | DOPRI5, DOP853, Tsitouras 5(4), Verner 6(5), Rosenbrock 2(3) on one adaptive stepper, RK4, turning points; dense output | [`integrate`] |
//! | events | crossings located on dense output, grazing pairs, resets, Zeno guard | [`event`] |
//! | driver | system + stepper + events + observers | [`drive`] |
//! | sliding | Filippov systems: crossing and sliding on switching surfaces, saltation, monodromy, orbits | [`filippov`] |
//! | time-stepping | many rigid contacts at once: Moreau–Jean with Lemke, projected and nonsmooth Gauss–Seidel | [`timestep`] |
//! | samplers | stroboscopic sections, impact sequences, period summaries | [`sample`] |
//! | sweeps | up/down continuation, hysteresis, transitions, ramps | [`sweep`] |
//! | chaos measures | top Lyapunov exponents (two-trajectory and QR), Tsallis entropy index | [`lyapunov`], [`entropy`] |
//! | analysis | spectra, harmonic fits, the paper's approximations, first grazing | [`analysis`] |
//! | measured data | time series, filter, threshold impacts, synthetic records, identification (the paper's configuration in [`systems::paper`]) | [`signal`], [`identify`] |
//!
//! `use nonsmooth::prelude::*` imports the types to build, run and record a system
//! ([`prelude`]). The [`guide`] walks through the crate chapter by chapter, from the first
//! impact oscillator to studies on a cluster, with code that runs as doctests.
//!
//! ## Quick start
//! ```
//! use nonsmooth::systems::paper::PAPER;
//! use nonsmooth::Dynamics;
//! use nalgebra::Vector2;
//!
//! // The paper's oscillator forced at ω = 14 rad/s, assembled from generic force laws.
//! let osc = PAPER.oscillator::<f64>(14.0)?;
//! // Its static equilibrium, pressed ~5 µm into the stop (paper: −2.0807e-3 m).
//! let x0 = PAPER.static_equilibrium()?;
//! assert!((x0 + 2.0807e-3).abs() < 5e-8);
//! // The right-hand side at rest in the equilibrium: no acceleration at t = 0.
//! let mut dy = Vector2::zeros();
//! osc.rhs(0.0, &Vector2::new(x0, 0.0), &mut dy);
//! assert!(dy[1].abs() < 1e-9);
//! # Ok::<(), nonsmooth::Error>(())
//! ```
#![warn(missing_docs)]
// Negated comparisons (`!(a > b)`) are used on purpose: they are true for NaN, so NaN
// inputs fail validation instead of slipping through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod analysis;
pub mod drive;
pub mod dynamics;
pub mod ensemble;
pub mod entropy;
pub mod error;
pub mod event;
pub mod excite;
mod fastmath;
pub mod filippov;
pub mod force;
pub mod guide;
pub mod identify;
pub mod integrate;
pub mod lanes;
mod linalg;
pub mod lyapunov;
pub mod model;
pub mod orbit;
pub mod output;
pub mod prelude;
mod roots;
pub mod sample;
mod scalar;
mod serde_check;
pub mod signal;
#[cfg(feature = "cli")]
pub mod study;
pub mod sweep;
pub mod systems;
#[cfg(feature = "testing")]
pub mod testing;
pub mod timestep;
pub mod util;
pub(crate) mod validate;

pub use dynamics::{Dynamics, LaneByLane, LaneDynamics};

/// The README's code blocks, compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
pub use error::{Error, Result};
pub use force::ForceLaw;
pub use scalar::Real;
pub use validate::ParameterError;
