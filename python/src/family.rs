//! The dispatch from a system's kind to the crate's concrete model types: each instrument
//! is written once, generic over the model, and instantiated here for every smooth system
//! (the paper's cart, Duffing–Ueda, the 2-DOF impact oscillator, described systems of one
//! to four degrees of freedom).

use nonsmooth::event::{Direction, Event, EventSet, Gap, Stop};
use nonsmooth::integrate::Tolerances;
use nonsmooth::lyapunov::{Dims, Norm, TangentDimension};
use nonsmooth::sample::Surface;
use nonsmooth::study::{DescribedModel, SurfaceEvents};
use nonsmooth::systems::duffing_ueda::DuffingUedaModel;
use nonsmooth::systems::paper::PaperOscillator;
use nonsmooth::systems::two_dof::TwoDofImpactModel;
use nonsmooth::{Dynamics, LaneDynamics};

use crate::errors::{Result, value};
use crate::system::Kind;

/// A smooth system at one parameter point: its model, its impact surfaces as events, the
/// selected surface for impact records, and its forcing period.
pub struct Parts<S, E, G> {
    pub model: S,
    pub events: E,
    pub surface: Option<G>,
    pub period: f64,
}

/// Builds a system's parts from its kind and the selected surface.
type Build<S, E, G> = fn(&Kind, usize) -> Result<Parts<S, E, G>>;

/// A smooth system and how to build it at other parameter values.
pub struct Family<S, E, G> {
    pub base: Kind,
    pub surface: usize,
    build: Build<S, E, G>,
}

impl<S, E, G> Family<S, E, G> {
    /// The parts at the system's own parameters.
    pub fn parts(&self) -> Result<Parts<S, E, G>> {
        (self.build)(&self.base, self.surface)
    }

    /// The parts with parameter `name` at `v`.
    pub fn at(&self, name: &str, v: f64) -> Result<Parts<S, E, G>> {
        (self.build)(&self.base.with_parameter(name, v)?, self.surface)
    }

    /// The tolerances: `rtol` on every component, `atol` per component (default
    /// `rtol ×` the system's absolute scale).
    pub fn tolerances<const M: usize>(
        &self,
        rtol: f64,
        atol: Option<&[f64]>,
    ) -> Result<Tolerances<f64, M>> {
        let a: Vec<f64> = match atol {
            Some(a) => a.to_vec(),
            None => self.base.atol_per_rtol().iter().map(|s| rtol * s).collect(),
        };
        let mut arr = [0.0; M];
        arr.copy_from_slice(&a[..M]);
        Ok(Tolerances::per_component(rtol, arr)?)
    }

    /// The weighted norm of the system's scales.
    pub fn norm<const M: usize>(&self) -> Result<Norm<f64, M>> {
        let s = self.base.scales();
        let mut arr = [0.0; M];
        arr.copy_from_slice(&s[..M]);
        Ok(Norm::weighted(arr)?)
    }
}

/// An instrument, generic over the smooth model (`M` its state size, `M2 = 2M`,
/// `MT = M + M²`).
pub trait Visit {
    type Out;
    fn smooth<const M: usize, const M2: usize, const MT: usize, S, E, G>(
        self,
        family: Family<S, E, G>,
    ) -> Result<Self::Out>
    where
        S: Dynamics<f64, M> + LaneDynamics<M> + Clone + Send + Sync + 'static,
        E: EventSet<f64, M> + Clone + Send + Sync + 'static,
        G: Surface<f64, M> + Clone + Send + Sync + 'static,
        Dims<M>: TangentDimension<M, MT>;
}

fn surface_out_of_range(k: usize, n: usize) -> crate::errors::Fail {
    value(format!(
        "surface {k} does not exist: the system has {n} impact surface(s)"
    ))
}

type PaperParts = Parts<PaperOscillator<f64>, Event<Stop<f64>>, Stop<f64>>;
type TwoDofParts = Parts<TwoDofImpactModel<f64>, Event<Gap<f64, 2>>, Gap<f64, 2>>;

