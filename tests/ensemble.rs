//! Ensembles in SIMD lanes against the scalar path: the paper's model (to the bit with the
//! exact math, within the tolerance with the vector math), a linear forced oscillator with
//! a closed form, event times, determinism over lane counts, batch order and threads, and
//! the lane math functions against libm.

use nalgebra::Vector2;
use nonsmooth::drive::{Control, EventRecord, Observer, Simulation};
use nonsmooth::ensemble::{Ensemble, F64x4, F64x8, LaneMath, Lanes, MemberRun, Simd};
use nonsmooth::event::{Direction, Event, Level, Stop};
use nonsmooth::integrate::{Dopri5, Stats, Tolerances};
use nonsmooth::lanes::math;
use nonsmooth::sample::Stroboscopic;
use nonsmooth::systems::paper::{Member, PAPER, PaperParameters};

/// Section points and event times of one run.
#[derive(Debug, Clone)]
struct Record {
    strobe: Stroboscopic<f64, 2>,
    events: Vec<(f64, f64, f64)>,
}

impl Record {
    fn new(period: f64) -> Self {
        Self {
            strobe: Stroboscopic::periodic(0.0, period, 0.5 * period, 1 << 16).unwrap(),
            events: Vec::new(),
        }
    }
    fn sections(&self) -> Vec<(f64, Vector2<f64>)> {
        self.strobe.points().iter().map(|p| (p.t, p.y)).collect()
    }
}

impl Observer<f64, 2> for Record {
    fn check_span(&self, t0: f64, t_end: f64) -> Result<(), nonsmooth::drive::RunError> {
        self.strobe.check_span(t0, t_end)
    }
    fn on_start(&mut self, t0: f64, y0: &Vector2<f64>) {
        self.strobe.on_start(t0, y0);
    }
    fn on_step<D: nonsmooth::integrate::DenseOutput<f64, 2>>(
        &mut self,
        s: &nonsmooth::drive::StepView<'_, f64, 2, D>,
    ) -> Control {
        self.strobe.on_step(s)
    }
    fn on_event(&mut self, e: &EventRecord<f64, 2>) -> Control {
        self.events.push((e.t, e.y[0], e.y[1]));
        Control::Continue
    }
}

fn tol(rtol: f64) -> Tolerances<f64, 2> {
    Tolerances::per_component(rtol, [rtol * 1e-4, rtol * 1e-2]).unwrap()
}

fn impact() -> Event<Stop<f64>> {
    Event::new(
        Stop {
            position: 0,
            velocity: 1,
            level: PAPER.x_i,
        },
        Direction::Rising,
    )
}

fn rest() -> Vector2<f64> {
    Vector2::new(PAPER.static_equilibrium().unwrap(), 0.0)
}

/// The scalar path: `Simulation` + `Dopri5`, steps landing on the sections.
fn scalar(
    job: &MemberRun<Member>,
    tol: Tolerances<f64, 2>,
    event: bool,
) -> (Record, Stats, Vector2<f64>) {
    let mut rec = Record::new(job.member.period());
    let sim = Simulation::new(*job.member.scalar(), Dopri5::new(tol))
        .landing_grid(job.grid)
        .unwrap();
    let out = if event {
        sim.with_events(impact())
            .run(job.t0, job.y0, job.t_end, &mut rec)
            .unwrap()
    } else {
        let mut sim = sim;
        sim.run(job.t0, job.y0, job.t_end, &mut rec).unwrap()
    };
    (rec, out.stats, out.y)
}

/// The ensemble path on the instruction set `simd` (and its width).
fn lanes(
    jobs: &[MemberRun<Member>],
    tol: Tolerances<f64, 2>,
    math: LaneMath,
    simd: Simd,
) -> Vec<(Record, Stats, Vector2<f64>)> {
    let mut recs: Vec<Record> = jobs
        .iter()
        .map(|j| Record::new(j.member.period()))
        .collect();
    let ens = Ensemble::new(tol)
        .unwrap()
        .with_event(impact())
        .unwrap()
        .with_math(math)
        .with_simd(simd);
    let out = ens.run(jobs, &mut recs).unwrap();
    recs.into_iter()
        .zip(out)
        .map(|(r, o)| {
            let o = o.unwrap();
            (r, o.stats, o.y)
        })
        .collect()
}

fn paper_jobs(omegas: &[f64], periods: f64) -> Vec<MemberRun<Member>> {
    omegas
        .iter()
        .map(|&w| MemberRun::periods(Member::paper(w).unwrap(), rest(), periods).unwrap())
        .collect()
}

#[test]
fn lanes_reproduce_the_scalar_paper_model_to_the_bit() {
    // Impact-free, one to five impacts per period, period 2, chaotic: all regimes.
    let omegas = [13.0, 14.5, 17.0, 18.0, 19.0, 20.465, 22.0, 25.0, 15.7];
    let jobs = paper_jobs(&omegas, 40.0);
    let tol = tol(1e-8);
    let ens = lanes(&jobs, tol, LaneMath::Exact, Simd::Auto);
    let mut impacts = 0;
    for (job, (rec, stats, y)) in jobs.iter().zip(&ens) {
        let (srec, sstats, sy) = scalar(job, tol, true);
        assert_eq!(*stats, sstats, "ω = {}", job.member.omega());
        assert_eq!(*y, sy);
        assert_eq!(rec.sections(), srec.sections());
        assert_eq!(rec.sections().len(), 40);
        assert_eq!(rec.events, srec.events);
        impacts += rec.events.len();
    }
    assert!(impacts > 200, "{impacts}");
}

