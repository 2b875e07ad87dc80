//! The Moreau–Jean θ-scheme at velocity level.

// The loops index several arrays of the same length together (state, forces, rows).
#![allow(clippy::needless_range_loop)]

use crate::Real;
use crate::drive::Control;
use crate::scalar::{lit, to_f64};
use crate::validate::{ParameterError, positive};

use super::error::TimeStepError;
use super::lcp::{LcpReport, Lemke, Nsgs, Pgs};
use super::observe::{ContactRecord, Energy, StepObserver, StepRecord, Summary};
use super::system::{ContactSet, Geometry, Jacobian, Lagrangian};

/// The solver of each step's contact problem.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Solver<T> {
    /// Lemke's pivoting method (frictionless contacts; exact, for few contacts).
    Lemke(Lemke<T>),
    /// Projected Gauss–Seidel (frictionless contacts; many contacts).
    Pgs(Pgs<T>),
    /// Nonsmooth Gauss–Seidel (contacts with Coulomb friction).
    Nsgs(Nsgs<T>),
}

impl<T: Real> Solver<T> {
    /// The solver's residual tolerance (relative, see [`lcp`](super::lcp)).
    fn tolerance(&self) -> T {
        match self {
            Solver::Lemke(s) => s.tolerance(),
            Solver::Pgs(s) => s.tolerance(),
            Solver::Nsgs(s) => s.tolerance(),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            Solver::Lemke(_) => "Lemke",
            Solver::Pgs(_) => "projected Gauss–Seidel",
            Solver::Nsgs(_) => "nonsmooth Gauss–Seidel",
        }
    }
}

/// The Moreau–Jean time-stepping scheme for a [`Lagrangian`] system with a
/// [`ContactSet`] (see the [module docs](super) for the equations).
///
/// Built with the step `h`; `θ = 1/2` and the activation weight `γ = 1/2` by default. The
/// solver defaults to [`Solver::Nsgs`] if any contact has friction, else [`Solver::Lemke`].
/// All workspaces are sized when the scheme is built: a step allocates nothing (the sparse
/// rows of the active contacts grow to their largest size in the first steps and are reused).
#[derive(Debug, Clone)]
pub struct MoreauJean<T: Real, S, C> {
    system: S,
    contacts: C,
    h: T,
    theta: T,
    gamma: T,
    threshold: Option<T>,
    solver: Solver<T>,
    projection: Option<Projection<T>>,
    ws: Workspace<T>,
}

/// The position projection's settings and its own exact solver.
#[derive(Debug, Clone)]
struct Projection<T> {
    tolerance: T,
    solver: Lemke<T>,
}

/// The largest number of linearized projections per step.
const PROJECTION_ITERATIONS: usize = 20;

#[derive(Debug, Clone)]
struct Workspace<T> {
    n: usize,
    m: usize,
    /// `M` is diagonal (the kinetic energy's shortcut).
    diagonal: bool,
    constant: bool,
    factored: bool,
    /// The stiff forces are taken implicitly (the iteration matrix `W` replaces `M`).
    implicit: bool,
    /// How the matrix the velocities are solved with is factorized.
    factor: Factor,
    mass: Vec<T>,
    /// The factor: Cholesky `L` of `M`, or the LU factors of `W` (row-major).
    chol: Vec<T>,
    /// The LU factorization's row of each pivot.
    piv: Vec<usize>,
    /// `K = −∂f/∂q`, `C = −∂f/∂q̇` (implicit forces only).
    tan_k: Vec<T>,
    tan_c: Vec<T>,
    inv_diag: Vec<T>,
    f0: Vec<T>,
    f1: Vec<T>,
    qpred: Vec<T>,
    vfree: Vec<T>,
    vnew: Vec<T>,
    dense: Vec<T>,
    last: Vec<[T; 2]>,
    scratch_n: Vec<(usize, T)>,
    scratch_t: Vec<(usize, T)>,
    rows: Vec<(usize, T)>,
    offsets: Vec<usize>,
    active: Vec<usize>,
    /// Contacts the last projection treated: active in the next step whatever their gap.
    held: Vec<bool>,
    gaps: Vec<T>,
    pre: Vec<[T; 2]>,
    w: Vec<T>,
    q: Vec<T>,
    p: Vec<T>,
    mu: Vec<T>,
    records: Vec<ContactRecord<T>>,
    work: T,
}

impl<T: Real> Workspace<T> {
    fn new(n: usize, m: usize) -> Self {
        let z = T::zero();
        Self {
            n,
            m,
            diagonal: false,
            constant: true,
            factored: false,
            implicit: false,
            factor: Factor::Cholesky,
            mass: vec![z; n * n],
            chol: vec![z; n * n],
            piv: Vec::new(),
            tan_k: Vec::new(),
            tan_c: Vec::new(),
            inv_diag: vec![z; n],
            f0: vec![z; n],
            f1: vec![z; n],
            qpred: vec![z; n],
            vfree: vec![z; n],
            vnew: vec![z; n],
            dense: Vec::new(),
            last: vec![[z; 2]; m],
            scratch_n: Vec::with_capacity(n.min(64)),
            scratch_t: Vec::with_capacity(n.min(64)),
            rows: Vec::with_capacity(12 * m),
            offsets: Vec::with_capacity(2 * m + 1),
            active: Vec::with_capacity(m),
            held: vec![false; m],
            gaps: Vec::with_capacity(m),
            pre: Vec::with_capacity(m),
            w: Vec::new(),
            q: Vec::with_capacity(2 * m),
            p: Vec::with_capacity(2 * m),
            mu: Vec::with_capacity(m),
            records: Vec::with_capacity(m),
            work: z,
        }
    }
}

