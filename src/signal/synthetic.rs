//! Synthetic experiments: the paper's model "measured" like the real stand.

use nalgebra::{SVector, Vector2};

use super::{SignalError, TimeSeries};
use crate::Dynamics;
use crate::drive::{Observer, Outcome, Simulation};
use crate::event::{Direction, Event, EventFunction, EventSet, Level};
use crate::integrate::{Dopri5, Stats, Tolerances};
use crate::sample::{Impact, ImpactSequence, Surface, Trajectory};
use crate::systems::paper::PaperParameters;
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative, positive};

/// How the paper's rotor is driven: at a constant angular frequency, or on the experiment's
/// linear ramp `ω(t) = ω₀ + r·t` (the phase is then `φ(t) = ω₀t + rt²/2`, see
/// [`RampedRotor`](crate::excite::RampedRotor)). Time starts at `t = 0` with `φ = 0`.
///
/// ```
/// use nonsmooth::signal::Forcing;
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

/// SplitMix64 (Steele, Lea & Flood, OOPSLA 2014) with the Box–Muller transform: a tiny,
/// seeded, platform-independent source of standard normal deviates for synthetic noise.
/// Not for cryptography, and not a substitute for a statistics-grade generator in
/// Monte-Carlo studies; its 64-bit state passes BigCrush, which is plenty for measurement
/// noise.
///
/// # Formula
/// With `u₁ ∈ (0, 1]`, `u₂ ∈ [0, 1)` uniform (53-bit), Box–Muller gives the pair
/// $$ g_1 = \sqrt{-2\ln u_1}\cos 2\pi u_2, \qquad g_2 = \sqrt{-2\ln u_1}\sin 2\pi u_2 $$
/// of independent standard normal deviates; the second is kept for the next call.
///
/// ```
/// use nonsmooth::signal::NormalNoise;
/// let mut g = NormalNoise::new(42);
/// let n = 100_000;
/// let v: Vec<f64> = (0..n).map(|_| g.sample()).collect();
/// let mean = v.iter().sum::<f64>() / n as f64;
/// let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
/// assert!(mean.abs() < 0.02 && (var - 1.0).abs() < 0.02);
/// // The same seed gives the same sequence.
/// assert_eq!(NormalNoise::new(42).sample(), v[0]);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct NormalNoise {
    state: u64,
    spare: Option<f64>,
}

