//! Continuation of periodic orbits: the hardening Duffing oscillator's frequency response
//! through its two folds, against harmonic balance and against brute-force sweeps.

use nalgebra::SVector;
use nonsmooth::drive::Simulation;
use nonsmooth::excite::Harmonic;
use nonsmooth::force::{CubicSpring, ViscousDamper};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::tangent_tolerances;
use nonsmooth::model::{Element, Load, Mechanical};
use nonsmooth::orbit::{BifurcationKind, BranchEnd, ContinuationSettings, Shooting, follow};
use nonsmooth::sample::Stroboscopic;

const C: f64 = 0.1;
const F: f64 = 0.5;

type Duffing = Mechanical<
    f64,
    1,
    Element<f64, 1, (CubicSpring<f64>, ViscousDamper<f64>)>,
    Load<f64, 1, Harmonic<f64>>,
>;

fn duffing(omega: f64) -> nonsmooth::Result<Duffing> {
    Ok(Mechanical::with_masses([1.0])?
        .with_elements(Element::on_dof(
            0,
            (CubicSpring::new(1.0, 1.0)?, ViscousDamper::new(C)?),
        )?)
        .with_loads(Load::on_dof(0, Harmonic::cosine(F, omega)?)?))
}

fn tol() -> Tolerances<f64, 2> {
    Tolerances::new(1e-10, 1e-12).unwrap()
}

/// Folds of the one-harmonic balance: `ω` where the cubic in `u = A²`,
/// `(9/16)u³ + (3/2)a u² + (a² + c²ω²)u − F² = 0` (`a = 1 − ω²`), gains or loses two real
/// roots (its discriminant changes sign).
fn harmonic_balance_folds() -> Vec<f64> {
    let disc = |w: f64| {
        let a = 1.0 - w * w;
        let (ca, cb, cc, cd) = (0.5625, 1.5 * a, a * a + (C * w).powi(2), -F * F);
        18.0 * ca * cb * cc * cd - 4.0 * cb.powi(3) * cd + cb * cb * cc * cc
            - 4.0 * ca * cc.powi(3)
            - 27.0 * ca * ca * cd * cd
    };
    let mut folds = Vec::new();
    let mut w = 1.0;
    while w < 3.0 {
        let (mut lo, mut hi) = (w, w + 1e-3);
        if disc(lo).signum() != disc(hi).signum() {
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if disc(lo).signum() == disc(mid).signum() {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            folds.push(0.5 * (lo + hi));
        }
        w += 1e-3;
    }
    folds
}

/// Stroboscopic x after each ω of a sweep (each value starts from the previous end).
fn sweep(omegas: &[f64]) -> Vec<f64> {
    let mut y = SVector::<f64, 2>::zeros();
    let mut xs = Vec::new();
    for &w in omegas {
        let period = std::f64::consts::TAU / w;
        let mut sim = Simulation::new(duffing(w).unwrap(), Dopri5::new(tol()));
        let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, period, 0.0, 1000).unwrap();
        let out = sim.run(0.0, y, 150.0 * period, &mut strobe).unwrap();
        y = out.y;
        xs.push(y[0].hypot(y[1] / w));
    }
    xs
}

