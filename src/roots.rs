//! Bracketing scalar root finding (Brent–Dekker), used for static equilibria, event
//! location on dense output and grazing searches.

use thiserror::Error;

use crate::Real;
use crate::scalar::{lit, to_f64};

/// Why a bracketing root search failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RootError {
    /// `f(a)` and `f(b)` have the same sign.
    #[error("no sign change on [{a}, {b}]: f(a) = {fa}, f(b) = {fb}")]
    NoBracket {
        /// Left end.
        a: f64,
        /// Right end.
        b: f64,
        /// `f(a)`.
        fa: f64,
        /// `f(b)`.
        fb: f64,
    },
    /// The function returned NaN or ∞.
    #[error("function value is not finite at x = {x}")]
    NotFinite {
        /// Where.
        x: f64,
    },
    /// The iteration cap was reached.
    #[error("root search did not converge in {iterations} iterations (bracket width {width})")]
    NotConverged {
        /// Iterations used.
        iterations: usize,
        /// Final bracket width.
        width: f64,
    },
}

/// Finds a root of `f` in `[a, b]` with Brent's method, to an absolute tolerance `xtol` on
/// the abscissa (plus 4·ε_mach·|x|).
///
/// `fa = f(a)` and `fb = f(b)` are passed in so that callers which already know them do not
/// pay for them again.
///
/// # Errors
/// [`RootError::NoBracket`] if `fa·fb > 0`, [`RootError::NotFinite`] if `f` returns NaN/∞,
/// [`RootError::NotConverged`] after `max_iter` iterations.
pub fn brent<T: Real, F: FnMut(T) -> T>(
    mut f: F,
    a: T,
    b: T,
    fa: T,
    fb: T,
    xtol: T,
    max_iter: usize,
) -> Result<T, RootError> {
    let (mut a, mut b, mut fa, mut fb) = (a, b, fa, fb);
    if !fa.is_finite() {
        return Err(RootError::NotFinite { x: to_f64(a) });
    }
    if !fb.is_finite() {
        return Err(RootError::NotFinite { x: to_f64(b) });
    }
    if fa == T::zero() {
        return Ok(a);
    }
    if fb == T::zero() {
        return Ok(b);
    }
    if (fa > T::zero()) == (fb > T::zero()) {
        return Err(RootError::NoBracket {
            a: to_f64(a),
            b: to_f64(b),
            fa: to_f64(fa),
            fb: to_f64(fb),
        });
    }
    let two = lit::<T>(2.0);
    let half = lit::<T>(0.5);
    let eps = T::default_epsilon();
    let mut c = a;
    let mut fc = fa;
    let mut d = b - a;
    let mut e = d;
    for _ in 0..max_iter {
        if (fb > T::zero()) == (fc > T::zero()) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = two * eps * b.abs() + half * xtol;
        let m = half * (c - b);
        if m.abs() <= tol || fb == T::zero() {
            return Ok(b);
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = two * m * s;
                q = T::one() - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (two * m * qq * (qq - r) - (b - a) * (r - T::one()));
                q = (qq - T::one()) * (r - T::one()) * (s - T::one());
            }
            if p > T::zero() {
                q = -q;
            } else {
                p = -p;
            }
            if two * p < (lit::<T>(3.0) * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol {
            d
        } else if m > T::zero() {
            tol
        } else {
            -tol
        };
        fb = f(b);
        if !fb.is_finite() {
            return Err(RootError::NotFinite { x: to_f64(b) });
        }
    }
    Err(RootError::NotConverged {
        iterations: max_iter,
        width: to_f64((c - b).abs()),
    })
}

/// Maximizes a unimodal `f` on `[a, b]` by golden-section search to an absolute tolerance
/// `xtol` (floored at the floating-point resolution of the interval, and capped at 300
/// iterations, so it always terminates); returns `(x*, f(x*))`.
pub fn golden_max<T: Real, F: FnMut(T) -> T>(mut f: F, a: T, b: T, xtol: T) -> (T, T) {
    let g = lit::<T>(0.618_033_988_749_894_9);
    let (mut a, mut b) = (a.min(b), a.max(b));
    let floor = lit::<T>(4.0) * T::default_epsilon() * a.abs().max(b.abs());
    let xtol = xtol.max(floor);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let mut fc = f(c);
    let mut fd = f(d);
    let mut iter = 0;
    while (b - a) > xtol && iter < 300 {
        iter += 1;
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    let x = (a + b) * lit(0.5);
    (x, f(x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_roots() {
        let r = brent(|x: f64| x * x - 2.0, 0.0, 2.0, -2.0, 2.0, 1e-14, 100).unwrap();
        assert!((r - 2.0_f64.sqrt()).abs() < 1e-13);
        let r = brent(
            |x: f64| x.cos() - x,
            0.0,
            1.0,
            1.0,
            1.0_f64.cos() - 1.0,
            1e-15,
            100,
        )
        .unwrap();
        assert!((r.cos() - r).abs() < 1e-14);
        let r = brent(|x: f32| x - 0.25, 0.0, 1.0, -0.25, 0.75, 1e-7, 100).unwrap();
        assert!((r - 0.25).abs() < 1e-6);
    }

    #[test]
    fn reports_failures() {
        assert!(matches!(
            brent(|x: f64| x * x + 1.0, -1.0, 1.0, 2.0, 2.0, 1e-12, 50),
            Err(RootError::NoBracket { .. })
        ));
        assert!(matches!(
            brent(
                |x: f64| if x > 0.3 { f64::NAN } else { x - 0.5 },
                0.0,
                1.0,
                -0.5,
                0.5,
                1e-12,
                50
            ),
            Err(RootError::NotFinite { .. })
        ));
    }

    #[test]
    fn golden_section_terminates_below_resolution() {
        let (x, _) = golden_max(|x: f64| -(x - 5.0).abs(), 5.0, 5.0 + 1e-15, 1e-30);
        assert!((x - 5.0).abs() < 1e-14);
        let (x, _) = golden_max(|x: f64| x, 3.0, 3.0, 1e-30);
        assert_eq!(x, 3.0);
    }

    #[test]
    fn golden_section_maximum() {
        let (x, fx) = golden_max(|x: f64| -(x - 0.62) * (x - 0.62) + 1.0, 0.0, 2.0, 1e-9);
        assert!((x - 0.62).abs() < 1e-8);
        assert!((fx - 1.0).abs() < 1e-12);
    }
}
