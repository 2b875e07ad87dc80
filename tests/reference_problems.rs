//! The reference problems of `nonsmooth::testing`: closed forms satisfy their ODEs (finite
//! differences in time, and an independent classical RK4 written here), Jacobians and time
//! derivatives match finite differences, impact and crossing formulas agree with
//! independent computations, and the convergence-order fit sees the orders of RK4, Euler and
//! a tableau with wrong nodes.

use nalgebra::{SMatrix, SVector, Vector1, Vector2, Vector3};
use nonsmooth::Dynamics;
use nonsmooth::testing::{
    BouncingBall, DampedOscillator, ExactSolution, ExponentialDecay, ForcedOscillator,
    HarmonicOscillator, HarmonicZeroCrossings, Lorenz, NearGrazing, ProtheroRobinson,
    convergence_fit, convergence_order,
};

/// One classical RK4 step with nodes `c = (c2, c3, c4)` (correct: `(½, ½, 1)`).
fn rk4_step<D: Dynamics<f64, N>, const N: usize>(
    d: &D,
    t: f64,
    y: &SVector<f64, N>,
    h: f64,
    c: [f64; 3],
) -> SVector<f64, N> {
    let f = |t: f64, y: &SVector<f64, N>| {
        let mut dy = SVector::<f64, N>::zeros();
        d.rhs(t, y, &mut dy);
        dy
    };
    let k1 = f(t, y);
    let k2 = f(t + c[0] * h, &(y + k1 * (0.5 * h)));
    let k3 = f(t + c[1] * h, &(y + k2 * (0.5 * h)));
    let k4 = f(t + c[2] * h, &(y + k3 * h));
    y + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
}

const RK4: [f64; 3] = [0.5, 0.5, 1.0];

/// Integrates from `y0` at 0 to `t_end` with `n` RK4 steps on the grid `i·t_end/n`.
fn rk4<D: Dynamics<f64, N>, const N: usize>(
    d: &D,
    y0: SVector<f64, N>,
    t_end: f64,
    n: usize,
    c: [f64; 3],
) -> SVector<f64, N> {
    let h = t_end / n as f64;
    let mut y = y0;
    for i in 0..n {
        y = rk4_step(d, i as f64 * h, &y, h, c);
    }
    y
}

/// Explicit Euler on the same grid.
fn euler<D: Dynamics<f64, N>, const N: usize>(
    d: &D,
    y0: SVector<f64, N>,
    t_end: f64,
    n: usize,
) -> SVector<f64, N> {
    let h = t_end / n as f64;
    let mut y = y0;
    let mut dy = SVector::<f64, N>::zeros();
    for i in 0..n {
        d.rhs(i as f64 * h, &y, &mut dy);
        y += dy * h;
    }
    y
}

/// `max_t |d/dt exact − f(t, exact)|` relative to `max(1, |f|)`, by central differences of
/// the closed form (error ~ h²·y''' ≈ 1e-10).
fn ode_residual<P: ExactSolution<f64, N>, const N: usize>(p: &P, y0: &SVector<f64, N>) -> f64 {
    let h = 1e-5;
    let mut worst: f64 = 0.0;
    for i in 0..=200 {
        let t = 0.05 * i as f64;
        let dnum = (p.exact(t + h, y0) - p.exact(t - h, y0)) / (2.0 * h);
        let mut f = SVector::<f64, N>::zeros();
        p.rhs(t, &p.exact(t, y0), &mut f);
        worst = worst.max((dnum - f).amax() / f.amax().max(1.0));
    }
    worst
}

/// The exact solution against 20 000 RK4 steps on `[0, t_end]` (global error ~ 1e-13).
fn rk4_gap<P: ExactSolution<f64, N>, const N: usize>(
    p: &P,
    y0: SVector<f64, N>,
    t_end: f64,
) -> f64 {
    (rk4(p, y0, t_end, 20_000, RK4) - p.exact(t_end, &y0)).amax()
}

