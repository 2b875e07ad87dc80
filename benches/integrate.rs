//! The paper's oscillator at ω = 20.465 rad/s: every impact (upward crossing of x_I) located
//! and the state at every t = 2πi/ω recorded (exact landing), with DOPRI5 and DOP853 at
//! rtol 1e-6, 1e-8, 1e-10.
//!
//! - `w1_100`: 100 forcing periods from rest at the static equilibrium (the start of W1,
//!   including the stiff phase in resting contact).
//! - `w2_100`: 100 periods on the attractor (from the state after 100 periods).
//!
//! - `paper_model_w2_100`: `w2_100` at rtol 1e-8 with the oscillator and with its scalar
//!   right-hand side written out (the cost of the `Mechanical` layer).
//!
//! - `turning_points_w2_100`: `w2_100` with DOPRI5 in time alone and with `TurningPoints`
//!   (DOPRI5 across `|ẋ| < 3e-3 m/s` in the velocity's power scale). Before it, the bench
//!   prints the attempts (accepted + rejected steps) per period of both, the segments per
//!   period and the attempts per switching point: a segment's own, and the time stepper's
//!   estimated as (attempts of time stepping alone − attempts of the time stepper outside
//!   the segments) / segments.
//!
//! - `rk_pairs_w2_100`: `w2_100` at rtol 1e-10 and 1e-12 with DOPRI5, Tsit5, Vern6 and
//!   DOP853, each plain and with `TurningPoints` over it (the same method in time and in
//!   the segments), the configurations `examples/rk_pairs.rs` compares.
//!
//! Time per period = reported time / 100.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use nonsmooth::Dynamics;
use nonsmooth::drive::Simulation;
use nonsmooth::event::{Direction, Event, Level};
use nonsmooth::integrate::{
    Adaptive, Dop853, Dop853Method, Dopri5, Dopri5Method, Method, Stepper, Tolerances, Tsit5Method,
    TurningPoints, Vern6Method,
};
use nonsmooth::sample::{ImpactSequence, Stroboscopic};
use nonsmooth::systems::paper::PAPER;
use std::hint::black_box;

#[path = "common/scalar.rs"]
mod scalar;

const OMEGA: f64 = 20.465;

fn tol(rtol: f64) -> Tolerances<f64, 2> {
    Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2]).unwrap()
}

fn run<St: Stepper<f64, 2>>(st: St, y0: Vector2<f64>, periods: u32) -> (usize, Vector2<f64>) {
    run_system(PAPER.oscillator::<f64>(OMEGA).unwrap(), st, y0, periods)
}

fn turning(rtol: f64) -> TurningPoints<f64, Dopri5<f64, 2>, Dopri5<f64, 2>> {
    TurningPoints::dopri5(tol(rtol), 3e-3).unwrap()
}

/// Turning points with method `M` in time and in the segments.
type Turning<M> = TurningPoints<f64, Adaptive<f64, 2, M>, Adaptive<f64, 2, M>>;

/// `TurningPoints` with method `M` in time and in the segments (the segment tolerances of
/// `TurningPoints::dopri5`).
fn turning_with<M: Method<f64, 2>>(rtol: f64) -> Turning<M> {
    let segment = Tolerances::per_component(rtol, [100.0 * rtol, rtol * 1e-4]).unwrap();
    TurningPoints::new(Adaptive::new(tol(rtol)), Adaptive::new(segment), 3e-3).unwrap()
}

/// The plain and turning-point runs of method `M` in group `g`.
fn bench_pair<M: Method<f64, 2>>(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    on_attractor: Vector2<f64>,
) {
    for rtol in [1e-10, 1e-12] {
        g.bench_function(format!("plain/{name}/{rtol:e}"), |b| {
            b.iter(|| {
                black_box(run(
                    Adaptive::<f64, 2, M>::new(tol(rtol)),
                    on_attractor,
                    100,
                ))
            })
        });
        g.bench_function(format!("turning/{name}/{rtol:e}"), |b| {
            b.iter(|| black_box(run(turning_with::<M>(rtol), on_attractor, 100)))
        });
    }
}

