//! Lyapunov exponents of systems with events and resets (rigid impacts).
//!
//! Both estimators run through the event engine ([`Simulation`]) with the system's own event
//! set, so impacts are located and reset exactly as in any other run.
//!
//! - [`HybridTwoTrajectory`]: a reference and a perturbed trajectory, each taking its own
//!   impacts (they come at different times). The separation is measured at the grid times
//!   `t0 + kτ` only when both have taken the same number of resets; otherwise both are
//!   carried on by a thousandth of the interval until they have (at most 999 times, so the
//!   next grid time is not passed), so the comparison never straddles an impact. The
//!   exponent is `Σ ln(d_k/d_{k−1}') / Σ Δt_k` (`d'` the separation realized by the
//!   previous renormalization).
//! - [`HybridTangentSpace`]: the variational equations with `K` tangent vectors, mapped
//!   across every reset by the **saltation matrix**
//!   $$S = R_y + \frac{\bigl(f^+ - R_y f^- - R_t\bigr)\,\nabla g^{\mathsf T}}
//!   {\nabla g\cdot f^- + \partial_t g},$$
//!   with `R` the reset, `g` the event function, `f^∓` the vector field before and after.
//!   `R_y`, `R_t`, `∇g` and `∂_t g` are central finite differences of the reset map and the
//!   event function (relative step `ε^{1/3}`, accurate to about `10⁻¹⁰` relative for smooth
//!   maps — far below the statistical spread of an exponent), so any event function and
//!   reset work without further code. Gram–Schmidt re-orthonormalization every `τ`.
//!
//! # References
//! P. C. Müller, *Chaos Solitons Fractals* 5 (1995) 1671–1681 (Lyapunov exponents of systems
//! with discontinuities via the saltation matrix); R. I. Leine, H. Nijmeijer, *Dynamics and
//! Bifurcations of Non-Smooth Mechanical Systems*, Springer 2004, ch. 2.

use nalgebra::{SMatrix, SVector};

use super::Result;
use super::runner::{Flow, Frame, Runner, Separation, Simulated};
use super::sizes::{Dims, TangentDimension};
use super::tangent::check_jacobian_at;
use super::{Estimate, LyapunovError, Norm, Spectrum, Variational, check_blocks, check_state};
use crate::drive::{Control, EventRecord, Observer, Simulation};
use crate::event::{Direction, EventError, EventSet};
use crate::integrate::{Stats, Stepper, Tolerances};
use crate::scalar::{epsilon, lit, to_f64};
use crate::{Dynamics, Real};

/// Counts resets.
#[derive(Debug, Default, Clone, Copy)]
struct ResetCount(u64);

impl<T: Real, const N: usize> Observer<T, N> for ResetCount {
    fn wants_steps(&self) -> bool {
        false
    }
    fn on_event(&mut self, e: &EventRecord<T, N>) -> Control {
        if e.y_after.is_some() {
            self.0 += 1;
        }
        Control::Continue
    }
}

/// The reference and the perturbed trajectory as two runs of the event engine; an interval
/// ends late while their reset counts differ.
#[derive(Debug, Clone)]
struct TwoRuns<T: Real, const N: usize, S, St, E> {
    reference: Simulation<T, N, S, St, E>,
    perturbed: Simulation<T, N, S, St, E>,
    work: Stats,
}

impl<T, const N: usize, S, St, E> TwoRuns<T, N, S, St, E>
where
    T: Real,
    S: Dynamics<T, N>,
    St: Stepper<T, N>,
    E: EventSet<T, N>,
{
    /// Both trajectories from `t` to `t_end`, counting resets.
    fn both(
        &mut self,
        pair: &mut Separation<T, N>,
        t: T,
        t_end: T,
        counts: &mut [ResetCount; 2],
    ) -> Result<()> {
        let oy = self
            .reference
            .run(t, pair.reference, t_end, &mut counts[0])?;
        let oz = self
            .perturbed
            .run(t, pair.perturbed, t_end, &mut counts[1])?;
        self.work += &oy.stats;
        self.work += &oz.stats;
        (pair.reference, pair.perturbed) = (oy.y, oz.y);
        Ok(())
    }
}

