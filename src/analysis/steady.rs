//! Steady periodic responses from simulation, and the exact first grazing.

use nalgebra::SVector;

use super::AnalysisError;
use crate::Dynamics;
use crate::drive::{RunError, Simulation};
use crate::integrate::Stepper;
use crate::roots::brent;
use crate::sample::Trajectory;

/// Uniform samples of a steady response over whole forcing periods.
#[derive(Debug, Clone, PartialEq)]
pub struct SteadySamples<const N: usize> {
    /// Sample times, measured from the stroboscopic section that starts the window
    /// (`t = 0` is a section time `2πi/ω`).
    pub t: Vec<f64>,
    /// The states.
    pub states: Vec<SVector<f64, N>>,
    /// The state at the end of the run (a section point).
    pub end_state: SVector<f64, N>,
}

impl<const N: usize> SteadySamples<N> {
    /// Component `c` of every sample.
    pub fn component(&self, c: usize) -> Vec<f64> {
        self.states.iter().map(|y| y[c]).collect()
    }
}

/// Runs `system` from `y0` for `transient` forcing periods of length `period`, then samples
/// `periods` periods at `per_period` points each (times `k·period/per_period` from the
/// start of the window, the window's end excluded, so the samples cover exactly
/// `periods` periods as [`AmplitudeSpectrum`](super::AmplitudeSpectrum) requires).
///
/// # Errors
/// [`AnalysisError::Simulation`] if the run fails, [`AnalysisError::TooFewSamples`] for
/// `periods == 0` or `per_period < 2`.
pub fn steady_samples<const N: usize, S, St>(
    system: S,
    stepper: St,
    y0: SVector<f64, N>,
    period: f64,
    transient: u32,
    periods: u32,
    per_period: usize,
) -> Result<SteadySamples<N>, AnalysisError>
where
    S: Dynamics<f64, N>,
    St: Stepper<f64, N>,
{
    let n = periods as usize * per_period;
    if periods == 0 || per_period < 2 {
        return Err(AnalysisError::TooFewSamples {
            samples: n,
            required: 2,
        });
    }
    let sim_err = |e: RunError| AnalysisError::Simulation(e.to_string());
    let t0 = transient as f64 * period;
    let dt = period / per_period as f64;
    let mut traj = Trajectory::<f64, N>::new(t0, dt, t0, n + 1).map_err(|e| sim_err(e.into()))?;
    let mut sim = Simulation::new(system, stepper);
    let out = sim
        .run(0.0, y0, t0 + periods as f64 * period, &mut traj)
        .map_err(sim_err)?;
    let samples = traj.samples();
    if samples.len() < n {
        return Err(AnalysisError::TooFewSamples {
            samples: samples.len(),
            required: n,
        });
    }
    Ok(SteadySamples {
        t: samples[..n].iter().map(|s| s.t - t0).collect(),
        states: samples[..n].iter().map(|s| s.y).collect(),
        end_state: out.y,
    })
}

/// The smallest gap `min_t x(t) − level` of a steady response over `periods` periods
/// (after `transient`), from dense samples (`per_period` per period) refined at the
/// minimum by a parabola through the three smallest neighbouring samples.
///
/// # Errors
/// As [`steady_samples`].
#[allow(clippy::too_many_arguments)]
pub fn steady_min_gap<const N: usize, S, St>(
    system: S,
    stepper: St,
    y0: SVector<f64, N>,
    period: f64,
    transient: u32,
    periods: u32,
    position: usize,
    level: f64,
) -> Result<f64, AnalysisError>
where
    S: Dynamics<f64, N>,
    St: Stepper<f64, N>,
{
    let per_period = 2000;
    let s = steady_samples(system, stepper, y0, period, transient, periods, per_period)?;
    let x = s.component(position);
    let (k, _) = x.iter().enumerate().fold(
        (0, f64::INFINITY),
        |b, (i, &v)| if v < b.1 { (i, v) } else { b },
    );
    let n = x.len();
    let (a, b, c) = (x[(k + n - 1) % n], x[k], x[(k + 1) % n]);
    let den = a - 2.0 * b + c;
    let min = if den > 0.0 {
        b - (c - a) * (c - a) / (8.0 * den)
    } else {
        b
    };
    Ok(min - level)
}

/// The exact first grazing: the forcing frequency in `[lo, hi]` where the steady
/// response's smallest gap `min x − level` crosses zero, found by Brent's method on
/// `ω ↦ steady_min_gap(ω)` to `tol` (rad/s). `make(ω)` builds the system, its period and the
/// initial state; each evaluation is a steady-state simulation of `transient + periods`
/// periods.
///
/// # Errors
/// [`AnalysisError::Root`]-wrapped errors if the gap does not change sign on `[lo, hi]`,
/// simulation errors as [`AnalysisError::Simulation`].
#[allow(clippy::too_many_arguments)]
pub fn first_grazing<const N: usize, S, St, F, G>(
    make: F,
    stepper: G,
    position: usize,
    level: f64,
    lo: f64,
    hi: f64,
    tol: f64,
    transient: u32,
    periods: u32,
) -> Result<f64, AnalysisError>
where
    S: Dynamics<f64, N>,
    St: Stepper<f64, N>,
    F: Fn(f64) -> Result<(S, f64, SVector<f64, N>), RunError>,
    G: Fn() -> St,
{
    let gap = |w: f64| -> Result<f64, AnalysisError> {
        let (sys, period, y0) = make(w).map_err(|e| AnalysisError::Simulation(e.to_string()))?;
        steady_min_gap(
            sys,
            stepper(),
            y0,
            period,
            transient,
            periods,
            position,
            level,
        )
    };
    let g_lo = gap(lo)?;
    let g_hi = gap(hi)?;
    let mut failure = None;
    let root = brent(
        |w| match gap(w) {
            Ok(g) => g,
            Err(e) => {
                failure = Some(e);
                f64::NAN
            }
        },
        lo,
        hi,
        g_lo,
        g_hi,
        tol,
        100,
    );
    if let Some(e) = failure {
        return Err(e);
    }
    Ok(root?)
}
