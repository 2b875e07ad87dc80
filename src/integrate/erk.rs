//! Explicit embedded Runge–Kutta pairs from a tableau: [`ExplicitTableau`] holds the
//! coefficients, one generic step advances any first-same-as-last pair over it, and
//! [`PowerInterpolant`] is the continuous extension in powers of `θ`.
//!
//! The step of a tableau with `s` stages (stage 0 is `f(t, y)`, cached from the last step;
//! the last stage is `f(t + h, y₁)`, kept for the next step):
//! $$k_i = f\Bigl(t + c_i h,\; y_0 + h\sum_{j<i} a_{ij} k_j\Bigr), \qquad
//!   y_1 = y_0 + h\sum_j a_{s-1,j}\,k_j,$$
//! the error estimate `h·Σ e_j k_j` (`e = b̂ − b`, the difference to the embedded
//! lower-order solution) in the weighted RMS norm of [`Tolerances`](super::Tolerances), and,
//! once the step is accepted, the stages `s…K−1` of the continuous extension (none for a
//! free interpolant) and
//! $$y(t_0 + θh) = y_0 + \sum_{m=1}^{D} θ^m q_m, \qquad q_m = h\sum_j r_{jm} k_j .$$

use nalgebra::SVector;

use super::adaptive::{Interpolant, MethodDense, StepParts, sealed};
use super::{HermiteDense, IntegrateError, Trial};
use crate::scalar::lit;
use crate::{Dynamics, Real};

/// The coefficients of an explicit embedded Runge–Kutta pair, first same as last, with a
/// continuous extension (read-only: the crate's methods expose theirs for inspection and
/// tests, e.g. [`Tsit5Method::TABLEAU`](super::Tsit5Method::TABLEAU)).
///
/// Stages are numbered from 0 (`c₀ = 0`). Stages `0…stages−1` make the step, the last of
/// them at `c = 1` on the new state (`a[stages−1]` is the weight vector `b`); stages
/// `stages…c.len()−1` are the extra stages of the continuous extension, evaluated only when a
/// step is accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ExplicitTableau {
    /// The order of the propagated solution.
    pub order: u8,
    /// The order of the embedded solution the error is estimated against.
    pub embedded_order: u8,
    /// The order of the continuous extension (uniform in `θ ∈ [0, 1]`).
    pub dense_order: u8,
    /// The stages of one step (the last is the first stage of the next step).
    pub stages: usize,
    /// The nodes `c_i` of every stage, the extension's included.
    pub c: &'static [f64],
    /// The rows of `A` (row `i` lists the nonzero `(j, a_ij)`, `j < i`); row `stages − 1`
    /// holds the weights `b`.
    pub a: &'static [&'static [(usize, f64)]],
    /// The nonzero `(j, b̂_j − b_j)`.
    pub error: &'static [(usize, f64)],
    /// The continuous extension: `(j, [r_j1, …, r_jD])`, `b_j(θ) = Σ_m r_jm θ^m`.
    pub dense: &'static [(usize, &'static [f64])],
}

impl ExplicitTableau {
    /// The weights `b_j` of the propagated solution (row `stages − 1` of `A`), dense.
    pub fn weights(&self) -> Vec<f64> {
        let mut b = vec![0.0; self.stages];
        for &(j, w) in self.a[self.stages - 1] {
            b[j] = w;
        }
        b
    }

    /// The weights `b̂_j` of the embedded solution, dense.
    pub fn embedded_weights(&self) -> Vec<f64> {
        let mut b = self.weights();
        for &(j, e) in self.error {
            b[j] += e;
        }
        b
    }

    /// The dense matrix `A` over every stage (extension included), row by row.
    pub fn matrix(&self) -> Vec<Vec<f64>> {
        let k = self.c.len();
        self.a
            .iter()
            .map(|row| {
                let mut r = vec![0.0; k];
                for &(j, a) in *row {
                    r[j] = a;
                }
                r
            })
            .collect()
    }

    /// The weights `b_j(θ)` of the continuous extension at `θ`, over every stage.
    pub fn dense_weights(&self, theta: f64) -> Vec<f64> {
        let mut b = vec![0.0; self.c.len()];
        for &(j, r) in self.dense {
            b[j] = r.iter().rev().fold(0.0, |acc, &x| (acc + x) * theta);
        }
        b
    }
}

/// A continuous extension in powers of `θ = (t − t₀)/h`: `y(t₀ + θh) = y₀ + Σ_{m=1}^{D} θ^m
/// q_m` (Horner), the dense output of [`Tsit5`](super::Tsit5) (`D = 4`) and
/// [`Vern6`](super::Vern6) (`D = 6`). `q_D` also carries what rounding leaves of
/// `y₁ − y₀ − Σ_m q_m` (the coefficients cancel: up to `10⁵` in magnitude for Vern6), so that
/// `θ = 1` gives the step's end `y₁` to the rounding of the sum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerInterpolant<T: Real, const N: usize, const D: usize> {
    h: T,
    q: [SVector<T, N>; D],
}

impl<T: Real, const N: usize, const D: usize> sealed::Sealed for PowerInterpolant<T, N, D> {}

impl<T: Real, const N: usize, const D: usize> Interpolant<T, N> for PowerInterpolant<T, N, D> {
    fn empty() -> Self {
        Self {
            h: T::zero(),
            q: [SVector::zeros(); D],
        }
    }

    #[inline(always)]
    fn eval(&self, ends: &HermiteDense<T, N>, t: T, out: &mut SVector<T, N>) {
        let th = (t - ends.t0) / self.h;
        for i in 0..N {
            let mut acc = T::zero();
            for m in (0..D).rev() {
                acc = (acc + self.q[m][i]) * th;
            }
            out[i] = ends.y0[i] + acc;
        }
    }
}

