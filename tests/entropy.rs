//! Integration tests of the `entropy` module: entropy definitions, the histogram estimator,
//! the entropy index, and every input error.

use nonsmooth::entropy::{
    EntropyError, EntropyIndex, Histogram, HistogramBin, HistogramEstimate, Probabilities,
    ProbabilitiesEstimator, QRange, RangeEnd, RangeTally, RedundancyPoint, entropy_index,
    redundancy, redundancy_curve, shannon, tsallis, tsallis_max,
};
use proptest::prelude::*;

/// Deterministic chaotic sample: logistic map `x ← r·x·(1 − x)` after 1000 transients,
/// mapped affinely to "intervals" `0.08 + 0.2·x` inside the paper's histogram range.
fn logistic_intervals(r: f64, x0: f64, n: usize) -> Vec<f64> {
    let mut x = x0;
    for _ in 0..1000 {
        x = r * x * (1.0 - x);
    }
    (0..n)
        .map(|_| {
            x = r * x * (1.0 - x);
            0.08 + 0.2 * x
        })
        .collect()
}

/// `argmax` of `f` over the grid `lo + k·h` by brute force (an independent check).
fn dense_argmax(lo: f64, hi: f64, h: f64, f: impl Fn(f64) -> f64) -> (f64, f64) {
    let n = ((hi - lo) / h).round() as usize;
    (0..=n).map(|k| lo + k as f64 * h).map(|q| (q, f(q))).fold(
        (f64::NAN, f64::NEG_INFINITY),
        |b, c| if c.1 > b.1 { c } else { b },
    )
}

/// Σ p·|ln p|^k.
fn log_moment(p: &[f64], k: i32) -> f64 {
    p.iter().map(|&x| x * x.ln().abs().powi(k)).sum()
}

// ---------------------------------------------------------------- entropy definitions

#[test]
fn uniform_distribution_has_zero_redundancy() {
    for n in [2usize, 3, 7, 250, 1000] {
        let p = Probabilities::new(vec![1.0 / n as f64; n]).unwrap();
        for q in [
            0.05,
            0.3,
            0.62,
            1.0 - 1e-12,
            1.0,
            1.0 + 1e-12,
            1.7,
            2.0,
            5.0,
        ] {
            let r = redundancy(&p, q).unwrap();
            assert!(r.abs() < 1e-13, "N = {n}, q = {q}: R = {r:e}");
            // And S_q is the maximum.
            let s = tsallis(&p, q).unwrap();
            let m = tsallis_max::<f64>(n, q).unwrap();
            assert!((s - m).abs() <= 1e-13 * m, "N = {n}, q = {q}");
        }
        let curve = redundancy_curve(&p, 0.05, 5.0, 50).unwrap();
        assert!(curve.iter().all(|c| c.redundancy.abs() < 1e-13));
        // ... and no entropy index exists.
        assert_eq!(
            entropy_index(&p, &QRange::default()),
            Err(EntropyError::Equiprobable { states: n })
        );
    }
    // f32.
    let p = Probabilities::new(vec![0.125_f32; 8]).unwrap();
    for q in [0.05_f32, 0.62, 1.0, 2.0, 5.0] {
        assert!(redundancy(&p, q).unwrap().abs() < 1e-6);
    }
}

