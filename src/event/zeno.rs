//! The chatter/Zeno guard and the history of recent events it keeps.

use crate::Real;
use crate::scalar::lit;
use crate::validate::ParameterError;

/// The chatter/Zeno guard.
///
/// # Rule (default, [`ZenoGuard::accumulation`])
/// The guard trips when `count` consecutive inter-event intervals each shrink by at least
/// the factor `ratio` (`Δ_{k+1} ≤ ratio·Δ_k`, a geometric accumulation of events) **and**
/// the last interval is below the time floor `floor + 64·ε_mach·|t|`. Both conditions are
/// about the events themselves, never about the length of the run:
/// - an orbit whose events are at least `floor` apart never trips, however long the run;
/// - a periodic orbit with at most `count` events per period never trips at all (its
///   intervals repeat, so no run of `count` strictly shrinking intervals exists);
/// - a true accumulation (a ball coming to rest by a geometric sequence of bounces) trips
///   after the same number of events whatever `t_end` is.
///
/// The default is `count = 16`, `ratio = 0.999`, `floor = 1e-9 s`. A fixed window
/// ([`ZenoGuard::window`]: more than `max_events` events within `window`) is available for
/// callers who know their time scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZenoGuard<T> {
    rule: ZenoRule<T>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum ZenoRule<T> {
    Accumulation { count: usize, ratio: T, floor: T },
    Window { max_events: usize, window: T },
}

impl<T: Real> Default for ZenoGuard<T> {
    fn default() -> Self {
        Self {
            rule: ZenoRule::Accumulation {
                count: 16,
                ratio: lit(0.999),
                floor: lit(1e-9),
            },
        }
    }
}

impl<T: Real> ZenoGuard<T> {
    /// The largest `max_events` supported by [`window`](Self::window) (the guard keeps a
    /// fixed ring buffer).
    pub const CAPACITY: usize = 256;

    /// Trips after `count` consecutive intervals each at most `ratio` times the previous,
    /// the last below `floor` seconds (plus `64·ε_mach·|t|`).
    ///
    /// # Errors
    /// [`ParameterError`] unless `count ≥ 2`, `0 < ratio < 1` and `floor` is finite and > 0.
    pub fn accumulation(count: usize, ratio: T, floor: T) -> Result<Self, ParameterError> {
        if count < 2 {
            return Err(ParameterError::new("count", count as f64, ">= 2"));
        }
        if !(ratio > T::zero() && ratio < T::one()) {
            return Err(ParameterError::new(
                "ratio",
                crate::scalar::to_f64(ratio),
                "in (0, 1)",
            ));
        }
        Ok(Self {
            rule: ZenoRule::Accumulation {
                count,
                ratio,
                floor: crate::validate::positive("floor", floor)?,
            },
        })
    }

    /// Trips when more than `max_events` events fall within any time window of length
    /// `window`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `1 ≤ max_events ≤ 256` and `window` is finite and > 0.
    pub fn window(max_events: usize, window: T) -> Result<Self, ParameterError> {
        if max_events == 0 || max_events > Self::CAPACITY {
            return Err(ParameterError::new(
                "max_events",
                max_events as f64,
                "in 1..=256",
            ));
        }
        Ok(Self {
            rule: ZenoRule::Window {
                max_events,
                window: crate::validate::positive("window", window)?,
            },
        })
    }

    /// Same as [`window`](Self::window) (the first-stage name).
    ///
    /// # Errors
    /// As [`window`](Self::window).
    pub fn new(max_events: usize, window: T) -> Result<Self, ParameterError> {
        Self::window(max_events, window)
    }
}

/// What the guard remembers of recent events.
#[derive(Debug, Clone)]
pub(crate) struct EventHistory<T> {
    times: [T; 256],
    next: usize,
    len: usize,
    last_interval: Option<T>,
    shrinking: usize,
}

