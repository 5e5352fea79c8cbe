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
//! The repository's `examples/downstream/` is such a crate, built and run by CI. The same
//! steps, run here on the paper's model, which the crate `camchain-models` compiles with
//! `camchain_build::compile_models` exactly as above:
//!
//! ```
//! use camchain::runtime::{Dynamics, Simulate};
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

#[cfg(feature = "reference")]
pub use camchain_reference as reference;

/// Includes the module that `camchain_build::compile_models` generated for a model, by its
/// module name (the model's `name:`, or its file stem): the `Model` type, which implements
/// [`runtime::Dynamics`], its `INFO` and its `OP_COUNTS`.
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
