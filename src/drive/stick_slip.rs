//! Dry friction as a set-valued Coulomb law: slip ↔ stick modes of a [`Mechanical`] system
//! whose coordinate `w·q` rubs on a surface moving with velocity `u(t)` (a belt, a moving
//! table, a fixed wall for `u = 0`).
//!
//! # Law
//! With the slip velocity `v_r = w·q̇ − u(t)` and the friction force `F` acting on the
//! coordinate (generalized force `F·w`):
//! $$ F = -\sigma F_k \ \text{ if } v_r \ne 0,\ \sigma = \operatorname{sgn} v_r,
//!    \qquad |F| \le F_s \ \text{ if } v_r = 0, $$
//! the kinetic force `F_k` and the static limit `F_s ≥ F_k` (e.g. `μ_k N`, `μ_s N` for a
//! constant normal force `N`). No regularization: sticking is exact, not a steep smooth
//! layer around `v_r = 0`.
//!
//! # Modes ([`SlipMode`])
//! - **Slip** (`Forward`: `v_r > 0`, `Backward`: `v_r < 0`): `M q̈ = f(t, q, q̇) − σ F_k w`,
//!   until `v_r` returns to zero (an event on the dense output). There the force that
//!   keeps `v_r = 0`,
//!   $$ \lambda = \frac{\dot u - w\cdot \mathbf M^{-1} f}{w^{\mathsf T}\mathbf M^{-1} w}, $$
//!   decides: `|λ| ≤ F_s` sticks, otherwise the body slips on in direction `−sgn λ`.
//! - **Stick**: `M q̈ = f + λ w` with `λ` as above (plus a Baumgarte term `−α v_r` that damps
//!   the drift of `v_r` from integration error), until `|λ|` reaches `F_s` (event); then
//!   slip starts in direction `−sgn λ` (the friction force saturates at `sgn λ · F_k`).
//! - **No friction** (`F_s = F_k = 0`): no stick and no mode change. The contact carries
//!   no force: a slip segment is the free motion to `t_end`, with no event at `v_r = 0`,
//!   where nothing changes (both slip modes are the free motion); its name is the
//!   direction it started in, which `v_r` may leave later. A start in
//!   [`SlipMode::Stick`] (consistent only with `λ = 0`) slips at once in the direction
//!   `v_r` starts to move (`−sgn λ`, or `−sgn λ̇` where `λ = 0`, forward where both
//!   vanish). Without the event no segment can end at a zero of `v_r` it never leaves
//!   (a restart at `v_r = 0` whose first step leaves `v_r` exactly 0).
//!
//! Transitions are located on the dense output like any event, so a run to `t_end` passes
//! through the same modes at the same times as a longer one.
//!
//! # Example
//! A block on a spring dragged by a belt (`m ẍ + k x = F`, belt speed `u`) sticks until the
//! spring force reaches `F_s`, slips, and sticks again where the slip velocity vanishes:
//! ```
//! use nalgebra::SVector;
//! use nonsmooth::drive::{Coulomb, SlipMode, StickSlip, run_modes};
//! use nonsmooth::excite::Constant;
//! use nonsmooth::force::LinearSpring;
//! use nonsmooth::integrate::{Dopri5, Tolerances};
//! use nonsmooth::model::{Coordinate, Element, Mechanical};
//!
//! let model = Mechanical::with_masses([1.0_f64])?
//!     .with_elements(Element::on_dof(0, LinearSpring::new(1.0)?)?);
//! let friction = Coulomb::new(Coordinate::dof(0)?, Constant::new(0.5)?, 1.0, 0.6)?;
//! let tol = Tolerances::new(1e-10, 1e-12)?;
//! let mut system = StickSlip::new(&model, friction, || Dopri5::new(tol));
//! let y0 = SVector::from([0.0, 0.5]); // moving with the belt
//! let run = run_modes(&mut system, SlipMode::Stick, 0.0, y0, 10.0, 100, &mut ())?;
//! // Stuck until k x = F_s: x = 1 at t = 2.
//! assert_eq!(run.transitions[0].1, SlipMode::Backward);
//! assert!((run.transitions[0].0 - 2.0).abs() < 1e-9);
//! # Ok::<(), nonsmooth::Error>(())
//! ```

use nalgebra::SVector;

