//! One-sided amplitude spectrum of a signal sampled over a whole number of forcing periods.

use std::fmt;
use std::sync::Arc;

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

use super::AnalysisError;
use crate::validate::ParameterError;

/// Default relative tolerance on the number of periods covered: `|n·dt·ω/2π − P| ≤ 10⁻⁶·P`.
///
/// A sample grid built as `t0 + i·P·(2π/ω)/n` meets it to rounding; a window that is off by
/// a millionth of its length leaks less than that fraction of each harmonic's amplitude into
/// the neighbouring bins, far below anything this module is used to resolve.
pub const PERIOD_TOLERANCE: f64 = 1e-6;

/// Default tolerance on the uniformity of the time stamps, in units of `dt`:
/// `|t_i − (t_0 + i·dt)| ≤ 10⁻⁶·dt`.
pub const SPACING_TOLERANCE: f64 = 1e-6;

/// Default relative amplitude threshold of [`AmplitudeSpectrum::dominant_harmonic_count`]: 1 % of the
/// largest non-DC harmonic.
///
/// Why 1 %: a harmonic at 1 % of the largest amplitude (−40 dB) carries 10⁻⁴ of its energy, so
/// the harmonics below the threshold change a reconstructed orbit by well under the line width
/// of a phase portrait; yet the threshold is far above rounding and window-leakage levels of
/// a simulated periodic orbit (≈10⁻¹²), so it counts what a reader of a spectrum plot (on a
/// log scale) calls "dominant". For an orbit whose second harmonic is a sixth of the first
/// and whose third and higher ones are far below 1 % the count is 2: "two dominant
/// frequencies, ω and 2ω".
pub const DOMINANCE_THRESHOLD: f64 = 0.01;

/// One harmonic `j` of a [`AmplitudeSpectrum`]:
/// `x_j(t) = amplitude·cos(jωt + phase) = cos·cos(jωt) + sin·sin(jωt)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HarmonicComponent {
    /// The harmonic number `j` (0 is the mean).
    pub harmonic: usize,
    /// `|a|`, the one-sided amplitude (for `j = 0`, the absolute mean).
    pub amplitude: f64,
    /// The phase `φ` in `(−π, π]`, in the time origin of the samples' time stamps.
    pub phase: f64,
    /// The cosine coefficient `a_j = amplitude·cos φ` (for `j = 0`, the mean).
    pub cos: f64,
    /// The sine coefficient `b_j = −amplitude·sin φ`.
    pub sin: f64,
}

/// The one-sided amplitude spectrum of a uniformly sampled signal covering exactly `P`
/// forcing periods.
///
/// # Normalization
/// With `n` samples `x_i = x(t_0 + i·dt)` and their DFT `X_m = Σ_i x_i e^{−2πi·mi/n}`, the
/// one-sided complex amplitude of bin `m` is
/// $$c_0 = \frac{X_0}{n},\qquad c_m = \frac{2X_m}{n}\ (0<m<n/2),\qquad c_{n/2} = \frac{X_{n/2}}{n}\ (n\text{ even}),$$
/// and the amplitude is `|c_m|`. Because the window holds `P` whole periods, the harmonic
/// `j` of the forcing frequency falls exactly on bin `m = j·P` (no leakage): a component
/// `a·cos(jωt + φ)` shows amplitude `|a|` at bin `j·P` and nothing elsewhere. Bins between
/// harmonics (`m` not a multiple of `P`) hold sub-harmonics, quasi-periodic content or noise.
/// Bin `m` is at angular frequency `m·ω/P`.
///
/// Energies are mean squares (Parseval): bin `m` carries `|c_m|²/2` (`|c_{n/2}|²` for the
/// Nyquist bin), and their sum over `m ≥ 1` is the variance of the samples.
///
/// # Examples
/// ```
/// use nonsmooth::analysis::AmplitudeSpectrum;
/// let omega = 14.0_f64;
/// let (n, periods) = (256, 4);
/// let dt = periods as f64 * std::f64::consts::TAU / omega / n as f64;
/// let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
/// let x: Vec<f64> = t.iter()
///     .map(|&t| 0.5 + 3.0 * (omega * t).sin() - 0.7 * (2.0 * omega * t).cos())
///     .collect();
/// let s = AmplitudeSpectrum::new(&t, &x, omega)?;
/// assert_eq!(s.periods(), 4);
/// let h1 = s.harmonic(1)?;
/// assert!((h1.amplitude - 3.0).abs() < 1e-12 && (h1.sin - 3.0).abs() < 1e-12);
/// assert!((s.harmonic(2)?.cos + 0.7).abs() < 1e-12);
/// assert_eq!(s.dominant_harmonic_count(nonsmooth::analysis::DOMINANCE_THRESHOLD)?, 2);
/// # Ok::<(), nonsmooth::analysis::AnalysisError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct AmplitudeSpectrum {
    omega: f64,
    periods: usize,
    t0: f64,
    dt: f64,
    n: usize,
    coefficients: Vec<Complex<f64>>,
    amplitudes: Vec<f64>,
}

