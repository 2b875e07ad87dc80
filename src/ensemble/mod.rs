//! Ensembles: many trajectories in the lanes of SIMD vectors, each with its own adaptive
//! step, error control, events and observers.
//!
//! A bifurcation sweep, a TLE diagram or a parameter plane integrates thousands of
//! independent trajectories of the same model. [`Ensemble::run`] puts `L` of them in the
//! lanes of a [`Lanes`] vector and steps them together with DOPRI5: `L = 16` with AVX2 or
//! AVX-512, 4 on the baseline instruction set (see [below](#instruction-sets-and-widths)).
//!
//! # Which models
//! Any model with a lane form ([`LaneDynamics`](crate::LaneDynamics)), of any state size
//! `M`, each trajectory with its own parameters:
//! * [`Oscillator`](crate::model::Oscillator) and the `N`-DOF
//!   [`Mechanical`](crate::model::Mechanical) (state `2N`) built from laws and
//!   excitations with lane forms — every built-in one
//!   ([`LaneLaw`](crate::force::LaneLaw), [`LaneExcitation`](crate::excite::LaneExcitation)),
//!   tuples and arrays of them, any coordinates, mass matrix, `K` and `C`;
//! * the paper's oscillator family as a [`Member`](crate::systems::paper::Member) (the
//!   same lane form);
//! * any other [`Dynamics`](crate::Dynamics), a law of one's own included, through
//!   [`LaneByLane`](crate::LaneByLane): the right-hand side is then evaluated lane by lane
//!   (correct, and slower by the share of the right-hand side in a step), everything else
//!   in lanes.
//!
//! The events are any [`EventSet`](crate::event::EventSet) of the crate
//! ([`Ensemble::with_events`]): level crossings, stops, gaps on fixed or moving surfaces,
//! resets ([`Restitution`](crate::event::Restitution),
//! [`NewtonImpact`](crate::event::NewtonImpact)), restarts and terminal events, handled
//! per lane by the scalar driver's own code.
//!
//! # The lane method
//! Every lane carries its own `t`, state `y`, cached derivative (first same as last),
//! proposed step `h`, step limit (the next landing point or its end) and controller memory
//! (`ln` of the last accepted error, whether the last trial was rejected). One pass of the
//! loop is one *trial* step in every lane: with `h_s = h` cut to the lane's limit
//! (`h_s = t_limit − t` when `h ≥ 0.99·(t_limit − t)`), the six stages
//! $$k_i = f\Bigl(t + c_i h_s,\; y + h_s\sum_{j<i} a_{ij}k_j\Bigr)$$
//! of Dormand and Prince are evaluated in all lanes at once, then the error norm
//! $$\|e\| = \sqrt{\tfrac1M\sum_i \bigl(e_i/(a_i + r_i\max(|y_{0,i}|,|y_{1,i}|))\bigr)^2}$$
//! and the PI controller `h_new = h_s / min(max(‖e‖^{α}‖e_old‖^{−β}/0.9, 1/10), 5)` on
//! acceptance, `h_s / min(‖e‖^{α}/0.9, 5)` on rejection (the scalar
//! [`Dopri5`](crate::integrate::Dopri5)'s constants, `α = 1/5 − 0.75β`, `β = 0.04`).
//! Nothing of the scalar method changes: the tableau, the norm, the controller, Hairer's
//! first-step guess and the landing rule are the scalar ones, operation for operation.
//!
//! # Masking
//! The accept test `‖e‖ ≤ 1` gives a mask `A`. The new state, derivative and step are
//! blended in by `A` (`y ← A ? y₁ : y`); rejected lanes keep their state and take the
//! smaller step on the next pass. A rejected lane therefore costs the others nothing but
//! the slot it occupies for one pass: no lane waits for another. Accepted lanes are then
//! visited one by one (a scalar loop over the set bits of `A`): their dense output is
//! taken out of the lanes and handed to the scalar driver's event handling — the same
//! code as [`Simulation`](crate::drive::Simulation)'s, not a copy: crossings and grazing
//! pairs located by the same search and tolerance `max(10⁻¹², 4ε|t|)`, records, resets,
//! restarts, terminal events, the sticking check and the Zeno guard — and the observer of
//! the lane's trajectory receives the step and its events exactly as from the driver. A
//! reset or restart moves the lane to the event's state (its derivative evaluated again,
//! its step and controller kept, as the scalar stepper does). A lane whose trajectory ends takes the
//! next one of the batch (a work queue), so the vectors stay full until the queue runs
//! dry. Events and observers are scalar work per accepted step and per event, a small
//! part of a step's six vector evaluations.
//!
//! # Same answers
//! With [`LaneMath::Exact`] (the default) every lane evaluates the same arithmetic as the
//! scalar path in the same order — `sin` by the lane form of the crate's `fastmath`
//! kernels, `exp`/`ln` by the platform's functions lane by lane — so a lane reproduces the
//! scalar [`Simulation`](crate::drive::Simulation) with
//! [`Dopri5`](crate::integrate::Dopri5) **to the bit**: the same steps, the same events,
//! the same section points (tested on the paper's model). With [`LaneMath::Vector`] the
//! exponentials are evaluated in the lanes (`math` gives their accuracy in ulps); results
//! then agree with the scalar path within the integration tolerance. Either way a
//! trajectory's result depends only on its own inputs: not on the lane count, on its
//! position in the batch, on the other lanes or on the number of threads
//! ([`Ensemble::run_parallel`]).
//!
//! # Instruction sets and widths
//! The lane types ([`F64x2`], [`F64x4`], [`F64x8`], [`F64x16`]) are arrays whose
//! operations are lane-wise loops; the lane step is compiled in this crate for the build's
//! target, for AVX2+FMA and for AVX-512F, and [`Simd`] picks the widest the CPU has when a
//! run starts ([`Ensemble::with_simd`] caps it), so a default build (x86-64 baseline) runs on
//! AVX2 or AVX-512 registers without `-C target-cpu`. Each instruction set has one width:
//! sixteen lanes with AVX2 (four registers per value) and AVX-512 (two), four on the
//! baseline (two SSE2 registers); once the queue is empty and at most half the lanes are
//! busy, the last trajectories move to half the width (eight, or two). The step is a chain
//! of dependent operations (the polynomials of `sin`, `exp`, `ln`, the stages), so more
//! lanes than one register holds pay: the extra registers are independent work that fills
//! the pipeline while a chain waits (the measured ratios per model and width are in
//! `docs/performance.md`). One width per instruction set keeps what a model compiles to
//! six lane loops (two widths, three instruction sets). The variants execute the same
//! IEEE operations in the same order (no fused multiply-add is introduced): results are
//! bit-identical across instruction sets and widths (tested).
//!
//! # Where ensembles are used
//! The instruments built on the ensemble live with their scalar forms, for any model with a
//! lane form:
//! * [`sweep::sweep_independent`](crate::sweep::sweep_independent) (and
//!   [`sweep_independent_parallel`](crate::sweep::sweep_independent_parallel)): a
//!   bifurcation sweep with independent starts, one parameter value per lane, returning
//!   the records of [`sweep`](crate::sweep::sweep) — to the bit with [`LaneMath::Exact`].
//! * [`sweep::sweep_starts`](crate::sweep::sweep_starts): independent starts, each from
//!   its own initial state, with a result per start — the points of a basin picture or a
//!   parameter plane; the study tool (`study`, feature `cli`) runs the points of every
//!   system with a lane form in an ensemble.
//! * [`lyapunov::tle_independent`](crate::lyapunov::tle_independent) (and
//!   [`tle_independent_parallel`](crate::lyapunov::tle_independent_parallel)): the two-trajectory top
//!   exponent of many parameter values from the same start, both copies of every pair in
//!   lanes, renormalized every interval as
//!   [`TwoTrajectory`](crate::lyapunov::TwoTrajectory) does; each copy has its own step,
//!   so the estimates agree with the scalar pair's within the estimator's scatter, not to
//!   the bit (see its docs).
//! * The entropy index of the inter-impact intervals is computed from the records of a
//!   sweep ([`SweepPoint::intervals`](crate::sweep::SweepPoint::intervals)): an entropy
//!   scan over ω is [`sweep_independent`](crate::sweep::sweep_independent) followed by the
//!   histogram and index of
//!   [`entropy`](crate::entropy) per value.
//!
//! A continuation sweep (and the continuation TLE diagram) starts each value from the end
//! state of the previous one: one branch is a sequential chain, and its values cannot
//! share lanes; those stay on the scalar path.
//!
//! # Examples
//! ```
//! use nalgebra::Vector2;
//! use nonsmooth::drive::Simulation;
//! use nonsmooth::ensemble::{Ensemble, MemberRun};
//! use nonsmooth::integrate::{Dopri5, Tolerances};
//! use nonsmooth::systems::DuffingUeda;
//!
//! let tol = Tolerances::new(1e-8, 1e-10)?;
//! let y0 = Vector2::new(1.0, 0.0);
//! // The Duffing–Ueda oscillator at eight forcing amplitudes, 5 periods each, in lanes.
//! let jobs = (0..8)
//!     .map(|i| {
//!         let p = DuffingUeda { b: 5.0 + i as f64, ..DuffingUeda::default() };
//!         Ok(MemberRun::periods_of(p.model::<f64>()?, y0, p.period(), 5.0)?)
//!     })
//!     .collect::<nonsmooth::Result<Vec<_>>>()?;
//! let mut observers = vec![(); jobs.len()];
//! let out = Ensemble::new(tol)?.run(&jobs, &mut observers)?;
//! // The same as the scalar path, to the bit.
//! let j = &jobs[3];
//! let scalar = Simulation::new(j.member, Dopri5::new(tol))
//!     .landing_grid(j.grid)?
//!     .run(0.0, y0, j.t_end, &mut ())?;
//! assert_eq!(out[3].as_ref().unwrap().y, scalar.y);
//! # Ok::<(), nonsmooth::Error>(())
//! ```

mod engine;
mod kernel;

pub use crate::lanes::{F64x2, F64x4, F64x8, F64x16, LaneMath, Lanes, Simd};
pub use engine::{Ensemble, LaneDense, MemberRun};
