//! Any model in SIMD lanes: four systems built from the crate's parts (and one law of the
//! user's own) run through `ensemble::Ensemble`, each checked against the scalar
//! `Simulation` + `Dopri5` and timed against it on one thread.
//!
//! `cargo run --release --features timing --example ensemble_any [-- --quick] [--only NAME]
//! [--simd avx2]` (`--only duffing_ueda`, `two_dof_impact`, `bouncing_ball` or
//! `user_law_fallback`: that model alone, e.g. under a profiler; `--simd baseline|avx2|avx512`
//! caps the run-time dispatch, so an AVX-512 host measures the AVX2 code too)
//!
//! * (a) the Duffing–Ueda oscillator (`systems::DuffingUeda`), 64 forcing amplitudes;
//! * (b) the 2-DOF impact system of the catalogue (`systems::TwoDofImpact`, state of
//!   size 4) with its Hertz stop on the relative coordinate and the stop as a detection
//!   event, 64 forcing frequencies;
//! * (c) the bouncing ball on a vibrating table (`systems::BouncingBallTable`): Newton's
//!   restitution on the moving table as a resetting event, per lane, 64 table amplitudes;
//! * (d) a forced oscillator with a law of the user's own (no lane form): the fallback
//!   `LaneByLane`, which evaluates the right-hand side lane by lane.
//!
//! For each, every trajectory's end time and state, statistics (steps, rejections,
//! evaluations, events) and every event record (time, state, state after the reset) must
//! equal the scalar path's to the bit (`LaneMath::Exact`, the default); the example exits
//! non-zero otherwise. It then times the scalar path and the ensemble in two
//! configurations (exact math and the vector math, `LaneMath::Vector`: `exp` and `ln` —
//! the Hertz law's power, the step-size controller's — as lane polynomials within 1 ulp
//! instead of the platform's per lane), the best of five turns each in this run (a turn
//! repeats a model's runs until the scalar path's turn takes about a quarter of a second:
//! the bouncing ball's run takes milliseconds), one thread, on the instruction set chosen
//! at run time and its lanes (sixteen with AVX2 or AVX-512, four on the baseline), and
//! prints `throughput ratio <name> ensemble/scalar: R` for the faster configuration.

use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

use nalgebra::SVector;
use nonsmooth::drive::{Control, EventRecord, Observer, Outcome, RunError, Simulation};
use nonsmooth::ensemble::{Ensemble, LaneMath, MemberRun, Simd};
use nonsmooth::event::{Direction, Event, EventSet};
use nonsmooth::excite::Harmonic;
use nonsmooth::force::ViscousDamper;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::model::Oscillator;
use nonsmooth::systems::{BouncingBallTable, DuffingUeda, TwoDofImpact};
use nonsmooth::{ForceLaw, LaneByLane, LaneDynamics};

/// Every event of a trajectory: time, state, state after the reset (bits).
#[derive(Debug, Clone, Default, PartialEq)]
struct Events<const M: usize>(Vec<(u64, [u64; M], Option<[u64; M]>)>);

impl<const M: usize> Observer<f64, M> for Events<M> {
    fn on_event(&mut self, e: &EventRecord<f64, M>) -> Control {
        let bits = |y: &SVector<f64, M>| core::array::from_fn(|i| y[i].to_bits());
        self.0
            .push((e.t.to_bits(), bits(&e.y), e.y_after.as_ref().map(bits)));
        Control::Continue
    }
    /// Events only: the lanes' quiet steps skip the scalar event search.
    fn wants_steps(&self) -> bool {
        false
    }
}

/// A trajectory's result, comparable bit for bit (errors by their message).
type Run<const M: usize> = Result<(u64, [u64; M], String), String>;

fn key<const M: usize, E: std::fmt::Display>(r: &Result<Outcome<f64, M>, E>) -> Run<M> {
    match r {
        Ok(o) => Ok((
            o.t.to_bits(),
            core::array::from_fn(|i| o.y[i].to_bits()),
            format!("{:?} {:?}", o.termination, o.stats),
        )),
        Err(e) => Err(e.to_string()),
    }
}

/// The scalar path: one `Simulation` after the other.
fn scalar<D: LaneDynamics<M>, E: EventSet<f64, M> + Clone, const M: usize>(
    jobs: &[MemberRun<D, M>],
    tol: Tolerances<f64, M>,
    events: &E,
    obs: &mut [Events<M>],
) -> Vec<nonsmooth::Result<Outcome<f64, M>>> {
    jobs.iter()
        .zip(obs)
        .map(|(j, o)| {
            let mut sim = Simulation::new(j.member.clone(), Dopri5::new(tol))
                .with_events(events.clone())
                .landing_grid(j.grid)?;
            Ok(sim.run(j.t0, j.y0, j.t_end, o)?)
        })
        .collect()
}

