//! Harmonic analysis and the paper's approximate solutions (Sect. 5).
//!
//! Paper values are checked at their printed precision (they must round to what the paper
//! prints) and, at full precision, against an independent implementation (plain bisection
//! in Python on the same formulas, run while writing this module); the numbers are quoted in
//! the comments as `python:`.

use std::f64::consts::TAU;

use nonsmooth::ForceLaw;
use nonsmooth::analysis::{
    AmplitudeLaw, AmplitudePhase, AmplitudeSpectrum, AnalysisError, DOMINANCE_THRESHOLD,
    ForcingAmplitude, HarmonicFit, LinearizedResponse, SpectrumAnalyzer, TurningPoint,
    fit_harmonics,
};
use nonsmooth::force::LinearSpring;
use nonsmooth::model::Oscillator;
use nonsmooth::systems::paper::PAPER;
use nonsmooth::util::brent;

// ---------------------------------------------------------------------------------------
// helpers

/// `t0 + i·P·(2π/ω)/n`, `i < n`: `n` uniform samples over exactly `P` periods.
fn grid(n: usize, periods: usize, omega: f64, t0: f64) -> Vec<f64> {
    let dt = periods as f64 * TAU / omega / n as f64;
    (0..n).map(|i| t0 + i as f64 * dt).collect()
}

/// A signal `a0 + Σ_j A_j cos(jωt + φ_j)`.
struct Signal {
    omega: f64,
    a0: f64,
    terms: Vec<(usize, f64, f64)>, // (j, A_j, φ_j)
}

impl Signal {
    fn at(&self, t: f64) -> f64 {
        self.a0
            + self
                .terms
                .iter()
                .map(|&(j, a, p)| a * (j as f64 * self.omega * t + p).cos())
                .sum::<f64>()
    }
    fn sample(&self, t: &[f64]) -> Vec<f64> {
        t.iter().map(|&t| self.at(t)).collect()
    }
    fn cos_sin(&self, j: usize) -> (f64, f64) {
        self.terms
            .iter()
            .filter(|&&(k, _, _)| k == j)
            .fold((0.0, 0.0), |(c, s), &(_, a, p)| {
                (c + a * p.cos(), s - a * p.sin())
            })
    }
}

/// Harmonics 1, 2, 3, 5 over a mean (dynamic range 100 between the mean and the smallest).
fn multi() -> Signal {
    Signal {
        omega: 14.0,
        a0: 0.3,
        terms: vec![
            (1, 1.0, 1.9),
            (2, 0.2, -0.4),
            (3, 0.05, 2.8),
            (5, 0.01, -3.0),
        ],
    }
}

/// Paper-like magnitudes: a mean of −2.08e-3 m with harmonics of µm down to nm.
fn paper_like() -> Signal {
    Signal {
        omega: 14.0,
        a0: -2.08e-3,
        terms: vec![
            (1, 4.1e-6, 1.9),
            (2, 7.3e-7, -0.4),
            (3, 5.0e-8, 2.8),
            (5, 1.0e-9, -3.0),
        ],
    }
}

