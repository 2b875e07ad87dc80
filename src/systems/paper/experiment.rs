//! The paper's synthetic experiment: its oscillator "measured" like the real stand, a
//! configuration of the generic [`ModelExperiment`].

use nalgebra::Vector2;

use super::PaperParameters;
use crate::Dynamics;
use crate::event::Stop;
use crate::integrate::{Stats, Tolerances};
use crate::sample::Impact;
use crate::signal::{ModelExperiment, ModelRecord, SignalError, TimeSeries};
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative, positive};

/// How the paper's rotor is driven: at a constant angular frequency, or on the experiment's
/// linear ramp `ω(t) = ω₀ + r·t` (the phase is then `φ(t) = ω₀t + rt²/2`, see
/// [`RampedRotor`](crate::excite::RampedRotor)). Time starts at `t = 0` with `φ = 0`.
///
/// ```
/// use nonsmooth::systems::paper::Forcing;
/// let f = Forcing::ramp(14.0, 0.5);
/// assert_eq!(f.omega_at(2.0), 15.0);
/// assert_eq!(f.phase_at(2.0), 14.0 * 2.0 + 0.25 * 4.0);
/// assert_eq!(Forcing::constant(20.0).phase_at(0.5), 10.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Forcing {
    /// `ω` constant (rad/s): the oscillator [`PaperParameters::oscillator`].
    Constant {
        /// Angular frequency (rad/s).
        omega: f64,
    },
    /// `ω(t) = omega0 + rate·t`: the oscillator [`PaperParameters::ramped`].
    Ramp {
        /// Angular frequency at `t = 0` (rad/s).
        omega0: f64,
        /// Angular acceleration (rad/s²); the paper's sweep uses `8.0905·10⁻³`.
        rate: f64,
    },
}

impl Forcing {
    /// The paper's sweep rate `8.0905·10⁻³ rad/s²` (Sect. 3).
    pub const PAPER_RATE: f64 = 8.0905e-3;

    /// A constant frequency `omega` (rad/s); validated when the model is built.
    pub fn constant(omega: f64) -> Self {
        Forcing::Constant { omega }
    }

    /// The ramp `ω(t) = omega0 + rate·t`; validated when the model is built.
    pub fn ramp(omega0: f64, rate: f64) -> Self {
        Forcing::Ramp { omega0, rate }
    }

    /// `ω(t)` (rad/s).
    pub fn omega_at(&self, t: f64) -> f64 {
        match *self {
            Forcing::Constant { omega } => omega,
            Forcing::Ramp { omega0, rate } => omega0 + rate * t,
        }
    }

    /// The rotor angle `φ(t)` (rad, unwrapped, `φ(0) = 0`).
    pub fn phase_at(&self, t: f64) -> f64 {
        match *self {
            Forcing::Constant { omega } => omega * t,
            Forcing::Ramp { omega0, rate } => (omega0 + 0.5 * rate * t) * t,
        }
    }
}

/// A synthetic experiment on the paper's model: the paper's oscillator "measured" like the
/// real stand, with a known answer.
///
/// It simulates the paper's oscillator ([`PaperParameters`]) with
/// known parameters, at a constant forcing frequency or on a linear frequency ramp
/// ([`Forcing`]), started at `t = 0` at rest in its static equilibrium `X0` (pressed into
/// the stop, as the experiment starts). It is a configuration of the generic
/// [`ModelExperiment`]: the noise-free position is sampled on the exact
/// grid `t_n = n·Δt` (the grid is computed from `n`, never accumulated), and the
/// "measurement" is
/// $$ x_\mathrm{meas}(t_n) = x(t_n) + \sigma\,g_n + A\sin(2\pi f_d t_n), $$
/// with `g_n` independent standard normal deviates from a seeded generator
/// ([`NormalNoise`](crate::signal::NormalNoise): SplitMix64 and the Box–Muller transform)
/// and an unmodelled small oscillation of amplitude `A` and frequency `f_d` (a mains hum or
/// a structural mode of the stand that the 1-DOF model does not contain). Optionally the
/// rotor angle `φ(t_n)`, wrapped into `[0, 2π)` as an encoder reports it, is recorded as
/// the phase column. The result is a [`TimeSeries`] that goes through exactly the same code
/// as a measured record (CSV via [`TimeSeries::write_csv_path`],
/// [`LowPass`](crate::signal::LowPass), [`ThresholdCrossing`](crate::signal::ThresholdCrossing),
/// [`PhaseSection`](crate::signal::PhaseSection)), together with the noise-free truth (the
/// clean position and the simulated impacts on the stop) to check that processing against.
///
/// Defaults: sampling at 1 kHz (`Δt = 1 ms`), no noise, no disturbance, no phase column,
/// `Dopri5` with `Tolerances::per_component(1e-12, [1e-16, 1e-14])` (a hundred times
/// tighter than [`PaperFit`](super::PaperFit) uses, so that the "truth" is not
/// limited by the integrator and a fit never sees its own discretization), at most `10⁸`
/// steps.
///
/// # Example
/// ```
/// use nonsmooth::systems::paper::{Forcing, PAPER, SyntheticExperiment};
///
/// // 0.5 s at ω = 20.465 rad/s, 1 kHz, 2 µm noise and a 1 µm, 60 Hz hum.
/// let record = SyntheticExperiment::new(PAPER, Forcing::constant(20.465), 0.5)?
///     .with_noise(2e-6, 7)?
///     .with_disturbance(1e-6, 60.0)?
///     .with_phase_column(true)
///     .generate()?;
/// assert_eq!(record.measured.len(), 501);
/// assert_eq!(record.measured.t()[500], 0.5);
/// // The noise is what was asked for: the residual's RMS is ≈ √(σ² + A²/2) ≈ 2.1 µm.
/// let rms = (record.measured.x().iter().zip(&record.clean)
///     .map(|(m, c)| (m - c).powi(2)).sum::<f64>() / 501.0).sqrt();
/// assert!((rms - 2.12e-6).abs() < 0.3e-6, "{rms}");
/// assert!(record.measured.phase().is_some());
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticExperiment {
    params: PaperParameters,
    forcing: Forcing,
    duration: f64,
    dt: f64,
    noise_std: f64,
    seed: u64,
    disturbance: (f64, f64, f64),
    phase_column: bool,
    tolerances: Tolerances<f64, 2>,
    max_steps: usize,
}

