//! The tangent-space (QR) method: variational equations and Gram–Schmidt.

use nalgebra::{SMatrix, SVector};

use super::Result;
use super::{
    DEFAULT_BLOCKS, DEFAULT_MAX_STEPS_PER_INTERVAL, LyapunovError, Norm, block_standard_error,
    check_blocks, check_interval_at, check_intervals, check_state, grid_time, integrate_to,
};
use crate::integrate::{Stats, Stepper, Tolerances};
use crate::linalg::gram_schmidt;
use crate::scalar::{lit, nan, to_f64};
use crate::{Dynamics, Real};

/// A system with `K` tangent vectors: state `(y, ψ_1, …, ψ_K)` of dimension
/// `M = N + N·K`, where `ψ_j` (components `N + jN .. N + (j+1)N`) obey the variational
/// equations in scaled coordinates,
/// $$\dot\psi_j = D^{-1} J(t, y)\, D\,\psi_j,\qquad D = \mathrm{diag}(w_1, \dots, w_N),$$
/// with `w` the scales of the [`Norm`] (all 1 for [`Norm::Euclidean`]) — the physical
/// tangent vector is `Dψ_j`.
///
/// `J` comes from [`Dynamics::jacobian`]; where it returns `None` the tangent derivatives
/// are NaN, which the stepper reports as a non-finite right-hand side
/// ([`TangentSpace::start`] checks that a Jacobian exists at the initial state and reports
/// [`LyapunovError::NoJacobian`] otherwise). No Jacobian of the augmented system is
/// provided (it would need second derivatives): use explicit steppers.
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::lyapunov::{Norm, Variational};
/// use nonsmooth::testing::HarmonicOscillator;
/// use nonsmooth::Dynamics;
///
/// // ẍ = −4x with both tangent vectors: M = 2 + 2·2 = 6.
/// let v = Variational::<f64, _, 2, 2, 6>::new(HarmonicOscillator::new(2.0)?, Norm::Euclidean)?;
/// let z = SVector::<f64, 6>::from([1.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
/// let mut dz = SVector::<f64, 6>::zeros();
/// v.rhs(0.0, &z, &mut dz);
/// // J·e1 = (0, −4), J·e2 = (1, 0).
/// assert_eq!(dz, SVector::<f64, 6>::from([0.0, -4.0, 0.0, -4.0, 1.0, 0.0]));
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variational<T, S, const N: usize, const K: usize, const M: usize> {
    system: S,
    /// `w_k`, for `(D⁻¹JD)_ik = J_ik·w_k/w_i`.
    scales: SVector<T, N>,
    /// `1/w_i`.
    inv_scales: SVector<T, N>,
}

impl<T: Real, S, const N: usize, const K: usize, const M: usize> Variational<T, S, N, K, M> {
    /// Wraps `system` with tangent vectors scaled by `norm`.
    ///
    /// # Errors
    /// [`LyapunovError::TangentCount`] unless `1 ≤ K ≤ N`; [`LyapunovError::Dimension`]
    /// unless `M == N + N·K`; [`LyapunovError::InvalidWeight`] for a bad norm.
    pub fn new(system: S, norm: Norm<T, N>) -> Result<Self, LyapunovError> {
        check_tangent_dims::<N, K, M>()?;
        norm.validate()?;
        let scales = norm.scales();
        let inv_scales = scales.map(|w| T::one() / w);
        Ok(Self {
            system,
            scales,
            inv_scales,
        })
    }

    /// The wrapped system.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// Replaces the wrapped system.
    pub fn set_system(&mut self, system: S) {
        self.system = system;
    }

