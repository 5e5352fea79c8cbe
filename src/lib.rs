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

/// The generated models, one module per file in `models/`.
pub mod models {
    include!(concat!(env!("OUT_DIR"), "/models.rs"));

    /// A built-in model by name.
    pub fn by_name(name: &str) -> Option<&'static (dyn ::camchain_runtime::Dynamics + Sync)> {
        ALL.iter().find(|(n, _)| *n == name).map(|(_, m)| *m)
    }
}