/// A pair's coefficients as dense constant arrays over its `K` stages (the extension's
/// included) and the `D` powers of its extension, derived at compile time from its
/// [`ExplicitTableau`]: the step's loops then run over constants the compiler unrolls, and
/// the zero entries drop out.
pub(crate) trait Pair<const K: usize, const D: usize> {
    /// The tableau.
    const TABLEAU: ExplicitTableau;
    /// `A`, dense.
    const A: [[f64; K]; K] = dense_rows(Self::TABLEAU.a);
    /// `b̂ − b`, dense.
    const E: [f64; K] = dense_row(Self::TABLEAU.error);
    /// `r_jm`, dense (`R[j][m − 1]`).
    const R: [[f64; D]; K] = dense_poly(Self::TABLEAU.dense);
}

const fn dense_row<const K: usize>(row: &[(usize, f64)]) -> [f64; K] {
    let mut out = [0.0; K];
    let mut n = 0;
    while n < row.len() {
        out[row[n].0] = row[n].1;
        n += 1;
    }
    out
}

const fn dense_rows<const K: usize>(rows: &[&[(usize, f64)]]) -> [[f64; K]; K] {
    let mut out = [[0.0; K]; K];
    let mut i = 0;
    while i < rows.len() {
        out[i] = dense_row(rows[i]);
        i += 1;
    }
    out
}

const fn dense_poly<const K: usize, const D: usize>(rows: &[(usize, &[f64])]) -> [[f64; D]; K] {
    let mut out = [[0.0; D]; K];
    let mut n = 0;
    while n < rows.len() {
        let (j, r) = rows[n];
        let mut m = 0;
        while m < r.len() {
            out[j][m] = r[m];
            m += 1;
        }
        n += 1;
    }
    out
}

/// `y₀ + h·Σ_j a_j k_j` over the first `upto` stages of a constant row.
#[inline(always)]
fn combine<T: Real, const N: usize, const K: usize>(
    y: &SVector<T, N>,
    row: &[f64; K],
    upto: usize,
    k: &[SVector<T, N>; K],
    h: T,
) -> SVector<T, N> {
    let mut acc = SVector::<T, N>::zeros();
    for j in 0..upto {
        if row[j] != 0.0 {
            acc += k[j] * lit::<T>(row[j]);
        }
    }
    y + acc * h
}

/// One accepted step of the pair `P` (`K` = all its stages, `D` = the degree of its
/// extension): the retry loop of [`Core::adapt`](super::Core::adapt) around the trial
/// stages, then the extension's stages and coefficients.
#[inline(always)]
pub(crate) fn advance<T: Real, const N: usize, const K: usize, const D: usize, P, S>(
    parts: StepParts<'_, T, N>,
    dense: &mut MethodDense<T, N, PowerInterpolant<T, N, D>>,
    sys: &S,
    t_limit: T,
) -> Result<(), IntegrateError>
where
    P: Pair<K, D>,
    S: Dynamics<T, N>,
{
    let stages = P::TABLEAU.stages;
    let c = P::TABLEAU.c;
    let StepParts { tol, ctrl, core } = parts;
    core.begin(sys, t_limit)?;
    let (t, y) = (core.t, core.y);
    let h = core.proposed(sys, P::TABLEAU.order, tol, ctrl.opts.h_max, t_limit);
    let last = stages - 1;
    let mut k = [SVector::<T, N>::zeros(); K];
    k[0] = core.f;
    let a = core.adapt(ctrl, t_limit, h, |stats, hs, t_new| {
        for i in 1..last {
            let yt = combine(&y, &P::A[i], i, &k, hs);
            let ti = if c[i] == 1.0 {
                t_new
            } else {
                t + lit::<T>(c[i]) * hs
            };
            let mut out = SVector::zeros();
            sys.rhs(ti, &yt, &mut out);
            k[i] = out;
        }
        let y_new = combine(&y, &P::A[last], last, &k, hs);
        let mut f_new = SVector::zeros();
        sys.rhs(t_new, &y_new, &mut f_new);
        k[last] = f_new;
        stats.rhs_evals += last as u64;
        Ok(Trial::new(y_new, f_new, || {
            let mut e = SVector::<T, N>::zeros();
            for (kj, &w) in k.iter().zip(&P::E) {
                if w != 0.0 {
                    e += kj * lit::<T>(w);
                }
            }
            tol.error_norm(&(e * hs), &y, &y_new)
        }))
    })?;
    let hs = a.hs;
    for i in stages..K {
        let yt = combine(&y, &P::A[i], i, &k, hs);
        let mut out = SVector::zeros();
        sys.rhs(t + lit::<T>(c[i]) * hs, &yt, &mut out);
        k[i] = out;
    }
    core.stats.rhs_evals += (K - stages) as u64;
    let mut q = [SVector::<T, N>::zeros(); D];
    for (kj, rj) in k.iter().zip(&P::R) {
        for (qm, &rm) in q.iter_mut().zip(rj) {
            if rm != 0.0 {
                *qm += kj * lit::<T>(rm);
            }
        }
    }
    // The coefficients are rounded and cancel (up to 10⁵ in magnitude for Vern6): put the
    // rounding left at θ = 1 into the top power, so that the extension ends on `y₁`.
    let mut gap = a.y - y;
    for qm in q.iter_mut() {
        *qm *= hs;
        gap -= *qm;
    }
    q[D - 1] += gap;
    *dense = MethodDense {
        ends: HermiteDense::new(t, a.t_new, y, a.y, k[0], a.f),
        poly: PowerInterpolant { h: hs, q },
    };
    core.accept(&a);
    Ok(())
}
