//! Regressions of the hostile probe (issue 27): each test names the defect it pins down.
//! Finite input never gives NaN or an infinity, out-of-range arguments are errors or
//! documented no-ops instead of panics, and invalid settings are rejected by name.

use nalgebra::{Matrix2, SVector, Vector2};
use nonsmooth::ForceLaw;
use nonsmooth::drive::Simulation;
use nonsmooth::event::{EventFunction, Level, ResetMap, Restitution};
use nonsmooth::excite::{Excitation, Harmonic, RampedRotor, UnbalancedRotor};
use nonsmooth::force::{DryFriction, LinearSpring, Regularization, ViscousDamper};
use nonsmooth::identify::{Parameter, ParameterSpace, Transform};
use nonsmooth::integrate::{Dopri5, Rosenbrock23, Tolerances};
use nonsmooth::lyapunov::tangent_tolerances;
use nonsmooth::model::{Element, Load, Mechanical, ModelError};
use nonsmooth::orbit::{ContinuationSettings, Extremum, Grazing, OrbitError, Shooting, follow};
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

/// Defect 3: `Harmonic` with ω ≈ 1e306 and `RampedRotor`/`UnbalancedRotor` with extreme
/// parameters gave NaN from `force`/`force_rate` (sin of an overflowed phase, `inf·0`).
#[test]
fn excitations_are_finite_for_finite_time() {
    let times = [
        0.0,
        1e-300,
        0.37,
        1000.0,
        -1000.0,
        1e15,
        1e200,
        -1e300,
        f64::MAX,
    ];
    let finite = |name: &str, e: &dyn Excitation<f64>| {
        for &t in &times {
            let (f, r) = (e.force(t), e.force_rate(t));
            assert!(
                f.is_finite() && r.is_finite(),
                "{name} at t = {t:e}: {f}, {r}"
            );
        }
    };
    for (amplitude, omega) in [(1.0, 1e306), (0.0, 1e306), (1e-300, 1e300), (2.0, 7.0)] {
        let h = Harmonic::new(amplitude, omega, 0.3).unwrap();
        finite(&format!("Harmonic({amplitude:e}, {omega:e})"), &h);
        assert!(h.force(1000.0).abs() <= amplitude);
    }
    // The force rate's amplitude A·ω must be finite.
    assert!(Harmonic::new(1e10, 1e306, 0.0).is_err());
    for (m0e, omega) in [(0.0, 1e306), (1e-300, 1e100), (0.01805, 20.0)] {
        let r = UnbalancedRotor::new(m0e, omega).unwrap();
        finite(&format!("UnbalancedRotor({m0e:e}, {omega:e})"), &r);
    }
    let mut ramps = 0;
    for m0e in [0.0, 1e-300, 1e-10, 0.01805, 1e10] {
        for omega0 in [1e-300, 1e-3, 14.0, 1e100, 1e300] {
            for rate in [-1e300, -8.0905e-3, 0.0, 8.0905e-3, 1.0, 1e300] {
                if let Ok(r) = RampedRotor::new(m0e, omega0, rate) {
                    finite(&format!("RampedRotor({m0e:e}, {omega0:e}, {rate:e})"), &r);
                    ramps += 1;
                }
            }
        }
    }
    assert!(ramps > 60, "{ramps}");
    // Ordinary parameters: unchanged (the paper's ramp against its closed form).
    let r = RampedRotor::new(0.01805, 14.0, 8.0905e-3).unwrap();
    let t: f64 = 12.3;
    let (w, phi) = (14.0 + 8.0905e-3 * t, (14.0 + 0.5 * 8.0905e-3 * t) * t);
    let exact = 0.01805 * (w * w * phi.sin() - 8.0905e-3 * phi.cos());
    assert!((r.force(t) - exact).abs() < 1e-12 * exact.abs().max(1.0));
    // The force at t = 0 is −m0e·rate: it must be finite.
    assert!(RampedRotor::new(1e300, 1e-20, 1e10).is_err());
    // f32: the phase overflows f32 long before f64.
    let h = Harmonic::<f32>::new(1.0, 1e30, 0.0).unwrap();
    assert!(h.force(1e9).is_finite() && h.force_rate(1e9).is_finite());
}

