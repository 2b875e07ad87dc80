//! Branches of periodic orbits of forced Filippov systems in a parameter, with the sliding
//! bifurcations on them located as zeros of test functions.
//!
//! # Method
//! At each parameter value `p_k = p₀ + k·Δp` of a grid (from the index, never accumulated)
//! the orbit of the forcing period `T(p)` is found by shooting through crossings and
//! sliding ([`FilippovSimulation::find_orbit`]: Newton on the period map with the
//! monodromy of the variational equations and saltation matrices), seeded by the secant
//! extrapolation of the two previous orbits. Its Floquet multipliers are the eigenvalues of
//! that monodromy (a sliding segment contributes a multiplier 0).
//!
//! # Test functions
//! Along one period of the orbit, for the switching surface `H = H_i` given in the
//! settings, with `h± = ∇H·F± + ∂_t H` the normal rates of the two fields:
//! - **grazing-sliding** (an orbit off the surface touches it tangentially at a point of
//!   the sliding region, and a sliding segment is born):
//!   $$ g_{\mathrm{gs}} = \begin{cases} \min_t\, s\,H(t, x(t)) & \text{no sliding on } H = 0,\\ -\,t_{\mathrm{slide}} & \text{sliding for a total time } t_{\mathrm{slide}}, \end{cases} $$
//!   `s = ±1` the side of the orbit (the closest approach, located on the dense output by
//!   [`Approach`]); positive while the orbit stays off the surface, zero where it grazes,
//!   negative once it slides. (An orbit that crosses the surface has approach 0: this test
//!   is for orbits that, without sliding, do not reach the surface.)
//! - **crossing-sliding** (a crossing point of the orbit reaches the boundary of the
//!   sliding region, where the far field is tangent, and the crossing turns into a short
//!   sliding segment): over the orbit's arrivals at the surface from a region (crossings
//!   and sliding entries, arriving from side `a` with `h_a ≠ 0`), the far-side rate signed
//!   so that a crossing is positive,
//!   $$ g_{\mathrm{cs}} = -\operatorname{sgn}(a)\, h_{\bar a}\quad\text{at the arrival with the smallest } |h_{\bar a}| , $$
//!   positive for a crossing, negative for a sliding entry, zero where the arrival point is
//!   on the boundary `h_ā = 0` of the sliding region. The field on the far side is
//!   continuous there, so the arrival point, and `g_cs`, move continuously through the
//!   bifurcation.
//!
//! A sign change of a test between two grid points is located by the Illinois method in
//! `p` (each trial a shooting from the interpolated state) to the settings' tolerance, and
//! reported if the test's value there is below `10⁻³` of its values at the two grid points
//! (a sign change by a jump — `g_cs` moving from one arrival to another — is not a
//! bifurcation).
//!
//! # References
//! M. di Bernardo, C. J. Budd, A. R. Champneys, P. Kowalczyk, *Piecewise-smooth Dynamical
//! Systems*, Springer 2008, §8.5 (the four sliding bifurcations); F. Dercole, Yu. A.
//! Kuznetsov, *SlideCont: an Auto97 driver for bifurcation analysis of Filippov systems*,
//! ACM TOMS 31(1), 2005 (their test functions); M. di Bernardo, P. Kowalczyk, A. Nordmark,
//! *Sliding bifurcations: a novel mechanism for the sudden onset of chaos in dry friction
//! oscillators*, IJBC 13(10), 2003.

use nalgebra::{Complex, SVector};

use super::{BranchEnd, OrbitError, Result};
use crate::filippov::{
    Approach, Filippov, FilippovSimulation, SlidingOrbit, Transition, TransitionKind,
};
use crate::integrate::{Stepper, Tolerances};

/// Settings of [`follow_sliding`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlidingContinuation {
    lo: f64,
    hi: f64,
    step: f64,
    surface: usize,
    locate_tolerance: f64,
    xtol: f64,
    max_iterations: usize,
    max_points: usize,
}

