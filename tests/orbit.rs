//! Periodic orbits by shooting: the three coexisting period-1 orbits of a hardening Duffing
//! oscillator (one a saddle no simulation shows), Liouville's formula for the product of
//! the multipliers, forward simulation onto the stable orbits; the paper's period-2 orbit
//! at ω = 19 and its top Lyapunov exponent against the QR estimator.
//!
//! Measured (this file's output):
//! - Duffing `ẍ + 0.1ẋ + x + x³ = 0.5 cos 1.6t`: orbits at x(0) = −0.3355 (μ = −0.3675 ±
//!   0.7350i), −1.1510 (saddle, μ = 2.1962 and 0.3075), 1.3368 (μ = 0.3840 ± 0.7265i), in
//!   3–5 Newton iterations from one-harmonic balance; |μ₁μ₂| = e^{−cT} to 7e-12.
//! - Paper, ω = 19: period-2 orbit μ = −0.24379, −7.4e-6, λ₁ = −2.1341 1/s (QR over 300
//!   periods on it: −2.1355 ± 0.0014; the reference −2.13); the period-1 orbit it
//!   doubled from is a saddle with μ = −10.73 (a flip).
//! - Multiple shooting, double well `ẍ + 0.05ẋ − x + x³ = 0.1 cos 0.4t`: the hilltop orbit
//!   (μ₁ = 4.12e6, ln μ₁/T = 0.9697) from the linear response in 16 segments, 3 iterations;
//!   single shooting from the same guess does not converge. On the Duffing orbits above,
//!   4 segments give single shooting's orbit to 1e-8 and its multipliers to 1e-7.

use nalgebra::SVector;
use nonsmooth::Dynamics;
use nonsmooth::drive::Simulation;
use nonsmooth::excite::Harmonic;
use nonsmooth::force::{CubicSpring, ViscousDamper};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{TangentSpace, tangent_tolerances};
use nonsmooth::model::{Element, Load, Mechanical};
use nonsmooth::orbit::{Shooting, modulus};
use nonsmooth::sample::Stroboscopic;
use nonsmooth::systems::paper::lyapunov::norm as paper_norm;

const C: f64 = 0.1;
const F: f64 = 0.5;
const OMEGA: f64 = 1.6;

fn duffing() -> impl Dynamics<f64, 2> + Clone {
    duffing_at(OMEGA)
}

/// One-harmonic balance `x ≈ a cos ωt + b sin ωt` of `ẍ + cẋ + x + x³ = F cos ωt`: with
/// `κ = 1 − ω² + ¾A²`, `(κ² + c²ω²)A² = F²`, `a = Fκ/(κ² + c²ω²)`, `b = Fcω/(κ² + c²ω²)`.
/// Returns the states `(a, bω)` at t = 0 of every amplitude root.
fn harmonic_balance() -> Vec<SVector<f64, 2>> {
    let f = |u: f64| {
        let k = 1.0 - OMEGA * OMEGA + 0.75 * u;
        (k * k + (C * OMEGA).powi(2)) * u - F * F
    };
    let mut roots = Vec::new();
    let (mut u0, du) = (1e-6, 1e-3);
    while u0 < 10.0 {
        let u1 = u0 + du;
        if f(u0).signum() != f(u1).signum() {
            let (mut lo, mut hi) = (u0, u1);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if f(lo).signum() == f(mid).signum() {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            roots.push(0.5 * (lo + hi));
        }
        u0 = u1;
    }
    roots
        .into_iter()
        .map(|u| {
            let k = 1.0 - OMEGA * OMEGA + 0.75 * u;
            let d = k * k + (C * OMEGA).powi(2);
            SVector::from([F * k / d, F * C * OMEGA / d * OMEGA])
        })
        .collect()
}

#[test]
fn duffing_three_period_one_orbits_one_saddle() {
    let guesses = harmonic_balance();
    assert_eq!(
        guesses.len(),
        3,
        "harmonic balance: three amplitudes at ω = {OMEGA}"
    );
    let period = std::f64::consts::TAU / OMEGA;
    let tol = Tolerances::new(1e-11, 1e-13).unwrap();
    let shooting = Shooting::new(
        duffing(),
        (),
        tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-11, 1e-13).unwrap(),
    );
    let mut orbits = Vec::new();
    for g in &guesses {
        let orbit = shooting.find(0.0, period, *g).unwrap();
        // Liouville: det Φ = exp(∫ tr J) = e^{−cT}.
        let det = modulus(&orbit.multipliers[0]) * modulus(&orbit.multipliers[1]);
        let exact = (-C * period).exp();
        println!(
            "guess {:?} -> orbit {:?}, μ = {:?}, |μ1 μ2| = {det} vs {exact}, {} iterations",
            g.as_slice(),
            orbit.state.as_slice(),
            orbit.multipliers,
            orbit.iterations
        );
        assert!((det - exact).abs() < 1e-8 * exact, "{det} vs {exact}");
        assert!(orbit.residual < 1e-8);
        orbits.push(orbit);
    }
    // Three distinct orbits.
    for i in 0..3 {
        for j in 0..i {
            assert!((orbits[i].state - orbits[j].state).norm() > 1e-3);
        }
    }
    // Exactly one saddle: one real multiplier > 1 (the middle amplitude).
    let unstable: Vec<_> = orbits.iter().filter(|o| !o.is_stable()).collect();
    assert_eq!(unstable.len(), 1);
    let mu = unstable[0].multipliers[0];
    assert!(mu.im == 0.0 && mu.re > 1.0, "saddle multiplier {mu}");
    // Forward simulation from each harmonic-balance guess of a stable orbit lands on it.
    for (g, o) in guesses.iter().zip(&orbits).filter(|(_, o)| o.is_stable()) {
        let mut sim = Simulation::new(duffing(), Dopri5::new(tol));
        let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, period, 0.0, 1000).unwrap();
        sim.run(0.0, *g, 400.0 * period, &mut strobe).unwrap();
        let last = strobe.points().last().unwrap().y;
        assert!(
            (last - o.state).amax() < 1e-7,
            "simulation {:?} vs shooting {:?}",
            last.as_slice(),
            o.state.as_slice()
        );
    }
}

