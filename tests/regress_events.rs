//! Regressions of the event engine: nested event sets, indices checked before a run, NaN
//! event functions, the start-on-surface rule, the Zeno guard's independence of the run's
//! span, and impacts on moving and N-DOF surfaces.

use nalgebra::{SVector, Vector2};
use nonsmooth::Dynamics;
use nonsmooth::drive::RunError;
use nonsmooth::drive::{Control, EventRecord, Observer, Simulation};
use nonsmooth::event::{Direction, Event, EventError, FnEvent, Gap, Level, Restitution};
use nonsmooth::excite::Harmonic;
use nonsmooth::integrate::{Dopri5, Stepper, Tolerances};
use nonsmooth::model::Coordinate;
use nonsmooth::sample::{ImpactSequence, PeriodSummary};
use nonsmooth::testing::HarmonicOscillator;

/// Collects event records.
#[derive(Default)]
struct Events(Vec<EventRecord<f64, 2>>);
impl Observer<f64, 2> for Events {
    fn on_event(&mut self, e: &EventRecord<f64, 2>) -> Control {
        self.0.push(*e);
        Control::Continue
    }
}

fn tol() -> Tolerances<f64, 2> {
    Tolerances::new(1e-10, 1e-12).unwrap()
}

fn oscillator() -> HarmonicOscillator<f64> {
    HarmonicOscillator::new(1.0).unwrap()
}

#[test]
fn nested_event_tuples_check_every_member() {
    // x = cos t: crossings of 0.5, −0.5 and 0 twice per period each. Before the fix the
    // inner tuple's second member (index 1) was never evaluated.
    let a = Event::new(Level::new(0, 0.5).unwrap(), Direction::Either);
    let b = Event::new(Level::new(0, -0.5).unwrap(), Direction::Either);
    let c = Event::new(Level::new(0, 0.0).unwrap(), Direction::Either);
    let mut obs = Events::default();
    let mut sim = Simulation::new(oscillator(), Dopri5::new(tol())).with_events(((a, b), c));
    let t_end = 4.0 * std::f64::consts::TAU;
    sim.run(0.0, Vector2::new(1.0, 0.0), t_end, &mut obs)
        .unwrap();
    for idx in 0..3 {
        let times: Vec<f64> = obs
            .0
            .iter()
            .filter(|e| e.index == idx)
            .map(|e| e.t)
            .collect();
        assert_eq!(times.len(), 8, "event {idx}: {times:?}");
        let level = [0.5f64, -0.5, 0.0][idx];
        for t in times {
            assert!((t.cos() - level).abs() < 1e-9, "event {idx} at {t}");
        }
    }
    // Deeper nesting and mixed shapes index the same way.
    let ev = (a, ((b,), (c, a)));
    let mut obs = Events::default();
    Simulation::new(oscillator(), Dopri5::new(tol()))
        .with_events(ev)
        .run(0.0, Vector2::new(1.0, 0.0), t_end, &mut obs)
        .unwrap();
    let per: Vec<usize> = (0..4)
        .map(|i| obs.0.iter().filter(|e| e.index == i).count())
        .collect();
    assert_eq!(per, vec![8, 8, 8, 8]);
}

#[test]
fn indices_outside_the_state_are_errors_not_panics() {
    let mut sim = Simulation::new(oscillator(), Dopri5::new(tol()))
        .with_events(Event::new(Level::new(5, 0.0).unwrap(), Direction::Rising));
    let e = sim
        .run(0.0, Vector2::new(1.0, 0.0), 1.0, &mut ())
        .unwrap_err();
    assert!(matches!(
        e,
        RunError::Event(EventError::IndexOutOfRange { index: 5, len: 2 })
    ));
    let mut sim = Simulation::new(oscillator(), Dopri5::new(tol())).with_events(
        Event::new(Level::new(0, 0.0).unwrap(), Direction::Rising)
            .with_reset(Restitution::new(7, 0.5).unwrap()),
    );
    let e = sim
        .run(0.0, Vector2::new(1.0, 0.0), 1.0, &mut ())
        .unwrap_err();
    assert!(matches!(
        e,
        RunError::Event(EventError::IndexOutOfRange { index: 7, .. })
    ));
    // Samplers with a component index outside the state.
    let mut sim = Simulation::new(oscillator(), Dopri5::new(tol()));
    let mut imp = ImpactSequence::new(0, 3, 1, 0.0, 0.0, 10).unwrap();
    assert!(matches!(
        sim.run(0.0, Vector2::new(1.0, 0.0), 1.0, &mut imp),
        Err(RunError::Event(EventError::IndexOutOfRange {
            index: 3,
            ..
        }))
    ));
    let mut per = PeriodSummary::periodic(0.0, 1.0, 0, 3, 1, 0.0, 0.0, 10).unwrap();
    assert!(sim.run(0.0, Vector2::new(1.0, 0.0), 1.0, &mut per).is_err());
}