impl SlidingContinuation {
    /// Follow the branch over the grid `p₀ + kΔp` (`step = Δp`, either sign) while `p` stays
    /// in `[lo, hi]` (at most 10⁴ points), testing surface `surface`; sign changes located
    /// to `10⁻⁹·max(1, |lo|, |hi|)` in `p`; shooting to `xtol = 10⁻¹¹` in at most 30 Newton
    /// iterations.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless `lo < hi` are finite and `step` is finite and
    /// non-zero.
    pub fn new(lo: f64, hi: f64, step: f64, surface: usize) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(invalid(
                "the parameter range [lo, hi]",
                "finite, lo < hi",
                hi,
            ));
        }
        if !(step.is_finite() && step != 0.0) {
            return Err(invalid("the parameter step", "finite and non-zero", step));
        }
        Ok(Self {
            lo,
            hi,
            step,
            surface,
            locate_tolerance: 1e-9 * lo.abs().max(hi.abs()).max(1.0),
            xtol: 1e-11,
            max_iterations: 30,
            max_points: 10_000,
        })
    }

    /// The most points of a branch (default 10⁴).
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] if `points < 2`.
    pub fn with_max_points(mut self, points: usize) -> Result<Self> {
        if points < 2 {
            return Err(invalid(
                "the number of branch points",
                ">= 2",
                points as f64,
            ));
        }
        self.max_points = points;
        Ok(self)
    }

    /// The tolerance in `p` to which a sliding bifurcation is located.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless it is finite and > 0.
    pub fn with_locate_tolerance(mut self, tolerance: f64) -> Result<Self> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(invalid("the locate tolerance", "finite and > 0", tolerance));
        }
        self.locate_tolerance = tolerance;
        Ok(self)
    }

    /// The shooting's convergence tolerance (see [`FilippovSimulation::find_orbit`]) and its
    /// iteration cap.
    ///
    /// # Errors
    /// [`OrbitError::InvalidSetting`] unless `xtol` is finite and > 0 and `iterations > 0`.
    pub fn with_shooting(mut self, xtol: f64, iterations: usize) -> Result<Self> {
        if !(xtol.is_finite() && xtol > 0.0) {
            return Err(invalid("the shooting tolerance", "finite and > 0", xtol));
        }
        if iterations == 0 {
            return Err(invalid("the shooting iterations", "> 0", 0.0));
        }
        self.xtol = xtol;
        self.max_iterations = iterations;
        Ok(self)
    }
}

fn invalid(what: &'static str, requirement: &'static str, value: f64) -> OrbitError {
    OrbitError::InvalidSetting {
        what,
        requirement,
        value,
    }
}

/// The sliding test functions of one orbit (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlidingTests {
    /// `g_gs`: the closest approach to the surface, or minus the time spent sliding on it.
    pub grazing_sliding: f64,
    /// `g_cs`: the signed far-side rate at the arrival nearest to the boundary of the
    /// sliding region; `None` if the orbit never arrives at the surface from a region.
    pub crossing_sliding: Option<f64>,
    /// The number of sliding segments on the surface over one period.
    pub sliding_segments: usize,
    /// The time spent sliding on the surface over one period.
    pub sliding_time: f64,
}

/// A point of a [`SlidingBranch`].
#[derive(Debug, Clone, PartialEq)]
pub struct SlidingBranchPoint<const N: usize> {
    /// The parameter.
    pub p: f64,
    /// The orbit's state at the section time.
    pub state: SVector<f64, N>,
    /// The Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// The test functions.
    pub tests: SlidingTests,
}

/// The kind of a sliding bifurcation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SlidingBifurcationKind {
    /// An orbit off the surface grazes it in the sliding region (`g_gs = 0`).
    GrazingSliding,
    /// A crossing point reaches the boundary of the sliding region (`g_cs = 0`).
    CrossingSliding,
}

/// A sliding bifurcation located on a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct SlidingBifurcation<const N: usize> {
    /// Which one.
    pub kind: SlidingBifurcationKind,
    /// The parameter where its test function vanishes.
    pub p: f64,
    /// The orbit there.
    pub state: SVector<f64, N>,
    /// The test function's value at `p` (zero up to the location tolerance).
    pub value: f64,
    /// The bracket `(p_a, p_b)` of the last iteration.
    pub bracket: (f64, f64),
}

