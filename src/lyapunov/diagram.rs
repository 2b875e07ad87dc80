//! The top exponent against a parameter, with continuation up and down (the paper's Fig. 5).

use nalgebra::SVector;

use super::Result;
use super::{
    DEFAULT_BLOCKS, LyapunovError, Norm, TwoTrajectory, check_blocks, check_interval,
    check_intervals,
};
use crate::integrate::{Stats, Stepper};
use crate::scalar::{lit, to_f64};
use crate::{Dynamics, Real};

/// The direction of a continuation branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum DiagramDirection {
    /// The parameter values in the given order (the paper's red line).
    Increasing,
    /// The parameter values in reverse order (the paper's green line).
    Decreasing,
}

impl DiagramDirection {
    /// `"increasing"` or `"decreasing"` (for tidy output).
    pub fn as_str(&self) -> &'static str {
        match self {
            DiagramDirection::Increasing => "increasing",
            DiagramDirection::Decreasing => "decreasing",
        }
    }
}

/// How the renormalization interval follows the parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum IntervalRule<T> {
    /// The same `τ` for every value.
    Fixed(T),
    /// `τ = 2π/p`: the parameter `p` is the angular forcing frequency and the interval is
    /// one forcing period (the paper's choice). Then every run covers whole periods from
    /// `t0`, ends at a stroboscopic point, and the next value starts at `t0` again: the
    /// forcing phase `ωt` is continuous across the parameter step.
    ForcingPeriod,
}

impl<T: Real> IntervalRule<T> {
    /// The interval for parameter value `p`.
    ///
    /// # Errors
    /// [`LyapunovError::InvalidInterval`] if the resulting `τ` is not finite and > 0.
    pub fn interval(&self, p: T) -> Result<T, LyapunovError> {
        match *self {
            IntervalRule::Fixed(tau) => check_interval(tau),
            IntervalRule::ForcingPeriod => check_interval(lit::<T>(std::f64::consts::TAU) / p),
        }
    }
}

/// The schedule of a diagram: transients and averaging lengths, in intervals.
///
/// Deserialization (feature `serde`) applies the checks of [`new`](Self::new) and
/// [`with_blocks`](Self::with_blocks); `t0`, which they do not take, is checked when a
/// diagram starts.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[non_exhaustive]
pub struct DiagramSettings<T> {
    /// The renormalization interval.
    pub interval: IntervalRule<T>,
    /// Intervals discarded at the first value of each branch (from the initial state).
    pub first_transient: usize,
    /// Intervals discarded after each parameter step.
    pub step_transient: usize,
    /// Intervals averaged per value.
    pub intervals: usize,
    /// Blocks for the spread.
    pub blocks: usize,
    /// The time at which every value's run starts (the clock restarts there; 0 for the
    /// paper's Poincaré section `t = 2πi/ω`).
    pub t0: T,
}

crate::serde_check::deserialize_checked! {
    "DiagramSettings",
    DiagramSettings<T: Real> {
        interval: IntervalRule<T>,
        first_transient: usize,
        step_transient: usize,
        intervals: usize,
        blocks: usize,
        t0: T,
    },
    |raw| -> LyapunovError {
        let settings = DiagramSettings::new(
            raw.interval,
            raw.first_transient,
            raw.step_transient,
            raw.intervals,
        )?
        .with_blocks(raw.blocks)?;
        DiagramSettings { t0: raw.t0, ..settings }
    }
}

impl<T: Real> DiagramSettings<T> {
    /// A schedule with 10 blocks and `t0 = 0`.
    ///
    /// # Errors
    /// [`LyapunovError::TooFewIntervals`] if `intervals < 2`;
    /// [`LyapunovError::InvalidInterval`] for a bad fixed interval.
    pub fn new(
        interval: IntervalRule<T>,
        first_transient: usize,
        step_transient: usize,
        intervals: usize,
    ) -> Result<Self, LyapunovError> {
        check_intervals(intervals, 2)?;
        if let IntervalRule::Fixed(tau) = interval {
            check_interval(tau)?;
        }
        Ok(Self {
            interval,
            first_transient,
            step_transient,
            intervals,
            blocks: DEFAULT_BLOCKS,
            t0: T::zero(),
        })
    }

