//! The implicit cusp step (`integrate::cusp`): its order and rest time on the closed-form
//! creep `m·v̇ = −C·sgn(v)|v|^q`, its dense output through the approach to rest, and the
//! switch on the paper's exact contact law against DOP853 at rtol 1e-13.

use nalgebra::{SVector, Vector2};
use nonsmooth::Dynamics;
use nonsmooth::drive::{Control, EventRecord, Observer, Simulation, StepView};
use nonsmooth::event::{Direction, Event, Stop};
use nonsmooth::integrate::{
    CuspImplicit, CuspSwitch, DenseOutput, Dop853, StepOptions, Stepper, Tolerances,
};
use nonsmooth::systems::paper::{PAPER, PaperParameters};

/// `m·ẍ = −C·sgn(ẋ)|ẋ|^q`, state `(x, ẋ)`.
struct Creep {
    m: f64,
    c: f64,
    q: f64,
}

const CREEP: Creep = Creep {
    m: 2.0,
    c: 3.0,
    q: 0.18667,
};

impl Dynamics<f64, 2> for Creep {
    fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
        dy[0] = y[1];
        dy[1] = -self.c * y[1].signum() * y[1].abs().powf(self.q) / self.m;
    }
    fn velocity_exponent(&self) -> Option<f64> {
        Some(self.q)
    }
}

impl Creep {
    /// `k = C(1−q)/m`.
    fn k(&self) -> f64 {
        self.c * (1.0 - self.q) / self.m
    }
    /// The rest time `t* = m|v₀|^{1−q}/(C(1−q))`.
    fn rest_time(&self, v0: f64) -> f64 {
        v0.abs().powf(1.0 - self.q) / self.k()
    }
    /// `v(t) = sgn(v₀)(|v₀|^{1−q} − k·t)^{1/(1−q)}`, 0 after `t*`.
    fn velocity(&self, v0: f64, t: f64) -> f64 {
        let b = v0.abs().powf(1.0 - self.q) - self.k() * t;
        if b <= 0.0 {
            0.0
        } else {
            v0.signum() * b.powf(1.0 / (1.0 - self.q))
        }
    }
    /// `x(t) = x₀ + m(|v₀|^{2−q} − |v(t)|^{2−q})·sgn(v₀)/(C(2−q))`.
    fn position(&self, x0: f64, v0: f64, t: f64) -> f64 {
        let v = self.velocity(v0, t);
        x0 + v0.signum() * self.m * (v0.abs().powf(2.0 - self.q) - v.abs().powf(2.0 - self.q))
            / (self.c * (2.0 - self.q))
    }
    /// The time at which `|v| = v`: `(|v₀|^{1−q} − |v|^{1−q})/k`.
    fn time_at(&self, v0: f64, v: f64) -> f64 {
        (v0.abs().powf(1.0 - self.q) - v.abs().powf(1.0 - self.q)) / self.k()
    }
}

/// Steps of exactly `h` (a loose tolerance, the step capped at `h`) to `t_end`; the error
/// of `(x, ẋ)` at `t_end` against the closed form.
fn fixed_step_error(h: f64, t_end: f64, v0: f64) -> [f64; 2] {
    let tol = Tolerances::new(1.0, 1.0).unwrap();
    let opts = StepOptions::default()
        .with_h_max(h)
        .unwrap()
        .with_h_init(h)
        .unwrap();
    let mut st = CuspImplicit::with_options(tol, opts);
    st.reset_state(0.0, Vector2::new(0.0, v0));
    while st.current().0 < t_end {
        st.step(&CREEP, t_end).unwrap();
    }
    let y = st.current().1;
    [
        (y[0] - CREEP.position(0.0, v0, t_end)).abs(),
        (y[1] - CREEP.velocity(v0, t_end)).abs(),
    ]
}

#[test]
fn implicit_step_is_third_order_before_rest() {
    // v₀ = −1.5: t* = 0.839; the errors at t = 0.5, on the smooth part.
    let v0 = -1.5;
    let t_end = 0.5;
    assert!(CREEP.rest_time(v0) > t_end + 0.2);
    let errs: Vec<[f64; 2]> = [40, 80, 160]
        .iter()
        .map(|&n| fixed_step_error(t_end / f64::from(n), t_end, v0))
        .collect();
    for c in 0..2 {
        for w in errs.windows(2) {
            let order = (w[0][c] / w[1][c]).log2();
            assert!(
                (2.7..=3.4).contains(&order),
                "component {c}: observed order {order} (errors {:e}, {:e})",
                w[0][c],
                w[1][c]
            );
        }
    }
}

