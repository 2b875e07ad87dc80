//! `TurningPoints` on `Mechanical` systems: the one-DOF system declares its laws' cusp
//! exponent and contact onset (mapped from the law's coordinate to `x`), so it takes the
//! same steps as the `Oscillator`; for several degrees of freedom it declares nothing.

use nalgebra::{SVector, Vector2};
use nonsmooth::Dynamics;
use nonsmooth::drive::Simulation;
use nonsmooth::excite::UnbalancedRotor;
use nonsmooth::force::{ContactOnset, HertzContact, LinearSpring, Side, ViscousDamper};
use nonsmooth::integrate::{Dopri5, SegmentCounts, Stats, Tolerances, TurningPoints};
use nonsmooth::model::{Coordinate, Element, Elements, Load, Mechanical};
use nonsmooth::systems::paper::{PAPER, PaperMechanical, PaperParameters};

const OMEGA: f64 = 20.465;
const BAND: f64 = 3e-3;
/// The contact band δ* of the module docs' measurements.
const ONSET_BAND: f64 = 1e-5;

fn tol(rtol: f64) -> Tolerances<f64, 2> {
    Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2]).unwrap()
}

fn turning(onset: bool) -> TurningPoints<f64, Dopri5<f64, 2>, Dopri5<f64, 2>> {
    let st = TurningPoints::dopri5(tol(1e-8), BAND).unwrap();
    if onset {
        st.with_onset_band(ONSET_BAND).unwrap()
    } else {
        st
    }
}

/// A run with `TurningPoints`: the final state, the stats, the completed velocity segments
/// and all segment counts.
fn run<S: Dynamics<f64, 2>>(
    sys: S,
    onset: bool,
    y0: Vector2<f64>,
    t1: f64,
) -> (SVector<f64, 2>, Stats, u64, SegmentCounts) {
    let mut sim = Simulation::new(sys, turning(onset));
    let out = sim.run(0.0, y0, t1, &mut ()).unwrap();
    let st = sim.stepper();
    (out.y, out.stats, st.segments(), st.segment_counts())
}

fn bits(y: &SVector<f64, 2>) -> [u64; 2] {
    [y[0].to_bits(), y[1].to_bits()]
}

/// The paper's model with every element and the load on the reversed coordinate `g = −x`:
/// the mirror image `x' = −x` of the paper's model (its laws see `g = x` exactly, and its
/// forces are the paper's negated).
fn mirrored(p: &PaperParameters) -> PaperMechanical<f64> {
    let g = Coordinate::dof(0).unwrap().reversed();
    Mechanical::with_masses([p.m])
        .unwrap()
        .with_elements(Element::new(g, p.laws().unwrap()))
        .with_loads(Load {
            coordinate: g,
            excitation: UnbalancedRotor::new(p.m0e, OMEGA).unwrap(),
        })
}

/// `PaperMechanical` and `PaperOscillator` under `TurningPoints`: the same steps (stats,
/// segment counts) and the same final state to the bit, over three periods from the
/// static equilibrium, with the exact law (η = 0) and the default η, with and without the
/// contact band.
#[test]
fn paper_mechanical_takes_the_oscillators_steps() {
    let t1 = 3.0 * PaperParameters::period(OMEGA);
    for p in [PaperParameters { eta: 0.0, ..PAPER }, PAPER] {
        let osc = p.oscillator::<f64>(OMEGA).unwrap();
        let mech = p.mechanical::<f64>(OMEGA).unwrap();
        assert_eq!(Dynamics::<f64, 2>::velocity_exponent(&mech), Some(p.n3));
        assert_eq!(
            Dynamics::<f64, 2>::contact_onset(&mech),
            osc.contact_onset()
        );
        assert!(osc.contact_onset().is_some());
        let y0 = Vector2::new(p.static_equilibrium().unwrap(), 0.0);
        for onset in [false, true] {
            let (y_o, s_o, n_o, c_o) = run(osc, onset, y0, t1);
            let (y_m, s_m, n_m, c_m) = run(mech, onset, y0, t1);
            let what = format!("η = {}, onset band {onset}", p.eta);
            // The runs are worth comparing: segments of both kinds were taken.
            assert!(n_o >= 5, "{what}: {c_o:?}");
            if onset {
                assert!(c_o.contact_completed >= 2, "{what}: {c_o:?}");
            } else {
                assert_eq!(c_o.contact_completed + c_o.contact_abandoned, 0);
            }
            assert_eq!(
                (s_m.accepted, s_m.rejected, s_m.rhs_evals),
                (s_o.accepted, s_o.rejected, s_o.rhs_evals),
                "{what}"
            );
            assert_eq!(s_m, s_o, "{what}");
            assert_eq!(n_m, n_o, "{what}");
            assert_eq!(c_m, c_o, "{what}");
            assert_eq!(bits(&y_m), bits(&y_o), "{what}: {y_m:?} vs {y_o:?}");
        }
    }
}

