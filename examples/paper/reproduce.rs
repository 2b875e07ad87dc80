//! The computations behind the paper's numbers, shared by `examples/paper` and the golden
//! test `tests/paper.rs`. Everything is assembled from the crate's generic parts.

#![allow(dead_code, clippy::too_many_arguments)]

use nalgebra::Vector2;
use nonsmooth::analysis::{
    AmplitudePhase, AmplitudeSpectrum, LinearizedResponse, TurningPoint, first_grazing,
    fit_harmonics, steady_samples,
};
use nonsmooth::entropy::{
    EntropyIndex, Histogram, HistogramEstimate, QRange, entropy_index, redundancy_curve,
};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{
    Diagram, DiagramSettings, IntervalRule, TwoTrajectory, pair_tolerances, tle_diagram,
};
use nonsmooth::sweep::{
    Stop, SweepConfig, SweepDirection, SweepPoint, SweepResult, SweepSystem, Transition, run_point,
    sweep,
};
use nonsmooth::systems::paper::lyapunov::{D0 as PAPER_D0, norm as paper_norm};
use nonsmooth::systems::paper::{PAPER, PaperOscillator};

pub type Res<T> = Result<T, nonsmooth::Error>;

pub const TAU: f64 = std::f64::consts::TAU;

pub fn stop() -> Stop {
    Stop {
        position: 0,
        velocity: 1,
        level: PAPER.x_i,
    }
}

pub fn tolerances(rtol: f64) -> Tolerances<f64, 2> {
    Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2]).expect("valid tolerances")
}

pub fn make(w: f64) -> Res<SweepSystem<PaperOscillator<f64>>> {
    Ok(SweepSystem {
        system: PAPER.oscillator::<f64>(w)?,
        period: TAU / w,
        stop: Some(stop()),
    })
}

pub fn rest() -> Res<Vector2<f64>> {
    Ok(Vector2::new(PAPER.static_equilibrium()?, 0.0))
}

/// Static equilibrium and the two approximate solutions at ω = 14 with their grazing
/// estimates: (X0, eq4 (sin, cos), eq4 grazing, eq6 (sin, cos), eq6 grazing).
pub struct Approximations {
    pub x0: f64,
    pub eq4: (f64, f64),
    pub eq4_grazing: f64,
    pub eq6: (f64, f64),
    pub eq6_grazing: f64,
}

pub fn approximations() -> Res<Approximations> {
    let omega = 14.0;
    let osc = PAPER.oscillator::<f64>(omega)?;
    let x0 = PAPER.static_equilibrium()?;
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c)?;
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c)?;
    let (a1, a2) = lin.coefficients(omega);
    let eq4_grazing = lin.grazing_omega(PAPER.x_i, 10.0, 30.0)?;
    let up = ap.solve(omega, TurningPoint::Upper)?;
    let eq6_grazing = ap.grazing_omega(PAPER.x_i, TurningPoint::Lower, 10.0, 14.0)?;
    Ok(Approximations {
        x0,
        eq4: (a1, a2),
        eq4_grazing,
        eq6: (up.sin_coefficient(), up.cos_coefficient()),
        eq6_grazing,
    })
}

/// The steady solution at ω (from rest, 100 transient periods), sampled over 4 periods.
pub struct Steady {
    pub omega: f64,
    pub t: Vec<f64>,
    pub x: Vec<f64>,
    pub v: Vec<f64>,
    /// a0, a1, b1, a2, b2 of the fit (3).
    pub fit: [f64; 5],
    /// Harmonic amplitudes j = 1..=12.
    pub harmonics: Vec<f64>,
}

pub fn steady(omega: f64, rtol: f64) -> Res<Steady> {
    let s = steady_samples(
        PAPER.oscillator::<f64>(omega)?,
        Dopri5::new(tolerances(rtol)),
        rest()?,
        TAU / omega,
        100,
        4,
        512,
    )?;
    let x = s.component(0);
    let v = s.component(1);
    let f = fit_harmonics(&s.t, &x, omega, 2)?;
    let sp = AmplitudeSpectrum::new(&s.t, &x, omega)?;
    let harmonics = (1..=12)
        .map(|j| sp.harmonic_amplitude(j))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Steady {
        omega,
        t: s.t,
        x,
        v,
        fit: [f.a0, f.a[0], f.b[0], f.a[1], f.b[1]],
        harmonics,
    })
}

/// Harmonics at least `frac` of the largest.
pub fn dominant(harmonics: &[f64], frac: f64) -> usize {
    let max = harmonics.iter().cloned().fold(0.0, f64::max);
    harmonics.iter().filter(|&&a| a >= frac * max).count()
}

