//! Named parameters and the map between physical values and the optimizer's vector.

use std::sync::Arc;

use super::IdentifyError;

/// How a parameter is reparametrized before the bounds are applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Transform {
    /// `z = x`.
    #[default]
    Identity,
    /// `z = ln x`: the parameter stays positive and the simplex moves in relative steps —
    /// the natural choice for stiffnesses, damping coefficients and friction forces that
    /// span orders of magnitude (`k_I ≈ 2.4·10⁸`, `c ≈ 6.7`).
    Log,
}

/// One named parameter: initial value, optional bounds, transform.
///
/// ```
/// use nonsmooth::identify::{Parameter, Transform};
/// let k = Parameter::positive("k", 1418.9).with_bounds(500.0, 5000.0);
/// assert_eq!(k.transform(), Transform::Log);
/// assert_eq!(k.bounds(), (Some(500.0), Some(5000.0)));
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Parameter {
    name: String,
    initial: f64,
    lower: Option<f64>,
    upper: Option<f64>,
    transform: Transform,
}

impl Parameter {
    /// An unbounded parameter with [`Transform::Identity`]. Validation happens in
    /// [`ParameterSpace::new`].
    pub fn new(name: impl Into<String>, initial: f64) -> Self {
        Self {
            name: name.into(),
            initial,
            lower: None,
            upper: None,
            transform: Transform::Identity,
        }
    }

    /// A positive parameter ([`Transform::Log`]).
    pub fn positive(name: impl Into<String>, initial: f64) -> Self {
        Self::new(name, initial).with_transform(Transform::Log)
    }

    /// Sets the transform.
    #[must_use]
    pub fn with_transform(mut self, transform: Transform) -> Self {
        self.transform = transform;
        self
    }

    /// Sets both bounds (inclusive).
    #[must_use]
    pub fn with_bounds(self, lower: f64, upper: f64) -> Self {
        self.with_lower(lower).with_upper(upper)
    }

    /// Sets the lower bound (inclusive).
    #[must_use]
    pub fn with_lower(mut self, lower: f64) -> Self {
        self.lower = Some(lower);
        self
    }

    /// Sets the upper bound (inclusive).
    #[must_use]
    pub fn with_upper(mut self, upper: f64) -> Self {
        self.upper = Some(upper);
        self
    }

    /// The name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The initial value.
    pub fn initial(&self) -> f64 {
        self.initial
    }

    /// `(lower, upper)`.
    pub fn bounds(&self) -> (Option<f64>, Option<f64>) {
        (self.lower, self.upper)
    }

    /// The transform.
    pub fn transform(&self) -> Transform {
        self.transform
    }
}

/// How `z = T(x)` is mapped to the unconstrained coordinate `u`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum BoundMap {
    /// `z = mid + half·sin u` (`= lo + (hi − lo)(1 + sin u)/2`), with `mid = lo/2 + hi/2`
    /// and `half = hi/2 − lo/2` (finite for bounds up to ±f64::MAX; values near the middle
    /// keep their own resolution, e.g. subnormal ones between −1 and 1).
    Both {
        lo: f64,
        hi: f64,
        mid: f64,
        half: f64,
    },
    /// `z = k·(lo + s(√(1 + (u/s)²) − 1))`, with the bound and the scale stored divided by
    /// `k` (1, or 8 for bounds or scales so large that `|z − bound|` or `u` would overflow).
    Lower { lo: f64, s: f64, k: f64 },
    /// `z = k·(hi − s(√(1 + (u/s)²) − 1))`, as [`Lower`](BoundMap::Lower).
    Upper { hi: f64, s: f64, k: f64 },
    /// `z = u`.
    Free,
}

/// `ln f64::MAX` plus 10⁻¹² (about ten units in its last place).
const LN_MAX_WITH_ROUNDING: f64 = 709.782_712_893_385;

/// The factor that one-sided maps divide `z` by when the unscaled map would overflow.
const WIDE: f64 = 8.0;

