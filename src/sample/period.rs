//! Period detection from stroboscopic points.

use nalgebra::SVector;

use crate::Real;
use crate::validate::ParameterError;

/// The regime read from a sequence of section points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Regime {
    /// Periodic with the given period in forcing periods (1 = period-1 orbit).
    Periodic(usize),
    /// No period up to the maximum tested (quasi-periodic or chaotic).
    NotPeriodic,
}

impl Regime {
    /// The period, if periodic.
    pub fn period(&self) -> Option<usize> {
        match self {
            Regime::Periodic(p) => Some(*p),
            Regime::NotPeriodic => None,
        }
    }
}

/// The smallest `p ≤ max_period` with `‖(P_{i+p} − P_i) ⊘ scale‖_∞ ≤ tol` for every
/// recorded `i` (component-wise scaling by `scale`), or [`Regime::NotPeriodic`].
///
/// Needs at least `2·p` points to accept a period `p`. A tolerance that is not finite and
/// `≥ 0` (negative, infinite or NaN) finds no period: [`Regime::NotPeriodic`]. Use
/// [`try_detect_period`] to have such a tolerance rejected.
pub fn detect_period<T: Real, const N: usize>(
    points: &[SVector<T, N>],
    scale: &SVector<T, N>,
    tol: T,
    max_period: usize,
) -> Regime {
    try_detect_period(points, scale, tol, max_period).unwrap_or(Regime::NotPeriodic)
}

/// [`detect_period`] with the tolerance checked first.
///
/// # Errors
/// [`ParameterError`] naming `tol` unless it is finite and `≥ 0` (a negative or `−∞`
/// tolerance would call every sequence not periodic, `+∞` every sequence period 1).
pub fn try_detect_period<T: Real, const N: usize>(
    points: &[SVector<T, N>],
    scale: &SVector<T, N>,
    tol: T,
    max_period: usize,
) -> Result<Regime, ParameterError> {
    let tol = crate::validate::non_negative("tol", tol)?;
    for p in 1..=max_period {
        if points.len() < 2 * p {
            break;
        }
        let ok = (0..points.len() - p).all(|i| {
            (0..N).all(|c| {
                let s = if scale[c] > T::zero() {
                    scale[c]
                } else {
                    T::one()
                };
                ((points[i + p][c] - points[i][c]) / s).abs() <= tol
            })
        });
        if ok {
            return Ok(Regime::Periodic(p));
        }
    }
    Ok(Regime::NotPeriodic)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn detects_periods() {
        let s = Vector2::new(1.0, 1.0);
        let p2: Vec<_> = (0..20)
            .map(|i| Vector2::new(if i % 2 == 0 { 1.0 } else { -1.0 }, 0.0))
            .collect();
        assert_eq!(detect_period(&p2, &s, 1e-9, 8), Regime::Periodic(2));
        let p1: Vec<_> = (0..20).map(|_| Vector2::new(0.5, 0.1)).collect();
        assert_eq!(detect_period(&p1, &s, 1e-9, 8), Regime::Periodic(1));
        let chaos: Vec<_> = (0..50)
            .map(|i| Vector2::new((i as f64 * 1.7).sin(), 0.0))
            .collect();
        assert_eq!(detect_period(&chaos, &s, 1e-6, 8), Regime::NotPeriodic);
        assert_eq!(Regime::Periodic(3).period(), Some(3));
    }
}
