//! Identification of the paper's model from a measured (or synthetic) position record, a
//! configuration of the generic [`ModelFit`].

use std::cell::Cell;
use std::time::{Duration, Instant};

use nalgebra::Vector2;

use super::{Forcing, PaperParameters};
use crate::Dynamics;
use crate::identify::{
    FitReport, IdentifyError, M2_TO_MM2, ModelFit, NelderMeadOptions, ParamValues, Parameter,
    ParameterSpace, objective_f0, simulate_at_nodes, window_nodes,
};
use crate::integrate::Tolerances;
use crate::signal::TimeSeries;
use crate::validate::ParameterError;

/// The names of the paper's estimated parameters `μ = (k, c, T, k_I, b, n₂, n₃)` (Sect. 2),
/// as [`PaperFit`] knows them: `k` (N/m), `c` (N·s/m), `t` (N), `k_i` (N/m^{3/2}), `b`
/// (m^{−n₃}·s^{n₃}), `n2`, `n3` — the fields [`PaperParameters::k`], `c`, `t`, `k_i`, `b`,
/// `n2`, `n3`, spelled as the fields (and as a study file names them).
///
/// Where a name is read ([`paper_parameter`], [`set_paper_parameter`], [`PaperFit::fit`],
/// [`PaperFitReport::value`]) the friction amplitude is also accepted as `T`, the paper's
/// symbol.
pub const PAPER_FIT_PARAMETERS: [&str; 7] = ["k", "c", "t", "k_i", "b", "n2", "n3"];

/// The name of [`PAPER_FIT_PARAMETERS`] that `name` spells (`T` is `t`), if any.
fn canonical(name: &str) -> Option<&'static str> {
    match name {
        "T" => Some("t"),
        _ => PAPER_FIT_PARAMETERS.iter().copied().find(|&n| n == name),
    }
}

/// The value of the estimated parameter `name` (one of [`PAPER_FIT_PARAMETERS`]; `T` is
/// accepted for `t`) in `p`.
///
/// # Errors
/// [`IdentifyError::UnknownParameter`] for any other name.
pub fn paper_parameter(p: &PaperParameters, name: &str) -> Result<f64, IdentifyError> {
    Ok(match canonical(name) {
        Some("k") => p.k,
        Some("c") => p.c,
        Some("t") => p.t,
        Some("k_i") => p.k_i,
        Some("b") => p.b,
        Some("n2") => p.n2,
        Some("n3") => p.n3,
        _ => return Err(IdentifyError::UnknownParameter { name: name.into() }),
    })
}

/// Sets the estimated parameter `name` (one of [`PAPER_FIT_PARAMETERS`]; `T` is accepted
/// for `t`) in `p` (no validation: the model's constructors validate).
///
/// # Errors
/// [`IdentifyError::UnknownParameter`] for any other name.
pub fn set_paper_parameter(
    p: &mut PaperParameters,
    name: &str,
    value: f64,
) -> Result<(), IdentifyError> {
    let slot = match canonical(name) {
        Some("k") => &mut p.k,
        Some("c") => &mut p.c,
        Some("t") => &mut p.t,
        Some("k_i") => &mut p.k_i,
        Some("b") => &mut p.b,
        Some("n2") => &mut p.n2,
        Some("n3") => &mut p.n3,
        _ => return Err(IdentifyError::UnknownParameter { name: name.into() }),
    };
    *slot = value;
    Ok(())
}