#[derive(Debug, Clone, PartialEq)]
struct Mapping {
    transform: Transform,
    bounds: BoundMap,
}

impl Mapping {
    fn z_of_x(&self, x: f64) -> f64 {
        match self.transform {
            Transform::Identity => x,
            Transform::Log => x.ln(),
        }
    }

    fn x_of_z(&self, z: f64) -> f64 {
        match self.transform {
            Transform::Identity => z,
            Transform::Log => {
                let x = z.exp();
                // ln f64::MAX rounded up by the bound maps (by a few units in the last place
                // of z ≈ 709.78) is f64::MAX, not an overflow.
                if x == f64::INFINITY && z <= LN_MAX_WITH_ROUNDING {
                    f64::MAX
                } else {
                    x
                }
            }
        }
    }

    fn z_of_u(&self, u: f64) -> f64 {
        match self.bounds {
            BoundMap::Free => u,
            BoundMap::Both { lo, hi, mid, half } => {
                let sin = u.sin();
                // The bounds themselves exactly; clamp: rounding must never leave [lo, hi].
                if sin >= 1.0 {
                    hi
                } else if sin <= -1.0 {
                    lo
                } else if half >= f64::MIN_POSITIVE {
                    (mid + half * sin).clamp(lo, hi)
                } else {
                    // Bounds a few subnormal steps apart: `half` would round.
                    (lo + (hi - lo) * (0.5 * (1.0 + sin))).clamp(lo, hi)
                }
            }
            // With k = 1 these are `lo + …` and `hi − …` (multiplying by 1 is exact).
            BoundMap::Lower { lo, s, k } => scaled_sum(k, lo, sqrt_one_plus_minus_one(u, s)),
            BoundMap::Upper { hi, s, k } => scaled_sum(k, hi, -sqrt_one_plus_minus_one(u, s)),
        }
    }

    fn u_of_z(&self, z: f64) -> f64 {
        match self.bounds {
            BoundMap::Free => z,
            BoundMap::Both { lo, hi, mid, half } => {
                if z >= hi {
                    std::f64::consts::FRAC_PI_2
                } else if z <= lo {
                    -std::f64::consts::FRAC_PI_2
                } else if half >= f64::MIN_POSITIVE {
                    ((z - mid) / half).clamp(-1.0, 1.0).asin()
                } else {
                    (2.0 * (z - lo) / (hi - lo) - 1.0).clamp(-1.0, 1.0).asin()
                }
            }
            BoundMap::Lower { lo, s, k } => inverse_sqrt_map(z / k - lo, s),
            BoundMap::Upper { hi, s, k } => inverse_sqrt_map(hi - z / k, s),
        }
    }
}

/// `k·(a + b)`; where that overflows by no more than the rounding of the maps (relative
/// 10⁻¹², the image of a value at ±f64::MAX), ±f64::MAX.
fn scaled_sum(k: f64, a: f64, b: f64) -> f64 {
    let z = k * (a + b);
    if z.is_infinite() && (0.5 * a + 0.5 * b).abs() <= 0.5 * f64::MAX / k * (1.0 + 1e-12) {
        f64::MAX.copysign(z)
    } else {
        z
    }
}

/// The one-sided map for bound `b` with the domain reaching `far` (`±f64::MAX`): the bound
/// and the scale divided by `k`, and `k` — 1 where every `z` of the domain has a finite `u`
/// (`|far − b|`, the scale and `u` at `far` finite), [`WIDE`] otherwise (bounds or a start
/// within about `10²⁹²` of `∓f64::MAX`), where the same map in `z/8` keeps them finite.
fn one_sided(z0: f64, b: f64, far: f64) -> (f64, f64, f64) {
    let scaled = |k: f64| {
        let (z0, b) = (z0 / k, b / k);
        let d = (z0 - b).abs();
        let s = if d > 0.0 { d } else { z0.abs().max(1.0 / k) };
        (b, s)
    };
    let (b1, s1) = scaled(1.0);
    let reach = (far - b1).abs();
    if s1.is_finite() && reach.is_finite() && inverse_sqrt_map(reach, s1) < f64::INFINITY {
        (b1, s1, 1.0)
    } else {
        let (bk, sk) = scaled(WIDE);
        (bk, sk, WIDE)
    }
}