#[test]
fn tsallis_tends_to_shannon_from_both_sides() {
    // A histogram-like distribution with rare states (|ln p| up to ~9).
    let counts = [5000u64, 2500, 1200, 600, 300, 150, 75, 40, 20, 10, 5, 2, 1];
    let p = Probabilities::<f64>::from_counts(&counts).unwrap();
    let h = shannon(&p);
    let m2 = log_moment(p.as_slice(), 2);
    let m3 = log_moment(p.as_slice(), 3);
    let ln_n = (counts.len() as f64).ln();
    assert_eq!(tsallis(&p, 1.0).unwrap(), h);
    assert_eq!(tsallis_max::<f64>(counts.len(), 1.0).unwrap(), ln_n);
    for delta in [1e-14, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4] {
        for d in [delta, -delta] {
            // S_{1+δ} = H − (δ/2)·Σp ln²p − (δ²/6)·Σp ln³p − … ; the neglected terms are
            // bounded by (δ²/6)·Σp|ln p|³·(1 + small).
            let s = tsallis(&p, 1.0 + d).unwrap();
            let series = h - 0.5 * d * m2;
            let bound = 1.1 * d * d * m3 / 6.0 + 8.0 * f64::EPSILON * h;
            assert!(
                (s - series).abs() <= bound,
                "δ = {d:e}: S = {s}, series = {series}, diff {:e} > {bound:e}",
                (s - series).abs()
            );
            // Agreement with Shannon to 1e-10 once the first-order term δ·Σp ln²p/2 is below
            // that (here Σp ln²p ≈ 2.8, so for |δ| ≤ 1e-12).
            if delta <= 1e-12 {
                assert!((s - h).abs() < 1e-10);
            }
            // S_max → ln N: (1 − N^{−δ})/δ = ln N − δ ln²N/2 + …
            let smax = tsallis_max::<f64>(counts.len(), 1.0 + d).unwrap();
            let bound = 1.1 * d * d * ln_n.powi(3) / 6.0 + 8.0 * f64::EPSILON * ln_n;
            assert!((smax - (ln_n - 0.5 * d * ln_n * ln_n)).abs() <= bound);
            // R is continuous through q = 1.
            let r1 = 1.0 - h / ln_n;
            let r = redundancy(&p, 1.0 + d).unwrap();
            assert!((r - r1).abs() <= 10.0 * delta + 1e-14, "δ = {d:e}");
        }
    }
    // f32: continuous through 1 at the f32 resolution.
    let p32 = Probabilities::<f32>::from_counts(&counts).unwrap();
    let h32 = shannon(&p32);
    assert!((h32 as f64 - h).abs() < 1e-6);
    for d in [1e-7_f32, -6e-8] {
        assert!((tsallis(&p32, 1.0 + d).unwrap() - h32).abs() < 1e-5);
    }
}

#[test]
fn tsallis_special_values() {
    let v = [0.4, 0.3, 0.2, 0.1];
    let p = Probabilities::new(v.to_vec()).unwrap();
    // q = 2: 1 − Σp²; q = 0: N − 1; q = 3: (1 − Σp³)/2.
    let s2 = 1.0 - v.iter().map(|x| x * x).sum::<f64>();
    assert!((tsallis(&p, 2.0).unwrap() - s2).abs() < 1e-15);
    assert!((tsallis(&p, 0.0).unwrap() - 3.0).abs() < 1e-14);
    let s3 = (1.0 - v.iter().map(|x| x * x * x).sum::<f64>()) / 2.0;
    assert!((tsallis(&p, 3.0).unwrap() - s3).abs() < 1e-15);
    // Shannon of a uniform distribution is ln N; of a point mass, 0.
    assert!((shannon(&Probabilities::new(vec![0.25; 4]).unwrap()) - 4f64.ln()).abs() < 1e-15);
    assert_eq!(shannon(&Probabilities::new(vec![1.0_f64]).unwrap()), 0.0);
    // R(0) = 0 and R(q) < 0 for q < 0.
    assert!(redundancy(&p, 0.0).unwrap().abs() < 1e-15);
    assert!(redundancy(&p, -0.5).unwrap() < 0.0);
}

