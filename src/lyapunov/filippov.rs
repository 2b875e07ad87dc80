//! The two-trajectory (Benettin) estimate of the top exponent of a Filippov system, through
//! crossings, sliding and exits.
//!
//! The method is documented on [`FilippovTwoTrajectory`].

use nalgebra::SVector;

use super::Result;
use super::runner::{Flow, Runner, Separation};
use super::{Estimate, Norm, check_blocks, check_state};
use crate::Real;
use crate::filippov::{Filippov, FilippovSimulation};
use crate::integrate::{Stats, Stepper};

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
    runs: Runs<T, Sys, St>,
    runner: Runner<T, Separation<T, N>>,
}

/// The two event-driven runs and their work.
#[derive(Debug, Clone)]
struct Runs<T: Real, Sys, St> {
    reference: FilippovSimulation<T, Sys, St>,
    perturbed: FilippovSimulation<T, Sys, St>,
    work: Stats,
}

/// [`Runs`] for `S` switching surfaces.
struct Sliding<'a, T: Real, Sys, St, const S: usize>(&'a mut Runs<T, Sys, St>);

impl<T, const N: usize, const S: usize, Sys, St> Flow<T, Separation<T, N>>
    for Sliding<'_, T, Sys, St, S>
where
    T: Real,
    Sys: Filippov<T, N, S>,
    St: Stepper<T, N>,
{
    fn advance(&mut self, pair: &mut Separation<T, N>, t: T, t_end: T) -> Result<T> {
        let runs = &mut *self.0;
        let rx = runs
            .reference
            .run::<N, S, ()>(t, pair.reference, t_end, &mut ())?;
        let ry = runs
            .perturbed
            .run::<N, S, ()>(t, pair.perturbed, t_end, &mut ())?;
        runs.work += &rx.stats;
        runs.work += &ry.stats;
        (pair.reference, pair.perturbed) = (rx.x, ry.x);
        Ok(t_end)
    }

    fn work(&self) -> Stats {
        self.0.work
    }
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
    /// [`LyapunovError::InvalidSeparation`](super::LyapunovError::InvalidSeparation) unless `d0` is finite and > 0;
    /// [`LyapunovError::InvalidWeight`](super::LyapunovError::InvalidWeight) for a bad norm.
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
        Ok(Self {
            runner: Runner::new(Separation::new(d0, norm)?),
            runs: Runs {
                perturbed: simulation.clone(),
                reference: simulation,
                work: Stats::default(),
            },
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
    /// [`LyapunovError::InvalidDirection`](super::LyapunovError::InvalidDirection) if it is zero or not finite.
    pub fn with_direction(mut self, direction: SVector<T, N>) -> Result<Self> {
        self.runner.state.set_direction(direction)?;
        Ok(self)
    }

    /// Sets the number of blocks for the standard error (default 10).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidBlocks`](super::LyapunovError::InvalidBlocks) if `blocks < 2`.
    pub fn with_blocks(mut self, blocks: usize) -> Result<Self> {
        self.runner.blocks = check_blocks(blocks)?;
        Ok(self)
    }

    /// Places the reference at `(t0, x0)` and the perturbed trajectory at `x0 + d0·e`.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`](super::LyapunovError::NonFinite) for a non-finite `t0` or `x0`;
    /// [`LyapunovError::UnresolvedSeparation`](super::LyapunovError::UnresolvedSeparation) if `d0` is lost to rounding at `x0`.
    pub fn start(&mut self, t0: T, x0: SVector<T, N>) -> Result<()> {
        check_state(t0, &x0)?;
        let placed = self.runner.state.placed(x0)?;
        self.runner.t = t0;
        self.runner.state = placed;
        self.runner.started = true;
        Ok(())
    }

    /// The reference state `(t, x)`, once started.
    pub fn reference(&self) -> Option<(T, SVector<T, N>)> {
        self.runner.current().map(|(t, pair)| (t, pair.reference))
    }

    /// The current separation `x̃ − x` (length `d0` after a renormalization), once started.
    pub fn separation(&self) -> Option<SVector<T, N>> {
        self.runner.current().map(|(_, pair)| pair.delta())
    }

    /// The system.
    pub fn system(&self) -> &Sys {
        self.runs.reference.system()
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
        let mut flow = Sliding::<T, Sys, St, S>(&mut self.runs);
        self.runner.transient::<_, 1>(&mut flow, tau, intervals)
    }

    /// Runs `intervals` intervals of length `tau` and returns the estimate
    /// (`local[k] = ln(d_k/d_{k−1}')/τ`, `d'` the separation realized after the previous
    /// renormalization; the spread from blocks, see the [module docs](super)).
    ///
    /// # Errors
    /// [`LyapunovError::NotStarted`](super::LyapunovError::NotStarted), [`LyapunovError::InvalidInterval`](super::LyapunovError::InvalidInterval),
    /// [`LyapunovError::TooFewIntervals`](super::LyapunovError::TooFewIntervals) (fewer than 2),
    /// [`LyapunovError::SeparationLost`](super::LyapunovError::SeparationLost) if the separation collapses or overflows,
    /// [`LyapunovError::Filippov`](super::LyapunovError::Filippov) for a run that fails (two surfaces at once, a repelling
    /// surface, …) and [`LyapunovError::Run`](super::LyapunovError::Run) for the integration's errors.
    pub fn estimate<const S: usize>(&mut self, tau: T, intervals: usize) -> Result<Estimate<T>>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        let mut flow = Sliding::<T, Sys, St, S>(&mut self.runs);
        Ok(self
            .runner
            .estimate::<_, 1>(&mut flow, tau, intervals)?
            .estimate())
    }
}