/// `true` if `ours` rounds to `paper` printed with `digits` significant digits.
fn rounds_to(ours: f64, paper: f64, digits: i32) -> bool {
    let e = paper.abs().log10().floor() as i32;
    let half_ulp = 0.5 * 10f64.powi(e - digits + 1);
    (ours - paper).abs() <= half_ulp * (1.0 + 1e-9)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

// ---------------------------------------------------------------------------------------
// spectrum

fn check_spectrum(s: &Signal, rel_tol: f64, abs_tol: f64) {
    let period = TAU / s.omega;
    for &(n, periods, t0) in &[
        (64, 1, 0.0),
        (256, 4, 0.0),
        (1000, 3, 0.0),          // n not a power of two
        (511, 5, 37.0 * period), // odd n, start on a later Poincaré section
        (512, 2, 0.123),         // start off a section: phases still in the origin t = 0
    ] {
        let t = grid(n, periods, s.omega, t0);
        let x = s.sample(&t);
        let sp = AmplitudeSpectrum::new(&t, &x, s.omega).unwrap();
        assert_eq!(sp.periods(), periods);
        assert_eq!(sp.len(), n);
        assert!(
            (sp.mean() - s.a0).abs() < rel_tol * s.a0.abs(),
            "mean, n = {n}"
        );
        for (m, &amp) in sp.amplitudes().iter().enumerate().skip(1) {
            let expect = s
                .terms
                .iter()
                .find(|&&(j, _, _)| j * periods == m)
                .map_or(0.0, |&(_, a, _)| a);
            let tol = rel_tol * expect + abs_tol;
            assert!(
                (amp - expect).abs() < tol,
                "n={n} bin {m}: {amp:e} vs {expect:e}"
            );
        }
        for &(j, a, p) in &s.terms {
            let h = sp.harmonic(j).unwrap();
            assert_eq!(h.harmonic, j);
            assert!((h.amplitude - a).abs() < rel_tol * a + abs_tol);
            let dphi = (h.phase - p).sin().atan2((h.phase - p).cos());
            assert!(dphi.abs() < rel_tol + abs_tol / a, "n={n} j={j}: {dphi:e}");
            let (c, sn) = s.cos_sin(j);
            assert!((h.cos - c).abs() < rel_tol * a + abs_tol);
            assert!((h.sin - sn).abs() < rel_tol * a + abs_tol);
        }
        let h0 = sp.harmonic(0).unwrap();
        assert_eq!((h0.cos, h0.sin), (sp.mean(), 0.0));
        let phase0 = if s.a0 < 0.0 {
            std::f64::consts::PI
        } else {
            0.0
        };
        assert_eq!(h0.phase, phase0);
    }
}

#[test]
fn spectrum_recovers_amplitudes_and_phases_exactly() {
    // Every amplitude and phase to 1e-12 relative, nothing between the harmonics.
    check_spectrum(&multi(), 1e-12, 1e-14);
}

#[test]
fn spectrum_of_paper_like_magnitudes() {
    // A 1e-9 harmonic under a 2e-3 mean: the FFT's rounding is relative to the whole signal
    // (~ε·|x|·log n ≈ 1e-18), so small harmonics are exact to that absolute level, not to
    // 1e-12 of themselves.
    check_spectrum(&paper_like(), 1e-12, 1e-14 * 2.08e-3);
}

#[test]
fn spectrum_of_a_sine_has_phase_minus_half_pi() {
    // sin θ = cos(θ − π/2).
    let omega = 20.465;
    let t = grid(128, 2, omega, 0.0);
    let x: Vec<f64> = t.iter().map(|&t| 0.25 * (3.0 * omega * t).sin()).collect();
    let h = AmplitudeSpectrum::new(&t, &x, omega)
        .unwrap()
        .harmonic(3)
        .unwrap();
    assert!((h.phase + std::f64::consts::FRAC_PI_2).abs() < 1e-13);
    assert!((h.sin - 0.25).abs() < 1e-14 && h.cos.abs() < 1e-14);
}

#[test]
fn dominant_harmonics_and_energy_fraction() {
    let omega = 14.0;
    let sig = Signal {
        omega,
        a0: 1.0,
        terms: vec![
            (1, 1.0, 0.3),
            (2, 0.2, -1.0),
            (3, 0.005, 0.5),
            (4, 0.0005, 2.0),
        ],
    };
    let t = grid(400, 2, omega, 0.0);
    let sp = AmplitudeSpectrum::new(&t, &sig.sample(&t), omega).unwrap();
    assert_eq!(sp.dominant_harmonic_count(DOMINANCE_THRESHOLD).unwrap(), 2);
    assert_eq!(sp.dominant_harmonic_count(1e-3).unwrap(), 3);
    assert_eq!(sp.dominant_harmonic_count(1e-4).unwrap(), 4);
    // (Threshold 0 would also count the rounding-level bins, ~1e-17: not asserted.)
    assert_eq!(sp.dominant_harmonic_count(1.0).unwrap(), 0);
    // Mean squares: A²/2 each.
    let e = [1.0, 0.04, 0.005 * 0.005, 0.0005 * 0.0005];
    let total: f64 = e.iter().sum();
    assert!(rel(sp.energy_fraction(1), e[0] / total) < 1e-12);
    assert!(rel(sp.energy_fraction(2), (e[0] + e[1]) / total) < 1e-12);
    assert!((sp.energy_fraction(10) - 1.0).abs() < 1e-12);
    assert_eq!(sp.energy_fraction(0), 0.0);
    assert!(matches!(
        sp.dominant_harmonic_count(1.5),
        Err(AnalysisError::Parameter(_))
    ));
    // A constant signal: nothing dominates, nothing is missed.
    let sp = AmplitudeSpectrum::new(&t, &vec![3.0; t.len()], omega).unwrap();
    assert_eq!(sp.dominant_harmonic_count(DOMINANCE_THRESHOLD).unwrap(), 0);
    assert_eq!(sp.energy_fraction(1), 1.0);
}

#[test]
fn subharmonic_energy_is_not_counted_as_harmonic() {
    // A period-2 orbit analyzed with the forcing frequency: its ω/2 content sits between
    // the harmonics and lowers the harmonic energy fraction.
    let omega = 19.0;
    let t = grid(256, 2, omega, 0.0);
    let x: Vec<f64> = t
        .iter()
        .map(|&t| (omega * t).sin() + 0.5 * (0.5 * omega * t).cos())
        .collect();
    let sp = AmplitudeSpectrum::new(&t, &x, omega).unwrap();
    assert!(rel(sp.amplitudes()[1], 0.5) < 1e-12);
    assert!((sp.bin_frequency(1) - omega / 2.0).abs() < 1e-14);
    let expect = 0.5 / (0.5 + 0.125);
    assert!(rel(sp.energy_fraction(5), expect) < 1e-12);
}

#[test]
fn analyzer_plans_once_for_a_sweep() {
    let mut an = SpectrumAnalyzer::new(240).unwrap();
    let mut first = None;
    for &omega in &[14.0, 14.1, 17.5, 18.0] {
        let t = grid(240, 3, omega, 0.0);
        let x: Vec<f64> = t.iter().map(|&t| (2.0 * omega * t).cos()).collect();
        match first.as_mut() {
            None => first = Some(an.analyze(&t, &x, omega).unwrap()),
            Some(s) => an.analyze_into(&t, &x, omega, s).unwrap(),
        }
        let s = first.as_ref().unwrap();
        assert!(rel(s.harmonic_amplitude(2).unwrap(), 1.0) < 1e-13);
        assert_eq!(s.omega(), omega);
    }
}

// ---------------------------------------------------------------------------------------
// harmonic fit

#[test]
fn fit_recovers_paper_like_coefficients_and_agrees_with_spectrum() {
    // Use the paper's eq. (3) coefficients as a synthetic signal, plus a small third
    // harmonic that a K = 2 fit must leave in the residual.
    let omega = 14.0;
    let (a0, a1, b1, a2, b2) = (-2.0813e-3, -1.3136e-6, 3.9328e-6, 6.6538e-7, 2.915e-7);
    let a3 = 2.0e-9;
    let f = |t: f64| {
        a0 + a1 * (omega * t).cos()
            + b1 * (omega * t).sin()
            + a2 * (2.0 * omega * t).cos()
            + b2 * (2.0 * omega * t).sin()
            + a3 * (3.0 * omega * t).cos()
    };
    let t = grid(600, 3, omega, 5.0 * TAU / omega);
    let x: Vec<f64> = t.iter().map(|&t| f(t)).collect();

    // Exact with K = 3.
    let fit = fit_harmonics(&t, &x, omega, 3).unwrap();
    let tol = 1e-12 * b1;
    assert!((fit.a0 - a0).abs() < 1e-12 * a0.abs());
    for (got, want) in [
        (fit.a[0], a1),
        (fit.b[0], b1),
        (fit.a[1], a2),
        (fit.b[1], b2),
        (fit.a[2], a3),
        (fit.b[2], 0.0),
    ] {
        assert!((got - want).abs() < tol, "{got:e} vs {want:e}");
    }
    // The residual cannot fall below the rounding of x itself (|x| ≈ 2.08e-3).
    assert!(
        fit.residual_rms < 64.0 * f64::EPSILON * a0.abs(),
        "{:e}",
        fit.residual_rms
    );
    // Uniform grid over whole periods: an orthogonal basis, condition number √2.
    assert!((fit.condition - 2f64.sqrt()).abs() < 1e-9);

    // Two independent methods agree: least squares and the FFT.
    let sp = AmplitudeSpectrum::new(&t, &x, omega).unwrap();
    for k in 1..=3 {
        let h = sp.harmonic(k).unwrap();
        assert!((h.cos - fit.a[k - 1]).abs() < tol, "a{k}");
        assert!((h.sin - fit.b[k - 1]).abs() < tol, "b{k}");
        assert!((h.amplitude - fit.amplitude(k).unwrap()).abs() < tol);
    }
    assert!((sp.mean() - fit.a0).abs() < 1e-12 * a0.abs());
    // The paper: "only two dominant frequencies, ω and 2ω".
    assert_eq!(sp.dominant_harmonic_count(DOMINANCE_THRESHOLD).unwrap(), 2);

    // With K = 2, the third harmonic is the residual: rms = a3/√2 (orthogonality).
    let fit2 = fit_harmonics(&t, &x, omega, 2).unwrap();
    assert!(rel(fit2.residual_rms, a3 / 2f64.sqrt()) < 1e-6);
    assert!((fit2.b[0] - b1).abs() < tol);
    let expect = f(0.3) - a3 * (3.0 * omega * 0.3).cos();
    assert!((fit2.evaluate(0.3) - expect).abs() < 64.0 * f64::EPSILON * a0.abs());
}

#[test]
fn fit_on_a_partial_period_nonuniform_grid() {
    // AmplitudeSpectrum cannot do this one; the fit can.
    let omega = 17.5;
    let t: Vec<f64> = (0..150).map(|i| 0.001 * (i as f64).powf(1.3)).collect();
    let sig = Signal {
        omega,
        ..paper_like()
    };
    let x = sig.sample(&t);
    let fit: HarmonicFit<f64> = fit_harmonics(&t, &x, omega, 5).unwrap();
    for j in 1..=5 {
        let (c, s) = sig.cos_sin(j);
        // Conditioning of a partial-period basis costs digits: measured condition ~1e2.
        let tol = 1e-12 * 2.08e-3 * fit.condition;
        assert!(
            (fit.a[j - 1] - c).abs() < tol,
            "a{j}: {:e} vs {c:e}",
            fit.a[j - 1]
        );
        assert!((fit.b[j - 1] - s).abs() < tol, "b{j}");
    }
    assert!(AmplitudeSpectrum::new(&t, &x, omega).is_err());
}

// ---------------------------------------------------------------------------------------
// the paper's approximations

#[test]
fn golden_static_equilibrium() {
    // Paper: X0 = −2.0807e-3 m.  python: −2.0806686874764524e-3.
    let x0 = PAPER.static_equilibrium().unwrap();
    assert!(rounds_to(x0, -2.0807e-3, 5), "{x0:e}");
    assert!(rel(x0, -2.0806686874764524e-3) < 1e-12);
    // The solver behind `at_equilibrium` finds the same point.
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let lin = LinearizedResponse::at_equilibrium(&osc, PAPER.x_i, 0.0, PAPER.c).unwrap();
    assert!(rel(lin.equilibrium(), x0) < 1e-14);
}

#[test]
fn static_stiffness_comes_from_the_laws() {
    // k_eff = k + n1·k_I·(X0 − x_I)^{n1−1}, written out by hand (the paper's Δ + mω²).
    let x0 = PAPER.static_equilibrium().unwrap();
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c).unwrap();
    let k_eff = PAPER.k + 1.5 * PAPER.k_i * (x0 - PAPER.x_i).sqrt();
    assert!(rel(lin.stiffness(), k_eff) < 1e-12);
    assert!(rel(lin.stiffness(), 832_056.980_478_533_2) < 1e-9); // python
    assert!(rel(lin.detuning(14.0), k_eff - PAPER.m * 196.0) < 1e-12);
}