#[test]
fn paper_period_two_orbit_at_omega_19() {
    use nonsmooth::systems::paper::PAPER;
    let omega = 19.0;
    let period = std::f64::consts::TAU / omega;
    let sys = PAPER.oscillator::<f64>(omega).unwrap();
    // A point on the attractor: 200 periods from rest.
    let tol = Tolerances::per_component(1e-10, [1e-14, 1e-12]).unwrap();
    let rest = SVector::from([PAPER.static_equilibrium().unwrap(), 0.0]);
    let mut sim = Simulation::new(sys, Dopri5::new(tol));
    let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, period, 0.0, 1000).unwrap();
    sim.run(0.0, rest, 200.0 * period, &mut strobe).unwrap();
    let guess = strobe.points().last().unwrap().y;
    let t0 = strobe.points().last().unwrap().t;
    let shooting = Shooting::new(
        sys,
        (),
        tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12).unwrap(),
    );
    let orbit = shooting.find(t0, 2.0 * period, guess).unwrap();
    // Newton on one period from the same point finds the period-1 orbit the period-2 orbit
    // doubled from: unstable, with a real multiplier below −1 (a flip).
    let once = shooting.find(t0, period, guess).unwrap();
    let lambda = orbit.top_exponent();
    // The QR estimate on the same orbit (an independent average over 300 periods).
    let mut qr = TangentSpace::<f64, 2, 2, 6, _, _>::new(
        sys,
        Dopri5::new(tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12).unwrap()),
        paper_norm(),
    )
    .unwrap();
    qr.start(t0, orbit.state).unwrap();
    let spec = qr.estimate(2.0 * period, 150).unwrap();
    println!(
        "period-2 orbit {:?}: μ = {:?}, λ = {:?}, {} iterations; QR {:?} ± {:?}; period-1 orbit {:?}, μ = {:?}",
        orbit.state.as_slice(),
        orbit.multipliers,
        orbit.exponents(),
        orbit.iterations,
        spec.exponents,
        spec.spread,
        once.state.as_slice(),
        once.multipliers,
    );
    assert!(!once.is_stable());
    let flip = once.multipliers[0];
    assert!(
        flip.im == 0.0 && flip.re < -1.0,
        "period-1 multiplier {flip}"
    );
    assert!(orbit.is_stable());
    assert!(
        (lambda - spec.top()).abs() < 0.02 + 3.0 * spec.spread[0],
        "{lambda} vs {}",
        spec.top()
    );
    assert!((lambda - (-2.13)).abs() < 0.05, "{lambda} vs −2.13 1/s");
    // Period 2, not 1: the point after one period is elsewhere.
    let after_one = shooting.map(t0, orbit.state, period).unwrap();
    assert!((after_one - orbit.state).amax() > 1e-6);
}

