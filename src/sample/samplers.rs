use crate::Real;
use nalgebra::SVector;

use super::surface::{Surface, component_max, component_min};
use crate::drive::{Control, EventRecord, Observer, RunError, StepView};
use crate::event::{Direction, EventFunction, Stop, locate};
use crate::excite::Excitation;
use crate::integrate::DenseOutput;
use crate::scalar::lit;
use crate::validate::ParameterError;
use crate::validate::{finite, positive};

/// The times `t_i` of a stroboscopic section.
pub trait SectionClock<T: Real> {
    /// The `i`-th section time, if defined.
    fn section_time(&self, i: u64) -> Option<T>;

    /// The first index whose time is `≥ t` (up to rounding). The default assumes section
    /// times increase with `i` and searches by doubling and bisection (at most ~128 calls
    /// of [`section_time`](Self::section_time), whatever `t`); an index without a time
    /// counts as past every `t`.
    fn first_index_from(&self, t: T) -> u64 {
        let at_or_after = |i: u64| {
            self.section_time(i)
                .is_none_or(|ti| ti >= t - lit::<T>(4.0) * T::default_epsilon() * t.abs())
        };
        if at_or_after(0) {
            return 0;
        }
        // section_time(lo) < t ≤ section_time(hi)
        let (mut lo, mut hi) = (0u64, 1u64);
        while !at_or_after(hi) {
            lo = hi;
            if hi >= 1 << 62 {
                return u64::MAX;
            }
            hi *= 2;
        }
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if at_or_after(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }
}

/// The most sections one [`Stroboscopic`] sampler visits in one run (10⁹): a clock whose
/// spacing is so small for the run's span that it would exceed it (or would not advance
/// time at all) is an error before the first step, not a loop without end.
pub const MAX_SECTIONS_PER_RUN: u64 = 1_000_000_000;

/// Sections at `t_i = origin + i·period` (computed from `i`, never accumulated).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Periodic<T> {
    origin: T,
    period: T,
}

impl<T: Real> Periodic<T> {
    /// `t_i = origin + i·period`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `origin` is finite and `period` finite and > 0.
    pub fn new(origin: T, period: T) -> Result<Self, ParameterError> {
        Ok(Self {
            origin: finite("origin", origin)?,
            period: positive("period", period)?,
        })
    }
}

impl<T: Real> SectionClock<T> for Periodic<T> {
    #[inline]
    fn section_time(&self, i: u64) -> Option<T> {
        Some(self.origin + lit::<T>(i as f64) * self.period)
    }
    fn first_index_from(&self, t: T) -> u64 {
        let k = ((t - self.origin) / self.period - lit::<T>(1e-9)).ceil();
        if k <= T::zero() {
            0
        } else {
            k.to_subset().unwrap_or(0.0) as u64
        }
    }
}

/// Sections where an excitation's phase passes `2πi` (exact for a ramped rotor).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseClock<E>(pub E);

impl<T: Real, E: Excitation<T>> SectionClock<T> for PhaseClock<E> {
    fn section_time(&self, i: u64) -> Option<T> {
        self.0.time_of_phase(T::two_pi() * lit::<T>(i as f64))
    }
}

/// The sections of `clock` in `[t0, t_end]` are at most [`MAX_SECTIONS_PER_RUN`] and each
/// advances time.
fn check_sections<T: Real, C: SectionClock<T>>(clock: &C, t0: T, t_end: T) -> Result<(), RunError> {
    let (a, b) = (clock.first_index_from(t0), clock.first_index_from(t_end));
    let count = b.saturating_sub(a);
    let too_many = || {
        RunError::from(ParameterError::new(
            "section clock",
            count as f64,
            "at most 10^9 sections per run, each advancing time (spacing too small for the span?)",
        ))
    };
    if count > MAX_SECTIONS_PER_RUN {
        return Err(too_many());
    }
    // Spacing below the time resolution at either end: consecutive sections coincide.
    for i in [a, b.saturating_sub(1)] {
        if let (Some(x), Some(y)) = (clock.section_time(i), clock.section_time(i + 1)) {
            if !(y > x) && count > 0 {
                return Err(too_many());
            }
        }
    }
    Ok(())
}

