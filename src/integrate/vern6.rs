//! Verner's "most efficient" 6(5) pair with its 6th-order continuous extension.

// The coefficients are quoted at the precision they were published with.
#![allow(clippy::excessive_precision)]

use super::IntegrateError;
use super::adaptive::{Adaptive, Method, MethodDense, StepParts, sealed};
use super::erk::{self, ExplicitTableau, Pair, PowerInterpolant};
use crate::{Dynamics, Real};

/// Verner's "most efficient" explicit Runge–Kutta pair of order 6 with an embedded order-5
/// error estimate, 9 stages, first same as last (8 evaluations per trial step), and its
/// 6th-order continuous extension (three extra stages, evaluated only when a step is
/// accepted: 11 evaluations per accepted step): the [`Adaptive`] stepper of
/// [`Vern6Method`].
///
/// Nodes `c = (0, 3/50, 1439/15000, 1439/10000, 4973/10000, 389/400, 1999/2000, 1, 1)`, the
/// extension's `1/2, 207/250, 7/25`.
///
/// # Coefficients in double precision
/// The published rationals rounded to the nearest double miss the row sums `c_i = Σ_j a_ij`
/// by up to `3·10⁻¹⁴` (rows with entries up to `2·10²`), which the weights `b₆ ≈ −176`,
/// `b₇ ≈ 172` amplify to a `7·10⁻¹²` defect in the second-order condition `Σ b_i c_i = 1/2`:
/// a global error floor proportional to `h`. The coefficients of stage 0 (column 0 of `A`,
/// of `b̂ − b` and of the extension) are therefore recomputed, in exact arithmetic from the
/// others' doubles, so that every row sums to its node, `Σ b_i = 1`, `Σ (b̂_i − b_i) = 0` and
/// `Σ_j b_j(θ) = θ`; stage 0 enters no other order condition (`c₀ = 0`). They differ from
/// the rounded rationals by at most `7·10⁻¹⁴` (the stages') and `4·10⁻¹²` (the extension's).
///
/// # Rounding of the stage times
/// The nodes `c₆ = 0.9995` and `c₇ = c₈ = 1` carry weights `b₆ ≈ −176`, `b₇ ≈ 172` (and
/// error weights ≈ ±100): the rounding of a stage time `t + c_i h` to the spacing of `t`
/// enters the step as `h·Σ_i b_i ∂_t f·δt_i`, with `(Σ b_i²)^{1/2} ≈ 250` where DOPRI5 has
/// about 1. On a forced system run to large `t` at a tight tolerance this term, and the same
/// noise in the error estimate, can exceed the tolerance (rejected steps accumulate); keep
/// `t` small (restart the clock each period) or use [`Dop853`](super::Dop853) there.
///
/// # References
/// J. H. Verner, *Numerically optimal Runge–Kutta pairs with interpolants*, Numer.
/// Algorithms 53 (2010) 383–396; the coefficients as published on Verner's web page and
/// tabulated in DifferentialEquations.jl's `Vern6`.
pub type Vern6<T, const N: usize> = Adaptive<T, N, Vern6Method>;

/// Dense output of a [`Vern6`] step.
pub type Vern6Dense<T, const N: usize> = MethodDense<T, N, Vern6Interpolant<T, N>>;

/// Verner's 6th-order continuous extension of a [`Vern6`] step (a polynomial of degree 6
/// in `θ` over the step's 9 stages and 3 extra ones).
pub type Vern6Interpolant<T, const N: usize> = PowerInterpolant<T, N, 6>;

/// Verner's 6(5) method (see [`Vern6`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Vern6Method;