fn paper(k: &Kind, surface: usize) -> Result<PaperParts> {
    let Kind::Paper(p, omega) = k else {
        unreachable!()
    };
    if surface > 0 {
        return Err(surface_out_of_range(surface, 1));
    }
    let stop = Stop {
        position: 0,
        velocity: 1,
        level: p.x_i,
    };
    Ok(Parts {
        model: p.oscillator::<f64>(*omega)?,
        events: Event::new(stop, Direction::Rising),
        surface: Some(stop),
        period: std::f64::consts::TAU / omega,
    })
}

fn duffing(k: &Kind, surface: usize) -> Result<Parts<DuffingUedaModel<f64>, (), Stop<f64>>> {
    let Kind::Duffing(d) = k else { unreachable!() };
    if surface > 0 {
        return Err(surface_out_of_range(surface, 0));
    }
    Ok(Parts {
        model: d.model::<f64>()?,
        events: (),
        surface: None,
        period: d.period(),
    })
}

fn two_dof(k: &Kind, surface: usize) -> Result<TwoDofParts> {
    let Kind::TwoDof(p, omega) = k else {
        unreachable!()
    };
    if surface > 0 {
        return Err(surface_out_of_range(surface, 1));
    }
    let stop = p.stop::<f64>()?;
    Ok(Parts {
        model: p.model::<f64>(*omega)?,
        events: Event::new(stop, Direction::Rising),
        surface: Some(stop),
        period: nonsmooth::systems::TwoDofImpact::period(*omega),
    })
}

type DescribedParts<const N: usize> =
    Parts<DescribedModel<N>, SurfaceEvents<Gap<f64, N>>, Gap<f64, N>>;

fn described<const N: usize>(k: &Kind, surface: usize) -> Result<DescribedParts<N>> {
    let Kind::Described(d) = k else {
        unreachable!()
    };
    let gaps = d.gaps::<N>()?;
    if surface > 0 && surface >= gaps.len() {
        return Err(surface_out_of_range(surface, gaps.len()));
    }
    Ok(Parts {
        model: d.model::<N>()?,
        surface: gaps.get(surface).cloned(),
        events: SurfaceEvents(gaps),
        period: d.period(),
    })
}

/// Runs `v` on the smooth system `kind` (impact records on surface `surface`).
///
/// # Errors
/// `ValueError` for a system that is not smooth (the ball on the table, the relay system:
/// `what` says which instruments take them), and the instrument's errors.
pub fn visit<V: Visit>(kind: &Kind, surface: usize, what: &str, v: V) -> Result<V::Out> {
    let base = kind.clone();
    match kind {
        Kind::Paper(..) => v.smooth::<2, 4, 6, _, _, _>(Family {
            base,
            surface,
            build: paper,
        }),
        Kind::Duffing(_) => v.smooth::<2, 4, 6, _, _, _>(Family {
            base,
            surface,
            build: duffing,
        }),
        Kind::TwoDof(..) => v.smooth::<4, 8, 20, _, _, _>(Family {
            base,
            surface,
            build: two_dof,
        }),
        Kind::Described(d) if !d.is_rigid() => match d.dofs() {
            1 => v.smooth::<2, 4, 6, _, _, _>(Family {
                base,
                surface,
                build: described::<1>,
            }),
            2 => v.smooth::<4, 8, 20, _, _, _>(Family {
                base,
                surface,
                build: described::<2>,
            }),
            3 => v.smooth::<6, 12, 42, _, _, _>(Family {
                base,
                surface,
                build: described::<3>,
            }),
            4 => v.smooth::<8, 16, 72, _, _, _>(Family {
                base,
                surface,
                build: described::<4>,
            }),
            n => Err(value(format!("{n} degrees of freedom; at most 4"))),
        },
        _ => Err(value(format!(
            "{what} is not available for the {} system ({})",
            kind.name(),
            match kind {
                Kind::Relay(_) | Kind::Belt(_) =>
                    "a Filippov system: use simulate, lyapunov, periodic_orbit or continuation",
                Kind::Woodpecker => "time-stepping only: use timestep",
                _ => "rigid impacts: use simulate, lyapunov or timestep",
            }
        ))),
    }
}