use super::constraint::ScalarConstraint;
use super::error::Result;
use super::modes::{ModeError, ModeSystem, Segment, rate_along_flow};
use super::{Observer, Simulation, Termination};
use crate::event::{Direction, Event, EventFunction};
use crate::excite::Excitation;
use crate::integrate::Stepper;
use crate::model::{Coordinate, Elements, Loads, Mechanical, shorter};
use crate::validate::ParameterError;
use crate::validate::{finite, non_negative};
use crate::{Dynamics, Real};

/// A set-valued Coulomb friction contact (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coulomb<T: Real, const N: usize, U> {
    coordinate: Coordinate<T, N>,
    surface_velocity: U,
    static_limit: T,
    kinetic: T,
}

impl<T: Real, const N: usize, U: Excitation<T>> Coulomb<T, N, U> {
    /// Friction on `coordinate` against a surface with velocity `surface_velocity`
    /// (`u(t)` as an [`Excitation`]: `force(t)` is the velocity, `force_rate(t)` its
    /// derivative), static limit `F_s` and kinetic force `F_k`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `0 ≤ F_k ≤ F_s` are finite.
    pub fn new(
        coordinate: Coordinate<T, N>,
        surface_velocity: U,
        static_limit: T,
        kinetic: T,
    ) -> std::result::Result<Self, ParameterError> {
        let kinetic = non_negative("kinetic friction force", kinetic)?;
        let static_limit = finite("static friction limit", static_limit)?;
        if static_limit < kinetic {
            return Err(ParameterError::new(
                "static friction limit",
                crate::scalar::to_f64(static_limit),
                "≥ the kinetic friction force",
            ));
        }
        Ok(Self {
            coordinate,
            surface_velocity,
            static_limit,
            kinetic,
        })
    }

    /// The slip velocity `v_r = w·q̇ − u(t)`.
    pub fn slip_velocity<const M: usize>(&self, t: T, y: &SVector<T, M>) -> T {
        self.coordinate.rate(&y.as_slice()[N..]) - self.surface_velocity.force(t)
    }

    /// The coordinate the friction acts on.
    pub fn coordinate(&self) -> &Coordinate<T, N> {
        &self.coordinate
    }

    /// The surface velocity `u(t)`.
    pub fn surface_velocity(&self) -> &U {
        &self.surface_velocity
    }

    /// The static limit `F_s`.
    pub fn static_limit(&self) -> T {
        self.static_limit
    }

    /// The kinetic force `F_k`.
    pub fn kinetic(&self) -> T {
        self.kinetic
    }
}

/// The modes of [`StickSlip`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlipMode {
    /// Slipping with `v_r > 0` (friction force `−F_k`).
    Forward,
    /// Slipping with `v_r < 0` (friction force `+F_k`).
    Backward,
    /// Stuck: `v_r = 0`, `|F| ≤ F_s`.
    Stick,
}

impl SlipMode {
    /// The mode's name (`"forward"`, `"backward"`, `"stick"`), as observers see it in
    /// [`Observer::on_mode`].
    pub fn name(self) -> &'static str {
        match self {
            SlipMode::Forward => "forward",
            SlipMode::Backward => "backward",
            SlipMode::Stick => "stick",
        }
    }
}

/// The largest `|v_r|` a start in [`SlipMode::Stick`] may have, relative to
/// `max(1, |u|, |w·q̇|)` (the stick mode damps what is left).
pub const STICK_RATE_TOLERANCE: f64 = 1e-8;

/// The right-hand side of one mode: slip with a friction force `force`, or stick.
#[derive(Debug)]
struct ModeRhs<'a, T: Real, const N: usize, const M: usize, El, Ld, U> {
    model: &'a Mechanical<T, N, El, Ld>,
    friction: &'a Coulomb<T, N, U>,
    constraint: ScalarConstraint<T, N>,
    /// `Some(F)`: slipping with friction force `F`; `None`: stuck.
    slip_force: Option<T>,
    alpha: T,
}

impl<T: Real, const N: usize, const M: usize, El, Ld, U> Clone for ModeRhs<'_, T, N, M, El, Ld, U> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Real, const N: usize, const M: usize, El, Ld, U> Copy for ModeRhs<'_, T, N, M, El, Ld, U> {}

