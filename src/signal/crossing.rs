//! Threshold crossings with linear interpolation and debounce (impact detection).

use super::{SignalError, validate_samples};
use crate::Real;
use crate::validate::{finite, non_negative};

pub use crate::event::Direction;

/// One located crossing.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Crossing<T> {
    /// The interpolated crossing time.
    pub t: T,
    /// The index `n` of the sample interval `[t_n, t_{n+1}]` containing the crossing.
    pub index: usize,
    /// [`Direction::Rising`] or [`Direction::Falling`] (never `Either`).
    pub direction: Direction,
}

/// Detects crossings of a level in sampled data, e.g. impacts as the upward crossings of a
/// level slightly below the stop (the paper's detector is
/// [`systems::paper::impact_detector`](crate::systems::paper::impact_detector)).
///
/// Deserialization (feature `serde`) applies the constructor's and the builders' checks.
///
/// # Formula
/// A rising crossing lies in the interval `[t_n, t_{n+1}]` when `x_n < L ≤ x_{n+1}`
/// (falling: `x_n > L ≥ x_{n+1}`); its time is the root of the linear interpolant,
/// $$ t_c = t_n + \frac{L - x_n}{x_{n+1} - x_n}\,(t_{n+1} - t_n), $$
/// which is exact for piecewise-linear signals and has error `O(h²·ẍ/ẋ)` otherwise.
///
/// # Debounce
/// Near a grazing contact noise makes the signal cross the level several times per impact.
/// Two rules, applied per direction, suppress those repeats:
/// - **hysteresis** `η ≥ 0`: after a rising crossing the detector is disarmed until a
///   sample lies strictly below `L − η`; only then can the next rising crossing count
///   (falling: re-armed strictly above `L + η`). At the start the rising detector is armed
///   if `x_0 < L`, the falling one if `x_0 > L` (a record starting inside the band can
///   therefore report its first crossing).
/// - **minimum separation** `Δ ≥ 0`: a crossing less than `Δ` after the previous
///   *reported* crossing of the same direction is dropped (it still disarms the detector).
///
/// With [`Direction::Either`] the two directions are detected independently, so the result
/// is exactly the time-ordered union of the `Rising` and `Falling` results.
///
/// # Examples
/// ```
/// use nonsmooth::signal::ThresholdCrossing;
/// let t = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
/// let x = [0.0, 2.0, 0.5, 1.5, -1.0, 1.5];
/// let level = ThresholdCrossing::new(1.0)?;
/// assert_eq!(level.times(&t, &x)?, vec![0.5, 2.5, 4.8]);
/// // With hysteresis 0.5 the dip to 0.5 (not strictly below 1 − 0.5) does not re-arm it.
/// assert_eq!(level.with_hysteresis(0.5)?.times(&t, &x)?, vec![0.5, 4.8]);
/// # Ok::<(), nonsmooth::signal::SignalError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ThresholdCrossing<T> {
    level: T,
    direction: Direction,
    hysteresis: T,
    min_separation: T,
}

crate::serde_check::deserialize_checked! {
    "ThresholdCrossing",
    ThresholdCrossing<T: Real> {
        level: T,
        direction: Direction,
        hysteresis: T,
        min_separation: T,
    },
    |raw| -> SignalError {
        ThresholdCrossing::new(raw.level)?
            .with_direction(raw.direction)
            .with_hysteresis(raw.hysteresis)?
            .with_min_separation(raw.min_separation)?
    }
}

impl<T: Real> ThresholdCrossing<T> {
    /// Rising crossings of `level`, no hysteresis, no minimum separation.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] if `level` is not finite.
    pub fn new(level: T) -> Result<Self, SignalError> {
        Ok(Self {
            level: finite("level", level)?,
            direction: Direction::Rising,
            hysteresis: T::zero(),
            min_separation: T::zero(),
        })
    }

