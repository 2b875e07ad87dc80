//! Complementarity solvers: Lemke's pivoting method, projected Gauss–Seidel, and a
//! nonsmooth (block) Gauss–Seidel for two-dimensional Coulomb contacts.
//!
//! # Problems
//! The **linear complementarity problem** LCP(M, q): find `z ∈ ℝⁿ` with
//! $$ w = Mz + q,\qquad 0 \le z \;\perp\; w \ge 0 ,$$
//! i.e. `z ≥ 0`, `w ≥ 0` and `zᵢwᵢ = 0` for every `i`. Matrices are dense, row-major
//! slices of length `n²` (`m[i * n + j]`).
//!
//! The **frictional contact problem** in the plane: for `k` contacts with impulses
//! `p = (p_{n,1}, p_{t,1}, …, p_{n,k}, p_{t,k})` and local velocities `u = Wp + q` (the same
//! interleaved order), each contact satisfies Signorini's condition and Coulomb's law
//! $$ 0 \le p_n \perp u_n \ge 0,\qquad
//!    |p_t| \le \mu p_n,\quad p_t = -\mu p_n \operatorname{sgn}(u_t) \text{ if } u_t \ne 0 .$$
//!
//! # Residual
//! Every solver reports the **complementarity residual** of its answer: the natural map
//! with `z` measured in the units of `w` by `s_M = max_ij |M_ij|`, relative to the data,
//! $$ r = \frac{\max_i |\min(s_M z_i,\, w_i)|}{\lVert q\rVert_\infty} ,$$
//! and for friction the same with the tangential term
//! `|s_M p_t − clamp(s_M p_t − u_t, −μ s_M p_n, μ s_M p_n)|`. `r` does not change when `q`
//! or `M` is multiplied by a positive factor (the answer `z` scales with `q` and inversely
//! with `M`), so one tolerance means the same at every scale: a residual of `10⁻¹⁰` leaves
//! every `w_i` of a positive `z_i` within `10⁻¹⁰ ‖q‖∞` of zero, whether the data are of
//! order 1, `10⁻³⁰⁰` or `10³⁰⁰`. Where `q ≥ 0` (no contact pressed), `z = 0` solves the
//! problem and every solver returns it at once (residual 0). A solver that cannot bring
//! `r` to its tolerance returns an [`LcpError`] naming the residual reached; it never
//! returns an unconverged answer.
//!
//! # Which solver
//! - [`Lemke`] is exact (to rounding: the final basis is re-solved by an LU factorization)
//!   for any `M` for which the method terminates — every P-matrix, hence every symmetric
//!   positive-definite Delassus matrix; the cost is a pivot count times `O(n²)`,
//!   usually a few times `n` pivots, exponential in the worst case (Murty's family).
//! - [`Pgs`], projected Gauss–Seidel, `O(n²)` per sweep; converges for symmetric
//!   positive-definite `M` (a column or chain of contacts), linearly, slowly when `M` is
//!   ill-conditioned. Warm-started from the `z` it is given.
//! - [`Nsgs`], the block version of PGS for frictional contacts, each 2×2 block solved
//!   exactly (take-off, stick, or slide in either direction).
//!
//! # References
//! C. E. Lemke, *Management Science* 11 (1965) 681–689; K. G. Murty, *Linear
//! Complementarity, Linear and Nonlinear Programming* (Heldermann, 1988), ch. 2 and 6;
//! R. W. Cottle, J.-S. Pang, R. E. Stone, *The Linear Complementarity Problem* (1992);
//! V. Acary, B. Brogliato, *Numerical Methods for Nonsmooth Dynamical Systems* (Springer,
//! 2008), ch. 12–13.

use thiserror::Error;

use crate::Real;
use crate::scalar::{lit, to_f64};