#[test]
fn golden_linearized_solution_eq4() {
    // Paper, eq. (4), ω = 14:  x = −2.0807e-3 − 4.7779e-10 cos ωt + 4.2606e-6 sin ωt.
    // Ours:                    A2 = −4.77790729e-10,         A1 = 4.26063900e-6.
    // python:                  A2 = −4.777907293581986e-10,  A1 = 4.260639004657809e-6.
    // (The cos coefficient is tiny because Δ ≈ 8.3e5 N/m ≫ ωc ≈ 93 N/m: A2/A1 = −ωc/Δ.)
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c).unwrap();
    let (a1, a2) = lin.coefficients(14.0);
    assert!(rounds_to(a1, 4.2606e-6, 5), "{a1:e}");
    assert!(rounds_to(a2, -4.7779e-10, 5), "{a2:e}");
    assert!(rel(a1, 4.260639004657809e-6) < 1e-9);
    assert!(rel(a2, -4.777907293581986e-10) < 1e-9);
    assert!(rel(a2 / a1, -14.0 * PAPER.c / lin.detuning(14.0)) < 1e-12);
    assert!(rel(lin.amplitude(14.0), a1.hypot(a2)) < 1e-14);
    let t = 0.0371;
    let x = lin.displacement(14.0, t);
    assert!((x - (x0 + a1 * (14.0 * t).sin() + a2 * (14.0 * t).cos())).abs() < 1e-18);
}

