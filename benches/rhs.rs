//! One right-hand-side evaluation of the paper's oscillator, in free flight and in contact
//! (also against the scalar right-hand side written out, the cost of the oscillator being a
//! layer over the 1-DOF `Mechanical` system, as a ratio in one run);
//! and the forcing's `sin` (`nonsmooth::util::sin` against `libm`, as a ratio in one run).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use nonsmooth::Dynamics;
use nonsmooth::systems::paper::PAPER;
use std::hint::black_box;

#[path = "common/scalar.rs"]
mod scalar;

fn rhs(c: &mut Criterion) {
    let osc = PAPER.oscillator::<f64>(20.465).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    let mut g = c.benchmark_group("paper_rhs");
    for (name, y) in [
        ("free_flight", Vector2::new(-2.5e-3, 3e-2)),
        ("contact", Vector2::new(x0, 2e-4)),
        ("contact_reversal", Vector2::new(x0, 3e-8)),
    ] {
        let mut dy = Vector2::zeros();
        g.bench_function(name, |b| {
            b.iter(|| {
                osc.rhs(black_box(0.123), black_box(&y), &mut dy);
                black_box(dy[1])
            })
        });
    }
    g.finish();
    // The oscillator (a layer over the 1-DOF `Mechanical` system) against the scalar
    // right-hand side written out: the layer's cost, as a ratio in one run.
    let reference = scalar::paper(20.465);
    let mut g = c.benchmark_group("paper_rhs_model");
    for (name, y) in [
        ("free_flight", Vector2::new(-2.5e-3, 3e-2)),
        ("contact", Vector2::new(x0, 2e-4)),
    ] {
        let mut dy = Vector2::zeros();
        g.bench_function(format!("scalar_{name}"), |b| {
            b.iter(|| {
                reference.rhs(black_box(0.123), black_box(&y), &mut dy);
                black_box(dy[1])
            })
        });
        g.bench_function(format!("oscillator_{name}"), |b| {
            b.iter(|| {
                osc.rhs(black_box(0.123), black_box(&y), &mut dy);
                black_box(dy[1])
            })
        });
    }
    g.finish();
}

fn sine(c: &mut Criterion) {
    // A run's arguments: ω·t over 1000 forcing periods.
    let xs: Vec<f64> = (0..1024).map(|i| 20.465 * 0.30 * i as f64 + 0.1).collect();
    let mut g = c.benchmark_group("forcing_sin_1024");
    g.bench_function("libm", |b| {
        b.iter(|| xs.iter().map(|&x| black_box(x).sin()).sum::<f64>())
    });
    g.bench_function("fastmath", |b| {
        b.iter(|| {
            xs.iter()
                .map(|&x| nonsmooth::util::sin(black_box(x)))
                .sum::<f64>()
        })
    });
    g.finish();
}

criterion_group!(benches, rhs, sine);
criterion_main!(benches);