impl<T, const N: usize, S, St, E> Flow<T, Separation<T, N>> for TwoRuns<T, N, S, St, E>
where
    T: Real,
    S: Dynamics<T, N>,
    St: Stepper<T, N>,
    E: EventSet<T, N>,
{
    const ON_GRID: bool = false;

    fn advance(&mut self, pair: &mut Separation<T, N>, t: T, t_end: T) -> Result<T> {
        let mut counts = [ResetCount::default(); 2];
        self.both(pair, t, t_end, &mut counts)?;
        // At most 999 extensions of a thousandth of the interval: the end stays before the
        // next grid time.
        let step = (t_end - t) * lit(1e-3);
        let mut t1 = t_end;
        for _ in 0..999 {
            if counts[0].0 == counts[1].0 {
                return Ok(t1);
            }
            let t2 = t1 + step;
            self.both(pair, t1, t2, &mut counts)?;
            t1 = t2;
        }
        if counts[0].0 == counts[1].0 {
            return Ok(t1);
        }
        Err(LyapunovError::SeparationLost {
            t: to_f64(t1),
            separation: f64::INFINITY,
        })
    }

    fn work(&self) -> Stats {
        self.work
    }
}

/// The two-trajectory (Benettin) estimate of the top exponent for a system with events and
/// resets (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct HybridTwoTrajectory<T: Real, const N: usize, S, St, E> {
    flow: TwoRuns<T, N, S, St, E>,
    runner: Runner<T, Separation<T, N>>,
}

impl<T, const N: usize, S, St, E> HybridTwoTrajectory<T, N, S, St, E>
where
    T: Real,
    S: Dynamics<T, N> + Clone,
    St: Stepper<T, N> + Clone,
    E: EventSet<T, N> + Clone,
{
    /// Two copies of `system`, each with its own stepper and the events `events`, initial
    /// separation `d0` measured in `norm` along the norm's first axis.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidSeparation`] unless `d0` is finite and > 0; a bad norm.
    pub fn new(system: S, stepper: St, events: E, d0: T, norm: Norm<T, N>) -> Result<Self> {
        let mut pair = Separation::new(d0, norm)?;
        pair.direction = SVector::zeros();
        pair.direction[0] = norm.scales()[0];
        let reference =
            Simulation::new(system.clone(), stepper.clone()).with_events(events.clone());
        let perturbed = Simulation::new(system, stepper).with_events(events);
        Ok(Self {
            flow: TwoRuns {
                reference,
                perturbed,
                work: Stats::default(),
            },
            runner: Runner::new(pair),
        })
    }

    /// Sets the direction of the initial perturbation (scaled to length `d0` in the norm).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidDirection`] if it is zero or not finite.
    pub fn with_direction(mut self, direction: SVector<T, N>) -> Result<Self> {
        self.runner.state.set_direction(direction)?;
        Ok(self)
    }

    /// The number of blocks for the standard error (default 10).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidBlocks`] if `blocks < 2`.
    pub fn with_blocks(mut self, blocks: usize) -> Result<Self> {
        self.runner.blocks = check_blocks(blocks)?;
        Ok(self)
    }

    /// Starts at `(t0, y0)` with the perturbation `d0` along the initial direction (the
    /// norm's first axis unless set by [`with_direction`](Self::with_direction)).
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] for a non-finite start;
    /// [`LyapunovError::UnresolvedSeparation`] if `d0` is lost to rounding on `y0`.
    pub fn start(&mut self, t0: T, y0: SVector<T, N>) -> Result<()> {
        check_state(t0, &y0)?;
        let placed = self.runner.state.placed(y0)?;
        self.runner.start(&mut self.flow, t0, placed);
        Ok(())
    }

    /// The reference state `(t, y)`.
    pub fn reference(&self) -> Option<(T, SVector<T, N>)> {
        self.runner.current().map(|(t, pair)| (t, pair.reference))
    }

    /// Runs `intervals` intervals of length `tau` and discards them (a separation that
    /// collapsed to zero is re-seeded along the initial direction).
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate), except that 0 intervals are allowed.
    pub fn transient(&mut self, tau: T, intervals: usize) -> Result<()> {
        self.runner
            .transient::<_, 1>(&mut self.flow, tau, intervals)
    }

    /// Runs `intervals` intervals on the grid `t_s + kτ` and returns the estimate
    /// `λ = Σ ln(d_k/d_{k−1}') / Σ Δt_k` (`local[k] = ln(d_k/d_{k−1}')/Δt_k`; an interval
    /// that ended late because the reset counts differed is longer, the next one shorter).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidInterval`], [`LyapunovError::TooFewIntervals`],
    /// [`LyapunovError::NotStarted`], [`LyapunovError::SeparationLost`] (collapse,
    /// overflow, or reset counts that do not match within 999 extensions), integration and
    /// event errors.
    pub fn estimate(&mut self, tau: T, intervals: usize) -> Result<Estimate<T>> {
        Ok(self
            .runner
            .estimate::<_, 1>(&mut self.flow, tau, intervals)?
            .estimate())
    }
}

