//! The exact impact map of a ball on a sinusoidally vibrating table.

use crate::systems::BouncingBallTable;

/// One impact of the exact sequence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableImpact {
    /// Impact time.
    pub t: f64,
    /// Ball velocity just before the impact.
    pub v_before: f64,
    /// Ball velocity just after (`ṡ − e(v⁻ − ṡ)`).
    pub v_after: f64,
}

/// The exact impact sequence of [`BouncingBallTable`]: flights are parabolas
/// `y(t) = y_k + v_k(t − t_k) − g(t − t_k)²/2`, impacts the first roots of
/// `h(t) = y(t) − A sin ωt` after each launch.
///
/// # Method
/// From a point with `h > 0` and `ḣ = D`, no root can come before
/// `τ* = (D + √(D² + 2Kh))/K` with `K = g + Aω²` (the bound on `|ḧ|`), so stepping by `τ*`
/// never steps over a root; once `τ*` falls below `10⁻⁷` periods, `h` is tested one such
/// step ahead and the bracket is bisected to the last bit, then polished by Newton's method
/// (root to about `10⁻¹⁴ s`). A crossing pair narrower than `10⁻⁷` periods is taken as the
/// impact it starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BallOnTableExact {
    params: BouncingBallTable,
}

impl BallOnTableExact {
    /// The exact map for `params`.
    pub fn new(params: BouncingBallTable) -> Self {
        Self { params }
    }

    /// Up to `n` impacts after a launch from the table at `t0` with ball velocity `v0`
    /// (`v0 > ṡ(t0)`), stopping early if the ball's relative launch velocity falls below
    /// `1e-9 m/s` (chattering to rest).
    pub fn impacts(&self, t0: f64, v0: f64, n: usize) -> Vec<TableImpact> {
        let p = &self.params;
        let k = p.g + p.amplitude * p.omega * p.omega;
        let small = 1e-7 * p.period();
        let mut out = Vec::with_capacity(n);
        let (mut tk, mut vk) = (t0, v0);
        let (mut yk, _) = p.table_motion(t0);
        for _ in 0..n {
            let h = |t: f64| {
                let d = t - tk;
                yk + vk * d - 0.5 * p.g * d * d - p.table_motion(t).0
            };
            let hd = |t: f64| vk - p.g * (t - tk) - p.table_motion(t).1;
            if hd(tk) <= 1e-9 {
                break;
            }
            // March with the safe step.
            let mut t = tk + 1e-12_f64.max(1e-9 * p.period());
            let (mut lo, mut hi);
            loop {
                let (ht, d) = (h(t), hd(t));
                if ht < 0.0 {
                    // The very first point is already below: the root is right at launch.
                    lo = tk;
                    hi = t;
                    break;
                }
                let tau = (d + (d * d + 2.0 * k * ht).sqrt()) / k;
                if tau < small {
                    let t2 = t + small;
                    if h(t2) < 0.0 {
                        lo = t;
                        hi = t2;
                        break;
                    }
                    t = t2;
                } else {
                    t += tau;
                }
            }
            for _ in 0..200 {
                let m = 0.5 * (lo + hi);
                if m <= lo || m >= hi {
                    break;
                }
                if h(m) >= 0.0 {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            let mut ti = 0.5 * (lo + hi);
            for _ in 0..3 {
                let d = hd(ti);
                if d != 0.0 {
                    let next = ti - h(ti) / d;
                    if (next - ti).abs() < (hi - lo).max(1e-15) * 4.0 {
                        ti = next;
                    }
                }
            }
            let v_before = vk - p.g * (ti - tk);
            let (s, sd) = p.table_motion(ti);
            let v_after = sd - p.e * (v_before - sd);
            out.push(TableImpact {
                t: ti,
                v_before,
                v_after,
            });
            tk = ti;
            yk = s;
            vk = v_after;
        }
        out
    }
}