/// The tail compaction: with the queue empty and at most half the lanes busy, the busy
/// lanes move to a vector of half the width (16 → 8 with AVX2 or AVX-512, 4 → 2 on the
/// baseline), as trajectories of 3 to 9 periods end one after another. Each trajectory is
/// still the scalar one to the bit with exact math, and with vector math the same on every
/// instruction set.
#[test]
fn tail_compaction_keeps_every_trajectory() {
    let omegas = [
        17.0, 18.0, 19.0, 20.465, 22.0, 25.0, 15.7, 13.0, 14.5, 21.0, 23.0,
    ];
    let jobs: Vec<MemberRun<Member>> = omegas
        .iter()
        .enumerate()
        .map(|(k, &w)| {
            MemberRun::periods(Member::paper(w).unwrap(), rest(), 3.0 + k as f64).unwrap()
        })
        .collect();
    let tol = tol(1e-8);
    let vector = summary(&lanes(&jobs, tol, LaneMath::Vector, Simd::Baseline));
    for simd in Simd::available() {
        let wide = lanes(&jobs, tol, LaneMath::Exact, simd);
        for (job, (rec, stats, y)) in jobs.iter().zip(&wide) {
            let (srec, sstats, sy) = scalar(job, tol, true);
            assert_eq!(*stats, sstats, "{simd:?}, ω = {}", job.member.omega());
            assert_eq!(*y, sy);
            assert_eq!(rec.sections(), srec.sections());
            assert_eq!(rec.events, srec.events);
        }
        assert_eq!(
            summary(&lanes(&jobs, tol, LaneMath::Vector, simd)),
            vector,
            "{simd:?}"
        );
    }
}

