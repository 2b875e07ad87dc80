//! Runs through modes (set-valued Coulomb stick–slip, rigid sticking) with the default
//! stepper options: every release is found, and the condition each mode enforces holds
//! *between* step ends (dense samples, at least 50 per forcing period), against independent
//! integrations written here (exact linear flows between switchings, closed-form releases).

use std::f64::consts::TAU;

use nalgebra::SVector;
use nonsmooth::drive::RunError;
use nonsmooth::drive::Simulation;
use nonsmooth::drive::{
    Control, Coulomb, EventRecord, ModeError, Observer, SlipMode, StepView, StickSlip, run_modes,
    run_with_sticking,
};
use nonsmooth::event::{Direction, Event, EventError, Gap, NewtonImpact};
use nonsmooth::excite::{Constant, Excitation, Harmonic};
use nonsmooth::force::{LinearSpring, ViscousDamper};
use nonsmooth::integrate::{DenseOutput, Dopri5, IntegrateError, Tolerances};
use nonsmooth::model::{Coordinate, Element, Load, Mechanical};
use nonsmooth::sample::ImpactSequence;
use nonsmooth::systems::BouncingBallTable;
use proptest::prelude::*;

fn tol() -> Tolerances<f64, 2> {
    Tolerances::new(1e-10, 1e-12).unwrap()
}

/// Samples every step of every mode at `t0 + k·dt` (a grid at least as fine as `dt`, plus
/// the step's end) and keeps the worst value of `violation(mode, t, y)` (positive: the
/// mode's condition is violated by that much).
struct Between<F> {
    mode: &'static str,
    dt: f64,
    violation: F,
    worst: f64,
    worst_at: (f64, &'static str),
    samples: usize,
    modes: Vec<(f64, &'static str)>,
}

impl<F: Fn(&'static str, f64, &SVector<f64, 2>) -> f64> Between<F> {
    fn new(dt: f64, violation: F) -> Self {
        Self {
            mode: "",
            dt,
            violation,
            worst: f64::NEG_INFINITY,
            worst_at: (0.0, ""),
            samples: 0,
            modes: Vec::new(),
        }
    }
}

impl<F: Fn(&'static str, f64, &SVector<f64, 2>) -> f64> Observer<f64, 2> for Between<F> {
    fn on_mode(&mut self, t: f64, mode: &'static str) {
        self.mode = mode;
        self.modes.push((t, mode));
    }
    fn on_step<D: DenseOutput<f64, 2>>(&mut self, s: &StepView<'_, f64, 2, D>) -> Control {
        let n = ((s.t1 - s.t0) / self.dt).ceil().max(1.0) as usize;
        let mut y = s.y1;
        for k in 1..=n {
            let t = if k == n {
                s.t1
            } else {
                s.t0 + (s.t1 - s.t0) * k as f64 / n as f64
            };
            s.state_at(t, &mut y);
            let v = (self.violation)(self.mode, t, &y);
            self.samples += 1;
            if v > self.worst {
                self.worst = v;
                self.worst_at = (t, self.mode);
            }
        }
        Control::Continue
    }
}

// ---------------------------------------------------------------------------------------
// An independent stick–slip integration of a 1-DOF linear oscillator with Coulomb friction
// against a surface of velocity u(t): exact flows of each mode, switchings by a fine scan
// and bisection.

/// `ẍ + x = f(t) − σF_k` while slipping (σ = sgn(ẋ − u)); stuck, `ẋ = u(t)` while
/// `|λ| = |u̇ + x − f(t)| ≤ F_s`.
struct Reference<'a> {
    /// Forcing `f(t)`.
    f: &'a dyn Fn(f64) -> f64,
    /// Slip flow: state at `t` from `(t0, x0, v0)` with friction force `ff` (exact).
    slip: &'a dyn Fn(f64, f64, f64, f64, f64) -> (f64, f64),
    /// Surface velocity and acceleration `(u, u̇)`.
    u: &'a dyn Fn(f64) -> (f64, f64),
    /// Its integral from `t0` to `t`.
    u_int: &'a dyn Fn(f64, f64) -> f64,
    fs: f64,
    fk: f64,
}

impl Reference<'_> {
    fn lambda(&self, t: f64, x: f64) -> f64 {
        (self.u)(t).1 + x - (self.f)(t)
    }

