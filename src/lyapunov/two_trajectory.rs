//! The two-trajectory (Benettin) estimate of the top exponent, and the `d0` study.

use nalgebra::{SMatrix, SVector};

use super::Result;
use super::runner::{Augmented, Flow, Runner, Separation, Stepped};
use super::sizes::{Dims, PairDimension};
use super::{
    DEFAULT_MAX_STEPS_PER_INTERVAL, Estimate, LyapunovError, Norm, check_blocks, check_interval,
    check_intervals, check_state,
};
use crate::integrate::{Stepper, Tolerances};
use crate::scalar::{lit, to_f64};
use crate::{Dynamics, Real};

/// A reference trajectory and a perturbed copy as one system of dimension `M = 2N`: the
/// state is `(y, ỹ)` with `y` in components `0..N` and `ỹ` in `N..2N`.
///
/// Const-generic arithmetic (`M = 2 * N`) is not stable, so `M` is a separate parameter:
/// [`new`](Self::new) checks it, and the estimator's
/// [`from_tolerances`](TwoTrajectory::from_tolerances) infers it ([`PairDimension`]). The Jacobian (block diagonal) and the time derivative are
/// forwarded when the system has them, so implicit steppers work on the pair too.
///
/// ```
/// use nalgebra::SVector;
/// use nonsmooth::lyapunov::PerturbedPair;
/// use nonsmooth::testing::HarmonicOscillator;
/// use nonsmooth::Dynamics;
///
/// let pair = PerturbedPair::<_, 2, 4>::new(HarmonicOscillator::new(1.0)?)?;
/// let mut dy = SVector::<f64, 4>::zeros();
/// pair.rhs(0.0, &SVector::<f64, 4>::new(1.0, 0.0, 2.0, 0.0), &mut dy);
/// assert_eq!(dy, SVector::<f64, 4>::new(0.0, -1.0, 0.0, -2.0));
/// assert!(PerturbedPair::<_, 2, 5>::new(HarmonicOscillator::new(1.0)?).is_err());
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerturbedPair<S, const N: usize, const M: usize> {
    system: S,
}

impl<S, const N: usize, const M: usize> PerturbedPair<S, N, M> {
    /// Wraps `system`.
    ///
    /// # Errors
    /// [`LyapunovError::Dimension`] unless `M == 2·N` and `N ≥ 1`.
    pub fn new(system: S) -> Result<Self, LyapunovError> {
        check_pair_dims::<N, M>()?;
        Ok(Self { system })
    }

    /// The wrapped system.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// Replaces the wrapped system.
    pub fn set_system(&mut self, system: S) {
        self.system = system;
    }

    /// The wrapped system, by value.
    pub fn into_inner(self) -> S {
        self.system
    }

    /// Splits an augmented state into `(y, ỹ)`.
    #[inline(always)]
    pub fn split<T: Real>(&self, z: &SVector<T, M>) -> (SVector<T, N>, SVector<T, N>) {
        let mut a = SVector::<T, N>::zeros();
        let mut b = SVector::<T, N>::zeros();
        for i in 0..N {
            a[i] = z[i];
            b[i] = z[N + i];
        }
        (a, b)
    }

    /// Joins `(y, ỹ)` into an augmented state.
    #[inline(always)]
    pub fn join<T: Real>(&self, a: &SVector<T, N>, b: &SVector<T, N>) -> SVector<T, M> {
        let mut z = SVector::<T, M>::zeros();
        for i in 0..N {
            z[i] = a[i];
            z[N + i] = b[i];
        }
        z
    }
}