/// A planned FFT of a fixed length, reused over many signals (e.g. one per frequency of a
/// sweep). [`analyze_into`](SpectrumAnalyzer::analyze_into) allocates nothing once the
/// output [`AmplitudeSpectrum`] has been created.
#[derive(Clone)]
pub struct SpectrumAnalyzer {
    n: usize,
    fft: Arc<dyn Fft<f64>>,
    buffer: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    period_tolerance: f64,
    spacing_tolerance: f64,
}

impl fmt::Debug for SpectrumAnalyzer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SpectrumAnalyzer")
            .field("n", &self.n)
            .field("period_tolerance", &self.period_tolerance)
            .field("spacing_tolerance", &self.spacing_tolerance)
            .finish_non_exhaustive()
    }
}

impl SpectrumAnalyzer {
    /// Plans the FFT for signals of `n` samples, with the default tolerances
    /// [`PERIOD_TOLERANCE`] and [`SPACING_TOLERANCE`].
    ///
    /// # Errors
    /// [`AnalysisError::TooFewSamples`] if `n < 3` (the first harmonic of one period needs
    /// three samples).
    pub fn new(n: usize) -> Result<Self, AnalysisError> {
        if n < 3 {
            return Err(AnalysisError::TooFewSamples {
                samples: n,
                required: 3,
            });
        }
        let fft = FftPlanner::<f64>::new().plan_fft_forward(n);
        let scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
        Ok(Self {
            n,
            fft,
            buffer: vec![Complex::new(0.0, 0.0); n],
            scratch,
            period_tolerance: PERIOD_TOLERANCE,
            spacing_tolerance: SPACING_TOLERANCE,
        })
    }