/// A recorded section point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionPoint<T: Real, const N: usize> {
    /// Section index `i`.
    pub index: u64,
    /// Time.
    pub t: T,
    /// State.
    pub y: SVector<T, N>,
}

/// Bounded storage shared by the samplers.
#[derive(Debug, Clone)]
struct Store<R> {
    items: Vec<R>,
    capacity: usize,
    dropped: u64,
}

impl<R> Store<R> {
    fn new(capacity: usize) -> Self {
        Self {
            items: Vec::new(),
            capacity,
            dropped: 0,
        }
    }
    fn push(&mut self, r: R) {
        if self.items.len() < self.capacity {
            self.items.push(r);
        } else {
            self.dropped += 1;
        }
    }
}

/// The stroboscopic (Poincaré) section: the state at `t_i` given by a [`SectionClock`].
///
/// ```
/// use nonsmooth::drive::Simulation;
/// use nonsmooth::integrate::{Dopri5, Tolerances};
/// use nonsmooth::systems::DuffingUeda;
/// use nonsmooth::sample::Stroboscopic;
/// use nalgebra::Vector2;
///
/// let p = DuffingUeda::default(); // ẍ + 0.05ẋ + x³ = 7.5 cos t
/// let period = p.period();
/// let mut strobe = Stroboscopic::periodic(0.0, period, 10.0 * period, 1000)?;
/// let model = p.model::<f64>()?;
/// let tol = Tolerances::new(1e-8, 1e-10)?;
/// Simulation::new(model, Dopri5::new(tol)).run(0.0, Vector2::new(1.0, 0.0), 20.0 * period, &mut strobe)?;
/// assert_eq!(strobe.points().len(), 11); // sections 10..=20
/// # Ok::<(), nonsmooth::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Stroboscopic<T: Real, const N: usize, C = Periodic<T>> {
    clock: C,
    next: Option<(u64, T)>,
    record_from: T,
    store: Store<SectionPoint<T, N>>,
}

impl<T: Real, const N: usize> Stroboscopic<T, N, Periodic<T>> {
    /// Sections at `origin + i·period`, recorded from `record_from` on, at most `capacity`.
    ///
    /// # Errors
    /// [`ParameterError`] for a non-finite origin or `record_from`, or a non-positive period.
    pub fn periodic(
        origin: T,
        period: T,
        record_from: T,
        capacity: usize,
    ) -> Result<Self, ParameterError> {
        Self::new(Periodic::new(origin, period)?, record_from, capacity)
    }
}

impl<T: Real, const N: usize, C: SectionClock<T>> Stroboscopic<T, N, C> {
    /// Sections from any clock.
    ///
    /// # Errors
    /// [`ParameterError`] if `record_from` is not finite.
    pub fn new(clock: C, record_from: T, capacity: usize) -> Result<Self, ParameterError> {
        Ok(Self {
            clock,
            next: None,
            record_from: finite("record_from", record_from)?,
            store: Store::new(capacity),
        })
    }

    /// The recorded points.
    pub fn points(&self) -> &[SectionPoint<T, N>] {
        &self.store.items
    }

    /// Takes the recorded points, leaving the sampler empty.
    pub fn take_points(&mut self) -> Vec<SectionPoint<T, N>> {
        std::mem::take(&mut self.store.items)
    }

    /// Points not stored because the capacity was reached.
    pub fn dropped(&self) -> u64 {
        self.store.dropped
    }

    /// Records from `t` on.
    pub fn set_record_from(&mut self, t: T) {
        self.record_from = t;
    }

    fn advance(&mut self, i: u64) {
        self.next = self.clock.section_time(i).map(|t| (i, t));
    }
}

impl<T: Real, const N: usize, C: SectionClock<T>> Observer<T, N> for Stroboscopic<T, N, C> {
    fn check_span(&self, t0: T, t_end: T) -> Result<(), RunError> {
        check_sections(&self.clock, t0, t_end)
    }

    fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
        let i = self.clock.first_index_from(t0);
        self.advance(i);
        if let Some((i, t)) = self.next {
            if (t - t0).abs() <= lit::<T>(4.0) * T::default_epsilon() * t0.abs().max(T::one()) {
                if t0 >= self.record_from {
                    self.store.push(SectionPoint {
                        index: i,
                        t: t0,
                        y: *y0,
                    });
                }
                self.advance(i + 1);
            }
        }
    }

    #[inline]
    fn on_step<D: DenseOutput<T, N>>(&mut self, s: &StepView<'_, T, N, D>) -> Control {
        while let Some((i, t)) = self.next {
            if t > s.t1 {
                break;
            }
            if t >= self.record_from {
                let mut y = SVector::zeros();
                s.state_at(t.max(s.t0), &mut y);
                self.store.push(SectionPoint { index: i, t, y });
            }
            self.advance(i + 1);
        }
        Control::Continue
    }
}

/// One impact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impact<T> {
    /// Impact time.
    pub t: T,
    /// Velocity at impact: the surface's penetration rate `ġ` (for a [`Stop`], the
    /// velocity component).
    pub velocity: T,
    /// Interval since the previous impact (`T_j`); `None` for the first.
    pub interval: Option<T>,
    /// Maximum penetration past the level during this contact (filled when the contact
    /// ends; `None` while it lasts or if the run ended in contact).
    pub max_penetration: Option<T>,
}

/// The impact sequence on a contact [`Surface`]: the rising crossings of its penetration
/// `g` reported by event `event` of the simulation (built on the same surface, e.g.
/// `Event::new(Stop { position: 0, velocity: 1, level: x_I }, Direction::Rising)` or a
/// [`Gap`](crate::event::Gap) of an `N`-DOF system against a moving surface), with the
/// inter-impact intervals `T_j`, the impact velocities `ġ` and the maximum penetration of
/// each contact (the maximum of `g` until it is negative again at a step end; interior
/// maxima are found on the dense output). Several surfaces: one sequence per surface, each
/// listening to its own event index.
#[derive(Debug, Clone)]
pub struct ImpactSequence<T: Real, G = Stop<T>> {
    event: usize,
    surface: G,
    record_from: T,
    last_t: Option<T>,
    in_contact: bool,
    current_max: T,
    store: Store<Impact<T>>,
    count: u64,
}

impl<T: Real> ImpactSequence<T, Stop<T>> {
    /// Impacts reported by event `event`, on `y[position]` crossing `level` upwards, with the
    /// velocity in `y[velocity]`; recorded from `record_from` on, at most `capacity`.
    ///
    /// # Errors
    /// [`ParameterError`] if `level` or `record_from` is not finite. Indices outside the
    /// state are reported when the run starts.
    pub fn new(
        event: usize,
        position: usize,
        velocity: usize,
        level: T,
        record_from: T,
        capacity: usize,
    ) -> Result<Self, ParameterError> {
        Self::on_surface(
            event,
            Stop {
                position,
                velocity,
                level: finite("level", level)?,
            },
            record_from,
            capacity,
        )
    }
}

impl<T: Real, G> ImpactSequence<T, G> {
    /// Impacts on `surface` reported by event `event`; recorded from `record_from` on, at
    /// most `capacity`.
    ///
    /// # Errors
    /// [`ParameterError`] if `record_from` is not finite.
    pub fn on_surface(
        event: usize,
        surface: G,
        record_from: T,
        capacity: usize,
    ) -> Result<Self, ParameterError> {
        Ok(Self {
            event,
            surface,
            record_from: finite("record_from", record_from)?,
            last_t: None,
            in_contact: false,
            current_max: T::zero(),
            store: Store::new(capacity),
            count: 0,
        })
    }

    /// The surface.
    pub fn surface(&self) -> &G {
        &self.surface
    }

    /// The recorded impacts.
    pub fn impacts(&self) -> &[Impact<T>] {
        &self.store.items
    }

    /// The inter-impact intervals `T_j` of the recorded impacts.
    pub fn intervals(&self) -> Vec<T> {
        self.store.items.iter().filter_map(|i| i.interval).collect()
    }

    /// Impacts seen in the recording window (including those beyond the capacity).
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Records dropped because the capacity was reached.
    pub fn dropped(&self) -> u64 {
        self.store.dropped
    }

