//! A study's points in SIMD lanes: the batch form of [`scalar::run_smooth`] for any
//! system with a lane form ([`LaneDynamics`]), record for record the scalar path's.
//!
//! The points of a batch are grouped by what a lane ensemble shares — the impact surfaces
//! (its events) and the model's structure ([`LaneDynamics::same_structure`]) — and each
//! group runs in one [`Ensemble`] with the scalar run's event set, landing grid, step cap
//! and observers. With [`LaneMath::Exact`](crate::lanes::LaneMath::Exact) every lane is
//! the scalar run to the bit; the exponent, where asked for, is the scalar two-trajectory
//! estimate from the lane's end state ([`scalar::smooth_record`]).

use super::scalar::{self, MAX_SURFACES, Observers, Recording, SurfaceEvents};
use super::system::{PointRun, RunSettings};
use crate::ensemble::{Ensemble, MemberRun};
use crate::event::EventFunction;
use crate::{Dynamics, LaneDynamics};

/// One point of a smooth batch: the model at the point, its impact surfaces, its forcing
/// period and its initial state — or why it has none.
pub(crate) type SmoothStart<S, G> = Result<(S, Vec<G>, f64, Vec<f64>), String>;

/// A point ready to run in lanes.
struct Ready<S, G, const M: usize> {
    slot: usize,
    system: S,
    surfaces: Vec<G>,
    period: f64,
    job: MemberRun<S, M>,
    rec: Recording<M>,
}

/// The points of `points` run in SIMD lanes (the ensemble's width for the instruction set
/// of the machine): for each, what
/// [`scalar::run_smooth`]`::<M, M2, _, _>(s, system, surfaces, period, y0)` returns, to the
/// bit, failure messages included.
pub(crate) fn run_smooth_batch<const M: usize, const M2: usize, S, G>(
    s: &RunSettings,
    points: Vec<SmoothStart<S, G>>,
) -> Vec<Result<PointRun, String>>
where
    S: Dynamics<f64, M> + LaneDynamics<M> + Clone,
    G: EventFunction<f64, M> + Clone + PartialEq,
{
    let mut out: Vec<Option<Result<PointRun, String>>> = vec![None; points.len()];
    // Groups of points that share one ensemble: equal surfaces, the same model structure.
    let mut groups: Vec<Vec<Ready<S, G, M>>> = Vec::new();
    for (slot, p) in points.into_iter().enumerate() {
        match ready::<M, S, G>(s, slot, p) {
            Err(m) => out[slot] = Some(Err(m)),
            Ok(r) => match groups
                .iter_mut()
                .find(|g| g[0].surfaces == r.surfaces && g[0].system.same_structure(&r.system))
            {
                Some(g) => g.push(r),
                None => groups.push(vec![r]),
            },
        }
    }
    for group in groups {
        run_group::<M, M2, S, G>(s, group, &mut out);
    }
    out.into_iter()
        .map(|r| r.unwrap_or_else(|| Err("internal: not computed".into())))
        .collect()
}

/// The scalar run's checks, in its order, and the point's job and observers.
fn ready<const M: usize, S, G>(
    s: &RunSettings,
    slot: usize,
    p: SmoothStart<S, G>,
) -> Result<Ready<S, G, M>, String>
where
    S: Dynamics<f64, M> + Clone,
    G: EventFunction<f64, M> + Clone,
{
    let (system, surfaces, period, y0) = p?;
    if surfaces.len() > MAX_SURFACES {
        return Err(format!(
            "{} impact surfaces; at most {MAX_SURFACES}",
            surfaces.len()
        ));
    }
    let y0 = scalar::state::<M>(&y0)?;
    scalar::tolerances::<M>(s)?;
    let rec = Recording::<M>::new(s, period, surfaces.len())?;
    let periods = f64::from(s.transient) + f64::from(s.record);
    let job =
        MemberRun::periods_of(system.clone(), y0, period, periods).map_err(|e| e.to_string())?;
    Ok(Ready {
        slot,
        system,
        surfaces,
        period,
        job,
        rec,
    })
}

/// Runs one group in one ensemble of the widths `W` and stores each point's record in
/// `out`.
fn run_group<const M: usize, const M2: usize, S, G>(
    s: &RunSettings,
    group: Vec<Ready<S, G, M>>,
    out: &mut [Option<Result<PointRun, String>>],
) where
    S: Dynamics<f64, M> + LaneDynamics<M> + Clone,
    G: EventFunction<f64, M> + Clone,
{
    let built = scalar::tolerances::<M>(s).and_then(|tol| {
        Ensemble::<(), M>::new(tol)
            .and_then(|e| e.with_events(SurfaceEvents(group[0].surfaces.clone())))
            .and_then(|e| e.max_steps(s.max_steps))
            .map_err(|e| e.to_string())
    });
    let (jobs, mut obs): (Vec<MemberRun<S, M>>, Vec<Observers<M>>) = group
        .iter()
        .map(|r| (r.job.clone(), r.rec.obs.clone()))
        .unzip();
    let results = built.and_then(|e| e.run(&jobs, &mut obs).map_err(|e| e.to_string()));
    match results {
        Err(m) => {
            for r in &group {
                out[r.slot] = Some(Err(m.clone()));
            }
        }
        Ok(results) => {
            for ((r, o), res) in group.into_iter().zip(obs).zip(results) {
                let Ready {
                    slot,
                    system,
                    period,
                    mut rec,
                    ..
                } = r;
                rec.obs = o;
                out[slot] = Some(
                    res.map(|outcome| {
                        scalar::smooth_record::<M, M2, S>(s, rec, system, period, outcome.y)
                    })
                    .map_err(|e| e.to_string()),
                );
            }
        }
    }
}