    /// The first `t ∈ (a + dt, b]` where `g` leaves the sign `sign` it has in the mode (the
    /// first `dt` of a mode is skipped: right after a switching `g` is zero to rounding), to
    /// 1e-14 (scan `dt`).
    fn first_root(g: impl Fn(f64) -> f64, sign: f64, a: f64, b: f64, dt: f64) -> Option<f64> {
        let mut t0 = a + dt;
        let g0 = sign;
        assert!(
            g(t0) * sign > 0.0,
            "reference: a mode shorter than {dt} at t = {a}"
        );
        while t0 < b {
            let t1 = (t0 + dt).min(b);
            let g1 = g(t1);
            if g0.signum() != g1.signum() {
                let (mut lo, mut hi) = (t0, t1);
                for _ in 0..200 {
                    let m = 0.5 * (lo + hi);
                    if g(m).signum() == g0.signum() && g(m) != 0.0 {
                        lo = m;
                    } else {
                        hi = m;
                    }
                    if hi - lo < 1e-14 {
                        break;
                    }
                }
                return Some(hi);
            }
            t0 = t1;
        }
        None
    }

    /// Mode transitions `(t, mode)` from `(0, x0, v0)` in `mode` up to `t_end`.
    fn transitions(
        &self,
        mut mode: SlipMode,
        x0: f64,
        v0: f64,
        t_end: f64,
    ) -> Vec<(f64, SlipMode)> {
        let (mut t, mut x, mut v) = (0.0, x0, v0);
        let mut out = Vec::new();
        let dt = 2e-3;
        while t < t_end {
            let (tn, xn) = match mode {
                SlipMode::Stick => {
                    let xs = x;
                    let t0 = t;
                    let g = |s: f64| self.lambda(s, xs + (self.u_int)(t0, s)).abs() - self.fs;
                    match Self::first_root(g, -1.0, t, t_end, dt) {
                        Some(tr) => (tr, xs + (self.u_int)(t0, tr)),
                        None => break,
                    }
                }
                _ => {
                    let ff = if mode == SlipMode::Forward {
                        -self.fk
                    } else {
                        self.fk
                    };
                    let (t0, x0, v0) = (t, x, v);
                    let g = |s: f64| (self.slip)(t0, x0, v0, ff, s).1 - (self.u)(s).0;
                    match Self::first_root(g, -ff.signum(), t, t_end, dt) {
                        Some(tr) => (tr, (self.slip)(t0, x0, v0, ff, tr).0),
                        None => break,
                    }
                }
            };
            t = tn;
            x = xn;
            v = (self.u)(t).0;
            let lambda = self.lambda(t, x);
            mode = match mode {
                SlipMode::Stick if lambda > 0.0 => SlipMode::Backward,
                SlipMode::Stick => SlipMode::Forward,
                _ if lambda.abs() <= self.fs => SlipMode::Stick,
                _ if lambda > 0.0 => SlipMode::Backward,
                _ => SlipMode::Forward,
            };
            out.push((t, mode));
        }
        out
    }
}

/// The exact flow of `ẍ + x = a·cos(ωt) + ff` from `(t0, x0, v0)`: `(x(t), ẋ(t))`.
fn forced_linear(a: f64, w: f64) -> impl Fn(f64, f64, f64, f64, f64) -> (f64, f64) {
    move |t0, x0, v0, ff, t| {
        let xp = |s: f64| a * (w * s).cos() / (1.0 - w * w) + ff;
        let vp = |s: f64| -a * w * (w * s).sin() / (1.0 - w * w);
        let (dx, dv) = (x0 - xp(t0), v0 - vp(t0));
        let (s, c) = (t - t0).sin_cos();
        (dx * c + dv * s + xp(t), -dx * s + dv * c + vp(t))
    }
}

/// Mode transitions `(t, mode entered)`.
type Transitions = Vec<(f64, SlipMode)>;