pub fn first_grazing_omega(rtol: f64) -> Res<f64> {
    let y0 = rest()?;
    Ok(first_grazing(
        |w: f64| Ok((PAPER.oscillator::<f64>(w)?, TAU / w, y0)),
        || Dopri5::new(tolerances(rtol)),
        0,
        PAPER.x_i,
        14.0,
        14.1,
        1e-4,
        100,
        2,
    )?)
}

/// The first grazing as a bifurcation: the period-1 orbit followed by pseudo-arclength
/// continuation from ω = 13 until its smallest x reaches x_I (located on the branch).
pub fn first_grazing_continuation(rtol: f64) -> Res<f64> {
    use nonsmooth::lyapunov::tangent_tolerances;
    use nonsmooth::orbit::{BifurcationKind, ContinuationSettings, Shooting, follow};
    let tol = tolerances(rtol);
    let tangent = tangent_tolerances::<f64, 2, 2, 6>(&tol, rtol, rtol * 1e-2)?;
    let build = |w: f64| Ok(Shooting::new(PAPER.oscillator::<f64>(w)?, (), tangent));
    let settings = ContinuationSettings::new(13.0, 14.3, 0.005)?
        .with_max_step(0.2)?
        .with_grazing(PAPER.grazing());
    let branch = follow(build, |w| TAU / w, 0.0, 13.0, rest()?, &settings)?;
    branch
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::Grazing)
        .map(|b| b.p)
        .ok_or_else(|| {
            nonsmooth::orbit::OrbitError::InvalidSetting {
                what: "the continuation range [13, 14.3]",
                requirement: "to contain the first grazing",
                value: 14.3,
            }
            .into()
        })
}

/// The period-`k` orbit of the attractor reached from rest at `omega` (400 forcing periods,
/// then shooting with period `k·2π/ω`), followed in ω towards `upward`/downward within
/// `[lo, hi]`, with its folds, period doublings and contact changes of local maxima of `x`
/// at `x_I` (a local maximum of the flight reaching the stop, or a contact splitting)
/// located to 1e-9 rad/s.
pub fn window_branch(
    omega: f64,
    k: u32,
    upward: bool,
    lo: f64,
    hi: f64,
    rtol: f64,
) -> Res<nonsmooth::orbit::Branch<2>> {
    use nonsmooth::drive::Simulation;
    use nonsmooth::lyapunov::tangent_tolerances;
    use nonsmooth::orbit::{ContinuationSettings, Extremum, Grazing, Shooting, follow};
    use nonsmooth::sample::Stroboscopic;
    let tol = tolerances(rtol);
    let tangent = tangent_tolerances::<f64, 2, 2, 6>(&tol, rtol, rtol * 1e-2)?;
    let build = |w: f64| Ok(Shooting::new(PAPER.oscillator::<f64>(w)?, (), tangent));
    let period = |w: f64| f64::from(k) * TAU / w;
    let mut sim = Simulation::new(PAPER.oscillator::<f64>(omega)?, Dopri5::new(tol));
    let mut none = Stroboscopic::<f64, 2>::periodic(0.0, TAU / omega, 0.0, 1)?;
    let y = sim.run(0.0, rest()?, 400.0 * TAU / omega, &mut none)?.y;
    let orbit = build(omega)?.find(0.0, period(omega), y)?;
    let contacts = Grazing {
        extremum: Extremum::Max,
        ..PAPER.grazing()
    };
    let mut settings = ContinuationSettings::new(lo, hi, 0.002)?
        .with_max_step(0.05)?
        .with_contact_changes(contacts);
    if !upward {
        settings = settings.downward();
    }
    Ok(follow(build, period, 0.0, omega, orbit.state, &settings)?)
}

/// One frequency from rest with the paper's transients (100) and `record` periods.
pub fn from_rest(omega: f64, record: u32, rtol: f64) -> Res<SweepPoint<2>> {
    from_state(omega, rest()?, 100, record, rtol)
}

/// One frequency from the state `y0` at t = 0 with `transient` periods and `record` recorded.
pub fn from_state(
    omega: f64,
    y0: Vector2<f64>,
    transient: u32,
    record: u32,
    rtol: f64,
) -> Res<SweepPoint<2>> {
    let cfg = SweepConfig::new(vec![omega])?.record(record)?;
    Ok(run_point(
        &cfg,
        omega,
        make(omega)?,
        Dopri5::new(tolerances(rtol)),
        y0,
        transient,
    )?)
}

/// Up and down sweep with the paper's transients (100 first, 50 per step), 50 recorded.
pub fn sweep_both(lo: f64, hi: f64, step: f64, record: u32, rtol: f64) -> Res<SweepResult<2>> {
    let cfg = SweepConfig::grid(lo, hi, step)?
        .direction(SweepDirection::Both)
        .transients(100, 50)
        .record(record)?;
    Ok(sweep(
        &cfg,
        make,
        || Dopri5::new(tolerances(rtol)),
        rest()?,
    )?)
}