impl<T: Real> EventHistory<T> {
    pub(crate) fn new() -> Self {
        Self {
            times: [T::zero(); 256],
            next: 0,
            len: 0,
            last_interval: None,
            shrinking: 0,
        }
    }

    pub(crate) fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
        self.last_interval = None;
        self.shrinking = 0;
    }

    /// Records `t`; returns `(count, last interval)` if the guard trips.
    pub(crate) fn push(&mut self, t: T, guard: &ZenoGuard<T>) -> Option<(usize, T)> {
        let prev = if self.len > 0 {
            Some(self.times[(self.next + 255) % 256])
        } else {
            None
        };
        self.times[self.next] = t;
        self.next = (self.next + 1) % 256;
        self.len = (self.len + 1).min(256);
        let interval = prev.map(|p| t - p);
        match guard.rule {
            ZenoRule::Accumulation {
                count,
                ratio,
                floor,
            } => {
                let d = interval?;
                if let Some(last) = self.last_interval {
                    if d <= ratio * last {
                        self.shrinking += 1;
                    } else {
                        self.shrinking = 0;
                    }
                }
                self.last_interval = Some(d);
                let floor_t = floor + lit::<T>(64.0) * T::default_epsilon() * t.abs();
                (self.shrinking >= count && d <= floor_t).then_some((self.shrinking, d))
            }
            ZenoRule::Window { max_events, window } => {
                if self.len > max_events {
                    // The (max_events+1)-th most recent event.
                    let idx = (self.next + 256 - 1 - max_events) % 256;
                    if t - self.times[idx] <= window {
                        return Some((max_events + 1, interval.unwrap_or(T::zero())));
                    }
                }
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeno_guard_counts_in_window() {
        let g = ZenoGuard::window(3, 1.0).unwrap();
        let mut h = EventHistory::new();
        assert!(h.push(0.0, &g).is_none());
        assert!(h.push(0.5, &g).is_none());
        assert!(h.push(2.0, &g).is_none());
        assert!(h.push(2.1, &g).is_none());
        assert!(h.push(2.2, &g).is_none());
        assert_eq!(h.push(2.3, &g).map(|c| c.0), Some(4));
        assert!(ZenoGuard::new(0, 1.0).is_err());
        assert!(ZenoGuard::new(3, 0.0).is_err());
    }

    #[test]
    fn accumulation_guard_trips_on_geometric_sequences_only() {
        let g = ZenoGuard::<f64>::default();
        // A geometric sequence of intervals 0.5^k from 0.1 s: trips once 16 consecutive
        // intervals have shrunk and the last is below 1e-9 s.
        let mut h = EventHistory::new();
        let mut t = 0.0;
        let mut tripped = None;
        for k in 0..200 {
            t += 0.1 * 0.5f64.powi(k);
            if let Some(c) = h.push(t, &g) {
                tripped = Some((k, c));
                break;
            }
        }
        let (k, (count, d)) = tripped.expect("geometric accumulation must trip");
        assert!(d <= 1e-9 && count >= 16, "{k} {count} {d}");
        assert_eq!(k, 27, "first k with 0.1·0.5^k ≤ 1e-9");
        // A periodic pattern of 16 distinct intervals per period, some tiny, repeated 10⁵
        // times: never trips, whatever the run length.
        let mut h = EventHistory::new();
        let pattern: Vec<f64> = (0..16).map(|k| 1e-12 * 2f64.powi(16 - k)).collect();
        let mut t = 0.0;
        for _ in 0..100_000 {
            for &d in &pattern {
                t += d + 1.0e-3 * (d == pattern[15]) as i32 as f64;
                assert!(h.push(t, &g).is_none());
            }
        }
        assert!(ZenoGuard::<f64>::accumulation(1, 0.5, 1e-9).is_err());
        assert!(ZenoGuard::<f64>::accumulation(4, 1.0, 1e-9).is_err());
        assert!(ZenoGuard::<f64>::accumulation(4, 0.5, 0.0).is_err());
    }
}