#[test]
fn golden_linearized_grazing() {
    // Paper: x_I = X0 − m0e ω²/√((ωc)² + Δ²)  ⇒  ω = 15.657.
    // Ours: 15.6565289.  python: 15.65652893994676.
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let lin = LinearizedResponse::new(&osc, PAPER.static_equilibrium().unwrap(), PAPER.c).unwrap();
    let w = lin.grazing_omega(PAPER.x_i, 10.0, 30.0).unwrap();
    assert!(rounds_to(w, 15.657, 5), "{w}");
    assert!(rel(w, 15.65652893994676) < 1e-10);
    assert!(rel(lin.amplitude(w), lin.equilibrium() - PAPER.x_i) < 1e-12);
}

#[test]
fn golden_amplitude_phase_eq6() {
    // Paper, eq. (6), ω = 14: x = −2.0807e-3 − 3.5707e-10 cos ωt + 3.6833e-6 sin ωt.
    // Ours (upper turning point, A > 0, α ≈ 9.69e-5): −3.57069158e-10 and 3.68325723e-6.
    // python: A = 3.683257e-6, cos coefficient −3.57069e-10.
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c).unwrap();
    let s = ap.solve(14.0, TurningPoint::Upper).unwrap();
    assert!(rounds_to(s.sin_coefficient(), 3.6833e-6, 5));
    assert!(rounds_to(s.cos_coefficient(), -3.5707e-10, 5));
    assert!(rel(s.amplitude, 3.683257e-6) < 1e-6);
    // The solution satisfies the paper's two equations as printed.
    let (a, alpha) = s.signed_amplitude_lag();
    let f0 = PAPER.m0e * 196.0;
    let lhs1 =
        -PAPER.m * a * 196.0 + PAPER.k * (a + x0) + PAPER.k_i * (a + x0 - PAPER.x_i).powf(PAPER.n1);
    assert!((lhs1 - f0 * alpha.cos()).abs() < 1e-12 * f0);
    assert!((PAPER.c * a * 14.0 - f0 * alpha.sin()).abs() < 1e-12 * f0);
    assert!((s.turning_position() - (x0 + a)).abs() < 1e-20);
    let t = 0.2;
    assert!(
        (s.displacement(t)
            - (x0
                + s.cos_coefficient() * (14.0 * t).cos()
                + s.sin_coefficient() * (14.0 * t).sin()))
        .abs()
            < 1e-18
    );
    // "The last method gives better results than the method of simple linearization": its
    // amplitude is smaller (the hardening contact), closer to the simulated b1 = 3.93e-6.
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c).unwrap();
    assert!(s.amplitude < lin.amplitude(14.0));
}