/// Jacobian and `∂f/∂t` against central differences at a few states and times.
fn check_derivatives<D: Dynamics<f64, N>, const N: usize>(d: &D, states: &[SVector<f64, N>]) {
    for (i, y) in states.iter().enumerate() {
        let t = 0.37 + 0.91 * i as f64;
        let jac: SMatrix<f64, N, N> = d.jacobian(t, y).expect("Jacobian provided");
        let f = |t: f64, y: &SVector<f64, N>| {
            let mut dy = SVector::<f64, N>::zeros();
            d.rhs(t, y, &mut dy);
            dy
        };
        for j in 0..N {
            let h = 1e-6 * y[j].abs().max(1.0);
            let mut yp = *y;
            let mut ym = *y;
            yp[j] += h;
            ym[j] -= h;
            let col = (f(t, &yp) - f(t, &ym)) / (2.0 * h);
            let gap = (col - jac.column(j)).amax();
            assert!(gap <= 1e-7 * jac.amax().max(1.0), "column {j}: {gap:e}");
        }
        let dt = d.time_derivative(t, y).expect("time derivative provided");
        let h = 1e-6;
        let num = (f(t + h, y) - f(t - h, y)) / (2.0 * h);
        assert!((num - dt).amax() <= 1e-7 * dt.amax().max(1.0), "df/dt");
    }
}

#[test]
fn problem_types_are_send_sync_copy() {
    fn check<T: Send + Sync + Copy + 'static>() {}
    check::<HarmonicOscillator<f64>>();
    check::<DampedOscillator<f64>>();
    check::<ExponentialDecay<f64>>();
    check::<ProtheroRobinson<f32>>();
    check::<ForcedOscillator<f64>>();
    check::<Lorenz<f64>>();
    check::<BouncingBall<f64>>();
    check::<nonsmooth::testing::BallDrop<f64>>();
    check::<HarmonicZeroCrossings<f64>>();
    check::<nonsmooth::testing::ZeroCrossing<f64>>();
    check::<NearGrazing<f64>>();
    check::<nonsmooth::testing::ConvergenceFit>();
}

#[test]
fn harmonic_oscillator_closed_form() {
    let p = HarmonicOscillator::<f64>::new(2.5).unwrap();
    let y0 = Vector2::new(0.7, -1.3);
    assert!(ode_residual(&p, &y0) < 1e-8);
    assert!(rk4_gap(&p, y0, 5.0) < 1e-11);
    // Energy is conserved by the closed form.
    let e0 = p.energy(&y0);
    for t in [0.3, 2.0, 17.0] {
        assert!((p.energy(&p.exact(t, &y0)) - e0).abs() < 1e-13 * e0);
    }
    check_derivatives(&p, &[y0, Vector2::new(-3.0, 0.2)]);
}

#[test]
fn damped_oscillator_closed_form() {
    for zeta in [0.0, 0.05, 0.5, 0.95] {
        let p = DampedOscillator::<f64>::new(3.0, zeta).unwrap();
        let y0 = Vector2::new(1.1, 0.4);
        assert!(ode_residual(&p, &y0) < 1e-8, "zeta = {zeta}");
        assert!(rk4_gap(&p, y0, 4.0) < 1e-11, "zeta = {zeta}");
        check_derivatives(&p, &[y0]);
    }
    // The envelope decays as e^{−ζω₀t}: after one damped period x returns scaled by it.
    let p = DampedOscillator::<f64>::new(2.0, 0.1).unwrap();
    let td = std::f64::consts::TAU / p.damped_frequency();
    let y0 = Vector2::new(1.0, -0.1 * 2.0);
    let y = p.exact(td, &y0);
    assert!((y[0] - (-0.1 * 2.0 * td).exp()).abs() < 1e-14);
}

#[test]
fn exponential_decay_closed_form() {
    for lambda in [-0.5, 0.0, 2.0] {
        let p = ExponentialDecay::<f64>::new(lambda).unwrap();
        let y0 = Vector1::new(1.5);
        assert!(ode_residual(&p, &y0) < 1e-8);
        assert!(rk4_gap(&p, y0, 3.0) < 1e-11);
        check_derivatives(&p, &[y0]);
    }
}

