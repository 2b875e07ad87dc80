//! DOP853: Dormand–Prince 8(5,3) with 7th-order dense output (Hairer's coefficients).

// The coefficients are quoted at the precision they were published with.
#![allow(clippy::excessive_precision)]

use nalgebra::SVector;

use super::{
    Controller, Core, DenseOutput, HermiteDense, IntegrateError, Stats, StepOptions, Stepper,
    Tolerances, adaptive_checks, adaptive_constructors, all_finite, clamp_to_limit, core_accessors,
    dense_endpoints, step_too_small,
};
use crate::scalar::{lit, to_f64};
use crate::{Dynamics, Real};

const C: [f64; 16] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
];

/// The nonzero entries `(j, a_ij)` of each row `i` of the extended Butcher matrix (row 12
/// holds the weights `b`, rows 13–15 the extra stages of the dense output).
const A: [&[(usize, f64)]; 16] = [
    &[],
    &[(0, 5.26001519587677318785587544488e-2)],
    &[
        (0, 1.97250569845378994544595329183e-2),
        (1, 5.91751709536136983633785987549e-2),
    ],
    &[
        (0, 2.95875854768068491816892993775e-2),
        (2, 8.87627564304205475450678981324e-2),
    ],
    &[
        (0, 2.41365134159266685502369798665e-1),
        (2, -8.84549479328286085344864962717e-1),
        (3, 9.24834003261792003115737966543e-1),
    ],
    &[
        (0, 3.7037037037037037037037037037e-2),
        (3, 1.70828608729473871279604482173e-1),
        (4, 1.25467687566822425016691814123e-1),
    ],
    &[
        (0, 3.7109375e-2),
        (3, 1.70252211019544039314978060272e-1),
        (4, 6.02165389804559606850219397283e-2),
        (5, -1.7578125e-2),
    ],
    &[
        (0, 3.70920001185047927108779319836e-2),
        (3, 1.70383925712239993810214054705e-1),
        (4, 1.07262030446373284651809199168e-1),
        (5, -1.53194377486244017527936158236e-2),
        (6, 8.27378916381402288758473766002e-3),
    ],
    &[
        (0, 6.24110958716075717114429577812e-1),
        (3, -3.36089262944694129406857109825),
        (4, -8.68219346841726006818189891453e-1),
        (5, 2.75920996994467083049415600797e1),
        (6, 2.01540675504778934086186788979e1),
        (7, -4.34898841810699588477366255144e1),
    ],
    &[
        (0, 4.77662536438264365890433908527e-1),
        (3, -2.48811461997166764192642586468),
        (4, -5.90290826836842996371446475743e-1),
        (5, 2.12300514481811942347288949897e1),
        (6, 1.52792336328824235832596922938e1),
        (7, -3.32882109689848629194453265587e1),
        (8, -2.03312017085086261358222928593e-2),
    ],
    &[
        (0, -9.3714243008598732571704021658e-1),
        (3, 5.18637242884406370830023853209),
        (4, 1.09143734899672957818500254654),
        (5, -8.14978701074692612513997267357),
        (6, -1.85200656599969598641566180701e1),
        (7, 2.27394870993505042818970056734e1),
        (8, 2.49360555267965238987089396762),
        (9, -3.0467644718982195003823669022),
    ],
    &[
        (0, 2.27331014751653820792359768449),
        (3, -1.05344954667372501984066689879e1),
        (4, -2.00087205822486249909675718444),
        (5, -1.79589318631187989172765950534e1),
        (6, 2.79488845294199600508499808837e1),
        (7, -2.85899827713502369474065508674),
        (8, -8.87285693353062954433549289258),
        (9, 1.23605671757943030647266201528e1),
        (10, 6.43392746015763530355970484046e-1),
    ],
    &[
        (0, 5.42937341165687622380535766363e-2),
        (5, 4.45031289275240888144113950566),
        (6, 1.89151789931450038304281599044),
        (7, -5.8012039600105847814672114227),
        (8, 3.1116436695781989440891606237e-1),
        (9, -1.52160949662516078556178806805e-1),
        (10, 2.01365400804030348374776537501e-1),
        (11, 4.47106157277725905176885569043e-2),
    ],
    &[
        (0, 5.61675022830479523392909219681e-2),
        (6, 2.53500210216624811088794765333e-1),
        (7, -2.46239037470802489917441475441e-1),
        (8, -1.24191423263816360469010140626e-1),
        (9, 1.5329179827876569731206322685e-1),
        (10, 8.20105229563468988491666602057e-3),
        (11, 7.56789766054569976138603589584e-3),
        (12, -8.298e-3),
    ],
    &[
        (0, 3.18346481635021405060768473261e-2),
        (5, 2.83009096723667755288322961402e-2),
        (6, 5.35419883074385676223797384372e-2),
        (7, -5.49237485713909884646569340306e-2),
        (10, -1.08347328697249322858509316994e-4),
        (11, 3.82571090835658412954920192323e-4),
        (12, -3.40465008687404560802977114492e-4),
        (13, 1.41312443674632500278074618366e-1),
    ],
    &[
        (0, -4.28896301583791923408573538692e-1),
        (5, -4.69762141536116384314449447206),
        (6, 7.68342119606259904184240953878),
        (7, 4.06898981839711007970213554331),
        (8, 3.56727187455281109270669543021e-1),
        (12, -1.39902416515901462129418009734e-3),
        (13, 2.9475147891527723389556272149),
        (14, -9.15095847217987001081870187138),
    ],
];

