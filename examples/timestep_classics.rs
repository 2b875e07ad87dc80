//! Moreau–Jean time-stepping on the classic rigid-contact problems, with the complementarity
//! solvers underneath: each section prints its check and the example exits non-zero if
//! one fails.
//!
//! 1. Lemke on Murty's exponential family (2ⁿ pivots, exact answers) and on random
//!    symmetric positive-definite problems to n = 200.
//! 2. A column of 100 balls at rest: projected Gauss–Seidel's residual against its sweeps
//!    (`pgs_residual.csv`, and `pgs_residual.png` with `--features plot`), against Lemke.
//! 3. A ball bouncing on the floor (e = 0.8): impact times and the rest time against the
//!    closed forms, with the order of convergence in h.
//! 4. Housner's rocking block: velocity ratio and amplitude decay over 10 impacts.
//! 5. Newton's cradle (N = 5): the simultaneous impact of touching balls and the
//!    sequential impacts of spaced ones.
//!
//! `cargo run --release [--features plot] --example timestep_classics -- [--out DIR]`
//! (writes into `out/timestep` by default).

use std::path::PathBuf;

use nonsmooth::analysis::observed_order;
use nonsmooth::drive::Control;
use nonsmooth::output::csv::{Cell, write_table_path};
use nonsmooth::timestep::lcp::{Lemke, Pgs, residual};
use nonsmooth::timestep::{
    ImpactLog, MoreauJean, PlanarBodies, PlanarContact, Plane, RigidBody, Solver, StepObserver,
    StepRecord,
};

type Res<T> = nonsmooth::Result<T>;

/// Bodies, contacts and initial positions of a column.
type Column = (PlanarBodies<f64>, Vec<PlanarContact<f64>>, Vec<f64>);

struct Checks(Vec<(String, bool)>);

impl Checks {
    fn check(&mut self, name: impl Into<String>, ok: bool) {
        let name = name.into();
        println!("  [{}] {name}", if ok { "ok" } else { "FAILED" });
        self.0.push((name, ok));
    }
}

/// 1. Lemke's method on problems with known solutions.
fn lcp_section(c: &mut Checks) -> Res<()> {
    println!("1. Lemke on Murty's family (lower triangular, 1 on / 2 below the diagonal):");
    println!("|  n | pivots | 2ⁿ | max |z − z*| | residual |");
    println!("|---|---|---|---|---|");
    for n in [2usize, 4, 6, 8, 10, 12] {
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            m[i * n + i] = 1.0;
            for j in 0..i {
                m[i * n + j] = 2.0;
            }
        }
        let mut acc = 0.0;
        let q: Vec<f64> = (0..n)
            .map(|i| {
                acc += 2f64.powi((n - i) as i32);
                -acc
            })
            .collect();
        // Exact: forward substitution (a triangular P-matrix).
        let mut exact = vec![0.0; n];
        for i in 0..n {
            let s = q[i] + (0..i).map(|j| m[i * n + j] * exact[j]).sum::<f64>();
            exact[i] = (-s).max(0.0);
        }
        let mut z = vec![0.0; n];
        let r = Lemke::new()
            .with_pivot_limit(1 << 16)
            .solve(&m, &q, &mut z)?;
        let err = z
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "| {n} | {} | {} | {err:.1e} | {:.1e} |",
            r.iterations,
            1 << n,
            r.residual
        );
        c.check(
            format!("Murty n = {n}: 2ⁿ pivots, exact"),
            r.iterations == 1 << n && err <= 1e-12 && r.residual <= 1e-12,
        );
    }
    // Random SPD with a planted solution.
    let mut s = 0x2545_f491_4f6c_dd1d_u64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for n in [50usize, 200] {
        let a: Vec<f64> = (0..n * n).map(|_| 2.0 * rnd() - 1.0).collect();
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                m[i * n + j] = (0..n).map(|k| a[i * n + k] * a[j * n + k]).sum::<f64>() / n as f64
                    + if i == j { 1.0 } else { 0.0 };
            }
        }
        let (mut zs, mut ws) = (vec![0.0; n], vec![0.0; n]);
        for i in 0..n {
            if rnd() < 0.5 {
                zs[i] = rnd() + 0.1;
            } else {
                ws[i] = rnd() + 0.1;
            }
        }
        let q: Vec<f64> = (0..n)
            .map(|i| ws[i] - (0..n).map(|j| m[i * n + j] * zs[j]).sum::<f64>())
            .collect();
        let mut z = vec![0.0; n];
        let r = Lemke::new().solve(&m, &q, &mut z)?;
        let err = z
            .iter()
            .zip(&zs)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "random SPD n = {n}: Lemke {} pivots, residual {:.1e}, error {err:.1e}",
            r.iterations, r.residual
        );
        c.check(
            format!("random SPD n = {n}: residual ≤ 1e-12"),
            r.residual <= 1e-12 && residual(&m, &q, &z)? <= 1e-12,
        );
    }
    Ok(())
}

