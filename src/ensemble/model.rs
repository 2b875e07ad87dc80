//! The built-in laws of the paper's oscillator in lane form.

use nalgebra::SVector;

use super::Lanes;
use super::math::{LaneMath, pow_masked, sin};
use crate::Dynamics;
use crate::scalar::Exponent;
use crate::systems::paper::{PaperOscillator, PaperParameters};
use crate::validate::ParameterError;

/// One member of an ensemble: the paper's oscillator (any [`PaperParameters`], not only
/// the paper's set) forced at `ω`, with its scalar model kept beside it.
///
/// # Model
/// $$m\ddot x + kx + c\dot x + T\frac{\dot x}{\sqrt{\dot x^2+\varepsilon^2}} + F_I(x,\dot x)
///   = m_0 e\,\omega^2\sin\omega t,$$
/// with the generalized Hertz law `F_I` of [`HertzContact`](crate::force::HertzContact)
/// (exponents `n1`, `n2`, damping `b·δ^{n2}·ẋ(ẋ²+η²)^{(n3−1)/2}`, or the exact
/// `sgn(ẋ)|ẋ|^{n3}` for `η = 0`). The lane form evaluates the same terms in the same
/// order as the scalar [`PaperOscillator`]; with
/// [`LaneMath::Exact`] each lane's value is the scalar one to the bit.
///
/// A linear forced oscillator is the member with `T = 0` and a stop out of reach
/// (`x_I` far above the motion): the smooth reference problem of the tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Member {
    params: PaperParameters,
    omega: f64,
    scalar: PaperOscillator<f64>,
}

impl Member {
    /// The oscillator with `params` forced at `omega` (rad/s).
    ///
    /// # Errors
    /// [`ParameterError`] for any invalid parameter (the checks of
    /// [`PaperParameters::oscillator`]).
    pub fn new(params: PaperParameters, omega: f64) -> Result<Self, ParameterError> {
        let scalar = params.oscillator::<f64>(omega)?;
        Ok(Self {
            params,
            omega,
            scalar,
        })
    }

    /// The paper's parameter set forced at `omega`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `omega` is finite and > 0 (with `m0e·ω³` finite).
    pub fn paper(omega: f64) -> Result<Self, ParameterError> {
        Self::new(crate::systems::paper::PAPER, omega)
    }

    /// The parameters.
    pub fn params(&self) -> &PaperParameters {
        &self.params
    }

    /// The forcing frequency `ω`.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The forcing period `2π/ω`.
    pub fn period(&self) -> f64 {
        core::f64::consts::TAU / self.omega
    }

    /// The same model on the scalar path.
    pub fn scalar(&self) -> &PaperOscillator<f64> {
        &self.scalar
    }
}

/// The parameters of `L` members, one per lane.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Packed<V> {
    inv_m: V,
    k: V,
    c: V,
    tf: V,
    eps2: V,
    x_i: V,
    k_i: V,
    b: V,
    b_zero: V,
    n1: ExpLanes<V>,
    n2: ExpLanes<V>,
    n2_is_n1: V,
    n3: V,
    half_n3m1: V,
    eta2: V,
    eta_pos: V,
    amp: V,
    omega: V,
    general: bool,
}

/// An [`Exponent`] per lane: masks of its kind and its value.
#[derive(Debug, Clone, Copy)]
struct ExpLanes<V> {
    one: V,
    three_halves: V,
    two: V,
    general: V,
    p: V,
}

const ALL: f64 = f64::from_bits(u64::MAX);

fn mask(b: bool) -> f64 {
    if b { ALL } else { 0.0 }
}

impl<V: Lanes> ExpLanes<V> {
    fn zero() -> Self {
        let z = V::splat(0.0);
        Self {
            one: z,
            three_halves: z,
            two: z,
            general: z,
            p: z,
        }
    }

    fn set(&mut self, i: usize, e: Exponent<f64>) {
        self.one = self.one.with_lane(i, mask(e == Exponent::One));
        self.three_halves = self
            .three_halves
            .with_lane(i, mask(e == Exponent::ThreeHalves));
        self.two = self.two.with_lane(i, mask(e == Exponent::Two));
        self.general = self
            .general
            .with_lane(i, mask(matches!(e, Exponent::General(_))));
        self.p = self.p.with_lane(i, e.value());
    }

    /// `d^p` where `inside` (`d > 0`), 0 elsewhere — [`Exponent::pow`] lane by lane.
    #[inline(always)]
    fn pow(&self, math: LaneMath, inside: V, d: V, general: bool) -> V {
        let z = V::splat(0.0);
        let ds = inside.select(d, V::splat(1.0));
        let mut v = self.three_halves.select(d * ds.sqrt(), z);
        v = self.one.select(d, v);
        v = self.two.select(d * d, v);
        if general {
            let g = self.general & inside;
            v = g.select(pow_masked(math, g, ds, self.p), v);
        }
        inside.select(v, z)
    }
}

