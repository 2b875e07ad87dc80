//! Throughput of many trajectories: the scalar path (`Simulation` + `Dopri5`, one
//! trajectory after the other) against the ensemble (`ensemble::Ensemble`, trajectories in
//! SIMD lanes), on one thread, on the paper's model at rtol 1e-8.
//!
//! The workload: 64 forcing frequencies in [17.5, 25] rad/s, 200 forcing periods each
//! from rest in the static equilibrium, steps landing on the sections `t = 2πi/ω`, every
//! impact located, section points and impacts collected per trajectory — the work of an
//! independent-start bifurcation sweep. Throughput is trajectory-periods per second on
//! one core; the last line is the ratio of the fastest ensemble configuration of this
//! build (instruction set, with its lanes, and math mode, named on the line before) to the
//! scalar path, both
//! measured in this run. The scalar path and the configurations run three times in turn
//! (once with `--quick`), and each keeps its fastest time: on a shared machine,
//! interference only adds time.
//!
//! ```sh
//! cargo run --release --features timing --example ensemble_throughput            # 64 × 200 periods
//! cargo run --release --features timing --example ensemble_throughput -- --quick # 16 × 100 periods
//! cargo run --release --features timing --example ensemble_throughput -- --simd avx2  # cap the dispatch
//! ```
//!
//! The lane loop is compiled for the baseline, AVX2+FMA and AVX-512F and picked at run time
//! (`ensemble::Simd`), so the default build runs at the machine's width; `--simd baseline`
//! shows the build's own target alone.

use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::drive::{Control, EventRecord, Observer, Simulation, StepView};
use nonsmooth::ensemble::{Ensemble, LaneMath, MemberRun, Simd};
use nonsmooth::event::{Direction, Event, Stop};
use nonsmooth::integrate::{DenseOutput, Dopri5, Tolerances};
use nonsmooth::systems::paper::{Member, PAPER};

/// Section points (steps land on them: a step ending on a grid time is a section) and
/// the number of impacts.
#[derive(Debug, Clone, Default)]
struct Collect {
    period: f64,
    sections: Vec<Vector2<f64>>,
    impacts: usize,
}

