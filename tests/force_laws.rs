//! Force laws: the built-in laws pass the checker of `nonsmooth::testing`, deliberately broken
//! laws are rejected for the right reason, and proptest invariants of the built-in laws.

use nonsmooth::ForceLaw;
use nonsmooth::force::{DryFriction, HertzContact, LinearSpring, Side, ViscousDamper};
use nonsmooth::systems::paper::PAPER;
use nonsmooth::testing::{
    CheckConfig, CheckReport, ContactClaim, GridAxis, LawSpec, LawViolation, Property, Variable,
    check_law, points_in,
};
use proptest::prelude::*;

// The paper's contact parameters.
const X_I: f64 = -2.086e-3;
const K_I: f64 = 2.3983e8;
const B: f64 = 0.8485;
const N2: f64 = 1.5;
const N3: f64 = 0.18667;

fn paper_contact(side: Side, eta: f64) -> HertzContact<f64> {
    let stop = match side {
        Side::Upper => X_I,
        Side::Lower => -X_I,
    };
    HertzContact::new(stop, K_I)
        .unwrap()
        .with_side(side)
        .with_damping(B, N2, N3)
        .unwrap()
        .with_rate_regularization(eta)
        .unwrap()
}

/// Around the stop: separations and penetrations 1 nm … 0.1 mm (and the stop itself).
fn x_near(stop: f64) -> GridAxis {
    GridAxis::log_around(stop, 1e-9, 1e-4).unwrap()
}

/// Velocities ±10 nm/s … 1 m/s, and 0.
fn v_axis() -> GridAxis {
    GridAxis::log_around(0.0, 1e-8, 1.0).unwrap()
}

fn x_wide() -> GridAxis {
    GridAxis::linear(-1e-2, 1e-2).unwrap()
}

fn contact_config(side: Side, stop: f64, kink_at_zero_rate: bool) -> CheckConfig {
    let mut spec = LawSpec::new()
        .contact(ContactClaim::new(stop, side))
        .analytic_partials();
    if kink_at_zero_rate {
        spec = spec.kink_v(0.0);
    }
    CheckConfig::new(x_near(stop), v_axis(), spec).unwrap()
}

/// A contact claim without analytic partials (for laws that use the default ones).
fn contact_only(side: Side, stop: f64) -> CheckConfig {
    let spec = LawSpec::new().contact(ContactClaim::new(stop, side));
    CheckConfig::new(x_near(stop), v_axis(), spec).unwrap()
}

fn pass<L: ForceLaw<f64>>(law: &L, config: &CheckConfig) -> CheckReport {
    match check_law(law, config) {
        Ok(r) => r,
        Err(e) => panic!("rejected a correct law: {e}"),
    }
}

fn reject<L: ForceLaw<f64>>(law: &L, config: &CheckConfig) -> LawViolation {
    match check_law(law, config) {
        Ok(r) => panic!("accepted a broken law: {r:?}"),
        Err(e) => e,
    }
}

#[test]
fn checker_types_are_send_sync_clone() {
    fn check<T: Send + Sync + Clone + 'static>() {}
    check::<GridAxis>();
    check::<LawSpec>();
    check::<ContactClaim>();
    check::<CheckConfig>();
    check::<CheckReport>();
    check::<LawViolation>();
    check::<Property>();
    check::<Variable>();
    // The violation converts into a boxed error for `?` in user tests.
    let _: Box<dyn std::error::Error + Send + Sync> = Box::new(LawViolation::NonFiniteForce {
        x: 0.0,
        v: 0.0,
        force: f64::NAN,
    });
}

// ---------------------------------------------------------------------------------------
// Built-in laws pass.

#[test]
fn linear_spring_passes() {
    let cfg = CheckConfig::new(x_wide(), v_axis(), LawSpec::new().analytic_partials()).unwrap();
    let r = pass(&LinearSpring::new(1418.9).unwrap(), &cfg);
    assert_eq!(r.partials_skipped, 0);
    assert!(r.partials_checked >= 2 * r.points - 10);
    let shifted = LinearSpring::new(3.0)
        .unwrap()
        .with_rest_position(2e-3)
        .unwrap();
    pass(&shifted, &cfg);
}

#[test]
fn viscous_damper_passes_as_dissipative() {
    let cfg = CheckConfig::new(
        x_wide(),
        v_axis(),
        LawSpec::new().dissipative().analytic_partials(),
    )
    .unwrap();
    let r = pass(&ViscousDamper::new(6.6511).unwrap(), &cfg);
    assert_eq!(r.dissipation_checks, r.points);
    assert!(r.points > 5000);
}

