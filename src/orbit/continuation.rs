//! Continuation of periodic orbits in a parameter: pseudo-arclength with step control,
//! through folds, with the bifurcations on the way located (not gridded).
//!
//! # Method
//! A periodic orbit of period `T(p)` through the section at `t₀` solves
//! `F(y, p) = P_p(y) − y = 0` (`N` equations, `N + 1` unknowns). In scaled unknowns
//! `u = (y/s_y, p/s_p)` the branch is followed by a tangent predictor `u + Δs·τ` and a Newton
//! corrector on
//! $$ \begin{pmatrix} F(y, p) \\ \tau\cdot(u - u_{\text{pred}}) \end{pmatrix} = 0, \qquad
//!    J = \begin{pmatrix} \Phi - I & F_p \\ \tau^{\mathsf T} \end{pmatrix}, $$
//! `Φ` the monodromy matrix (integrated with the orbit, through resets) and `F_p` a central
//! difference in `p`. The new tangent solves `(Φ − I, F_p)τ = 0`, `τ·τ_prev = 1`
//! (normalized), so folds are passed without turning back. The step is controlled by the
//! corrector's effort: ×1.5 after at most 3 Newton steps, ×1.1 after 4–5, ×0.7 after more
//! than 7, halved after a failure.
//!
//! # Bifurcations and grazing
//! Test functions are evaluated at every point and a sign change between two points is
//! located by the Illinois method on the arclength (each trial corrected onto the branch)
//! to `locate_tolerance` in `p`:
//! - **fold** (a multiplier through +1): the `p` component of the tangent, `τ_p`;
//! - **period doubling** (a multiplier through −1): `det(Φ + I) = Π(μ_i + 1)`;
//! - **Neimark–Sacker** (a complex pair through the unit circle): `Re Π_{i<j}(μ_iμ_j − 1)`,
//!   kept only where the located multipliers are a complex pair on the unit circle (a real
//!   pair with `μ_iμ_j = 1`, a neutral saddle, is not a bifurcation);
//! - **grazing** (optional, [`Grazing`]): the orbit's extremum of a position minus a
//!   contact level ([`Shooting::extremum`]), whose zero is where the orbit touches the
//!   surface and the number of impacts per period changes.
//!
//! # Example
//! The steady state of `ẍ + 2ζẋ + x = cos ωt` followed in `ω` (exact: `x(0) = (1 − ω²)/d`,
//! `d = (1 − ω²)² + (2ζω)²`):
//! ```
//! use nalgebra::SVector;
//! use nonsmooth::excite::Harmonic;
//! use nonsmooth::force::{LinearSpring, ViscousDamper};
//! use nonsmooth::integrate::Tolerances;
//! use nonsmooth::lyapunov::tangent_tolerances;
//! use nonsmooth::model::{Element, Load, Mechanical};
//! use nonsmooth::orbit::{ContinuationSettings, Shooting, follow};
//!
//! let zeta = 0.1;
//! let tol = Tolerances::new(1e-10, 1e-12)?;
//! let build = |w: f64| {
//!     let model = Mechanical::with_masses([1.0])?
//!         .with_elements(Element::on_dof(0, (LinearSpring::new(1.0)?, ViscousDamper::new(2.0 * zeta)?))?)
//!         .with_loads(Load::on_dof(0, Harmonic::cosine(1.0, w)?)?);
//!     Ok(Shooting::new(model, (), tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12)?))
//! };
//! let period = |w: f64| std::f64::consts::TAU / w;
//! let settings = ContinuationSettings::new(0.5, 0.9, 0.05)?;
//! let branch = follow(build, period, 0.0, 0.5, SVector::<f64, 2>::zeros(), &settings)?;
//! assert!(branch.points.len() > 3 && branch.bifurcations.is_empty());
//! for q in &branch.points {
//!     let d = (1.0 - q.p * q.p).powi(2) + (2.0 * zeta * q.p).powi(2);
//!     assert!((q.state[0] - (1.0 - q.p * q.p) / d).abs() < 1e-7);
//! }
//! # Ok::<(), nonsmooth::Error>(())
//! ```
//!
//! References: E. Doedel, H. B. Keller, J. P. Kernévez, *Int. J. Bifurcation Chaos* 1
//! (1991) 493–520 (pseudo-arclength, test functions); Yu. A. Kuznetsov, *Elements of Applied
//! Bifurcation Theory* (2004), ch. 10.