/// Defect 4: `DryFriction` at (x, v) = (1e300, 1e-121) gave a NaN partial (`T·ε²/s^{3/2}`
/// with `s^{3/2}` underflowing to 0), and `v²` overflow gave a zero or NaN force.
#[test]
fn dry_friction_partials_are_finite() {
    let speeds = [
        0.0,
        1e-121,
        -1e-121,
        5e-324,
        1e-300,
        1e-6,
        -1.0,
        1e150,
        -1e200,
        1e300,
        f64::MAX,
        -f64::MAX,
    ];
    let mut laws = 0;
    for t in [0.0_f64, 1e-300, 0.63133, 1e10, 1e300] {
        for eps in [1.5e-154_f64, 1e-150, 1e-6, 1.0, 1e100, 1e154] {
            for reg in [Regularization::Sqrt, Regularization::Tanh] {
                let Ok(f) = DryFriction::new(t, eps, reg) else {
                    // Only a slope T/ε at v = 0 beyond the range is rejected.
                    assert!(!(t / eps).is_finite(), "T = {t:e}, ε = {eps:e}");
                    continue;
                };
                laws += 1;
                for &v in &speeds {
                    let force = f.force(1e300, v);
                    let (dx, dv) = f.partials(1e300, v);
                    assert!(
                        force.is_finite() && dx.is_finite() && dv.is_finite(),
                        "{f:?} at v = {v:e}: {force}, ({dx}, {dv})"
                    );
                    assert!(
                        force.abs() <= t * (1.0 + 4.0 * f64::EPSILON),
                        "{f:?} at v = {v:e}: {force}"
                    );
                    assert!(
                        (0.0..=t / eps * (1.0 + 1e-15)).contains(&dv),
                        "{f:?} at v = {v:e}: {dv}"
                    );
                    // Far outside the layer the force is ±T.
                    if v.abs() >= 1e150 && v.abs() > 1e20 * eps {
                        assert!(
                            (force - t * v.signum()).abs() <= 4.0 * f64::EPSILON * t,
                            "{f:?} at v = {v:e}: {force}"
                        );
                    }
                }
            }
        }
    }
    assert!(laws > 40, "{laws}");
    // The probe's point, with a regularization scale whose ε² is near the underflow limit.
    let f = DryFriction::sqrt(1.0, 1e-150).unwrap();
    let (_, dv) = f.partials(1e300, 1e-121);
    let want = (1e-150_f64 / 1e-121).powi(2) / 1e-121; // ε²/v³ = 1e63

    assert!((dv / want - 1.0).abs() < 1e-12, "{dv:e} vs {want:e}");
    // The paper's law is unchanged.
    let paper = DryFriction::sqrt(0.63133, 1e-6).unwrap();
    let (v, e2): (f64, f64) = (3e-6, 1e-6 * 1e-6);
    let s = v * v + e2;
    assert_eq!(paper.partials(0.0, v).1, 0.63133 * e2 / (s * s.sqrt()));
}