/// One adaptive run from `(0, v₀)` to `2t*`: the relative error of the time at which
/// `|v| = 10⁻⁴|v₀|` (located on the dense output), and the dense output's largest error in
/// `v` between step ends, relative to the larger error at the step's ends plus one error
/// scale `atol + rtol·|v|`, on the smooth part (steps
/// ending before `|v| = 10⁻²|v₀|`) and on the approach to rest.
fn rest_run(rtol: f64, v0: f64) -> (f64, f64, f64) {
    let tol = Tolerances::per_component(rtol, [rtol, rtol * 1e-2]).unwrap();
    let mut st = CuspImplicit::new(tol);
    st.reset_state(0.0, Vector2::new(0.0, v0));
    let t_star = CREEP.rest_time(v0);
    let t_end = 2.0 * t_star;
    let v_eps = 1e-4 * v0.abs();
    let t_smooth = CREEP.time_at(v0, 1e-2 * v0);
    let mut t_eps = None;
    let mut dense_smooth = 0.0f64;
    let mut dense_rest = 0.0f64;
    while st.current().0 < t_end {
        st.step(&CREEP, t_end).unwrap();
        let d = st.dense();
        let (t0, t1) = d.span();
        let (y0, y1) = d.endpoints();
        for j in 1..8 {
            let t = t0 + (t1 - t0) * f64::from(j) / 8.0;
            let v = d.interpolate(t).unwrap()[1];
            let exact = CREEP.velocity(v0, t);
            // Against the error the step's ends already carry (the global error) plus
            // one error scale: what interpolation adds.
            let e_ends = (y0[1] - CREEP.velocity(v0, t0))
                .abs()
                .max((y1[1] - CREEP.velocity(v0, t1)).abs());
            let e = (v - exact).abs() / (e_ends + tol.atol[1] + rtol * exact.abs());
            if t1 < t_smooth {
                dense_smooth = dense_smooth.max(e);
            } else {
                dense_rest = dense_rest.max(e);
            }
        }
        if t_eps.is_none() && y0[1].abs() > v_eps && y1[1].abs() <= v_eps {
            // |v(t)| = v_eps on the dense output (bisection: |v| decreases on the step).
            let (mut a, mut b) = (t0, t1);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                if d.interpolate(m).unwrap()[1].abs() > v_eps {
                    a = m;
                } else {
                    b = m;
                }
            }
            t_eps = Some(0.5 * (a + b));
        }
        // At rest after t*(1 + 10⁻³): |v| below its absolute tolerance, x at x(t*).
        if t1 > t_star * (1.0 + 1e-3) {
            let x_rest = CREEP.position(0.0, v0, t_star);
            assert!(
                (y1[0] - x_rest).abs() <= 10.0 * rtol * x_rest.abs(),
                "rtol {rtol}: x at rest {} vs {x_rest}",
                y1[0]
            );
            assert!(
                y1[1].abs() <= tol.atol[1],
                "rtol {rtol}: v at rest {}",
                y1[1]
            );
        }
    }
    let t_eps = t_eps.expect("|v| fell below v_eps");
    let t_ref = CREEP.time_at(v0, v_eps);
    ((t_eps - t_ref).abs() / t_ref, dense_smooth, dense_rest)
}

#[test]
fn rest_time_to_tolerance_and_dense_output() {
    for rtol in [1e-6, 1e-8, 1e-10] {
        for v0 in [1.0, -0.3] {
            let (rel, smooth, rest) = rest_run(rtol, v0);
            println!(
                "rtol {rtol:e} v0 {v0}: time of |v| = 1e-4|v0| rel. error {rel:.2e}; dense output error / (end error + scale) {smooth:.2} (smooth), {rest:.2} (approach to rest)"
            );
            assert!(
                rel <= 10.0 * rtol,
                "rtol {rtol}, v0 {v0}: time off by {rel:e}"
            );
            assert!(smooth <= 2.0, "rtol {rtol}, v0 {v0}: dense output {smooth}");
            assert!(rest <= 10.0, "rtol {rtol}, v0 {v0}: dense output {rest}");
        }
    }
}

/// Sections (steps land on `t = 2πk/ω`) and impacts.
struct Record {
    period: f64,
    sections: Vec<Vector2<f64>>,
    impacts: u64,
    end: Vector2<f64>,
}

impl Observer<f64, 2> for Record {
    fn on_step<D: DenseOutput<f64, 2>>(&mut self, s: &StepView<'_, f64, 2, D>) -> Control {
        let k = (s.t1 / self.period).round();
        if k >= 1.0 && s.t1 == k * self.period {
            self.sections.push(s.y1);
        }
        Control::Continue
    }
    fn on_event(&mut self, _e: &EventRecord<f64, 2>) -> Control {
        self.impacts += 1;
        Control::Continue
    }
}

