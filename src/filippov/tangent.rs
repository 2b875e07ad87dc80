//! Tangent dynamics through sliding: the monodromy matrix of a Filippov run from the
//! variational equations of each mode and the saltation matrix of each transition.

use nalgebra::{SMatrix, SVector};

use super::error::{FilippovError, Result};
use super::field::{ModeField, rates, with_side};
use super::run::{FilippovRun, FilippovSimulation, TransitionKind};
use super::system::{Filippov, Mode};
use crate::drive::Simulation;
use crate::integrate::{Dopri5, Stepper, Tolerances};
use crate::{Dynamics, Real};

/// The variational equations `ẋ = F(x)`, `Φ̇ = J(x)Φ` of one mode, on the augmented state
/// `z = (x, Φ)` (`Φ` by columns), `M = N + N²`.
struct Variational<'a, Sys, const S: usize, const N: usize> {
    field: ModeField<'a, Sys, S>,
}

impl<T: Real, Sys: Filippov<T, N, S>, const S: usize, const N: usize, const M: usize> Dynamics<T, M>
    for Variational<'_, Sys, S, N>
{
    fn rhs(&self, t: T, z: &SVector<T, M>, dz: &mut SVector<T, M>) {
        let x = SVector::<T, N>::from_fn(|i, _| z[i]);
        let mut f = SVector::<T, N>::zeros();
        self.field.eval(t, &x, &mut f);
        let j = self.field.jacobian(t, &x);
        for i in 0..N {
            dz[i] = f[i];
        }
        for c in 0..N {
            for i in 0..N {
                let mut s = T::zero();
                for k in 0..N {
                    s += j[(i, k)] * z[N + c * N + k];
                }
                dz[N + c * N + i] = s;
            }
        }
    }

    fn time_scale(&self, t: T) -> Option<T> {
        self.field.sys.time_scale(t)
    }
}

/// The saltation matrix of a transition at `(t, x)` on surface `i`, from `from` to `to`:
/// - crossing from side `a` to `b`: `S = I + (F_b − F_a)∇Hᵀ / (∇H·F_a + ∂H/∂t)`;
/// - sliding entry from side `a`: `S = I + (F_s − F_a)∇Hᵀ / (∇H·F_a + ∂H/∂t)`, which maps
///   every perturbation into the surface's tangent space;
/// - sliding exit and grazing: `S = I` (the field is continuous there: at the exit
///   `F_s = F_b`).
pub fn saltation<T, const N: usize, const S: usize, Sys>(
    system: &Sys,
    i: usize,
    kind: TransitionKind,
    from: &Mode<S>,
    to: &Mode<S>,
    t: T,
    x: &SVector<T, N>,
) -> SMatrix<T, N, N>
where
    T: Real,
    Sys: Filippov<T, N, S>,
{
    let id = SMatrix::<T, N, N>::identity();
    match kind {
        TransitionKind::SlidingExit | TransitionKind::Graze => id,
        TransitionKind::Crossing | TransitionKind::SlidingEntry => {
            let r = rates(system, i, &from.sides, t, x);
            let a = from.sides[i];
            let f_a = *r.field(a);
            let den = r.rate(a);
            let f_after = if kind == TransitionKind::Crossing {
                let mut f = SVector::zeros();
                system.field(&with_side(&from.sides, i, to.sides[i]), t, x, &mut f);
                f
            } else {
                r.f_minus + (r.f_plus - r.f_minus) * r.alpha()
            };
            id + (f_after - f_a) * r.grad.transpose() / den
        }
    }
}

/// The monodromy of a Filippov run: `∂x(t₁)/∂x(t₀)`, and the run it follows.
#[derive(Debug, Clone, PartialEq)]
pub struct Monodromy<T: Real, const N: usize, const S: usize> {
    /// `Φ = ∂x(t₁)/∂x(t₀)`.
    pub matrix: SMatrix<T, N, N>,
    /// The run from `t₀` to `t₁`.
    pub run: FilippovRun<T, N, S>,
}

