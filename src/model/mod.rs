//! Systems assembled from force laws and excitations.
//!
//! [`Oscillator`] is a one-degree-of-freedom system `m·ẍ + ΣF(x, ẋ) = f(t)` built from a
//! mass, any [`ForceLaw`](crate::ForceLaw) (a tuple of laws is one) and any
//! [`Excitation`](crate::excite::Excitation). The paper's impact oscillator is
//! [`paper::PaperOscillator`], assembled from the generic parts in [`paper`].

mod oscillator;
pub mod paper;

pub use oscillator::Oscillator;