/// A Den Hartog oscillator `ẍ + x + F sgn ẋ ∋ F₀ cos ωt` (m = k = F₀ = 1): the crate's
/// transitions with the default stepper options, the worst violation of the static limit
/// (stuck) and of the slip direction (slipping) between step ends, and the reference.
fn den_hartog(ratio: f64, w: f64, periods: f64) -> (Transitions, Transitions, f64, usize) {
    let model = Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(Element::on_dof(0, LinearSpring::new(1.0).unwrap()).unwrap())
        .with_loads(Load::on_dof(0, Harmonic::cosine(1.0, w).unwrap()).unwrap());
    let friction = Coulomb::new(
        Coordinate::dof(0).unwrap(),
        Constant::new(0.0).unwrap(),
        ratio,
        ratio,
    )
    .unwrap();
    let mut system = StickSlip::new(&model, friction, || Dopri5::new(tol()));
    let t_end = periods * TAU / w;
    let y0 = SVector::from([0.0, 0.0]);
    let start = system.mode_at(0.0, &y0);
    let period = TAU / w;
    let mut watch = Between::new(period / 50.0, |mode, t, y: &SVector<f64, 2>| match mode {
        // Stuck: |k x − F₀ cos ωt| ≤ F_s, and at rest.
        "stick" => ((y[0] - (w * t).cos()).abs() - ratio).max(y[1].abs()),
        "forward" => -y[1],
        "backward" => y[1],
        _ => f64::INFINITY,
    });
    let run = run_modes(&mut system, start, 0.0, y0, t_end, 1_000_000, &mut watch).unwrap();
    let f = move |t: f64| (w * t).cos();
    let slip = forced_linear(1.0, w);
    let reference = Reference {
        f: &f,
        slip: &slip,
        u: &|_| (0.0, 0.0),
        u_int: &|_, _| 0.0,
        fs: ratio,
        fk: ratio,
    };
    let exact = reference.transitions(start, 0.0, 0.0, t_end);
    assert!(
        watch.samples as f64 >= 50.0 * periods,
        "{} samples",
        watch.samples
    );
    (run.transitions, exact, watch.worst, watch.samples)
}

/// Compares two transition lists: same modes, times within `tol`.
fn same_transitions(got: &[(f64, SlipMode)], exact: &[(f64, SlipMode)], tol: f64) -> f64 {
    assert_eq!(
        got.len(),
        exact.len(),
        "{:?}\nvs\n{:?}",
        &got[..got.len().min(6)],
        &exact[..exact.len().min(6)]
    );
    let mut worst: f64 = 0.0;
    for (k, (a, b)) in got.iter().zip(exact).enumerate() {
        assert_eq!(a.1, b.1, "transition {k}: {a:?} vs {b:?}");
        worst = worst.max((a.0 - b.0).abs());
        assert!((a.0 - b.0).abs() < tol, "transition {k}: {a:?} vs {b:?}");
    }
    worst
}

#[test]
fn den_hartog_sticks_twice_per_period_with_default_options() {
    // F/F₀ = 0.9, r = 0.6: two stick intervals per period. Before the mode conditions
    // declared their time scale, one stick from t = 1.196 to t = 2093.8 hid 399 releases
    // (the static limit exceeded by up to 0.135 between step ends).
    let (got, exact, worst, _) = den_hartog(0.9, 0.6, 200.0);
    let sticks = got.iter().filter(|t| t.1 == SlipMode::Stick).count();
    assert_eq!(sticks, 400);
    let dt = same_transitions(&got, &exact, 1e-8);
    println!(
        "400 sticks; transition times within {dt:.1e} of the exact flow; worst violation between step ends {worst:.1e}"
    );
    assert!(
        worst < 1e-9,
        "condition violated between step ends by {worst}"
    );
}

#[test]
fn den_hartog_other_ratios_match_the_exact_flow() {
    // Two more sets: a long stick per half period (F/F₀ = 0.95, r = 0.3) and short ones
    // near the sticking boundary (F/F₀ = 0.5, r = 0.8).
    for (ratio, w) in [(0.95, 0.3), (0.5, 0.8)] {
        let (got, exact, worst, _) = den_hartog(ratio, w, 40.0);
        let dt = same_transitions(&got, &exact, 1e-8);
        println!(
            "F/F0 = {ratio}, r = {w}: {} transitions within {dt:.1e}; worst violation {worst:.1e}",
            got.len()
        );
        assert!(worst < 1e-9, "F/F0 = {ratio}, r = {w}: violated by {worst}");
    }
}

/// A belt whose speed is forced: `u(t) = u₀ + u₁ sin Ωt` (an excitation of the user's own,
/// declaring its frequency so that its time scale bounds the stuck steps).
#[derive(Debug, Clone, Copy)]
struct Belt {
    u0: f64,
    u1: f64,
    omega: f64,
}

impl Excitation<f64> for Belt {
    fn force(&self, t: f64) -> f64 {
        self.u0 + self.u1 * (self.omega * t).sin()
    }
    fn force_rate(&self, t: f64) -> f64 {
        self.u1 * self.omega * (self.omega * t).cos()
    }
    fn angular_frequency(&self, _t: f64) -> Option<f64> {
        Some(self.omega)
    }
}