/// Two states `(a, 1 − a)`: closed-form `R(q)` and an independent dense-scan argmax.
#[test]
fn two_state_distribution_closed_form() {
    for a in [0.45_f64, 0.3, 0.1, 0.01, 1e-4] {
        let closed =
            |q: f64| 1.0 - (1.0 - a.powf(q) - (1.0 - a).powf(q)) / (1.0 - 2f64.powf(1.0 - q));
        let p = Probabilities::new(vec![a, 1.0 - a]).unwrap();
        for q in [0.05, 0.3, 0.62, 0.9, 1.1, 2.0, 2.45, 5.0] {
            let (r, c) = (redundancy(&p, q).unwrap(), closed(q));
            assert!(
                (r - c).abs() <= 1e-12 * c.max(1e-3),
                "a = {a}, q = {q}: {r} vs {c}"
            );
        }
        // The closed form is 0/0 at q = 1: scan on a grid that avoids it (step 1e-5 from
        // 0.05 + 0.5e-5 never lands on 1 exactly).
        let (q_scan, r_scan) = dense_argmax(0.050_005, 5.0, 1e-5, closed);
        let index = entropy_index(&p, &QRange::default()).unwrap();
        assert!(
            (index.q - q_scan).abs() < 1e-5,
            "a = {a}: q* = {} vs scan {q_scan}",
            index.q
        );
        assert!(index.redundancy >= r_scan - 1e-13);
        assert!((index.redundancy - closed(index.q)).abs() < 1e-12);
        assert_eq!(index.at_bound, None);
        assert_eq!(index.scan_maxima, 1);
        assert_eq!(index.states, 2);
        // Two states: q* lies in [2.42, 2.48] for every a (module docs).
        assert!(index.q > 2.42 && index.q < 2.48, "a = {a}: {}", index.q);
        // f32 agrees to its resolution: with R computed to ~8·ε₃₂·R, a maximum of curvature
        // R'' is located to √(2·8·ε₃₂·R/|R''|) (R is flat at its peak: R'' ≈ −0.01 for
        // a = 0.01, so f32 resolves q* only to ~1e-2 there).
        let h = 1e-3;
        let curvature =
            (closed(index.q + h) - 2.0 * closed(index.q) + closed(index.q - h)) / (h * h);
        let resolution =
            (2.0 * 8.0 * f32::EPSILON as f64 * index.redundancy / curvature.abs()).sqrt();
        let p32 = Probabilities::new(vec![a as f32, 1.0 - a as f32]).unwrap();
        let i32 = entropy_index(&p32, &QRange::default()).unwrap();
        assert!(
            (i32.q as f64 - index.q).abs() < resolution,
            "a = {a}: f32 q* = {}, f64 q* = {}, resolution {resolution:e}",
            i32.q,
            index.q
        );
    }
}

/// Near equiprobability, `p_i = (1 + ε s_i)/N`, the redundancy is
/// `R ≈ (ε²σ²/2)·q(q−1)/(N^{q−1} − 1)`, whose maximizer depends on `N` only.
#[test]
fn near_uniform_limit_of_the_index() {
    for n in [3usize, 10, 100, 250] {
        let limit = |q: f64| q * (q - 1.0) / ((n as f64).powf(q - 1.0) - 1.0);
        let (q_lim, _) = dense_argmax(0.050_005, 5.0, 1e-5, limit);
        let mut errors = Vec::new();
        for eps in [1e-1, 1e-2, 1e-3] {
            let w: Vec<f64> = (0..n)
                .map(|i| 1.0 + eps * ((i as f64) * 2.3).sin())
                .collect();
            let p = Probabilities::from_weights(&w).unwrap();
            let index = entropy_index(&p, &QRange::default()).unwrap();
            errors.push((index.q - q_lim).abs());
        }
        // The correction is O(ε) (largest for small N: 1.1e-2 at N = 3, ε = 0.1): ten times
        // smaller ε, about ten times smaller error, down to the rounding floor (R ~ ε² is
        // then ~1e-7 and known to ~N·ε_mach, which limits q* to a few 1e-5).
        assert!(
            errors[0] < 2e-2,
            "N = {n}: q_lim = {q_lim}, errors {errors:?}"
        );
        assert!(
            errors[1] < 0.2 * errors[0] + 1e-4,
            "N = {n}: errors {errors:?}"
        );
        assert!(
            errors[2] < 0.2 * errors[1] + 1e-4,
            "N = {n}: errors {errors:?}"
        );
    }
}

#[test]
fn index_is_a_global_maximum_for_a_bimodal_sample() {
    // Two separated clusters of intervals plus a sparse tail.
    let mut samples = Vec::new();
    for k in 0..4000 {
        samples.push(0.1 + 0.01 * ((k as f64) * 0.618).fract());
    }
    for k in 0..500 {
        samples.push(0.2 + 0.03 * ((k as f64) * 0.414).fract());
    }
    let h = Histogram::new(0.05, 0.3, 0.001).unwrap();
    let p = h.probabilities(&samples).unwrap();
    let index = entropy_index(&p, &QRange::default()).unwrap();
    let naive = |q: f64| {
        let n = p.len() as f64;
        1.0 - (1.0 - p.iter().map(|x| x.powf(q)).sum::<f64>()) / (1.0 - n.powf(1.0 - q))
    };
    let (q_scan, _) = dense_argmax(0.050_005, 5.0, 1e-5, naive);
    assert!((index.q - q_scan).abs() < 1e-5, "{} vs {q_scan}", index.q);
}