    /// Records from `t` on.
    pub fn set_record_from(&mut self, t: T) {
        self.record_from = t;
    }

    /// Clears the records (keeps the configuration and the last impact time).
    pub fn clear(&mut self) {
        self.store.items.clear();
        self.store.dropped = 0;
        self.count = 0;
    }
}

impl<T: Real, const N: usize, G: Surface<T, N>> Observer<T, N> for ImpactSequence<T, G> {
    fn check(&self) -> Result<(), RunError> {
        Ok(self.surface.check()?)
    }

    fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
        let g = self.surface.gap(t0, y0);
        self.in_contact = g >= T::zero();
        self.current_max = g;
    }

    #[inline]
    fn on_step<D: DenseOutput<T, N>>(&mut self, s: &StepView<'_, T, N, D>) -> Control {
        if !self.in_contact {
            return Control::Continue;
        }
        let m = self.surface.max_gap(s);
        if m > self.current_max {
            self.current_max = m;
        }
        if self.surface.gap(s.t1, &s.y1) < T::zero() {
            self.in_contact = false;
            if let Some(last) = self.store.items.last_mut() {
                if last.max_penetration.is_none() && Some(last.t) == self.last_t {
                    last.max_penetration = Some(self.current_max);
                }
            }
        }
        Control::Continue
    }

    fn on_event(&mut self, e: &EventRecord<T, N>) -> Control {
        if e.index != self.event || e.direction != Direction::Rising {
            return Control::Continue;
        }
        let interval = self.last_t.map(|l| e.t - l);
        self.last_t = Some(e.t);
        self.in_contact = true;
        self.current_max = T::zero();
        if e.t >= self.record_from {
            self.count += 1;
            self.store.push(Impact {
                t: e.t,
                velocity: self.surface.gap_rate(e.t, &e.y),
                interval,
                max_penetration: None,
            });
        }
        Control::Continue
    }
}

/// A summary of one forcing period `[t_i, t_{i+1})`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodRecord<T> {
    /// Period index `i`.
    pub index: u64,
    /// Start time `t_i`.
    pub t_start: T,
    /// Impacts in the period.
    pub impacts: u32,
    /// Minimum of `y[position]`.
    pub x_min: T,
    /// Maximum of `y[position]`.
    pub x_max: T,
    /// Grazing margin `−max g` over the period (for a [`Stop`], `level − x_max`): positive
    /// when the surface was not reached.
    pub margin: T,
}

/// Per-period summaries: impacts, extrema of one component and the grazing margin to a
/// contact [`Surface`] (by default the stop `y[position] = level`; any other with
/// [`with_surface`](PeriodSummary::with_surface)).
#[derive(Debug, Clone)]
pub struct PeriodSummary<T: Real, C = Periodic<T>, G = Stop<T>> {
    clock: C,
    event: usize,
    position: usize,
    velocity: usize,
    surface: G,
    g_max: T,
    record_from: T,
    current: Option<(u64, T, T)>, // (index, start, end)
    /// The current period has not begun yet (the run started inside an earlier one).
    pending: bool,
    impacts: u32,
    x_min: T,
    x_max: T,
    store: Store<PeriodRecord<T>>,
}

impl<T: Real> PeriodSummary<T, Periodic<T>> {
    /// Periods `[origin + i·period, origin + (i+1)·period)`; impacts counted from rising
    /// events `event`; extrema of `y[position]` (`y[velocity]` its rate); stop at `level`.
    ///
    /// # Errors
    /// [`ParameterError`] for non-finite values or a non-positive period.
    #[allow(clippy::too_many_arguments)]
    pub fn periodic(
        origin: T,
        period: T,
        event: usize,
        position: usize,
        velocity: usize,
        level: T,
        record_from: T,
        capacity: usize,
    ) -> Result<Self, ParameterError> {
        Ok(Self {
            clock: Periodic::new(origin, period)?,
            event,
            position,
            velocity,
            surface: Stop {
                position,
                velocity,
                level: finite("level", level)?,
            },
            g_max: T::zero(),
            record_from: finite("record_from", record_from)?,
            current: None,
            pending: false,
            impacts: 0,
            x_min: T::zero(),
            x_max: T::zero(),
            store: Store::new(capacity),
        })
    }
}

