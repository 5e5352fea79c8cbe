//! camchain: multibody chains whose tip slides on a fixed cam.
//!
//! Every `models/*.ron` file is turned at build time into a module of [`models`] holding a
//! `Model` type that implements [`runtime::Dynamics`]; [`runtime::Simulate`] adds assembly,
//! stepping and simulation to it.
//!
//! ```no_run
//! use camchain::models::paper_concave::Model;
//! let model = Model;
//! let mut state = model.assemble().expect("the paper model assembles");
//! model.step(&mut state, 0.01).expect("one step");
//! ```

pub use camchain_runtime as runtime;

pub mod stress;

/// The generated models, one module per file in `models/`.
pub mod models {
    include!(concat!(env!("OUT_DIR"), "/models.rs"));

    /// A built-in model by name.
    pub fn by_name(name: &str) -> Option<&'static (dyn ::camchain_runtime::Dynamics + Sync)> {
        ALL.iter().find(|(n, _)| *n == name).map(|(_, m)| *m)
    }
}

/// Random models of the property tests (`tests/random_models/`, written by
/// `runtime/tests/random_models.rs`), compiled like the built-in ones so that
/// `tests/random_compiled.rs` checks the emitted Rust itself against the numeric reference.
/// Not part of the user-facing model list: compiled only with the `random-models` feature, which
/// this package's tests turn on.
#[cfg(feature = "random-models")]
#[doc(hidden)]
pub mod random_models {
    include!(concat!(env!("OUT_DIR"), "/random_models.rs"));
}
