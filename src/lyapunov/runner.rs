//! One renormalizing runner for every estimator of this module.
//!
//! An estimator is a *renormalization* — a separation vector between two trajectories
//! ([`Separation`]) or `K` tangent vectors re-orthonormalized by QR ([`Frame`]) — moved
//! between renormalizations by a *flow*: one stepper on an augmented system ([`Stepped`]:
//! [`PerturbedPair`](super::PerturbedPair), [`Variational`](super::Variational)), a
//! simulation with events and resets ([`Simulated`], the hybrid QR method), or two runs of
//! their own (the hybrid and Filippov pairs, in their files). The [`Runner`] owns the rest:
//! the grid `t_k = t_s + kτ` (from the start `t_s` of each stage, never accumulated), the
//! transient (renormalized, not recorded, collapsed directions re-seeded), the records of
//! the per-interval log growths, the statistics and the errors.
//!
//! # Statistics
//! Interval `k` yields the log growths `ℓ_k = ln(d_k/d_{k−1}')` (or `ln R_jj`) over its
//! length `Δt_k`. With the grid's intervals (`Δt_k = τ`) the estimate is the mean of the
//! rates `s_k = ℓ_k/τ`; a flow that may end an interval late (the hybrid pair waits until
//! both trajectories have taken the same resets) gives the time-weighted mean
//! `Σℓ_k / ΣΔt_k`, with rates `ℓ_k/Δt_k`. The spread is the block standard error of the
//! rates (module docs of [`lyapunov`](super)).

use nalgebra::{SMatrix, SVector};

use super::{
    DEFAULT_BLOCKS, Estimate, LyapunovError, Norm, Result, block_standard_error, check_interval_at,
    check_intervals, grid_time, integrate_to,
};
use crate::drive::Simulation;
use crate::event::EventSet;
use crate::integrate::{Stats, Stepper};
use crate::linalg::gram_schmidt;
use crate::scalar::{lit, to_f64};
use crate::{Dynamics, Real};

/// What is renormalized every interval: measures the growth of the interval that ended at
/// `t` and pulls the perturbation back.
pub(crate) trait Renormalize<T: Real, const K: usize> {
    /// The `K` log growth factors of the interval, after which the perturbation is
    /// renormalized; `reseed`: replace a direction that collapsed to exactly zero instead of
    /// failing (transients only have to reach the attractor; the factors of such an interval
    /// are not recorded).
    ///
    /// # Errors
    /// [`LyapunovError::SeparationLost`], [`LyapunovError::UnresolvedSeparation`],
    /// [`LyapunovError::TangentCollapse`].
    fn renormalize(&mut self, t: T, reseed: bool) -> Result<[T; K]>;
}

/// How the perturbation is moved from one renormalization to the next.
pub(crate) trait Flow<T: Real, R> {
    /// Whether every interval ends on the grid (`Δt = τ`); otherwise intervals may end late
    /// and are weighted by their length.
    const ON_GRID: bool = true;

    /// Advances `state` from `t` to `t_end` (or later, when not [`ON_GRID`](Self::ON_GRID));
    /// returns the time reached.
    ///
    /// # Errors
    /// The run's errors.
    fn advance(&mut self, state: &mut R, t: T, t_end: T) -> Result<T>;

    /// Takes the renormalized state back at `t` (a stepper restarts from it).
    fn restart(&mut self, _state: &R, _t: T) {}

    /// All work done so far.
    fn work(&self) -> Stats;
}

/// The statistics of one estimate (`K` exponents).
pub(crate) struct Record<T, const K: usize> {
    pub(crate) exponents: [T; K],
    pub(crate) spread: [T; K],
    pub(crate) history: Vec<[T; K]>,
    pub(crate) local: Vec<[T; K]>,
    pub(crate) interval: T,
    pub(crate) blocks: usize,
    pub(crate) stats: Stats,
}

impl<T: Real> Record<T, 1> {
    /// As an [`Estimate`] of the top exponent.
    pub(crate) fn estimate(self) -> Estimate<T> {
        Estimate {
            exponent: self.exponents[0],
            spread: self.spread[0],
            history: self.history.iter().map(|h| h[0]).collect(),
            local: self.local.iter().map(|s| s[0]).collect(),
            interval: self.interval,
            blocks: self.blocks,
            stats: self.stats,
        }
    }
}