impl NormalNoise {
    /// A generator with the given seed.
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed,
            spare: None,
        }
    }

    /// The next raw 64-bit SplitMix64 output.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform deviate in `[0, 1)` (53 random bits).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A standard normal deviate.
    pub fn sample(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        // 1 − u ∈ (0, 1]: the logarithm is finite.
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

/// A synthetic experiment on the paper's model: the paper's oscillator "measured" like the
/// real stand, with a known answer.
///
/// It simulates the paper's oscillator ([`PaperParameters`]) with
/// known parameters, at a constant forcing frequency or on a linear frequency ramp
/// ([`Forcing`]), started at `t = 0` at rest in its static equilibrium `X0` (pressed into
/// the stop, as the experiment starts). The noise-free position is sampled on the exact
/// grid `t_n = n·Δt` (the [`Trajectory`] sampler interpolates the integrator's dense output
/// there; the grid is computed from `n`, never accumulated), and the "measurement" is
/// $$ x_\mathrm{meas}(t_n) = x(t_n) + \sigma\,g_n + A\sin(2\pi f_d t_n), $$
/// with `g_n` independent standard normal deviates from a seeded generator
/// ([`NormalNoise`]: SplitMix64 and the Box–Muller transform) and an unmodelled small
/// oscillation of amplitude `A` and frequency `f_d` (a mains hum or a structural mode of
/// the stand that the 1-DOF model does not contain). Optionally the rotor angle
/// `φ(t_n)`, wrapped into `[0, 2π)` as an encoder reports it, is recorded as the phase
/// column. The result is a [`TimeSeries`] that goes through exactly the same code as a
/// measured record (CSV via [`TimeSeries::write_csv_path`], [`LowPass`](super::LowPass),
/// [`ThresholdCrossing`](super::ThresholdCrossing), [`PhaseSection`](super::PhaseSection)),
/// together with the noise-free truth (the clean position and the simulated impacts) to
/// check that processing against.
///
/// Defaults: sampling at 1 kHz (`Δt = 1 ms`), no noise, no disturbance, no phase column,
/// `Dopri5` with `Tolerances::per_component(1e-12, [1e-16, 1e-14])` (a hundred times
/// tighter than [`PaperFit`](crate::identify::PaperFit) uses, so that the "truth" is not
/// limited by the integrator and a fit never sees its own discretization), at most `10⁸`
/// steps.
///
/// # Example
/// ```
/// use nonsmooth::systems::paper::PAPER;
/// use nonsmooth::signal::{Forcing, SyntheticExperiment};
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
            tolerances: default_tolerances(),
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

    /// Simulates and "measures".
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) for invalid model parameters or forcing;
    /// the static-equilibrium search's error; the simulation's errors
    /// ([`IntegrateError`](crate::integrate::IntegrateError), e.g. the step cap, or
    /// [`EventError`](crate::event::EventError)).
    pub fn generate(&self) -> crate::Result<SyntheticRecord> {
        let n = self.samples();
        let t_end = (n - 1) as f64 * self.dt;
        let mut grid = Trajectory::<f64, 2>::new(0.0, self.dt, 0.0, n)?;
        let mut impacts = ImpactSequence::new(0, 0, 1, self.params.x_i, 0.0, usize::MAX)?;
        let event = Event::new(Level::new(0, self.params.x_i)?, Direction::Rising);
        let (x0, out) = run_paper(
            &self.params,
            self.forcing,
            self.tolerances,
            self.max_steps,
            event,
            t_end,
            &mut (&mut grid, &mut impacts),
        )?;
        let samples = grid.samples();
        // The sampler records every grid time in [0, t_end]; a shortfall would be a bug.
        debug_assert_eq!(samples.len(), n);
        let t: Vec<f64> = samples.iter().map(|p| p.t).collect();
        let clean: Vec<f64> = samples.iter().map(|p| p.y[0]).collect();
        let velocity: Vec<f64> = samples.iter().map(|p| p.y[1]).collect();
        let x = measure(&t, &clean, self.noise_std, self.seed, self.disturbance);
        let phase = self.phase_column.then(|| {
            t.iter()
                .map(|&ti| {
                    let p = self.forcing.phase_at(ti).rem_euclid(std::f64::consts::TAU);
                    // rem_euclid may round up to exactly 2π.
                    if p >= std::f64::consts::TAU { 0.0 } else { p }
                })
                .collect()
        });
        let measured = TimeSeries::new(t, x, phase)?;
        Ok(SyntheticRecord {
            measured,
            clean,
            velocity,
            impacts: impacts.impacts().to_vec(),
            x0,
            stats: out.stats,
        })
    }
}

/// `x(t_n) + σ·g_n + A·sin(2π f_d t_n + φ_d)`: the instrument of a synthetic experiment.
fn measure(
    t: &[f64],
    clean: &[f64],
    noise_std: f64,
    seed: u64,
    (amp, freq, phase0): (f64, f64, f64),
) -> Vec<f64> {
    let mut noise = NormalNoise::new(seed);
    t.iter()
        .zip(clean)
        .map(|(&ti, &xi)| {
            let mut m = xi;
            if noise_std > 0.0 {
                m += noise_std * noise.sample();
            }
            if amp > 0.0 {
                m += amp * (std::f64::consts::TAU * freq * ti + phase0).sin();
            }
            m
        })
        .collect()
}

/// A synthetic experiment on **any** model: the system simulated from `(0, y0)`, one state
/// component "measured" on the grid `t_n = n·Δt` with the instrument of
/// [`SyntheticExperiment`] (seeded Gaussian noise and an unmodelled oscillation,
/// $$ y_\mathrm{meas}(t_n) = y_c(t_n) + \sigma\,g_n + A\sin(2\pi f_d t_n + \varphi_d) $$),
/// with the noise-free states and, optionally, the impacts on a contact surface as the
/// truth. [`SyntheticExperiment`] is the paper's configuration of the same instrument.
///
/// Defaults: component 0, `Δt = 10⁻³`, no noise, no disturbance, DOPRI5 at `rtol = 10⁻¹²`,
/// `atol = 10⁻¹⁴`, at most `10⁸` steps.
///
/// ```
/// use nonsmooth::signal::ModelExperiment;
/// use nonsmooth::systems::DuffingUeda;
/// use nalgebra::{SVector, Vector2};
/// let rec = ModelExperiment::new(DuffingUeda::default().model::<f64>()?, Vector2::new(3.0, 0.0), 2.0)?
///     .with_sample_interval(0.01)?
///     .with_noise(1e-3, 1)?
///     .generate()?;
/// assert_eq!(rec.measured.len(), 201);
/// assert_eq!(rec.states[0], Vector2::new(3.0, 0.0));
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct ModelExperiment<S, const N: usize> {
    system: S,
    y0: SVector<f64, N>,
    component: usize,
    duration: f64,
    dt: f64,
    noise_std: f64,
    seed: u64,
    disturbance: (f64, f64, f64),
    tolerances: Tolerances<f64, N>,
    max_steps: usize,
}