/// `s·(√(1 + (u/s)²) − 1) = u²/(√(u² + s²) + s)`, evaluated as `|u|·(|u|/(hypot(u, s) + s))`:
/// no cancellation for `|u| ≪ s`, no overflow of `u/s` for a tiny scale or of `u²` for a
/// large `u`.
fn sqrt_one_plus_minus_one(u: f64, s: f64) -> f64 {
    let a = u.abs();
    a * (a / (a.hypot(s) + s))
}

/// The inverse of [`sqrt_one_plus_minus_one`] on `d = |z − bound| ≥ 0`:
/// `s·√(r² − 1)` with `r = d/s + 1` is `√d·√(d + 2s)`. Infinite where `d` or `u` overflows,
/// which [`one_sided`] rules out for the values of a parameter's domain.
fn inverse_sqrt_map(d: f64, s: f64) -> f64 {
    let d = d.max(0.0);
    d.sqrt() * (d + 2.0 * s).sqrt()
}

/// Physical parameter values by name, as handed to the objective.
///
/// ```
/// use nonsmooth::identify::{Parameter, ParameterSpace};
/// let space = ParameterSpace::new([Parameter::new("k", 1418.9), Parameter::new("c", 6.65)])?;
/// let p = space.initial_values();
/// assert_eq!(p.get("c")?, 6.65);
/// assert_eq!(p["k"], 1418.9);
/// assert!(p.get("T").is_err());
/// # Ok::<(), nonsmooth::identify::IdentifyError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ParamValues {
    names: Arc<[String]>,
    values: Vec<f64>,
}

impl ParamValues {
    /// The value of `name`.
    ///
    /// # Errors
    /// [`IdentifyError::UnknownParameter`] if there is no such parameter.
    pub fn get(&self, name: &str) -> Result<f64, IdentifyError> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.values[i])
            .ok_or_else(|| IdentifyError::UnknownParameter { name: name.into() })
    }

    /// The values in the space's order.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The names in the space's order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// `(name, value)` pairs in order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> + '_ {
        self.names
            .iter()
            .map(String::as_str)
            .zip(self.values.iter().copied())
    }

    /// The number of parameters.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// `true` if there are no parameters (never, for values from a [`ParameterSpace`]).
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

/// `values["name"]`.
///
/// # Panics
/// If there is no parameter `name`; use [`ParamValues::get`] for a `Result`.
impl std::ops::Index<&str> for ParamValues {
    type Output = f64;
    fn index(&self, name: &str) -> &f64 {
        match self.names.iter().position(|n| n == name) {
            Some(i) => &self.values[i],
            None => panic!("no parameter named `{name}`"),
        }
    }
}

impl std::fmt::Display for ParamValues {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, (n, v)) in self.iter().enumerate() {
            if i > 0 {
                write!(f, ", ")?;
            }
            write!(f, "{n} = {v}")?;
        }
        Ok(())
    }
}