#[test]
fn golden_amplitude_phase_grazing() {
    // Paper: x_I = X0 + A(ω)  ⇒  ω = 12.789.
    // Reproduced by the LOWER turning point: the paper's equations with A = x_I − X0 < 0
    // and cos α < 0. Ours: 12.7889511.  python: 12.788951113128032.
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c).unwrap();
    let w = ap
        .grazing_omega(PAPER.x_i, TurningPoint::Lower, 10.0, 14.0)
        .unwrap();
    assert!(rounds_to(w, 12.789, 5), "{w}");
    assert!(rel(w, 12.788951113128032) < 1e-10);

    // In the paper's (A, α) form at the grazing point: A = x_I − X0, cos α < 0, and the
    // first equation holds with the contact force zero (R(x_I) = k·x_I).
    let a = PAPER.x_i - x0;
    let f0 = PAPER.m0e * w * w;
    let sin_a = PAPER.c * a * w / f0;
    let cos_a = -(1.0 - sin_a * sin_a).sqrt();
    let lhs = -PAPER.m * a * w * w + PAPER.k * PAPER.x_i;
    assert!((lhs - f0 * cos_a).abs() < 1e-9 * f0);

    // The grazing is a fold at the contact boundary: just below it the lower branch's
    // amplitude tends to X0 − x_I; just above, the small root is gone.
    let below = ap.solve(w * (1.0 - 1e-9), TurningPoint::Lower).unwrap();
    assert!(
        rel(below.amplitude, x0 - PAPER.x_i) < 1e-3,
        "{:e}",
        below.amplitude
    );
    let (pa, palpha) = below.signed_amplitude_lag();
    assert!(pa < 0.0 && palpha.cos() < 0.0);
    let above = ap.solve(w * (1.0 + 1e-6), TurningPoint::Lower).unwrap();
    assert!(above.amplitude > 1e-3, "{:e}", above.amplitude);
}

