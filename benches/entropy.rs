//! Benchmarks of the `entropy` module: the histogram of 10⁵ intervals on the paper's grid
//! ((0.05, 0.3), step 0.001) and the entropy index of the resulting distribution.

use criterion::{Criterion, criterion_group, criterion_main};
use nonsmooth::entropy::{Histogram, QRange, entropy_index};
use std::hint::black_box;

/// 10⁵ deterministic chaotic "intervals" (logistic map, r = 3.9) in (0.08, 0.28).
fn intervals() -> Vec<f64> {
    let mut x = 0.3;
    for _ in 0..1000 {
        x = 3.9 * x * (1.0 - x);
    }
    (0..100_000)
        .map(|_| {
            x = 3.9 * x * (1.0 - x);
            0.08 + 0.2 * x
        })
        .collect()
}

fn entropy(c: &mut Criterion) {
    let samples = intervals();
    let hist = Histogram::new(0.05, 0.3, 0.001).unwrap();
    let range = QRange::default();
    let est = hist.estimate(&samples).unwrap();
    let samples32: Vec<f32> = samples.iter().map(|&x| x as f32).collect();
    let hist32 = Histogram::new(0.05_f32, 0.3, 0.001).unwrap();

    let mut g = c.benchmark_group("entropy");
    let mut counts = vec![0u64; hist.bins()];
    g.bench_function("histogram_counts_into_1e5", |b| {
        b.iter(|| black_box(hist.counts_into(black_box(&samples), &mut counts).unwrap()))
    });
    g.bench_function("histogram_estimate_1e5", |b| {
        b.iter(|| black_box(hist.estimate(black_box(&samples)).unwrap()))
    });
    g.bench_function("entropy_index_176_states", |b| {
        b.iter(|| black_box(entropy_index(black_box(&est.probabilities), &range).unwrap()))
    });
    g.bench_function("histogram_and_index_1e5", |b| {
        b.iter(|| {
            let est = hist.estimate(black_box(&samples)).unwrap();
            black_box(entropy_index(&est.probabilities, &range).unwrap())
        })
    });
    g.bench_function("histogram_and_index_1e5_f32", |b| {
        b.iter(|| {
            let est = hist32.estimate(black_box(&samples32)).unwrap();
            black_box(entropy_index(&est.probabilities, &QRange::default()).unwrap())
        })
    });
    g.finish();
}

criterion_group!(benches, entropy);
criterion_main!(benches);