#[test]
fn duffing_frequency_response_two_folds() {
    let tol = tol();
    let build = |w: f64| {
        Ok(Shooting::new(
            duffing(w)?,
            (),
            tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12)?,
        ))
    };
    let period = |w: f64| std::f64::consts::TAU / w;
    let settings = ContinuationSettings::new(1.0, 2.5, 0.02).unwrap();
    let branch = follow(
        build,
        period,
        0.0,
        1.0,
        SVector::from([0.0, 0.0]),
        &settings,
    )
    .unwrap();
    assert_eq!(branch.end, BranchEnd::ParameterRange);
    let folds: Vec<f64> = branch
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::Fold)
        .map(|b| b.p)
        .collect();
    let hb = harmonic_balance_folds();
    println!(
        "{} points; folds {folds:?}; harmonic balance {hb:?}; other: {:?}",
        branch.points.len(),
        branch
            .bifurcations
            .iter()
            .filter(|b| b.kind != BifurcationKind::Fold)
            .map(|b| (b.kind, b.p))
            .collect::<Vec<_>>()
    );
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert_eq!(hb.len(), 2, "{hb:?}");
    // Along the branch: upper fold first (the large-amplitude branch ends), then the lower.
    let (upper, lower) = (folds[0], folds[1]);
    assert!(upper > lower);
    for (got, want) in [(lower, hb[0]), (upper, hb[1])] {
        assert!(
            (got - want).abs() < 0.02 * want,
            "fold {got} vs harmonic balance {want}"
        );
    }
    // Between the folds (in arclength) the orbit is a saddle; before the first and after
    // the second it is stable (away from the folds themselves).
    let fold_s: Vec<f64> = branch
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::Fold)
        .map(|b| b.arclength)
        .collect();
    let near_fold = |p: f64| (p - upper).abs() < 1e-4 || (p - lower).abs() < 1e-4;
    let mut middle = 0;
    for q in branch.points.iter().filter(|q| !near_fold(q.p)) {
        if q.arclength > fold_s[0] && q.arclength < fold_s[1] {
            assert!(!q.stable, "middle segment at {} should be a saddle", q.p);
            assert!(q.multipliers[0].re > 1.0 && q.multipliers[0].im == 0.0);
            middle += 1;
        } else {
            assert!(q.stable, "outer segment at {} should be stable", q.p);
        }
    }
    assert!(middle >= 3, "{middle} points on the middle segment");
    // Brute-force sweeps up and down jump where the folds are: the amplitude drops on the
    // way up right after the upper fold, and rises on the way down right after the lower.
    let step = 0.01;
    let up: Vec<f64> = (0..=150).map(|i| 1.0 + step * i as f64).collect();
    let a_up = sweep(&up);
    let jump_up = (1..up.len())
        .max_by(|&i, &j| {
            (a_up[i - 1] - a_up[i])
                .partial_cmp(&(a_up[j - 1] - a_up[j]))
                .unwrap()
        })
        .unwrap();
    let down: Vec<f64> = up.iter().rev().copied().collect();
    let a_down = sweep(&down);
    let jump_down = (1..down.len())
        .max_by(|&i, &j| {
            (a_down[i] - a_down[i - 1])
                .partial_cmp(&(a_down[j] - a_down[j - 1]))
                .unwrap()
        })
        .unwrap();
    println!(
        "sweep up jumps between {} and {}; down between {} and {}",
        up[jump_up - 1],
        up[jump_up],
        down[jump_down - 1],
        down[jump_down]
    );
    assert!(up[jump_up - 1] <= upper && upper <= up[jump_up] + 1e-9);
    assert!(down[jump_down] - 1e-9 <= lower && lower <= down[jump_down - 1]);
}

#[test]
fn paper_period_one_orbit_first_grazing() {
    use nonsmooth::analysis::first_grazing;

    use nonsmooth::systems::paper::PAPER;
    let tol = Tolerances::per_component(1e-10, [1e-14, 1e-12]).unwrap();
    let build = |w: f64| {
        Ok(Shooting::new(
            PAPER.oscillator::<f64>(w)?,
            (),
            tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12)?,
        ))
    };
    let period = |w: f64| std::f64::consts::TAU / w;
    let settings = ContinuationSettings::new(10.0, 14.3, 0.005)
        .unwrap()
        .with_max_step(0.2)
        .unwrap()
        .with_grazing(PAPER.grazing());
    let rest = SVector::from([PAPER.static_equilibrium().unwrap(), 0.0]);
    let branch = follow(build, period, 0.0, 10.0, rest, &settings).unwrap();
    let grazing: Vec<f64> = branch
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::Grazing)
        .map(|b| b.p)
        .collect();
    // The simulation-based estimate (steady response sampled 2000 times per period).
    let x0 = PAPER.static_equilibrium().unwrap();
    let by_simulation = first_grazing(
        |w: f64| {
            Ok((
                PAPER.oscillator::<f64>(w)?,
                period(w),
                SVector::from([x0, 0.0]),
            ))
        },
        || Dopri5::new(tol),
        0,
        PAPER.x_i,
        14.0,
        14.1,
        1e-9,
        100,
        2,
    )
    .unwrap();
    println!(
        "{} points, all stable: {}; grazing by continuation {grazing:?}, by simulation {by_simulation}; other {:?}",
        branch.points.len(),
        branch.points.iter().all(|q| q.stable),
        branch
            .bifurcations
            .iter()
            .filter(|b| b.kind != BifurcationKind::Grazing)
            .map(|b| (b.kind, b.p))
            .collect::<Vec<_>>()
    );
    assert_eq!(grazing.len(), 1);
    assert!((grazing[0] - 14.045).abs() < 1e-3);
    assert!(
        (grazing[0] - by_simulation).abs() < 1e-5,
        "{} vs {by_simulation}",
        grazing[0]
    );
}

type DoubleWell = Mechanical<
    f64,
    1,
    Element<f64, 1, (CubicSpring<f64>, ViscousDamper<f64>)>,
    Load<f64, 1, Harmonic<f64>>,
