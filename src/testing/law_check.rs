//! A property checker for force laws written by users.
//!
//! See the [module documentation](super) for the properties and the example; the entry
//! point is [`check_law`].

use std::fmt;

use proptest::prelude::*;
use thiserror::Error;

use crate::force::Side;
use crate::scalar::{epsilon, lit, to_f64};
use crate::validate::ParameterError;
use crate::{ForceLaw, Real};

/// Which way a [`GridAxis::log_around`] axis extends from its centre.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sides {
    /// Both `centre − offset` and `centre + offset`, and the centre itself.
    Both,
    /// Only `centre + offset`.
    Above,
    /// Only `centre − offset`.
    Below,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum AxisKind {
    Linear {
        lo: f64,
        hi: f64,
    },
    Log {
        centre: f64,
        min_offset: f64,
        max_offset: f64,
        sides: Sides,
    },
}

/// The range of one coordinate (`x` or `v`) over which a law is checked.
///
/// Two shapes:
/// - [`GridAxis::linear`]: `[lo, hi]`, sampled uniformly;
/// - [`GridAxis::log_around`]: `centre ± 10^s` for `s` uniform in `[log₁₀ min, log₁₀ max]`, plus
///   the centre itself — for tiny penetrations around a stop (`x_I ± 10⁻⁹…10⁻⁴ m`) or
///   velocities around a reversal (`0 ± 10⁻⁸…1 m/s`), where a linear grid would never land.
///
/// Grids always contain the special points of the axis: its ends, the centre of a
/// logarithmic axis (unless one-sided) and `0` if a linear axis contains it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridAxis {
    kind: AxisKind,
}

impl GridAxis {
    /// The interval `[lo, hi]`, sampled uniformly.
    ///
    /// # Errors
    /// [`ParameterError`] unless `lo` and `hi` are finite and `lo < hi`.
    pub fn linear(lo: f64, hi: f64) -> Result<Self, ParameterError> {
        if !lo.is_finite() {
            return Err(ParameterError::new("lo", lo, "finite"));
        }
        if !(hi.is_finite() && hi > lo) {
            return Err(ParameterError::new("hi", hi, "finite and > lo"));
        }
        Ok(Self {
            kind: AxisKind::Linear { lo, hi },
        })
    }

    /// The points `centre ± d` with `d` log-uniform in `[min_offset, max_offset]`, and the
    /// centre itself (both sides; see [`with_sides`](Self::with_sides)).
    ///
    /// # Errors
    /// [`ParameterError`] unless `centre` is finite and `0 < min_offset ≤ max_offset < ∞`.
    pub fn log_around(
        centre: f64,
        min_offset: f64,
        max_offset: f64,
    ) -> Result<Self, ParameterError> {
        if !centre.is_finite() {
            return Err(ParameterError::new("centre", centre, "finite"));
        }
        if !(min_offset.is_finite() && min_offset > 0.0) {
            return Err(ParameterError::new(
                "min_offset",
                min_offset,
                "finite and > 0",
            ));
        }
        if !(max_offset.is_finite() && max_offset >= min_offset) {
            return Err(ParameterError::new(
                "max_offset",
                max_offset,
                "finite and >= min_offset",
            ));
        }
        Ok(Self {
            kind: AxisKind::Log {
                centre,
                min_offset,
                max_offset,
                sides: Sides::Both,
            },
        })
    }

    /// Restricts a logarithmic axis to one side of its centre (no effect on a linear axis).
    pub fn with_sides(mut self, sides: Sides) -> Self {
        if let AxisKind::Log { sides: s, .. } = &mut self.kind {
            *s = sides;
        }
        self
    }

    /// The smallest and largest value of the axis.
    pub fn bounds(&self) -> (f64, f64) {
        match self.kind {
            AxisKind::Linear { lo, hi } => (lo, hi),
            AxisKind::Log {
                centre,
                min_offset,
                max_offset,
                sides,
            } => match sides {
                Sides::Both => (centre - max_offset, centre + max_offset),
                Sides::Above => (centre + min_offset, centre + max_offset),
                Sides::Below => (centre - max_offset, centre - min_offset),
            },
        }
    }

    /// The magnitude of the axis, `max(|lo|, |hi|)` (used to scale finite-difference steps
    /// and the kink margin).
    pub fn scale(&self) -> f64 {
        let (lo, hi) = self.bounds();
        lo.abs().max(hi.abs())
    }