impl Vern6Method {
    /// The coefficients (stages 0…8 of the step, 9…11 of the extension).
    pub const TABLEAU: ExplicitTableau = ExplicitTableau {
        order: 6,
        embedded_order: 5,
        dense_order: 6,
        stages: 9,
        c: &[
            0.0,
            0.06,
            0.09593333333333333,
            0.1439,
            0.4973,
            0.9725,
            0.9995,
            1.0,
            1.0,
            0.5,
            0.828,
            0.28,
        ],
        a: &[
            &[],
            &[(0, 0.06)],
            &[(0, 0.019239962962962962), (1, 0.07669337037037037)],
            &[(0, 0.035975), (2, 0.107925)],
            &[
                (0, 1.3186834152331484),
                (2, -5.042058063628562),
                (3, 4.220674648395414),
            ],
            &[
                (0, -41.87259166432753),
                (2, 159.4325621631375),
                (3, -122.11921356501003),
                (4, 5.531743066200054),
            ],
            &[
                (0, -54.430156935316525),
                (2, 207.06725136501848),
                (3, -158.61081378459),
                (4, 6.991816585950242),
                (5, -0.018597231062203234),
            ],
            &[
                (0, -54.663741787281964),
                (2, 207.95280625538936),
                (3, -159.2889574744995),
                (4, 7.018743740796944),
                (5, -0.018338785905045722),
                (6, -0.0005119484997882099),
            ],
            &[
                (0, 0.03438957868355663),
                (3, 0.2582624555633503),
                (4, 0.4209371189673537),
                (5, 4.40539646966931),
                (6, -176.48311902429865),
                (7, 172.36413340141507),
            ],
            &[
                (0, 0.01652415901357279),
                (3, 0.3053128187514179),
                (4, 0.2071200938201979),
                (5, -1.293879140655123),
                (6, 57.11988411588149),
                (7, -55.87979207510932),
                (8, 0.024830028297766014),
            ],
            &[
                (0, 0.0381500818186282),
                (3, 0.2502358252513705),
                (4, 0.3249441447817608),
                (5, 1.8224606658327962),
                (6, -67.7137233269262),
                (7, 66.03587911808127),
                (8, -0.0363881087495127),
                (9, 0.106441599909888),
            ],
            &[
                (0, 0.11178168039672667),
                (3, 0.025757505109345213),
                (4, 3.785140856363646),
                (5, 92.34088993695727),
                (6, -3819.461508432344),
                (7, 3732.492711530704),
                (8, -1.0756940209963033),
                (9, -3.231539970732086),
                (10, -4.7075390854586345),
            ],
        ],
        error: &[
            (0, 0.008623404282193468),
            (3, -0.019434029953152708),
            (4, 0.028450072588037983),
            (5, -2.109711061065291),
            (6, 103.45854289996399),
            (7, -101.39980461914911),
            (8, 0.03333333333333333),
        ],
        dense: &[
            (
                0,
                &[
                    1.0,
                    -7.778593856495589,
                    27.052438572263412,
                    -45.78019011457657,
                    36.72377741043936,
                    -11.183042432949552,
                ],
            ),
            (
                3,
                &[
                    0.0,
                    16.632102138279762,
                    -86.25583404770623,
                    171.7330546182696,
                    -149.67744091315947,
                    47.826380659879696,
                ],
            ),
            (
                4,
                &[
                    0.0,
                    27.10835046149758,
                    -140.58676162962996,
                    279.9044757968917,
                    -243.95644583707966,
                    77.95131832728772,
                ],
            ),
            (
                5,
                &[
                    0.0,
                    283.70753264670356,
                    -1471.3371557366656,
                    2929.3928569314394,
                    -2553.17199842168,
                    815.8141610498723,
                ],
            ),
            (
                6,
                &[
                    0.0,
                    -11365.512865164834,
                    58942.74718938947,
                    -117353.43045697975,
                    102281.77209230464,
                    -32682.059078573824,
                ],
            ),
            (
                7,
                &[
                    0.0,
                    11100.250191051131,
                    -57567.067013355576,
                    114614.48808378985,
                    -99894.591091309,
                    31919.283963225014,
                ],
            ),
            (
                8,
                &[
                    0.0,
                    -3.0022825150732126,
                    14.946122435958785,
                    -27.826954732510288,
                    21.824672217437076,
                    -5.941557405812358,
                ],
            ),
            (
                9,
                &[
                    0.0,
                    -19.610347376201034,
                    93.13370014508226,
                    -165.3493635542416,
                    129.73901617804057,
                    -37.91300539268019,
                ],
            ),
            (
                10,
                &[
                    0.0,
                    -18.23029074639409,
                    96.74593449012313,
                    -199.08634973839895,
                    180.85605899200485,
                    -60.285352997334954,
                ],
            ),
            (
                11,
                &[
                    0.0,
                    -13.563796638614157,
                    90.62137973668116,
                    -204.04515601697273,
                    190.48135937835858,
                    -63.493786459452856,
                ],
            ),
        ],
    };
}

impl sealed::Sealed for Vern6Method {}

impl Pair<12, 6> for Vern6Method {
    const TABLEAU: ExplicitTableau = Self::TABLEAU;
}

impl<T: Real, const N: usize> Method<T, N> for Vern6Method {
    const ORDER: u8 = 6;
    const ERROR_ORDER: f64 = 6.0;
    type Poly = Vern6Interpolant<T, N>;

    fn advance<S: Dynamics<T, N>>(
        parts: StepParts<'_, T, N>,
        dense: &mut Vern6Dense<T, N>,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        erk::advance::<T, N, 12, 6, Self, S>(parts, dense, sys, t_limit)
    }
}
