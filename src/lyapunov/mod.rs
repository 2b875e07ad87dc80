//! (under construction)

/// Errors of this module.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LyapunovError {
    /// Placeholder until the module lands.
    #[error("not available")]
    Unavailable,
}
