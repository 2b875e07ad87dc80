//! The lane form of [`Mechanical`]: its right-hand side in SIMD lanes, from the lane forms
//! of its laws and excitations.
//!
//! The coordinates, the shape of the mass matrix (diagonal or not) and the presence of the
//! linear matrices are the model's *structure*: every lane uses the structure of the
//! model packed by [`LaneDynamics::pack`], and the ensemble runs only members that share
//! it ([`LaneDynamics::same_structure`]). The numbers — laws' and excitations'
//! parameters, masses, `K`, `C` — are per lane.

// Index loops: they spell the scalar code's summation order, which the lanes must keep.
#![allow(clippy::needless_range_loop)]

use super::{Coordinate, Element, Load, Mechanical, Shape, state_size};
use crate::LaneDynamics;
use crate::excite::LaneExcitation;
use crate::force::LaneLaw;
use crate::lanes::{LaneMath, Lanes};

impl<T: crate::Real, const N: usize> Coordinate<T, N> {
    /// `(c(q), w·q̇)` lane-wise ([`value`](Coordinate::value) and
    /// [`rate`](Coordinate::rate) of every lane, to the bit for `T = f64`).
    #[inline(always)]
    pub(crate) fn lanes<V: Lanes>(&self, q: &[V], qd: &[V]) -> (V, V) {
        (
            self.combine_lanes(crate::scalar::to_f64(self.offset), q),
            self.combine_lanes(0.0, qd),
        )
    }
}

impl<T: crate::Real, const N: usize> Coordinate<T, N> {
    /// [`combine`](Coordinate::combine) lane-wise, by the same shapes (weights read as
    /// `f64`).
    #[inline(always)]
    fn combine_lanes<V: Lanes>(&self, start: f64, x: &[V]) -> V {
        let start_v = V::splat(start);
        if self.dof < N {
            return x[self.dof];
        }
        match self.shape {
            Shape::Dof(i) | Shape::DofOffset(i) => start_v + x[i.min(N - 1)],
            Shape::Pair { plus, minus } => {
                if start == 0.0 {
                    x[plus] - x[minus]
                } else if plus < minus {
                    start_v + x[plus] - x[minus]
                } else {
                    start_v - x[minus] + x[plus]
                }
            }
            Shape::General => {
                let mut g = start_v;
                for (w, v) in self.weights.iter().zip(x) {
                    g = g + V::splat(crate::scalar::to_f64(*w)) * *v;
                }
                g
            }
        }
    }

    /// [`distribute`](Coordinate::distribute) lane-wise.
    #[inline(always)]
    fn distribute_lanes<V: Lanes>(&self, f: V, out: &mut [V; N]) {
        if self.dof < N {
            out[self.dof] = out[self.dof] + f;
            return;
        }
        match self.shape {
            Shape::Dof(i) | Shape::DofOffset(i) => {
                let i = i.min(N - 1);
                out[i] = out[i] + f;
            }
            Shape::Pair { plus, minus } => {
                out[plus] = out[plus] + f;
                out[minus] = out[minus] - f;
            }
            Shape::General => {
                for k in 0..N {
                    out[k] = out[k] + V::splat(crate::scalar::to_f64(self.weights[k])) * f;
                }
            }
        }
    }
}

/// The lane form of a set of [`Elements`](super::Elements): the elements' laws implement
/// [`LaneLaw`]. Implemented for [`Element`], `()`, tuples and arrays, as `Elements` is.
pub trait LaneElements<const N: usize>: super::Elements<f64, N> {
    /// The laws' parameters in `L` lanes.
    type Packed<V: Lanes>: Copy + core::fmt::Debug + Send + Sync;
    /// Every lane set to these elements.
    fn pack<V: Lanes>(&self) -> Self::Packed<V>;
    /// Lane `lane` set to these elements.
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize);
    /// Adds `Σ w·F(g, ġ)` to `out` in every lane (the coordinates are `self`'s).
    fn add_forces_lanes<V: Lanes>(
        &self,
        packed: &Self::Packed<V>,
        math: LaneMath,
        q: &[V],
        qd: &[V],
        out: &mut [V; N],
    );
    /// Whether `other` has the same coordinates (the structure of the lane form).
    fn same_coordinates(&self, other: &Self) -> bool;
}