fn paper_run<St: Stepper<f64, 2>>(
    omega: f64,
    k0: u32,
    y0: Vector2<f64>,
    periods: u32,
    st: St,
) -> Record {
    let mut p = PAPER;
    p.eta = 0.0;
    let period = PaperParameters::period(omega);
    let impact = Event::new(
        Stop {
            position: 0,
            velocity: 1,
            level: p.x_i,
        },
        Direction::Rising,
    );
    let mut sim = Simulation::new(p.oscillator::<f64>(omega).unwrap(), st)
        .with_events(impact)
        .landing_grid(Some((0.0, period)))
        .unwrap();
    let mut rec = Record {
        period,
        sections: Vec::new(),
        impacts: 0,
        end: y0,
    };
    let t0 = f64::from(k0) * period;
    let out = sim
        .run(t0, y0, t0 + f64::from(periods) * period, &mut rec)
        .unwrap();
    rec.end = out.y;
    rec
}

fn tol(rtol: f64) -> Tolerances<f64, 2> {
    Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2]).unwrap()
}

/// Compares the switch at rtol 1e-8 and 1e-10 from `y0` at `t = 2πk0/ω` with `reference`
/// (sections and impacts): `bounds[r]` on `max |Δx|`, `max |Δẋ|` at the r-th rtol.
fn compare(
    omega: f64,
    k0: u32,
    y0: Vector2<f64>,
    periods: u32,
    reference: &Record,
    bounds: [[f64; 2]; 2],
) {
    for (rtol, bound) in [1e-8, 1e-10].into_iter().zip(bounds) {
        let st = CuspSwitch::dopri5(tol(rtol), 1e-6).unwrap();
        let r = paper_run(omega, k0, y0, periods, st);
        assert_eq!(r.sections.len(), reference.sections.len());
        let mut dx = 0.0f64;
        let mut dv = 0.0f64;
        for (a, b) in r.sections.iter().zip(&reference.sections) {
            dx = dx.max((a[0] - b[0]).abs());
            dv = dv.max((a[1] - b[1]).abs());
        }
        println!(
            "ω = {omega}, from period {k0}, rtol {rtol:e}: max |Δx| {dx:.2e} m, max |Δẋ| {dv:.2e} m/s over {periods} sections; impacts {} vs {}",
            r.impacts, reference.impacts
        );
        assert_eq!(r.impacts, reference.impacts, "ω = {omega}, rtol {rtol:e}");
        assert!(
            dx <= bound[0] && dv <= bound[1],
            "ω = {omega}, rtol {rtol:e}: {dx:e} m, {dv:e} m/s"
        );
    }
}

/// The creep from rest (the first period of W1 at ω = 20.465 rad/s, and ω = 14 and 17
/// rad/s where the cart stays on the stop) against DOPRI5 on the exact law at rtol 1e-11,
/// then W1's next three periods (impacts, chaotic) against DOP853 at rtol 1e-13.
///
/// DOP853 at rtol 1e-13 through the creep takes about 6 minutes (measured, 4 periods of
/// W1 from rest: the creep makes any explicit method stiffness-bound), too slow for a
/// test; there DOPRI5 at rtol 1e-11, an independent explicit method, is the reference.
/// W1's 1100 periods run in `examples/exact_law.rs -- --cusp`.
#[test]
fn switch_agrees_with_explicit_references() {
    let rest = Vector2::new(PAPER.static_equilibrium().unwrap(), 0.0);
    let dopri = nonsmooth::integrate::Dopri5::new(tol(1e-11));
    let mut w1_after_creep = rest;
    for omega in [20.465, 14.0, 17.0] {
        let reference = paper_run(omega, 0, rest, 1, dopri.clone());
        // Measured: ≤ 2.9e-11 m, 5.0e-10 m/s at 1e-8; ≤ 1.3e-13 m, 3.4e-12 m/s at 1e-10.
        compare(
            omega,
            0,
            rest,
            1,
            &reference,
            [[1e-9, 1e-8], [1e-11, 1e-10]],
        );
        if omega == 20.465 {
            w1_after_creep = reference.end;
        }
    }
    let reference = paper_run(20.465, 1, w1_after_creep, 3, Dop853::new(tol(1e-13)));
    compare(
        20.465,
        1,
        w1_after_creep,
        3,
        &reference,
        [[1e-7, 1e-6], [1e-9, 1e-8]],
    );
}

