//! Poincaré sampling from a measured rotor phase.

use super::{Location, SignalError, validate_finite, validate_samples};
use crate::Real;
use crate::scalar::{lit, to_f64};
use crate::validate::finite;

/// How a measured phase is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum PhaseInput {
    /// Wrapped into one turn (e.g. `[0, 2π)` or `(−π, π]`), as an encoder reports it; it is
    /// unwrapped on the fly. Requires less than half a turn between samples. Unwrapping an
    /// already unwrapped phase is harmless as long as that holds.
    #[default]
    Wrapped,
    /// Already continuous (unwrapped); used as is, any increment per sample allowed.
    Unwrapped,
}

/// One point of the stroboscopic (Poincaré) section `φ = 2πi + φ_0`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PoincarePoint<T> {
    /// The interpolated time at which the phase passes the level.
    pub t: T,
    /// The position interpolated at that time.
    pub x: T,
    /// The level's turn number `i` (the level is `2πi + φ_0` on the unwrapped phase).
    pub i: i64,
}

/// Samples a signal where the (unwrapped) forcing phase passes `2πi + φ_0`, `i ∈ ℤ`: the
/// paper's section `t = 2πi/ω` generalized to a measured or ramped phase.
///
/// Deserialization (feature `serde`) applies the check of
/// [`with_offset`](Self::with_offset).
///
/// # Formula
/// Wrapped input is unwrapped by adding the multiple of `2π` that keeps every increment in
/// `[−π, π]`: `φ̃_n = φ_n + 2πk_n`, `k_n = k_{n−1} − round((φ_n + 2πk_{n−1} − φ̃_{n−1})/2π)`
/// (the offsets are exact multiples of `2π`, never accumulated sums). A level
/// `L_i = 2πi + φ_0` is passed in `[t_n, t_{n+1}]` when `φ̃_n < L_i ≤ φ̃_{n+1}`; with
/// `s = (L_i − φ̃_n)/(φ̃_{n+1} − φ̃_n)` the point is
/// $$ t_i = t_n + s\,(t_{n+1} - t_n), \qquad x_i = x_n + s\,(x_{n+1} - x_n). $$
/// Each level is reported once, the first time the phase reaches it; levels at or below the
/// first sample's phase are not reported, and intervals where the phase decreases (encoder
/// jitter) report nothing until the phase exceeds its previous maximum.
///
/// # Examples
/// ```
/// use nonsmooth::signal::PhaseSection;
/// use std::f64::consts::PI;
/// // A rotor at 10 rad/s sampled at 1 kHz, the encoder phase wrapped into [0, 2π).
/// let t: Vec<f64> = (0..2000).map(|n| n as f64 * 1e-3).collect();
/// let phase: Vec<f64> = t.iter().map(|&t| (10.0 * t).rem_euclid(2.0 * PI)).collect();
/// let x: Vec<f64> = t.iter().map(|&t| t).collect();
/// let points = PhaseSection::new().sample(&t, &phase, &x)?;
/// assert_eq!(points.len(), 3); // 2 s · 10 rad/s = 20 rad: levels 2π, 4π, 6π
/// for p in &points {
///     assert!((p.t - 2.0 * PI * p.i as f64 / 10.0).abs() < 1e-12);
/// }
/// # Ok::<(), nonsmooth::signal::SignalError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PhaseSection<T> {
    offset: T,
    input: PhaseInput,
}

crate::serde_check::deserialize_checked! {
    "PhaseSection", PhaseSection<T: Real> { offset: T, input: PhaseInput },
    |raw| -> SignalError { PhaseSection::new().with_offset(raw.offset)?.with_input(raw.input) }
}

impl<T: Real> Default for PhaseSection<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> PhaseSection<T> {
    /// The section `φ = 2πi` for a wrapped phase.
    pub fn new() -> Self {
        Self {
            offset: T::zero(),
            input: PhaseInput::Wrapped,
        }
    }

    /// Sets the section's phase offset `φ_0` (radians).
    ///
    /// # Errors
    /// [`SignalError::Parameter`] if `offset` is not finite or `|offset| > 2π·2⁴⁰` (beyond
    /// that, levels `2π` apart are not resolved in floating point).
    pub fn with_offset(mut self, offset: T) -> Result<Self, SignalError> {
        self.offset = resolvable("offset", finite("offset", offset)?)?;
        Ok(self)
    }