/// Attempts per period and per switching point, time stepping alone against segments.
fn print_attempts(on_attractor: Vector2<f64>, periods: u32) {
    let osc = PAPER.oscillator::<f64>(OMEGA).unwrap();
    let t1 = periods as f64 * std::f64::consts::TAU / OMEGA;
    for rtol in [1e-6, 1e-8, 1e-10] {
        let mut plain = Simulation::new(osc, Dopri5::new(tol(rtol)));
        let a = plain.run(0.0, on_attractor, t1, &mut ()).unwrap().stats;
        let mut seg = Simulation::new(osc, turning(rtol));
        let b = seg.run(0.0, on_attractor, t1, &mut ()).unwrap().stats;
        let st = seg.stepper();
        let c = st.segment_counts();
        let ts = st.time_stepper().stats();
        let n = f64::from(periods);
        let (att_plain, att_time) = (
            (a.accepted + a.rejected) as f64,
            (ts.accepted + ts.rejected) as f64,
        );
        let segs = c.completed.max(1) as f64;
        println!(
            "rtol {rtol:e}: attempts/period {:.0} (time) vs {:.0} (time {:.0} + segments {:.0}); \
             RHS/period {:.0} vs {:.0}; segments/period {:.2}; attempts per switching point: \
             time stepping ≈ {:.1}, segment {:.1}; abandoned {}",
            att_plain / n,
            (att_time + c.attempts as f64) / n,
            att_time / n,
            c.attempts as f64 / n,
            a.rhs_evals as f64 / n,
            b.rhs_evals as f64 / n,
            c.completed as f64 / n,
            (att_plain - att_time) / segs,
            c.attempts as f64 / segs,
            c.abandoned
        );
    }
}

fn run_system<S: Dynamics<f64, 2>, St: Stepper<f64, 2>>(
    system: S,
    st: St,
    y0: Vector2<f64>,
    periods: u32,
) -> (usize, Vector2<f64>) {
    let period = std::f64::consts::TAU / OMEGA;
    let ev = Event::new(Level::new(0, PAPER.x_i).unwrap(), Direction::Rising);
    let mut sim = Simulation::new(system, st)
        .with_events(ev)
        .landing_grid(Some((0.0, period)))
        .unwrap();
    let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, period, 0.0, 1 << 20).unwrap();
    let mut imp = ImpactSequence::new(0, 0, 1, PAPER.x_i, 0.0, 1 << 20).unwrap();
    let out = sim
        .run(
            0.0,
            y0,
            periods as f64 * period,
            &mut (&mut strobe, &mut imp),
        )
        .unwrap();
    (imp.impacts().len() + strobe.points().len(), out.y)
}

fn bench(c: &mut Criterion) {
    let rest = Vector2::new(PAPER.static_equilibrium().unwrap(), 0.0);
    let (_, on_attractor) = run(Dopri5::new(tol(1e-10)), rest, 100);
    let mut g = c.benchmark_group("paper_20.465");
    g.sample_size(10);
    for rtol in [1e-6, 1e-8, 1e-10] {
        g.bench_function(format!("w1_100/dopri5/{rtol:e}"), |b| {
            b.iter(|| black_box(run(Dopri5::new(tol(rtol)), rest, 100)))
        });
        g.bench_function(format!("w2_100/dopri5/{rtol:e}"), |b| {
            b.iter(|| black_box(run(Dopri5::new(tol(rtol)), on_attractor, 100)))
        });
        g.bench_function(format!("w2_100/dop853/{rtol:e}"), |b| {
            b.iter(|| black_box(run(Dop853::new(tol(rtol)), on_attractor, 100)))
        });
    }
    g.finish();
    // The same W2 run with the oscillator (a layer over the 1-DOF `Mechanical` system) and
    // with the scalar right-hand side written out (bit-identical trajectories): the layer's
    // cost on a whole run, as a ratio in one run.
    let mut g = c.benchmark_group("paper_model_w2_100");
    g.sample_size(20);
    let reference = scalar::paper(OMEGA);
    assert_eq!(
        run_system(reference, Dopri5::new(tol(1e-8)), on_attractor, 10).1,
        run(Dopri5::new(tol(1e-8)), on_attractor, 10).1,
        "the two forms must give the same trajectory"
    );
    g.bench_function("scalar/1e-8", |b| {
        b.iter(|| {
            black_box(run_system(
                reference,
                Dopri5::new(tol(1e-8)),
                on_attractor,
                100,
            ))
        })
    });
    g.bench_function("oscillator/1e-8", |b| {
        b.iter(|| black_box(run(Dopri5::new(tol(1e-8)), on_attractor, 100)))
    });
    g.finish();
    print_attempts(on_attractor, 100);
    let mut g = c.benchmark_group("turning_points_w2_100");
    g.sample_size(10);
    for rtol in [1e-6, 1e-8, 1e-10] {
        g.bench_function(format!("time/{rtol:e}"), |b| {
            b.iter(|| black_box(run(Dopri5::new(tol(rtol)), on_attractor, 100)))
        });
        g.bench_function(format!("segments/{rtol:e}"), |b| {
            b.iter(|| black_box(run(turning(rtol), on_attractor, 100)))
        });
    }
    g.finish();
    let mut g = c.benchmark_group("rk_pairs_w2_100");
    g.sample_size(10);
    bench_pair::<Dopri5Method>(&mut g, "dopri5", on_attractor);
    bench_pair::<Tsit5Method>(&mut g, "tsit5", on_attractor);
    bench_pair::<Vern6Method>(&mut g, "vern6", on_attractor);
    bench_pair::<Dop853Method>(&mut g, "dop853", on_attractor);
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