impl Observer<f64, 2> for Collect {
    fn on_step<D: DenseOutput<f64, 2>>(&mut self, s: &StepView<'_, f64, 2, D>) -> Control {
        let k = (s.t1 / self.period).round();
        if k >= 1.0 && s.t1 == k * self.period {
            self.sections.push(s.y1);
        }
        Control::Continue
    }
    fn on_event(&mut self, _e: &EventRecord<f64, 2>) -> Control {
        self.impacts += 1;
        Control::Continue
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    // `--simd baseline|avx2|avx512` caps the run-time dispatch (default: the widest).
    let simd = match args
        .iter()
        .position(|a| a == "--simd")
        .and_then(|i| args.get(i + 1))
        .map(String::as_str)
    {
        Some("baseline") => Simd::Baseline,
        Some("avx2") => Simd::Avx2,
        Some("avx512") => Simd::Avx512,
        _ => Simd::Auto,
    };
    let (n, periods, reps) = if quick {
        (16, 100.0, 1)
    } else {
        (64, 200.0, 3)
    };
    let rtol = 1e-8;
    let tol = Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?;
    let y0 = Vector2::new(PAPER.static_equilibrium()?, 0.0);
    let impact = Event::new(
        Stop {
            position: 0,
            velocity: 1,
            level: PAPER.x_i,
        },
        Direction::Rising,
    );
    let jobs: Vec<MemberRun<Member>> = (0..n)
        .map(|i| {
            let w = 17.5 + 7.5 * i as f64 / (n - 1) as f64;
            MemberRun::periods(Member::paper(w)?, y0, periods)
        })
        .collect::<Result<_, nonsmooth::drive::RunError>>()?;
    let observers = || -> Vec<Collect> {
        jobs.iter()
            .map(|j| Collect {
                period: j.member.period(),
                ..Collect::default()
            })
            .collect()
    };
    let work = n as f64 * periods;
    println!(
        "{n} trajectories × {periods} periods of the paper's model (ω ∈ [17.5, 25]), rtol {rtol:e}, one thread, fastest of {reps} turns"
    );
    println!(
        "target features: avx2 {}, fma {}, avx512f {}",
        cfg!(target_feature = "avx2"),
        cfg!(target_feature = "fma"),
        cfg!(target_feature = "avx512f")
    );
    println!("lane loop dispatched at run time to: {:?}", simd.resolve());

    // The scalar path and every ensemble configuration, `reps` times in turn; each keeps
    // its fastest time. The machine is shared: interference only adds time, and taking
    // turns exposes every configuration to the same interference.
    let scalar = || -> nonsmooth::Result<(Vec<Collect>, u64)> {
        let mut obs = observers();
        let mut evals = 0u64;
        for (j, o) in jobs.iter().zip(obs.iter_mut()) {
            let mut sim = Simulation::new(*j.member.scalar(), Dopri5::new(tol))
                .with_events(impact)
                .landing_grid(j.grid)?;
            evals += sim.run(j.t0, j.y0, j.t_end, o)?.stats.rhs_evals;
        }
        Ok((obs, evals))
    };
    fn lanes(
        e: &Ensemble<Event<Stop<f64>>>,
        jobs: &[MemberRun<Member>],
        obs: &mut [Collect],
    ) -> nonsmooth::Result<()> {
        for r in e.run(jobs, obs)? {
            r?;
        }
        Ok(())
    }
    type Run<'a> = Box<dyn Fn(&mut [Collect]) -> nonsmooth::Result<()> + 'a>;
    // Each instruction set of this machine up to the cap, with its lanes, in both math
    // modes.
    let mut ensembles = Vec::new();
    for s in Simd::available() {
        let e = Ensemble::new(tol)?.with_event(impact)?.with_simd(s);
        ensembles.push((format!("{s:?}, exact"), e.clone()));
        ensembles.push((format!("{s:?}, vector"), e.with_math(LaneMath::Vector)));
        if s == simd.resolve() {
            break;
        }
    }
    let configs: Vec<(String, Run)> = ensembles
        .iter()
        .map(|(name, e)| {
            let run: Run = Box::new(|o| lanes(e, &jobs, o));
            (format!("ensemble {name}"), run)
        })
        .collect();
    let mut scalar_s = f64::INFINITY;
    let mut best_s = vec![f64::INFINITY; configs.len()];
    let (scalar_obs, evals) = scalar()?;
    let mut same = vec![0; configs.len()];
    for _ in 0..reps {
        let start = Instant::now();
        scalar()?;
        scalar_s = scalar_s.min(start.elapsed().as_secs_f64());
        for (k, (_, f)) in configs.iter().enumerate() {
            let mut obs = observers();
            let start = Instant::now();
            f(&mut obs)?;
            best_s[k] = best_s[k].min(start.elapsed().as_secs_f64());
            // Same impacts and sections as the scalar path (the vector math: within
            // rounding).
            same[k] = obs
                .iter()
                .zip(&scalar_obs)
                .filter(|(a, b)| a.sections == b.sections && a.impacts == b.impacts)
                .count();
        }
    }
    println!(
        "scalar                     {scalar_s:7.3} s  {:9.0} trajectory-periods/s  ({:.1} ns per evaluation)",
        work / scalar_s,
        scalar_s * 1e9 / evals as f64
    );
    let mut best = (0.0f64, "");
    for (k, (name, _)) in configs.iter().enumerate() {
        let name = name.as_str();
        let s = best_s[k];
        let ratio = scalar_s / s;
        println!(
            "{name:<26} {s:7.3} s  {:9.0} trajectory-periods/s  ratio {ratio:5.2}  ({}/{n} trajectories identical to scalar)",
            work / s,
            same[k]
        );
        if ratio > best.0 {
            best = (ratio, name);
        }
    }
    println!("fastest ensemble configuration: {}", best.1);
    println!("throughput ratio ensemble/scalar: {:.2}", best.0);
    Ok(())
}