use nalgebra::{Complex, DMatrix, DVector, SMatrix, SVector};

use super::Result;
use super::{Extremum, OrbitError, Shooting, modulus, multipliers};
use crate::Dynamics;
use crate::event::EventSet;

/// A grazing test: the orbit's [`Extremum`] of `component` minus `level`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grazing {
    /// The position component.
    pub component: usize,
    /// The contact level.
    pub level: f64,
    /// Which extremum approaches the level (`Min` for a stop below the motion).
    pub extremum: Extremum,
}

/// Settings of [`follow`].
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationSettings {
    step: f64,
    min_step: f64,
    max_step: f64,
    max_points: usize,
    range: (f64, f64),
    direction: f64,
    locate_tolerance: f64,
    scales: Option<(Vec<f64>, f64)>,
    grazing: Option<Grazing>,
    contacts: Option<Grazing>,
}

impl ContinuationSettings {
    /// Follow the branch while `p` stays in `[lo, hi]`, starting towards increasing `p`
    /// with arclength step `step` (in scaled units, see [`with_scales`](Self::with_scales)),
    /// steps between `step/1024` and `16·step`, at most 10 000 points, bifurcations located
    /// to `1e-9·max(|p|, 1)`.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless `lo < hi` are finite and `step` is finite and
    /// `> 0`.
    pub fn new(lo: f64, hi: f64, step: f64) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(invalid(
                "the parameter range",
                "finite with lo < hi",
                hi - lo,
            ));
        }
        if !(step.is_finite() && step > 0.0) {
            return Err(invalid("the arclength step", "finite and > 0", step));
        }
        Ok(Self {
            step,
            min_step: step / 1024.0,
            max_step: 16.0 * step,
            max_points: 10_000,
            range: (lo, hi),
            direction: 1.0,
            locate_tolerance: 1e-9 * lo.abs().max(hi.abs()).max(1.0),
            scales: None,
            grazing: None,
            contacts: None,
        })
    }

    /// Starts towards decreasing `p`.
    #[must_use]
    pub fn downward(mut self) -> Self {
        self.direction = -1.0;
        self
    }

    /// At most `points` points on the branch.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] for fewer than 2.
    pub fn with_max_points(mut self, points: usize) -> Result<Self> {
        if points < 2 {
            return Err(invalid("the point cap", "at least 2", points as f64));
        }
        self.max_points = points;
        Ok(self)
    }

    /// The largest arclength step.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless finite and at least the initial step.
    pub fn with_max_step(mut self, max_step: f64) -> Result<Self> {
        if !(max_step.is_finite() && max_step >= self.step) {
            return Err(invalid(
                "the largest step",
                "finite and ≥ the initial step",
                max_step,
            ));
        }
        self.max_step = max_step;
        Ok(self)
    }

    /// Locates bifurcations to `tolerance` in `p`.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless finite and `> 0`.
    pub fn with_locate_tolerance(mut self, tolerance: f64) -> Result<Self> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(invalid(
                "the location tolerance",
                "finite and > 0",
                tolerance,
            ));
        }
        self.locate_tolerance = tolerance;
        Ok(self)
    }

    /// The scales of the state components and of the parameter in the arclength
    /// (default: each component's range `max − min` over the first orbit, floored at
    /// `10⁻⁶` of its magnitude, and `max(|p₀|, 1)`).
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless every scale is finite and `> 0`.
    pub fn with_scales(mut self, state: Vec<f64>, parameter: f64) -> Result<Self> {
        for &s in state.iter().chain(std::iter::once(&parameter)) {
            if !(s.is_finite() && s > 0.0) {
                return Err(invalid("a scale", "finite and > 0", s));
            }
        }
        self.scales = Some((state, parameter));
        Ok(self)
    }

    /// Also locates grazing of the orbit with a contact level. [`follow`] rejects a level
    /// that is not finite and a component outside the state
    /// ([`OrbitError::InvalidSetting`]).
    #[must_use]
    pub fn with_grazing(mut self, grazing: Grazing) -> Self {
        self.grazing = Some(grazing);
        self
    }

    /// Also locates each local extremum of the component ([`Shooting::local_extrema`]) that
    /// crosses the level: for a stop below the motion, a local minimum of the position
    /// reaching the stop adds a contact per period (impact adding, where the orbit touches
    /// the stop at a new place while it is already in contact elsewhere, which
    /// [`with_grazing`](Self::with_grazing)'s global extremum does not see). Located by
    /// following that one extremum (the one nearest in time to where the count of extrema
    /// beyond the level changed) onto the level. Extrema born beyond the level are not
    /// crossings and are not reported; a local maximum rising out of a contact (a contact
    /// splitting in two) is not tested. [`follow`] checks the level and the component as
    /// for [`with_grazing`](Self::with_grazing).
    #[must_use]
    pub fn with_contact_changes(mut self, grazing: Grazing) -> Self {
        self.contacts = Some(grazing);
        self
    }
}