    /// The point at the fraction `u ∈ [0, 1]` of the axis (clamped), increasing in `u`:
    /// uniform for a linear axis, log-uniform in the offset for a logarithmic one (for
    /// [`Sides::Both`], `u < ½` is the lower side and `u ≥ ½` the upper side).
    pub fn at(&self, u: f64) -> f64 {
        let u = if u.is_nan() { 0.5 } else { u.clamp(0.0, 1.0) };
        match self.kind {
            AxisKind::Linear { lo, hi } => {
                if u >= 1.0 {
                    hi
                } else {
                    lo + u * (hi - lo)
                }
            }
            AxisKind::Log {
                centre,
                min_offset,
                max_offset,
                sides,
            } => {
                let offset = |t: f64| {
                    if t >= 1.0 {
                        max_offset
                    } else if t <= 0.0 {
                        min_offset
                    } else {
                        min_offset * (max_offset / min_offset).powf(t)
                    }
                };
                match sides {
                    Sides::Above => centre + offset(u),
                    Sides::Below => centre - offset(1.0 - u),
                    Sides::Both => {
                        if u < 0.5 {
                            centre - offset(1.0 - 2.0 * u)
                        } else {
                            centre + offset(2.0 * u - 1.0)
                        }
                    }
                }
            }
        }
    }

    /// The special points of the axis: its ends, the centre of a two-sided logarithmic axis,
    /// and `0` if a linear axis contains it.
    pub fn special_points(&self) -> Vec<f64> {
        let (lo, hi) = self.bounds();
        let mut out = vec![lo, hi];
        match self.kind {
            AxisKind::Linear { lo, hi } => {
                if lo < 0.0 && 0.0 < hi {
                    out.push(0.0);
                }
            }
            AxisKind::Log {
                centre,
                min_offset,
                sides,
                ..
            } => match sides {
                Sides::Both => {
                    out.push(centre);
                    out.push(centre - min_offset);
                    out.push(centre + min_offset);
                }
                Sides::Above => out.push(centre + min_offset),
                Sides::Below => out.push(centre - min_offset),
            },
        }
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }

    /// `n` points at `u = i/(n−1)` (see [`at`](Self::at)) merged with the
    /// [special points](Self::special_points), sorted and without duplicates.
    pub fn grid(&self, n: usize) -> Vec<f64> {
        let mut out = self.special_points();
        match n {
            0 => {}
            1 => out.push(self.at(0.5)),
            _ => out.extend((0..n).map(|i| self.at(i as f64 / (n - 1) as f64))),
        }
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }
}

/// A claim that a law is a one-sided contact with a stop at `stop` (see the
/// [module docs](super) for what is checked).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ContactClaim {
    /// The stop position `x_I`: the contact starts there.
    pub stop: f64,
    /// [`Side::Upper`]: contact for `x > x_I`, force `F ≥ 0` (pushes towards smaller `x`).
    /// [`Side::Lower`]: contact for `x < x_I`, force `F ≤ 0`.
    pub side: Side,
}

impl ContactClaim {
    /// A contact with a stop at `stop` on `side` (validated by [`CheckConfig::new`]).
    pub fn new(stop: f64, side: Side) -> Self {
        Self { stop, side }
    }

    /// The penetration `x − x_I` (upper) or `x_I − x` (lower).
    fn penetration(&self, x: f64) -> f64 {
        match self.side {
            Side::Upper => x - self.stop,
            Side::Lower => self.stop - x,
        }
    }
}

/// The properties a law claims; [`check_law`] verifies each claimed property (and always
/// that the output is finite).
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct LawSpec {
    /// `F(x, v)·v ≥ 0` everywhere (dampers, friction).
    pub dissipative: bool,
    /// A one-sided contact: zero when separated, never adhesive, continuous at onset.
    pub contact: Option<ContactClaim>,
    /// [`ForceLaw::partials`] matches finite differences away from the declared kinks.
    pub analytic_partials: bool,
    /// Positions `x = x_k` where the law is not differentiable in `x` (the stop of a
    /// [`contact`](Self::contact) claim is added automatically).
    pub kinks_x: Vec<f64>,
    /// Velocities `v = v_k` where the law is not differentiable in `v` (e.g. `v = 0` for
    /// `|v|^{n3}` damping with `n3 < 1`, or the cut-off velocity of a clamped damping term).
    pub kinks_v: Vec<f64>,
}

impl LawSpec {
    /// No claims: only finiteness is checked.
    pub fn new() -> Self {
        Self::default()
    }

    /// Claims `F(x, v)·v ≥ 0`.
    pub fn dissipative(mut self) -> Self {
        self.dissipative = true;
        self
    }

    /// Claims a one-sided contact.
    pub fn contact(mut self, claim: ContactClaim) -> Self {
        self.contact = Some(claim);
        self
    }

    /// Claims analytic partials that match finite differences.
    pub fn analytic_partials(mut self) -> Self {
        self.analytic_partials = true;
        self
    }

