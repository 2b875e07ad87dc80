//! One adaptive stepper over the crate's methods: [`Adaptive`] holds the tolerances, the PI
//! controller, the state and the dense output of the last step; a [`Method`] supplies its
//! orders, its step (trial stages, error estimate, dense output) and its interpolant.

use core::fmt::Debug;
use core::marker::PhantomData;

use nalgebra::SVector;

use super::{
    Controller, Core, DenseOutput, HermiteDense, IntegrateError, Stats, StepOptions, Stepper,
    Tolerances,
};
use crate::scalar::lit;
use crate::{Dynamics, Real};

pub(crate) mod sealed {
    /// Only the crate's methods and interpolants implement [`Method`](super::Method) and
    /// [`Interpolant`](super::Interpolant).
    pub trait Sealed {}
}

/// What an adaptive method advances in one step: its tolerances, controller and state.
/// Opaque: only the crate's [`Method`]s use it.
#[doc(hidden)]
pub struct StepParts<'a, T: Real, const N: usize> {
    pub(crate) tol: &'a Tolerances<T, N>,
    pub(crate) ctrl: &'a mut Controller<T>,
    pub(crate) core: &'a mut Core<T, N>,
}

/// An adaptive one-step method of the crate: [`Dopri5Method`](super::Dopri5Method),
/// [`Dop853Method`](super::Dop853Method), [`Rosenbrock23Method`](super::Rosenbrock23Method).
///
/// The method supplies the order of its solution ([`ORDER`](Self::ORDER)), the order of its
/// error estimate ([`ERROR_ORDER`](Self::ERROR_ORDER), the controller's exponent), its step
/// and its dense output ([`Poly`](Self::Poly)); [`Adaptive`] supplies everything else, once
/// for all of them. Sealed: the crate's methods only.
pub trait Method<T: Real, const N: usize>:
    sealed::Sealed + Debug + Clone + Copy + Default + Send + Sync + 'static
{
    /// The order of the propagated solution.
    const ORDER: u8;
    /// The order of the error estimate (the step-size controller's exponent `1/q`).
    const ERROR_ORDER: f64;
    /// The interpolant of one step beside its ends.
    type Poly: Interpolant<T, N>;

    /// One accepted step: advances `parts.core` from its state towards `t_limit` (never past
    /// it) and writes the step's dense output into `dense` (untouched on an error).
    #[doc(hidden)]
    fn advance<S: Dynamics<T, N>>(
        parts: StepParts<'_, T, N>,
        dense: &mut MethodDense<T, N, Self::Poly>,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError>;
}

/// The interpolant of a method's step, evaluated with the step's ends. Sealed.
pub trait Interpolant<T: Real, const N: usize>:
    sealed::Sealed + Debug + Clone + Copy + PartialEq
{
    /// Before the first step.
    #[doc(hidden)]
    fn empty() -> Self;

    /// Writes `y(t)` into `out` from the step's ends `ends`.
    #[doc(hidden)]
    fn eval(&self, ends: &HermiteDense<T, N>, t: T, out: &mut SVector<T, N>);

    /// [`DenseOutput::chord_bounds`] of the interpolant (default `None`).
    #[doc(hidden)]
    fn chord_bounds(&self, _ends: &HermiteDense<T, N>) -> Option<(SVector<T, N>, SVector<T, N>)> {
        None
    }
}

/// The dense output of one step of an [`Adaptive`] method: the step's ends (states and
/// derivatives, [`HermiteDense`]) and the method's interpolant `P`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodDense<T: Real, const N: usize, P> {
    pub(crate) ends: HermiteDense<T, N>,
    pub(crate) poly: P,
}

impl<T: Real, const N: usize, P: Interpolant<T, N>> MethodDense<T, N, P> {
    /// Before the first step.
    fn empty() -> Self {
        Self {
            ends: HermiteDense::zeros(),
            poly: P::empty(),
        }
    }
}

impl<T: Real, const N: usize, P: Interpolant<T, N>> DenseOutput<T, N> for MethodDense<T, N, P> {
    #[inline(always)]
    fn span(&self) -> (T, T) {
        self.ends.span()
    }