/// Why a complementarity problem was not solved.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum LcpError {
    /// The data do not fit together.
    #[error("complementarity problem: {what} has length {got}, expected {expected}")]
    Dimension {
        /// Which input.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length the problem size requires.
        expected: usize,
    },
    /// An entry of the data is NaN or infinite.
    #[error("complementarity problem: {what}[{index}] = {value} is not finite")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// The flat index of the entry.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A diagonal entry a Gauss–Seidel sweep divides by is not positive.
    #[error(
        "complementarity problem: diagonal entry {index} = {value} is not > 0 (Gauss–Seidel needs a positive diagonal; use Lemke)"
    )]
    NonPositiveDiagonal {
        /// The row.
        index: usize,
        /// The entry.
        value: f64,
    },
    /// Lemke's method found an unbounded ray: the problem has no solution it can reach
    /// (e.g. an infeasible problem, or `M` not copositive-plus).
    #[error(
        "Lemke: ray termination after {pivots} pivots (entering variable {entering} has no blocking row): the problem has no solution reachable by Lemke's method"
    )]
    RayTermination {
        /// Pivots done.
        pivots: usize,
        /// The entering variable (`0..n`: `w`, `n..2n`: `z`, `2n`: the artificial `z₀`).
        entering: usize,
    },
    /// Lemke's method reached its pivot limit (exponential worst case, or cycling).
    #[error(
        "Lemke: pivot limit {limit} reached (the artificial variable is still {artificial}): raise the limit or use an iterative solver"
    )]
    PivotLimit {
        /// The limit.
        limit: usize,
        /// The artificial variable's value when stopped.
        artificial: f64,
    },
    /// An iterative solver did not reach its tolerance.
    #[error(
        "{solver}: not converged after {iterations} iterations (residual {residual:e} > tolerance {tolerance:e})"
    )]
    NotConverged {
        /// The solver.
        solver: &'static str,
        /// Iterations done.
        iterations: usize,
        /// The residual reached.
        residual: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// The answer's scale, `‖q‖∞ / max_ij |M_ij|`, lies outside the range of the scalar
    /// type: `z` would overflow or underflow.
    #[error(
        "complementarity problem: the answer's scale ‖q‖∞ / max|M_ij| = {q_norm:e} / {m_norm:e} is outside the range of the scalar type (z would overflow or underflow): rescale the problem"
    )]
    Scale {
        /// `‖q‖∞`.
        q_norm: f64,
        /// `max_ij |M_ij|`.
        m_norm: f64,
    },
    /// Lemke's method terminated but its answer (after re-solving the final basis) misses
    /// the tolerance: the problem is too ill-conditioned for the scalar type.
    #[error(
        "Lemke: terminated with residual {residual:e} > tolerance {tolerance:e} (ill-conditioned problem)"
    )]
    Inaccurate {
        /// The residual.
        residual: f64,
        /// The tolerance.
        tolerance: f64,
    },
}

/// What a successful solve did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LcpReport {
    /// Pivots (Lemke) or sweeps (Gauss–Seidel).
    pub iterations: usize,
    /// The complementarity residual of the answer (see the [module docs](self)).
    pub residual: f64,
}

/// The default residual tolerance (relative, see the [module docs](self)): `10⁻¹⁰`, or
/// `1000 ε` if larger (`1.2·10⁻⁴` for `f32`).
fn default_tolerance<T: Real>() -> T {
    lit::<T>(1e-10).max(lit::<T>(1000.0) * T::default_epsilon())
}

/// `max_i |x_i|`.
fn norm_inf<T: Real>(x: &[T]) -> T {
    x.iter().fold(T::zero(), |a, &v| a.max(v.abs()))
}

/// The exponent `e` with `2^e ≤ |x| < 2^{e+1}` (of the `f64` value; 0 for 0 or non-finite).
fn exponent<T: Real>(x: T) -> i32 {
    let v = to_f64(x).abs();
    if v > 0.0 && v.is_finite() {
        v.log2().floor() as i32
    } else {
        0
    }
}

/// `x · 2^e`, exact unless the result over- or underflows (in steps of at most `2^±960`,
/// all of one sign, so that no intermediate result loses what the final one keeps).
fn ldexp<T: Real>(mut x: T, mut e: i32) -> T {
    while e != 0 {
        let k = e.clamp(-960, 960);
        x *= lit::<T>(2.0_f64.powi(k));
        e -= k;
    }
    x
}

/// The scaled complementarity residual `max_i |min(s_M z_i, w_i)| / ‖q‖∞` of `z` for
/// LCP(M, q), `w = Mz + q`, `s_M = max_ij |M_ij|` (see the [module docs](self)); 0 where
/// `q = 0` and `z = 0`. NaN entries give NaN.
///
/// # Errors
/// [`LcpError::Dimension`] if `m` is not `n × n` or `z` not of length `n = q.len()`.
pub fn residual<T: Real>(m: &[T], q: &[T], z: &[T]) -> Result<T, LcpError> {
    let n = q.len();
    check_len("m", m.len(), n * n)?;
    check_len("z", z.len(), n)?;
    Ok(residual_unchecked(m, q, z))
}

fn residual_unchecked<T: Real>(m: &[T], q: &[T], z: &[T]) -> T {
    let n = q.len();
    let sm = norm_inf(m);
    let mut r = T::zero();
    for i in 0..n {
        let row = &m[i * n..(i + 1) * n];
        let w = row.iter().zip(z).fold(q[i], |a, (&mij, &zj)| a + mij * zj);
        let e = (sm * z[i]).min(w).abs();
        if !(e >= T::zero()) {
            return e;
        }
        r = r.max(e);
    }
    relative(r, norm_inf(q))
}

/// `r / scale`, 0 for `r = 0` (a zero problem solved by zero), infinite for `r > 0 = scale`.
fn relative<T: Real>(r: T, scale: T) -> T {
    if r == T::zero() { r } else { r / scale }
}

fn check_len(what: &'static str, got: usize, expected: usize) -> Result<(), LcpError> {
    if got == expected {
        Ok(())
    } else {
        Err(LcpError::Dimension {
            what,
            got,
            expected,
        })
    }
}

fn check_finite<T: Real>(what: &'static str, x: &[T]) -> Result<(), LcpError> {
    match x.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(LcpError::NonFinite {
            what,
            index,
            value: to_f64(x[index]),
        }),
    }
}