    /// Declares a kink at `x = x_k`.
    pub fn kink_x(mut self, x_k: f64) -> Self {
        self.kinks_x.push(x_k);
        self
    }

    /// Declares a kink at `v = v_k`.
    pub fn kink_v(mut self, v_k: f64) -> Self {
        self.kinks_v.push(v_k);
        self
    }
}

/// What [`check_law`] checks and where.
///
/// Built by [`CheckConfig::new`] (which validates the domain and the claims) and tuned with
/// the `with_*` methods; the defaults are listed on each.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckConfig {
    x: GridAxis,
    v: GridAxis,
    spec: LawSpec,
    grid: usize,
    random: usize,
    seed: u64,
    partials_rel_tol: f64,
    kink_margin: f64,
    onset_rel_tol: f64,
    onset_decades: u32,
}

impl CheckConfig {
    /// Default grid points per axis.
    pub const DEFAULT_GRID: usize = 33;
    /// Default number of pseudo-random points.
    pub const DEFAULT_RANDOM: usize = 4096;
    /// Default seed of the pseudo-random points.
    pub const DEFAULT_SEED: u64 = 0x6e6f_6e73_6d6f_6f74;
    /// Default relative tolerance of the partials check.
    pub const DEFAULT_PARTIALS_REL_TOL: f64 = 1e-6;
    /// Default kink margin, relative to `max(|kink|, axis scale)`.
    pub const DEFAULT_KINK_MARGIN: f64 = 1e-10;
    /// Default onset ratio `|F(h_min)| / |F(h_ref)|` allowed.
    pub const DEFAULT_ONSET_REL_TOL: f64 = 1e-2;
    /// Default number of decades the onset probe descends below the smallest penetration.
    pub const DEFAULT_ONSET_DECADES: u32 = 8;

    /// Checks `spec` on the rectangle `x × v`.
    ///
    /// # Errors
    /// [`ParameterError`] if a contact stop or a declared kink is not finite.
    pub fn new(x: GridAxis, v: GridAxis, spec: LawSpec) -> Result<Self, ParameterError> {
        if let Some(c) = &spec.contact {
            if !c.stop.is_finite() {
                return Err(ParameterError::new("contact.stop", c.stop, "finite"));
            }
        }
        if let Some(&k) = spec.kinks_x.iter().find(|k| !k.is_finite()) {
            return Err(ParameterError::new("kinks_x", k, "finite"));
        }
        if let Some(&k) = spec.kinks_v.iter().find(|k| !k.is_finite()) {
            return Err(ParameterError::new("kinks_v", k, "finite"));
        }
        Ok(Self {
            x,
            v,
            spec,
            grid: Self::DEFAULT_GRID,
            random: Self::DEFAULT_RANDOM,
            seed: Self::DEFAULT_SEED,
            partials_rel_tol: Self::DEFAULT_PARTIALS_REL_TOL,
            kink_margin: Self::DEFAULT_KINK_MARGIN,
            onset_rel_tol: Self::DEFAULT_ONSET_REL_TOL,
            onset_decades: Self::DEFAULT_ONSET_DECADES,
        })
    }

    /// Grid points per axis (default [`DEFAULT_GRID`](Self::DEFAULT_GRID)); the grid is the
    /// Cartesian product of the two axes' [grids](GridAxis::grid).
    pub fn with_grid(mut self, n: usize) -> Self {
        self.grid = n;
        self
    }

    /// Number of pseudo-random points (default [`DEFAULT_RANDOM`](Self::DEFAULT_RANDOM)).
    pub fn with_random(mut self, n: usize) -> Self {
        self.random = n;
        self
    }

    /// Seed of the pseudo-random points (SplitMix64; default
    /// [`DEFAULT_SEED`](Self::DEFAULT_SEED)). The check is deterministic for a given seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Relative tolerance of the partials check (default
    /// [`DEFAULT_PARTIALS_REL_TOL`](Self::DEFAULT_PARTIALS_REL_TOL)).
    ///
    /// # Errors
    /// [`ParameterError`] unless `rel_tol` is finite and > 0.
    pub fn with_partials_tolerance(mut self, rel_tol: f64) -> Result<Self, ParameterError> {
        if !(rel_tol.is_finite() && rel_tol > 0.0) {
            return Err(ParameterError::new("rel_tol", rel_tol, "finite and > 0"));
        }
        self.partials_rel_tol = rel_tol;
        Ok(self)
    }

