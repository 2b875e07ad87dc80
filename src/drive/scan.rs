//! The driver's event handling after a step: every event's crossings on the step's dense
//! output in time order, their records, resets, restarts and terminal stops, the sticking
//! check, and the observer's view of the step. [`Simulation`](super::Simulation) runs it
//! after each step of its stepper, and the ensemble after each accepted step of each lane
//! ([`ensemble`](crate::ensemble)): one implementation of the event contract for both.

use nalgebra::SVector;

use super::error::Result;
use super::{Control, EventRecord, Observer, RunError, StepView, Termination};
use crate::event::{Direction, EventError, EventHistory, EventSet, MAX_EVENTS, ZenoGuard, locate};
use crate::integrate::{DenseOutput, Stats};
use crate::lanes::Lanes;
use crate::scalar::{lit, to_f64};
use crate::{Dynamics, Real};

/// The event handling of one step of one trajectory: the system and events, the Zeno
/// guard and history, the step's dense output, and where its work and a restart go.
///
/// A reset, a restart, a terminal event or an error at an event leaves the state the
/// trajectory continues from (or stops at) in `restart`; the caller moves its stepper
/// there. The events and right-hand side evaluations made here are added to `stats`.
pub(crate) struct Scan<'a, T: Real, const N: usize, S, E, D> {
    pub(crate) system: &'a S,
    pub(crate) events: &'a E,
    pub(crate) zeno: &'a ZenoGuard<T>,
    pub(crate) event_tol: T,
    pub(crate) history: &'a mut EventHistory<T>,
    pub(crate) dense: &'a D,
    pub(crate) stats: &'a mut Stats,
    pub(crate) restart: &'a mut Option<(T, SVector<T, N>)>,
}

/// Each event's side at the current state, every event armed.
///
/// # Errors
/// [`EventError::NonFinite`] for an event value that is not finite;
/// [`EventError::SimultaneousContacts`] where the run starts with two or more impact
/// events closed and moving into one of them ([`simultaneous_contacts`]).
pub(crate) fn initial_sides<T: Real, const N: usize, S: Dynamics<T, N>, E: EventSet<T, N>>(
    system: &S,
    events: &E,
    t: T,
    y: &SVector<T, N>,
) -> Result<Sides> {
    let mut sides = Sides {
        side: [0; MAX_EVENTS],
        armed: [true; MAX_EVENTS],
    };
    let mut f = SVector::zeros();
    let mut have_f = false;
    // Impact events closed at the start (see `simultaneous_contacts`).
    let (mut closed, mut n_closed) = ([false; MAX_EVENTS], 0);
    for (i, s) in sides.side.iter_mut().enumerate().take(E::LEN) {
        let g = events.value(i, t, y);
        if !g.is_finite() {
            return Err(non_finite(i, t, g));
        }
        *s = sign_of(g);
        let far = far_side(events, i);
        if far != 0 && (*s == 0 || *s == far) {
            closed[i] = true;
            n_closed += 1;
        }
        if *s == 0 {
            // Start on the surface: it has not been crossed; the side is the one
            // the trajectory moves to (from the rate, else from the first step).
            if !have_f {
                system.rhs(t, y, &mut f);
                have_f = true;
            }
            if let Some(r) = events.rate(i, t, y, &f) {
                *s = sign_of(r);
            }
        }
    }
    if n_closed >= 2 {
        if !have_f {
            system.rhs(t, y, &mut f);
        }
        simultaneous_contacts(events, t, y, &f, &closed)?;
    }
    Ok(sides)
}

/// The far side of an impact event (a resetting event with a direction): the side its
/// crossings are reset away from, `+1` for a rising one, `−1` for a falling one; 0 for
/// any other event.
fn far_side<T: Real, const N: usize, E: EventSet<T, N>>(events: &E, i: usize) -> i8 {
    if !events.resets(i) {
        return 0;
    }
    match events.direction(i) {
        Direction::Rising => 1,
        Direction::Falling => -1,
        Direction::Either => 0,
    }
}

/// A simultaneous impact at the start: of the impact events `closed` at `(t, y)` (two or
/// more; a closed event has `g = 0` or `g` on its far side: the bodies touch), one whose
/// rate `ġ` (the field `f`) points to its far side is being struck while another contact
/// is closed. The event-driven method locates one crossing at a time and resets it; for
/// contacts closed at once the outcome depends on how the impulses are shared (Newton's
/// cradle of touching balls: Moreau's problem of all contacts at once moves the struck
/// balls as one body, a sequence of impacts passes the momentum along), so the run does not
/// choose and names the time-stepper. Contacts that are closed at rest (`ġ = 0`, a stack at
/// rest) are not struck and start as before; a single closed contact is left to the scan
/// (an impact, or sticking).
///
/// # Errors
/// [`EventError::SimultaneousContacts`] with the first event struck and the first other
/// closed one.
fn simultaneous_contacts<T: Real, const N: usize, E: EventSet<T, N>>(
    events: &E,
    t: T,
    y: &SVector<T, N>,
    f: &SVector<T, N>,
    closed: &[bool; MAX_EVENTS],
) -> Result<()> {
    let closed_ones = || (0..E::LEN).filter(|&i| closed[i]);
    for i in closed_ones() {
        let Some(r) = events.rate(i, t, y, f) else {
            continue;
        };
        if sign_of(r) != 0 && sign_of(r) == far_side(events, i) {
            let other = closed_ones().find(|&j| j != i).unwrap_or(i);
            return Err(EventError::SimultaneousContacts {
                t: to_f64(t),
                moving: i,
                other,
                rate: to_f64(r),
            }
            .into());
        }
    }
    Ok(())
}