/// Estimates parameters of the paper's model from a measured position record by minimizing
/// the paper's objective `F0` with Nelder–Mead, as the paper does with `fminsearch`
/// (Sect. 2).
///
/// # Method
/// A configuration of the generic [`ModelFit`]: for trial parameters `μ` (the fitted ones
/// from the optimizer, the others fixed at the base [`PaperParameters`]) the model is simulated from `t = 0` — the time origin of the
/// record and of the forcing phase — at rest in the static equilibrium `X0(μ)` **of the
/// trial parameters** (the stand starts at rest pressed into the stop, and `X0` depends on
/// `k` and `k_I`), with [`Dopri5`](crate::integrate::Dopri5) at the configured tolerances
/// (default `Tolerances::per_component(1e-10, [1e-14, 1e-12])`, see below). The dense
/// output is
/// sampled exactly at the window ends and at every measured time inside the window, and
/// $$ F_0(\mu) = \frac{1}{t_2 - t_1}\int_{t_1}^{t_2}
///    \bigl(x_\mathrm{exp}(t) - x_\mathrm{sim}(t;\mu)\bigr)^2\,dt $$
/// is evaluated by [`objective_f0`](crate::identify::objective_f0) (trapezoidal rule on the
/// measured samples, in m²; reported in mm² as the paper does).
///
/// The fitted parameters are [`Parameter::positive`] (log-transformed: every one of
/// `k, c, T, k_I, b, n₂, n₃` is positive, the simplex moves in relative steps, and
/// parameters spanning eight decades, `c ≈ 7` and `k_I ≈ 2·10⁸`, are treated alike),
/// optionally with bounds; [`fit_parameter`](Self::fit_parameter) accepts any
/// [`Parameter`] (e.g. an identity transform), in which case a trial outside the model's
/// domain (a negative `c`) fails to build the model.
///
/// # Tolerances
/// The integrator's error is not a smooth function of the parameters (the adaptive step
/// sequence changes discretely), so `F0` computed by simulation carries a "jitter" that
/// Nelder–Mead sees as a rough landscape once the simplex is small. On the paper's model at
/// ω = 17 rad/s, 2 s of data with 2 µm noise (`F0 ≈ 4.4·10⁻¹² m²`), the jitter of `F0` under
/// parameter changes of `10⁻⁹` is `2.4·10⁻¹⁷ m²` at `rtol = 10⁻⁸`, `1.8·10⁻¹⁸` at `10⁻⁹` and
/// below `8·10⁻¹⁹` at `10⁻¹⁰`, while the cost per simulation grows only from 5.5 to 6.7 ms
/// (the work is dominated by the nonsmooth points, not by the tolerance). At `10⁻⁸` the
/// jitter is comparable to the `F0` differences that separate parameter values one standard
/// deviation apart along the weakest direction, and seven-parameter fits stalled; hence the
/// default `10⁻¹⁰`.
///
/// A trial whose simulation fails — invalid parameters, no static equilibrium, the step cap
/// ([`with_max_steps`](Self::with_max_steps)) reached, the step size underflowing, an
/// accumulation of events — is a bad point: the optimizer gives it `+∞` and moves on
/// ([`fit_nelder_mead`](crate::identify::fit_nelder_mead)), and
/// [`PaperFitReport::failed_simulations`] counts it.
///
/// The paper reaches `F0 = 0.00997 mm²` on its measured record.
///
/// # Examples
/// ```
/// use nonsmooth::systems::paper::{Forcing, PAPER, PaperFit, SyntheticExperiment};
///
/// // Half a second "measured" at ω = 20.465 rad/s with the paper's parameters…
/// let data = SyntheticExperiment::new(PAPER, Forcing::constant(20.465), 0.5)?.generate()?;
/// // …and c recovered from a guess 20 % off, the other parameters fixed at the paper's.
/// let report = PaperFit::new(data.measured, (0.0, 0.5), Forcing::constant(20.465), PAPER)?
///     .fit("c", 1.2 * PAPER.c)?
///     .run()?;
/// assert!((report.parameters.c / PAPER.c - 1.0).abs() < 1e-3);
/// assert!(report.f0_mm2 < 1e-8);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PaperFit {
    measured: TimeSeries,
    window: (f64, f64),
    forcing: Forcing,
    base: PaperParameters,
    fitted: Vec<Parameter>,
    tolerances: Tolerances<f64, 2>,
    max_steps: Option<usize>,
    options: NelderMeadOptions,
    nodes: Vec<f64>,
}

/// The result of [`PaperFit::run`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PaperFitReport {
    /// The complete fitted parameter set (the base set with the fitted values).
    pub parameters: PaperParameters,
    /// The optimizer's report: fitted values by name, `F0` (m²), evaluations, iterations,
    /// convergence history (best `F0` in m² per iteration), termination.
    pub fit: FitReport,
    /// `F0` at the fitted parameters (mm²).
    pub f0_mm2: f64,
    /// `F0` at the initial guess (mm²).
    pub initial_f0_mm2: f64,
    /// Simulations run (one per objective evaluation).
    pub simulations: u64,
    /// Trials that failed (simulation error, or parameters outside the model's domain).
    pub failed_simulations: u64,
    /// Wall time of the whole fit.
    pub wall_time: Duration,
}