    #[inline(always)]
    fn endpoints(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        self.ends.endpoints()
    }

    #[inline(always)]
    fn end_derivatives(&self) -> (&SVector<T, N>, &SVector<T, N>) {
        self.ends.end_derivatives()
    }

    #[inline(always)]
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, N>) {
        self.poly.eval(&self.ends, t, out)
    }

    fn chord_bounds(&self) -> Option<(SVector<T, N>, SVector<T, N>)> {
        self.poly.chord_bounds(&self.ends)
    }
}

/// An adaptive stepper of method `M` ([`Dopri5`](super::Dopri5) = `Adaptive<T, N,
/// Dopri5Method>`, [`Dop853`](super::Dop853), [`Rosenbrock23`](super::Rosenbrock23)): the
/// tolerances, the PI step-size controller with Hairer's first-step guess, the state with
/// its cached derivative (first same as last), the work counters and the dense output of the
/// last accepted step, written once for every method.
#[derive(Debug, Clone)]
pub struct Adaptive<T: Real, const N: usize, M: Method<T, N>> {
    tol: Tolerances<T, N>,
    ctrl: Controller<T>,
    core: Core<T, N>,
    dense: MethodDense<T, N, M::Poly>,
    method: PhantomData<M>,
}

impl<T: Real, const N: usize, M: Method<T, N>> Adaptive<T, N, M> {
    /// A stepper with the given tolerances and default [`StepOptions`].
    pub fn new(tol: Tolerances<T, N>) -> Self {
        Self::with_options(tol, StepOptions::default())
    }

    /// A stepper with explicit step options.
    pub fn with_options(tol: Tolerances<T, N>, opts: StepOptions<T>) -> Self {
        Self {
            tol,
            ctrl: Controller::new(opts, lit(M::ERROR_ORDER)),
            core: Core::new(opts.h_init),
            dense: MethodDense::empty(),
            method: PhantomData,
        }
    }

    /// The tolerances.
    pub fn tolerances(&self) -> &Tolerances<T, N> {
        &self.tol
    }

    /// The step size the controller proposes next.
    pub fn proposed_step(&self) -> Option<T> {
        self.core.h
    }

    /// Sets the step the next step tries first (a stepper that hands its state over to this
    /// one passes on its step size).
    pub(crate) fn set_proposed_step(&mut self, h: T) {
        if h.is_finite() && h > T::zero() {
            self.core.h = Some(h.min(self.ctrl.opts.h_max));
        }
    }
}

impl<T: Real, const N: usize, M: Method<T, N>> Stepper<T, N> for Adaptive<T, N, M> {
    type Dense = MethodDense<T, N, M::Poly>;

    fn reset_state(&mut self, t: T, y: SVector<T, N>) {
        self.core.reset(t, y);
    }

    fn start(&mut self, t: T, y: SVector<T, N>) {
        self.core.start(t, y);
    }

    fn step<S: Dynamics<T, N>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError> {
        let parts = StepParts {
            tol: &self.tol,
            ctrl: &mut self.ctrl,
            core: &mut self.core,
        };
        M::advance(parts, &mut self.dense, sys, t_limit)
    }

    fn current(&self) -> (T, &SVector<T, N>) {
        (self.core.t, &self.core.y)
    }

    fn dense(&self) -> &Self::Dense {
        &self.dense
    }

    fn stats(&self) -> &Stats {
        &self.core.stats
    }

    fn stats_mut(&mut self) -> &mut Stats {
        &mut self.core.stats
    }

    fn order(&self) -> u8 {
        M::ORDER
    }

    fn check(&self) -> Result<(), IntegrateError> {
        self.tol
            .validate()
            .and_then(|()| self.ctrl.opts.validate())
            .map_err(IntegrateError::InvalidSettings)
    }

    fn max_step(&self) -> Option<T> {
        let h = self.ctrl.opts.h_max;
        (h.is_finite() && h > T::zero()).then_some(h)
    }
}
