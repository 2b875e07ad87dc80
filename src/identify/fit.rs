//! Nelder–Mead fitting in a [`ParameterSpace`].

use super::{IdentifyError, ParamValues, ParameterSpace};
use crate::validate::ParameterError;
use crate::validate::positive;

/// Settings of [`fit_nelder_mead`].
///
/// ```
/// use nonsmooth::identify::NelderMeadOptions;
/// let o = NelderMeadOptions::default().with_max_iterations(500).with_tolerances(1e-9, 1e-12);
/// assert_eq!(o.max_iterations, Some(500));
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct NelderMeadOptions {
    /// Iteration cap over all runs; `None` means `200·n` as in `fminsearch`.
    pub max_iterations: Option<u64>,
    /// Cap on objective calls over all runs (checked before each iteration, which makes at
    /// most `n + 2` calls); `None`: no cap besides the iteration cap.
    pub max_evaluations: Option<u64>,
    /// Simplex-size tolerance: converged when, in every unconstrained coordinate, all
    /// vertices lie within `x_tolerance` times that coordinate's start-simplex step of the
    /// best vertex (unit-free; default `1e-8`).
    pub x_tolerance: f64,
    /// Objective-spread tolerance: converged when every vertex's objective is within
    /// `f_tolerance·|F(initial)|` of the best (absolute if `F(initial) = 0`; default
    /// `1e-10`). Both tolerances must hold, as in `fminsearch`.
    pub f_tolerance: f64,
    /// Relative step of the start simplex (default 0.05, `fminsearch`'s).
    pub relative_step: f64,
    /// Step for parameters whose value is 0 (default 0.00025, `fminsearch`'s).
    pub zero_step: f64,
    /// Objective value given to a point where the objective fails (returns `Err`, NaN or
    /// `+∞`) or the parameters cannot be mapped; default `+∞`, which Nelder–Mead simply
    /// moves away from. Must not be NaN.
    pub failure_penalty: f64,
    /// Stop as soon as the best objective is `≤ target` (default none).
    pub target: Option<f64>,
    /// Number of restarts: after convergence a fresh start simplex is built around the best
    /// point and the search repeated, up to this many times, stopping early when a restart
    /// does not improve the best value (guards against Nelder–Mead's premature collapse).
    /// Default 0.
    pub restarts: usize,
}

impl Default for NelderMeadOptions {
    fn default() -> Self {
        Self {
            max_iterations: None,
            max_evaluations: None,
            x_tolerance: 1e-8,
            f_tolerance: 1e-10,
            relative_step: 0.05,
            zero_step: 0.00025,
            failure_penalty: f64::INFINITY,
            target: None,
            restarts: 0,
        }
    }
}

impl NelderMeadOptions {
    /// Sets the iteration cap.
    #[must_use]
    pub fn with_max_iterations(mut self, max_iterations: u64) -> Self {
        self.max_iterations = Some(max_iterations);
        self
    }

    /// Sets the cap on objective calls.
    #[must_use]
    pub fn with_max_evaluations(mut self, max_evaluations: u64) -> Self {
        self.max_evaluations = Some(max_evaluations);
        self
    }

    /// Sets the simplex-size and objective-spread tolerances.
    #[must_use]
    pub fn with_tolerances(mut self, x_tolerance: f64, f_tolerance: f64) -> Self {
        self.x_tolerance = x_tolerance;
        self.f_tolerance = f_tolerance;
        self
    }

    /// Sets the start-simplex steps.
    #[must_use]
    pub fn with_steps(mut self, relative_step: f64, zero_step: f64) -> Self {
        self.relative_step = relative_step;
        self.zero_step = zero_step;
        self
    }

    /// Sets the value given to failing points.
    #[must_use]
    pub fn with_failure_penalty(mut self, failure_penalty: f64) -> Self {
        self.failure_penalty = failure_penalty;
        self
    }