/// Two degrees of freedom: the paper's exact laws on the first, a spring to a second mass.
/// The system declares the cusp ([`Dynamics::cusp_exponent`]), the switch steps the creep
/// implicitly (Gauss–Seidel over the two velocities), and agrees with DOPRI5 at rtol 1e-11.
#[test]
fn two_degrees_of_freedom_creep() {
    use nonsmooth::excite::UnbalancedRotor;
    use nonsmooth::force::LinearSpring;
    use nonsmooth::model::{Element, Load, Mechanical};
    let omega = 17.0;
    let mut p = PAPER;
    p.eta = 0.0;
    let m = Mechanical::with_masses([p.m, 1.0])
        .unwrap()
        .with_elements((
            Element::on_dof(0, p.laws::<f64>().unwrap()).unwrap(),
            Element::between(1, 0, LinearSpring::new(100.0).unwrap()).unwrap(),
        ))
        .with_loads(Load::on_dof(0, UnbalancedRotor::new(p.m0e, omega).unwrap()).unwrap());
    assert_eq!(Dynamics::<f64, 4>::velocity_exponent(&m), None);
    assert_eq!(Dynamics::<f64, 4>::cusp_exponent(&m), Some(p.n3));
    let x = PAPER.static_equilibrium().unwrap();
    let y0 = SVector::<f64, 4>::new(x, x, 0.0, 0.0);
    let t_end = PaperParameters::period(omega);
    let tol4 = |rtol: f64| {
        Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-4, rtol * 1e-2, rtol * 1e-2])
            .unwrap()
    };
    let mut reference = Simulation::new(&m, nonsmooth::integrate::Dopri5::new(tol4(1e-11)));
    let yr = reference.run(0.0, y0, t_end, &mut ()).unwrap().y;
    for rtol in [1e-8, 1e-10] {
        let mut sim = Simulation::new(&m, CuspSwitch::dopri5(tol4(rtol), 1e-6).unwrap());
        let y = sim.run(0.0, y0, t_end, &mut ()).unwrap().y;
        let c = sim.stepper().counts();
        let d = (y - yr).abs();
        println!(
            "2 DOF, rtol {rtol:e}: |Δq| {:.1e} {:.1e} m, |Δq̇| {:.1e} {:.1e} m/s; implicit steps {}; RHS {} vs DOPRI5 1e-11 {}",
            d[0],
            d[1],
            d[2],
            d[3],
            c.implicit_steps,
            sim.stepper().stats().rhs_evals,
            reference.stepper().stats().rhs_evals
        );
        assert!(c.implicit_steps > 0);
        assert!(d[0].max(d[1]) <= 1e3 * rtol * 1e-4 && d[2].max(d[3]) <= 1e3 * rtol * 1e-2);
    }
}

/// `ẍ = −sgn(ẋ)|ẋ|^{1/4}` with or without the cusp declared.
struct Quarter(bool);

impl Dynamics<f64, 2> for Quarter {
    fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
        dy[0] = y[1];
        dy[1] = -y[1].signum() * y[1].abs().powf(0.25);
    }
    fn velocity_exponent(&self) -> Option<f64> {
        self.0.then_some(0.25)
    }
}

/// `ẍ = −c·ẋ`: stiff, but no cusp.
struct Damped(f64);

impl Dynamics<f64, 2> for Damped {
    fn rhs(&self, _t: f64, y: &SVector<f64, 2>, dy: &mut SVector<f64, 2>) {
        dy[0] = y[1];
        dy[1] = -self.0 * y[1];
    }
}

#[test]
fn an_undeclared_cusp_is_named_instead_of_crept_through() {
    // Before, CuspSwitch::dopri5 on the undeclared cusp crept with steps of ~1e-8 s and
    // needed 1e8 steps to reach t = 2.4.
    let tol = Tolerances::new(1e-8, 1e-10).unwrap();
    let y0 = Vector2::new(0.0, 1.0);
    let mut sim = Simulation::new(Quarter(false), CuspSwitch::dopri5(tol, 1e-6).unwrap());
    let e = sim.run(0.0, y0, 5.0, &mut ()).unwrap_err();
    let steps = sim.stepper().stats().accepted;
    println!("undeclared: {e} after {steps} steps");
    assert!(e.to_string().contains("cusp_exponent"), "{e}");
    assert!(steps < 100_000, "{steps} steps");
    match e {
        nonsmooth::drive::RunError::Integrate(
            nonsmooth::integrate::IntegrateError::UndeclaredCusp {
                exponent, index, ..
            },
        ) => {
            assert_eq!(index, 0);
            assert!((exponent - 0.25).abs() < 0.05, "q ≈ {exponent}");
        }
        other => panic!("{other:?}"),
    }
    // Declared: the implicit step takes it to rest (v = 0 at t = 4/3·1^{3/4} = 1.333…).
    let mut sim = Simulation::new(Quarter(true), CuspSwitch::dopri5(tol, 1e-6).unwrap());
    let out = sim.run(0.0, y0, 5.0, &mut ()).unwrap();
    assert!(out.y[1].abs() < 1e-6, "{:?}", out.y);
    // A stiff linear damping (ρ = 1e6 at every velocity) is not taken for a cusp.
    let mut sim = Simulation::new(Damped(1e6), CuspSwitch::dopri5(tol, 1e-6).unwrap());
    sim.run(0.0, Vector2::new(0.0, 1e-7), 0.01, &mut ())
        .unwrap();
}