    /// Replaces the tolerances: relative on the number of periods, and on the spacing in
    /// units of `dt` (see [`PERIOD_TOLERANCE`], [`SPACING_TOLERANCE`]).
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] unless both are finite and > 0.
    pub fn with_tolerances(mut self, period: f64, spacing: f64) -> Result<Self, AnalysisError> {
        self.period_tolerance = crate::validate::positive("period_tolerance", period)?;
        self.spacing_tolerance = crate::validate::positive("spacing_tolerance", spacing)?;
        Ok(self)
    }

    /// The planned number of samples.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always `false` (at least three samples are planned); present for API symmetry.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The spectrum of `x` sampled at `t`, for the forcing frequency `omega` (rad/s).
    ///
    /// # Errors
    /// As [`analyze_into`](Self::analyze_into).
    pub fn analyze(
        &mut self,
        t: &[f64],
        x: &[f64],
        omega: f64,
    ) -> Result<AmplitudeSpectrum, AnalysisError> {
        let mut out = AmplitudeSpectrum {
            omega,
            periods: 0,
            t0: 0.0,
            dt: 0.0,
            n: 0,
            coefficients: Vec::with_capacity(self.n / 2 + 1),
            amplitudes: Vec::with_capacity(self.n / 2 + 1),
        };
        self.analyze_into(t, x, omega, &mut out)?;
        Ok(out)
    }

    /// As [`analyze`](Self::analyze), writing into `out` (whose buffers are reused).
    ///
    /// On error `out` is left unchanged.
    ///
    /// # Errors
    /// - [`AnalysisError::PlanLengthMismatch`] if `t.len()` is not the planned length;
    /// - [`AnalysisError::LengthMismatch`] if `t` and `x` differ in length;
    /// - [`AnalysisError::InvalidFrequency`] unless `omega` is finite and > 0;
    /// - [`AnalysisError::NonFinite`] for a NaN/∞ time stamp or value;
    /// - [`AnalysisError::NonUniformSampling`] if the time stamps are not increasing and
    ///   uniform to the spacing tolerance;
    /// - [`AnalysisError::NotWholePeriods`] if `n·dt` is not a whole number `P ≥ 1` of
    ///   periods `2π/ω` to the period tolerance;
    /// - [`AnalysisError::TooFewSamples`] if the first harmonic (bin `P`) is not below the
    ///   Nyquist bin, i.e. `n < 2P + 1`.
    pub fn analyze_into(
        &mut self,
        t: &[f64],
        x: &[f64],
        omega: f64,
        out: &mut AmplitudeSpectrum,
    ) -> Result<(), AnalysisError> {
        if t.len() != self.n {
            return Err(AnalysisError::PlanLengthMismatch {
                planned: self.n,
                samples: t.len(),
            });
        }
        let (t0, dt, periods) =
            validate_window(t, x, omega, self.period_tolerance, self.spacing_tolerance)?;
        let n = self.n;
        for (b, &v) in self.buffer.iter_mut().zip(x) {
            *b = Complex::new(v, 0.0);
        }
        self.fft
            .process_with_scratch(&mut self.buffer, &mut self.scratch);
        let inv_n = 1.0 / n as f64;
        out.coefficients.clear();
        out.amplitudes.clear();
        for (m, z) in self.buffer[..=n / 2].iter().enumerate() {
            let scale = if m == 0 || 2 * m == n {
                inv_n
            } else {
                2.0 * inv_n
            };
            let c = z * scale;
            out.coefficients.push(c);
            out.amplitudes.push(c.norm());
        }
        out.omega = omega;
        out.periods = periods;
        out.t0 = t0;
        out.dt = dt;
        out.n = n;
        Ok(())
    }
}

/// Checks lengths, finiteness, uniform spacing and whole periods; returns `(t0, dt, P)`.
fn validate_window(
    t: &[f64],
    x: &[f64],
    omega: f64,
    period_tol: f64,
    spacing_tol: f64,
) -> Result<(f64, f64, usize), AnalysisError> {
    if t.len() != x.len() {
        return Err(AnalysisError::LengthMismatch {
            t: t.len(),
            x: x.len(),
        });
    }
    if !(omega.is_finite() && omega > 0.0) {
        return Err(AnalysisError::InvalidFrequency { omega });
    }
    let n = t.len();
    if n < 3 {
        return Err(AnalysisError::TooFewSamples {
            samples: n,
            required: 3,
        });
    }
    check_finite(t, x)?;
    let t0 = t[0];
    let dt = (t[n - 1] - t0) / (n - 1) as f64;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(AnalysisError::NonUniformSampling {
            index: n - 1,
            deviation: f64::NAN,
            dt,
        });
    }
    let (mut worst, mut worst_i) = (0.0_f64, 0);
    for (i, &ti) in t.iter().enumerate() {
        let dev = ((ti - t0) - i as f64 * dt).abs() / dt;
        if dev > worst {
            worst = dev;
            worst_i = i;
        }
    }
    if worst > spacing_tol {
        return Err(AnalysisError::NonUniformSampling {
            index: worst_i,
            deviation: worst,
            dt,
        });
    }
    let period = std::f64::consts::TAU / omega;
    let span = n as f64 * dt;
    let p = span / period;
    let whole = p.round();
    if whole < 1.0 || (p - whole).abs() > period_tol * whole {
        // The usual mistake: the grid includes the end point t0 + P·T.
        let q = (n - 1) as f64 * dt / period;
        let hint = if q.round() >= 1.0 && (q - q.round()).abs() <= period_tol * q.round() {
            "; the last sample repeats the first one a period later: drop it"
        } else {
            ""
        };
        return Err(AnalysisError::NotWholePeriods {
            span,
            period,
            periods: p,
            hint,
        });
    }
    let periods = whole as usize;
    if n < 2 * periods + 1 {
        return Err(AnalysisError::TooFewSamples {
            samples: n,
            required: 2 * periods + 1,
        });
    }
    Ok((t0, dt, periods))
}