fn invalid(what: &'static str, requirement: &'static str, value: f64) -> OrbitError {
    OrbitError::InvalidSetting {
        what,
        requirement,
        value,
    }
}

/// The kind of a located bifurcation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BifurcationKind {
    /// A multiplier through +1: the branch turns back in `p`.
    Fold,
    /// A multiplier through −1: a period-`2k` orbit branches off.
    PeriodDoubling,
    /// A complex pair through the unit circle: a torus branches off.
    NeimarkSacker,
    /// The orbit touches the contact level: the number of impacts per period changes.
    Grazing,
}

/// A located bifurcation.
#[derive(Debug, Clone, PartialEq)]
pub struct Bifurcation<const N: usize> {
    /// What it is.
    pub kind: BifurcationKind,
    /// Its arclength along the branch (scaled units).
    pub arclength: f64,
    /// The parameter.
    pub p: f64,
    /// The orbit's state at the section.
    pub state: SVector<f64, N>,
    /// The Floquet multipliers there.
    pub multipliers: Vec<Complex<f64>>,
    /// The monodromy matrix there.
    pub monodromy: SMatrix<f64, N, N>,
}

impl<const N: usize> Bifurcation<N> {
    /// The unit eigenvector of the monodromy matrix for its multiplier nearest `mu` (the
    /// smallest singular vector of `Φ − μI`): the critical direction, e.g. `mu = −1` for a
    /// period doubling.
    pub fn critical_direction(&self, mu: f64) -> SVector<f64, N> {
        let m = DMatrix::from_iterator(
            N,
            N,
            (self.monodromy - SMatrix::<f64, N, N>::identity() * mu)
                .iter()
                .copied(),
        );
        let svd = m.svd(false, true);
        let (k, _) =
            svd.singular_values
                .iter()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |b, (i, &v)| if v < b.1 { (i, v) } else { b },
                );
        match svd.v_t {
            Some(vt) => SVector::<f64, N>::from_iterator(vt.row(k).iter().copied()),
            None => SVector::<f64, N>::zeros(),
        }
    }
}

/// The period-doubled orbit born at a period doubling `at` of a branch with period
/// `period(p)`: tries `p = at.p ± dp` (the side where it exists is not known in advance)
/// and starting points `y ± ε v` (`v` the critical direction, `ε` from `10⁻³` to `10⁻¹` of
/// `scale`), shooting with period `2·period(p)`, and returns the first orbit within
/// `0.1·scale` of the bifurcation that is not the original one (`‖P(y) − y‖` over one
/// original period above `10⁻⁶·scale`).
///
/// # Errors
/// [`OrbitError::NotConverged`] if no start converges to a period-doubled orbit.
pub fn period_doubled<S, E, const N: usize, const M: usize, B, P>(
    build: B,
    period: P,
    t0: f64,
    at: &Bifurcation<N>,
    dp: f64,
    scale: f64,
) -> Result<(f64, super::PeriodicOrbit<f64, N>)>
where
    B: Fn(f64) -> Result<Shooting<f64, S, E, N, M>>,
    P: Fn(f64) -> f64,
    S: Dynamics<f64, N> + Clone,
    E: EventSet<f64, N> + Clone,
{
    let v = at.critical_direction(-1.0);
    for side in [1.0, -1.0] {
        let p = at.p + side * dp;
        let shooting = build(p)?;
        for eps in [1e-3, 3e-3, 1e-2, 3e-2, 1e-1] {
            for sign in [1.0, -1.0] {
                let guess = at.state + v * (sign * eps * scale);
                let Ok(orbit) = shooting.find(t0, 2.0 * period(p), guess) else {
                    continue;
                };
                let once = shooting.map(t0, orbit.state, period(p))?;
                let near = (orbit.state - at.state).amax() < 0.1 * scale;
                if near && (once - orbit.state).amax() > 1e-6 * scale {
                    return Ok((p, orbit));
                }
            }
        }
    }
    Err(OrbitError::NotConverged {
        iterations: 0,
        step: f64::NAN,
        residual: f64::NAN,
    })
}

