//! The lane forms of the parts against their scalar forms, to the bit (`LaneMath::Exact`):
//! every built-in force law and excitation, tuples of laws, and the right-hand sides of
//! `Oscillator` and `Mechanical` (diagonal and full mass matrices, `K`/`C`, relative and
//! general coordinates), each lane with its own parameters, over free, contact and
//! sticking (`v = 0`) states.

use nalgebra::{SMatrix, SVector};
use nonsmooth::excite::{Constant, Harmonic, LaneExcitation, RampedRotor, UnbalancedRotor};
use nonsmooth::force::{
    Bilinear, CubicSpring, DryFriction, HertzContact, LaneLaw, LinearSpring, Polynomial, Side,
    ViscousDamper,
};
use nonsmooth::lanes::{F64x8, LaneMath, Lanes};
use nonsmooth::model::{Coordinate, Element, Load, Mechanical, Oscillator};
use nonsmooth::{LaneByLane, LaneDynamics};
use proptest::prelude::*;

type V = F64x8;
const L: usize = 8;

/// Bits of a lane vector.
fn lanes(v: V) -> [u64; L] {
    core::array::from_fn(|i| v.lane(i).to_bits())
}

/// A state component that is often exactly 0 (sticking), sometimes tiny, else ordinary.
fn component() -> impl Strategy<Value = f64> {
    prop_oneof![
        1 => Just(0.0),
        1 => Just(-0.0),
        2 => -1e-9..1e-9f64,
        6 => -5e-3..5e-3f64,
        2 => -2.0..2.0f64,
    ]
}

/// Checks `law_of(params_i)` packed in lane `i` against each scalar law.
fn check_law<W: LaneLaw>(laws: &[W], xs: &[f64], vs: &[f64], math: LaneMath) {
    let mut p = laws[0].pack::<V>();
    for (i, w) in laws.iter().enumerate() {
        w.pack_lane(&mut p, i);
    }
    let f = W::force_lanes(&p, math, V::load(xs), V::load(vs));
    let want: [u64; L] = core::array::from_fn(|i| laws[i].force(xs[i], vs[i]).to_bits());
    assert_eq!(lanes(f), want, "x = {xs:?}, v = {vs:?}");
}

fn states() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    (
        prop::collection::vec(component(), L),
        prop::collection::vec(component(), L),
    )
}

/// A Hertz stop `(x_i, k_i, b, n1, n2, n3, η, lower side)`.
type HertzParams = (f64, f64, f64, f64, f64, f64, f64, bool);

fn hertz((x_i, k_i, b, n1, n2, n3, eta, lower): HertzParams) -> HertzContact<f64> {
    HertzContact::new(x_i, k_i)
        .unwrap()
        .with_side(if lower { Side::Lower } else { Side::Upper })
        .with_stiffness_exponent(n1)
        .unwrap()
        .with_damping(b, n2, n3)
        .unwrap()
        .with_rate_regularization(eta)
        .unwrap()
}

