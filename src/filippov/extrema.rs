//! The local extrema of the equivalent control along the sliding flow: the closest approach
//! of a sliding orbit to the boundary of its sliding region, the test function of an
//! adding-sliding bifurcation.

use nalgebra::SVector;

use super::error::Result;
use super::field::{ModeField, rates};
use super::run::FilippovSimulation;
use super::system::{Filippov, Mode, Region};
use crate::Real;
use crate::drive::modes::rate_along_flow;
use crate::drive::{Control, EventRecord, Observer, Simulation};
use crate::event::{Direction, Event, EventFunction};
use crate::integrate::Stepper;
use crate::validate::ParameterError;

/// The second-order rate `L²_F H = d/dt (∇H·F + ∂_t H)` along the field `F = F_σ` of the
/// region `sides` at `(t, x)` on surface `surface` (a central difference along the flow):
/// where `F_σ` is tangent to the surface (`∇H·F + ∂_t H = 0`), the orbit of `F_σ` through
/// `x` lies on the side of `sgn(L²_F H)` (a quadratic tangency; *visible* from region `σ` if
/// that is `σ`'s own side, *invisible* otherwise).
pub fn second_rate<T, const N: usize, const S: usize, Sys>(
    system: &Sys,
    surface: usize,
    sides: &[Region; S],
    t: T,
    x: &SVector<T, N>,
) -> T
where
    T: Real,
    Sys: Filippov<T, N, S>,
{
    let rate = |t: T, y: &SVector<T, N>| {
        let mut f = SVector::zeros();
        system.field(sides, t, y, &mut f);
        system.gradient(surface, t, y).dot(&f) + system.surface_time_rate(surface, t, y)
    };
    let mut f = SVector::zeros();
    system.field(sides, t, x, &mut f);
    rate_along_flow(rate, t, x, &f, system.time_scale(t))
}

/// A local extremum of the equivalent control `α` along the sliding flow
/// ([`FilippovSimulation::control_extrema`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlExtremum<T> {
    /// Its time.
    pub t: T,
    /// `α` there.
    pub alpha: T,
    /// The distance to the bound it turns back from: `α` at a minimum (the bound 0, exit
    /// into `H < 0`), `1 − α` at a maximum (the bound 1, exit into `H > 0`); negative where
    /// the sliding flow, continued past an exit, lies beyond the bound.
    pub margin: T,
    /// Whether it is a minimum of `α`.
    pub minimum: bool,
}

/// The event function `dα/dt` along the sliding flow (a central difference along the
/// flow); rising through zero at a minimum of `α`, falling at a maximum.
struct ControlRate<'a, Sys, const S: usize> {
    field: ModeField<'a, Sys, S>,
    surface: usize,
}

impl<T: Real, const N: usize, const S: usize, Sys: Filippov<T, N, S>> EventFunction<T, N>
    for ControlRate<'_, Sys, S>
{
    fn value(&self, t: T, y: &SVector<T, N>) -> T {
        let sides = &self.field.mode.sides;
        let alpha =
            |t: T, y: &SVector<T, N>| rates(self.field.sys, self.surface, sides, t, y).alpha();
        let mut f = SVector::zeros();
        self.field.eval(t, y, &mut f);
        rate_along_flow(alpha, t, y, &f, self.field.sys.time_scale(t))
    }
}

/// Collects the located extrema.
struct Collect<'a, Sys, T, const S: usize> {
    sys: &'a Sys,
    surface: usize,
    sides: [Region; S],
    found: Vec<ControlExtremum<T>>,
}

impl<T: Real, const N: usize, const S: usize, Sys: Filippov<T, N, S>> Observer<T, N>
    for Collect<'_, Sys, T, S>
{
    fn on_event(&mut self, e: &EventRecord<T, N>) -> Control {
        let alpha = rates(self.sys, self.surface, &self.sides, e.t, &e.y).alpha();
        let minimum = e.direction == Direction::Rising;
        self.found.push(ControlExtremum {
            t: e.t,
            alpha,
            margin: if minimum { alpha } else { T::one() - alpha },
            minimum,
        });
        Control::Continue
    }
}

impl<T: Real, Sys, St> FilippovSimulation<T, Sys, St> {
    /// The local extrema of Utkin's equivalent control
    /// `α = h₋/(h₋ − h₊)` (`h± = ∇H·F± + ∂_t H`) along the sliding flow on surface
    /// `surface` (the other surfaces on `sides`) from `(t0, x0)` to `t1`, in time order:
    /// the zeros of `dα/dt` (a central difference along the flow), located by the driver's
    /// event search on the dense output of a copy of the simulation's stepper.
    ///
    /// The flow is integrated **without** the exit event: past a point where `α` leaves
    /// `[0, 1]` it is the sliding flow continued beyond the sliding region (defined while
    /// `h₋ > h₊`). An extremum's [`margin`](ControlExtremum::margin) is then the signed
    /// distance of the orbit's turning point to the boundary of the sliding region: the
    /// test function of an adding-sliding bifurcation (see
    /// [`orbit::sliding`](crate::orbit::sliding)). For a curved surface the state is not
    /// projected back onto it (the drift is the integration error).
    ///
    /// # Errors
    /// The run's errors ([`FilippovError::Run`](super::FilippovError::Run)): invalid
    /// span or state, failed steps.
    pub fn control_extrema<const N: usize, const S: usize>(
        &self,
        surface: usize,
        sides: [Region; S],
        t0: T,
        x0: SVector<T, N>,
        t1: T,
    ) -> Result<Vec<ControlExtremum<T>>>
    where
        Sys: Filippov<T, N, S>,
        St: Stepper<T, N> + Clone,
    {
        if surface >= S {
            return Err(ParameterError::new(
                "surface",
                surface as f64,
                "< S (the number of surfaces)",
            )
            .into());
        }
        let field = ModeField {
            sys: self.system(),
            mode: Mode::sliding_on(surface, sides),
            exit_samples: 0,
        };
        let mut sim = Simulation::new(field, self.stepper().clone())
            .with_events(
                Event::new(ControlRate { field, surface }, Direction::Either)
                    .with_interior_samples(3),
            )
            .event_tolerance(self.settings().event_tol)?;
        let mut collect = Collect {
            sys: self.system(),
            surface,
            sides,
            found: Vec::new(),
        };
        sim.run(t0, x0, t1, &mut collect)?;
        Ok(collect.found)
    }
}