/// How the matrix of the velocity solves is factorized.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Factor {
    /// `M` diagonal: its inverse diagonal.
    Diagonal,
    /// `M = LLᵀ`.
    Cholesky,
    /// `W = M + hθC + h²θ²K = P⁻¹LU` (implicit forces; `W` need not be symmetric).
    Lu,
}

/// Sparse row `a` of the rows stored at `offsets`.
#[inline(always)]
fn row<'a, T>(rows: &'a [(usize, T)], offsets: &[usize], a: usize) -> &'a [(usize, T)] {
    &rows[offsets[a]..offsets[a + 1]]
}

/// Contact `i`'s geometry at `(t, q)`, its Jacobian rows into the workspace's scratch rows.
#[inline]
fn evaluate_contact<T: Real, C: ContactSet<T>>(
    contacts: &C,
    ws: &mut Workspace<T>,
    i: usize,
    t: T,
    q: &[T],
) -> Result<Geometry<T>, TimeStepError> {
    ws.scratch_n.clear();
    ws.scratch_t.clear();
    let mut jac = Jacobian {
        normal: &mut ws.scratch_n,
        tangent: &mut ws.scratch_t,
        dofs: ws.n,
        out_of_range: None,
    };
    let geo = contacts.evaluate(i, t, q, &mut jac);
    match jac.out_of_range {
        Some(dof) => Err(TimeStepError::Dimension {
            what: "contact Jacobian index",
            got: dof,
            expected: ws.n,
        }),
        None => Ok(geo),
    }
}

/// LU factorization with partial pivoting of the row-major `n × n` matrix `a` in place
/// (`L` below the diagonal with a unit diagonal, `U` on and above it), the pivot rows in
/// `piv`. Fails with `(column, pivot)` where the largest pivot candidate is zero or not
/// finite.
fn lu_in_place<T: Real>(a: &mut [T], piv: &mut [usize], n: usize) -> Result<(), (usize, T)> {
    for j in 0..n {
        let p = (j..n)
            .max_by(|&x, &y| {
                a[x * n + j]
                    .abs()
                    .partial_cmp(&a[y * n + j].abs())
                    .unwrap_or(core::cmp::Ordering::Equal)
            })
            .unwrap_or(j);
        let pivot = a[p * n + j];
        if !(pivot.abs() > T::zero() && pivot.is_finite()) {
            return Err((j, pivot));
        }
        piv[j] = p;
        if p != j {
            for c in 0..n {
                a.swap(j * n + c, p * n + c);
            }
        }
        for i in j + 1..n {
            let l = a[i * n + j] / pivot;
            a[i * n + j] = l;
            for c in j + 1..n {
                let u = a[j * n + c];
                a[i * n + c] -= l * u;
            }
        }
    }
    Ok(())
}

/// Checks that the row-major `n × n` mass matrix `m` is symmetric to rounding:
/// `|M_ij − M_ji| ≤ 64 ε max(|M_ii|, |M_jj|)` (the Cholesky factorization reads one
/// triangle only, so an asymmetric matrix would be integrated as another one).
fn symmetric<T: Real>(m: &[T], n: usize, t: T) -> Result<(), TimeStepError> {
    let tol = lit::<T>(64.0) * T::default_epsilon();
    for i in 0..n {
        for j in 0..i {
            let (a, b) = (m[i * n + j], m[j * n + i]);
            let scale = m[i * n + i].abs().max(m[j * n + j].abs());
            if !((a - b).abs() <= tol * scale) {
                return Err(TimeStepError::MassAsymmetric {
                    t: to_f64(t),
                    row: i,
                    col: j,
                    value: to_f64(a),
                    transposed: to_f64(b),
                });
            }
        }
    }
    Ok(())
}

/// `x ← A⁻¹ x` with the factors of [`lu_in_place`].
fn lu_solve<T: Real>(lu: &[T], piv: &[usize], x: &mut [T]) {
    let n = piv.len();
    for j in 0..n {
        x.swap(j, piv[j]);
    }
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            s -= lu[i * n + k] * x[k];
        }
        x[i] = s;
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            s -= lu[i * n + k] * x[k];
        }
        x[i] = s / lu[i * n + i];
    }
}

/// The stored row of the problem's row `a`: frictional problems use every row (normal,
/// tangent, normal, …), frictionless ones the normal rows (every other stored row).
#[inline]
fn row_index(a: usize, frictional: bool) -> usize {
    if frictional { a } else { 2 * a }
}

impl<T: Real, S: Lagrangian<T>, C: ContactSet<T>> MoreauJean<T, S, C> {
    /// The scheme with step `h` for `system` and `contacts`.
    ///
    /// # Errors
    /// [`TimeStepError::Parameter`] unless `h` is finite and > 0 and every contact has
    /// `0 ≤ e ≤ 1` and a finite `μ ≥ 0`; a contact's own check
    /// ([`Contact::check`](super::Contact::check)).
    pub fn new(system: S, contacts: C, h: T) -> Result<Self, TimeStepError> {
        let h = positive("h", h)?;
        let n = system.dofs();
        if n == 0 {
            return Err(TimeStepError::Dimension {
                what: "number of coordinates",
                got: 0,
                expected: 1,
            });
        }
        let m = contacts.len();
        let mut frictional = false;
        for i in 0..m {
            contacts.check(i, n)?;
            let e = contacts.restitution(i);
            if !(e >= T::zero() && e <= T::one()) {
                return Err(ParameterError::new("restitution", to_f64(e), "in [0, 1]").into());
            }
            let mu = crate::validate::non_negative("friction", contacts.friction(i))?;
            frictional |= mu > T::zero();
        }
        let solver = if frictional {
            Solver::Nsgs(Nsgs::new())
        } else {
            let mut l = Lemke::new();
            l.reserve(m.min(1024));
            Solver::Lemke(l)
        };
        let mut ws = Workspace::new(n, m);
        ws.diagonal = system.diagonal_mass();
        ws.constant = system.constant_mass();
        ws.factor = if ws.diagonal {
            Factor::Diagonal
        } else {
            Factor::Cholesky
        };
        Ok(Self {
            system,
            contacts,
            h,
            theta: lit(0.5),
            gamma: lit(0.5),
            threshold: None,
            solver,
            projection: None,
            ws,
        })
    }

