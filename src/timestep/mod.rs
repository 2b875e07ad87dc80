//! Many rigid contacts at once: Moreau–Jean time-stepping with complementarity solvers.
//!
//! The event-driven engine ([`drive`](crate::drive)) locates every impact and mode change;
//! this module does not. It integrates impulses over fixed steps, so contacts may close,
//! open and strike simultaneously and impacts may accumulate (a ball chattering to rest,
//! a rocking block, a column of balls) without the scheme stalling.
//!
//! # Model
//! A Lagrangian system ([`Lagrangian`]) with unilateral contacts ([`Contact`]):
//! $$ M(q)\,\mathrm dv = f(t, q, v)\,\mathrm dt + \sum_i \big(\nabla g_i(q)\,\mathrm dP_{n,i} +
//!    t_i(q)\,\mathrm dP_{t,i}\big),\qquad g_i(q, t) \ge 0, $$
//! with Newton's impact law and Coulomb friction at each contact in Moreau's velocity form:
//! $$ 0 \le \dot g_i^+ + e_i \dot g_i^- \;\perp\; P_{n,i} \ge 0 \quad(\text{while } g_i \le 0),
//!    \qquad |P_{t,i}| \le \mu_i P_{n,i},\; P_{t,i} = -\mu_i P_{n,i}\operatorname{sgn}(u_{t,i}). $$
//!
//! # Scheme ([`MoreauJean`])
//! On the grid `t_k = t₀ + k h`, with `θ ∈ [½, 1]` (default ½) and `γ = ½`:
//! 1. free velocity: $v_{\rm free} = v_k + h M^{-1}\big((1-\theta) f(t_k, q_k, v_k) +
//!    \theta f(t_{k+1}, q_k + h v_k, v_k)\big)$ (the forces θ-weighted, explicitly);
//! 2. active set: contact `i` enters the step's problem if its predicted gap
//!    $g_i(q_k, t_k) + \gamma h \dot g_i^-\le \delta$, $\dot g_i^- = \nabla g_i\cdot v_k +
//!    \partial_t g_i$, with a threshold δ of a few ulps of the positions (rounding must not
//!    open a resting contact), or if it is resting (it carried an impulse in the last step
//!    and left it at rest to the solver's tolerance) or the last step's position
//!    projection treated it;
//! 3. one complementarity problem for the impulses $p$ of the active contacts:
//!    $$ u = W p + q_{\rm free},\quad W = H M^{-1} H^{\mathsf T},\quad
//!    q_{{\rm free},n,i} = \nabla g_i\cdot v_{\rm free} + \partial_t g_i(t_{k+1}) +
//!    e_i \dot g_i^- ,$$
//!    so that $u_{n,i} = \dot g_i^+ + e_i\dot g_i^-$; frictionless: LCP(W, q) by [`lcp::Lemke`]
//!    or [`lcp::Pgs`]; frictional: the planar Signorini–Coulomb problem by [`lcp::Nsgs`];
//! 4. update: $v_{k+1} = v_{\rm free} + M^{-1}H^{\mathsf T}p$,
//!    $q_{k+1} = q_k + h\big((1-\theta)v_k + \theta v_{k+1}\big)$.
//!
//! The scheme is of order one; impacts land on the step grid (an impact time is known to
//! `O(h)`), the gaps may become slightly negative (`O(h²)` per step where a gap is
//! nonlinear in `q`; [`MoreauJean::with_projection`] projects the positions back after every
//! step), and accumulation points are passed in finitely many steps: once the impact velocity
//! falls below about `g h`, the contact stays active and its impulse holds the body at rest.
//!
//! # What you get
//! - per step a [`StepRecord`]: state, [`Energy`] (kinetic, potential, the work of the
//!   impulses), every active contact's [`ContactRecord`] (gap, velocities before and after,
//!   impulses) and the solver's [`LcpReport`](lcp::LcpReport) (iterations, residual), to a
//!   [`StepObserver`]; [`ImpactLog`] turns the impulses into impacts, [`StroboscopicSection`]
//!   samples the state at `t₀ + i·T`; [`DriveObserver`] lets any
//!   [`drive::Observer`](crate::drive::Observer) (the [`sample`](crate::sample) samplers)
//!   watch the run, each step with a [`LinearStep`] dense output, each impact an event;
//! - a contact problem that is not solved to its tolerance stops the run with
//!   [`TimeStepError::Contact`] naming the step, its time and the residual reached.
//!
//! # Systems
//! [`PlanarBodies`] (rigid bodies `(x, y, θ)` under gravity) with [`PlanarContact`]s
//! (corner–plane, point–plane, disc–plane, disc–disc); any
//! [`Mechanical`](crate::model::Mechanical) system (its constant mass matrix and forces) with
//! user contacts implementing [`Contact`]; or any [`Lagrangian`] implementation. Contact
//! sets are `Vec<C>`, `[C; K]` and pairs of sets ([`ContactSet`]): statically dispatched.
//!
//! # Examples
//! A ball dropped on the floor comes to rest:
//! ```
//! use nonsmooth::timestep::{MoreauJean, PlanarBodies, PlanarContact, Plane, RigidBody};
//! let ball = PlanarBodies::new(vec![RigidBody::disc(1.0, 0.1)?], 9.81)?;
//! let floor = vec![PlanarContact::disc_plane(0, 0.1, Plane::floor(0.0)?, 0.5, 0.0)?];
//! let mut scheme = MoreauJean::new(ball, floor, 1e-3)?;
//! let (mut q, mut v) = ([0.0_f64, 1.1, 0.0], [0.0_f64; 3]);
//! scheme.run(0.0, &mut q, &mut v, 3.0, &mut ())?;
//! assert!(v[1].abs() < 1e-9 && (q[1] - 0.1).abs() < 1e-4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # References
//! J. J. Moreau, *Eur. J. Mech. A/Solids* 13 (1994) 93–114; M. Jean, *Comput. Methods Appl.
//! Mech. Engrg.* 177 (1999) 235–257; V. Acary, B. Brogliato, *Numerical Methods for
//! Nonsmooth Dynamical Systems* (Springer, 2008), ch. 10; the Siconos platform's
//! `MoreauJeanOSI`.

mod error;
pub mod lcp;
mod observe;
mod planar;
mod scheme;
mod system;

pub use error::TimeStepError;
pub use observe::{
    ContactRecord, DriveObserver, Energy, ImpactLog, LinearStep, RidingLog, SectionSample,
    StepImpact, StepObserver, StepRecord, StroboscopicSection, Summary,
};
pub use planar::{PlanarBodies, PlanarContact, Plane, RigidBody};
pub use scheme::{MoreauJean, Solver};
pub use system::{Contact, ContactSet, Geometry, Jacobian, Lagrangian, LinearContact};