/// The output of [`ModelExperiment::generate`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ModelRecord<const N: usize> {
    /// The "measured" record: times `t_n = n·Δt` and the noisy component.
    pub measured: TimeSeries,
    /// The noise-free component at the same times.
    pub clean: Vec<f64>,
    /// The noise-free states at the same times.
    pub states: Vec<SVector<f64, N>>,
    /// The impacts on the surface given to
    /// [`generate_with_impacts`](ModelExperiment::generate_with_impacts) (empty otherwise).
    pub impacts: Vec<Impact<f64>>,
    /// The integrator's work.
    pub stats: Stats,
}

impl<S: Dynamics<f64, N>, const N: usize> ModelExperiment<S, N> {
    /// An experiment of `duration` (time units of the model) on `system` from `(0, y0)`.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `duration` is finite and `> 0` and `y0` finite.
    pub fn new(system: S, y0: SVector<f64, N>, duration: f64) -> Result<Self, SignalError> {
        for &v in y0.iter() {
            finite("y0", v)?;
        }
        Ok(Self {
            system,
            y0,
            component: 0,
            duration: positive("duration", duration)?,
            dt: 1e-3,
            noise_std: 0.0,
            seed: 0,
            disturbance: (0.0, 0.0, 0.0),
            tolerances: Tolerances {
                rtol: SVector::repeat(1e-12),
                atol: SVector::repeat(1e-14),
            },
            max_steps: 100_000_000,
        })
    }

    /// Measures state component `component` (default 0).
    ///
    /// # Errors
    /// [`SignalError::Parameter`] if `component ≥ N`.
    pub fn with_component(mut self, component: usize) -> Result<Self, SignalError> {
        if component >= N {
            return Err(ParameterError::new(
                "component",
                component as f64,
                "< the state dimension",
            )
            .into());
        }
        self.component = component;
        Ok(self)
    }

    /// Sets the sampling interval `Δt` (default `10⁻³`).
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

    /// Adds Gaussian measurement noise of standard deviation `std`, seeded by `seed`.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `std` is finite and `≥ 0`.
    pub fn with_noise(mut self, std: f64, seed: u64) -> Result<Self, SignalError> {
        self.noise_std = non_negative("noise_std", std)?;
        self.seed = seed;
        Ok(self)
    }

    /// Adds the unmodelled oscillation `amplitude·sin(2π·frequency·t + phase)`.
    ///
    /// # Errors
    /// [`SignalError::Parameter`] unless `amplitude ≥ 0`, `frequency ≥ 0` and `phase` are
    /// finite.
    pub fn with_disturbance(
        mut self,
        amplitude: f64,
        frequency: f64,
        phase: f64,
    ) -> Result<Self, SignalError> {
        self.disturbance = (
            non_negative("amplitude", amplitude)?,
            non_negative("frequency", frequency)?,
            finite("phase", phase)?,
        );
        Ok(self)
    }