/// Checks `m` (`n × n`), `q` and `z` (length `n`) and their finiteness.
fn check_problem<T: Real>(m: &[T], q: &[T], z: &[T]) -> Result<usize, LcpError> {
    let n = q.len();
    check_len("m", m.len(), n * n)?;
    check_len("z", z.len(), n)?;
    check_finite("m", m)?;
    check_finite("q", q)?;
    Ok(n)
}

/// Lemke's complementary pivoting method with the covering vector `d = (1, …, 1)` and a
/// lexicographic ratio test (no cycling on degenerate problems), followed by a re-solve of
/// the final basis `M_BB z_B = −q_B` by LU with partial pivoting, which brings the answer to
/// rounding accuracy.
///
/// The tableau (`n × (2n + 2)`) is kept between calls: repeated solves of problems of the
/// same or smaller size allocate nothing ([`reserve`](Self::reserve) sizes it up front).
///
/// # Examples
/// ```
/// use nonsmooth::timestep::lcp::Lemke;
/// // Two balls pressed together and onto the floor: M symmetric positive definite.
/// let m = [2.0, -1.0, -1.0, 2.0];
/// let q = [-1.0, 0.5];
/// let mut z = [0.0_f64; 2];
/// let report = Lemke::new().solve(&m, &q, &mut z)?;
/// assert!((z[0] - 0.5).abs() < 1e-15 && z[1] == 0.0);
/// assert!(report.residual <= 1e-15);
/// # Ok::<(), nonsmooth::timestep::lcp::LcpError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Lemke<T> {
    pivot_limit: Option<usize>,
    tolerance: T,
    tableau: Vec<T>,
    basis: Vec<usize>,
    candidates: Vec<usize>,
    lu: Vec<T>,
    rhs: Vec<T>,
    perm: Vec<usize>,
    active: Vec<usize>,
    trial: Vec<T>,
}

impl<T: Real> Default for Lemke<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> Lemke<T> {
    /// The solver with the default pivot limit `1000 + 50n` and residual tolerance `10⁻¹⁰`
    /// (`1000 ε` if larger: `1.2·10⁻⁴` for `f32`).
    pub fn new() -> Self {
        Self {
            pivot_limit: None,
            tolerance: default_tolerance(),
            tableau: Vec::new(),
            basis: Vec::new(),
            candidates: Vec::new(),
            lu: Vec::new(),
            rhs: Vec::new(),
            perm: Vec::new(),
            active: Vec::new(),
            trial: Vec::new(),
        }
    }

    /// Sets the pivot limit.
    pub fn with_pivot_limit(mut self, limit: usize) -> Self {
        self.pivot_limit = Some(limit.max(1));
        self
    }

    /// Sets the residual an answer must reach (scaled, see the [module docs](self)).
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `tolerance` is finite and > 0.
    pub fn with_tolerance(mut self, tolerance: T) -> Result<Self, crate::ParameterError> {
        self.tolerance = crate::validate::positive("tolerance", tolerance)?;
        Ok(self)
    }

    /// The residual tolerance (relative, see the [module docs](self)).
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// Sizes the workspace for problems up to `n` unknowns.
    pub fn reserve(&mut self, n: usize) {
        let grow = |v: &mut Vec<T>, len: usize| {
            if v.len() < len {
                v.resize(len, T::zero());
            }
        };
        grow(&mut self.tableau, n * (2 * n + 2));
        grow(&mut self.lu, n * n);
        grow(&mut self.rhs, n);
        grow(&mut self.trial, n);
        for v in [
            &mut self.basis,
            &mut self.candidates,
            &mut self.perm,
            &mut self.active,
        ] {
            if v.len() < n {
                v.resize(n, 0);
            }
        }
    }