    /// Sets a target objective value.
    #[must_use]
    pub fn with_target(mut self, target: f64) -> Self {
        self.target = Some(target);
        self
    }

    /// Sets the number of restarts.
    #[must_use]
    pub fn with_restarts(mut self, restarts: usize) -> Self {
        self.restarts = restarts;
        self
    }

    fn validate(&self) -> Result<(), ParameterError> {
        for (name, v) in [
            ("x_tolerance", self.x_tolerance),
            ("f_tolerance", self.f_tolerance),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ParameterError::new(name, v, "finite and >= 0"));
            }
        }
        positive("relative_step", self.relative_step)?;
        positive("zero_step", self.zero_step)?;
        if self.failure_penalty.is_nan() {
            return Err(ParameterError::new(
                "failure_penalty",
                self.failure_penalty,
                "not NaN",
            ));
        }
        if let Some(t) = self.target {
            if t.is_nan() {
                return Err(ParameterError::new("target", t, "not NaN"));
            }
        }
        Ok(())
    }
}

/// Why the search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum FitTermination {
    /// Both tolerances were met.
    Converged,
    /// The iteration cap was reached.
    MaxIterations,
    /// The cap on objective calls was reached.
    MaxEvaluations,
    /// The target value was reached.
    TargetReached,
}

impl std::fmt::Display for FitTermination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FitTermination::Converged => "converged",
            FitTermination::MaxIterations => "maximum number of iterations reached",
            FitTermination::MaxEvaluations => "maximum number of objective evaluations reached",
            FitTermination::TargetReached => "target objective reached",
        })
    }
}

/// The result of [`fit_nelder_mead`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FitReport {
    /// The best parameters found, by name.
    pub values: ParamValues,
    /// The objective at [`values`](Self::values).
    pub objective: f64,
    /// The objective at the initial values.
    pub initial_objective: f64,
    /// Number of calls of the objective (the best point is never re-evaluated).
    pub evaluations: u64,
    /// Points treated as failed (objective error, NaN/`+∞`, or unmappable parameters).
    pub failed_evaluations: u64,
    /// The message of the last failure, if any.
    pub last_failure: Option<String>,
    /// Nelder–Mead iterations over all runs.
    pub iterations: u64,
    /// Runs performed (1 + restarts actually made).
    pub runs: usize,
    /// The best objective so far: one entry after each run's start simplex, then one per
    /// iteration (so `history.len() == iterations + runs`; non-increasing).
    pub history: Vec<f64>,
    /// Why the last run stopped.
    pub termination: FitTermination,
}

/// The objective in unconstrained coordinates with failure handling and book-keeping.
struct Evaluator<'a, F> {
    space: &'a ParameterSpace,
    objective: F,
    penalty: f64,
    evaluations: u64,
    failures: u64,
    last_failure: Option<String>,
}

impl<F, E> Evaluator<'_, F>
where
    F: FnMut(&ParamValues) -> Result<f64, E>,
    E: std::fmt::Display,
{
    /// The objective at `u`, `None` on failure.
    fn try_eval(&mut self, u: &[f64]) -> Option<f64> {
        let values = match self.space.to_physical(u) {
            Ok(v) => v,
            Err(e) => {
                self.failures += 1;
                self.last_failure = Some(e.to_string());
                return None;
            }
        };
        self.evaluations += 1;
        match (self.objective)(&values) {
            Ok(v) if !v.is_nan() && v != f64::INFINITY => Some(v),
            Ok(v) => {
                self.failures += 1;
                self.last_failure = Some(format!("objective returned {v}"));
                None
            }
            Err(e) => {
                self.failures += 1;
                self.last_failure = Some(e.to_string());
                None
            }
        }
    }

    /// The objective at `u`, failures replaced by the penalty.
    fn eval(&mut self, u: &[f64]) -> f64 {
        self.try_eval(u).unwrap_or(self.penalty)
    }
}

/// A simplex vertex.
#[derive(Debug, Clone)]
struct Vertex {
    u: Vec<f64>,
    f: f64,
}