impl<T: Real, const N: usize, S: Dynamics<T, N>, E: EventSet<T, N>, D: DenseOutput<T, N>>
    Scan<'_, T, N, S, E, D>
{
    /// The events and observer calls of the step just taken: its crossings in time order
    /// ([`crossings`](Self::crossings)), the sticking check, then the observer's view of
    /// the rest of the step. Returns how the run ends, if it ends here.
    pub(crate) fn scan_step<O: Observer<T, N>>(
        &mut self,
        sides: &mut Sides,
        observer: &mut O,
    ) -> Result<Option<Termination>> {
        if let Some(positive) = self.quiet(sides) {
            // What the scan below does when it finds nothing: the whole step to the
            // observer, then each event's side to that of the step's end.
            let stop = observer.on_step(&StepView::whole(self.dense)) == Control::Stop;
            for (i, &p) in positive.iter().enumerate().take(E::LEN) {
                sides.quiet_step(i, p);
            }
            return Ok(stop.then_some(Termination::ObserverStopped));
        }
        let mut scan = self.start_scan(sides)?;
        let (t_lo, y_lo) = match self.crossings(&mut scan, sides, observer)? {
            Crossings::Through(t_lo, y_lo) => (t_lo, y_lo),
            // The state was reset or cut at an event: the next step starts there.
            Crossings::Cut => return Ok(None),
            Crossings::End(t) => return Ok(Some(t)),
        };
        self.check_sticking(&scan, sides, t_lo, y_lo, observer)?;
        let dense = self.dense;
        let view = StepView {
            t0: t_lo,
            t1: scan.t1,
            y0: y_lo,
            y1: scan.y1,
            dense,
        };
        let stop = observer.on_step(&view) == Control::Stop;
        for (i, s) in sides.side.iter_mut().enumerate().take(E::LEN) {
            if scan.g_end[i] != T::zero() {
                *s = sign_of(scan.g_end[i]);
            }
        }
        Ok(stop.then_some(Termination::ObserverStopped))
    }

    /// Whether the step is quiet for every event ([`QuietEnds::of`] of its ends and
    /// [`Sides::is_quiet_with`]): then the scan would find nothing and only move the
    /// sides; `Some` with each event's side at the end (`g > 0`). Any doubt (a value that
    /// is not finite, a zero, a grazing pair, an unknown side, interior samples, sticking)
    /// is `None`, and the full scan decides.
    fn quiet(&self, sides: &Sides) -> Option<[bool; MAX_EVENTS]> {
        let dense = self.dense;
        let (t0, t1) = dense.span();
        let (y0, y1) = dense.endpoints();
        let (f0, f1) = dense.end_derivatives();
        let mut positive = [false; MAX_EVENTS];
        for (i, p) in positive.iter_mut().enumerate().take(E::LEN) {
            let g = (self.events.value(i, t0, y0), self.events.value(i, t1, y1));
            let r = (
                self.events.rate(i, t0, y0, f0),
                self.events.rate(i, t1, y1, f1),
            );
            let q = QuietEnds::of(g, r)?;
            if !sides.is_quiet_with(self.events, i, q) {
                return None;
            }
            *p = q.positive;
        }
        Some(positive)
    }

    /// Every event's values and rates at both ends of the step and its first crossing.
    fn start_scan(&self, sides: &mut Sides) -> Result<StepScan<T, N>> {
        let dense = self.dense;
        let (ts0, ts1) = dense.span();
        let (y_start, y_end) = dense.endpoints();
        let (f_start, f_end) = dense.end_derivatives();
        let (y_start, y_end, f_start, f_end) = (*y_start, *y_end, *f_start, *f_end);
        let mut scan = StepScan {
            t0: ts0,
            t1: ts1,
            y0: y_start,
            y1: y_end,
            g_end: [T::zero(); MAX_EVENTS],
            r_end: [None; MAX_EVENTS],
            found: [None; MAX_EVENTS],
        };
        for i in 0..E::LEN {
            let g0 = self.events.value(i, ts0, &y_start);
            let ge = self.events.value(i, ts1, &y_end);
            scan.g_end[i] = ge;
            if !(g0.is_finite() && ge.is_finite()) {
                let (t, g) = if g0.is_finite() { (ts1, ge) } else { (ts0, g0) };
                return Err(non_finite(i, t, g));
            }
            if sides.side[i] == 0 {
                // Started on the surface with no rate: the side is where it goes.
                sides.side[i] = if ge != T::zero() { sign_of(ge) } else { 1 };
            }
            let st_g = if g0 == T::zero() {
                signed_tiny(sides.side[i])
            } else {
                g0
            };
            let st_r = self.events.rate(i, ts0, &y_start, &f_start);
            scan.r_end[i] = self.events.rate(i, ts1, &y_end, &f_end);
            scan.found[i] = self.find_crossing(i, ts0, st_g, st_r, ts1, ge, scan.r_end[i]);
        }
        Ok(scan)
    }

    /// The step's crossings, earliest first: the observer's view up to each accepted one,
    /// its record, its reset (which ends the step there), a restart, a terminal event or
    /// an observer's stop. Returns where the step's last piece starts if it goes on to the
    /// step's end.
    fn crossings<O: Observer<T, N>>(
        &mut self,
        scan: &mut StepScan<T, N>,
        sides: &mut Sides,
        observer: &mut O,
    ) -> Result<Crossings<T, N>> {
        let n_ev = E::LEN;
        let mut t_lo = scan.t0;
        let mut y_lo = scan.y0;
        loop {
            let Some((i, c)) = scan.earliest(n_ev) else {
                return Ok(Crossings::Through(t_lo, y_lo));
            };
            // Where the scan of event i resumes (None: no further crossing this step).
            scan.found[i] = match c.resume {
                Some((tr, gr)) => {
                    self.find_crossing(i, tr, gr, None, scan.t1, scan.g_end[i], scan.r_end[i])
                }
                None => None,
            };
            let was_armed = sides.armed[i];
            sides.armed[i] = true;
            sides.side[i] = if c.rising { 1 } else { -1 };
            if !was_armed || !self.events.direction(i).accepts(c.rising) {
                // Re-arming crossing (the exit after a reset) or an unwanted direction.
                continue;
            }
            let tc = c.t;
            let dense = self.dense;
            let mut yc = SVector::zeros();
            dense.interpolate_unchecked(tc, &mut yc);
            let view = StepView {
                t0: t_lo,
                t1: tc,
                y0: y_lo,
                y1: yc,
                dense,
            };
            let stop_obs = observer.on_step(&view) == Control::Stop;
            let direction = if c.rising {
                Direction::Rising
            } else {
                Direction::Falling
            };
            self.count_event(i, tc, &yc)?;
            let terminal = self.events.is_terminal(i);
            if self.events.resets(i) {
                let stop_ev = self.impact(i, (tc, &yc), c.rising, sides, observer)?;
                return Ok(if terminal {
                    Crossings::End(Termination::TerminalEvent(i))
                } else if stop_obs || stop_ev {
                    Crossings::End(Termination::ObserverStopped)
                } else {
                    Crossings::Cut
                });
            }
            let rec = EventRecord {
                index: i,
                t: tc,
                y: yc,
                y_after: None,
                direction,
            };
            let stop_ev = observer.on_event(&rec) == Control::Stop;
            if self.events.restarts(i) && !(terminal || stop_obs || stop_ev) {
                // A switching point: cut the step here and start the next one on it.
                *self.restart = Some((tc, yc));
                return Ok(Crossings::Cut);
            }
            if terminal || stop_obs || stop_ev {
                // Rewind the stepper to the event.
                *self.restart = Some((tc, yc));
                return Ok(Crossings::End(if terminal {
                    Termination::TerminalEvent(i)
                } else {
                    Termination::ObserverStopped
                }));
            }
            t_lo = tc;
            y_lo = yc;
        }
    }

    /// Counts event `i` at `(tc, yc)` in the history; when the Zeno guard trips, leaves the
    /// simulation at the event (after its reset, so that the caller can change the model
    /// and continue from there) and returns [`EventError::Zeno`].
    fn count_event(&mut self, i: usize, tc: T, yc: &SVector<T, N>) -> Result<()> {
        self.stats.events += 1;
        let Some((count, last)) = self.history.push(tc, self.zeno) else {
            return Ok(());
        };
        let mut ya = *yc;
        if self.events.resets(i) {
            self.events.apply_reset(i, tc, &mut ya);
        }
        *self.restart = Some((tc, ya));
        Err(EventError::Zeno {
            t: to_f64(tc),
            count,
            last_interval: to_f64(last),
            state: ya.iter().map(|&v| to_f64(v)).collect(),
        }
        .into())
    }

    /// The crossing of resetting event `i` at `(tc, yc)` (`rising` its direction): its
    /// record with the state after the reset, which the step restarts from. Returns
    /// whether the observer stopped the run.
    ///
    /// An impact moves into the surface. A located crossing where the rate does not (the
    /// far end of a bracket past the top of a graze of zero normal velocity: the arrival of
    /// a chattering sequence) is no impact: the body stays on the surface, reported as
    /// sticking ([`EventError::Sticking`]), not as an event.
    #[inline(always)]
    fn impact<O: Observer<T, N>>(
        &mut self,
        i: usize,
        (tc, yc): (T, &SVector<T, N>),
        rising: bool,
        sides: &mut Sides,
        observer: &mut O,
    ) -> Result<bool> {
        let mut fc = SVector::zeros();
        self.system.rhs(tc, yc, &mut fc);
        self.stats.rhs_evals += 1;
        let into = if rising { T::one() } else { -T::one() };
        if let Some(r) = self.events.rate(i, tc, yc, &fc) {
            if !(into * r > T::zero()) {
                self.stats.events -= 1;
                *self.restart = Some((tc, *yc));
                return Err(EventError::Sticking {
                    index: i,
                    t: to_f64(tc),
                    depth: to_f64(self.events.value(i, tc, yc).abs()),
                    state: yc.iter().map(|&v| to_f64(v)).collect(),
                }
                .into());
            }
        }
        let mut ya = *yc;
        self.events.apply_reset(i, tc, &mut ya);
        let rec = EventRecord {
            index: i,
            t: tc,
            y: *yc,
            y_after: Some(ya),
            direction: if rising {
                Direction::Rising
            } else {
                Direction::Falling
            },
        };
        let stop = observer.on_event(&rec) == Control::Stop;
        *self.restart = Some((tc, ya));
        self.after_reset(i, tc, &ya, sides);
        Ok(stop)
    }

    /// The sides after event `i`'s reset to `ya` at `tc`; event `i` is disarmed if the
    /// reset left the state on the far side while moving back out.
    fn after_reset(&mut self, i: usize, tc: T, ya: &SVector<T, N>, sides: &mut Sides) {
        let mut fa = SVector::zeros();
        self.system.rhs(tc, ya, &mut fa);
        self.stats.rhs_evals += 1;
        for (j, s) in sides.side.iter_mut().enumerate().take(E::LEN) {
            let g = self.events.value(j, tc, ya);
            if g != T::zero() {
                *s = sign_of(g);
            }
            if j == i {
                // Left on the far side but moving back out: disarmed until it has
                // crossed back.
                let r = self.events.rate(j, tc, ya, &fa).unwrap_or(T::zero());
                sides.armed[j] = !(g != T::zero() && r != T::zero() && sign_of(g) != sign_of(r));
                if g == T::zero() && r != T::zero() {
                    *s = sign_of(r);
                }
            }
        }
    }

    /// Sticking: an event disarmed after a reset (or an impact event on its far side),
    /// still on the far side at the step end and moving deeper again, never left the
    /// surface: the reset could not separate the trajectory from it. Never silent: stops
    /// where it turned (the extremum of g on the dense output), with the state to go on
    /// from, and an [`EventError::Sticking`].
    fn check_sticking<O: Observer<T, N>>(
        &mut self,
        scan: &StepScan<T, N>,
        sides: &Sides,
        t_lo: T,
        y_lo: SVector<T, N>,
        observer: &mut O,
    ) -> Result<()> {
        for i in 0..E::LEN {
            // For an impact (a resetting event with a direction) the far side is the
            // wrong side at any step end: its crossings are reset away from it.
            let wrong_side = match self.events.direction(i) {
                Direction::Rising => 1,
                Direction::Falling => -1,
                Direction::Either => 0,
            };
            let (ge, re) = (scan.g_end[i], scan.r_end[i]);
            let stuck = !sides.armed[i] || (self.events.resets(i) && sign_of(ge) == wrong_side);
            if !(stuck
                && ge != T::zero()
                && re.is_some_and(|r| r != T::zero() && sign_of(r) == sign_of(ge)))
            {
                continue;
            }
            let dense = self.dense;
            let tol = self
                .event_tol
                .max(lit::<T>(4.0) * T::default_epsilon() * scan.t1.abs());
            let sg = if ge > T::zero() { T::one() } else { -T::one() };
            let events = &self.events;
            let (te, _) = crate::roots::golden_max(
                |t| {
                    let mut y = SVector::<T, N>::zeros();
                    dense.interpolate_unchecked(t, &mut y);
                    -sg * events.value(i, t, &y)
                },
                t_lo,
                scan.t1,
                tol,
            );
            let mut ye = SVector::zeros();
            dense.interpolate_unchecked(te, &mut ye);
            let view = StepView {
                t0: t_lo,
                t1: te,
                y0: y_lo,
                y1: ye,
                dense,
            };
            observer.on_step(&view);
            let depth = self.events.value(i, te, &ye).abs();
            *self.restart = Some((te, ye));
            return Err(EventError::Sticking {
                index: i,
                t: to_f64(te),
                depth: to_f64(depth),
                state: ye.iter().map(|&v| to_f64(v)).collect(),
            }
            .into());
        }
        Ok(())
    }

    /// The earliest crossing (any direction) of event `i` in `(t_lo, t1]`, starting from
    /// `g_lo ≠ 0` (rate `r_lo` if known) and ending at `g1` (rate `r1`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn find_crossing(
        &self,
        i: usize,
        t_lo: T,
        g_lo: T,
        r_lo: Option<T>,
        t1: T,
        g1: T,
        r1: Option<T>,
    ) -> Option<Crossing<T>> {
        let ev = &self.events;
        let dense = self.dense;
        let tol = self
            .event_tol
            .max(lit::<T>(4.0) * T::default_epsilon() * t1.abs());
        let g_at = |t: T| {
            let mut y = SVector::<T, N>::zeros();
            dense.interpolate_unchecked(t, &mut y);
            ev.value(i, t, &y)
        };
        // Interior samples (grazing safety for functions without a rate).
        let k = ev.interior_samples(i);
        if k > 0 {
            let mut ta = t_lo;
            let mut ga = g_lo;
            for m in 1..=(k + 1) {
                let (tb, gb) = if m == k + 1 {
                    (t1, g1)
                } else {
                    let tb = t_lo + (t1 - t_lo) * lit::<T>(m as f64 / (k as f64 + 1.0));
                    (tb, g_at(tb))
                };
                if !gb.is_finite() {
                    // Not a crossing (the step ends are checked to be finite).
                    continue;
                }
                if gb != T::zero() && sign_of(gb) != sign_of(ga) {
                    let (tc, _) = locate(g_at, ta, tb, ga, gb, tol);
                    let resume = if m == k + 1 { None } else { Some((tb, gb)) };
                    return Some(Crossing {
                        t: tc,
                        rising: gb > T::zero(),
                        resume,
                    });
                }
                if gb != T::zero() {
                    ta = tb;
                    ga = gb;
                }
            }
            return None;
        }
        let rate_lo = || {
            r_lo.or_else(|| {
                let mut y = SVector::zeros();
                dense.interpolate_unchecked(t_lo, &mut y);
                let mut f = SVector::zeros();
                self.system.rhs(t_lo, &y, &mut f);
                ev.rate(i, t_lo, &y, &f)
            })
        };
        // A grazing pair that cannot reach the surface: both ends farther from it than
        // the function can stray from its chord on the step (from the start of the step
        // only: a chord from a point inside it is not the one bounded).
        let out_of_reach = || {
            let (t0, t_end) = dense.span();
            if t_lo != t0 || t1 != t_end {
                return false;
            }
            let Some((dev, mag)) = dense.chord_bounds() else {
                return false;
            };
            let Some((d, a)) = ev.chord_bounds(i, t0, t1, &dev, &mag) else {
                return false;
            };
            clear_of_chord(g_lo, g1, d, a)
        };
        crossing_between(g_at, rate_lo, out_of_reach, tol, t_lo, g_lo, t1, g1, r1)
    }
}