#[test]
fn impact_oscillator_orbit_through_restitution() {
    // ẍ + 0.1ẋ + x = cos 1.5t, rigid stop at x = 0.3 with e = 0.8: a period-1 orbit with one
    // impact; Φ crosses the impact by the saltation matrix (det e²), so |μ₁μ₂| = e²e^{−cT}.
    use nonsmooth::event::{Direction, Event, Level, Restitution};
    use nonsmooth::force::LinearSpring;
    let (c, e, d, omega) = (0.1_f64, 0.8_f64, 0.3_f64, 1.5_f64);
    let model = Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(
            Element::on_dof(
                0,
                (
                    LinearSpring::new(1.0).unwrap(),
                    ViscousDamper::new(c).unwrap(),
                ),
            )
            .unwrap(),
        )
        .with_loads(Load::on_dof(0, Harmonic::cosine(1.0, omega).unwrap()).unwrap());
    let events = Event::new(Level::new(0, d).unwrap(), Direction::Rising)
        .with_reset(Restitution::new(1, e).unwrap());
    let period = std::f64::consts::TAU / omega;
    let tol = Tolerances::new(1e-11, 1e-13).unwrap();
    // A point on the attractor after 100 periods.
    let mut sim = Simulation::new(model, Dopri5::new(tol)).with_events(events);
    let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, period, 0.0, 1000).unwrap();
    sim.run(
        0.0,
        SVector::from([d - 0.5, 0.0]),
        100.0 * period,
        &mut strobe,
    )
    .unwrap();
    let guess = strobe.points().last().unwrap().y;
    let shooting = Shooting::new(
        model,
        events,
        tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-11, 1e-13).unwrap(),
    );
    let orbit = shooting.find(0.0, period, guess).unwrap();
    let det = modulus(&orbit.multipliers[0]) * modulus(&orbit.multipliers[1]);
    let exact = e * e * (-c * period).exp();
    println!(
        "impact orbit {:?}: μ = {:?}, λ = {:?}",
        orbit.state.as_slice(),
        orbit.multipliers,
        orbit.exponents()
    );
    assert!((det - exact).abs() < 1e-7 * exact, "{det} vs {exact}");
    assert!(orbit.is_stable());
    // A complex pair: both exponents are ln(det)/(2T) = −0.103272 (the QR and two-trajectory
    // estimators give −0.10332 in tests/impact_lyapunov.rs).
    for l in orbit.exponents() {
        assert!((l - exact.ln() / (2.0 * period)).abs() < 1e-7);
    }
}

#[test]
fn invalid_settings_are_errors() {
    use nonsmooth::orbit::{ContinuationSettings, Extremum, OrbitError, follow};
    let tol = Tolerances::new(1e-9, 1e-11).unwrap();
    let shooting = Shooting::new(
        duffing(),
        (),
        tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-9, 1e-11).unwrap(),
    );
    let y = SVector::from([0.1, 0.0]);
    for period in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            shooting.find(0.0, period, y),
            Err(OrbitError::InvalidSetting { .. })
        ));
    }
    assert!(shooting.clone().with_max_iterations(0).is_err());
    assert!(shooting.clone().with_newton_tolerance(0.0).is_err());
    assert!(shooting.clone().with_newton_tolerance(f64::NAN).is_err());
    assert!(matches!(
        shooting.extremum(0.0, 1.0, y, 2, Extremum::Min),
        Err(OrbitError::InvalidSetting { .. })
    ));
    // One Newton iteration from far away does not converge: a clear error, not a wrong orbit.
    let once = shooting.clone().with_max_iterations(1).unwrap();
    assert!(matches!(
        once.find(
            0.0,
            std::f64::consts::TAU / OMEGA,
            SVector::from([5.0, 5.0])
        ),
        Err(OrbitError::NotConverged { .. })
    ));
    assert!(ContinuationSettings::new(1.0, 0.0, 0.1).is_err());
    assert!(ContinuationSettings::new(0.0, 1.0, 0.0).is_err());
    assert!(ContinuationSettings::new(0.0, f64::INFINITY, 0.1).is_err());
    let s = ContinuationSettings::new(0.0, 1.0, 0.1).unwrap();
    assert!(s.clone().with_max_points(1).is_err());
    assert!(s.clone().with_max_step(0.01).is_err());
    assert!(s.clone().with_locate_tolerance(-1.0).is_err());
    assert!(s.clone().with_scales(vec![1.0, 0.0], 1.0).is_err());
    // Scales for the wrong number of components.
    let wrong = s.with_scales(vec![1.0], 1.0).unwrap();
    let build = |w: f64| {
        Ok(Shooting::new(
            duffing_at(w),
            (),
            tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-9, 1e-11)?,
        ))
    };
    assert!(matches!(
        follow(build, |w| std::f64::consts::TAU / w, 0.0, 0.5, y, &wrong),
        Err(OrbitError::InvalidSetting { .. })
    ));
}