/// A stop on the reversed coordinate is a stop on the other side in `x`; the mirrored
/// paper's model declares it there and runs as the mirror image of the oscillator: the
/// negated state to the bit, the same steps and segments (contact segments included).
#[test]
fn the_mirrored_model_runs_as_the_mirror_image() {
    let p = PaperParameters { eta: 0.0, ..PAPER };
    let mech = mirrored(&p);
    assert_eq!(Dynamics::<f64, 2>::velocity_exponent(&mech), Some(p.n3));
    assert_eq!(
        Dynamics::<f64, 2>::contact_onset(&mech),
        Some(ContactOnset {
            position: -p.x_i,
            side: Side::Lower,
            exponent: p.n1,
        })
    );
    let osc = p.oscillator::<f64>(OMEGA).unwrap();
    let y0 = Vector2::new(p.static_equilibrium().unwrap(), 0.0);
    let t1 = 3.0 * PaperParameters::period(OMEGA);
    for onset in [false, true] {
        let (y_o, s_o, n_o, c_o) = run(osc, onset, y0, t1);
        let (y_m, s_m, n_m, c_m) = run(mech, onset, -y0, t1);
        assert!(n_o >= 5, "{c_o:?}");
        assert_eq!(s_m, s_o, "onset band {onset}");
        assert_eq!(n_m, n_o, "onset band {onset}");
        assert_eq!(c_m, c_o, "onset band {onset}");
        assert_eq!(bits(&y_m), bits(&(-y_o)), "onset band {onset}");
    }
}

/// The force of a one-DOF system's elements at `(x, 0)` without loads.
fn force<El: Elements<f64, 1>>(m: &Mechanical<f64, 1, El>, x: f64) -> f64 {
    let mut dy = SVector::<f64, 2>::zeros();
    m.rhs(0.0, &Vector2::new(x, 0.0), &mut dy);
    dy[1]
}

/// Stops on reversed, offset and scaled coordinates are mapped to `x`: `x_I = (g_I − o)/w`,
/// the side flipped for `w < 0`, the exponent kept; the force is on exactly where the mapped
/// penetration is positive.
#[test]
fn onsets_on_reversed_offset_and_scaled_coordinates_are_mapped() {
    let (g_i, o) = (1e-3, 0.25);
    let law = HertzContact::new(g_i, 1e7)
        .unwrap()
        .with_damping(0.5, 1.25, 0.3)
        .unwrap();
    let dof = Coordinate::<f64, 1>::dof(0).unwrap();
    let cases = [
        (dof, Side::Upper, g_i),
        (dof.reversed(), Side::Lower, -g_i),
        (dof.with_offset(o).unwrap(), Side::Upper, g_i - o),
        (
            dof.with_offset(o).unwrap().reversed(),
            Side::Lower,
            -(g_i + o),
        ),
        (Coordinate::linear([2.0]).unwrap(), Side::Upper, g_i / 2.0),
        (Coordinate::linear([-0.5]).unwrap(), Side::Lower, -2.0 * g_i),
    ];
    for (c, side, position) in cases {
        let on_side = |l: HertzContact<f64>| {
            Mechanical::with_masses([1.0])
                .unwrap()
                .with_elements(Element::new(c, l))
        };
        for law in [law, law.with_side(Side::Lower)] {
            let m = on_side(law);
            let side = if law.side() == Side::Upper {
                side
            } else if side == Side::Upper {
                Side::Lower
            } else {
                Side::Upper
            };
            let onset = Dynamics::<f64, 2>::contact_onset(&m).unwrap();
            assert_eq!(onset.side, side, "{c:?}");
            assert_eq!(onset.position, position, "{c:?}");
            // The damping's n2 = 1.25 is the smaller exponent.
            assert_eq!(onset.exponent, 1.25);
            assert_eq!(Dynamics::<f64, 2>::velocity_exponent(&m), Some(0.3));
            for d in [-1e-4, -1e-6, 1e-6, 1e-4] {
                let x = position + d;
                let f = force(&m, x);
                assert_eq!(
                    f != 0.0,
                    onset.penetration(x) > 0.0,
                    "{c:?}, {:?}: x = {x}, F = {f}",
                    law.side()
                );
            }
        }
    }
    // A stop whose image in x is not finite ((g_I − o)/w overflows) is skipped; the cusp
    // is still declared.
    let tiny = Mechanical::with_masses([1.0])
        .unwrap()
        .with_elements(Element::new(
            Coordinate::linear([1e-300]).unwrap(),
            HertzContact::new(1e10, 1e7)
                .unwrap()
                .with_damping(0.5, 1.25, 0.3)
                .unwrap(),
        ));
    assert_eq!(Dynamics::<f64, 2>::contact_onset(&tiny), None);
    assert_eq!(Dynamics::<f64, 2>::velocity_exponent(&tiny), Some(0.3));
    // Loads do not change the declarations; a law without a cusp or a stop declares none.
    let plain = Mechanical::with_masses([1.0]).unwrap().with_elements(
        Element::on_dof(
            0,
            (
                LinearSpring::new(4.0).unwrap(),
                ViscousDamper::new(0.1).unwrap(),
            ),
        )
        .unwrap(),
    );
    assert_eq!(Dynamics::<f64, 2>::velocity_exponent(&plain), None);
    assert_eq!(Dynamics::<f64, 2>::contact_onset(&plain), None);
    let loaded = plain
        .with_elements(Element::new(dof.reversed(), law))
        .with_loads(Load::on_dof(0, UnbalancedRotor::new(0.01, OMEGA).unwrap()).unwrap());
    assert_eq!(
        Dynamics::<f64, 2>::contact_onset(&loaded).map(|o| (o.position, o.side)),
        Some((-g_i, Side::Lower))
    );
}