impl<T: Real, const N: usize, const S: usize> Monodromy<T, N, S> {
    /// The eigenvalues of `Φ` (the Floquet multipliers when `t₁ − t₀` is the period of a
    /// periodic orbit through `x(t₀)`), by modulus, largest first.
    pub fn multipliers(&self) -> Vec<nalgebra::Complex<T>> {
        let m = nalgebra::DMatrix::from_fn(N, N, |i, j| self.matrix[(i, j)]);
        let mut ev: Vec<_> = m.complex_eigenvalues().iter().copied().collect();
        ev.sort_by(|a, b| {
            modulus(b)
                .partial_cmp(&modulus(a))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        ev
    }
}

/// `|z|` of a complex number.
fn modulus<T: Real>(z: &nalgebra::Complex<T>) -> T {
    (z.re * z.re + z.im * z.im).sqrt()
}

impl<T: Real, Sys, St> FilippovSimulation<T, Sys, St> {
    /// The monodromy `∂x(t_end)/∂x(t0)` of the run from `(t0, x0)`: the run, then along each
    /// of its modes the variational equations `Φ̇ = J Φ` (`J` the region's Jacobian or the
    /// sliding field's, see the [module docs](super)) integrated by [`Dopri5`] with `tol`
    /// on the augmented state `(x, Φ)` of dimension `M = N + N²`, and the [`saltation`]
    /// matrix of each transition.
    ///
    /// # Errors
    /// [`FilippovError::Dimension`] unless `M == N + N²`; the run's errors; the variational
    /// integration's ([`FilippovError::Run`]); [`FilippovError::GrazingSaltation`] at a
    /// crossing with zero normal rate.
    pub fn monodromy<const N: usize, const S: usize, const M: usize>(
        &mut self,
        t0: T,
        x0: SVector<T, N>,
        t_end: T,
        tol: Tolerances<T, M>,
    ) -> Result<Monodromy<T, N, S>>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        if M != N + N * N {
            return Err(FilippovError::Dimension {
                what: "augmented state of the variational equations (N + N²)",
                expected: N + N * N,
                got: M,
            });
        }
        let run = self.run(t0, x0, t_end, &mut ())?;
        let mut phi = SMatrix::<T, N, N>::identity();
        let mut seg_start = (t0, run.start_mode, run.x);
        seg_start.2 = x0;
        let system = self.system();
        let ends = run
            .transitions
            .iter()
            .map(|tr| (tr.t, Some(tr)))
            .chain(std::iter::once((run.t, None)));
        for (t1, tr) in ends {
            let (ta, mode, xa) = seg_start;
            if t1 > ta {
                let var = Variational {
                    field: ModeField {
                        sys: system,
                        mode,
                        exit_samples: 0,
                    },
                };
                let mut z = SVector::<T, M>::zeros();
                for i in 0..N {
                    z[i] = xa[i];
                    z[N + i * N + i] = T::one();
                }
                let mut sim = Simulation::new(var, Dopri5::new(tol));
                let out = sim.run(ta, z, t1, &mut ())?;
                let seg = SMatrix::<T, N, N>::from_fn(|i, c| out.y[N + c * N + i]);
                phi = seg * phi;
            }
            if let Some(tr) = tr {
                let s = saltation(system, tr.surface, tr.kind, &tr.from, &tr.to, tr.t, &tr.x);
                if !s.iter().all(|v| v.is_finite()) {
                    // A crossing decided by the second-order test (h_a = 0): the saltation
                    // matrix of a grazing is unbounded.
                    return Err(FilippovError::GrazingSaltation {
                        t: crate::scalar::to_f64(tr.t),
                        surface: tr.surface,
                    });
                }
                phi = s * phi;
                seg_start = (tr.t, tr.to, tr.x);
            }
        }
        Ok(Monodromy { matrix: phi, run })
    }
}

/// A periodic orbit of a Filippov system found by shooting
/// ([`FilippovSimulation::find_orbit`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SlidingOrbit<T: Real, const N: usize, const S: usize> {
    /// A point of the orbit (at the start time).
    pub state: SVector<T, N>,
    /// The period.
    pub period: T,
    /// The monodromy over one period from `state`.
    pub monodromy: Monodromy<T, N, S>,
    /// Newton iterations taken.
    pub iterations: usize,
}