/// Running sums of one estimate.
struct Tally<T, const K: usize> {
    on_grid: bool,
    local: Vec<[T; K]>,
    history: Vec<[T; K]>,
    /// `Σ s_k` on the grid, `Σ ℓ_k` otherwise.
    sum: [T; K],
    /// `Σ Δt_k`.
    time: T,
}

impl<T: Real, const K: usize> Tally<T, K> {
    fn new(on_grid: bool, intervals: usize) -> Self {
        Self {
            on_grid,
            local: Vec::with_capacity(intervals.min(1 << 16)),
            history: Vec::with_capacity(intervals.min(1 << 16)),
            sum: [T::zero(); K],
            time: T::zero(),
        }
    }

    fn push(&mut self, logs: [T; K], dt: T, tau: T) {
        let n = lit::<T>((self.local.len() + 1) as f64);
        self.time += dt;
        let mut rate = [T::zero(); K];
        let mut mean = [T::zero(); K];
        for j in 0..K {
            if self.on_grid {
                rate[j] = logs[j] / tau;
                self.sum[j] += rate[j];
                mean[j] = self.sum[j] / n;
            } else {
                rate[j] = logs[j] / dt;
                self.sum[j] += logs[j];
                mean[j] = self.sum[j] / self.time;
            }
        }
        self.local.push(rate);
        self.history.push(mean);
    }

    fn finish(self, tau: T, blocks: usize, stats: Stats) -> Record<T, K> {
        let n = self.local.len();
        let blocks = blocks.min(n);
        let mut exponents = [T::zero(); K];
        let mut spread = [T::zero(); K];
        for j in 0..K {
            exponents[j] = if self.on_grid {
                self.sum[j] / lit::<T>(n as f64)
            } else {
                self.sum[j] / self.time
            };
            spread[j] = block_standard_error(n, blocks, |k| self.local[k][j]);
        }
        Record {
            exponents,
            spread,
            history: self.history,
            local: self.local,
            interval: tau,
            blocks,
            stats,
        }
    }
}

/// The lifecycle every estimator shares: start, transient, estimate.
#[derive(Debug, Clone)]
pub(crate) struct Runner<T, R> {
    /// The renormalized perturbation (and the state it perturbs).
    pub(crate) state: R,
    /// The time of `state`.
    pub(crate) t: T,
    pub(crate) started: bool,
    pub(crate) blocks: usize,
}

impl<T: Real, R> Runner<T, R> {
    /// A runner that has not started, 10 blocks for the spread.
    pub(crate) fn new(state: R) -> Self {
        Self {
            state,
            t: T::zero(),
            started: false,
            blocks: DEFAULT_BLOCKS,
        }
    }

    /// Places the state at `t0` (validated by the caller) and hands it to the flow.
    pub(crate) fn start<F: Flow<T, R>>(&mut self, flow: &mut F, t0: T, state: R) {
        self.state = state;
        self.t = t0;
        self.started = true;
        flow.restart(&self.state, t0);
    }

    /// The state and its time, once started.
    pub(crate) fn current(&self) -> Option<(T, &R)> {
        self.started.then_some((self.t, &self.state))
    }

    /// Restarts the clock at `t0`, keeping the state.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] if `t0` is not finite; [`LyapunovError::NotStarted`].
    pub(crate) fn set_time<F: Flow<T, R>>(&mut self, flow: &mut F, t0: T) -> Result<()> {
        if !t0.is_finite() {
            return Err(LyapunovError::NonFinite {
                what: "t0",
                value: to_f64(t0),
            });
        }
        if !self.started {
            return Err(LyapunovError::NotStarted);
        }
        self.t = t0;
        flow.restart(&self.state, t0);
        Ok(())
    }

