//! Parameter validation: the [`ParameterError`] every constructor returns (re-exported as
//! `nonsmooth::ParameterError` and `nonsmooth::error::ParameterError`) and the validators
//! shared by the constructors: each returns the value when it satisfies the requirement and a
//! [`ParameterError`] naming the parameter otherwise. NaN fails every check (the comparisons
//! are written so that NaN is rejected). A leaf: imports nothing from the crate but the scalar
//! type.

use thiserror::Error;

/// A parameter that failed validation in a constructor.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("invalid parameter `{name}` = {}: must be {requirement}", Compact(*value))]
pub struct ParameterError {
    /// The parameter's name as documented on the constructor.
    pub name: &'static str,
    /// The rejected value (as `f64`).
    pub value: f64,
    /// What the value must satisfy, e.g. `"finite and > 0"`.
    pub requirement: &'static str,
}

/// A value printed in full when moderate and in scientific notation when very large or small
/// (`1e-300`, not three hundred zeros).
struct Compact(f64);

impl std::fmt::Display for Compact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a != 0.0 && a.is_finite() && !(1e-4..1e7).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

impl ParameterError {
    /// Builds the error.
    pub fn new(name: &'static str, value: f64, requirement: &'static str) -> Self {
        Self {
            name,
            value,
            requirement,
        }
    }
}

/// Validates that `value` is finite and strictly positive.
pub(crate) fn positive<T: crate::Real>(
    name: &'static str,
    value: T,
) -> std::result::Result<T, ParameterError> {
    let v = crate::scalar::to_f64(value);
    if value.is_finite() && value > T::zero() {
        Ok(value)
    } else {
        Err(ParameterError::new(name, v, "finite and > 0"))
    }
}

/// Validates that `value` is finite, strictly positive and has a finite inverse (a mass or
/// an inertia that is divided by: a subnormal value would make `1/value` infinite).
pub(crate) fn invertible<T: crate::Real>(
    name: &'static str,
    value: T,
) -> std::result::Result<T, ParameterError> {
    let v = crate::scalar::to_f64(value);
    if value.is_finite() && value > T::zero() && (T::one() / value).is_finite() {
        Ok(value)
    } else {
        Err(ParameterError::new(
            name,
            v,
            "finite and > 0 with a finite inverse (>= 5.6e-309 for f64)",
        ))
    }
}

/// Validates that `value` is finite and non-negative.
pub(crate) fn non_negative<T: crate::Real>(
    name: &'static str,
    value: T,
) -> std::result::Result<T, ParameterError> {
    let v = crate::scalar::to_f64(value);
    if value.is_finite() && value >= T::zero() {
        Ok(value)
    } else {
        Err(ParameterError::new(name, v, "finite and >= 0"))
    }
}

/// Validates that `value` is finite.
pub(crate) fn finite<T: crate::Real>(
    name: &'static str,
    value: T,
) -> std::result::Result<T, ParameterError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ParameterError::new(
            name,
            crate::scalar::to_f64(value),
            "finite",
        ))
    }
}

/// Validates that `value²` is a normal number (no underflow to 0 or a subnormal), for
/// regularization scales that enter as `x² + value²`.
pub(crate) fn normal_square<T: crate::Real>(
    name: &'static str,
    value: T,
) -> std::result::Result<T, ParameterError> {
    let sq = crate::scalar::to_f64(value * value);
    if sq.is_normal() {
        Ok(value)
    } else {
        Err(ParameterError::new(
            name,
            crate::scalar::to_f64(value),
            "with a square that does not underflow (>= 1.5e-154 for f64)",
        ))
    }
}
