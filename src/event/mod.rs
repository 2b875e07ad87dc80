//! (under construction)

/// Errors of this module.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EventError {
    /// Placeholder until the module lands.
    #[error("not available")]
    Unavailable,
}
