//! Event location against closed forms: zero crossings, a bouncing ball with restitution
//! (analytic impact times, Zeno accumulation), grazing pairs inside one step.

use nalgebra::Vector2;
use nonsmooth::Dynamics;
use nonsmooth::drive::RunError;
use nonsmooth::drive::{Control, EventRecord, Observer, Simulation, Termination};
use nonsmooth::event::{Direction, Event, EventError, FnEvent, Level, Restitution, ZenoGuard};
use nonsmooth::integrate::{Dop853, Dopri5, Tolerances};

struct Harmonic;
impl Dynamics<f64, 2> for Harmonic {
    fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }
}

/// Free fall `h'' = −g`.
struct Ball {
    g: f64,
}
impl Dynamics<f64, 2> for Ball {
    fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        dy[0] = y[1];
        dy[1] = -self.g;
    }
}

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

#[test]
fn harmonic_zero_crossings() {
    // x = cos t: zeros at π/2 + kπ, falling for even k.
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Either);
    let mut sim = Simulation::new(Harmonic, Dopri5::new(tol())).with_events(ev);
    let mut obs = Events::default();
    sim.run(0.0, Vector2::new(1.0, 0.0), 30.0, &mut obs)
        .unwrap();
    let n = (30.0 / std::f64::consts::PI - 0.5).floor() as usize + 1;
    assert_eq!(obs.0.len(), n);
    for (k, e) in obs.0.iter().enumerate() {
        let exact = std::f64::consts::FRAC_PI_2 + k as f64 * std::f64::consts::PI;
        assert!(
            (e.t - exact).abs() < 1e-9,
            "crossing {k}: {} vs {exact}",
            e.t
        );
        let want = if k % 2 == 0 {
            Direction::Falling
        } else {
            Direction::Rising
        };
        assert_eq!(e.direction, want);
        assert!(e.y[0].abs() < 1e-9);
    }
    // Direction filter.
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Rising);
    let mut sim = Simulation::new(Harmonic, Dopri5::new(tol())).with_events(ev);
    let mut obs = Events::default();
    sim.run(0.0, Vector2::new(1.0, 0.0), 30.0, &mut obs)
        .unwrap();
    assert!(obs.0.iter().all(|e| e.direction == Direction::Rising));
    assert_eq!(obs.0.len(), n / 2);
}

/// Analytic bounce times for a drop from `h0` at rest with restitution `r`.
fn bounce_times(h0: f64, g: f64, r: f64, n: usize) -> Vec<f64> {
    let v1 = (2.0 * g * h0).sqrt();
    let mut t = v1 / g;
    let mut out = vec![t];
    let mut v = v1;
    for _ in 1..n {
        v *= r;
        t += 2.0 * v / g;
        out.push(t);
    }
    out
}

#[test]
fn bouncing_ball_matches_analytic_impacts() {
    let (g, r, h0) = (9.81, 0.95, 1.0);
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Falling)
        .with_reset(Restitution::new(1, r).unwrap());
    for stepper_is_853 in [false, true] {
        let mut obs = Events::default();
        // Before the accumulation point t∞ = 17.6 s.
        let t_end = 12.0;
        let out = if stepper_is_853 {
            Simulation::new(Ball { g }, Dop853::new(tol()))
                .with_events(ev)
                .run(0.0, Vector2::new(h0, 0.0), t_end, &mut obs)
        } else {
            Simulation::new(Ball { g }, Dopri5::new(tol()))
                .with_events(ev)
                .run(0.0, Vector2::new(h0, 0.0), t_end, &mut obs)
        }
        .unwrap();
        assert_eq!(out.termination, Termination::ReachedEnd);
        let exact = bounce_times(h0, g, r, 40);
        let expected = exact.iter().filter(|&&t| t <= t_end).count();
        assert!(expected >= 20, "{expected}");
        assert_eq!(obs.0.len(), expected);
        for (k, e) in obs.0.iter().enumerate() {
            assert!(
                (e.t - exact[k]).abs() < 1e-9 * (k + 1) as f64,
                "bounce {k}: {} vs {}",
                e.t,
                exact[k]
            );
            let after = e.y_after.unwrap();
            assert!((after[1] + r * e.y[1]).abs() < 1e-15);
        }
    }
}