impl<V: Lanes> Packed<V> {
    /// Every lane set to `m`.
    pub(crate) fn splat(m: &Member) -> Self {
        let z = V::splat(0.0);
        let mut p = Self {
            inv_m: z,
            k: z,
            c: z,
            tf: z,
            eps2: z,
            x_i: z,
            k_i: z,
            b: z,
            b_zero: z,
            n1: ExpLanes::zero(),
            n2: ExpLanes::zero(),
            n2_is_n1: z,
            n3: z,
            half_n3m1: z,
            eta2: z,
            eta_pos: z,
            amp: z,
            omega: z,
            general: false,
        };
        for i in 0..V::LANES {
            p.set(i, m);
        }
        p
    }

    /// Lane `i` set to `m`.
    pub(crate) fn set(&mut self, i: usize, m: &Member) {
        let q = &m.params;
        let osc = &m.scalar;
        self.inv_m = self
            .inv_m
            .with_lane(i, osc.mechanical().inverse_mass_matrix()[(0, 0)]);
        self.k = self.k.with_lane(i, q.k);
        self.c = self.c.with_lane(i, q.c);
        self.tf = self.tf.with_lane(i, q.t);
        self.eps2 = self.eps2.with_lane(i, q.eps * q.eps);
        self.x_i = self.x_i.with_lane(i, q.x_i);
        self.k_i = self.k_i.with_lane(i, q.k_i);
        self.b = self.b.with_lane(i, q.b);
        self.b_zero = self.b_zero.with_lane(i, mask(q.b == 0.0));
        let (n1, n2) = (Exponent::new(q.n1), Exponent::new(q.n2));
        self.n1.set(i, n1);
        self.n2.set(i, n2);
        self.n2_is_n1 = self.n2_is_n1.with_lane(i, mask(n1 == n2));
        self.n3 = self.n3.with_lane(i, q.n3);
        self.half_n3m1 = self.half_n3m1.with_lane(i, (q.n3 - 1.0) * 0.5);
        self.eta2 = self.eta2.with_lane(i, q.eta * q.eta);
        self.eta_pos = self.eta_pos.with_lane(i, mask(q.eta > 0.0));
        let rotor = osc.excitation();
        self.amp = self.amp.with_lane(i, rotor.amplitude());
        self.omega = self.omega.with_lane(i, rotor.omega());
        let general = |e: ExpLanes<V>| e.general.bits() != 0;
        self.general = general(self.n1) || general(self.n2);
    }

    /// The forcing `m₀eω²·sin ωt` in every lane.
    #[inline(always)]
    pub(crate) fn excitation(&self, t: V) -> V {
        self.amp * sin(self.omega * t)
    }

    /// `(ẋ, v̇)` of the oscillator in every lane, with the forcing's value given (the last
    /// two stages of a step share their time, and so their forcing).
    #[inline(always)]
    pub(crate) fn rhs_forced(&self, math: LaneMath, excitation: V, x: V, v: V) -> (V, V) {
        let z = V::splat(0.0);
        let spring = self.k * x;
        let damper = self.c * v;
        let friction = self.tf * v / (v * v + self.eps2).sqrt();
        let d = x - self.x_i;
        let inside = !d.le(z);
        let contact = if inside.bits() == 0 {
            z
        } else {
            self.contact(math, inside, d, v)
        };
        let laws = (((z + spring) + damper) + friction) + contact;
        (v, (excitation - laws) * self.inv_m)
    }

    /// The Hertz force `k_I·f` where `f = δ^{n1} + b·δ^{n2}·g(δ̇) > 0` inside contact.
    #[inline(always)]
    fn contact(&self, math: LaneMath, inside: V, d: V, w: V) -> V {
        let z = V::splat(0.0);
        let p1 = self.n1.pow(math, inside, d, self.general);
        let p2 = if (self.n2_is_n1 & inside).bits() == inside.bits() {
            p1
        } else {
            self.n2_is_n1
                .select(p1, self.n2.pow(math, inside, d, self.general))
        };
        // g(w): w·(w²+η²)^{(n3−1)/2} for η > 0, sgn(w)|w|^{n3} for η = 0.
        let damped = inside & !self.b_zero;
        let s = w * w + self.eta2;
        let reg = damped & self.eta_pos;
        let g_reg = w * pow_masked(math, reg, s, self.half_n3m1);
        let exact = damped & !self.eta_pos & !w.eq(z);
        let g = if exact.bits() == 0 {
            g_reg
        } else {
            let m = pow_masked(math, exact, w.abs(), self.n3);
            let g_ex = w.gt(z).select(m, -m);
            exact.select(g_ex, self.eta_pos.select(g_reg, z))
        };
        let f = self.b_zero.select(p1, p1 + self.b * p2 * g);
        (inside & !f.le(z)).select(self.k_i * f, z)
    }
}

/// The scalar right-hand side of a member (used where one lane is handled alone: its
/// first derivative, the initial step, the event rates).
#[inline(always)]
pub(crate) fn scalar_rhs(m: &Member, t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
    let mut dy = SVector::zeros();
    m.scalar.rhs(t, y, &mut dy);
    dy
}