#[test]
fn range_end_is_reported() {
    let p = Probabilities::new(vec![0.9, 0.1]).unwrap(); // q* ≈ 2.45
    let low = entropy_index(&p, &QRange::new(0.1, 1.5).unwrap()).unwrap();
    assert_eq!(low.at_bound, Some(RangeEnd::Upper));
    assert_eq!(low.q, 1.5);
    let high = entropy_index(&p, &QRange::new(3.0, 6.0).unwrap()).unwrap();
    assert_eq!(high.at_bound, Some(RangeEnd::Lower));
    assert_eq!(high.q, 3.0);
    let inside = entropy_index(&p, &QRange::new(2.0, 3.0).unwrap()).unwrap();
    assert_eq!(inside.at_bound, None);
}

#[test]
fn q_range_options() {
    let p = Probabilities::<f64>::from_counts(&[40, 30, 20, 7, 2, 1]).unwrap();
    let coarse = QRange::default().with_scan_points(5).unwrap();
    let fine = QRange::default()
        .with_scan_points(1000)
        .unwrap()
        .with_tolerance(1e-12)
        .unwrap();
    let a = entropy_index(&p, &coarse).unwrap();
    let b = entropy_index(&p, &fine).unwrap();
    assert!((a.q - b.q).abs() < 1e-7, "{} vs {}", a.q, b.q);
    assert!(b.evaluations > 1000 && a.evaluations < 100);
    let d = QRange::<f64>::default();
    assert_eq!((d.lo(), d.hi(), d.scan_points()), (0.05, 5.0, 100));
    assert_eq!(d.tolerance(), f64::EPSILON.sqrt());
}

#[test]
fn redundancy_curve_matches_pointwise_values() {
    let p = Probabilities::from_counts(&[9, 5, 3, 1, 1]).unwrap();
    let c = redundancy_curve(&p, -1.0, 4.0, 101).unwrap();
    assert_eq!(c.len(), 101);
    assert_eq!(c[0].q, -1.0);
    assert_eq!(c[100].q, 4.0);
    for (k, pt) in c.iter().enumerate() {
        assert!((pt.q - (-1.0 + 0.05 * k as f64)).abs() < 1e-14);
        assert_eq!(pt.redundancy, redundancy(&p, pt.q).unwrap());
    }
    let index = entropy_index(&p, &QRange::default()).unwrap();
    assert!(c.iter().all(|pt| pt.redundancy <= index.redundancy));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// 0 ≤ R(q) ≤ 1 for q > 0 (up to rounding, which is ~N·ε near equiprobability).
    #[test]
    fn redundancy_lies_in_unit_interval(
        w in prop::collection::vec(prop_oneof![Just(0.0), 1e-6..1.0f64], 2..80),
        q in 0.05..5.0f64,
    ) {
        prop_assume!(w.iter().filter(|&&x| x > 0.0).count() >= 2);
        let p = Probabilities::from_weights(&w).unwrap();
        let r = redundancy(&p, q).unwrap();
        prop_assert!((-1e-13..=1.0).contains(&r), "R = {r:e}");
        // Monotone structure: S_q ≤ S_q,max.
        prop_assert!(tsallis(&p, q).unwrap() <= tsallis_max::<f64>(p.len(), q).unwrap() * (1.0 + 1e-13));
    }

    /// The maximizer beats every point of an independent dense grid on the range.
    #[test]
    fn index_is_the_maximum_over_the_range(
        w in prop::collection::vec(1e-4..1.0f64, 2..40),
    ) {
        let p = Probabilities::from_weights(&w).unwrap();
        prop_assume!(!p.is_equiprobable());
        let index = entropy_index(&p, &QRange::default()).unwrap();
        prop_assert!(index.q >= 0.05 && index.q <= 5.0);
        let curve = redundancy_curve(&p, 0.05, 5.0, 2000).unwrap();
        for pt in &curve {
            prop_assert!(pt.redundancy <= index.redundancy + 1e-14 * index.redundancy.abs().max(1e-300) + 1e-16,
                "R({}) = {} > R(q* = {}) = {}", pt.q, pt.redundancy, index.q, index.redundancy);
        }
    }

    /// Every sample is counted in the bin whose computed edges contain it.
    #[test]
    fn histogram_bins_contain_their_samples(
        xs in prop::collection::vec(-0.1..0.4f64, 1..300),
    ) {
        let h = Histogram::new(0.05, 0.3, 0.001).unwrap();
        let est = h.estimate(&xs);
        let inside = xs.iter().filter(|&&x| (0.05..=0.3).contains(&x)).count();
        if inside == 0 {
            prop_assert!(
                matches!(est, Err(EntropyError::AllOutsideRange { .. })),
                "expected AllOutsideRange"
            );
            return Ok(());
        }
        let est = est.unwrap();
        prop_assert_eq!(est.tally.in_range, inside);
        prop_assert_eq!(est.tally.total(), xs.len());
        prop_assert_eq!(est.bins.iter().map(|b| b.count as usize).sum::<usize>(), inside);
        for &x in &xs {
            if let Some(i) = h.bin_of(x) {
                prop_assert!(h.edge(i) <= x);
                prop_assert!(x < h.edge(i + 1) || (i + 1 == h.bins() && x <= h.edge(i + 1)));
            }
        }
        prop_assert_eq!(est.occupied() + est.probabilities.dropped_zeros(), h.bins());
    }
}