fn duffing_at(omega: f64) -> impl Dynamics<f64, 2> + Clone {
    Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(
            Element::on_dof(
                0,
                (
                    CubicSpring::new(1.0, 1.0).unwrap(),
                    ViscousDamper::new(C).unwrap(),
                ),
            )
            .unwrap(),
        )
        .with_loads(Load::on_dof(0, Harmonic::cosine(F, omega).unwrap()).unwrap())
}

#[test]
fn extrema_along_an_orbit_are_exact() {
    // ẍ + 2ζẋ + x = cos ωt: the steady state x = A cos(ωt − δ), A = 1/√d, has one minimum
    // −A and one maximum A per period.
    use nonsmooth::force::LinearSpring;
    use nonsmooth::orbit::Extremum;
    let (zeta, omega) = (0.05_f64, 1.3_f64);
    let model = Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(
            Element::on_dof(
                0,
                (
                    LinearSpring::new(1.0).unwrap(),
                    ViscousDamper::new(2.0 * zeta).unwrap(),
                ),
            )
            .unwrap(),
        )
        .with_loads(Load::on_dof(0, Harmonic::cosine(1.0, omega).unwrap()).unwrap());
    let tol = Tolerances::new(1e-11, 1e-13).unwrap();
    let shooting = Shooting::new(
        model,
        (),
        tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-11, 1e-13).unwrap(),
    );
    let period = std::f64::consts::TAU / omega;
    let orbit = shooting
        .find(0.0, period, SVector::<f64, 2>::zeros())
        .unwrap();
    let d = (1.0 - omega * omega).powi(2) + (2.0 * zeta * omega).powi(2);
    let a = 1.0 / d.sqrt();
    let minima = shooting
        .local_extrema(0.0, period, orbit.state, 0, Extremum::Min)
        .unwrap();
    let maxima = shooting
        .local_extrema(0.0, period, orbit.state, 0, Extremum::Max)
        .unwrap();
    assert_eq!((minima.len(), maxima.len()), (1, 1));
    assert!((minima[0].1 + a).abs() < 1e-9, "{minima:?} vs −{a}");
    assert!((maxima[0].1 - a).abs() < 1e-9, "{maxima:?} vs {a}");
    // The minimum is at ωt − δ = π, δ = atan2(2ζω, 1 − ω²).
    let delta = (2.0 * zeta * omega).atan2(1.0 - omega * omega);
    let t_min = (std::f64::consts::PI + delta) / omega % period;
    assert!(
        (minima[0].0 - t_min).abs() < 1e-8,
        "{} vs {t_min}",
        minima[0].0
    );
    let global = shooting
        .extremum(0.0, period, orbit.state, 0, Extremum::Min)
        .unwrap();
    assert_eq!(global, minima[0].1);
}

/// `ẍ + cẋ − x + x³ = γ cos ωt`, slowly forced: the orbit on the hilltop `x ≈ 0` is a
/// saddle with `μ ≈ e^{0.97·T}`, `T = 2π/ω`.
fn double_well(c: f64, gamma: f64, omega: f64) -> impl Dynamics<f64, 2> + Clone {
    Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(
            Element::on_dof(
                0,
                (
                    CubicSpring::new(-1.0, 1.0).unwrap(),
                    ViscousDamper::new(c).unwrap(),
                ),
            )
            .unwrap(),
        )
        .with_loads(Load::on_dof(0, Harmonic::cosine(gamma, omega).unwrap()).unwrap())
}

