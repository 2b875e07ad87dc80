//! Periodic orbits of periodically forced systems by shooting, their monodromy matrix and
//! Floquet multipliers — stable and unstable orbits alike, with contact (compliant laws) and
//! rigid impacts (resets, through saltation matrices).
//!
//! # Method
//! For forcing of period `T` the stroboscopic map `P(y) = φ(t₀ + kT; t₀, y)` (the flow over
//! `k` periods) has the orbit's point as a fixed point. Newton's method on
//! `F(y) = P(y) − y` needs `∂P/∂y = Φ`, the monodromy matrix, which is integrated with the
//! state: the variational equations `Φ̇ = J(t, y)Φ`, `Φ(t₀) = I` between events
//! ([`Variational`]), and `Φ⁺ = S Φ⁻` across each reset, `S` the saltation matrix
//! ([`Saltation`]). Each iteration solves `(Φ − I)Δ = −F` and takes the step with
//! backtracking on `‖F‖`. The orbit is converged when every component of the step is
//! within the state's integration tolerance `atol_i + rtol_i|y_i|` (the flow itself is not
//! more accurate).
//!
//! The eigenvalues `μ` of `Φ` at the converged orbit are its Floquet multipliers: the orbit
//! is asymptotically stable if all `|μ| < 1`; a real `μ` leaving through `+1` is a fold, through
//! `−1` a period doubling, a complex pair a Neimark–Sacker bifurcation. The orbit's Lyapunov
//! exponents are `ln|μ_j| / (kT)`. Liouville's formula gives an exact check:
//! `Π μ_j = det Φ = exp(∫ tr J dt) · Π det S` (e.g. `e^{−c kT/m}` for a linear damper).
//!
//! Newton does not care about stability: started near a saddle it converges to the saddle,
//! an orbit no forward simulation shows. On a strongly unstable orbit (`|μ| ≫ 1`) one shot
//! over the whole period amplifies the start's error by `|μ|` into the nonlinear range;
//! [`Shooting::find_multiple`] cuts the period into `m` segments, each amplifying it only by
//! `|μ|^{1/m}`, and solves for all segment starts `yᵢ` at once:
//! `φᵢ(yᵢ) − y₍ᵢ₊₁₎ mod m = 0`, Jacobian blocks `Φᵢ` and `−I`, `Φ = Φ_{m−1}⋯Φ₀`.
//!
//! Orbits of forced Filippov systems (crossings and sliding) are followed by
//! [`sliding::follow_sliding`], shooting through
//! [`FilippovSimulation::find_orbit`](crate::filippov::FilippovSimulation::find_orbit),
//! with the sliding bifurcations located on the branch as zeros of their test functions.
//!
//! # Example
//! A forced linear oscillator `ẍ + 2ζẋ + x = cos ωt`: its periodic orbit is the steady state,
//! its multipliers `e^{(−ζ ± i√(1−ζ²))T}`.
//! ```
//! use nalgebra::SVector;
//! use nonsmooth::excite::Harmonic;
//! use nonsmooth::force::{LinearSpring, ViscousDamper};
//! use nonsmooth::integrate::Tolerances;
//! use nonsmooth::lyapunov::tangent_tolerances;
//! use nonsmooth::model::{Element, Load, Mechanical};
//! use nonsmooth::orbit::Shooting;
//!
//! let (zeta, omega) = (0.05, 1.3);
//! let model = Mechanical::with_masses([1.0])?
//!     .with_elements(Element::on_dof(0, (LinearSpring::new(1.0)?, ViscousDamper::new(2.0 * zeta)?))?)
//!     .with_loads(Load::on_dof(0, Harmonic::cosine(1.0, omega)?)?);
//! let tol = Tolerances::new(1e-11, 1e-13)?;
//! let shooting = Shooting::new(model, (), tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-11, 1e-13)?);
//! let period = std::f64::consts::TAU / omega;
//! let orbit = shooting.find(0.0, period, SVector::from([0.0, 0.0]))?;
//! // Steady state x = A cos(ωt − δ): at t = 0, x = A cos δ = (1 − ω²)/((1 − ω²)² + (2ζω)²).
//! let d = (1.0 - omega * omega).powi(2) + (2.0 * zeta * omega).powi(2);
//! assert!((orbit.state[0] - (1.0 - omega * omega) / d).abs() < 1e-9);
//! let modulus = (-zeta * period).exp();
//! for mu in &orbit.multipliers {
//!     assert!((mu.norm() - modulus).abs() < 1e-9);
//! }
//! assert!(orbit.is_stable());
//! # Ok::<(), nonsmooth::Error>(())
//! ```

