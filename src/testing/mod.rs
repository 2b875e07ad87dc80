//! Testing helpers (feature `testing`): a property checker for force laws, reference
//! problems with closed-form solutions, and a convergence-order fit.
//!
//! # Checking your own force law
//! [`check_law`] evaluates a [`ForceLaw`](crate::ForceLaw) on a rectangle
//! `x ∈ X`, `v ∈ V` ([`GridAxis`]: linear, or logarithmic around a centre for tiny penetrations
//! and velocities) — a deterministic grid, a probe of the contact onset, then pseudo-random
//! points (SplitMix64, fixed seed) — and verifies what the law claims in its [`LawSpec`]:
//!
//! | property | claim | checked |
//! |---|---|---|
//! | [`Finite`](Property::Finite) | always | `F` finite everywhere; partials finite away from declared kinks |
//! | [`Dissipative`](Property::Dissipative) | [`LawSpec::dissipative`] | $F(x,v)\,v \ge 0$ |
//! | [`SeparatedZero`](Property::SeparatedZero) | [`LawSpec::contact`] | $F = 0$ for $x \le x_I$ (upper stop; $x \ge x_I$ lower) |
//! | [`NonAdhesive`](Property::NonAdhesive) | [`LawSpec::contact`] | $F \ge 0$ in contact (upper; $F \le 0$ lower) |
//! | [`OnsetContinuity`](Property::OnsetContinuity) | [`LawSpec::contact`] | $\lvert F(x_I \pm h_{\min}, v)\rvert \le \tau\,\lvert F(x_I \pm h_{\mathrm{ref}}, v)\rvert$ |
//! | [`AnalyticPartials`](Property::AnalyticPartials) | [`LawSpec::analytic_partials`] | partials = central differences, away from kinks |
//!
//! The first failure is returned as a [`LawViolation`] naming the property, the point and
//! the values; success returns a [`CheckReport`] counting what was checked.
//!
//! ## Partials near kinks
//! Contact and friction laws are not smooth everywhere: `(x − x_I)^{3/2}` switches on at the
//! stop, the paper's damping `|v|^{n3}` (`n3 < 1`) has an infinite slope at `v = 0`. Declare
//! such lines as kinks ([`LawSpec::kink_x`], [`LawSpec::kink_v`]; the stop of a contact claim
//! is declared automatically). For each partial the checker then uses a central difference
//! whose half-width adapts to the distance `d` to the nearest kink of that variable:
//! $$h = \min\big(\varepsilon^{1/3}\max(\lvert p\rvert,\ 10^{-8}\,s),\ \kappa\,d\big),\qquad \kappa = 10^{-4},$$
//! (`p` the coordinate, `s` the axis scale), evaluated with steps `h` and `2h`. The stencil
//! never straddles a kink, and for a power law `d^q` the relative truncation error is
//! `≈ |(q−1)(q−2)|κ²/6 ≈ 10⁻⁹` however close the point is — so points at 1 nm from the stop
//! or at `v = 10⁻⁸ m/s` are checked, not skipped. Only points within
//! `margin·max(|kink|, s)` of a kink (default margin `10⁻¹⁰`,
//! [`CheckConfig::with_kink_margin`]) are skipped, which includes the kink itself: at
//! `v = 0` the paper's law returns the largest finite value for `∂F/∂v`, a correct answer to
//! an ill-posed question that is not compared. The comparison is
//! $$\lvert a - \mathrm{fd}_h\rvert \le \mathrm{rtol}\cdot\max(\lvert a\rvert, \lvert\mathrm{fd}_h\rvert)
//!   \;+\; 32\,\varepsilon\,\frac{\max\lvert F\rvert_{\text{stencil}}}{h}
//!   \;+\; \lvert \mathrm{fd}_h - \mathrm{fd}_{2h}\rvert$$
//! (default `rtol = 10⁻⁶`). The second term is the rounding noise of the difference (it
//! matters where a large smooth term, e.g. a spring, is added to a small contact force), the
//! third a Richardson estimate of its truncation error (it matters where the true partial is
//! ~0, e.g. `∂(x³)/∂x` at `x = 0`). A wrong partial fails at every ordinary point (in the
//! tests, partials off by a relative `3·10⁻⁶` are rejected); an undeclared kink fails where a
//! stencil straddles it, with a message suggesting to declare it.
//!
//! Kinks are lines `x = const` or `v = const`; a law whose non-smooth set is a curve in the
//! `(x, v)` plane needs a domain that avoids it.
//!
//! ## Continuity at onset
//! With `h_ref` the smallest positive penetration on the grid, the force at
//! `h_min = h_ref·10^{−8}` (bounded below by what the scalar type resolves next to the stop)
//! must be at most `τ = 10⁻²` times the force at `h_ref`, at every grid velocity and 64
//! pseudo-random ones ([`CheckConfig::with_onset_probe`]). A jump is caught when it exceeds
//! `τ` times the force at `h_ref` (so put the grid's smallest penetration where the force is
//! small); a force that vanishes like `δ^q` passes for `q > 1/4` (Hertz: `q = 3/2`).
//!
//! ## Example: a Hunt–Crossley contact
//! ```
//! use nonsmooth::ForceLaw;
//! use nonsmooth::force::Side;
//! use nonsmooth::testing::{GridAxis, CheckConfig, ContactClaim, LawSpec, Property, check_law};
//!
//! /// Hunt–Crossley contact `F = k·δ^{3/2}·(1 + α·v)`, `δ = x − x_I > 0`, clamped at 0
//! /// (a contact pushes, it never pulls) unless `clamped` is false.
//! #[derive(Clone, Copy)]
//! struct HuntCrossley { x_i: f64, k: f64, alpha: f64, clamped: bool }
//!
//! impl ForceLaw<f64> for HuntCrossley {
//!     fn force(&self, x: f64, v: f64) -> f64 {
//!         let d = x - self.x_i;
//!         if d <= 0.0 { return 0.0; }
//!         let f = self.k * d * d.sqrt() * (1.0 + self.alpha * v);
//!         if self.clamped { f.max(0.0) } else { f }
//!     }
//!     fn partials(&self, x: f64, v: f64) -> (f64, f64) {
//!         let d = x - self.x_i;
//!         let c = 1.0 + self.alpha * v;
//!         if d <= 0.0 || (self.clamped && c <= 0.0) { return (0.0, 0.0); }
//!         let s = d.sqrt();
//!         (1.5 * self.k * s * c, self.k * d * s * self.alpha)
//!     }
//! }
//!
//! let law = HuntCrossley { x_i: -2e-3, k: 1e8, alpha: 1.5, clamped: true };
//! let spec = LawSpec::new()
//!     .contact(ContactClaim::new(-2e-3, Side::Upper)) // declares the kink x = x_I too
//!     .analytic_partials()
//!     .kink_v(-1.0 / 1.5); // where the clamp switches
//! let config = CheckConfig::new(
//!     GridAxis::log_around(-2e-3, 1e-9, 1e-4)?, // x_I ± 1 nm … 0.1 mm, and x_I itself
//!     GridAxis::log_around(0.0, 1e-8, 2.0)?,    // v = ±10 nm/s … 2 m/s, and 0
//!     spec,
//! )?;
//! let report = check_law(&law, &config).expect("a correct law passes");
//! assert!(report.partials_checked > 8000 && report.onset_probes > 30);
//!
//! // Without the clamp the law pulls the body into the stop when it leaves fast.
//! let unclamped = HuntCrossley { clamped: false, ..law };
//! let err = check_law(&unclamped, &config).unwrap_err();
//! assert_eq!(err.property(), Property::NonAdhesive);
//! assert!(err.point().1 < -1.0 / 1.5);
//! # Ok::<(), nonsmooth::Error>(())
//! ```
//! For your own property tests, [`points_in`] is a proptest strategy over the same domain.
//!
//! # Reference problems
//! Every problem implements [`Dynamics`](crate::Dynamics) (with its Jacobian and `∂f/∂t`),
//! generic over `T: Real`; those with a closed form implement [`ExactSolution`]:
//!
//! | problem | `N` | solution |
//! |---|---|---|
//! | [`HarmonicOscillator`] | 2 | `x₀ cos ωt + (v₀/ω) sin ωt` |
//! | [`DampedOscillator`] | 2 | underdamped closed form |
//! | [`ExponentialDecay`] | 1 | `y₀ e^{−λt}` |
//! | [`ProtheroRobinson`] | 1 | `sin t + y₀ e^{−λt}` (non-autonomous) |
//! | [`ForcedOscillator`] | 2 | `ẍ + ω²x = a cos Ωt` (non-autonomous) |
//! | [`Lorenz`] | 3 | none; Lyapunov sum `−(σ+1+β)`, top exponent ≈ 0.9056 |
//! | [`BouncingBall`] | 2 | impact times, speeds, Zeno time ([`BallDrop`]) |
//! | [`HarmonicZeroCrossings`] | 2 | zero crossings of `A cos(ωt + φ)` |
//! | [`NearGrazing`] | 2 | a crossing pair of width `≈ 2√(2δ/L)/ω` |
//! | [`BallOnTableExact`] | — | the exact impact map of a ball on a vibrating table |
//! | [`TwoDofImpactByHand`] | 4 | none; the catalogue's 2-DOF impact oscillator written out by hand |
//! | [`DuffingUedaByHand`] | 2 | none; the catalogue's Duffing–Ueda oscillator written out by hand |
//!
//! Order tests of integrators should use a non-autonomous problem: a tableau with a wrong
//! node `c_i` is exact on autonomous ones. [`convergence_order`] fits the observed order.

mod ball_table;
mod convergence;
mod hand_written;
mod impacts;
mod law_check;
mod problems;

pub use ball_table::{BallOnTableExact, TableImpact};
pub use convergence::{ConvergenceFit, convergence_fit, convergence_order};
pub use hand_written::{DuffingUedaByHand, TwoDofImpactByHand};
pub use impacts::{BallDrop, BouncingBall, HarmonicZeroCrossings, NearGrazing, ZeroCrossing};
pub use law_check::{
    CheckConfig, CheckReport, ContactClaim, GridAxis, LawSpec, LawViolation, Property, Sides,
    Variable, axis_values, check_law, points_in,
};
pub use problems::{
    DampedOscillator, ExactSolution, ExponentialDecay, ForcedOscillator, HarmonicOscillator,
    Lorenz, ProtheroRobinson,
};