#[test]
fn dry_friction_sqrt_and_tanh_pass_as_dissipative() {
    // Velocities down to 1e-10 m/s, well inside the regularization ε = 1e-6 m/s.
    let cfg = CheckConfig::new(
        x_wide(),
        GridAxis::log_around(0.0, 1e-10, 1.0).unwrap(),
        LawSpec::new().dissipative().analytic_partials(),
    )
    .unwrap();
    for law in [
        DryFriction::sqrt(0.63133, 1e-6).unwrap(),
        DryFriction::tanh(0.63133, 1e-6).unwrap(),
    ] {
        let r = pass(&law, &cfg);
        // Smooth at v = 0 (no kink declared): nothing is skipped.
        assert_eq!(r.partials_skipped, 0, "{law:?}");
        assert!(r.max_partial_error_ratio <= 1.0);
    }
    // A damper and friction together are dissipative too.
    pass(
        &(
            ViscousDamper::new(6.6511).unwrap(),
            DryFriction::sqrt(0.63133, 1e-6).unwrap(),
        ),
        &cfg,
    );
}

#[test]
fn paper_hertz_contact_passes_both_sides_exact_rate_term() {
    for side in [Side::Upper, Side::Lower] {
        let law = paper_contact(side, 0.0);
        let cfg = contact_config(side, law.stop(), true);
        let r = pass(&law, &cfg);
        assert!(
            r.contact_checks > 2000 && r.separated_checks > 2000,
            "{r:?}"
        );
        assert!(r.onset_probes > 64, "{r:?}");
        // Only the partials exactly on a kink are skipped: ∂F/∂x at x = x_I and ∂F/∂v at
        // v = 0 on the grid. Points 1 nm from the stop or at |v| = 1e-8 m/s are checked.
        let (nx, nv) = (cfg.x().grid(33).len(), cfg.v().grid(33).len());
        assert_eq!(r.partials_skipped, nx + nv, "{r:?}");
        assert!(r.partials_checked > 9000);
    }
}

#[test]
fn paper_hertz_contact_passes_with_rate_regularization() {
    for side in [Side::Upper, Side::Lower] {
        for eta in [1e-9, 1e-6] {
            let law = paper_contact(side, eta);
            // Regularized: smooth in v, no kink at v = 0 needed.
            let r = pass(&law, &contact_config(side, law.stop(), false));
            assert!(r.partials_checked > 9000);
        }
    }
}

#[test]
fn elastic_hertz_contact_passes() {
    let law = HertzContact::new(X_I, K_I).unwrap();
    pass(&law, &contact_config(Side::Upper, X_I, false));
    let lower = HertzContact::new(1e-3, 5e9)
        .unwrap()
        .with_side(Side::Lower)
        .with_stiffness_exponent(1.0)
        .unwrap();
    pass(&lower, &contact_config(Side::Lower, 1e-3, false));
}

#[test]
fn tuple_of_the_four_paper_laws_passes() {
    let exact = (
        LinearSpring::new(PAPER.k).unwrap(),
        ViscousDamper::new(PAPER.c).unwrap(),
        DryFriction::sqrt(PAPER.t, PAPER.eps).unwrap(),
        paper_contact(Side::Upper, 0.0),
    );
    // Not a contact (the spring acts when separated) and not dissipative (springs store
    // energy): only finiteness and the partials, with the contact's kinks declared.
    let spec = LawSpec::new().analytic_partials().kink_x(X_I).kink_v(0.0);
    let cfg = CheckConfig::new(x_near(X_I), v_axis(), spec).unwrap();
    let r = pass(&exact, &cfg);
    assert!(r.partials_checked > 9000);
    // The library's paper laws (regularized with η = 1e-9): no kink at v = 0.
    let spec = LawSpec::new().analytic_partials().kink_x(X_I);
    let cfg = CheckConfig::new(x_near(X_I), v_axis(), spec).unwrap();
    pass(&PAPER.laws::<f64>().unwrap(), &cfg);
    // On a wide linear domain too.
    let spec = LawSpec::new().analytic_partials().kink_x(X_I).kink_v(0.0);
    let cfg = CheckConfig::new(GridAxis::linear(-5e-3, 1e-3).unwrap(), v_axis(), spec).unwrap();
    pass(&exact, &cfg);
}

