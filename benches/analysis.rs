//! Benchmarks of the `analysis` module: harmonic fit and spectrum of 4096 samples, and the
//! paper's approximations.

use std::f64::consts::TAU;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nonsmooth::analysis::{
    AmplitudePhase, AmplitudeSpectrum, LinearizedResponse, SpectrumAnalyzer, TurningPoint,
    fit_harmonics,
};
use nonsmooth::systems::paper::PAPER;

const N: usize = 4096;
const OMEGA: f64 = 14.0;

/// 4096 samples over 8 periods of a paper-like orbit (eq. 3 plus a small third harmonic).
fn samples() -> (Vec<f64>, Vec<f64>) {
    let dt = 8.0 * TAU / OMEGA / N as f64;
    let t: Vec<f64> = (0..N).map(|i| i as f64 * dt).collect();
    let x = t
        .iter()
        .map(|&t| {
            -2.0813e-3 - 1.3136e-6 * (OMEGA * t).cos()
                + 3.9328e-6 * (OMEGA * t).sin()
                + 6.6538e-7 * (2.0 * OMEGA * t).cos()
                + 2.915e-7 * (2.0 * OMEGA * t).sin()
                + 1e-9 * (3.0 * OMEGA * t).sin()
        })
        .collect();
    (t, x)
}

fn harmonic_analysis(c: &mut Criterion) {
    let (t, x) = samples();
    c.bench_function("fit_harmonics_4096_k2", |b| {
        b.iter(|| fit_harmonics(black_box(&t), black_box(&x), OMEGA, 2).unwrap())
    });
    c.bench_function("fit_harmonics_4096_k5", |b| {
        b.iter(|| fit_harmonics(black_box(&t), black_box(&x), OMEGA, 5).unwrap())
    });
    let mut analyzer = SpectrumAnalyzer::new(N).unwrap();
    let mut out = analyzer.analyze(&t, &x, OMEGA).unwrap();
    c.bench_function("spectrum_4096_planned", |b| {
        b.iter(|| {
            analyzer
                .analyze_into(black_box(&t), black_box(&x), OMEGA, &mut out)
                .unwrap();
            black_box(out.harmonic(2).unwrap())
        })
    });
    c.bench_function("spectrum_4096_one_off", |b| {
        b.iter(|| AmplitudeSpectrum::new(black_box(&t), black_box(&x), OMEGA).unwrap())
    });
}

fn approximations(c: &mut Criterion) {
    let osc = PAPER.oscillator::<f64>(OMEGA).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c).unwrap();
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c).unwrap();
    c.bench_function("linearized_grazing", |b| {
        b.iter(|| lin.grazing_omega(black_box(PAPER.x_i), 10.0, 30.0).unwrap())
    });
    c.bench_function("amplitude_phase_solve_upper", |b| {
        b.iter(|| ap.solve(black_box(OMEGA), TurningPoint::Upper).unwrap())
    });
    c.bench_function("amplitude_phase_grazing_lower", |b| {
        b.iter(|| {
            ap.grazing_omega(black_box(PAPER.x_i), TurningPoint::Lower, 10.0, 14.0)
                .unwrap()
        })
    });
}

criterion_group!(benches, harmonic_analysis, approximations);
criterion_main!(benches);
