//! Deserialization applies the constructors' checks: a valid value round-trips unchanged,
//! and a value a constructor would reject is an error naming the parameter (before, serde
//! accepted `k_I = −1`, `ε = 0`, `ω = 0`, …). Run with `--features serde`.
#![cfg(feature = "serde")]

use nonsmooth::event::{Level, Restitution};
use nonsmooth::excite::{Harmonic, RampedRotor, UnbalancedRotor};
use nonsmooth::force::{
    Bilinear, CubicSpring, DryFriction, HertzContact, LinearSpring, ViscousDamper,
};
use nonsmooth::signal::{LowPass, PhaseSection, ThresholdCrossing};
use nonsmooth::systems::paper::PAPER;
use nonsmooth::systems::{BouncingBallTable, DuffingUeda, TwoDofImpact};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

/// `value` round-trips through JSON unchanged.
fn round_trip<V>(value: &V) -> Value
where
    V: Serialize + DeserializeOwned + PartialEq + std::fmt::Debug,
{
    let json = serde_json::to_value(value).unwrap();
    let back: V = serde_json::from_value(json.clone()).unwrap();
    assert_eq!(&back, value, "round trip of {json}");
    json
}

/// `value` round-trips; setting `field` to `bad` is rejected with a message naming `name`.
fn check<V>(value: &V, field: &str, bad: Value, name: &str)
where
    V: Serialize + DeserializeOwned + PartialEq + std::fmt::Debug,
{
    let json = round_trip(value);
    let mut broken = json.clone();
    *pointer(&mut broken, field) = bad.clone();
    let err = serde_json::from_value::<V>(broken)
        .expect_err(&format!("{field} = {bad} must be rejected in {json}"))
        .to_string();
    assert!(
        err.contains(name),
        "{field} = {bad}: error `{err}` does not name `{name}`"
    );
}

fn pointer<'a>(v: &'a mut Value, path: &str) -> &'a mut Value {
    let p = format!("/{}", path.replace('.', "/"));
    v.pointer_mut(&p)
        .unwrap_or_else(|| panic!("no field {path}"))
}

#[test]
fn force_laws_validate_on_deserialize() {
    check(&LinearSpring::new(1418.9).unwrap(), "k", (-1.0).into(), "k");
    check(&ViscousDamper::new(6.65).unwrap(), "c", (-0.1).into(), "c");
    check(
        &DryFriction::sqrt(8.5, 1e-6).unwrap(),
        "eps",
        0.0.into(),
        "eps",
    );
    let hertz = HertzContact::new(-2.086e-3, 2.4e8)
        .unwrap()
        .with_damping(3.5e9, 1.5, 0.187)
        .unwrap()
        .with_rate_regularization(1e-8)
        .unwrap();
    check(&hertz, "k_i", (-1.0).into(), "k_i");
    check(&hertz, "n3", 0.0.into(), "n3");
    check(&hertz, "b", (-3.0).into(), "b");
    check(&hertz, "eta", 1e-300.into(), "eta");
    // Only non-finite values are invalid here, and JSON cannot carry them.
    round_trip(&CubicSpring::new(1.0, 0.05).unwrap());
    check(
        &Bilinear::backlash(10.0, 0.1).unwrap(),
        "lo",
        1.0.into(),
        "lo",
    );
}

#[test]
fn excitations_models_and_systems_validate_on_deserialize() {
    check(
        &Harmonic::cosine(1.0, 2.0).unwrap(),
        "omega",
        0.0.into(),
        "omega",
    );
    check(
        &UnbalancedRotor::new(0.02, 20.0).unwrap(),
        "omega",
        (-1.0).into(),
        "omega",
    );
    check(
        &UnbalancedRotor::new(0.49, 1e3).unwrap(),
        "m0e",
        1e300.into(),
        "m0e·ω³",
    );
    check(
        &RampedRotor::new(0.02, 19.0, 0.5).unwrap(),
        "omega0",
        0.0.into(),
        "omega",
    );
    let osc = PAPER.oscillator::<f64>(20.465).unwrap();
    check(&osc, "mass", 0.0.into(), "mass");
    check(&osc, "laws.3.k_i", (-1.0).into(), "k_i");
    check(&osc, "excitation.omega", 0.0.into(), "omega");
    check(&PAPER, "k_i", (-1.0).into(), "k_i");
    check(&PAPER, "eps", 0.0.into(), "eps");
    check(&TwoDofImpact::default(), "m2", 0.0.into(), "m");
    check(&DuffingUeda::default(), "k", (-0.1).into(), "`k`");
    check(
        &BouncingBallTable::with_gamma(1.2, 0.5).unwrap(),
        "e",
        1.5.into(),
        "e",
    );
}

#[test]
fn events_and_signal_tools_validate_on_deserialize() {
    round_trip(&Level::new(0, -2.086e-3).unwrap());
    check(&Restitution::new(1, 0.8).unwrap(), "r", (-0.5).into(), "r");
    check(&LowPass::new(1e-3).unwrap(), "theta", 0.0.into(), "theta");
    let crossing = ThresholdCrossing::new(-2.0e-3)
        .unwrap()
        .with_hysteresis(1e-6)
        .unwrap();
    check(&crossing, "hysteresis", (-1.0).into(), "hysteresis");
    let section = PhaseSection::new().with_offset(0.5).unwrap();
    check(&section, "offset", (-1.7e308).into(), "offset");
}