    /// Sets `θ ∈ [1/2, 1]` of the velocity and force averages (1/2: trapezoidal, 1:
    /// implicit Euler for the positions).
    ///
    /// # Errors
    /// [`ParameterError`] unless `0.5 ≤ θ ≤ 1`.
    pub fn with_theta(mut self, theta: T) -> Result<Self, ParameterError> {
        if !(theta >= lit(0.5) && theta <= T::one()) {
            return Err(ParameterError::new("theta", to_f64(theta), "in [0.5, 1]"));
        }
        self.theta = theta;
        Ok(self)
    }

    /// Sets the activation weight `γ ∈ [0, 1]`: contact `i` enters the step's problem when
    /// its predicted gap `g_i + γ h ġ_i ≤ δ` (see
    /// [`with_activation_threshold`](Self::with_activation_threshold)).
    ///
    /// # Errors
    /// [`ParameterError`] unless `0 ≤ γ ≤ 1`.
    pub fn with_activation(mut self, gamma: T) -> Result<Self, ParameterError> {
        if !(gamma >= T::zero() && gamma <= T::one()) {
            return Err(ParameterError::new("gamma", to_f64(gamma), "in [0, 1]"));
        }
        self.gamma = gamma;
        Ok(self)
    }

    /// Sets the activation threshold `δ ≥ 0` (a length, in the units of the gaps): contact
    /// `i` enters the step's problem when `g_i + γ h ġ_i ≤ δ`. The default,
    /// `16 ε max(1, ‖q‖∞)`, keeps a resting contact active when rounding leaves its gap a few
    /// ulps above zero or its velocity a few ulps separating (a stack of balls would
    /// otherwise lose a contact and let the balls above it fall for a step).
    ///
    /// A **resting** contact — one that carried a normal impulse in the last step and left
    /// it with a normal velocity `ġ⁺ ≤ r ‖q‖∞` (`r` the solver's relative tolerance, `q`
    /// the step's free velocities: at rest to the solver's accuracy) — stays in the next
    /// step's problem whatever its gap. An iterative solver leaves the velocities of a
    /// resting stack within `r ‖q‖∞` of zero, always on the same side, so the gaps move by
    /// up to `h r ‖q‖∞` per step in one direction and would pass any threshold after
    /// enough steps (a 50-ball column with projected Gauss–Seidel at `r = 10⁻¹⁰` opened
    /// within 0.1 s before this rule). A contact that separates faster (a bounce) leaves
    /// the problem by the predicted-gap test.
    ///
    /// # Errors
    /// [`ParameterError`] unless `δ` is finite and ≥ 0.
    pub fn with_activation_threshold(mut self, delta: T) -> Result<Self, ParameterError> {
        self.threshold = Some(crate::validate::non_negative("delta", delta)?);
        Ok(self)
    }

    /// Projects the positions back onto the admissible set after every step, so that no
    /// gap stays below `−tolerance` (`tolerance > 0`, in the units of the gaps).
    ///
    /// The velocity-level scheme keeps `ġ ≥ 0` on active contacts but not `g ≥ 0`: where a
    /// gap is nonlinear in `q` (a curved surface, a rotating body) the position update
    /// `q + h v` leaves it by `O(h²)` per step, and the penetration of a contact that stays
    /// closed grows with time. The projection (the positions only; velocities and impulses
    /// are the step's) solves, for the contacts with `g_i ≤ tolerance` at `(t_{k+1},
    /// q_{k+1})`, the position-level complementarity problem
    /// $$ 0 \le g + W\mu \;\perp\; \mu \ge 0,\qquad W = H M^{-1} H^{\mathsf T}, $$
    /// by Lemke's method, moves `q ← q + M⁻¹Hᵀμ` (the smallest move in the kinetic-energy
    /// metric that closes the linearized gaps) and repeats with the gaps re-evaluated until
    /// every gap is `≥ −tolerance` (at most 20 times; each pass is a Newton step on the
    /// active gaps, so a curvature error `O(h²)` is removed in one or two).
    ///
    /// Every contact the projection treats (`g_i ≤ tolerance` in one of its passes) is
    /// active in the next step's problem whatever its gap, as resting contacts are (see
    /// [`with_activation_threshold`](Self::with_activation_threshold)): the projection
    /// leaves closed contacts at `g ≈ 0` instead of slightly inside, where the `O(Δq²)`
    /// error of its linearized passes and of the position update (measured up to `10⁻⁹` m
    /// on a rocking block) can open them above the activation threshold. A contact that
    /// separates leaves the problem at the next step, with a zero impulse.
    ///
    /// # Errors
    /// [`ParameterError`] unless `tolerance` is finite and > 0.
    pub fn with_projection(mut self, tolerance: T) -> Result<Self, ParameterError> {
        let tolerance = positive("projection tolerance", tolerance)?;
        let mut solver = Lemke::new();
        solver.reserve(self.contacts.len().min(1024));
        self.projection = Some(Projection { tolerance, solver });
        Ok(self)
    }

