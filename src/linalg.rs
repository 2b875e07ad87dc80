//! Small dense linear algebra on the stack for `const N` (no allocation, no trait bounds
//! beyond `Real`): LU with partial pivoting and modified Gram–Schmidt QR.

use nalgebra::{SMatrix, SVector};

use crate::Real;

/// An LU factorization `P·A = L·U` with partial pivoting, stored in place.
#[derive(Debug, Clone, Copy)]
pub struct Lu<T: Real, const N: usize> {
    lu: SMatrix<T, N, N>,
    perm: [usize; N],
}

impl<T: Real, const N: usize> Lu<T, N> {
    /// Factorizes `a`; `None` if a pivot is exactly zero or not finite.
    pub fn new(mut a: SMatrix<T, N, N>) -> Option<Self> {
        let mut perm = [0usize; N];
        for (i, p) in perm.iter_mut().enumerate() {
            *p = i;
        }
        for k in 0..N {
            let mut p = k;
            let mut best = a[(k, k)].abs();
            for i in (k + 1)..N {
                let v = a[(i, k)].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if !(best > T::zero()) || !best.is_finite() {
                return None;
            }
            if p != k {
                a.swap_rows(p, k);
                perm.swap(p, k);
            }
            let piv = a[(k, k)];
            for i in (k + 1)..N {
                let l = a[(i, k)] / piv;
                a[(i, k)] = l;
                for j in (k + 1)..N {
                    let u = a[(k, j)];
                    a[(i, j)] -= l * u;
                }
            }
        }
        Some(Self { lu: a, perm })
    }

    /// Solves `A·x = b`.
    pub fn solve(&self, b: &SVector<T, N>) -> SVector<T, N> {
        let mut x = SVector::<T, N>::zeros();
        for i in 0..N {
            x[i] = b[self.perm[i]];
        }
        for i in 0..N {
            for j in 0..i {
                let l = self.lu[(i, j)];
                let xj = x[j];
                x[i] -= l * xj;
            }
        }
        for i in (0..N).rev() {
            for j in (i + 1)..N {
                let u = self.lu[(i, j)];
                let xj = x[j];
                x[i] -= u * xj;
            }
            x[i] /= self.lu[(i, i)];
        }
        x
    }
}

/// Orthonormalizes the first `k` columns of `m` in place by modified Gram–Schmidt and
/// returns the diagonal of `R` (the stretch factors), as used by the QR method of
/// Lyapunov exponents.
pub fn gram_schmidt<T: Real, const N: usize, const K: usize>(m: &mut SMatrix<T, N, K>) -> [T; K] {
    let mut r = [T::zero(); K];
    #[allow(clippy::needless_range_loop)] // j indexes columns of m as well as r
    for j in 0..K {
        for i in 0..j {
            let dot = m.column(i).dot(&m.column(j));
            let ci = m.column(i).into_owned();
            let mut cj = m.column_mut(j);
            cj -= ci * dot;
        }
        let n = m.column(j).norm();
        r[j] = n;
        if n > T::zero() {
            let mut cj = m.column_mut(j);
            cj /= n;
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lu_solves() {
        let a = SMatrix::<f64, 3, 3>::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0);
        let b = SVector::<f64, 3>::new(1.0, 2.0, 3.0);
        let x = Lu::new(a).unwrap().solve(&b);
        assert!((a * x - b).norm() < 1e-14);
        assert!(Lu::new(SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 4.0)).is_none());
    }

    #[test]
    fn gram_schmidt_orthonormalizes() {
        let mut m = SMatrix::<f64, 3, 2>::new(1.0, 1.0, 0.0, 1.0, 1.0, 0.0);
        let r = gram_schmidt(&mut m);
        assert!((m.column(0).norm() - 1.0).abs() < 1e-15);
        assert!(m.column(0).dot(&m.column(1)).abs() < 1e-15);
        assert!((r[0] - 2.0_f64.sqrt()).abs() < 1e-15);
    }
}