/// The earliest crossing of `g` (its value on the step's dense output: `g_at`) in
/// `(t_lo, t1]`, from `g_lo ≠ 0` to `g1` with the rate `r1` at `t1`: a sign change of the
/// ends, located by the bracketing solver; else, with the same sign at both ends (or
/// `g1 = 0`), a grazing pair when the rates show an interior extremum that reaches the
/// other side (`rate_lo`, the rate at `t_lo`, is evaluated only then): the extremum by
/// golden-section search, the crossing before it, and the extremum as where the scan
/// resumes; the search is skipped where `out_of_reach` shows that no point of the step
/// reaches the surface (the search would find none: the same result).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn crossing_between<T: Real>(
    g_at: impl Fn(T) -> T + Copy,
    rate_lo: impl FnOnce() -> Option<T>,
    out_of_reach: impl FnOnce() -> bool,
    tol: T,
    t_lo: T,
    g_lo: T,
    t1: T,
    g1: T,
    r1: Option<T>,
) -> Option<Crossing<T>> {
    let s = sign_of(g_lo);
    if g1 != T::zero() && sign_of(g1) != s {
        let (tc, _) = locate(g_at, t_lo, t1, g_lo, g1, tol);
        return Some(Crossing {
            t: tc,
            rising: g1 > T::zero(),
            resume: None,
        });
    }
    let (Some(r_lo), Some(r1)) = (rate_lo(), r1) else {
        return None;
    };
    let towards = if s > 0 {
        r_lo < T::zero()
    } else {
        r_lo > T::zero()
    };
    let away = if s > 0 {
        r1 > T::zero()
    } else {
        r1 < T::zero()
    };
    if !(towards && (away || g1 == T::zero())) || out_of_reach() {
        return None;
    }
    let sg = if s > 0 { T::one() } else { -T::one() };
    let (te, neg) = crate::roots::golden_max(|t| -sg * g_at(t), t_lo, t1, tol);
    let ge = -neg * sg;
    if ge == T::zero() || sign_of(ge) == s {
        return None;
    }
    let (tc, _) = locate(g_at, t_lo, te, g_lo, ge, tol);
    Some(Crossing {
        t: tc,
        rising: ge > T::zero(),
        resume: Some((te, ge)),
    })
}