#[test]
fn prothero_robinson_closed_form() {
    for lambda in [1.0, 10.0] {
        let p = ProtheroRobinson::<f64>::new(lambda).unwrap();
        let y0 = Vector1::new(0.8);
        assert!(ode_residual(&p, &y0) < 1e-8);
        assert!(rk4_gap(&p, y0, 3.0) < 1e-11);
        check_derivatives(&p, &[y0, Vector1::new(-2.0)]);
    }
    // λ = 1 is ẏ = −y + sin t + cos t.
    let p = ProtheroRobinson::<f64>::new(1.0).unwrap();
    let mut dy = Vector1::zeros();
    p.rhs(0.7, &Vector1::new(0.3), &mut dy);
    assert!((dy[0] - (-0.3 + 0.7_f64.sin() + 0.7_f64.cos())).abs() < 1e-15);
}

#[test]
fn forced_oscillator_closed_form() {
    let canon = ForcedOscillator::<f64>::canonical();
    let general = ForcedOscillator::<f64>::new(1.7, -0.6, 0.45).unwrap();
    let y0 = Vector2::new(0.2, 0.9);
    for p in [canon, general] {
        assert!(ode_residual(&p, &y0) < 1e-8);
        assert!(rk4_gap(&p, y0, 6.0) < 1e-11);
        check_derivatives(&p, &[y0, Vector2::new(-1.0, 0.0)]);
    }
    // ẍ + x = cos 2t: x = (x₀ + ⅓)cos t + v₀ sin t − ⅓ cos 2t.
    let t: f64 = 1.3;
    let x = (0.2 + 1.0 / 3.0) * t.cos() + 0.9 * t.sin() - (2.0 * t).cos() / 3.0;
    assert!((canon.exact(t, &y0)[0] - x).abs() < 1e-15);
}

#[test]
fn f32_problems_agree_with_f64() {
    let p32 = ForcedOscillator::<f32>::canonical();
    let p64 = ForcedOscillator::<f64>::canonical();
    let y32 = p32.exact(2.0, &Vector2::new(0.2, 0.9));
    let y64 = p64.exact(2.0, &Vector2::new(0.2, 0.9));
    assert!((y32[0] as f64 - y64[0]).abs() < 1e-6);
    let d32 = DampedOscillator::<f32>::new(3.0, 0.2).unwrap();
    let d64 = DampedOscillator::<f64>::new(3.0, 0.2).unwrap();
    let a = d32.exact(1.0, &Vector2::new(1.0, 0.0));
    let b = d64.exact(1.0, &Vector2::new(1.0, 0.0));
    assert!((a[1] as f64 - b[1]).abs() < 1e-5);
    let l = Lorenz::<f32>::classic();
    let mut dy = Vector3::zeros();
    l.rhs(0.0, &Vector3::new(1.0, 2.0, 3.0), &mut dy);
    assert_eq!(dy, Vector3::new(10.0, 23.0, 2.0 - 8.0));
}

#[test]
fn lorenz_jacobian_and_trace() {
    let l = Lorenz::<f64>::classic();
    let states = [
        Vector3::new(1.0, 1.0, 1.0),
        Vector3::new(-8.5, -7.2, 27.1),
        Vector3::new(3.3, 10.0, 15.0),
    ];
    check_derivatives(&l, &states);
    for y in &states {
        let tr = l.jacobian(0.0, y).unwrap().trace();
        assert!((tr - l.lyapunov_sum()).abs() < 1e-14);
    }
    assert!((l.lyapunov_sum() + 41.0 / 3.0).abs() < 1e-14);
    assert_eq!(Lorenz::<f64>::TOP_LYAPUNOV_CLASSIC, 0.9056);
    // The equilibria (±√(β(ρ−1)), ±√(β(ρ−1)), ρ−1) are fixed points.
    let (_, rho, beta) = l.parameters();
    let q = (beta * (rho - 1.0)).sqrt();
    let mut dy = Vector3::zeros();
    l.rhs(0.0, &Vector3::new(q, q, rho - 1.0), &mut dy);
    assert!(dy.amax() < 1e-13);
}

// ---------------------------------------------------------------------------------------
// Impacts.

