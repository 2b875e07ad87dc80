//! Time-stepping (`nonsmooth::timestep`): the complementarity solvers on problems with known
//! solutions, and the Moreau–Jean scheme on the classic rigid-contact problems against
//! closed forms (bouncing ball, Housner's rocking block), against the event-driven engine
//! (ball on a vibrating table) and against conservation laws (Newton's cradle).

use nonsmooth::drive::Control;
use nonsmooth::timestep::lcp::{LcpError, Lemke, Nsgs, Pgs, frictional_contact_residual, residual};
use nonsmooth::timestep::{
    Contact, Geometry, ImpactLog, Jacobian, MoreauJean, PlanarBodies, PlanarContact, Plane,
    RigidBody, Solver, StepObserver, StepRecord, TimeStepError,
};

/// A seeded xorshift generator (uniform in [0, 1)).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Murty's family (K. G. Murty, *Linear Complementarity, Linear and Nonlinear Programming*,
/// 1988, §6.2): lower triangular, 1 on the diagonal and 2 below it.
fn murty(n: usize) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        m[i * n + i] = 1.0;
        for j in 0..i {
            m[i * n + j] = 2.0;
        }
    }
    m
}

/// Murty's right-hand side `q_i = −(2ⁿ + 2ⁿ⁻¹ + … + 2ⁿ⁻ⁱ)`, on which Lemke's method with
/// the covering vector `(1, …, 1)` makes `2ⁿ` pivots.
fn murty_q(n: usize) -> Vec<f64> {
    let mut acc = 0.0;
    (0..n)
        .map(|i| {
            acc += 2f64.powi((n - i) as i32);
            -acc
        })
        .collect()
}

/// The unique solution of LCP(M, q) for a lower-triangular M with a positive diagonal (a
/// P-matrix), by forward substitution: `z_i = max(0, −(q_i + Σ_{j<i} M_ij z_j)) / M_ii`.
fn triangular_solution(m: &[f64], q: &[f64]) -> Vec<f64> {
    let n = q.len();
    let mut z = vec![0.0; n];
    for i in 0..n {
        let s = q[i] + (0..i).map(|j| m[i * n + j] * z[j]).sum::<f64>();
        z[i] = (-s).max(0.0) / m[i * n + i];
    }
    z
}

#[test]
fn lemke_solves_murtys_family_exactly() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut lemke = Lemke::new().with_pivot_limit(1 << 14);
    let mut pivots = Vec::new();
    for n in 1..=10 {
        let m = murty(n);
        let mut cases = vec![murty_q(n), vec![-1.0; n]];
        for _ in 0..5 {
            cases.push((0..n).map(|_| 4.0 * rng.next() - 3.0).collect());
        }
        for (c, q) in cases.iter().enumerate() {
            let exact = triangular_solution(&m, q);
            let mut z = vec![0.0; n];
            let report = lemke.solve(&m, q, &mut z).unwrap();
            let err = z
                .iter()
                .zip(&exact)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(report.residual <= 1e-12, "n = {n}, case {c}: {report:?}");
            assert!(residual(&m, q, &z).unwrap() <= 1e-12);
            assert!(err <= 1e-12, "n = {n}, case {c}: error {err:e}");
            if c == 0 {
                pivots.push(report.iterations);
            }
        }
        // Murty's theorem: exactly 2ⁿ pivots on his right-hand side.
        assert_eq!(pivots[n - 1], 1 << n, "n = {n}");
    }
    println!("Lemke pivots on Murty's family, n = 1..10: {pivots:?}");
    // A pivot limit below the count needed is an error naming the limit, not an answer.
    let e = Lemke::new()
        .with_pivot_limit(1000)
        .solve(&murty(10), &murty_q(10), &mut [0.0; 10])
        .unwrap_err();
    assert!(matches!(e, LcpError::PivotLimit { limit: 1000, .. }), "{e}");
}