impl<T: Real, S: Dynamics<T, N>, const N: usize, const M: usize> Dynamics<T, M>
    for PerturbedPair<S, N, M>
{
    #[inline(always)]
    fn rhs(&self, t: T, z: &SVector<T, M>, dz: &mut SVector<T, M>) {
        let (a, b) = self.split(z);
        let mut da = SVector::<T, N>::zeros();
        let mut db = SVector::<T, N>::zeros();
        self.system.rhs(t, &a, &mut da);
        self.system.rhs(t, &b, &mut db);
        for i in 0..N {
            dz[i] = da[i];
            dz[N + i] = db[i];
        }
    }

    fn jacobian(&self, t: T, z: &SVector<T, M>) -> Option<SMatrix<T, M, M>> {
        let (a, b) = self.split(z);
        let ja = self.system.jacobian(t, &a)?;
        let jb = self.system.jacobian(t, &b)?;
        let mut j = SMatrix::<T, M, M>::zeros();
        for r in 0..N {
            for c in 0..N {
                j[(r, c)] = ja[(r, c)];
                j[(N + r, N + c)] = jb[(r, c)];
            }
        }
        Some(j)
    }

    fn time_derivative(&self, t: T, z: &SVector<T, M>) -> Option<SVector<T, M>> {
        let (a, b) = self.split(z);
        let da = self.system.time_derivative(t, &a)?;
        let db = self.system.time_derivative(t, &b)?;
        Some(self.join(&da, &db))
    }
}

/// Validates `M == 2N`, `d0` and the norm.
pub(crate) fn check_pair_settings<T: Real, const N: usize, const M: usize>(
    d0: T,
    norm: &Norm<T, N>,
) -> Result<(), LyapunovError> {
    check_pair_dims::<N, M>()?;
    if !(d0.is_finite() && d0 > T::zero()) {
        return Err(LyapunovError::InvalidSeparation { d0: to_f64(d0) });
    }
    norm.validate()
}

impl<T: Real, S, const N: usize, const M: usize> Augmented<T, M, Separation<T, N>>
    for PerturbedPair<S, N, M>
{
    #[inline]
    fn pack(&self, state: &Separation<T, N>) -> SVector<T, M> {
        self.join(&state.reference, &state.perturbed)
    }

    #[inline]
    fn unpack(&self, z: &SVector<T, M>, state: &mut Separation<T, N>) {
        (state.reference, state.perturbed) = self.split(z);
    }
}

/// The tolerances of a [`PerturbedPair`]: the system's tolerances for both copies.
///
/// The pair's dimension `M = 2N` is inferred (a wrong `M` does not compile, see
/// [`PairDimension`]):
/// ```
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::lyapunov::pair_tolerances;
/// let pair = Dopri5::new(pair_tolerances(&Tolerances::per_component(1e-9, [1e-12, 1e-10])?)?);
/// assert_eq!(pair.tolerances().atol.len(), 4);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
///
/// # Errors
/// [`LyapunovError::Dimension`] for `N = 0`.
pub fn pair_tolerances<T: Real, const N: usize, const M: usize>(
    tol: &Tolerances<T, N>,
) -> Result<Tolerances<T, M>, LyapunovError>
where
    Dims<N>: PairDimension<M>,
{
    check_pair_dims::<N, M>()?;
    Ok(doubled(tol))
}

fn check_pair_dims<const N: usize, const M: usize>() -> Result<(), LyapunovError> {
    if N == 0 || M != 2 * N {
        return Err(LyapunovError::Dimension {
            what: "two trajectories (M = 2N)",
            n: N,
            expected: 2 * N,
            found: M,
        });
    }
    Ok(())
}

/// `tol` for both copies (`M = 2N`, checked by the caller).
fn doubled<T: Real, const N: usize, const M: usize>(tol: &Tolerances<T, N>) -> Tolerances<T, M> {
    let mut rtol = SVector::<T, M>::zeros();
    let mut atol = SVector::<T, M>::zeros();
    for i in 0..N {
        rtol[i] = tol.rtol[i];
        rtol[N + i] = tol.rtol[i];
        atol[i] = tol.atol[i];
        atol[N + i] = tol.atol[i];
    }
    Tolerances { rtol, atol }
}