/// Discs of radius `r`, unit mass, stacked on the floor, touching (`r = 1/16` makes every
/// gap exactly zero).
fn column(n: usize, r: f64, e: f64) -> Res<Column> {
    let bodies = PlanarBodies::new(vec![RigidBody::disc(1.0, r)?; n], 9.81)?;
    let mut contacts = vec![PlanarContact::disc_plane(0, r, Plane::floor(0.0)?, e, 0.0)?];
    for i in 0..n - 1 {
        contacts.push(PlanarContact::disc_disc(i, r, i + 1, r, e, 0.0)?);
    }
    let mut q = vec![0.0; 3 * n];
    for i in 0..n {
        q[3 * i + 1] = r + 2.0 * r * i as f64;
    }
    Ok((bodies, contacts, q))
}

/// 2. PGS on the contact problem of a resting column of 100 balls.
fn column_section(c: &mut Checks, out: &std::path::Path) -> Res<()> {
    println!("2. Column of 100 balls at rest, h = 1 ms: the first step's contact problem");
    let (n, h) = (100, 1e-3);
    let (bodies, contacts, q0) = column(n, 0.0625, 0.0)?;
    // The Delassus problem of the first step, assembled by hand (the scheme's own): unit
    // masses, rows along y: W = tridiag(−1, 2, −1) with W₀₀ = 1; q = (−g h, 0, …, 0).
    let mut w = vec![0.0; n * n];
    for i in 0..n {
        w[i * n + i] = if i == 0 { 1.0 } else { 2.0 };
        if i > 0 {
            w[i * n + i - 1] = -1.0;
            w[(i - 1) * n + i] = -1.0;
        }
    }
    let mut qv = vec![0.0; n];
    qv[0] = -9.81 * h;
    let mut history = Vec::new();
    let mut z = vec![0.0; n];
    let r = Pgs::new()
        .with_max_iterations(200_000)
        .with_tolerance(1e-12)?
        .solve_traced(&w, &qv, &mut z, |k, res| history.push((k, res)))?;
    let exact: Vec<f64> = (0..n).map(|i| (n - i) as f64 * 9.81 * h).collect();
    let err = z
        .iter()
        .zip(&exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "PGS: {} sweeps to residual {:.1e}; worst impulse error {err:.1e} N·s (bound ‖W⁻¹‖∞·r = {:.1e})",
        r.iterations,
        r.residual,
        5050.0 * r.residual
    );
    for k in [1usize, 10, 100, 1000, 10_000] {
        if let Some(&(_, res)) = history.get(k - 1) {
            println!("  residual after {k:>6} sweeps: {res:.3e}");
        }
    }
    write_table_path(
        out.join("pgs_residual.csv"),
        &["sweep", "residual"],
        history
            .iter()
            .map(|&(k, res)| [Cell::Number(k as f64), Cell::Number(res)]),
    )?;
    #[cfg(feature = "plot")]
    {
        use nonsmooth::output::plot::{Panel, Rgb, Series, plot_series};
        let panel = Panel::new("sweep", "log₁₀ residual")
            .title("PGS on a resting column of 100 balls")
            .with(
                Series::line(history.iter().map(|&(k, res)| (k as f64, res.log10())))
                    .color(Rgb::BLUE),
            );
        plot_series(out.join("pgs_residual.png"), &panel)?;
    }
    c.check(
        "100-ball column: PGS converged, impulses exact within ‖W⁻¹‖∞ × residual",
        r.residual <= 1e-12 && err <= 5050.0 * r.residual.max(f64::EPSILON),
    );
    // The same through the scheme, Lemke and warm-started PGS over 100 steps.
    for (name, solver) in [
        ("Lemke", Solver::Lemke(Lemke::new())),
        ("PGS", Solver::Pgs(Pgs::new().with_max_iterations(200_000))),
    ] {
        let mut scheme =
            MoreauJean::new(bodies.clone(), contacts.clone(), h)?.with_solver(solver)?;
        let (mut q, mut v) = (q0.clone(), vec![0.0; 3 * n]);
        let s = scheme.run(0.0, &mut q, &mut v, 0.1, &mut ())?;
        let drift = (0..n)
            .map(|i| (q[3 * i + 1] - q0[3 * i + 1]).abs())
            .fold(0.0, f64::max);
        println!(
            "{name} in the scheme: {} steps, {} solver iterations in all (first step included), largest residual {:.1e}, largest drift of a ball {drift:.1e} m",
            s.steps, s.solver_iterations, s.max_residual
        );
        c.check(
            format!("100-ball column stays at rest ({name})"),
            drift < 1e-9,
        );
    }
    Ok(())
}

