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
//! - **grazing-sliding of one arc** of an orbit that already slides elsewhere (a short
//!   sliding segment is born or dies where a region arc touches the surface): over the
//!   region arcs, each arc's interior local minimum of `s·H` (a near miss) and, at each
//!   arrival from a region `a` that slides or grazes, the minimum the arriving arc would
//!   reach past the surface by its second-order expansion,
//!   $$ g_{\mathrm{lgs}} = \operatorname*{arg\,min}_{|\cdot|}\Bigl\{\min_{\text{arc}} s\,H,\;
//!   -\frac{v^2}{2c}\Bigr\},\qquad v = s_a\,L_{F_a}H < 0,\quad c = s_a\,L^2_{F_a}H > 0, $$
//!   the candidate nearest to zero (`SlidingTests::local_grazing_sliding`; defined for
//!   orbits that slide). It is smooth through the graze (the near miss and the virtual
//!   minimum are the same quadratic's minimum on the two sides).
//! - **crossing-sliding** and **switching-sliding** (a point where the orbit arrives at
//!   the surface from a region reaches the boundary of the sliding region, where the far
//!   field `F_ā` is tangent, `h_ā = 0`, a fold of `F_ā`): over the orbit's arrivals at the
//!   surface from a region (crossings and sliding entries, arriving from side `a` with
//!   `h_a ≠ 0`), the far-side rate signed so that a crossing is positive,
//!   $$ g_{\mathrm{cs}} = -\operatorname{sgn}(a)\, h_{\bar a}\quad\text{at the arrival with the smallest } |h_{\bar a}| , $$
//!   positive for a crossing, negative for a sliding entry, zero where the arrival point is
//!   on the boundary `h_ā = 0` of the sliding region. The field on the far side is
//!   continuous there, so the arrival point, and `g_cs`, move continuously through the
//!   bifurcation. Which of the two it is depends on the fold, i.e. on the far field's
//!   orbit through the arrival point, `H(τ) ≈ h_ā τ + ½ L²_{F_ā}H τ²`: with
//!   $$ c = \operatorname{sgn}(\bar a)\, L^2_{F_{\bar a}} H, \qquad L^2_F H = \frac{d}{dt}\big(\nabla H\cdot F + \partial_t H\big) \text{ along } F $$
//!   (by [`second_rate`]),
//!   `c > 0` (a fold visible from the far region: its orbit moves away into it) makes a
//!   **crossing-sliding**: on the crossing side the orbit goes on in the far region, on
//!   the other it slides for a time `∝ |g_cs|` and leaves at the fold; `c < 0` (an
//!   invisible fold: the far orbit turns back to the surface) makes a
//!   **switching-sliding**: on the crossing side the orbit makes an excursion into the far
//!   region of duration `≈ 2h_ā/|L²H| ∝ |g_cs|` and slides where it comes back (arriving
//!   from `ā`, where `F_a` still pushes into the surface), on the other it slides at once.
//! - **adding-sliding** (a sliding segment's exit point reaches a point of the boundary
//!   of the sliding region where the departing field's orbit has a cubic tangency,
//!   `h_b = 0` and `L²_{F_b}H = 0`; there the sliding flow is tangent to the boundary):
//!   along each sliding segment the equivalent control `α` (exit into `H < 0` at `α = 0`,
//!   into `H > 0` at `α = 1`) has local extrema, and
//!   $$ g_{\mathrm{as}} = \min\!\big(\alpha, 1 - \alpha\big) \text{ at the extremum nearest to its bound}, $$
//!   found by [`FilippovSimulation::control_extrema`] (zeros of `dα/dt` along the sliding
//!   flow). To keep the test continuous, the sliding flow of a segment that exits into side
//!   `b` and re-enters sliding from side `b` is continued past its exit (the sliding field
//!   is defined while `h₋ > h₊`) up to the re-entry: its extremum there lies beyond the
//!   bound and `g_as < 0`. So `g_as > 0` while the segment slides past the near-touch,
//!   `0` where `α` touches its bound, `< 0` once the segment splits around an excursion,
//!   whose duration grows as `√|g_as|`.
//!
//! The four are the sliding bifurcations of di Bernardo, Kowalczyk & Nordmark (2003) (and
//! di Bernardo et al. 2008, §8.5): all occur where the orbit meets the fold of `F_b` that
//! bounds the sliding region — crossing it (crossing- and switching-sliding, by the
//! visibility of the fold), grazing at it (grazing-sliding), or sliding into a point of it
//! where the fold changes visibility (adding-sliding; in the classification of Jeffrey &
//! Hogan (2011) a cusp of the boundary's projection).
//!
//! # Autonomous orbits
//! With [`SlidingContinuation::autonomous`] the period is an unknown of each shooting
//! ([`FilippovSimulation::find_orbit`] with the phase fixed by the section through the
//! guess normal to the field there), seeded by the secant extrapolation of the last two
//! periods; [`SlidingBranchPoint::period`] records it and the tests run over it.
//!
//! # Folds
//! [`follow_sliding`] steps in `p` and cannot pass a turning point of the branch;
//! [`follow_sliding_arclength`] follows the curve `φ(x; p) = x` in `(x, p)` by
//! pseudo-arclength (tangent from `[Φ − I, ∂φ/∂p]`, `Φ` with the saltation matrices, so
//! through crossings and sliding) and locates folds as zeros of the tangent's
//! `p`-component, where a Floquet multiplier is 1.
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
//! oscillators*, IJBC 13(10), 2003; M. R. Jeffrey, S. J. Hogan, *The geometry of generic
//! sliding bifurcations*, SIAM Review 53(3), 2011.

