//! Validators shared by the constructors: each returns the value when it satisfies the
//! requirement and a [`ParameterError`] naming the parameter otherwise. NaN fails every
//! check (the comparisons are written so that NaN is rejected).

use crate::error::ParameterError;

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
