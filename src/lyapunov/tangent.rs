//! The tangent-space (QR) method: variational equations and Gram–Schmidt.

use nalgebra::{SMatrix, SVector};

use super::Result;
use super::runner::{Augmented, Flow, Frame, Record, Runner, Stepped};
use super::sizes::{Dims, TangentDimension};
use super::{
    DEFAULT_MAX_STEPS_PER_INTERVAL, LyapunovError, Norm, block_standard_error, check_blocks,
    check_state,
};
use crate::integrate::{Stats, Stepper, Tolerances};
use crate::scalar::{nan, to_f64};
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

impl<T: Real, S, const N: usize, const K: usize, const M: usize> Augmented<T, M, Frame<T, N, K>>
    for Variational<T, S, N, K, M>
{
    #[inline]
    fn pack(&self, state: &Frame<T, N, K>) -> SVector<T, M> {
        self.join(&state.y, &state.psi)
    }

    #[inline]
    fn unpack(&self, z: &SVector<T, M>, state: &mut Frame<T, N, K>) {
        (state.y, state.psi) = self.split(z);
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
/// `M = N + N·K` is inferred (a wrong `M` does not compile, see [`TangentDimension`]).
///
/// # Errors
/// [`LyapunovError::TangentCount`] unless `1 ≤ K ≤ N`;
/// [`ParameterError`](crate::ParameterError) unless both tangent tolerances are finite and
/// > 0.
pub fn tangent_tolerances<T: Real, const N: usize, const K: usize, const M: usize>(
    tol: &Tolerances<T, N>,
    tangent_rtol: T,
    tangent_atol: T,
) -> Result<Tolerances<T, M>>
where
    Dims<N>: TangentDimension<K, M>,
{
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

impl<T: Real, const K: usize> Record<T, K> {
    /// As a [`Spectrum`] of `K` exponents.
    pub(crate) fn spectrum(self) -> Spectrum<T, K> {
        Spectrum {
            exponents: self.exponents,
            spread: self.spread,
            history: self.history,
            local: self.local,
            interval: self.interval,
            blocks: self.blocks,
            stats: self.stats,
        }
    }
}

/// The tangent-space (QR) estimator of the `K` leading Lyapunov exponents.
///
/// Owns the [`Variational`] system and a stepper for it (`St: Stepper<T, M>`,
/// `M = N + N·K`); used like [`TwoTrajectory`](super::TwoTrajectory):
/// [`start`](Self::start), [`transient`](Self::transient), [`estimate`](Self::estimate).
/// The tangent vectors start as the first `K` scaled unit vectors. For the whole spectrum
/// (`K = N`), [`from_tolerances`](Self::from_tolerances) infers every size:
///
/// ```
/// use nalgebra::Vector2;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::lyapunov::{Norm, TangentSpace};
/// use nonsmooth::testing::DampedOscillator;
///
/// // ẍ + 2ζω₀ẋ + ω₀²x = 0: both exponents are −ζω₀ = −0.3.
/// let osc = DampedOscillator::new(2.0, 0.15)?;
/// let tol = Tolerances::new(1e-10, 1e-12)?;
/// let mut qr = TangentSpace::from_tolerances(osc, &tol, Dopri5::new, (1e-10, 1e-10), Norm::Euclidean)?;
/// qr.start(0.0, Vector2::new(1.0, 0.0))?;
/// let s = qr.estimate(std::f64::consts::PI, 200)?;
/// assert!((s.exponents[0] + 0.3).abs() < 1e-2 && (s.exponents[1] + 0.3).abs() < 1e-2);
/// assert!((s.sum() + 0.6).abs() < 1e-8); // tr J = −2ζω₀, exactly, at every interval
/// # Ok::<(), nonsmooth::Error>(())
/// ```
///
/// With fewer tangent vectors, `K` is the one size to write (`N` comes from the system,
/// `M` follows):
/// ```
/// # use nalgebra::Vector2;
/// # use nonsmooth::integrate::{Dopri5, Tolerances};
/// # use nonsmooth::lyapunov::{Norm, TangentSpace};
/// # use nonsmooth::testing::DampedOscillator;
/// let osc = DampedOscillator::new(2.0, 0.15)?;
/// let tol = Tolerances::new(1e-10, 1e-12)?;
/// let mut top = TangentSpace::<_, _, 1, _, _, _>::with_tolerances(
///     osc, Dopri5::new, &tol, (1e-10, 1e-10), Norm::Euclidean,
/// )?;
/// top.start(0.0, Vector2::new(1.0, 0.0))?;
/// assert_eq!(top.estimate(1.0, 10)?.exponents.len(), 1);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct TangentSpace<T: Real, const N: usize, const K: usize, const M: usize, S, St> {
    flow: Stepped<Variational<T, S, N, K, M>, St, M>,
    runner: Runner<T, Frame<T, N, K>>,
    norm: Norm<T, N>,
}

impl<T, const N: usize, const M: usize, S, St> TangentSpace<T, N, N, M, S, St>
where
    T: Real,
    S: Dynamics<T, N>,
    St: Stepper<T, M>,
    Dims<N>: TangentDimension<N, M>,
{
    /// The whole spectrum (`K = N`), the stepper built from the system's tolerances `tol`
    /// (extended by [`tangent_tolerances`] with `tangent_rtol`, `tangent_atol`), the size
    /// `M = N + N²` inferred: no size is written, and a wrong `M` does not compile
    /// ([`TangentDimension`]).
    ///
    /// # Errors
    /// As [`tangent_tolerances`] and [`new`](Self::new).
    pub fn from_tolerances(
        system: S,
        tol: &Tolerances<T, N>,
        make_stepper: impl FnOnce(Tolerances<T, M>) -> St,
        (tangent_rtol, tangent_atol): (T, T),
        norm: Norm<T, N>,
    ) -> Result<Self> {
        Self::with_tolerances(
            system,
            make_stepper,
            tol,
            (tangent_rtol, tangent_atol),
            norm,
        )
    }
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
            flow: Stepped {
                system: Variational::new(system, norm)?,
                stepper,
                max_steps: DEFAULT_MAX_STEPS_PER_INTERVAL,
            },
            runner: Runner::new(Frame::at(SVector::zeros())),
            norm,
        })
    }

    /// An estimator whose stepper is built from the system's tolerances: `make_stepper`
    /// receives them extended by [`tangent_tolerances`] with `tangent_rtol`,
    /// `tangent_atol`. `M = N + N·K` is inferred (and a wrong one does not compile,
    /// [`TangentDimension`]); for `K = N`, [`from_tolerances`](TangentSpace::from_tolerances)
    /// infers `K` too.
    ///
    /// ```
    /// use nonsmooth::integrate::{Dopri5, Tolerances};
    /// use nonsmooth::lyapunov::{Norm, TangentSpace};
    /// use nonsmooth::systems::DuffingUeda;
    /// let tol = Tolerances::new(1e-8, 1e-10)?;
    /// let qr = TangentSpace::<_, 2, 2, 6, _, _>::with_tolerances(
    ///     DuffingUeda::default().model::<f64>()?,
    ///     Dopri5::new,
    ///     &tol,
    ///     (1e-8, 1e-8),
    ///     Norm::weighted([1.0, 2.0])?,
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
    ) -> Result<Self>
    where
        Dims<N>: TangentDimension<K, M>,
    {
        let t = tangent_tolerances::<T, N, K, M>(tol, tangent_rtol, tangent_atol)?;
        Self::new(system, make_stepper(t), norm)
    }

    /// Sets the number of blocks for the standard error (default 10).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidBlocks`] if `blocks < 2`.
    pub fn with_blocks(mut self, blocks: usize) -> Result<Self> {
        self.runner.blocks = check_blocks(blocks)?;
        Ok(self)
    }

    /// Caps the accepted steps per interval (default 10⁷).
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) if `max_steps == 0`.
    pub fn with_max_steps_per_interval(mut self, max_steps: usize) -> Result<Self> {
        self.flow.max_steps = super::check_max_steps(max_steps)?;
        Ok(self)
    }

    /// Places the state at `(t0, y0)` and the tangent vectors at the first `K` (scaled)
    /// unit vectors.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] for a non-finite `t0` or `y0`;
    /// [`LyapunovError::NoJacobian`] if the system has no Jacobian at `(t0, y0)`.
    pub fn start(&mut self, t0: T, y0: SVector<T, N>) -> Result<()> {
        check_jacobian_at(self.flow.system.system(), t0, &y0)?;
        self.runner.start(&mut self.flow, t0, Frame::at(y0));
        Ok(())
    }

    /// Replaces the system, keeping the state and the tangent vectors.
    pub fn set_system(&mut self, system: S) {
        self.flow.system.set_system(system);
        if let Some((t, state)) = self.runner.current() {
            self.flow.restart(state, t);
        }
    }

    /// Restarts the clock at `t0`, keeping the state and the tangent vectors.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] if `t0` is not finite; [`LyapunovError::NotStarted`].
    pub fn set_time(&mut self, t0: T) -> Result<()> {
        self.runner.set_time(&mut self.flow, t0)
    }

    /// Runs `intervals` re-orthonormalization intervals of length `tau`, discarding them.
    ///
    /// A tangent vector that collapses onto the span of the previous ones within an
    /// interval (`R_jj = 0` in floating point: its contraction relative to them exceeds the
    /// range of `T`, as happens to a cart resting against a stop, where velocity
    /// perturbations decay at `~10⁶ s⁻¹`) is replaced by a unit vector orthogonal to them:
    /// transients only have to bring the state onto the attractor. In
    /// [`estimate`](Self::estimate) the same event is an error.
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate), except that 0 intervals are allowed (a no-op).
    pub fn transient(&mut self, tau: T, intervals: usize) -> Result<()> {
        self.runner
            .transient::<_, K>(&mut self.flow, tau, intervals)
    }

    /// Runs `intervals` intervals of length `tau` and returns the spectrum estimate.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidInterval`], [`LyapunovError::TooFewIntervals`] (fewer than
    /// 2), [`LyapunovError::NotStarted`], [`LyapunovError::TangentCollapse`] if a tangent
    /// vector degenerates within an interval (shorten `tau`), and integration errors (a
    /// non-finite right-hand side where the Jacobian is missing or infinite).
    pub fn estimate(&mut self, tau: T, intervals: usize) -> Result<Spectrum<T, K>> {
        Ok(self
            .runner
            .estimate::<_, K>(&mut self.flow, tau, intervals)?
            .spectrum())
    }

    /// The state `(t, y)`.
    pub fn state(&self) -> (T, SVector<T, N>) {
        (self.runner.t, self.runner.state.y)
    }

    /// The current tangent vectors in physical units (`Dψ_j`, orthonormal in the norm
    /// right after a re-orthonormalization).
    pub fn tangent_vectors(&self) -> SMatrix<T, N, K> {
        let w = self.norm.scales();
        let mut out = self.runner.state.psi;
        for c in 0..K {
            for i in 0..N {
                out[(i, c)] *= w[i];
            }
        }
        out
    }

    /// The system.
    pub fn system(&self) -> &S {
        self.flow.system.system()
    }

    /// The stepper.
    pub fn stepper(&self) -> &St {
        &self.flow.stepper
    }
}

/// Checks `(t0, y0)` and that the system has a Jacobian there.
///
/// # Errors
/// [`LyapunovError::NonFinite`], [`LyapunovError::NoJacobian`].
pub(crate) fn check_jacobian_at<T: Real, const N: usize, S: Dynamics<T, N>>(
    system: &S,
    t0: T,
    y0: &SVector<T, N>,
) -> Result<()> {
    check_state(t0, y0)?;
    if system.jacobian(t0, y0).is_none() {
        return Err(LyapunovError::NoJacobian { t: to_f64(t0) });
    }
    Ok(())
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
        use super::super::runner::reseed_columns;
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