#[test]
fn multiple_shooting_finds_a_strongly_unstable_orbit() {
    let (c, gamma, omega) = (0.05, 0.1, 0.4);
    let period = std::f64::consts::TAU / omega;
    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let tangent = tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12).unwrap();
    let shooting = Shooting::new(double_well(c, gamma, omega), (), tangent);
    // Guess: the linear response x = a cos ωt + b sin ωt of ẍ + cẋ − x = γ cos ωt.
    let (k, d) = (-1.0 - omega * omega, c * omega);
    let (a, b) = (gamma * k / (k * k + d * d), gamma * d / (k * k + d * d));
    let linear = |t: f64| {
        let (s, co) = (omega * t).sin_cos();
        SVector::from([a * co + b * s, omega * (b * co - a * s)])
    };
    let m = 16;
    let guesses: Vec<_> = (0..m)
        .map(|i| linear(i as f64 * period / m as f64))
        .collect();
    let orbit = shooting.find_multiple(0.0, period, &guesses).unwrap();
    let mu = modulus(&orbit.multipliers[0]);
    // Measured: μ₁ ≈ 4.1e6 (ln μ₁/T = 0.970, the hilltop's e^{λt} with λ = 0.975 softened
    // by the orbit's x² ≈ 0.004), in 3 iterations.
    assert!(mu > 1e6 && (mu.ln() / period - 0.97).abs() < 0.02, "{mu}");
    assert!(orbit.state.amax() < 0.2, "{:?}", orbit.state);
    // A second, independent integration (state only, at the state's tolerances) segment by
    // segment closes the orbit.
    let h = period / m as f64;
    let mut y = orbit.state;
    let mut worst = 0.0_f64;
    for i in 0..m {
        y = shooting.map(i as f64 * h, y, h).unwrap();
        worst = worst.max(if i + 1 < m {
            0.0
        } else {
            (y - orbit.state).amax()
        });
    }
    // Over the whole period the flow amplifies the integration error by μ₁: the closing
    // mismatch stays within μ₁ times the tolerance.
    assert!(worst < mu * 1e-9, "closing mismatch {worst:e}");
    // Single shooting from the multiple-shooting point agrees (a Newton step of
    // (Φ − I)⁻¹ r ≈ r/μ₁ is tiny), while from the linear guess its one shot leaves the
    // hilltop for a well: measured, no convergence in 50 iterations (residual 0.18).
    let single = shooting.find(0.0, period, orbit.state).unwrap();
    let from_guess = shooting.find(0.0, period, guesses[0]);
    println!(
        "μ₁ = {mu:e}, ln μ₁/T = {:.4}, {} iterations, closing mismatch {worst:e}; single \
         shooting from the guess: {:?}",
        mu.ln() / period,
        orbit.iterations,
        from_guess.as_ref().map(|o| o.state)
    );
    assert!(
        (single.state - orbit.state).amax() < 1e-8,
        "{:?}",
        single.state
    );
    let from_guess = shooting.find(0.0, period, guesses[0]);
    assert!(
        from_guess
            .as_ref()
            .map_or(true, |o| (o.state - orbit.state).amax() > 1e-3),
        "{from_guess:?}"
    );
}

#[test]
fn multiple_shooting_equals_single_shooting_on_a_stable_orbit() {
    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let tangent = tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12).unwrap();
    let shooting = Shooting::new(duffing(), (), tangent);
    let period = std::f64::consts::TAU / OMEGA;
    for guess in harmonic_balance() {
        let one = shooting.find(0.0, period, guess).unwrap();
        // Segment starts from a forward run along the single-shooting orbit, perturbed.
        let m = 4;
        let mut starts = vec![one.state];
        for i in 1..m {
            let prev = starts[i - 1];
            starts.push(
                shooting
                    .map((i - 1) as f64 * period / m as f64, prev, period / m as f64)
                    .unwrap(),
            );
        }
        let perturbed: Vec<_> = starts
            .iter()
            .map(|y| y + SVector::from([1e-3, -1e-3]))
            .collect();
        let multi = shooting.find_multiple(0.0, period, &perturbed).unwrap();
        assert!(
            (multi.state - one.state).amax() < 1e-8,
            "{:?} vs {:?}",
            multi.state,
            one.state
        );
        for (a, b) in multi.multipliers.iter().zip(&one.multipliers) {
            assert!((a - b).norm() < 1e-7, "{a} vs {b}");
        }
        let m1 = shooting.find_multiple(0.0, period, &[guess]).unwrap();
        assert!((m1.state - one.state).amax() < 1e-9);
    }
    assert!(shooting.find_multiple(0.0, period, &[]).is_err());
}