/// The two-trajectory (Benettin) estimator of the top Lyapunov exponent.
///
/// Owns the [`PerturbedPair`] and a stepper for it (`St: Stepper<T, M>`). Use it in three
/// stages — [`start`](Self::start) at an initial state, [`transient`](Self::transient)
/// intervals (the pair is renormalized but nothing is recorded, which also turns the
/// separation towards the most expanding direction), then [`estimate`](Self::estimate).
/// For continuation in a parameter, [`set_system`](Self::set_system) and
/// [`set_time`](Self::set_time) keep the state (and the separation) of the pair.
///
/// Build it from the system's tolerances with [`from_tolerances`](Self::from_tolerances):
/// the pair's size `M = 2N` is then inferred, no size is written.
///
/// See the [module docs](super) for the formula and an example.
#[derive(Debug, Clone)]
pub struct TwoTrajectory<T: Real, const N: usize, const M: usize, S, St> {
    flow: Stepped<PerturbedPair<S, N, M>, St, M>,
    runner: Runner<T, Separation<T, N>>,
}

impl<T, const N: usize, const M: usize, S, St> TwoTrajectory<T, N, M, S, St>
where
    T: Real,
    S: Dynamics<T, N>,
    St: Stepper<T, M>,
{
    /// An estimator with separation `d0` (in `norm`), initial perturbation along
    /// `(w_1, …, w_N)` (equal in every scaled component), 10 blocks for the spread and at
    /// most 10⁷ steps per interval.
    ///
    /// # Errors
    /// [`LyapunovError::Dimension`] unless `M == 2·N`; [`LyapunovError::InvalidSeparation`]
    /// unless `d0` is finite and > 0; [`LyapunovError::InvalidWeight`] for a bad norm.
    pub fn new(system: S, stepper: St, d0: T, norm: Norm<T, N>) -> Result<Self> {
        check_pair_settings::<T, N, M>(d0, &norm)?;
        Ok(Self {
            flow: Stepped {
                system: PerturbedPair::new(system)?,
                stepper,
                max_steps: DEFAULT_MAX_STEPS_PER_INTERVAL,
            },
            runner: Runner::new(Separation::new(d0, norm)?),
        })
    }

    /// An estimator whose stepper is built from the system's tolerances: `make_stepper`
    /// receives them doubled for the pair ([`pair_tolerances`]); the sizes are written
    /// (for code generic in them, where [`from_tolerances`](Self::from_tolerances) would
    /// need the bound `Dims<N>: PairDimension<M>`) and `M` is checked when called.
    ///
    /// ```
    /// use nonsmooth::integrate::{Dopri5, Tolerances};
    /// use nonsmooth::lyapunov::{Norm, TwoTrajectory};
    /// use nonsmooth::systems::DuffingUeda;
    /// let tol = Tolerances::new(1e-8, 1e-10)?;
    /// let est = TwoTrajectory::<_, 2, 4, _, _>::with_tolerances(
    ///     DuffingUeda::default().model::<f64>()?,
    ///     Dopri5::new,
    ///     &tol,
    ///     1e-8,
    ///     Norm::weighted([1.0, 2.0])?,
    /// )?;
    /// # drop(est);
    /// # Ok::<(), nonsmooth::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn with_tolerances(
        system: S,
        make_stepper: impl FnOnce(Tolerances<T, M>) -> St,
        tol: &Tolerances<T, N>,
        d0: T,
        norm: Norm<T, N>,
    ) -> Result<Self> {
        check_pair_dims::<N, M>()?;
        Self::new(system, make_stepper(doubled(tol)), d0, norm)
    }

    /// An estimator whose stepper is built from the system's tolerances `tol`
    /// (`make_stepper`, e.g. `Dopri5::new`, receives them doubled for the pair), with the pair's size
    /// `M = 2N` inferred: no size is written, and a wrong `M` does not compile
    /// ([`PairDimension`]).
    ///
    /// ```
    /// use nalgebra::Vector3;
    /// use nonsmooth::integrate::{Dopri5, Tolerances};
    /// use nonsmooth::lyapunov::{Norm, TwoTrajectory};
    /// use nonsmooth::testing::Lorenz;
    ///
    /// let lorenz = Lorenz::new(10.0, 28.0, 8.0 / 3.0)?;
    /// let tol = Tolerances::new(1e-9, 1e-9)?;
    /// let mut est = TwoTrajectory::from_tolerances(lorenz, &tol, Dopri5::new, 1e-8, Norm::Euclidean)?;
    /// est.start(0.0, Vector3::new(1.0, 1.0, 20.0))?;
    /// est.transient(1.0, 5)?;
    /// let e = est.estimate(1.0, 20)?;
    /// assert!(e.exponent > 0.0);
    /// # Ok::<(), nonsmooth::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`new`](Self::new).
    pub fn from_tolerances(
        system: S,
        tol: &Tolerances<T, N>,
        make_stepper: impl FnOnce(Tolerances<T, M>) -> St,
        d0: T,
        norm: Norm<T, N>,
    ) -> Result<Self>
    where
        Dims<N>: PairDimension<M>,
    {
        Self::with_tolerances(system, make_stepper, tol, d0, norm)
    }

    /// Sets the direction of the initial perturbation (any non-zero finite vector; it is
    /// scaled to length `d0` in the norm).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidDirection`] if it is zero or not finite.
    pub fn with_direction(mut self, direction: SVector<T, N>) -> Result<Self> {
        self.runner.state.set_direction(direction)?;
        Ok(self)
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

    /// Places the reference at `(t0, y0)` and the perturbed trajectory at
    /// `y0 + d0·e` (`e` the unit perturbation direction).
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] for a non-finite `t0` or `y0`;
    /// [`LyapunovError::UnresolvedSeparation`] if `d0` is lost to rounding at `y0`.
    pub fn start(&mut self, t0: T, y0: SVector<T, N>) -> Result<()> {
        check_state(t0, &y0)?;
        let placed = self.runner.state.placed(y0)?;
        self.runner.start(&mut self.flow, t0, placed);
        Ok(())
    }

    /// Replaces the system (e.g. the next parameter value of a continuation); the pair's
    /// state is kept.
    pub fn set_system(&mut self, system: S) {
        self.flow.system.set_system(system);
        if let Some((t, state)) = self.runner.current() {
            self.flow.restart(state, t);
        }
    }

    /// Restarts the clock at `t0`, keeping the pair's state (for forced systems started
    /// afresh at phase 0 after a parameter step).
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] if `t0` is not finite; [`LyapunovError::NotStarted`].
    pub fn set_time(&mut self, t0: T) -> Result<()> {
        self.runner.set_time(&mut self.flow, t0)
    }

    /// Runs `intervals` renormalization intervals of length `tau` and discards them.
    ///
    /// A separation that collapses to exactly zero within an interval (lost to rounding in
    /// a strongly contracting phase — e.g. a cart resting against a stop, where a contact
    /// damping contracts velocity differences at `~10⁶ s⁻¹`) is re-seeded along the initial
    /// direction: transients only have to bring the pair onto the attractor. In
    /// [`estimate`](Self::estimate) the same event is an error.
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate), except that 0 intervals are allowed (a no-op).
    pub fn transient(&mut self, tau: T, intervals: usize) -> Result<()> {
        self.runner
            .transient::<_, 1>(&mut self.flow, tau, intervals)
    }

    /// Runs `intervals` renormalization intervals of length `tau` and returns the estimate.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidInterval`], [`LyapunovError::TooFewIntervals`] (fewer than
    /// 2), [`LyapunovError::NotStarted`], [`LyapunovError::SeparationLost`] if the
    /// separation collapses or overflows, and integration errors.
    pub fn estimate(&mut self, tau: T, intervals: usize) -> Result<Estimate<T>> {
        Ok(self
            .runner
            .estimate::<_, 1>(&mut self.flow, tau, intervals)?
            .estimate())
    }

    /// The reference state `(t, y)`.
    pub fn reference(&self) -> (T, SVector<T, N>) {
        (self.runner.t, self.runner.state.reference)
    }

    /// The current separation `ỹ − y` (length `d0` right after a renormalization).
    pub fn separation(&self) -> SVector<T, N> {
        self.runner.state.delta()
    }

    /// The separation `d0`.
    pub fn d0(&self) -> T {
        self.runner.state.d0
    }

    /// The norm.
    pub fn norm(&self) -> &Norm<T, N> {
        &self.runner.state.norm
    }

    /// The system.
    pub fn system(&self) -> &S {
        self.flow.system.system()
    }

    /// The stepper (its [`stats`](Stepper::stats) count all work so far).
    pub fn stepper(&self) -> &St {
        &self.flow.stepper
    }
}

