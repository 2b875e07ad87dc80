//! The relay feedback system of di Bernardo, Johansson and Vasca: a third-order linear plant
//! under relay feedback, whose attractor is a periodic orbit with sliding segments (the test
//! problem of Piiroinen and Kuznetsov for event-driven Filippov solvers).
//!
//! # Model
//! $$\dot x = A x - b\,\mathrm{sgn}(c^\top x),\quad
//! A = \begin{pmatrix} -(2\zeta\omega+1) & 1 & 0\\ -(2\zeta\omega+\omega^2) & 0 & 1\\
//! -\omega^2 & 0 & 0\end{pmatrix},\quad b = (1, -2\sigma, 1)^\top,\quad c = (1, 0, 0)^\top,$$
//! with `ζ = 0.05`, `ω = 25`, `σ = 1` and the start `x₀ = (0, −0.001, −0.02)` of the test
//! problem ([`RelayFeedback::default`], [`RelayFeedback::X0`]).
//!
//! # References
//! M. di Bernardo, K. H. Johansson, F. Vasca, *Self-oscillations and sliding in relay
//! feedback systems: symmetry and bifurcations*, IJBC 11(4) (2001); P. T. Piiroinen,
//! Yu. A. Kuznetsov, *An event-driven method to simulate Filippov systems with accurate
//! computing of sliding motions*, ACM TOMS 34(3) (2008), eq. (32).

use nalgebra::{Matrix3, Vector3};

use crate::filippov::LinearRelay;
use crate::validate::ParameterError;

/// The relay feedback system's parameters (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelayFeedback {
    /// Damping ratio `ζ`.
    pub zeta: f64,
    /// Natural frequency `ω`.
    pub omega: f64,
    /// The input's middle weight `σ` (`b = (1, −2σ, 1)`).
    pub sigma: f64,
}

impl Default for RelayFeedback {
    /// The test problem: `ζ = 0.05`, `ω = 25`, `σ = 1`.
    fn default() -> Self {
        Self {
            zeta: 0.05,
            omega: 25.0,
            sigma: 1.0,
        }
    }
}

impl RelayFeedback {
    /// The test problem's initial state `(0, −0.001, −0.02)`.
    pub const X0: [f64; 3] = [0.0, -0.001, -0.02];

    /// The plant matrix `A`.
    pub fn a(&self) -> Matrix3<f64> {
        let (z, w) = (self.zeta, self.omega);
        Matrix3::new(
            -(2.0 * z * w + 1.0),
            1.0,
            0.0,
            -(2.0 * z * w + w * w),
            0.0,
            1.0,
            -w * w,
            0.0,
            0.0,
        )
    }

    /// The input vector `b = (1, −2σ, 1)`.
    pub fn b(&self) -> Vector3<f64> {
        Vector3::new(1.0, -2.0 * self.sigma, 1.0)
    }

    /// The switching direction `c = (1, 0, 0)` (the surface `x₁ = 0`).
    pub fn c(&self) -> Vector3<f64> {
        Vector3::new(1.0, 0.0, 0.0)
    }

    /// The system `ẋ = A x − b sgn(x₁)`.
    ///
    /// # Errors
    /// [`ParameterError`] naming the first non-finite entry (a non-finite parameter).
    pub fn system(&self) -> Result<LinearRelay<f64, 3>, ParameterError> {
        LinearRelay::new(self.a(), self.b(), self.c())
    }
}