use nalgebra::{Complex, DMatrix, SMatrix, SVector};

use crate::Real;
use crate::drive::RunError;
use crate::drive::Simulation;
use crate::dynamics::Dynamics;
use crate::event::EventSet;
use crate::integrate::{Dopri5, Tolerances};
use crate::linalg::Lu;
use crate::lyapunov::{LyapunovError, Norm, Saltation, Variational};
use crate::scalar::{lit, to_f64};

pub mod continuation;
pub mod sliding;

pub use continuation::{
    Bifurcation, BifurcationKind, Branch, BranchEnd, BranchPoint, ContinuationSettings, Grazing,
    follow, period_doubled,
};

/// Why a periodic-orbit computation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OrbitError {
    /// Newton's method did not converge.
    #[error(
        "periodic orbit: Newton did not converge in {iterations} iterations (last step {step:e} \
         tolerances, residual {residual:e}); start closer to the orbit or check its period"
    )]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// The last step in units of the integration tolerance.
        step: f64,
        /// `‖P(y) − y‖∞` at the last iterate.
        residual: f64,
    },
    /// `Φ − I` is singular: a multiplier is exactly 1 (a fold, or an autonomous direction).
    #[error("periodic orbit: Φ − I is singular at iteration {iteration} (a multiplier at +1)")]
    Singular {
        /// The iteration.
        iteration: usize,
    },
    /// A parameter is invalid.
    #[error("periodic orbit: {what} must be {requirement} (got {value})")]
    InvalidSetting {
        /// Which setting.
        what: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value.
        value: f64,
    },
    /// A run failed (the integration, the events, a rejected setting), or the system could
    /// not be built. Converts into the crate's [`Error`](crate::Error) as the run's error
    /// itself (`Error::Integrate(..)`, …).
    #[error(transparent)]
    Run(#[from] RunError),
    /// The variational system (state and monodromy matrix) could not be set up.
    #[error(transparent)]
    Lyapunov(#[from] LyapunovError),
    /// A builder of the problem at a parameter value failed with an error of another layer
    /// (its message).
    #[error("building the problem failed: {0}")]
    Build(String),
    /// A run or shooting of a Filippov system failed where only sliding motion can fail
    /// (two surfaces met at once, a repelling surface, no convergence of the shooting, …);
    /// its engine errors are [`Run`](Self::Run).
    #[error(transparent)]
    Filippov(crate::filippov::FilippovError),
}

impl From<crate::filippov::FilippovError> for OrbitError {
    /// The engine's errors as [`Run`](OrbitError::Run), the rest as
    /// [`Filippov`](OrbitError::Filippov).
    fn from(e: crate::filippov::FilippovError) -> Self {
        match e {
            crate::filippov::FilippovError::Run(e) => OrbitError::Run(e),
            e => OrbitError::Filippov(e),
        }
    }
}

/// `Result` with [`OrbitError`].
pub(crate) type Result<T, E = OrbitError> = std::result::Result<T, E>;

crate::drive::from_engine_errors!(OrbitError);

/// A periodic orbit found by [`Shooting::find`].
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodicOrbit<T: Real, const N: usize> {
    /// The section time `t₀` (the orbit's point is taken there).
    pub t0: T,
    /// The orbit's period `kT`.
    pub period: T,
    /// The state at `t₀` (and at `t₀ + kT`).
    pub state: SVector<T, N>,
    /// The monodromy matrix `Φ = ∂P/∂y` at the orbit.
    pub monodromy: SMatrix<T, N, N>,
    /// The Floquet multipliers (eigenvalues of `Φ`), largest modulus first.
    pub multipliers: Vec<Complex<T>>,
    /// Newton iterations used.
    pub iterations: usize,
    /// `‖P(y) − y‖∞` at the returned state.
    pub residual: T,
}

impl<T: Real, const N: usize> PeriodicOrbit<T, N> {
    /// Asymptotically stable: every multiplier inside the unit circle.
    pub fn is_stable(&self) -> bool {
        self.multipliers.iter().all(|m| modulus(m) < T::one())
    }

    /// The orbit's Lyapunov exponents `ln|μ_j| / period`, largest first.
    pub fn exponents(&self) -> Vec<T> {
        self.multipliers
            .iter()
            .map(|m| modulus(m).ln() / self.period)
            .collect()
    }

    /// The top Lyapunov exponent `ln max|μ| / period`.
    pub fn top_exponent(&self) -> T {
        modulus(&self.multipliers[0]).ln() / self.period
    }
}

/// Periodic orbits of `system` (with the events `events`, `()` for none) by shooting on
/// the stroboscopic map; see the [module docs](self).
///
/// `M = N + N²` is the size of the state with its monodromy matrix; it is fixed by the
/// tolerances, e.g. [`tangent_tolerances::<f64, 2, 2, 6>`](crate::lyapunov::tangent_tolerances)
/// (the first `N` components are the state's, the rest the matrix's).
#[derive(Debug, Clone)]
pub struct Shooting<T: Real, S, E, const N: usize, const M: usize> {
    system: S,
    events: E,
    tolerances: Tolerances<T, M>,
    max_iterations: usize,
    newton_tolerance: f64,
}

impl<T, S, E, const N: usize, const M: usize> Shooting<T, S, E, N, M>
where
    T: Real,
    S: Dynamics<T, N> + Clone,
    E: EventSet<T, N> + Clone,
{
    /// Shooting on `system` with `events`, integrating the state and its monodromy matrix
    /// with DOPRI5 at `tolerances`; at most 50 Newton iterations, converged at 100× the
    /// integration tolerance ([`with_newton_tolerance`](Self::with_newton_tolerance)).
    pub fn new(system: S, events: E, tolerances: Tolerances<T, M>) -> Self {
        Self {
            system,
            events,
            tolerances,
            max_iterations: 50,
            newton_tolerance: 100.0,
        }
    }

    /// Sets the convergence threshold: Newton stops when every component of its step is
    /// within `factor` times the state's integration tolerance `atol_i + rtol_i|y_i|`
    /// (default 100: the map `P` carries the global error of the flow, a small multiple
    /// of the local tolerance).
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless `factor` is finite and `> 0`.
    pub fn with_newton_tolerance(mut self, factor: f64) -> Result<Self> {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(OrbitError::InvalidSetting {
                what: "the Newton tolerance factor",
                requirement: "finite and > 0",
                value: factor,
            });
        }
        self.newton_tolerance = factor;
        Ok(self)
    }

    /// Sets the Newton iteration cap.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] for 0.
    pub fn with_max_iterations(mut self, iterations: usize) -> Result<Self> {
        if iterations == 0 {
            return Err(OrbitError::InvalidSetting {
                what: "the iteration cap",
                requirement: "at least 1",
                value: 0.0,
            });
        }
        self.max_iterations = iterations;
        Ok(self)
    }

    /// The flow over `span` from `(t0, y0)` and its Jacobian `∂y(t0 + span)/∂y0` (through
    /// the events' resets).
    ///
    /// # Errors
    /// Integration and event errors of the run; [`LyapunovError`]
    /// if `M ≠ N + N²` or the system has no Jacobian.
    pub fn flow(
        &self,
        t0: T,
        y0: SVector<T, N>,
        span: T,
    ) -> Result<(SVector<T, N>, SMatrix<T, N, N>)> {
        let var = Variational::<T, S, N, N, M>::new(self.system.clone(), Norm::Euclidean)?;
        let lifted = Saltation::<T, S, E, N, N>::new(
            self.system.clone(),
            self.events.clone(),
            SVector::repeat(T::one()),
        );
        let z0 = var.join(&y0, &SMatrix::<T, N, N>::identity());
        let mut sim = Simulation::new(var, Dopri5::new(self.tolerances)).with_events(lifted);
        let out = sim.run(t0, z0, t0 + span, &mut ())?;
        let (y, phi) = sim.system().split(&out.y);
        Ok((y, phi))
    }

    /// The state after `span` from `(t0, y0)` through the events' resets, without the
    /// monodromy matrix (the map `P` alone: `N` instead of `N + N²` components, at the
    /// state's tolerances).
    ///
    /// # Errors
    /// Integration and event errors of the run.
    pub fn map(&self, t0: T, y0: SVector<T, N>, span: T) -> Result<SVector<T, N>> {
        let mut sim = Simulation::new(self.system.clone(), Dopri5::new(self.state_tolerances()))
            .with_events(self.events.clone());
        Ok(sim.run(t0, y0, t0 + span, &mut ())?.y)
    }

    /// The periodic orbit of period `period` (the forcing period `T` times `k` for a
    /// period-`k` orbit) through the section at `t0`, by Newton's method from `guess`.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] for a period that is not finite and `> 0`,
    /// [`OrbitError::Singular`], [`OrbitError::NotConverged`], and the errors of
    /// [`flow`](Self::flow).
    pub fn find(&self, t0: T, period: T, guess: SVector<T, N>) -> Result<PeriodicOrbit<T, N>> {
        check_period(period)?;
        let mut y = guess;
        let (p, mut phi) = self.flow(t0, y, period)?;
        let mut residual = p - y;
        let mut step = f64::INFINITY;
        for iteration in 0..self.max_iterations {
            let jac = phi - SMatrix::<T, N, N>::identity();
            let lu = Lu::new(jac).ok_or(OrbitError::Singular { iteration })?;
            let delta = lu.solve(&(-residual));
            let accepted = backtrack(residual.amax(), |lambda| {
                let trial = y + delta * lambda;
                let (p_t, phi_t) = self.flow(t0, trial, period).ok()?;
                let r_t = p_t - trial;
                Some(((trial, phi_t, r_t), r_t.amax()))
            });
            let Some((trial, phi_t, r_t)) = accepted else {
                break;
            };
            step = self.step_in_tolerances(&y, &trial);
            y = trial;
            phi = phi_t;
            residual = r_t;
            if step <= self.newton_tolerance {
                return Ok(PeriodicOrbit {
                    t0,
                    period,
                    state: y,
                    monodromy: phi,
                    multipliers: multipliers(&phi),
                    iterations: iteration + 1,
                    residual: residual.amax(),
                });
            }
        }
        Err(OrbitError::NotConverged {
            iterations: self.max_iterations,
            step,
            residual: to_f64(residual.amax()),
        })
    }

    /// The periodic orbit of period `period` by multiple shooting from `m = guesses.len()`
    /// points: segment `i` runs over `[tᵢ, tᵢ + h]`, `tᵢ = t₀ + i·h`, `h = period/m`, from
    /// `yᵢ = guesses[i]`, and Newton solves the `m·N` equations `φᵢ(yᵢ) − y₍ᵢ₊₁₎ mod m = 0`
    /// at once, with the block-cyclic Jacobian (`Φᵢ` on the diagonal, `−I` right of it, and
    /// `−I` in the top-right corner for the closing segment) and the same backtracking and
    /// convergence test as [`find`](Self::find), on every segment.
    ///
    /// On an unstable orbit a single shot amplifies the error of its start by `|μ| ≈ e^{λ·period}`
    /// before Newton sees it, and the nonlinear part of that error defeats the linear
    /// model; each segment here amplifies it only by `e^{λh}`. The returned orbit is taken
    /// at `t₀` (`state = y₀`), its monodromy matrix is the product `Φ_{m−1}⋯Φ₀` and its
    /// residual the largest segment mismatch. `m = 1` is single shooting.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] for no guesses or a period that is not finite and
    /// `> 0`; [`OrbitError::Singular`], [`OrbitError::NotConverged`], and the errors of
    /// [`flow`](Self::flow).
    pub fn find_multiple(
        &self,
        t0: T,
        period: T,
        guesses: &[SVector<T, N>],
    ) -> Result<PeriodicOrbit<T, N>> {
        let m = guesses.len();
        if m == 0 {
            return Err(OrbitError::InvalidSetting {
                what: "the number of shooting points",
                requirement: "at least 1",
                value: 0.0,
            });
        }
        check_period(period)?;
        let h = period / lit(m as f64);
        let mut ys = guesses.to_vec();
        let (mut phis, mut residuals) = self.segments(t0, h, &ys)?;
        let mut step = f64::INFINITY;
        for iteration in 0..self.max_iterations {
            let delta =
                cyclic_newton_step(&phis, &residuals).ok_or(OrbitError::Singular { iteration })?;
            let accepted = backtrack(largest_mismatch(&residuals), |lambda| {
                let trial: Vec<SVector<T, N>> = (0..m)
                    .map(|i| ys[i] + delta.fixed_rows::<N>(i * N) * lambda)
                    .collect();
                let (phis_t, r_t) = self.segments(t0, h, &trial).ok()?;
                let mismatch = largest_mismatch(&r_t);
                Some(((trial, phis_t, r_t), mismatch))
            });
            let Some((trial, phis_t, r_t)) = accepted else {
                break;
            };
            step = ys
                .iter()
                .zip(&trial)
                .map(|(y, trial)| self.step_in_tolerances(y, trial))
                .fold(0.0, f64::max);
            ys = trial;
            phis = phis_t;
            residuals = r_t;
            if step <= self.newton_tolerance {
                let monodromy = phis
                    .iter()
                    .fold(SMatrix::<T, N, N>::identity(), |acc, phi| phi * acc);
                return Ok(PeriodicOrbit {
                    t0,
                    period,
                    state: ys[0],
                    monodromy,
                    multipliers: multipliers(&monodromy),
                    iterations: iteration + 1,
                    residual: largest_mismatch(&residuals),
                });
            }
        }
        Err(OrbitError::NotConverged {
            iterations: self.max_iterations,
            step,
            residual: to_f64(largest_mismatch(&residuals)),
        })
    }

    /// The segments of multiple shooting from the starts `ys` at `t₀ + i·h`: each one's
    /// Jacobian `Φᵢ` and mismatch `φᵢ(yᵢ) − y₍ᵢ₊₁₎ mod m`.
    fn segments(&self, t0: T, h: T, ys: &[SVector<T, N>]) -> Result<Segments<T, N>> {
        let m = ys.len();
        let mut phis = Vec::with_capacity(m);
        let mut residuals = Vec::with_capacity(m);
        for i in 0..m {
            let (p, phi) = self.flow(t0 + h * lit(i as f64), ys[i], h)?;
            phis.push(phi);
            residuals.push(p - ys[(i + 1) % m]);
        }
        Ok((phis, residuals))
    }

    /// The largest component of the step from `y` to `trial` in units of the state's
    /// integration tolerance `atol_i + rtol_i·|trialᵢ|` (Newton's convergence measure).
    fn step_in_tolerances(&self, y: &SVector<T, N>, trial: &SVector<T, N>) -> f64 {
        let taken = trial - y;
        (0..N)
            .map(|i| {
                let scale = self.tolerances.atol[i] + self.tolerances.rtol[i] * trial[i].abs();
                to_f64(taken[i].abs() / scale)
            })
            .fold(0.0, f64::max)
    }
}