/// `b − b̂` of the embedded 3rd-order estimate: nonzero at stages 1, 9 and 12 beyond `b`.
const BHH: [(usize, f64); 3] = [
    (0, 0.244094488188976377952755905512),
    (8, 0.733846688281611857341361741547),
    (11, 0.220588235294117647058823529412e-1),
];

/// Weights of the embedded 5th-order error estimate.
const E5: [(usize, f64); 8] = [
    (0, 0.1312004499419488073250102996e-1),
    (5, -0.1225156446376204440720569753e1),
    (6, -0.4957589496572501915214079952),
    (7, 0.1664377182454986536961530415e1),
    (8, -0.3503288487499736816886487290),
    (9, 0.3341791187130174790297318841),
    (10, 0.8192320648511571246570742613e-1),
    (11, -0.2235530786388629525884427845e-1),
];

/// Dense-output coefficients `d_{4..7, j}` (stages 0, 5..=15).
const D: [[f64; 16]; 4] = [
    [
        -0.84289382761090128651353491142e1,
        0.0,
        0.0,
        0.0,
        0.0,
        0.56671495351937776962531783590,
        -0.30689499459498916912797304727e1,
        0.23846676565120698287728149680e1,
        0.21170345824450282767155149946e1,
        -0.87139158377797299206789907490,
        0.22404374302607882758541771650e1,
        0.63157877876946881815570249290,
        -0.88990336451333310820698117400e-1,
        0.18148505520854727256656404962e2,
        -0.91946323924783554000451984436e1,
        -0.44360363875948939664310572000e1,
    ],
    [
        0.10427508642579134603413151009e2,
        0.0,
        0.0,
        0.0,
        0.0,
        0.24228349177525818288430175319e3,
        0.16520045171727028198505394887e3,
        -0.37454675472269020279518312152e3,
        -0.22113666853125306036270938578e2,
        0.77334326684722638389603898808e1,
        -0.30674084731089398182061213626e2,
        -0.93321305264302278729567221706e1,
        0.15697238121770843886131091075e2,
        -0.31139403219565177677282850411e2,
        -0.93529243588444783865713862664e1,
        0.35816841486394083752465898540e2,
    ],
    [
        0.19985053242002433820987653617e2,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.38703730874935176555105901742e3,
        -0.18917813819516756882830838328e3,
        0.52780815920542364900561016686e3,
        -0.11573902539959630126141871134e2,
        0.68812326946963000169666922661e1,
        -0.10006050966910838403183860980e1,
        0.77771377980534432092869265740,
        -0.27782057523535084065932004339e1,
        -0.60196695231264120758267380846e2,
        0.84320405506677161018159903784e2,
        0.11992291136182789328035130030e2,
    ],
    [
        -0.25693933462703749003312586129e2,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.15418974869023643374053993627e3,
        -0.23152937917604549567536039109e3,
        0.35763911791061412378285349910e3,
        0.93405324183624310003907691704e2,
        -0.37458323136451633156875139351e2,
        0.10409964950896230045147246184e3,
        0.29840293426660503123344363579e2,
        -0.43533456590011143754432175058e2,
        0.96324553959188282948394950600e2,
        -0.39177261675615439165231486172e2,
        -0.14972683625798562581422125276e3,
    ],
];

/// The explicit Runge–Kutta method DOP853 of Dormand and Prince (order 8, error estimated
/// by combined 5th- and 3rd-order embedded formulas, 12 stages, FSAL) with its 7th-order
/// dense output (three extra stages, computed only when a step is accepted).
///
/// # References
/// E. Hairer, S. P. Nørsett, G. Wanner, *Solving ODEs I*, Sect. II.10 (DOP853).
#[derive(Debug, Clone)]
pub struct Dop853<T: Real, const N: usize> {
    tol: Tolerances<T, N>,
    ctrl: Controller<T>,
    core: Core<T, N>,
    dense: Dop853Dense<T, N>,
}

/// Dense output of a [`Dop853`] step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dop853Dense<T: Real, const N: usize> {
    ends: HermiteDense<T, N>,
    h: T,
    r: [SVector<T, N>; 7],
}

impl<T: Real, const N: usize> DenseOutput<T, N> for Dop853Dense<T, N> {
    dense_endpoints!();

    #[inline(always)]
    fn interpolate_unchecked(&self, t: T, out: &mut SVector<T, N>) {
        let (t0, y0) = (self.ends.t0, &self.ends.y0);
        let s = (t - t0) / self.h;
        let s1 = T::one() - s;
        let r = &self.r;
        for i in 0..N {
            let conpar = r[3][i] + s * (r[4][i] + s1 * (r[5][i] + s * r[6][i]));
            out[i] = y0[i] + s * (r[0][i] + s1 * (r[1][i] + s * (r[2][i] + s1 * conpar)));
        }
    }
}