/// A point of a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchPoint<const N: usize> {
    /// The arclength from the first point (scaled units, see
    /// [`ContinuationSettings::with_scales`]).
    pub arclength: f64,
    /// The parameter.
    pub p: f64,
    /// The orbit's state at the section.
    pub state: SVector<f64, N>,
    /// The Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// The grazing margin (extremum − level) if grazing is tested.
    pub grazing_margin: Option<f64>,
}

/// Why a branch ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BranchEnd {
    /// `p` left the range.
    ParameterRange,
    /// The point cap was reached.
    MaxPoints,
    /// The corrector failed down to the smallest step (at this `p`).
    StepTooSmall {
        /// The last parameter on the branch.
        p: f64,
    },
}

/// A followed branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch<const N: usize> {
    /// The points in order of arclength.
    pub points: Vec<BranchPoint<N>>,
    /// The bifurcations, in order of arclength.
    pub bifurcations: Vec<Bifurcation<N>>,
    /// Why it ended.
    pub end: BranchEnd,
}

/// A corrected point with what the next step and the tests need.
#[derive(Debug, Clone)]
struct Point<const N: usize> {
    arclength: f64,
    u: DVector<f64>,
    p: f64,
    y: SVector<f64, N>,
    phi: SMatrix<f64, N, N>,
    tangent: DVector<f64>,
    multipliers: Vec<Complex<f64>>,
    tests: [f64; 4],
    margin: Option<f64>,
    /// The local extrema `(t, value − level)` of the contact-change test.
    extrema: Vec<(f64, f64)>,
}

impl<const N: usize> From<Point<N>> for BranchPoint<N> {
    fn from(q: Point<N>) -> Self {
        Self {
            arclength: q.arclength,
            p: q.p,
            state: q.y,
            stable: q.multipliers.iter().all(|m| modulus(m) < 1.0),
            multipliers: q.multipliers,
            grazing_margin: q.margin,
        }
    }
}

const FOLD: usize = 0;
const PD: usize = 1;
const NS: usize = 2;
const GRAZE: usize = 3;

/// The residual and Jacobian at one point, with the shooting problem there.
struct Evaluation<S, E, const N: usize, const M: usize> {
    /// `F/s_y`.
    f: DVector<f64>,
    /// `(D⁻¹(Φ − I)D, D⁻¹F_p s_p)`.
    a: DMatrix<f64>,
    shooting: Shooting<f64, S, E, N, M>,
}

/// The continuation problem: the family of shooting problems and the scales.
struct Problem<'a, B, P, const N: usize> {
    build: &'a B,
    period: &'a P,
    t0: f64,
    sy: SVector<f64, N>,
    sp: f64,
    grazing: Option<Grazing>,
    contacts: Option<Grazing>,
}