#[test]
fn belt_with_forced_speed_matches_the_exact_flow() {
    // m = k = 1, F_s = F_k = 1, belt u = 0.3 + 0.5 sin(0.7 t): stick (moving with the
    // belt) until |u̇ + x| = F_s, slip with constant friction.
    let belt = Belt {
        u0: 0.3,
        u1: 0.5,
        omega: 0.7,
    };
    let (fs, fk) = (1.0, 0.8);
    let model = Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(Element::on_dof(0, LinearSpring::new(1.0).unwrap()).unwrap());
    let friction = Coulomb::new(Coordinate::dof(0).unwrap(), belt, fs, fk).unwrap();
    let mut system = StickSlip::new(&model, friction, || Dopri5::new(tol()));
    let y0 = SVector::from([0.0, belt.force(0.0)]);
    let t_end = 30.0 * TAU / belt.omega;
    let mut watch = Between::new(TAU / belt.omega / 50.0, |mode, t, y: &SVector<f64, 2>| {
        let (u, ud) = (belt.force(t), belt.force_rate(t));
        match mode {
            "stick" => ((ud + y[0]).abs() - fs).max((y[1] - u).abs() - 1e-7),
            "forward" => -(y[1] - u),
            "backward" => y[1] - u,
            _ => f64::INFINITY,
        }
    });
    let run = run_modes(
        &mut system,
        SlipMode::Stick,
        0.0,
        y0,
        t_end,
        100_000,
        &mut watch,
    )
    .unwrap();
    let f = |_: f64| 0.0;
    let slip = |t0: f64, x0: f64, v0: f64, ff: f64, t: f64| {
        let (s, c) = (t - t0).sin_cos();
        ((x0 - ff) * c + v0 * s + ff, -(x0 - ff) * s + v0 * c)
    };
    let u = |t: f64| (belt.force(t), belt.force_rate(t));
    let u_int = |t0: f64, t: f64| {
        belt.u0 * (t - t0)
            - belt.u1 / belt.omega * ((belt.omega * t).cos() - (belt.omega * t0).cos())
    };
    let reference = Reference {
        f: &f,
        slip: &slip,
        u: &u,
        u_int: &u_int,
        fs,
        fk,
    };
    let exact = reference.transitions(SlipMode::Stick, 0.0, belt.force(0.0), t_end);
    assert!(exact.len() > 20, "{exact:?}");
    let dt = same_transitions(&run.transitions, &exact, 1e-8);
    println!(
        "belt: {} transitions within {dt:.1e}; worst violation {:.1e}",
        exact.len(),
        watch.worst
    );
    assert!(
        watch.worst < 1e-9,
        "violated by {} at {:?}",
        watch.worst,
        watch.worst_at
    );
}

// ---------------------------------------------------------------------------------------
// Rigid sticking on a stop.

/// Stick and release times, the worst violation between step ends, the impacts.
type StopRun = (
    Vec<f64>,
    Vec<f64>,
    f64,
    ImpactSequence<f64, Gap<f64, 1, Constant<f64>>>,
);

/// `ẍ + 2ζẋ + x = cos ωt` with a rigid stop at `x = d` (restitution `e`): the run with
/// sticking, the releases, and the worst violation of "stuck only while the stop pushes"
/// (`cos ωt ≥ d`) between step ends.
fn impact_oscillator(w: f64, d: f64, e: f64, periods: f64) -> StopRun {
    let zeta = 0.05;
    let model = Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements((
            Element::on_dof(0, LinearSpring::new(1.0).unwrap()).unwrap(),
            Element::on_dof(0, ViscousDamper::new(2.0 * zeta).unwrap()).unwrap(),
        ))
        .with_loads(Load::on_dof(0, Harmonic::cosine(1.0, w).unwrap()).unwrap());
    let gap = Gap::below(Coordinate::dof(0).unwrap(), Constant::new(d).unwrap());
    let impact = NewtonImpact::new(gap, e, model.mass_matrix()).unwrap();
    let period = TAU / w;
    let mut watch = Between::new(period / 50.0, |mode, t, y: &SVector<f64, 2>| match mode {
        // Stuck at the stop: the force it must supply, cos ωt − d, pushes (≥ 0), and the
        // body is on it.
        "stuck" => (d - (w * t).cos()).max((y[0] - d).abs() * 1e3),
        "free" => (y[0] - d) * 1e3,
        _ => f64::INFINITY,
    });
    let mut seq = ImpactSequence::on_surface(0, gap, 0.0, 1_000_000).unwrap();
    let (out, log) = run_with_sticking(
        &model,
        &impact,
        || Dopri5::new(tol()),
        0.0,
        SVector::from([0.0, 0.0]),
        periods * period,
        1_000_000,
        &mut (&mut watch, &mut seq),
    )
    .unwrap();
    assert_eq!(out.t, periods * period);
    (log.stick, log.release, watch.worst, seq)
}

