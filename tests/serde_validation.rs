//! Deserialization applies the constructors' checks (feature `serde`).
//!
//! For every type whose constructors validate: a valid value survives a JSON round trip
//! unchanged, and a JSON value with one invalid field is rejected with the constructor's own
//! error message (which names the parameter). NaN and ±∞ are not representable in JSON; the
//! checks that only reject them are exercised through serde's in-memory map deserializer.

#![cfg(feature = "serde")]

use std::fmt::Debug;

use serde::de::value::{Error as ValueError, MapDeserializer};
use serde::de::{DeserializeOwned, Deserializer, IntoDeserializer, Visitor};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use nonsmooth::ParameterError;
use nonsmooth::analysis::{AmplitudeLaw, LinearizedResponse};
use nonsmooth::event::{Direction, Level, Restitution};
use nonsmooth::excite::{Harmonic, RampedRotor, UnbalancedRotor};
use nonsmooth::force::{
    Bilinear, CubicSpring, DryFriction, HertzContact, LinearSpring, Regularization, Side,
    ViscousDamper,
};
use nonsmooth::lyapunov::{DiagramSettings, IntervalRule, LyapunovError};
use nonsmooth::model::Oscillator;
use nonsmooth::signal::{InitialState, LowPass, PhaseInput, PhaseSection, ThresholdCrossing};
use nonsmooth::systems::paper::lyapunov::diagram_settings as paper_diagram_settings;
use nonsmooth::systems::{BouncingBallTable, DuffingUeda, TwoDofImpact};

// ---------------------------------------------------------------------------------------
// helpers

/// A valid value: JSON and back gives the identical value, and the JSON is the derive's.
fn round_trip<T: Serialize + DeserializeOwned + PartialEq + Debug>(value: &T) {
    let text = serde_json::to_string(value).unwrap();
    let back: T = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{text}: {e}"));
    assert_eq!(&back, value, "{text}");
    assert_eq!(serde_json::to_string(&back).unwrap(), text);
}

/// `valid` serialized, with `field` (a JSON pointer, e.g. `/k`) replaced by `bad`, must be
/// rejected with an error containing `expected` (the constructor's message).
fn rejects<T: Serialize + DeserializeOwned + Debug>(
    valid: &T,
    field: &str,
    bad: Value,
    expected: impl ToString,
) {
    let mut v = serde_json::to_value(valid).unwrap();
    let shown = v.to_string();
    *v.pointer_mut(field)
        .unwrap_or_else(|| panic!("no field {field} in {shown}")) = bad;
    let text = v.to_string();
    let expected = expected.to_string();
    match serde_json::from_str::<T>(&text) {
        Ok(t) => panic!("{text} was accepted as {t:?}"),
        Err(e) => assert!(
            e.to_string().contains(&expected),
            "{text}: error `{e}` does not contain `{expected}`"
        ),
    }
}

/// As [`rejects`], for a constructor's error on a value that JSON may not carry exactly
/// (serde_json's default float parser can be an ulp off for huge or tiny numbers): the
/// message must name the parameter and its requirement.
fn rejects_param<T: Serialize + DeserializeOwned + Debug>(
    valid: &T,
    field: &str,
    bad: Value,
    expected: ParameterError,
) {
    rejects(
        valid,
        field,
        bad.clone(),
        format!("invalid parameter `{}`", expected.name),
    );
    rejects(
        valid,
        field,
        bad,
        format!("must be {}", expected.requirement),
    );
}

/// A field value of [`from_fields`]: NaN and ±∞ are allowed, unlike in JSON.
#[derive(Clone, Copy)]
enum F {
    U(u64),
    X(f64),
    Variant(&'static str),
}

struct FieldDeserializer(F);

impl<'de> IntoDeserializer<'de, ValueError> for F {
    type Deserializer = FieldDeserializer;
    fn into_deserializer(self) -> FieldDeserializer {
        FieldDeserializer(self)
    }
}

impl<'de> Deserializer<'de> for FieldDeserializer {
    type Error = ValueError;
    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, ValueError> {
        match self.0 {
            F::U(u) => visitor.visit_u64(u),
            F::X(x) => visitor.visit_f64(x),
            F::Variant(s) => visitor.visit_borrowed_str(s),
        }
    }
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        name: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, ValueError> {
        match self.0 {
            F::Variant(s) => IntoDeserializer::<ValueError>::into_deserializer(s)
                .deserialize_enum(name, variants, visitor),
            _ => self.deserialize_any(visitor),
        }
    }
    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map struct identifier
        ignored_any
    }
}

