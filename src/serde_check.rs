//! Deserialization that applies the constructors' checks (feature `serde`).
//!
//! A type whose constructors validate derives only `Serialize`; its `Deserialize` comes from
//! [`deserialize_checked!`]: the fields are read exactly as the derive would read them (same
//! struct name, same field names, so the format is unchanged), assembled into a raw value,
//! and that value is rebuilt through the type's constructors. An invalid field is a serde
//! error whose message contains the constructor's, e.g.
//! ``invalid parameter `k` = -1: must be finite and >= 0``. Derived fields (cached
//! quantities such as `1/m`) are recomputed by the rebuild, never trusted.
//!
//! The fields are listed once more at the invocation; the raw value is built with a struct
//! literal, so a list that misses, adds or mistypes a field does not compile.

/// `deserialize_checked! { "Name", Name<T: Bound, U> { field: Type, … }, |raw| -> Error { … } }`
/// implements `serde::Deserialize` for `Name` (feature `serde`; without it, nothing).
///
/// The block receives `raw: Name<…>` (the fields as read, unchecked) and evaluates to the
/// validated value; `?` converts into `Error`, whose `Display` becomes the serde error. The
/// string literal is the struct's name as the derive would report it to the format. Bounds
/// on the generic parameters are those the block needs; every parameter also gets
/// `Deserialize<'de>`.
macro_rules! deserialize_checked {
    (
        $name:literal,
        $ty:ident $(< $($g:ident $(: $bound:path)?),+ >)?
        { $($field:ident : $fty:ty),+ $(,)? },
        |$raw:ident| -> $err:ty $body:block
    ) => {
        #[cfg(feature = "serde")]
        const _: () = {
            #[derive(::serde::Deserialize)]
            #[serde(rename = $name)]
            struct Fields $(< $($g),+ >)? {
                $($field: $fty),+
            }

            impl<'de $(, $($g),+)?> ::serde::Deserialize<'de> for $ty $(< $($g),+ >)?
            where
                $($($g: ::serde::Deserialize<'de> $(+ $bound)?,)+)?
            {
                fn deserialize<D>(deserializer: D) -> ::core::result::Result<Self, D::Error>
                where
                    D: ::serde::Deserializer<'de>,
                {
                    let Fields { $($field),+ }: Fields $(< $($g),+ >)? =
                        ::serde::Deserialize::deserialize(deserializer)?;
                    let $raw = $ty { $($field),+ };
                    let check = || -> ::core::result::Result<Self, $err> { Ok($body) };
                    check().map_err(::serde::de::Error::custom)
                }
            }
        };
    };
}

pub(crate) use deserialize_checked;