impl<B, P, S, E, const N: usize, const M: usize> Problem<'_, B, P, N>
where
    B: Fn(f64) -> Result<Shooting<f64, S, E, N, M>>,
    P: Fn(f64) -> f64,
    S: Dynamics<f64, N> + Clone,
    E: EventSet<f64, N> + Clone,
{
    fn unscale(&self, u: &DVector<f64>) -> (SVector<f64, N>, f64) {
        let mut y = SVector::<f64, N>::zeros();
        for i in 0..N {
            y[i] = u[i] * self.sy[i];
        }
        (y, u[N] * self.sp)
    }

    fn scale(&self, y: &SVector<f64, N>, p: f64) -> DVector<f64> {
        let mut u = DVector::zeros(N + 1);
        for i in 0..N {
            u[i] = y[i] / self.sy[i];
        }
        u[N] = p / self.sp;
        u
    }

    /// `F/s_y` and the scaled Jacobian `(D⁻¹(Φ − I)D, D⁻¹F_p s_p)`.
    fn evaluate(&self, y: &SVector<f64, N>, p: f64) -> Result<Evaluation<S, E, N, M>> {
        let shooting = (self.build)(p)?;
        let (py, phi) = shooting.flow(self.t0, *y, (self.period)(p))?;
        let h = 1e-6 * p.abs().max(self.sp);
        // F_p needs the map only, not its Jacobian.
        let pp = (self.build)(p + h)?.map(self.t0, *y, (self.period)(p + h))?;
        let pm = (self.build)(p - h)?.map(self.t0, *y, (self.period)(p - h))?;
        let fp = (pp - pm) / (2.0 * h);
        let mut f = DVector::zeros(N);
        let mut a = DMatrix::zeros(N, N + 1);
        for i in 0..N {
            f[i] = (py[i] - y[i]) / self.sy[i];
            for j in 0..N {
                let d = if i == j { 1.0 } else { 0.0 };
                a[(i, j)] = (phi[(i, j)] - d) * self.sy[j] / self.sy[i];
            }
            a[(i, N)] = fp[i] * self.sp / self.sy[i];
        }
        Ok(Evaluation { f, a, shooting })
    }

    /// Newton's corrector from the prediction `pred` with the arclength condition along
    /// `tangent`; the point and the iterations used.
    fn correct(
        &self,
        pred: &DVector<f64>,
        tangent: &DVector<f64>,
        reach: f64,
    ) -> Result<(Point<N>, usize)> {
        let mut u = pred.clone();
        for iteration in 1..=10 {
            let (y, p) = self.unscale(&u);
            let Evaluation { f, a, shooting } = self.evaluate(&y, p)?;
            let mut j = DMatrix::zeros(N + 1, N + 1);
            let mut h = DVector::zeros(N + 1);
            for i in 0..N {
                for k in 0..=N {
                    j[(i, k)] = a[(i, k)];
                }
                h[i] = -f[i];
            }
            for k in 0..=N {
                j[(N, k)] = tangent[k];
            }
            h[N] = -tangent.dot(&(&u - pred));
            let mut du = j
                .clone()
                .lu()
                .solve(&h)
                .ok_or(OrbitError::Singular { iteration })?;
            // A Newton step longer than the predictor's is cut to it: far from the branch
            // the linearization of a nonsmooth flow is not to be trusted.
            let length = du.norm();
            if length > reach {
                du *= reach / length;
            }
            u += &du;
            // Converged when the step is within 100× the integration tolerance.
            let (y_new, p_new) = self.unscale(&u);
            let tol = shooting.state_tolerances();
            let small = (0..N).all(|i| {
                (du[i] * self.sy[i]).abs() <= 100.0 * (tol.atol[i] + tol.rtol[i] * y_new[i].abs())
            }) && (du[N] * self.sp).abs()
                <= 100.0 * tol.rtol[0] * p_new.abs().max(self.sp);
            if small && du.iter().all(|v| v.is_finite()) {
                let Evaluation { a, shooting, .. } = self.evaluate(&y_new, p_new)?;
                return Ok((
                    self.point(u, y_new, p_new, &a, tangent, &shooting)?,
                    iteration,
                ));
            }
        }
        Err(OrbitError::NotConverged {
            iterations: 10,
            step: f64::NAN,
            residual: f64::NAN,
        })
    }

    /// The point at a converged `u`: tangent, multipliers, tests.
    fn point(
        &self,
        u: DVector<f64>,
        y: SVector<f64, N>,
        p: f64,
        a: &DMatrix<f64>,
        previous: &DVector<f64>,
        shooting: &Shooting<f64, S, E, N, M>,
    ) -> Result<Point<N>> {
        let mut j = DMatrix::zeros(N + 1, N + 1);
        for i in 0..N {
            for k in 0..=N {
                j[(i, k)] = a[(i, k)];
            }
        }
        for k in 0..=N {
            j[(N, k)] = previous[k];
        }
        let mut rhs = DVector::zeros(N + 1);
        rhs[N] = 1.0;
        let mut tangent = j
            .lu()
            .solve(&rhs)
            .ok_or(OrbitError::Singular { iteration: 0 })?;
        tangent /= tangent.norm();
        // Φ from the scaled block: Φ_ij = a_ij s_i / s_j + δ_ij.
        let mut phi = SMatrix::<f64, N, N>::zeros();
        for i in 0..N {
            for k in 0..N {
                phi[(i, k)] = a[(i, k)] * self.sy[i] / self.sy[k] + if i == k { 1.0 } else { 0.0 };
            }
        }
        let mu = multipliers(&phi);
        let pd = mu
            .iter()
            .fold(Complex::new(1.0, 0.0), |acc, m| acc * (m + 1.0))
            .re;
        let mut ns = Complex::new(1.0, 0.0);
        for i in 0..mu.len() {
            for k in 0..i {
                ns *= mu[i] * mu[k] - Complex::new(1.0, 0.0);
            }
        }
        let margin = match self.grazing {
            Some(g) => Some(
                shooting.extremum(self.t0, (self.period)(p), y, g.component, g.extremum)? - g.level,
            ),
            None => None,
        };
        let extrema = match self.contacts {
            Some(g) => shooting
                .local_extrema(self.t0, (self.period)(p), y, g.component, g.extremum)?
                .into_iter()
                .map(|(t, v)| (t - self.t0, v - g.level))
                .collect(),
            None => Vec::new(),
        };
        Ok(Point {
            extrema,
            arclength: 0.0,
            u,
            p,
            y,
            phi,
            tests: [tangent[N], pd, ns.re, margin.unwrap_or(1.0)],
            tangent,
            multipliers: mu,
            margin,
        })
    }

    /// The bifurcations between consecutive points `a` and `b` (`b` at arclength `ds` along
    /// `a`'s tangent), located.
    fn bifurcations(
        &self,
        a: &Point<N>,
        b: &Point<N>,
        ds: f64,
        settings: &ContinuationSettings,
    ) -> Result<Vec<Bifurcation<N>>> {
        let mut found = Vec::new();
        for which in [FOLD, PD, NS, GRAZE] {
            if which == GRAZE && self.grazing.is_none() {
                continue;
            }
            // A test that is not finite at either end (NaN multipliers, an extremum that
            // could not be evaluated) has no sign change to locate.
            let (ta, tb) = (a.tests[which], b.tests[which]);
            if !(ta.is_finite() && tb.is_finite()) || ta.signum() == tb.signum() {
                continue;
            }
            let at = self.locate(a, b, ds, which, settings.locate_tolerance)?;
            let kind = match which {
                FOLD => BifurcationKind::Fold,
                PD => BifurcationKind::PeriodDoubling,
                GRAZE => BifurcationKind::Grazing,
                _ => {
                    let on_circle = at
                        .multipliers
                        .iter()
                        .any(|m| m.im != 0.0 && (modulus(m) - 1.0).abs() < 1e-3);
                    if !on_circle {
                        continue;
                    }
                    BifurcationKind::NeimarkSacker
                }
            };
            found.push(Bifurcation {
                kind,
                p: at.p,
                state: at.y,
                multipliers: at.multipliers,
                monodromy: at.phi,
                arclength: at.arclength,
            });
        }
        if let Some(g) = self.contacts {
            found.extend(self.contact_changes(a, b, ds, g, settings.locate_tolerance)?);
        }
        found.sort_by(|x, y| x.arclength.total_cmp(&y.arclength));
        Ok(found)
    }

    /// The contact changes between `a` and `b`: while the number of local extrema beyond
    /// the level differs, the extremum nearest the level (at the point with more of them,
    /// or fewer) is followed by its time in the period and located on the level.
    fn contact_changes(
        &self,
        a: &Point<N>,
        b: &Point<N>,
        ds: f64,
        g: Grazing,
        tolerance: f64,
    ) -> Result<Vec<Bifurcation<N>>> {
        let beyond = |q: &Point<N>| {
            q.extrema
                .iter()
                .filter(|e| beyond_side(e.1, g.extremum))
                .count()
        };
        if beyond(a) == beyond(b) {
            return Ok(Vec::new());
        }
        // The extremum that crossed: nearest the level at the end where it is beyond it.
        let ref_point = if beyond(b) > beyond(a) { b } else { a };
        let Some(&(t_star, _)) = ref_point.extrema.iter().min_by(|x, y| {
            let beyond_x = beyond_side(x.1, g.extremum);
            let beyond_y = beyond_side(y.1, g.extremum);
            // Prefer extrema beyond the level, then the one nearest it.
            beyond_y
                .cmp(&beyond_x)
                .then(x.1.abs().total_cmp(&y.1.abs()))
        }) else {
            return Ok(Vec::new());
        };
        let period = (self.period)(a.p);
        let slot = move |q: &Point<N>| {
            q.extrema
                .iter()
                .min_by(|x, y| {
                    phase_distance(x.0, t_star, period)
                        .total_cmp(&phase_distance(y.0, t_star, period))
                })
                .map_or(f64::NAN, |e| e.1)
        };
        let (fa, fb) = (slot(a), slot(b));
        if !(fa.is_finite() && fb.is_finite()) || fa.signum() == fb.signum() {
            return Ok(Vec::new());
        }
        let at = self.locate_by(a, b, ds, tolerance, slot)?;
        Ok(vec![Bifurcation {
            kind: BifurcationKind::Grazing,
            p: at.p,
            state: at.y,
            multipliers: at.multipliers,
            monodromy: at.phi,
            arclength: at.arclength,
        }])
    }

    /// Locates the zero of test `which` between `a` (arclength 0) and the point at
    /// arclength `ds` along `a`'s tangent, by the Illinois method.
    fn locate(
        &self,
        a: &Point<N>,
        b: &Point<N>,
        ds: f64,
        which: usize,
        tolerance: f64,
    ) -> Result<Point<N>> {
        self.locate_by(a, b, ds, tolerance, |q: &Point<N>| q.tests[which])
    }

    /// Locates the zero of `test` between `a` (arclength 0) and `b` (arclength `ds` along
    /// `a`'s tangent), `test(a)` and `test(b)` of opposite signs, by the Illinois method.
    fn locate_by(
        &self,
        a: &Point<N>,
        b: &Point<N>,
        ds: f64,
        tolerance: f64,
        test: impl Fn(&Point<N>) -> f64,
    ) -> Result<Point<N>> {
        let (mut lo, mut hi) = (0.0, ds);
        let (mut f_lo, mut f_hi) = (test(a), test(b));
        let mut best = b.clone();
        let mut p_prev = b.p;
        let mut side = 0i8;
        for _ in 0..60 {
            let s = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
            let s = if s.is_finite() && s > lo && s < hi {
                s
            } else {
                0.5 * (lo + hi)
            };
            let pred = &a.u + &a.tangent * s;
            let (mut pt, _) = self.correct(&pred, &a.tangent, ds)?;
            pt.arclength = a.arclength + s;
            let f = test(&pt);
            let done = (pt.p - p_prev).abs() <= tolerance || f == 0.0;
            p_prev = pt.p;
            best = pt;
            if done {
                break;
            }
            if f.signum() == f_lo.signum() {
                lo = s;
                f_lo = f;
                if side == -1 {
                    f_hi *= 0.5;
                }
                side = -1;
            } else {
                hi = s;
                f_hi = f;
                if side == 1 {
                    f_lo *= 0.5;
                }
                side = 1;
            }
        }
        Ok(best)
    }
}