/// The location of a transition: the midpoint of its parameter step.
pub fn location(t: &Transition) -> f64 {
    0.5 * (t.before + t.after)
}

/// The detected transition nearest to `value`.
pub fn nearest(ts: &[Transition], value: f64) -> Option<f64> {
    ts.iter()
        .map(location)
        .min_by(|a, b| (a - value).abs().total_cmp(&(b - value).abs()))
}

/// The entropy index of the inter-impact intervals at ω from rest (100 transient periods,
/// `record` recorded), histogram on (0.05, 0.3) with step 0.001 (the paper's).
pub struct Entropy {
    pub omega: f64,
    pub intervals: Vec<f64>,
    pub estimate: HistogramEstimate<f64>,
    pub index: Option<EntropyIndex<f64>>,
    pub curve: Vec<(f64, f64)>,
}

pub fn entropy(omega: f64, record: u32, rtol: f64) -> Res<Entropy> {
    let p = from_rest(omega, record, rtol)?;
    let h = Histogram::new(0.05, 0.3, 0.001)?;
    let estimate = h.estimate(&p.intervals)?;
    let index = entropy_index(&estimate.probabilities, &QRange::default()).ok();
    let curve = redundancy_curve(&estimate.probabilities, 0.05, 3.0, 300)
        .map(|c| c.iter().map(|r| (r.q, r.redundancy)).collect())
        .unwrap_or_default();
    Ok(Entropy {
        omega,
        intervals: p.intervals,
        estimate,
        index,
        curve,
    })
}

/// The top Lyapunov exponent at ω from rest: two trajectories, d0 = `PAPER_D0`, the
/// paper's norm, renormalized every forcing period, `transient` then `periods` periods.
/// Returns (λ₁, standard error) in 1/s.
pub fn tle(omega: f64, transient: usize, periods: usize, rtol: f64) -> Res<(f64, f64)> {
    let osc = PAPER.oscillator::<f64>(omega)?;
    let tol = pair_tolerances(&tolerances(rtol))?;
    let mut est = TwoTrajectory::new(osc, Dopri5::new(tol), PAPER_D0, paper_norm())?;
    est.start(0.0, rest()?)?;
    let tau = TAU / omega;
    est.transient(tau, transient)?;
    let e = est.estimate(tau, periods)?;
    Ok((e.exponent, e.spread))
}

/// The TLE diagram (Fig. 5) over `omegas`, both directions with continuation.
pub fn tle_fig5(
    omegas: &[f64],
    transient: usize,
    step_transient: usize,
    periods: usize,
    rtol: f64,
) -> Res<Diagram<f64>> {
    let settings = DiagramSettings::new(
        IntervalRule::ForcingPeriod,
        transient,
        step_transient,
        periods,
    )?;
    let tol = pair_tolerances(&tolerances(rtol))?;
    Ok(tle_diagram(
        |w: f64| Ok(PAPER.oscillator::<f64>(w)?),
        &Dopri5::new(tol),
        rest()?,
        omegas,
        PAPER_D0,
        paper_norm(),
        &settings,
    )?)
}

/// A synthetic experiment at ω = 17 rad/s (`duration` s at 1 kHz, σ = 2 µm noise and a
/// 1 µm, 60 Hz unmodelled oscillation, seed 7), then Nelder–Mead on `F0` for `names` from
/// a guess 20 % off. Returns (F0 at the fit in mm², F0 of the true parameters in mm², the
/// fitted values relative to the true ones, simulations).
pub fn synthetic_fit(duration: f64, names: &[&str]) -> Res<(f64, f64, Vec<f64>, u64)> {
    use nonsmooth::identify::{M2_TO_MM2, NelderMeadOptions};
    use nonsmooth::systems::paper::{Forcing, PaperFit, SyntheticExperiment, paper_parameter};
    let forcing = Forcing::constant(17.0);
    let rec = SyntheticExperiment::new(PAPER, forcing, duration)?
        .with_noise(2e-6, 7)?
        .with_disturbance(1e-6, 60.0)?
        .generate()?;
    let floor = PaperFit::new(rec.measured.clone(), (0.0, duration), forcing, PAPER)?
        .objective(&PAPER)?
        * M2_TO_MM2;
    let mut fit = PaperFit::new(rec.measured, (0.0, duration), forcing, PAPER)?
        .with_options(NelderMeadOptions::default().with_tolerances(1e-4, 1e-6));
    for n in names {
        let v = paper_parameter(&PAPER, n)?;
        fit = fit.fit_bounded(n, 1.2 * v, 0.4 * v, 3.6 * v)?;
    }
    let r = fit.run()?;
    let rel = names
        .iter()
        .map(|n| Ok(paper_parameter(&r.parameters, n)? / paper_parameter(&PAPER, n)?))
        .collect::<Res<Vec<f64>>>()?;
    Ok((r.f0_mm2, floor, rel, r.simulations))
}