/// Whether `g` keeps the side of `g0` on the whole step, given the chord bounds `(d, a)`
/// of its values `g0`, `g1` at the ends ([`EventFunction::chord_bounds`]): both ends on
/// one side, farther from 0 than `d` and a rounding allowance (`10⁻¹²·a` plus `10⁻⁹·d`,
/// thousands of times the rounding of the values computed on the dense output), so that
/// every value computed inside keeps the sign.
///
/// [`EventFunction::chord_bounds`]: crate::event::EventFunction::chord_bounds
#[inline(always)]
fn clear_of_chord<T: Real>(g0: T, g1: T, d: T, a: T) -> bool {
    let need = d + lit::<T>(1e-9) * d + lit::<T>(1e-12) * a;
    let s = if g0 > T::zero() { T::one() } else { -T::one() };
    // False for NaN bounds (every comparison with NaN is).
    need.is_finite() && s * g0 > need && s * g1 > need
}

fn non_finite<T: Real>(index: usize, t: T, g: T) -> RunError {
    EventError::NonFinite {
        index,
        t: to_f64(t),
        value: to_f64(g),
    }
    .into()
}

/// Each event's side of its surface (+1/−1; 0 = not known yet, for a start exactly on it,
/// used when g is exactly zero at a step boundary) and whether it is armed (false right
/// after a reset that left the state on the far side while moving back out). Carried
/// from step to step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sides {
    pub(crate) side: [i8; MAX_EVENTS],
    pub(crate) armed: [bool; MAX_EVENTS],
}