/// A followed branch of orbits with sliding segments.
#[derive(Debug, Clone, PartialEq)]
pub struct SlidingBranch<const N: usize> {
    /// The points, in order of the grid.
    pub points: Vec<SlidingBranchPoint<N>>,
    /// The located sliding bifurcations, in order of the grid.
    pub bifurcations: Vec<SlidingBifurcation<N>>,
    /// Why it ended ([`BranchEnd::StepTooSmall`] if the shooting failed at the next grid
    /// point; the `p` is the last one on the branch).
    pub end: BranchEnd,
}

/// The orbit at one parameter value with its tests.
struct Evaluated<const N: usize> {
    point: SlidingBranchPoint<N>,
}

/// Evaluates the sliding tests of an orbit of `sim` on surface `i` over one period from
/// `(t0, x0)`.
///
/// # Errors
/// The errors of the run ([`OrbitError::Filippov`], [`OrbitError::Run`]).
pub fn sliding_tests<Sys, St, const N: usize, const S: usize>(
    sim: &mut FilippovSimulation<f64, Sys, St>,
    surface: usize,
    t0: f64,
    x0: SVector<f64, N>,
    period: f64,
) -> Result<SlidingTests>
where
    Sys: Filippov<f64, N, S> + Clone,
    St: Stepper<f64, N>,
{
    let system = sim.system().clone();
    let mut approach = Approach::new(&system, surface, t0, 8);
    let run = sim.run(t0, x0, t0 + period, &mut approach)?;
    Ok(tests_of_run(
        &system,
        surface,
        &run.transitions,
        run.start_mode.sliding == Some(surface),
        (t0, run.t),
        approach.closest.map(|c| c.0),
    ))
}

/// The tests from a run's transitions and the closest approach of its region steps.
fn tests_of_run<Sys, const N: usize, const S: usize>(
    system: &Sys,
    surface: usize,
    transitions: &[Transition<f64, N, S>],
    starts_sliding: bool,
    (t0, t1): (f64, f64),
    closest: Option<f64>,
) -> SlidingTests
where
    Sys: Filippov<f64, N, S>,
{
    // Sliding time and segments on the surface.
    let mut sliding_time = 0.0;
    let mut segments = 0usize;
    let mut since = if starts_sliding { Some(t0) } else { None };
    let mut crossing: Option<f64> = None;
    for tr in transitions.iter().filter(|tr| tr.surface == surface) {
        let slides_after = tr.to.sliding == Some(surface);
        let slid_before = tr.from.sliding == Some(surface);
        if slides_after && !slid_before {
            since = Some(tr.t);
            segments += 1;
        }
        if slid_before
            && !slides_after
            && let Some(s) = since.take()
        {
            sliding_time += tr.t - s;
        }
        let arrival = tr.from.sliding.is_none()
            && matches!(
                tr.kind,
                TransitionKind::Crossing | TransitionKind::SlidingEntry
            );
        if arrival {
            let a = tr.from.sides[surface];
            let mut far = tr.from.sides;
            far[surface] = a.flip();
            let mut f = SVector::zeros();
            system.field(&far, tr.t, &tr.x, &mut f);
            let h = system.gradient(surface, tr.t, &tr.x).dot(&f)
                + system.surface_time_rate(surface, tr.t, &tr.x);
            let c = -a.sign::<f64>() * h;
            if c.is_finite() && crossing.is_none_or(|best| c.abs() < best.abs()) {
                crossing = Some(c);
            }
        }
    }
    if let Some(s) = since {
        if starts_sliding && segments == 0 {
            segments = 1;
        }
        sliding_time += t1 - s;
    }
    let grazing_sliding = if sliding_time > 0.0 || segments > 0 {
        -sliding_time
    } else {
        closest.unwrap_or(f64::INFINITY)
    };
    SlidingTests {
        grazing_sliding,
        crossing_sliding: crossing,
        sliding_segments: segments,
        sliding_time,
    }
}

/// A located zero: the point, the test's value there and the final bracket.
type Located<const N: usize> = (SlidingBranchPoint<N>, f64, (f64, f64));