/// The largest distance between the section points of two runs relative to the points'
/// scale per component, over the last `n` sections.
fn section_distance(a: &Record, b: &Record, n: usize) -> f64 {
    let (pa, pb) = (a.sections(), b.sections());
    assert_eq!(pa.len(), pb.len());
    let mut scale = [0.0f64; 2];
    for (_, y) in &pa {
        for c in 0..2 {
            scale[c] = scale[c].max(y[c].abs());
        }
    }
    pa.iter()
        .zip(&pb)
        .rev()
        .take(n)
        .map(|((ta, ya), (tb, yb))| {
            assert_eq!(ta, tb);
            (0..2)
                .map(|c| (ya[c] - yb[c]).abs() / scale[c])
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

#[test]
fn vector_math_lanes_agree_with_scalar_within_the_tolerance() {
    // Periodic attractors (on a chaotic one any two computations separate): the section
    // points of the vector-math lanes against the scalar path, and the scatter of the
    // scalar path itself between rtol 1e-8 and 1e-9 as the yardstick.
    let omegas = [14.5, 16.0, 17.0, 19.0, 20.2, 24.0];
    let jobs = paper_jobs(&omegas, 150.0);
    let ens = lanes(&jobs, tol(1e-8), LaneMath::Vector, Simd::Auto);
    for (job, (rec, stats, _)) in jobs.iter().zip(&ens) {
        let (srec, sstats, _) = scalar(job, tol(1e-8), true);
        let (frec, _, _) = scalar(job, tol(1e-9), true);
        let d = section_distance(rec, &srec, 20);
        let yard = section_distance(&frec, &srec, 20);
        println!(
            "ω = {}: lanes {d:e}, scalar 1e-8 vs 1e-9 {yard:e}",
            job.member.omega()
        );
        assert!(
            // Two runs at the same tolerance differ by up to about twice the error of
            // either (the 1e-8 vs 1e-9 spread); factor 3 for the variation along the orbit.
            d <= 3.0 * yard.max(1e-9),
            "ω = {}: lanes {d:e} vs scalar tolerance spread {yard:e}",
            job.member.omega()
        );
        // The same number of impacts in the recorded window, and close work.
        let count = |r: &Record| {
            r.events
                .iter()
                .filter(|e| e.0 > 50.0 * job.member.period())
                .count()
        };
        assert_eq!(count(rec), count(&srec), "ω = {}", job.member.omega());
        let ratio = stats.rhs_evals as f64 / sstats.rhs_evals as f64;
        assert!((0.9..1.1).contains(&ratio), "work ratio {ratio}");
    }
}

/// A linear forced oscillator `m ẍ + c ẋ + k x = A sin ωt` (the paper's member without
/// friction and with the stop out of reach) and its closed form.
struct Linear {
    m: f64,
    c: f64,
    k: f64,
    a: f64,
    w: f64,
}

impl Linear {
    fn params() -> PaperParameters {
        PaperParameters {
            t: 0.0,
            x_i: 1.0,
            ..PAPER
        }
    }
    fn new(w: f64) -> Self {
        let p = Self::params();
        Self {
            m: p.m,
            c: p.c,
            k: p.k,
            a: p.m0e * w * w,
            w,
        }
    }
    /// `x(t)` from `(x0, v0)` at `t = 0`.
    fn x(&self, t: f64, x0: f64, v0: f64) -> f64 {
        let (m, c, k, a, w) = (self.m, self.c, self.k, self.a, self.w);
        let d = (k - m * w * w).powi(2) + (c * w).powi(2);
        let (p, q) = (a * (k - m * w * w) / d, -a * c * w / d);
        let s = c / (2.0 * m);
        let wd = (k / m - s * s).sqrt();
        let c1 = x0 - q;
        let c2 = (v0 + s * c1 - p * w) / wd;
        (-s * t).exp() * (c1 * (wd * t).cos() + c2 * (wd * t).sin())
            + p * (w * t).sin()
            + q * (w * t).cos()
    }
}

#[test]
fn smooth_reference_closed_form() {
    let omegas = [6.0, 9.0, 12.7, 15.0, 20.0, 31.0];
    let y0 = Vector2::new(1e-3, -2e-2);
    let jobs: Vec<MemberRun<Member>> = omegas
        .iter()
        .map(|&w| MemberRun::periods(Member::new(Linear::params(), w).unwrap(), y0, 30.0).unwrap())
        .collect();
    let tol = Tolerances::per_component(1e-9, [1e-13, 1e-11]).unwrap();
    for math in [LaneMath::Exact, LaneMath::Vector] {
        let ens = lanes(&jobs, tol, math, Simd::Auto);
        for (job, (rec, _, _)) in jobs.iter().zip(&ens) {
            let lin = Linear::new(job.member.omega());
            let (srec, _, _) = scalar(job, tol, true);
            let err = |r: &Record| {
                r.sections()
                    .iter()
                    .map(|(t, y)| (y[0] - lin.x(*t, y0[0], y0[1])).abs())
                    .fold(0.0, f64::max)
            };
            let (el, es) = (err(rec), err(&srec));
            let amplitude = rec
                .sections()
                .iter()
                .map(|(_, y)| y[0].abs())
                .fold(0.0, f64::max);
            // Both paths meet the closed form to the tolerance's order (rtol 1e-9).
            assert!(
                es < 1e-8 * amplitude && el < 1e-8 * amplitude,
                "ω = {}: {el:e} {es:e} of {amplitude:e}",
                lin.w
            );
            if math == LaneMath::Exact {
                assert_eq!(rec.sections(), srec.sections());
            } else {
                // Within the scalar path's own error of the closed form.
                assert!(section_distance(rec, &srec, 30) * amplitude <= 2.0 * es.max(1e-15));
            }
        }
    }
}

#[test]
fn events_in_lanes_are_located_like_the_scalar_ones() {
    // Crossings of x = 3e-4 (both directions) on the linear oscillator against the roots of
    // the closed form, in lanes and on the scalar path.
    let level = 3e-4;
    let y0 = Vector2::new(1e-3, 0.0);
    let omegas = [7.0, 11.0, 13.0, 17.0];
    let tol = Tolerances::per_component(1e-9, [1e-13, 1e-11]).unwrap();
    let ev = Event::new(Level::new(0, level).unwrap(), Direction::Either);
    for math in [LaneMath::Exact, LaneMath::Vector] {
        let jobs: Vec<MemberRun<Member>> = omegas
            .iter()
            .map(|&w| {
                MemberRun::periods(Member::new(Linear::params(), w).unwrap(), y0, 20.0).unwrap()
            })
            .collect();
        let mut recs: Vec<Record> = jobs
            .iter()
            .map(|j| Record::new(j.member.period()))
            .collect();
        let ens = Ensemble::new(tol)
            .unwrap()
            .with_event(ev)
            .unwrap()
            .with_math(math);
        ens.run(&jobs, &mut recs).unwrap();
        let mut n = 0;
        for (job, rec) in jobs.iter().zip(&recs) {
            let lin = Linear::new(job.member.omega());
            let mut srec = Record::new(job.member.period());
            Simulation::new(*job.member.scalar(), Dopri5::new(tol))
                .with_events(ev)
                .landing_grid(job.grid)
                .unwrap()
                .run(0.0, y0, job.t_end, &mut srec)
                .unwrap();
            assert_eq!(rec.events.len(), srec.events.len());
            for (a, b) in rec.events.iter().zip(&srec.events) {
                // The exact crossing near the located one (bisection on the closed form).
                let g = |t: f64| lin.x(t, y0[0], y0[1]) - level;
                let (mut lo, mut hi) = (a.0 - 1e-6, a.0 + 1e-6);
                assert!(g(lo) * g(hi) < 0.0);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if g(lo) * g(mid) <= 0.0 {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let exact = 0.5 * (lo + hi);
                assert!((a.0 - exact).abs() < 1e-9, "lane {} vs {exact}", a.0);
                assert!((b.0 - exact).abs() < 1e-9, "scalar {} vs {exact}", b.0);
                if math == LaneMath::Exact {
                    assert_eq!(a, b);
                }
                n += 1;
            }
        }
        assert!(n > 100, "{n}");
    }
}

/// What a run produced: section points, events, work and end state.
type Summary = (
    Vec<(f64, Vector2<f64>)>,
    Vec<(f64, f64, f64)>,
    Stats,
    Vector2<f64>,
);

fn summary(r: &[(Record, Stats, Vector2<f64>)]) -> Vec<Summary> {
    r.iter()
        .map(|(a, s, y)| (a.sections(), a.events.clone(), *s, *y))
        .collect()
}

#[test]
fn results_do_not_depend_on_lanes_order_or_threads() {
    let omegas: Vec<f64> = (0..11).map(|i| 17.5 + 0.7 * i as f64).collect();
    let jobs = paper_jobs(&omegas, 12.0);
    let tol = tol(1e-8);
    for math in [LaneMath::Exact, LaneMath::Vector] {
        let base = summary(&lanes(&jobs, tol, math, Simd::Auto));
        // Every instruction set (and its width) gives the same bits.
        for simd in Simd::available() {
            assert_eq!(summary(&lanes(&jobs, tol, math, simd)), base, "{simd:?}");
        }
        // Reversed batch: the same per trajectory.
        let rev: Vec<MemberRun<Member>> = jobs.iter().rev().copied().collect();
        let mut r = summary(&lanes(&rev, tol, math, Simd::Auto));
        r.reverse();
        assert_eq!(r, base);
        // Threads and chunks.
        let ens = Ensemble::new(tol)
            .unwrap()
            .with_event(impact())
            .unwrap()
            .with_math(math);
        for (threads, chunk) in [(1, 3), (2, 4), (2, 1)] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut recs: Vec<Record> = jobs
                .iter()
                .map(|j| Record::new(j.member.period()))
                .collect();
            let out = pool
                .install(|| ens.run_parallel(&jobs, &mut recs, chunk))
                .unwrap();
            let got: Vec<_> = recs
                .into_iter()
                .zip(out)
                .map(|(r, o)| {
                    let o = o.unwrap();
                    (r, o.stats, o.y)
                })
                .collect();
            assert_eq!(summary(&got), base, "{threads} threads, chunk {chunk}");
        }
    }
}

/// Distance in units in the last place of the reference.
fn ulps(a: f64, b: f64) -> f64 {
    if a == b {
        return 0.0;
    }
    let ulp = f64::from_bits(b.abs().to_bits() + 1) - b.abs();
    ((a - b) / ulp).abs()
}

fn lcg(n: usize) -> impl Iterator<Item = f64> {
    let mut s: u64 = 0x2545_f491_4f6c_dd1d;
    (0..n).map(move |_| {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    })
}

#[test]
fn lane_sin_cos_and_sin_cos_are_the_scalar_kernels_to_the_bit() {
    let mut xs: Vec<f64> = lcg(40_000)
        .flat_map(|u| [u * 8.0 - 4.0, (u - 0.5) * 1.1e6, u * 2e4, (u - 0.5) * 1e-8])
        .collect();
    xs.extend([
        0.0,
        -0.0,
        1e-300,
        1e7,
        -3e9,
        f64::INFINITY,
        f64::NAN,
        524_288.0,
        524_288.5,
    ]);
    for c in xs.chunks(4) {
        let v = F64x4::load(c);
        let (s, co) = (math::sin(v), math::cos(v));
        let (s2, co2) = math::sin_cos(v);
        for (i, &x) in c.iter().enumerate() {
            let (want, want_cos) = (nonsmooth::util::sin_f64(x), nonsmooth::util::cos_f64(x));
            // One reduction for both: the same bits as each alone, and as the scalar pair.
            let pair = nonsmooth::util::sin_cos_f64(x);
            assert!(
                s2.lane(i).to_bits() == s.lane(i).to_bits()
                    || (s2.lane(i).is_nan() && s.lane(i).is_nan())
            );
            assert!(
                co2.lane(i).to_bits() == co.lane(i).to_bits()
                    || (co2.lane(i).is_nan() && co.lane(i).is_nan())
            );
            assert!(
                pair.0.to_bits() == want.to_bits() || (pair.0.is_nan() && want.is_nan()),
                "sin_cos_f64({x})"
            );
            assert!(
                pair.1.to_bits() == want_cos.to_bits() || (pair.1.is_nan() && want_cos.is_nan()),
                "sin_cos_f64({x})"
            );
            let (got, got_cos) = (s.lane(i), co.lane(i));
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "sin({x}): {got} vs {want}"
            );
            assert!(
                got_cos.to_bits() == want_cos.to_bits() || (got_cos.is_nan() && want_cos.is_nan()),
                "cos({x}): {got_cos} vs {want_cos}"
            );
        }
    }
}

#[test]
fn vector_exp_and_ln_against_libm() {
    let mut worst_exp: f64 = 0.0;
    let mut worst_ln: f64 = 0.0;
    let mut worst_ln_abs: f64 = 0.0;
    for u in lcg(200_000).collect::<Vec<_>>().chunks(4) {
        // exp on [−40, 40] (the controller's and the contact law's exponents).
        let x: Vec<f64> = u.iter().map(|u| (u - 0.5) * 80.0).collect();
        let e = math::exp(LaneMath::Vector, F64x4::load(&x));
        for (i, &xi) in x.iter().enumerate() {
            worst_exp = worst_exp.max(ulps(e.lane(i), xi.exp()));
        }
        // ln over [1e-300, 1e300] and near 1.
        let y: Vec<f64> = u
            .iter()
            .enumerate()
            .map(|(i, u)| {
                if i % 2 == 0 {
                    10f64.powf((u - 0.5) * 600.0)
                } else {
                    0.5 + u
                }
            })
            .collect();
        let l = math::ln(LaneMath::Vector, F64x4::load(&y));
        for (i, &yi) in y.iter().enumerate() {
            let want = yi.ln();
            if want.abs() > 0.5 {
                worst_ln = worst_ln.max(ulps(l.lane(i), want));
            } else {
                worst_ln_abs = worst_ln_abs.max((l.lane(i) - want).abs() / f64::EPSILON);
            }
        }
    }
    // The whole range of exp, past the fast path's |x| ≤ 708 (those lanes take libm).
    for u in lcg(100_000).collect::<Vec<_>>().chunks(8) {
        let x: Vec<f64> = u.iter().map(|u| -745.0 + 1455.0 * u).collect();
        let e = math::exp(LaneMath::Vector, F64x8::load(&x));
        for (i, &xi) in x.iter().enumerate() {
            let want = xi.exp();
            if want >= f64::MIN_POSITIVE {
                worst_exp = worst_exp.max(ulps(e.lane(i), want));
            } else {
                assert_eq!(e.lane(i).to_bits(), want.to_bits(), "exp({xi}) (subnormal)");
            }
        }
    }
    // Special values go to libm in both functions.
    let special = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        -0.0,
        -1.0,
        5e-324,
        1e-310,
        f64::MIN_POSITIVE,
        f64::MAX,
        708.0,
        -708.0,
        709.7,
        -744.0,
        1e-300,
        1.0,
        // The edges of ln's bit test for positive normal numbers.
        f64::from_bits(f64::MIN_POSITIVE.to_bits() - 1),
        -5e-324,
        -f64::MIN_POSITIVE,
        -f64::MAX,
        f64::from_bits(0xfff8_0000_0000_0000),
        f64::from_bits(0x7ff0_0000_0000_0001),
        f64::from_bits(f64::INFINITY.to_bits() - 1),
        2.0 * f64::MIN_POSITIVE,
    ];
    for c in special.chunks(8) {
        let v = F64x8::load(c);
        let (e, l) = (
            math::exp(LaneMath::Vector, v),
            math::ln(LaneMath::Vector, v),
        );
        for (i, &x) in c.iter().enumerate() {
            let same = |got: f64, want: f64| {
                got.to_bits() == want.to_bits()
                    || (got.is_nan() && want.is_nan())
                    || ulps(got, want) <= 1.0
            };
            assert!(
                same(e.lane(i), x.exp()),
                "exp({x}) = {} vs {}",
                e.lane(i),
                x.exp()
            );
            assert!(
                same(l.lane(i), x.ln()),
                "ln({x}) = {} vs {}",
                l.lane(i),
                x.ln()
            );
        }
    }
    println!("exp {worst_exp} ulp, ln {worst_ln} ulp (|ln| > 0.5), ln near 1 {worst_ln_abs} ε abs");
    assert!(worst_exp <= 1.0, "exp: {worst_exp} ulp");
    assert!(worst_ln <= 1.0, "ln: {worst_ln} ulp");
    assert!(worst_ln_abs <= 1.0, "ln near 1: {worst_ln_abs} ε");
    // Exact mode is libm itself.
    let x = F64x4::load(&[0.3, -7.0, 25.0, 1e-3]);
    for i in 0..4 {
        assert_eq!(math::exp(LaneMath::Exact, x).lane(i), x.lane(i).exp());
    }
}

#[test]
fn invalid_input_is_an_error() {
    let tol = tol(1e-8);
    let ens = Ensemble::new(tol).unwrap();
    let m = Member::paper(20.0).unwrap();
    assert!(Member::paper(f64::NAN).is_err());
    assert!(Member::paper(-1.0).is_err());
    assert!(MemberRun::new(m, 0.0, rest(), 0.0).is_err());
    assert!(MemberRun::new(m, 0.0, Vector2::new(f64::NAN, 0.0), 1.0).is_err());
    assert!(MemberRun::periods(m, rest(), 0.0).is_err());
    assert!(
        MemberRun::new(m, 0.0, rest(), 1.0)
            .unwrap()
            .with_grid(0.0, -1.0)
            .is_err()
    );
    let jobs = paper_jobs(&[20.0, 21.0], 2.0);
    let mut one = vec![()];
    assert!(ens.run(&jobs, &mut one).is_err());
    let mut bad = impact();
    bad.function.position = 5;
    assert!(Ensemble::new(tol).unwrap().with_event(bad).is_err());
    assert!(ens.clone().max_steps(0).is_err());
    // A step cap too small for a trajectory fails that trajectory only.
    let capped = ens.max_steps(50).unwrap();
    let short = [MemberRun::new(m, 0.0, rest(), 2e-5).unwrap(), jobs[0]];
    let mut obs = vec![(); 2];
    let out = capped.run(&jobs, &mut obs).unwrap();
    assert!(out.iter().all(|o| o.is_err()));
    let out = capped.run(&short, &mut obs).unwrap();
    assert!(out[0].is_ok() && out[1].is_err(), "{out:?}");
}

/// Runs `f` on its own thread and waits at most `secs` seconds for it (a hang fails the
/// test instead of stalling the suite).
fn within<T: Send + 'static>(secs: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(std::time::Duration::from_secs(secs))
        .expect("the ensemble did not finish in time")
}