impl Sides {
    /// Whether [`Scan::scan_step`] would find nothing in a step where event `i` goes from
    /// `g0` to `g1` with rates `r0`, `r1` at the ends (the event's own values), given the
    /// ends' part `q = QuietEnds::of((g0, g1), (r0, r1))`: both ends finite and on one
    /// side of the surface, no grazing pair in the rates (one end moving towards the
    /// surface and the other away) — that is `q` — and here a known side, no interior
    /// samples, and no sticking (the conditions of `start_scan`, `crossing_between` and
    /// `check_sticking`, in which any doubt means "not quiet"): not disarmed, or on the
    /// wrong side of a resetting event, while moving into its side. The scan of such a
    /// step only moves the side to that of the ends ([`quiet_step`](Self::quiet_step));
    /// the ensemble skips it where every event's step is quiet, with `q` from
    /// [`QuietEnds::lanes`] and this rule in lanes ([`LaneSides::quiet`], which the tests
    /// hold to it); the driver skips its own scan of such a step ([`Scan::quiet`]).
    #[inline(always)]
    pub(crate) fn is_quiet_with<T: Real, const N: usize, E: EventSet<T, N>>(
        &self,
        events: &E,
        i: usize,
        q: QuietEnds,
    ) -> bool {
        if self.side[i] == 0 || events.interior_samples(i) > 0 {
            return false;
        }
        let s = if q.positive { 1 } else { -1 };
        let wrong_side = match events.direction(i) {
            Direction::Rising => 1,
            Direction::Falling => -1,
            Direction::Either => 0,
        };
        let stuck = !self.armed[i] || (events.resets(i) && s == wrong_side);
        !(stuck && q.rate_on_side)
    }

    /// What the scan of a quiet step ([`is_quiet_with`](Self::is_quiet_with)) does to
    /// event `i`: its side becomes that of the step's ends (`positive`: `g > 0` there).
    /// The ensemble's form: [`LaneSides::quiet_step`].
    #[inline(always)]
    pub(crate) fn quiet_step(&mut self, i: usize, positive: bool) {
        self.side[i] = if positive { 1 } else { -1 };
    }
}

/// The [`Sides`] of up to 32 trajectories as bit masks (bit `l` for trajectory `l`, the
/// ensemble's lane `l`): the lane form of the quiet-step rule, so that the ensemble decides
/// which lanes' steps are quiet, and moves their sides, with a few bit operations per
/// event instead of a visit to each lane.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LaneSides {
    /// Per event: the side is known (`side ≠ 0`).
    known: [u32; MAX_EVENTS],
    /// Per event: the side is `+1`.
    positive: [u32; MAX_EVENTS],
    /// Per event: armed.
    armed: [u32; MAX_EVENTS],
}

impl LaneSides {
    /// Lane `l`'s sides.
    #[inline(always)]
    pub(crate) fn get(&self, l: usize) -> Sides {
        let bit = |m: u32| m >> l & 1 == 1;
        Sides {
            side: core::array::from_fn(|e| match (bit(self.known[e]), bit(self.positive[e])) {
                (false, _) => 0,
                (true, true) => 1,
                (true, false) => -1,
            }),
            armed: core::array::from_fn(|e| bit(self.armed[e])),
        }
    }