#[test]
fn f32_laws_pass() {
    let cfg = CheckConfig::new(
        GridAxis::linear(-1e-2, 1e-2).unwrap(),
        GridAxis::log_around(0.0, 1e-6, 1.0).unwrap(),
        LawSpec::new().dissipative().analytic_partials(),
    )
    .unwrap();
    check_law(&DryFriction::<f32>::sqrt(0.63133, 1e-4).unwrap(), &cfg).unwrap();
    check_law(&ViscousDamper::<f32>::new(6.6511).unwrap(), &cfg).unwrap();
    let law = HertzContact::<f32>::new(X_I as f32, K_I as f32)
        .unwrap()
        .with_damping(B as f32, N2 as f32, N3 as f32)
        .unwrap();
    let spec = LawSpec::new()
        .contact(ContactClaim::new(X_I, Side::Upper))
        .analytic_partials()
        .kink_v(0.0);
    // f32 resolves ~2e-10 m next to the stop: penetrations from 1e-6 m.
    let cfg = CheckConfig::new(
        GridAxis::log_around(X_I, 1e-6, 1e-4).unwrap(),
        GridAxis::log_around(0.0, 1e-5, 1.0).unwrap(),
        spec,
    )
    .unwrap();
    let r = check_law(&law, &cfg).unwrap();
    assert!(r.partials_checked > 5000 && r.onset_probes > 0, "{r:?}");
}

#[test]
fn the_check_is_deterministic() {
    let law = paper_contact(Side::Upper, 0.0);
    let cfg = contact_config(Side::Upper, X_I, true);
    assert_eq!(pass(&law, &cfg), pass(&law, &cfg));
    let other = pass(&law, &cfg.clone().with_seed(7));
    assert_eq!(other.points, pass(&law, &cfg).points);
}

// ---------------------------------------------------------------------------------------
// Broken laws are rejected, for the right reason.

/// `F = −c·v`: a damper that feeds energy in.
struct WrongSignDamper(f64);
impl ForceLaw<f64> for WrongSignDamper {
    fn force(&self, _x: f64, v: f64) -> f64 {
        -self.0 * v
    }
    fn partials(&self, _x: f64, _v: f64) -> (f64, f64) {
        (0.0, -self.0)
    }
}

#[test]
fn wrong_sign_damping_is_not_dissipative() {
    let cfg = CheckConfig::new(
        x_wide(),
        v_axis(),
        LawSpec::new().dissipative().analytic_partials(),
    )
    .unwrap();
    let e = reject(&WrongSignDamper(6.6511), &cfg);
    assert_eq!(e.property(), Property::Dissipative, "{e}");
    let LawViolation::NotDissipative {
        v, force, power, ..
    } = e
    else {
        panic!("{e:?}")
    };
    assert!(power < 0.0 && (power - force * v).abs() <= 1e-12 * power.abs());
}

/// A cubic spring `k3·x³` whose `∂F/∂x` is off by a factor 2.
struct CubicSpring {
    k3: f64,
    factor: f64,
}
impl ForceLaw<f64> for CubicSpring {
    fn force(&self, x: f64, _v: f64) -> f64 {
        self.k3 * x * x * x
    }
    fn partials(&self, x: f64, _v: f64) -> (f64, f64) {
        (self.factor * 3.0 * self.k3 * x * x, 0.0)
    }
}

#[test]
fn wrong_analytic_partial_is_rejected() {
    let cfg = CheckConfig::new(x_wide(), v_axis(), LawSpec::new().analytic_partials()).unwrap();
    pass(
        &CubicSpring {
            k3: 1e7,
            factor: 1.0,
        },
        &cfg,
    );
    let e = reject(
        &CubicSpring {
            k3: 1e7,
            factor: 2.0,
        },
        &cfg,
    );
    assert_eq!(e.property(), Property::AnalyticPartials, "{e}");
    let LawViolation::WrongPartial {
        wrt,
        analytic,
        finite_difference,
        ..
    } = e
    else {
        panic!("{e:?}")
    };
    assert_eq!(wrt, Variable::X);
    assert!((analytic / finite_difference - 2.0).abs() < 1e-6);
    // Even slightly wrong (by 1e-4) is caught.
    let e = reject(
        &CubicSpring {
            k3: 1e7,
            factor: 1.0 + 1e-4,
        },
        &cfg,
    );
    assert_eq!(e.property(), Property::AnalyticPartials);
}