#[test]
fn non_finite_event_functions_are_errors() {
    // NaN everywhere: an error at the start, not Ok with no events.
    let nan = Event::new(
        FnEvent(|_t: f64, _y: &SVector<f64, 2>| f64::NAN),
        Direction::Either,
    );
    let mut sim = Simulation::new(oscillator(), Dopri5::new(tol())).with_events(nan);
    assert!(matches!(
        sim.run(0.0, Vector2::new(1.0, 0.0), 10.0, &mut ()),
        Err(RunError::Event(EventError::NonFinite { index: 0, .. }))
    ));
    // NaN in part of the state space (√x for x < 0): no spurious event before, an error
    // once a step ends there. x = cos t leaves x > 0 at t = π/2.
    let partial = Event::new(
        FnEvent(|_t: f64, y: &SVector<f64, 2>| y[0].sqrt() - 0.9),
        Direction::Either,
    )
    .with_interior_samples(4);
    let mut obs = Events::default();
    let mut sim = Simulation::new(oscillator(), Dopri5::new(tol())).with_events(partial);
    let e = sim
        .run(0.0, Vector2::new(1.0, 0.0), 10.0, &mut obs)
        .unwrap_err();
    match e {
        RunError::Event(EventError::NonFinite { t, .. }) => {
            assert!(t > std::f64::consts::FRAC_PI_2, "{t}")
        }
        other => panic!("{other}"),
    }
    // The one genuine crossing (√cos t = 0.9) before the NaN region, nothing else.
    assert_eq!(obs.0.len(), 1, "{:?}", obs.0);
    assert!((obs.0[0].t.cos().sqrt() - 0.9).abs() < 1e-9);
}

#[test]
fn a_start_on_the_surface_fires_in_neither_direction() {
    // x = ±sin t from x = 0: the first events are at π and 2π in both cases (before the
    // fix the downward start fired a Falling event at t0).
    for v0 in [1.0, -1.0] {
        let mut obs = Events::default();
        let mut sim = Simulation::new(oscillator(), Dopri5::new(tol()))
            .with_events(Event::new(Level::new(0, 0.0).unwrap(), Direction::Either));
        sim.run(0.0, Vector2::new(0.0, v0), 7.0, &mut obs).unwrap();
        let times: Vec<f64> = obs.0.iter().map(|e| e.t).collect();
        assert_eq!(times.len(), 2, "v0 = {v0}: {times:?}");
        assert!((times[0] - std::f64::consts::PI).abs() < 1e-9);
        assert!((times[1] - std::f64::consts::TAU).abs() < 1e-9);
    }
}

/// Free fall `ÿ = −g`.
struct Fall(f64);
impl Dynamics<f64, 2> for Fall {
    fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
        dy[0] = y[1];
        dy[1] = -self.0;
    }
}