    /// Kink margin (default [`DEFAULT_KINK_MARGIN`](Self::DEFAULT_KINK_MARGIN)): a partial is
    /// not compared where the point lies within `margin·max(|kink|, axis scale)` of a
    /// declared kink of its variable.
    ///
    /// # Errors
    /// [`ParameterError`] unless `margin` is finite and ≥ 0.
    pub fn with_kink_margin(mut self, margin: f64) -> Result<Self, ParameterError> {
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(ParameterError::new("margin", margin, "finite and >= 0"));
        }
        self.kink_margin = margin;
        Ok(self)
    }

    /// The onset-continuity probe: descend `decades` decades below the smallest penetration of
    /// the grid and require `|F(h_min)| ≤ rel_tol·|F(h_ref)|` (defaults
    /// [`DEFAULT_ONSET_DECADES`](Self::DEFAULT_ONSET_DECADES),
    /// [`DEFAULT_ONSET_REL_TOL`](Self::DEFAULT_ONSET_REL_TOL)).
    ///
    /// # Errors
    /// [`ParameterError`] unless `decades ≥ 1` and `0 < rel_tol < 1`.
    pub fn with_onset_probe(mut self, decades: u32, rel_tol: f64) -> Result<Self, ParameterError> {
        if decades == 0 {
            return Err(ParameterError::new("decades", 0.0, ">= 1"));
        }
        if !(rel_tol > 0.0 && rel_tol < 1.0) {
            return Err(ParameterError::new("rel_tol", rel_tol, "in (0, 1)"));
        }
        self.onset_decades = decades;
        self.onset_rel_tol = rel_tol;
        Ok(self)
    }

    /// The position axis.
    pub fn x(&self) -> &GridAxis {
        &self.x
    }

    /// The velocity axis.
    pub fn v(&self) -> &GridAxis {
        &self.v
    }

    /// The claimed properties.
    pub fn spec(&self) -> &LawSpec {
        &self.spec
    }

    /// Declared `x`-kinks, including the contact stop.
    fn kinks_x(&self) -> Vec<f64> {
        let mut k = self.spec.kinks_x.clone();
        if let Some(c) = &self.spec.contact {
            k.push(c.stop);
        }
        k
    }
}

/// The properties [`check_law`] verifies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Property {
    /// Force (everywhere) and partials (away from declared kinks) are finite.
    Finite,
    /// `F(x, v)·v ≥ 0`.
    Dissipative,
    /// Zero force when separated from the stop.
    SeparatedZero,
    /// The contact force never pulls towards the stop.
    NonAdhesive,
    /// `F(x_I ± h, v) → 0` as `h → 0⁺`.
    OnsetContinuity,
    /// Analytic partials match finite differences.
    AnalyticPartials,
}

impl fmt::Display for Property {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Property::Finite => "finite output",
            Property::Dissipative => "dissipative",
            Property::SeparatedZero => "zero force when separated",
            Property::NonAdhesive => "non-adhesive contact",
            Property::OnsetContinuity => "continuity at contact onset",
            Property::AnalyticPartials => "analytic partials",
        })
    }
}

/// The variable of a partial derivative.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Variable {
    /// `∂F/∂x`.
    X,
    /// `∂F/∂v`.
    V,
}

impl fmt::Display for Variable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Variable::X => "x",
            Variable::V => "v",
        })
    }
}

