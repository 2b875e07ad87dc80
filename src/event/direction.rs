//! The direction of a zero crossing.

/// The direction of a zero crossing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Direction {
    /// `g` goes from negative to positive.
    Rising,
    /// `g` goes from positive to negative.
    Falling,
    /// Either.
    Either,
}

impl Direction {
    /// Whether a crossing towards `sign` (+1 rising, −1 falling) is wanted.
    #[inline(always)]
    pub fn accepts(self, rising: bool) -> bool {
        match self {
            Direction::Rising => rising,
            Direction::Falling => !rising,
            Direction::Either => true,
        }
    }
}
