//! The two-trajectory (Benettin) estimate of the top exponent of a Filippov system, through
//! crossings, sliding and exits.
//!
//! The method is documented on [`FilippovTwoTrajectory`].

use nalgebra::SVector;

use super::Result;
use super::{
    DEFAULT_BLOCKS, Estimate, LyapunovError, Norm, block_standard_error, check_blocks,
    check_interval_at, check_intervals, check_state, grid_time,
};
use crate::Real;
use crate::filippov::{Filippov, FilippovSimulation};
use crate::integrate::{Stats, Stepper};
use crate::scalar::{lit, to_f64};

/// The two-trajectory (Benettin) estimator of the top Lyapunov exponent of a Filippov
/// system: two [`FilippovSimulation`]s of the same system, used in three stages like
/// [`TwoTrajectory`](super::TwoTrajectory) — [`start`](Self::start),
/// [`transient`](Self::transient), [`estimate`](Self::estimate).
///
/// # Method
/// A Filippov flow is continuous in the state (the field jumps across a switching surface,
/// the state does not), so the separation of two trajectories is a continuous function of
/// time whatever modes they are in: unlike a system with resets
/// ([`HybridTwoTrajectory`](super::HybridTwoTrajectory)) it can be measured at the grid times
/// `t_k = t₀ + kτ` even when one trajectory slides and the other has not reached the
/// surface yet. Each trajectory is an event-driven [`FilippovSimulation`] run of its own
/// (crossings, sliding entries and exits at its own times); every `τ` the separation is
/// pulled back to `d0` along its direction:
/// $$d_k = \|\tilde x(t_k) - x(t_k)\|_w,\qquad
///   \tilde x(t_k) \leftarrow x(t_k) + \frac{d_0}{d_k}\bigl(\tilde x(t_k) - x(t_k)\bigr),\qquad
///   \lambda_1 \approx \frac{1}{n\tau}\sum_{k=1}^{n}\ln\frac{d_k}{d_0}.$$
/// Sliding contracts the direction normal to the surface (to zero in one instant: the
/// saltation matrix of a sliding entry is singular); the separation then lies in the
/// surface, and what is measured is the growth along it. No Jacobian and no saltation
/// matrix is formed: this is the check of the tangent-space estimate
/// [`FilippovSimulation::exponents`] (variational equations of each mode and saltation
/// matrices at each transition), by a method that shares nothing with it but the runs.
///
/// # Example
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::filippov::Switched;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::lyapunov::{FilippovTwoTrajectory, Norm};
///
/// // A harmonic oscillator ẋ = y, ẏ = −x that never reaches its switching surface
/// // y = 10: the flow rotates the separation without stretching it, λ = 0.
/// let osc = Switched::new(
///     |x: &SVector<f64, 2>| x[1] - 10.0,
///     |_x: &SVector<f64, 2>| SVector::from([0.0, 1.0]),
///     |_t, x: &SVector<f64, 2>| SVector::from([x[1], -x[0]]),
///     |_t, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] - 1.0]),
/// );
/// let stepper = Dopri5::new(Tolerances::new(1e-10, 1e-12)?);
/// let mut est = FilippovTwoTrajectory::new(osc, stepper, 1e-6, Norm::Euclidean)?;
/// est.start(0.0, SVector::from([1.0, 0.0]))?;
/// let e = est.estimate(1.0, 20)?;
/// assert!(e.exponent.abs() < 1e-3, "{}", e.exponent);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct FilippovTwoTrajectory<T: Real, const N: usize, Sys, St> {
    reference: FilippovSimulation<T, Sys, St>,
    perturbed: FilippovSimulation<T, Sys, St>,
    d0: T,
    norm: Norm<T, N>,
    direction: SVector<T, N>,
    blocks: usize,
    state: Option<(T, SVector<T, N>, SVector<T, N>)>,
}

impl<T, const N: usize, Sys, St> FilippovTwoTrajectory<T, N, Sys, St>
where
    T: Real,
    Sys: Clone,
    St: Clone,
{
    /// Two runs of `system` stepped by copies of `stepper` (default
    /// [`Settings`](crate::filippov::Settings)), initial separation `d0` in `norm` along
    /// `(w_1, …, w_N)`, 10 blocks for the spread.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidSeparation`] unless `d0` is finite and > 0;
    /// [`LyapunovError::InvalidWeight`] for a bad norm.
    pub fn new(system: Sys, stepper: St, d0: T, norm: Norm<T, N>) -> Result<Self> {
        Self::from_simulation(FilippovSimulation::new(system, stepper), d0, norm)
    }

    /// As [`new`](Self::new), from a configured simulation (its settings and Zeno guard
    /// are used by both runs).
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn from_simulation(
        simulation: FilippovSimulation<T, Sys, St>,
        d0: T,
        norm: Norm<T, N>,
    ) -> Result<Self> {
        if N == 0 || !(d0.is_finite() && d0 > T::zero()) {
            return Err(LyapunovError::InvalidSeparation { d0: to_f64(d0) });
        }
        norm.validate()?;
        let w = norm.scales();
        let direction = w / norm.norm(&w);
        Ok(Self {
            perturbed: simulation.clone(),
            reference: simulation,
            d0,
            norm,
            direction,
            blocks: DEFAULT_BLOCKS,
            state: None,
        })
    }
}

