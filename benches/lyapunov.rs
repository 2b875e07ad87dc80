//! The top Lyapunov exponent of the paper's oscillator at ω = 20.465 rad/s (chaotic):
//! 50 forcing periods on the attractor by two trajectories (the Fig. 5 method) and by the
//! tangent-space (QR) method.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{TangentSpace, TwoTrajectory, pair_tolerances};
use nonsmooth::systems::paper::PAPER;
use nonsmooth::systems::paper::lyapunov::{D0 as PAPER_D0, norm as paper_norm};
use std::hint::black_box;

fn tle(c: &mut Criterion) {
    let omega = 20.465;
    let tau = std::f64::consts::TAU / omega;
    let osc = PAPER.oscillator::<f64>(omega).unwrap();
    let y0 = Vector2::new(PAPER.static_equilibrium().unwrap(), 0.0);
    let tol = Tolerances::per_component(1e-8, [1e-12, 1e-10]).unwrap();

    // On the attractor first (100 transient periods from rest, outside the timing).
    let mut tt = TwoTrajectory::new(
        osc,
        Dopri5::new(pair_tolerances(&tol).unwrap()),
        PAPER_D0,
        paper_norm(),
    )
    .unwrap();
    tt.start(0.0, y0).unwrap();
    tt.transient(tau, 100).unwrap();
    let mut qr =
        TangentSpace::from_tolerances(osc, &tol, Dopri5::new, (1e-8, 1e-8), paper_norm()).unwrap();
    qr.start(0.0, y0).unwrap();
    qr.transient(tau, 100).unwrap();

    let mut g = c.benchmark_group("lyapunov_paper_20.465");
    g.sample_size(20);
    g.bench_function("two_trajectory_50_periods", |b| {
        b.iter(|| {
            let mut e = tt.clone();
            black_box(e.estimate(black_box(tau), 50).unwrap().exponent)
        })
    });
    g.bench_function("qr_spectrum_50_periods", |b| {
        b.iter(|| {
            let mut e = qr.clone();
            black_box(e.estimate(black_box(tau), 50).unwrap().exponents[0])
        })
    });
    g.finish();
}

criterion_group!(benches, tle);
criterion_main!(benches);