/// The Jacobians `Φᵢ` and mismatches of the segments of multiple shooting.
type Segments<T, const N: usize> = (Vec<SMatrix<T, N, N>>, Vec<SVector<T, N>>);

/// The largest mismatch of the segments of multiple shooting.
fn largest_mismatch<T: Real, const N: usize>(residuals: &[SVector<T, N>]) -> T {
    residuals.iter().map(|v| v.amax()).fold(T::zero(), T::max)
}

/// Newton's step for multiple shooting: the solution `Δy` of the block-cyclic system
/// `Φᵢ·Δyᵢ − Δy₍ᵢ₊₁₎ mod m = −rᵢ` (`Φᵢ` on the diagonal, `−I` right of it and in the
/// top-right corner for the closing segment), `None` if it is singular.
fn cyclic_newton_step<T: Real, const N: usize>(
    phis: &[SMatrix<T, N, N>],
    residuals: &[SVector<T, N>],
) -> Option<nalgebra::DVector<T>> {
    let m = phis.len();
    let size = m * N;
    let mut jac = DMatrix::<T>::zeros(size, size);
    let mut rhs = nalgebra::DVector::<T>::zeros(size);
    for i in 0..m {
        let next = (i + 1) % m;
        for r in 0..N {
            rhs[i * N + r] = -residuals[i][r];
            for c in 0..N {
                jac[(i * N + r, i * N + c)] += phis[i][(r, c)];
            }
            jac[(i * N + r, next * N + r)] -= T::one();
        }
    }
    jac.lu().solve(&rhs)
}