    /// Sets lane `l`'s sides.
    #[inline(always)]
    pub(crate) fn set(&mut self, l: usize, sides: &Sides) {
        let put = |m: &mut u32, on: bool| *m = (*m & !(1 << l)) | (u32::from(on) << l);
        for e in 0..MAX_EVENTS {
            put(&mut self.known[e], sides.side[e] != 0);
            put(&mut self.positive[e], sides.side[e] > 0);
            put(&mut self.armed[e], sides.armed[e]);
        }
    }

    /// The lanes among `lanes` where [`Sides::is_quiet_with`] holds for event `i`, given the
    /// masks of [`QuietEnds::lanes`] (`[ends, positive, rate_on_side]`): the ends allow a
    /// quiet step and the lane's side and arming do.
    #[inline(always)]
    pub(crate) fn quiet<T: Real, const N: usize, E: EventSet<T, N>>(
        &self,
        events: &E,
        i: usize,
        lanes: u32,
        [ends, positive, rate_on_side]: [u32; 3],
    ) -> u32 {
        if events.interior_samples(i) > 0 {
            return 0;
        }
        // On the wrong side of a resetting event (its side is that of the ends).
        let wrong_side = match (events.resets(i), events.direction(i)) {
            (false, _) | (true, Direction::Either) => 0,
            (true, Direction::Rising) => positive,
            (true, Direction::Falling) => !positive,
        };
        let stuck = !self.armed[i] | wrong_side;
        lanes & ends & self.known[i] & !(stuck & rate_on_side)
    }

    /// [`Sides::quiet_step`] of event `i` in the lanes of `lanes`: their side becomes that
    /// of their step's ends (`positive`: `g > 0` there).
    #[inline(always)]
    pub(crate) fn quiet_step(&mut self, i: usize, lanes: u32, positive: u32) {
        self.known[i] |= lanes;
        self.positive[i] = (self.positive[i] & !lanes) | (positive & lanes);
    }

    /// Every mask mapped by `f` (the ensemble moves lanes with it).
    pub(crate) fn map(&self, f: impl Fn(u32) -> u32) -> Self {
        Self {
            known: self.known.map(&f),
            positive: self.positive.map(&f),
            armed: self.armed.map(&f),
        }
    }
}

/// What a quiet step's ends say about one event ([`QuietEnds::of`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct QuietEnds {
    /// The side of both ends: `g > 0` (else `g < 0`).
    pub(crate) positive: bool,
    /// The rate at the end is known, non-zero and points into that side (`ġ > 0` on the
    /// positive side): moving away from the surface.
    pub(crate) rate_on_side: bool,
}

impl QuietEnds {
    /// The ends' part of [`Sides::is_quiet_with`]: `None` unless `g0`, `g1` are finite,
    /// non-zero and of one sign, and the rates (where both are known) are not a grazing
    /// pair (the start moving towards the surface, the end away from it). The rule as the
    /// scan states it, for one lane (the driver's quiet steps, [`Scan::quiet`]); the
    /// ensemble uses its lane form [`lanes`](Self::lanes), which the tests hold to it.
    #[inline(always)]
    pub(crate) fn of<T: Real>((g0, g1): (T, T), (r0, r1): (Option<T>, Option<T>)) -> Option<Self> {
        if !(g0.is_finite() && g1.is_finite()) || g0 == T::zero() || g1 == T::zero() {
            return None;
        }
        let s = sign_of(g0);
        if sign_of(g1) != s {
            return None;
        }
        let positive = s > 0;
        let towards = |r: T| {
            if positive {
                r < T::zero()
            } else {
                r > T::zero()
            }
        };
        let away = |r: T| {
            if positive {
                r > T::zero()
            } else {
                r < T::zero()
            }
        };
        if let (Some(r0), Some(r1)) = (r0, r1) {
            if towards(r0) && away(r1) {
                return None;
            }
        }
        Some(Self {
            positive,
            rate_on_side: r1.is_some_and(away),
        })
    }

    /// [`of`](Self::of) in every lane, as masks: the lanes where it is `Some`, their
    /// `positive` and their `rate_on_side` (the last two meaningful where the first is
    /// set). Where the first mask is set, [`of`](Self::of) of the same values is `Some`
    /// with the same fields; it may be clear where [`of`](Self::of) is `Some` only when
    /// `g0·g1` under- or overflows (one rounded product tests both ends' sign and
    /// finiteness). A lane so reported not quiet goes through the whole scan, which finds
    /// the same nothing: the answer is conservative, never wrong.
    #[inline(always)]
    pub(crate) fn lanes<V: Lanes>((g0, g1): (V, V), (r0, r1): (Option<V>, Option<V>)) -> [V; 3] {
        let z = V::splat(0.0);
        let p = g0 * g1;
        // `p ≤ MAX` rather than `p < ∞` (the same lanes): the compiler turned the pair
        // `0 < p < ∞` into a class test of the bits, evaluated lane by lane in scalar code.
        let mut quiet = p.gt(z) & p.le(V::splat(f64::MAX));
        let positive = g0.gt(z);
        let Some(r1) = r1 else {
            return [quiet, positive, z];
        };
        // Away from the surface at the end: into the side.
        let away = (positive & r1.gt(z)) | (!positive & r1.lt(z));
        if let Some(r0) = r0 {
            // Towards it at the start: a grazing pair.
            let towards = (positive & r0.lt(z)) | (!positive & r0.gt(z));
            quiet = quiet & !(towards & away);
        }
        [quiet, positive, away]
    }
}

/// One step's event data: its ends, each event's value and rate at the end, and the next
/// crossing found for each (cached while earlier crossings are handled).
#[derive(Debug, Clone, Copy)]
struct StepScan<T: Real, const N: usize> {
    t0: T,
    t1: T,
    y0: SVector<T, N>,
    y1: SVector<T, N>,
    g_end: [T; MAX_EVENTS],
    r_end: [Option<T>; MAX_EVENTS],
    found: [Option<Crossing<T>>; MAX_EVENTS],
}