#[test]
fn the_zeno_guard_does_not_depend_on_the_span() {
    // A ball dropped from 1 m with r = 0.5 accumulates bounces at t∞ = 3·√(2/g). With the
    // default guard the run stops at the same event, with the same state, whatever t_end.
    let g = 9.81;
    let t_inf = 3.0 * (2.0f64 / g).sqrt();
    let mut stops = Vec::new();
    for t_end in [2.0, 20.0, 2000.0] {
        let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Falling)
            .with_reset(Restitution::new(1, 0.5).unwrap());
        let mut sim = Simulation::new(Fall(g), Dopri5::new(tol())).with_events(ev);
        let mut obs = Events::default();
        match sim.run(0.0, Vector2::new(1.0, 0.0), t_end, &mut obs) {
            Err(RunError::Event(EventError::Zeno {
                t,
                count,
                last_interval,
                state,
            })) => {
                assert!(t < t_inf && t_inf - t < 1e-8, "{t} vs {t_inf}");
                assert!(last_interval <= 1e-9 && count >= 16);
                assert_eq!(state.len(), 2);
                // The simulation is left at the event, to continue from.
                assert_eq!(sim.stepper().current().0, t);
                stops.push((t, obs.0.len()));
            }
            other => panic!("t_end = {t_end}: expected Zeno, got {other:?}"),
        }
    }
    // Same number of bounces and the same stop to the integration tolerance (the first
    // step size depends on the span, so the trajectories differ at the 1e-12 level).
    assert!(
        stops
            .windows(2)
            .all(|w| w[0].1 == w[1].1 && (w[0].0 - w[1].0).abs() < 1e-10),
        "{stops:?}"
    );

    // An elastic ball (r = 1) bounces periodically, 20 000 times here: the guard never trips.
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Falling)
        .with_reset(Restitution::new(1, 1.0).unwrap());
    let mut obs = Events::default();
    let mut sim = Simulation::new(Fall(g), Dopri5::new(tol())).with_events(ev);
    let period = 2.0 * (2.0f64 / g).sqrt();
    let out = sim
        .run(0.0, Vector2::new(1.0, 0.0), 20_000.0 * period, &mut obs)
        .unwrap();
    assert_eq!(out.stats.events, 20_000);
}

#[test]
fn impacts_on_a_moving_surface_of_a_two_dof_system() {
    // Two uncoupled unit oscillators q̈_i = −q_i, the second with amplitude 1, against a
    // surface moving as s(t) = 0.5 + 0.1·sin(3t) from below (g = q_2 − s(t)), no reset: the
    // impacts are the rising crossings of cos t = 0.5 + 0.1 sin 3t, checked by bisection.
    use nonsmooth::force::LinearSpring;
    use nonsmooth::model::{Element, Mechanical};
    use nonsmooth::sample::Surface;
    let model = Mechanical::with_masses([1.0, 1.0]).unwrap().with_elements((
        Element::on_dof(0, LinearSpring::new(1.0).unwrap()).unwrap(),
        Element::on_dof(1, LinearSpring::new(1.0).unwrap()).unwrap(),
    ));
    let motion = Harmonic::new(0.1, 3.0, 0.0).unwrap();
    let surface = Gap::below(
        Coordinate::<f64, 2>::dof(1)
            .unwrap()
            .with_offset(-0.5)
            .unwrap(),
        motion,
    );
    let mut imp = ImpactSequence::on_surface(0, surface, 0.0, 100).unwrap();
    let mut sim = Simulation::new(model, Dopri5::new(Tolerances::new(1e-10, 1e-12).unwrap()))
        .with_events(Event::new(surface, Direction::Rising));
    let y0 = SVector::<f64, 4>::new(0.3, -1.0, 0.0, 0.0); // q_2 = −cos t
    sim.run(0.0, y0, 20.0, &mut imp).unwrap();
    let g = |t: f64| -t.cos() - 0.5 - 0.1 * (3.0 * t).sin();
    let mut exact = Vec::new();
    let n = 20_000;
    for k in 0..n {
        let (a, b) = (20.0 * k as f64 / n as f64, 20.0 * (k + 1) as f64 / n as f64);
        if g(a) < 0.0 && g(b) >= 0.0 {
            let (mut lo, mut hi) = (a, b);
            for _ in 0..100 {
                let m = 0.5 * (lo + hi);
                if g(m) < 0.0 { lo = m } else { hi = m }
            }
            exact.push(hi);
        }
    }
    assert!(exact.len() >= 3);
    assert_eq!(imp.impacts().len(), exact.len());
    for (i, e) in imp.impacts().iter().zip(&exact) {
        assert!((i.t - e).abs() < 1e-8, "{} vs {e}", i.t);
        // Impact velocity: ġ = q̇_2 − ṡ = sin t − 0.3 cos 3t.
        let rate = i.t.sin() - 0.3 * (3.0 * i.t).cos();
        assert!((i.velocity - rate).abs() < 1e-7, "{} vs {rate}", i.velocity);
    }
    // The surface helper agrees with the event function.
    let y = SVector::<f64, 4>::new(0.0, 0.7, 0.0, 0.2);
    assert!((surface.gap(1.0, &y) - (0.7 - 0.5 - 0.1 * 3.0f64.sin())).abs() < 1e-15);
    assert!((surface.gap_rate(1.0, &y) - (0.2 - 0.3 * 3.0f64.cos())).abs() < 1e-15);
}