    /// Splits an augmented state into `y` and the tangent matrix `Ψ` (columns `ψ_j`, in
    /// scaled coordinates).
    #[inline(always)]
    pub fn split(&self, z: &SVector<T, M>) -> (SVector<T, N>, SMatrix<T, N, K>) {
        let mut y = SVector::<T, N>::zeros();
        let mut psi = SMatrix::<T, N, K>::zeros();
        for i in 0..N {
            y[i] = z[i];
        }
        for c in 0..K {
            for i in 0..N {
                psi[(i, c)] = z[N + c * N + i];
            }
        }
        (y, psi)
    }

    /// Joins `y` and `Ψ` into an augmented state.
    #[inline(always)]
    pub fn join(&self, y: &SVector<T, N>, psi: &SMatrix<T, N, K>) -> SVector<T, M> {
        let mut z = SVector::<T, M>::zeros();
        for i in 0..N {
            z[i] = y[i];
        }
        for c in 0..K {
            for i in 0..N {
                z[N + c * N + i] = psi[(i, c)];
            }
        }
        z
    }
}

fn check_tangent_dims<const N: usize, const K: usize, const M: usize>() -> Result<(), LyapunovError>
{
    if K == 0 || K > N {
        return Err(LyapunovError::TangentCount { k: K, n: N });
    }
    if M != N + N * K {
        return Err(LyapunovError::Dimension {
            what: "tangent space (M = N + N·K)",
            n: N,
            expected: N + N * K,
            found: M,
        });
    }
    Ok(())
}

impl<T: Real, S: Dynamics<T, N>, const N: usize, const K: usize, const M: usize> Dynamics<T, M>
    for Variational<T, S, N, K, M>
{
    #[inline(always)]
    fn rhs(&self, t: T, z: &SVector<T, M>, dz: &mut SVector<T, M>) {
        let mut y = SVector::<T, N>::zeros();
        for i in 0..N {
            y[i] = z[i];
        }
        let mut dy = SVector::<T, N>::zeros();
        self.system.rhs(t, &y, &mut dy);
        for i in 0..N {
            dz[i] = dy[i];
        }
        match self.system.jacobian(t, &y) {
            Some(j) => {
                for i in 0..N {
                    for c in 0..K {
                        let mut s = T::zero();
                        for k in 0..N {
                            s += j[(i, k)] * self.scales[k] * z[N + c * N + k];
                        }
                        dz[N + c * N + i] = s * self.inv_scales[i];
                    }
                }
            }
            None => {
                for v in dz.iter_mut().skip(N) {
                    *v = nan();
                }
            }
        }
    }
}

/// The tolerances of a [`Variational`] system: the system's tolerances for the state and
/// `tangent_rtol`, `tangent_atol` for the tangent components.
///
/// The tangent vectors have length 1 right after each re-orthonormalization and length
/// `~e^{λ_j τ}` at the end of an interval, so the relative accuracy of `ψ_j` — and of
/// `ln R_jj` — is limited by `tangent_atol·e^{−λ_j τ}`. `tangent_atol = tangent_rtol =` the
/// state's relative tolerance is a sensible choice when `e^{λ_K τ}` is not small; for
/// strongly contracting directions shorten `τ` (or lower `tangent_atol`). On Lorenz
/// (`λ₃ = −14.57`), `rtol = atol = 10⁻¹⁰`, the per-interval error of `Σ_j ln R_jj` is
/// `1.7·10⁻³` with `τ = 1` and `2·10⁻⁸` with `τ = 0.25`. A direction that contracts
/// below `tangent_atol` within one interval is not resolved at all: its estimate saturates
/// near `ln(tangent_atol)/τ` (for `ẏ = −800·y`, `τ = 1`, `tangent_atol = 10⁻¹¹` the method
/// returns −26.6, not −800).
///
/// # Errors
/// [`LyapunovError::TangentCount`] / [`LyapunovError::Dimension`] for mismatched `K`, `M`;
/// [`ParameterError`](crate::ParameterError) unless both tangent tolerances are finite and
/// > 0.
pub fn tangent_tolerances<T: Real, const N: usize, const K: usize, const M: usize>(
    tol: &Tolerances<T, N>,
    tangent_rtol: T,
    tangent_atol: T,
) -> Result<Tolerances<T, M>> {
    check_tangent_dims::<N, K, M>()?;
    crate::validate::positive("tangent_rtol", tangent_rtol)?;
    crate::validate::positive("tangent_atol", tangent_atol)?;
    let mut rtol = SVector::<T, M>::repeat(tangent_rtol);
    let mut atol = SVector::<T, M>::repeat(tangent_atol);
    for i in 0..N {
        rtol[i] = tol.rtol[i];
        atol[i] = tol.atol[i];
    }
    Ok(Tolerances { rtol, atol })
}