/// The problem of a branch: the builder, the period, the section and the settings.
struct Problem<'a, B, P> {
    build: &'a B,
    period: &'a P,
    t0: f64,
    settings: &'a SlidingContinuation,
}

impl<B, P> Problem<'_, B, P> {
    fn evaluate<Sys, St, const N: usize, const S: usize, const M: usize>(
        &self,
        p: f64,
        guess: SVector<f64, N>,
        tol: Tolerances<f64, M>,
    ) -> Result<Evaluated<N>>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S> + Clone,
        St: Stepper<f64, N>,
    {
        let mut sim = (self.build)(p)?;
        let period = (self.period)(p);
        let orbit: SlidingOrbit<f64, N, S> = sim.find_orbit(
            self.t0,
            guess,
            period,
            false,
            tol,
            self.settings.xtol,
            self.settings.max_iterations,
        )?;
        let tests = sliding_tests(
            &mut sim,
            self.settings.surface,
            self.t0,
            orbit.state,
            period,
        )?;
        Ok(Evaluated {
            point: SlidingBranchPoint {
                p,
                state: orbit.state,
                multipliers: orbit
                    .monodromy
                    .multipliers()
                    .into_iter()
                    .map(|m| Complex::new(m.re, m.im))
                    .collect(),
                tests,
            },
        })
    }

    /// Locates the zero of `test` between two points by the Illinois method in `p`.
    fn locate<Sys, St, const N: usize, const S: usize, const M: usize>(
        &self,
        a: &SlidingBranchPoint<N>,
        b: &SlidingBranchPoint<N>,
        test: impl Fn(&SlidingTests) -> Option<f64>,
        tol: Tolerances<f64, M>,
    ) -> Result<Option<Located<N>>>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S> + Clone,
        St: Stepper<f64, N>,
    {
        let (Some(mut fa), Some(mut fb)) = (test(&a.tests), test(&b.tests)) else {
            return Ok(None);
        };
        if !(fa.is_finite() && fb.is_finite()) || fa.signum() == fb.signum() || fa == 0.0 {
            return Ok(None);
        }
        let (mut pa, mut pb) = (a.p, b.p);
        let (mut xa, mut xb) = (a.state, b.state);
        let mut best = if fb.abs() < fa.abs() {
            (b.clone(), fb)
        } else {
            (a.clone(), fa)
        };
        let mut side = 0i8;
        for _ in 0..100 {
            if (pb - pa).abs() <= self.settings.locate_tolerance {
                break;
            }
            let mut pc = pb - fb * (pb - pa) / (fb - fa);
            // Keep the trial strictly inside the bracket.
            let (lo, hi) = (pa.min(pb), pa.max(pb));
            if !(pc > lo && pc < hi) {
                pc = 0.5 * (pa + pb);
            }
            let w = (pc - pa) / (pb - pa);
            let guess = xa + (xb - xa) * w;
            let ev = match self.evaluate::<Sys, St, N, S, M>(pc, guess, tol) {
                Ok(ev) => ev,
                // A failed shooting inside the bracket (e.g. a start at a tangency): try
                // the midpoint, else report the bracket reached so far.
                Err(_) if pc != 0.5 * (pa + pb) => {
                    let pm = 0.5 * (pa + pb);
                    match self.evaluate::<Sys, St, N, S, M>(pm, xa + (xb - xa) * 0.5, tol) {
                        Ok(ev) => {
                            let Some(fm) = test(&ev.point.tests) else {
                                return Ok(None);
                            };
                            if fm.signum() == fa.signum() {
                                (pa, fa, xa) = (pm, fm, ev.point.state);
                            } else {
                                (pb, fb, xb) = (pm, fm, ev.point.state);
                            }
                            best = (ev.point, fm);
                            side = 0;
                            continue;
                        }
                        Err(_) => break,
                    }
                }
                Err(_) => break,
            };
            let Some(fc) = test(&ev.point.tests) else {
                return Ok(None);
            };
            let state = ev.point.state;
            best = (ev.point, fc);
            if fc == 0.0 {
                pa = pc;
                pb = pc;
                break;
            }
            if fc.signum() == fb.signum() {
                (pb, fb, xb) = (pc, fc, state);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            } else {
                (pa, fa, xa) = (pc, fc, state);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            }
        }
        Ok(Some((best.0, best.1, (pa, pb))))
    }
}