#[test]
fn other_conventions_give_other_numbers() {
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c).unwrap();
    // 1. The upper amplitude mirrored to the lower side, x_I = X0 − a_upper(ω):
    //    ω = 17.2831205 (python: 17.283120526848556). Not the paper's 12.789.
    let gap = x0 - PAPER.x_i;
    let f = |w: f64| ap.solve(w, TurningPoint::Upper).unwrap().amplitude - gap;
    let w = brent(f, 10.0, 30.0, f(10.0), f(30.0), 1e-13, 200).unwrap();
    assert!(rel(w, 17.283120526848556) < 1e-9, "{w}");
    // 2. The upper balance cannot put its turning point at a stop below X0.
    assert!(matches!(
        ap.grazing_omega(PAPER.x_i, TurningPoint::Upper, 10.0, 14.0),
        Err(AnalysisError::WrongSide { .. })
    ));
    // 3. The lower balance at ω = 14 only has the far, out-of-contact root (the free spring
    //    k is past its resonance √(k/m) = 12.745): a = 2.0276e-2 m, ψ = 2.5787
    //    (python: A = −2.027613e-2, α = −0.562935 = ψ − π).
    let low = ap.solve(14.0, TurningPoint::Lower).unwrap();
    assert!(rel(low.amplitude, 2.027613e-2) < 1e-6);
    assert!((low.lag - (-0.562935 + std::f64::consts::PI)).abs() < 1e-6);
    // Below the grazing it is a small in-contact root (python at ω = 12: A = −4.035636e-6).
    let low12 = ap.solve(12.0, TurningPoint::Lower).unwrap();
    assert!(rel(low12.amplitude, 4.035636e-6) < 1e-6);
    // 4. The restoring force linearized about X0 turns the method back into eq. (4).
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c).unwrap();
    let spring = LinearSpring::new(lin.stiffness())
        .unwrap()
        .with_rest_position(x0)
        .unwrap();
    let linear = Oscillator::new(PAPER.m, spring, *osc.excitation()).unwrap();
    let ap_lin = AmplitudePhase::new(&linear, x0, PAPER.c).unwrap();
    let s = ap_lin.solve(14.0, TurningPoint::Upper).unwrap();
    let (a1, a2) = lin.coefficients(14.0);
    assert!(rel(s.sin_coefficient(), a1) < 1e-10);
    assert!(rel(s.cos_coefficient(), a2) < 1e-9);
    let w = ap_lin
        .grazing_omega(PAPER.x_i, TurningPoint::Lower, 10.0, 30.0)
        .unwrap();
    assert!(rel(w, 15.65652893994676) < 1e-10);
}

#[test]
fn approximations_in_f32() {
    let osc = PAPER.oscillator::<f32>(14.0).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap() as f32;
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c as f32).unwrap();
    let (a1, _) = lin.coefficients(14.0);
    assert!((a1 as f64 - 4.260639e-6).abs() < 1e-3 * 4.26e-6, "{a1:e}");
    let w = lin.grazing_omega(PAPER.x_i as f32, 10.0, 30.0).unwrap();
    assert!((w as f64 - 15.6565).abs() < 1e-2, "{w}");
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c as f32).unwrap();
    let s = ap.solve(14.0, TurningPoint::Upper).unwrap();
    assert!(
        (s.amplitude as f64 - 3.683257e-6).abs() < 1e-2 * 3.68e-6,
        "{:e}",
        s.amplitude
    );
}

#[test]
fn forcing_laws() {
    let rotor = *PAPER.oscillator::<f64>(3.0).unwrap().excitation();
    // The rotor's law ignores the speed it was built with.
    assert!(rel(rotor.amplitude_at(14.0), PAPER.m0e * 196.0) < 1e-15);
    assert_eq!(AmplitudeLaw::Constant(2.0).amplitude_at(14.0), 2.0);
    // A custom law through from_parts: the static limit of a constant force is F0/k.
    let lin =
        LinearizedResponse::from_parts(1.0, 4.0, 0.1, 0.5, AmplitudeLaw::Constant(2.0)).unwrap();
    assert!(rel(lin.amplitude(1e-8), 0.5) < 1e-12);
    assert_eq!(lin.forcing(), &AmplitudeLaw::Constant(2.0));
}