// ---------------------------------------------------------------- histogram estimator

#[test]
fn histogram_counts_hand_computed() {
    // Bins of 0.25 on [0, 1]: [0, .25) [.25, .5) [.5, .75) [.75, 1].
    let h = Histogram::new(0.0_f64, 1.0, 0.25).unwrap();
    let xs = [
        0.0,
        0.1,
        0.2499,
        0.25,
        0.5,
        0.6,
        0.74,
        0.75,
        1.0,
        -1e-9,
        1.0 + 1e-9,
        7.0,
    ];
    let est = h.estimate(&xs).unwrap();
    let counts: Vec<u64> = est.bins.iter().map(|b| b.count).collect();
    assert_eq!(counts, [3, 1, 3, 2]);
    assert_eq!(
        est.tally,
        RangeTally {
            in_range: 9,
            below: 1,
            above: 2
        }
    );
    let expected = [3.0 / 9.0, 1.0 / 9.0, 3.0 / 9.0, 2.0 / 9.0];
    for (b, e) in est.bins.iter().zip(expected) {
        assert!((b.probability - e).abs() < 1e-16);
        assert!((b.density - e / 0.25).abs() < 1e-15);
    }
    assert_eq!(
        est.bins.iter().map(|b| b.centre).collect::<Vec<_>>(),
        [0.125, 0.375, 0.625, 0.875]
    );
    assert_eq!(est.probabilities.len(), 4);
    assert_eq!(est.probabilities.dropped_zeros(), 0);
}

#[test]
fn histogram_on_the_paper_grid() {
    // (0.05, 0.3) with step 0.001: 250 bins; edges are 0.05 + i·0.001 as computed in f64.
    let h = Histogram::new(0.05, 0.3, 0.001).unwrap();
    assert_eq!(h.bins(), 250);
    let e1 = h.edge(1);
    assert_eq!(e1, 0.05 + 0.001);
    let xs = [
        0.05,    // bin 0 (closed lower end)
        0.0505,  // bin 0
        e1,      // bin 1: an edge opens the upper bin
        0.1234,  // bin 73
        0.12345, // bin 73
        0.2995,  // bin 249
        0.3,     // bin 249 (closed upper end)
        0.0499,  // below
        0.3001,  // above
    ];
    let est = h.estimate(&xs).unwrap();
    let occupied: Vec<(usize, u64)> = est
        .bins
        .iter()
        .enumerate()
        .filter(|(_, b)| b.count > 0)
        .map(|(i, b)| (i, b.count))
        .collect();
    assert_eq!(occupied, [(0, 2), (1, 1), (73, 2), (249, 2)]);
    assert_eq!((est.tally.below, est.tally.above), (1, 1));
    assert_eq!(
        est.probabilities.as_slice(),
        &[2.0 / 7.0, 1.0 / 7.0, 2.0 / 7.0, 2.0 / 7.0]
    );
    assert_eq!(est.probabilities.dropped_zeros(), 246);
    // The normalized histogram sums to 1 and the density integrates to 1.
    let total: f64 = est.bins.iter().map(|b| b.probability).sum();
    let integral: f64 = est
        .bins
        .iter()
        .map(|b| b.density * (b.upper - b.lower))
        .sum();
    assert!((total - 1.0).abs() < 1e-15 && (integral - 1.0).abs() < 1e-12);
    // The estimator trait gives the same probabilities.
    assert_eq!(h.probabilities(&xs).unwrap(), est.probabilities);
    // f32.
    let h32 = Histogram::new(0.05_f32, 0.3, 0.001).unwrap();
    assert_eq!(h32.bins(), 250);
    let est32 = h32
        .estimate(&[0.05_f32, 0.0505, 0.1234, 0.12345, 0.2995, 0.3])
        .unwrap();
    let occ32: Vec<usize> = est32
        .bins
        .iter()
        .enumerate()
        .filter(|(_, b)| b.count > 0)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(occ32, [0, 73, 249]);
}