struct LastFree(f64);

impl StepObserver<f64> for LastFree {
    fn on_step(&mut self, s: &StepRecord<'_, f64>) -> Control {
        if s.contacts.is_empty() {
            self.0 = s.t1;
        }
        Control::Continue
    }
}

/// 3. The bouncing ball.
fn ball_section(c: &mut Checks, out: &std::path::Path) -> Res<()> {
    println!("3. Ball on the floor, e = 0.8, dropped from 1 m:");
    let (g, e, d) = (9.81_f64, 0.8_f64, 1.0_f64);
    let t1 = (2.0 * d / g).sqrt();
    let v1 = g * t1;
    let mut exact = vec![t1];
    for k in 1..10 {
        let last = exact[exact.len() - 1];
        exact.push(last + 2.0 * e.powi(k) * v1 / g);
    }
    let t_inf = t1 + 2.0 * e * v1 / (g * (1.0 - e));
    println!("t∞ = t₁ + 2e·v₁/(g(1−e)) = {t_inf:.6} s");
    println!("| h (s) | impacts | first-10 impact-time error (s) | rest time (s) | error (s) |");
    println!("|---|---|---|---|---|");
    let hs = [4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5];
    let (mut et, mut er) = (Vec::new(), Vec::new());
    let mut rows = Vec::new();
    for &h in &hs {
        let ball = PlanarBodies::new(vec![RigidBody::disc(1.0, 0.1)?], g)?;
        let floor = vec![PlanarContact::disc_plane(
            0,
            0.1,
            Plane::floor(0.0)?,
            e,
            0.0,
        )?];
        let mut scheme = MoreauJean::new(ball, floor, h)?;
        let (mut q, mut v) = (vec![0.0, 0.1 + d, 0.0], vec![0.0; 3]);
        let mut obs = (ImpactLog::new(g * h)?, LastFree(0.0));
        scheme.run(0.0, &mut q, &mut v, t_inf + 1.0, &mut obs)?;
        let impacts = &obs.0.impacts;
        let err = impacts
            .iter()
            .zip(&exact)
            .map(|(i, t)| (i.t0 - t).abs())
            .fold(0.0, f64::max);
        let rest = obs.1.0;
        println!(
            "| {h:.3e} | {} | {err:.3e} | {rest:.6} | {:.3e} |",
            impacts.len(),
            (rest - t_inf).abs()
        );
        rows.push([h, err, rest, (rest - t_inf).abs()]);
        et.push(err);
        er.push((rest - t_inf).abs());
        c.check(
            format!("h = {h:e}: at rest on the floor after t∞"),
            v[1].abs() < 1e-12 && (q[1] - 0.1).abs() < g * h * h,
        );
    }
    write_table_path(
        out.join("ball_convergence.csv"),
        &[
            "h_s",
            "impact_time_error_s",
            "rest_time_s",
            "rest_time_error_s",
        ],
        rows.iter().map(|r| r.map(Cell::Number)),
    )?;
    let (pt, pr) = (observed_order(&hs, &et)?, observed_order(&hs, &er)?);
    println!("fitted orders: impact times {pt:.3}, rest time {pr:.3}");
    c.check(
        "impact times converge at first order",
        (pt - 1.0).abs() < 0.15,
    );
    c.check(
        "rest time converges at first order",
        (pr - 1.0).abs() < 0.25,
    );
    Ok(())
}