impl<T: Real, const N: usize> Dop853Dense<T, N> {
    fn empty() -> Self {
        Self {
            ends: HermiteDense::zeros(),
            h: T::zero(),
            r: [SVector::zeros(); 7],
        }
    }
}

adaptive_constructors!(Dop853, Dop853Dense, 8.0);

impl<T: Real, const N: usize> Dop853<T, N> {
    #[inline(always)]
    fn stage<S: Dynamics<T, N>>(
        sys: &S,
        t: T,
        y: &SVector<T, N>,
        h: T,
        k: &mut [SVector<T, N>; 16],
        i: usize,
    ) {
        let mut acc = SVector::<T, N>::zeros();
        for &(j, a) in A[i] {
            acc += k[j] * lit::<T>(a);
        }
        let yt = y + acc * h;
        let mut out = SVector::zeros();
        sys.rhs(t + lit::<T>(C[i]) * h, &yt, &mut out);
        k[i] = out;
    }
}

impl<T: Real, const N: usize> Stepper<T, N> for Dop853<T, N> {
    type Dense = Dop853Dense<T, N>;

    core_accessors!();
    adaptive_checks!();

    fn step<S: Dynamics<T, N>>(&mut self, sys: &S, t_limit: T) -> Result<(), IntegrateError> {
        self.core.begin(sys, t_limit)?;
        let (t, y) = (self.core.t, self.core.y);
        let mut h = self
            .core
            .proposed(sys, 8, &self.tol, self.ctrl.opts.h_max, t_limit);
        let mut k = [SVector::<T, N>::zeros(); 16];
        k[0] = self.core.f;
        let mut nonfinite = 0u32;
        loop {
            let (hs, lands) = clamp_to_limit(t, h, t_limit);
            if step_too_small(t, hs, self.ctrl.opts.h_min) && !lands {
                return Err(IntegrateError::StepSizeTooSmall {
                    t: to_f64(t),
                    h: to_f64(hs),
                });
            }
            for i in 1..12 {
                Self::stage(sys, t, &y, hs, &mut k, i);
            }
            let mut inc = SVector::<T, N>::zeros();
            for &(j, a) in A[12] {
                inc += k[j] * lit::<T>(a);
            }
            let y_new = y + inc * hs;
            let t_new = if lands { t_limit } else { t + hs };
            let mut f_new = SVector::zeros();
            sys.rhs(t_new, &y_new, &mut f_new);
            self.core.stats.rhs_evals += 12;
            let err = if all_finite(&y_new) && all_finite(&f_new) {
                let mut e3 = inc;
                for &(j, b) in &BHH {
                    e3 -= k[j] * lit::<T>(b);
                }
                let mut e5 = SVector::<T, N>::zeros();
                for &(j, e) in &E5 {
                    e5 += k[j] * lit::<T>(e);
                }
                let (mut s5, mut s3) = (T::zero(), T::zero());
                for i in 0..N {
                    let sk = self.tol.atol[i] + self.tol.rtol[i] * y[i].abs().max(y_new[i].abs());
                    s3 += (e3[i] / sk) * (e3[i] / sk);
                    s5 += (e5[i] / sk) * (e5[i] / sk);
                }
                let mut deno = s5 + lit::<T>(0.01) * s3;
                if deno <= T::zero() {
                    deno = T::one();
                }
                hs.abs() * s5 * (T::one() / (lit::<T>(N as f64) * deno)).sqrt()
            } else {
                nonfinite += 1;
                if nonfinite > 20 {
                    return Err(IntegrateError::NonFiniteRhs { t: to_f64(t) });
                }
                crate::scalar::nan()
            };
            let (accept, h_next) = self.ctrl.propose(err, hs);
            if accept {
                k[12] = f_new;
                for i in 13..16 {
                    Self::stage(sys, t, &y, hs, &mut k, i);
                }
                self.core.stats.rhs_evals += 3;
                let ydiff = y_new - y;
                let bspl = k[0] * hs - ydiff;
                let mut r = [SVector::<T, N>::zeros(); 7];
                r[0] = ydiff;
                r[1] = bspl;
                r[2] = ydiff - f_new * hs - bspl;
                for (m, drow) in D.iter().enumerate() {
                    let mut acc = SVector::<T, N>::zeros();
                    for (j, &d) in drow.iter().enumerate() {
                        if d != 0.0 {
                            acc += k[j] * lit::<T>(d);
                        }
                    }
                    r[3 + m] = acc * hs;
                }
                self.dense = Dop853Dense {
                    ends: HermiteDense::new(t, t_new, y, y_new, k[0], f_new),
                    h: hs,
                    r,
                };
                self.core.accept(t_new, y_new, f_new, h_next, lands, h);
                return Ok(());
            }
            self.core.stats.rejected += 1;
            h = h_next;
        }
    }

    fn order(&self) -> u8 {
        8
    }
}