impl PaperFitReport {
    /// The fitted value of `name` (as it was given to the fit; `T` and `t` name the same
    /// parameter).
    ///
    /// # Errors
    /// [`IdentifyError::UnknownParameter`] if `name` was not fitted.
    pub fn value(&self, name: &str) -> Result<f64, IdentifyError> {
        let wanted = canonical(name);
        match self.fit.values.get(name) {
            Err(e) if wanted.is_some() => self
                .fit
                .values
                .iter()
                .find(|&(n, _)| canonical(n) == wanted)
                .map(|(_, v)| v)
                .ok_or(e),
            found => found,
        }
    }
}

impl PaperFit {
    /// Steps allowed per simulated second by default (see [`with_max_steps`](Self::with_max_steps)).
    pub const DEFAULT_STEPS_PER_SECOND: usize = 250_000;

    /// A fit of the model `base` under `forcing` to `measured` on the window `[t1, t2]`
    /// (seconds, the record's time axis, whose origin `t = 0` is the start from rest and
    /// the forcing's phase origin). No parameter is fitted yet: add them with
    /// [`fit`](Self::fit).
    ///
    /// # Errors
    /// [`IdentifyError::InvalidWindow`] unless `0 ≤ t1 < t2` are finite;
    /// [`IdentifyError::WindowOutsideData`] if `[t1, t2]` is not inside the record;
    /// [`IdentifyError::EmptyWindow`] if fewer than two samples lie in it.
    pub fn new(
        measured: TimeSeries,
        window: (f64, f64),
        forcing: Forcing,
        base: PaperParameters,
    ) -> Result<Self, IdentifyError> {
        let nodes = window_nodes(&measured, window)?;
        Ok(Self {
            measured,
            window,
            forcing,
            base,
            fitted: Vec::new(),
            tolerances: Tolerances {
                rtol: Vector2::repeat(1e-10),
                atol: Vector2::new(1e-14, 1e-12),
            },
            max_steps: None,
            options: NelderMeadOptions::default()
                .with_tolerances(1e-4, 1e-6)
                .with_restarts(1),
            nodes,
        })
    }

    /// Fits `name` (one of [`PAPER_FIT_PARAMETERS`]; `T` is accepted for `t`) from the
    /// initial guess `initial`, as a positive (log-transformed) parameter.
    ///
    /// # Errors
    /// As [`fit_parameter`](Self::fit_parameter).
    pub fn fit(self, name: &str, initial: f64) -> Result<Self, IdentifyError> {
        self.fit_parameter(Parameter::positive(name, initial))
    }

    /// Fits `name` as a positive parameter within `[lower, upper]`.
    ///
    /// # Errors
    /// As [`fit_parameter`](Self::fit_parameter).
    pub fn fit_bounded(
        self,
        name: &str,
        initial: f64,
        lower: f64,
        upper: f64,
    ) -> Result<Self, IdentifyError> {
        self.fit_parameter(Parameter::positive(name, initial).with_bounds(lower, upper))
    }

    /// Fits a parameter given in full (name, initial value, bounds, transform). The
    /// report and the fit's values use the name as given.
    ///
    /// # Errors
    /// [`IdentifyError::UnknownParameter`] unless the name is one of
    /// [`PAPER_FIT_PARAMETERS`] (or `T`); [`IdentifyError::DuplicateParameter`] if it is
    /// already fitted (under either spelling); the [`ParameterSpace::new`] errors for an
    /// invalid initial value or bounds.
    pub fn fit_parameter(mut self, parameter: Parameter) -> Result<Self, IdentifyError> {
        let name = parameter.name();
        paper_parameter(&self.base, name)?;
        if self
            .fitted
            .iter()
            .any(|p| canonical(p.name()) == canonical(name))
        {
            return Err(IdentifyError::DuplicateParameter { name: name.into() });
        }
        ParameterSpace::new([parameter.clone()])?;
        self.fitted.push(parameter);
        Ok(self)
    }

    /// Sets the integrator's tolerances (default
    /// `Tolerances::per_component(1e-10, [1e-14, 1e-12])`; see the type's docs for why
    /// tighter than the sweeps' `1e-8`).
    #[must_use]
    pub fn with_tolerances(mut self, tolerances: Tolerances<f64, 2>) -> Self {
        self.tolerances = tolerances;
        self
    }