/// Angle, angular velocity and impact steps of the rocking block.
struct Rocking {
    speed: f64,
    trace: Vec<(f64, f64, f64)>,
    impacts: Vec<usize>,
}

impl StepObserver<f64> for Rocking {
    fn on_start(&mut self, t0: f64, q: &[f64], v: &[f64]) {
        self.trace.push((t0, q[2], v[2]));
    }
    fn on_step(&mut self, s: &StepRecord<'_, f64>) -> Control {
        self.trace.push((s.t1, s.q[2], s.v[2]));
        if s.contacts.iter().any(|c| c.is_impact(self.speed)) {
            self.impacts.push(self.trace.len() - 1);
        }
        Control::Continue
    }
}

/// 4. Housner's rocking block.
fn block_section(c: &mut Checks) -> Res<()> {
    println!(
        "4. Rocking block, half-sizes 0.1 × 0.5 m (tan α = 1/5), released at α/2, e = 0, μ = 0.9:"
    );
    let (b, hh, g) = (0.1_f64, 0.5_f64, 9.81);
    let alpha = (b / hh).atan();
    let r = 1.0 - 1.5 * alpha.sin().powi(2);
    println!("Housner: r = 1 − (3/2) sin²α = {r:.6}");
    println!("| h (s) | worst |ω⁺/ω⁻ − r| | worst relative amplitude error (10 impacts) |");
    println!("|---|---|---|");
    let mut prev: Option<(f64, f64)> = None;
    for h in [1e-3, 5e-4, 2.5e-4, 1.25e-4] {
        let body = PlanarBodies::new(vec![RigidBody::rectangle(1.0, b, hh)?], g)?;
        let floor = Plane::floor(0.0)?;
        let corners = vec![
            PlanarContact::corner_plane(0, [-b, -hh], floor, 0.0, 0.9)?,
            PlanarContact::corner_plane(0, [b, -hh], floor, 0.0, 0.9)?,
        ];
        let mut scheme = MoreauJean::new(body, corners, h)?;
        let theta0 = -0.5 * alpha;
        let (s, co) = theta0.sin_cos();
        let mut q = vec![b - (co * b + s * hh), -(s * b - co * hh), theta0];
        let mut v = vec![0.0; 3];
        let mut obs = Rocking {
            speed: g * h,
            trace: Vec::new(),
            impacts: Vec::new(),
        };
        scheme.run(0.0, &mut q, &mut v, 8.0, &mut obs)?;
        if obs.impacts.len() < 11 {
            c.check(format!("h = {h:e}: 10 impacts"), false);
            continue;
        }
        let ratio_err = obs.impacts[..10]
            .iter()
            .map(|&k| (obs.trace[k].2 / obs.trace[k - 1].2 - r).abs())
            .fold(0.0, f64::max);
        let mut predicted = -theta0;
        let mut amp_err: f64 = 0.0;
        for w in obs.impacts.windows(2).take(10) {
            let amp = obs.trace[w[0]..w[1]]
                .iter()
                .map(|x| x.1.abs())
                .fold(0.0, f64::max);
            let cc = alpha.cos() + r * r * ((alpha - predicted).cos() - alpha.cos());
            predicted = alpha - cc.acos();
            amp_err = amp_err.max((amp - predicted).abs() / predicted);
        }
        println!("| {h:.3e} | {ratio_err:.3e} | {amp_err:.3e} |");
        if let Some((pr, pa)) = prev {
            c.check(
                format!("h = {h:e}: both errors halve with h (first order)"),
                (0.4..0.6).contains(&(ratio_err / pr)) && (0.4..0.6).contains(&(amp_err / pa)),
            );
        }
        prev = Some((ratio_err, amp_err));
    }
    Ok(())
}