/// The start simplex of one run around `best` (kept as vertex 0, not evaluated again) and
/// its per-coordinate steps, the yardstick of the x tolerance.
fn start_simplex<F, E>(
    best: &Vertex,
    ev: &mut Evaluator<'_, F>,
    options: &NelderMeadOptions,
) -> Result<(Vec<Vertex>, Vec<f64>), IdentifyError>
where
    F: FnMut(&ParamValues) -> Result<f64, E>,
    E: std::fmt::Display,
{
    let space = ev.space;
    let n = space.len();
    let at = space.to_physical(&best.u)?;
    let start = space.simplex(at.values(), options.relative_step, options.zero_step)?;
    let steps: Vec<f64> = (0..n)
        .map(|j| (start[j + 1][j] - start[0][j]).abs())
        .collect();
    let mut simplex: Vec<Vertex> = Vec::with_capacity(n + 1);
    simplex.push(best.clone());
    for u in start.into_iter().skip(1) {
        let f = ev.eval(&u);
        simplex.push(Vertex { u, f });
    }
    Ok((simplex, steps))
}

/// Minimizes `objective` over the named parameters of `space` with the Nelder–Mead simplex
/// method, as the paper minimizes `F0` with MATLAB's `fminsearch`.
///
/// # Algorithm
/// Standard coefficients: reflection 1, expansion 2, contraction 1/2, shrink 1/2; outside
/// and inside contractions and the shrink step as in Lagarias et al. (1998). The search runs
/// in the unconstrained coordinates of [`ParameterSpace`] (log and bound maps), so the
/// objective only ever sees physical values inside the bounds. The start simplex is
/// [`ParameterSpace::simplex`] around the initial values: one vertex per parameter, that
/// parameter moved by [`relative_step`](NelderMeadOptions::relative_step) (5 %) of its
/// value, or by [`zero_step`](NelderMeadOptions::zero_step) if it is 0. A run stops when
/// both tolerances hold ([`NelderMeadOptions::x_tolerance`],
/// [`NelderMeadOptions::f_tolerance`]), at the iteration or evaluation cap, or at the
/// target.
///
/// # Why not argmin's `NelderMead`
/// The crate depends on `argmin` with `default-features = false`, which builds
/// `argmin-math` with scalar (`f64`) parameters only: `NelderMead<Vec<f64>, f64>` does not
/// compile without `argmin-math`'s `vec` feature (which also pulls in `rand`). The simplex
/// method is short and outside every hot path, so it is written here, following the
/// `fminsearch` variant (Lagarias et al., SIAM J. Optim. 9 (1998) 112–147) that the paper
/// used, with its termination test (simplex size *and* objective spread).
///
/// # Failures
/// A failing point — the objective returns `Err`, NaN or `+∞`, or the parameters overflow —
/// gets [`NelderMeadOptions::failure_penalty`] (`+∞` by default) and the search goes on; it
/// is counted in [`FitReport::failed_evaluations`]. Only a failure at the initial values is
/// an error. The objective is assumed deterministic: the best vertex carried into a restart
/// is not re-evaluated.
///
/// # Errors
/// [`IdentifyError::Parameter`] for invalid options, [`IdentifyError::InitialPointFailed`]
/// if the objective fails at the initial values, [`IdentifyError::DegenerateSimplex`] if no
/// start step fits within a parameter's bounds.
///
/// # Examples
/// ```
/// use nonsmooth::identify::{NelderMeadOptions, Parameter, ParameterSpace, fit_nelder_mead};
/// let space = ParameterSpace::new([Parameter::new("a", 0.0), Parameter::positive("b", 1.0)])?;
/// let report = fit_nelder_mead(
///     &space,
///     |p| Ok::<f64, String>((p["a"] - 3.0).powi(2) + (p["b"].ln() - 2.0).powi(2)),
///     &NelderMeadOptions::default(),
/// )?;
/// assert!((report.values.get("a")? - 3.0).abs() < 1e-6);
/// assert!((report.values.get("b")? - 2f64.exp()).abs() < 1e-5);
/// # Ok::<(), nonsmooth::identify::IdentifyError>(())
/// ```
pub fn fit_nelder_mead<F, E>(
    space: &ParameterSpace,
    objective: F,
    options: &NelderMeadOptions,
) -> Result<FitReport, IdentifyError>
where
    F: FnMut(&ParamValues) -> Result<f64, E>,
    E: std::fmt::Display,
{
    options.validate()?;
    let n = space.len();
    let max_iterations = options.max_iterations.unwrap_or(200 * n as u64);
    let max_evaluations = options.max_evaluations.unwrap_or(u64::MAX);
    let target = options.target.unwrap_or(f64::NEG_INFINITY);
    let mut ev = Evaluator {
        space,
        objective,
        penalty: options.failure_penalty,
        evaluations: 0,
        failures: 0,
        last_failure: None,
    };
    let initial = space.initial_values();
    let u0 = space.to_unconstrained(initial.values())?;
    let initial_objective = ev
        .try_eval(&u0)
        .ok_or_else(|| IdentifyError::InitialPointFailed {
            message: ev.last_failure.clone().unwrap_or_default(),
        })?;
    let f_tol = if initial_objective != 0.0 && initial_objective.is_finite() {
        options.f_tolerance * initial_objective.abs()
    } else {
        options.f_tolerance
    };

    let mut best = Vertex {
        u: u0,
        f: initial_objective,
    };
    let mut history = Vec::new();
    let mut iterations = 0;
    let mut runs = 0;
    let mut termination;
    loop {
        runs += 1;
        let best_before = best.f;
        let (mut simplex, steps) = start_simplex(&best, &mut ev, options)?;
        sort(&mut simplex);
        history.push(simplex[0].f);
        termination = loop {
            if converged(&simplex, &steps, options.x_tolerance, f_tol) {
                break FitTermination::Converged;
            }
            if simplex[0].f <= target {
                break FitTermination::TargetReached;
            }
            if iterations >= max_iterations {
                break FitTermination::MaxIterations;
            }
            if ev.evaluations >= max_evaluations {
                break FitTermination::MaxEvaluations;
            }
            iterate(&mut simplex, &mut ev);
            iterations += 1;
            history.push(simplex[0].f);
        };
        // The previous best stays in the simplex (shrinks keep vertex 0), so this is ≤ it.
        best = simplex[0].clone();
        let improved = best.f < best_before;
        if termination != FitTermination::Converged
            || runs > options.restarts
            || (runs > 1 && !improved)
        {
            break;
        }
    }
    Ok(FitReport {
        values: space.to_physical(&best.u)?,
        objective: best.f,
        initial_objective,
        evaluations: ev.evaluations,
        failed_evaluations: ev.failures,
        last_failure: ev.last_failure,
        iterations,
        runs,
        history,
        termination,
    })
}