#[test]
fn zeno_accumulation_ends_the_run_cleanly() {
    let (g, r, h0): (f64, f64, f64) = (9.81, 0.5, 1.0);
    let v1 = (2.0 * g * h0).sqrt();
    let t_inf = v1 / g + 2.0 * v1 * r / (g * (1.0 - r));
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Falling)
        .with_reset(Restitution::new(1, r).unwrap());
    let mut obs = Events::default();
    let mut sim = Simulation::new(Ball { g }, Dopri5::new(tol()))
        .with_events(ev)
        .zeno_guard(ZenoGuard::new(20, 1e-3).unwrap());
    let e = sim
        .run(0.0, Vector2::new(h0, 0.0), 5.0, &mut obs)
        .unwrap_err();
    match e {
        RunError::Event(EventError::Zeno { t, count, .. }) => {
            assert_eq!(count, 21);
            assert!(
                t < t_inf && t_inf - t < 1e-3,
                "stopped at {t}, accumulation at {t_inf}"
            );
        }
        other => panic!("expected a Zeno error, got {other}"),
    }
    // Every located bounce before the stop is the analytic one.
    let exact = bounce_times(h0, g, r, obs.0.len());
    for (k, e) in obs.0.iter().enumerate().take(15) {
        assert!((e.t - exact[k]).abs() < 1e-8, "bounce {k}");
    }
}

#[test]
fn grazing_pair_inside_one_step_is_found() {
    // x = cos t exceeds the level 1 − δ on |t − 2πk| < arccos(1 − δ): a pair of crossings
    // 2·√(2δ) ≈ 2.8e-4 apart, far inside one step at these tolerances.
    let delta: f64 = 1e-8;
    let level = 1.0 - delta;
    let half_width = (1.0 - delta).acos();
    let ev = Event::new(Level::new(0, level).unwrap(), Direction::Either);
    let mut sim = Simulation::new(Harmonic, Dopri5::new(Tolerances::new(1e-9, 1e-12).unwrap()))
        .with_events(ev);
    let mut obs = Events::default();
    // Start just after the first excursion so that every excursion is a full pair.
    let t0: f64 = 0.5;
    let out = sim
        .run(t0, Vector2::new(t0.cos(), -t0.sin()), 40.0, &mut obs)
        .unwrap();
    // Steps are much longer than the excursion.
    let mean_step = (40.0 - t0) / out.stats.accepted as f64;
    assert!(
        mean_step > 100.0 * 2.0 * half_width,
        "mean step {mean_step}"
    );
    let tau = std::f64::consts::TAU;
    let k_max = (40.0 / tau).floor() as usize;
    assert_eq!(
        obs.0.len(),
        2 * k_max,
        "{:?}",
        obs.0.iter().map(|e| e.t).collect::<Vec<_>>()
    );
    for k in 1..=k_max {
        let up = &obs.0[2 * (k - 1)];
        let down = &obs.0[2 * (k - 1) + 1];
        assert_eq!(up.direction, Direction::Rising);
        assert_eq!(down.direction, Direction::Falling);
        let c = tau * k as f64;
        // The time of a grazing crossing is ill-conditioned: error ≈ (interpolant error in x)
        // / |ẋ|, with |ẋ| ≈ √(2δ) = 1.4e-4 there and an interpolant error ≲ 10·rtol = 1e-8.
        let bound = 1e-8 / (2.0 * delta).sqrt();
        assert!(
            (up.t - (c - half_width)).abs() < bound,
            "{} vs {}",
            up.t,
            c - half_width
        );
        assert!((down.t - (c + half_width)).abs() < bound);
        assert!(down.t > up.t);
    }
}

#[test]
fn grazing_without_rate_needs_interior_samples() {
    let delta: f64 = 1e-3;
    let level = 1.0 - delta;
    let g = FnEvent(move |_t: f64, y: &Vector2<f64>| y[0] - level);
    let t0: f64 = 0.5;
    let y0 = Vector2::new(t0.cos(), -t0.sin());
    let tol = Tolerances::new(1e-6, 1e-9).unwrap();
    let k_max = (40.0 / std::f64::consts::TAU).floor() as usize;
    let mut obs = Events::default();
    Simulation::new(Harmonic, Dopri5::new(tol))
        .with_events(Event::new(g, Direction::Either).with_interior_samples(64))
        .run(t0, y0, 40.0, &mut obs)
        .unwrap();
    assert_eq!(obs.0.len(), 2 * k_max);
}