fn exponent() -> impl Strategy<Value = f64> {
    prop_oneof![Just(1.0), Just(1.5), Just(2.0), 0.5..2.5f64]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn hertz_contact(
        (xs, vs) in states(),
        params in prop::collection::vec(
            (-2e-3..2e-3f64, 1e6..1e9f64, prop_oneof![Just(0.0), 0.0..2.0f64],
             exponent(), exponent(), prop_oneof![Just(1.0), 0.1..1.5f64],
             prop_oneof![Just(0.0), Just(1e-8), 1e-6..1e-2f64], any::<bool>()),
            L),
    ) {
        let laws: Vec<_> = params
            .iter()
            .map(|&p| hertz(p))
            .collect();
        check_law(&laws, &xs, &vs, LaneMath::Exact);
    }

    /// Every lane a damped Hertz stop above with `n1 = n2 = 3/2` and no regularization
    /// (the lane form's own path for that shape), `n3 = 1` or not per lane, in both math
    /// modes (exact: to the bit; vector: the same where `n3 = 1` in every lane).
    #[test]
    fn hertz_contact_uniform(
        (xs, vs) in states(),
        params in prop::collection::vec(
            (-2e-3..2e-3f64, 1e6..1e9f64, 1e-3..2.0f64, prop_oneof![Just(1.0), 0.1..1.5f64]),
            L),
        all_linear in any::<bool>(),
    ) {
        let laws: Vec<_> = params
            .iter()
            .map(|&(x_i, k_i, b, n3)| {
                hertz((x_i, k_i, b, 1.5, 1.5, if all_linear { 1.0 } else { n3 }, 0.0, false))
            })
            .collect();
        check_law(&laws, &xs, &vs, LaneMath::Exact);
        if all_linear {
            check_law(&laws, &xs, &vs, LaneMath::Vector);
        }
    }

    #[test]
    fn dry_friction(
        (xs, vs) in states(),
        params in prop::collection::vec((0.0..5.0f64, 1e-6..1e-2f64, any::<bool>()), L),
    ) {
        let laws: Vec<_> = params
            .iter()
            .map(|&(t, eps, tanh)| if tanh { DryFriction::tanh(t, eps) } else { DryFriction::sqrt(t, eps) }.unwrap())
            .collect();
        check_law(&laws, &xs, &vs, LaneMath::Exact);
        check_law(&laws, &xs, &vs, LaneMath::Vector);
    }

    #[test]
    fn polynomial_laws(
        (xs, vs) in states(),
        params in prop::collection::vec((-10.0..10.0f64, -1e4..1e4f64, -1e-3..1e-3f64), L),
    ) {
        let springs: Vec<_> = params
            .iter()
            .map(|&(k, _, x0)| LinearSpring::new(k.abs()).unwrap().with_rest_position(x0).unwrap())
            .collect();
        check_law(&springs, &xs, &vs, LaneMath::Exact);
        let dampers: Vec<_> = params.iter().map(|&(c, _, _)| ViscousDamper::new(c.abs()).unwrap()).collect();
        check_law(&dampers, &xs, &vs, LaneMath::Exact);
        let cubics: Vec<_> = params
            .iter()
            .map(|&(k1, k3, x0)| CubicSpring::new(k1, k3).unwrap().with_rest_position(x0).unwrap())
            .collect();
        check_law(&cubics, &xs, &vs, LaneMath::Exact);
        let polys: Vec<_> = params
            .iter()
            .map(|&(a, b, x0)| Polynomial::new([a, b, 0.5, -a]).unwrap().with_rest_position(x0).unwrap())
            .collect();
        check_law(&polys, &xs, &vs, LaneMath::Exact);
    }

    #[test]
    fn bilinear(
        (xs, vs) in states(),
        params in prop::collection::vec((0.0..10.0f64, 0.0..1e4f64, -3e-3..0.0f64, 0.0..3e-3f64, 0..3u8), L),
    ) {
        let laws: Vec<_> = params
            .iter()
            .map(|&(k_in, k_out, lo, hi, kind)| match kind {
                0 => Bilinear::new(k_in, k_out, lo, hi).unwrap(),
                1 => Bilinear::one_sided(k_in, k_out, hi).unwrap(),
                _ => Bilinear::backlash(k_out, hi).unwrap(),
            })
            .collect();
        check_law(&laws, &xs, &vs, LaneMath::Exact);
    }

    /// The paper's law tuple: the sum in the scalar order.
    #[test]
    fn tuple_of_laws(
        (xs, vs) in states(),
        params in prop::collection::vec((0.0..1e3f64, 0.0..5.0f64, -2e-3..2e-3f64), L),
    ) {
        let laws: Vec<_> = params
            .iter()
            .map(|&(k, t, x_i)| {
                (
                    LinearSpring::new(k).unwrap(),
                    ViscousDamper::new(0.3).unwrap(),
                    DryFriction::sqrt(t, 1e-4).unwrap(),
                    hertz((x_i, 2.4e8, 0.85, 1.5, 1.5, 0.18667, 0.0, false)),
                )
            })
            .collect();
        check_law(&laws, &xs, &vs, LaneMath::Exact);
    }

    #[test]
    fn excitations(
        ts in prop::collection::vec(prop_oneof![Just(0.0), 0.0..1e3f64, Just(1e300)], L),
        params in prop::collection::vec((0.1..30.0f64, 0.0..10.0f64, -3.0..3.0f64), L),
    ) {
        fn check<E: LaneExcitation>(es: &[E], ts: &[f64]) {
            let mut p = es[0].pack::<V>();
            for (i, e) in es.iter().enumerate() {
                e.pack_lane(&mut p, i);
            }
            let f = E::force_lanes(&p, LaneMath::Exact, V::load(ts));
            let want: [u64; L] = core::array::from_fn(|i| es[i].force(ts[i]).to_bits());
            assert_eq!(lanes(f), want, "t = {ts:?}");
        }
        check(&params.iter().map(|&(w, a, ph)| Harmonic::new(a, w, ph).unwrap()).collect::<Vec<_>>(), &ts);
        check(&params.iter().map(|&(w, a, _)| UnbalancedRotor::new(a * 1e-3, w).unwrap()).collect::<Vec<_>>(), &ts);
        check(&params.iter().map(|&(_, a, _)| Constant::new(a).unwrap()).collect::<Vec<_>>(), &ts);
        check(&params.iter().map(|&(w, a, _)| RampedRotor::new(a * 1e-3, w, 8e-3).unwrap()).collect::<Vec<_>>(), &ts);
    }
}

