//! Crossing the turning points in the velocity's power scale ([`TurningPoints`]) against
//! time stepping alone, on the paper's model.
//!
//! For starts on the attractor at ω = 20.465 rad/s (every 5 periods after 100), x after 5
//! periods is compared with DOP853 at rtol 1e-13; printed per rtol: the RMS error of x,
//! right-hand-side evaluations and trial steps per forcing period, segments per period,
//! trial steps per segment, abandoned segments and CPU time per 1000 periods; then the
//! work–precision gain on a stable periodic orbit and the exact law's creep from rest.
//!
//! Measured (one run, shared machine; band 3e-3 m/s, `TurningPoints::dopri5`):
//!
//! | rtol | RHS/period time → segments | attempts/period | attempts/segment | RMS err x time → segments | CPU |
//! |---|---|---|---|---|---|
//! | 1e-6 | 1014 → 756 (−25 %) | 169 → 123 | 7.8 | 4.6e-6 → 3.2e-6 | −15 % |
//! | 1e-8 | 1928 → 1486 (−23 %) | 321 → 245 | 17.2 | 7.1e-8 → 5.9e-8 | −15 % |
//! | 1e-10 | 3933 → 3134 (−20 %) | 655 → 520 | 35.3 | 2.6e-9 → 5.1e-10 | −12 % |
//!
//! Four segments per period (two turning points in contact, two friction reversals in free
//! flight), none abandoned. On the chaotic attractor errors grow from period to period, so
//! the second table measures on the stable period-2 orbit at ω = 19 rad/s: time stepping
//! needs 1.02–1.47× (median 1.28×) the evaluations to reach the segments' error at rtol
//! 1e-6…1e-12. With θ to rtol (`--theta-atol 1`) the gain is 0.85–1.13×, with 1000·rtol
//! 0.94–1.35×.
//!
//! The third table runs the exact law (η = 0) from rest: the first period creeps out of
//! resting contact with `a ≈ 0` (the damping term balances the forcing), which is not a
//! turning point, and segments save 0.2–8 % there (280 850 → 277 290 evaluations at
//! rtol 1e-8).
//!
//! With `--onset 1e-5` the first 10 µm of each contact are crossed in contact segments as
//! well (`with_onset_band`): 4 per period, 2.9 / 6.7 / 13.4 trial steps each at rtol
//! 1e-6 / 1e-8 / 1e-10; evaluations per period 853 / 1609 / 3234 (more than the velocity
//! segments alone) at RMS errors 2.3e-6 / 6.4e-8 / 8.8e-10, and a period-2 gain of
//! 0.95–1.69× (median 1.33×): no clear gain.
//!
//! `cargo run --release --example turning_points -- [--quick] [--band V] [--theta-atol F]
//! [--onset D]` (`F`: the segments' absolute tolerance on θ in units of rtol, default 100
//! as in `TurningPoints::dopri5`; `D`: the contact band δ* in m, off by default).

use std::f64::consts::TAU;
use std::time::Instant;

use nalgebra::Vector2;
use nonsmooth::drive::{Control, Observer, Simulation, StepView};
use nonsmooth::integrate::{DenseOutput, Dop853, Dopri5, Stepper, Tolerances, TurningPoints};
use nonsmooth::sample::Stroboscopic;
use nonsmooth::systems::paper::PAPER;

const OMEGA: f64 = 20.465;

/// The segments' settings.
#[derive(Clone, Copy)]
struct Config {
    /// The velocity band V* (m/s).
    band: f64,
    /// Absolute tolerance of a segment's θ in units of rtol.
    theta_atol: f64,
    /// The contact band δ* (m), if contact segments are on.
    onset: Option<f64>,
}

impl Config {
    fn stepper(
        &self,
        rtol: f64,
    ) -> nonsmooth::Result<TurningPoints<f64, Dopri5<f64, 2>, Dopri5<f64, 2>>> {
        let seg_tol = Tolerances::per_component(rtol, [rtol * self.theta_atol, rtol * 1e-4])?;
        let st = TurningPoints::new(
            Dopri5::new(time_tolerances(rtol)?),
            Dopri5::new(seg_tol),
            self.band,
        )?;
        Ok(match self.onset {
            Some(d) => st.with_onset_band(d)?,
            None => st,
        })
    }
}

fn time_tolerances(rtol: f64) -> nonsmooth::Result<Tolerances<f64, 2>> {
    Ok(Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2])?)
}