/// The paper's contact with `∂F/∂v` doubled.
struct DoubledRatePartial(HertzContact<f64>);
impl ForceLaw<f64> for DoubledRatePartial {
    fn force(&self, x: f64, v: f64) -> f64 {
        self.0.force(x, v)
    }
    fn partials(&self, x: f64, v: f64) -> (f64, f64) {
        let (a, b) = self.0.partials(x, v);
        (a, 2.0 * b)
    }
}

#[test]
fn wrong_rate_partial_of_a_kinked_law_is_rejected() {
    // The kink at v = 0 is declared, so the correct law passes (tested above) and the
    // wrong one fails elsewhere.
    let cfg = contact_config(Side::Upper, X_I, true);
    let e = reject(&DoubledRatePartial(paper_contact(Side::Upper, 0.0)), &cfg);
    assert_eq!(e.property(), Property::AnalyticPartials, "{e}");
    assert!(matches!(
        e,
        LawViolation::WrongPartial {
            wrt: Variable::V,
            ..
        }
    ));
}

#[test]
fn undeclared_kink_is_reported_as_a_partials_failure() {
    // The exact law's ∂F/∂v is infinite at v = 0 (reported as f64::MAX); without the
    // declared kink the checker compares it there and fails, pointing at v = 0.
    let cfg = contact_config(Side::Upper, X_I, false);
    let e = reject(&paper_contact(Side::Upper, 0.0), &cfg);
    assert_eq!(e.property(), Property::AnalyticPartials, "{e}");
    assert_eq!(e.point().1, 0.0);
    assert!(e.to_string().contains("declare it"), "{e}");
}

/// A law whose partials are scaled by `(sx, sy)`.
struct ScaledPartials<L>(L, f64, f64);
impl<L: ForceLaw<f64>> ForceLaw<f64> for ScaledPartials<L> {
    fn force(&self, x: f64, v: f64) -> f64 {
        self.0.force(x, v)
    }
    fn partials(&self, x: f64, v: f64) -> (f64, f64) {
        let (a, b) = self.0.partials(x, v);
        (a * self.1, b * self.2)
    }
}

#[test]
fn small_partial_errors_of_the_paper_laws_are_caught() {
    let contact = paper_contact(Side::Upper, 0.0);
    let cfg = contact_config(Side::Upper, X_I, true);
    let r = pass(&contact, &cfg);
    assert!(r.max_partial_error_ratio < 0.05, "{r:?}");
    for (sx, sv, wrt) in [
        (1.0 + 3e-6, 1.0, Variable::X),
        (1.0, 1.0 + 3e-6, Variable::V),
    ] {
        let e = reject(&ScaledPartials(contact, sx, sv), &cfg);
        assert!(
            matches!(e, LawViolation::WrongPartial { wrt: w, .. } if w == wrt),
            "{e}"
        );
    }
    let laws = (
        LinearSpring::new(PAPER.k).unwrap(),
        ViscousDamper::new(PAPER.c).unwrap(),
        DryFriction::sqrt(PAPER.t, PAPER.eps).unwrap(),
        contact,
    );
    let spec = LawSpec::new().analytic_partials().kink_x(X_I).kink_v(0.0);
    let cfg = CheckConfig::new(x_near(X_I), v_axis(), spec).unwrap();
    for (sx, sv, wrt) in [
        (1.0 + 1e-5, 1.0, Variable::X),
        (1.0, 1.0 + 1e-5, Variable::V),
    ] {
        let e = reject(&ScaledPartials(laws, sx, sv), &cfg);
        assert!(
            matches!(e, LawViolation::WrongPartial { wrt: w, .. } if w == wrt),
            "{e}"
        );
    }
}

/// Hunt–Crossley contact `k·δ^{3/2}(1 + α·v)` without the clamp: it pulls when `v < −1/α`.
struct UnclampedHuntCrossley {
    x_i: f64,
    k: f64,
    alpha: f64,
}
impl ForceLaw<f64> for UnclampedHuntCrossley {
    fn force(&self, x: f64, v: f64) -> f64 {
        let d = x - self.x_i;
        if d <= 0.0 {
            0.0
        } else {
            self.k * d * d.sqrt() * (1.0 + self.alpha * v)
        }
    }
}