/// Finds the first non-finite time stamp or value.
pub(super) fn check_finite<T: crate::Real>(t: &[T], x: &[T]) -> Result<(), AnalysisError> {
    if let Some(index) = t.iter().position(|v| !v.is_finite()) {
        return Err(AnalysisError::NonFinite {
            what: "time",
            index,
        });
    }
    if let Some(index) = x.iter().position(|v| !v.is_finite()) {
        return Err(AnalysisError::NonFinite {
            what: "value",
            index,
        });
    }
    Ok(())
}

impl AmplitudeSpectrum {
    /// The spectrum of `x` sampled at the uniform time stamps `t`, which must cover a whole
    /// number `P` of forcing periods `2π/omega`: `n·dt = P·2π/ω` (the grid
    /// `t_i = t_0 + i·dt`, `i < n`, stops one step short of `t_0 + P·2π/ω`). Plans a
    /// one-off FFT; use [`SpectrumAnalyzer`] to analyze many signals of one length.
    ///
    /// # Errors
    /// As [`SpectrumAnalyzer::analyze_into`].
    pub fn new(t: &[f64], x: &[f64], omega: f64) -> Result<Self, AnalysisError> {
        if t.len() != x.len() {
            return Err(AnalysisError::LengthMismatch {
                t: t.len(),
                x: x.len(),
            });
        }
        SpectrumAnalyzer::new(t.len())?.analyze(t, x, omega)
    }

    /// The forcing frequency `ω` (rad/s).
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The number `P` of forcing periods covered.
    pub fn periods(&self) -> usize {
        self.periods
    }

    /// The number of samples `n`.
    pub fn len(&self) -> usize {
        self.n
    }

    /// `true` if the spectrum holds no samples (never, for a successfully built one).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The sample spacing `dt`.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The one-sided amplitudes of bins `0..=n/2` (see the type's normalization).
    pub fn amplitudes(&self) -> &[f64] {
        &self.amplitudes
    }

    /// The angular frequency of bin `m`: `m·ω/P` (rad/s).
    pub fn bin_frequency(&self, m: usize) -> f64 {
        m as f64 * self.omega / self.periods as f64
    }

    /// The mean of the samples (the DC coefficient `a_0`).
    pub fn mean(&self) -> f64 {
        self.coefficients[0].re
    }

    /// The largest resolved harmonic: the largest `j` with `j·P < n/2` (the Nyquist bin is
    /// excluded because its sine part is invisible).
    pub fn max_harmonic(&self) -> usize {
        // j·P < n/2  ⟺  2·j·P < n  ⟺  j ≤ (n − 1)/(2P).
        (self.n - 1) / (2 * self.periods)
    }

    /// The amplitude of harmonic `j` (bin `j·P`).
    ///
    /// # Errors
    /// [`AnalysisError::HarmonicOutOfRange`] if `j > max_harmonic()`.
    pub fn harmonic_amplitude(&self, j: usize) -> Result<f64, AnalysisError> {
        self.check_harmonic(j)?;
        Ok(self.amplitudes[j * self.periods])
    }

