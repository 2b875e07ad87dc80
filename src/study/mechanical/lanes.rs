//! The lane form of a described system: its laws, elements and loads in SIMD lanes, so
//! that a shard runs a smooth described system's points together in an
//! [`Ensemble`](crate::ensemble::Ensemble), as it runs the catalogue's.
//!
//! Which law acts where is the description's, the same at every point: it is the
//! *structure* of the lane form (with the coordinates), and the numbers are per lane. The
//! law of each element is chosen once per stage for all lanes (a `match` on the law's
//! kind), then evaluated lane-wise by the law's own lane form, so each lane is the scalar
//! [`Law::force`] to the bit with exact math.

use super::{DescribedElements, DescribedLoads, Law};
use crate::excite::{Harmonic, LaneExcitation};
use crate::force::{CubicSpring, DryFriction, HertzContact, LaneLaw, LinearSpring, ViscousDamper};
use crate::lanes::{LaneMath, Lanes};
use crate::model::{LaneElements, LaneLoads};

/// The most elements a described system runs in lanes with (its packed parameters are a
/// fixed array); a description with more runs its points one by one.
pub(crate) const MAX_LANE_ELEMENTS: usize = 16;

/// The most loads a described system runs in lanes with.
pub(crate) const MAX_LANE_LOADS: usize = 8;

/// A [`Law`]'s parameters in lanes: the law's own packed form, by kind (public only as
/// the packed form of [`DescribedElements`](super::DescribedElements)).
#[derive(Debug, Clone, Copy)]
pub enum LawLanes<V: Lanes> {
    Linear(<LinearSpring<f64> as LaneLaw>::Packed<V>),
    Damper(<ViscousDamper<f64> as LaneLaw>::Packed<V>),
    Cubic(<CubicSpring<f64> as LaneLaw>::Packed<V>),
    Hertz(<HertzContact<f64> as LaneLaw>::Packed<V>),
    Friction(<DryFriction<f64> as LaneLaw>::Packed<V>),
}

impl Law {
    /// Whether `other` is a law of the same kind (the structure of the lane form).
    fn same_kind(&self, other: &Self) -> bool {
        core::mem::discriminant(self) == core::mem::discriminant(other)
    }
}

impl LaneLaw for Law {
    type Packed<V: Lanes> = LawLanes<V>;
    fn pack<V: Lanes>(&self) -> LawLanes<V> {
        match self {
            Law::Linear(l) => LawLanes::Linear(l.pack()),
            Law::Damper(l) => LawLanes::Damper(l.pack()),
            Law::Cubic(l) => LawLanes::Cubic(l.pack()),
            Law::Hertz(l) => LawLanes::Hertz(l.pack()),
            Law::Friction(l) => LawLanes::Friction(l.pack()),
        }
    }
    /// Lane `lane` set to this law. The ensemble packs only models of one structure
    /// ([`same_coordinates`](LaneElements::same_coordinates) compares the kinds), so the
    /// kinds agree; were they to differ, every lane would take this law.
    fn pack_lane<V: Lanes>(&self, packed: &mut LawLanes<V>, lane: usize) {
        match (self, &mut *packed) {
            (Law::Linear(l), LawLanes::Linear(p)) => l.pack_lane(p, lane),
            (Law::Damper(l), LawLanes::Damper(p)) => l.pack_lane(p, lane),
            (Law::Cubic(l), LawLanes::Cubic(p)) => l.pack_lane(p, lane),
            (Law::Hertz(l), LawLanes::Hertz(p)) => l.pack_lane(p, lane),
            (Law::Friction(l), LawLanes::Friction(p)) => l.pack_lane(p, lane),
            _ => *packed = self.pack(),
        }
    }
    #[inline(always)]
    fn force_lanes<V: Lanes>(packed: &LawLanes<V>, math: LaneMath, x: V, v: V) -> V {
        match packed {
            LawLanes::Linear(p) => LinearSpring::force_lanes(p, math, x, v),
            LawLanes::Damper(p) => ViscousDamper::force_lanes(p, math, x, v),
            LawLanes::Cubic(p) => CubicSpring::force_lanes(p, math, x, v),
            LawLanes::Hertz(p) => HertzContact::force_lanes(p, math, x, v),
            LawLanes::Friction(p) => DryFriction::force_lanes(p, math, x, v),
        }
    }
}