#[test]
fn adhesive_contact_is_rejected() {
    let law = UnclampedHuntCrossley {
        x_i: X_I,
        k: K_I,
        alpha: 1.5,
    };
    let e = reject(&law, &contact_only(Side::Upper, X_I));
    assert_eq!(e.property(), Property::NonAdhesive, "{e}");
    let (x, v) = e.point();
    assert!(x > X_I && v < -1.0 / 1.5, "{e}");
    // A contact force of the wrong sign everywhere.
    let mirrored = paper_contact(Side::Lower, 0.0);
    struct Negated(HertzContact<f64>);
    impl ForceLaw<f64> for Negated {
        fn force(&self, x: f64, v: f64) -> f64 {
            -self.0.force(x, v)
        }
    }
    let e = reject(
        &Negated(mirrored),
        &contact_only(Side::Lower, mirrored.stop()),
    );
    assert_eq!(e.property(), Property::NonAdhesive, "{e}");
}

/// `k_I·(δ^{3/2} + 10⁻³)` in contact: a force jump at onset.
struct JumpAtOnset;
impl ForceLaw<f64> for JumpAtOnset {
    fn force(&self, x: f64, _v: f64) -> f64 {
        let d = x - X_I;
        if d <= 0.0 {
            0.0
        } else {
            K_I * (d * d.sqrt() + 1e-3)
        }
    }
    fn partials(&self, x: f64, _v: f64) -> (f64, f64) {
        let d = x - X_I;
        if d <= 0.0 {
            (0.0, 0.0)
        } else {
            (1.5 * K_I * d.sqrt(), 0.0)
        }
    }
}

/// `k_I·(δ^{3/2} + 10⁻¹⁵)`: a jump of 0.24 µN — 3 % of the force at the smallest grid
/// penetration (1 nm), above the onset tolerance of 1 %.
struct TinyJumpAtOnset;
impl ForceLaw<f64> for TinyJumpAtOnset {
    fn force(&self, x: f64, _v: f64) -> f64 {
        let d = x - X_I;
        if d <= 0.0 {
            0.0
        } else {
            K_I * (d * d.sqrt() + 1e-15)
        }
    }
}

#[test]
fn discontinuous_contact_onset_is_rejected() {
    let cfg = contact_config(Side::Upper, X_I, false);
    let e = reject(&JumpAtOnset, &cfg);
    assert_eq!(e.property(), Property::OnsetContinuity, "{e}");
    let LawViolation::DiscontinuousOnset {
        penetration,
        force,
        reference_penetration,
        ..
    } = e
    else {
        panic!("{e:?}")
    };
    assert!(penetration < 1e-14 && reference_penetration <= 1.0001e-9);
    assert!((force / (K_I * 1e-3) - 1.0).abs() < 1e-6);
    let e = reject(&TinyJumpAtOnset, &contact_only(Side::Upper, X_I));
    assert_eq!(e.property(), Property::OnsetContinuity, "{e}");
}

/// Friction `T·v/|v|`: NaN at `v = 0`.
struct SignFriction(f64);
impl ForceLaw<f64> for SignFriction {
    fn force(&self, _x: f64, v: f64) -> f64 {
        self.0 * v / v.abs()
    }
}

/// A spring with a NaN partial at negative `x`.
struct NanPartial;
impl ForceLaw<f64> for NanPartial {
    fn force(&self, x: f64, _v: f64) -> f64 {
        2.0 * x
    }
    fn partials(&self, x: f64, _v: f64) -> (f64, f64) {
        (if x < 0.0 { f64::NAN } else { 2.0 }, 0.0)
    }
}

#[test]
fn nan_in_the_domain_is_rejected() {
    let cfg = CheckConfig::new(x_wide(), v_axis(), LawSpec::new().dissipative()).unwrap();
    let e = reject(&SignFriction(0.63133), &cfg);
    assert_eq!(e.property(), Property::Finite, "{e}");
    assert_eq!(e.point().1, 0.0);
    assert!(matches!(e, LawViolation::NonFiniteForce { force, .. } if force.is_nan()));
    // Finiteness is checked even when nothing else is claimed, for partials too.
    let cfg = CheckConfig::new(x_wide(), v_axis(), LawSpec::new()).unwrap();
    let e = reject(&NanPartial, &cfg);
    assert_eq!(e.property(), Property::Finite, "{e}");
    assert!(matches!(e, LawViolation::NonFinitePartials { x, .. } if x < 0.0));
    // NaN only at a few random points (not on the grid) is still found.
    struct NanInWindow;
    impl ForceLaw<f64> for NanInWindow {
        fn force(&self, x: f64, _v: f64) -> f64 {
            if (1.31e-3..1.37e-3).contains(&x) {
                f64::NAN
            } else {
                x
            }
        }
    }
    let e = reject(&NanInWindow, &cfg);
    assert_eq!(e.property(), Property::Finite, "{e}");
}