/// Defect 5: `ParameterSpace` round trips failed at ±f64::MAX (NaN, infinite `u`, a sign
/// flip for a bound at −MAX) and at subnormal values (a `Log` parameter came back as the
/// smallest normal number; a subnormal value between −1 and 1 came back as 0).
#[test]
fn parameter_space_round_trips_at_the_ends_of_the_range() {
    let m = f64::MAX;
    let base = [
        m,
        -m,
        0.0,
        1.0,
        -1.0,
        5e-324,
        -5e-324,
        1e-310,
        -1e-310,
        f64::MIN_POSITIVE,
        1e300,
        -1e300,
        1e-300,
        3.7,
        m / 3.0,
        -m / 7.0,
    ];
    let values: Vec<f64> = base
        .iter()
        .copied()
        .chain(base.iter().map(|x| x * 0.999))
        .collect();
    let mut checked = 0;
    for &x0 in &values {
        for &b in &values {
            for p in [
                Parameter::new("x", x0),
                Parameter::positive("x", x0),
                Parameter::new("x", x0).with_lower(b),
                Parameter::new("x", x0).with_upper(b),
                Parameter::new("x", x0).with_bounds(-b, b),
                Parameter::new("x", x0).with_bounds(b, m),
                Parameter::new("x", x0).with_bounds(-m, b),
                Parameter::positive("x", x0).with_lower(b),
                Parameter::positive("x", x0).with_upper(b),
                Parameter::positive("x", x0).with_bounds(5e-324, b),
            ] {
                let Ok(space) = ParameterSpace::new([p.clone()]) else {
                    continue;
                };
                let (lo, hi) = p.bounds();
                for &x in &values {
                    let Ok(u) = space.to_unconstrained(&[x]) else {
                        continue; // outside the bounds, or not positive under Log
                    };
                    assert!(u[0].is_finite(), "{p:?}: {x:e} -> {}", u[0]);
                    let back = space
                        .to_physical(&u)
                        .unwrap_or_else(|e| panic!("{p:?}: {x:e} -> {:e}: {e}", u[0]))
                        .values()[0];
                    assert!(
                        back >= lo.unwrap_or(-m) && back <= hi.unwrap_or(m),
                        "{p:?}: {x:e} -> {back:e}"
                    );
                    let ok = if p.transform() == Transform::Log {
                        // A few ulps of ln x, ln(bounds) and the map's scale (≲ 3000).
                        (back / x - 1.0).abs() <= 4e-12 || (back - x).abs() <= 2e-323
                    } else {
                        let scale = [Some(x), lo, hi, Some(p.initial())]
                            .into_iter()
                            .flatten()
                            .fold(0.0_f64, |a, v| a.max(v.abs()));
                        (back - x).abs() <= 16.0 * f64::EPSILON * scale
                            || (back - x).abs() <= 2e-323
                    };
                    assert!(ok, "{p:?}: {x:e} -> {:e} -> {back:e}", u[0]);
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 20_000, "{checked}");
    // Exact or nearly so where the representation allows it: a value near the middle of
    // bounds at ±MAX, subnormal values near the middle of the bounds and under Log.
    let one = ParameterSpace::new([Parameter::new("x", 0.0).with_bounds(-m, m)]).unwrap();
    let back = one
        .to_physical(&one.to_unconstrained(&[1.0]).unwrap())
        .unwrap()
        .values()[0];
    assert!((back - 1.0).abs() <= f64::EPSILON, "{back}"); // was 0
    for (p, x) in [
        (Parameter::new("x", 0.0).with_bounds(-1.0, 1.0), 1e-310),
        (Parameter::positive("x", 1.0), 1e-310),
        (Parameter::positive("x", 1.0), 5e-324),
    ] {
        let space = ParameterSpace::new([p.clone()]).unwrap();
        let back = space
            .to_physical(&space.to_unconstrained(&[x]).unwrap())
            .unwrap()
            .values()[0];
        assert_eq!(back, x, "{p:?}");
    }
}

/// Defect 6: a deserialized `HertzContact` whose cached `(n3 − 1)/2` disagrees with `n3`
/// must not keep the cached value (it is rebuilt through the constructors).
#[cfg(feature = "serde")]
#[test]
fn deserialized_hertz_contact_recomputes_its_cached_exponent() {
    use nonsmooth::force::HertzContact;
    let h = HertzContact::new(-2.086e-3, 2.3983e8)
        .unwrap()
        .with_damping(0.8485, 1.5, 0.18667)
        .unwrap()
        .with_rate_regularization(1e-8)
        .unwrap();
    for bad in [3.0, -0.25, 1e300] {
        let mut v = serde_json::to_value(h).unwrap();
        v["half_n3_minus_1"] = serde_json::json!(bad);
        let back: HertzContact<f64> = serde_json::from_value(v).unwrap();
        assert_eq!(back, h);
        assert_eq!(back.force(0.0, 0.1), h.force(0.0, 0.1));
    }
}

/// Defect 7: mass matrices whose inverse overflowed were accepted (NaN/∞ stored), a tiny
/// well-conditioned one was called "singular", N = 0 ran into "step size too small", and a
/// chain of 400 masses overflowed the stack (now a compile error beyond `MAX_DOFS`, see
/// the `compile_fail` examples on `Mechanical`).
#[test]
fn mass_matrices_at_extreme_scales() {
    // A lumped mass whose inverse overflows.
    let e = Mechanical::with_masses([5e-324, 1.0]).unwrap_err();
    assert_eq!((e.name, e.value), ("mass", 5e-324), "{e}");
    // Tiny and huge well-conditioned matrices: accepted, with the right finite inverse.
    for s in [1e-170, 1e-300, 1e300] {
        let mass = Matrix2::new(2.0, 0.5, 0.5, 1.0) * s;
        let model = Mechanical::<f64, 2>::with_mass_matrix(mass)
            .unwrap_or_else(|e| panic!("scale {s:e}: {e}"));
        let inv = model.inverse_mass_matrix();
        assert!(inv.iter().all(|v| v.is_finite()), "scale {s:e}: {inv}");
        let want = Matrix2::new(1.0, -0.5, -0.5, 2.0) / (1.75 * s);
        for (a, b) in inv.iter().zip(want.iter()) {
            assert!(
                (a - b).abs() <= 1e-14 * b.abs(),
                "scale {s:e}: {inv} vs {want}"
            );
        }
        let diag =
            Mechanical::<f64, 2>::with_mass_matrix(Matrix2::from_diagonal(&Vector2::new(s, s)))
                .unwrap();
        let inv = diag.inverse_mass_matrix()[(1, 1)];
        assert!(
            (inv * s - 1.0).abs() <= 4.0 * f64::EPSILON,
            "scale {s:e}: {inv:e}"
        );
    }
    // A positive-definite matrix whose inverse is beyond the range: an error naming it.
    let tiny = Matrix2::from_diagonal(&Vector2::new(1e-310, 1.0));
    match Mechanical::<f64, 2>::with_mass_matrix(tiny) {
        Err(e @ ModelError::MassInverseOverflow { smallest_mass }) => {
            assert_eq!(smallest_mass, 1e-310);
            assert!(e.to_string().contains("1e-310"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    // The ordinary case is unchanged to the bit.
    let m = Matrix2::new(2.0, 0.3, 0.3, 1.5);
    let model = Mechanical::<f64, 2>::with_mass_matrix(m).unwrap();
    assert_eq!(*model.inverse_mass_matrix(), m.try_inverse().unwrap());
    assert_eq!(Mechanical::<f64, 2>::MAX_DOFS, 64);
}

/// Defect 7, size limit: a chain of `MAX_DOFS` masses is built and run with an implicit
/// stepper (Jacobians of 128×128) on a spawned thread's 2 MiB stack.
#[test]
fn largest_mechanical_system_runs_on_a_two_mib_stack() {
    fn chain() {
        const N: usize = 64;
        type Spring = Element<f64, N, (LinearSpring<f64>, ViscousDamper<f64>)>;
        let elements: [Spring; N] = std::array::from_fn(|i| {
            let law = (
                LinearSpring::new(10.0).unwrap(),
                ViscousDamper::new(0.1).unwrap(),
            );
            if i == 0 {
                Element::on_dof(0, law).unwrap()
            } else {
                Element::between(i, i - 1, law).unwrap()
            }
        });
        let model = Mechanical::<f64, N>::with_masses([1.0; N])
            .unwrap()
            .with_elements(elements)
            .with_loads(Load::on_dof(N - 1, Harmonic::new(1.0, 1.0, 0.0).unwrap()).unwrap());
        let y0 = SVector::<f64, { 2 * N }>::zeros();
        let tol = Tolerances::new(1e-6, 1e-8).unwrap();
        let explicit = Simulation::new(&model, Dopri5::new(tol))
            .run(0.0, y0, 1.0, &mut ())
            .unwrap();
        let implicit = Simulation::new(&model, Rosenbrock23::new(tol))
            .run(0.0, y0, 1.0, &mut ())
            .unwrap();
        assert!((explicit.y - implicit.y).amax() < 1e-4);
    }
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(chain)
        .unwrap()
        .join()
        .unwrap();
}

/// Defect 8: `orbit::follow` with a NaN grazing level reported grazing bifurcations (the
/// sign test of a NaN margin); the level must be finite and the component in range.
#[test]
fn continuation_rejects_a_nan_grazing_level() {
    type Model = Mechanical<
        f64,
        1,
        Element<f64, 1, (LinearSpring<f64>, ViscousDamper<f64>)>,
        Load<f64, 1, Harmonic<f64>>,
    >;
    let model = |w: f64| -> nonsmooth::Result<Model> {
        Ok(Mechanical::with_masses([1.0])?
            .with_elements(Element::on_dof(
                0,
                (LinearSpring::new(1.0)?, ViscousDamper::new(0.1)?),
            )?)
            .with_loads(Load::on_dof(0, Harmonic::cosine(0.5, w)?)?))
    };
    let tol = Tolerances::new(1e-10, 1e-12).unwrap();
    let build = |w: f64| {
        Ok(Shooting::new(
            model(w)?,
            (),
            tangent_tolerances::<f64, 2, 2, 6>(&tol, 1e-10, 1e-12)?,
        ))
    };
    let period = |w: f64| std::f64::consts::TAU / w;
    let settings = |g: Grazing| {
        ContinuationSettings::new(0.5, 0.8, 0.05)
            .unwrap()
            .with_grazing(g)
    };
    for (component, level) in [(0, f64::NAN), (0, f64::INFINITY), (2, 0.0)] {
        let g = Grazing {
            component,
            level,
            extremum: Extremum::Min,
        };
        for s in [
            settings(g),
            ContinuationSettings::new(0.5, 0.8, 0.05)
                .unwrap()
                .with_contact_changes(g),
        ] {
            match follow(build, period, 0.0, 0.5, SVector::zeros(), &s) {
                Err(OrbitError::InvalidSetting { what, value, .. }) => {
                    assert!(what.contains("grazing"), "{what}");
                    assert!(value.is_nan() == level.is_nan() || value == component as f64);
                }
                other => panic!("component {component}, level {level}: {other:?}"),
            }
        }
    }
    // A finite level far below the motion: no grazing on the branch.
    let far = Grazing {
        component: 0,
        level: -100.0,
        extremum: Extremum::Min,
    };
    let branch = follow(
        build,
        period,
        0.0,
        0.5,
        SVector::<f64, 2>::zeros(),
        &settings(far),
    )
    .unwrap();
    assert!(branch.bifurcations.is_empty(), "{:?}", branch.bifurcations);
    assert!(
        branch
            .points
            .iter()
            .all(|q| q.grazing_margin.unwrap() > 0.0)
    );
}