/// A Lyapunov spectrum estimate (`K` exponents) with its convergence history.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum<T, const K: usize> {
    /// The exponents `λ_j = (1/(nτ)) Σ ln R_jj`, in Gram–Schmidt order (which converges to
    /// descending order).
    pub exponents: [T; K],
    /// Their standard errors from blocks.
    pub spread: [T; K],
    /// The running estimates after each interval.
    pub history: Vec<[T; K]>,
    /// The finite-time rates `ln(R_jj)/τ` of the single intervals.
    pub local: Vec<[T; K]>,
    /// The renormalization interval `τ`.
    pub interval: T,
    /// The number of blocks behind [`spread`](Self::spread).
    pub blocks: usize,
    /// Work done (augmented system).
    pub stats: Stats,
}

impl<T: Real, const K: usize> Spectrum<T, K> {
    /// The top exponent `λ_1`.
    pub fn top(&self) -> T {
        self.exponents[0]
    }

    /// `Σ_j λ_j` (for `K = N`: the time average of `tr J`).
    pub fn sum(&self) -> T {
        self.exponents.iter().fold(T::zero(), |a, &b| a + b)
    }

    /// The number of intervals averaged.
    pub fn intervals(&self) -> usize {
        self.local.len()
    }

    /// The standard error of the sum of the exponents, from blocks.
    pub fn sum_spread(&self) -> T {
        block_standard_error(self.local.len(), self.blocks, |k| {
            self.local[k].iter().fold(T::zero(), |a, &b| a + b)
        })
    }
}

/// The tangent-space (QR) estimator of the `K` leading Lyapunov exponents.
///
/// Owns the [`Variational`] system and a stepper for it (`St: Stepper<T, M>`,
/// `M = N + N·K`); used like [`TwoTrajectory`](super::TwoTrajectory):
/// [`start`](Self::start), [`transient`](Self::transient), [`estimate`](Self::estimate).
/// The tangent vectors start as the first `K` scaled unit vectors.
///
/// ```
/// use nalgebra::Vector2;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::lyapunov::{Norm, TangentSpace, tangent_tolerances};
/// use nonsmooth::testing::DampedOscillator;
///
/// // ẍ + 2ζω₀ẋ + ω₀²x = 0: both exponents are −ζω₀ = −0.3.
/// let osc = DampedOscillator::new(2.0, 0.15)?;
/// let tol = tangent_tolerances::<f64, 2, 2, 6>(&Tolerances::new(1e-10, 1e-12)?, 1e-10, 1e-10)?;
/// let mut qr = TangentSpace::<f64, 2, 2, 6, _, _>::new(osc, Dopri5::new(tol), Norm::Euclidean)?;
/// qr.start(0.0, Vector2::new(1.0, 0.0))?;
/// let s = qr.estimate(std::f64::consts::PI, 200)?;
/// assert!((s.exponents[0] + 0.3).abs() < 1e-2 && (s.exponents[1] + 0.3).abs() < 1e-2);
/// assert!((s.sum() + 0.6).abs() < 1e-8); // tr J = −2ζω₀, exactly, at every interval
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TangentSpace<T: Real, const N: usize, const K: usize, const M: usize, S, St> {
    var: Variational<T, S, N, K, M>,
    stepper: St,
    norm: Norm<T, N>,
    blocks: usize,
    max_steps: usize,
    started: bool,
}