/// An independent event-driven simulation: free flight solved as a quadratic per bounce.
fn simulated_impacts(g: f64, r: f64, h0: f64, n: usize) -> Vec<(f64, f64)> {
    let (mut t, mut h, mut v) = (0.0, h0, 0.0);
    let mut out = Vec::new();
    for _ in 0..n {
        // h + v·τ − g·τ²/2 = 0, the positive root.
        let tau = (v + (v * v + 2.0 * g * h).sqrt()) / g;
        t += tau;
        let v_hit = v - g * tau;
        out.push((t, v_hit));
        h = 0.0;
        v = -r * v_hit;
    }
    out
}

#[test]
fn bouncing_ball_impacts_match_a_simulation() {
    let ball = BouncingBall::<f64>::new(9.81, 0.7).unwrap();
    let drop = ball.drop_from(1.3).unwrap();
    for (k, (t, v)) in simulated_impacts(9.81, 0.7, 1.3, 30)
        .into_iter()
        .enumerate()
    {
        assert!((drop.impact_time(k) - t).abs() < 1e-13 * t, "k = {k}");
        assert!(
            (drop.impact_speed(k) + v).abs() < 1e-12 * v.abs().max(1e-3),
            "k = {k}"
        );
        // The state just before and at the impact.
        let before = drop.state_at(t - 1e-9);
        assert!(before[0].abs() < 1e-8 && (before[1] - v).abs() < 1e-7);
        let at = drop.state_at(drop.impact_time(k));
        assert!(at[0].abs() < 1e-12 && (at[1] + 0.7 * v).abs() < 1e-12);
    }
}

#[test]
fn bouncing_ball_energy_and_zeno_time() {
    let (g, r, h0): (f64, f64, f64) = (9.81, 0.6, 2.0);
    let ball = BouncingBall::<f64>::new(g, r).unwrap();
    let drop = ball.drop_from(h0).unwrap();
    // Energy ratio r² per bounce: apex heights and impact speeds.
    assert!((drop.apex_height(0) - r * r * h0).abs() < 1e-15);
    for k in 1..20 {
        let ratio = drop.apex_height(k) / drop.apex_height(k - 1);
        assert!((ratio - r * r).abs() < 1e-14);
        let e_before = drop.impact_speed(k).powi(2) / 2.0;
        let e_prev = drop.impact_speed(k - 1).powi(2) / 2.0;
        assert!((e_before / e_prev - r * r).abs() < 1e-14);
        // The energy of the state along the flight is constant between impacts.
        let mid = 0.5 * (drop.impact_time(k - 1) + drop.impact_time(k));
        let e = ball.energy(&drop.state_at(mid));
        assert!((e - e_before).abs() < 1e-12 * e_before, "k = {k}");
    }
    // The reset.
    let mut y = Vector2::new(0.0, -3.0);
    ball.reset(&mut y);
    assert!(y[0] == 0.0 && (y[1] - 1.8).abs() < 1e-15);
    // Zeno: t_∞ = t₀(1+r)/(1−r) and the tail t_∞ − t_k = (2u₀/g)·r^{k+1}/(1−r).
    let t0 = (2.0 * h0 / g).sqrt();
    let tz = drop.zeno_time().unwrap();
    assert!((tz - t0 * (1.0 + r) / (1.0 - r)).abs() < 1e-14);
    let u0 = (2.0 * g * h0).sqrt();
    for k in [0usize, 3, 10, 30] {
        let tail = 2.0 * u0 / g * r.powi(k as i32 + 1) / (1.0 - r);
        assert!((tz - drop.impact_time(k) - tail).abs() < 1e-13, "k = {k}");
    }
    // Summing the simulated flight times converges to t_∞.
    let sim = simulated_impacts(g, r, h0, 80);
    assert!((sim[79].0 - tz).abs() < 1e-12);
    assert_eq!(drop.state_at(tz + 1.0), Vector2::zeros());
    assert_eq!(drop.impacts_until(tz), None);
    // Elastic: no accumulation, equal flight times.
    let elastic = BouncingBall::<f64>::new(g, 1.0)
        .unwrap()
        .drop_from(h0)
        .unwrap();
    assert_eq!(elastic.zeno_time(), None);
    let period = elastic.impact_time(1) - elastic.impact_time(0);
    assert!((elastic.impact_time(50) - elastic.impact_time(0) - 50.0 * period).abs() < 1e-12);
    assert!((period - 2.0 * t0).abs() < 1e-14);
}

