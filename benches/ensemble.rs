//! Ensemble throughput on the paper's model at rtol 1e-8, one thread: 64 forcing
//! frequencies in [17.5, 25] rad/s, 20 periods each from rest, every impact located, steps
//! landing on the sections — the scalar path (`Simulation` + `Dopri5`, one trajectory
//! after the other) against the ensemble on each instruction set of the machine (its
//! lanes: four on the baseline, sixteen with AVX2 or AVX-512), exact and vector math.
//! After the group, the throughput ratio ensemble/scalar of the fastest configuration,
//! measured in this run, is printed as `throughput ratio ensemble/scalar: R`; the line before
//! it gives the same ratio with the lane loop capped at AVX2 (`Simd::Avx2`, the `_avx2`
//! configurations; equal to the first on a machine without AVX-512).
//!
//! The group `ensemble_any_64x20_periods` runs models built generically from the parts
//! (their lane forms): the Duffing–Ueda oscillator (64 amplitudes) and the 2-DOF impact
//! system of the catalogue (64 frequencies, state of size 4, its stop as an event), each
//! on the scalar path and in lanes (exact math, the widest instruction set); after it, the
//! ratio ensemble/scalar of each is printed as `throughput ratio <model> ensemble/scalar: R`.

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::SVector;
use nalgebra::Vector2;
use nonsmooth::LaneDynamics;
use nonsmooth::drive::Simulation;
use nonsmooth::ensemble::{Ensemble, LaneMath, MemberRun, Simd};
use nonsmooth::event::{Direction, Event, EventSet, Stop};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::systems::paper::{Member, PAPER};
use nonsmooth::systems::{DuffingUeda, TwoDofImpact};

struct Setup {
    jobs: Vec<MemberRun<Member>>,
    tol: Tolerances<f64, 2>,
    impact: Event<Stop<f64>>,
}

fn setup() -> Setup {
    let rtol = 1e-8;
    let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2]).unwrap();
    let y0 = Vector2::new(PAPER.static_equilibrium().unwrap(), 0.0);
    // 64 trajectories: four per lane even with 16 lanes, so that the time measures
    // throughput rather than the slowest single trajectory.
    let jobs = (0..64)
        .map(|i| {
            let w = 17.5 + 7.5 * i as f64 / 63.0;
            MemberRun::periods(Member::paper(w).unwrap(), y0, 20.0).unwrap()
        })
        .collect();
    let impact = Event::new(
        Stop {
            position: 0,
            velocity: 1,
            level: PAPER.x_i,
        },
        Direction::Rising,
    );
    Setup { jobs, tol, impact }
}

fn scalar(s: &Setup) -> u64 {
    let mut evals = 0;
    for j in &s.jobs {
        let mut sim = Simulation::new(*j.member.scalar(), Dopri5::new(s.tol))
            .with_events(s.impact)
            .landing_grid(j.grid)
            .unwrap();
        evals += sim
            .run(j.t0, j.y0, j.t_end, &mut ())
            .unwrap()
            .stats
            .rhs_evals;
    }
    evals
}

fn lanes(s: &Setup, math: LaneMath) -> u64 {
    lanes_in(s, math, Simd::Auto)
}

fn lanes_in(s: &Setup, math: LaneMath, simd: Simd) -> u64 {
    let e = Ensemble::new(s.tol)
        .unwrap()
        .with_event(s.impact)
        .unwrap()
        .with_math(math)
        .with_simd(simd);
    let mut obs = vec![(); s.jobs.len()];
    e.run(&s.jobs, &mut obs)
        .unwrap()
        .into_iter()
        .map(|o| o.unwrap().stats.rhs_evals)
        .sum()
}

