//! Lyapunov exponents through resets: a ball on a vibrating table, both estimators against
//! the exact impact map's exponent.

use nalgebra::SVector;
use nonsmooth::event::{Direction, Event};
use nonsmooth::integrate::{Dopri5, Tolerances};
use nonsmooth::lyapunov::{HybridTangentSpace, HybridTwoTrajectory, Norm, tangent_tolerances};
use nonsmooth::systems::BouncingBallTable;
use nonsmooth::testing::BallOnTableExact;

/// Measured (this test's output):
/// - Γ = 1.2, e = 0.8 (period 2): exact map −0.2230; two trajectories −0.2231 ± 0.0011;
///   QR −0.2230 ± 0.0012.
/// - Γ = 1.5, e = 0.9 (chaotic, no sticking over 20 000 exact impacts): exact map 0.568 over
///   20 000 impacts; two trajectories 0.463 ± 0.060 and QR 0.588 ± 0.040 over 1500 s
///   (≈ 860 impacts) — within 2σ of their own spread.
/// - QR sum: `2 ln e` per impact exactly (the flight is volume-preserving, each impact
///   contracts areas by `e²`), checked against the impacts counted in the run.
#[test]
fn ball_on_table_exponent_three_ways() {
    for (gamma, e, periodic) in [(1.2, 0.8, true), (1.5, 0.9, false)] {
        let p = BouncingBallTable::with_gamma(gamma, e).unwrap();
        let v0 = p.table_motion(0.0).1 + 2.0;
        let exact = BallOnTableExact::new(p)
            .lyapunov(0.0, v0, 200, 20_000)
            .unwrap();
        let events = Event::new(p.table::<f64>().unwrap(), Direction::Rising)
            .with_reset(p.impact::<f64>().unwrap());
        let tol = Tolerances::new(1e-10, 1e-12).unwrap();
        let mut pair = HybridTwoTrajectory::new(
            p.model::<f64>().unwrap(),
            Dopri5::new(tol),
            events,
            1e-8,
            Norm::Euclidean,
        )
        .unwrap();
        pair.start(0.0, SVector::<f64, 2>::new(0.0, v0)).unwrap();
        pair.transient(1.0, 50).unwrap();
        let two = pair.estimate(1.0, 1500).unwrap();
        let ttol = tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12).unwrap();
        let mut qr = HybridTangentSpace::<f64, 2, 2, 6, _, _, _>::new(
            p.model::<f64>().unwrap(),
            Dopri5::new(ttol),
            events,
            Norm::Euclidean,
        )
        .unwrap();
        qr.start(0.0, SVector::<f64, 2>::new(0.0, v0)).unwrap();
        qr.transient(1.0, 50).unwrap();
        let spec = qr.estimate(1.0, 1500).unwrap();
        println!(
            "Γ = {gamma}, e = {e}: exact map {exact:.4}; two trajectories {:.4} ± {:.4}; QR {:.4} ± {:.4} (λ₂ {:.4}, sum {:.4})",
            two.exponent,
            two.spread,
            spec.exponents[0],
            spec.spread[0],
            spec.exponents[1],
            spec.sum()
        );
        if periodic {
            assert!(
                (two.exponent - exact).abs() < 2e-3,
                "{} vs {exact}",
                two.exponent
            );
            assert!(
                (spec.top() - exact).abs() < 2e-3,
                "{} vs {exact}",
                spec.top()
            );
        } else {
            assert!(exact > 0.4, "chaotic: {exact}");
            assert!((two.exponent - exact).abs() < 3.0 * two.spread + 0.02);
            assert!((spec.top() - exact).abs() < 3.0 * spec.spread[0] + 0.02);
        }
        // Σλ = 2 ln e × impacts per unit time, exactly.
        let rate = spec.stats.events as f64 / 1500.0;
        let expected = 2.0 * e.ln() * rate;
        assert!(
            (spec.sum() - expected).abs() < 2e-3 * expected.abs().max(0.1),
            "{} vs {expected}",
            spec.sum()
        );
    }
}