/// A property a law claimed (or finiteness) failed at a point; returned by [`check_law`].
///
/// Coordinates are those the law was evaluated at (after rounding to its scalar type), as
/// `f64`. [`property`](Self::property) says which property failed, [`point`](Self::point)
/// where.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum LawViolation {
    /// The force is NaN or infinite (at a grid or random point, at an onset probe, or at a
    /// finite-difference stencil point within `2κ·d` of one).
    #[error("force is not finite at x = {x:e}, v = {v:e}: F = {force}")]
    NonFiniteForce {
        /// Position.
        x: f64,
        /// Velocity.
        v: f64,
        /// The force returned.
        force: f64,
    },
    /// A partial is NaN or infinite away from the declared kinks.
    #[error(
        "partials are not finite at x = {x:e}, v = {v:e}: dF/dx = {dfdx}, dF/dv = {dfdv} \
         (declare a kink if the law is not differentiable there)"
    )]
    NonFinitePartials {
        /// Position.
        x: f64,
        /// Velocity.
        v: f64,
        /// `∂F/∂x` returned.
        dfdx: f64,
        /// `∂F/∂v` returned.
        dfdv: f64,
    },
    /// `F·v < 0` for a law claimed dissipative.
    #[error("not dissipative at x = {x:e}, v = {v:e}: F = {force:e}, F·v = {power:e} < 0")]
    NotDissipative {
        /// Position.
        x: f64,
        /// Velocity.
        v: f64,
        /// The force.
        force: f64,
        /// `F·v`.
        power: f64,
    },
    /// Non-zero force while separated from the stop.
    #[error("force {force:e} while separated from the stop at x = {x:e}, v = {v:e}")]
    ForceWhenSeparated {
        /// Position.
        x: f64,
        /// Velocity.
        v: f64,
        /// The force (should be 0).
        force: f64,
    },
    /// The contact force pulls towards the stop (`F < 0` for an upper stop).
    #[error("adhesive contact force {force:e} at x = {x:e}, v = {v:e}")]
    Adhesive {
        /// Position.
        x: f64,
        /// Velocity.
        v: f64,
        /// The force (wrong sign).
        force: f64,
    },
    /// The force does not vanish as the penetration goes to zero.
    #[error(
        "discontinuous at contact onset (v = {v:e}): F = {force:e} at penetration {penetration:e}, \
         but F = {reference_force:e} at penetration {reference_penetration:e}"
    )]
    DiscontinuousOnset {
        /// Position of the deepest probe `x_I ± h_min`.
        x: f64,
        /// Velocity.
        v: f64,
        /// The smallest penetration probed, `h_min`.
        penetration: f64,
        /// `F` at `h_min`.
        force: f64,
        /// The reference penetration `h_ref`.
        reference_penetration: f64,
        /// `F` at `h_ref`.
        reference_force: f64,
    },
    /// An analytic partial differs from the finite difference by more than the tolerance.
    #[error(
        "dF/d{wrt} = {analytic:e} at x = {x:e}, v = {v:e}, but the finite difference (step \
         {step:e}) gives {finite_difference:e} (tolerance {tolerance:e}); if the law has a kink \
         there, declare it"
    )]
    WrongPartial {
        /// The variable differentiated.
        wrt: Variable,
        /// Position.
        x: f64,
        /// Velocity.
        v: f64,
        /// The law's partial.
        analytic: f64,
        /// The central finite difference.
        finite_difference: f64,
        /// Half-width of the finite-difference stencil.
        step: f64,
        /// The allowed difference.
        tolerance: f64,
    },
}

impl LawViolation {
    /// The property that failed.
    pub fn property(&self) -> Property {
        match self {
            LawViolation::NonFiniteForce { .. } | LawViolation::NonFinitePartials { .. } => {
                Property::Finite
            }
            LawViolation::NotDissipative { .. } => Property::Dissipative,
            LawViolation::ForceWhenSeparated { .. } => Property::SeparatedZero,
            LawViolation::Adhesive { .. } => Property::NonAdhesive,
            LawViolation::DiscontinuousOnset { .. } => Property::OnsetContinuity,
            LawViolation::WrongPartial { .. } => Property::AnalyticPartials,
        }
    }

    /// The point `(x, v)` where it failed.
    pub fn point(&self) -> (f64, f64) {
        match *self {
            LawViolation::NonFiniteForce { x, v, .. }
            | LawViolation::NonFinitePartials { x, v, .. }
            | LawViolation::NotDissipative { x, v, .. }
            | LawViolation::ForceWhenSeparated { x, v, .. }
            | LawViolation::Adhesive { x, v, .. }
            | LawViolation::DiscontinuousOnset { x, v, .. }
            | LawViolation::WrongPartial { x, v, .. } => (x, v),
        }
    }
}

/// What [`check_law`] verified.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct CheckReport {
    /// Points `(x, v)` evaluated (grid and pseudo-random).
    pub points: usize,
    /// Dissipation checks (`F·v ≥ 0`) made.
    pub dissipation_checks: usize,
    /// Points checked for zero force while separated.
    pub separated_checks: usize,
    /// Points checked for non-adhesion (in contact).
    pub contact_checks: usize,
    /// Velocities at which continuity at onset was probed.
    pub onset_probes: usize,
    /// Partials (one per variable and point) compared with finite differences.
    pub partials_checked: usize,
    /// Partials not compared because the point lies within the margin of a declared kink.
    pub partials_skipped: usize,
    /// The largest `|analytic − finite difference| / tolerance` seen (≤ 1 when passing).
    pub max_partial_error_ratio: f64,
}

