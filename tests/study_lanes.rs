//! Systems described in a study file (`model = "mechanical"`) run in SIMD lanes: every
//! record equals the scalar path's to the bit (feature `cli`).
#![cfg(feature = "cli")]

use nonsmooth::study::{Shard, Study, compute_point, run_shard};

/// The 2-DOF impact damper of the examples (Hertz walls on `q1 − q0`, two counting
/// surfaces), shortened.
const DAMPER: &str = include_str!("../examples/studies/impact_damper_2dof.toml");

/// One degree of freedom with every other law of a description: a cubic spring, regularized
/// dry friction and a Hertz stop from below, with a phase on the load.
const ONE_DOF: &str = r#"
name = "one_dof_laws"
[system]
model = "mechanical"
masses = ["m"]
[[system.elements]]
law = "cubic_spring"
dof = 0
k1 = 1.0
k3 = 0.5
[[system.elements]]
law = "dry_friction"
dof = 0
t = 0.05
eps = 1e-3
[[system.elements]]
law = "hertz"
dof = 0
side = "lower"
position = -0.8
k = 200.0
b = 0.5
[[system.loads]]
dof = 0
amplitude = 1.2
phase = 0.3
[[system.surfaces]]
dof = 0
position = -0.8
side = "lower"
[grid]
x = { parameter = "omega", start = 0.6, end = 1.4, points = 5 }
y = { parameter = "m", start = 0.8, end = 1.2, points = 3 }
[periods]
transient = 20
record = 8
[record]
lyapunov = { periods = 4 }
"#;

/// Three masses in a chain (springs on each coordinate and between neighbours), a linear
/// spring with a rest position, a load on each end, a stop of the last mass.
const CHAIN: &str = r#"
name = "chain"
[system]
model = "mechanical"
masses = [1.0, 0.5, 0.25]
parameters = { gap = 0.05 }
[[system.elements]]
law = "linear_spring"
dof = 0
k = 1.0
[[system.elements]]
law = "linear_spring"
between = [1, 0]
k = 2.0
x0 = 0.01
[[system.elements]]
law = "linear_spring"
between = [2, 1]
k = "k2"
[[system.elements]]
law = "viscous_damper"
dof = 2
c = 0.05
[[system.elements]]
law = "viscous_damper"
dof = 0
c = 0.02
[[system.elements]]
law = "hertz"
dof = 2
position = "gap"
k = 1e3
b = 1.0
[[system.loads]]
dof = 0
amplitude = 0.3
[[system.loads]]
dof = 2
amplitude = 0.1
phase = 1.0
[[system.surfaces]]
dof = 2
position = "gap"
[grid]
x = { parameter = "omega", start = 0.5, end = 1.5, points = 4 }
y = { parameter = "k2", start = 0.5, end = 1.5, points = 3 }
[periods]
transient = 20
record = 8
"#;

#[test]
fn described_systems_in_lanes_give_the_scalar_records_to_the_bit() {
    // `run_shard` runs a described system's points in SIMD lanes (`run_batch`),
    // `compute_point` one by one on the scalar path. Every field (Debug prints every f64
    // exactly), and every failure message, must agree.
    let damper = DAMPER
        .replace("transient = 200", "transient = 30")
        .replace("record = 40", "record = 10")
        .replace("periods = 20", "periods = 4");
    let capped = damper.replace(
        "name = \"impact_damper_2dof\"",
        "name = \"capped\"\n[integration]\nmax_steps = 4000",
    );
    for text in [damper.as_str(), capped.as_str(), ONE_DOF, CHAIN] {
        let study = Study::from_toml(text).unwrap();
        let lanes = run_shard(&study, Shard::WHOLE, || {});
        assert_eq!(lanes.len(), study.points());
        let mut failed = 0;
        let mut impacts = 0.0;
        for (i, got) in lanes.iter().enumerate() {
            let want = compute_point(&study, i);
            assert_eq!(
                format!("{got:?}"),
                format!("{want:?}"),
                "point {i} of\n{text}"
            );
            failed += usize::from(!got.is_ok());
            impacts += got.impacts_per_period.max(0.0);
        }
        if text == capped {
            assert!(failed > 0, "the step cap must fail some points");
        } else {
            assert_eq!(failed, 0, "{text}");
            assert!(
                impacts > 0.0,
                "a surface must be hit somewhere on the grid\n{text}"
            );
        }
    }
}