#[test]
fn impact_oscillator_releases_every_period_where_the_stop_stops_pushing() {
    // ω = 0.2, d = 0.5, e = 0.5: chatter, stick, and release at the phase acos d each
    // period. Before: one stick of 18 periods while the contact force was tensile (up to
    // 1.5).
    let (w, d) = (0.2, 0.5);
    let (stick, release, worst, seq) = impact_oscillator(w, d, 0.5, 20.0);
    assert_eq!(
        (stick.len(), release.len()),
        (20, 19),
        "{stick:?} {release:?}"
    );
    for (k, &tr) in release.iter().enumerate() {
        // Closed form: cos ωt = d, falling.
        let phase = (w * tr).rem_euclid(TAU);
        assert!(
            (phase - d.acos()).abs() < 1e-8,
            "release {k} at {tr}: phase {phase}"
        );
        // Between two sticks.
        assert!(
            stick[k] < tr && tr < stick[k + 1],
            "{k}: {stick:?} {release:?}"
        );
    }
    assert!(
        worst < 1e-9,
        "stuck while the stop pulls, or off the stop, by {worst}"
    );
    // No zero-velocity "impact" at the moment of sticking: every recorded impact moves
    // into the stop (before: one with ġ ≈ −5e-5, 5e-13 s after the previous, per stick).
    let imps = seq.impacts();
    assert!(imps.len() > 100);
    for i in imps {
        assert!(i.velocity > 0.0, "{i:?}");
        assert!(i.interval.is_none_or(|dt| dt > 1e-9), "{i:?}");
    }
}