    /// Sets how the phase is given.
    #[must_use]
    pub fn with_input(mut self, input: PhaseInput) -> Self {
        self.input = input;
        self
    }

    /// The offset `φ_0`.
    pub fn offset(&self) -> T {
        self.offset
    }

    /// How the phase is given.
    pub fn input(&self) -> PhaseInput {
        self.input
    }

    /// The section points of `x(t)` with phase `phase(t)` into `out` (cleared first).
    /// Allocates nothing beyond `out`'s growth.
    ///
    /// # Errors
    /// [`SignalError::LengthMismatch`], [`SignalError::NonIncreasingTime`] or
    /// [`SignalError::NonFinite`] (with the sample index) for invalid data;
    /// [`SignalError::Parameter`] for an (unwrapped) phase beyond `2π·2⁴⁰`; `out` is then
    /// left empty.
    pub fn sample_into(
        &self,
        t: &[T],
        phase: &[T],
        x: &[T],
        out: &mut Vec<PoincarePoint<T>>,
    ) -> Result<(), SignalError> {
        out.clear();
        validate_samples(t, phase, "phase", 0)?;
        if x.len() != t.len() {
            return Err(SignalError::LengthMismatch {
                what: "x",
                expected: t.len(),
                found: x.len(),
            });
        }
        validate_finite(x, "x")?;
        let Some(&phi0) = phase.first() else {
            return Ok(());
        };
        resolvable("phase", phi0)?;
        let two_pi = T::two_pi();
        let level = |i: i64| two_pi * lit::<T>(i as f64) + self.offset;
        // The first level strictly above the initial phase.
        let mut next = ((phi0 - self.offset) / two_pi).floor();
        let mut next_i = to_f64(next) as i64 + 1;
        next = level(next_i);
        while next <= phi0 {
            next_i += 1;
            next = level(next_i);
        }
        while level(next_i - 1) > phi0 {
            next_i -= 1;
            next = level(next_i);
        }
        let mut unwrap = Unwrapper::new(phi0, self.input);
        let mut p0 = phi0;
        for n in 0..t.len() - 1 {
            let p1 = match resolvable("phase", unwrap.next(phase[n + 1])) {
                Ok(p) => p,
                Err(e) => {
                    out.clear();
                    return Err(e);
                }
            };
            while p1 >= next {
                // p0 < next ≤ p1 by the invariant `next > max φ so far`.
                let s = (next - p0) / (p1 - p0);
                out.push(PoincarePoint {
                    t: t[n] + s * (t[n + 1] - t[n]),
                    x: x[n] + s * (x[n + 1] - x[n]),
                    i: next_i,
                });
                next_i += 1;
                next = level(next_i);
            }
            p0 = p1;
        }
        Ok(())
    }

    /// The section points of `x(t)` with phase `phase(t)`.
    ///
    /// # Errors
    /// As [`sample_into`](Self::sample_into).
    pub fn sample(
        &self,
        t: &[T],
        phase: &[T],
        x: &[T],
    ) -> Result<Vec<PoincarePoint<T>>, SignalError> {
        let mut out = Vec::new();
        self.sample_into(t, phase, x, &mut out)?;
        Ok(out)
    }
}

/// The largest phase magnitude (and offset) a section takes, `2π·2⁴⁰`: the section levels
/// `2πi + φ₀` stay resolved (`ulp(φ) ≤ 2⁻¹⁰`) and their indices fit an `i64` exactly.
const MAX_PHASE: f64 = std::f64::consts::TAU * 1_099_511_627_776.0;

/// `value` if `|value| ≤ MAX_PHASE`.
fn resolvable<T: Real>(name: &'static str, value: T) -> Result<T, SignalError> {
    if value.abs() <= lit::<T>(MAX_PHASE) {
        Ok(value)
    } else {
        Err(crate::ParameterError::new(
            name,
            to_f64(value),
            "|phase| <= 2π·2^40 (levels 2π apart must be resolvable)",
        )
        .into())
    }
}

