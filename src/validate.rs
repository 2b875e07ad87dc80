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

/// Serde for a type whose constructor validates: `Serialize` is the derived code, and
/// `Deserialize` is the derived code followed by `$check`, an expression of the raw value
/// `$v` that rebuilds it through the constructors (so deserialization applies exactly the
/// constructor's checks) and returns `Result<Self, impl Display>`.
///
/// The type derives `Serialize, Deserialize` with `#[serde(remote = "Self")]`, which makes
/// the derive generate inherent `serialize`/`deserialize` functions instead of the trait
/// impls; this macro writes the trait impls around them.
#[cfg(feature = "serde")]
macro_rules! serde_validated {
    ([$($gen:tt)*] $ty:ty, [$($ser:tt)*], [$($de:tt)*], |$v:ident| $check:expr) => {
        impl<$($gen)*> serde::Serialize for $ty
        where
            $($ser)*
        {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                <$ty>::serialize(self, serializer)
            }
        }

        impl<'de, $($gen)*> serde::Deserialize<'de> for $ty
        where
            $($de)*
        {
            fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                let $v = <$ty>::deserialize(deserializer)?;
                $check.map_err(serde::de::Error::custom)
            }
        }
    };
}

#[cfg(feature = "serde")]
pub(crate) use serde_validated;
