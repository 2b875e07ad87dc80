//! Benchmarks of the `filippov` module: the relay feedback system through 10 s of its
//! sliding orbit (about 24 sliding segments), the belt oscillator's stick–slip over 20
//! forcing periods, and the relay's monodromy over one period; the instruments of sliding
//! bifurcations (group `filippov_bifurcations`): the four test functions of one orbit (an
//! evaluation with the equivalent control's extrema), one pseudo-arclength step, and one
//! step of the relay's autonomous orbit in ζ.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::SVector;
use nonsmooth::filippov::{FilippovSimulation, LinearRelay, Switched};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::systems::RelayFeedback;

/// The relay feedback system `ẋ = A x − b sgn(x₁)` of the catalogue (ζ = 0.05, ω = 25,
/// σ = 1).
fn relay() -> LinearRelay<f64, 3> {
    RelayFeedback::default()
        .system()
        .expect("finite relay matrices")
}

fn relay_runs(c: &mut Criterion) {
    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let x0 = SVector::from([0.0, -0.001, -0.02]);
    c.bench_function("filippov_relay_10s_rtol1e-10", |b| {
        b.iter(|| {
            let mut sim = FilippovSimulation::new(relay(), Dopri5::new(tol));
            black_box(sim.run(0.0, black_box(x0), 10.0, &mut ()).unwrap())
        })
    });
    // A point of the orbit (after 40 s from x₀) and its period.
    let mut sim = FilippovSimulation::new(relay(), Dopri5::new(tol));
    let run = sim.run(0.0, x0, 40.0, &mut ()).unwrap();
    let tol12 = Tolerances::<f64, 12>::new(1e-10, 1e-12).unwrap();
    c.bench_function("filippov_relay_monodromy_one_period", |b| {
        b.iter(|| {
            let mut sim = FilippovSimulation::new(relay(), Dopri5::new(tol));
            black_box(
                sim.monodromy(40.0, run.x, 40.0 + 5.961836942608, tol12)
                    .unwrap(),
            )
        })
    });
}

fn belt(c: &mut Criterion) {
    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let (f0, w) = (0.8, 1.3);
    let system = Switched::new(
        |x: &SVector<f64, 2>| x[1] - 0.5,
        |_x: &SVector<f64, 2>| SVector::from([0.0, 1.0]),
        move |t: f64, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] + f0 * (w * t).cos() + 1.0]),
        move |t: f64, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] + f0 * (w * t).cos() - 1.0]),
    );
    let t_end = 20.0 * std::f64::consts::TAU / w;
    c.bench_function("filippov_belt_20_periods_rtol1e-10", |b| {
        b.iter(|| {
            let mut sim = FilippovSimulation::new(&system, Dopri5::new(tol));
            black_box(
                sim.run(0.0, SVector::from([0.0, 0.0]), t_end, &mut ())
                    .unwrap(),
            )
        })
    });
}

/// The belt oscillator `ẍ + x = F₀ cos ωt − sgn(ẋ − 0.5)`.
fn belt_at(f0: f64, w: f64) -> impl nonsmooth::filippov::Filippov<f64, 2, 1> + Clone {
    Switched::new(
        |x: &SVector<f64, 2>| x[1] - 0.5,
        |_x: &SVector<f64, 2>| SVector::from([0.0, 1.0]),
        move |t: f64, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] + f0 * (w * t).cos() + 1.0]),
        move |t: f64, x: &SVector<f64, 2>| SVector::from([x[1], -x[0] + f0 * (w * t).cos() - 1.0]),
    )
}

fn bifurcations(c: &mut Criterion) {
    use nonsmooth::orbit::sliding::{
        SlidingContinuation, follow_sliding, follow_sliding_arclength, sliding_tests,
    };
    let mut group = c.benchmark_group("filippov_bifurcations");
    group.sample_size(10);
    let tol = Tolerances::new(1e-12, 1e-14).unwrap();
    let tol6 = Tolerances::<f64, 6>::new(1e-12, 1e-14).unwrap();
    // The stick-slip orbit at ω = 0.8, F₀ = 0.9 (one stick per period, its equivalent
    // control close to the bound at an extremum).
    let (f0, w) = (0.9, 0.8);
    let period = std::f64::consts::TAU / w;
    let mut sim = FilippovSimulation::new(belt_at(f0, w), Dopri5::new(tol));
    let x0 = sim
        .run(0.0, SVector::from([0.5, 0.0]), 80.0 * period, &mut ())
        .unwrap()
        .x;
    let orbit = sim
        .find_orbit(0.0, x0, period, false, tol6, 1e-11, 30)
        .unwrap();
    group.bench_function("sliding_tests_one_orbit", |b| {
        b.iter(|| {
            black_box(sliding_tests(&mut sim, 0, 0.0, black_box(orbit.state), period).unwrap())
        })
    });
    let build = move |f0: f64| Ok(FilippovSimulation::new(belt_at(f0, w), Dopri5::new(tol)));
    let settings = SlidingContinuation::new(0.5, 1.5, 0.01, 0)
        .unwrap()
        .with_max_points(2)
        .unwrap();
    group.bench_function("arclength_one_step", |b| {
        b.iter(|| {
            black_box(
                follow_sliding_arclength(build, |_| period, 0.0, f0, orbit.state, tol6, &settings)
                    .unwrap(),
            )
        })
    });
    // The relay's orbit: a start in a region piece (after 40 s) and its period.
    let relay_at = |zeta: f64| {
        Ok(FilippovSimulation::new(
            RelayFeedback {
                zeta,
                ..RelayFeedback::default()
            }
            .system()
            .unwrap(),
            Dopri5::new(Tolerances::new(1e-10, 1e-12).unwrap()),
        ))
    };
    let mut sim = relay_at(0.05).unwrap();
    let x40 = sim
        .run(0.0, SVector::from(RelayFeedback::X0), 40.0, &mut ())
        .unwrap()
        .x;
    let tol12 = Tolerances::<f64, 12>::new(1e-10, 1e-12).unwrap();
    let settings = SlidingContinuation::new(0.04, 0.06, 0.001, 0)
        .unwrap()
        .autonomous()
        .with_max_points(2)
        .unwrap();
    group.bench_function("relay_autonomous_one_step", |b| {
        b.iter(|| {
            black_box(
                follow_sliding(
                    relay_at,
                    |_| 5.961836942608,
                    0.0,
                    0.05,
                    x40,
                    tol12,
                    &settings,
                )
                .unwrap(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, relay_runs, belt, bifurcations);
criterion_main!(benches);
