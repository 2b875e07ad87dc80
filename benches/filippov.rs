//! Benchmarks of the `filippov` module: the relay feedback system through 10 s of its
//! sliding orbit (about 24 sliding segments), the belt oscillator's stick–slip over 20
//! forcing periods, and the relay's monodromy over one period.

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

criterion_group!(benches, relay_runs, belt);
criterion_main!(benches);