/// A moving table without its chord bounds: the same function, every grazing pair searched.
struct Unbounded<G>(G);
impl<G: nonsmooth::event::EventFunction<f64, 2>> nonsmooth::event::EventFunction<f64, 2>
    for Unbounded<G>
{
    fn value(&self, t: f64, y: &SVector<f64, 2>) -> f64 {
        self.0.value(t, y)
    }
    fn rate(&self, t: f64, y: &SVector<f64, 2>, dy: &SVector<f64, 2>) -> Option<f64> {
        self.0.rate(t, y, dy)
    }
    fn time_scale(&self, t: f64) -> Option<f64> {
        self.0.time_scale(t)
    }
}

#[test]
fn chord_bounds_change_no_result() {
    // The bouncing ball on a vibrating table (period-one, period-two and chaotic bouncing,
    // chattering included): with the table's chord bounds the grazing pairs farther from
    // the table than the bounds are not searched; every impact and the end state must be
    // those of the search without them, to the bit.
    use nonsmooth::systems::BouncingBallTable;
    let (mut impacts, mut finished) = (0, 0);
    for gamma in [1.5, 2.5, 3.2, 3.9] {
        let ball = BouncingBallTable::with_gamma(gamma, 0.8).unwrap();
        let y0 = Vector2::new(0.0, ball.table_motion(0.0).1 + 2.0);
        let t_end = 60.0 * ball.period();
        let impact = ball.impact::<f64>().unwrap();
        let run = |with: &mut Events, bounded: bool| {
            let tol = Tolerances::new(1e-10, 1e-12).unwrap();
            let table = ball.table::<f64>().unwrap();
            let out = if bounded {
                Simulation::new(ball.model::<f64>().unwrap(), Dopri5::new(tol))
                    .with_events(Event::new(table, Direction::Rising).with_reset(impact))
                    .run(0.0, y0, t_end, with)
            } else {
                Simulation::new(ball.model::<f64>().unwrap(), Dopri5::new(tol))
                    .with_events(Event::new(Unbounded(table), Direction::Rising).with_reset(impact))
                    .run(0.0, y0, t_end, with)
            };
            out.map(|o| (o.t.to_bits(), o.y.map(f64::to_bits), o.stats.rhs_evals))
                .map_err(|e| e.to_string())
        };
        let (mut a, mut b) = (Events::default(), Events::default());
        let ra = run(&mut a, true);
        let rb = run(&mut b, false);
        assert_eq!(ra, rb, "Γ = {gamma}");
        finished += usize::from(ra.is_ok());
        assert_eq!(a.0.len(), b.0.len(), "Γ = {gamma}");
        for (x, y) in a.0.iter().zip(&b.0) {
            assert_eq!(
                (
                    x.t.to_bits(),
                    x.y.map(f64::to_bits),
                    x.y_after.map(|v| v.map(f64::to_bits))
                ),
                (
                    y.t.to_bits(),
                    y.y.map(f64::to_bits),
                    y.y_after.map(|v| v.map(f64::to_bits))
                ),
                "Γ = {gamma}"
            );
        }
        impacts += a.0.len();
    }
    assert!(
        impacts > 100 && finished >= 2,
        "{impacts} impacts, {finished} runs finished"
    );
}