/// An event set of `N`-dimensional states lifted to the variational system of dimension
/// `M = N + N·K`: the events look at the state part; a reset maps the state by the event's
/// reset and the tangent vectors by the saltation matrix.
#[derive(Debug, Clone)]
pub struct Saltation<T: Real, S, E, const N: usize, const K: usize> {
    system: S,
    events: E,
    scales: SVector<T, N>,
}

impl<T: Real, S: Dynamics<T, N>, E: EventSet<T, N>, const N: usize, const K: usize>
    Saltation<T, S, E, N, K>
{
    /// `events` of `system` lifted to its variational system with tangent vectors scaled by
    /// `scales` (see [`Norm`]).
    pub(crate) fn new(system: S, events: E, scales: SVector<T, N>) -> Self {
        Self {
            system,
            events,
            scales,
        }
    }

    fn state<const M: usize>(z: &SVector<T, M>) -> SVector<T, N> {
        let mut y = SVector::<T, N>::zeros();
        for i in 0..N {
            y[i] = z[i];
        }
        y
    }

    /// The saltation matrix of event `i` at `(t, y⁻)`.
    pub fn matrix(&self, i: usize, t: T, y: &SVector<T, N>) -> SMatrix<T, N, N> {
        let h_rel = epsilon::<T>().powf(lit(1.0 / 3.0));
        let reset = |t: T, y: &SVector<T, N>| {
            let mut r = *y;
            self.events.apply_reset(i, t, &mut r);
            r
        };
        let mut yp = *y;
        self.events.apply_reset(i, t, &mut yp);
        let mut f_minus = SVector::zeros();
        let mut f_plus = SVector::zeros();
        self.system.rhs(t, y, &mut f_minus);
        self.system.rhs(t, &yp, &mut f_plus);
        let mut r_y = SMatrix::<T, N, N>::zeros();
        let mut grad = SVector::<T, N>::zeros();
        let two = lit::<T>(2.0);
        for k in 0..N {
            let h = h_rel * y[k].abs().max(self.scales[k]);
            let (mut a, mut b) = (*y, *y);
            a[k] += h;
            b[k] -= h;
            let col = (reset(t, &a) - reset(t, &b)) / (two * h);
            r_y.set_column(k, &col);
            grad[k] = (self.events.value(i, t, &a) - self.events.value(i, t, &b)) / (two * h);
        }
        let ht = h_rel * t.abs().max(T::one());
        let r_t = (reset(t + ht, y) - reset(t - ht, y)) / (two * ht);
        let g_t = (self.events.value(i, t + ht, y) - self.events.value(i, t - ht, y)) / (two * ht);
        let denom = grad.dot(&f_minus) + g_t;
        let v = f_plus - r_y * f_minus - r_t;
        r_y + v * grad.transpose() / denom
    }
}

impl<T, S, E, const N: usize, const K: usize, const M: usize> EventSet<T, M>
    for Saltation<T, S, E, N, K>
where
    T: Real,
    S: Dynamics<T, N>,
    E: EventSet<T, N>,
{
    const LEN: usize = E::LEN;
    #[inline(always)]
    fn value(&self, i: usize, t: T, z: &SVector<T, M>) -> T {
        self.events.value(i, t, &Self::state(z))
    }
    #[inline(always)]
    fn rate(&self, i: usize, t: T, z: &SVector<T, M>, dz: &SVector<T, M>) -> Option<T> {
        self.events.rate(i, t, &Self::state(z), &Self::state(dz))
    }
    fn direction(&self, i: usize) -> Direction {
        self.events.direction(i)
    }
    fn is_terminal(&self, i: usize) -> bool {
        self.events.is_terminal(i)
    }
    fn resets(&self, i: usize) -> bool {
        self.events.resets(i)
    }
    fn apply_reset(&self, i: usize, t: T, z: &mut SVector<T, M>) {
        let y = Self::state(z);
        let s = self.matrix(i, t, &y);
        let mut yp = y;
        self.events.apply_reset(i, t, &mut yp);
        // Tangent vectors are stored scaled: ψ = D⁻¹δy, so ψ⁺ = D⁻¹ S D ψ⁻.
        for c in 0..K {
            let mut psi = SVector::<T, N>::zeros();
            for k in 0..N {
                psi[k] = z[N + c * N + k] * self.scales[k];
            }
            let out = s * psi;
            for k in 0..N {
                z[N + c * N + k] = out[k] / self.scales[k];
            }
        }
        for k in 0..N {
            z[k] = yp[k];
        }
    }
    fn interior_samples(&self, i: usize) -> usize {
        self.events.interior_samples(i)
    }
    fn restarts(&self, i: usize) -> bool {
        self.events.restarts(i)
    }
    fn check(&self) -> Result<(), EventError> {
        if M != N + N * K {
            return Err(EventError::IndexOutOfRange {
                index: N + N * K - 1,
                len: M,
            });
        }
        self.events.check()
    }
    fn max_step(&self, t: T) -> Option<T> {
        self.events.max_step(t)
    }
    fn constant_max_step(&self) -> bool {
        self.events.constant_max_step()
    }
}