impl<T, const N: usize, const M: usize, El, Ld, U> ModeRhs<'_, T, N, M, El, Ld, U>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    U: Excitation<T>,
{
    /// `M⁻¹f` and the force `λ` that keeps `v_r` at zero (damping its drift at rate `α`).
    fn multiplier(&self, t: T, y: &SVector<T, M>) -> (SVector<T, N>, T) {
        let a = self.model.acceleration(t, y);
        let w = self.friction.coordinate.weights();
        let drift = self.friction.slip_velocity(t, y);
        let target = self.friction.surface_velocity.force_rate(t) - self.alpha * drift;
        (a, self.constraint.multiplier(w, &a, target))
    }
}

impl<T, const N: usize, const M: usize, El, Ld, U> Dynamics<T, M>
    for ModeRhs<'_, T, N, M, El, Ld, U>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    U: Excitation<T>,
{
    /// Stuck, the state moves with the surface while the force needed to hold it changes
    /// with the loads: the loads' and the surface velocity's time scales bound the step.
    fn time_scale(&self, t: T) -> Option<T> {
        match self.slip_force {
            Some(_) => None,
            None => shorter(
                self.model.forcing_time_scale(t),
                self.friction.surface_velocity.time_scale(t),
            ),
        }
    }

    fn rhs(&self, t: T, y: &SVector<T, M>, dy: &mut SVector<T, M>) {
        let (a, force) = match self.slip_force {
            Some(f) => (self.model.acceleration(t, y), f),
            None => self.multiplier(t, y),
        };
        self.constraint.rhs(y, &a, force, dy);
    }
}

/// The end of a slip (`v_r = 0`) or of a stick (`|λ| = F_s`).
#[derive(Debug, Clone, Copy)]
struct ModeEnd<'a, T: Real, const N: usize, const M: usize, El, Ld, U>(
    ModeRhs<'a, T, N, M, El, Ld, U>,
);

impl<T, const N: usize, const M: usize, El, Ld, U> EventFunction<T, M>
    for ModeEnd<'_, T, N, M, El, Ld, U>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    U: Excitation<T>,
{
    fn value(&self, t: T, y: &SVector<T, M>) -> T {
        match self.0.slip_force {
            Some(_) => self.0.friction.slip_velocity(t, y),
            None => self.0.multiplier(t, y).1.abs() - self.0.friction.static_limit,
        }
    }
    /// Slipping, `v̇_r = w·q̈ − u̇(t)` exactly; stuck, along the flow by a central
    /// difference, so that a release and a re-stick between two step ends is found by the
    /// driver's grazing search.
    fn rate(&self, t: T, y: &SVector<T, M>, dy: &SVector<T, M>) -> Option<T> {
        let f = &self.0.friction;
        Some(match self.0.slip_force {
            Some(_) => f.coordinate.rate(&dy.as_slice()[N..]) - f.surface_velocity.force_rate(t),
            None => rate_along_flow(|s, z| self.value(s, z), t, y, dy, self.time_scale(t)),
        })
    }
    /// Both conditions depend on time through the surface velocity; the static limit also
    /// through the loads.
    fn time_scale(&self, t: T) -> Option<T> {
        shorter(
            Dynamics::time_scale(&self.0, t),
            self.0.friction.surface_velocity.time_scale(t),
        )
    }
}

/// A [`Mechanical`] system with a set-valued [`Coulomb`] contact as a
/// [`ModeSystem`] (see the [module docs](self)).
pub struct StickSlip<'a, T: Real, const N: usize, const M: usize, El, Ld, U, F> {
    model: &'a Mechanical<T, N, El, Ld>,
    friction: Coulomb<T, N, U>,
    constraint: ScalarConstraint<T, N>,
    alpha: T,
    stepper: F,
}