/// Runs `jobs` through the scalar path and through the ensemble in both configurations
/// (exact and vector math, in the lanes of the instruction set), compares them and prints
/// the throughput ratios. Returns whether every trajectory of every exact configuration agreed with the
/// scalar path to the bit.
fn compare<D, E, const M: usize>(
    name: &str,
    jobs: &[MemberRun<D, M>],
    tol: Tolerances<f64, M>,
    events: E,
    simd: Simd,
) -> nonsmooth::Result<bool>
where
    D: LaneDynamics<M>,
    E: EventSet<f64, M> + Clone,
{
    let exact = Ensemble::new(tol)?
        .with_simd(simd)
        .with_events(events.clone())?;
    let vector = exact.clone().with_math(LaneMath::Vector);
    type Run<'a, const M: usize> = Box<
        dyn Fn(&mut [Events<M>]) -> Result<Vec<Result<Outcome<f64, M>, RunError>>, RunError> + 'a,
    >;
    let configs: Vec<(&str, bool, Run<M>)> = vec![
        ("exact", true, Box::new(|o| exact.run(jobs, o))),
        ("vector", false, Box::new(|o| vector.run(jobs, o))),
    ];
    let fresh = || vec![Events::<M>::default(); jobs.len()];
    let mut obs_s = fresh();
    let t_check = Instant::now();
    let s = scalar(jobs, tol, &events, &mut obs_s);
    // Each timed turn repeats a short model's runs until the scalar path's turn takes
    // about a quarter of a second: a turn of a few milliseconds is at the mercy of the
    // host's scheduler.
    let reps = (0.25 / t_check.elapsed().as_secs_f64())
        .ceil()
        .clamp(1.0, 100.0) as usize;
    let impacts: usize = obs_s.iter().map(|e| e.0.len()).sum();
    let failed = s.iter().filter(|r| r.is_err()).count();
    let mut same = true;
    let mut agree = vec![0usize; configs.len()];
    for (c, (cname, bits, run)) in configs.iter().enumerate() {
        let mut obs_l = fresh();
        let l = run(&mut obs_l)?;
        for (k, ((a, b), (ea, eb))) in s.iter().zip(&l).zip(obs_s.iter().zip(&obs_l)).enumerate() {
            if key(a) == key(b) && ea == eb {
                agree[c] += 1;
            } else if *bits {
                println!(
                    "  {name}, {cname}: trajectory {k} differs: scalar {:?}, lanes {:?}",
                    key(a),
                    key(b)
                );
                same = false;
            }
        }
    }
    // Timings: the best of five of each path, in turns (interference on a shared machine
    // only adds time, and taking turns exposes every path to the same interference); a
    // turn is `reps` runs, and a run's time is the turn's over `reps`.
    let mut ts = f64::INFINITY;
    let mut tl = vec![f64::INFINITY; configs.len()];
    for _ in 0..5 {
        let t = Instant::now();
        for _ in 0..reps {
            black_box(scalar(jobs, tol, &events, &mut fresh()));
        }
        ts = ts.min(t.elapsed().as_secs_f64() / reps as f64);
        for (c, (_, _, run)) in configs.iter().enumerate() {
            let t = Instant::now();
            for _ in 0..reps {
                let mut obs = fresh();
                black_box(run(&mut obs)?);
            }
            tl[c] = tl[c].min(t.elapsed().as_secs_f64() / reps as f64);
        }
    }
    println!(
        "{name}: {} trajectories ({failed} ended in an error), {impacts} events; scalar {ts:.4} s (best of 5 turns of {reps} run{})",
        jobs.len(),
        if reps == 1 { "" } else { "s" }
    );
    let mut best = (0.0f64, "");
    for (c, (cname, bits, _)) in configs.iter().enumerate() {
        let r = ts / tl[c];
        println!(
            "  {cname:<7} {:.4} s  ratio {r:.2}  {}/{} trajectories equal to the scalar path to the bit{}",
            tl[c],
            agree[c],
            jobs.len(),
            if *bits {
                ""
            } else {
                " (vector math: within rounding, not to the bit)"
            }
        );
        if r > best.0 {
            best = (r, cname);
        }
    }
    println!("  fastest configuration: {} math", best.1);
    println!("throughput ratio {name} ensemble/scalar: {:.2}", best.0);
    Ok(same)
}

/// A law of the user's own, without a lane form: a softening spring `k·x/(1 + x²)`.
#[derive(Debug, Clone, Copy)]
struct Softening {
    k: f64,
}

impl ForceLaw<f64> for Softening {
    fn force(&self, x: f64, _v: f64) -> f64 {
        self.k * x / (1.0 + x * x)
    }
}