type Path = (&'static str, fn(&Setup) -> u64);

const PATHS: [Path; 7] = [
    ("scalar", scalar),
    ("exact", |s| lanes(s, LaneMath::Exact)),
    ("vector", |s| lanes(s, LaneMath::Vector)),
    ("exact_avx2", |s| lanes_in(s, LaneMath::Exact, Simd::Avx2)),
    ("vector_avx2", |s| lanes_in(s, LaneMath::Vector, Simd::Avx2)),
    ("exact_baseline", |s| {
        lanes_in(s, LaneMath::Exact, Simd::Baseline)
    }),
    ("vector_baseline", |s| {
        lanes_in(s, LaneMath::Vector, Simd::Baseline)
    }),
];

fn bench(c: &mut Criterion) {
    let s = setup();
    let mut g = c.benchmark_group("ensemble_64x20_periods");
    g.sample_size(10);
    for (name, f) in PATHS {
        g.bench_function(name, |b| b.iter(|| black_box(f(&s))));
    }
    g.finish();
    // The ratio in this run: the best of five timings of each path.
    let time = |f: fn(&Setup) -> u64| {
        (0..5)
            .map(|_| {
                let t = Instant::now();
                black_box(f(&s));
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let t_scalar = time(PATHS[0].1);
    let ratios: Vec<(f64, &str)> = PATHS[1..]
        .iter()
        .map(|(n, f)| (t_scalar / time(*f), *n))
        .collect();
    let fastest = |avx2_only: bool| {
        ratios
            .iter()
            .filter(|(_, n)| !avx2_only || n.ends_with("_avx2"))
            .fold((0.0, ""), |a, b| if b.0 > a.0 { *b } else { a })
    };
    let (r2, n2) = fastest(true);
    println!("throughput ratio ensemble/scalar with the lane loop capped at AVX2: {r2:.2} ({n2})");
    let (best, name) = fastest(false);
    println!("fastest ensemble configuration: {name}");
    println!("throughput ratio ensemble/scalar: {best:.2}");
}

/// A generic model's trajectories and events.
struct Any<D, E, const M: usize> {
    jobs: Vec<MemberRun<D, M>>,
    tol: Tolerances<f64, M>,
    events: E,
}

fn any_scalar<D: LaneDynamics<M>, E: EventSet<f64, M> + Clone, const M: usize>(
    s: &Any<D, E, M>,
) -> u64 {
    s.jobs
        .iter()
        .map(|j| {
            Simulation::new(j.member.clone(), Dopri5::new(s.tol))
                .with_events(s.events.clone())
                .landing_grid(j.grid)
                .unwrap()
                .run(j.t0, j.y0, j.t_end, &mut ())
                .unwrap()
                .stats
                .rhs_evals
        })
        .sum()
}

fn any_lanes<D: LaneDynamics<M>, E: EventSet<f64, M> + Clone, const M: usize>(
    s: &Any<D, E, M>,
) -> u64 {
    let e = Ensemble::new(s.tol)
        .unwrap()
        .with_events(s.events.clone())
        .unwrap();
    let mut obs = vec![(); s.jobs.len()];
    e.run(&s.jobs, &mut obs)
        .unwrap()
        .into_iter()
        .map(|o| o.unwrap().stats.rhs_evals)
        .sum()
}

fn bench_any(c: &mut Criterion) {
    let duffing = Any {
        jobs: (0..64)
            .map(|i| {
                let p = DuffingUeda {
                    b: 5.0 + 7.0 * i as f64 / 63.0,
                    ..DuffingUeda::default()
                };
                MemberRun::<_, 2>::periods_of(
                    p.model::<f64>().unwrap(),
                    SVector::from([1.0, 0.0]),
                    p.period(),
                    20.0,
                )
                .unwrap()
            })
            .collect(),
        tol: Tolerances::new(1e-8, 1e-10).unwrap(),
        events: (),
    };
    let p = TwoDofImpact::default();
    let two_dof = Any {
        jobs: (0..64)
            .map(|i| {
                let w = 0.3 + i as f64 / 63.0;
                MemberRun::<_, 4>::periods_of(
                    p.model::<f64>(w).unwrap(),
                    SVector::zeros(),
                    TwoDofImpact::period(w),
                    20.0,
                )
                .unwrap()
            })
            .collect(),
        tol: Tolerances::new(1e-8, 1e-10).unwrap(),
        events: Event::new(p.stop::<f64>().unwrap(), Direction::Rising),
    };
    let mut g = c.benchmark_group("ensemble_any_64x20_periods");
    g.sample_size(10);
    g.bench_function("duffing_scalar", |b| {
        b.iter(|| black_box(any_scalar(&duffing)))
    });
    g.bench_function("duffing_lanes", |b| {
        b.iter(|| black_box(any_lanes(&duffing)))
    });
    g.bench_function("two_dof_scalar", |b| {
        b.iter(|| black_box(any_scalar(&two_dof)))
    });
    g.bench_function("two_dof_lanes", |b| {
        b.iter(|| black_box(any_lanes(&two_dof)))
    });
    g.finish();
    let best = |f: &dyn Fn() -> u64| {
        (0..5)
            .map(|_| {
                let t = Instant::now();
                black_box(f());
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let d = best(&|| any_scalar(&duffing)) / best(&|| any_lanes(&duffing));
    println!("throughput ratio duffing_ueda ensemble/scalar: {d:.2}");
    let t = best(&|| any_scalar(&two_dof)) / best(&|| any_lanes(&two_dof));
    println!("throughput ratio two_dof_impact ensemble/scalar: {t:.2}");
}

criterion_group!(benches, bench, bench_any);
criterion_main!(benches);