impl<T: Real, const N: usize> StepScan<T, N> {
    /// The earliest crossing found among the first `n` events, with its event's index (the
    /// lowest index among equal times).
    fn earliest(&self, n: usize) -> Option<(usize, Crossing<T>)> {
        let mut best: Option<(usize, Crossing<T>)> = None;
        for (i, f) in self.found.iter().enumerate().take(n) {
            if let Some(c) = f {
                if best.is_none_or(|(_, b)| c.t < b.t) {
                    best = Some((i, *c));
                }
            }
        }
        best
    }
}

/// How a step's crossings ended.
enum Crossings<T: Real, const N: usize> {
    /// No crossing stopped the step: its last piece starts at this time and state.
    Through(T, SVector<T, N>),
    /// The state was reset or restarted at an event: the next step starts there.
    Cut,
    /// The run ends.
    End(Termination),
}

/// A crossing found on a step.
#[derive(Debug, Clone, Copy)]
struct Crossing<T> {
    t: T,
    rising: bool,
    /// Where to resume scanning this event after it (`None`: nothing more this step).
    resume: Option<(T, T)>,
}

#[inline(always)]
pub(crate) fn signed_tiny<T: Real>(side: i8) -> T {
    let tiny = T::default_epsilon() * T::default_epsilon();
    if side < 0 { -tiny } else { tiny }
}