/// The output of [`SyntheticExperiment::generate`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SyntheticRecord {
    /// The "measured" record: time `t_n = n·Δt` (s), noisy position (m) and, if asked for,
    /// the wrapped rotor phase (rad).
    pub measured: TimeSeries,
    /// The noise-free simulated position at the same times (m).
    pub clean: Vec<f64>,
    /// The noise-free simulated velocity at the same times (m/s).
    pub velocity: Vec<f64>,
    /// The simulated impacts: upward crossings of `x_I`, located on the dense output (the
    /// initial contact at rest is not an impact).
    pub impacts: Vec<Impact<f64>>,
    /// The static equilibrium the run started from (m).
    pub x0: f64,
    /// The integrator's work.
    pub stats: Stats,
}

impl SyntheticExperiment {
    /// An experiment of `duration` seconds on the model `params` under `forcing`.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `duration` is finite and `> 0` (the parameters and
    /// the forcing are validated by [`generate`](Self::generate)).
    pub fn new(
        params: PaperParameters,
        forcing: Forcing,
        duration: f64,
    ) -> Result<Self, SignalError> {
        Ok(Self {
            params,
            forcing,
            duration: positive("duration", duration)?,
            dt: 1e-3,
            noise_std: 0.0,
            seed: 0,
            disturbance: (0.0, 0.0, 0.0),
            phase_column: false,
            tolerances: Tolerances {
                rtol: Vector2::repeat(1e-12),
                atol: Vector2::new(1e-16, 1e-14),
            },
            max_steps: 100_000_000,
        })
    }

    /// Sets the sampling interval `Δt` (s; default `10⁻³`).
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `dt` is finite, `> 0` and at most the duration.
    pub fn with_sample_interval(mut self, dt: f64) -> Result<Self, SignalError> {
        positive("dt", dt)?;
        if dt > self.duration {
            return Err(ParameterError::new("dt", dt, "<= duration").into());
        }
        self.dt = dt;
        Ok(self)
    }

    /// Adds Gaussian measurement noise of standard deviation `std` (m), seeded by `seed`.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `std` is finite and `≥ 0`.
    pub fn with_noise(mut self, std: f64, seed: u64) -> Result<Self, SignalError> {
        self.noise_std = non_negative("noise_std", std)?;
        self.seed = seed;
        Ok(self)
    }

    /// Adds the unmodelled oscillation `amplitude·sin(2π·frequency·t)` (m, Hz).
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `amplitude ≥ 0` and `frequency ≥ 0` are finite.
    pub fn with_disturbance(mut self, amplitude: f64, frequency: f64) -> Result<Self, SignalError> {
        let phase = self.disturbance.2;
        self.disturbance = (
            non_negative("amplitude", amplitude)?,
            non_negative("frequency", frequency)?,
            phase,
        );
        Ok(self)
    }

    /// Sets the phase (rad) of the unmodelled oscillation (default 0).
    ///
    /// # Errors
    /// [`SignalError::Parameter`] if `phase` is not finite.
    pub fn with_disturbance_phase(mut self, phase: f64) -> Result<Self, SignalError> {
        self.disturbance.2 = finite("phase", phase)?;
        Ok(self)
    }

    /// Records the rotor angle, wrapped into `[0, 2π)`, as the phase column.
    #[must_use]
    pub fn with_phase_column(mut self, on: bool) -> Self {
        self.phase_column = on;
        self
    }

    /// Sets the integrator's tolerances.
    #[must_use]
    pub fn with_tolerances(mut self, tolerances: Tolerances<f64, 2>) -> Self {
        self.tolerances = tolerances;
        self
    }