    /// Solves LCP(`m`, `q`) into `z` (its input value is ignored).
    ///
    /// # Errors
    /// [`LcpError::Dimension`] / [`LcpError::NonFinite`] for bad data;
    /// [`LcpError::RayTermination`] if the method finds no solution;
    /// [`LcpError::PivotLimit`] at the pivot limit; [`LcpError::Inaccurate`] if the
    /// residual of the answer exceeds the tolerance. `z` is unspecified after an error.
    pub fn solve(&mut self, m: &[T], q: &[T], z: &mut [T]) -> Result<LcpReport, LcpError> {
        let n = check_problem(m, q, z)?;
        z.iter_mut().for_each(|x| *x = T::zero());
        if n == 0 || q.iter().all(|&x| x >= T::zero()) {
            return Ok(LcpReport {
                iterations: 0,
                residual: 0.0,
            });
        }
        self.reserve(n);
        // The method runs on the problem scaled by powers of two, exactly, to entries of
        // order 1: `M/2^a`, `q/2^b` (its tests and floors are then relative to the data),
        // and `z = z̃·2^(b−a)`.
        let (m_norm, q_norm) = (norm_inf(m), norm_inf(q));
        let (ea, eb) = (exponent(m_norm), exponent(q_norm));
        let scale_error = || LcpError::Scale {
            q_norm: to_f64(q_norm),
            m_norm: to_f64(m_norm),
        };
        if !(m_norm > T::zero()) {
            // M = 0 with some q_i < 0: w_i = q_i < 0 whatever z.
            return Err(LcpError::RayTermination {
                pivots: 0,
                entering: 2 * n,
            });
        }
        let limit = self.pivot_limit.unwrap_or(1000 + 50 * n);
        let cols = 2 * n + 2;
        let (z0, rhs) = (2 * n, 2 * n + 1);
        let tab = &mut self.tableau[..n * cols];
        // w − M z − d z₀ = q, basis w.
        for i in 0..n {
            let row = &mut tab[i * cols..(i + 1) * cols];
            row.iter_mut().for_each(|x| *x = T::zero());
            row[i] = T::one();
            for j in 0..n {
                row[n + j] = -ldexp(m[i * n + j], -ea);
            }
            row[z0] = -T::one();
            row[rhs] = ldexp(q[i], -eb);
            self.basis[i] = i;
        }
        // z₀ enters; the row of the most negative q leaves (ties broken lexicographically).
        let mut r = 0;
        for i in 1..n {
            if q[i] < q[r] {
                r = i;
            }
        }
        let tie = lit::<T>(1e-12) * q_norm;
        let mut ties = 0;
        for i in 0..n {
            if q[i] - q[r] <= tie {
                self.candidates[ties] = i;
                ties += 1;
            }
        }
        if ties > 1 {
            // Lexicographic minimum of (q_i, e_i) / (−1) ⇔ smallest ratio row first; the
            // identity part decides: the largest index among ties has the smallest e-row.
            r = self.candidates[ties - 1];
        }
        pivot(tab, n, cols, r, z0);
        let leaving = self.basis[r];
        self.basis[r] = z0;
        let mut entering = complement(leaving, n);
        let mut pivots = 1;
        loop {
            if pivots >= limit {
                let artificial = (0..n)
                    .find(|&i| self.basis[i] == z0)
                    .map_or(0.0, |i| to_f64(tab[i * cols + rhs]));
                return Err(LcpError::PivotLimit { limit, artificial });
            }
            let Some(r) = lex_ratio(tab, n, cols, entering, &self.basis, &mut self.candidates)
            else {
                return Err(LcpError::RayTermination { pivots, entering });
            };
            pivot(tab, n, cols, r, entering);
            let leaving = self.basis[r];
            self.basis[r] = entering;
            pivots += 1;
            if leaving == z0 {
                break;
            }
            entering = complement(leaving, n);
        }
        let mut largest = T::zero();
        for i in 0..n {
            let b = self.basis[i];
            if (n..2 * n).contains(&b) {
                let zi = tab[i * cols + rhs].max(T::zero());
                largest = largest.max(zi);
                z[b - n] = ldexp(zi, eb - ea);
            }
        }
        // The largest entry must survive the scaling both ways (no overflow, no loss of
        // digits to underflow); smaller ones may underflow, below its rounding.
        let back = ldexp(largest, eb - ea);
        if !back.is_finite() || ldexp(back, ea - eb) != largest {
            return Err(scale_error());
        }
        let mut res = residual_unchecked(m, q, z);
        if let Some(polished) = self.polish(m, q, z) {
            if polished < res || !(res >= T::zero()) {
                res = polished;
                z[..n].copy_from_slice(&self.trial[..n]);
            }
        }
        if !(res <= self.tolerance) {
            return Err(LcpError::Inaccurate {
                residual: to_f64(res),
                tolerance: to_f64(self.tolerance),
            });
        }
        Ok(LcpReport {
            iterations: pivots,
            residual: to_f64(res),
        })
    }

    /// Re-solves `M_BB z_B = −q_B` on the support `B` of `z` into `trial`; returns the
    /// residual of the result if it is a valid (non-negative) answer.
    fn polish(&mut self, m: &[T], q: &[T], z: &[T]) -> Option<T> {
        let n = q.len();
        let mut k = 0;
        for (j, &zj) in z.iter().enumerate() {
            if zj > T::zero() {
                self.active[k] = j;
                k += 1;
            }
        }
        let act = &self.active[..k];
        let a = &mut self.lu[..k * k];
        for (r, &i) in act.iter().enumerate() {
            for (c, &j) in act.iter().enumerate() {
                a[r * k + c] = m[i * n + j];
            }
            self.rhs[r] = -q[i];
        }
        if !lu_solve(a, k, &mut self.rhs[..k], &mut self.perm[..k]) {
            return None;
        }
        self.trial[..n].iter_mut().for_each(|x| *x = T::zero());
        for (r, &j) in act.iter().enumerate() {
            let v = self.rhs[r];
            if !(v >= T::zero()) {
                return None;
            }
            self.trial[j] = v;
        }
        Some(residual_unchecked(m, q, &self.trial[..n]))
    }
}

/// The complement of a variable: `w_j ↔ z_j`.
fn complement(v: usize, n: usize) -> usize {
    if v < n { v + n } else { v - n }
}