#[inline(always)]
pub(crate) fn sign_of<T: Real>(x: T) -> i8 {
    if x > T::zero() {
        1
    } else if x < T::zero() {
        -1
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::{LaneSides, QuietEnds, Sides, clear_of_chord};
    use crate::event::{
        Direction, Event, EventFunction, EventSet, Gap, Level, MAX_EVENTS, Restitution,
    };
    use crate::excite::Harmonic;
    use crate::integrate::{DenseOutput, Dopri5, Stepper, Tolerances};
    use crate::lanes::{F64x4, Lanes};
    use crate::model::Coordinate;
    use crate::testing::HarmonicOscillator;
    use nalgebra::SVector;

    /// Where the chord bounds rule a step out, every value of the event function on the
    /// step's dense output keeps the ends' side (2 001 points a step), and the function
    /// stays within `d` of its chord: an oscillator of period 2π against a surface that
    /// moves with amplitude 0.3 at ω = 3, over 400 steps of `Dopri5` at a loose tolerance
    /// (long steps, large deviations) and a tight one. Grazing pairs must be among the
    /// steps ruled out, and crossings among those not.
    #[test]
    fn chord_bounds_rule_out_only_steps_that_stay_clear() {
        let sys = HarmonicOscillator::new(1.0).unwrap();
        let surface = Harmonic::new(0.3, 3.0, 0.5).unwrap();
        let gap = Gap::above(Coordinate::<f64, 1>::dof(0).unwrap(), surface);
        for rtol in [1e-3, 1e-9] {
            let tol = Tolerances::new(rtol, rtol * 1e-2).unwrap();
            let mut st = Dopri5::new(tol);
            st.reset_state(0.0, SVector::from([1.0, 0.0]));
            let (mut ruled_out, mut grazing, mut kept_crossings) = (0, 0, 0);
            for _ in 0..400 {
                st.step(&sys, f64::INFINITY).unwrap();
                let d = st.dense();
                let (t0, t1) = d.span();
                let (y0, y1) = d.endpoints();
                let (f0, f1) = d.end_derivatives();
                let g0 = EventFunction::<f64, 2>::value(&gap, t0, y0);
                let g1 = EventFunction::<f64, 2>::value(&gap, t1, y1);
                let (dev, mag) = d.chord_bounds().unwrap();
                let (dg, a) = gap.chord_bounds(t0, t1, &dev, &mag).unwrap();
                let values: Vec<(f64, f64)> = (0..=2000)
                    .map(|k| {
                        let t = t0 + (t1 - t0) * k as f64 / 2000.0;
                        let mut y = SVector::zeros();
                        d.interpolate_unchecked(t, &mut y);
                        (t, EventFunction::<f64, 2>::value(&gap, t, &y))
                    })
                    .collect();
                let crosses = values.iter().any(|&(_, g)| g * g0 <= 0.0);
                if clear_of_chord(g0, g1, dg, a) {
                    ruled_out += 1;
                    assert!(!crosses, "a step ruled out holds a crossing: [{t0}, {t1}]");
                    let r0 = gap.rate(t0, y0, f0).unwrap();
                    let r1 = gap.rate(t1, y1, f1).unwrap();
                    if r0 * g0 < 0.0 && r1 * g0 > 0.0 {
                        grazing += 1;
                    }
                } else if crosses {
                    kept_crossings += 1;
                }
                for &(t, g) in &values {
                    let chord = g0 + (g1 - g0) * (t - t0) / (t1 - t0);
                    assert!((g - chord).abs() <= dg * (1.0 + 1e-9) + 1e-12 * a);
                }
            }
            assert!(ruled_out > 100, "rtol {rtol}: {ruled_out} steps ruled out");
            assert!(grazing > 0, "rtol {rtol}: no grazing pair ruled out");
            assert!(kept_crossings > 0, "rtol {rtol}: no crossing in 400 steps");
        }
    }

    /// `LaneSides::quiet` and `quiet_step` are `Sides::is_quiet_with` and `quiet_step` lane
    /// for lane: every side (unknown, −, +), arming, ends' answer and event (with and
    /// without a reset, each direction, with interior samples), 30 lanes at once; and
    /// `get`, `set` and `map` carry the sides unchanged.
    #[test]
    fn lane_sides_are_the_scalar_rule() {
        let level = Level::new(0, 0.0).unwrap();
        let reset = Restitution::new(1, 0.5).unwrap();
        let dirs = [Direction::Rising, Direction::Falling, Direction::Either];
        // Every lane's (side, armed, ends, positive, rate_on_side).
        let mut lanes = Vec::new();
        for side in [-1i8, 0, 1] {
            for armed in [false, true] {
                for (ends, positive, on) in [
                    (false, false, false),
                    (true, false, false),
                    (true, true, false),
                    (true, false, true),
                    (true, true, true),
                ] {
                    lanes.push((side, armed, ends, positive, on));
                }
            }
        }
        let mut quiet_seen = 0;
        for chunk in lanes.chunks(30) {
            let mut masks = LaneSides::default();
            let mut q = [0u32; 3];
            for (l, &(side, armed, ends, positive, on)) in chunk.iter().enumerate() {
                let mut sides = Sides {
                    side: [0; MAX_EVENTS],
                    armed: [true; MAX_EVENTS],
                };
                (sides.side[0], sides.armed[0]) = (side, armed);
                masks.set(l, &sides);
                for (m, b) in q.iter_mut().zip([ends, positive, on]) {
                    *m |= u32::from(b) << l;
                }
            }
            let all = (1u32 << chunk.len()) - 1;
            for dir in dirs {
                for samples in [0, 3] {
                    let plain = Event::new(level, dir).with_interior_samples(samples);
                    let resetting = plain.with_reset(reset);
                    quiet_seen += rule(&plain, &masks, all, q, chunk);
                    quiet_seen += rule(&resetting, &masks, all, q, chunk);
                }
            }
            // The quiet step moves the side to the ends' and keeps the arming.
            let mut moved = masks;
            moved.quiet_step(0, all, q[1]);
            for (l, &(side, armed, _, positive, _)) in chunk.iter().enumerate() {
                let mut want = Sides {
                    side: [0; MAX_EVENTS],
                    armed: [true; MAX_EVENTS],
                };
                (want.side[0], want.armed[0]) = (side, armed);
                assert_eq!(masks.get(l).side, want.side);
                assert_eq!(masks.get(l).armed, want.armed);
                want.quiet_step(0, positive);
                assert_eq!(moved.get(l).side, want.side);
                assert_eq!(moved.get(l).armed, want.armed);
            }
            // Lanes 5, 0, 7 moved to 0, 1, 2.
            let g = masks.map(|m| (m >> 5 & 1) | (m & 1) << 1 | (m >> 7 & 1) << 2);
            for (k, l) in [5, 0, 7].into_iter().enumerate() {
                assert_eq!(g.get(k).side, masks.get(l).side);
                assert_eq!(g.get(k).armed, masks.get(l).armed);
            }
            assert_eq!(g.get(3).side, [0; MAX_EVENTS]);
        }
        // The rule is not trivially false.
        assert!(quiet_seen > 20, "{quiet_seen}");
    }

    /// The mask rule held to the scalar rule for event 0 of `events` over the lanes of
    /// `chunk`; the number of quiet lanes.
    fn rule<E: EventSet<f64, 2>>(
        events: &E,
        masks: &LaneSides,
        all: u32,
        q: [u32; 3],
        chunk: &[(i8, bool, bool, bool, bool)],
    ) -> u32 {
        let got = masks.quiet(events, 0, all, q);
        for (l, &(_, _, ends, positive, rate_on_side)) in chunk.iter().enumerate() {
            let ends_q = QuietEnds {
                positive,
                rate_on_side,
            };
            let want = ends && masks.get(l).is_quiet_with(events, 0, ends_q);
            assert_eq!(got >> l & 1 == 1, want, "lane {l}: {:?}", chunk[l]);
        }
        got.count_ones()
    }

    /// `QuietEnds::lanes` is `QuietEnds::of` lane for lane, over signed zeros, tiny, huge,
    /// ordinary, infinite and NaN values and every combination of known rates, except
    /// that it may answer "not quiet" where the product of the ends rounds to zero or
    /// infinity.
    #[test]
    fn quiet_ends_in_lanes_is_the_scalar_rule() {
        let vals = [
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            0.5,
            -2.0,
            1e200,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let mut cases = Vec::new();
        for &g0 in &vals {
            for &g1 in &vals {
                for &r0 in &vals {
                    for &r1 in &vals {
                        cases.push([g0, g1, r0, r1]);
                    }
                }
            }
        }
        // Not quiet; quiet on either side; quiet with the rate into the side.
        let mut seen = [0usize; 4];
        let mut conservative = 0;
        for chunk in cases.chunks(4) {
            let col = |k: usize| F64x4::load(&chunk.iter().map(|c| c[k]).collect::<Vec<_>>());
            let (g0, g1, r0, r1) = (col(0), col(1), col(2), col(3));
            for (has0, has1) in [(false, false), (true, false), (false, true), (true, true)] {
                let r = (has0.then_some(r0), has1.then_some(r1));
                let [q, pos, on] = QuietEnds::lanes((g0, g1), r);
                let (q, pos, on) = (q.bits(), pos.bits(), on.bits());
                for (i, c) in chunk.iter().enumerate() {
                    let want =
                        QuietEnds::of((c[0], c[1]), (has0.then_some(c[2]), has1.then_some(c[3])));
                    let got = (q >> i & 1 == 1).then_some(QuietEnds {
                        positive: pos >> i & 1 == 1,
                        rate_on_side: on >> i & 1 == 1,
                    });
                    // Conservative only where the product of the ends is not a finite
                    // non-zero number although both ends are.
                    let product = c[0] * c[1];
                    let rounded = !(product != 0.0 && product.is_finite());
                    assert!(
                        got == want || (got.is_none() && rounded),
                        "g = ({}, {}), r = {:?}: {got:?} vs {want:?}",
                        c[0],
                        c[1],
                        (has0, has1, c[2], c[3])
                    );
                    conservative += usize::from(got != want);
                    match want {
                        None => seen[0] += 1,
                        Some(w) => {
                            seen[1 + usize::from(w.positive)] += 1;
                            seen[3] += usize::from(w.rate_on_side);
                        }
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n > 0), "{seen:?}");
        // The rounded products occur (1e-300², 1e200·1e300) and are the only difference.
        assert!(conservative > 0);
    }
}
