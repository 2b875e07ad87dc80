//! The paper's Lyapunov settings: the norm of its state `(x, ẋ)`, the separation `d0` of
//! the two-trajectory estimate, the schedule of its exponent diagram (Sect. 4, Fig. 5), and
//! how the two methods of [`lyapunov`](crate::lyapunov) compare on its model.
//!
//! # Where the Jacobian is singular
//! The paper's contact damping `b·δ^{n2}·sgn(ẋ)|ẋ|^{n3}` with `n3 ≈ 0.187 < 1` has an
//! infinite slope `∂F/∂ẋ` at `ẋ = 0` in contact, and the regularized friction
//! `T·ẋ/√(ẋ²+ε²)` a slope `T/ε ≈ 6·10⁵ N·s/m` there. For the exact law the variational
//! equations are therefore not defined wherever the cart reverses while pressed into the
//! stop — at the turning point of *every* impact, and whenever it rests against the stop —
//! and `∂F/∂ẋ` returned by [`HertzContact`](crate::force::HertzContact) is the largest
//! finite number there. (The singularity is integrable along a trajectory — `∫|ẋ|^{n3−1}dt`
//! converges when `ẍ ≠ 0` — but no step-based integrator can evaluate `J` at it.) With the
//! exact law (`η = 0`) the QR method fails at the first reversal in contact
//! ([`IntegrateError::StepSizeTooSmall`] — measured at ω = 20.465 after 0.08 s), while the
//! two-trajectory method runs at its usual cost and gives `λ₁ = 0.694 ± 0.013 s⁻¹`, the
//! regularized model's value within the spread.
//!
//! The crate's paper model uses the rate regularization
//! `sgn(ẋ)|ẋ|^{n3} → ẋ(ẋ²+η²)^{(n3−1)/2}` with `η = 10⁻⁸ m/s`
//! ([`PAPER.eta`](crate::systems::paper::PaperParameters::eta)), whose slope at `ẋ = 0` is
//! `η^{n3−1} ≈ 3·10⁶ (m/s)^{n3−1}`: `J` is finite but very large in short windows around
//! each reversal in contact — `J_ẋẋ = −∂F/∂ẋ/m ≈ −k_I·b·δ^{3/2}·η^{n3−1}/m` is about
//! `−10⁶ s⁻¹` for the cart resting in the stop (`δ ≈ 5 µm`) and `−10⁸ s⁻¹` at the turning
//! point of an impact (`δ ≈ 0.1 mm`), over a time `~η/|ẍ| ≈ 10⁻⁹ s`. Those windows are
//! strongly *contracting* (the large entry is damping), so they cannot blow the tangent
//! vectors up, and they carry only a few per cent of the integrated damping
//! `∫ ∂F/∂ẋ dt` through a reversal (`2g(η)` of `2g(v_impact)`, `g(v) = v^{n3}`), so an
//! explicit stepper that steps over them errs little. The QR method then estimates the
//! exponents of the regularized flow. The two-trajectory method never forms `J`, and the two
//! agree on the paper's model (`tests/lyapunov.rs`, measured with DOPRI5):
//!
//! | ω (rad/s) | two trajectories | QR `λ₁` (`λ₂`) | tolerances, `d0` |
//! |---|---|---|---|
//! | 19.0 (period 2) | −2.13346 ± 0.00025 | −2.13408 (−17.859) | rtol 1e-10, `d0 = 10⁻⁶` |
//! | 20.465 (chaotic) | 0.682 ± 0.015 | 0.702 ± 0.017 (−8.741) | rtol 1e-10, `d0 = 10⁻⁶` |
//! | 19.0 | −2.1142 ± 0.0006 | −2.1340 (−17.859) | rtol 1e-8, `d0 = 10⁻⁴` |
//! | 20.465 | 0.707 ± 0.015 | 0.697 ± 0.015 (−8.737) | rtol 1e-8, `d0 = 10⁻⁴` |
//!
//! On the chaotic attractor the two runs follow different (diverged) trajectories, so they
//! agree within their spreads; on the periodic orbit they agree to `3·10⁻⁴` at tight
//! tolerances and to 1 % at the paper-grade tolerances, where the two-trajectory estimate
//! carries the integration error of the difference (see [`D0`]). The QR method costs
//! more per period (`benches/lyapunov.rs`; figures in `docs/performance.md`) and gives the
//! second exponent too; the two-trajectory method is the one that needs no derivatives and
//! also works for the exact law (`η = 0`).
//!
//!
//! The paper's exponent-versus-ω diagram (Fig. 5) uses [`diagram_settings`] with [`norm`]
//! and [`D0`] (`cargo run --release --example lyapunov_fig5`).

use crate::Real;
#[cfg(doc)]
use crate::integrate::IntegrateError;
use crate::lyapunov::{DEFAULT_BLOCKS, DiagramSettings, IntervalRule, Norm};
use crate::scalar::lit;

/// Characteristic scales `(w_x, w_ẋ) = (10⁻³ m, 3·10⁻² m/s)` of the paper's model, used by
/// [`norm`].
///
/// Measured on the attractors of the paper's oscillator reached from rest (200 periods
/// sampled 64 times per period after 100 transient periods): the standard deviations of
/// position and velocity are `(3.1·10⁻⁴ m, 1.0·10⁻² m/s)` at `ω = 17.5`,
/// `(5.3·10⁻⁴, 1.7·10⁻²)` at 19, `(9.0·10⁻⁴, 2.8·10⁻²)` at 20.465 and
/// `(1.6·10⁻³, 5.5·10⁻²)` at 25 rad/s — a ratio `σ_ẋ/σ_x ≈ 30–34 s⁻¹`, above `ω` because
/// the impacts put energy into higher harmonics. With these weights a separation of 1 in
/// the norm is about one typical amplitude in either component, so neither dominates.
pub const NORM_SCALES: [f64; 2] = [1e-3, 3e-2];