/// The right-hand side of `model_i` packed in lane `i` against each scalar model.
fn check_model<D: LaneDynamics<M>, const M: usize>(models: &[D], t: &[f64], y: &[[f64; M]]) {
    let mut p = models[0].pack::<V>();
    for (i, m) in models.iter().enumerate() {
        m.pack_lane(&mut p, i);
    }
    let tv = V::load(t);
    let yv: [V; M] = core::array::from_fn(|c| V::load(&y.iter().map(|s| s[c]).collect::<Vec<_>>()));
    let time = D::time_lanes(&p, LaneMath::Exact, tv);
    let mut dy = [V::splat(0.0); M];
    D::rhs_lanes(&p, LaneMath::Exact, tv, &time, &yv, &mut dy);
    for (i, m) in models.iter().enumerate() {
        let mut want = SVector::<f64, M>::zeros();
        m.rhs(t[i], &SVector::from(y[i]), &mut want);
        for c in 0..M {
            assert_eq!(
                dy[c].lane(i).to_bits(),
                want[c].to_bits(),
                "lane {i}, component {c}: {} vs {}",
                dy[c].lane(i),
                want[c]
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// A 2-DOF impact damper: a full mass matrix, `K` and `C`, a relative Hertz stop, a
    /// general coordinate, a load on each DOF.
    #[test]
    fn mechanical_two_dof(
        t in prop::collection::vec(0.0..50.0f64, L),
        y in prop::collection::vec(prop::array::uniform4(component()), L),
        params in prop::collection::vec((0.5..2.0f64, 0.05..0.5f64, 1e-4..2e-3f64, 5.0..30.0f64), L),
        full_mass in any::<bool>(),
    ) {
        let models: Vec<_> = params
            .iter()
            .map(|&(m1, m2, gap, w)| {
                let base = if full_mass {
                    Mechanical::with_mass_matrix(SMatrix::<f64, 2, 2>::new(m1, 0.1 * m2, 0.1 * m2, m2)).unwrap()
                } else {
                    Mechanical::with_masses([m1, m2]).unwrap()
                };
                base.with_elements((
                    Element::on_dof(0, (LinearSpring::new(100.0 * m1).unwrap(), ViscousDamper::new(0.1).unwrap())).unwrap(),
                    Element::between(1, 0, hertz((gap, 1e7, 0.5, 1.5, 1.5, 0.3, 0.0, false))).unwrap(),
                    Element::new(
                        Coordinate::linear([0.5, -0.25]).unwrap().with_offset(1e-4).unwrap(),
                        CubicSpring::new(3.0, 1e4).unwrap(),
                    ),
                ))
                .with_loads((
                    Load::on_dof(0, Harmonic::new(1.0, w, 0.2).unwrap()).unwrap(),
                    Load::on_dof(1, Constant::new(-9.81 * m2).unwrap()).unwrap(),
                ))
                .with_stiffness(SMatrix::<f64, 2, 2>::new(5.0, -1.0, -1.0, 3.0))
                .unwrap()
                .with_damping(SMatrix::<f64, 2, 2>::new(0.01, 0.0, 0.0, 0.02))
                .unwrap()
            })
            .collect();
        let y: Vec<[f64; 4]> = y.into_iter().collect();
        check_model::<_, 4>(&models, &t, &y);
    }

    /// The paper's oscillator and its lane-by-lane fallback.
    #[test]
    fn oscillator_and_fallback(
        t in prop::collection::vec(0.0..50.0f64, L),
        y in prop::collection::vec(prop::array::uniform2(component()), L),
        omegas in prop::collection::vec(10.0..30.0f64, L),
    ) {
        let models: Vec<_> = omegas
            .iter()
            .map(|&w| nonsmooth::systems::paper::PAPER.oscillator::<f64>(w).unwrap())
            .collect();
        check_model::<_, 2>(&models, &t, &y);
        let fallback: Vec<_> = models.iter().map(|m| LaneByLane(*m)).collect();
        check_model::<_, 2>(&fallback, &t, &y);
        let duffing: Vec<_> = omegas
            .iter()
            .map(|&w| {
                Oscillator::new(
                    1.0,
                    (CubicSpring::new(0.0, 1.0).unwrap(), ViscousDamper::new(0.05).unwrap()),
                    Harmonic::new(7.5, w * 0.05, 0.0).unwrap(),
                )
                .unwrap()
            })
            .collect();
        check_model::<_, 2>(&duffing, &t, &y);
    }
}

/// What declares a constant time scale has the same one at every time (the ensemble then
/// bounds the steps in the lanes with the value at the start); what varies does not
/// declare it.
#[test]
fn constant_time_scales_are_constant() {
    use nonsmooth::Dynamics;
    use nonsmooth::event::{Direction, Event, EventFunction, EventSet, FnEvent, Gap, Level, Stop};
    use nonsmooth::excite::Excitation;
    let ts: Vec<f64> = (0..400)
        .map(|k| (k as f64 - 200.0) * 0.731 + 1e-3 * k as f64)
        .collect();
    let same = |f: &dyn Fn(f64) -> Option<f64>| ts.iter().all(|&t| f(t) == f(ts[0]));
    fn motion<S: Excitation<f64>>(s: &S) -> (bool, Vec<Option<f64>>) {
        let ts = (0..400).map(|k| (k as f64 - 200.0) * 0.731);
        (
            s.constant_time_scale(),
            ts.map(|t| s.time_scale(t)).collect(),
        )
    }
    let harmonic = Harmonic::new(0.7, 3.3, 0.4).unwrap();
    for (flag, values) in [
        motion(&()),
        motion(&Constant::new(-9.81).unwrap()),
        motion(&harmonic),
        motion(&UnbalancedRotor::new(0.018, 20.465).unwrap()),
    ] {
        assert!(flag);
        assert!(values.iter().all(|v| *v == values[0]), "{values:?}");
    }
    assert_eq!(
        motion(&harmonic).1[0],
        Some(std::f64::consts::TAU / (16.0 * 3.3))
    );
    let ramp = RampedRotor::new(0.018, 10.0, 0.5).unwrap();
    let (flag, values) = motion(&ramp);
    assert!(!flag && values.iter().any(|v| *v != values[0]));
    // Event functions and sets.
    let coord = Coordinate::<f64, 1>::linear([1.0]).unwrap();
    let table = Gap::<f64, 1, _>::above(coord, harmonic);
    let ramped = Gap::<f64, 1, _>::above(coord, ramp);
    assert!(EventFunction::<f64, 2>::constant_time_scale(&table));
    assert!(same(&|t| EventFunction::<f64, 2>::time_scale(&table, t)));
    assert!(!EventFunction::<f64, 2>::constant_time_scale(&ramped));
    let level = Level::new(0, 0.5).unwrap();
    let stop = Stop {
        position: 0,
        velocity: 1,
        level: 0.5,
    };
    let f = FnEvent(|t: f64, y: &SVector<f64, 2>| y[0] - t.sin());
    assert!(EventFunction::<f64, 2>::constant_time_scale(&level));
    assert!(EventFunction::<f64, 2>::constant_time_scale(&stop));
    assert!(EventFunction::<f64, 2>::constant_time_scale(&f));
    for g in [
        EventFunction::<f64, 2>::time_scale(&level, 3.0),
        EventFunction::<f64, 2>::time_scale(&stop, 3.0),
        EventFunction::<f64, 2>::time_scale(&f, 3.0),
    ] {
        assert_eq!(g, None);
    }
    let set = (
        Event::new(table, Direction::Rising),
        Event::new(level, Direction::Either),
    );
    assert!(EventSet::<f64, 2>::constant_max_step(&set));
    assert!(same(&|t| EventSet::<f64, 2>::max_step(&set, t)));
    assert!(EventSet::<f64, 2>::constant_max_step(&()));
    let varying = (set.0, Event::new(ramped, Direction::Rising));
    assert!(!EventSet::<f64, 2>::constant_max_step(&varying));
    // The models declare no time scale.
    let osc = nonsmooth::systems::paper::PAPER
        .oscillator::<f64>(20.0)
        .unwrap();
    assert!(osc.constant_time_scale() && same(&|t| osc.time_scale(t)));
    assert_eq!(osc.time_scale(1.0), None);
    let mech = Mechanical::with_masses([1.0])
        .unwrap()
        .with_loads(Load::on_dof(0, harmonic).unwrap());
    assert!(LaneDynamics::<2>::constant_time_scale(&mech));
    assert!(same(&|t| Dynamics::<f64, 2>::time_scale(&mech, t)));
    assert!(!LaneByLane(osc).constant_time_scale());
}
