//! camchain-models: the built-in models, one module per `*.ron` file of this crate's
//! directory, compiled by its build script through `camchain_build::compile_models` exactly
//! as a user's own models are.
//!
//! - `paper_concave`, `paper_convex`, `paper_convex_text`: the paper's four-body chain
//!   swinging freely over its concave and convex cams (`docs/method.md` §7);
//! - `driven_concave`, `driven_convex`: the same chain in a horizontal plane with its first
//!   joint driven;
//! - `double_pendulum`: no cam (the plain tree dynamics);
//! - `spatial_arm`: a spatial chain with its cam in a tilted plane.
//!
//! ```
//! use camchain_models::paper_concave::Model;
//! let model = Model;
//! let mut state = model.assemble().expect("the paper model assembles");
//! model.step(&mut state, 0.01).expect("one step");
//! ```

include!(concat!(env!("OUT_DIR"), "/camchain/models.rs"));

/// A built-in model by name.
pub fn by_name(name: &str) -> Option<&'static (dyn camchain::runtime::Dynamics + Sync)> {
    ALL.iter().find(|(n, _)| *n == name).map(|(_, m)| *m)
}

/// The text of a built-in model's file, by name (what the command line draws the mechanism
/// from and runs `--numeric` on).
pub fn source(name: &str) -> Option<&'static str> {
    SOURCES.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// Random models of the property tests (`tests/random_models/`, written by
/// `reference/tests/random_models.rs`), compiled like the built-in ones so that
/// `tests/random_compiled.rs` checks the emitted Rust itself against the numeric reference.
/// Not part of the built-in model list: compiled only with the `random-models` feature,
/// which this package's tests turn on.
#[cfg(feature = "random-models")]
#[doc(hidden)]
pub mod random_models {
    include!(concat!(env!("OUT_DIR"), "/random_models/random_models.rs"));
}