#[test]
fn force_when_separated_is_rejected() {
    /// `k_I·|δ|^{3/2}` on both sides of the stop.
    struct TwoSided;
    impl ForceLaw<f64> for TwoSided {
        fn force(&self, x: f64, _v: f64) -> f64 {
            let d = (x - X_I).abs();
            K_I * d * d.sqrt()
        }
    }
    let e = reject(&TwoSided, &contact_only(Side::Upper, X_I));
    assert_eq!(e.property(), Property::SeparatedZero, "{e}");
    assert!(e.point().0 < X_I);
    // A correct upper contact declared as a lower one.
    let e = reject(
        &paper_contact(Side::Upper, 0.0),
        &contact_config(Side::Lower, X_I, true),
    );
    assert_eq!(e.property(), Property::SeparatedZero, "{e}");
}

// ---------------------------------------------------------------------------------------
// proptest invariants of the built-in laws.

fn contact_domain(stop: f64) -> CheckConfig {
    CheckConfig::new(x_near(stop), v_axis(), LawSpec::new()).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn contact_is_zero_when_separated(
        sep in 1e-12_f64..1e-2,
        v in -1.0_f64..1.0,
        eta in prop_oneof![Just(0.0), Just(1e-9), 1e-10_f64..1e-6],
    ) {
        let up = paper_contact(Side::Upper, eta);
        prop_assert_eq!(up.force(X_I - sep, v), 0.0);
        let lo = paper_contact(Side::Lower, eta);
        prop_assert_eq!(lo.force(-X_I + sep, v), 0.0);
    }

    #[test]
    fn contact_pushes_out_of_the_stop((x, v) in points_in(&contact_domain(X_I))) {
        prop_assert!(paper_contact(Side::Upper, 0.0).force(x, v) >= 0.0);
        prop_assert!(paper_contact(Side::Lower, 0.0).force(-x, -v) <= 0.0);
    }

    #[test]
    fn contact_is_monotone_in_penetration_at_rest(
        a in -12.0_f64..-3.0,
        b in -12.0_f64..-3.0,
        eta in prop_oneof![Just(0.0), Just(1e-9)],
    ) {
        let (d1, d2) = (10f64.powf(a.min(b)), 10f64.powf(a.max(b)));
        let up = paper_contact(Side::Upper, eta);
        prop_assert!(up.force(X_I + d1, 0.0) <= up.force(X_I + d2, 0.0));
        let lo = paper_contact(Side::Lower, eta);
        prop_assert!(lo.force(-X_I - d1, 0.0).abs() <= lo.force(-X_I - d2, 0.0).abs());
    }

    #[test]
    fn friction_is_bounded_by_its_magnitude(
        v in prop_oneof![-1e3_f64..1e3, -1e-5_f64..1e-5],
        t in 0.0_f64..10.0,
        eps in 1e-9_f64..1e-2,
    ) {
        for law in [DryFriction::sqrt(t, eps).unwrap(), DryFriction::tanh(t, eps).unwrap()] {
            let f = law.force(0.0, v);
            // |v|/√(v²+ε²) ≤ 1 exactly, but T·v is rounded before the division: for ε ≪ |v|
            // the result may exceed T by one rounding (seen: T = 7.26562476379122,
            // v = −621.27, ε = 1e-9 gives |F| = T + 1 ulp). Two ulps of T bound that.
            prop_assert!(f.abs() <= t * (1.0 + 4.0 * f64::EPSILON), "{:?}: F({}) = {}", law, v, f);
        }
    }

    #[test]
    fn dampers_and_friction_are_dissipative(
        (x, v) in points_in(&CheckConfig::new(x_wide(), v_axis(), LawSpec::new()).unwrap()),
        c in 0.0_f64..100.0,
        t in 0.0_f64..10.0,
    ) {
        let laws = (
            ViscousDamper::new(c).unwrap(),
            DryFriction::sqrt(t, 1e-6).unwrap(),
            DryFriction::tanh(t, 1e-6).unwrap(),
        );
        prop_assert!(laws.force(x, v) * v >= 0.0);
        prop_assert!(laws.0.force(x, v) * v >= 0.0);
        prop_assert!(laws.1.force(x, v) * v >= 0.0);
        prop_assert!(laws.2.force(x, v) * v >= 0.0);
    }
}