    /// Runs `intervals` intervals of length `tau` and discards them.
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate), except that 0 intervals are allowed.
    pub(crate) fn transient<F: Flow<T, R>, const K: usize>(
        &mut self,
        flow: &mut F,
        tau: T,
        intervals: usize,
    ) -> Result<()>
    where
        R: Renormalize<T, K>,
    {
        self.check(tau)?;
        self.run::<F, K>(flow, tau, intervals, None)
    }

    /// Runs `intervals` intervals of length `tau` and returns their statistics.
    ///
    /// # Errors
    /// [`LyapunovError::NotStarted`], [`LyapunovError::InvalidInterval`],
    /// [`LyapunovError::TooFewIntervals`], the renormalization's and the flow's errors.
    pub(crate) fn estimate<F: Flow<T, R>, const K: usize>(
        &mut self,
        flow: &mut F,
        tau: T,
        intervals: usize,
    ) -> Result<Record<T, K>>
    where
        R: Renormalize<T, K>,
    {
        self.check(tau)?;
        check_intervals(intervals, 2)?;
        let w0 = flow.work();
        let mut tally = Tally::new(F::ON_GRID, intervals);
        self.run::<F, K>(flow, tau, intervals, Some(&mut tally))?;
        Ok(tally.finish(tau, self.blocks, flow.work().since(&w0)))
    }

    fn check(&self, tau: T) -> Result<()> {
        if !self.started {
            return Err(LyapunovError::NotStarted);
        }
        check_interval_at(self.t, tau)?;
        Ok(())
    }

    fn run<F: Flow<T, R>, const K: usize>(
        &mut self,
        flow: &mut F,
        tau: T,
        intervals: usize,
        mut tally: Option<&mut Tally<T, K>>,
    ) -> Result<()>
    where
        R: Renormalize<T, K>,
    {
        let t_start = self.t;
        for k in 0..intervals {
            let t_end = grid_time(t_start, tau, k + 1);
            let reached = flow.advance(&mut self.state, self.t, t_end)?;
            let logs = self.state.renormalize(reached, tally.is_none())?;
            if let Some(tally) = tally.as_deref_mut() {
                tally.push(logs, reached - self.t, tau);
            }
            flow.restart(&self.state, reached);
            self.t = reached;
        }
        Ok(())
    }
}

/// Two trajectories `y` (reference) and `ỹ` (perturbed), pulled back to the separation
/// `d0` along their difference every interval:
/// `ℓ = ln(‖ỹ − y‖/d')`, `ỹ ← y + (ỹ − y)·d0/‖ỹ − y‖`, with `d'` the separation realized by
/// the previous renormalization (`d0` up to rounding).
#[derive(Debug, Clone)]
pub(crate) struct Separation<T: Real, const N: usize> {
    pub(crate) reference: SVector<T, N>,
    pub(crate) perturbed: SVector<T, N>,
    pub(crate) d0: T,
    pub(crate) norm: Norm<T, N>,
    /// The unit (in `norm`) direction of the initial perturbation and of re-seeding.
    pub(crate) direction: SVector<T, N>,
    /// The separation realized at the start of the interval.
    d_start: T,
}

impl<T: Real, const N: usize> Separation<T, N> {
    /// Validates `N ≥ 1`, `d0` and the norm; the initial direction is along the norm's
    /// scales `(w_1, …, w_N)`.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidSeparation`], [`LyapunovError::InvalidWeight`].
    pub(crate) fn new(d0: T, norm: Norm<T, N>) -> Result<Self> {
        if N == 0 || !(d0.is_finite() && d0 > T::zero()) {
            return Err(LyapunovError::InvalidSeparation { d0: to_f64(d0) });
        }
        norm.validate()?;
        let w = norm.scales();
        Ok(Self {
            reference: SVector::zeros(),
            perturbed: SVector::zeros(),
            d0,
            norm,
            direction: w / norm.norm(&w),
            d_start: d0,
        })
    }

    /// Sets the direction of the initial perturbation.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidDirection`] if it is zero or not finite.
    pub(crate) fn set_direction(&mut self, direction: SVector<T, N>) -> Result<()> {
        self.direction = super::unit_direction(&self.norm, direction)?;
        Ok(())
    }

    /// The reference at `y0` (checked by the caller), the perturbed trajectory at
    /// `y0 + d0·e`.
    ///
    /// # Errors
    /// [`LyapunovError::UnresolvedSeparation`] if `d0` is lost to rounding at `y0`.
    pub(crate) fn placed(&self, y0: SVector<T, N>) -> Result<Self> {
        let y1 = y0 + self.direction * self.d0;
        let realized = self.norm.norm(&(y1 - y0));
        if !((realized - self.d0).abs() <= lit::<T>(1e-3) * self.d0) {
            return Err(LyapunovError::UnresolvedSeparation {
                d0: to_f64(self.d0),
                realized: to_f64(realized),
            });
        }
        Ok(Self {
            reference: y0,
            perturbed: y1,
            d_start: realized,
            ..self.clone()
        })
    }

    /// `ỹ − y`.
    pub(crate) fn delta(&self) -> SVector<T, N> {
        self.perturbed - self.reference
    }
}