/// The ensemble's results with `Record` observers: per trajectory its summary or the error
/// message.
fn run_records(jobs: Vec<MemberRun<Member>>) -> Vec<Result<Summary, String>> {
    within(120, move || {
        let mut recs: Vec<Record> = jobs
            .iter()
            .map(|j| Record::new(j.member.period()))
            .collect();
        let ens = Ensemble::new(tol(1e-8))
            .unwrap()
            .with_event(impact())
            .unwrap();
        let out = ens.run(&jobs, &mut recs).unwrap();
        recs.into_iter()
            .zip(out)
            .map(|(r, o)| {
                o.map(|o| (r.sections(), r.events.clone(), o.stats, o.y))
                    .map_err(|e| e.to_string())
            })
            .collect()
    })
}

/// Issue 27: one trajectory among 64 with a landing grid `dt = −1` (set through the public
/// field) hung the whole batch. Invalid trajectories — wherever they are in the batch,
/// the first included — are now errors in their own result slots; every other trajectory
/// completes, bit for bit as without them.
#[test]
fn an_invalid_trajectory_fails_alone() {
    let omegas: Vec<f64> = (0..64).map(|i| 17.5 + 0.1 * i as f64).collect();
    let good = paper_jobs(&omegas, 3.0);
    let base = run_records(good.clone());
    assert!(base.iter().all(Result::is_ok));
    let nan = f64::NAN;
    let cases: [&[(usize, (f64, f64))]; 2] = [
        &[(37, (0.0, -1.0))],
        &[
            (0, (0.0, -1.0)),
            (20, (0.0, 0.0)),
            (41, (nan, 0.1)),
            (63, (0.0, f64::INFINITY)),
        ],
    ];
    for bad in cases {
        let mut jobs = good.clone();
        for &(k, grid) in bad {
            jobs[k].grid = Some(grid);
        }
        let got = run_records(jobs);
        for (k, (g, b)) in got.iter().zip(&base).enumerate() {
            if bad.iter().any(|&(j, _)| j == k) {
                let e = g.as_ref().expect_err("an invalid grid is an error");
                assert!(e.contains("grid"), "trajectory {k}: {e}");
            } else {
                assert_eq!(g, b, "trajectory {k} with {bad:?}");
            }
        }
    }
    // A bad time span or state through the public fields fails alone too.
    let mut jobs = good.clone();
    jobs[0].t0 = nan;
    jobs[5].y0 = Vector2::new(f64::INFINITY, 0.0);
    jobs[6].t_end = -1.0;
    let got = run_records(jobs);
    for (k, (g, b)) in got.iter().zip(&base).enumerate() {
        if [0, 5, 6].contains(&k) {
            assert!(g.is_err(), "trajectory {k}");
        } else {
            assert_eq!(g, b, "trajectory {k}");
        }
    }
}