// ---------------------------------------------------------------------------------------
// bad inputs

#[test]
fn spectrum_rejects_bad_input() {
    let omega = 14.0;
    let t = grid(64, 2, omega, 0.0);
    let x: Vec<f64> = t.iter().map(|&t| (omega * t).sin()).collect();
    assert!(matches!(
        AmplitudeSpectrum::new(&t, &x[..63], omega),
        Err(AnalysisError::LengthMismatch { t: 64, x: 63 })
    ));
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            AmplitudeSpectrum::new(&t, &x, bad),
            Err(AnalysisError::InvalidFrequency { .. })
        ));
    }
    let mut xn = x.clone();
    xn[7] = f64::NAN;
    assert_eq!(
        AmplitudeSpectrum::new(&t, &xn, omega),
        Err(AnalysisError::NonFinite {
            what: "value",
            index: 7
        })
    );
    let mut tn = t.clone();
    tn[3] = f64::INFINITY;
    assert!(matches!(
        AmplitudeSpectrum::new(&tn, &x, omega),
        Err(AnalysisError::NonFinite {
            what: "time",
            index: 3
        })
    ));
    let mut tj = t.clone();
    tj[10] += 1e-3 * (t[1] - t[0]);
    assert!(matches!(
        AmplitudeSpectrum::new(&tj, &x, omega),
        Err(AnalysisError::NonUniformSampling { index: 10, .. })
    ));
    let mut tr = t.clone();
    tr.reverse();
    assert!(matches!(
        AmplitudeSpectrum::new(&tr, &x, omega),
        Err(AnalysisError::NonUniformSampling { .. })
    ));
    // 2.5 periods.
    let t25 = grid(64, 5, 2.0 * omega, 0.0);
    match AmplitudeSpectrum::new(&t25, &x, omega) {
        Err(AnalysisError::NotWholePeriods { periods, hint, .. }) => {
            assert!((periods - 2.5).abs() < 1e-12);
            assert!(hint.is_empty());
        }
        other => panic!("{other:?}"),
    }
    // The classic mistake: the end point t0 + P·T included. The hint says so.
    let dt = 2.0 * TAU / omega / 64.0;
    let t_end: Vec<f64> = (0..=64).map(|i| i as f64 * dt).collect();
    let x_end: Vec<f64> = t_end.iter().map(|&t| (omega * t).sin()).collect();
    match AmplitudeSpectrum::new(&t_end, &x_end, omega) {
        Err(AnalysisError::NotWholePeriods { hint, .. }) => assert!(hint.contains("drop")),
        other => panic!("{other:?}"),
    }
    // Less than one period.
    let t_short = grid(64, 1, 2.0 * omega, 0.0);
    assert!(matches!(
        AmplitudeSpectrum::new(&t_short, &x, omega),
        Err(AnalysisError::NotWholePeriods { .. })
    ));
    // 4 periods in 8 samples: the first harmonic is at the Nyquist bin.
    let t8 = grid(8, 4, omega, 0.0);
    assert_eq!(
        AmplitudeSpectrum::new(&t8, &[0.0; 8], omega),
        Err(AnalysisError::TooFewSamples {
            samples: 8,
            required: 9
        })
    );
    assert!(matches!(
        AmplitudeSpectrum::new(&t[..2], &x[..2], omega),
        Err(AnalysisError::TooFewSamples { .. })
    ));
    let sp = AmplitudeSpectrum::new(&t, &x, omega).unwrap();
    assert_eq!(sp.max_harmonic(), 15);
    assert_eq!(
        sp.harmonic(16),
        Err(AnalysisError::HarmonicOutOfRange {
            harmonic: 16,
            max_harmonic: 15
        })
    );
    assert!(sp.harmonic_amplitude(16).is_err());
}