>;

/// The double-well Duffing oscillator `ẍ + 0.3ẋ − x + x³ = γ cos 1.2t`.
fn double_well(gamma: f64) -> nonsmooth::Result<DoubleWell> {
    Ok(Mechanical::with_masses([1.0])?
        .with_elements(Element::on_dof(
            0,
            (CubicSpring::new(-1.0, 1.0)?, ViscousDamper::new(0.3)?),
        )?)
        .with_loads(Load::on_dof(0, Harmonic::cosine(gamma, 1.2)?)?))
}

#[test]
fn double_well_duffing_period_doubling_cascade() {
    use nonsmooth::orbit::period_doubled;
    let tol = tol();
    let build = |g: f64| {
        Ok(Shooting::new(
            double_well(g)?,
            (),
            tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12)?,
        ))
    };
    let t = std::f64::consts::TAU / 1.2;
    // Follow period 1 from γ = 0.2 (right well), switch to the doubled branch at each
    // period doubling, follow it to its own doubling: periods 1, 2, 4, 8.
    let mut k = 1.0;
    let (mut p, mut y) = (0.2, SVector::from([1.0, 0.0]));
    let mut hi = 0.4;
    let mut doublings = Vec::new();
    for _ in 0..4 {
        let period = move |_g: f64| k * t;
        let settings = ContinuationSettings::new(0.1, hi, 0.01)
            .unwrap()
            .with_max_points(400)
            .unwrap();
        let branch = follow(build, period, 0.0, p, y, &settings).unwrap();
        let pd = branch
            .bifurcations
            .iter()
            .find(|b| b.kind == BifurcationKind::PeriodDoubling)
            .expect("a period doubling on each branch of the cascade")
            .clone();
        // The critical multiplier is −1 there.
        assert!(
            pd.multipliers
                .iter()
                .any(|m| (m.re + 1.0).abs() < 1e-5 && m.im == 0.0),
            "{:?}",
            pd.multipliers
        );
        doublings.push(pd.p);
        let (p2, orbit) = period_doubled(build, period, 0.0, &pd, 1e-5, 1.0).unwrap();
        if let [.., a, b] = doublings[..] {
            hi = b + 0.5 * (b - a); // the next doubling comes well before this
        }
        p = p2;
        y = orbit.state;
        k *= 2.0;
    }
    let d1 = (doublings[1] - doublings[0]) / (doublings[2] - doublings[1]);
    let d2 = (doublings[2] - doublings[1]) / (doublings[3] - doublings[2]);
    println!("period doublings at γ = {doublings:?}; ratios {d1:.4}, {d2:.4} (Feigenbaum 4.6692)");
    // Measured: γ = 0.2655818, 0.2866932, 0.2910899, 0.2920310; ratios 4.802, 4.672.
    assert!((d1 - 4.6692).abs() < 0.2, "{d1}");
    assert!((d2 - 4.6692).abs() < 0.05, "{d2}");
    // Independent check by simulation: period 1 just below the first doubling, period 2 just
    // above (stroboscopic points after a transient).
    for (gamma, want) in [(doublings[0] - 2e-3, 1), (doublings[0] + 2e-3, 2)] {
        let mut sim = Simulation::new(double_well(gamma).unwrap(), Dopri5::new(tol));
        let mut strobe = Stroboscopic::<f64, 2>::periodic(0.0, t, 3000.0 * t, 100).unwrap();
        sim.run(0.0, SVector::from([1.0, 0.0]), 3010.0 * t, &mut strobe)
            .unwrap();
        let pts = strobe.points();
        let distinct = if (pts[0].y - pts[1].y).amax() < 1e-6 {
            1
        } else {
            2
        };
        assert_eq!(distinct, want, "γ = {gamma}");
        assert!(
            (pts[0].y - pts[2].y).amax() < 1e-6,
            "period ≤ 2 at γ = {gamma}"
        );
    }
}

