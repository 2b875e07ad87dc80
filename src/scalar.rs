//! The scalar type of the crate.
//!
//! Every generic item is written for `T: Real`, a blanket alias of
//! [`nalgebra::RealField`]` + Copy`, so that `f64` and `f32` both work. `num_traits::Float`
//! is deliberately not part of the bound (it makes method calls such as `x.sqrt()`
//! ambiguous); the few helpers it would have provided live here.

/// The scalar bound used throughout the crate: `f64` and `f32` implement it.
///
/// It is blanket-implemented for every [`nalgebra::RealField`]` + Copy`, so it never has to
/// be implemented by hand.
pub trait Real: nalgebra::RealField + Copy {}

impl<T: nalgebra::RealField + Copy> Real for T {}

/// Converts an `f64` literal into `T` (exact for `f64`, rounded for `f32`).
#[inline(always)]
pub fn lit<T: Real>(x: f64) -> T {
    nalgebra::convert(x)
}

/// Converts `T` into `f64` for diagnostics and output (NaN if not representable).
#[inline]
pub fn to_f64<T: Real>(x: T) -> f64 {
    x.to_subset().unwrap_or(f64::NAN)
}

/// Machine epsilon of `T`.
#[inline(always)]
pub fn epsilon<T: Real>() -> T {
    T::default_epsilon()
}

/// A power exponent with fast paths for the common values 1, 3/2 and 2.
///
/// `d^{3/2}` is evaluated as `d·sqrt(d)`, which is several times cheaper than `powf` and
/// exact to rounding; other exponents use `exp(p·ln d)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Exponent<T> {
    /// `d^1`.
    One,
    /// `d^{3/2} = d·√d` (the Hertz exponent).
    ThreeHalves,
    /// `d^2`.
    Two,
    /// Any other positive exponent.
    General(T),
}

impl<T: Real> Exponent<T> {
    /// Classifies `p`, picking a fast path when `p` is exactly 1, 3/2 or 2.
    pub fn new(p: T) -> Self {
        if p == T::one() {
            Exponent::One
        } else if p == lit(1.5) {
            Exponent::ThreeHalves
        } else if p == lit(2.0) {
            Exponent::Two
        } else {
            Exponent::General(p)
        }
    }

    /// The exponent's value.
    pub fn value(&self) -> T {
        match *self {
            Exponent::One => T::one(),
            Exponent::ThreeHalves => lit(1.5),
            Exponent::Two => lit(2.0),
            Exponent::General(p) => p,
        }
    }

    /// `d^p` for `d ≥ 0` (returns 0 for `d ≤ 0`).
    #[inline(always)]
    pub fn pow(&self, d: T) -> T {
        if d <= T::zero() {
            return T::zero();
        }
        match *self {
            Exponent::One => d,
            Exponent::ThreeHalves => d * d.sqrt(),
            Exponent::Two => d * d,
            Exponent::General(p) => (p * d.ln()).exp(),
        }
    }

    /// `(d^p, p·d^{p−1})` for `d > 0`; `(0, 0)` for `d ≤ 0` (the one-sided derivative at
    /// `d = 0` is 0 for `p > 1` and is reported as 0 for `p ≤ 1` too).
    #[inline(always)]
    pub fn pow_and_derivative(&self, d: T) -> (T, T) {
        if d <= T::zero() {
            return (T::zero(), T::zero());
        }
        match *self {
            Exponent::One => (d, T::one()),
            Exponent::ThreeHalves => {
                let s = d.sqrt();
                (d * s, lit::<T>(1.5) * s)
            }
            Exponent::Two => (d * d, lit::<T>(2.0) * d),
            Exponent::General(p) => {
                let v = (p * d.ln()).exp();
                (v, p * v / d)
            }
        }
    }
}

/// NaN of type `T`.
#[inline(always)]
pub fn nan<T: Real>() -> T {
    lit(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponent_fast_paths_match_powf() {
        for &d in &[1e-9_f64, 3.7e-6, 0.25, 1.0, 7.5] {
            for &p in &[1.0, 1.5, 2.0, 0.18667, 2.7] {
                let e = Exponent::new(p);
                let (v, dv) = e.pow_and_derivative(d);
                assert!((v - d.powf(p)).abs() <= 1e-14 * d.powf(p));
                assert!((dv - p * d.powf(p - 1.0)).abs() <= 1e-13 * p * d.powf(p - 1.0));
                assert_eq!(e.pow(d), v);
            }
        }
        assert_eq!(Exponent::new(1.5_f64).pow(-1.0), 0.0);
    }
}