/// The elements in lanes, in the description's order (the scalar sum's): the first
/// `MAX_LANE_ELEMENTS` (16) slots, `None` past the last element (elements beyond the slots
/// are not packed: a description with more runs its points one by one).
impl<const N: usize> LaneElements<N> for DescribedElements<N> {
    type Packed<V: Lanes> = [Option<LawLanes<V>>; MAX_LANE_ELEMENTS];
    fn pack<V: Lanes>(&self) -> Self::Packed<V> {
        core::array::from_fn(|k| self.0.get(k).map(|e| e.law.pack()))
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
        for (e, p) in self.0.iter().zip(packed.iter_mut()) {
            match p {
                Some(p) => e.law.pack_lane(p, lane),
                None => *p = Some(e.law.pack()),
            }
        }
    }
    #[inline(always)]
    fn add_forces_lanes<V: Lanes>(
        &self,
        packed: &Self::Packed<V>,
        math: LaneMath,
        q: &[V],
        qd: &[V],
        out: &mut [V; N],
    ) {
        for (e, p) in self.0.iter().zip(packed) {
            if let Some(p) = p {
                e.add_forces_lanes(p, math, q, qd, out);
            }
        }
    }
    fn same_coordinates(&self, other: &Self) -> bool {
        self.0.len() == other.0.len()
            && self
                .0
                .iter()
                .zip(&other.0)
                .all(|(a, b)| a.law.same_kind(&b.law) && LaneElements::<N>::same_coordinates(a, b))
    }
}

/// The loads in lanes, as the elements (`MAX_LANE_LOADS` (8) slots).
impl<const N: usize> LaneLoads<N> for DescribedLoads<N> {
    type Packed<V: Lanes> = [Option<<Harmonic<f64> as LaneExcitation>::Packed<V>>; MAX_LANE_LOADS];
    fn pack<V: Lanes>(&self) -> Self::Packed<V> {
        core::array::from_fn(|k| self.0.get(k).map(|l| l.excitation.pack()))
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
        for (l, p) in self.0.iter().zip(packed.iter_mut()) {
            match p {
                Some(p) => l.excitation.pack_lane(p, lane),
                None => *p = Some(l.excitation.pack()),
            }
        }
    }
    #[inline(always)]
    fn add_forces_lanes<V: Lanes>(
        &self,
        packed: &Self::Packed<V>,
        math: LaneMath,
        t: V,
        out: &mut [V; N],
    ) {
        for (l, p) in self.0.iter().zip(packed) {
            if let Some(p) = p {
                l.add_forces_lanes(p, math, t, out);
            }
        }
    }
    fn same_coordinates(&self, other: &Self) -> bool {
        self.0.len() == other.0.len()
            && self
                .0
                .iter()
                .zip(&other.0)
                .all(|(a, b)| LaneLoads::<N>::same_coordinates(a, b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ForceLaw;
    use crate::force::Regularization;
    use crate::lanes::F64x4;

    /// Each law's lane form through the enum is the law's scalar force to the bit, lane by
    /// lane, over free, contact and sliding states.
    #[test]
    fn the_law_enum_in_lanes_is_the_scalar_law() {
        let hertz = HertzContact::new(0.1, 1e3)
            .unwrap()
            .with_damping(0.2, 1.5, 1.0)
            .unwrap();
        let laws = [
            Law::Linear(LinearSpring::new(3.0).unwrap()),
            Law::Damper(ViscousDamper::new(0.4).unwrap()),
            Law::Cubic(CubicSpring::new(1.0, -0.5).unwrap()),
            Law::Hertz(hertz),
            Law::Friction(DryFriction::new(0.3, 1e-3, Regularization::Sqrt).unwrap()),
        ];
        let states = [(0.05, 1.0), (0.15, -0.3), (0.2, 0.7), (-0.4, 0.0)];
        for law in laws {
            let mut p = law.pack::<F64x4>();
            let mut x = F64x4::splat(0.0);
            let mut v = F64x4::splat(0.0);
            for (i, (xi, vi)) in states.into_iter().enumerate() {
                law.pack_lane(&mut p, i);
                x = x.with_lane(i, xi);
                v = v.with_lane(i, vi);
            }
            let f = Law::force_lanes(&p, LaneMath::Exact, x, v);
            for (i, (xi, vi)) in states.into_iter().enumerate() {
                assert_eq!(f.lane(i).to_bits(), law.force(xi, vi).to_bits(), "{law:?}");
            }
        }
        assert!(laws[0].same_kind(&Law::Linear(LinearSpring::new(1.0).unwrap())));
        assert!(!laws[0].same_kind(&laws[1]));
    }
}