    /// Caps the integrator's steps per simulation (default
    /// [`DEFAULT_STEPS_PER_SECOND`](Self::DEFAULT_STEPS_PER_SECOND)` · ⌈t2⌉`, about ten
    /// times what the paper's model needs at the default tolerances in its stiffest
    /// regime, sticking contact near ω = 15 rad/s). A trial reaching the cap is a bad point,
    /// which keeps absurd trials (a contact stiffness a thousand times too high) cheap.
    ///
    /// # Errors
    /// [`IdentifyError::Parameter`] if `max_steps == 0`.
    pub fn with_max_steps(mut self, max_steps: usize) -> Result<Self, IdentifyError> {
        if max_steps == 0 {
            return Err(ParameterError::new("max_steps", 0.0, "> 0").into());
        }
        self.max_steps = Some(max_steps);
        Ok(self)
    }

    /// Sets the Nelder–Mead options (default: `x_tolerance = 10⁻⁴`, `f_tolerance = 10⁻⁶`,
    /// one restart, the rest as [`NelderMeadOptions::default`]).
    #[must_use]
    pub fn with_options(mut self, options: NelderMeadOptions) -> Self {
        self.options = options;
        self
    }

    /// The window `(t1, t2)`.
    pub fn window(&self) -> (f64, f64) {
        self.window
    }

    /// The forcing.
    pub fn forcing(&self) -> Forcing {
        self.forcing
    }

    /// The base (fixed) parameters.
    pub fn base(&self) -> &PaperParameters {
        &self.base
    }

    /// The measured record.
    pub fn measured(&self) -> &TimeSeries {
        &self.measured
    }

    /// The times at which the simulation is compared with the record: `t1`, the measured
    /// times strictly inside the window, `t2`.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// The step cap per simulation in effect.
    pub fn max_steps(&self) -> usize {
        self.max_steps.unwrap_or_else(|| {
            let seconds = self.window.1.ceil().max(1.0);
            // Saturates for absurd windows rather than overflowing.
            (Self::DEFAULT_STEPS_PER_SECOND as f64 * seconds).min(usize::MAX as f64) as usize
        })
    }

    /// The parameter space of the fitted parameters.
    ///
    /// # Errors
    /// [`IdentifyError::EmptySpace`] if nothing is fitted.
    pub fn space(&self) -> Result<ParameterSpace, IdentifyError> {
        ParameterSpace::new(self.fitted.iter().cloned())
    }

    /// The base parameters with `values` substituted.
    ///
    /// # Errors
    /// [`IdentifyError::UnknownParameter`] if a name is not one of [`PAPER_FIT_PARAMETERS`].
    pub fn parameters(&self, values: &ParamValues) -> Result<PaperParameters, IdentifyError> {
        let mut p = self.base;
        for (name, v) in values.iter() {
            set_paper_parameter(&mut p, name, v)?;
        }
        Ok(p)
    }

    /// The simulated position at [`nodes`](Self::nodes) for the parameter set `params`
    /// (from rest in its static equilibrium at `t = 0`).
    ///
    /// # Errors
    /// Invalid parameters ([`ParameterError`](crate::ParameterError)), no static
    /// equilibrium, or a failed simulation (e.g.
    /// [`IntegrateError::MaxSteps`](crate::integrate::IntegrateError::MaxSteps)).
    pub fn simulate(&self, params: &PaperParameters) -> crate::Result<Vec<f64>> {
        let x0 = params.static_equilibrium()?;
        let y0 = Vector2::new(x0, 0.0);
        let (nodes, tol, cap, w) = (
            &self.nodes[..],
            self.tolerances,
            self.max_steps(),
            self.window,
        );
        Ok(match self.forcing {
            Forcing::Constant { omega } => {
                simulate_at_nodes(params.oscillator::<f64>(omega)?, tol, cap, y0, nodes, 0, w)
            }
            Forcing::Ramp { omega0, rate } => simulate_at_nodes(
                params.ramped::<f64>(omega0, rate)?,
                tol,
                cap,
                y0,
                nodes,
                0,
                w,
            ),
        }?)
    }

    /// `F0` (m²) of the parameter set `params` against the record on the window.
    ///
    /// # Errors
    /// As [`simulate`](Self::simulate), and [`objective_f0`]'s.
    pub fn objective(&self, params: &PaperParameters) -> crate::Result<f64> {
        let x = self.simulate(params)?;
        Ok(objective_f0(&self.measured, &self.nodes, &x, self.window)?)
    }

    /// `F0` (m²) with the fitted parameters set to `values`.
    ///
    /// # Errors
    /// As [`parameters`](Self::parameters) and [`objective`](Self::objective).
    pub fn objective_at(&self, values: &ParamValues) -> crate::Result<f64> {
        self.objective(&self.parameters(values)?)
    }

