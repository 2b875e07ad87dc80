//! Augmented sizes computed by the type system (see [`Dims`]).
use nalgebra::{Const, DimAdd, DimMul, DimProd};

/// The state size `N` as a type, for the bounds [`PairDimension`] and [`TangentDimension`].
///
/// Augmented sizes computed by the type system: `M = 2N` for two trajectories in one
/// state, `M = N + N·K` for a state with `K` tangent vectors.
///
/// Stable Rust cannot write `SVector<T, { 2 * N }>` (that needs `generic_const_exprs`). What
/// it can do is resolve an associated type: nalgebra's type-level arithmetic
/// ([`DimAdd`], [`DimMul`] on [`Const`]) maps `Const<2>` + `Const<2>` to `Const<4>`, and a
/// bound `Dims<N>: PairDimension<M>` whose only implementation requires
/// `Const<N> + Const<N> = Const<M>` lets the compiler *infer* `M` from `N` — and reject a
/// wrong `M` at compile time ("expected `4`, found `5`"). The constructors that take the
/// system's [`Tolerances<T, N>`](crate::integrate::Tolerances)
/// ([`TwoTrajectory::from_tolerances`](super::TwoTrajectory::from_tolerances),
/// [`TangentSpace::from_tolerances`](super::TangentSpace::from_tolerances),
/// [`HybridTangentSpace::from_tolerances`](super::HybridTangentSpace::from_tolerances),
/// and for `K < N` [`TangentSpace::with_tolerances`](super::TangentSpace::with_tolerances)
/// with `K` written) and
/// the helpers [`pair_tolerances`](super::pair_tolerances) and
/// [`tangent_tolerances`](super::tangent_tolerances) carry these bounds, so a user never
/// writes `M`.
///
/// ```
/// use nonsmooth::integrate::Tolerances;
/// use nonsmooth::lyapunov::{pair_tolerances, tangent_tolerances};
/// let tol = Tolerances::per_component(1e-9, [1e-12, 1e-10])?;
/// let pair = pair_tolerances(&tol)?; // M = 4, inferred
/// let tangent = tangent_tolerances::<_, 2, 2, _>(&tol, 1e-9, 1e-9)?; // M = 6, inferred
/// assert_eq!((pair.atol.len(), tangent.atol.len()), (4, 6));
/// # Ok::<(), nonsmooth::Error>(())
/// ```
/// A wrong `M` is a compile error, not a run-time one:
/// ```compile_fail
/// use nonsmooth::integrate::Tolerances;
/// use nonsmooth::lyapunov::pair_tolerances;
/// let tol = Tolerances::per_component(1e-9, [1e-12, 1e-10])?;
/// let pair = pair_tolerances::<f64, 2, 5>(&tol)?; // Dims<2>: PairDimension<5> does not hold
/// # Ok::<(), nonsmooth::Error>(())
/// ```
///
/// # Limits
/// nalgebra's conversions between `Const<n>` and type-level integers cover `n ≤ 127`: every
/// operand and result must be in range, i.e. `N ≤ 63` for a pair, `N + N·K ≤ 127` with
/// tangent vectors (`N ≤ 10` for the full spectrum). Larger systems use the constructors
/// with an explicit stepper (`new`), which check `M` when called.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Dims<const N: usize>;

/// `Dims<N>: PairDimension<M>` holds exactly when `M = 2N` (with `2N ≤ 127`); as a bound it
/// lets the compiler infer `M` from `N`.
#[diagnostic::on_unimplemented(
    message = "two trajectories of dimension N need the augmented dimension M = 2N",
    label = "M must be twice N (and at most 127)"
)]
pub trait PairDimension<const M: usize> {}

impl<const N: usize, const M: usize> PairDimension<M> for Dims<N> where
    Const<N>: DimAdd<Const<N>, Output = Const<M>>
{
}

/// `Dims<N>: TangentDimension<K, M>` holds exactly when `M = N + N·K` (with every size
/// `≤ 127`); as a bound it lets the compiler infer `M` from `N` and `K`.
#[diagnostic::on_unimplemented(
    message = "a state of dimension N with K tangent vectors needs the augmented dimension M = N + N·K",
    label = "M must be N + N·K (and at most 127)"
)]
pub trait TangentDimension<const K: usize, const M: usize> {}

impl<const N: usize, const K: usize, const M: usize> TangentDimension<K, M> for Dims<N>
where
    Const<N>: DimMul<Const<K>>,
    Const<N>: DimAdd<DimProd<Const<N>, Const<K>>, Output = Const<M>>,
{
}