/// Backtracking on the largest mismatch: the Newton step scaled by `λ = 1, ½, ¼, …` (at
/// most 12 trials) until a trial's mismatch is below `before`, or any trial once
/// `λ < 10⁻³`. `trial(λ)` returns the trial with its mismatch, `None` if its run failed.
fn backtrack<T: Real, X>(before: T, mut trial: impl FnMut(T) -> Option<(X, T)>) -> Option<X> {
    let mut lambda = T::one();
    for _ in 0..12 {
        if let Some((x, mismatch)) = trial(lambda)
            && (mismatch < before || lambda < lit(1e-3))
        {
            return Some(x);
        }
        lambda *= lit(0.5);
    }
    None
}

/// A shooting period must be finite and `> 0`.
fn check_period<T: Real>(period: T) -> Result<()> {
    if period.is_finite() && period > T::zero() {
        Ok(())
    } else {
        Err(OrbitError::InvalidSetting {
            what: "the period",
            requirement: "finite and > 0",
            value: to_f64(period),
        })
    }
}

/// Which extremum of a component along an orbit ([`Shooting::extremum`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extremum {
    /// The smallest value (e.g. the gap to a stop below the motion).
    Min,
    /// The largest value.
    Max,
}

/// The rate `ẏ_c` of one component, as an event function (its zeros are the component's
/// extrema).
#[derive(Debug, Clone)]
struct Rate<S> {
    system: S,
    component: usize,
}