/// Gauss–Jordan pivot on `(r, c)`.
fn pivot<T: Real>(tab: &mut [T], n: usize, cols: usize, r: usize, c: usize) {
    let inv = T::one() / tab[r * cols + c];
    for j in 0..cols {
        tab[r * cols + j] *= inv;
    }
    tab[r * cols + c] = T::one();
    for i in 0..n {
        if i == r {
            continue;
        }
        let f = tab[i * cols + c];
        if f == T::zero() {
            continue;
        }
        for j in 0..cols {
            let v = tab[r * cols + j];
            tab[i * cols + j] -= f * v;
        }
        tab[i * cols + c] = T::zero();
    }
}

/// The leaving row for entering column `c` by the lexicographic minimum ratio test (the
/// `w` columns hold `B⁻¹`); `None` if no row blocks (a ray). The artificial variable leaves
/// first among ties.
fn lex_ratio<T: Real>(
    tab: &[T],
    n: usize,
    cols: usize,
    c: usize,
    basis: &[usize],
    cand: &mut [usize],
) -> Option<usize> {
    let rhs = cols - 1;
    let eps = T::default_epsilon();
    let col_max = (0..n).fold(T::zero(), |a, i| a.max(tab[i * cols + c].abs()));
    let piv_tol = eps * lit::<T>(64.0) * col_max.max(T::one());
    let mut k = 0;
    for i in 0..n {
        if tab[i * cols + c] > piv_tol {
            cand[k] = i;
            k += 1;
        }
    }
    if k == 0 {
        return None;
    }
    // Column −1 stands for the right-hand side, then the columns of B⁻¹ in order.
    let mut col: isize = -1;
    while k > 1 && col < n as isize {
        let idx = if col < 0 { rhs } else { col as usize };
        let ratio = |i: usize| tab[i * cols + idx] / tab[i * cols + c];
        let best = (0..k).fold(T::max_value().unwrap_or(T::one() / eps), |a, s| {
            a.min(ratio(cand[s]))
        });
        let tol = eps * lit::<T>(64.0) * best.abs().max(T::one());
        let mut kept = 0;
        for s in 0..k {
            if ratio(cand[s]) <= best + tol {
                cand[kept] = cand[s];
                kept += 1;
            }
        }
        k = kept;
        if col < 0 {
            // Let the artificial variable leave when it ties: it ends the method.
            if let Some(s) = (0..k).find(|&s| basis[cand[s]] == 2 * n) {
                return Some(cand[s]);
            }
        }
        col += 1;
    }
    Some(cand[0])
}

/// Solves `A x = b` in place (`b` ← `x`) by LU with partial pivoting of the `k × k`
/// row-major `a`; `false` if singular or not finite.
fn lu_solve<T: Real>(a: &mut [T], k: usize, b: &mut [T], perm: &mut [usize]) -> bool {
    for (i, p) in perm.iter_mut().enumerate() {
        *p = i;
    }
    for c in 0..k {
        let mut p = c;
        for r in c + 1..k {
            if a[r * k + c].abs() > a[p * k + c].abs() {
                p = r;
            }
        }
        let piv = a[p * k + c];
        if !(piv.abs() > T::zero()) || !piv.is_finite() {
            return false;
        }
        if p != c {
            for j in 0..k {
                a.swap(p * k + j, c * k + j);
            }
            b.swap(p, c);
            perm.swap(p, c);
        }
        for r in c + 1..k {
            let l = a[r * k + c] / piv;
            if l == T::zero() {
                continue;
            }
            for j in c + 1..k {
                let u = a[c * k + j];
                a[r * k + j] -= l * u;
            }
            let bc = b[c];
            b[r] -= l * bc;
        }
    }
    for i in (0..k).rev() {
        let mut s = b[i];
        for j in i + 1..k {
            s -= a[i * k + j] * b[j];
        }
        b[i] = s / a[i * k + i];
    }
    b.iter().all(|x| x.is_finite())
}

/// Projected Gauss–Seidel for LCP(M, q):
/// `z_i ← max(0, z_i − (Mz + q)_i / M_ii)` row by row, optionally over-relaxed
/// (`ω ∈ (0, 2)`), until the residual reaches the tolerance.
///
/// Converges for symmetric positive-definite `M`; it needs a positive diagonal. Warm-started
/// from the `z` it is given (the previous step's impulses, in a time-stepping scheme).
///
/// # Examples
/// ```
/// use nonsmooth::timestep::lcp::Pgs;
/// let m = [2.0, -1.0, -1.0, 2.0];
/// let q = [-1.0, 0.5];
/// let mut z = [0.0_f64; 2];
/// let report = Pgs::new().solve(&m, &q, &mut z)?;
/// assert!((z[0] - 0.5).abs() < 1e-9 && z[1] == 0.0);
/// assert!(report.residual <= 1e-10);
/// # Ok::<(), nonsmooth::timestep::lcp::LcpError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pgs<T> {
    max_iterations: usize,
    tolerance: T,
    omega: T,
}

impl<T: Real> Default for Pgs<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> Pgs<T> {
    /// At most 10 000 sweeps to a residual of `10⁻¹⁰` (`1000 ε` if larger), no relaxation
    /// (`ω = 1`).
    pub fn new() -> Self {
        Self {
            max_iterations: 10_000,
            tolerance: default_tolerance(),
            omega: T::one(),
        }
    }