/// The initial separation `d0` (in the [`norm`] norm) for the two-trajectory
/// estimate on the paper's model with the paper-grade tolerances
/// `Tolerances::per_component(1e-8, [1e-12, 1e-10])`.
///
/// # The study behind it
/// [`separation_study`](crate::lyapunov::separation_study) from rest, 100 transient and 10³ recorded periods, DOPRI5 at
/// `rtol = 10⁻⁸`; `λ₁` in s⁻¹ (± the block standard error):
///
/// | d0 | ω = 20.465 (chaotic) | ω = 18 (chaotic) | ω = 19 (period 2) | ω = 20.2 (periodic) |
/// |---|---|---|---|---|
/// | 1e-8 | 0.829 ± 0.029 | 1.780 ± 0.027 | −1.923 ± 0.025 | −0.693 ± 0.005 |
/// | 1e-7 | 0.822 ± 0.027 | 1.768 ± 0.029 | −1.920 ± 0.007 | −0.700 ± 0.004 |
/// | 1e-6 | 0.713 ± 0.019 | 1.439 ± 0.024 | −2.129 ± 0.001 | −0.666 ± 0.003 |
/// | 1e-5 | 0.653 ± 0.029 | 1.429 ± 0.029 | −2.125 ± 0.001 | −0.697 ± 0.002 |
/// | **1e-4** | **0.707 ± 0.015** | **1.429 ± 0.022** | **−2.114 ± 0.001** | **−0.698 ± 0.001** |
/// | 1e-3 | 0.659 ± 0.024 | 1.451 ± 0.041 | −2.135 ± 0.000 | −0.686 ± 0.000 |
/// | 1e-2 | 0.707 ± 0.014 | 1.297 ± 0.038 | −2.192 ± 0.000 | −0.690 ± 0.000 |
/// | 1e-1 | 0.108 ± 0.045 | −2.353 ± 0.064 | −5.107 ± 0.040 | −0.804 ± 0.000 |
/// | QR (rtol 1e-10) | 0.702 ± 0.017 | 1.360 ± 0.041 | −2.1341 | −0.6886 |
///
/// - **Too small** (`d0 ≲ 3·10⁻⁷`): biased (0.82 instead of 0.70 at 20.465, −1.92 instead
///   of −2.13 at 19). The error controller allows a local error of about
///   `atol + rtol·|y|` ≈ `3·10⁻¹¹ m` and `4·10⁻¹⁰ m/s` per step; the two copies share
///   their steps, so their errors are correlated where `f` is smooth on the scale of a step,
///   but not at the contact entries and exits and the velocity reversals (where, as the
///   crate's profiling shows, most steps are spent). There the separation picks up errors of
///   the size of that allowance, i.e. a relative error `~(3·10⁻¹¹ m)/(d0·w_x)`. At
///   `rtol = 10⁻¹⁰` the same study is flat from `d0 = 10⁻⁸` up: at ω = 19 it gives
///   −2.1353, −2.1339, −2.1332, −2.1340, −2.1348 for `d0 = 10⁻⁷ … 10⁻³`, the QR value
///   −2.1341 to 4 digits.
/// - **Too large** (`d0 ≳ 3·10⁻³`): the pair is no longer local (−2.19 at 19 and 1.30 at
///   18 for `10⁻²`, nonsense at `10⁻¹` — a tenth of the attractor).
/// - In between, the estimates are flat within their spreads on the chaotic attractors and
///   within about 1 % of the QR value on the periodic ones. `10⁻⁴` (a position offset of
///   `~7·10⁻⁸ m`, velocity `~2·10⁻⁶ m/s`) sits a factor `~10³` above the error allowance
///   and a factor `~30` below the onset of non-locality. Rule of thumb for other tolerances:
///   `d0 ≈ 10⁴·rtol` (for `rtol = 10⁻¹⁰`, `d0 = 10⁻⁶`, at twice the cost and with the
///   periodic orbits' exponents correct to `~10⁻⁴`).
///
/// `tests/lyapunov.rs` (`d0_study_is_flat_on_the_paper_model`) checks the plateau over a
/// decade around this value at ω = 20.465, with `10⁻⁸` and `10⁻¹` as controls.
pub const D0: f64 = 1e-4;

/// The norm used for the paper's model: weights [`NORM_SCALES`] `(10⁻³ m, 3·10⁻² m/s)`.
pub fn norm<T: Real>() -> Norm<T, 2> {
    Norm::Weighted([lit(NORM_SCALES[0]), lit(NORM_SCALES[1])])
}

/// The paper's schedule (Sect. 4): one forcing period per interval, 100 transient periods
/// at the start, 50 after each parameter step, 10³ periods for the exponent, 10 blocks,
/// `t0 = 0`.
pub fn diagram_settings<T: Real>() -> DiagramSettings<T> {
    DiagramSettings {
        interval: IntervalRule::ForcingPeriod,
        first_transient: 100,
        step_transient: 50,
        intervals: 1000,
        blocks: DEFAULT_BLOCKS,
        t0: T::zero(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_and_norm() {
        let p = diagram_settings::<f64>();
        assert_eq!(
            (p.first_transient, p.step_transient, p.intervals),
            (100, 50, 1000)
        );
        assert_eq!((p.blocks, p.t0), (DEFAULT_BLOCKS, 0.0));
        assert_eq!(p.interval, IntervalRule::ForcingPeriod);
        assert_eq!(norm::<f32>(), Norm::Weighted([1e-3_f32, 3e-2]));
    }
}
