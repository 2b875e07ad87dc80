//! Lyapunov exponents through resets on a harmonically forced impact oscillator with
//! Newton restitution at a rigid stop: `ẍ + cẋ + x = cos ωt`, impact at `x = d` with
//! `v⁺ = −e·v⁻`. Independent checks: (1) the QR sum equals the phase-volume rate exactly,
//! `Σλ = −c + 2 ln e · (impacts per unit time)` (the flow's divergence is `−c`, each
//! impact's saltation matrix has determinant `e²`); (2) the two estimators (trajectory pair,
//! saltation-matrix QR) agree; (3) on a period-1 orbit whose Floquet multipliers form a
//! complex pair, `λ₁ = λ₂ = Σλ/2` exactly.

use nalgebra::SVector;
use nonsmooth::event::{Direction, Event, Level, Restitution};
use nonsmooth::excite::Harmonic;
use nonsmooth::force::{LinearSpring, ViscousDamper};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{HybridTangentSpace, HybridTwoTrajectory, Norm, tangent_tolerances};
use nonsmooth::model::{Element, Load, Mechanical};

/// Measured (this test's output, 400 forcing periods after 100 of transient, DOPRI5 at
/// rtol 1e-10):
/// - d = 0.3, ω = 1.5 (period 1, one impact per period): two trajectories −0.10332 ±
///   0.00046; QR −0.10332 ± 0.00046 and −0.10322 ± 0.00046; Σλ/2 = (−c + 2 ln e·ω/2π)/2 =
///   −0.103272. QR sum −0.206543, equal to the exact rate to 1e-6.
/// - d = −0.2, ω = 1.2 (chaotic, 1.875 impacts per period): two trajectories 0.0821 ±
///   0.0091; QR 0.0829 ± 0.0075 and −0.3428 ± 0.0083; sum −0.259815 = exact.
#[test]
fn forced_impact_oscillator_exponents_through_restitution() {
    let (c, e) = (0.1_f64, 0.8_f64);
    for (d, omega, periodic) in [(0.3_f64, 1.5_f64, true), (-0.2, 1.2, false)] {
        let model = || {
            Mechanical::with_masses([1.0])
                .unwrap()
                .with_elements((
                    Element::on_dof(0, LinearSpring::new(1.0).unwrap()).unwrap(),
                    Element::on_dof(0, ViscousDamper::new(c).unwrap()).unwrap(),
                ))
                .with_loads(Load::on_dof(0, Harmonic::cosine(1.0, omega).unwrap()).unwrap())
        };
        let events = Event::new(Level::new(0, d).unwrap(), Direction::Rising)
            .with_reset(Restitution::new(1, e).unwrap());
        let period = std::f64::consts::TAU / omega;
        let tol = Tolerances::new(1e-10, 1e-12).unwrap();
        let y0 = SVector::<f64, 2>::new(d - 0.5, 0.0);
        let (intervals, transient) = (400, 100);

        let mut pair =
            HybridTwoTrajectory::new(model(), Dopri5::new(tol), events, 1e-8, Norm::Euclidean)
                .unwrap();
        pair.start(0.0, y0).unwrap();
        pair.transient(period, transient).unwrap();
        let two = pair.estimate(period, intervals).unwrap();

        let ttol = tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12).unwrap();
        let mut qr = HybridTangentSpace::<f64, 2, 2, 6, _, _, _>::new(
            model(),
            Dopri5::new(ttol),
            events,
            Norm::Euclidean,
        )
        .unwrap();
        qr.start(0.0, y0).unwrap();
        qr.transient(period, transient).unwrap();
        let spec = qr.estimate(period, intervals).unwrap();
        let span = period * intervals as f64;
        let rate = spec.stats.events as f64 / span;
        let sum = -c + 2.0 * e.ln() * rate;
        println!(
            "d = {d}, ω = {omega}: two trajectories {:.5} ± {:.5}; QR {:.5} ± {:.5}, {:.5} ± {:.5}; \
             sum {:.6} vs exact {sum:.6}; impacts per period {:.3}",
            two.exponent,
            two.spread,
            spec.exponents[0],
            spec.spread[0],
            spec.exponents[1],
            spec.spread[1],
            spec.sum(),
            rate * period
        );
        assert!(spec.stats.events > 0, "the orbit must impact");
        assert!(
            (spec.sum() - sum).abs() < 1e-6 * sum.abs(),
            "{} vs {sum}",
            spec.sum()
        );
        assert!(
            (two.exponent - spec.top()).abs() < 3.0 * (two.spread + spec.spread[0]) + 2e-3,
            "{} vs {}",
            two.exponent,
            spec.top()
        );
        if periodic {
            // One impact per period and a complex pair of multipliers: |μ|² = det of the
            // period map = e²·e^{−cT}, so λ₁ = λ₂ = Σλ/2.
            assert_eq!(spec.stats.events, intervals as u64);
            for l in [spec.exponents[0], spec.exponents[1], two.exponent] {
                assert!((l - sum / 2.0).abs() < 1e-3, "{l} vs {}", sum / 2.0);
            }
        } else {
            assert!(spec.top() > 0.03, "chaotic: {}", spec.top());
            assert!(rate * period > 1.2, "impacts per period {}", rate * period);
        }
    }
}