    /// Takes the smooth forces implicitly where the system provides their Jacobians
    /// ([`Lagrangian::force_jacobians`]): the linearized θ-method of Siconos' `MoreauJeanOSI`,
    /// $$ W = M + h\theta C + h^2\theta^2 K,\qquad K = -\partial f/\partial q,\;
    ///    C = -\partial f/\partial \dot q, $$
    /// $$ W (v_{\rm free} - v_k) = h\big((1-\theta) f(t_k, q_k, v_k) +
    ///    \theta f(t_{k+1}, q_k, v_k)\big) - h^2\theta K v_k, $$
    /// and the impulses act through `W⁻¹` (`v_{k+1} = v_free + W⁻¹Hᵀp`, the Delassus matrix
    /// `H W⁻¹ Hᵀ`). For forces linear in `(q, q̇)` this is the θ-method itself: a stiff
    /// spring does not bound the step (the explicit treatment is unstable for
    /// `hω > 2`). `W` is built and LU-factorized at every step (it depends on `h`, `q`
    /// and `q̇`).
    ///
    /// # Errors
    /// [`TimeStepError::Parameter`] if the system does not provide its Jacobians
    /// (`force_jacobians` returns `false`).
    pub fn with_implicit_forces(mut self) -> Result<Self, TimeStepError> {
        let n = self.ws.n;
        let (mut k, mut c) = (vec![T::zero(); n * n], vec![T::zero(); n * n]);
        let zero = vec![T::zero(); n];
        if !self
            .system
            .force_jacobians(T::zero(), &zero, &zero, &mut k, &mut c)
        {
            return Err(ParameterError::new(
                "implicit forces",
                0.0,
                "a system that provides its force Jacobians (Lagrangian::force_jacobians)",
            )
            .into());
        }
        let ws = &mut self.ws;
        ws.implicit = true;
        ws.factor = Factor::Lu;
        ws.piv = vec![0; n];
        ws.tan_k = k;
        ws.tan_c = c;
        Ok(self)
    }

    /// Sets the contact solver.
    ///
    /// # Errors
    /// [`TimeStepError::FrictionUnsupported`] for a frictionless solver when a contact has
    /// friction.
    pub fn with_solver(mut self, solver: Solver<T>) -> Result<Self, TimeStepError> {
        if !matches!(solver, Solver::Nsgs(_)) {
            for i in 0..self.contacts.len() {
                let mu = self.contacts.friction(i);
                if mu > T::zero() {
                    return Err(TimeStepError::FrictionUnsupported {
                        contact: i,
                        mu: to_f64(mu),
                        solver: solver.name(),
                    });
                }
            }
        }
        self.solver = solver;
        Ok(self)
    }

    /// The step.
    pub fn step_size(&self) -> T {
        self.h
    }

    /// The system.
    pub fn system(&self) -> &S {
        &self.system
    }

    /// The contacts.
    pub fn contacts(&self) -> &C {
        &self.contacts
    }

    /// Runs from `(t0, q, v)` to `t_end` on the grid `t_k = t0 + k·h` (the last step ends
    /// at `t_end`, shorter if `t_end − t0` is not a multiple of `h`), updating `q` and `v`
    /// in place and calling `observer` after every step.
    ///
    /// # Errors
    /// [`TimeStepError::Dimension`] if `q` or `v` does not have `dofs()` entries;
    /// [`TimeStepError::Parameter`] unless `t0 ≤ t_end` are finite;
    /// [`TimeStepError::Clock`] if the clock cannot resolve the step, where
    /// `ε·max(|t0|, |t_end|)` exceeds `h/1024` (below it every step has length `h` to
    /// within 0.1 %, never 0); [`TimeStepError::MassMatrix`] /
    /// [`TimeStepError::MassAsymmetric`] for a mass matrix that is not symmetric positive
    /// definite, [`TimeStepError::IterationMatrix`] for a singular iteration matrix of the
    /// implicit forces; [`TimeStepError::NonFinite`] for a non-finite force, gap, Jacobian
    /// entry or state; [`TimeStepError::Contact`] if a step's contact problem
    /// is not solved (with the step, its time and the residual reached). The state is that
    /// of the last completed step after an error.
    pub fn run<O: StepObserver<T>>(
        &mut self,
        t0: T,
        q: &mut [T],
        v: &mut [T],
        t_end: T,
        observer: &mut O,
    ) -> Result<Summary, TimeStepError> {
        let n = self.ws.n;
        for (what, len) in [("length of q", q.len()), ("length of v", v.len())] {
            if len != n {
                return Err(TimeStepError::Dimension {
                    what,
                    got: len,
                    expected: n,
                });
            }
        }
        crate::validate::finite("t0", t0)?;
        crate::validate::finite("t_end", t_end)?;
        if !(t_end >= t0) {
            return Err(ParameterError::new("t_end", to_f64(t_end), "≥ t0").into());
        }
        for (what, x) in [("q", &*q), ("v", &*v)] {
            if let Some(i) = x.iter().position(|a| !a.is_finite()) {
                return Err(TimeStepError::NonFinite {
                    step: 0,
                    t: to_f64(t0),
                    what,
                    index: i,
                    value: to_f64(x[i]),
                });
            }
        }
        // Number of steps: (t_end − t0)/h rounded up, unless within 1e-9 of an integer.
        let ratio = to_f64((t_end - t0) / self.h);
        let steps = if (ratio - ratio.round()).abs() <= 1e-9 * ratio.max(1.0) {
            ratio.round()
        } else {
            ratio.ceil()
        };
        if !(steps < 1e15) {
            return Err(ParameterError::new("h", to_f64(self.h), "giving < 1e15 steps").into());
        }
        // The grid t₀ + k·h must be resolved by the clock: otherwise the steps t_{k+1} − t_k
        // are rounded to other lengths than h, or to 0.
        let t_max = t0.abs().max(t_end.abs());
        let spacing = T::default_epsilon() * t_max;
        if spacing > self.h / lit(1024.0) {
            return Err(TimeStepError::Clock {
                t: to_f64(t_max),
                h: to_f64(self.h),
                spacing: to_f64(spacing),
            });
        }
        let steps = steps as usize;
        self.ws.factored = false;
        self.ws.held.iter_mut().for_each(|x| *x = false);
        observer.on_start(t0, q, v);
        let mut summary = Summary {
            steps: 0,
            t: to_f64(t0),
            stopped: false,
            max_residual: 0.0,
            solver_iterations: 0,
            max_active: 0,
        };
        for k in 0..steps {
            let ta = t0 + lit::<T>(k as f64) * self.h;
            let tb = if k + 1 == steps {
                t_end
            } else {
                t0 + lit::<T>((k + 1) as f64) * self.h
            };
            let report = self.step(k, ta, tb, q, v)?;
            summary.steps += 1;
            summary.t = to_f64(tb);
            summary.max_residual = summary.max_residual.max(report.residual);
            summary.solver_iterations += report.iterations;
            summary.max_active = summary.max_active.max(self.ws.records.len());
            let energy = self.energy(tb, q, v);
            let record = StepRecord {
                step: k,
                t0: ta,
                t1: tb,
                q,
                v,
                energy,
                contacts: &self.ws.records,
                solver: report,
            };
            if observer.on_step(&record) == Control::Stop {
                summary.stopped = true;
                break;
            }
        }
        observer.on_finish(&summary);
        Ok(summary)
    }