/// Accepted steps by phase: free flight, contact (`x ≥ x_I` at an end), and the band
/// `|ẋ| < V*` (both ends inside it, i.e. the segments' steps when segments are on).
#[derive(Default)]
struct Phases {
    band: f64,
    free: u64,
    contact: u64,
    in_band: u64,
    onset_exit: u64,
}

impl Observer<f64, 2> for Phases {
    fn on_step<D: DenseOutput<f64, 2>>(&mut self, s: &StepView<'_, f64, 2, D>) -> Control {
        let inside = |y: &Vector2<f64>| y[0] >= PAPER.x_i;
        let edge = self.band * (1.0 + 1e-9);
        if s.y0[1].abs() <= edge && s.y1[1].abs() <= edge {
            self.in_band += 1;
        } else if inside(&s.y0) != inside(&s.y1) {
            self.onset_exit += 1;
        } else if inside(&s.y0) {
            self.contact += 1;
        } else {
            self.free += 1;
        }
        Control::Continue
    }
}

/// Where the accepted steps go, per period, with and without segments (rtol 1e-8).
fn phases(cfg: Config, starts: &[(f64, Vector2<f64>, f64)], span: f64) -> nonsmooth::Result<()> {
    let osc = PAPER.oscillator::<f64>(OMEGA)?;
    let period = TAU / OMEGA;
    let rtol = 1e-8;
    println!();
    println!("accepted steps per period by phase, rtol {rtol:e} (band: both ends with |ẋ| < V*)");
    println!("| method | free flight | contact onset/exit | in contact | band | rejected (all) |");
    println!("|---|---|---|---|---|---|");
    let periods = starts.len() as f64 * span;
    for with_segments in [false, true] {
        let mut ph = Phases {
            band: cfg.band,
            ..Phases::default()
        };
        let mut rejected = 0;
        for &(t0, y0, _) in starts {
            let t1 = t0 + span * period;
            if with_segments {
                let st = cfg.stepper(rtol)?;
                let mut sim = Simulation::new(osc, st);
                rejected += sim.run(t0, y0, t1, &mut ph)?.stats.rejected;
            } else {
                let mut sim = Simulation::new(osc, Dopri5::new(time_tolerances(rtol)?));
                rejected += sim.run(t0, y0, t1, &mut ph)?.stats.rejected;
            }
        }
        println!(
            "| {} | {:.0} | {:.1} | {:.0} | {:.0} | {:.0} |",
            if with_segments {
                "DOPRI5 + segments"
            } else {
                "DOPRI5 in time"
            },
            ph.free as f64 / periods,
            ph.onset_exit as f64 / periods,
            ph.contact as f64 / periods,
            ph.in_band as f64 / periods,
            rejected as f64 / periods
        );
    }
    Ok(())
}

/// `periods` periods from `(t0, y0)` landing on the sections: the section points and the
/// right-hand-side evaluations.
fn sections<St: Stepper<f64, 2>>(
    omega: f64,
    st: St,
    t0: f64,
    y0: Vector2<f64>,
    periods: u32,
) -> nonsmooth::Result<(Vec<Vector2<f64>>, u64)> {
    let period = TAU / omega;
    let mut sim =
        Simulation::new(PAPER.oscillator::<f64>(omega)?, st).landing_grid(Some((0.0, period)))?;
    // Steps land on the sections, so the sampler records the step ends there.
    let mut strobe =
        Stroboscopic::<f64, 2>::periodic(0.0, period, t0 + 0.5 * period, periods as usize)?;
    let out = sim.run(t0, y0, t0 + f64::from(periods) * period, &mut strobe)?;
    let points = strobe.points().iter().map(|p| p.y).collect();
    Ok((points, out.stats.rhs_evals))
}