/// A set of named parameters and the bijection between their physical values `x` and the
/// unconstrained vector `u` the optimizer works on.
///
/// # Formula
/// Each parameter is first transformed, `z = x` or `z = ln x` ([`Transform`]); its bounds are
/// transformed alike (under `Log` a lower bound `≤ 0` is no constraint). Then the bounds in `z`
/// are removed by the MINUIT-style maps (F. James, *MINUIT Reference Manual*, Sect. 1.3):
/// $$ z = z_l + (z_h - z_l)\,\tfrac{1 + \sin u}{2} \quad\text{(both bounds)}, $$
/// $$ z = z_l + s\Bigl(\sqrt{1 + (u/s)^2} - 1\Bigr) \quad\text{(lower only; upper mirrored)}, $$
/// with the scale `s = |z_0 − z_l|` (or `max(|z_0|, 1)` if the initial value lies on the
/// bound), so that the map is nearly linear, of unit slope, around the start. Both maps reach
/// the bound at a finite `u` and are defined for every `u`, so the optimizer is
/// unconstrained and the objective is never called outside the bounds.
///
/// # Examples
/// ```
/// use nonsmooth::identify::{Parameter, ParameterSpace};
/// let space = ParameterSpace::new([
///     Parameter::positive("k_I", 2.3983e8),
///     Parameter::new("n3", 0.18667).with_bounds(0.0, 1.0),
/// ])?;
/// let u = space.to_unconstrained(&[2.0e8, 0.25])?;
/// let x = space.to_physical(&u)?;
/// assert!((x["k_I"] - 2.0e8).abs() < 1e-6 && (x["n3"] - 0.25).abs() < 1e-15);
/// // Any u maps inside the bounds.
/// let far = space.to_physical(&[50.0, 123.4])?;
/// assert!(far["k_I"] > 0.0 && (0.0..=1.0).contains(&far["n3"]));
/// # Ok::<(), nonsmooth::identify::IdentifyError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterSpace {
    params: Vec<Parameter>,
    names: Arc<[String]>,
    maps: Vec<Mapping>,
}

impl ParameterSpace {
    /// Validates the parameters and builds the maps.
    ///
    /// # Errors
    /// [`IdentifyError::EmptySpace`], [`IdentifyError::DuplicateParameter`],
    /// [`IdentifyError::NonFiniteInitial`], [`IdentifyError::InvalidBounds`] (NaN, or
    /// `lower ≥ upper`), [`IdentifyError::NonPositiveUnderLog`] (initial value or upper
    /// bound `≤ 0` under [`Transform::Log`]), [`IdentifyError::OutsideBounds`] for an initial
    /// value outside its bounds.
    pub fn new(params: impl IntoIterator<Item = Parameter>) -> Result<Self, IdentifyError> {
        let params: Vec<Parameter> = params.into_iter().collect();
        if params.is_empty() {
            return Err(IdentifyError::EmptySpace);
        }
        let mut maps = Vec::with_capacity(params.len());
        for (i, p) in params.iter().enumerate() {
            if params[..i].iter().any(|q| q.name == p.name) {
                return Err(IdentifyError::DuplicateParameter {
                    name: p.name.clone(),
                });
            }
            maps.push(Self::mapping(p)?);
        }
        let names: Arc<[String]> = params.iter().map(|p| p.name.clone()).collect();
        Ok(Self {
            params,
            names,
            maps,
        })
    }

