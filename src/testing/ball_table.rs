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

    /// The top Lyapunov exponent per unit time from the exact impact map
    /// `(t_k, v_k) ↦ (t_{k+1}, v_{k+1})` (`v_k` the ball's velocity after impact `k`) and its
    /// Jacobian in closed form: with `Δ = t_{k+1} − t_k`, `u = v_k − gΔ` and
    /// `F = s(t_k) + v_kΔ − gΔ²/2 − s(t_{k+1}) = 0`,
    /// $$\frac{\partial t_{k+1}}{\partial(t_k, v_k)} = -\frac{(\dot s_k - v_k + g\Delta,\;
    ///   \Delta)}{u - \dot s_{k+1}},\qquad v_{k+1} = (1+e)\dot s(t_{k+1}) - e\,u .$$
    /// The product of `impacts` Jacobians (after `transient` impacts) is renormalized at each
    /// step; the exponent is `Σ ln‖J_k ξ_k‖ / (t_end − t_start)`. Returns `None` if the
    /// sequence ends (chattering) before `transient + impacts` impacts.
    pub fn lyapunov(&self, t0: f64, v0: f64, transient: usize, impacts: usize) -> Option<f64> {
        let seq = self.impacts(t0, v0, transient + impacts + 1);
        if seq.len() < transient + impacts + 1 {
            return None;
        }
        let p = &self.params;
        let accel = |t: f64| -p.amplitude * p.omega * p.omega * (p.omega * t).sin();
        let mut xi = [1.0f64, 0.0];
        let mut log_sum = 0.0;
        for k in transient..transient + impacts {
            let (a, b) = (&seq[k], &seq[k + 1]);
            let d = b.t - a.t;
            let sd_k = p.table_motion(a.t).1;
            let sd_1 = p.table_motion(b.t).1;
            let u = a.v_after - p.g * d;
            let f_t1 = u - sd_1;
            let dt_dt = -(sd_k - a.v_after + p.g * d) / f_t1;
            let dt_dv = -d / f_t1;
            let du_dt = -p.g * (dt_dt - 1.0);
            let du_dv = 1.0 - p.g * dt_dv;
            let s2 = accel(b.t);
            let dv_dt = (1.0 + p.e) * s2 * dt_dt - p.e * du_dt;
            let dv_dv = (1.0 + p.e) * s2 * dt_dv - p.e * du_dv;
            let next = [dt_dt * xi[0] + dt_dv * xi[1], dv_dt * xi[0] + dv_dv * xi[1]];
            let n = next[0].hypot(next[1]);
            log_sum += n.ln();
            xi = [next[0] / n, next[1] / n];
        }
        Some(log_sum / (seq[transient + impacts].t - seq[transient].t))
    }
}
