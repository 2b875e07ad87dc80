//! Identification of any model from a measured record of one state component.

use std::marker::PhantomData;

use nalgebra::SVector;

use super::{
    FitReport, IdentifyError, NelderMeadOptions, ParamValues, Parameter, ParameterSpace,
    fit_nelder_mead, objective_f0,
};
use crate::Dynamics;
use crate::drive::Simulation;
use crate::integrate::{Dopri5, Tolerances};
use crate::sample::{SectionClock, Stroboscopic};
use crate::signal::TimeSeries;

/// The measured times at which a simulation is sampled, as a section clock.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Nodes<'a>(pub(crate) &'a [f64]);

impl SectionClock<f64> for Nodes<'_> {
    fn section_time(&self, i: u64) -> Option<f64> {
        usize::try_from(i).ok().and_then(|i| self.0.get(i).copied())
    }
    fn first_index_from(&self, t: f64) -> u64 {
        self.0.partition_point(|&s| s < t) as u64
    }
}

/// The nodes of the trapezoidal rule on `[t1, t2]`: `t1`, the measured times strictly
/// inside, `t2`, after checking the window against the record.
pub(crate) fn window_nodes(
    measured: &TimeSeries,
    window: (f64, f64),
) -> Result<Vec<f64>, IdentifyError> {
    let (t1, t2) = window;
    if !(t1.is_finite() && t2.is_finite() && 0.0 <= t1 && t1 < t2) {
        return Err(IdentifyError::InvalidWindow { t1, t2 });
    }
    let (start, end) = measured.span().unwrap_or((f64::NAN, f64::NAN));
    if !(start <= t1 && t2 <= end) {
        return Err(IdentifyError::WindowOutsideData {
            which: "measured",
            t1,
            t2,
            start,
            end,
        });
    }
    let t = measured.t();
    let lo = t.partition_point(|&s| s < t1);
    let hi = t.partition_point(|&s| s <= t2);
    if hi - lo < 2 {
        return Err(IdentifyError::EmptyWindow {
            t1,
            t2,
            samples: hi - lo,
        });
    }
    let mut nodes = Vec::with_capacity(hi - lo + 2);
    nodes.push(t1);
    nodes.extend(t[lo..hi].iter().copied().filter(|&s| t1 < s && s < t2));
    nodes.push(t2);
    Ok(nodes)
}

/// Simulates `system` from `(0, y0)` with DOPRI5 and returns component `component` at
/// `nodes` (which must lie in `[0, ∞)`, increasing).
pub(crate) fn simulate_at_nodes<S: Dynamics<f64, N>, const N: usize>(
    system: S,
    tolerances: Tolerances<f64, N>,
    max_steps: usize,
    y0: SVector<f64, N>,
    nodes: &[f64],
    component: usize,
    window: (f64, f64),
) -> Result<Vec<f64>, IdentifyError> {
    let mut sampler = Stroboscopic::<f64, N, _>::new(Nodes(nodes), 0.0, nodes.len())?;
    let t_end = nodes[nodes.len() - 1];
    Simulation::new(system, Dopri5::new(tolerances))
        .max_steps(max_steps)?
        .run(0.0, y0, t_end, &mut sampler)?;
    let points = sampler.points();
    if points.len() != nodes.len() {
        // Every node in [0, t_end] is sampled when the run succeeds; report a shortfall
        // as the simulation not covering the window rather than trusting it.
        return Err(IdentifyError::WindowOutsideData {
            which: "simulated",
            t1: window.0,
            t2: window.1,
            start: points.first().map_or(f64::NAN, |p| p.t),
            end: points.last().map_or(f64::NAN, |p| p.t),
        });
    }
    Ok(points.iter().map(|p| p.y[component]).collect())
}