    fn mapping(p: &Parameter) -> Result<Mapping, IdentifyError> {
        let name = || p.name.clone();
        if !p.initial.is_finite() {
            return Err(IdentifyError::NonFiniteInitial {
                name: name(),
                value: p.initial,
            });
        }
        let lo = p.lower.unwrap_or(f64::NEG_INFINITY);
        let hi = p.upper.unwrap_or(f64::INFINITY);
        if lo.is_nan() || hi.is_nan() || lo >= hi || lo == f64::INFINITY || hi == f64::NEG_INFINITY
        {
            return Err(IdentifyError::InvalidBounds {
                name: name(),
                lower: lo,
                upper: hi,
            });
        }
        if p.transform == Transform::Log {
            if p.initial <= 0.0 {
                return Err(IdentifyError::NonPositiveUnderLog {
                    name: name(),
                    what: "initial value",
                    value: p.initial,
                });
            }
            if hi <= 0.0 {
                return Err(IdentifyError::NonPositiveUnderLog {
                    name: name(),
                    what: "upper bound",
                    value: hi,
                });
            }
        }
        if !(lo <= p.initial && p.initial <= hi) {
            return Err(IdentifyError::OutsideBounds {
                name: name(),
                value: p.initial,
                lower: lo,
                upper: hi,
            });
        }
        let t = Mapping {
            transform: p.transform,
            bounds: BoundMap::Free,
        };
        let z0 = t.z_of_x(p.initial);
        // Transformed bounds; under Log a lower bound ≤ 0 is no constraint (ln → −∞).
        let zl = if lo.is_finite() && !(p.transform == Transform::Log && lo <= 0.0) {
            Some(t.z_of_x(lo))
        } else {
            None
        };
        let zh = hi.is_finite().then(|| t.z_of_x(hi));
        let bounds = match (zl, zh) {
            (None, None) => BoundMap::Free,
            (Some(lo), Some(hi)) => BoundMap::Both {
                lo,
                hi,
                mid: 0.5 * lo + 0.5 * hi,
                half: 0.5 * hi - 0.5 * lo,
            },
            (Some(lo), None) => {
                let (lo, s, k) = one_sided(z0, lo, f64::MAX);
                BoundMap::Lower { lo, s, k }
            }
            (None, Some(hi)) => {
                let (hi, s, k) = one_sided(z0, hi, -f64::MAX);
                BoundMap::Upper { hi, s, k }
            }
        };
        Ok(Mapping {
            transform: p.transform,
            bounds,
        })
    }

    /// The number of parameters.
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// Always `false` (an empty space is rejected by [`new`](Self::new)).
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// The parameters in order.
    pub fn parameters(&self) -> &[Parameter] {
        &self.params
    }