impl<'a, T, const N: usize, const M: usize, El, Ld, U, F, St> StickSlip<'a, T, N, M, El, Ld, U, F>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    U: Excitation<T>,
    F: Fn() -> St,
    St: Stepper<T, M>,
{
    /// `model` with the friction contact `friction`; `stepper()` makes the stepper of each
    /// segment. The stick mode damps the drift of `v_r` at rate `α = 1/s`
    /// ([`with_drift_rate`](Self::with_drift_rate)).
    pub fn new(
        model: &'a Mechanical<T, N, El, Ld>,
        friction: Coulomb<T, N, U>,
        stepper: F,
    ) -> Self {
        let constraint = ScalarConstraint::new(model, friction.coordinate.weights());
        Self {
            model,
            friction,
            constraint,
            alpha: T::one(),
            stepper,
        }
    }

    /// Sets the rate `α > 0` (1/s) at which the stick mode damps the drift of `v_r`.
    ///
    /// # Errors
    /// [`ParameterError`] unless `alpha` is finite and `> 0`.
    pub fn with_drift_rate(mut self, alpha: T) -> std::result::Result<Self, ParameterError> {
        self.alpha = crate::validate::positive("drift rate", alpha)?;
        Ok(self)
    }

    fn rhs(&self, slip_force: Option<T>) -> ModeRhs<'_, T, N, M, El, Ld, U> {
        ModeRhs {
            model: self.model,
            friction: &self.friction,
            constraint: self.constraint,
            slip_force,
            alpha: self.alpha,
        }
    }

    /// The mode a state is in: the sign of `v_r`, or, at `v_r = 0`, stick if the force
    /// needed to hold it is within the static limit, else slip in direction `−sgn λ`
    /// (never stick without friction, `F_s = 0`: see the [module docs](self)).
    pub fn mode_at(&self, t: T, y: &SVector<T, M>) -> SlipMode {
        let v = self.friction.slip_velocity(t, y);
        if v > T::zero() {
            SlipMode::Forward
        } else if v < T::zero() {
            SlipMode::Backward
        } else {
            self.mode_on_surface(t, y)
        }
    }

    /// The mode at `v_r = 0`: stick while the force needed to hold it is below the static
    /// limit, or at the limit and not growing past it; else slip in direction `−sgn λ`.
    ///
    /// Without friction (`F_s = 0`, hence `F_k = 0`) there is no stick: the contact carries
    /// no force, and the body moves as it would without it. Holding it would need `λ = 0`
    /// along the way, and the stick mode's end, `|λ| − F_s = |λ|` rising through 0, never
    /// changes sign (`|λ|` only touches 0), so a stick entered there would last for good.
    /// The slip direction is the way `v_r` starts to move on the free flow: with
    /// `v̇_r = −λ·wᵀM⁻¹w` there, `−sgn λ`; where `λ = 0`, `−sgn λ̇` (`λ̇` along the flow,
    /// by a central difference); forward where both vanish. Both slip modes have the same
    /// field then (`F_k = 0`): the direction only names the segment.
    fn mode_on_surface(&self, t: T, y: &SVector<T, M>) -> SlipMode {
        let rhs = self.rhs(None);
        let lambda = rhs.multiplier(t, y).1;
        if self.friction.static_limit == T::zero() {
            let trend = if lambda == T::zero() {
                let mut dy = SVector::zeros();
                rhs.rhs(t, y, &mut dy);
                let scale = ModeEnd(rhs).time_scale(t);
                rate_along_flow(|s, z| rhs.multiplier(s, z).1, t, y, &dy, scale)
            } else {
                lambda
            };
            return if trend > T::zero() {
                SlipMode::Backward
            } else {
                SlipMode::Forward
            };
        }
        let holds = lambda.abs() < self.friction.static_limit
            || (lambda.abs() == self.friction.static_limit && {
                let mut dy = SVector::zeros();
                rhs.rhs(t, y, &mut dy);
                ModeEnd(rhs).rate(t, y, &dy).is_some_and(|r| r <= T::zero())
            });
        if holds {
            SlipMode::Stick
        } else if lambda > T::zero() {
            SlipMode::Backward
        } else {
            SlipMode::Forward
        }
    }

    /// [`ModeError::InconsistentStart`] unless `mode` can start at `(t, y)`: slipping in
    /// the sign of `v_r` (or at `v_r = 0` accelerating that way), stuck with `|v_r|` within
    /// [`STICK_RATE_TOLERANCE`] of the surface speed and `|λ| ≤ F_s`.
    fn check_start(&self, mode: SlipMode, t: T, y: &SVector<T, M>) -> Result<()> {
        let v = self.friction.slip_velocity(t, y);
        let err = |quantity, value: T, requirement: String| -> Result<()> {
            Err(ModeError::inconsistent_start(mode.name(), t, quantity, value, requirement).into())
        };
        match mode {
            SlipMode::Forward | SlipMode::Backward => {
                let sign = if mode == SlipMode::Forward {
                    T::one()
                } else {
                    -T::one()
                };
                if sign * v < T::zero() {
                    return err(
                        "slip velocity",
                        v,
                        format!("of the sign of {}", mode.name()),
                    );
                }
                if v == T::zero() {
                    // On the surface: the slip must move the way it is named.
                    let rhs = self.rhs(Some(-sign * self.friction.kinetic));
                    let mut dy = SVector::zeros();
                    rhs.rhs(t, y, &mut dy);
                    let a = ModeEnd(rhs).rate(t, y, &dy).unwrap_or(T::zero());
                    if sign * a < T::zero() {
                        return err(
                            "slip acceleration at zero slip velocity",
                            a,
                            format!("of the sign of {}", mode.name()),
                        );
                    }
                }
            }
            SlipMode::Stick => {
                let scale = self
                    .friction
                    .surface_velocity
                    .force(t)
                    .abs()
                    .max(self.friction.coordinate.rate(&y.as_slice()[N..]).abs());
                let tol = crate::scalar::lit::<T>(STICK_RATE_TOLERANCE) * scale.max(T::one());
                if v.abs() > tol {
                    return err(
                        "slip velocity",
                        v,
                        format!("within {STICK_RATE_TOLERANCE:e}·max(1, |u|, |w·q̇|) of 0"),
                    );
                }
                let lambda = self.rhs(None).multiplier(t, y).1;
                if lambda.abs() > self.friction.static_limit {
                    return err(
                        "force needed to hold the contact",
                        lambda,
                        format!(
                            "within the static limit ±{}",
                            crate::scalar::to_f64(self.friction.static_limit)
                        ),
                    );
                }
            }
        }
        Ok(())
    }

    /// Sets `v_r = 0` exactly, changing the velocities along `M⁻¹w` only.
    fn project(&self, t: T, y: &mut SVector<T, M>) {
        let v = self.friction.slip_velocity(t, y);
        self.constraint.shift_velocities(y, -v);
    }
}