/// Estimates named parameters of any model from a measured record of one state component
/// by minimizing `F0` with Nelder–Mead, the model given as a builder. The paper's
/// configuration is [`systems::paper::PaperFit`](crate::systems::paper::PaperFit).
///
/// # Method
/// For trial values `μ` of the fitted parameters, `build(μ)` returns the system and its
/// initial state at `t = 0` (the time origin of the record and of any forcing); the system
/// is simulated with [`Dopri5`] at the configured tolerances, component `component` is
/// sampled on the dense output at the window ends and at every measured time inside the
/// window, and
/// $$ F_0(\mu) = \frac{1}{t_2 - t_1}\int_{t_1}^{t_2}
///    \bigl(x_\mathrm{exp}(t) - y_{c}(t;\mu)\bigr)^2\,dt $$
/// is evaluated by [`objective_f0`] (trapezoidal rule on the measured samples). A trial
/// whose build or simulation fails (an unknown name, a value outside the model's domain,
/// the step cap) is a bad point: the optimizer gives it `+∞` and moves on.
///
/// The builder returns an [`IdentifyError`]; the crate's [`Error`](crate::Error) converts
/// into it, so `?` works on the catalogue's constructors (as in the example).
///
/// # Examples
/// The damping of the Duffing–Ueda oscillator recovered from a synthetic record of `x`:
/// ```
/// use nonsmooth::identify::{ModelFit, Parameter};
/// use nonsmooth::integrate::Tolerances;
/// use nonsmooth::signal::ModelExperiment;
/// use nonsmooth::systems::DuffingUeda;
/// use nalgebra::Vector2;
///
/// let truth = DuffingUeda { k: 0.1, b: 1.0, omega: 1.2 };
/// let y0 = Vector2::new(1.0, 0.0);
/// let data = ModelExperiment::new(truth.model::<f64>()?, y0, 20.0)?
///     .with_sample_interval(0.05)?
///     .generate()?;
/// let report = ModelFit::new(data.measured, (0.0, 20.0), 0, move |p| {
///     let m = DuffingUeda { k: p.get("k")?, ..truth };
///     Ok((m.model::<f64>()?, y0))
/// })?
/// .fit_parameter(Parameter::positive("k", 0.15))?
/// .with_tolerances(Tolerances::new(1e-10, 1e-12)?)
/// .run()?;
/// assert!((report.values.get("k")? / 0.1 - 1.0).abs() < 1e-4);
/// # Ok::<(), nonsmooth::Error>(())
/// ```
pub struct ModelFit<F, S, const N: usize> {
    measured: TimeSeries,
    window: (f64, f64),
    component: usize,
    build: F,
    fitted: Vec<Parameter>,
    tolerances: Tolerances<f64, N>,
    max_steps: usize,
    options: NelderMeadOptions,
    nodes: Vec<f64>,
    system: PhantomData<fn() -> S>,
}

impl<F, S, const N: usize> std::fmt::Debug for ModelFit<F, S, N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ModelFit")
            .field("window", &self.window)
            .field("component", &self.component)
            .field("fitted", &self.fitted)
            .field("max_steps", &self.max_steps)
            .finish_non_exhaustive()
    }
}