impl<const N: usize> LaneElements<N> for () {
    type Packed<V: Lanes> = ();
    fn pack<V: Lanes>(&self) {}
    fn pack_lane<V: Lanes>(&self, _packed: &mut (), _lane: usize) {}
    #[inline(always)]
    fn add_forces_lanes<V: Lanes>(
        &self,
        _packed: &(),
        _math: LaneMath,
        _q: &[V],
        _qd: &[V],
        _out: &mut [V; N],
    ) {
    }
    fn same_coordinates(&self, _other: &Self) -> bool {
        true
    }
}

impl<const N: usize, L: LaneLaw> LaneElements<N> for Element<f64, N, L> {
    type Packed<V: Lanes> = L::Packed<V>;
    fn pack<V: Lanes>(&self) -> L::Packed<V> {
        self.law.pack()
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut L::Packed<V>, lane: usize) {
        self.law.pack_lane(packed, lane);
    }
    #[inline(always)]
    fn add_forces_lanes<V: Lanes>(
        &self,
        packed: &L::Packed<V>,
        math: LaneMath,
        q: &[V],
        qd: &[V],
        out: &mut [V; N],
    ) {
        let c = &self.coordinate;
        let g = c.combine_lanes(c.offset, q);
        let gd = c.combine_lanes(0.0, qd);
        let f = L::force_lanes(packed, math, g, gd);
        c.distribute_lanes(f, out);
    }
    fn same_coordinates(&self, other: &Self) -> bool {
        self.coordinate == other.coordinate
    }
}

impl<const N: usize, E: LaneElements<N>, const K: usize> LaneElements<N> for [E; K] {
    type Packed<V: Lanes> = [E::Packed<V>; K];
    fn pack<V: Lanes>(&self) -> Self::Packed<V> {
        core::array::from_fn(|k| self[k].pack())
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
        for (e, p) in self.iter().zip(packed.iter_mut()) {
            e.pack_lane(p, lane);
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
        for (e, p) in self.iter().zip(packed) {
            e.add_forces_lanes(p, math, q, qd, out);
        }
    }
    fn same_coordinates(&self, other: &Self) -> bool {
        self.iter().zip(other).all(|(a, b)| a.same_coordinates(b))
    }
}

macro_rules! lane_element_tuple {
    ($($name:ident $idx:tt),+) => {
        impl<const N: usize, $($name: LaneElements<N>),+> LaneElements<N> for ($($name,)+) {
            type Packed<V: Lanes> = ($($name::Packed<V>,)+);
            fn pack<V: Lanes>(&self) -> Self::Packed<V> {
                ($(self.$idx.pack(),)+)
            }
            fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
                $(self.$idx.pack_lane(&mut packed.$idx, lane);)+
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
                $(self.$idx.add_forces_lanes(&packed.$idx, math, q, qd, out);)+
            }
            fn same_coordinates(&self, other: &Self) -> bool {
                true $(&& self.$idx.same_coordinates(&other.$idx))+
            }
        }
    };
}

lane_element_tuple!(A 0);
lane_element_tuple!(A 0, B 1);
lane_element_tuple!(A 0, B 1, C 2);
lane_element_tuple!(A 0, B 1, C 2, D 3);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9, K 10);
lane_element_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9, K 10, L 11);

/// The lane form of a set of [`Loads`](super::Loads): the loads' excitations implement
/// [`LaneExcitation`].
pub trait LaneLoads<const N: usize>: super::Loads<f64, N> {
    /// The excitations' parameters in `L` lanes.
    type Packed<V: Lanes>: Copy + core::fmt::Debug + Send + Sync;
    /// Every lane set to these loads.
    fn pack<V: Lanes>(&self) -> Self::Packed<V>;
    /// Lane `lane` set to these loads.
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize);
    /// Adds the generalized forces `Σ w·f(t)` to `out` in every lane.
    fn add_forces_lanes<V: Lanes>(
        &self,
        packed: &Self::Packed<V>,
        math: LaneMath,
        t: V,
        out: &mut [V; N],
    );
    /// Whether `other` has the same coordinates.
    fn same_coordinates(&self, other: &Self) -> bool;
}

impl<const N: usize> LaneLoads<N> for () {
    type Packed<V: Lanes> = ();
    fn pack<V: Lanes>(&self) {}
    fn pack_lane<V: Lanes>(&self, _packed: &mut (), _lane: usize) {}
    #[inline(always)]
    fn add_forces_lanes<V: Lanes>(&self, _p: &(), _math: LaneMath, _t: V, _out: &mut [V; N]) {}
    fn same_coordinates(&self, _other: &Self) -> bool {
        true
    }
}