#[test]
fn histogram_agrees_with_independent_floor_binning_on_a_chaotic_sample() {
    let xs = logistic_intervals(3.9, 0.3, 100_000);
    let h = Histogram::new(0.05, 0.3, 0.001).unwrap();
    let est = h.estimate(&xs).unwrap();
    let mut naive = vec![0u64; 250];
    for &x in &xs {
        naive[((x - 0.05) / 0.001).floor() as usize] += 1;
    }
    let counts: Vec<u64> = est.bins.iter().map(|b| b.count).collect();
    assert_eq!(counts, naive);
    assert_eq!(est.tally.in_range, 100_000);
}

/// The example's pipeline: logistic-map intervals → histogram → q*. The value is checked
/// against an independent dense scan of the naive formula on the same probabilities.
#[test]
fn logistic_pipeline_index() {
    let xs = logistic_intervals(3.9, 0.3, 100_000);
    let est = Histogram::new(0.05, 0.3, 0.001)
        .unwrap()
        .estimate(&xs)
        .unwrap();
    let p = &est.probabilities;
    let index = entropy_index(p, &QRange::default()).unwrap();
    let n = p.len() as f64;
    let naive =
        |q: f64| 1.0 - (1.0 - p.iter().map(|x| x.powf(q)).sum::<f64>()) / (1.0 - n.powf(1.0 - q));
    let (q_scan, r_scan) = dense_argmax(0.050_005, 5.0, 1e-5, naive);
    assert!((index.q - q_scan).abs() < 1e-5, "{} vs {q_scan}", index.q);
    assert!((index.redundancy - r_scan).abs() < 1e-10);
    assert_eq!(index.at_bound, None);
    // Regression pin of the value computed here and confirmed by the dense scan above (not
    // a paper number: the paper's q* = 0.62 is for the oscillator's intervals at
    // ω = 20.465).
    assert_eq!(index.states, 176);
    assert!((index.q - 0.650438).abs() < 1e-5, "q* = {}", index.q);
    assert!(
        (index.redundancy - 0.063096).abs() < 1e-6,
        "R* = {}",
        index.redundancy
    );
}

// ---------------------------------------------------------------- errors

