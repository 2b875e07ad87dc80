//! Filippov systems: the relay feedback system (sliding periodic orbit, period and Floquet
//! multipliers against the exact piecewise-linear flow), Den Hartog's forced Coulomb
//! oscillator (steady amplitude against the closed form, the static limit while stuck on
//! the dense output), the belt oscillator against `StickSlip`, and the error paths.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use nonsmooth::drive::{Coulomb, SlipMode, StepView, StickSlip, run_modes};
use nonsmooth::excite::{Constant, Harmonic};
use nonsmooth::filippov::{
    Filippov, FilippovError, FilippovSimulation, Mode, Side, SlidingObserver, Switched, Transition,
    TransitionKind,
};
use nonsmooth::force::LinearSpring;
use nonsmooth::integrate::{DenseOutput, Dopri5, Tolerances};
use nonsmooth::model::{Coordinate, Element, Load, Mechanical};
use std::f64::consts::{PI, TAU};

// ---------------------------------------------------------------------------------------
// The relay feedback system of di Bernardo, Johansson & Vasca (IJBC 11(4), 2001), the test
// problem of Piiroinen & Kuznetsov (ACM TOMS 34(3), 2008, eq. (32)):
// ẋ = A x + B u, u = −sgn(C x),
// A = [[−(2ζω+1), 1, 0], [−(2ζω+ω²), 0, 1], [−ω², 0, 0]], B = (1, −2σ, 1)ᵀ, C = (1, 0, 0).
const ZETA: f64 = 0.05;
const OMEGA: f64 = 25.0;
const SIGMA: f64 = 1.0;
const X0: [f64; 3] = [0.0, -0.001, -0.02];

fn relay_a() -> Matrix3<f64> {
    let (z, w) = (ZETA, OMEGA);
    Matrix3::new(
        -(2.0 * z * w + 1.0),
        1.0,
        0.0,
        -(2.0 * z * w + w * w),
        0.0,
        1.0,
        -w * w,
        0.0,
        0.0,
    )
}

fn relay_b() -> Vector3<f64> {
    Vector3::new(1.0, -2.0 * SIGMA, 1.0)
}

struct Relay {
    a: Matrix3<f64>,
    b: Vector3<f64>,
}

impl Relay {
    fn new() -> Self {
        Self {
            a: relay_a(),
            b: relay_b(),
        }
    }
}

impl Filippov<f64, 3, 1> for Relay {
    fn surface(&self, _i: usize, _t: f64, x: &SVector<f64, 3>) -> f64 {
        x[0]
    }
    fn gradient(&self, _i: usize, _t: f64, _x: &SVector<f64, 3>) -> SVector<f64, 3> {
        SVector::from([1.0, 0.0, 0.0])
    }
    fn field(&self, sides: &[Side; 1], _t: f64, x: &SVector<f64, 3>, dx: &mut SVector<f64, 3>) {
        // u = −sgn(x₁): +1 below the surface, −1 above.
        let u = -sides[0].sign::<f64>();
        *dx = self.a * x + self.b * u;
    }
    fn field_jacobian(
        &self,
        _sides: &[Side; 1],
        _t: f64,
        _x: &SVector<f64, 3>,
    ) -> Option<SMatrix<f64, 3, 3>> {
        Some(self.a)
    }
}

fn tol3() -> Tolerances<f64, 3> {
    Tolerances::new(1e-12, 1e-14).unwrap()
}

/// Samples `|x₁|` on the dense output of every sliding step (8 interior points) and records
/// the steps' modes.
#[derive(Default)]
struct SlideWatch {
    worst_h: f64,
    sliding_samples: usize,
    steps: usize,
}

