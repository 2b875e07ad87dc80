//! A catalogue of ready systems, each assembled from the crate's parts, with its source and
//! validated parameters.
//!
//! | system | equation | module |
//! |---|---|---|
//! | the paper's cart | `m·ẍ + kx + cẋ + T·ẋ/√(ẋ²+ε²) + F_I(x, ẋ) = m₀eω² sin ωt` | [`paper`] |
//! | ball on a vibrating table | `ÿ = −g` above `s = A sin ωt`, Newton restitution `e` (rigid) | [`bouncing_ball`] |
//! | Duffing–Ueda oscillator | `ẍ + kẋ + x³ = B cos ωt` | [`duffing_ueda`] |
//! | 2-DOF impact oscillator | primary mass, coupled secondary mass hitting a Hertz stop | [`two_dof`] |
//! | woodpecker toy | sleeve and bird on a pole, three frictional impact contacts (time-stepping) | [`woodpecker`] |
//! | relay feedback system | `ẋ = A x − b sgn(x₁)`, a third-order plant sliding on `x₁ = 0` (Filippov) | [`relay`] |
//!
//! Every entry is an ordinary [`Oscillator`](crate::model::Oscillator),
//! [`Mechanical`](crate::model::Mechanical) model, [`filippov`](crate::filippov) system or
//! [`timestep`](crate::timestep) `Lagrangian`:
//! nothing in the engine knows about any of them.

pub mod bouncing_ball;
pub mod duffing_ueda;
pub mod paper;
pub mod relay;
pub mod two_dof;
pub mod woodpecker;

pub use bouncing_ball::{BouncingBallTable, TableContact};
pub use duffing_ueda::DuffingUeda;
pub use relay::RelayFeedback;
pub use two_dof::TwoDofImpact;
pub use woodpecker::Woodpecker;