impl<const N: usize, E: LaneExcitation> LaneLoads<N> for Load<f64, N, E> {
    type Packed<V: Lanes> = E::Packed<V>;
    fn pack<V: Lanes>(&self) -> E::Packed<V> {
        self.excitation.pack()
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut E::Packed<V>, lane: usize) {
        self.excitation.pack_lane(packed, lane);
    }
    #[inline(always)]
    fn add_forces_lanes<V: Lanes>(
        &self,
        packed: &E::Packed<V>,
        math: LaneMath,
        t: V,
        out: &mut [V; N],
    ) {
        let f = E::force_lanes(packed, math, t);
        self.coordinate.distribute_lanes(f, out);
    }
    fn same_coordinates(&self, other: &Self) -> bool {
        self.coordinate == other.coordinate
    }
}

impl<const N: usize, E: LaneLoads<N>, const K: usize> LaneLoads<N> for [E; K] {
    type Packed<V: Lanes> = [E::Packed<V>; K];
    fn pack<V: Lanes>(&self) -> Self::Packed<V> {
        core::array::from_fn(|k| self[k].pack())
    }
    fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
        for (e, p) in self.iter().zip(packed.iter_mut()) {
            e.pack_lane(p, lane);
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
        for (e, p) in self.iter().zip(packed) {
            e.add_forces_lanes(p, math, t, out);
        }
    }
    fn same_coordinates(&self, other: &Self) -> bool {
        self.iter().zip(other).all(|(a, b)| a.same_coordinates(b))
    }
}

macro_rules! lane_load_tuple {
    ($($name:ident $idx:tt),+) => {
        impl<const N: usize, $($name: LaneLoads<N>),+> LaneLoads<N> for ($($name,)+) {
            type Packed<V: Lanes> = ($($name::Packed<V>,)+);
            fn pack<V: Lanes>(&self) -> Self::Packed<V> {
                ($(self.$idx.pack(),)+)
            }
            fn pack_lane<V: Lanes>(&self, packed: &mut Self::Packed<V>, lane: usize) {
                $(self.$idx.pack_lane(&mut packed.$idx, lane);)+
            }
            #[inline(always)]
            fn add_forces_lanes<V: Lanes>(
                &self,
                packed: &Self::Packed<V>,
                math: LaneMath,
                t: V,
                out: &mut [V; N],
            ) {
                $(self.$idx.add_forces_lanes(&packed.$idx, math, t, out);)+
            }
            fn same_coordinates(&self, other: &Self) -> bool {
                true $(&& self.$idx.same_coordinates(&other.$idx))+
            }
        }
    };
}

lane_load_tuple!(A 0);
lane_load_tuple!(A 0, B 1);
lane_load_tuple!(A 0, B 1, C 2);
lane_load_tuple!(A 0, B 1, C 2, D 3);
lane_load_tuple!(A 0, B 1, C 2, D 3, E 4);
lane_load_tuple!(A 0, B 1, C 2, D 3, E 4, F 5);
lane_load_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6);
lane_load_tuple!(A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);

/// The numbers of a [`Mechanical`] system in `L` lanes: `M⁻¹`, `[K, C]` (if the model has
/// them), the elements' and loads' parameters, and the structure of the model packed first.
#[derive(Debug, Clone, Copy)]
pub struct MechanicalLanes<V, const N: usize, E, L> {
    inv_mass: [[V; N]; N],
    linear: [[[V; N]; N]; 2],
    elements: E,
    loads: L,
}

impl<const N: usize, El, Ld> Mechanical<f64, N, El, Ld> {
    /// The structure of the lane form: coordinates, mass shape, linear matrices present.
    fn same_lane_structure(&self, other: &Self) -> bool
    where
        El: LaneElements<N>,
        Ld: LaneLoads<N>,
    {
        self.diagonal == other.diagonal
            && self.linear.is_some() == other.linear.is_some()
            && self.elements.same_coordinates(&other.elements)
            && self.loads.same_coordinates(&other.loads)
    }
}

