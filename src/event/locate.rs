//! The bracketing search for a crossing inside a step.

use crate::Real;
use crate::scalar::lit;

/// Locates a crossing of `g` in `[a, b]` (with `ga`, `gb` of opposite signs, `gb` on the
/// far side) by the Illinois variant of regula falsi, which keeps a bracket at all times.
/// Returns `(t, g(t))` with `t` the end of the final bracket on the far side, within `tol`
/// of the crossing.
pub(crate) fn locate<T: Real, F: FnMut(T) -> T>(
    mut g: F,
    a: T,
    b: T,
    ga: T,
    gb: T,
    tol: T,
) -> (T, T) {
    let (mut a, mut b, mut ga, mut gb) = (a, b, ga, gb);
    let far_positive = gb > T::zero() || (gb == T::zero() && ga < T::zero());
    let mut side = 0i8;
    let half = lit::<T>(0.5);
    for _ in 0..200 {
        let w = b - a;
        if w.abs() <= tol {
            break;
        }
        let mut c = if gb != ga {
            (a * gb - b * ga) / (gb - ga)
        } else {
            (a + b) * half
        };
        // Keep c strictly inside, at least tol/2 from either end, so the bracket shrinks.
        let lo = a.min(b) + tol * half;
        let hi = a.max(b) - tol * half;
        // (NaN-safe: a NaN c falls through both tests to the clamp.)
        if c.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
            c = lo;
        }
        if c.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
            c = hi;
        }
        let gc = g(c);
        let on_far = if far_positive {
            gc >= T::zero()
        } else {
            gc <= T::zero()
        };
        if on_far {
            b = c;
            gb = gc;
            if side == 1 {
                ga *= half;
            }
            side = 1;
        } else {
            a = c;
            ga = gc;
            if side == -1 {
                gb *= half;
            }
            side = -1;
        }
    }
    (b, gb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locate_keeps_far_side() {
        let (t, g) = locate(|t: f64| t * t - 2.0, 0.0, 2.0, -2.0, 2.0, 1e-13);
        assert!(g >= 0.0);
        assert!(
            t - 2.0_f64.sqrt() >= 0.0 && t - 2.0_f64.sqrt() < 1e-12,
            "{t}"
        );
        let (t, g) = locate(|t: f64| 1.0 - t, 0.0, 3.0, 1.0, -2.0, 1e-13);
        assert!(g <= 0.0 && (t - 1.0).abs() < 1e-12);
    }
}