impl<T: Real, const N: usize, S: Dynamics<T, N>> crate::event::EventFunction<T, N> for Rate<S> {
    fn value(&self, t: T, y: &SVector<T, N>) -> T {
        let mut dy = SVector::<T, N>::zeros();
        self.system.rhs(t, y, &mut dy);
        dy[self.component]
    }
}

/// Tracks the extremum of one component at the rate event and the run's ends.
struct Extrema<T> {
    component: usize,
    event: usize,
    which: Extremum,
    best: Option<T>,
    /// Every extremum at the rate event, `(t, value)`.
    all: Vec<(T, T)>,
}

impl<T: Real> Extrema<T> {
    fn offer(&mut self, v: T) {
        let better = match (self.best, self.which) {
            (None, _) => true,
            (Some(b), Extremum::Min) => v < b,
            (Some(b), Extremum::Max) => v > b,
        };
        if better {
            self.best = Some(v);
        }
    }
}

impl<T: Real, const N: usize> crate::drive::Observer<T, N> for Extrema<T> {
    fn on_start(&mut self, _t0: T, y0: &SVector<T, N>) {
        self.offer(y0[self.component]);
    }
    fn on_event(&mut self, event: &crate::drive::EventRecord<T, N>) -> crate::drive::Control {
        if event.index == self.event {
            self.offer(event.y[self.component]);
            self.all.push((event.t, event.y[self.component]));
        }
        crate::drive::Control::Continue
    }
    fn on_finish(&mut self, outcome: &crate::drive::Outcome<T, N>) {
        self.offer(outcome.y[self.component]);
    }
}