#[test]
fn bouncing_ball_free_flight_is_the_dynamics() {
    // Between impacts state_at solves the ODE (RK4 is exact on the parabola).
    let ball = BouncingBall::<f64>::new(9.81, 0.8).unwrap();
    let drop = ball.drop_from(1.0).unwrap();
    let (ta, tb) = (drop.impact_time(2), drop.impact_time(3));
    let t1 = ta + 0.3 * (tb - ta);
    let t2 = ta + 0.9 * (tb - ta);
    let y1 = drop.state_at(t1);
    let h = (t2 - t1) / 10.0;
    let mut y = y1;
    for i in 0..10 {
        y = rk4_step(&ball, t1 + i as f64 * h, &y, h, RK4);
    }
    assert!((y - drop.state_at(t2)).amax() < 1e-13);
    check_derivatives(&ball, &[Vector2::new(1.0, -2.0)]);
}

#[test]
fn harmonic_zero_crossings_are_sign_changes() {
    let z = HarmonicZeroCrossings::<f64>::new(0.8, 3.1, 0.4).unwrap();
    let crossings = z.crossings_in(0.0, 10.0);
    // Count sign changes on a fine grid independently.
    let n = 200_000;
    let x = |t: f64| 0.8 * (3.1 * t + 0.4).cos();
    let mut changes = Vec::new();
    for i in 0..n {
        let (a, b) = (10.0 * i as f64 / n as f64, 10.0 * (i + 1) as f64 / n as f64);
        if x(a).signum() != x(b).signum() {
            changes.push((a, b, x(b) > 0.0));
        }
    }
    assert_eq!(crossings.len(), changes.len());
    for (c, (a, b, rising)) in crossings.iter().zip(changes) {
        assert!(a <= c.t && c.t <= b, "{} not in [{a}, {b}]", c.t);
        assert_eq!(c.rising, rising);
    }
    // The same signal from an initial state, evolved by the oscillator's closed form.
    let y0 = z.initial_state();
    let from = HarmonicZeroCrossings::<f64>::from_state(3.1, y0[0], y0[1]).unwrap();
    let osc = from.oscillator();
    for c in from.crossings_in(0.0, 10.0) {
        assert!(osc.exact(c.t, &y0)[0].abs() < 1e-14);
    }
    assert_eq!(from.crossings_in(0.0, 10.0).len(), crossings.len());
}

#[test]
fn near_grazing_crossing_pair() {
    for delta in [1e-2, 1e-6, 1e-10, 1e-13] {
        let g = NearGrazing::<f64>::new(2.0, 0.5, delta, 1.2).unwrap();
        let (up, down) = g.crossing_pair();
        assert!(up < 1.2 && 1.2 < down);
        // At the crossings x = L to rounding of x (|x'| small there, so the time is exact
        // to ~ulp(L)/|x'|).
        let osc = g.oscillator();
        let y0 = g.initial_state();
        for t in [up, down] {
            let x = osc.exact(t, &y0)[0];
            assert!(
                (x - 0.5).abs() < 8.0 * f64::EPSILON,
                "δ = {delta}: {:e}",
                x - 0.5
            );
        }
        // Above the level in between, below it just outside.
        let w = down - up;
        assert!(g.event_value(&g.state_at(1.2)) > 0.0);
        assert!((g.event_value(&g.state_at(1.2)) - delta).abs() < 1e-15);
        assert!(g.event_value(&g.state_at(up - 0.5 * w)) < 0.0);
        assert!(g.event_value(&g.state_at(down + 0.5 * w)) < 0.0);
        // θ = √(2δ/L)·(1 + O(δ/L)) for small δ (θ/ω with ω = 2).
        let series = (2.0 * delta / 0.5).sqrt() / 2.0;
        assert!(
            (g.half_width() / series - 1.0).abs() < 4.0 * delta + 1e-15,
            "δ = {delta}"
        );
        assert!((w - 2.0 * g.half_width()).abs() <= 4.0 * f64::EPSILON);
    }
}