    /// The energies at `(t, q, v)` and the impulses' work of the last step.
    fn energy(&self, t: T, q: &[T], v: &[T]) -> Energy<T> {
        let ws = &self.ws;
        let n = ws.n;
        let mut kin = T::zero();
        if ws.diagonal {
            for i in 0..n {
                kin += ws.mass[i * n + i] * v[i] * v[i];
            }
        } else {
            for i in 0..n {
                let mut s = T::zero();
                for j in 0..n {
                    s += ws.mass[i * n + j] * v[j];
                }
                kin += v[i] * s;
            }
        }
        let work = ws.work;
        Energy {
            kinetic: kin * lit(0.5),
            potential: self.system.potential(t, q),
            impulse_work: work,
        }
    }

    fn nonfinite(step: usize, t: T, what: &'static str, x: &[T]) -> Result<(), TimeStepError> {
        match x.iter().position(|a| !a.is_finite()) {
            None => Ok(()),
            Some(i) => Err(TimeStepError::NonFinite {
                step,
                t: to_f64(t),
                what,
                index: i,
                value: to_f64(x[i]),
            }),
        }
    }

    /// Factorizes the mass matrix at `q` (Cholesky, or the inverse diagonal), or with
    /// implicit forces the iteration matrix `W` of the step `h` at `(t, q, v)` (LU).
    fn factor(&mut self, k: usize, t: T, h: T, q: &[T], v: &[T]) -> Result<(), TimeStepError> {
        let ws = &mut self.ws;
        let n = ws.n;
        self.system.mass(q, &mut ws.mass);
        Self::nonfinite(k, t, "mass", &ws.mass)?;
        if !ws.diagonal {
            symmetric(&ws.mass, n, t)?;
        }
        if ws.implicit {
            if !self
                .system
                .force_jacobians(t, q, v, &mut ws.tan_k, &mut ws.tan_c)
            {
                return Err(ParameterError::new(
                    "implicit forces",
                    to_f64(t),
                    "force Jacobians at every time (Lagrangian::force_jacobians returned false)",
                )
                .into());
            }
            Self::nonfinite(k, t, "stiffness K", &ws.tan_k)?;
            Self::nonfinite(k, t, "damping C", &ws.tan_c)?;
            let ht = h * self.theta;
            for i in 0..n * n {
                ws.chol[i] = ws.mass[i] + ht * ws.tan_c[i] + ht * ht * ws.tan_k[i];
            }
            lu_in_place(&mut ws.chol, &mut ws.piv, n).map_err(|(pivot, value)| {
                TimeStepError::IterationMatrix {
                    t: to_f64(t),
                    h: to_f64(h),
                    pivot,
                    value: to_f64(value),
                }
            })?;
        } else if ws.diagonal {
            for i in 0..n {
                let d = ws.mass[i * n + i];
                let inv = T::one() / d;
                if !(d > T::zero() && inv.is_finite()) {
                    return Err(TimeStepError::MassMatrix {
                        t: to_f64(t),
                        pivot: i,
                        value: to_f64(d),
                    });
                }
                ws.inv_diag[i] = inv;
            }
        } else {
            let l = &mut ws.chol;
            l.copy_from_slice(&ws.mass);
            for j in 0..n {
                let mut d = l[j * n + j];
                for k2 in 0..j {
                    d -= l[j * n + k2] * l[j * n + k2];
                }
                if !(d > T::zero() && (T::one() / d).is_finite()) {
                    return Err(TimeStepError::MassMatrix {
                        t: to_f64(t),
                        pivot: j,
                        value: to_f64(d),
                    });
                }
                let d = d.sqrt();
                l[j * n + j] = d;
                for i in j + 1..n {
                    let mut s = l[i * n + j];
                    for k2 in 0..j {
                        s -= l[i * n + k2] * l[j * n + k2];
                    }
                    l[i * n + j] = s / d;
                }
            }
        }
        ws.factored = true;
        Ok(())
    }