impl<T: Real, Sys, St> FilippovSimulation<T, Sys, St> {
    /// A periodic orbit through (near) `x0` at `t0` by Newton's method on the period map,
    /// with the [`monodromy`](Self::monodromy) (variational equations and saltation
    /// matrices through crossings and sliding) as its Jacobian.
    ///
    /// - `autonomous = false`: a forced system of period `period` (fixed);
    ///   `(Φ − I)Δx = −(φ(x) − x)`.
    /// - `autonomous = true`: the period is unknown too (`period` is the guess), and the
    ///   phase is fixed by the section through `x0` normal to the field there:
    ///   `[[Φ − I, F(φ)], [F(x₀)ᵀ, 0]] (Δx, ΔT) = −(φ(x) − x, F(x₀)·(x − x₀))`.
    ///
    /// Converged when the step is within `xtol·(1 + ‖x‖∞)`; at most `max_iter` iterations.
    ///
    /// # Errors
    /// [`FilippovError::NoConvergence`], [`FilippovError::Singular`], a non-finite or
    /// non-positive period ([`FilippovError::Run`] with a parameter error), and the errors
    /// of the runs and of the monodromy.
    #[allow(clippy::too_many_arguments)]
    pub fn find_orbit<const N: usize, const S: usize, const M: usize>(
        &mut self,
        t0: T,
        x0: SVector<T, N>,
        period: T,
        autonomous: bool,
        tol: Tolerances<T, M>,
        xtol: T,
        max_iter: usize,
    ) -> Result<SlidingOrbit<T, N, S>>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        crate::validate::positive("period", period)?;
        crate::validate::positive("xtol", xtol)?;
        let mut x = x0;
        let mut p = period;
        // The section's normal: the field at the start.
        let mode0 = self.mode_at(t0, &x0)?;
        let mut normal = SVector::<T, N>::zeros();
        ModeField {
            sys: self.system(),
            mode: mode0,
            exit_samples: 0,
        }
        .eval(t0, &x0, &mut normal);
        let dim = if autonomous { N + 1 } else { N };
        let (mut residual, mut step) = (T::zero(), T::zero());
        for it in 0..max_iter {
            let mono = self.monodromy(t0, x, t0 + p, tol)?;
            let r = mono.run.x - x;
            residual = r.amax();
            let mut a = nalgebra::DMatrix::<T>::zeros(dim, dim);
            let mut b = nalgebra::DVector::<T>::zeros(dim);
            for i in 0..N {
                for j in 0..N {
                    a[(i, j)] = mono.matrix[(i, j)];
                }
                a[(i, i)] -= T::one();
                b[i] = -r[i];
            }
            if autonomous {
                let mut f_end = SVector::<T, N>::zeros();
                ModeField {
                    sys: self.system(),
                    mode: mono.run.mode,
                    exit_samples: 0,
                }
                .eval(mono.run.t, &mono.run.x, &mut f_end);
                for i in 0..N {
                    a[(i, N)] = f_end[i];
                    a[(N, i)] = normal[i];
                }
                b[N] = -normal.dot(&(x - x0));
            }
            let Some(d) = a.lu().solve(&b) else {
                return Err(FilippovError::Singular { iteration: it });
            };
            step = d.amax();
            for i in 0..N {
                x[i] += d[i];
            }
            if autonomous {
                p += d[N];
                crate::validate::positive("period", p)?;
            }
            if step <= xtol * (T::one() + x.amax()) {
                let monodromy = self.monodromy(t0, x, t0 + p, tol)?;
                return Ok(SlidingOrbit {
                    state: x,
                    period: p,
                    monodromy,
                    iterations: it + 1,
                });
            }
        }
        Err(FilippovError::NoConvergence {
            iterations: max_iter,
            residual: crate::scalar::to_f64(residual),
            step: crate::scalar::to_f64(step),
        })
    }
}