// ---------------------------------------------------------------------------------------
// Convergence orders.

fn order_of<P: ExactSolution<f64, N>, const N: usize>(
    p: &P,
    y0: SVector<f64, N>,
    t_end: f64,
    ns: &[usize],
    method: impl Fn(&P, SVector<f64, N>, f64, usize) -> SVector<f64, N>,
) -> f64 {
    let exact = p.exact(t_end, &y0);
    let hs: Vec<f64> = ns.iter().map(|&n| t_end / n as f64).collect();
    let errs: Vec<f64> = ns
        .iter()
        .map(|&n| (method(p, y0, t_end, n) - exact).amax())
        .collect();
    let fit = convergence_fit(&hs, &errs).unwrap();
    assert!(fit.max_residual < 0.3, "{fit:?}");
    eprintln!(
        "observed order {:.4} (max residual {:.3})",
        fit.order, fit.max_residual
    );
    fit.order
}

const NS: [usize; 5] = [20, 40, 80, 160, 320];

#[test]
fn convergence_order_of_rk4_and_euler() {
    let forced = ForcedOscillator::<f64>::canonical();
    let y0 = Vector2::new(0.2, 0.9);
    let p = order_of(&forced, y0, 4.0, &NS, |d, y, t, n| rk4(d, y, t, n, RK4));
    assert!((p - 4.0).abs() < 0.15, "RK4: {p}");
    let pr = ProtheroRobinson::<f64>::new(2.0).unwrap();
    let p = order_of(&pr, Vector1::new(1.0), 3.0, &NS, |d, y, t, n| {
        rk4(d, y, t, n, RK4)
    });
    assert!((p - 4.0).abs() < 0.15, "RK4: {p}");
    let p = order_of(
        &pr,
        Vector1::new(1.0),
        3.0,
        &[200, 400, 800, 1600, 3200],
        euler,
    );
    assert!((p - 1.0).abs() < 0.05, "Euler: {p}");
}

#[test]
fn wrong_nodes_are_caught_only_by_non_autonomous_problems() {
    // RK4 with all nodes c_i = 0: the same method on autonomous problems (c never enters),
    // first order as soon as f depends on t.
    let wrong = [0.0, 0.0, 0.0];
    let osc = HarmonicOscillator::<f64>::new(1.5).unwrap();
    let y0 = Vector2::new(1.0, 0.0);
    let p = order_of(&osc, y0, 4.0, &NS, |d, y, t, n| rk4(d, y, t, n, wrong));
    assert!((p - 4.0).abs() < 0.15, "autonomous: {p}");
    let forced = ForcedOscillator::<f64>::canonical();
    let p = order_of(&forced, y0, 4.0, &NS, |d, y, t, n| rk4(d, y, t, n, wrong));
    assert!((p - 1.0).abs() < 0.15, "forced: {p}");
    let pr = ProtheroRobinson::<f64>::new(2.0).unwrap();
    let p = order_of(&pr, Vector1::new(1.0), 3.0, &NS, |d, y, t, n| {
        rk4(d, y, t, n, wrong)
    });
    assert!((p - 1.0).abs() < 0.15, "Prothero–Robinson: {p}");
}

#[test]
fn convergence_order_validates_input() {
    assert!(convergence_order(&[0.1, 0.05], &[1e-3, 1e-4]).is_err());
    assert!(convergence_order(&[0.1, 0.05, 0.025], &[1e-3, 1e-4]).is_err());
    assert!(convergence_order(&[0.1, -0.05, 0.025], &[1e-3, 1e-4, 1e-5]).is_err());
    assert!(convergence_order(&[0.1, 0.05, 0.025], &[1e-3, 0.0, 1e-5]).is_err());
    let p = convergence_order(&[0.1, 0.05, 0.025], &[2e-4, 2.5e-5, 3.125e-6]).unwrap();
    assert!((p - 3.0).abs() < 1e-12);
}