impl<T, S, E, const N: usize, const M: usize> Shooting<T, S, E, N, M>
where
    T: Real,
    S: Dynamics<T, N> + Clone,
    E: EventSet<T, N> + Clone,
{
    /// The state's tolerances (the first `N` components of the shooting tolerances).
    pub fn state_tolerances(&self) -> Tolerances<T, N> {
        let mut tol = Tolerances {
            rtol: SVector::<T, N>::zeros(),
            atol: SVector::<T, N>::zeros(),
        };
        for i in 0..N {
            tol.rtol[i] = self.tolerances.rtol[i];
            tol.atol[i] = self.tolerances.atol[i];
        }
        tol
    }

    /// Every local minimum (or maximum) of component `component` along the trajectory from
    /// `(t0, y)` over `span`, as `(t, value)` in time order: the zeros of its rate `ẏ_c`
    /// located on the dense output (the ends are not included).
    ///
    /// # Errors
    /// As [`extremum`](Self::extremum).
    pub fn local_extrema(
        &self,
        t0: T,
        span: T,
        y: SVector<T, N>,
        component: usize,
        which: Extremum,
    ) -> Result<Vec<(T, T)>> {
        let mut observer = self.extrema_run(t0, span, y, component, which)?;
        Ok(std::mem::take(&mut observer.all))
    }

    /// The smallest or largest value of component `component` along the trajectory from
    /// `(t0, y)` over `span` (an orbit's period): at the zeros of its rate `ẏ_c` located on
    /// the dense output (to the event time tolerance), and at both ends. With `component` a
    /// position and `span` the period of an orbit, `min − level` is the orbit's grazing
    /// margin to a stop at `level`.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] for `component ≥ N`; the run's errors.
    pub fn extremum(
        &self,
        t0: T,
        span: T,
        y: SVector<T, N>,
        component: usize,
        which: Extremum,
    ) -> Result<T> {
        let observer = self.extrema_run(t0, span, y, component, which)?;
        Ok(observer.best.unwrap_or(y[component]))
    }

    /// Runs the trajectory with the rate event of `component`, collecting its extrema.
    fn extrema_run(
        &self,
        t0: T,
        span: T,
        y: SVector<T, N>,
        component: usize,
        which: Extremum,
    ) -> Result<Extrema<T>> {
        if component >= N {
            return Err(OrbitError::InvalidSetting {
                what: "the component",
                requirement: "below the state size",
                value: component as f64,
            });
        }
        let direction = match which {
            Extremum::Min => crate::event::Direction::Rising,
            Extremum::Max => crate::event::Direction::Falling,
        };
        let rate = crate::event::Event::new(
            Rate {
                system: self.system.clone(),
                component,
            },
            direction,
        );
        let mut observer = Extrema {
            component,
            event: E::LEN,
            which,
            best: None,
            all: Vec::new(),
        };
        let mut sim = Simulation::new(self.system.clone(), Dopri5::new(self.state_tolerances()))
            .with_events((self.events.clone(), rate));
        sim.run(t0, y, t0 + span, &mut observer)?;
        Ok(observer)
    }
}

/// The eigenvalues of `phi`, largest modulus first.
pub fn multipliers<T: Real, const N: usize>(phi: &SMatrix<T, N, N>) -> Vec<Complex<T>> {
    let dynamic = DMatrix::from_iterator(N, N, phi.iter().copied());
    let mut mu: Vec<Complex<T>> = dynamic.complex_eigenvalues().iter().copied().collect();
    mu.sort_by(|a, b| {
        modulus(b)
            .partial_cmp(&modulus(a))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    mu
}

/// `|μ|`.
pub fn modulus<T: Real>(mu: &Complex<T>) -> T {
    mu.re.hypot(mu.im)
}