#[test]
fn impact_oscillator_other_parameters_release_at_the_closed_form_phase() {
    // A third set: ω = 0.3, d = 0.3, e = 0.3.
    let (w, d) = (0.3, 0.3);
    let (stick, release, worst, _) = impact_oscillator(w, d, 0.3, 15.0);
    assert!(
        stick.len() >= 14 && release.len() >= 13,
        "{stick:?} {release:?}"
    );
    for &tr in &release {
        let phase = (w * tr).rem_euclid(TAU);
        assert!(
            (phase - d.acos()).abs() < 1e-8,
            "release at {tr}: phase {phase}"
        );
    }
    assert!(worst < 1e-9, "{worst}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, .. ProptestConfig::default() })]

    /// Random forcing amplitudes, frequencies and friction limits: no stick interval of
    /// `StickSlip` violates the static limit at any interior sample.
    #[test]
    fn stick_slip_never_violates_the_static_limit_between_step_ends(
        amplitude in 0.3f64..3.0,
        w in 0.2f64..2.5,
        fraction in 0.2f64..1.2,
        kinetic in 0.5f64..1.0,
    ) {
        prop_assume!((w - 1.0).abs() > 0.05);
        let fs = fraction * amplitude;
        let model = Mechanical::with_masses([1.0]).unwrap()
            .with_elements(Element::on_dof(0, LinearSpring::new(1.0).unwrap()).unwrap())
            .with_loads(Load::on_dof(0, Harmonic::cosine(amplitude, w).unwrap()).unwrap());
        let friction = Coulomb::new(Coordinate::dof(0).unwrap(), Constant::new(0.0).unwrap(), fs, kinetic * fs).unwrap();
        let mut system = StickSlip::new(&model, friction, || Dopri5::new(tol()));
        let y0 = SVector::from([0.0, 0.0]);
        let start = system.mode_at(0.0, &y0);
        let mut watch = Between::new(TAU / w / 50.0, |mode, t, y: &SVector<f64, 2>| match mode {
            "stick" => ((y[0] - amplitude * (w * t).cos()).abs() - fs) / amplitude,
            _ => f64::NEG_INFINITY,
        });
        run_modes(&mut system, start, 0.0, y0, 15.0 * TAU / w, 100_000, &mut watch).unwrap();
        prop_assert!(watch.worst < 1e-9, "violated by {} at {:?}", watch.worst, watch.worst_at);
    }

    /// Random forcing of the rigid impact oscillator: stuck only while the stop pushes.
    #[test]
    fn rigid_sticking_never_holds_a_pulling_contact(
        w in 0.1f64..0.5,
        d in 0.1f64..0.8,
        e in 0.2f64..0.7,
    ) {
        let (_, _, worst, _) = impact_oscillator(w, d, e, 6.0);
        prop_assert!(worst < 1e-9, "violated by {worst}");
    }
}

// ---------------------------------------------------------------------------------------
// Starts and long runs.

fn block() -> Mechanical<f64, 1, Element<f64, 1, LinearSpring<f64>>> {
    Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(Element::on_dof(0, LinearSpring::new(80.0).unwrap()).unwrap())
}

#[test]
fn a_start_mode_that_contradicts_the_state_is_an_error() {
    let model = block();
    let friction = Coulomb::new(
        Coordinate::dof(0).unwrap(),
        Constant::new(0.0).unwrap(),
        1.0,
        0.8,
    )
    .unwrap();
    let mut system = StickSlip::new(&model, friction, || Dopri5::new(tol()));
    // Stuck while the spring pulls with 80 N > F_s = 1.
    let r = run_modes(
        &mut system,
        SlipMode::Stick,
        0.0,
        SVector::from([1.0, 0.0]),
        1.0,
        100,
        &mut (),
    );
    assert!(
        matches!(r, Err(RunError::Mode(ModeError::InconsistentStart { value, .. })) if value == 80.0),
        "{r:?}"
    );
    // Forward slip while v_r < 0.
    let r = run_modes(
        &mut system,
        SlipMode::Forward,
        0.0,
        SVector::from([0.0, -1.0]),
        1.0,
        100,
        &mut (),
    );
    assert!(
        matches!(r, Err(RunError::Mode(ModeError::InconsistentStart { .. }))),
        "{r:?}"
    );
    // Zero segments is a parameter error, not an accumulation.
    let r = run_modes(
        &mut system,
        SlipMode::Stick,
        0.0,
        SVector::from([0.0, 0.0]),
        1.0,
        0,
        &mut (),
    );
    assert!(matches!(r, Err(RunError::Parameter(_))), "{r:?}");
    // A rigid start 1 cm inside the table.
    let p = BouncingBallTable::with_gamma(1.2, 0.5).unwrap();
    let r = run_with_sticking(
        &p.model::<f64>().unwrap(),
        &p.impact::<f64>().unwrap(),
        || Dopri5::new(tol()),
        0.0,
        SVector::from([-0.01, 0.0]),
        1.0,
        100,
        &mut (),
    );
    assert!(
        matches!(r, Err(RunError::Mode(ModeError::InconsistentStart { .. }))),
        "{r:?}"
    );
}

#[test]
fn a_block_stuck_exactly_at_the_static_limit_leaves_it() {
    // Dragged by a belt at 0.5 m/s: k x = F_s exactly at the start, the spring force
    // growing; it must slip at once, as it does from 1e-9 below the limit.
    let model = Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(Element::on_dof(0, LinearSpring::new(1.0).unwrap()).unwrap());
    let friction = Coulomb::new(
        Coordinate::dof(0).unwrap(),
        Constant::new(0.5).unwrap(),
        1.0,
        0.6,
    )
    .unwrap();
    let mut system = StickSlip::new(&model, friction, || Dopri5::new(tol()));
    let at = run_modes(
        &mut system,
        SlipMode::Stick,
        0.0,
        SVector::from([1.0, 0.5]),
        20.0,
        100,
        &mut (),
    )
    .unwrap();
    let below = run_modes(
        &mut system,
        SlipMode::Stick,
        0.0,
        SVector::from([1.0 - 1e-9, 0.5]),
        20.0,
        100,
        &mut (),
    )
    .unwrap();
    assert_eq!(
        at.transitions[0],
        (0.0, SlipMode::Backward),
        "{:?}",
        at.transitions
    );
    assert_eq!(at.transitions.len(), below.transitions.len());
    for (a, b) in at.transitions.iter().zip(&below.transitions) {
        assert_eq!(a.1, b.1);
        assert!((a.0 - b.0).abs() < 1e-6, "{a:?} vs {b:?}");
    }
}

/// The deepest penetration of the table at any step end and 8 interior points per step.
struct Depth {
    p: BouncingBallTable,
    deepest: f64,
}

impl Observer<f64, 2> for Depth {
    fn on_step<D: DenseOutput<f64, 2>>(&mut self, s: &StepView<'_, f64, 2, D>) -> Control {
        let mut y = s.y1;
        for k in 1..=9 {
            let t = s.t0 + (s.t1 - s.t0) * k as f64 / 9.0;
            s.state_at(if k == 9 { s.t1 } else { t }, &mut y);
            self.deepest = self.deepest.max(self.p.table_motion(t).0 - y[0]);
        }
        Control::Continue
    }
    fn on_event(&mut self, _e: &EventRecord<f64, 2>) -> Control {
        Control::Continue
    }
}

#[test]
fn a_ball_riding_the_table_late_in_a_long_run_stays_on_it() {
    // Γ = 1.2, e = 0.5 for 6 s from t₀ = 10⁴ and 10⁶ s. Before: the table's acceleration
    // in the sticking mode was a central difference whose step grew with |t|; the ball
    // ended 0.4 mm (t₀ = 10⁴) and 14 mm (t₀ = 10⁶) below the table.
    for t0 in [1e4, 1e6] {
        let p = BouncingBallTable::with_gamma(1.2, 0.5).unwrap();
        let (s, sd) = p.table_motion(t0);
        let mut depth = Depth {
            p,
            deepest: f64::NEG_INFINITY,
        };
        let (_, log) = run_with_sticking(
            &p.model::<f64>().unwrap(),
            &p.impact::<f64>().unwrap(),
            || Dopri5::new(tol()),
            t0,
            SVector::from([s, sd + 2.0]),
            t0 + 6.0,
            10_000,
            &mut depth,
        )
        .unwrap();
        assert!(!log.stick.is_empty() && !log.release.is_empty(), "{log:?}");
        for &tr in &log.release {
            let phase = (TAU * tr).rem_euclid(TAU);
            assert!(
                (phase - (1.0f64 / 1.2).asin()).abs() < 1e-6,
                "t₀ = {t0}: release at {tr}: {phase}"
            );
        }
        // The documented drift tolerance (1e-8 m) bounds the penetration everywhere.
        assert!(depth.deepest < 1e-8, "t₀ = {t0}: {}", depth.deepest);
    }
}

#[test]
fn a_run_that_needs_more_steps_than_the_cap_fails_up_front() {
    // Γ = 6, e = 1 for 10⁷ table periods: the table's time scale (T/16) bounds every step,
    // so 1.6·10⁸ steps are needed; before, the run went to the 10⁸-step cap.
    let p = BouncingBallTable::with_gamma(6.0, 1.0).unwrap();
    let table = p.table::<f64>().unwrap();
    let mut sim = Simulation::new(p.model::<f64>().unwrap(), Dopri5::new(tol()))
        .with_events(Event::new(table, Direction::Rising).with_reset(p.impact::<f64>().unwrap()));
    let r = sim.run(0.0, SVector::from([0.0, 3.0]), 1e7, &mut ());
    assert!(
        matches!(r, Err(RunError::Integrate(IntegrateError::WorkExceedsCap { needed, .. })) if needed > 1e8),
        "{r:?}"
    );
}

// ---------------------------------------------------------------------------------------
// Issue 49: simultaneous contacts at the start, a contact without friction.

#[test]
fn touching_balls_at_the_start_name_the_time_stepper() {
    // Newton's cradle of three unit balls on a line, touching (the positions are measured
    // from each ball's place in the chain, so every gap is 0), the first moving at 1 m/s
    // into the others, e = 1. Ball i hits ball i + 1 when g_i = x_i − x_{i+1} rises
    // through 0. Both contacts are closed at the start and the first is being struck: a
    // simultaneous impact, whose outcome depends on how the impulses are shared (Moreau's
    // LCP gives (−1/3, 2/3, 2/3), a sequence (0, 0, 1)). Before, the run stopped after its
    // first step with an error calling it sticking.
    let model = Mechanical::with_masses([1.0; 3]).unwrap();
    let contact = |i: usize| {
        let gap = Gap::below(Coordinate::relative(i, i + 1).unwrap(), ());
        let impact = NewtonImpact::new(gap, 1.0, model.mass_matrix()).unwrap();
        Event::new(gap, Direction::Rising).with_reset(impact)
    };
    let tol = Tolerances::<f64, 6>::new(1e-10, 1e-12).unwrap();
    let mut sim = Simulation::new(model, Dopri5::new(tol)).with_events((contact(0), contact(1)));
    let y0 = SVector::from([0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    let r = sim.run(0.0, y0, 1.0, &mut ());
    match &r {
        Err(
            e @ RunError::Event(EventError::SimultaneousContacts {
                t,
                moving,
                other,
                rate,
            }),
        ) => {
            assert_eq!((*t, *moving, *other, *rate), (0.0, 0, 1, 1.0));
            let msg = e.to_string();
            assert!(
                msg.contains("nonsmooth::timestep::MoreauJean") && !msg.contains("sticking"),
                "{msg}"
            );
        }
        other => panic!("expected SimultaneousContacts, got {other:?}"),
    }
    // Spaced by 1 cm the impacts come one at a time: the textbook cradle, (0, 0, 1).
    let spaced = SVector::from([-0.02, -0.01, 0.0, 1.0, 0.0, 0.0]);
    let out = sim.run(0.0, spaced, 1.0, &mut ()).unwrap();
    let v = [out.y[3], out.y[4], out.y[5]];
    assert!(
        v[0].abs() < 1e-12 && v[1].abs() < 1e-12 && (v[2] - 1.0).abs() < 1e-12,
        "{v:?}"
    );
    // Touching but at rest: nothing is struck, the run goes on.
    let rest = SVector::from([0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert!(sim.run(0.0, rest, 1.0, &mut ()).is_ok());
}

#[test]
fn a_block_on_a_belt_without_friction_moves_as_a_free_oscillator() {
    // m = 2, k = 8, belt at 0.5 m/s, F_s = F_k = 0, started "stuck" at x = 0 moving with the
    // belt (the force needed to hold it, k x = 0, is within the static limit 0). Without
    // friction there is no stick: x = (u/ω) sin ωt, ω = √(k/m) = 2, v = u cos ωt. Before,
    // the block stayed stuck: x(10) = 5 with the spring pulling 40 N, no transition (the
    // stick's end |λ| − F_s = |λ| only touches 0, at t = 0).
    let model = Mechanical::with_masses([2.0])
        .unwrap()
        .with_elements(Element::on_dof(0, LinearSpring::new(8.0).unwrap()).unwrap());
    let friction = Coulomb::new(
        Coordinate::dof(0).unwrap(),
        Constant::new(0.5).unwrap(),
        0.0,
        0.0,
    )
    .unwrap();
    let mut system = StickSlip::new(&model, friction, || Dopri5::new(tol()));
    let exact = |t: f64| (0.25 * (2.0 * t).sin(), 0.5 * (2.0 * t).cos());
    let mut modes = Between::new(0.05, |mode, t, y| {
        // Every sample on the free flow (and never in the stick mode).
        let (x, v) = exact(t);
        let off = (y[0] - x).abs().max((y[1] - v).abs());
        if mode == "stick" { f64::INFINITY } else { off }
    });
    let run = run_modes(
        &mut system,
        SlipMode::Stick,
        0.0,
        SVector::from([0.0, 0.5]),
        10.0,
        100,
        &mut modes,
    )
    .unwrap();
    let (x, v) = exact(10.0);
    assert!(
        (run.outcome.y[0] - x).abs() < 1e-8 && (run.outcome.y[1] - v).abs() < 1e-8,
        "{:?} vs ({x}, {v}); transitions {:?}",
        run.outcome.y,
        run.transitions
    );
    assert!(
        modes.worst < 1e-8,
        "{} at {:?}",
        modes.worst,
        modes.worst_at
    );
    assert!(run.transitions.iter().all(|&(_, m)| m != SlipMode::Stick));
    // Started in slip from the same state: the same flow.
    let slip = run_modes(
        &mut system,
        SlipMode::Backward,
        0.0,
        SVector::from([0.0, 0.5]),
        10.0,
        100,
        &mut (),
    )
    .unwrap();
    assert!(
        (slip.outcome.y[0] - x).abs() < 1e-8 && (slip.outcome.y[1] - v).abs() < 1e-8,
        "{:?}",
        slip.outcome.y
    );
    // 1e-9 faster than the belt: v_r = (u + 1e-9) cos 2t − u crosses 0 near t = 0 and
    // rises 1e-9 above it around t = π. Each zero of v_r ended a slip segment and the next
    // began at v_r = 0 exactly, where a first step of 5e-13 left v_r at 0 (the increment
    // below the rounding of u) and ended the segment again: 100 segments at t = π − 3e-5,
    // a Zeno error. Without friction nothing changes at v_r = 0: one free segment.
    let v0 = 0.5 + 1e-9;
    let fast = run_modes(
        &mut system,
        SlipMode::Forward,
        0.0,
        SVector::from([0.0, v0]),
        10.0,
        100,
        &mut (),
    )
    .unwrap();
    let (x, v) = (v0 / 2.0 * 20.0f64.sin(), v0 * 20.0f64.cos());
    assert!(
        (fast.outcome.y[0] - x).abs() < 1e-8 && (fast.outcome.y[1] - v).abs() < 1e-8,
        "{:?} vs ({x}, {v})",
        fast.outcome.y
    );
    assert!(fast.transitions.is_empty(), "{:?}", fast.transitions);
}