use nalgebra::{Complex, SVector};

use super::{BranchEnd, OrbitError, Result};
use crate::filippov::{
    Approach, Filippov, FilippovRun, FilippovSimulation, ModeTransition, Region, SlidingOrbit,
    TransitionKind, second_rate,
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
    autonomous: bool,
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
            autonomous: false,
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

impl SlidingContinuation {
    /// Orbits of an autonomous system: the period is an unknown of the shooting (its guess
    /// at the first point is `period(p₀)`, later the secant extrapolation of the last two
    /// periods), the phase fixed by the section through the guess normal to the field
    /// there (see [`FilippovSimulation::find_orbit`]). Default: forced (the period is
    /// `period(p)`).
    pub fn autonomous(mut self) -> Self {
        self.autonomous = true;
        self
    }
}

/// [`OrbitError::InvalidSetting`] for a tested surface the system lacks.
fn check_surface<const S: usize>(settings: &SlidingContinuation) -> Result<()> {
    if settings.surface >= S {
        return Err(invalid(
            "the tested surface",
            "< S (the number of surfaces)",
            settings.surface as f64,
        ));
    }
    Ok(())
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
    /// `c = s_ā L²_{F_ā}H` at that arrival (`ā` the far side, `s_ā = ±1` its sign): where
    /// `g_cs = 0`, positive if the far field's orbit through the arrival point moves into
    /// the far region (a visible fold: crossing-sliding), negative if it turns back to the
    /// surface (an invisible fold: switching-sliding).
    pub crossing_curvature: Option<f64>,
    /// `g_as`: the margin `α` or `1 − α` at the local extremum of the equivalent control
    /// along a sliding segment (continued past its exit up to a re-entry from the side it
    /// left to) nearest to its bound; `None` if there is no such extremum.
    pub adding_sliding: Option<f64>,
    /// `g_lgs`, the local grazing-sliding test of an orbit that slides on the surface: over
    /// its region arcs, the interior local minimum of `s·H` (a near miss, `> 0`) or, at a
    /// sliding entry from a region whose field turns back (`c = s·L²_F H > 0`), the
    /// minimum the arriving arc would reach past the surface, `−v²/(2c)` with
    /// `v = s·L_F H` (`< 0`), whichever is nearest to zero. It vanishes where one arc of
    /// the orbit grazes the surface while the orbit slides elsewhere: a short sliding
    /// segment appears or disappears. `None` for an orbit that does not slide (its test
    /// is `grazing_sliding`) or has no such arc.
    pub local_grazing_sliding: Option<f64>,
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
    /// The period (the forcing period, or an autonomous orbit's).
    pub period: f64,
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
    /// A crossing point reaches the boundary of the sliding region (`g_cs = 0`) at a fold
    /// of the far field that is visible from the far region (`c > 0`): a crossing turns
    /// into a short sliding segment.
    CrossingSliding,
    /// A crossing point reaches the boundary of the sliding region (`g_cs = 0`) at an
    /// invisible fold of the far field (`c < 0`): the excursion into the far region
    /// between a crossing and a sliding entry from the far side shrinks to nothing.
    SwitchingSliding,
    /// The equivalent control along a sliding segment touches its bound at a local
    /// extremum (`g_as = 0`): a sliding segment splits in two around a short excursion.
    AddingSliding,
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
/// `(t0, x0)` (the system must be periodic in `t` with that period, or autonomous).
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
    St: Stepper<f64, N> + Clone,
{
    let system = sim.system().clone();
    let mut approach = Approach::new(&system, surface, t0, 8);
    let run = sim.run(t0, x0, t0 + period, &mut approach)?;
    let mut tests = tests_of_run(
        &system,
        surface,
        &run.transitions,
        run.start_mode.sliding == Some(surface),
        (t0, run.t),
        (
            approach.closest.map(|c| c.0),
            approach.near_miss.map(|c| c.0),
        ),
    );
    tests.adding_sliding = adding_test(sim, surface, &run, (t0, x0));
    Ok(tests)
}

/// A sliding segment's start and the end of the window its extrema are sought in.
struct Window<const N: usize, const S: usize> {
    t: f64,
    x: SVector<f64, N>,
    sides: [Region; S],
    end: f64,
}

/// `g_as` of a run over one period: the extremum of `α` nearest to its bound over every
/// sliding segment on `surface`, each continued past its exit up to a re-entry from the
/// side it left to (a segment open at the period's end is continued into the next period
/// up to the end of the first segment's window). A window whose integration fails offers
/// no candidate.
fn adding_test<Sys, St, const N: usize, const S: usize>(
    sim: &FilippovSimulation<f64, Sys, St>,
    surface: usize,
    run: &FilippovRun<f64, N, S>,
    (t0, x0): (f64, SVector<f64, N>),
) -> Option<f64>
where
    Sys: Filippov<f64, N, S>,
    St: Stepper<f64, N> + Clone,
{
    let all = &run.transitions;
    let mut windows: Vec<Window<N, S>> = Vec::new();
    let starts_sliding = run.start_mode.sliding == Some(surface);
    let mut open = starts_sliding.then_some((t0, x0, run.start_mode.sides));
    // The end of the window of the segment open at t0, if it closes within the period.
    let mut first_end = None;
    for (k, tr) in all.iter().enumerate() {
        let slides_after = tr.to.sliding == Some(surface);
        let slid_before = tr.from.sliding == Some(surface);
        if slides_after && !slid_before {
            open = Some((tr.t, tr.x, tr.to.sides));
        } else if slid_before
            && !slides_after
            && let Some((t, x, sides)) = open.take()
        {
            let side = tr.to.sides[surface];
            let end = match all.get(k + 1) {
                Some(next)
                    if next.surface == surface
                        && next.kind == TransitionKind::SlidingEntry
                        && next.from.sides[surface] == side =>
                {
                    next.t
                }
                _ => tr.t,
            };
            if t == t0 && starts_sliding && first_end.is_none() && windows.is_empty() {
                first_end = Some(end);
            }
            windows.push(Window { t, x, sides, end });
        }
    }
    if let Some((t, x, sides)) = open {
        // Open at the end: continued over the period boundary (the first segment's window
        // is then a part of this one).
        let end = match first_end {
            Some(e) => {
                windows.retain(|w| w.t != t0);
                run.t + (e - t0)
            }
            None => run.t,
        };
        windows.push(Window { t, x, sides, end });
    }
    let mut best: Option<f64> = None;
    for w in windows.iter().filter(|w| w.end > w.t) {
        // A window whose continued sliding flow cannot be integrated (it left the domain
        // where h₋ > h₊ far from the surface) offers no candidate.
        let Ok(extrema) = sim.control_extrema(surface, w.sides, w.t, w.x, w.end) else {
            continue;
        };
        for e in extrema {
            if e.t > w.t && e.t < w.end && best.is_none_or(|b| e.margin.abs() < b.abs()) {
                best = Some(e.margin);
            }
        }
    }
    best
}

/// The tests from a run's transitions and the closest approach of its region steps
/// (all but `g_as`).
fn tests_of_run<Sys, const N: usize, const S: usize>(
    system: &Sys,
    surface: usize,
    transitions: &[ModeTransition<f64, N, S>],
    starts_sliding: bool,
    (t0, t1): (f64, f64),
    (closest, near_miss): (Option<f64>, Option<f64>),
) -> SlidingTests
where
    Sys: Filippov<f64, N, S>,
{
    // Sliding time and segments on the surface.
    let mut sliding_time = 0.0;
    let mut segments = 0usize;
    let mut since = if starts_sliding { Some(t0) } else { None };
    let mut crossing: Option<(f64, f64)> = None;
    let mut local = near_miss;
    for tr in transitions.iter().filter(|tr| tr.surface == surface) {
        let slides_after = tr.to.sliding == Some(surface);
        let slid_before = tr.from.sliding == Some(surface);
        if slides_after && !slid_before {
            since = Some(tr.t);
            segments += 1;
        }
        // An arrival from a region that slides, or touches and stays (a graze judged by
        // the second-order test): the arc's minimum past the surface.
        let arrives = tr.from.sliding.is_none()
            && (slides_after || (tr.kind == TransitionKind::Graze && tr.to.sliding.is_none()));
        if arrives {
            let v = entry_minimum(system, surface, tr);
            if v.is_some_and(|v| local.is_none_or(|l| v.abs() < l.abs())) {
                local = v;
            }
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
            if c.is_finite() && crossing.is_none_or(|best| c.abs() < best.0.abs()) {
                let curvature =
                    a.flip().sign::<f64>() * second_rate(system, surface, &far, tr.t, &tr.x);
                crossing = Some((c, curvature));
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
        local_grazing_sliding: local.filter(|_| segments > 0),
        crossing_sliding: crossing.map(|c| c.0),
        crossing_curvature: crossing.map(|c| c.1),
        adding_sliding: None,
        sliding_segments: segments,
        sliding_time,
    }
}

/// At an arrival from a region `a` (sign `s`) that slides or grazes: the minimum of `s·H`
/// the arriving arc would reach past the surface, `−v²/(2c)` with `v = s·L_F H` and `c = s·L²_F H`, if
/// the field turns back (`c > 0`, finite).
fn entry_minimum<Sys, const N: usize, const S: usize>(
    system: &Sys,
    surface: usize,
    tr: &ModeTransition<f64, N, S>,
) -> Option<f64>
where
    Sys: Filippov<f64, N, S>,
{
    let sign = tr.from.sides[surface].sign::<f64>();
    let mut f = SVector::zeros();
    system.field(&tr.from.sides, tr.t, &tr.x, &mut f);
    let v = sign
        * (system.gradient(surface, tr.t, &tr.x).dot(&f)
            + system.surface_time_rate(surface, tr.t, &tr.x));
    let c = sign * second_rate(system, surface, &tr.from.sides, tr.t, &tr.x);
    let m = -v * v / (2.0 * c);
    (c > 0.0 && m.is_finite()).then_some(m)
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
        (guess, period_guess): (SVector<f64, N>, f64),
        tol: Tolerances<f64, M>,
    ) -> Result<Evaluated<N>>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S> + Clone,
        St: Stepper<f64, N> + Clone,
    {
        let mut sim = (self.build)(p)?;
        let auto = self.settings.autonomous;
        let period = if auto { period_guess } else { (self.period)(p) };
        let orbit: SlidingOrbit<f64, N, S> = sim.find_orbit(
            self.t0,
            guess,
            period,
            auto,
            tol,
            self.settings.xtol,
            self.settings.max_iterations,
        )?;
        let multipliers = orbit
            .monodromy
            .multipliers()
            .into_iter()
            .map(|m| Complex::new(m.re, m.im))
            .collect();
        let point = self.point_on(&mut sim, p, orbit.state, orbit.period, multipliers)?;
        Ok(Evaluated { point })
    }

    /// The branch point at `p` on the orbit through `state` of period `period` of `sim`,
    /// with its Floquet `multipliers`: its sliding tests evaluated.
    fn point_on<Sys, St, const N: usize, const S: usize>(
        &self,
        sim: &mut FilippovSimulation<f64, Sys, St>,
        p: f64,
        state: SVector<f64, N>,
        period: f64,
        multipliers: Vec<Complex<f64>>,
    ) -> Result<SlidingBranchPoint<N>>
    where
        Sys: Filippov<f64, N, S> + Clone,
        St: Stepper<f64, N> + Clone,
    {
        let tests = sliding_tests(sim, self.settings.surface, self.t0, state, period)?;
        Ok(SlidingBranchPoint {
            p,
            state,
            period,
            multipliers,
            tests,
        })
    }

    /// The sliding bifurcations between two points of a branch along which `p` is
    /// monotone: each test function's sign change, located by [`locate`](Self::locate)
    /// and kept if its value there is a zero (not a jump of the test), crossing-sliding
    /// told from switching-sliding by the far field's curvature.
    fn sliding_bifurcations<Sys, St, const N: usize, const S: usize, const M: usize>(
        &self,
        a: &SlidingBranchPoint<N>,
        b: &SlidingBranchPoint<N>,
        tol: Tolerances<f64, M>,
    ) -> Result<Vec<SlidingBifurcation<N>>>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S> + Clone,
        St: Stepper<f64, N> + Clone,
    {
        let mut found = Vec::new();
        use SlidingBifurcationKind::{AddingSliding, CrossingSliding, GrazingSliding};
        let local: fn(&SlidingTests) -> Option<f64> = |t| t.local_grazing_sliding;
        for (kind, test) in [
            (GrazingSliding, test_of(GrazingSliding)),
            (GrazingSliding, local),
            (CrossingSliding, test_of(CrossingSliding)),
            (AddingSliding, test_of(AddingSliding)),
        ] {
            let (fa, fb) = (test(&a.tests), test(&b.tests));
            if let Some((at, value, bracket)) = self.locate::<Sys, St, N, S, M>(a, b, test, tol)?
                && is_zero(value, fa, fb)
            {
                // g_cs = 0 at a visible or an invisible fold of the far field.
                let kind = match (kind, at.tests.crossing_curvature) {
                    (SlidingBifurcationKind::CrossingSliding, Some(c)) if c < 0.0 => {
                        SlidingBifurcationKind::SwitchingSliding
                    }
                    _ => kind,
                };
                found.push(SlidingBifurcation {
                    kind,
                    p: at.p,
                    state: at.state,
                    value,
                    bracket,
                });
            }
        }
        Ok(found)
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
        St: Stepper<f64, N> + Clone,
    {
        let (Some(mut fa), Some(mut fb)) = (test(&a.tests), test(&b.tests)) else {
            return Ok(None);
        };
        if !(fa.is_finite() && fb.is_finite()) || fa.signum() == fb.signum() || fa == 0.0 {
            return Ok(None);
        }
        let (mut pa, mut pb) = (a.p, b.p);
        let (mut xa, mut xb) = ((a.state, a.period), (b.state, b.period));
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
            let guess = (xa.0 + (xb.0 - xa.0) * w, xa.1 + (xb.1 - xa.1) * w);
            let ev = match self.evaluate::<Sys, St, N, S, M>(pc, guess, tol) {
                Ok(ev) => ev,
                // A failed shooting inside the bracket (e.g. a start at a tangency): try
                // the midpoint, else report the bracket reached so far.
                Err(_) if pc != 0.5 * (pa + pb) => {
                    let pm = 0.5 * (pa + pb);
                    match self.evaluate::<Sys, St, N, S, M>(
                        pm,
                        (xa.0 + (xb.0 - xa.0) * 0.5, 0.5 * (xa.1 + xb.1)),
                        tol,
                    ) {
                        Ok(ev) => {
                            let Some(fm) = test(&ev.point.tests) else {
                                return Ok(None);
                            };
                            if fm.signum() == fa.signum() {
                                (pa, fa, xa) = (pm, fm, (ev.point.state, ev.point.period));
                            } else {
                                (pb, fb, xb) = (pm, fm, (ev.point.state, ev.point.period));
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
            let state = (ev.point.state, ev.point.period);
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

/// The test function whose zero is a bifurcation of `kind` (`g_cs` for both crossing- and
/// switching-sliding).
fn test_of(kind: SlidingBifurcationKind) -> fn(&SlidingTests) -> Option<f64> {
    match kind {
        SlidingBifurcationKind::GrazingSliding => |t| Some(t.grazing_sliding),
        SlidingBifurcationKind::CrossingSliding | SlidingBifurcationKind::SwitchingSliding => {
            |t| t.crossing_sliding
        }
        SlidingBifurcationKind::AddingSliding => |t| t.adding_sliding,
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
    St: Stepper<f64, N> + Clone,
{
    check_surface::<S>(settings)?;
    let problem = Problem {
        build: &build,
        period: &period,
        t0,
        settings,
    };
    let first = problem.evaluate::<Sys, St, N, S, M>(p0, (guess, period(p0)), tol)?;
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
            let w = (p - last.p) / (last.p - prev.p);
            (
                last.state + (last.state - prev.state) * w,
                last.period + (last.period - prev.period) * w,
            )
        } else {
            (last.state, last.period)
        };
        let Ok(ev) = problem
            .evaluate::<Sys, St, N, S, M>(p, guess, tol)
            .or_else(|_| problem.evaluate::<Sys, St, N, S, M>(p, (last.state, last.period), tol))
        else {
            break BranchEnd::StepTooSmall { p: last.p };
        };
        let b = ev.point;
        bifurcations.extend(problem.sliding_bifurcations::<Sys, St, N, S, M>(last, &b, tol)?);
        points.push(b);
        k += 1;
    };
    Ok(SlidingBranch {
        points,
        bifurcations,
        end,
    })
}

/// A fold (turning point in `p`) located on a branch of [`follow_sliding_arclength`].
#[derive(Debug, Clone, PartialEq)]
pub struct SlidingFold<const N: usize> {
    /// The index in [`SlidingArcBranch::points`] of the last point before the fold.
    pub after: usize,
    /// The parameter at the fold (an extremum of `p` along the branch).
    pub p: f64,
    /// The orbit there.
    pub state: SVector<f64, N>,
    /// The `p`-component of the unit tangent there (zero up to the location tolerance).
    pub tangent_p: f64,
    /// The Floquet multipliers there (one of them is 1 at a fold).
    pub multipliers: Vec<Complex<f64>>,
}

/// A branch followed by pseudo-arclength ([`follow_sliding_arclength`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SlidingArcBranch<const N: usize> {
    /// The points in order of arclength.
    pub points: Vec<SlidingBranchPoint<N>>,
    /// The folds, in order of arclength.
    pub folds: Vec<SlidingFold<N>>,
    /// The sliding bifurcations located between neighbouring points, in order of
    /// arclength (as in [`follow_sliding`]; not between the two neighbours of a fold,
    /// where `p` is not monotone).
    pub bifurcations: Vec<SlidingBifurcation<N>>,
    /// Why it ended.
    pub end: BranchEnd,
}

/// A corrected point of the arclength continuation: `z = (x, p)`, its unit tangent and the
/// monodromy's multipliers.
struct ArcPoint<const N: usize> {
    x: SVector<f64, N>,
    p: f64,
    tangent: nalgebra::DVector<f64>,
    multipliers: Vec<Complex<f64>>,
}

/// The arclength step `Δs` of [`follow_sliding_arclength`]: `|step|` at first, halved when
/// the corrector fails (down to `10⁻⁴|step|`), grown by 1.5 after a corrector of at most 3
/// iterations (up to `4|step|`).
struct ArcStep {
    ds: f64,
    min: f64,
    max: f64,
}

impl ArcStep {
    fn new(step: f64) -> Self {
        Self {
            ds: step.abs(),
            min: 1e-4 * step.abs(),
            max: 4.0 * step.abs(),
        }
    }

    /// Halves the step after a failed corrector; `false` if it fell below the smallest (the
    /// branch ends).
    fn halve(&mut self) -> bool {
        self.ds *= 0.5;
        !(self.ds < self.min)
    }

    /// Grows the step after a corrector of `iterations` if that was at most 3.
    fn grow(&mut self, iterations: usize) {
        if iterations <= 3 {
            self.ds = (self.ds * 1.5).min(self.max);
        }
    }
}

impl<B, P> Problem<'_, B, P> {
    /// The period map's residual `φ(x; p) − x`, its Jacobian `[Φ − I, ∂φ/∂p]` (`∂φ/∂p` by a
    /// central difference in `p`, the period `period(p)` included) and the multipliers.
    #[allow(clippy::type_complexity)]
    fn residual<Sys, St, const N: usize, const S: usize, const M: usize>(
        &self,
        x: &SVector<f64, N>,
        p: f64,
        tol: Tolerances<f64, M>,
    ) -> Result<(SVector<f64, N>, nalgebra::DMatrix<f64>, Vec<Complex<f64>>)>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S>,
        St: Stepper<f64, N>,
    {
        let mut sim = (self.build)(p)?;
        let mono = sim.monodromy(self.t0, *x, self.t0 + (self.period)(p), tol)?;
        let r = mono.run.x - x;
        let h = 1e-6 * p.abs().max(1.0);
        let end = |q: f64| -> Result<SVector<f64, N>> {
            let mut sim = (self.build)(q)?;
            Ok(sim.run(self.t0, *x, self.t0 + (self.period)(q), &mut ())?.x)
        };
        let dp = (end(p + h)? - end(p - h)?) / (2.0 * h);
        let mut j = nalgebra::DMatrix::<f64>::zeros(N, N + 1);
        for i in 0..N {
            for k in 0..N {
                j[(i, k)] = mono.matrix[(i, k)];
            }
            j[(i, i)] -= 1.0;
            j[(i, N)] = dp[i];
        }
        let multipliers = mono
            .multipliers()
            .into_iter()
            .map(|m| Complex::new(m.re, m.im))
            .collect();
        Ok((r, j, multipliers))
    }

    /// The unit tangent at a solution: the null vector of `[Φ − I, ∂φ/∂p]`, oriented along
    /// `previous`.
    fn tangent<const N: usize>(
        j: &nalgebra::DMatrix<f64>,
        previous: &nalgebra::DVector<f64>,
    ) -> Option<nalgebra::DVector<f64>> {
        let mut a = nalgebra::DMatrix::<f64>::zeros(N + 1, N + 1);
        a.view_mut((0, 0), (N, N + 1)).copy_from(j);
        for k in 0..=N {
            a[(N, k)] = previous[k];
        }
        let mut rhs = nalgebra::DVector::<f64>::zeros(N + 1);
        rhs[N] = 1.0;
        let t = a.lu().solve(&rhs)?;
        let n = t.norm();
        (n.is_finite() && n > 0.0).then(|| t / n)
    }

    /// The unit tangent at the first orbit `x` at `p`, oriented to the settings' step in
    /// `p` (increasing `p` for `step > 0`).
    ///
    /// # Errors
    /// Those of [`residual`](Self::residual); [`FilippovError::Singular`](
    /// crate::filippov::FilippovError::Singular) without a tangent.
    fn first_tangent<Sys, St, const N: usize, const S: usize, const M: usize>(
        &self,
        x: &SVector<f64, N>,
        p: f64,
        tol: Tolerances<f64, M>,
    ) -> Result<nalgebra::DVector<f64>>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S>,
        St: Stepper<f64, N>,
    {
        let (_, j, _) = self.residual::<Sys, St, N, S, M>(x, p, tol)?;
        let mut along_p = nalgebra::DVector::<f64>::zeros(N + 1);
        along_p[N] = self.settings.step.signum();
        match Self::tangent::<N>(&j, &along_p) {
            Some(tangent) => Ok(tangent),
            None => Err(crate::filippov::FilippovError::Singular { iteration: 0 }.into()),
        }
    }

    /// Newton's method on `φ(x; p) − x = 0`, `τ·(z − z_pred) = 0` from the prediction
    /// `z_pred = z + σ τ`, then the tangent there.
    fn correct<Sys, St, const N: usize, const S: usize, const M: usize>(
        &self,
        from: &ArcPoint<N>,
        sigma: f64,
        tol: Tolerances<f64, M>,
    ) -> Result<(ArcPoint<N>, usize)>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S>,
        St: Stepper<f64, N>,
    {
        let tau = &from.tangent;
        let mut x = from.x + SVector::<f64, N>::from_fn(|i, _| sigma * tau[i]);
        let mut p = from.p + sigma * tau[N];
        let (x_pred, p_pred) = (x, p);
        for it in 0..self.settings.max_iterations {
            let (r, j, _) = self.residual::<Sys, St, N, S, M>(&x, p, tol)?;
            let mut a = nalgebra::DMatrix::<f64>::zeros(N + 1, N + 1);
            a.view_mut((0, 0), (N, N + 1)).copy_from(&j);
            let mut b = nalgebra::DVector::<f64>::zeros(N + 1);
            let mut arc = 0.0;
            for k in 0..N {
                a[(N, k)] = tau[k];
                b[k] = -r[k];
                arc += tau[k] * (x[k] - x_pred[k]);
            }
            a[(N, N)] = tau[N];
            b[N] = -(arc + tau[N] * (p - p_pred));
            let Some(d) = a.lu().solve(&b) else {
                return Err(crate::filippov::FilippovError::Singular { iteration: it }.into());
            };
            for k in 0..N {
                x[k] += d[k];
            }
            p += d[N];
            if !(p.is_finite() && x.iter().all(|v| v.is_finite())) {
                break;
            }
            if d.amax() <= self.settings.xtol * (1.0 + x.amax().max(p.abs())) {
                let (_, j, multipliers) = self.residual::<Sys, St, N, S, M>(&x, p, tol)?;
                let Some(tangent) = Self::tangent::<N>(&j, tau) else {
                    return Err(crate::filippov::FilippovError::Singular { iteration: it }.into());
                };
                return Ok((
                    ArcPoint {
                        x,
                        p,
                        tangent,
                        multipliers,
                    },
                    it + 1,
                ));
            }
        }
        Err(crate::filippov::FilippovError::NoConvergence {
            iterations: self.settings.max_iterations,
            residual: f64::NAN,
            step: f64::NAN,
        }
        .into())
    }

    /// The fold between `a` and the point at arclength `sigma` from it (their tangents'
    /// `p`-components of opposite signs): the zero of the `p`-component of the tangent, by
    /// the Illinois method in the arclength from `a`.
    fn locate_fold<Sys, St, const N: usize, const S: usize, const M: usize>(
        &self,
        a: &ArcPoint<N>,
        b: &ArcPoint<N>,
        sigma: f64,
        tol: Tolerances<f64, M>,
    ) -> Result<ArcPoint<N>>
    where
        B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
        P: Fn(f64) -> f64,
        Sys: Filippov<f64, N, S>,
        St: Stepper<f64, N>,
    {
        let (mut sa, mut fa) = (0.0, a.tangent[N]);
        let (mut sb, mut fb) = (sigma, b.tangent[N]);
        let mut best: Option<ArcPoint<N>> = None;
        let mut side = 0i8;
        let width = self.settings.locate_tolerance * sigma.abs().max(1.0);
        for _ in 0..100 {
            if (sb - sa).abs() <= width {
                break;
            }
            let mut sc = sb - fb * (sb - sa) / (fb - fa);
            if !(sc > sa.min(sb) && sc < sa.max(sb)) {
                sc = 0.5 * (sa + sb);
            }
            let (c, _) = self.correct::<Sys, St, N, S, M>(a, sc, tol)?;
            let fc = c.tangent[N];
            let done = fc == 0.0;
            best = Some(c);
            if done {
                break;
            }
            if fc.signum() == fb.signum() {
                (sb, fb) = (sc, fc);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            } else {
                (sa, fa) = (sc, fc);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            }
        }
        match best {
            Some(c) => Ok(c),
            None => self
                .correct::<Sys, St, N, S, M>(a, 0.5 * sigma, tol)
                .map(|c| c.0),
        }
    }
}

/// Follows the periodic orbit of a forced Filippov system through `guess` at `p0` by
/// **pseudo-arclength continuation** in `(x, p)`, so that the branch passes folds
/// (turning points in `p`), and locates the folds.
///
/// # Method
/// With `φ(x; p)` the state after one forcing period `period(p)` from `(t0, x)` (through
/// crossings and sliding), the branch is the curve `R(x, p) = φ(x; p) − x = 0` in
/// `ℝ^{N+1}`, followed from `z_k = (x_k, p_k)` with unit tangent `τ_k` (the null vector of
/// `[Φ − I, ∂φ/∂p]`, `Φ` the monodromy with saltation matrices, `∂φ/∂p` a central
/// difference) by the predictor `z_k + Δs τ_k` and Newton's method on
/// $$ \begin{pmatrix} \Phi - I & \partial_p\varphi \\ \tau_k^{\mathsf T} \end{pmatrix}
///    \Delta z = -\begin{pmatrix} R \\ \tau_k\cdot(z - z_k) - \Delta s \end{pmatrix}. $$
/// `Δs` starts at `|step|` of the settings (the first tangent points to increasing `p` for
/// `step > 0`), is halved when the corrector fails (the branch ends below `10⁻⁴|step|`)
/// and grows by 1.5 after a corrector of at most 3 iterations (up to `4|step|`).
///
/// A **fold** is a zero of the tangent's `p`-component `τ_p` (there `Φ − I` is singular:
/// a Floquet multiplier 1); a sign change of `τ_p` between two points is located by the
/// Illinois method in the arclength to the settings' locate tolerance (relative to the
/// step). The sliding tests of each point are evaluated as in [`follow_sliding`], and
/// a sign change of a test between two neighbouring points is located as there (by the
/// Illinois method in `p`, each trial orbit found by shooting from the points'
/// interpolation), except between the two neighbours of a fold, where `p` is not
/// monotone: a sliding bifurcation that close to a fold is not located.
///
/// # Errors
/// [`OrbitError::InvalidSetting`] for a tested surface `≥ S` or autonomous settings (not
/// supported here); the errors of the first orbit. A corrector that fails down to the
/// smallest step ends the branch ([`BranchEnd::StepTooSmall`]).
pub fn follow_sliding_arclength<Sys, St, B, P, const N: usize, const S: usize, const M: usize>(
    build: B,
    period: P,
    t0: f64,
    p0: f64,
    guess: SVector<f64, N>,
    tol: Tolerances<f64, M>,
    settings: &SlidingContinuation,
) -> Result<SlidingArcBranch<N>>
where
    B: Fn(f64) -> Result<FilippovSimulation<f64, Sys, St>>,
    P: Fn(f64) -> f64,
    Sys: Filippov<f64, N, S> + Clone,
    St: Stepper<f64, N> + Clone,
{
    check_surface::<S>(settings)?;
    if settings.autonomous {
        return Err(invalid(
            "autonomous orbits in arclength continuation",
            "a forced system",
            1.0,
        ));
    }
    let problem = Problem {
        build: &build,
        period: &period,
        t0,
        settings,
    };
    let first = problem.evaluate::<Sys, St, N, S, M>(p0, (guess, period(p0)), tol)?;
    let tangent = problem.first_tangent::<Sys, St, N, S, M>(&first.point.state, p0, tol)?;
    let mut current = ArcPoint {
        x: first.point.state,
        p: p0,
        tangent,
        multipliers: first.point.multipliers.clone(),
    };
    let mut points = vec![first.point];
    let mut folds = Vec::new();
    let mut bifurcations = Vec::new();
    let mut step = ArcStep::new(settings.step);
    let end = loop {
        if points.len() >= settings.max_points {
            break BranchEnd::MaxPoints;
        }
        let ds = step.ds;
        let (next, iterations) = match problem.correct::<Sys, St, N, S, M>(&current, ds, tol) {
            Ok(c) => c,
            Err(_) => {
                if !step.halve() {
                    break BranchEnd::StepTooSmall { p: current.p };
                }
                continue;
            }
        };
        if next.p < settings.lo || next.p > settings.hi {
            break BranchEnd::ParameterRange;
        }
        let mut sim = build(next.p)?;
        let multipliers = next.multipliers.clone();
        let b = problem.point_on(&mut sim, next.p, next.x, period(next.p), multipliers)?;
        if next.tangent[N].signum() != current.tangent[N].signum() {
            let fold = problem.locate_fold::<Sys, St, N, S, M>(&current, &next, ds, tol)?;
            folds.push(SlidingFold {
                after: points.len() - 1,
                p: fold.p,
                state: fold.x,
                tangent_p: fold.tangent[N],
                multipliers: fold.multipliers,
            });
        } else if let Some(a) = points.last() {
            bifurcations.extend(problem.sliding_bifurcations::<Sys, St, N, S, M>(a, &b, tol)?);
        }
        points.push(b);
        current = next;
        step.grow(iterations);
    };
    Ok(SlidingArcBranch {
        points,
        folds,
        bifurcations,
        end,
    })
}