impl<T: Real, const N: usize> Renormalize<T, 1> for Separation<T, N> {
    fn renormalize(&mut self, t: T, reseed: bool) -> Result<[T; 1]> {
        let mut delta = self.delta();
        let mut d = self.norm.norm(&delta);
        if reseed && d == T::zero() {
            delta = self.direction * self.d0;
            d = self.norm.norm(&delta);
        }
        if !(d.is_finite() && d > T::zero()) {
            return Err(LyapunovError::SeparationLost {
                t: to_f64(t),
                separation: to_f64(d),
            });
        }
        let log = (d / self.d_start).ln();
        self.perturbed = self.reference + delta * (self.d0 / d);
        self.d_start = self.norm.norm(&self.delta());
        if !(self.d_start > T::zero()) {
            return Err(LyapunovError::UnresolvedSeparation {
                d0: to_f64(self.d0),
                realized: to_f64(self.d_start),
            });
        }
        Ok([log])
    }
}

/// A state `y` with `K` tangent vectors `Ψ` (scaled coordinates), re-orthonormalized by
/// modified Gram–Schmidt every interval: `Ψ = QR`, `Ψ ← Q`, `ℓ_j = ln R_jj`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame<T: Real, const N: usize, const K: usize> {
    pub(crate) y: SVector<T, N>,
    pub(crate) psi: SMatrix<T, N, K>,
}

impl<T: Real, const N: usize, const K: usize> Frame<T, N, K> {
    /// `y0` with the first `K` unit vectors.
    pub(crate) fn at(y0: SVector<T, N>) -> Self {
        Self {
            y: y0,
            psi: SMatrix::identity(),
        }
    }
}

impl<T: Real, const N: usize, const K: usize> Renormalize<T, K> for Frame<T, N, K> {
    fn renormalize(&mut self, t: T, reseed: bool) -> Result<[T; K]> {
        let r = gram_schmidt(&mut self.psi);
        if reseed && r.iter().all(|v| v.is_finite()) && r.iter().any(|&v| v == T::zero()) {
            reseed_columns(&mut self.psi, &r);
            return Ok([T::zero(); K]);
        }
        let mut logs = [T::zero(); K];
        for j in 0..K {
            if !(r[j].is_finite() && r[j] > T::zero()) {
                return Err(LyapunovError::TangentCollapse {
                    t: to_f64(t),
                    index: j,
                    value: to_f64(r[j]),
                });
            }
            logs[j] = r[j].ln();
        }
        Ok(logs)
    }
}

/// Replaces the zero columns `j` (`r[j] == 0`) of `psi` (orthonormal otherwise) by unit
/// vectors orthogonal to all other columns.
pub(crate) fn reseed_columns<T: Real, const N: usize, const K: usize>(
    psi: &mut SMatrix<T, N, K>,
    r: &[T; K],
) {
    for (j, &rj) in r.iter().enumerate() {
        if rj != T::zero() {
            continue;
        }
        // The unit vector e_i with the largest component outside the other columns' span.
        let mut best = SVector::<T, N>::zeros();
        let mut best_norm = T::zero();
        for i in 0..N {
            let mut v = SVector::<T, N>::zeros();
            v[i] = T::one();
            // Zero columns (not yet re-seeded) contribute nothing.
            for c in (0..K).filter(|&c| c != j) {
                let col = psi.column(c).into_owned();
                v -= col * col.dot(&v);
            }
            let n = v.norm();
            if n > best_norm {
                best_norm = n;
                best = v;
            }
        }
        if best_norm > T::zero() {
            psi.set_column(j, &(best / best_norm));
        }
    }
}

/// An augmented system of dimension `M` that carries a renormalized state `R` in one
/// vector ([`PerturbedPair`](super::PerturbedPair): `(y, ỹ)`;
/// [`Variational`](super::Variational): `(y, Ψ)`).
pub(crate) trait Augmented<T: Real, const M: usize, R> {
    /// `R` as the augmented state.
    fn pack(&self, state: &R) -> SVector<T, M>;
    /// The augmented state `z` into `state`.
    fn unpack(&self, z: &SVector<T, M>, state: &mut R);
}

/// The flow of an augmented system under one stepper: both trajectories (or the state and
/// its tangent vectors) take the same steps.
#[derive(Debug, Clone)]
pub(crate) struct Stepped<Sys, St, const M: usize> {
    pub(crate) system: Sys,
    pub(crate) stepper: St,
    pub(crate) max_steps: usize,
}