/// The stable period-2 orbit at ω = 19 rad/s, where errors do not grow from period to
/// period: the largest |x − x_ref| over 20 section points against DOP853 at rtol 1e-13.
fn periodic(cfg: Config) -> nonsmooth::Result<()> {
    const OMEGA_P2: f64 = 19.0;
    const H: u32 = 20;
    let period = TAU / OMEGA_P2;
    let x0 = PAPER.static_equilibrium()?;
    let t0 = 200.0 * period;
    let y0 = Simulation::new(
        PAPER.oscillator::<f64>(OMEGA_P2)?,
        Dop853::new(time_tolerances(1e-13)?),
    )
    .run(0.0, Vector2::new(x0, 0.0), t0, &mut ())?
    .y;
    let (reference, _) = sections(OMEGA_P2, Dop853::new(time_tolerances(1e-13)?), t0, y0, H)?;
    let worst = |pts: &[Vector2<f64>]| {
        pts.iter()
            .zip(&reference)
            .map(|(a, b)| (a[0] - b[0]).abs())
            .fold(0.0, f64::max)
    };
    println!();
    println!(
        "stable period-2 orbit, ω = {OMEGA_P2}: largest |x − x_ref| over {H} section points (DOP853, rtol 1e-13); \
         gain = evaluations time stepping needs for the same error (log-log interpolation) / evaluations with segments"
    );
    println!(
        "| rtol | time: max err x (m) | time: RHS/period | segments: max err x (m) | segments: RHS/period | gain |"
    );
    println!("|---|---|---|---|---|---|");
    let all: Vec<f64> = (0..=6).map(|k| 10f64.powi(-6 - k)).collect();
    let mut time = vec![];
    for &rtol in &all {
        let (pts, n) = sections(OMEGA_P2, Dopri5::new(time_tolerances(rtol)?), t0, y0, H)?;
        time.push((worst(&pts), n as f64 / f64::from(H)));
    }
    // Evaluations time stepping needs for `err` (log-log interpolation along rtol).
    let needed = |err: f64| -> Option<f64> {
        time.windows(2).find_map(|w| {
            let ((e0, n0), (e1, n1)) = (w[0], w[1]);
            (err <= e0 && err >= e1).then(|| {
                let f = (err.ln() - e0.ln()) / (e1.ln() - e0.ln());
                (n0.ln() + f * (n1.ln() - n0.ln())).exp()
            })
        })
    };
    for (k, &rtol) in all.iter().enumerate() {
        let st = cfg.stepper(rtol)?;
        let (pts, n) = sections(OMEGA_P2, st, t0, y0, H)?;
        let (e, n) = (worst(&pts), n as f64 / f64::from(H));
        let gain = needed(e).map_or("–".to_string(), |m| format!("{:.2}", m / n));
        println!(
            "| {rtol:e} | {:.2e} | {:.0} | {e:.2e} | {n:.0} | {gain} |",
            time[k].0, time[k].1
        );
    }
    Ok(())
}

