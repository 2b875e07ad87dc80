//! SIMD lanes: `L` values of `f64` in one vector, the math functions in lane form, and the
//! instruction set the lane code runs on.
//!
//! The ensemble ([`ensemble`](crate::ensemble)) steps `L` trajectories in the lanes of a
//! [`Lanes`] vector. What it evaluates there is the lane form of the model: of its force
//! laws ([`LaneLaw`](crate::force::LaneLaw)), excitations
//! ([`LaneExcitation`](crate::excite::LaneExcitation)) and of the model itself
//! ([`LaneDynamics`](crate::LaneDynamics)). Those are written with the lane-wise operations
//! of [`Lanes`] (arithmetic, comparisons giving masks, [`Lanes::select`]) and the functions
//! of [`math`]: with [`LaneMath::Exact`] each lane computes the scalar path's value to the
//! bit.
//!
//! # Writing a lane form
//! A branch of a scalar law (`if d <= 0 { 0 } else { … }`) becomes a mask and a select:
//! ```
//! use nonsmooth::lanes::{F64x4, Lanes};
//!
//! // max(x − x0, 0)·k in every lane.
//! fn stop<V: Lanes>(x: V, x0: V, k: V) -> V {
//!     let d = x - x0;
//!     let inside = d.gt(V::splat(0.0));
//!     inside.select(k * d, V::splat(0.0))
//! }
//! let f = stop(F64x4::load(&[-1.0, 0.5, 2.0, 3.0]), F64x4::splat(0.0), F64x4::splat(2.0));
//! assert_eq!([f.lane(0), f.lane(1), f.lane(2), f.lane(3)], [0.0, 1.0, 4.0, 6.0]);
//! ```

pub mod math;
mod simd;
mod vector;

pub use math::LaneMath;
pub use simd::Simd;
pub use vector::{F64x2, F64x4, F64x8, F64x16, Lanes};

/// All bits set: the `true` of a lane mask.
pub const TRUE: f64 = f64::from_bits(u64::MAX);

/// The mask of a `bool`: all bits set for `true`, zero for `false`.
#[inline(always)]
pub fn mask(b: bool) -> f64 {
    if b { TRUE } else { 0.0 }
}
