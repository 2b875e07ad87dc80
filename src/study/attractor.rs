//! Attractor labels: which points reached the same attractor.
//!
//! See the [module docs](super#attractor-identification) for the criterion.

use std::collections::BTreeMap;

use super::record::PointRecord;
use super::spec::Study;

/// One attractor found in a group of points with the same system parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct AttractorSummary {
    /// The group: the system parameters' grid coordinates `(ix, iy)` (`None` on an
    /// initial-condition axis).
    pub group: (Option<usize>, Option<usize>),
    /// The label within the group (0 = the attractor of the group's lowest point index).
    pub label: usize,
    /// The first point that reached it.
    pub representative: usize,
    /// How many points reached it.
    pub points: usize,
    /// Their fraction of the group (the basin's share of the initial-condition plane).
    pub fraction: f64,
    /// Period (0: not periodic).
    pub period: usize,
    /// Impacts per forcing period of the representative.
    pub impacts_per_period: f64,
    /// Mean top Lyapunov exponent over its points (NaN if not recorded).
    pub tle_mean: f64,
    /// The representative's mean section point (the whole state).
    pub centroid: Vec<f64>,
}

/// The group key of a point: the coordinates of its parameter axes.
fn group(study: &Study, index: usize) -> (Option<usize>, Option<usize>) {
    let (ix, iy) = study.coordinates(index);
    let g = &study.spec().grid;
    (
        (!g.x.is_initial_condition()).then_some(ix),
        g.y.as_ref()
            .and_then(|y| (!y.is_initial_condition()).then_some(iy)),
    )
}

/// Symmetric Hausdorff distance of two point sets in the scaled max norm.
fn hausdorff(a: &[Vec<f64>], b: &[Vec<f64>], s: &[f64]) -> f64 {
    let d = |p: &Vec<f64>, q: &Vec<f64>| {
        p.iter()
            .zip(q)
            .zip(s)
            .map(|((p, q), s)| ((p - q) / s).abs())
            .reduce(f64::max)
            .unwrap_or(0.0)
    };
    let one = |a: &[Vec<f64>], b: &[Vec<f64>]| {
        a.iter()
            .map(|p| b.iter().map(|q| d(p, q)).fold(f64::INFINITY, f64::min))
            .fold(0.0, f64::max)
    };
    one(a, b).max(one(b, a))
}

/// Jaccard overlap `|A ∩ B| / |A ∪ B|` of two sorted cell lists.
fn jaccard(a: &[Vec<i64>], b: &[Vec<i64>]) -> f64 {
    let (mut i, mut j, mut common) = (0, 0, 0usize);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                common += 1;
                i += 1;
                j += 1;
            }
        }
    }
    let union = a.len() + b.len() - common;
    if union == 0 {
        0.0
    } else {
        common as f64 / union as f64
    }
}

/// The orbit's own section points: the last `period` kept points.
fn orbit(r: &PointRecord) -> &[Vec<f64>] {
    let n = r.sections.len();
    &r.sections[n - r.period.min(n)..]
}

/// Whether `r` reached the attractor of `rep`.
fn same(r: &PointRecord, rep: &PointRecord, study: &Study) -> bool {
    let a = &study.spec().attractors;
    let scales = &study.scales();
    if r.period > 0 && r.period == rep.period {
        (r.impacts_per_period - rep.impacts_per_period).abs() < 1e-9
            && hausdorff(orbit(r), orbit(rep), scales) <= a.tol
    } else {
        jaccard(&r.cells, &rep.cells) >= a.overlap
    }
}