/// Verifies the claimed properties of `law` on the configured domain.
///
/// Evaluates the Cartesian grid of the two axes, then the onset probe (for a contact
/// claim), then the configured number of pseudo-random points (SplitMix64 from the seed);
/// the first failure is returned. Deterministic for a given configuration. The points are
/// given in `f64` and rounded to `T`; the finite-difference steps and noise floors use the
/// machine epsilon of `T`.
///
/// # Errors
/// The first [`LawViolation`] found.
///
/// # Examples
/// See the [module documentation](super).
pub fn check_law<T: Real, L: ForceLaw<T> + ?Sized>(
    law: &L,
    config: &CheckConfig,
) -> Result<CheckReport, LawViolation> {
    let mut ctx = Checker::<T, L> {
        law,
        config,
        kinks_x: config.kinks_x(),
        report: CheckReport::default(),
        _t: std::marker::PhantomData,
    };
    let xs = config.x.grid(config.grid);
    let vs = config.v.grid(config.grid);
    for &x in &xs {
        for &v in &vs {
            ctx.point(x, v)?;
        }
    }
    let mut rng = SplitMix64(config.seed);
    if let Some(claim) = config.spec.contact {
        // Onset probes at every grid velocity and at some pseudo-random ones.
        let h_ref = xs
            .iter()
            .map(|&x| claim.penetration(x))
            .filter(|&p| p > 0.0)
            .fold(f64::INFINITY, f64::min);
        let h_ref = if h_ref.is_finite() {
            h_ref
        } else {
            1e-6 * config
                .x
                .scale()
                .max(claim.stop.abs())
                .max(f64::MIN_POSITIVE)
        };
        let n_random_v = config.random.min(64);
        let extra: Vec<f64> = (0..n_random_v).map(|_| config.v.at(rng.unit())).collect();
        for &v in vs.iter().chain(extra.iter()) {
            ctx.onset(claim, h_ref, v)?;
        }
    }
    for _ in 0..config.random {
        let x = config.x.at(rng.unit());
        let v = config.v.at(rng.unit());
        ctx.point(x, v)?;
    }
    Ok(ctx.report)
}

/// A proptest strategy over the points `(x, v)` of the configured domain: log-uniform on
/// logarithmic axes, with the axes' [special points](GridAxis::special_points) drawn one time in
/// eight. Use it to write your own property tests of a law.
///
/// ```
/// use nonsmooth::testing::{GridAxis, CheckConfig, LawSpec, points_in};
/// use proptest::strategy::{Strategy, ValueTree};
/// use proptest::test_runner::TestRunner;
///
/// let cfg = CheckConfig::new(
///     GridAxis::linear(-1.0, 1.0)?,
///     GridAxis::log_around(0.0, 1e-8, 1.0)?,
///     LawSpec::new(),
/// )?;
/// let mut runner = TestRunner::deterministic();
/// let (x, v) = points_in(&cfg).new_tree(&mut runner).unwrap().current();
/// assert!((-1.0..=1.0).contains(&x) && v.abs() <= 1.0);
/// # Ok::<(), nonsmooth::ParameterError>(())
/// ```
pub fn points_in(config: &CheckConfig) -> impl Strategy<Value = (f64, f64)> + Clone + use<> {
    (axis_values(&config.x), axis_values(&config.v))
}

/// A proptest strategy over one axis (see [`points_in`]).
pub fn axis_values(axis: &GridAxis) -> impl Strategy<Value = f64> + Clone + use<> {
    let a = *axis;
    let specials = a.special_points();
    prop_oneof![
        7 => (0.0..=1.0_f64).prop_map(move |u| a.at(u)),
        1 => proptest::sample::select(specials),
    ]
}

/// Step of a central difference, as a fraction of the distance to the nearest kink: keeps
/// the stencil (which reaches `2h`) inside the smooth piece and the truncation error of power laws `d^p` at
/// `≈ |(p−1)(p−2)|·κ²/6` relative.
const KINK_STEP_FRACTION: f64 = 1e-4;
/// Rounding-noise allowance of a finite difference, in units of `ε·max|F|/h`.
const NOISE_FACTOR: f64 = 32.0;

struct Checker<'a, T, L: ?Sized> {
    law: &'a L,
    config: &'a CheckConfig,
    kinks_x: Vec<f64>,
    report: CheckReport,
    _t: std::marker::PhantomData<T>,
}