fn main() -> ExitCode {
    match run() {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => {
            eprintln!("ensemble_any: lanes and scalar path differ");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("ensemble_any: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> nonsmooth::Result<bool> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let only = args
        .iter()
        .position(|a| a == "--only")
        .map(|k| args.get(k + 1).map_or("", String::as_str));
    let names = [
        "duffing_ueda",
        "two_dof_impact",
        "bouncing_ball",
        "user_law_fallback",
    ];
    if let Some(o) = only.filter(|o| !names.contains(o)) {
        eprintln!("ensemble_any: --only takes one of {names:?}, not {o:?}");
        return Ok(false);
    }
    let simd = match args
        .iter()
        .position(|a| a == "--simd")
        .map(|k| args.get(k + 1).map_or("", String::as_str))
    {
        None => Simd::Auto,
        Some("baseline") => Simd::Baseline,
        Some("avx2") => Simd::Avx2,
        Some("avx512") => Simd::Avx512,
        Some(o) => {
            eprintln!("ensemble_any: --simd takes baseline, avx2 or avx512, not {o:?}");
            return Ok(false);
        }
    };
    println!("instruction set: {:?}", simd.resolve());
    let runs = |name: &str| only.is_none_or(|o| o == name);
    let n = 64;
    let periods = if quick { 10.0 } else { 200.0 };
    let mut ok = true;

    // (a) Duffing–Ueda, B from 5 to 12.
    if runs(names[0]) {
        let tol = Tolerances::new(1e-8, 1e-10)?;
        let jobs = (0..n)
            .map(|i| {
                let p = DuffingUeda {
                    b: 5.0 + 7.0 * i as f64 / (n - 1) as f64,
                    ..DuffingUeda::default()
                };
                Ok(MemberRun::<_, 2>::periods_of(
                    p.model::<f64>()?,
                    SVector::from([1.0, 0.0]),
                    p.period(),
                    periods,
                )?)
            })
            .collect::<nonsmooth::Result<Vec<_>>>()?;
        ok &= compare(names[0], &jobs, tol, (), simd)?;
    }

    // (b) The 2-DOF impact system, ω from 0.3 to 1.3, its stop as a detection event.
    if runs(names[1]) {
        let p = TwoDofImpact::default();
        let tol = Tolerances::new(1e-8, 1e-10)?;
        let jobs = (0..n)
            .map(|i| {
                let w = 0.3 + i as f64 / (n - 1) as f64;
                Ok(MemberRun::<_, 4>::periods_of(
                    p.model::<f64>(w)?,
                    SVector::zeros(),
                    TwoDofImpact::period(w),
                    periods,
                )?)
            })
            .collect::<nonsmooth::Result<Vec<_>>>()?;
        let stop = Event::new(p.stop::<f64>()?, Direction::Rising);
        ok &= compare(names[1], &jobs, tol, stop, simd)?;
    }

    // (c) The bouncing ball, Γ from 2.5 to 4 at e = 0.8: restitution on the moving table.
    // Each lane has its own table (Γ), so the event's surface differs per trajectory: one
    // ensemble per table would lose the lanes; instead the table amplitude is the same and
    // the ball's gravity varies (Γ = Aω²/g).
    if runs(names[2]) {
        let base = BouncingBallTable::with_gamma(3.0, 0.8)?;
        let tol = Tolerances::new(1e-10, 1e-12)?;
        let jobs = (0..n)
            .map(|i| {
                let gamma = 2.5 + 1.5 * i as f64 / (n - 1) as f64;
                let ball = BouncingBallTable {
                    g: base.amplitude * base.omega * base.omega / gamma,
                    ..base
                };
                let v0 = ball.table_motion(0.0).1 + 2.0;
                Ok(MemberRun::<_, 2>::periods_of(
                    ball.model::<f64>()?,
                    SVector::from([0.0, v0]),
                    ball.period(),
                    periods,
                )?)
            })
            .collect::<nonsmooth::Result<Vec<_>>>()?;
        let impact =
            Event::new(base.table::<f64>()?, Direction::Rising).with_reset(base.impact::<f64>()?);
        ok &= compare(names[2], &jobs, tol, impact, simd)?;
    }

    // (d) A law of one's own: the fallback evaluates the right-hand side lane by lane.
    if runs(names[3]) {
        let tol = Tolerances::new(1e-8, 1e-10)?;
        let jobs = (0..n)
            .map(|i| {
                let w = 0.5 + i as f64 / (n - 1) as f64;
                let osc = Oscillator::new(
                    1.0,
                    (Softening { k: 1.0 }, ViscousDamper::new(0.1)?),
                    Harmonic::new(0.5, w, 0.0)?,
                )?;
                Ok(MemberRun::periods_of(
                    LaneByLane(osc),
                    SVector::from([0.1, 0.0]),
                    std::f64::consts::TAU / w,
                    periods,
                )?)
            })
            .collect::<nonsmooth::Result<Vec<_>>>()?;
        ok &= compare(names[3], &jobs, tol, (), simd)?;
    }
    Ok(ok)
}
