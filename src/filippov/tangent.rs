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
    /// integration's ([`FilippovError::Run`]).
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
                phi = s * phi;
                seg_start = (tr.t, tr.to, tr.x);
            }
        }
        Ok(Monodromy { matrix: phi, run })
    }
}