/// A terminal event and a restarting event run in lanes as in the scalar driver: the
/// terminal impact ends each trajectory at its first impact (same time and state to the
/// bit, same termination and statistics); a restart at every impact gives the scalar
/// run's end state and statistics.
#[test]
fn terminal_and_restarting_events_match_the_driver() {
    use nonsmooth::drive::Termination;
    let tol = tol(1e-8);
    let jobs = paper_jobs(&[17.0, 19.0, 20.465, 22.0, 25.0], 10.0);
    for restart in [false, true] {
        let mut ev = impact();
        ev.terminal = !restart;
        ev.restart = restart;
        let ens = Ensemble::new(tol).unwrap().with_event(ev).unwrap();
        let mut obs = vec![(); jobs.len()];
        let out = ens.run(&jobs, &mut obs).unwrap();
        for (j, o) in jobs.iter().zip(&out) {
            let o = o.as_ref().unwrap();
            let want = Simulation::new(*j.member.scalar(), Dopri5::new(tol))
                .with_events(ev)
                .landing_grid(j.grid)
                .unwrap()
                .run(j.t0, j.y0, j.t_end, &mut ())
                .unwrap();
            assert_eq!((o.t, o.y, o.stats), (want.t, want.y, want.stats));
            assert_eq!(o.termination, want.termination);
            if !restart {
                assert_eq!(o.termination, Termination::TerminalEvent(0));
            }
        }
    }
}