#[test]
fn terminal_event_rewinds_the_state() {
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Falling).terminal();
    let mut sim = Simulation::new(Harmonic, Dopri5::new(tol())).with_events(ev);
    let out = sim.run(0.0, Vector2::new(1.0, 0.0), 10.0, &mut ()).unwrap();
    assert_eq!(out.termination, Termination::TerminalEvent(0));
    assert!((out.t - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    assert!(out.y[0].abs() < 1e-9 && (out.y[1] + 1.0).abs() < 1e-9);
    // The run continues from the event without re-firing at the same instant.
    let mut obs = Events::default();
    let out2 = sim.run_on(10.0, &mut obs).unwrap();
    assert_eq!(out2.termination, Termination::TerminalEvent(0));
    assert!(
        (out2.t - (std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU)).abs() < 1e-9,
        "{}",
        out2.t
    );
}

#[test]
fn observers_see_steps_split_at_events_in_time_order() {
    #[derive(Default)]
    struct Order {
        last: f64,
        ok: bool,
        steps: usize,
        events: usize,
    }
    impl Observer<f64, 2> for Order {
        fn on_start(&mut self, t0: f64, _y: &Vector2<f64>) {
            self.last = t0;
            self.ok = true;
        }
        fn on_step<D: nonsmooth::integrate::DenseOutput<f64, 2>>(
            &mut self,
            s: &nonsmooth::drive::StepView<'_, f64, 2, D>,
        ) -> Control {
            self.ok &= s.t0 == self.last && s.t1 >= s.t0;
            self.last = s.t1;
            self.steps += 1;
            Control::Continue
        }
        fn on_event(&mut self, e: &EventRecord<f64, 2>) -> Control {
            self.ok &= e.t == self.last;
            self.events += 1;
            Control::Continue
        }
    }
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Either);
    let mut o = Order::default();
    Simulation::new(Harmonic, Dopri5::new(tol()))
        .with_events(ev)
        .run(0.0, Vector2::new(1.0, 0.0), 20.0, &mut o)
        .unwrap();
    assert!(o.ok);
    assert_eq!(o.events, 6);
    assert!(o.steps > o.events);
}

#[test]
fn observer_can_stop_the_run() {
    struct StopAfter(usize);
    impl Observer<f64, 2> for StopAfter {
        fn on_event(&mut self, _e: &EventRecord<f64, 2>) -> Control {
            self.0 -= 1;
            if self.0 == 0 {
                Control::Stop
            } else {
                Control::Continue
            }
        }
    }
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Either);
    let out = Simulation::new(Harmonic, Dopri5::new(tol()))
        .with_events(ev)
        .run(0.0, Vector2::new(1.0, 0.0), 20.0, &mut StopAfter(3))
        .unwrap();
    assert_eq!(out.termination, Termination::ObserverStopped);
    assert!((out.t - (std::f64::consts::FRAC_PI_2 + 2.0 * std::f64::consts::PI)).abs() < 1e-9);
}

#[test]
fn landing_grid_hits_exact_times() {
    #[derive(Default)]
    struct Ends(Vec<f64>);
    impl Observer<f64, 2> for Ends {
        fn on_step<D: nonsmooth::integrate::DenseOutput<f64, 2>>(
            &mut self,
            s: &nonsmooth::drive::StepView<'_, f64, 2, D>,
        ) -> Control {
            self.0.push(s.t1);
            Control::Continue
        }
    }
    let dt = 0.3;
    let mut e = Ends::default();
    Simulation::new(Harmonic, Dopri5::new(tol()))
        .landing_grid(Some((0.0, dt)))
        .unwrap()
        .run(0.0, Vector2::new(1.0, 0.0), 30.0, &mut e)
        .unwrap();
    for i in 1..100 {
        let g = i as f64 * dt;
        assert!(e.0.contains(&g), "grid point {g} not landed on");
    }
}

#[test]
fn restart_at_a_switching_surface_keeps_the_solution() {
    // x = cos t with a restart at every zero crossing: same crossings, same end state
    // (to the tolerance), and every restart refreshes the derivative cache (one evaluation).
    let ev = Event::new(Level::new(0, 0.0).unwrap(), Direction::Either);
    let mut plain = Events::default();
    let a = Simulation::new(Harmonic, Dopri5::new(tol()))
        .with_events(ev)
        .run(0.0, Vector2::new(1.0, 0.0), 20.0, &mut plain)
        .unwrap();
    let mut cut = Events::default();
    let b = Simulation::new(Harmonic, Dopri5::new(tol()))
        .with_events(ev.restart())
        .run(0.0, Vector2::new(1.0, 0.0), 20.0, &mut cut)
        .unwrap();
    assert_eq!(plain.0.len(), cut.0.len());
    for (p, c) in plain.0.iter().zip(&cut.0) {
        assert!((p.t - c.t).abs() < 1e-9);
    }
    assert!((a.y - b.y).norm() < 1e-8);
    assert!((b.y[0] - 20.0_f64.cos()).abs() < 1e-8);
    assert_ne!(a.stats.rhs_evals, b.stats.rhs_evals);
}
