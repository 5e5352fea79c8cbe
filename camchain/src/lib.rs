//! camchain: multibody chains in contact with cams, simulated from code generated at build
//! time.
//!
//! A mechanism is described in a model file (RON: bodies, joints, springs, drives, cam
//! contacts; `docs/model-format.md`). At build time `camchain-build` derives its dynamics
//! symbolically (a recursive Newton–Euler formulation) and its cam constraints, and emits a
//! Rust module holding only the operations the model needs; at run time this crate's
//! [`runtime`] assembles the mechanism on its cams and integrates it by generalised
//! coordinate partitioning (`docs/method.md`).
//!
//! # Your own model in your own crate
//!
//! `Cargo.toml`:
//!
//! ```toml
//! [dependencies]
//! camchain = "0.1"
//!
//! [build-dependencies]
//! camchain-build = "0.1"
//! ```
//!
//! `build.rs` (a bad model stops the build with `file:line:column: field: message`):
//!
//! ```no_run
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     camchain_build::compile_models(&["models/follower.ron"])?;
//!     Ok(())
//! }
//! ```
//!
//! `src/main.rs`:
//!
//! ```ignore
//! mod follower {
//!     camchain::include_model!("follower");
//! }
//!
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     let model = follower::Model::default();
//!     let mut state = model.assemble()?; // every contact point on its cam
//!     model.step(&mut state, 1.0)?; // 1 s with the model's default integrator
//!     println!("q = {:?}", state.q);
//!     Ok(())
//! }
//! ```
//!
//! The generated `Model` has the common runs as its own methods (`assemble`, `step`,
//! `sample`, `simulate`, `simulate_metrics`, `default_settings`); the others
//! (`simulate_unilateral`, `simulate_observed`, `simulate_monitored`, …) and `info()` are
//! methods of the traits [`runtime::Simulate`] and [`runtime::Dynamics`], which must be in
//! scope to be called. `use camchain::prelude::*;` brings them, with the settings and the
//! error types a program's `main` needs (see [`prelude`]).
//!
//! The repository's `examples/downstream/` is such a crate, built and run by CI. The same
//! steps, run here on the paper's model, which the crate `camchain-models` compiles with
//! `camchain_build::compile_models` exactly as above:
//!
//! ```
//! use camchain::prelude::*;
//! use camchain_models::paper_concave::Model;
//!
//! let model = Model::default();
//! let mut state = model.assemble()?;
//! model.step(&mut state, 0.5)?;
//! let run = model.simulate(state, &model.default_settings())?;
//! let last = run.samples.last().expect("a 10 s run has samples");
//! // The constraint is solved by Newton at every evaluation (tolerance 1e-12 m).
//! assert!(last.h[0].abs() < 1e-12, "the tip stays on the cam");
//! // On the concave cam the contact stays compressive, 22.2–23.4 N (docs/method.md §7.5).
//! assert!(last.normal_force[0] > 20.0, "the cam pushes the tip");
//! assert_eq!(model.info().coordinates.len(), 4);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Crates
//!
//! - `camchain` (this crate): what a program links: [`runtime`] and [`include_model!`];
//!   with the `reference` feature also `camchain::reference`, the numeric recursive
//!   reference that loads a model file at run time (no rebuild; it brings the model parser).
//! - `camchain-build`: the build script's API (`compile_models`, `Config`).
//! - `camchain-codegen`: the model schema and the symbolic engine, used by `camchain-build`.

pub use camchain_runtime as runtime;

/// What a program that runs generated models needs in scope: `use camchain::prelude::*;`.
///
/// The traits [`Dynamics`](runtime::Dynamics) (what every generated `Model` implements:
/// `info`, the parameters, the equations) and [`Simulate`](runtime::Simulate) (every run:
/// `simulate_unilateral`, `simulate_observed`, `simulate_monitored`, `step_with`, …, for any
/// `Dynamics`), whose methods cannot be called without them in scope; the settings of a run
/// and what it returns; and the errors, whose `Debug` is their one-line message, so that
/// `?` in a `main` returning `Result<(), Box<dyn std::error::Error>>` prints it.
///
/// A function generic over any model, which compiles with the prelude alone:
///
/// ```
/// use camchain::prelude::*;
///
/// /// Runs `model` with one-sided contact and returns when its follower first lifts off (s).
/// fn first_lift_off<M: Dynamics>(
///     model: &M,
///     t_end: f64,
/// ) -> Result<Option<f64>, Box<dyn std::error::Error>> {
///     let state: State = model.assemble(0.0)?;
///     let settings = SimSettings {
///         t_end,
///         dt_out: 0.01,
///         integrator: IntegratorKind::Dopri5,
///         dt: 1e-3,
///         rtol: 1e-8,
///         atol: 1e-10,
///     };
///     let run: Trajectory = model.simulate_unilateral(state.clone(), &settings, 0.5)?;
///     let metrics: RunMetrics =
///         model.simulate_metrics(state, &settings, MetricsOptions::default())?;
///     let _ = (metrics.max_normal_force, model.info().n());
///     Ok(run.events.first().map(|event| event.t))
/// }
///
/// // The error types convert into the `Box<dyn Error>` of such a function.
/// fn _errors(
///     _: SimError,
///     _: Box<SimFailure>,
///     _: Box<MetricsFailure>,
///     _: ParameterError,
///     _: InvalidSetting,
/// ) {
/// }
/// ```
pub mod prelude {
    pub use camchain_runtime::events::{ContactEvent, EventKind};
    pub use camchain_runtime::{
        ContactLaw, Dynamics, IntegratorKind, InvalidSetting, MetricsFailure, MetricsOptions,
        ModelInfo, ParameterError, ParameterInfo, RunMetrics, Sample, SimError, SimFailure,
        SimSettings, Simulate, State, Stats, Trajectory,
    };
}

#[cfg(feature = "reference")]
pub use camchain_reference as reference;

/// The FMI 3.0 Co-Simulation functions over a model (feature `fmu`): a `cdylib` crate whose
/// root holds `camchain::fmu::export!(my_model::boxed);` is an FMU's library, which
/// `camchain fmu --library` packs with its `modelDescription.xml` (docs/fmu.md).
#[cfg(feature = "fmu")]
pub use camchain_fmu as fmu;

/// Includes the module that `camchain_build::compile_models` generated for a model, by its
/// module name (the model's `name:`, or its file stem): the `Model` type, which implements
/// [`runtime::Dynamics`], its `INFO` and its `OP_COUNTS`.
///
/// `Model`'s own methods cover the common runs; the other runs are methods of the traits
/// [`runtime::Simulate`] and [`runtime::Dynamics`], in scope with `use camchain::prelude::*;`
/// (rustc may suggest `camchain::camchain_runtime::Simulate`, which does not resolve: the
/// path is `camchain::runtime::Simulate`, or the prelude).
///
/// The generated items go where the macro is invoked; give them a module of their own:
///
/// ```ignore
/// mod follower {
///     camchain::include_model!("follower");
/// }
/// let model = follower::Model::default();
/// ```
///
/// It reads `$OUT_DIR/camchain/<name>.rs`, where `compile_models` writes by default; with
/// `Config::out_dir`, include the file with `include!` instead.
#[macro_export]
macro_rules! include_model {
    ($name:literal) => {
        include!(concat!(env!("OUT_DIR"), "/camchain/", $name, ".rs"));
    };
}