/// Every event of a run, to the bit (time, state, state after the reset), and nothing
/// else: it does not want steps, so the ensemble skips the scalar event search of the
/// lanes' quiet steps.
#[derive(Debug, Clone, Default, PartialEq)]
struct EventsOnly<const M: usize>(Vec<(u64, [u64; M], Option<[u64; M]>)>);

impl<const M: usize> Observer<f64, M> for EventsOnly<M> {
    fn on_event(&mut self, e: &EventRecord<f64, M>) -> Control {
        let bits = |y: &nalgebra::SVector<f64, M>| core::array::from_fn(|i| y[i].to_bits());
        self.0
            .push((e.t.to_bits(), bits(&e.y), e.y_after.as_ref().map(bits)));
        Control::Continue
    }
    fn wants_steps(&self) -> bool {
        false
    }
}

/// Every step view (its ends and the dense output at its middle) and every event of a
/// run, to the bit; stops the run at its `stop_at`-th view if set. It wants steps: the
/// ensemble shows it the quiet steps without the scalar event search.
#[derive(Debug, Clone, Default, PartialEq)]
struct StepsAndEvents<const M: usize> {
    views: Vec<[u64; 3]>,
    events: EventsOnly<M>,
    stop_at: Option<usize>,
}

impl<const M: usize> Observer<f64, M> for StepsAndEvents<M> {
    fn on_step<D: nonsmooth::integrate::DenseOutput<f64, M>>(
        &mut self,
        s: &nonsmooth::drive::StepView<'_, f64, M, D>,
    ) -> Control {
        let mid = s.dense.interpolate(0.5 * (s.t0 + s.t1)).unwrap();
        let sum = |y: &nalgebra::SVector<f64, M>| {
            y.iter().fold(0u64, |h, v| h.rotate_left(7) ^ v.to_bits())
        };
        let ends = s.t0.to_bits() ^ s.t1.to_bits().rotate_left(1);
        self.views.push([ends, sum(&s.y0) ^ sum(&s.y1), sum(&mid)]);
        if self.stop_at == Some(self.views.len()) {
            Control::Stop
        } else {
            Control::Continue
        }
    }
    fn on_event(&mut self, e: &EventRecord<f64, M>) -> Control {
        self.events.on_event(e)
    }
}

/// The ensemble against the driver, with an observer that does not want steps and with
/// one that does (running to the end, and stopping at a step): outcomes, statistics,
/// every step view and every event record equal to the bit; on the instruction set `simd`.
fn same_as_driver<D, E, const M: usize>(
    jobs: &[MemberRun<D, M>],
    tol: Tolerances<f64, M>,
    ev: E,
    simd: Simd,
) where
    D: nonsmooth::LaneDynamics<M>,
    E: nonsmooth::event::EventSet<f64, M> + Clone,
{
    let n = jobs.len();
    let (events, _) =
        same_as_driver_with::<_, _, _, M>(jobs, tol, (ev.clone(), simd), |_| EventsOnly::default());
    assert!(events > 10 * n, "{events} events");
    let (events, _) = same_as_driver_with::<_, _, _, M>(jobs, tol, (ev.clone(), simd), |_| {
        StepsAndEvents::default()
    });
    assert!(events > 10 * n, "{events} events");
    let (_, stopped) =
        same_as_driver_with::<_, _, _, M>(jobs, tol, (ev, simd), |j| StepsAndEvents {
            stop_at: Some(40 + 7 * j),
            ..StepsAndEvents::default()
        });
    assert!(
        stopped > n / 2,
        "{stopped} of {n} runs stopped by their observer"
    );
}

