//! `ensemble`: many starts (initial states, parameter values) of one smooth system in the
//! SIMD lanes of the crate's ensemble integrator, each start's record the one
//! `poincare` gives for it, to the bit (`sweep::sweep_starts`, exact lane math).

use nonsmooth::ensemble::Ensemble;
use nonsmooth::event::EventSet;
use nonsmooth::lyapunov::{Dims, TangentDimension};
use nonsmooth::sample::Surface;
use nonsmooth::sweep::{IndependentSweep, LaneStart, sweep_starts};
use nonsmooth::{Dynamics, LaneDynamics};
use rayon::prelude::*;

use crate::analysis::{Detect, point_rec};
use crate::errors::{Fail, Result};
use crate::family::{Family, Visit, visit};
use crate::interrupt::{Cancel, state};
use crate::record::Rec;
use crate::system::Kind;

/// Starts per task: each task fills its own lanes; a Ctrl-C stops the tasks not started.
const CHUNK: usize = 32;

/// Ensemble settings: start `j` has the initial state `y0s[j]` (or the only one) and the
/// parameter value `values[j]` (if a parameter is swept).
#[derive(Debug, Clone)]
pub struct EnsembleSpec {
    pub parameter: Option<String>,
    pub values: Vec<f64>,
    pub y0s: Vec<Vec<f64>>,
    pub transient: u32,
    pub record: u32,
    pub rtol: f64,
    pub atol: Option<Vec<f64>>,
    pub detect: Detect,
    pub cancel: Cancel,
}

struct Lanes(EnsembleSpec);

impl Visit for Lanes {
    type Out = Rec;
    fn smooth<const M: usize, const M2: usize, const MT: usize, S, E, G>(
        self,
        f: Family<S, E, G>,
    ) -> Result<Rec>
    where
        S: Dynamics<f64, M> + LaneDynamics<M> + Clone + Send + Sync + 'static,
        E: EventSet<f64, M> + Clone + Send + Sync + 'static,
        G: Surface<f64, M> + Clone + Send + Sync + 'static,
        Dims<M>: TangentDimension<M, MT>,
    {
        let s = self.0;
        let tol = f.tolerances::<M>(s.rtol, s.atol.as_deref())?;
        let ensemble = Ensemble::new(tol)?;
        let settings = IndependentSweep::new(s.transient, s.record)?
            .period_detection(s.detect.period_tol, s.detect.max_period)?
            .max_steps(s.detect.max_steps);
        let n = s.values.len().max(s.y0s.len());
        let base = f.parts()?;
        let base_param = f.base.parameter("omega").unwrap_or(0.0);
        let mut starts = Vec::with_capacity(n);
        for j in 0..n {
            let y0 = state::<M>(&s.y0s[j.min(s.y0s.len() - 1)]);
            let start = match &s.parameter {
                Some(name) => {
                    let v = s.values[j];
                    let p = f
                        .at(name, v)
                        .map_err(|e| e.context(&format!("{name} = {v}")))?;
                    LaneStart {
                        param: v,
                        system: p.model,
                        period: p.period,
                        y0,
                    }
                }
                None => LaneStart {
                    param: base_param,
                    system: base.model.clone(),
                    period: base.period,
                    y0,
                },
            };
            starts.push(start);
        }
        let surface = base.surface;
        let chunks: Vec<Result<Vec<Rec>>> = starts
            .par_chunks(CHUNK)
            .map(|chunk| {
                s.cancel.check()?;
                let out = sweep_starts::<S, G, M>(&ensemble, &settings, chunk, surface.clone())?;
                Ok(out
                    .iter()
                    .map(|r| match r {
                        Ok(p) => point_rec(p).s("status", "ok"),
                        Err(e) => Rec::new().s("status", e.to_string()),
                    })
                    .collect())
            })
            .collect();
        s.cancel.check()?;
        let mut records = Vec::with_capacity(n);
        for c in chunks {
            records.extend(c?);
        }
        Ok(Rec::new().list("starts", records))
    }
}

/// Runs the starts of `s` in lanes.
pub fn ensemble(kind: &Kind, surface: usize, s: EnsembleSpec) -> Result<Rec> {
    if s.y0s.is_empty() {
        return Err(Fail::Value("no initial state".into()));
    }
    visit(kind, surface, "ensemble", Lanes(s))
}
