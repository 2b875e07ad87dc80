//! Tsitouras' 5(4) pair with its free 4th-order continuous extension.

// The coefficients are quoted at the precision they were published with.
#![allow(clippy::excessive_precision)]

use super::IntegrateError;
use super::adaptive::{Adaptive, Method, MethodDense, StepParts, sealed};
use super::erk::{self, ExplicitTableau, Pair, PowerInterpolant};
use crate::{Dynamics, Real};

/// The explicit Runge–Kutta pair of Tsitouras (2011), order 5 with an embedded order-4
/// error estimate, 7 stages, first same as last (6 evaluations per accepted step), and its
/// 4th-order continuous extension, which needs no extra stage: the [`Adaptive`] stepper of
/// [`Tsit5Method`].
///
/// The pair drops all simplifying assumptions but the first column's, and spends the
/// freedom on smaller 6th-order error coefficients than Dormand–Prince 5(4) at the same
/// cost per step. Its nodes are `c = (0, 0.161, 0.327, 0.9, 0.98002554…, 1, 1)`.
///
/// # References
/// Ch. Tsitouras, *Runge–Kutta pairs of order 5(4) satisfying only the first column
/// simplifying assumption*, Comput. Math. Appl. 62 (2011) 770–775 (the coefficients as
/// tabulated in DifferentialEquations.jl's `Tsit5`).
pub type Tsit5<T, const N: usize> = Adaptive<T, N, Tsit5Method>;

/// Dense output of a [`Tsit5`] step.
pub type Tsit5Dense<T, const N: usize> = MethodDense<T, N, Tsit5Interpolant<T, N>>;

/// Tsitouras' free 4th-order continuous extension of a [`Tsit5`] step (a polynomial of
/// degree 4 in `θ`).
pub type Tsit5Interpolant<T, const N: usize> = PowerInterpolant<T, N, 4>;

/// The Tsitouras 5(4) method (see [`Tsit5`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tsit5Method;

impl Tsit5Method {
    /// The coefficients (stages 0…6; no extra stage for the extension).
    pub const TABLEAU: ExplicitTableau = ExplicitTableau {
        order: 5,
        embedded_order: 4,
        dense_order: 4,
        stages: 7,
        c: &[0.0, 0.161, 0.327, 0.9, 0.9800255409045097, 1.0, 1.0],
        a: &[
            &[],
            &[(0, 0.161)],
            &[(0, -0.008480655492356989), (1, 0.335480655492357)],
            &[
                (0, 2.8971530571054935),
                (1, -6.359448489975075),
                (2, 4.3622954328695815),
            ],
            &[
                (0, 5.325864828439257),
                (1, -11.748883564062828),
                (2, 7.4955393428898365),
                (3, -0.09249506636175525),
            ],
            &[
                (0, 5.86145544294642),
                (1, -12.92096931784711),
                (2, 8.159367898576159),
                (3, -0.071584973281401),
                (4, -0.028269050394068383),
            ],
            &[
                (0, 0.09646076681806523),
                (1, 0.01),
                (2, 0.4798896504144996),
                (3, 1.379008574103742),
                (4, -3.290069515436081),
                (5, 2.324710524099774),
            ],
        ],
        error: &[
            (0, -0.00178001105222577714),
            (1, -0.0008164344596567469),
            (2, 0.007880878010261995),
            (3, -0.1447110071732629),
            (4, 0.5823571654525552),
            (5, -0.45808210592918697),
            (6, 1.0 / 66.0),
        ],
        dense: &[
            (
                0,
                &[
                    1.0,
                    -2.763706197274826,
                    2.9132554618219126,
                    -1.0530884977290216,
                ],
            ),
            (1, &[0.0, 0.13169999999999998, -0.2234, 0.1017]),
            (
                2,
                &[
                    0.0,
                    3.9302962368947516,
                    -5.941033872131505,
                    2.490627285651253,
                ],
            ),
            (
                3,
                &[
                    0.0,
                    -12.411077166933676,
                    30.33818863028232,
                    -16.548102889244902,
                ],
            ),
            (
                4,
                &[0.0, 37.50931341651104, -88.1789048947664, 47.37952196281928],
            ),
            (
                5,
                &[
                    0.0,
                    -27.896526289197286,
                    65.09189467479366,
                    -34.87065786149661,
                ],
            ),
            (6, &[0.0, 1.5, -4.0, 2.5]),
        ],
    };
}

impl sealed::Sealed for Tsit5Method {}

impl Pair<7, 4> for Tsit5Method {
    const TABLEAU: ExplicitTableau = Self::TABLEAU;
}

impl<T: Real, const N: usize> Method<T, N> for Tsit5Method {
    const ORDER: u8 = 5;
    const ERROR_ORDER: f64 = 5.0;
    type Poly = Tsit5Interpolant<T, N>;

    fn advance<S: Dynamics<T, N>>(
        parts: StepParts<'_, T, N>,
        dense: &mut Tsit5Dense<T, N>,
        sys: &S,
        t_limit: T,
    ) -> Result<(), IntegrateError> {
        erk::advance::<T, N, 7, 4, Self, S>(parts, dense, sys, t_limit)
    }
}