/// One row of a [`separation_study`].
#[derive(Debug, Clone)]
pub struct SeparationPoint<T> {
    /// The separation used.
    pub d0: T,
    /// The estimate obtained with it, or why it failed (e.g. a separation lost to rounding
    /// at too small a `d0`: that is a result of the study too).
    pub estimate: Result<Estimate<T>>,
}

/// `per_decade` logarithmically spaced values per decade from `10^lo` to `10^hi`
/// (inclusive), computed from the index (no accumulation). Decades are clamped to
/// `10⁻³⁰⁷ … 10³⁰⁸` (beyond, a value is 0 or ∞) and `per_decade` so that at most about 10⁶
/// values are returned.
///
/// ```
/// let d = nonsmooth::lyapunov::decades::<f64>(-9, -6, 1);
/// assert_eq!(d.len(), 4);
/// assert!((d[0] - 1e-9).abs() < 1e-24 && (d[3] - 1e-6).abs() < 1e-21);
/// ```
pub fn decades<T: Real>(lo: i32, hi: i32, per_decade: usize) -> Vec<T> {
    if hi < lo || per_decade == 0 {
        return Vec::new();
    }
    // Decades outside the normal f64 range give 0 or ∞, never a separation: clamp them,
    // and bound the count (at most 10⁶ values).
    let (lo, hi) = (lo.max(-307), hi.min(308));
    if hi < lo {
        return Vec::new();
    }
    let per_decade = per_decade.min(1_000_000 / (hi - lo).max(1) as usize).max(1);
    let n = (hi - lo) as usize * per_decade;
    (0..=n)
        .map(|i| lit::<T>(10f64.powf(lo as f64 + i as f64 / per_decade as f64)))
        .collect()
}