impl<F, S, const N: usize> ModelFit<F, S, N>
where
    F: Fn(&ParamValues) -> Result<(S, SVector<f64, N>), IdentifyError>,
    S: Dynamics<f64, N>,
{
    /// A fit of the model `build` to `measured` (a record of state component `component`)
    /// on the window `[t1, t2]`. No parameter is fitted yet: add them with
    /// [`fit_parameter`](Self::fit_parameter). Defaults: tolerances `rtol = 10⁻¹⁰`,
    /// `atol = 10⁻¹²`, at most 10⁷ steps per simulation, Nelder–Mead with
    /// `x_tolerance = 10⁻⁴`, `f_tolerance = 10⁻⁶` and one restart.
    ///
    /// # Errors
    /// [`IdentifyError::InvalidWindow`] unless `0 ≤ t1 < t2` are finite;
    /// [`IdentifyError::WindowOutsideData`] if the window is not inside the record;
    /// [`IdentifyError::EmptyWindow`] if fewer than two samples lie in it;
    /// [`IdentifyError::Parameter`] if `component ≥ N`.
    pub fn new(
        measured: TimeSeries,
        window: (f64, f64),
        component: usize,
        build: F,
    ) -> Result<Self, IdentifyError> {
        if component >= N {
            return Err(crate::ParameterError::new(
                "component",
                component as f64,
                "< the state dimension",
            )
            .into());
        }
        let nodes = window_nodes(&measured, window)?;
        Ok(Self {
            measured,
            window,
            component,
            build,
            fitted: Vec::new(),
            tolerances: Tolerances {
                rtol: SVector::repeat(1e-10),
                atol: SVector::repeat(1e-12),
            },
            max_steps: 10_000_000,
            options: NelderMeadOptions::default()
                .with_tolerances(1e-4, 1e-6)
                .with_restarts(1),
            nodes,
            system: PhantomData,
        })
    }

    /// Fits a parameter (name, initial value, bounds, transform); the name is what the
    /// builder asks [`ParamValues::get`] for.
    ///
    /// # Errors
    /// [`IdentifyError::DuplicateParameter`] if it is already fitted; the
    /// [`ParameterSpace::new`] errors for an invalid initial value or bounds.
    pub fn fit_parameter(mut self, parameter: Parameter) -> Result<Self, IdentifyError> {
        if self.fitted.iter().any(|p| p.name() == parameter.name()) {
            return Err(IdentifyError::DuplicateParameter {
                name: parameter.name().into(),
            });
        }
        ParameterSpace::new([parameter.clone()])?;
        self.fitted.push(parameter);
        Ok(self)
    }

    /// Sets the integrator's tolerances.
    #[must_use]
    pub fn with_tolerances(mut self, tolerances: Tolerances<f64, N>) -> Self {
        self.tolerances = tolerances;
        self
    }

    /// Caps the integrator's steps per simulation.
    ///
    /// # Errors
    /// [`IdentifyError::Parameter`] if `max_steps == 0`.
    pub fn with_max_steps(mut self, max_steps: usize) -> Result<Self, IdentifyError> {
        if max_steps == 0 {
            return Err(crate::ParameterError::new("max_steps", 0.0, "> 0").into());
        }
        self.max_steps = max_steps;
        Ok(self)
    }

    /// Sets the Nelder–Mead options.
    #[must_use]
    pub fn with_options(mut self, options: NelderMeadOptions) -> Self {
        self.options = options;
        self
    }

    /// The comparison times: `t1`, the measured times strictly inside the window, `t2`.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// The parameter space of the fitted parameters.
    ///
    /// # Errors
    /// [`IdentifyError::EmptySpace`] if nothing is fitted.
    pub fn space(&self) -> Result<ParameterSpace, IdentifyError> {
        ParameterSpace::new(self.fitted.iter().cloned())
    }

    /// The simulated component at [`nodes`](Self::nodes) for the values `values`.
    ///
    /// # Errors
    /// The builder's error, or a failed simulation ([`IdentifyError::Run`]).
    pub fn simulate(&self, values: &ParamValues) -> Result<Vec<f64>, IdentifyError> {
        let (system, y0) = (self.build)(values)?;
        simulate_at_nodes(
            system,
            self.tolerances,
            self.max_steps,
            y0,
            &self.nodes,
            self.component,
            self.window,
        )
    }

    /// `F0` (squared units of the record) at `values`.
    ///
    /// # Errors
    /// As [`simulate`](Self::simulate), and [`objective_f0`]'s.
    pub fn objective_at(&self, values: &ParamValues) -> Result<f64, IdentifyError> {
        let y = self.simulate(values)?;
        objective_f0(&self.measured, &self.nodes, &y, self.window)
    }

    /// Runs the fit.
    ///
    /// # Errors
    /// [`IdentifyError::EmptySpace`] if nothing is fitted;
    /// [`IdentifyError::InitialPointFailed`] if the build or simulation fails at the initial
    /// values (e.g. a name the builder does not know).
    pub fn run(&self) -> Result<FitReport, IdentifyError> {
        let space = self.space()?;
        fit_nelder_mead(&space, |values| self.objective_at(values), &self.options)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_clock_reports_the_given_times() {
        let t = [0.25, 0.5, 0.75];
        let c = Nodes(&t);
        assert_eq!(c.section_time(1), Some(0.5));
        assert_eq!(c.section_time(3), None);
        assert_eq!(c.first_index_from(0.0), 0);
        assert_eq!(c.first_index_from(0.5), 1);
        assert_eq!(c.first_index_from(0.6), 2);
    }
}