impl<T, const N: usize, const K: usize, const M: usize, S, St> TangentSpace<T, N, K, M, S, St>
where
    T: Real,
    S: Dynamics<T, N>,
    St: Stepper<T, M>,
{
    /// An estimator with tangent vectors scaled by `norm`, 10 blocks for the spread and at
    /// most 10⁷ steps per interval.
    ///
    /// # Errors
    /// As [`Variational::new`].
    pub fn new(system: S, stepper: St, norm: Norm<T, N>) -> Result<Self> {
        Ok(Self {
            var: Variational::new(system, norm)?,
            stepper,
            norm,
            blocks: DEFAULT_BLOCKS,
            max_steps: DEFAULT_MAX_STEPS_PER_INTERVAL,
            started: false,
        })
    }

    /// An estimator whose stepper is built from the system's tolerances: `make_stepper`
    /// receives them extended by [`tangent_tolerances`] with `tangent_rtol`,
    /// `tangent_atol`, so the sizes are spelled once, on the estimator.
    ///
    /// ```
    /// use nonsmooth::integrate::{Dopri5, Tolerances};
    /// use nonsmooth::lyapunov::{Norm, TangentSpace};
    /// use nonsmooth::systems::paper::PAPER;
    /// let tol = Tolerances::per_component(1e-8, [1e-12, 1e-10])?;
    /// let qr = TangentSpace::<_, 2, 2, 6, _, _>::with_tolerances(
    ///     PAPER.oscillator::<f64>(14.0)?,
    ///     Dopri5::new,
    ///     &tol,
    ///     (1e-8, 1e-8),
    ///     Norm::weighted([1e-3, 3e-2])?,
    /// )?;
    /// # drop(qr);
    /// # Ok::<(), nonsmooth::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`tangent_tolerances`] and [`new`](Self::new).
    pub fn with_tolerances(
        system: S,
        make_stepper: impl FnOnce(Tolerances<T, M>) -> St,
        tol: &Tolerances<T, N>,
        (tangent_rtol, tangent_atol): (T, T),
        norm: Norm<T, N>,
    ) -> Result<Self> {
        let t = tangent_tolerances::<T, N, K, M>(tol, tangent_rtol, tangent_atol)?;
        Self::new(system, make_stepper(t), norm)
    }

    /// Sets the number of blocks for the standard error (default 10).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidBlocks`] if `blocks < 2`.
    pub fn with_blocks(mut self, blocks: usize) -> Result<Self> {
        self.blocks = check_blocks(blocks)?;
        Ok(self)
    }

    /// Caps the accepted steps per interval (default 10⁷).
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) if `max_steps == 0`.
    pub fn with_max_steps_per_interval(mut self, max_steps: usize) -> Result<Self> {
        self.max_steps = super::check_max_steps(max_steps)?;
        Ok(self)
    }

    /// Places the state at `(t0, y0)` and the tangent vectors at the first `K` (scaled)
    /// unit vectors.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] for a non-finite `t0` or `y0`;
    /// [`LyapunovError::NoJacobian`] if the system has no Jacobian at `(t0, y0)`.
    pub fn start(&mut self, t0: T, y0: SVector<T, N>) -> Result<()> {
        check_state(t0, &y0)?;
        if self.var.system().jacobian(t0, &y0).is_none() {
            return Err(LyapunovError::NoJacobian { t: to_f64(t0) });
        }
        let psi = SMatrix::<T, N, K>::identity();
        self.stepper.reset_state(t0, self.var.join(&y0, &psi));
        self.started = true;
        Ok(())
    }

    /// Replaces the system, keeping the state and the tangent vectors.
    pub fn set_system(&mut self, system: S) {
        self.var.set_system(system);
        if self.started {
            super::refresh_cache(&mut self.stepper);
        }
    }

    /// Restarts the clock at `t0`, keeping the state and the tangent vectors.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] if `t0` is not finite; [`LyapunovError::NotStarted`].
    pub fn set_time(&mut self, t0: T) -> Result<()> {
        super::set_clock(&mut self.stepper, self.started, t0)
    }

    /// Runs `intervals` re-orthonormalization intervals of length `tau`, discarding them.
    ///
    /// A tangent vector that collapses onto the span of the previous ones within an
    /// interval (`R_jj = 0` in floating point: its contraction relative to them exceeds the
    /// range of `T`, as happens to the paper's cart resting against the stop, where velocity
    /// perturbations decay at `~10⁶ s⁻¹`) is replaced by a unit vector orthogonal to them:
    /// transients only have to bring the state onto the attractor. In
    /// [`estimate`](Self::estimate) the same event is an error.
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate), except that 0 intervals are allowed (a no-op).
    pub fn transient(&mut self, tau: T, intervals: usize) -> Result<()> {
        check_interval_at(self.stepper.current().0, tau)?;
        self.run(tau, intervals, true, |_, _| {})
    }

    /// Runs `intervals` intervals of length `tau` and returns the spectrum estimate.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidInterval`], [`LyapunovError::TooFewIntervals`] (fewer than
    /// 2), [`LyapunovError::NotStarted`], [`LyapunovError::TangentCollapse`] if a tangent
    /// vector degenerates within an interval (shorten `tau`), and integration errors (a
    /// non-finite right-hand side where the Jacobian is missing or infinite).
    pub fn estimate(&mut self, tau: T, intervals: usize) -> Result<Spectrum<T, K>> {
        check_interval_at(self.stepper.current().0, tau)?;
        check_intervals(intervals, 2)?;
        let blocks = self.blocks.min(intervals);
        let s0 = *self.stepper.stats();
        let mut local = Vec::with_capacity(intervals.min(1 << 16));
        let mut history = Vec::with_capacity(intervals.min(1 << 16));
        let mut sum = [T::zero(); K];
        self.run(tau, intervals, false, |k, s| {
            local.push(s);
            let n = lit::<T>((k + 1) as f64);
            let mut h = [T::zero(); K];
            for j in 0..K {
                sum[j] += s[j];
                h[j] = sum[j] / n;
            }
            history.push(h);
        })?;
        let nf = lit::<T>(intervals as f64);
        let mut exponents = [T::zero(); K];
        let mut spread = [T::zero(); K];
        for j in 0..K {
            exponents[j] = sum[j] / nf;
            spread[j] = block_standard_error(intervals, blocks, |k| local[k][j]);
        }
        Ok(Spectrum {
            exponents,
            spread,
            history,
            local,
            interval: tau,
            blocks,
            stats: self.stepper.stats().since(&s0),
        })
    }

    /// The state `(t, y)`.
    pub fn state(&self) -> (T, SVector<T, N>) {
        let (t, z) = self.stepper.current();
        (t, self.var.split(z).0)
    }

    /// The current tangent vectors in physical units (`Dψ_j`, orthonormal in the norm
    /// right after a re-orthonormalization).
    pub fn tangent_vectors(&self) -> SMatrix<T, N, K> {
        let (_, psi) = self.var.split(self.stepper.current().1);
        let w = self.norm.scales();
        let mut out = psi;
        for c in 0..K {
            for i in 0..N {
                out[(i, c)] *= w[i];
            }
        }
        out
    }

    /// The system.
    pub fn system(&self) -> &S {
        self.var.system()
    }

    /// The stepper.
    pub fn stepper(&self) -> &St {
        &self.stepper
    }

    /// The core loop: `intervals` intervals, `sink(k, [ln(R_jj)/τ])` after each;
    /// `reseed`: replace collapsed tangent vectors instead of failing.
    fn run(
        &mut self,
        tau: T,
        intervals: usize,
        reseed: bool,
        mut sink: impl FnMut(usize, [T; K]),
    ) -> Result<()> {
        if !self.started {
            return Err(LyapunovError::NotStarted);
        }
        let t_start = self.stepper.current().0;
        for k in 0..intervals {
            let t_k = grid_time(t_start, tau, k + 1);
            integrate_to(&mut self.stepper, &self.var, t_k, self.max_steps)?;
            let (y, mut psi) = self.var.split(self.stepper.current().1);
            let r = gram_schmidt(&mut psi);
            if reseed && r.iter().all(|v| v.is_finite()) && r.iter().any(|&v| v == T::zero()) {
                reseed_columns(&mut psi, &r);
                self.stepper.reset_state(t_k, self.var.join(&y, &psi));
                continue;
            }
            let mut s = [T::zero(); K];
            for j in 0..K {
                if !(r[j].is_finite() && r[j] > T::zero()) {
                    return Err(LyapunovError::TangentCollapse {
                        t: to_f64(t_k),
                        index: j,
                        value: to_f64(r[j]),
                    });
                }
                s[j] = r[j].ln() / tau;
            }
            sink(k, s);
            self.stepper.reset_state(t_k, self.var.join(&y, &psi));
        }
        Ok(())
    }
}