/// The `d0` study: the two-trajectory estimate for each separation in `d0s`, each from the
/// same initial state `(t0, y0)` with `transient` discarded intervals and `intervals`
/// recorded ones of length `tau`.
///
/// Choose `d0` where the estimates are flat within their spreads. Too small a `d0` lets the
/// integration and rounding errors of the difference dominate (the estimate drifts or
/// scatters); too large a `d0` makes the pair non-local (for chaotic attractors the
/// estimate drops, since finite separations saturate at the attractor's size). Runs the
/// values in parallel with feature `parallel`; the results do not depend on it.
///
/// # Study on the paper's model
/// See [`systems::paper::lyapunov::D0`](crate::systems::paper::lyapunov::D0) for the table at four frequencies and the reasons for
/// both ends of the plateau.
///
/// # Errors
/// The settings are validated first ([`LyapunovError::Dimension`],
/// [`LyapunovError::InvalidWeight`], [`LyapunovError::InvalidInterval`],
/// [`LyapunovError::TooFewIntervals`], [`LyapunovError::NonFinite`],
/// [`LyapunovError::InvalidSeparation`] for any `d0`); a failure of a single run is
/// reported in its [`SeparationPoint::estimate`].
#[allow(clippy::too_many_arguments)]
pub fn separation_study<T, const N: usize, const M: usize, S, St>(
    system: &S,
    stepper: &St,
    norm: Norm<T, N>,
    t0: T,
    y0: SVector<T, N>,
    d0s: &[T],
    tau: T,
    transient: usize,
    intervals: usize,
) -> Result<Vec<SeparationPoint<T>>>
where
    T: Real,
    S: Dynamics<T, N> + Sync,
    St: Stepper<T, M> + Clone + Send + Sync,
{
    check_interval(tau)?;
    check_intervals(intervals, 2)?;
    check_state(t0, &y0)?;
    for &d0 in d0s {
        check_pair_settings::<T, N, M>(d0, &norm)?;
    }
    let one = |d0: T| -> SeparationPoint<T> {
        let run = || -> Result<Estimate<T>> {
            let mut est = TwoTrajectory::<T, N, M, &S, St>::new(system, stepper.clone(), d0, norm)?;
            est.start(t0, y0)?;
            est.transient(tau, transient)?;
            est.estimate(tau, intervals)
        };
        SeparationPoint {
            d0,
            estimate: run(),
        }
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        Ok(d0s.par_iter().map(|&d0| one(d0)).collect())
    }
    #[cfg(not(feature = "parallel"))]
    {
        Ok(d0s.iter().map(|&d0| one(d0)).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Dopri5, Rk4};
    use nalgebra::Vector2;

    /// `ẏ = a·y` in 1-D: the exponent is `a` exactly.
    struct Linear(f64);
    impl Dynamics<f64, 1> for Linear {
        fn rhs(&self, _t: f64, y: &SVector<f64, 1>, dy: &mut SVector<f64, 1>) {
            dy[0] = self.0 * y[0];
        }
    }

    /// A 2-D linear system `ẏ = diag(a, b)·y`.
    struct Diag(f64, f64);
    impl Dynamics<f64, 2> for Diag {
        fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
            dy[0] = self.0 * y[0];
            dy[1] = self.1 * y[1];
        }
    }

    #[test]
    fn linear_growth_and_decay_are_exact_per_interval() {
        for a in [0.7, -1.3] {
            let tol =
                pair_tolerances::<f64, 1, 2>(&Tolerances::new(1e-12, 1e-14).unwrap()).unwrap();
            let mut est = TwoTrajectory::<f64, 1, 2, _, _>::new(
                Linear(a),
                Dopri5::new(tol),
                1e-3,
                Norm::Euclidean,
            )
            .unwrap();
            est.start(0.0, SVector::<f64, 1>::new(1.0)).unwrap();
            let e = est.estimate(0.5, 20).unwrap();
            assert!((e.exponent - a).abs() < 1e-9, "{}", e.exponent);
            assert!(e.local.iter().all(|s| (s - a).abs() < 1e-9));
            assert_eq!(e.history.len(), 20);
            assert_eq!(*e.history.last().unwrap(), e.exponent);
            assert!(e.spread < 1e-9);
            assert_eq!(est.reference().0, 10.0);
            // d0 up to the rounding of ỹ = y + δ: |y|·ε ≈ e^{7}·2.2e-16 ≈ 2.4e-13 for a > 0.
            let y = est.reference().1[0].abs().max(1.0);
            let err = (est.norm().norm(&est.separation()) - 1e-3).abs();
            assert!(err <= 2.0 * y * f64::EPSILON, "{err:e}");
        }
    }

    #[test]
    fn separation_aligns_with_the_most_expanding_direction() {
        // Start along (1, 1): the first intervals mix both rates, then λ1 = 0.5 wins.
        let mut est = TwoTrajectory::<f64, 2, 4, _, _>::new(
            Diag(0.5, -2.0),
            Rk4::new(0.01).unwrap(),
            1e-6,
            Norm::Euclidean,
        )
        .unwrap();
        est.start(0.0, Vector2::new(0.0, 0.0)).unwrap();
        est.transient(1.0, 10).unwrap();
        let e = est.estimate(1.0, 10).unwrap();
        assert!((e.exponent - 0.5).abs() < 1e-8, "{}", e.exponent);
        let s = est.separation();
        assert!(s[1].abs() < 1e-6 * s[0].abs());
    }

    #[test]
    fn rejects_bad_input() {
        let tol = pair_tolerances::<f64, 1, 2>(&Tolerances::new(1e-8, 1e-8).unwrap()).unwrap();
        let mk = |d0: f64| {
            TwoTrajectory::<f64, 1, 2, _, _>::new(
                Linear(1.0),
                Dopri5::new(tol),
                d0,
                Norm::Euclidean,
            )
        };
        for d0 in [0.0, -1e-6, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                mk(d0),
                Err(LyapunovError::InvalidSeparation { .. })
            ));
        }
        let mut est = mk(1e-6).unwrap();
        assert!(matches!(
            est.estimate(1.0, 10),
            Err(LyapunovError::NotStarted)
        ));
        assert!(matches!(
            est.start(0.0, SVector::<f64, 1>::new(f64::NAN)),
            Err(LyapunovError::NonFinite { what: "y0[0]", .. })
        ));
        // d0 far below the rounding of the state.
        assert!(matches!(
            est.start(0.0, SVector::<f64, 1>::new(1e12)),
            Err(LyapunovError::UnresolvedSeparation { .. })
        ));
        est.start(0.0, SVector::<f64, 1>::new(1.0)).unwrap();
        for n in [0, 1] {
            assert!(matches!(
                est.estimate(1.0, n),
                Err(LyapunovError::TooFewIntervals { .. })
            ));
        }
        assert!(matches!(
            est.estimate(0.0, 5),
            Err(LyapunovError::InvalidInterval { .. })
        ));
        assert!(est.transient(1.0, 0).is_ok());
        assert!(
            TwoTrajectory::<f64, 1, 3, _, _>::new(
                Linear(1.0),
                Dopri5::new(Tolerances::new(1e-8, 1e-8).unwrap()),
                1e-6,
                Norm::Euclidean
            )
            .is_err()
        );
        // pair_tolerances::<f64, 2, 3> does not compile (Dims<2>: PairDimension<3> fails).
        assert!(mk(1e-6).unwrap().with_blocks(1).is_err());
        assert!(
            mk(1e-6)
                .unwrap()
                .with_direction(SVector::<f64, 1>::zeros())
                .is_err()
        );
        assert!(mk(1e-6).unwrap().set_time(0.0).is_err());
    }

    #[test]
    fn collapse_is_reported() {
        // Decay e^{-800·τ} underflows the separation to zero within one interval.
        let tol = pair_tolerances::<f64, 1, 2>(&Tolerances::new(1e-6, 1e-300).unwrap()).unwrap();
        let mut est = TwoTrajectory::<f64, 1, 2, _, _>::new(
            Linear(-800.0),
            Dopri5::new(tol),
            1e-3,
            Norm::Euclidean,
        )
        .unwrap();
        est.start(0.0, SVector::<f64, 1>::new(1.0)).unwrap();
        // Transients re-seed the collapsed separation; estimates report it.
        est.transient(1.0, 2).unwrap();
        assert!((est.norm().norm(&est.separation()) - 1e-3).abs() < 1e-15);
        let r = est.estimate(1.0, 4);
        assert!(
            matches!(r, Err(LyapunovError::SeparationLost { .. })),
            "{r:?}"
        );
    }

    #[test]
    fn decades_grid() {
        let d = decades::<f64>(-3, -1, 2);
        assert_eq!(d.len(), 5);
        assert!((d[1] - 10f64.powf(-2.5)).abs() < 1e-18);
        assert!(decades::<f64>(1, 0, 1).is_empty());
        assert!(decades::<f64>(0, 1, 0).is_empty());
    }
}