    /// Runs the fit: the [`ModelFit`] of the oscillator under the forcing, built from the
    /// base parameters with the trial values and started from rest in its static
    /// equilibrium, on the position.
    ///
    /// # Errors
    /// [`IdentifyError::EmptySpace`] if nothing is fitted;
    /// [`IdentifyError::InitialPointFailed`] if the simulation fails at the initial guess;
    /// [`IdentifyError::Parameter`] for invalid optimizer options. Failures at other trial
    /// points are not errors (see the type's docs).
    pub fn run(&self) -> Result<PaperFitReport, IdentifyError> {
        let start = Instant::now();
        let simulations = Cell::new(0u64);
        let fit = match self.forcing {
            Forcing::Constant { omega } => {
                self.fit_with(&simulations, move |p| p.oscillator::<f64>(omega))
            }
            Forcing::Ramp { omega0, rate } => {
                self.fit_with(&simulations, move |p| p.ramped::<f64>(omega0, rate))
            }
        }?;
        let parameters = self.parameters(&fit.values)?;
        Ok(PaperFitReport {
            parameters,
            f0_mm2: fit.objective * M2_TO_MM2,
            initial_f0_mm2: fit.initial_objective * M2_TO_MM2,
            simulations: simulations.get(),
            failed_simulations: fit.failed_evaluations,
            fit,
            wall_time: start.elapsed(),
        })
    }

    /// The [`ModelFit`] of `system(parameters)` from rest in the static equilibrium, run;
    /// `simulations` counts the models built (one per objective evaluation).
    fn fit_with<S: Dynamics<f64, 2>>(
        &self,
        simulations: &Cell<u64>,
        system: impl Fn(&PaperParameters) -> Result<S, ParameterError>,
    ) -> Result<FitReport, IdentifyError> {
        let build = |values: &ParamValues| {
            simulations.set(simulations.get() + 1);
            let p = self.parameters(values)?;
            let x0 = p.static_equilibrium()?;
            Ok((system(&p)?, Vector2::new(x0, 0.0)))
        };
        let mut fit = ModelFit::new(self.measured.clone(), self.window, 0, build)?
            .with_tolerances(self.tolerances)
            .with_max_steps(self.max_steps())?
            .with_options(self.options.clone());
        for parameter in &self.fitted {
            fit = fit.fit_parameter(parameter.clone())?;
        }
        fit.run()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::systems::paper::PAPER;

    #[test]
    fn names_map_to_fields() {
        let mut p = PAPER;
        for (i, name) in PAPER_FIT_PARAMETERS.iter().enumerate() {
            set_paper_parameter(&mut p, name, i as f64 + 0.5).unwrap();
        }
        assert_eq!(
            (p.k, p.c, p.t, p.k_i, p.b, p.n2, p.n3),
            (0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5)
        );
        for (i, name) in PAPER_FIT_PARAMETERS.iter().enumerate() {
            assert_eq!(paper_parameter(&p, name).unwrap(), i as f64 + 0.5);
        }
        // Untouched fields.
        assert_eq!(
            (p.m, p.x_i, p.n1, p.eps),
            (PAPER.m, PAPER.x_i, PAPER.n1, PAPER.eps)
        );
        assert!(matches!(
            paper_parameter(&p, "m"),
            Err(IdentifyError::UnknownParameter { .. })
        ));
    }

    #[test]
    fn the_symbol_t_is_an_alias_of_the_field_name() {
        let mut p = PAPER;
        set_paper_parameter(&mut p, "T", 0.25).unwrap();
        assert_eq!(p.t, 0.25);
        assert_eq!(paper_parameter(&p, "T").unwrap(), 0.25);
        assert!(paper_parameter(&p, "K").is_err());
        let t: Vec<f64> = (0..=10).map(|i| 0.1 * i as f64).collect();
        let record = TimeSeries::new(t, vec![0.0; 11], None).unwrap();
        let fit = PaperFit::new(record, (0.0, 1.0), Forcing::constant(20.0), PAPER)
            .unwrap()
            .fit("T", 0.5)
            .unwrap();
        assert!(matches!(
            fit.clone().fit("t", 0.5),
            Err(IdentifyError::DuplicateParameter { .. })
        ));
        let values = fit.space().unwrap().initial_values();
        assert_eq!(fit.parameters(&values).unwrap().t, 0.5);
    }
}
