//! A Neimark–Sacker bifurcation located by continuation: the forced van der Pol oscillator
//! `ẍ − ε(1 − x²)ẋ + x = F cos ωt` (ε = 0.1, F = 0.3). Its entrained period-1 orbit loses
//! stability when a complex pair of multipliers leaves the unit circle and a torus
//! (quasi-periodic motion) is born. Checked against the averaged (one-harmonic) equations,
//! whose fixed point has a Hopf bifurcation where the amplitude reaches `r = √2`:
//! `F² = 2[(1 − ω²)² + ε²ω²/4]`, and by simulation on both sides.
//!
//! Measured: ω = 1.097546721 (averaging 1.097684), μ = 0.857369 ± 0.514702i, and
//! ω = 0.890089708 (averaging 0.890276), μ = 0.728736 ± 0.684795i; the stroboscopic
//! sections 0.005 rad/s inside spread by 1e-9 (period 1), outside by ≈ 1 (a torus). With
//! F = 0.1 the entrainment ends at folds instead (the averaged fixed point is a saddle
//! there), as averaging predicts for weak forcing.

use nalgebra::SVector;
use nonsmooth::ForceLaw;
use nonsmooth::drive::Simulation;
use nonsmooth::excite::Harmonic;
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::tangent_tolerances;
use nonsmooth::model::{Element, Load, Mechanical};
use nonsmooth::orbit::{BifurcationKind, ContinuationSettings, Shooting, follow, modulus};
use nonsmooth::sample::Stroboscopic;

const EPS: f64 = 0.1;
const F: f64 = 0.3;

/// The van der Pol restoring and self-exciting force `x − ε(1 − x²)v`.
#[derive(Debug, Clone, Copy)]
struct VanDerPol(f64);

impl ForceLaw<f64> for VanDerPol {
    fn force(&self, x: f64, v: f64) -> f64 {
        x - self.0 * (1.0 - x * x) * v
    }
    fn partials(&self, x: f64, v: f64) -> (f64, f64) {
        (1.0 + 2.0 * self.0 * x * v, -self.0 * (1.0 - x * x))
    }
}

type Forced = Mechanical<f64, 1, Element<f64, 1, VanDerPol>, Load<f64, 1, Harmonic<f64>>>;

fn van_der_pol(omega: f64) -> nonsmooth::Result<Forced> {
    Ok(Mechanical::with_masses([1.0])?
        .with_elements(Element::on_dof(0, VanDerPol(EPS))?)
        .with_loads(Load::on_dof(0, Harmonic::cosine(F, omega)?)?))
}

/// The averaged equations' Hopf points: `(1 − ω²)² = F²/2 − ε²ω²/4`, solved for ω by
/// fixed-point iteration from ω = 1 on either side.
fn averaged_hopf(side: f64) -> f64 {
    let mut w: f64 = 1.0;
    for _ in 0..100 {
        let d = (F * F / 2.0 - EPS * EPS * w * w / 4.0).sqrt();
        w = (1.0 + side * d).sqrt();
    }
    w
}

#[test]
fn forced_van_der_pol_loses_entrainment_through_a_neimark_sacker_bifurcation() {
    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let tangent = tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12).unwrap();
    let build = |w: f64| Ok(Shooting::new(van_der_pol(w)?, (), tangent));
    let period = |w: f64| std::f64::consts::TAU / w;
    // Start on the entrained orbit at ω = 1 (a forward run lands on it).
    let mut sim = Simulation::new(van_der_pol(1.0).unwrap(), Dopri5::new(tol));
    let mut none = Stroboscopic::<f64, 2>::periodic(0.0, period(1.0), 0.0, 1).unwrap();
    let y = sim
        .run(
            0.0,
            SVector::from([1.0, 0.0]),
            300.0 * period(1.0),
            &mut none,
        )
        .unwrap()
        .y;
    let start = build(1.0).unwrap().find(0.0, period(1.0), y).unwrap();
    assert!(start.is_stable(), "{:?}", start.multipliers);

    let mut found = Vec::new();
    for (up, side) in [(true, 1.0), (false, -1.0)] {
        let mut settings = ContinuationSettings::new(0.8, 1.2, 0.005).unwrap();
        if !up {
            settings = settings.downward();
        }
        let branch = follow(build, period, 0.0, 1.0, start.state, &settings).unwrap();
        let ns = branch
            .bifurcations
            .iter()
            .find(|b| b.kind == BifurcationKind::NeimarkSacker)
            .unwrap_or_else(|| panic!("no Neimark–Sacker point: {:?}", branch.bifurcations));
        // A complex pair on the unit circle there.
        let mu = &ns.multipliers;
        assert!(mu[0].im.abs() > 1e-3, "{mu:?}");
        assert!((modulus(&mu[0]) - 1.0).abs() < 1e-6, "{mu:?}");
        let estimate = averaged_hopf(side);
        println!(
            "Neimark–Sacker at ω = {:.9} (averaging {estimate:.6}), μ = {:.6} ± {:.6}i",
            ns.p,
            mu[0].re,
            mu[0].im.abs()
        );
        // Averaging is first order in ε and F: its detuning agrees to a few per cent.
        assert!(
            ((ns.p - 1.0) / (estimate - 1.0) - 1.0).abs() < 0.1,
            "{} vs {estimate}",
            ns.p
        );
        found.push((ns.p, ns.state, side));
    }
    // Simulation: entrained (period 1) inside, quasi-periodic outside.
    for (w_ns, y_ns, side) in found {
        let sections = |w: f64| {
            let mut sim = Simulation::new(van_der_pol(w).unwrap(), Dopri5::new(tol));
            let mut strobe =
                Stroboscopic::<f64, 2>::periodic(0.0, period(w), 500.0 * period(w), 1000).unwrap();
            sim.run(0.0, y_ns, 600.0 * period(w), &mut strobe).unwrap();
            let s = strobe.points();
            s.iter()
                .map(|p| (p.y - s[s.len() - 1].y).amax())
                .fold(0.0, f64::max)
        };
        let (inside, outside) = (sections(w_ns - side * 0.005), sections(w_ns + side * 0.005));
        println!("  spread of the sections: inside {inside:e}, outside {outside:e}");
        assert!(inside < 1e-6, "{inside}");
        assert!(outside > 1e-2, "{outside}");
    }
}