/// [`same_as_driver`] with one observer kind; returns the number of events recorded and
/// of runs that their observer stopped.
fn same_as_driver_with<D, E, O, const M: usize>(
    jobs: &[MemberRun<D, M>],
    tol: Tolerances<f64, M>,
    (ev, simd): (E, Simd),
    observer: impl Fn(usize) -> O,
) -> (usize, usize)
where
    D: nonsmooth::LaneDynamics<M>,
    E: nonsmooth::event::EventSet<f64, M> + Clone,
    O: Observer<f64, M> + PartialEq + core::fmt::Debug + EventCount,
{
    use nonsmooth::drive::Termination;
    let ens = Ensemble::new(tol)
        .unwrap()
        .with_events(ev.clone())
        .unwrap()
        .with_simd(simd);
    let mut lanes: Vec<O> = (0..jobs.len()).map(&observer).collect();
    let out = ens.run(jobs, &mut lanes).unwrap();
    let (mut events, mut stopped) = (0, 0);
    for (k, ((j, o), rec)) in jobs.iter().zip(&out).zip(&lanes).enumerate() {
        let mut want_rec = observer(k);
        let want = Simulation::new(j.member.clone(), Dopri5::new(tol))
            .with_events(ev.clone())
            .landing_grid(j.grid)
            .unwrap()
            .run(j.t0, j.y0, j.t_end, &mut want_rec);
        match (o, want) {
            (Ok(o), Ok(w)) => {
                assert_eq!((o.t, o.y, o.stats), (w.t, w.y, w.stats));
                assert_eq!(o.termination, w.termination);
            }
            (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
            (a, b) => panic!("lanes {a:?}, driver {b:?}"),
        }
        assert_eq!(rec, &want_rec);
        events += rec.event_count();
        if o.as_ref()
            .is_ok_and(|o| o.termination == Termination::ObserverStopped)
        {
            stopped += 1;
        }
    }
    (events, stopped)
}

/// The number of events an observer recorded.
trait EventCount {
    fn event_count(&self) -> usize;
}

impl<const M: usize> EventCount for EventsOnly<M> {
    fn event_count(&self) -> usize {
        self.0.len()
    }
}

impl<const M: usize> EventCount for StepsAndEvents<M> {
    fn event_count(&self) -> usize {
        self.events.0.len()
    }
}

#[test]
fn quiet_steps_skipped_in_lanes_keep_every_event() {
    use nalgebra::SVector;
    use nonsmooth::systems::{BouncingBallTable, TwoDofImpact};
    use nonsmooth::testing::HarmonicOscillator;
    // The ball on the vibrating table: restitution on a moving surface (a `Gap` on a
    // harmonic motion), events evaluated in the lanes at every step end.
    let base = BouncingBallTable::with_gamma(3.0, 0.8).unwrap();
    let jobs: Vec<_> = (0..12)
        .map(|i| {
            let gamma = 2.5 + 0.125 * i as f64;
            let ball = BouncingBallTable {
                g: base.amplitude * base.omega * base.omega / gamma,
                ..base
            };
            let v0 = ball.table_motion(0.0).1 + 2.0;
            MemberRun::<_, 2>::periods_of(
                ball.model::<f64>().unwrap(),
                SVector::from([0.0, v0]),
                ball.period(),
                25.0,
            )
            .unwrap()
        })
        .collect();
    let impact = Event::new(base.table::<f64>().unwrap(), Direction::Rising)
        .with_reset(base.impact::<f64>().unwrap());
    // In two lanes (the model's lane step is compiled once per width and instruction set:
    // the widths are checked on the paper's model and on the 2-DOF system below).
    same_as_driver(
        &jobs,
        Tolerances::new(1e-10, 1e-12).unwrap(),
        impact,
        Simd::Baseline,
    );
    // The 2-DOF impact system: its stop on the relative coordinate, with a level crossing
    // of the first mass in both directions (two events, one of them grazing often).
    let p = TwoDofImpact::default();
    let jobs: Vec<_> = (0..10)
        .map(|i| {
            let w = 0.4 + 0.09 * i as f64;
            MemberRun::<_, 4>::periods_of(
                p.model::<f64>(w).unwrap(),
                SVector::zeros(),
                TwoDofImpact::period(w),
                15.0,
            )
            .unwrap()
        })
        .collect();
    let events = (
        Event::new(p.stop::<f64>().unwrap(), Direction::Rising),
        Event::new(Level::new(0, 0.0).unwrap(), Direction::Either),
    );
    same_as_driver(
        &jobs,
        Tolerances::new(1e-8, 1e-10).unwrap(),
        events,
        Simd::Auto,
    );
    // Grazing pairs: x = cos ωt against the level 0.9999, crossed twice within
    // 2·acos(0.9999)/ω ≈ 0.028/ω of every maximum, inside one step at this tolerance (the
    // rates at the step's ends show the pair).
    let jobs: Vec<_> = (0..8)
        .map(|i| {
            let w = 1.0 + 0.3 * i as f64;
            let osc = nonsmooth::LaneByLane(HarmonicOscillator::new(w).unwrap());
            MemberRun::new(osc, 0.0, SVector::from([1.0, 0.0]), 40.0).unwrap()
        })
        .collect();
    let graze = Event::new(Level::new(0, 0.9999).unwrap(), Direction::Either);
    same_as_driver(
        &jobs,
        Tolerances::new(1e-6, 1e-8).unwrap(),
        graze,
        Simd::Baseline,
    );
}

#[test]
fn lane_forms_of_events_and_motions_are_the_scalar_ones_to_the_bit() {
    use nalgebra::SVector;
    use nonsmooth::event::{EventFunction, Gap};
    use nonsmooth::excite::{Constant, Excitation, Harmonic, UnbalancedRotor};
    use nonsmooth::model::Coordinate;
    let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
    let pts: Vec<f64> = lcg(4 * 2000).map(|u| (u - 0.5) * 40.0).collect();
    fn motion<S: Excitation<f64>>(s: &S, ts: &[f64], same: impl Fn(f64, f64) -> bool) {
        for c in ts.chunks(8) {
            let (f, df) = s.motion_lanes(F64x8::load(c)).unwrap();
            for (i, &t) in c.iter().enumerate() {
                assert!(same(f.lane(i), s.force(t)), "f({t})");
                assert!(same(df.lane(i), s.force_rate(t)), "df({t})");
            }
        }
    }
    motion(&Harmonic::new(0.7, 3.3, 0.4).unwrap(), &pts, same);
    motion(&UnbalancedRotor::new(0.018, 20.465).unwrap(), &pts, same);
    motion(&Constant::new(-9.81).unwrap(), &pts, same);
    motion(&(), &pts, same);
    // Level, Stop, and gaps of every coordinate shape on a moving and a fixed surface.
    fn check<G: EventFunction<f64, 4>>(g: &G, pts: &[f64], same: impl Fn(f64, f64) -> bool) {
        for c in pts.chunks(4 * 9).filter(|c| c.len() == 36) {
            let t = F64x4::load(&c[0..4]);
            let y: [F64x4; 4] = core::array::from_fn(|k| F64x4::load(&c[4 + 4 * k..]));
            let dy: [F64x4; 4] = core::array::from_fn(|k| F64x4::load(&c[20 + 4 * k..]));
            let (v, r) = g.lanes(t, &y, &dy).unwrap();
            for i in 0..4 {
                let ys = SVector::<f64, 4>::from_fn(|k, _| y[k].lane(i));
                let dys = SVector::<f64, 4>::from_fn(|k, _| dy[k].lane(i));
                assert!(same(v.lane(i), g.value(t.lane(i), &ys)));
                let want = g.rate(t.lane(i), &ys, &dys);
                assert_eq!(r.is_some(), want.is_some());
                if let (Some(r), Some(w)) = (r, want) {
                    assert!(same(r.lane(i), w));
                }
            }
        }
    }
    check(&Level::new(2, 0.3).unwrap(), &pts, same);
    let stop = Stop {
        position: 1,
        velocity: 3,
        level: -0.2,
    };
    check(&stop, &pts, same);
    let surf = Harmonic::new(0.1, 5.0, 0.2).unwrap();
    let shapes = [
        Coordinate::dof(1).unwrap(),
        Coordinate::dof(0).unwrap().with_offset(0.25).unwrap(),
        Coordinate::relative(1, 0).unwrap(),
        Coordinate::relative(0, 1)
            .unwrap()
            .with_offset(-0.5)
            .unwrap(),
        Coordinate::linear([0.3, -1.7])
            .unwrap()
            .with_offset(0.1)
            .unwrap(),
    ];
    for c in shapes {
        check(&Gap::below(c, surf), &pts, same);
        check(&Gap::above(c, ()), &pts, same);
    }
    // An index outside the state has no lane form (the scalar value is NaN).
    let y = [F64x4::splat(0.0); 4];
    assert!(
        EventFunction::<f64, 4>::lanes(&Level::new(7, 0.0).unwrap(), F64x4::splat(0.0), &y, &y)
            .is_none()
    );
}

/// `ẍ = −ω²x`, with a right-hand side that is NaN for `t > t_bad`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Blowup {
    w: f64,
    t_bad: f64,
}