    /// Harmonic `j` (bin `j·P`): amplitude, phase and cos/sin coefficients in the time origin
    /// of the samples' time stamps (`t = 0`, not `t_0`).
    ///
    /// # Errors
    /// [`AnalysisError::HarmonicOutOfRange`] if `j > max_harmonic()`.
    pub fn harmonic(&self, j: usize) -> Result<HarmonicComponent, AnalysisError> {
        self.check_harmonic(j)?;
        if j == 0 {
            let mean = self.mean();
            return Ok(HarmonicComponent {
                harmonic: 0,
                amplitude: mean.abs(),
                phase: if mean < 0.0 {
                    std::f64::consts::PI
                } else {
                    0.0
                },
                cos: mean,
                sin: 0.0,
            });
        }
        let c = self.coefficients[j * self.periods];
        // c = A·e^{i(jω·t0 + φ)}: move the phase from the window start t0 to t = 0.
        let amplitude = c.norm();
        let raw = c.arg() - j as f64 * self.omega * self.t0;
        let phase = wrap_phase(raw);
        let (s, co) = raw.sin_cos();
        Ok(HarmonicComponent {
            harmonic: j,
            amplitude,
            phase,
            cos: amplitude * co,
            sin: -amplitude * s,
        })
    }

    /// The number of harmonics `j ≥ 1` whose amplitude exceeds `threshold` times the largest
    /// non-DC harmonic amplitude. See [`DOMINANCE_THRESHOLD`] for the default.
    ///
    /// Amplitudes at the rounding level of the FFT, below `100·ε·Σ_m |c_m|` (a bound on the
    /// rounding of the transform relative to the signal's size), are never counted: a
    /// constant signal has no dominant harmonic rather than dozens of rounding-noise ones.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] unless `0 ≤ threshold ≤ 1`.
    pub fn dominant_harmonic_count(&self, threshold: f64) -> Result<usize, AnalysisError> {
        if !(0.0..=1.0).contains(&threshold) {
            return Err(ParameterError::new("threshold", threshold, "in [0, 1]").into());
        }
        let floor = self.noise_floor();
        let amps = self.harmonic_amplitudes();
        let largest = amps.clone().fold(0.0_f64, f64::max);
        if largest <= floor {
            return Ok(0);
        }
        Ok(amps
            .filter(|&a| a > floor && a > threshold * largest)
            .count())
    }

    /// The fraction of the non-DC energy (the variance of the samples) carried by the `k`
    /// strongest harmonics `j ≥ 1`. The rest is in weaker harmonics and in the bins between
    /// harmonics (sub-harmonics, non-periodic content). Returns 1 for a constant signal
    /// (non-DC content at the rounding level, see
    /// [`dominant_harmonic_count`](Self::dominant_harmonic_count)).
    pub fn energy_fraction(&self, k: usize) -> f64 {
        let total: f64 = (1..self.amplitudes.len()).map(|m| self.bin_energy(m)).sum();
        if total.sqrt() <= self.noise_floor() {
            return 1.0;
        }
        let mut e: Vec<f64> = (1..=self.max_harmonic())
            .map(|j| self.bin_energy(j * self.periods))
            .collect();
        e.sort_unstable_by(|a, b| b.total_cmp(a));
        let top: f64 = e.iter().take(k).sum();
        (top / total).min(1.0)
    }

    /// Amplitudes below this are rounding noise of the transform.
    fn noise_floor(&self) -> f64 {
        100.0 * f64::EPSILON * self.amplitudes.iter().sum::<f64>()
    }

    /// Mean-square contribution of bin `m ≥ 1`.
    fn bin_energy(&self, m: usize) -> f64 {
        let a = self.amplitudes[m];
        if 2 * m == self.n { a * a } else { 0.5 * a * a }
    }

