//! Regressions of the hostile probe (issue 27): each test names the defect it pins down.
//! Finite input never gives NaN or an infinity, out-of-range arguments are errors or
//! documented no-ops instead of panics, and invalid settings are rejected by name.

use nalgebra::Vector2;
use nonsmooth::event::{EventFunction, Level, ResetMap, Restitution};
use nonsmooth::sample::{Regime, detect_period, try_detect_period};

/// Defect 1: `Level::value`/`rate` and `Restitution::apply` with a component index beyond
/// the state panicked ("Matrix index out of bounds") when called directly.
#[test]
fn level_and_restitution_out_of_range_do_not_panic() {
    let y = Vector2::new(0.5, -2.0);
    let level = Level::new(5, 0.0).unwrap();
    assert!(EventFunction::<f64, 2>::value(&level, 0.0, &y).is_nan());
    assert_eq!(EventFunction::<f64, 2>::rate(&level, 0.0, &y, &y), None);
    assert!(EventFunction::<f64, 2>::check(&level).is_err());
    // In range: unchanged behaviour.
    let inside = Level::new(1, 1.0).unwrap();
    assert_eq!(EventFunction::<f64, 2>::value(&inside, 0.0, &y), -3.0);
    assert_eq!(
        EventFunction::<f64, 2>::rate(&inside, 0.0, &y, &y),
        Some(-2.0)
    );

    let reset = Restitution::new(7, 0.8).unwrap();
    let mut z = y;
    ResetMap::<f64, 2>::apply(&reset, 0.0, &mut z);
    assert_eq!(z, y, "an out-of-range reset leaves the state unchanged");
    assert!(ResetMap::<f64, 2>::check(&reset).is_err());
    let inside = Restitution::new(1, 0.5).unwrap();
    ResetMap::<f64, 2>::apply(&inside, 0.0, &mut z);
    assert_eq!(z, Vector2::new(0.5, 1.0));
}

/// Defect 2: period detection accepted a negative or −∞ tolerance (every sequence "not
/// periodic"); `+∞` called every sequence period 1.
#[test]
fn period_detection_rejects_invalid_tolerances() {
    let scale = Vector2::new(1.0, 1.0);
    let p2: Vec<_> = (0..20)
        .map(|i| Vector2::new(if i % 2 == 0 { 1.0 } else { -1.0 }, 0.0))
        .collect();
    for tol in [-1e-6, f64::NEG_INFINITY, f64::INFINITY, f64::NAN] {
        let e = try_detect_period(&p2, &scale, tol, 8).unwrap_err();
        assert_eq!(e.name, "tol");
        assert!(e.value == tol || (tol.is_nan() && e.value.is_nan()), "{e}");
        assert!(e.to_string().contains("`tol`"), "{e}");
        // The infallible form finds no period with such a tolerance.
        assert_eq!(detect_period(&p2, &scale, tol, 8), Regime::NotPeriodic);
    }
    assert_eq!(
        try_detect_period(&p2, &scale, 0.0, 8).unwrap(),
        Regime::Periodic(2)
    );
    assert_eq!(detect_period(&p2, &scale, 1e-9, 8), Regime::Periodic(2));
}