/// Whether a located sign change is a zero of the test (its value there below 10⁻³ of its
/// values at the bracketing grid points), not a jump (the arrival nearest to the boundary
/// of the sliding region changed from one arrival to another).
fn is_zero(value: f64, fa: Option<f64>, fb: Option<f64>) -> bool {
    let scale = fa.unwrap_or(0.0).abs().max(fb.unwrap_or(0.0).abs());
    value.abs() <= 1e-3 * scale
}

/// Follows the periodic orbit of a forced Filippov system through `guess` at `p0` over the
/// grid `p₀ + kΔp` of `settings`, with `build(p)` the simulation at `p`, `period(p)` the
/// forcing period and `tol` the tolerances of the variational equations
/// (`M = N + N²`), and locates the sliding bifurcations on it (see the
/// [module docs](self)).
///
/// # Errors
/// [`OrbitError::InvalidSetting`] for a tested surface `≥ S`; the errors of the first orbit
/// (builder, shooting: [`OrbitError::Filippov`], [`OrbitError::Run`]). A shooting that
/// fails at a later grid point ends the branch ([`BranchEnd::StepTooSmall`]), as does the
/// point cap ([`BranchEnd::MaxPoints`]).
pub fn follow_sliding<Sys, St, B, P, const N: usize, const S: usize, const M: usize>(
    build: B,
    period: P,
    t0: f64,
    p0: f64,
    guess: SVector<f64, N>,
    tol: Tolerances<f64, M>,
    settings: &SlidingContinuation,
) -> Result<SlidingBranch<N>>
where
    B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
    P: Fn(f64) -> f64,
    Sys: Filippov<f64, N, S> + Clone,
    St: Stepper<f64, N>,
{
    if settings.surface >= S {
        return Err(invalid(
            "the tested surface",
            "< S (the number of surfaces)",
            settings.surface as f64,
        ));
    }
    let problem = Problem {
        build: &build,
        period: &period,
        t0,
        settings,
    };
    let first = problem.evaluate::<Sys, St, N, S, M>(p0, guess, tol)?;
    let mut points = vec![first.point];
    let mut bifurcations = Vec::new();
    let mut k = 1usize;
    let end = loop {
        if points.len() >= settings.max_points {
            break BranchEnd::MaxPoints;
        }
        let p = p0 + settings.step * k as f64;
        if p < settings.lo || p > settings.hi {
            break BranchEnd::ParameterRange;
        }
        let n = points.len();
        let last = &points[n - 1];
        let guess = if n >= 2 {
            let prev = &points[n - 2];
            last.state + (last.state - prev.state) * ((p - last.p) / (last.p - prev.p))
        } else {
            last.state
        };
        let Ok(ev) = problem
            .evaluate::<Sys, St, N, S, M>(p, guess, tol)
            .or_else(|_| problem.evaluate::<Sys, St, N, S, M>(p, last.state, tol))
        else {
            break BranchEnd::StepTooSmall { p: last.p };
        };
        let b = ev.point;
        for (kind, test) in [
            (
                SlidingBifurcationKind::GrazingSliding,
                (|t: &SlidingTests| Some(t.grazing_sliding)) as fn(&SlidingTests) -> Option<f64>,
            ),
            (
                SlidingBifurcationKind::CrossingSliding,
                |t: &SlidingTests| t.crossing_sliding,
            ),
        ] {
            let (fa, fb) = (test(&last.tests), test(&b.tests));
            if let Some((at, value, bracket)) =
                problem.locate::<Sys, St, N, S, M>(last, &b, test, tol)?
                && is_zero(value, fa, fb)
            {
                bifurcations.push(SlidingBifurcation {
                    kind,
                    p: at.p,
                    state: at.state,
                    value,
                    bracket,
                });
            }
        }
        points.push(b);
        k += 1;
    };
    Ok(SlidingBranch {
        points,
        bifurcations,
        end,
    })
}