    /// Sets the integrator's tolerances.
    #[must_use]
    pub fn with_tolerances(mut self, tolerances: Tolerances<f64, N>) -> Self {
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

    /// The number of samples, `⌊duration/Δt⌋ + 1`.
    pub fn samples(&self) -> usize {
        (self.duration / self.dt + 1e-9).floor() as usize + 1
    }

    /// Simulates and "measures".
    ///
    /// # Errors
    /// The simulation's errors (e.g. the step cap).
    pub fn generate(&self) -> crate::Result<ModelRecord<N>>
    where
        S: Clone,
    {
        self.generate_inner::<crate::event::Stop<f64>>(None)
    }

    /// As [`generate`](Self::generate), also recording the impacts on `surface` (its rising
    /// crossings, located on the dense output) as the truth.
    ///
    /// # Errors
    /// As [`generate`](Self::generate); an index of the surface outside the state.
    pub fn generate_with_impacts<G: Surface<f64, N> + EventFunction<f64, N> + Clone>(
        &self,
        surface: G,
    ) -> crate::Result<ModelRecord<N>>
    where
        S: Clone,
    {
        self.generate_inner(Some(surface))
    }

    fn generate_inner<G: Surface<f64, N> + EventFunction<f64, N> + Clone>(
        &self,
        surface: Option<G>,
    ) -> crate::Result<ModelRecord<N>>
    where
        S: Clone,
    {
        let n = self.samples();
        let t_end = (n - 1) as f64 * self.dt;
        let cap = usize::MAX;
        let mut grid = Trajectory::<f64, N>::new(0.0, self.dt, 0.0, n)?;
        let sim = Simulation::new(self.system.clone(), Dopri5::new(self.tolerances))
            .max_steps(self.max_steps)?;
        let (out, impacts) = match surface {
            Some(g) => {
                let mut seq = ImpactSequence::on_surface(0, g.clone(), 0.0, cap)?;
                let out = sim.with_events(Event::new(g, Direction::Rising)).run(
                    0.0,
                    self.y0,
                    t_end,
                    &mut (&mut grid, &mut seq),
                )?;
                (out, seq.impacts().to_vec())
            }
            None => {
                let mut sim = sim;
                (sim.run(0.0, self.y0, t_end, &mut grid)?, Vec::new())
            }
        };
        let samples = grid.samples();
        let t: Vec<f64> = samples.iter().map(|p| p.t).collect();
        let states: Vec<SVector<f64, N>> = samples.iter().map(|p| p.y).collect();
        let clean: Vec<f64> = states.iter().map(|y| y[self.component]).collect();
        let x = measure(&t, &clean, self.noise_std, self.seed, self.disturbance);
        Ok(ModelRecord {
            measured: TimeSeries::new(t, x, None)?,
            clean,
            states,
            impacts,
            stats: out.stats,
        })
    }
}

/// `Tolerances::per_component(1e-12, [1e-16, 1e-14])`.
fn default_tolerances() -> Tolerances<f64, 2> {
    Tolerances {
        rtol: Vector2::repeat(1e-12),
        atol: Vector2::new(1e-16, 1e-14),
    }
}

/// Runs the paper's model under `forcing` from rest at its static equilibrium at `t = 0`
/// to `t_end` with `Dopri5`, streaming to `observer`; returns the equilibrium and the
/// outcome.
pub(crate) fn run_paper<Ev: EventSet<f64, 2>, O: Observer<f64, 2>>(
    params: &PaperParameters,
    forcing: Forcing,
    tolerances: Tolerances<f64, 2>,
    max_steps: usize,
    events: Ev,
    t_end: f64,
    observer: &mut O,
) -> crate::Result<(f64, Outcome<f64, 2>)> {
    let x0 = params.static_equilibrium()?;
    let y0 = Vector2::new(x0, 0.0);
    let out = match forcing {
        Forcing::Constant { omega } => go(
            params.oscillator::<f64>(omega)?,
            tolerances,
            max_steps,
            events,
            y0,
            t_end,
            observer,
        ),
        Forcing::Ramp { omega0, rate } => go(
            params.ramped::<f64>(omega0, rate)?,
            tolerances,
            max_steps,
            events,
            y0,
            t_end,
            observer,
        ),
    }?;
    Ok((x0, out))
}

fn go<S: Dynamics<f64, 2>, Ev: EventSet<f64, 2>, O: Observer<f64, 2>>(
    system: S,
    tolerances: Tolerances<f64, 2>,
    max_steps: usize,
    events: Ev,
    y0: Vector2<f64>,
    t_end: f64,
    observer: &mut O,
) -> crate::Result<Outcome<f64, 2>> {
    Simulation::new(system, Dopri5::new(tolerances))
        .with_events(events)
        .max_steps(max_steps)?
        .run(0.0, y0, t_end, observer)
        .map_err(Into::into)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::systems::paper::PAPER;

    #[test]
    fn normal_noise_moments_and_determinism() {
        let mut g = NormalNoise::new(1);
        let n = 200_000;
        let v: Vec<f64> = (0..n).map(|_| g.sample()).collect();
        let mean = v.iter().sum::<f64>() / n as f64;
        let m2 = v.iter().map(|x| x * x).sum::<f64>() / n as f64;
        let m4 = v.iter().map(|x| x.powi(4)).sum::<f64>() / n as f64;
        // Standard errors: mean 1/√n ≈ 0.0022, m2 √(2/n) ≈ 0.0032, m4 √(96/n) ≈ 0.022.
        assert!(mean.abs() < 5.0 * 0.0022, "{mean}");
        assert!((m2 - 1.0).abs() < 5.0 * 0.0032, "{m2}");
        assert!((m4 - 3.0).abs() < 5.0 * 0.022, "{m4}");
        // The first SplitMix64 output for seed 0 (reference value of the published code).
        assert_eq!(NormalNoise::new(0).next_u64(), 0xE220_A839_7B1D_CDAF);
        let mut u = NormalNoise::new(9);
        assert!(
            (0..10_000)
                .map(|_| u.uniform())
                .all(|x| (0.0..1.0).contains(&x))
        );
    }

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