impl SlidingObserver<f64, 3, 1> for SlideWatch {
    fn on_step<D: DenseOutput<f64, 3>>(
        &mut self,
        mode: &Mode<1>,
        step: &StepView<'_, f64, 3, D>,
    ) -> nonsmooth::drive::Control {
        self.steps += 1;
        if mode.is_sliding() {
            let mut y = SVector::zeros();
            for k in 0..=8 {
                let t = step.t0 + (step.t1 - step.t0) * k as f64 / 8.0;
                step.state_at(t, &mut y);
                self.worst_h = self.worst_h.max(y[0].abs());
                self.sliding_samples += 1;
            }
        } else {
            // In a region, x₁ has the region's sign (to the event location) between ends.
            let mut y = SVector::zeros();
            let s = mode.sides[0].sign::<f64>();
            for k in 1..8 {
                let t = step.t0 + (step.t1 - step.t0) * k as f64 / 8.0;
                step.state_at(t, &mut y);
                assert!(
                    s * y[0] > -1e-12,
                    "region {mode:?}: x₁ = {} at t = {t}",
                    y[0]
                );
            }
        }
        nonsmooth::drive::Control::Continue
    }
}

// The independent computation: the exact flow of the piecewise-linear system (matrix
// exponentials) between switchings, the switching times solved by bisection.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Piece {
    Minus,
    Plus,
    Slide,
}

struct ExactRelay {
    a: Matrix3<f64>,
    /// `A⁻¹B`.
    aib: Vector3<f64>,
    /// The sliding dynamics on x₁ = 0: `A − B (C A)/(C B)`.
    a_s: Matrix3<f64>,
}

impl ExactRelay {
    fn new() -> Self {
        let a = relay_a();
        let b = relay_b();
        let ca = a.row(0).into_owned();
        let a_s = a - b * ca / b[0];
        Self {
            a,
            aib: a.try_inverse().unwrap() * b,
            a_s,
        }
    }

    fn flow(&self, piece: Piece, x: &Vector3<f64>, t: f64) -> Vector3<f64> {
        match piece {
            Piece::Slide => (self.a_s * t).exp() * x,
            Piece::Minus | Piece::Plus => {
                let u = if piece == Piece::Minus { 1.0 } else { -1.0 };
                (self.a * t).exp() * (x + self.aib * u) - self.aib * u
            }
        }
    }

    /// The event function of a piece: x₁ in a region, distance of α = (x₂+1)/2 to its
    /// nearest bound while sliding (x₂ ∓ 1).
    fn event(&self, piece: Piece, x: &Vector3<f64>) -> f64 {
        match piece {
            Piece::Minus | Piece::Plus => x[0],
            Piece::Slide => (1.0 - x[1].abs()).min(1.0),
        }
    }