/// Deserializes `T` from named fields in memory (no JSON, so NaN and ±∞ get through).
fn from_fields<T: for<'de> Deserialize<'de>>(
    fields: &[(&'static str, F)],
) -> Result<T, ValueError> {
    T::deserialize(MapDeserializer::new(fields.iter().copied()))
}

fn rejects_fields<T: for<'de> Deserialize<'de> + Debug>(
    fields: &[(&'static str, F)],
    expected: impl ToString,
) {
    let expected = expected.to_string();
    match from_fields::<T>(fields) {
        Ok(t) => panic!("accepted as {t:?}"),
        Err(e) => assert!(
            e.to_string().contains(&expected),
            "error `{e}` does not contain `{expected}`"
        ),
    }
}

fn paper_contact() -> HertzContact<f64> {
    HertzContact::new(-2.086e-3, 2.3983e8)
        .unwrap()
        .with_damping(0.8485, 1.5, 0.18667)
        .unwrap()
        .with_rate_regularization(1e-8)
        .unwrap()
}

// ---------------------------------------------------------------------------------------
// force laws

#[test]
fn linear_spring() {
    let s = LinearSpring::new(1418.9)
        .unwrap()
        .with_rest_position(0.25)
        .unwrap();
    round_trip(&s);
    round_trip(&LinearSpring::new(0.0_f32).unwrap());
    rejects(&s, "/k", json!(-1.0), LinearSpring::new(-1.0).unwrap_err());
    assert!(
        LinearSpring::new(-1.0)
            .unwrap_err()
            .to_string()
            .contains("`k`")
    );
    // The hand-written form of the derive is read as before.
    let read: LinearSpring<f64> = serde_json::from_str(r#"{"k": 2.0, "x0": 0.5}"#).unwrap();
    assert_eq!(
        read,
        LinearSpring::new(2.0)
            .unwrap()
            .with_rest_position(0.5)
            .unwrap()
    );
    let err = serde_json::from_str::<LinearSpring<f64>>(r#"{"k": -1, "x0": 0}"#).unwrap_err();
    assert!(err.to_string().contains("invalid parameter `k`"), "{err}");
    rejects_fields::<LinearSpring<f64>>(&[("k", F::X(1.0)), ("x0", F::X(f64::NAN))], "`x0`");
    rejects_fields::<LinearSpring<f64>>(&[("k", F::X(f64::INFINITY)), ("x0", F::X(0.0))], "`k`");
}

#[test]
fn viscous_damper() {
    let d = ViscousDamper::new(6.6511).unwrap();
    round_trip(&d);
    rejects(&d, "/c", json!(-0.1), ViscousDamper::new(-0.1).unwrap_err());
}

#[test]
fn dry_friction() {
    let f = DryFriction::sqrt(0.63133, 1e-6).unwrap();
    round_trip(&f);
    round_trip(&DryFriction::tanh(0.5_f32, 1e-3).unwrap());
    rejects(
        &f,
        "/eps",
        json!(0.0),
        DryFriction::sqrt(0.63133, 0.0).unwrap_err(),
    );
    rejects(&f, "/eps", json!(-1e-6), "`eps`");
    // ε² underflows: 0/0 at v = 0.
    rejects_param(
        &f,
        "/eps",
        json!(1e-160),
        DryFriction::sqrt(0.63133, 1e-160).unwrap_err(),
    );
    rejects(
        &f,
        "/t",
        json!(-0.5),
        DryFriction::sqrt(-0.5, 1e-6).unwrap_err(),
    );
    assert_eq!(
        serde_json::from_value::<DryFriction<f64>>(json!({"t": 1.0, "eps": 0.5, "reg": "Tanh"}))
            .unwrap(),
        DryFriction::new(1.0, 0.5, Regularization::Tanh).unwrap()
    );
}

#[test]
fn hertz_contact() {
    let h = paper_contact();
    round_trip(&h);
    round_trip(&HertzContact::new(0.1, 1e3).unwrap());
    round_trip(
        &HertzContact::new(0.0_f32, 1e3)
            .unwrap()
            .with_side(Side::Lower)
            .with_stiffness_exponent(1.3)
            .unwrap()
            .with_damping(0.2, 1.0, 0.5)
            .unwrap(),
    );
    rejects(
        &h,
        "/k_i",
        json!(0.0),
        HertzContact::new(0.0, 0.0).unwrap_err(),
    );
    rejects(&h, "/k_i", json!(-2.4e8), "`k_i`");
    rejects(&h, "/b", json!(-1.0), "`b`");
    rejects(&h, "/n3", json!(0.0), "`n3`");
    rejects(&h, "/n1", json!({"General": -1.5}), "`n1`");
    rejects(&h, "/n2", json!({"General": 0.0}), "`n2`");
    rejects(&h, "/eta", json!(-1e-8), "`eta`");
    // η² underflows.
    rejects(&h, "/eta", json!(1e-300), "`eta`");
    // η^(n3−1) overflows: the rate term would be 0·∞ at v = 0.
    let steep = HertzContact::new(0.0, 1.0)
        .unwrap()
        .with_rate_regularization(10.0)
        .unwrap();
    rejects_param(
        &steep,
        "/n3",
        json!(1000.0),
        steep.with_damping(0.0, 1.5, 1000.0).unwrap_err(),
    );
    // The cached (n3 − 1)/2 is recomputed, not read.
    let mut v = serde_json::to_value(h).unwrap();
    v["half_n3_minus_1"] = json!(1e300);
    assert_eq!(serde_json::from_value::<HertzContact<f64>>(v).unwrap(), h);
}

#[test]
fn bilinear() {
    let b = Bilinear::backlash(2.0, 0.1).unwrap();
    round_trip(&b);
    round_trip(&Bilinear::new(1.0, 9.0, -0.5, 0.5).unwrap());
    // lo ≤ hi is checked across the fields.
    rejects(
        &b,
        "/lo",
        json!(0.2),
        Bilinear::new(0.0, 2.0, 0.2, 0.1).unwrap_err(),
    );
    rejects(&b, "/k_out", json!(-1.0), "`k_out`");
    rejects(&b, "/k_in", json!(-1.0), "`k_in`");
}

#[test]
fn cubic_spring() {
    let s = CubicSpring::new(-1.0, 1.0)
        .unwrap()
        .with_rest_position(0.1)
        .unwrap();
    round_trip(&s);
    // Every finite coefficient is valid: only NaN and ±∞ are rejected.
    rejects_fields::<CubicSpring<f64>>(
        &[("k1", F::X(f64::NAN)), ("k3", F::X(1.0)), ("x0", F::X(0.0))],
        CubicSpring::new(f64::NAN, 1.0).unwrap_err(),
    );
    rejects_fields::<CubicSpring<f64>>(
        &[
            ("k1", F::X(0.0)),
            ("k3", F::X(f64::NEG_INFINITY)),
            ("x0", F::X(0.0)),
        ],
        "`k3`",
    );
    assert_eq!(
        from_fields::<CubicSpring<f64>>(&[
            ("k1", F::X(-1.0)),
            ("k3", F::X(1.0)),
            ("x0", F::X(0.1))
        ])
        .unwrap(),
        s
    );
}

// ---------------------------------------------------------------------------------------
// excitations and models

#[test]
fn harmonic() {
    let h = Harmonic::new(7.5, 1.0, 0.3).unwrap();
    round_trip(&h);
    round_trip(&Harmonic::cosine(1.0_f32, 2.0).unwrap());
    rejects(
        &h,
        "/omega",
        json!(0.0),
        Harmonic::new(7.5, 0.0, 0.3).unwrap_err(),
    );
    rejects(&h, "/omega", json!(-1.0), "`omega`");
    rejects_fields::<Harmonic<f64>>(
        &[
            ("amplitude", F::X(1.0)),
            ("omega", F::X(1.0)),
            ("phase0", F::X(f64::INFINITY)),
        ],
        "`phase0`",
    );
}

#[test]
fn unbalanced_rotor() {
    let r = UnbalancedRotor::new(0.01805, 20.465).unwrap();
    round_trip(&r);
    rejects(&r, "/omega", json!(0.0), "`omega`");
    rejects(&r, "/m0e", json!(-0.01805), "`m0e`");
    // The force m0e·ω³ overflows.
    let big = UnbalancedRotor::new(0.49, 1.0).unwrap();
    rejects_param(
        &big,
        "/omega",
        json!(1e265),
        UnbalancedRotor::new(0.49, 1e265).unwrap_err(),
    );
    // The amplitude m0e·ω² is recomputed, not read.
    let mut v = serde_json::to_value(r).unwrap();
    v["amp"] = json!(-1e308);
    assert_eq!(
        serde_json::from_value::<UnbalancedRotor<f64>>(v).unwrap(),
        r
    );
}

#[test]
fn ramped_rotor() {
    let r = RampedRotor::new(0.01805, 14.0, 8.0905e-3).unwrap();
    round_trip(&r);
    rejects(&r, "/omega0", json!(0.0), "`omega0`");
    rejects(&r, "/m0e", json!(-1.0), "`m0e`");
    let big = RampedRotor::new(2.0, 1.0, 0.5).unwrap();
    rejects_param(
        &big,
        "/omega0",
        json!(3e184),
        RampedRotor::new(2.0, 3e184, 0.5).unwrap_err(),
    );
    rejects_param(
        &big,
        "/rate",
        json!(1e308),
        RampedRotor::new(2.0, 1.0, 1e308).unwrap_err(),
    );
}

type Model = Oscillator<f64, (LinearSpring<f64>, ViscousDamper<f64>), Harmonic<f64>>;

#[test]
fn oscillator() {
    let osc: Model = Oscillator::new(
        8.735,
        (
            LinearSpring::new(1418.9).unwrap(),
            ViscousDamper::new(6.6511).unwrap(),
        ),
        Harmonic::new(1.0, 14.0, 0.0).unwrap(),
    )
    .unwrap();
    round_trip(&osc);
    rejects(
        &osc,
        "/mass",
        json!(0.0),
        Model::new(0.0, *osc.laws(), *osc.excitation()).unwrap_err(),
    );
    rejects(&osc, "/mass", json!(-8.7), "`mass`");
    // The nested laws and excitation check themselves.
    rejects(&osc, "/laws/0/k", json!(-1.0), "`k`");
    rejects(&osc, "/excitation/omega", json!(0.0), "`omega`");
    // 1/m is recomputed, not read.
    let mut v = serde_json::to_value(osc).unwrap();
    v["inv_mass"] = json!(0.0);
    assert_eq!(serde_json::from_value::<Model>(v).unwrap(), osc);
}

#[test]
fn linearized_response() {
    let lin: LinearizedResponse<f64> = LinearizedResponse::from_parts(
        8.735,
        1500.0,
        6.6511,
        -2.08e-3,
        AmplitudeLaw::Unbalance(0.01805),
    )
    .unwrap();
    round_trip(&lin);
    rejects(
        &lin,
        "/mass",
        json!(0.0),
        LinearizedResponse::from_parts(0.0, 1.0, 1.0, 0.0, AmplitudeLaw::Constant(1.0))
            .unwrap_err(),
    );
    rejects(&lin, "/damping", json!(-1.0), "`damping`");
}

// ---------------------------------------------------------------------------------------
// events

#[test]
fn level() {
    let l = Level::new(0, -2.086e-3).unwrap();
    round_trip(&l);
    rejects_fields::<Level<f64>>(
        &[("index", F::U(0)), ("level", F::X(f64::NAN))],
        Level::new(0, f64::NAN).unwrap_err(),
    );
    assert_eq!(
        from_fields::<Level<f64>>(&[("index", F::U(1)), ("level", F::X(0.5))]).unwrap(),
        Level::new(1, 0.5).unwrap()
    );
}

#[test]
fn restitution() {
    let r = Restitution::new(1, 0.8).unwrap();
    round_trip(&r);
    rejects(
        &r,
        "/r",
        json!(-0.5),
        Restitution::new(1, -0.5).unwrap_err(),
    );
}

// ---------------------------------------------------------------------------------------
// measured data

#[test]
fn low_pass() {
    let f = LowPass::new(1e-3)
        .unwrap()
        .with_initial(InitialState::Value(0.25));
    round_trip(&f);
    round_trip(&nonsmooth::systems::paper::low_pass::<f64>().unwrap());
    rejects(&f, "/theta", json!(0.0), LowPass::new(0.0).unwrap_err());
    rejects(&f, "/theta", json!(-1e-3), "`theta`");
}

#[test]
fn threshold_crossing() {
    let c = nonsmooth::systems::paper::impact_detector(-2.086e-3)
        .unwrap()
        .with_direction(Direction::Either)
        .with_hysteresis(1e-6)
        .unwrap()
        .with_min_separation(0.01)
        .unwrap();
    round_trip(&c);
    rejects(
        &c,
        "/hysteresis",
        json!(-1e-6),
        ThresholdCrossing::new(0.0)
            .unwrap()
            .with_hysteresis(-1e-6)
            .unwrap_err(),
    );
    rejects(&c, "/min_separation", json!(-1.0), "`min_separation`");
    rejects_fields::<ThresholdCrossing<f64>>(
        &[
            ("level", F::X(f64::NAN)),
            ("direction", F::Variant("Rising")),
            ("hysteresis", F::X(0.0)),
            ("min_separation", F::X(0.0)),
        ],
        "`level`",
    );
}

#[test]
fn phase_section() {
    let p = PhaseSection::new()
        .with_offset(0.5)
        .unwrap()
        .with_input(PhaseInput::Unwrapped);
    round_trip(&p);
    // Beyond 2π·2⁴⁰ levels 2π apart are not resolved.
    rejects(
        &p,
        "/offset",
        json!(1e13),
        PhaseSection::new().with_offset(1e13).unwrap_err(),
    );
    rejects(&p, "/offset", json!(-1e308), "`offset`");
}

// ---------------------------------------------------------------------------------------
// Lyapunov schedule

#[test]
fn diagram_settings() {
    let mut s = DiagramSettings::new(IntervalRule::Fixed(0.5), 10, 5, 200)
        .unwrap()
        .with_blocks(4)
        .unwrap();
    s.t0 = 3.5;
    round_trip(&s);
    round_trip(&paper_diagram_settings::<f64>());
    rejects(
        &s,
        "/intervals",
        json!(1),
        DiagramSettings::new(IntervalRule::Fixed(0.5), 10, 5, 1).unwrap_err(),
    );
    rejects(
        &s,
        "/intervals",
        json!(1_000_000_000u64),
        LyapunovError::TooManyIntervals {
            intervals: 1_000_000_000,
            maximum: nonsmooth::lyapunov::MAX_INTERVALS,
        },
    );
    rejects(
        &s,
        "/blocks",
        json!(1),
        LyapunovError::InvalidBlocks { blocks: 1 },
    );
    rejects(
        &s,
        "/interval",
        json!({"Fixed": 0.0}),
        LyapunovError::InvalidInterval { tau: 0.0 },
    );
}

// ---------------------------------------------------------------------------------------
// parameter sets of the catalogue

#[test]
fn two_dof_impact() {
    let p = TwoDofImpact::default();
    round_trip(&p);
    let bad = TwoDofImpact { m1: 0.0, ..p };
    rejects(&p, "/m1", json!(0.0), bad.validate().unwrap_err());
    rejects(&p, "/c2", json!(-0.05), "`c2`");
    rejects(&p, "/k_contact", json!(-1e3), "`k_contact`");
}

#[test]
fn duffing_ueda() {
    let p = DuffingUeda::default();
    round_trip(&p);
    let bad = DuffingUeda { omega: 0.0, ..p };
    rejects(&p, "/omega", json!(0.0), bad.validate().unwrap_err());
    rejects(&p, "/k", json!(-0.05), "`k`");
}

#[test]
fn bouncing_ball_table() {
    let p = BouncingBallTable::with_gamma(2.0, 0.5).unwrap();
    round_trip(&p);
    rejects(
        &p,
        "/e",
        json!(1.5),
        BouncingBallTable::with_gamma(2.0, 1.5).unwrap_err(),
    );
    rejects(&p, "/amplitude", json!(0.0), "`amplitude`");
    rejects(&p, "/g", json!(-9.81), "`g`");
}

#[test]
fn paper_parameters() {
    use nonsmooth::systems::paper::PAPER;
    round_trip(&PAPER);
    rejects(&PAPER, "/k_i", json!(-1.0), "`k_i`");
    rejects(&PAPER, "/eps", json!(0.0), "`eps`");
    rejects(&PAPER, "/m", json!(0.0), "`mass`");
    rejects(&PAPER, "/n3", json!(0.0), "`n3`");
}