    /// Sets the sweep limit (at least 1).
    pub fn with_max_iterations(mut self, n: usize) -> Self {
        self.max_iterations = n.max(1);
        self
    }

    /// Sets the residual tolerance.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless finite and > 0.
    pub fn with_tolerance(mut self, tolerance: T) -> Result<Self, crate::ParameterError> {
        self.tolerance = crate::validate::positive("tolerance", tolerance)?;
        Ok(self)
    }

    /// The residual tolerance (relative, see the [module docs](self)).
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// Sets the relaxation factor `ω ∈ (0, 2)`.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `0 < ω < 2`.
    pub fn with_relaxation(mut self, omega: T) -> Result<Self, crate::ParameterError> {
        if !(omega > T::zero() && omega < lit(2.0)) {
            return Err(crate::ParameterError::new(
                "omega",
                to_f64(omega),
                "in (0, 2)",
            ));
        }
        self.omega = omega;
        Ok(self)
    }

    /// Solves LCP(`m`, `q`), starting from `z`.
    ///
    /// # Errors
    /// As [`solve_traced`](Self::solve_traced).
    pub fn solve(&self, m: &[T], q: &[T], z: &mut [T]) -> Result<LcpReport, LcpError> {
        self.solve_traced(m, q, z, |_, _| {})
    }

    /// As [`solve`](Self::solve), calling `trace(sweep, residual)` after each sweep (e.g. to
    /// record the convergence history).
    ///
    /// # Errors
    /// [`LcpError::Dimension`] / [`LcpError::NonFinite`] for bad data (a non-finite start
    /// `z` is reset to 0 instead), [`LcpError::NonPositiveDiagonal`], and
    /// [`LcpError::NotConverged`] with the residual reached after the sweep limit.
    pub fn solve_traced(
        &self,
        m: &[T],
        q: &[T],
        z: &mut [T],
        mut trace: impl FnMut(usize, T),
    ) -> Result<LcpReport, LcpError> {
        let n = check_problem(m, q, z)?;
        for i in 0..n {
            let d = m[i * n + i];
            if !(d > T::zero()) {
                return Err(LcpError::NonPositiveDiagonal {
                    index: i,
                    value: to_f64(d),
                });
            }
        }
        if q.iter().all(|&x| x >= T::zero()) {
            z.iter_mut().for_each(|x| *x = T::zero());
            return Ok(LcpReport {
                iterations: 0,
                residual: 0.0,
            });
        }
        for x in z.iter_mut() {
            if !(x.is_finite() && *x > T::zero()) {
                *x = T::zero();
            }
        }
        let mut res = T::zero();
        for it in 1..=self.max_iterations {
            for i in 0..n {
                let row = &m[i * n..(i + 1) * n];
                let w = row
                    .iter()
                    .zip(z.iter())
                    .fold(q[i], |a, (&a_ij, &zj)| a + a_ij * zj);
                z[i] = (z[i] - self.omega * w / row[i]).max(T::zero());
            }
            res = residual_unchecked(m, q, z);
            trace(it, res);
            if res <= self.tolerance {
                return Ok(LcpReport {
                    iterations: it,
                    residual: to_f64(res),
                });
            }
        }
        Err(LcpError::NotConverged {
            solver: "projected Gauss–Seidel",
            iterations: self.max_iterations,
            residual: to_f64(res),
            tolerance: to_f64(self.tolerance),
        })
    }
}

/// Nonsmooth (block) Gauss–Seidel for planar frictional contact: sweeps over the contacts,
/// solving each contact's 2×2 problem (Signorini + Coulomb with the others held fixed)
/// exactly — take-off (`p = 0`), stick (`u = 0`), or slide (`u_n = 0`,
/// `p_t = ∓μ p_n` opposing the slip) — until the residual (see the [module docs](self))
/// reaches the tolerance. With `μ = 0` it is projected Gauss–Seidel on the normal rows.
///
/// # Examples
/// ```
/// use nonsmooth::timestep::lcp::Nsgs;
/// // One contact, unit mass point: W = I; pushed down (q_n = −1) and sideways (q_t = 2).
/// let w = [1.0, 0.0, 0.0, 1.0];
/// let q = [-1.0, 2.0];
/// let mut p = [0.0_f64; 2];
/// Nsgs::new().solve(&w, &q, &[0.5], &mut p)?;
/// // Slides: p_t at the cone's edge, opposing the slip.
/// assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] + 0.5).abs() < 1e-12);
/// # Ok::<(), nonsmooth::timestep::lcp::LcpError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nsgs<T> {
    max_iterations: usize,
    tolerance: T,
}

impl<T: Real> Default for Nsgs<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> Nsgs<T> {
    /// At most 10 000 sweeps to a residual of `10⁻¹⁰` (`1000 ε` if larger).
    pub fn new() -> Self {
        Self {
            max_iterations: 10_000,
            tolerance: default_tolerance(),
        }
    }

    /// Sets the sweep limit (at least 1).
    pub fn with_max_iterations(mut self, n: usize) -> Self {
        self.max_iterations = n.max(1);
        self
    }