    /// Caps the integrator's steps.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] if `max_steps == 0`.
    pub fn with_max_steps(mut self, max_steps: usize) -> Result<Self, SignalError> {
        if max_steps == 0 {
            return Err(ParameterError::new("max_steps", 0.0, "> 0").into());
        }
        self.max_steps = max_steps;
        Ok(self)
    }

    /// The model's parameters.
    pub fn parameters(&self) -> &PaperParameters {
        &self.params
    }

    /// The forcing.
    pub fn forcing(&self) -> Forcing {
        self.forcing
    }

    /// The number of samples, `⌊duration/Δt⌋ + 1` (up to a rounding margin of `10⁻⁹`).
    pub fn samples(&self) -> usize {
        (self.duration / self.dt + 1e-9).floor() as usize + 1
    }

    /// Simulates and "measures": the [`ModelExperiment`] of the oscillator under the
    /// forcing, from `(X0, 0)`, measuring the position, with the impacts on the stop
    /// `x = x_I` as the truth.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) for invalid model parameters or forcing;
    /// the static-equilibrium search's error; the simulation's errors
    /// ([`IntegrateError`](crate::integrate::IntegrateError), e.g. the step cap, or
    /// [`EventError`](crate::event::EventError)).
    pub fn generate(&self) -> crate::Result<SyntheticRecord> {
        let x0 = self.params.static_equilibrium()?;
        let record = match self.forcing {
            Forcing::Constant { omega } => self.measure(self.params.oscillator::<f64>(omega)?, x0),
            Forcing::Ramp { omega0, rate } => {
                self.measure(self.params.ramped::<f64>(omega0, rate)?, x0)
            }
        }?;
        let velocity = record.states.iter().map(|y| y[1]).collect();
        let measured = if self.phase_column {
            let (t, x, _) = record.measured.into_parts();
            let phase = t
                .iter()
                .map(|&ti| {
                    let p = self.forcing.phase_at(ti).rem_euclid(std::f64::consts::TAU);
                    // rem_euclid may round up to exactly 2π.
                    if p >= std::f64::consts::TAU { 0.0 } else { p }
                })
                .collect();
            TimeSeries::new(t, x, Some(phase))?
        } else {
            record.measured
        };
        Ok(SyntheticRecord {
            measured,
            clean: record.clean,
            velocity,
            impacts: record.impacts,
            x0,
            stats: record.stats,
        })
    }

    /// The generic experiment on `system` from rest at `x0`.
    fn measure<S: Dynamics<f64, 2> + Clone>(
        &self,
        system: S,
        x0: f64,
    ) -> Result<ModelRecord<2>, SignalError> {
        let (amplitude, frequency, phase) = self.disturbance;
        ModelExperiment::new(system, Vector2::new(x0, 0.0), self.duration)?
            .with_sample_interval(self.dt)?
            .with_noise(self.noise_std, self.seed)?
            .with_disturbance(amplitude, frequency, phase)?
            .with_tolerances(self.tolerances)
            .with_max_steps(self.max_steps)?
            .generate_with_impacts(Stop {
                position: 0,
                velocity: 1,
                level: self.params.x_i,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::systems::paper::PAPER;

    #[test]
    fn builder_validates() {
        let f = Forcing::constant(20.0);
        assert!(SyntheticExperiment::new(PAPER, f, 0.0).is_err());
        assert!(SyntheticExperiment::new(PAPER, f, f64::NAN).is_err());
        let e = SyntheticExperiment::new(PAPER, f, 1.0).unwrap();
        assert!(e.clone().with_sample_interval(0.0).is_err());
        assert!(e.clone().with_sample_interval(2.0).is_err());
        assert!(e.clone().with_noise(-1.0, 0).is_err());
        assert!(e.clone().with_disturbance(1e-6, f64::INFINITY).is_err());
        assert!(e.clone().with_disturbance_phase(f64::NAN).is_err());
        assert!(e.clone().with_max_steps(0).is_err());
        assert_eq!(e.samples(), 1001);
        let bad = SyntheticExperiment::new(PAPER, Forcing::constant(-1.0), 0.01).unwrap();
        assert!(bad.generate().is_err());
    }

    #[test]
    fn noise_free_record_is_the_simulation_on_the_grid() {
        let r = SyntheticExperiment::new(PAPER, Forcing::ramp(19.0, 0.5), 0.2)
            .unwrap()
            .with_phase_column(true)
            .generate()
            .unwrap();
        let m = &r.measured;
        assert_eq!(m.len(), 201);
        for (n, &t) in m.t().iter().enumerate() {
            assert_eq!(t, n as f64 * 1e-3);
        }
        assert_eq!(m.x(), &r.clean[..]);
        // Starts at rest in the equilibrium.
        assert_eq!(m.x()[0], r.x0);
        assert_eq!(r.velocity[0], 0.0);
        let phase = m.phase().unwrap();
        for (&t, &p) in m.t().iter().zip(phase) {
            let exact = (19.0 + 0.25 * t) * t;
            assert!((0.0..std::f64::consts::TAU).contains(&p));
            let d = (exact - p) / std::f64::consts::TAU;
            assert!((d - d.round()).abs() < 1e-12);
        }
    }
}