    /// Sets the number of blocks (it is capped at the number of intervals).
    ///
    /// # Errors
    /// [`LyapunovError::InvalidBlocks`] if `blocks < 2`.
    pub fn with_blocks(mut self, blocks: usize) -> Result<Self, LyapunovError> {
        self.blocks = check_blocks(blocks)?;
        Ok(self)
    }
}

/// One value of a diagram.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DiagramPoint<T> {
    /// The parameter value.
    pub parameter: T,
    /// The top-exponent estimate.
    pub exponent: T,
    /// Its standard error from blocks.
    pub spread: T,
    /// The work for this value (transient and estimate, augmented system).
    pub stats: Stats,
}

/// Both branches of a diagram, each in the order it was computed.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Diagram<T> {
    /// The values in the given order.
    pub increasing: Vec<DiagramPoint<T>>,
    /// The values in reverse order.
    pub decreasing: Vec<DiagramPoint<T>>,
}

impl<T> Diagram<T> {
    /// The points of one branch.
    pub fn branch(&self, branch: DiagramDirection) -> &[DiagramPoint<T>] {
        match branch {
            DiagramDirection::Increasing => &self.increasing,
            DiagramDirection::Decreasing => &self.decreasing,
        }
    }
}

/// The top Lyapunov exponent over a list of parameter values by the two-trajectory method,
/// with continuation in both directions (the paper's Fig. 5).
///
/// The increasing branch visits `values` in the given order, the decreasing branch in
/// reverse order. Each branch starts from `y0` at its first value and runs
/// `first_transient` intervals; every further value starts from the end state of the
/// previous one (reference *and* perturbation), with the clock reset to `settings.t0`,
/// runs `step_transient` intervals, then `intervals` recorded ones. `make(p)` builds the
/// system for parameter `p`. With feature `parallel` the two branches run concurrently
/// (rayon); each is sequential, so the results are bit-identical whatever the number of
/// threads.
///
/// This is a small self-contained sweep; the crate's general sweep module may take it over.
///
/// ```
/// use nalgebra::Vector2;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::lyapunov::{DiagramSettings, IntervalRule, Norm, pair_tolerances, tle_diagram};
/// use nonsmooth::testing::DampedOscillator;
///
/// // Damped oscillators ω₀ = 1, ζ = p: the exponent is −p.
/// let tol = pair_tolerances::<f64, 2, 4>(&Tolerances::new(1e-10, 1e-12)?)?;
/// let settings = DiagramSettings::new(IntervalRule::Fixed(1.0), 5, 2, 100)?;
/// let d = tle_diagram(
///     |p: f64| Ok(DampedOscillator::new(1.0, p)?),
///     &Dopri5::new(tol),
///     Vector2::new(1.0, 0.0),
///     &[0.1, 0.2],
///     1e-6,
///     Norm::Euclidean,
///     &settings,
/// )?;
/// assert_eq!(d.decreasing[0].parameter, 0.2);
/// assert!((d.increasing[1].exponent + 0.2).abs() < 0.02);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
///
/// # Errors
/// [`LyapunovError::NoParameters`] for an empty list; [`LyapunovError::InvalidParameter`]
/// for a non-finite value (or a non-positive one with [`IntervalRule::ForcingPeriod`]);
/// the errors of `make`, of [`TwoTrajectory::new`] and of its runs (the first failure of
/// either branch is returned).
#[allow(clippy::too_many_arguments)]
pub fn tle_diagram<T, const N: usize, const M: usize, S, St, F>(
    make: F,
    stepper: &St,
    y0: SVector<T, N>,
    values: &[T],
    d0: T,
    norm: Norm<T, N>,
    settings: &DiagramSettings<T>,
) -> Result<Diagram<T>>
where
    T: Real,
    S: Dynamics<T, N>,
    St: Stepper<T, M> + Clone + Send + Sync,
    F: Fn(T) -> Result<S> + Sync,
{
    check_diagram::<T, N, M>(values, d0, &norm, settings)?;
    let branch = |dir: DiagramDirection| -> Result<Vec<DiagramPoint<T>>> {
        let mut out = Vec::with_capacity(values.len());
        let mut est: Option<TwoTrajectory<T, N, M, S, St>> = None;
        for i in 0..values.len() {
            let p = match dir {
                DiagramDirection::Increasing => values[i],
                DiagramDirection::Decreasing => values[values.len() - 1 - i],
            };
            let system = make(p)?;
            let tau = settings.interval.interval(p)?;
            let point = match est.as_mut() {
                None => {
                    let mut e = TwoTrajectory::new(system, stepper.clone(), d0, norm)?
                        .with_blocks(settings.blocks)?;
                    e.start(settings.t0, y0)?;
                    let point = measure(&mut e, p, tau, settings.first_transient, settings)?;
                    est = Some(e);
                    point
                }
                // From the previous value's end state, reference and perturbation.
                Some(e) => {
                    e.set_system(system);
                    e.set_time(settings.t0)?;
                    measure(e, p, tau, settings.step_transient, settings)?
                }
            };
            out.push(point);
        }
        Ok(out)
    };
    #[cfg(feature = "parallel")]
    let (up, down) = rayon::join(
        || branch(DiagramDirection::Increasing),
        || branch(DiagramDirection::Decreasing),
    );
    #[cfg(not(feature = "parallel"))]
    let (up, down) = (
        branch(DiagramDirection::Increasing),
        branch(DiagramDirection::Decreasing),
    );
    Ok(Diagram {
        increasing: up?,
        decreasing: down?,
    })
}