impl<T: Real, C: SectionClock<T>, G> PeriodSummary<T, C, G> {
    /// The completed periods.
    pub fn periods(&self) -> &[PeriodRecord<T>] {
        &self.store.items
    }

    /// Margins (and impacts, from event `event`) on another contact surface.
    pub fn with_surface<G2>(self, surface: G2) -> PeriodSummary<T, C, G2> {
        PeriodSummary {
            clock: self.clock,
            event: self.event,
            position: self.position,
            velocity: self.velocity,
            surface,
            g_max: self.g_max,
            record_from: self.record_from,
            current: self.current,
            pending: self.pending,
            impacts: self.impacts,
            x_min: self.x_min,
            x_max: self.x_max,
            store: self.store,
        }
    }

    fn open(&mut self, i: u64, x: T, g: T) {
        self.current = match (self.clock.section_time(i), self.clock.section_time(i + 1)) {
            (Some(a), Some(b)) => Some((i, a, b)),
            _ => None,
        };
        self.impacts = 0;
        self.x_min = x;
        self.x_max = x;
        self.g_max = g;
    }

    fn close(&mut self) {
        if let Some((i, a, _)) = self.current {
            if a >= self.record_from {
                self.store.push(PeriodRecord {
                    index: i,
                    t_start: a,
                    impacts: self.impacts,
                    x_min: self.x_min,
                    x_max: self.x_max,
                    margin: -self.g_max,
                });
            }
        }
    }
}

impl<T: Real, const N: usize, C: SectionClock<T>, G: Surface<T, N>> Observer<T, N>
    for PeriodSummary<T, C, G>
{
    fn check(&self) -> Result<(), RunError> {
        crate::event::check_index(self.position, N)?;
        crate::event::check_index(self.velocity, N)?;
        Ok(self.surface.check()?)
    }

    fn check_span(&self, t0: T, t_end: T) -> Result<(), RunError> {
        check_sections(&self.clock, t0, t_end)
    }

    fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
        // Periods that began before t0 are incomplete: start with the first at or after t0.
        let i = self.clock.first_index_from(t0);
        self.open(i, y0[self.position], self.surface.gap(t0, y0));
        self.pending = self.current.is_some_and(|(_, a, _)| a > t0);
    }

    fn on_step<D: DenseOutput<T, N>>(&mut self, s: &StepView<'_, T, N, D>) -> Control {
        let mut t_lo = s.t0;
        while let Some((i, a, b)) = self.current {
            if self.pending {
                // Waiting for the first full period to begin.
                if a > s.t1 {
                    return Control::Continue;
                }
                let mut y = SVector::zeros();
                let ta = a.max(s.t0);
                s.state_at(ta, &mut y);
                self.open(i, y[self.position], self.surface.gap(ta, &y));
                self.pending = false;
                t_lo = a.max(s.t0);
                continue;
            }
            let end = b.min(s.t1);
            let mut ya = SVector::zeros();
            let mut yb = SVector::zeros();
            s.state_at(t_lo, &mut ya);
            s.state_at(end, &mut yb);
            let part = StepView {
                t0: t_lo,
                t1: end,
                y0: ya,
                y1: yb,
                dense: s.dense,
            };
            self.x_max = self
                .x_max
                .max(component_max(&part, self.position, self.velocity));
            self.x_min = self
                .x_min
                .min(component_min(&part, self.position, self.velocity));
            self.g_max = self.g_max.max(self.surface.max_gap(&part));
            if b <= s.t1 {
                self.close();
                self.open(i + 1, yb[self.position], self.surface.gap(end, &yb));
                t_lo = b;
                if b == s.t1 {
                    break;
                }
            } else {
                break;
            }
        }
        Control::Continue
    }

    fn on_event(&mut self, e: &EventRecord<T, N>) -> Control {
        if e.index == self.event && e.direction == Direction::Rising && !self.pending {
            if let Some((_, a, b)) = self.current {
                if e.t >= a && e.t < b {
                    self.impacts += 1;
                }
            }
        }
        Control::Continue
    }
}

