//! One scalar constraint on a [`Mechanical`] system, the piece the two set-valued modes
//! share: sticking on a [`Gap`](crate::event::Gap) surface (`w·q̈ = s̈`) and the stick mode
//! of Coulomb friction (`w·q̈ = u̇`).
//!
//! For a direction `w` (a coordinate's weights), a generalized force `λw` added to the
//! model's `f` gives the accelerations `q̈ = M⁻¹f + λ·M⁻¹w`; the constraint `w·q̈ = target`
//! holds for
//! $$\lambda = \frac{\text{target} - w\cdot \mathbf M^{-1} f}{w^{\mathsf T}\mathbf M^{-1}w}.$$
//! Moving a state onto the constraint changes positions or velocities along `M⁻¹w` only (the
//! smallest change in the kinetic-energy metric): a coordinate error `e` is removed by
//! `q ← q − e·M⁻¹w/(wᵀM⁻¹w)`, a rate error likewise on `q̇`.

use nalgebra::SVector;

use crate::Real;
use crate::model::{Elements, Loads, Mechanical};

/// The mass-metric quantities of one constraint direction `w`: `M⁻¹w` and `wᵀM⁻¹w`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ScalarConstraint<T: Real, const N: usize> {
    /// `M⁻¹w`.
    m_w: SVector<T, N>,
    /// `wᵀM⁻¹w` (> 0 for a direction with a nonzero weight: `M` is positive definite).
    w_m_w: T,
}

impl<T: Real, const N: usize> ScalarConstraint<T, N> {
    /// The constraint along `w` on `model`.
    pub(crate) fn new<El: Elements<T, N>, Ld: Loads<T, N>>(
        model: &Mechanical<T, N, El, Ld>,
        w: &SVector<T, N>,
    ) -> Self {
        let (m_w, w_m_w) = model.mobility(w);
        Self { m_w, w_m_w }
    }

    /// The multiplier `λ` that makes `w·(a + λM⁻¹w) = target` (`a = M⁻¹f`).
    #[inline]
    pub(crate) fn multiplier(&self, w: &SVector<T, N>, a: &SVector<T, N>, target: T) -> T {
        (target - w.dot(a)) / self.w_m_w
    }

    /// The state derivative `(q̇, a + λM⁻¹w)` of a state `y = (q, q̇)`.
    #[inline]
    pub(crate) fn rhs<const M: usize>(
        &self,
        y: &SVector<T, M>,
        a: &SVector<T, N>,
        lambda: T,
        dy: &mut SVector<T, M>,
    ) {
        for k in 0..N {
            dy[k] = y[N + k];
            dy[N + k] = a[k] + lambda * self.m_w[k];
        }
    }

    /// Moves the positions so that the coordinate changes by `dc`: `q += dc·M⁻¹w/(wᵀM⁻¹w)`.
    #[inline]
    pub(crate) fn shift_positions<const M: usize>(&self, y: &mut SVector<T, M>, dc: T) {
        for k in 0..N {
            y[k] += dc * self.m_w[k] / self.w_m_w;
        }
    }

    /// Moves the velocities so that the coordinate's rate changes by `dv`.
    #[inline]
    pub(crate) fn shift_velocities<const M: usize>(&self, y: &mut SVector<T, M>, dv: T) {
        for k in 0..N {
            y[N + k] += dv * self.m_w[k] / self.w_m_w;
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Matrix2, SVector, Vector2, Vector4};

    use super::ScalarConstraint;
    use crate::model::Mechanical;

    /// A full mass matrix: the multiplier makes `w·q̈` the target, and the shifts move the
    /// coordinate (and its rate) by exactly the requested amount.
    #[test]
    fn multiplier_and_shifts_meet_the_constraint() {
        let model = Mechanical::with_mass_matrix(Matrix2::<f64>::new(2.0, 0.5, 0.5, 1.0)).unwrap();
        let w = Vector2::<f64>::new(1.0, -1.0);
        let c = ScalarConstraint::new(&model, &w);
        let a = Vector2::<f64>::new(0.3, -1.7);
        let lambda = c.multiplier(&w, &a, 0.25);
        let y = Vector4::<f64>::new(0.1, 0.2, -0.4, 0.9);
        let mut dy = SVector::<f64, 4>::zeros();
        c.rhs(&y, &a, lambda, &mut dy);
        assert_eq!(dy.fixed_rows::<2>(0), y.fixed_rows::<2>(2));
        let qdd = Vector2::new(dy[2], dy[3]);
        assert!((w.dot(&qdd) - 0.25).abs() < 1e-15);
        let mut z = y;
        c.shift_positions(&mut z, 0.125);
        c.shift_velocities(&mut z, -0.5);
        let dq = Vector2::new(z[0] - y[0], z[1] - y[1]);
        let dv = Vector2::new(z[2] - y[2], z[3] - y[3]);
        assert!((w.dot(&dq) - 0.125).abs() < 1e-15);
        assert!((w.dot(&dv) + 0.5).abs() < 1e-15);
        // The change is along M⁻¹w: M·dq is parallel to w.
        let f = model.mass_matrix() * dq;
        assert!((f[0] + f[1]).abs() < 1e-15);
    }
}