    /// Sets the residual tolerance.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless finite and > 0.
    pub fn with_tolerance(mut self, tolerance: T) -> Result<Self, crate::ParameterError> {
        self.tolerance = crate::validate::positive("tolerance", tolerance)?;
        Ok(self)
    }

    /// The residual tolerance (relative, see the [module docs](self)).
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// Solves the planar frictional contact problem with Delassus matrix `w` (`2k × 2k`,
    /// rows in the order `n₁, t₁, n₂, t₂, …`), free velocities `q` (`2k`) and friction
    /// coefficients `mu` (`k`, each ≥ 0), starting from the impulses `p`.
    ///
    /// # Errors
    /// [`LcpError::Dimension`] / [`LcpError::NonFinite`] for bad data (a negative `μ` is
    /// reported as non-finite data of `mu`), [`LcpError::NonPositiveDiagonal`] for a
    /// normal diagonal entry ≤ 0, [`LcpError::NotConverged`] at the sweep limit.
    pub fn solve(&self, w: &[T], q: &[T], mu: &[T], p: &mut [T]) -> Result<LcpReport, LcpError> {
        let n = check_problem(w, q, p)?;
        check_len("q", n, 2 * mu.len())?;
        check_finite("mu", mu)?;
        if let Some(i) = mu.iter().position(|&m| m < T::zero()) {
            return Err(LcpError::NonFinite {
                what: "mu",
                index: i,
                value: to_f64(mu[i]),
            });
        }
        for c in 0..mu.len() {
            let d = w[2 * c * n + 2 * c];
            if !(d > T::zero()) {
                return Err(LcpError::NonPositiveDiagonal {
                    index: 2 * c,
                    value: to_f64(d),
                });
            }
        }
        if q.iter().step_by(2).all(|&x| x >= T::zero()) {
            // Every contact takes off: p = 0 (u = q, u_n ≥ 0).
            p.iter_mut().for_each(|x| *x = T::zero());
            return Ok(LcpReport {
                iterations: 0,
                residual: 0.0,
            });
        }
        for x in p.iter_mut() {
            if !x.is_finite() {
                *x = T::zero();
            }
        }
        let mut res = T::zero();
        for it in 1..=self.max_iterations {
            for (c, &mu_c) in mu.iter().enumerate() {
                let (i, j) = (2 * c, 2 * c + 1);
                // Local velocities without this contact's own impulse.
                let mut rn = q[i];
                let mut rt = q[j];
                for k in 0..n {
                    if k != i && k != j {
                        rn += w[i * n + k] * p[k];
                        rt += w[j * n + k] * p[k];
                    }
                }
                let (pn, pt) = local_contact(
                    [w[i * n + i], w[i * n + j], w[j * n + i], w[j * n + j]],
                    rn,
                    rt,
                    mu_c,
                    p[j],
                );
                p[i] = pn;
                p[j] = pt;
            }
            res = frictional_residual(w, q, mu, p);
            if res <= self.tolerance {
                return Ok(LcpReport {
                    iterations: it,
                    residual: to_f64(res),
                });
            }
        }
        Err(LcpError::NotConverged {
            solver: "nonsmooth Gauss–Seidel",
            iterations: self.max_iterations,
            residual: to_f64(res),
            tolerance: to_f64(self.tolerance),
        })
    }
}

/// The exact solution of one planar contact, `u = A p + r`, `A = [[a_nn, a_nt], [a_tn,
/// a_tt]]`; `pt_old` is used only by the projected fallback (never reached for a positive
/// definite `A` and `μ` within its range).
fn local_contact<T: Real>(a: [T; 4], rn: T, rt: T, mu: T, pt_old: T) -> (T, T) {
    // Where `a_nn` is far from 1, on `A/2^e` (entries of order 1, exactly: the
    // determinant neither over- nor underflows), and `p = p̃/2^e`.
    if a[0] >= lit(1e-150) && a[0] <= lit(1e150) {
        return local_contact_unit(a, rn, rt, mu, pt_old);
    }
    let e = exponent(a[0]);
    let (pn, pt) = local_contact_unit(a.map(|x| ldexp(x, -e)), rn, rt, mu, ldexp(pt_old, e));
    (ldexp(pn, -e), ldexp(pt, -e))
}

/// [`local_contact`] for a block `A` with entries of order 1.
fn local_contact_unit<T: Real>(a: [T; 4], rn: T, rt: T, mu: T, pt_old: T) -> (T, T) {
    let [ann, ant, atn, att] = a;
    let zero = T::zero();
    if rn >= zero {
        return (zero, zero); // take-off
    }
    if mu == zero || !(att > zero) {
        return ((-rn / ann).max(zero), zero);
    }
    // Stick: A p = −r.
    let det = ann * att - ant * atn;
    if det > zero {
        let pn = (-rn * att + ant * rt) / det;
        let pt = (atn * rn - ann * rt) / det;
        if pn >= zero && pt.abs() <= mu * pn {
            return (pn, pt);
        }
    }
    // Slide in direction s (u_t has the sign of s, p_t = −s μ p_n).
    for s in [T::one(), -T::one()] {
        let den = ann - s * mu * ant;
        if den > zero {
            let pn = -rn / den;
            let pt = -s * mu * pn;
            let ut = atn * pn + att * pt + rt;
            if pn >= zero && s * ut >= zero {
                return (pn, pt);
            }
        }
    }
    // Projected fallback.
    let pn = (-(rn + ant * pt_old) / ann).max(zero);
    let pt = (-(rt + atn * pn) / att).max(-mu * pn).min(mu * pn);
    (pn, pt)
}