#[test]
fn contact_changes_of_a_two_harmonic_response_match_the_closed_form() {
    // ẍ + 2ζẋ + x = cos ωt + a·cos 3ωt has the steady state
    // x(t) = R₁cos(ωt − δ₁) + a·R₃cos(3ωt − δ₃), R_k = 1/|1 − (kω)² + 2iζkω|. As `a` grows
    // the third harmonic bends new extrema into x(t) (born in pairs near a ≈ 0.29, the new
    // minimum above the level L = 0.3: not a contact yet); the number of contacts per period
    // (downward crossings of L) changes where that minimum reaches L. Located by
    // continuation in `a` and, independently, from the closed form. Measured: 1.28615171211
    // both ways (6e-13 apart); the birth of extrema below the level is not reported.
    use nonsmooth::force::LinearSpring;
    use nonsmooth::orbit::{Extremum, Grazing};
    let (zeta, omega, level) = (0.05_f64, 0.5_f64, 0.3_f64);
    let harmonic = |k: f64| {
        let re = 1.0 - (k * omega).powi(2);
        let im = 2.0 * zeta * k * omega;
        (1.0 / re.hypot(im), im.atan2(re))
    };
    let ((r1, d1), (r3, d3)) = (harmonic(1.0), harmonic(3.0));
    let x = |t: f64, a: f64| r1 * (omega * t - d1).cos() + a * r3 * (3.0 * omega * t - d3).cos();
    let dx = |t: f64, a: f64| {
        -r1 * omega * (omega * t - d1).sin() - 3.0 * a * r3 * omega * (3.0 * omega * t - d3).sin()
    };
    let ddx = |t: f64, a: f64| {
        -r1 * omega * omega * (omega * t - d1).cos()
            - 9.0 * a * r3 * omega * omega * (3.0 * omega * t - d3).cos()
    };
    let period = std::f64::consts::TAU / omega;
    // Contacts per period = downward crossings of the level (dense scan of the closed
    // form); where their number changes, the minimum that crossed is located exactly:
    // Newton on x'(t) = 0 from its time, bisection in a on x(t*, a) = L.
    let contacts = |a: f64| {
        let n = 20_000;
        (0..n)
            .filter(|&i| {
                let (t0, t1) = (
                    period * i as f64 / n as f64,
                    period * (i + 1) as f64 / n as f64,
                );
                x(t0, a) >= level && x(t1, a) < level
            })
            .count()
    };
    let min_near = |t: f64, a: f64| {
        let mut t = t;
        for _ in 0..40 {
            t -= dx(t, a) / ddx(t, a);
        }
        (t, x(t, a))
    };
    let mut exact = Vec::new();
    let grid: Vec<f64> = (0..=145).map(|i| 0.05 + 0.01 * i as f64).collect();
    for w in grid.windows(2) {
        if contacts(w[0]) == contacts(w[1]) {
            continue;
        }
        // The minimum nearest the level at the end with more contacts.
        let a_ref = if contacts(w[1]) > contacts(w[0]) {
            w[1]
        } else {
            w[0]
        };
        let n = 4000;
        let t_ref = (0..n)
            .map(|i| period * (i as f64 + 0.5) / n as f64)
            .filter(|&t| dx(t - 1e-9, a_ref) < 0.0 && dx(t + period / n as f64, a_ref) >= 0.0)
            .map(|t| min_near(t, a_ref))
            .min_by(|p, q| (p.1 - level).abs().total_cmp(&(q.1 - level).abs()))
            .expect("a minimum")
            .0;
        let f = |a: f64| min_near(t_ref, a).1 - level;
        let (mut lo, mut hi) = (w[0], w[1]);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if f(mid).signum() == f(lo).signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        exact.push(0.5 * (lo + hi));
    }
    let tol = Tolerances::new(1e-11, 1e-13).unwrap();
    let build = |a: f64| {
        let model = Mechanical::with_masses([1.0])?
            .with_elements(Element::on_dof(
                0,
                (LinearSpring::new(1.0)?, ViscousDamper::new(2.0 * zeta)?),
            )?)
            .with_loads((
                Load::on_dof(0, Harmonic::cosine(1.0, omega)?)?,
                Load::on_dof(0, Harmonic::cosine(a, 3.0 * omega)?)?,
            ));
        Ok(Shooting::new(
            model,
            (),
            tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-11, 1e-13)?,
        ))
    };
    let settings = ContinuationSettings::new(0.05, 1.5, 0.02)
        .unwrap()
        .with_contact_changes(Grazing {
            component: 0,
            level,
            extremum: Extremum::Min,
        });
    let branch = follow(
        build,
        |_| period,
        0.0,
        0.05,
        SVector::<f64, 2>::zeros(),
        &settings,
    )
    .unwrap();
    let found: Vec<f64> = branch
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::Grazing)
        .map(|b| b.p)
        .collect();
    println!("contact changes: continuation {found:?}, closed form {exact:?}");
    assert!(!exact.is_empty(), "the test needs at least one change");
    assert_eq!(found.len(), exact.len(), "{found:?} vs {exact:?}");
    for (f, e) in found.iter().zip(&exact) {
        assert!((f - e).abs() < 1e-6, "{f} vs {e}");
    }
}