impl<T, const M: usize, R, Sys, St> Flow<T, R> for Stepped<Sys, St, M>
where
    T: Real,
    Sys: Dynamics<T, M> + Augmented<T, M, R>,
    St: Stepper<T, M>,
{
    fn advance(&mut self, state: &mut R, _t: T, t_end: T) -> Result<T> {
        integrate_to(&mut self.stepper, &self.system, t_end, self.max_steps)?;
        self.system.unpack(self.stepper.current().1, state);
        Ok(t_end)
    }

    fn restart(&mut self, state: &R, t: T) {
        self.stepper.reset_state(t, self.system.pack(state));
    }

    fn work(&self) -> Stats {
        *self.stepper.stats()
    }
}

/// The flow of an augmented system through the event engine (resets included).
#[derive(Debug, Clone)]
pub(crate) struct Simulated<T: Real, const M: usize, Sys, St, E> {
    pub(crate) sim: Simulation<T, M, Sys, St, E>,
    pub(crate) work: Stats,
}

impl<T, const M: usize, R, Sys, St, E> Flow<T, R> for Simulated<T, M, Sys, St, E>
where
    T: Real,
    Sys: Dynamics<T, M> + Augmented<T, M, R>,
    St: Stepper<T, M>,
    E: EventSet<T, M>,
{
    fn advance(&mut self, state: &mut R, t: T, t_end: T) -> Result<T> {
        let z = self.sim.system().pack(state);
        let out = self.sim.run(t, z, t_end, &mut ())?;
        self.work += &out.stats;
        self.sim.system().unpack(&out.y, state);
        Ok(out.t)
    }

    fn work(&self) -> Stats {
        self.work
    }
}

#[cfg(test)]
mod tests {
    //! The runner against closed forms: `ẏ = A·y` with diagonal `A` has the exponents
    //! `A_jj` exactly (every interval), and a reset that multiplies the separation by `e`
    //! adds `ln e` per reset.
    use super::*;
    use crate::event::{Direction, Event, EventFunction, ResetMap};
    use crate::integrate::{Dopri5, Rk4, Tolerances};
    use crate::lyapunov::{
        HybridTangentSpace, HybridTwoTrajectory, TangentSpace, TwoTrajectory, Variational,
    };

    /// `ẏ = diag(a)·y`.
    #[derive(Clone, Copy)]
    struct Diagonal<const N: usize>([f64; N]);
    impl<const N: usize> Dynamics<f64, N> for Diagonal<N> {
        fn rhs(&self, _t: f64, y: &SVector<f64, N>, dy: &mut SVector<f64, N>) {
            for i in 0..N {
                dy[i] = self.0[i] * y[i];
            }
        }
        fn jacobian(&self, _t: f64, _y: &SVector<f64, N>) -> Option<SMatrix<f64, N, N>> {
            Some(SMatrix::from_diagonal(&SVector::from(self.0)))
        }
    }

    #[test]
    fn runner_gives_the_eigenvalues_of_a_diagonal_flow() {
        let a = [0.3, -0.7, -2.0];
        let tol = Tolerances::new(1e-12, 1e-14).unwrap();
        // Through the runner directly: a QR frame on the variational system.
        let var = Variational::<f64, _, 3, 3, 12>::new(Diagonal(a), Norm::Euclidean).unwrap();
        let mut flow = Stepped {
            system: var,
            stepper: Dopri5::new(
                crate::lyapunov::tangent_tolerances::<_, 3, 3, _>(&tol, 1e-12, 1e-14).unwrap(),
            ),
            max_steps: 100_000,
        };
        let mut runner = Runner::new(Frame::<f64, 3, 3>::at(SVector::zeros()));
        runner.start(&mut flow, 0.0, Frame::at(SVector::from([1.0, 1.0, 1.0])));
        runner.transient::<_, 3>(&mut flow, 0.25, 2).unwrap();
        let r = runner.estimate::<_, 3>(&mut flow, 0.25, 8).unwrap();
        for j in 0..3 {
            assert!((r.exponents[j] - a[j]).abs() < 1e-9, "{:?}", r.exponents);
            assert!(r.local.iter().all(|s| (s[j] - a[j]).abs() < 1e-9));
        }
        assert_eq!(runner.t, 0.5 + 0.25 * 8.0);
        // The same flow through the public estimators, sizes inferred from the tolerances.
        let mut qr = TangentSpace::from_tolerances(
            Diagonal(a),
            &tol,
            Dopri5::new,
            (1e-12, 1e-14),
            Norm::Euclidean,
        )
        .unwrap();
        qr.start(0.0, SVector::from([1.0, 1.0, 1.0])).unwrap();
        let s = qr.estimate(0.5, 4).unwrap();
        assert_eq!(s.exponents.len(), 3);
        assert!((s.sum() - a.iter().sum::<f64>()).abs() < 1e-9);
        let mut tt =
            TwoTrajectory::from_tolerances(Diagonal(a), &tol, Dopri5::new, 1e-6, Norm::Euclidean)
                .unwrap();
        // The reference at the fixed point 0 stays there; the separation is the perturbed
        // trajectory itself (integrated to the tolerances' accuracy relative to d0).
        tt.start(0.0, SVector::zeros()).unwrap();
        tt.transient(1.0, 20).unwrap();
        let e = tt.estimate(1.0, 4).unwrap();
        assert!((e.exponent - a[0]).abs() < 1e-8, "{}", e.exponent);
    }