/// A general Poincaré section: crossings of `g(t, y) = 0` in a direction, located on the
/// dense output by the same bracketing iteration as the events (to `tol` in time). It does
/// not look for grazing pairs inside one view (use a simulation event for that).
#[derive(Debug, Clone)]
pub struct Section<T: Real, const N: usize, G> {
    g: G,
    direction: Direction,
    tol: T,
    record_from: T,
    g_prev: Option<T>,
    count: u64,
    store: Store<SectionPoint<T, N>>,
}

impl<T: Real, const N: usize, G: EventFunction<T, N>> Section<T, N, G> {
    /// A section through `g = 0` in `direction`, time tolerance `tol`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `tol > 0` and `record_from` finite.
    pub fn new(
        g: G,
        direction: Direction,
        tol: T,
        record_from: T,
        capacity: usize,
    ) -> Result<Self, ParameterError> {
        Ok(Self {
            g,
            direction,
            tol: positive("tol", tol)?,
            record_from: finite("record_from", record_from)?,
            g_prev: None,
            count: 0,
            store: Store::new(capacity),
        })
    }

    /// The recorded crossings (`index` counts crossings from the start of the run).
    pub fn points(&self) -> &[SectionPoint<T, N>] {
        &self.store.items
    }
}

impl<T: Real, const N: usize, G: EventFunction<T, N>> Observer<T, N> for Section<T, N, G> {
    fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
        self.g_prev = Some(self.g.value(t0, y0));
    }

    fn on_step<D: DenseOutput<T, N>>(&mut self, s: &StepView<'_, T, N, D>) -> Control {
        let g0 = self.g_prev.unwrap_or_else(|| self.g.value(s.t0, &s.y0));
        let g1 = self.g.value(s.t1, &s.y1);
        if g0 != T::zero() && g1 != T::zero() && (g0 > T::zero()) != (g1 > T::zero()) {
            let rising = g1 > T::zero();
            if self.direction.accepts(rising) {
                let g = &self.g;
                let (tc, _) = locate(
                    |t| {
                        let mut y = SVector::zeros();
                        s.dense.interpolate_unchecked(t, &mut y);
                        g.value(t, &y)
                    },
                    s.t0,
                    s.t1,
                    g0,
                    g1,
                    self.tol,
                );
                let mut y = SVector::zeros();
                s.state_at(tc, &mut y);
                self.count += 1;
                if tc >= self.record_from {
                    self.store.push(SectionPoint {
                        index: self.count - 1,
                        t: tc,
                        y,
                    });
                }
            }
        }
        if g1 != T::zero() {
            self.g_prev = Some(g1);
        }
        Control::Continue
    }
}

/// The state on the uniform grid `origin + i·dt` (never accumulated), from `record_from`.
#[derive(Debug, Clone)]
pub struct Trajectory<T: Real, const N: usize> {
    clock: Periodic<T>,
    inner: Stroboscopic<T, N, Periodic<T>>,
}

impl<T: Real, const N: usize> Trajectory<T, N> {
    /// Samples every `dt` from `origin`, recording from `record_from`, at most `capacity`.
    ///
    /// # Errors
    /// [`ParameterError`] for a non-positive `dt` or non-finite times.
    pub fn new(origin: T, dt: T, record_from: T, capacity: usize) -> Result<Self, ParameterError> {
        let clock = Periodic::new(origin, dt)?;
        Ok(Self {
            clock,
            inner: Stroboscopic::new(clock, record_from, capacity)?,
        })
    }

    /// The samples.
    pub fn samples(&self) -> &[SectionPoint<T, N>] {
        self.inner.points()
    }

    /// The grid.
    pub fn grid(&self) -> Periodic<T> {
        self.clock
    }
}

impl<T: Real, const N: usize> Observer<T, N> for Trajectory<T, N> {
    fn on_start(&mut self, t0: T, y0: &SVector<T, N>) {
        Observer::<T, N>::on_start(&mut self.inner, t0, y0)
    }
    fn on_step<D: DenseOutput<T, N>>(&mut self, s: &StepView<'_, T, N, D>) -> Control {
        self.inner.on_step(s)
    }
}