impl<T, const N: usize, const M: usize, El, Ld, U, F, St> ModeSystem<T, M>
    for StickSlip<'_, T, N, M, El, Ld, U, F>
where
    T: Real,
    El: Elements<T, N>,
    Ld: Loads<T, N>,
    U: Excitation<T>,
    F: Fn() -> St,
    St: Stepper<T, M>,
{
    type Mode = SlipMode;

    fn mode_name(&self, mode: SlipMode) -> &'static str {
        mode.name()
    }

    fn segment<O: Observer<T, M>>(
        &mut self,
        mode: SlipMode,
        t: T,
        y: SVector<T, M>,
        t_end: T,
        observer: &mut O,
    ) -> Result<Segment<T, M, SlipMode>> {
        self.check_start(mode, t, &y)?;
        if mode == SlipMode::Stick && self.mode_on_surface(t, &y) != SlipMode::Stick {
            // At the static limit with the force growing past it: slip at once.
            let mut y = y;
            self.project(t, &mut y);
            let next = self.mode_on_surface(t, &y);
            return Ok(Segment {
                outcome: super::Outcome {
                    t,
                    y,
                    termination: Termination::TerminalEvent(0),
                    stats: Default::default(),
                },
                next: Some(next),
            });
        }
        if self.friction.static_limit == T::zero() {
            // No friction: the free motion to the end, nothing changes where v_r = 0.
            let mut sim = Simulation::new(self.rhs(Some(T::zero())), (self.stepper)());
            let outcome = sim.run(t, y, t_end, observer)?;
            return Ok(Segment {
                outcome,
                next: None,
            });
        }
        let (slip_force, direction) = match mode {
            SlipMode::Forward => (Some(-self.friction.kinetic), Direction::Falling),
            SlipMode::Backward => (Some(self.friction.kinetic), Direction::Rising),
            SlipMode::Stick => (None, Direction::Rising),
        };
        let rhs = self.rhs(slip_force);
        let mut sim = Simulation::new(rhs, (self.stepper)())
            .with_events(Event::new(ModeEnd(rhs), direction).terminal());
        let mut outcome = sim.run(t, y, t_end, observer)?;
        let next = match outcome.termination {
            Termination::TerminalEvent(_) => {
                // The slip velocity is zero at the event (to the location tolerance): make
                // it exact, then choose the next mode from the force balance there.
                self.project(outcome.t, &mut outcome.y);
                Some(match mode {
                    SlipMode::Stick => {
                        let lambda = self.rhs(None).multiplier(outcome.t, &outcome.y).1;
                        if lambda > T::zero() {
                            SlipMode::Backward
                        } else {
                            SlipMode::Forward
                        }
                    }
                    _ => self.mode_on_surface(outcome.t, &outcome.y),
                })
            }
            _ => None,
        };
        Ok(Segment { outcome, next })
    }
}