    /// `ẏ = (1, 0)`: a clock `y₀` and a constant `y₁`.
    #[derive(Clone, Copy)]
    struct Drift;
    impl Dynamics<f64, 2> for Drift {
        fn rhs(&self, _t: f64, _y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
            dy[0] = 1.0;
            dy[1] = 0.0;
        }
        fn jacobian(&self, _t: f64, _y: &SVector<f64, 2>) -> Option<SMatrix<f64, 2, 2>> {
            Some(SMatrix::zeros())
        }
    }

    /// `g = sin(π·y₀)`: zero at every integer value of the clock.
    #[derive(Clone, Copy)]
    struct Ticks;
    impl EventFunction<f64, 2> for Ticks {
        fn value(&self, _t: f64, y: &SVector<f64, 2>) -> f64 {
            (std::f64::consts::PI * y[0]).sin()
        }
    }

    /// `y₁ ← e·y₁`.
    #[derive(Clone, Copy)]
    struct Scale(f64);
    impl ResetMap<f64, 2> for Scale {
        fn apply(&self, _t: f64, y: &mut SVector<f64, 2>) {
            y[1] *= self.0;
        }
    }

    #[test]
    fn a_reset_adds_the_log_of_its_factor() {
        // Between resets the flow is a translation (no stretching); the reset at every
        // integer y₀ has R_y = diag(1, e), f⁺ = R_y f⁻, so its saltation matrix is
        // S = R_y + (f⁺ − R_y f⁻)∇gᵀ/(∇g·f⁻) = diag(1, e): one reset per unit time gives
        // the exponents 0 and ln e. RK4 is exact on this flow.
        let e = 0.5_f64;
        let events = Event::new(Ticks, Direction::Either).with_reset(Scale(e));
        let tol = Tolerances::new(1e-12, 1e-14).unwrap();
        let rk4 = |_| Rk4::new(0.05).unwrap();
        let mut qr = HybridTangentSpace::from_tolerances(
            Drift,
            &tol,
            rk4,
            (1e-12, 1e-14),
            events,
            Norm::Euclidean,
        )
        .unwrap();
        let y0 = SVector::from([0.25, 1.0]);
        qr.start(0.0, y0).unwrap();
        let s = qr.estimate(2.0, 5).unwrap();
        // Resets at t = 0.75, 1.75, …: two per interval.
        assert_eq!(s.stats.events, 10);
        assert!(s.exponents[0].abs() < 1e-8, "{:?}", s.exponents);
        assert!((s.exponents[1] - e.ln()).abs() < 1e-8, "{:?}", s.exponents);
        // Two trajectories reset at the same times: a separation along y₁ shrinks by e at
        // each reset, one along y₀ (the default direction, the first axis) does not change.
        for (direction, want) in [
            (SVector::from([0.0, 1.0]), e.ln()),
            (SVector::from([1.0, 0.0]), 0.0),
        ] {
            let mut pair = HybridTwoTrajectory::new(
                Drift,
                Rk4::new(0.05).unwrap(),
                events,
                1e-6,
                Norm::Euclidean,
            )
            .unwrap()
            .with_direction(direction)
            .unwrap();
            pair.start(0.0, y0).unwrap();
            let p = pair.estimate(2.0, 5).unwrap();
            assert!((p.exponent - want).abs() < 1e-8, "{} vs {want}", p.exponent);
            assert!(p.local.iter().all(|l| (l - want).abs() < 1e-8));
        }
    }
}