impl<T: Real, L: ForceLaw<T> + ?Sized> Checker<'_, T, L> {
    fn force(&self, x: T, v: T) -> Result<T, LawViolation> {
        let f = self.law.force(x, v);
        if f.is_finite() {
            Ok(f)
        } else {
            Err(LawViolation::NonFiniteForce {
                x: to_f64(x),
                v: to_f64(v),
                force: to_f64(f),
            })
        }
    }

    /// Distance (in `T`) from `p` to the nearest kink, and the skip margin for that kink.
    fn kink_distance(&self, p: T, kinks: &[f64], axis: &GridAxis) -> (T, bool) {
        let mut best = T::max_value().unwrap_or(T::one());
        let mut near = false;
        let margin = lit::<T>(self.config.kink_margin).max(lit::<T>(4.0) * epsilon::<T>());
        for &k in kinks {
            let kt: T = lit(k);
            let d = (p - kt).abs();
            let scale = lit::<T>(k.abs().max(axis.scale()));
            if d <= margin * scale {
                near = true;
            }
            best = best.min(d);
        }
        (best, near)
    }

    fn point(&mut self, x64: f64, v64: f64) -> Result<(), LawViolation> {
        let x: T = lit(x64);
        let v: T = lit(v64);
        let (xr, vr) = (to_f64(x), to_f64(v));
        self.report.points += 1;
        let f = self.force(x, v)?;
        let (dist_x, near_x) = self.kink_distance(x, &self.kinks_x, &self.config.x);
        let (dist_v, near_v) = self.kink_distance(v, &self.config.spec.kinks_v, &self.config.v);
        let (fx, fv) = self.law.partials(x, v);
        if (!near_x && !fx.is_finite()) || (!near_v && !fv.is_finite()) {
            return Err(LawViolation::NonFinitePartials {
                x: xr,
                v: vr,
                dfdx: to_f64(fx),
                dfdv: to_f64(fv),
            });
        }
        let spec = &self.config.spec;
        if spec.dissipative {
            self.report.dissipation_checks += 1;
            let power = f * v;
            if power < T::zero() {
                return Err(LawViolation::NotDissipative {
                    x: xr,
                    v: vr,
                    force: to_f64(f),
                    power: to_f64(power),
                });
            }
        }
        if let Some(c) = spec.contact {
            let stop: T = lit(c.stop);
            let separated = match c.side {
                Side::Upper => x <= stop,
                Side::Lower => x >= stop,
            };
            if separated {
                self.report.separated_checks += 1;
                if f != T::zero() {
                    return Err(LawViolation::ForceWhenSeparated {
                        x: xr,
                        v: vr,
                        force: to_f64(f),
                    });
                }
            } else {
                self.report.contact_checks += 1;
                let adhesive = match c.side {
                    Side::Upper => f < T::zero(),
                    Side::Lower => f > T::zero(),
                };
                if adhesive {
                    return Err(LawViolation::Adhesive {
                        x: xr,
                        v: vr,
                        force: to_f64(f),
                    });
                }
            }
        }
        if spec.analytic_partials {
            for (wrt, analytic, dist, near) in [
                (Variable::X, fx, dist_x, near_x),
                (Variable::V, fv, dist_v, near_v),
            ] {
                if near {
                    self.report.partials_skipped += 1;
                    continue;
                }
                self.compare_partial(wrt, x, v, f, analytic, dist)?;
            }
        }
        Ok(())
    }

    /// Compares one analytic partial with central differences of half-widths `h` and `2h`,
    /// `h = min(∛ε·max(|p|, 10⁻⁸·scale), κ·d)` (`d` the distance to the nearest kink).
    fn compare_partial(
        &mut self,
        wrt: Variable,
        x: T,
        v: T,
        f: T,
        analytic: T,
        dist: T,
    ) -> Result<(), LawViolation> {
        let (p, axis) = match wrt {
            Variable::X => (x, &self.config.x),
            Variable::V => (v, &self.config.v),
        };
        let eps = epsilon::<T>();
        let s = p.abs().max(lit::<T>(1e-8 * axis.scale()));
        let h = (eps.powf(lit(1.0 / 3.0)) * s).min(lit::<T>(KINK_STEP_FRACTION) * dist);
        let (pp, pm) = (p + h, p - h);
        let (pp2, pm2) = (p + h + h, p - h - h);
        let width = pp - pm;
        let width2 = pp2 - pm2;
        if width <= T::zero() || width2 <= T::zero() {
            self.report.partials_skipped += 1;
            return Ok(());
        }
        let eval = |a: T| match wrt {
            Variable::X => self.force(a, v),
            Variable::V => self.force(x, a),
        };
        let (fp, fm) = (eval(pp)?, eval(pm)?);
        let (fp2, fm2) = (eval(pp2)?, eval(pm2)?);
        let fd = (fp - fm) / width;
        let fd2 = (fp2 - fm2) / width2;
        let half = width * lit(0.5);
        let m = fp.abs().max(fm.abs()).max(f.abs());
        let noise = lit::<T>(NOISE_FACTOR) * eps * m / half;
        // Richardson: the truncation error of `fd` is about |fd − fd2|/3 (it scales as h²);
        // allowing |fd − fd2| covers it where the derivative itself is ~0.
        let truncation = (fd - fd2).abs();
        let tol = lit::<T>(self.config.partials_rel_tol) * analytic.abs().max(fd.abs())
            + noise
            + truncation;
        let err = (analytic - fd).abs();
        self.report.partials_checked += 1;
        let ratio = if tol > T::zero() {
            to_f64(err / tol)
        } else if err > T::zero() {
            f64::INFINITY
        } else {
            0.0
        };
        // Incomparable (NaN) counts as a failure.
        let within = matches!(
            err.partial_cmp(&tol),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        );
        if !within {
            return Err(LawViolation::WrongPartial {
                wrt,
                x: to_f64(x),
                v: to_f64(v),
                analytic: to_f64(analytic),
                finite_difference: to_f64(fd),
                step: to_f64(half),
                tolerance: to_f64(tol),
            });
        }
        self.report.max_partial_error_ratio = self.report.max_partial_error_ratio.max(ratio);
        Ok(())
    }

    /// `|F(x_I ± h_min, v)| ≤ tol·|F(x_I ± h_ref, v)|` with `h_min = h_ref·10^{−decades}`
    /// (bounded below by what `T` resolves next to the stop).
    fn onset(&mut self, claim: ContactClaim, h_ref: f64, v64: f64) -> Result<(), LawViolation> {
        let eps = to_f64(epsilon::<T>());
        let resolvable = 16.0 * eps * claim.stop.abs().max(h_ref);
        let h_min = (h_ref * 10f64.powi(-(self.config.onset_decades as i32))).max(resolvable);
        if h_min >= 1e-1 * h_ref {
            return Ok(());
        }
        let at = |h: f64| -> T {
            match claim.side {
                Side::Upper => lit::<T>(claim.stop) + lit::<T>(h),
                Side::Lower => lit::<T>(claim.stop) - lit::<T>(h),
            }
        };
        let v: T = lit(v64);
        let (x_ref, x_min) = (at(h_ref), at(h_min));
        let f_ref = self.force(x_ref, v)?;
        let f_min = self.force(x_min, v)?;
        self.report.onset_probes += 1;
        if f_min.abs() > lit::<T>(self.config.onset_rel_tol) * f_ref.abs() {
            return Err(LawViolation::DiscontinuousOnset {
                x: to_f64(x_min),
                v: to_f64(v),
                penetration: h_min,
                force: to_f64(f_min),
                reference_penetration: h_ref,
                reference_force: to_f64(f_ref),
            });
        }
        Ok(())
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): a tiny deterministic generator, enough to scatter
/// check points.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_reference_values() {
        // First outputs for seed 1234567 (reference implementation by S. Vigna).
        let mut r = SplitMix64(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
        let mut r = SplitMix64(7);
        for _ in 0..1000 {
            let u = r.unit();
            assert!((0.0..1.0).contains(&u));
        }
    }

    #[test]
    fn axes_map_and_grid() {
        let a = GridAxis::log_around(-2e-3, 1e-9, 1e-4).unwrap();
        assert_eq!(a.at(0.0), -2e-3 - 1e-4);
        assert_eq!(a.at(1.0), -2e-3 + 1e-4);
        assert!((a.at(0.75) - (-2e-3 + 1e-9 * 1e5_f64.powf(0.5))).abs() < 1e-18);
        let g = a.grid(9);
        assert!(g.contains(&-2e-3));
        assert!(g.windows(2).all(|w| w[0] < w[1]));
        let above = GridAxis::log_around(0.0, 1e-8, 1.0)
            .unwrap()
            .with_sides(Sides::Above);
        assert_eq!(above.bounds(), (1e-8, 1.0));
        assert!(above.grid(5).iter().all(|&v| v > 0.0));
        let below = GridAxis::log_around(0.0, 1e-8, 1.0)
            .unwrap()
            .with_sides(Sides::Below);
        assert!(below.grid(5).iter().all(|&v| v < 0.0));
        let l = GridAxis::linear(-1.0, 3.0).unwrap();
        assert_eq!(l.grid(5), vec![-1.0, 0.0, 1.0, 2.0, 3.0]);
        assert_eq!(l.scale(), 3.0);
        assert!(GridAxis::linear(1.0, 1.0).is_err());
        assert!(GridAxis::linear(f64::NAN, 1.0).is_err());
        assert!(GridAxis::log_around(0.0, 0.0, 1.0).is_err());
        assert!(GridAxis::log_around(0.0, 2.0, 1.0).is_err());
    }

    #[test]
    fn config_validation() {
        let x = GridAxis::linear(-1.0, 1.0).unwrap();
        let spec = LawSpec::new().contact(ContactClaim::new(f64::NAN, Side::Upper));
        assert!(CheckConfig::new(x, x, spec).is_err());
        assert!(CheckConfig::new(x, x, LawSpec::new().kink_v(f64::INFINITY)).is_err());
        let c = CheckConfig::new(x, x, LawSpec::new()).unwrap();
        assert!(c.clone().with_partials_tolerance(0.0).is_err());
        assert!(c.clone().with_kink_margin(-1.0).is_err());
        assert!(c.clone().with_onset_probe(0, 0.1).is_err());
        assert!(c.with_onset_probe(4, 1.0).is_err());
    }
}