    /// Sets the direction.
    #[must_use]
    pub fn with_direction(mut self, direction: Direction) -> Self {
        self.direction = direction;
        self
    }

    /// Sets the hysteresis band `η` (same units as the signal).
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `η` is finite and `≥ 0`.
    pub fn with_hysteresis(mut self, hysteresis: T) -> Result<Self, SignalError> {
        self.hysteresis = non_negative("hysteresis", hysteresis)?;
        Ok(self)
    }

    /// Sets the minimum time between two reported crossings of the same direction.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless the value is finite and `≥ 0`.
    pub fn with_min_separation(mut self, min_separation: T) -> Result<Self, SignalError> {
        self.min_separation = non_negative("min_separation", min_separation)?;
        Ok(self)
    }

    /// The level `L`.
    pub fn level(&self) -> T {
        self.level
    }

    /// The direction.
    pub fn direction(&self) -> Direction {
        self.direction
    }

    /// The hysteresis band `η`.
    pub fn hysteresis(&self) -> T {
        self.hysteresis
    }

    /// The minimum separation `Δ`.
    pub fn min_separation(&self) -> T {
        self.min_separation
    }

    /// The core scan on validated data; calls `emit` for each reported crossing in order.
    fn scan<F: FnMut(Crossing<T>)>(&self, t: &[T], x: &[T], mut emit: F) {
        let Some(&x_first) = x.first() else {
            return;
        };
        let level = self.level;
        let low = level - self.hysteresis;
        let high = level + self.hysteresis;
        let want_up = self.direction != Direction::Falling;
        let want_down = self.direction != Direction::Rising;
        let mut armed_up = x_first < level;
        let mut armed_down = x_first > level;
        let mut last_up: Option<T> = None;
        let mut last_down: Option<T> = None;
        for n in 0..x.len().saturating_sub(1) {
            let (x0, x1) = (x[n], x[n + 1]);
            if x0 < level && x1 >= level {
                if armed_up && want_up {
                    let tc = t[n] + (level - x0) / (x1 - x0) * (t[n + 1] - t[n]);
                    if last_up.is_none_or(|tl| tc - tl >= self.min_separation) {
                        emit(Crossing {
                            t: tc,
                            index: n,
                            direction: Direction::Rising,
                        });
                        last_up = Some(tc);
                    }
                }
                armed_up = false;
            } else if x0 > level && x1 <= level {
                if armed_down && want_down {
                    let tc = t[n] + (level - x0) / (x1 - x0) * (t[n + 1] - t[n]);
                    if last_down.is_none_or(|tl| tc - tl >= self.min_separation) {
                        emit(Crossing {
                            t: tc,
                            index: n,
                            direction: Direction::Falling,
                        });
                        last_down = Some(tc);
                    }
                }
                armed_down = false;
            }
            if x1 < low {
                armed_up = true;
            }
            if x1 > high {
                armed_down = true;
            }
        }
    }