impl<T, const N: usize, Sys, St> FilippovTwoTrajectory<T, N, Sys, St>
where
    T: Real,
{
    /// Sets the direction of the initial perturbation (scaled to length `d0` in the norm).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidDirection`] if it is zero or not finite.
    pub fn with_direction(mut self, direction: SVector<T, N>) -> Result<Self> {
        self.direction = super::unit_direction(&self.norm, direction)?;
        Ok(self)
    }

    /// Sets the number of blocks for the standard error (default 10).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidBlocks`] if `blocks < 2`.
    pub fn with_blocks(mut self, blocks: usize) -> Result<Self> {
        self.blocks = check_blocks(blocks)?;
        Ok(self)
    }

    /// Places the reference at `(t0, x0)` and the perturbed trajectory at `x0 + d0·e`.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] for a non-finite `t0` or `x0`;
    /// [`LyapunovError::UnresolvedSeparation`] if `d0` is lost to rounding at `x0`.
    pub fn start(&mut self, t0: T, x0: SVector<T, N>) -> Result<()> {
        check_state(t0, &x0)?;
        let x1 = x0 + self.direction * self.d0;
        let realized = self.norm.norm(&(x1 - x0));
        if !((realized - self.d0).abs() <= lit::<T>(1e-3) * self.d0) {
            return Err(LyapunovError::UnresolvedSeparation {
                d0: to_f64(self.d0),
                realized: to_f64(realized),
            });
        }
        self.state = Some((t0, x0, x1));
        Ok(())
    }

    /// The reference state `(t, x)`, once started.
    pub fn reference(&self) -> Option<(T, SVector<T, N>)> {
        self.state.map(|(t, x, _)| (t, x))
    }

    /// The current separation `x̃ − x` (length `d0` after a renormalization), once started.
    pub fn separation(&self) -> Option<SVector<T, N>> {
        self.state.map(|(_, x, y)| y - x)
    }

    /// The system.
    pub fn system(&self) -> &Sys {
        self.reference.system()
    }

    /// Runs `intervals` intervals of length `tau` and discards them (a separation that
    /// collapsed to zero, e.g. both trajectories sliding into the same point, is re-seeded
    /// along the initial direction).
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate), except that 0 intervals are allowed.
    pub fn transient<const S: usize>(&mut self, tau: T, intervals: usize) -> Result<()>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let (t, _, _) = self.state.ok_or(LyapunovError::NotStarted)?;
        check_interval_at(t, tau)?;
        let mut stats = Stats::default();
        self.run::<S>(tau, intervals, true, &mut stats, |_, _| {})
    }

    /// Runs `intervals` intervals of length `tau` and returns the estimate
    /// (`local[k] = ln(d_k/d_{k−1}')/τ`, `d'` the separation realized after the previous
    /// renormalization; the spread from blocks, see the [module docs](super)).
    ///
    /// # Errors
    /// [`LyapunovError::NotStarted`], [`LyapunovError::InvalidInterval`],
    /// [`LyapunovError::TooFewIntervals`] (fewer than 2),
    /// [`LyapunovError::SeparationLost`] if the separation collapses or overflows,
    /// [`LyapunovError::Filippov`] for a run that fails (two surfaces at once, a repelling
    /// surface, …) and [`LyapunovError::Run`] for the integration's errors.
    pub fn estimate<const S: usize>(&mut self, tau: T, intervals: usize) -> Result<Estimate<T>>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let (t, _, _) = self.state.ok_or(LyapunovError::NotStarted)?;
        check_interval_at(t, tau)?;
        check_intervals(intervals, 2)?;
        let blocks = self.blocks.min(intervals);
        let mut stats = Stats::default();
        let mut local = Vec::with_capacity(intervals.min(1 << 16));
        let mut history = Vec::with_capacity(intervals.min(1 << 16));
        let mut sum = T::zero();
        self.run::<S>(tau, intervals, false, &mut stats, |k, s| {
            local.push(s);
            sum += s;
            history.push(sum / lit::<T>((k + 1) as f64));
        })?;
        Ok(Estimate {
            exponent: sum / lit::<T>(intervals as f64),
            spread: block_standard_error(intervals, blocks, |k| local[k]),
            history,
            local,
            interval: tau,
            blocks,
            stats,
        })
    }

    /// The core loop: `intervals` intervals on the grid `t_start + kτ`,
    /// `sink(k, ln(d_k/d_start)/τ)` after each.
    fn run<const S: usize>(
        &mut self,
        tau: T,
        intervals: usize,
        reseed: bool,
        stats: &mut Stats,
        mut sink: impl FnMut(usize, T),
    ) -> Result<()>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let (t_start, mut x, mut y) = self.state.ok_or(LyapunovError::NotStarted)?;
        let mut d_start = self.norm.norm(&(y - x));
        for k in 0..intervals {
            let (ta, tb) = (grid_time(t_start, tau, k), grid_time(t_start, tau, k + 1));
            let rx = self.reference.run::<N, S, ()>(ta, x, tb, &mut ())?;
            let ry = self.perturbed.run::<N, S, ()>(ta, y, tb, &mut ())?;
            *stats += &rx.stats;
            *stats += &ry.stats;
            x = rx.x;
            let mut delta = ry.x - x;
            let mut d = self.norm.norm(&delta);
            if reseed && d == T::zero() {
                delta = self.direction * self.d0;
                d = self.norm.norm(&delta);
            }
            if !(d.is_finite() && d > T::zero()) {
                self.state = Some((ta, x, ry.x));
                return Err(LyapunovError::SeparationLost {
                    t: to_f64(tb),
                    separation: to_f64(d),
                });
            }
            sink(k, (d / d_start).ln() / tau);
            y = x + delta * (self.d0 / d);
            d_start = self.norm.norm(&(y - x));
            if !(d_start > T::zero()) {
                return Err(LyapunovError::UnresolvedSeparation {
                    d0: to_f64(self.d0),
                    realized: to_f64(d_start),
                });
            }
            self.state = Some((tb, x, y));
        }
        Ok(())
    }
}