/// Follows the periodic orbit through `guess` at `p0` (period `period(p)`, section at `t0`)
/// in the parameter `p`, with `build(p)` the shooting problem at `p` (system, events,
/// tolerances); see the [module docs](self).
///
/// # Errors
/// The errors of the first orbit's [`Shooting::find`]; invalid scales (wrong count);
/// [`OrbitError::InvalidSetting`] for a [`Grazing`] test whose level is not finite or whose
/// component is not `< N`. A corrector that fails down to the smallest step ends the branch
/// ([`BranchEnd::StepTooSmall`]) rather than failing.
pub fn follow<S, E, const N: usize, const M: usize, B, P>(
    build: B,
    period: P,
    t0: f64,
    p0: f64,
    guess: SVector<f64, N>,
    settings: &ContinuationSettings,
) -> Result<Branch<N>>
where
    B: Fn(f64) -> Result<Shooting<f64, S, E, N, M>>,
    P: Fn(f64) -> f64,
    S: Dynamics<f64, N> + Clone,
    E: EventSet<f64, N> + Clone,
{
    check_grazing_tests::<N>(settings)?;
    let first = build(p0)?.find(t0, period(p0), guess)?;
    let (sy, sp) = match &settings.scales {
        Some((s, sp)) => {
            if s.len() != N {
                return Err(invalid("the number of state scales", "N", s.len() as f64));
            }
            (SVector::<f64, N>::from_iterator(s.iter().copied()), *sp)
        }
        None => (
            orbit_ranges(&build(p0)?, t0, period(p0), &first.state)?,
            p0.abs().max(1.0),
        ),
    };
    let problem = Problem {
        build: &build,
        period: &period,
        t0,
        sy,
        sp,
        grazing: settings.grazing,
        contacts: settings.contacts,
    };
    // The first point: its tangent from the direction of p.
    let mut seed = DVector::zeros(N + 1);
    seed[N] = settings.direction;
    let u0 = problem.scale(&first.state, p0);
    let at_start = problem.evaluate(&first.state, p0)?;
    let start = problem.point(u0, first.state, p0, &at_start.a, &seed, &at_start.shooting)?;
    let mut points = vec![start];
    let mut bifurcations = Vec::new();
    let mut ds = settings.step;
    let end = loop {
        if points.len() >= settings.max_points {
            break BranchEnd::MaxPoints;
        }
        let a = points.last().expect("the branch has its first point");
        let pred = &a.u + &a.tangent * ds;
        let step = problem
            .correct(&pred, &a.tangent, ds)
            .and_then(|(b, iterations)| {
                let found = problem.bifurcations(a, &b, ds, settings)?;
                Ok((b, iterations, found))
            });
        match step {
            Ok((mut b, iterations, found)) => {
                b.arclength = a.arclength + ds;
                bifurcations.extend(found);
                let outside = b.p < settings.range.0 || b.p > settings.range.1;
                points.push(b);
                if outside {
                    break BranchEnd::ParameterRange;
                }
                ds = (ds * step_factor(iterations)).clamp(settings.min_step, settings.max_step);
            }
            Err(_) => {
                ds *= 0.5;
                if ds < settings.min_step {
                    break BranchEnd::StepTooSmall {
                        p: points.last().map_or(p0, |q| q.p),
                    };
                }
            }
        }
    };
    Ok(Branch {
        points: points.into_iter().map(BranchPoint::from).collect(),
        bifurcations,
        end,
    })
}

