//! Benchmarks of the `timestep` module: Moreau–Jean steps per second against the number of
//! contacts, on a resting column of N balls on the floor (N contacts, all active, each
//! step's problem a chain): Lemke, warm-started projected Gauss–Seidel, and nonsmooth
//! Gauss–Seidel with friction (μ = 0.3).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nonsmooth::timestep::lcp::{Lemke, Nsgs, Pgs};
use nonsmooth::timestep::{MoreauJean, PlanarBodies, PlanarContact, Plane, RigidBody, Solver};
use std::hint::black_box;

const STEPS: usize = 10;
const H: f64 = 1e-3;

/// A resting column of `n` discs (radius 1/16 m, unit mass) with friction `mu`.
fn column(n: usize, mu: f64) -> (PlanarBodies<f64>, Vec<PlanarContact<f64>>, Vec<f64>) {
    let r = 0.0625;
    let bodies = PlanarBodies::new(vec![RigidBody::disc(1.0, r).unwrap(); n], 9.81).unwrap();
    let mut contacts =
        vec![PlanarContact::disc_plane(0, r, Plane::floor(0.0).unwrap(), 0.0, mu).unwrap()];
    for i in 0..n - 1 {
        contacts.push(PlanarContact::disc_disc(i, r, i + 1, r, 0.0, mu).unwrap());
    }
    let mut q = vec![0.0; 3 * n];
    for i in 0..n {
        q[3 * i + 1] = r + 2.0 * r * i as f64;
    }
    (bodies, contacts, q)
}

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("timestep_column");
    g.sample_size(10);
    g.warm_up_time(std::time::Duration::from_secs(1));
    g.measurement_time(std::time::Duration::from_secs(3));
    g.throughput(Throughput::Elements(STEPS as u64));
    for n in [10usize, 30, 100, 300] {
        let cases: Vec<(&str, f64, Solver<f64>)> = vec![
            ("lemke", 0.0, Solver::Lemke(Lemke::new())),
            (
                "pgs",
                0.0,
                Solver::Pgs(Pgs::new().with_max_iterations(1_000_000)),
            ),
            (
                "nsgs_mu0.3",
                0.3,
                Solver::Nsgs(Nsgs::new().with_max_iterations(1_000_000)),
            ),
        ];
        for (name, mu, solver) in cases {
            // Gauss–Seidel's first (cold) step on a chain of n contacts takes O(n²) sweeps
            // of O(n²) each: the columns above 100 balls are left to Lemke.
            if name != "lemke" && n > 100 {
                continue;
            }
            let (bodies, contacts, q0) = column(n, mu);
            let mut scheme = MoreauJean::new(bodies, contacts, H)
                .unwrap()
                .with_solver(solver)
                .unwrap();
            let (mut q, mut v) = (q0, vec![0.0; 3 * n]);
            // Settle: the iterative solvers start warm, as in a long run.
            scheme.run(0.0, &mut q, &mut v, 0.05, &mut ()).unwrap();
            let mut t = 0.05;
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| {
                    let t1 = t + STEPS as f64 * H;
                    black_box(scheme.run(t, &mut q, &mut v, t1, &mut ()).unwrap());
                    t = t1;
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, steps);
criterion_main!(benches);
