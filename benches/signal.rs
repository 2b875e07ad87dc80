//! The measured-data pipeline on 10⁶ samples: the first-order filter, threshold-crossing
//! detection, and both in sequence (filter into a reused buffer, then crossings into a
//! reused vector — no allocation inside the timed loop).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nonsmooth::signal::{LowPass, ThresholdCrossing};
use std::hint::black_box;

const N: usize = 1_000_000;

/// 100 s at 10 kHz of a 20.465 rad/s oscillation with a 7× harmonic and small
/// deterministic pseudo-noise, in metres (about 1 mm amplitude).
fn signal() -> (Vec<f64>, Vec<f64>) {
    let h = 1e-4;
    let t: Vec<f64> = (0..N).map(|i| i as f64 * h).collect();
    let mut state = 0x1234_5678_9abc_def0_u64;
    let x = t
        .iter()
        .map(|&t| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            let noise = ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            1e-3 * (20.465 * t).sin() + 1e-4 * (7.0 * 20.465 * t).sin() + 2e-6 * noise
        })
        .collect();
    (t, x)
}

fn pipeline(c: &mut Criterion) {
    let (t, x) = signal();
    let filter: LowPass<f64> = nonsmooth::systems::paper::low_pass().unwrap();
    let detector = ThresholdCrossing::new(0.8e-3)
        .unwrap()
        .with_hysteresis(1e-5)
        .unwrap();
    let mut y = Vec::with_capacity(N);
    let mut times = Vec::with_capacity(4096);

    let mut g = c.benchmark_group("signal_1e6");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(20);
    g.bench_function("lowpass_filter_into", |b| {
        b.iter(|| {
            filter
                .filter_into(black_box(&t), black_box(&x), &mut y)
                .unwrap();
            black_box(y[N - 1])
        })
    });
    g.bench_function("crossings_times_into", |b| {
        b.iter(|| {
            detector
                .times_into(black_box(&t), black_box(&x), &mut times)
                .unwrap();
            black_box(times.len())
        })
    });
    g.bench_function("filter_then_crossings", |b| {
        b.iter(|| {
            filter
                .filter_into(black_box(&t), black_box(&x), &mut y)
                .unwrap();
            detector.times_into(&t, &y, &mut times).unwrap();
            black_box(times.len())
        })
    });
    g.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
