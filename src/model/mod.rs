//! Systems assembled from force laws and excitations.
//!
//! - [`Mechanical`]: an `N`-degree-of-freedom system `M q̈ + C q̇ + K q + Σ w F(w·q + o, w·q̇)
//!   = Σ w f(t)` assembled from [`Element`]s (any [`ForceLaw`](crate::ForceLaw) acting on a
//!   [`Coordinate`]: a degree of freedom, a relative coordinate `q_i − q_j + o`, any linear
//!   form) and [`Load`]s (any [`Excitation`](crate::excite::Excitation) acting on a
//!   coordinate), with the Jacobian assembled from the laws' partials and a Newton static
//!   equilibrium.
//! - [`Oscillator`]: the one-degree-of-freedom case `m·ẍ + ΣF(x, ẋ) = f(t)` in scalar form
//!   (bit-identical to `Mechanical` with `N = 1`, without the vector bookkeeping).
//!
//! Ready-made systems — the paper's impact oscillator among them, in
//! [`systems::paper`](crate::systems::paper) — are in [`systems`](crate::systems).

mod mechanical;
mod oscillator;

pub(crate) use mechanical::shorter;
pub use mechanical::{
    Coordinate, Element, Elements, LaneElements, LaneLoads, Load, Loads, Mechanical,
    MechanicalLanes, MechanicalPacked, ModelError,
};
pub use oscillator::Oscillator;