/// The residual of the planar frictional contact problem (see the [module docs](self)).
fn frictional_residual<T: Real>(w: &[T], q: &[T], mu: &[T], p: &[T]) -> T {
    let n = q.len();
    let sw = norm_inf(w);
    let mut r = T::zero();
    for (c, &mu_c) in mu.iter().enumerate() {
        let (i, j) = (2 * c, 2 * c + 1);
        let mut un = q[i];
        let mut ut = q[j];
        for k in 0..n {
            un += w[i * n + k] * p[k];
            ut += w[j * n + k] * p[k];
        }
        let (pn, pt) = (sw * p[i], sw * p[j]);
        let en = pn.min(un).abs();
        let bound = mu_c * pn.max(T::zero());
        let et = (pt - (pt - ut).max(-bound).min(bound)).abs();
        let e = en.max(et);
        if !(e >= T::zero()) {
            return e;
        }
        r = r.max(e);
    }
    relative(r, norm_inf(q))
}

/// The residual of the planar frictional contact problem for impulses `p` (see the
/// [module docs](self)); arguments as in [`Nsgs::solve`].
///
/// # Errors
/// [`LcpError::Dimension`] if the lengths do not fit.
pub fn frictional_contact_residual<T: Real>(
    w: &[T],
    q: &[T],
    mu: &[T],
    p: &[T],
) -> Result<T, LcpError> {
    let n = q.len();
    check_len("w", w.len(), n * n)?;
    check_len("p", p.len(), n)?;
    check_len("q", n, 2 * mu.len())?;
    Ok(frictional_residual(w, q, mu, p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lemke_trivial_and_two_by_two() {
        let mut s = Lemke::<f64>::new();
        let mut z = [1.0; 2];
        let r = s.solve(&[1.0, 0.0, 0.0, 1.0], &[1.0, 2.0], &mut z).unwrap();
        assert_eq!((z, r.iterations), ([0.0, 0.0], 0));
        let r = s
            .solve(&[1.0, 0.0, 0.0, 1.0], &[-1.0, -2.0], &mut z)
            .unwrap();
        assert_eq!(z, [1.0, 2.0]);
        assert!(r.residual == 0.0);
    }

    #[test]
    fn lemke_ray_on_infeasible() {
        // w = −z − 1 ≥ 0 is impossible with z ≥ 0.
        let e = Lemke::<f64>::new()
            .solve(&[-1.0], &[-1.0], &mut [0.0])
            .unwrap_err();
        assert!(matches!(e, LcpError::RayTermination { .. }), "{e}");
        assert!(e.to_string().contains("ray termination"));
    }

    #[test]
    fn bad_data_is_an_error() {
        let e = Lemke::<f64>::new()
            .solve(&[1.0], &[f64::NAN], &mut [0.0])
            .unwrap_err();
        assert!(matches!(e, LcpError::NonFinite { what: "q", .. }));
        let e = Pgs::<f64>::new()
            .solve(&[0.0], &[-1.0], &mut [0.0])
            .unwrap_err();
        assert!(matches!(e, LcpError::NonPositiveDiagonal { .. }));
        let e = Pgs::<f64>::new()
            .solve(&[1.0, 0.0], &[-1.0], &mut [0.0])
            .unwrap_err();
        assert!(matches!(e, LcpError::Dimension { .. }));
    }

    #[test]
    fn pgs_reports_unconverged() {
        let m = [1.0, 0.99, 0.99, 1.0];
        let e = Pgs::<f64>::new()
            .with_max_iterations(3)
            .solve(&m, &[-1.0, -1.0], &mut [0.0; 2])
            .unwrap_err();
        match e {
            LcpError::NotConverged {
                iterations,
                residual,
                ..
            } => {
                assert_eq!(iterations, 3);
                assert!(residual > 1e-10);
            }
            _ => panic!("{e}"),
        }
    }

    #[test]
    fn local_contact_cases() {
        let a = [1.0, 0.0, 0.0, 1.0];
        assert_eq!(local_contact(a, 1.0, 5.0, 0.3, 0.0), (0.0, 0.0));
        assert_eq!(local_contact(a, -1.0, 0.2, 0.3, 0.0), (1.0, -0.2));
        assert_eq!(local_contact(a, -1.0, -2.0, 0.3, 0.0), (1.0, 0.3));
    }

    #[test]
    fn f32_lemke() {
        let mut z = [0.0f32; 2];
        Lemke::<f32>::new()
            .with_tolerance(1e-5)
            .unwrap()
            .solve(&[2.0, -1.0, -1.0, 2.0], &[-1.0, -1.0], &mut z)
            .unwrap();
        assert!((z[0] - 1.0).abs() < 1e-6 && (z[1] - 1.0).abs() < 1e-6);
    }
}