/// The tangent-space (QR) estimate of `K` exponents for a system with events and resets:
/// the variational equations between events, the saltation matrix across each reset (see
/// the [module docs](self)), Gram–Schmidt every `τ`.
#[derive(Debug, Clone)]
pub struct HybridTangentSpace<T: Real, const N: usize, const K: usize, const M: usize, S, St, E> {
    flow: Simulated<T, M, Variational<T, S, N, K, M>, St, Saltation<T, S, E, N, K>>,
    runner: Runner<T, Frame<T, N, K>>,
}

impl<T, const N: usize, const M: usize, S, St, E> HybridTangentSpace<T, N, N, M, S, St, E>
where
    T: Real,
    S: Dynamics<T, N> + Clone,
    St: Stepper<T, M>,
    Dims<N>: TangentDimension<N, M>,
    E: EventSet<T, N>,
{
    /// The whole spectrum (`K = N`) of `system` with the events `events`, the stepper built
    /// from the system's tolerances `tol` (extended by
    /// [`tangent_tolerances`](super::tangent_tolerances) with `tangent_rtol`,
    /// `tangent_atol`), the size `M = N + N²` inferred: no size is written.
    ///
    /// # Errors
    /// As [`tangent_tolerances`](super::tangent_tolerances) and [`new`](Self::new).
    pub fn from_tolerances(
        system: S,
        tol: &Tolerances<T, N>,
        make_stepper: impl FnOnce(Tolerances<T, M>) -> St,
        (tangent_rtol, tangent_atol): (T, T),
        events: E,
        norm: Norm<T, N>,
    ) -> Result<Self> {
        let t = super::tangent_tolerances::<T, N, N, M>(tol, tangent_rtol, tangent_atol)?;
        Self::new(system, make_stepper(t), events, norm)
    }
}

impl<T, const N: usize, const K: usize, const M: usize, S, St, E>
    HybridTangentSpace<T, N, K, M, S, St, E>
where
    T: Real,
    S: Dynamics<T, N> + Clone,
    St: Stepper<T, M>,
    E: EventSet<T, N>,
{
    /// The variational system of `system` with `K` tangent vectors (`M = N + N·K`, checked),
    /// integrated by `stepper` with the events `events`.
    ///
    /// # Errors
    /// [`LyapunovError::TangentCount`], [`LyapunovError::Dimension`], a bad norm.
    pub fn new(system: S, stepper: St, events: E, norm: Norm<T, N>) -> Result<Self> {
        let scales = norm.scales();
        let var = Variational::<T, S, N, K, M>::new(system.clone(), norm)?;
        let lifted = Saltation::<T, S, E, N, K> {
            system,
            events,
            scales,
        };
        Ok(Self {
            flow: Simulated {
                sim: Simulation::new(var, stepper).with_events(lifted),
                work: Stats::default(),
            },
            runner: Runner::new(Frame::at(SVector::zeros())),
        })
    }

    /// Starts at `(t0, y0)` with the unit tangent vectors `e_1 … e_K`.
    ///
    /// # Errors
    /// [`LyapunovError::NonFinite`] for a non-finite start; [`LyapunovError::NoJacobian`]
    /// if the system has no Jacobian at `y0`.
    pub fn start(&mut self, t0: T, y0: SVector<T, N>) -> Result<()> {
        check_jacobian_at(self.flow.sim.system().system(), t0, &y0)?;
        self.runner.start(&mut self.flow, t0, Frame::at(y0));
        Ok(())
    }

    /// Runs `intervals` intervals of length `tau` and discards them (a tangent vector that
    /// collapsed is replaced, as in [`TangentSpace::transient`](super::TangentSpace::transient)).
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate), except that 0 intervals are allowed.
    pub fn transient(&mut self, tau: T, intervals: usize) -> Result<()> {
        self.runner
            .transient::<_, K>(&mut self.flow, tau, intervals)
    }

    /// Runs `intervals` intervals on the grid `t_s + kτ` and returns the `K` exponents.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidInterval`], [`LyapunovError::TooFewIntervals`],
    /// [`LyapunovError::NotStarted`], [`LyapunovError::TangentCollapse`], integration and
    /// event errors.
    pub fn estimate(&mut self, tau: T, intervals: usize) -> Result<Spectrum<T, K>> {
        Ok(self
            .runner
            .estimate::<_, K>(&mut self.flow, tau, intervals)?
            .spectrum())
    }
}
