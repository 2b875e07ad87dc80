//! Sweeps of the paper's oscillator: a small up-and-down sweep (20 values over
//! ω ∈ [19.9, 20.1], transients 100/50, 20 recorded periods) on one thread and on the
//! default pool — the ratio is the parallel speed-up of the two branches. The full W3
//! workload (ω ∈ [17.5, 25], step 0.005) is `examples/paper` (full mode) and `examples/fig3`,
//! `examples/fig4`.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::sweep::{Stop, SweepConfig, SweepSystem, sweep};
use nonsmooth::systems::paper::{PAPER, PaperOscillator};
use std::hint::black_box;

fn make(w: f64) -> nonsmooth::Result<SweepSystem<PaperOscillator<f64>>> {
    Ok(SweepSystem {
        system: PAPER.oscillator::<f64>(w)?,
        period: std::f64::consts::TAU / w,
        stop: Some(Stop {
            position: 0,
            velocity: 1,
            level: PAPER.x_i,
        }),
    })
}

fn bench(c: &mut Criterion) {
    let cfg = SweepConfig::grid(19.9, 20.1, 0.01)
        .unwrap()
        .transients(100, 50)
        .record(20)
        .unwrap();
    let tol = Tolerances::per_component(1e-8, [1e-12, 1e-10]).unwrap();
    let y0 = Vector2::new(PAPER.static_equilibrium().unwrap(), 0.0);
    let mut g = c.benchmark_group("sweep_both_21_values");
    g.sample_size(10);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    g.bench_function("1_thread", |b| {
        b.iter(|| one.install(|| black_box(sweep(&cfg, make, || Dopri5::new(tol), y0).unwrap())))
    });
    g.bench_function("default_pool", |b| {
        b.iter(|| black_box(sweep(&cfg, make, || Dopri5::new(tol), y0).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