    /// The crossings of `x(t)`, with interval index and direction, into `out` (cleared first).
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`], [`SignalError::NonIncreasingTime`] or
    /// [`SignalError::NonFinite`] (with the sample index) for invalid data; `out` is then
    /// left empty.
    pub fn detect_into(
        &self,
        t: &[T],
        x: &[T],
        out: &mut Vec<Crossing<T>>,
    ) -> Result<(), SignalError> {
        out.clear();
        validate_samples(t, x, "x", 0)?;
        self.scan(t, x, |c| out.push(c));
        Ok(())
    }

    /// The crossings of `x(t)` with interval index and direction.
    ///
    /// # Errors
    /// As [`detect_into`](Self::detect_into).
    pub fn detect(&self, t: &[T], x: &[T]) -> Result<Vec<Crossing<T>>, SignalError> {
        let mut out = Vec::new();
        self.detect_into(t, x, &mut out)?;
        Ok(out)
    }

    /// The crossing times of `x(t)` into `out` (cleared first).
    ///
    /// # Errors
    /// As [`detect_into`](Self::detect_into).
    pub fn times_into(&self, t: &[T], x: &[T], out: &mut Vec<T>) -> Result<(), SignalError> {
        out.clear();
        validate_samples(t, x, "x", 0)?;
        self.scan(t, x, |c| out.push(c.t));
        Ok(())
    }

    /// The crossing times of `x(t)`.
    ///
    /// # Errors
    /// As [`detect_into`](Self::detect_into).
    pub fn times(&self, t: &[T], x: &[T]) -> Result<Vec<T>, SignalError> {
        let mut out = Vec::new();
        self.times_into(t, x, &mut out)?;
        Ok(out)
    }
}

/// The intervals `T_j = t_{j+1} − t_j` between successive event times into `out` (cleared
/// first; empty for fewer than two times).
pub fn intervals_into<T: Real>(times: &[T], out: &mut Vec<T>) {
    out.clear();
    out.extend(times.windows(2).map(|w| w[1] - w[0]));
}

/// The intervals `T_j = t_{j+1} − t_j` between successive event times — the paper's
/// inter-impact sequence when `times` are impact times.
///
/// ```
/// assert_eq!(nonsmooth::signal::intervals(&[1.0, 1.5, 2.25]), vec![0.5, 0.75]);
/// ```
pub fn intervals<T: Real>(times: &[T]) -> Vec<T> {
    let mut out = Vec::with_capacity(times.len().saturating_sub(1));
    intervals_into(times, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn touching_from_below_counts_once() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let x = [0.0, 1.0, 1.0, 0.0];
        let c = ThresholdCrossing::new(1.0)
            .unwrap()
            .with_direction(Direction::Either);
        let found = c.detect(&t, &x).unwrap();
        assert_eq!(
            found,
            vec![Crossing {
                t: 1.0,
                index: 0,
                direction: Direction::Rising
            }]
        );
    }

    #[test]
    fn start_above_is_not_a_crossing() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let x = [2.0, 0.0, 2.0, 2.0];
        let c = ThresholdCrossing::new(1.0).unwrap();
        assert_eq!(c.times(&t, &x).unwrap(), vec![1.5]);
        let f = c.with_direction(Direction::Falling);
        assert_eq!(f.times(&t, &x).unwrap(), vec![0.5]);
    }

    #[test]
    fn min_separation_drops_close_repeats() {
        // Rising crossings at 0.5, 2.5, 4.5, 6.5; min separation 2.5 keeps 0.5, 4.5.
        let t: Vec<f64> = (0..8).map(|i| i as f64).collect();
        let x = [0.0, 2.0, 0.0, 2.0, 0.0, 2.0, 0.0, 2.0];
        let c = ThresholdCrossing::new(1.0)
            .unwrap()
            .with_min_separation(2.5)
            .unwrap();
        assert_eq!(c.times(&t, &x).unwrap(), vec![0.5, 4.5]);
    }

    #[test]
    fn level_and_validation() {
        let c = ThresholdCrossing::new(-2.01e-3_f64).unwrap();
        assert_eq!(c.level(), -2.01e-3);
        assert!(ThresholdCrossing::new(f64::NAN).is_err());
        assert!(c.with_hysteresis(-1.0).is_err());
        assert!(c.with_min_separation(f64::INFINITY).is_err());
        let mut out = vec![1.0];
        assert!(c.times_into(&[0.0, 0.0], &[0.0, 1.0], &mut out).is_err());
        assert!(out.is_empty());
        assert!(c.times(&[] as &[f64], &[]).unwrap().is_empty());
    }

    #[test]
    fn f32_crossing() {
        let c = ThresholdCrossing::new(0.25_f32).unwrap();
        assert_eq!(c.times(&[0.0, 1.0], &[0.0, 1.0]).unwrap(), vec![0.25]);
    }
}