impl nonsmooth::Dynamics<f64, 2> for Blowup {
    fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        let bad = if t > self.t_bad { f64::NAN } else { 1.0 };
        dy[0] = y[1];
        dy[1] = -self.w * self.w * y[0] * bad;
    }
}

/// The ends the lanes count for themselves fail or end each trajectory as the driver does
/// (same error, or same end, state and statistics), whatever runs in the other lanes: a
/// right-hand side that is NaN after the start (21 non-finite trial steps in a row), one
/// that turns NaN later (the step falls below the minimum), the step cap, the end time,
/// with and without a landing grid, on the widest instruction set of the machine (sixteen
/// lanes, eight after compaction) and on the baseline (four, then two).
#[test]
fn failures_and_caps_counted_in_lanes_match_the_driver() {
    let tol = tol(1e-8);
    let mut jobs = Vec::new();
    for k in 0..12 {
        let w = 1.0 + 0.37 * k as f64;
        let t_bad = [0.0, 3.7, f64::INFINITY][k % 3];
        let m = nonsmooth::LaneByLane(Blowup { w, t_bad });
        let job = MemberRun::new(m, 0.0, Vector2::new(1.0, 0.0), 6.0 + k as f64).unwrap();
        jobs.push(if k % 2 == 0 {
            job.with_grid(0.0, 0.25).unwrap()
        } else {
            job
        });
    }
    for cap in [100_000_000, 150] {
        let ens = Ensemble::new(tol).unwrap().max_steps(cap).unwrap();
        let mut kinds = std::collections::BTreeSet::new();
        for simd in [Simd::Auto, Simd::Baseline] {
            let mut obs = vec![(); jobs.len()];
            let out = ens.clone().with_simd(simd).run(&jobs, &mut obs).unwrap();
            for (k, (j, o)) in jobs.iter().zip(&out).enumerate() {
                let want = Simulation::new(j.member.0, Dopri5::new(tol))
                    .max_steps(cap)
                    .unwrap()
                    .landing_grid(j.grid)
                    .unwrap()
                    .run(j.t0, j.y0, j.t_end, &mut ());
                match (o, want) {
                    (Ok(o), Ok(w)) => {
                        assert_eq!((o.t, o.y, o.stats), (w.t, w.y, w.stats), "job {k}");
                        assert_eq!(o.termination, w.termination, "job {k}");
                        kinds.insert("ends".to_string());
                    }
                    (Err(e), Err(w)) => {
                        assert_eq!(e.to_string(), w.to_string(), "job {k}");
                        let e = e.to_string();
                        let kind = ["not finite", "too small", "maximum number of steps"]
                            .into_iter()
                            .find(|k| e.contains(k))
                            .unwrap_or("other");
                        kinds.insert(kind.to_string());
                    }
                    (o, w) => panic!("job {k}, cap {cap}: lanes {o:?}, driver {w:?}"),
                }
            }
        }
        // Each kind of end occurs: a non-finite right-hand side, a step below the minimum,
        // and the end time (the cap of 150 steps stops every trajectory that lives longer).
        let last = if cap == 150 {
            "maximum number of steps"
        } else {
            "ends"
        };
        let want = ["not finite", "too small", last].map(String::from);
        assert_eq!(kinds, want.into_iter().collect(), "cap {cap}");
    }
}

/// An event function whose time scale is declared only after `t = 2`: 0.01 s.
#[derive(Debug, Clone, Copy)]
struct LateScale;

impl nonsmooth::event::EventFunction<f64, 2> for LateScale {
    fn value(&self, _t: f64, y: &Vector2<f64>) -> f64 {
        y[0] - 0.5
    }
    fn time_scale(&self, t: f64) -> Option<f64> {
        (t > 2.0).then_some(0.01)
    }
}

/// The step bound of a time scale that the events declare only later in the run bounds the
/// lanes' steps as it bounds the driver's (the ensemble used to look at the start only):
/// same end, state and statistics, and the bound shows in the step count.
#[test]
fn a_time_scale_declared_later_bounds_the_lanes_steps() {
    use nonsmooth::testing::HarmonicOscillator;
    let tol = tol(1e-8);
    let ev = Event::new(LateScale, Direction::Either);
    let ens = Ensemble::new(tol).unwrap().with_event(ev).unwrap();
    let jobs: Vec<_> = (0..6)
        .map(|k| {
            let m = nonsmooth::LaneByLane(HarmonicOscillator::new(1.0 + 0.2 * k as f64).unwrap());
            MemberRun::new(m, 0.0, Vector2::new(1.0, 0.0), 6.0).unwrap()
        })
        .collect();
    let mut obs = vec![(); jobs.len()];
    let out = ens.run(&jobs, &mut obs).unwrap();
    for (j, o) in jobs.iter().zip(&out) {
        let o = o.as_ref().unwrap();
        let want = Simulation::new(j.member.0, Dopri5::new(tol))
            .with_events(ev)
            .run(j.t0, j.y0, j.t_end, &mut ())
            .unwrap();
        assert_eq!((o.t, o.y, o.stats), (want.t, want.y, want.stats));
        // 4 s at no more than 0.01 s per step.
        assert!(o.stats.accepted >= 400, "{:?}", o.stats);
    }
}