fn main() -> nonsmooth::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let band = args
        .iter()
        .position(|a| a == "--band")
        .and_then(|i| args.get(i + 1))
        .map_or(3e-3, |s| s.parse::<f64>().unwrap_or(f64::NAN));
    // Absolute tolerance of a segment's θ, in units of rtol (`TurningPoints::dopri5`: 100).
    let theta_atol = args
        .iter()
        .position(|a| a == "--theta-atol")
        .and_then(|i| args.get(i + 1))
        .map_or(100.0, |s| s.parse::<f64>().unwrap_or(f64::NAN));
    // The contact band δ* (m): contact segments on if given.
    let onset = args
        .iter()
        .position(|a| a == "--onset")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.parse::<f64>().unwrap_or(f64::NAN));
    let cfg = Config {
        band,
        theta_atol,
        onset,
    };
    let osc = PAPER.oscillator::<f64>(OMEGA)?;
    let period = TAU / OMEGA;
    let (n_starts, span) = if quick { (5, 5.0) } else { (20, 5.0) };
    let rtols: &[f64] = if quick { &[1e-8] } else { &[1e-6, 1e-8, 1e-10] };
    let reference = |t0: f64, y0: Vector2<f64>, t1: f64| -> nonsmooth::Result<Vector2<f64>> {
        Ok(Simulation::new(osc, Dop853::new(time_tolerances(1e-13)?))
            .run(t0, y0, t1, &mut ())?
            .y)
    };
    let mut starts = Vec::new();
    let x0 = PAPER.static_equilibrium()?;
    let mut y = reference(0.0, Vector2::new(x0, 0.0), 100.0 * period)?;
    let mut t = 100.0 * period;
    for _ in 0..n_starts {
        let y1 = reference(t, y, t + span * period)?;
        starts.push((t, y, y1[0]));
        (t, y) = (t + span * period, y1);
    }
    println!(
        "ω = {OMEGA}, {n_starts} starts on the attractor, x after {span} periods against DOP853 at rtol 1e-13, band {band:e} m/s"
    );
    println!(
        "| rtol | method | RMS err x (m) | RHS/period | trial steps/period | segments/period | trial steps/segment | abandoned | CPU s/1000 periods |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let periods = n_starts as f64 * span;
    for &rtol in rtols {
        // Time stepping alone.
        let mut sq = 0.0;
        let (mut evals, mut attempts) = (0u64, 0u64);
        let clock = Instant::now();
        for &(t0, y0, x_ref) in &starts {
            let mut sim = Simulation::new(osc, Dopri5::new(time_tolerances(rtol)?));
            let out = sim.run(t0, y0, t0 + span * period, &mut ())?;
            sq += (out.y[0] - x_ref).powi(2);
            evals += out.stats.rhs_evals;
            attempts += out.stats.accepted + out.stats.rejected;
        }
        let cpu = clock.elapsed().as_secs_f64();
        println!(
            "| {rtol:e} | DOPRI5 in time | {:.2e} | {:.0} | {:.0} | – | – | – | {:.3} |",
            (sq / n_starts as f64).sqrt(),
            evals as f64 / periods,
            attempts as f64 / periods,
            1000.0 * cpu / periods
        );
        // With segments.
        let mut sq = 0.0;
        let (mut evals, mut attempts, mut segs, mut seg_attempts, mut abandoned) =
            (0u64, 0u64, 0u64, 0u64, 0u64);
        let (mut contact, mut contact_attempts) = (0u64, 0u64);
        let clock = Instant::now();
        for &(t0, y0, x_ref) in &starts {
            let stepper = cfg.stepper(rtol)?;
            let mut sim = Simulation::new(osc, stepper);
            let out = sim.run(t0, y0, t0 + span * period, &mut ())?;
            sq += (out.y[0] - x_ref).powi(2);
            evals += out.stats.rhs_evals;
            let st = sim.stepper();
            let c = st.segment_counts();
            let ts = st.time_stepper().stats();
            attempts += ts.accepted + ts.rejected + c.attempts + c.contact_attempts;
            contact += c.contact_completed;
            contact_attempts += c.contact_attempts;
            abandoned += c.contact_abandoned;
            segs += c.completed;
            seg_attempts += c.attempts;
            abandoned += c.abandoned;
        }
        let cpu = clock.elapsed().as_secs_f64();
        println!(
            "| {rtol:e} | DOPRI5 + segments | {:.2e} | {:.0} | {:.0} | {:.2} | {:.1} | {abandoned} | {:.3} |",
            (sq / n_starts as f64).sqrt(),
            evals as f64 / periods,
            attempts as f64 / periods,
            segs as f64 / periods,
            seg_attempts as f64 / segs.max(1) as f64,
            1000.0 * cpu / periods
        );
        if cfg.onset.is_some() {
            println!(
                "|  | contact segments: {:.2}/period, {:.1} trial steps each |  |  |  |  |  |  |  |",
                contact as f64 / periods,
                contact_attempts as f64 / contact.max(1) as f64
            );
        }
    }
    phases(cfg, &starts, span)?;
    periodic(cfg)?;
    // The exact law (η = 0) from rest in contact: the first period creeps out of resting
    // contact, where the law's rate term has its cusp.
    let mut exact = PAPER;
    exact.eta = 0.0;
    let osc0 = exact.oscillator::<f64>(OMEGA)?;
    println!();
    println!(
        "exact law (η = 0), from rest at the static equilibrium, {n_exact} periods",
        n_exact = 10
    );
    println!("| rtol | method | RHS evaluations | x at the end (m) |");
    println!("|---|---|---|---|");
    for &rtol in rtols {
        let y0 = Vector2::new(x0, 0.0);
        let t1 = 10.0 * period;
        let plain =
            Simulation::new(osc0, Dopri5::new(time_tolerances(rtol)?)).run(0.0, y0, t1, &mut ());
        match plain {
            Ok(o) => println!(
                "| {rtol:e} | DOPRI5 in time | {} | {:.10e} |",
                o.stats.rhs_evals, o.y[0]
            ),
            Err(e) => println!("| {rtol:e} | DOPRI5 in time | failed: {e} | – |"),
        }
        let stepper = cfg.stepper(rtol)?;
        let mut sim = Simulation::new(osc0, stepper);
        match sim.run(0.0, y0, t1, &mut ()) {
            Ok(o) => println!(
                "| {rtol:e} | DOPRI5 + segments | {} | {:.10e} |",
                o.stats.rhs_evals, o.y[0]
            ),
            Err(e) => println!("| {rtol:e} | DOPRI5 + segments | failed: {e} | – |"),
        }
    }
    Ok(())
}