    /// The first time the piece's event function changes sign, by a scan of step `dt` and
    /// bisection to rounding.
    fn next_switch(&self, piece: Piece, x: &Vector3<f64>) -> f64 {
        let g0 = if piece == Piece::Slide {
            1.0
        } else if piece == Piece::Minus {
            -1.0
        } else {
            1.0
        };
        let dt = 1e-3;
        let mut lo = 0.0;
        let mut k = 1;
        loop {
            let hi = k as f64 * dt;
            let g = self.event(piece, &self.flow(piece, x, hi));
            if g * g0 < 0.0 || (piece == Piece::Slide && g < 0.0) {
                let (mut a, mut b) = (lo, hi);
                for _ in 0..200 {
                    let m = 0.5 * (a + b);
                    if m <= a || m >= b {
                        break;
                    }
                    let gm = self.event(piece, &self.flow(piece, x, m));
                    if gm * g0 > 0.0 {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                return b;
            }
            lo = hi;
            k += 1;
            assert!(k < 100_000, "no switching from {x:?} in {piece:?}");
        }
    }

    /// The piece after reaching the surface in `piece` at `x` (x₁ = 0 there): the rates
    /// h± = x₂ ∓ 1... (h₋ = x₂ + 1 below, h₊ = x₂ − 1 above).
    fn after(&self, piece: Piece, x: &Vector3<f64>) -> Piece {
        let (hm, hp) = (x[1] + 1.0, x[1] - 1.0);
        match piece {
            Piece::Minus => {
                if hp > 0.0 {
                    Piece::Plus
                } else {
                    Piece::Slide
                }
            }
            Piece::Plus => {
                if hm < 0.0 {
                    Piece::Minus
                } else {
                    Piece::Slide
                }
            }
            Piece::Slide => {
                if x[1] < 0.0 {
                    Piece::Minus
                } else {
                    Piece::Plus
                }
            }
        }
    }

    /// The switchings `(t, piece entered, state)` from `(x, piece)` up to `t_end`.
    fn switchings(
        &self,
        mut piece: Piece,
        mut x: Vector3<f64>,
        t_end: f64,
    ) -> Vec<(f64, Piece, Vector3<f64>)> {
        let mut t = 0.0;
        let mut out = Vec::new();
        loop {
            let d = self.next_switch(piece, &x);
            if t + d > t_end {
                return out;
            }
            t += d;
            x = self.flow(piece, &x, d);
            if piece == Piece::Slide {
                x[1] = x[1].signum(); // on the exit bound
            } else {
                x[0] = 0.0; // on the surface
            }
            piece = self.after(piece, &x);
            out.push((t, piece, x));
        }
    }

    /// The flow over `duration` from `(x, piece)` through the switchings.
    fn flow_for(&self, mut piece: Piece, mut x: Vector3<f64>, duration: f64) -> Vector3<f64> {
        let mut left = duration;
        loop {
            let d = self.next_switch(piece, &x);
            if d >= left {
                return self.flow(piece, &x, left);
            }
            left -= d;
            x = self.flow(piece, &x, d);
            if piece == Piece::Slide {
                x[1] = x[1].signum();
            } else {
                x[0] = 0.0;
            }
            piece = self.after(piece, &x);
        }
    }
}

fn piece_of(mode: &Mode<1>) -> Piece {
    match (mode.sliding, mode.sides[0]) {
        (Some(_), _) => Piece::Slide,
        (None, Side::Minus) => Piece::Minus,
        (None, Side::Plus) => Piece::Plus,
    }
}

#[test]
fn relay_feedback_converges_to_its_sliding_orbit_with_the_exact_period_and_multipliers() {
    let t_end = 40.0;
    let mut sim = FilippovSimulation::new(Relay::new(), Dopri5::new(tol3()));
    let mut watch = SlideWatch::default();
    let run = sim.run(0.0, SVector::from(X0), t_end, &mut watch).unwrap();
    // The exact switching sequence from x₀.
    let exact = ExactRelay::new();
    let start = piece_of(&run.start_mode);
    let want = exact.switchings(start, Vector3::from(X0), t_end);
    let got: Vec<&Transition<f64, 3, 1>> = run
        .transitions
        .iter()
        .filter(|tr| tr.kind != TransitionKind::Graze)
        .collect();
    assert_eq!(got.len(), want.len(), "{:?}", &want[..want.len().min(8)]);
    let mut worst_t: f64 = 0.0;
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(piece_of(&g.to), w.1, "at t = {}", w.0);
        worst_t = worst_t.max((g.t - w.0).abs());
    }
    assert!(worst_t < 1e-9, "worst switching time error {worst_t:e}");
    // Sliding segments are there, and |H| while sliding is at rounding.
    let entries: Vec<f64> = got
        .iter()
        .filter(|tr| tr.kind == TransitionKind::SlidingEntry)
        .map(|tr| tr.t)
        .collect();
    assert!(entries.len() >= 10, "{} sliding entries", entries.len());
    assert!(watch.sliding_samples > 100);
    assert!(
        watch.worst_h <= 1e-12,
        "|H| while sliding {:e}",
        watch.worst_h
    );
    assert!(run.max_drift <= 1e-12, "max drift {:e}", run.max_drift);
    // The orbit is symmetric (x → −x): each half period has seven sliding segments, one
    // of them after a long region piece (> 1 s); the period is the time between every
    // second entry that follows one.
    let marks = |entries: &[f64]| -> Vec<f64> {
        entries
            .windows(2)
            .filter(|w| w[1] - w[0] > 1.0)
            .map(|w| w[1])
            .collect()
    };
    let got_marks = marks(&entries);
    let n = got_marks.len();
    assert!(n >= 8, "{n} half periods");
    let period = got_marks[n - 1] - got_marks[n - 3];
    let prev = got_marks[n - 2] - got_marks[n - 4];
    let exact_entries: Vec<f64> = want
        .iter()
        .filter(|w| w.1 == Piece::Slide)
        .map(|w| w.0)
        .collect();
    let exact_marks = marks(&exact_entries);
    let m = exact_marks.len();
    let exact_period = exact_marks[m - 1] - exact_marks[m - 3];
    assert!(
        (period - prev).abs() < 1e-10,
        "not converged: {period} vs {prev}"
    );
    assert!(
        (period - exact_period).abs() < 1e-9,
        "period {period} vs exact {exact_period}"
    );
    // Refine the orbit point by following the exact flow further, then the monodromy
    // over one period from the middle of the first region piece after a sliding exit.
    let (_, piece, x_ref) = *want
        .iter()
        .rev()
        .find(|w| matches!(w.1, Piece::Minus | Piece::Plus) && w.0 < exact_marks[m - 1])
        .unwrap();
    let half = 0.5 * exact.next_switch(piece, &x_ref);
    let p0 = exact.flow(piece, &x_ref, half);
    // The exact orbit through p0: iterate the exact period map until it is fixed.
    let mut p = p0;
    for _ in 0..200 {
        let next = exact.flow_for(piece, p, exact_period);
        if (next - p).amax() < 1e-15 {
            break;
        }
        p = next;
    }
    // Its period from the exact switchings.
    let sw = exact.switchings(piece, p, 1.8 * exact_period);
    let ent: Vec<f64> = sw
        .iter()
        .filter(|w| w.1 == Piece::Slide)
        .map(|w| w.0)
        .collect();
    let ent = marks(&ent);
    let t_orbit = ent[2] - ent[0];
    assert!(
        (t_orbit - exact_period).abs() < 1e-11,
        "{t_orbit} vs {exact_period}"
    );
    // Exact monodromy: central differences of the exact time-T map, extrapolated. The
    // flow is stiff along the orbit (ω² = 625): the O(h²) error of a central difference is
    // large (measured for Φ₀₁: 3.59769 at h = 1e-6, 3.597858 at 2.5e-7, 3.5978679 at
    // 6e-8), so Richardson's (4D(h/2) − D(h))/3 at h = 2.5e-7 is taken (3.59786847).
    let central = |h: f64| {
        let mut d = Matrix3::zeros();
        for k in 0..3 {
            let mut up = p;
            let mut down = p;
            up[k] += h;
            down[k] -= h;
            let col = (exact.flow_for(piece, up, t_orbit) - exact.flow_for(piece, down, t_orbit))
                / (2.0 * h);
            d.set_column(k, &col);
        }
        d
    };
    let h = 2.5e-7;
    let phi_exact = (central(0.5 * h) * 4.0 - central(h)) / 3.0;
    let tol12 = Tolerances::<f64, 12>::new(1e-12, 1e-14).unwrap();
    let mono = sim.monodromy(0.0, p, t_orbit, tol12).unwrap();
    let diff = (mono.matrix - phi_exact).amax() / phi_exact.amax();
    println!(
        "relay: period {period:.15} (exact {exact_period:.15}), switching times within {worst_t:.2e}, |H| sliding ≤ {:.2e}, monodromy rel. diff {diff:.2e}",
        watch.worst_h
    );
    println!("monodromy {:?}\nexact {:?}", mono.matrix, phi_exact);
    assert!(diff < 1e-6, "monodromy differs by {diff:e}");
    // Multipliers: 1 (the flow), 0 (sliding collapses the normal direction), and μ.
    let mus = mono.multipliers();
    let ex = phi_exact.complex_eigenvalues();
    let mut ex: Vec<_> = ex.iter().copied().collect();
    ex.sort_by(|a, b| b.norm().partial_cmp(&a.norm()).unwrap());
    println!("multipliers {mus:?}\nexact {ex:?}");
    for (a, b) in mus.iter().zip(&ex) {
        assert!((a - b).norm() < 1e-6, "{a} vs {b}");
    }
    assert!(mus.iter().any(|m| (m - 1.0).norm() < 1e-6), "{mus:?}");
    assert!(mus.iter().any(|m| m.norm() < 1e-6), "{mus:?}");
}