    fn harmonic_amplitudes(&self) -> impl Iterator<Item = f64> + Clone + '_ {
        (1..=self.max_harmonic()).map(|j| self.amplitudes[j * self.periods])
    }

    fn check_harmonic(&self, j: usize) -> Result<(), AnalysisError> {
        let max_harmonic = self.max_harmonic();
        if j > max_harmonic {
            Err(AnalysisError::HarmonicOutOfRange {
                harmonic: j,
                max_harmonic,
            })
        } else {
            Ok(())
        }
    }
}

/// Wraps an angle into `(−π, π]`.
pub(super) fn wrap_phase(a: f64) -> f64 {
    let w = a.sin().atan2(a.cos());
    if w == -std::f64::consts::PI {
        std::f64::consts::PI
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn grid(n: usize, periods: usize, omega: f64, t0: f64) -> Vec<f64> {
        let dt = periods as f64 * TAU / omega / n as f64;
        (0..n).map(|i| t0 + i as f64 * dt).collect()
    }

    #[test]
    fn single_cosine_lands_on_its_bin() {
        let omega = 3.0;
        let t = grid(64, 3, omega, 0.0);
        let x: Vec<f64> = t.iter().map(|&t| 2.5 * (2.0 * omega * t).cos()).collect();
        let s = AmplitudeSpectrum::new(&t, &x, omega).unwrap();
        assert_eq!(s.periods(), 3);
        assert_eq!(s.max_harmonic(), 10);
        for (m, &a) in s.amplitudes().iter().enumerate() {
            let expect = if m == 6 { 2.5 } else { 0.0 };
            assert!((a - expect).abs() < 1e-13, "bin {m}: {a}");
        }
        assert!((s.bin_frequency(6) - 2.0 * omega).abs() < 1e-15);
        let h = s.harmonic(2).unwrap();
        assert!(h.phase.abs() < 1e-13 && (h.cos - 2.5).abs() < 1e-13 && h.sin.abs() < 1e-13);
    }

    #[test]
    fn nyquist_bin_normalization() {
        // x_i = a·(−1)^i is a cosine at the Nyquist bin with amplitude a.
        let omega = TAU; // period 1
        let n = 8;
        let t = grid(n, 1, omega, 0.0);
        let x: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 0.3 } else { -0.3 })
            .collect();
        let s = AmplitudeSpectrum::new(&t, &x, omega).unwrap();
        assert!((s.amplitudes()[4] - 0.3).abs() < 1e-15);
        assert_eq!(s.max_harmonic(), 3);
        // Parseval: the variance 0.09 is all in the Nyquist bin, which is not a resolved
        // harmonic.
        assert!(s.energy_fraction(3) < 1e-15);
    }

    #[test]
    fn wrap_phase_range() {
        assert_eq!(wrap_phase(std::f64::consts::PI), std::f64::consts::PI);
        assert_eq!(wrap_phase(-std::f64::consts::PI), std::f64::consts::PI);
        assert!((wrap_phase(7.0) - (7.0 - TAU)).abs() < 1e-15);
    }

    #[test]
    fn analyzer_reuses_buffers() {
        let omega = 2.0;
        let mut an = SpectrumAnalyzer::new(32).unwrap();
        let t = grid(32, 1, omega, 0.0);
        let x: Vec<f64> = t.iter().map(|&t| (omega * t).sin()).collect();
        let mut s = an.analyze(&t, &x, omega).unwrap();
        let ptr = s.amplitudes().as_ptr();
        let y: Vec<f64> = t.iter().map(|&t| 2.0 * (omega * t).sin()).collect();
        an.analyze_into(&t, &y, omega, &mut s).unwrap();
        assert_eq!(ptr, s.amplitudes().as_ptr());
        assert!((s.harmonic_amplitude(1).unwrap() - 2.0).abs() < 1e-14);
        assert!(matches!(
            an.analyze(&t[..16], &x[..16], omega),
            Err(AnalysisError::PlanLengthMismatch { .. })
        ));
        assert!(SpectrumAnalyzer::new(2).is_err());
        assert!(an.clone().with_tolerances(0.0, 1e-6).is_err());
    }
}
