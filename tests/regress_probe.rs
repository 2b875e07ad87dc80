//! Regressions of the hostile probe (issue 27): each test names the defect it pins down.
//! Finite input never gives NaN or an infinity, out-of-range arguments are errors or
//! documented no-ops instead of panics, and invalid settings are rejected by name.

use nalgebra::Vector2;
use nonsmooth::event::{EventFunction, Level, ResetMap, Restitution};

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