/// The structure of the model packed first travels with the packed numbers: the lane form
/// evaluates through a model reference, kept in the packed data.
#[derive(Debug, Clone)]
pub struct MechanicalPacked<V: Lanes, const N: usize, El: LaneElements<N>, Ld: LaneLoads<N>> {
    structure: Mechanical<f64, N, El, Ld>,
    lanes: MechanicalLanes<V, N, El::Packed<V>, Ld::Packed<V>>,
}

impl<const N: usize, const M: usize, El, Ld> LaneDynamics<M> for Mechanical<f64, N, El, Ld>
where
    El: LaneElements<N> + Clone + core::fmt::Debug + Send + Sync,
    Ld: LaneLoads<N> + Clone + core::fmt::Debug + Send + Sync,
{
    type Packed<V: Lanes> = MechanicalPacked<V, N, El, Ld>;
    /// The generalized load `Σ w·f(t)`.
    type Time<V: Lanes> = [V; N];

    fn pack<V: Lanes>(&self) -> Self::Packed<V> {
        let z = V::splat(0.0);
        let mut p = MechanicalPacked {
            structure: self.clone(),
            lanes: MechanicalLanes {
                inv_mass: [[z; N]; N],
                linear: [[[z; N]; N]; 2],
                elements: self.elements.pack(),
                loads: self.loads.pack(),
            },
        };
        for i in 0..V::LANES {
            <Self as LaneDynamics<M>>::pack_lane(self, &mut p, i);
        }
        p
    }

    fn pack_lane<V: Lanes>(&self, p: &mut Self::Packed<V>, lane: usize) {
        let l = &mut p.lanes;
        for i in 0..N {
            for j in 0..N {
                l.inv_mass[i][j] = l.inv_mass[i][j].with_lane(lane, self.inv_mass[(i, j)]);
                if let Some(kc) = &self.linear {
                    for (m, a) in l.linear.iter_mut().zip(kc) {
                        m[i][j] = m[i][j].with_lane(lane, a[(i, j)]);
                    }
                }
            }
        }
        self.elements.pack_lane(&mut l.elements, lane);
        self.loads.pack_lane(&mut l.loads, lane);
    }

    /// No time scale is declared (the driver's default `None`).
    fn constant_time_scale(&self) -> bool {
        true
    }
    fn same_structure(&self, other: &Self) -> bool {
        self.same_lane_structure(other)
    }

    #[inline(always)]
    fn time_lanes<V: Lanes>(p: &Self::Packed<V>, math: LaneMath, t: V) -> [V; N] {
        // The scalar accumulators start at −0 (see `generalized_force`).
        let mut load = [V::splat(-0.0); N];
        p.structure
            .loads
            .add_forces_lanes(&p.lanes.loads, math, t, &mut load);
        load
    }

    /// [`Mechanical`]'s `rhs` lane-wise: the same terms in the same order (the generalized
    /// force, then `M⁻¹` by the diagonal or as nalgebra's product, column by column).
    #[inline(always)]
    fn rhs_lanes<V: Lanes>(
        p: &Self::Packed<V>,
        math: LaneMath,
        _t: V,
        load: &[V; N],
        y: &[V; M],
        dy: &mut [V; M],
    ) {
        state_size::<N, M>();
        let s = &p.structure;
        let l = &p.lanes;
        let (q, qd) = y.split_at(N);
        let mut r = [V::splat(-0.0); N];
        s.elements
            .add_forces_lanes(&l.elements, math, q, qd, &mut r);
        if s.linear.is_some() {
            let [k, c] = &l.linear;
            for i in 0..N {
                for j in 0..N {
                    r[i] = r[i] + k[i][j] * q[j];
                }
                for j in 0..N {
                    r[i] = r[i] + c[i][j] * qd[j];
                }
            }
        }
        let mut f = [V::splat(0.0); N];
        for i in 0..N {
            f[i] = load[i] - r[i];
        }
        dy[..N].copy_from_slice(qd);
        if N == 1 || s.diagonal {
            for i in 0..N {
                dy[N + i] = f[i] * l.inv_mass[i][i];
            }
        } else {
            // nalgebra's matrix–vector product: the first column times f₀, then each next
            // column's product added.
            for i in 0..N {
                let mut a = l.inv_mass[i][0] * f[0];
                for j in 1..N {
                    a = a + l.inv_mass[i][j] * f[j];
                }
                dy[N + i] = a;
            }
        }
    }
}