/// Labels every point (in the order given — the merge passes index order, which makes the
/// labels deterministic and the same for any sharding) and summarizes the attractors.
/// Failed points get no label. `labels[k]` belongs to `records[k]`.
pub fn identify(
    study: &Study,
    records: &[PointRecord],
) -> (Vec<Option<usize>>, Vec<AttractorSummary>) {
    type Group = (Option<usize>, Option<usize>);
    let mut reps: BTreeMap<Group, Vec<usize>> = BTreeMap::new();
    let mut sizes: BTreeMap<Group, usize> = BTreeMap::new();
    let mut labels = Vec::with_capacity(records.len());
    // (group, label) -> (count, tle sum, tle count)
    let mut stats: BTreeMap<(Group, usize), (usize, f64, usize)> = BTreeMap::new();
    for (pos, r) in records.iter().enumerate() {
        let g = group(study, r.index);
        *sizes.entry(g).or_default() += 1;
        if !r.is_ok() && r.sections.is_empty() {
            labels.push(None);
            continue;
        }
        let list = reps.entry(g).or_default();
        let label = match list.iter().position(|&k| same(r, &records[k], study)) {
            Some(l) => l,
            None => {
                list.push(pos);
                list.len() - 1
            }
        };
        let s = stats.entry((g, label)).or_insert((0, 0.0, 0));
        s.0 += 1;
        if r.tle.is_finite() {
            s.1 += r.tle;
            s.2 += 1;
        }
        labels.push(Some(label));
    }
    let mut summary = Vec::new();
    for (g, list) in &reps {
        for (label, &k) in list.iter().enumerate() {
            let rep = &records[k];
            let (count, tsum, tn) = stats.get(&(*g, label)).copied().unwrap_or((0, 0.0, 0));
            let n = rep.sections.len().max(1) as f64;
            let mut centroid = vec![0.0; study.system().dimension()];
            for p in &rep.sections {
                for (c, x) in centroid.iter_mut().zip(p) {
                    *c += x / n;
                }
            }
            summary.push(AttractorSummary {
                group: *g,
                label,
                representative: rep.index,
                points: count,
                fraction: count as f64 / sizes.get(g).copied().unwrap_or(1).max(1) as f64,
                period: rep.period,
                impacts_per_period: rep.impacts_per_period,
                tle_mean: if tn > 0 { tsum / tn as f64 } else { f64::NAN },
                centroid,
            });
        }
    }
    (labels, summary)
}

/// The regime class of a point for the regime map: `P{p}, {n} imp.` for a period-`p` orbit
/// with `n` impacts per orbit period, `chaotic` for a non-periodic point with a positive
/// top exponent (more than twice its spread), `not periodic` otherwise, `failed`.
pub fn regime_class(r: &PointRecord) -> String {
    if !r.is_ok() && r.sections.is_empty() {
        return "failed".into();
    }
    if r.period > 0 {
        let n = (r.impacts_per_period * r.period as f64).round();
        format!("P{}, {} imp.", r.period, n)
    } else if r.tle.is_finite() && r.tle > 2.0 * r.tle_spread.max(0.0) && r.tle > 0.0 {
        "chaotic".into()
    } else {
        "not periodic".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jaccard_and_hausdorff() {
        let a = [vec![0, 0], vec![1, 2], vec![3, 4]];
        let b = [vec![1, 2], vec![3, 4], vec![5, 5]];
        assert!((jaccard(&a, &b) - 0.5).abs() < 1e-15);
        assert_eq!(jaccard(&a, &[]), 0.0);
        let p = [vec![0.0, 0.0], vec![1.0, 1.0]];
        let q = [vec![1.0, 1.0], vec![0.0, 0.1]];
        assert!((hausdorff(&p, &q, &[1.0, 1.0]) - 0.1).abs() < 1e-15);
        assert!((hausdorff(&p, &q, &[1.0, 0.5]) - 0.2).abs() < 1e-15);
        // Four components: the largest scaled difference.
        let p = [vec![0.0, 0.0, 0.0, 0.0]];
        let q = [vec![0.0, 0.1, 0.0, 0.3]];
        assert!((hausdorff(&p, &q, &[1.0, 1.0, 1.0, 0.5]) - 0.6).abs() < 1e-15);
    }
}