/// Sorts vertices by objective (stable, so older vertices win ties).
fn sort(simplex: &mut [Vertex]) {
    simplex.sort_by(|a, b| a.f.total_cmp(&b.f));
}

/// `fminsearch`'s test: simplex size and objective spread both small.
fn converged(simplex: &[Vertex], steps: &[f64], x_tol: f64, f_tol: f64) -> bool {
    let b = &simplex[0];
    let f_ok = simplex[1..].iter().all(|v| (v.f - b.f).abs() <= f_tol);
    f_ok && simplex[1..].iter().all(|v| {
        v.u.iter()
            .zip(&b.u)
            .zip(steps)
            .all(|((a, c), s)| (a - c).abs() <= x_tol * s)
    })
}

/// One Nelder–Mead iteration on a sorted simplex; leaves it sorted.
fn iterate<F, E>(simplex: &mut [Vertex], ev: &mut Evaluator<'_, F>)
where
    F: FnMut(&ParamValues) -> Result<f64, E>,
    E: std::fmt::Display,
{
    let n = simplex.len() - 1;
    let dim = simplex[0].u.len();
    let mut centroid = vec![0.0; dim];
    for v in &simplex[..n] {
        for (c, x) in centroid.iter_mut().zip(&v.u) {
            *c += x;
        }
    }
    for c in &mut centroid {
        *c /= n as f64;
    }
    // x(τ) = centroid + τ·(centroid − worst).
    let along = |tau: f64, worst: &[f64]| -> Vec<f64> {
        centroid
            .iter()
            .zip(worst)
            .map(|(c, w)| c + tau * (c - w))
            .collect()
    };
    let (f_best, f_second, f_worst) = (simplex[0].f, simplex[n - 1].f, simplex[n].f);
    let xr = along(1.0, &simplex[n].u);
    let fr = ev.eval(&xr);
    let replace = if fr < f_best {
        let xe = along(2.0, &simplex[n].u);
        let fe = ev.eval(&xe);
        if fe < fr {
            Some(Vertex { u: xe, f: fe })
        } else {
            Some(Vertex { u: xr, f: fr })
        }
    } else if fr < f_second {
        Some(Vertex { u: xr, f: fr })
    } else if fr < f_worst {
        let xc = along(0.5, &simplex[n].u);
        let fc = ev.eval(&xc);
        (fc <= fr).then_some(Vertex { u: xc, f: fc })
    } else {
        let xcc = along(-0.5, &simplex[n].u);
        let fcc = ev.eval(&xcc);
        (fcc < f_worst).then_some(Vertex { u: xcc, f: fcc })
    };
    match replace {
        Some(v) => simplex[n] = v,
        None => {
            let best = simplex[0].u.clone();
            for v in &mut simplex[1..] {
                for (x, b) in v.u.iter_mut().zip(&best) {
                    *x = b + 0.5 * (*x - b);
                }
                v.f = ev.eval(&v.u);
            }
        }
    }
    sort(simplex);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::Parameter;

    #[test]
    fn options_are_validated() {
        let s = ParameterSpace::new([Parameter::new("a", 1.0)]).unwrap();
        let f = |p: &ParamValues| Ok::<f64, String>(p["a"] * p["a"]);
        for o in [
            NelderMeadOptions::default().with_tolerances(-1.0, 0.0),
            NelderMeadOptions::default().with_tolerances(0.0, f64::NAN),
            NelderMeadOptions::default().with_steps(0.0, 1e-3),
            NelderMeadOptions::default().with_failure_penalty(f64::NAN),
            NelderMeadOptions::default().with_target(f64::NAN),
        ] {
            assert!(matches!(
                fit_nelder_mead(&s, f, &o),
                Err(IdentifyError::Parameter(_))
            ));
        }
    }

    #[test]
    fn initial_failure_is_an_error() {
        let s = ParameterSpace::new([Parameter::new("a", 1.0)]).unwrap();
        let e = fit_nelder_mead(
            &s,
            |_| Err::<f64, _>("simulation diverged"),
            &NelderMeadOptions::default(),
        )
        .unwrap_err();
        assert_eq!(
            e,
            IdentifyError::InitialPointFailed {
                message: "simulation diverged".into()
            }
        );
    }

    #[test]
    fn one_dimensional_quadratic() {
        let s = ParameterSpace::new([Parameter::new("a", 1.0)]).unwrap();
        let r = fit_nelder_mead(
            &s,
            |p| Ok::<f64, String>((p["a"] - 0.3).powi(2) + 2.0),
            &NelderMeadOptions::default(),
        )
        .unwrap();
        assert!((r.values["a"] - 0.3).abs() < 1e-6, "{}", r.values);
        assert_eq!(r.termination, FitTermination::Converged);
        assert_eq!(r.runs, 1);
        assert_eq!(r.history.len() as u64, r.iterations + 1);
        assert!(r.history.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(r.objective, r.history[r.history.len() - 1]);
    }
}