/// The grazing and contact tests' settings: a finite level, a component `< N`.
fn check_grazing_tests<const N: usize>(settings: &ContinuationSettings) -> Result<()> {
    for g in [settings.grazing, settings.contacts].into_iter().flatten() {
        if !g.level.is_finite() {
            return Err(invalid("the grazing level", "finite", g.level));
        }
        if g.component >= N {
            return Err(invalid(
                "the grazing component",
                "< N (the state dimension)",
                g.component as f64,
            ));
        }
    }
    Ok(())
}

/// The default state scales of a branch: each component by its range over the first orbit
/// (how far it moves), floored at 10⁻⁶ of its magnitude.
fn orbit_ranges<S, E, const N: usize, const M: usize>(
    shooting: &Shooting<f64, S, E, N, M>,
    t0: f64,
    span: f64,
    state: &SVector<f64, N>,
) -> Result<SVector<f64, N>>
where
    S: Dynamics<f64, N> + Clone,
    E: EventSet<f64, N> + Clone,
{
    let mut sy = SVector::<f64, N>::zeros();
    for i in 0..N {
        let lo = shooting.extremum(t0, span, *state, i, Extremum::Min)?;
        let hi = shooting.extremum(t0, span, *state, i, Extremum::Max)?;
        sy[i] = (hi - lo)
            .max(1e-6 * lo.abs().max(hi.abs()))
            .max(f64::MIN_POSITIVE);
    }
    Ok(sy)
}

/// Step control on the corrector's effort: grow after easy corrections, hold after
/// moderate ones, shrink after hard ones.
fn step_factor(iterations: usize) -> f64 {
    match iterations {
        0..=3 => 1.5,
        4..=5 => 1.1,
        6..=7 => 1.0,
        _ => 0.7,
    }
}

/// Whether a value relative to the level is beyond it for this kind of extremum.
fn beyond_side(v: f64, which: Extremum) -> bool {
    match which {
        Extremum::Min => v < 0.0,
        Extremum::Max => v > 0.0,
    }
}

/// The distance of two times modulo `period`.
fn phase_distance(t: f64, u: f64, period: f64) -> f64 {
    let d = (t - u).rem_euclid(period);
    d.min(period - d)
}