/// A random symmetric positive-definite LCP with a planted solution: `M = AAᵀ/n + I`,
/// `z*` and `w*` complementary, `q = w* − M z*`.
fn planted(n: usize, rng: &mut Rng) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let a: Vec<f64> = (0..n * n).map(|_| 2.0 * rng.next() - 1.0).collect();
    let mut m = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let s: f64 = (0..n).map(|k| a[i * n + k] * a[j * n + k]).sum();
            m[i * n + j] = s / n as f64 + if i == j { 1.0 } else { 0.0 };
        }
    }
    let mut z = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        if rng.next() < 0.5 {
            z[i] = rng.next() + 0.1;
        } else {
            w[i] = rng.next() + 0.1;
        }
    }
    let q = (0..n)
        .map(|i| w[i] - (0..n).map(|j| m[i * n + j] * z[j]).sum::<f64>())
        .collect();
    (m, q, z)
}

#[test]
fn lemke_and_pgs_solve_random_spd_problems_to_n_200() {
    let mut rng = Rng(42);
    let mut lemke = Lemke::new();
    let pgs = Pgs::new().with_tolerance(1e-13).unwrap();
    for n in [2, 5, 10, 20, 50, 100, 200] {
        let (m, q, exact) = planted(n, &mut rng);
        let mut z = vec![0.0; n];
        let r = lemke.solve(&m, &q, &mut z).unwrap();
        let err = z
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            r.residual <= 1e-12 && err <= 1e-12,
            "Lemke n = {n}: {r:?}, error {err:e}"
        );
        let mut z2 = vec![0.0; n];
        let r2 = pgs.solve(&m, &q, &mut z2).unwrap();
        let err2 = z2
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            r2.residual <= 1e-12 && err2 <= 1e-11,
            "PGS n = {n}: {r2:?}, error {err2:e}"
        );
        println!(
            "n = {n}: Lemke {} pivots, residual {:.1e}, error {err:.1e}; PGS {} sweeps, residual {:.1e}",
            r.iterations, r.residual, r2.iterations, r2.residual
        );
    }
}

#[test]
fn nsgs_solves_planted_frictional_problems() {
    // Contacts planted in each regime (take-off, stick, slide ±) on a random SPD Delassus
    // matrix; NSGS must find impulses with residual ≤ 1e-12 that reproduce the regimes.
    let mut rng = Rng(7);
    for k in [1, 3, 10, 30] {
        let d = 2 * k;
        let (w, _, _) = planted(d, &mut rng);
        let mu: Vec<f64> = (0..k).map(|_| 0.2 + 0.6 * rng.next()).collect();
        let mut p = vec![0.0; d];
        let mut u = vec![0.0; d];
        for c in 0..k {
            match c % 4 {
                0 => u[2 * c] = rng.next() + 0.1, // take-off: p = 0, u_n > 0
                1 => {
                    p[2 * c] = rng.next() + 0.5; // stick: u = 0, |p_t| < μ p_n
                    p[2 * c + 1] = mu[c] * p[2 * c] * (1.6 * rng.next() - 0.8);
                }
                r => {
                    let s = if r == 2 { 1.0 } else { -1.0 }; // slide: u_t = s·|u_t|
                    p[2 * c] = rng.next() + 0.5;
                    p[2 * c + 1] = -s * mu[c] * p[2 * c];
                    u[2 * c + 1] = s * (rng.next() + 0.1);
                }
            }
        }
        let q: Vec<f64> = (0..d)
            .map(|i| u[i] - (0..d).map(|j| w[i * d + j] * p[j]).sum::<f64>())
            .collect();
        let mut sol = vec![0.0; d];
        let r = Nsgs::new()
            .with_tolerance(1e-13)
            .unwrap()
            .solve(&w, &q, &mu, &mut sol)
            .unwrap();
        assert!(r.residual <= 1e-12, "k = {k}: {r:?}");
        assert!(frictional_contact_residual(&w, &q, &mu, &p).unwrap() <= 1e-14);
        let err = sol
            .iter()
            .zip(&p)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // The frictional problem need not have a unique solution; here W is strongly
        // diagonally dominant relative to μ, and the planted impulses are recovered.
        assert!(err <= 1e-10, "k = {k}: error {err:e}, {r:?}");
        println!(
            "NSGS k = {k} contacts: {} sweeps, residual {:.1e}, error {err:.1e}",
            r.iterations, r.residual
        );
    }
}