/// Checks the inputs of [`tle_diagram`], everything that can be checked before spending
/// time on a branch: the values (at least one, finite, `> 0` with
/// [`IntervalRule::ForcingPeriod`]), the schedule and the pair's `d0` and norm.
fn check_diagram<T: Real, const N: usize, const M: usize>(
    values: &[T],
    d0: T,
    norm: &Norm<T, N>,
    settings: &DiagramSettings<T>,
) -> Result<()> {
    if values.is_empty() {
        return Err(LyapunovError::NoParameters);
    }
    for &p in values {
        if !p.is_finite() {
            return Err(LyapunovError::InvalidParameter {
                value: to_f64(p),
                requirement: "must be finite",
            });
        }
        if settings.interval == IntervalRule::ForcingPeriod && !(p > T::zero()) {
            return Err(LyapunovError::InvalidParameter {
                value: to_f64(p),
                requirement: "must be > 0 (an angular forcing frequency) with IntervalRule::ForcingPeriod",
            });
        }
    }
    check_intervals(settings.intervals, 2)?;
    check_blocks(settings.blocks)?;
    if !settings.t0.is_finite() {
        return Err(LyapunovError::NonFinite {
            what: "t0",
            value: to_f64(settings.t0),
        });
    }
    super::two_trajectory::check_pair_settings::<T, N, M>(d0, norm)
}

/// The point at `p` of a started estimator `e`: `transient` intervals `tau` discarded,
/// then `settings.intervals` averaged; its work counts both.
fn measure<T, const N: usize, const M: usize, S, St>(
    e: &mut TwoTrajectory<T, N, M, S, St>,
    p: T,
    tau: T,
    transient: usize,
    settings: &DiagramSettings<T>,
) -> Result<DiagramPoint<T>>
where
    T: Real,
    S: Dynamics<T, N>,
    St: Stepper<T, M>,
{
    let s0 = *e.stepper().stats();
    e.transient(tau, transient)?;
    let r = e.estimate(tau, settings.intervals)?;
    Ok(DiagramPoint {
        parameter: p,
        exponent: r.exponent,
        spread: r.spread,
        stats: e.stepper().stats().since(&s0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_rules() {
        assert_eq!(IntervalRule::Fixed(0.5_f64).interval(3.0), Ok(0.5));
        assert!(IntervalRule::Fixed(0.0_f64).interval(3.0).is_err());
        let t = IntervalRule::ForcingPeriod.interval(20.0_f64).unwrap();
        assert!((t - std::f64::consts::TAU / 20.0).abs() < 1e-16);
        assert!(IntervalRule::<f64>::ForcingPeriod.interval(0.0).is_err());
        assert_eq!(DiagramDirection::Decreasing.as_str(), "decreasing");
        let p = DiagramSettings::new(IntervalRule::<f64>::ForcingPeriod, 100, 50, 1000).unwrap();
        assert_eq!(
            (p.first_transient, p.step_transient, p.intervals, p.blocks),
            (100, 50, 1000, DEFAULT_BLOCKS)
        );
        assert!(DiagramSettings::new(IntervalRule::Fixed(1.0_f64), 1, 1, 1).is_err());
        assert!(DiagramSettings::new(IntervalRule::Fixed(f64::NAN), 1, 1, 10).is_err());
        assert!(p.with_blocks(1).is_err());
    }
}