/// Lyapunov exponents through crossings and sliding ([`FilippovSimulation::exponents`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Exponents<T: Real, const N: usize> {
    /// The exponents `λ_j`, largest first (`Σ ln R_jj / time`).
    pub values: SVector<T, N>,
    /// The time they are averaged over.
    pub time: T,
    /// The state at the end.
    pub x: SVector<T, N>,
}

impl<T: Real, Sys, St> FilippovSimulation<T, Sys, St> {
    /// The Lyapunov spectrum from `(t0, x0)` over `intervals` intervals of length `tau`
    /// (after none of transient: start on the attractor): on each interval the
    /// [`monodromy`](Self::monodromy) (variational equations and saltation matrices through
    /// crossings and sliding) multiplies the orthonormal frame `Q`, which a QR factorization
    /// re-orthonormalizes; `λ_j = Σ ln |R_jj| / (intervals·τ)`.
    ///
    /// Sliding collapses the direction normal to the surface (its saltation matrix has a
    /// zero multiplier): that exponent is `−∞` in exact arithmetic; numerically it is the
    /// logarithm of a rounding error over `τ`, not a measured rate.
    ///
    /// # Errors
    /// [`ParameterError`](crate::ParameterError) unless `tau > 0` and `intervals > 0`; the
    /// errors of [`monodromy`](Self::monodromy).
    pub fn exponents<const N: usize, const S: usize, const M: usize>(
        &mut self,
        t0: T,
        x0: SVector<T, N>,
        tau: T,
        intervals: usize,
        tol: Tolerances<T, M>,
    ) -> Result<Exponents<T, N>>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N>,
    {
        crate::validate::positive("tau", tau)?;
        if intervals == 0 {
            return Err(crate::validate::ParameterError::new("intervals", 0.0, "> 0").into());
        }
        let mut q = SMatrix::<T, N, N>::identity();
        let mut sums = SVector::<T, N>::zeros();
        let mut x = x0;
        for k in 0..intervals {
            let ta = t0 + tau * crate::scalar::lit::<T>(k as f64);
            let mono = self.monodromy(ta, x, ta + tau, tol)?;
            let a = mono.matrix * q;
            for j in 0..N {
                // Modified Gram–Schmidt: R_jj is the growth of the j-th direction.
                let mut v = a.column(j).into_owned();
                for i in 0..j {
                    let r = q.column(i).dot(&v);
                    v -= q.column(i) * r;
                }
                let r_jj = v.norm();
                if r_jj > T::zero() {
                    sums[j] += r_jj.ln();
                    q.set_column(j, &(v / r_jj));
                } else {
                    // A collapsed direction (sliding): −∞, and any unit vector orthogonal to
                    // the previous ones continues the frame.
                    sums[j] = T::zero().ln();
                    q.set_column(j, &orthogonal_unit(&q, j));
                }
            }
            x = mono.run.x;
        }
        let time = tau * crate::scalar::lit::<T>(intervals as f64);
        Ok(Exponents {
            values: sums / time,
            time,
            x,
        })
    }
}

/// A unit vector orthogonal to the first `j` columns of `q` (orthonormal): the first of the
/// unit vectors `e_k` with a non-zero remainder, orthogonalized.
fn orthogonal_unit<T: Real, const N: usize>(q: &SMatrix<T, N, N>, j: usize) -> SVector<T, N> {
    let mut best = SVector::<T, N>::zeros();
    let mut best_norm = T::zero();
    for k in 0..N {
        let mut v = SVector::<T, N>::zeros();
        v[k] = T::one();
        for i in 0..j {
            let r = q.column(i).dot(&v);
            v -= q.column(i) * r;
        }
        let n = v.norm();
        if n > best_norm {
            best_norm = n;
            best = v;
        }
    }
    best / best_norm
}