#[test]
fn every_bad_input_is_an_error() {
    let h = Histogram::new(0.0, 1.0, 0.1).unwrap();
    assert_eq!(h.estimate(&[]), Err(EntropyError::EmptySample));
    assert_eq!(h.probabilities(&[]), Err(EntropyError::EmptySample));
    assert!(matches!(
        h.estimate(&[0.5, f64::NAN]),
        Err(EntropyError::NonFiniteSample { index: 1, .. })
    ));
    assert_eq!(
        h.estimate(&[0.5, f64::INFINITY]),
        Err(EntropyError::NonFiniteSample {
            index: 1,
            value: f64::INFINITY
        })
    );
    assert_eq!(
        Histogram::new(1.0, 0.5, 0.1),
        Err(EntropyError::InvalidRange { min: 1.0, max: 0.5 })
    );
    assert!(matches!(
        Histogram::new(0.0, f64::NAN, 0.1),
        Err(EntropyError::InvalidRange { .. })
    ));
    assert_eq!(
        Histogram::new(0.0, 1.0, -0.1),
        Err(EntropyError::InvalidBinWidth { width: -0.1 })
    );
    assert!(matches!(
        Histogram::new(0.0, 1.0, 1e-12),
        Err(EntropyError::UnresolvableBinWidth { .. })
    ));
    assert_eq!(
        h.estimate(&[-1.0, 2.0, 3.0]),
        Err(EntropyError::AllOutsideRange {
            total: 3,
            below: 1,
            above: 2,
            min: 0.0,
            max: 1.0
        })
    );
    assert!(matches!(
        h.counts_into(&[0.5], &mut [0; 3]),
        Err(EntropyError::CountsLength {
            expected: 10,
            got: 3
        })
    ));

    // One occupied bin: N = 1, R undefined.
    let single = h.estimate(&[0.51, 0.52, 0.53]).unwrap().probabilities;
    assert_eq!(single.len(), 1);
    assert_eq!(redundancy(&single, 0.5), Err(EntropyError::SingleState));
    assert_eq!(
        entropy_index(&single, &QRange::default()),
        Err(EntropyError::SingleState)
    );
    assert_eq!(
        redundancy_curve(&single, 0.1, 2.0, 10),
        Err(EntropyError::SingleState)
    );

    let p = Probabilities::new(vec![0.7, 0.3]).unwrap();
    assert!(matches!(
        tsallis(&p, f64::NAN),
        Err(EntropyError::InvalidQ { .. })
    ));
    assert!(matches!(
        redundancy(&p, f64::NEG_INFINITY),
        Err(EntropyError::InvalidQ { .. })
    ));
    assert!(matches!(
        tsallis_max(3, f64::INFINITY),
        Err(EntropyError::InvalidQ { .. })
    ));
    assert_eq!(tsallis_max(0, 0.5), Err(EntropyError::EmptyDistribution));
    for (lo, hi) in [
        (0.0, 1.0),
        (-0.5, 1.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (0.1, f64::NAN),
    ] {
        assert!(
            matches!(QRange::new(lo, hi), Err(EntropyError::InvalidQRange { .. })),
            "[{lo}, {hi}]"
        );
    }
    assert_eq!(
        QRange::<f64>::default().with_scan_points(2),
        Err(EntropyError::TooFewPoints {
            points: 2,
            minimum: 3
        })
    );
    assert!(matches!(
        QRange::<f64>::default().with_tolerance(0.0),
        Err(EntropyError::InvalidTolerance { .. })
    ));
    assert!(matches!(
        QRange::<f64>::default().with_tolerance(f64::NAN),
        Err(EntropyError::InvalidTolerance { .. })
    ));
    assert!(matches!(
        redundancy_curve(&p, 1.0, 1.0, 10),
        Err(EntropyError::InvalidQRange { .. })
    ));
    assert_eq!(
        redundancy_curve(&p, 0.0, 1.0, 1),
        Err(EntropyError::TooFewPoints {
            points: 1,
            minimum: 2
        })
    );
    assert!(matches!(
        Probabilities::new(vec![0.6, 0.6]),
        Err(EntropyError::NotNormalized { .. })
    ));
    assert_eq!(
        Probabilities::new(vec![1.0, 0.0]),
        Err(EntropyError::ZeroProbability { index: 1 })
    );
    assert!(matches!(
        Probabilities::new(vec![1.5, -0.5]),
        Err(EntropyError::InvalidProbability { index: 1, .. })
    ));
    assert_eq!(
        Probabilities::<f64>::from_counts(&[0, 0, 0]),
        Err(EntropyError::EmptyDistribution)
    );
    assert_eq!(
        entropy_index(
            &Probabilities::<f64>::from_counts(&[4, 0, 4]).unwrap(),
            &QRange::default()
        ),
        Err(EntropyError::Equiprobable { states: 2 })
    );
}

#[test]
fn error_messages_are_clear_and_convert_to_crate_error() {
    let msg = EntropyError::SingleState.to_string();
    assert!(msg.contains("N = 1") && msg.contains("undefined"), "{msg}");
    let msg = Histogram::new(0.3, 0.05, 0.001).unwrap_err().to_string();
    assert!(msg.contains("min < max"), "{msg}");
    let msg = Histogram::new(0.0, 1.0, 0.25)
        .unwrap()
        .estimate(&[2.0])
        .unwrap_err()
        .to_string();
    assert!(msg.contains("outside") && msg.contains("1 above"), "{msg}");
    let e: nonsmooth::Error = EntropyError::EmptySample.into();
    assert!(matches!(
        e,
        nonsmooth::Error::Entropy(EntropyError::EmptySample)
    ));
    assert!(e.to_string().contains("empty sample"));
}

#[test]
fn public_types_are_send_sync_clone() {
    fn check<T: Send + Sync + Clone + 'static>() {}
    check::<Probabilities<f64>>();
    check::<Histogram<f32>>();
    check::<HistogramEstimate<f64>>();
    check::<HistogramBin<f64>>();
    check::<RangeTally>();
    check::<QRange<f64>>();
    check::<EntropyIndex<f64>>();
    check::<RedundancyPoint<f64>>();
    check::<EntropyError>();
}