/// Replaces the zero columns `j` (`r[j] == 0`) of `psi` (orthonormal otherwise) by unit
/// vectors orthogonal to all other columns.
fn reseed_columns<T: Real, const N: usize, const K: usize>(psi: &mut SMatrix<T, N, K>, r: &[T; K]) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::Dopri5;
    use nalgebra::Vector2;

    /// `ẏ = diag(a, b)·y`, with Jacobian.
    struct Diag(f64, f64);
    impl Dynamics<f64, 2> for Diag {
        fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
            dy[0] = self.0 * y[0];
            dy[1] = self.1 * y[1];
        }
        fn jacobian(&self, _t: f64, _y: &SVector<f64, 2>) -> Option<SMatrix<f64, 2, 2>> {
            Some(SMatrix::<f64, 2, 2>::new(self.0, 0.0, 0.0, self.1))
        }
    }

    /// No Jacobian.
    struct Bare;
    impl Dynamics<f64, 2> for Bare {
        fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    fn tol6() -> Tolerances<f64, 6> {
        tangent_tolerances::<f64, 2, 2, 6>(&Tolerances::new(1e-11, 1e-13).unwrap(), 1e-11, 1e-11)
            .unwrap()
    }

    #[test]
    fn diagonal_spectrum_is_exact() {
        // Gram–Schmidt on a diagonal flow keeps the unit vectors: both rates are exact, and
        // the weights do not matter.
        for norm in [Norm::Euclidean, Norm::Weighted([1e-3, 5.0])] {
            let mut qr =
                TangentSpace::<f64, 2, 2, 6, _, _>::new(Diag(0.4, -1.5), Dopri5::new(tol6()), norm)
                    .unwrap();
            qr.start(0.0, Vector2::new(1.0, 1.0)).unwrap();
            let s = qr.estimate(0.5, 10).unwrap();
            assert!((s.exponents[0] - 0.4).abs() < 1e-9, "{:?}", s.exponents);
            assert!((s.exponents[1] + 1.5).abs() < 1e-9, "{:?}", s.exponents);
            assert_eq!(s.history.len(), 10);
            assert!(s.spread.iter().all(|&e| e < 1e-9));
            let v = qr.tangent_vectors();
            assert!((norm.norm(&v.column(0).into_owned()) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn one_tangent_vector_gives_the_top_exponent() {
        let tol = tangent_tolerances::<f64, 2, 1, 4>(
            &Tolerances::new(1e-11, 1e-13).unwrap(),
            1e-11,
            1e-11,
        )
        .unwrap();
        let mut qr = TangentSpace::<f64, 2, 1, 4, _, _>::new(
            Diag(0.4, -1.5),
            Dopri5::new(tol),
            Norm::Euclidean,
        )
        .unwrap();
        qr.start(0.0, Vector2::new(1.0, 1.0)).unwrap();
        let s = qr.estimate(1.0, 3).unwrap();
        assert!((s.top() - 0.4).abs() < 1e-9);
    }

    #[test]
    fn collapsed_columns_are_reseeded_orthonormal() {
        let mut psi = SMatrix::<f64, 3, 3>::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        reseed_columns(&mut psi, &[1.0, 0.0, 0.0]);
        assert!((psi.transpose() * psi - SMatrix::<f64, 3, 3>::identity()).norm() < 1e-15);
        assert_eq!(psi.column(0)[0], 1.0);
    }

    #[test]
    fn transient_survives_a_collapse_that_estimate_reports() {
        // ẏ = diag(0, −800)·y: over τ = 1 the second tangent vector shrinks by e^{−800},
        // below the range of f64 (with a tangent atol that does not stop the decay at
        // the atol level: see `tangent_tolerances`).
        let tol = tangent_tolerances::<f64, 2, 2, 6>(
            &Tolerances::new(1e-8, 1e-13).unwrap(),
            1e-8,
            1e-300,
        )
        .unwrap();
        let mut qr = TangentSpace::<f64, 2, 2, 6, _, _>::new(
            Diag(0.0, -800.0),
            Dopri5::new(tol),
            Norm::Euclidean,
        )
        .unwrap();
        qr.start(0.0, Vector2::new(1.0, 1.0)).unwrap();
        qr.transient(1.0, 2).unwrap();
        let r = qr.estimate(1.0, 2);
        assert!(
            matches!(r, Err(LyapunovError::TangentCollapse { index: 1, .. })),
            "{r:?}"
        );
    }

    #[test]
    fn rejects_bad_input() {
        assert!(matches!(
            Variational::<f64, _, 2, 3, 8>::new(Bare, Norm::Euclidean),
            Err(LyapunovError::TangentCount { k: 3, n: 2 })
        ));
        assert!(matches!(
            Variational::<f64, _, 2, 0, 2>::new(Bare, Norm::Euclidean),
            Err(LyapunovError::TangentCount { k: 0, n: 2 })
        ));
        assert!(matches!(
            Variational::<f64, _, 2, 2, 5>::new(Bare, Norm::Euclidean),
            Err(LyapunovError::Dimension {
                expected: 6,
                found: 5,
                ..
            })
        ));
        assert!(
            tangent_tolerances::<f64, 2, 2, 6>(&Tolerances::new(1e-8, 1e-8).unwrap(), 0.0, 1e-8)
                .is_err()
        );
        let mut qr =
            TangentSpace::<f64, 2, 2, 6, _, _>::new(Bare, Dopri5::new(tol6()), Norm::Euclidean)
                .unwrap();
        assert!(matches!(
            qr.start(0.0, Vector2::new(1.0, 0.0)),
            Err(LyapunovError::NoJacobian { .. })
        ));
        assert!(matches!(
            qr.estimate(1.0, 5),
            Err(LyapunovError::NotStarted)
        ));
        let mut qr = TangentSpace::<f64, 2, 2, 6, _, _>::new(
            Diag(1.0, 1.0),
            Dopri5::new(tol6()),
            Norm::Euclidean,
        )
        .unwrap();
        assert!(qr.start(f64::INFINITY, Vector2::new(1.0, 0.0)).is_err());
        qr.start(0.0, Vector2::new(1.0, 0.0)).unwrap();
        assert!(qr.estimate(-1.0, 5).is_err());
        assert!(qr.estimate(1.0, 0).is_err());
        assert!(
            TangentSpace::<f64, 2, 2, 6, _, _>::new(
                Diag(1.0, 1.0),
                Dopri5::new(tol6()),
                Norm::Weighted([1.0, -1.0])
            )
            .is_err()
        );
    }
}