    /// `x ← M⁻¹ x` (or `W⁻¹ x`) with the factorization.
    fn solve_mass(factor: Factor, inv_diag: &[T], l: &[T], piv: &[usize], x: &mut [T]) {
        let n = inv_diag.len();
        match factor {
            Factor::Diagonal => {
                for i in 0..n {
                    x[i] *= inv_diag[i];
                }
                return;
            }
            Factor::Lu => return lu_solve(l, piv, x),
            Factor::Cholesky => {}
        }
        for i in 0..n {
            let mut s = x[i];
            for k in 0..i {
                s -= l[i * n + k] * x[k];
            }
            x[i] = s / l[i * n + i];
        }
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..n {
                s -= l[k * n + i] * x[k];
            }
            x[i] = s / l[i * n + i];
        }
    }

    /// One step `[ta, tb]`: the free velocity, the active contacts, their complementarity
    /// problem, the impulses applied, the records, the position update.
    fn step(
        &mut self,
        k: usize,
        ta: T,
        tb: T,
        q: &mut [T],
        v: &mut [T],
    ) -> Result<LcpReport, TimeStepError> {
        let h = tb - ta;
        if !self.ws.factored || !self.ws.constant || self.ws.implicit {
            self.factor(k, ta, tb - ta, q, v)?;
        }
        self.free_velocity(k, ta, tb, q, v)?;
        self.activate(k, ta, h, q, v)?;
        let frictional = matches!(self.solver, Solver::Nsgs(_));
        let report = self.solve_contacts(k, ta, tb, q, frictional)?;
        // v⁺ = v_free + M⁻¹ Σ p_α r_αᵀ.
        self.ws.vnew.copy_from_slice(&self.ws.vfree);
        self.apply_impulses(frictional);
        Self::nonfinite(k, ta, "velocity", &self.ws.vnew)?;
        let resting =
            self.solver.tolerance() * self.ws.q.iter().fold(T::zero(), |a, &x| a.max(x.abs()));
        self.record(tb, q, frictional, resting);
        // q⁺ = q + h ((1−θ) v + θ v⁺).
        let theta = self.theta;
        for i in 0..self.ws.n {
            q[i] += h * ((T::one() - theta) * v[i] + theta * self.ws.vnew[i]);
        }
        v.copy_from_slice(&self.ws.vnew);
        Self::nonfinite(k, tb, "position", q)?;
        if self.projection.is_some() {
            self.project(k, tb, q)?;
        }
        Ok(report)
    }

    /// The position projection at the end of step `k` (see
    /// [`with_projection`](Self::with_projection)). It reuses the step's contact rows,
    /// Delassus matrix and velocity buffers, which the step's records no longer need.
    fn project(&mut self, k: usize, tb: T, q: &mut [T]) -> Result<(), TimeStepError> {
        let Some(tolerance) = self.projection.as_ref().map(|p| p.tolerance) else {
            return Ok(());
        };
        let n = self.ws.n;
        for iteration in 0..=PROJECTION_ITERATIONS {
            let worst = self.gather_gaps(k, tb, q, tolerance)?;
            let act = self.ws.active.len();
            match worst {
                Some((_, g)) if g >= -tolerance => return Ok(()),
                None => return Ok(()),
                Some((contact, gap)) if iteration == PROJECTION_ITERATIONS => {
                    return Err(TimeStepError::Projection {
                        step: k,
                        t: to_f64(tb),
                        contact,
                        gap: to_f64(gap),
                        iterations: iteration,
                        tolerance: to_f64(tolerance),
                    });
                }
                Some(_) => {}
            }
            self.delassus(act, false);
            let ws = &mut self.ws;
            ws.q.clear();
            ws.q.extend_from_slice(&ws.gaps);
            ws.p.clear();
            ws.p.resize(act, T::zero());
            let Some(projection) = self.projection.as_mut() else {
                return Ok(());
            };
            projection
                .solver
                .solve(&ws.w[..act * act], &ws.q, &mut ws.p)
                .map_err(|source| TimeStepError::Contact {
                    step: k,
                    t: to_f64(tb),
                    source,
                })?;
            ws.vnew.iter_mut().for_each(|x| *x = T::zero());
            self.apply_impulses(false);
            let ws = &self.ws;
            for i in 0..n {
                q[i] += ws.vnew[i];
            }
            Self::nonfinite(k, tb, "projected position", q)?;
        }
        Ok(())
    }

    /// The contacts with `g_i ≤ tolerance` at `(t, q)`: their indices, gaps and normal rows
    /// into the workspace (an empty tangent row after each, the layout of the step's
    /// rows). Returns the most penetrated contact and its gap.
    fn gather_gaps(
        &mut self,
        k: usize,
        t: T,
        q: &[T],
        tolerance: T,
    ) -> Result<Option<(usize, T)>, TimeStepError> {
        let ws = &mut self.ws;
        ws.rows.clear();
        ws.offsets.clear();
        ws.offsets.push(0);
        ws.active.clear();
        ws.gaps.clear();
        let mut worst: Option<(usize, T)> = None;
        for i in 0..ws.m {
            let gap = evaluate_contact(&self.contacts, ws, i, t, q)?.gap;
            if !gap.is_finite() {
                return Err(TimeStepError::NonFinite {
                    step: k,
                    t: to_f64(t),
                    what: "projected gap",
                    index: i,
                    value: to_f64(gap),
                });
            }
            if gap <= tolerance {
                if worst.is_none_or(|(_, g)| gap < g) {
                    worst = Some((i, gap));
                }
                ws.held[i] = true;
                ws.active.push(i);
                ws.gaps.push(gap);
                ws.rows.extend_from_slice(&ws.scratch_n);
                ws.offsets.push(ws.rows.len());
                ws.offsets.push(ws.rows.len());
            }
        }
        Ok(worst)
    }

    /// The free velocity `v_free = v + h M⁻¹ ((1−θ) f(ta, q, v) + θ f(tb, q + h v, v))`.
    fn free_velocity(
        &mut self,
        k: usize,
        ta: T,
        tb: T,
        q: &[T],
        v: &[T],
    ) -> Result<(), TimeStepError> {
        let (h, theta, n) = (tb - ta, self.theta, self.ws.n);
        let ws = &mut self.ws;
        self.system.forces(ta, q, v, &mut ws.f0);
        if ws.implicit {
            // f(t_{k+1}, q_k, v_k); the change of q over the step enters through W and
            // −h²θ K v_k.
            self.system.forces(tb, q, v, &mut ws.f1);
        } else {
            for i in 0..n {
                ws.qpred[i] = q[i] + h * v[i];
            }
            self.system.forces(tb, &ws.qpred, v, &mut ws.f1);
        }
        Self::nonfinite(k, ta, "force", &ws.f0)?;
        Self::nonfinite(k, tb, "force", &ws.f1)?;
        for i in 0..n {
            ws.vfree[i] = h * ((T::one() - theta) * ws.f0[i] + theta * ws.f1[i]);
        }
        if ws.implicit {
            let hht = h * h * theta;
            for i in 0..n {
                let mut kv = T::zero();
                for j in 0..n {
                    kv += ws.tan_k[i * n + j] * v[j];
                }
                ws.vfree[i] -= hht * kv;
            }
        }
        Self::solve_mass(ws.factor, &ws.inv_diag, &ws.chol, &ws.piv, &mut ws.vfree);
        for i in 0..n {
            ws.vfree[i] += v[i];
        }
        Ok(())
    }

    /// The active contacts, by the predicted gap `g + γ h ġ ≤ δ` or held by the last
    /// position projection (see [`with_projection`](Self::with_projection)): their indices, gaps,
    /// pre-step rates and Jacobian rows (normal, tangent) into the workspace; an inactive
    /// contact's warm start is cleared.
    fn activate(&mut self, k: usize, ta: T, h: T, q: &[T], v: &[T]) -> Result<(), TimeStepError> {
        let ws = &mut self.ws;
        let threshold = match self.threshold {
            Some(d) => d,
            None => {
                let scale = q.iter().fold(T::one(), |a, &x| a.max(x.abs()));
                lit::<T>(16.0) * T::default_epsilon() * scale
            }
        };
        ws.rows.clear();
        ws.offsets.clear();
        ws.offsets.push(0);
        ws.active.clear();
        ws.gaps.clear();
        ws.pre.clear();
        ws.records.clear();
        for i in 0..ws.m {
            let geo = evaluate_contact(&self.contacts, ws, i, ta, q)?;
            let drift = self.contacts.drift(i, ta, q);
            let mut un = drift[0];
            for &(j, x) in ws.scratch_n.iter() {
                un += x * v[j];
            }
            let mut ut = drift[1];
            for &(j, x) in ws.scratch_t.iter() {
                ut += x * v[j];
            }
            let check = [geo.gap, un, ut];
            if check.iter().any(|x| !x.is_finite()) {
                return Err(TimeStepError::NonFinite {
                    step: k,
                    t: to_f64(ta),
                    what: "contact gap or rows",
                    index: i,
                    value: to_f64(geo.gap + un + ut),
                });
            }
            let held = core::mem::replace(&mut ws.held[i], false);
            if held || geo.gap + self.gamma * h * un <= threshold {
                ws.active.push(i);
                ws.gaps.push(geo.gap);
                ws.pre.push([un, ut]);
                ws.rows.extend_from_slice(&ws.scratch_n);
                ws.offsets.push(ws.rows.len());
                ws.rows.extend_from_slice(&ws.scratch_t);
                ws.offsets.push(ws.rows.len());
            } else {
                ws.last[i] = [T::zero(); 2];
            }
        }
        Ok(())
    }

    /// The complementarity problem of the active contacts, `w = W p + q`, solved into
    /// `ws.p` (warm-started from the last step's impulses): rows `(n₁, t₁, n₂, t₂, …)` if
    /// `frictional`, normal rows only otherwise.
    fn solve_contacts(
        &mut self,
        k: usize,
        ta: T,
        tb: T,
        q: &[T],
        frictional: bool,
    ) -> Result<LcpReport, TimeStepError> {
        let act = self.ws.active.len();
        let d = if frictional { 2 * act } else { act };
        if act == 0 {
            return Ok(LcpReport {
                iterations: 0,
                residual: 0.0,
            });
        }
        self.delassus(d, frictional);
        let ws = &mut self.ws;
        ws.q.clear();
        ws.p.clear();
        ws.mu.clear();
        for a in 0..d {
            let c = if frictional { a / 2 } else { a };
            let normal = !frictional || a % 2 == 0;
            let i = ws.active[c];
            let drift = self.contacts.drift(i, tb, q);
            let mut s = if normal { drift[0] } else { drift[1] };
            for &(j, x) in row(&ws.rows, &ws.offsets, row_index(a, frictional)) {
                s += x * ws.vfree[j];
            }
            if normal {
                s += self.contacts.restitution(i) * ws.pre[c][0];
            }
            ws.q.push(s);
            ws.p.push(ws.last[i][if normal { 0 } else { 1 }]);
        }
        if frictional {
            for c in 0..act {
                ws.mu.push(self.contacts.friction(ws.active[c]));
            }
        }
        let w = &ws.w[..d * d];
        let result = match &mut self.solver {
            Solver::Lemke(s) => s.solve(w, &ws.q, &mut ws.p),
            Solver::Pgs(s) => s.solve(w, &ws.q, &mut ws.p),
            Solver::Nsgs(s) => s.solve(w, &ws.q, &ws.mu, &mut ws.p),
        };
        result.map_err(|source| TimeStepError::Contact {
            step: k,
            t: to_f64(ta),
            source,
        })
    }

    /// The Delassus matrix `W = H M⁻¹ Hᵀ` of the `d` problem rows into `ws.w` (and, for a
    /// general mass matrix, `G_β = M⁻¹ r_βᵀ` into `ws.dense`).
    fn delassus(&mut self, d: usize, frictional: bool) {
        let ws = &mut self.ws;
        let n = ws.n;
        if ws.w.len() < d * d {
            ws.w.resize(d * d, T::zero());
        }
        if ws.factor != Factor::Diagonal && ws.dense.len() < d * n {
            ws.dense.resize(d * n, T::zero());
        }
        if ws.factor != Factor::Diagonal {
            for b in 0..d {
                let rb = row_index(b, frictional);
                let (lo, hi) = (ws.offsets[rb], ws.offsets[rb + 1]);
                let g = &mut ws.dense[b * n..(b + 1) * n];
                g.iter_mut().for_each(|x| *x = T::zero());
                for &(j, x) in &ws.rows[lo..hi] {
                    g[j] += x;
                }
            }
            for b in 0..d {
                Self::solve_mass(
                    ws.factor,
                    &ws.inv_diag,
                    &ws.chol,
                    &ws.piv,
                    &mut ws.dense[b * n..(b + 1) * n],
                );
            }
        }
        for a in 0..d {
            let ra = row(&ws.rows, &ws.offsets, row_index(a, frictional));
            for b in 0..d {
                let mut s = T::zero();
                if ws.factor == Factor::Diagonal {
                    let rb = row(&ws.rows, &ws.offsets, row_index(b, frictional));
                    for &(i, x) in ra {
                        for &(j, y) in rb {
                            if i == j {
                                s += x * y * ws.inv_diag[i];
                            }
                        }
                    }
                } else {
                    let g = &ws.dense[b * n..(b + 1) * n];
                    for &(i, x) in ra {
                        s += x * g[i];
                    }
                }
                ws.w[a * d + b] = s;
            }
        }
    }

    /// `ws.vnew += M⁻¹ Σ p_α r_αᵀ` over the problem's rows.
    fn apply_impulses(&mut self, frictional: bool) {
        let ws = &mut self.ws;
        let n = ws.n;
        let act = ws.active.len();
        let d = if frictional { 2 * act } else { act };
        for a in 0..d {
            let pa = ws.p[a];
            if pa == T::zero() {
                continue;
            }
            if ws.factor == Factor::Diagonal {
                for &(j, x) in row(&ws.rows, &ws.offsets, row_index(a, frictional)) {
                    ws.vnew[j] += pa * x * ws.inv_diag[j];
                }
            } else {
                for j in 0..n {
                    ws.vnew[j] += pa * ws.dense[a * n + j];
                }
            }
        }
    }

    /// The records of the active contacts, the work of the impulses, and the warm start
    /// of the next step.
    fn record(&mut self, tb: T, q: &[T], frictional: bool, resting: T) {
        let ws = &mut self.ws;
        ws.work = T::zero();
        for c in 0..ws.active.len() {
            let i = ws.active[c];
            let (pn, pt) = if frictional {
                (ws.p[2 * c], ws.p[2 * c + 1])
            } else {
                (ws.p[c], T::zero())
            };
            ws.last[i] = [pn, pt];
            let drift = self.contacts.drift(i, tb, q);
            let (mut post, mut slip, mut free, mut free_slip) =
                (drift[0], drift[1], drift[0], drift[1]);
            for &(j, x) in row(&ws.rows, &ws.offsets, 2 * c) {
                post += x * ws.vnew[j];
                free += x * ws.vfree[j];
            }
            for &(j, x) in row(&ws.rows, &ws.offsets, 2 * c + 1) {
                slip += x * ws.vnew[j];
                free_slip += x * ws.vfree[j];
            }
            // A resting contact (pressed, left at rest to the solver's tolerance) stays in
            // the next step's problem.
            if pn > T::zero() && post <= resting {
                ws.held[i] = true;
            }
            // ΔT = ½ pᵀ H (v⁺ + v_free): the drift terms cancel in the sums below.
            ws.work += lit::<T>(0.5)
                * (pn * (post + free - drift[0] - drift[0])
                    + pt * (slip + free_slip - drift[1] - drift[1]));
            ws.records.push(ContactRecord {
                index: i,
                gap: ws.gaps[c],
                pre: ws.pre[c][0],
                post,
                free,
                slip,
                free_slip,
                normal_impulse: pn,
                tangent_impulse: pt,
            });
        }
    }
}