#[test]
fn fit_rejects_bad_input() {
    let t: Vec<f64> = (0..10).map(|i| 0.01 * i as f64).collect();
    let x = vec![1.0; 10];
    assert_eq!(
        fit_harmonics(&t, &x[..9], 14.0, 1),
        Err(AnalysisError::LengthMismatch { t: 10, x: 9 })
    );
    assert_eq!(
        fit_harmonics(&t, &x, 14.0, 5),
        Err(AnalysisError::TooFewSamples {
            samples: 10,
            required: 11
        })
    );
    assert!(fit_harmonics(&t, &x, 14.0, 4).is_ok());
    for bad in [0.0, -14.0, f64::NAN] {
        assert!(matches!(
            fit_harmonics(&t, &x, bad, 1),
            Err(AnalysisError::InvalidFrequency { .. })
        ));
    }
    let mut xn = x.clone();
    xn[4] = f64::NEG_INFINITY;
    assert_eq!(
        fit_harmonics(&t, &xn, 14.0, 1),
        Err(AnalysisError::NonFinite {
            what: "value",
            index: 4
        })
    );
    // Repeated time stamps: rank deficient.
    let t_rep = vec![0.5; 10];
    assert!(matches!(
        fit_harmonics(&t_rep, &x, 14.0, 1),
        Err(AnalysisError::IllConditioned { .. })
    ));
}

#[test]
fn approximations_reject_bad_input() {
    let osc = PAPER.oscillator::<f64>(14.0).unwrap();
    let x0 = PAPER.static_equilibrium().unwrap();
    // No equilibrium in a bracket above the spring's rest position.
    assert_eq!(
        LinearizedResponse::at_equilibrium(&osc, 1e-3, 2e-3, PAPER.c),
        Err(AnalysisError::NoEquilibrium { lo: 1e-3, hi: 2e-3 })
    );
    assert!(matches!(
        AmplitudePhase::at_equilibrium(&osc, 1e-3, 2e-3, PAPER.c),
        Err(AnalysisError::NoEquilibrium { .. })
    ));
    assert!(matches!(
        LinearizedResponse::new(&osc, x0, -1.0),
        Err(AnalysisError::Parameter(_))
    ));
    assert!(matches!(
        AmplitudePhase::new(&osc, f64::NAN, PAPER.c),
        Err(AnalysisError::Parameter(_))
    ));
    let lin = LinearizedResponse::new(&osc, x0, PAPER.c).unwrap();
    // The linearized grazing is at 15.657: none in [20, 30].
    match lin.grazing_omega(PAPER.x_i, 20.0, 30.0) {
        Err(AnalysisError::NoGrazingBracket { gap_lo, gap_hi, .. }) => {
            assert!(gap_lo < 0.0 && gap_hi < 0.0)
        }
        other => panic!("{other:?}"),
    }
    for (lo, hi) in [(30.0, 20.0), (0.0, 20.0), (-1.0, 5.0), (1.0, f64::NAN)] {
        assert!(matches!(
            lin.grazing_omega(PAPER.x_i, lo, hi),
            Err(AnalysisError::InvalidBracket { .. })
        ));
    }
    let ap = AmplitudePhase::new(&osc, x0, PAPER.c).unwrap();
    assert!(matches!(
        ap.grazing_omega(PAPER.x_i, TurningPoint::Lower, 14.0, 20.0),
        Err(AnalysisError::NoGrazingBracket { .. })
    ));
    assert!(matches!(
        ap.solve(0.0, TurningPoint::Upper),
        Err(AnalysisError::InvalidFrequency { .. })
    ));
    // An undamped linear oscillator exactly at resonance has no finite amplitude.
    let res = Oscillator::new(1.0, LinearSpring::new(4.0).unwrap(), *osc.excitation()).unwrap();
    let ap_res = AmplitudePhase::new(&res, 0.0, 0.0).unwrap();
    assert_eq!(
        ap_res.solve(2.0, TurningPoint::Upper),
        Err(AnalysisError::NoSolution {
            omega: 2.0,
            branch: "upper"
        })
    );
    assert!(ap_res.solve(1.0, TurningPoint::Upper).is_ok());
}

#[test]
fn public_types_are_send_sync_clone() {
    fn check<T: Send + Sync + Clone>() {}
    check::<AmplitudeSpectrum>();
    check::<SpectrumAnalyzer>();
    check::<HarmonicFit<f64>>();
    check::<LinearizedResponse<f64>>();
    check::<
        AmplitudePhase<
            f64,
            nonsmooth::systems::paper::PaperLaws<f64>,
            nonsmooth::excite::UnbalancedRotor<f64>,
        >,
    >();
    check::<AnalysisError>();
    fn law<L: ForceLaw<f64>>(_: &L) {}
    law(PAPER.oscillator::<f64>(1.0).unwrap().laws());
}