/// Several elements: the smallest exponent of all, the first onset in element order.
#[test]
fn several_elements_declare_the_smallest_exponent_and_the_first_stop() {
    let dof = Coordinate::<f64, 1>::dof(0).unwrap();
    let upper = HertzContact::new(1e-3, 1e7)
        .unwrap()
        .with_damping(0.5, 1.5, 0.2)
        .unwrap();
    let lower = HertzContact::new(-2e-3, 1e7)
        .unwrap()
        .with_damping(0.5, 1.5, 0.4)
        .unwrap();
    let m = Mechanical::with_masses([1.0]).unwrap().with_elements((
        Element::new(dof, LinearSpring::new(4.0).unwrap()),
        [Element::new(dof.reversed(), lower.with_side(Side::Lower))],
        Element::new(dof, upper),
    ));
    assert_eq!(Dynamics::<f64, 2>::velocity_exponent(&m), Some(0.2));
    let onset = Dynamics::<f64, 2>::contact_onset(&m).unwrap();
    assert_eq!((onset.position, onset.side), (2e-3, Side::Upper));
}

/// Two degrees of freedom: the system declares nothing (`TurningPoints` steps `(x, ẋ)`),
/// though its elements report their declarations per coordinate.
#[test]
fn two_degrees_of_freedom_declare_nothing() {
    let laws = PAPER.laws::<f64>().unwrap();
    let m = Mechanical::with_masses([PAPER.m, 1.0])
        .unwrap()
        .with_elements((
            Element::on_dof(0, laws).unwrap(),
            Element::between(1, 0, LinearSpring::new(100.0).unwrap()).unwrap(),
        ))
        .with_loads(Load::on_dof(0, UnbalancedRotor::new(PAPER.m0e, OMEGA).unwrap()).unwrap());
    assert_eq!(Dynamics::<f64, 4>::velocity_exponent(&m), None);
    assert_eq!(Dynamics::<f64, 4>::contact_onset(&m), None);
    let dof0 = Coordinate::<f64, 2>::dof(0).unwrap();
    let on_dof0 = |c: &Coordinate<f64, 2>| *c == dof0;
    assert_eq!(
        m.elements()
            .velocity_exponent_on(&|c, q| on_dof0(c).then_some(q)),
        Some(PAPER.n3)
    );
    let onset = m
        .elements()
        .contact_onset_on(&|c, o| on_dof0(c).then_some(o))
        .unwrap();
    assert_eq!((onset.position, onset.side), (PAPER.x_i, Side::Upper));
    assert_eq!(
        m.elements()
            .velocity_exponent_on(&|c, q| (!on_dof0(c)).then_some(q)),
        None
    );
}