/// Discs of radius `r` and unit mass stacked in a column on the floor, touching.
fn column(n: usize, r: f64, e: f64) -> (PlanarBodies<f64>, Vec<PlanarContact<f64>>, Vec<f64>) {
    let bodies = PlanarBodies::new(vec![RigidBody::disc(1.0, r).unwrap(); n], 9.81).unwrap();
    let mut contacts =
        vec![PlanarContact::disc_plane(0, r, Plane::floor(0.0).unwrap(), e, 0.0).unwrap()];
    for i in 0..n - 1 {
        contacts.push(PlanarContact::disc_disc(i, r, i + 1, r, e, 0.0).unwrap());
    }
    let mut q = vec![0.0; 3 * n];
    for i in 0..n {
        q[3 * i + 1] = r + 2.0 * r * i as f64;
    }
    (bodies, contacts, q)
}

/// The impulses of the first step.
#[derive(Default)]
struct FirstStep(Vec<(usize, f64)>, usize, f64);

impl StepObserver<f64> for FirstStep {
    fn on_step(&mut self, s: &StepRecord<'_, f64>) -> Control {
        self.0 = s
            .contacts
            .iter()
            .map(|c| (c.index, c.normal_impulse))
            .collect();
        self.1 = s.solver.iterations;
        self.2 = s.solver.residual;
        Control::Stop
    }
}

#[test]
fn pgs_converges_on_a_column_of_100_balls() {
    // At rest, each contact carries the weight of the balls above it over the step:
    // p_i = (N − i) m g h. PGS on the tridiagonal Delassus matrix from a cold start.
    let n = 100;
    let h = 1e-3;
    // r = 1/16: the stacked positions and the gaps are exact in binary (all gaps exactly 0).
    let (bodies, contacts, q0) = column(n, 0.0625, 0.0);
    let pgs = Pgs::new()
        .with_max_iterations(200_000)
        .with_tolerance(1e-12)
        .unwrap();
    for solver in [Solver::Pgs(pgs), Solver::Lemke(Lemke::new())] {
        let mut scheme = MoreauJean::new(bodies.clone(), contacts.clone(), h)
            .unwrap()
            .with_solver(solver)
            .unwrap();
        let (mut q, mut v) = (q0.clone(), vec![0.0; 3 * n]);
        let mut first = FirstStep::default();
        scheme.run(0.0, &mut q, &mut v, 1.0, &mut first).unwrap();
        assert_eq!(first.0.len(), n);
        let worst = first
            .0
            .iter()
            .map(|&(i, p)| (p - (n - i) as f64 * 9.81 * h).abs())
            .fold(0.0, f64::max);
        println!(
            "100-ball column: {} iterations, residual {:.1e}, worst impulse error {worst:.1e}",
            first.1, first.2
        );
        assert!(first.2 <= 1e-12);
        // The impulse error is at most ‖W⁻¹‖∞ times the residual (scaled by max(1, ‖q‖∞)
        // = 1): W is the path Laplacian grounded at the floor, W⁻¹_ij = min(i, j) + 1,
        // ‖W⁻¹‖∞ = N(N + 1)/2.
        let bound = (n * (n + 1) / 2) as f64 * first.2.max(f64::EPSILON);
        assert!(worst <= bound, "worst impulse error {worst:e} > {bound:e}");
        assert!(
            v.iter().all(|x| x.abs() < 1e-10),
            "column moved: {:?}",
            &v[..6]
        );
    }
    // Too few sweeps: an error with the step and the residual, not an impulse.
    let mut scheme = MoreauJean::new(bodies, contacts, h)
        .unwrap()
        .with_solver(Solver::Pgs(Pgs::new().with_max_iterations(10)))
        .unwrap();
    let (mut q, mut v) = (q0, vec![0.0; 3 * n]);
    let e = scheme.run(0.0, &mut q, &mut v, 0.01, &mut ()).unwrap_err();
    match &e {
        TimeStepError::Contact {
            step: 0,
            source: LcpError::NotConverged { residual, .. },
            ..
        } => {
            assert!(*residual > 1e-10)
        }
        _ => panic!("{e}"),
    }
    assert!(
        e.to_string().contains("step 0") && e.to_string().contains("residual"),
        "{e}"
    );
}
