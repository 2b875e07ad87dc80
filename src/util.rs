//! Numerical utilities the crate is built on, for users who want the same tools: Brent's
//! bracketing root finder and a golden-section maximizer ([`brent`], [`golden_max`], their
//! [`RootError`]), the sine and cosine the excitations evaluate ([`sin`], [`cos`],
//! [`sin_cos`] and their `f64` forms: fdlibm's kernels with a Cody–Waite reduction, within
//! 1 ulp of `libm` where `|sin x|, |cos x| > 10⁻³` and independent of the platform's `libm`), and the scalar helpers for generic code ([`lit`], [`to_f64`]).
//!
//! The modules behind them are private: everything a user of the crate needs from them is
//! here, and the rest may change without notice.

pub use crate::fastmath::{cos, cos_f64, sin, sin_cos, sin_cos_f64, sin_f64};
pub use crate::roots::{RootError, brent, golden_max};
pub use crate::scalar::{lit, to_f64};