/// Streaming unwrapper: adds exact multiples of 2π.
struct Unwrapper<T> {
    prev: T,
    turns: T,
    wrapped: bool,
}

impl<T: Real> Unwrapper<T> {
    fn new(first: T, input: PhaseInput) -> Self {
        Self {
            prev: first,
            turns: T::zero(),
            wrapped: input == PhaseInput::Wrapped,
        }
    }

    #[inline]
    fn next(&mut self, raw: T) -> T {
        if !self.wrapped {
            return raw;
        }
        let two_pi = T::two_pi();
        let d = raw + two_pi * self.turns - self.prev;
        self.turns -= (d / two_pi).round();
        let value = raw + two_pi * self.turns;
        self.prev = value;
        value
    }
}

/// Unwraps a phase in place: adds to each sample the multiple of `2π` that keeps every
/// increment within `[−π, π]` (the first sample is unchanged).
///
/// # Errors
/// [`SignalError::NonFinite`] with the sample index; `phase` is unchanged then.
pub fn unwrap_phase_inplace<T: Real>(phase: &mut [T]) -> Result<(), SignalError> {
    validate_finite(phase, "phase")?;
    let Some(&first) = phase.first() else {
        return Ok(());
    };
    let mut u = Unwrapper::new(first, PhaseInput::Wrapped);
    for p in phase.iter_mut().skip(1) {
        *p = u.next(*p);
    }
    Ok(())
}

/// Unwraps a phase (see [`unwrap_phase_inplace`]).
///
/// ```
/// use std::f64::consts::PI;
/// let u = nonsmooth::signal::unwrap_phase(&[6.0, 0.2, 1.0])?;
/// assert!((u[1] - (0.2 + 2.0 * PI)).abs() < 1e-15);
/// # Ok::<(), nonsmooth::signal::SignalError>(())
/// ```
///
/// # Errors
/// [`SignalError::NonFinite`] with the sample index.
pub fn unwrap_phase<T: Real>(phase: &[T]) -> Result<Vec<T>, SignalError> {
    let mut out = phase.to_vec();
    unwrap_phase_inplace(&mut out)?;
    Ok(out)
}

