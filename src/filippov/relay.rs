//! Relay feedback of a linear plant, `ẋ = A x − b sgn(c·x)`, as a Filippov system.

use nalgebra::{SMatrix, SVector};

use super::system::{Filippov, Region};
use crate::Real;
use crate::scalar::to_f64;
use crate::validate::ParameterError;

/// A linear plant `ẋ = A x + b u` under relay feedback `u = −sgn(c·x)`: one switching
/// surface `H = c·x`, the fields `A x ± b` below and above it. Where `c·b > 0` both fields
/// push into the surface for `|c·A x| < c·b`, and the state slides with the equivalent
/// control `u_eq = −(c·A x)/(c·b)`.
///
/// # Example
/// The relay feedback system of di Bernardo, Johansson & Vasca (IJBC 11(4), 2001), the test
/// problem of Piiroinen & Kuznetsov (ACM TOMS 34(3), 2008, eq. (32)): `ζ = 0.05`, `ω = 25`,
/// `σ = 1`,
/// `A = [[−(2ζω+1), 1, 0], [−(2ζω+ω²), 0, 1], [−ω², 0, 0]]`, `b = (1, −2σ, 1)`,
/// `c = (1, 0, 0)`:
/// ```
/// use nalgebra::{Matrix3, SVector, Vector3};
/// use nonsmooth::filippov::{FilippovSimulation, LinearRelay};
/// use nonsmooth::integrate::{Dopri5, Tolerances};
///
/// let (z, w, s) = (0.05, 25.0, 1.0);
/// let a = Matrix3::new(
///     -(2.0 * z * w + 1.0), 1.0, 0.0,
///     -(2.0 * z * w + w * w), 0.0, 1.0,
///     -w * w, 0.0, 0.0,
/// );
/// let relay = LinearRelay::new(a, Vector3::new(1.0, -2.0 * s, 1.0), Vector3::new(1.0, 0.0, 0.0))?;
/// let mut sim = FilippovSimulation::new(relay, Dopri5::new(Tolerances::new(1e-10, 1e-12)?));
/// let run = sim.run(0.0, SVector::from([0.0, -0.001, -0.02]), 1.0, &mut ())?;
/// assert!(run.start_mode.is_sliding()); // x₀ is on the surface, both fields push into it
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearRelay<T: Real, const N: usize> {
    a: SMatrix<T, N, N>,
    b: SVector<T, N>,
    c: SVector<T, N>,
}

impl<T: Real, const N: usize> LinearRelay<T, N> {
    /// The plant `(A, b)` with the relay on `c·x`.
    ///
    /// # Errors
    /// [`ParameterError`] naming the first non-finite entry of `A`, `b` or `c`, or if `c` is
    /// zero (no surface).
    pub fn new(
        a: SMatrix<T, N, N>,
        b: SVector<T, N>,
        c: SVector<T, N>,
    ) -> Result<Self, ParameterError> {
        for (name, v) in a
            .iter()
            .map(|v| ("A", *v))
            .chain(b.iter().map(|v| ("b", *v)))
            .chain(c.iter().map(|v| ("c", *v)))
        {
            if !v.is_finite() {
                return Err(ParameterError::new(name, to_f64(v), "finite entries"));
            }
        }
        if c.amax() == T::zero() {
            return Err(ParameterError::new(
                "c",
                0.0,
                "non-zero (the switching surface c·x = 0)",
            ));
        }
        Ok(Self { a, b, c })
    }
}

impl<T: Real, const N: usize> Filippov<T, N, 1> for LinearRelay<T, N> {
    #[inline(always)]
    fn surface(&self, _i: usize, _t: T, x: &SVector<T, N>) -> T {
        self.c.dot(x)
    }
    fn gradient(&self, _i: usize, _t: T, _x: &SVector<T, N>) -> SVector<T, N> {
        self.c
    }
    #[inline(always)]
    fn field(&self, sides: &[Region; 1], _t: T, x: &SVector<T, N>, dx: &mut SVector<T, N>) {
        // u = −sgn(c·x): +1 below the surface, −1 above.
        *dx = self.a * x - self.b * sides[0].sign::<T>();
    }
    fn field_jacobian(
        &self,
        _s: &[Region; 1],
        _t: T,
        _x: &SVector<T, N>,
    ) -> Option<SMatrix<T, N, N>> {
        Some(self.a)
    }
}