    /// The names in order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The position of `name`.
    ///
    /// # Errors
    /// [`IdentifyError::UnknownParameter`].
    pub fn index_of(&self, name: &str) -> Result<usize, IdentifyError> {
        self.names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| IdentifyError::UnknownParameter { name: name.into() })
    }

    /// The initial values.
    pub fn initial_values(&self) -> ParamValues {
        ParamValues {
            names: Arc::clone(&self.names),
            values: self.params.iter().map(|p| p.initial).collect(),
        }
    }

    /// Wraps physical values (in the space's order) as [`ParamValues`], checking them.
    ///
    /// # Errors
    /// As [`to_unconstrained`](Self::to_unconstrained).
    pub fn values(&self, values: Vec<f64>) -> Result<ParamValues, IdentifyError> {
        self.to_unconstrained(&values)?;
        Ok(ParamValues {
            names: Arc::clone(&self.names),
            values,
        })
    }

    /// Maps physical values to the optimizer's vector `u`.
    ///
    /// # Errors
    /// [`IdentifyError::DimensionMismatch`], [`IdentifyError::NonFiniteValue`] for NaN/∞,
    /// [`IdentifyError::NonPositiveUnderLog`], [`IdentifyError::OutsideBounds`].
    pub fn to_unconstrained(&self, values: &[f64]) -> Result<Vec<f64>, IdentifyError> {
        self.check_len(values.len())?;
        let mut u = Vec::with_capacity(values.len());
        for ((p, m), &x) in self.params.iter().zip(&self.maps).zip(values) {
            if !x.is_finite() {
                return Err(IdentifyError::NonFiniteValue {
                    name: p.name.clone(),
                    value: x,
                });
            }
            let probe = Parameter {
                initial: x,
                ..p.clone()
            };
            Self::mapping(&probe)?;
            u.push(m.u_of_z(m.z_of_x(x)));
        }
        Ok(u)
    }

    /// Maps the optimizer's vector `u` to physical values, always within the bounds (the
    /// result is clamped to them against rounding; a `Log` value that underflows to 0
    /// becomes the smallest positive `f64`, 5e-324).
    ///
    /// `to_physical(to_unconstrained(x))` gives `x` back to a few units in the last place
    /// of the coordinate the bounds are applied in: of `ln x` under [`Transform::Log`]
    /// (relative error below 10⁻¹³, subnormal values included), of `max(|x|, |bound|)` with
    /// one bound, of the bounds' half-span measured from their middle with both, for every
    /// finite `x` in the bounds (±f64::MAX included).
    ///
    /// # Errors
    /// [`IdentifyError::DimensionMismatch`]; [`IdentifyError::NonFiniteValue`] if a value
    /// is not finite (NaN in `u`, `exp` overflow under [`Transform::Log`], or a `u` beyond
    /// the one that maps to ±f64::MAX).
    pub fn to_physical(&self, u: &[f64]) -> Result<ParamValues, IdentifyError> {
        self.check_len(u.len())?;
        let mut values = Vec::with_capacity(u.len());
        for ((p, m), &ui) in self.params.iter().zip(&self.maps).zip(u) {
            let mut x = m.x_of_z(m.z_of_u(ui));
            if !x.is_finite() {
                return Err(IdentifyError::NonFiniteValue {
                    name: p.name.clone(),
                    value: x,
                });
            }
            // exp(ln b) may round past the bound b, and exp may underflow to 0: clamp
            // (exp's subnormal results are kept: they are the values asked for).
            if let Some(lo) = p.lower {
                x = x.max(lo);
            }
            if let Some(hi) = p.upper {
                x = x.min(hi);
            }
            if p.transform == Transform::Log {
                x = x.max(f64::from_bits(1));
            }
            values.push(x);
        }
        Ok(ParamValues {
            names: Arc::clone(&self.names),
            values,
        })
    }

    /// The `n + 1` vertices (in `u`) of a start simplex around the physical point `at`.
    ///
    /// Vertex 0 is `at`; vertex `j` changes parameter `j` alone, as MATLAB's `fminsearch`
    /// does (the routine used in the paper): `x_j → (1 + relative_step)·x_j`, or
    /// `x_j + zero_step` when `x_j = 0`. If that leaves the bounds the step is taken the
    /// other way, then halved until it fits. The step is made in physical units and mapped
    /// to `u`, so a `Log` parameter moves by the factor `1 + relative_step`. A relative
    /// step too small to move `u` (a tiny `x_j` far from its bound) is replaced by
    /// `zero_step`.
    ///
    /// # Errors
    /// As [`to_unconstrained`](Self::to_unconstrained) for `at`;
    /// [`IdentifyError::Parameter`] unless `relative_step` and `zero_step` are finite and
    /// `> 0`.
    pub fn simplex(
        &self,
        at: &[f64],
        relative_step: f64,
        zero_step: f64,
    ) -> Result<Vec<Vec<f64>>, IdentifyError> {
        crate::validate::positive("relative_step", relative_step)?;
        crate::validate::positive("zero_step", zero_step)?;
        let u0 = self.to_unconstrained(at)?;
        let mut vertices = vec![u0.clone()];
        for (j, p) in self.params.iter().enumerate() {
            let x = at[j];
            let lo = p.lower.unwrap_or(f64::NEG_INFINITY);
            let hi = p.upper.unwrap_or(f64::INFINITY);
            let fits = |y: f64| {
                y.is_finite()
                    && lo <= y
                    && y <= hi
                    && !(p.transform == Transform::Log && y <= 0.0)
                    && y != x
            };
            let m = &self.maps[j];
            // The vertex coordinate for a physical step `step`: tried forwards, then
            // backwards, then halved until it fits the bounds; `None` if it never fits or
            // does not move `u` (a step below the resolution of the map there).
            let vertex = |step: f64| {
                let mut h = step;
                for _ in 0..60 {
                    for y in [x + h, x - h] {
                        if fits(y) {
                            let u = m.u_of_z(m.z_of_x(y));
                            return (u != u0[j] && u.is_finite()).then_some(u);
                        }
                    }
                    h *= 0.5;
                }
                None
            };
            // A tiny nonzero x (e.g. −1e-16 reached by an optimizer near a bound at −1)
            // gives a relative step below the map's resolution: fall back to `zero_step`.
            let u = if x == 0.0 {
                vertex(zero_step)
            } else {
                vertex(relative_step * x).or_else(|| vertex(zero_step))
            };
            let u = u.ok_or(IdentifyError::DegenerateSimplex {
                name: p.name.clone(),
                value: x,
            })?;
            let mut v = u0.clone();
            v[j] = u;
            vertices.push(v);
        }
        Ok(vertices)
    }

    fn check_len(&self, found: usize) -> Result<(), IdentifyError> {
        if found == self.params.len() {
            Ok(())
        } else {
            Err(IdentifyError::DimensionMismatch {
                expected: self.params.len(),
                found,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn space() -> ParameterSpace {
        ParameterSpace::new([
            Parameter::new("a", -3.0),
            Parameter::positive("b", 2.0e8),
            Parameter::new("c", 0.3).with_bounds(0.0, 1.0),
            Parameter::new("d", 5.0).with_lower(1.0),
            Parameter::positive("e", 0.5).with_upper(2.0),
            Parameter::positive("f", 3.0).with_bounds(0.0, 10.0),
            Parameter::new("g", 0.0).with_upper(0.0),
        ])
        .unwrap()
    }

    #[test]
    fn round_trip_every_map() {
        let s = space();
        for x in [
            [-3.0, 2.0e8, 0.3, 5.0, 0.5, 3.0, 0.0],
            [7.5, 1.0e-3, 0.0, 1.0, 2.0, 10.0, -4.0],
            [0.0, 3.3e12, 1.0, 1.25, 1e-6, 1e-3, -1e-9],
        ] {
            let u = s.to_unconstrained(&x).unwrap();
            let back = s.to_physical(&u).unwrap();
            for (a, b) in x.iter().zip(back.values()) {
                assert!((a - b).abs() <= 1e-12 * a.abs().max(1e-3), "{a} vs {b}");
            }
        }
    }

    #[test]
    fn any_u_stays_in_bounds() {
        let s = space();
        for k in -50..50 {
            let u = [k as f64 * 0.37; 7];
            let x = s.to_physical(&u).unwrap();
            assert!(x["b"] > 0.0);
            assert!((0.0..=1.0).contains(&x["c"]));
            assert!(x["d"] >= 1.0);
            assert!(x["e"] > 0.0 && x["e"] <= 2.0);
            assert!(x["f"] > 0.0 && x["f"] <= 10.0);
            assert!(x["g"] <= 0.0);
        }
    }

    #[test]
    fn extreme_magnitudes_give_finite_vertices_and_round_trips() {
        // Scales from 1e-100 to 1e100 on every kind of map: the simplex vertices are finite
        // and map back to finite values within the bounds (an infinite vertex came from
        // (z − lo)/s squared overflowing for a tiny scale s).
        let mags = [1e-100, 1e-30, 1e-3, 1.0, 1e3, 1e30, 1e100];
        for &a in &mags {
            for &b in &mags {
                for p in [
                    Parameter::new("x", a).with_lower(a * (1.0 - 1e-15)),
                    Parameter::new("x", a).with_lower(-b),
                    Parameter::new("x", -a).with_upper(b),
                    Parameter::new("x", a).with_bounds(-b, a + b),
                    Parameter::positive("x", a).with_lower(a * 0.5),
                    Parameter::positive("x", a).with_upper(a + b),
                    Parameter::new("x", a).with_bounds(-f64::MAX, f64::MAX),
                ] {
                    let space = ParameterSpace::new([p.clone()]).unwrap();
                    for at in [p.initial(), p.initial() + b, p.initial() * 0.5] {
                        let Ok(v) = space.simplex(&[at], 0.05, 2.5e-4) else {
                            continue; // `at` outside the bounds
                        };
                        for vertex in &v {
                            assert!(vertex[0].is_finite(), "{p:?} at {at}: {v:?}");
                            let x = space.to_physical(vertex).unwrap();
                            assert!(x.values()[0].is_finite(), "{p:?}");
                        }
                        // The maps resolve z relative to the bounds' magnitude.
                        let (lo, hi) = p.bounds();
                        let scale = [Some(at), lo, hi]
                            .into_iter()
                            .flatten()
                            .fold(0.0_f64, |m, x| m.max(x.abs()));
                        let back = space.to_physical(&v[0]).unwrap().values()[0];
                        assert!(
                            (back - at).abs() <= 1e-9 * scale,
                            "{p:?}: {at} -> {} -> {back}",
                            v[0][0]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn maps_have_unit_slope_at_the_start_for_one_sided_bounds() {
        let s = space();
        let u0 = s
            .to_unconstrained(&[-3.0, 2.0e8, 0.3, 5.0, 0.5, 3.0, 0.0])
            .unwrap();
        // d: lower bound 1, start 5, s = 4 → u0 = 4√3, slope √3/2.
        assert!((u0[3] - 4.0 * 3.0_f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn construction_errors() {
        use IdentifyError as E;
        let e = ParameterSpace::new([]).unwrap_err();
        assert_eq!(e, E::EmptySpace);
        let e = ParameterSpace::new([Parameter::new("a", 1.0), Parameter::new("a", 2.0)]);
        assert!(matches!(e, Err(E::DuplicateParameter { .. })));
        let e = ParameterSpace::new([Parameter::positive("k", 0.0)]);
        assert!(matches!(e, Err(E::NonPositiveUnderLog { .. })));
        let e = ParameterSpace::new([Parameter::positive("k", 1.0).with_upper(-1.0)]);
        assert!(matches!(e, Err(E::NonPositiveUnderLog { .. })));
        let e = ParameterSpace::new([Parameter::new("k", 2.0).with_bounds(0.0, 1.0)]);
        assert!(matches!(e, Err(E::OutsideBounds { .. })));
        let e = ParameterSpace::new([Parameter::new("k", 0.5).with_bounds(1.0, 0.0)]);
        assert!(matches!(e, Err(E::InvalidBounds { .. })));
        let e = ParameterSpace::new([Parameter::new("k", f64::NAN)]);
        assert!(matches!(e, Err(E::NonFiniteInitial { .. })));
        let s = space();
        assert!(matches!(s.index_of("zz"), Err(E::UnknownParameter { .. })));
        assert!(matches!(
            s.to_physical(&[0.0]),
            Err(E::DimensionMismatch {
                expected: 7,
                found: 1
            })
        ));
        assert!(matches!(
            s.to_physical(&[0.0, 1e6, 0.0, 0.0, 0.0, 0.0, 0.0]),
            Err(E::NonFiniteValue { .. })
        ));
    }

    #[test]
    fn simplex_follows_fminsearch_steps() {
        let s = space();
        let x0 = [-3.0, 2.0e8, 0.3, 5.0, 0.5, 3.0, 0.0];
        let v = s.simplex(&x0, 0.05, 0.00025).unwrap();
        assert_eq!(v.len(), 8);
        let expected = [
            -3.15, 2.1e8, 0.315, 5.25, 0.525, 3.15,
            -0.00025, // +0.00025 would leave the upper bound 0
        ];
        for j in 0..7 {
            let x = s.to_physical(&v[j + 1]).unwrap();
            for (i, (&got, &start)) in x.values().iter().zip(&x0).enumerate() {
                let want = if i == j { expected[j] } else { start };
                assert!(
                    (got - want).abs() <= 1e-12 * want.abs().max(1e-3),
                    "vertex {j}, param {i}: {got} vs {want}"
                );
            }
        }
        // A tight bound halves the step.
        let t = ParameterSpace::new([Parameter::new("k", 1.0).with_bounds(0.99, 1.01)]).unwrap();
        let v = t.simplex(&[1.0], 0.05, 0.00025).unwrap();
        let x = t.to_physical(&v[1]).unwrap()["k"];
        assert!((x - 1.00625).abs() < 1e-12, "{x}");
    }
}