/// The forcing angular frequency `ω = dφ/dt` (rad/s) at each section point, for plotting
/// section diagrams against `ω` during a frequency ramp.
///
/// # Formula
/// Through three successive points `(t_{k−1}, 2πi_{k−1})`, `(t_k, 2πi_k)`,
/// `(t_{k+1}, 2πi_{k+1})` the parabola is differentiated at `t_k`: with `h_1, h_2` the
/// time steps and `d_1, d_2` the secant slopes,
/// $$ \omega_k = \frac{h_2\,d_1 + h_1\,d_2}{h_1 + h_2}, $$
/// and the one-sided three-point formulas at the ends. This is exact when `φ(t)` is
/// quadratic — constant `ω` or the paper's linear ramp `ω(t) = ω_0 + αt` — up to the error
/// of the crossing times themselves. With two points the secant slope is returned for both.
///
/// # Errors
/// [`SignalError::TooFewSamples`] for fewer than two points,
/// [`SignalError::NonIncreasingTime`] if the point times do not increase strictly.
pub fn section_frequencies<T: Real>(points: &[PoincarePoint<T>]) -> Result<Vec<T>, SignalError> {
    if points.len() < 2 {
        return Err(SignalError::TooFewSamples {
            found: points.len(),
            required: 2,
        });
    }
    for (k, w) in points.windows(2).enumerate() {
        // NaN times fail this too.
        if w[1].t.partial_cmp(&w[0].t) != Some(std::cmp::Ordering::Greater) {
            return Err(SignalError::NonIncreasingTime {
                location: Location::Sample(k + 1),
                previous: to_f64(w[0].t),
                t: to_f64(w[1].t),
            });
        }
    }
    let two_pi = T::two_pi();
    let slope = |a: &PoincarePoint<T>, b: &PoincarePoint<T>| {
        two_pi * lit::<T>((b.i - a.i) as f64) / (b.t - a.t)
    };
    let m = points.len();
    if m == 2 {
        let d = slope(&points[0], &points[1]);
        return Ok(vec![d, d]);
    }
    let mut out = Vec::with_capacity(m);
    for k in 0..m {
        let c = k.clamp(1, m - 2);
        let (a, b, e) = (&points[c - 1], &points[c], &points[c + 1]);
        let (h1, h2) = (b.t - a.t, e.t - b.t);
        let (d1, d2) = (slope(a, b), slope(b, e));
        let w = if k == c {
            (h2 * d1 + h1 * d2) / (h1 + h2)
        } else if k < c {
            d1 - (d2 - d1) * h1 / (h1 + h2)
        } else {
            d2 + (d2 - d1) * h2 / (h1 + h2)
        };
        out.push(w);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn unwrap_handles_both_directions() {
        let u = unwrap_phase(&[0.1, 6.2, 0.0, 6.0]).unwrap();
        assert!((u[1] - (6.2 - 2.0 * PI)).abs() < 1e-15);
        assert!((u[2] - 0.0).abs() < 1e-15);
        assert!((u[3] - (6.0 - 2.0 * PI)).abs() < 1e-15);
        assert!(unwrap_phase(&[0.0, f64::NAN]).is_err());
        assert!(unwrap_phase::<f64>(&[]).unwrap().is_empty());
    }

    #[test]
    fn levels_above_first_sample_only() {
        // Starts exactly on the level 2π: that level is not reported, 4π is.
        let t = [0.0, 1.0, 2.0];
        let p = [2.0 * PI, 3.0 * PI, 4.5 * PI];
        let pts = PhaseSection::new()
            .with_input(PhaseInput::Unwrapped)
            .sample(&t, &p, &[0.0, 1.0, 2.0])
            .unwrap();
        assert_eq!(pts.len(), 1);
        assert_eq!(pts[0].i, 2);
        assert!((pts[0].t - (1.0 + 1.0 / 1.5)).abs() < 1e-14);
        assert!((pts[0].x - pts[0].t).abs() < 1e-14);
    }

    #[test]
    fn jitter_does_not_repeat_a_level() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let p = [-0.5_f64, 0.5, -0.2, 0.3, 1.0];
        let pts = PhaseSection::new()
            .sample(&t, &p, &[0.0, 1.0, 2.0, 3.0, 4.0])
            .unwrap();
        assert_eq!(pts.len(), 1);
        assert_eq!(pts[0].i, 0);
        assert!((pts[0].t - 0.5).abs() < 1e-15);
    }

    #[test]
    fn coarse_unwrapped_phase_reports_every_level() {
        let pts = PhaseSection::new()
            .with_input(PhaseInput::Unwrapped)
            .with_offset(0.5)
            .unwrap()
            .sample(&[0.0, 1.0], &[0.0, 7.0 * PI], &[0.0, 1.0])
            .unwrap();
        assert_eq!(
            pts.iter().map(|p| p.i).collect::<Vec<_>>(),
            vec![0, 1, 2, 3]
        );
        for p in &pts {
            assert!((p.t - (2.0 * PI * p.i as f64 + 0.5) / (7.0 * PI)).abs() < 1e-15);
        }
    }

    #[test]
    fn frequencies_exact_for_a_quadratic_phase_f32() {
        // φ(t) = ω0 t + α t²/2 with ω0 = 14, α = 0.5; points at exact level times.
        let (w0, a) = (14.0_f64, 0.5_f64);
        let pts: Vec<PoincarePoint<f32>> = (1..6)
            .map(|i| {
                let phi = 2.0 * PI * i as f64;
                let t = (-w0 + (w0 * w0 + 2.0 * a * phi).sqrt()) / a;
                PoincarePoint {
                    t: t as f32,
                    x: 0.0,
                    i,
                }
            })
            .collect();
        let w = section_frequencies(&pts).unwrap();
        for (p, wk) in pts.iter().zip(&w) {
            let exact = w0 + a * p.t as f64;
            let rel = (*wk as f64 - exact).abs() / exact;
            // f32 rounding of t (≈ 2.5e-7 s on 0.44 s steps) limits this to ~1e-7.
            assert!(rel < 1e-6, "{wk} vs {exact}");
        }
        assert!(section_frequencies(&pts[..1]).is_err());
        let two = section_frequencies(&pts[..2]).unwrap();
        assert_eq!(two[0], two[1]);
    }
}