/// 5. Newton's cradle.
fn cradle_section(c: &mut Checks) -> Res<()> {
    println!("5. Newton's cradle, 5 equal discs, e = 1, the first at 1 m/s:");
    let (n, r, h) = (5, 0.0625, 1e-3);
    for spacing in [0.0, 1e-2] {
        let bodies = PlanarBodies::new(vec![RigidBody::disc(1.0, r)?; n], 0.0)?;
        let contacts = (0..n - 1)
            .map(|i| PlanarContact::disc_disc(i, r, i + 1, r, 1.0, 0.0))
            .collect::<Result<Vec<_>, _>>()?;
        let mut scheme = MoreauJean::new(bodies, contacts, h)?;
        let mut q = vec![0.0; 3 * n];
        for i in 0..n {
            q[3 * i] = (2.0 * r + spacing) * i as f64;
        }
        let mut v = vec![0.0; 3 * n];
        v[0] = 1.0;
        scheme.run(0.0, &mut q, &mut v, 1.0, &mut ())?;
        let vx: Vec<f64> = (0..n).map(|i| v[3 * i]).collect();
        let p: f64 = vx.iter().sum();
        let e: f64 = vx.iter().map(|x| 0.5 * x * x).sum();
        println!(
            "spacing {spacing} m: v⁺ = {vx:.6?}, momentum − 1 = {:.1e}, energy − 1/2 = {:.1e}",
            p - 1.0,
            e - 0.5
        );
        c.check(
            format!("spacing {spacing}: momentum conserved to round-off"),
            (p - 1.0).abs() <= 8.0 * f64::EPSILON,
        );
        if spacing == 0.0 {
            c.check(
                "touching: Moreau's distribution (−3/5, 2/5, 2/5, 2/5, 2/5)",
                (vx[0] + 0.6).abs() < 1e-14 && vx[1..].iter().all(|x| (x - 0.4).abs() < 1e-14),
            );
        } else {
            c.check(
                "spaced: the textbook cradle (0, 0, 0, 0, 1)",
                vx[..4].iter().all(|x| x.abs() < 1e-12) && (vx[4] - 1.0).abs() < 1e-12,
            );
        }
    }
    Ok(())
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out/timestep"));
    std::fs::create_dir_all(&out)?;
    let mut c = Checks(Vec::new());
    lcp_section(&mut c)?;
    column_section(&mut c, &out)?;
    ball_section(&mut c, &out)?;
    block_section(&mut c)?;
    cradle_section(&mut c)?;
    let failed: Vec<&str> = c.0.iter().filter(|x| !x.1).map(|x| x.0.as_str()).collect();
    println!(
        "{} checks, {} failed; files in {}",
        c.0.len(),
        failed.len(),
        out.display()
    );
    if !failed.is_empty() {
        for f in failed {
            println!("FAILED: {f}");
        }
        std::process::exit(1);
    }
    Ok(())
}
