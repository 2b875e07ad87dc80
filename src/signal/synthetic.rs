//! Synthetic experiments: a model "measured" like a real stand, with a known answer.

use nalgebra::SVector;

use super::{SignalError, TimeSeries};
use crate::Dynamics;
use crate::drive::Simulation;
use crate::event::{Direction, Event, EventFunction};
use crate::integrate::{Dopri5, Stats, Tolerances};
use crate::sample::{Impact, ImpactSequence, Surface, Trajectory};
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative, positive};

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

/// A synthetic experiment on any model: the system simulated from `(0, y0)`, one state
/// component "measured" on the grid `t_n = n·Δt` (computed from `n`, never accumulated; the
/// [`Trajectory`] sampler interpolates the integrator's dense output there) with seeded
/// Gaussian noise ([`NormalNoise`]) and an unmodelled oscillation (a mains hum or a
/// structural mode of the stand that the model does not contain),
/// $$ y_\mathrm{meas}(t_n) = y_c(t_n) + \sigma\,g_n + A\sin(2\pi f_d t_n + \varphi_d), $$
/// with the noise-free states and, optionally, the impacts on a contact surface as the
/// truth. The result is a [`TimeSeries`] that goes through exactly the same code as a
/// measured record. The paper's configuration is
/// [`systems::paper::SyntheticExperiment`](crate::systems::paper::SyntheticExperiment).
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
    /// [`SignalError::Run`] with the simulation's error (e.g. the step cap).
    pub fn generate(&self) -> Result<ModelRecord<N>, SignalError>
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
    ) -> Result<ModelRecord<N>, SignalError>
    where
        S: Clone,
    {
        self.generate_inner(Some(surface))
    }

    fn generate_inner<G: Surface<f64, N> + EventFunction<f64, N> + Clone>(
        &self,
        surface: Option<G>,
    ) -> Result<ModelRecord<N>, SignalError>
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
