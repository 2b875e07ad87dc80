//! # The guide
//!
//! A narrative path through the crate, from one impact oscillator to studies on a cluster.
//! Each chapter is a page of prose with code that compiles and runs as a doctest
//! (`cargo test --doc guide`), and ends with an example of `examples/` to run and the numbers
//! it printed when the chapter was written.
//!
//! | chapter | what you learn | main modules |
//! |---|---|---|
//! | [1. The first impact oscillator](ch01_impact_oscillator) | a system from the catalogue, a run with located impacts, stroboscopic sections | [`drive`](crate::drive), [`event`](crate::event), [`sample`](crate::sample) |
//! | [2. Your own force law](ch02_force_law) | implementing [`ForceLaw`](crate::ForceLaw), checking it with the property checker, using it in a model | [`force`](crate::force), `testing` |
//! | [3. N-DOF systems](ch03_n_dof) | [`Mechanical`](crate::model::Mechanical) systems from elements, relative coordinates, surfaces | [`model`](crate::model), [`systems`](crate::systems) |
//! | [4. Rigid impacts, sticking and stick–slip](ch04_rigid_impacts) | restitution, chattering to sticking, set-valued Coulomb friction | [`drive`](crate::drive), [`event`](crate::event) |
//! | [5. Filippov sliding](ch05_filippov) | discontinuous fields, sliding by Utkin's equivalent control | [`filippov`](crate::filippov) |
//! | [6. Time-stepping many contacts](ch06_time_stepping) | Moreau–Jean with Lemke, PGS and NSGS | [`timestep`](crate::timestep) |
//! | [7. Periodic orbits and continuation](ch07_orbits) | shooting, Floquet multipliers, branches with folds and grazings | [`orbit`](crate::orbit) |
//! | [8. Chaos measures](ch08_chaos) | Lyapunov exponents two ways, the Tsallis entropy index | [`lyapunov`](crate::lyapunov), [`entropy`](crate::entropy) |
//! | [9. Ensembles](ch09_ensembles) | many trajectories in SIMD lanes, bit-identical to the scalar path | [`ensemble`](crate::ensemble), [`sweep`](crate::sweep) |
//! | [10. Studies on a laptop and on Slurm](ch10_studies) | regime maps and basins from a TOML file, shards and a verified merge | `study` (feature `cli`) |
//! | [11. The paper, reproduced](ch11_paper) | the paper's model as a client of the library | [`systems::paper`](crate::systems::paper) |
//! | [12. Performance and how to measure it](ch12_performance) | what a run costs, how to time it fairly | [`integrate`](crate::integrate) |
//! | [13. Choosing an integrator](ch13_integrators) | which stepper or engine for which problem | [`integrate`](crate::integrate), [`timestep`](crate::timestep) |
//!
//! The chapters build on each other loosely; each one stands alone. The API reference of
//! every type is one click away from the code. Measured figures (throughput, ratios to
//! other solvers, build times) are kept in `docs/performance.md` of the repository, with the
//! commands that produce them.
//!
//! Read the guide locally with `cargo doc --open` (then `nonsmooth` → `guide`), or on
//! docs.rs: <https://docs.rs/nonsmooth/latest/nonsmooth/guide/>.

#[doc = include_str!("ch01_impact_oscillator.md")]
pub mod ch01_impact_oscillator {}

#[doc = include_str!("ch02_force_law.md")]
pub mod ch02_force_law {}

#[doc = include_str!("ch03_n_dof.md")]
pub mod ch03_n_dof {}

#[doc = include_str!("ch04_rigid_impacts.md")]
pub mod ch04_rigid_impacts {}

#[doc = include_str!("ch05_filippov.md")]
pub mod ch05_filippov {}

#[doc = include_str!("ch06_time_stepping.md")]
pub mod ch06_time_stepping {}

#[doc = include_str!("ch07_orbits.md")]
pub mod ch07_orbits {}

#[doc = include_str!("ch08_chaos.md")]
pub mod ch08_chaos {}

#[doc = include_str!("ch09_ensembles.md")]
pub mod ch09_ensembles {}

#[doc = include_str!("ch10_studies.md")]
pub mod ch10_studies {}

#[doc = include_str!("ch11_paper.md")]
pub mod ch11_paper {}

#[doc = include_str!("ch12_performance.md")]
pub mod ch12_performance {}

#[doc = include_str!("ch13_integrators.md")]
pub mod ch13_integrators {}
