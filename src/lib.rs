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
//! let model = Model::default();
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

/// The files a built-in model's file names (its tables of points), by model name: (the path
/// the model writes, the text), for parsing its [`source`] with
/// `camchain_codegen::schema::Files::Embedded`.
pub fn files(name: &str) -> &'static [(&'static str, &'static str)] {
    FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map_or(&[], |(_, f)| *f)
}

/// Random models of the property tests (`tests/random_models/`, written by
/// `reference/tests/suite/random_models.rs`), compiled like the built-in ones so that
/// `tests/suite/random_compiled.rs` checks the emitted Rust itself against the numeric reference.
/// Not part of the built-in model list: compiled only with the `random-models` feature,
/// which this package's tests turn on.
#[cfg(feature = "random-models")]
#[doc(hidden)]
pub mod random_models {
    include!(concat!(env!("OUT_DIR"), "/random_models/random_models.rs"));
}

/// The contact kinds the built-in models do not use (`tests/contact_models/`: parametric
/// profiles, rollers and flat faces on explicit ones, an applied joint torque), compiled like
/// the built-in ones for `tests/suite/contacts_compiled.rs`. Behind the `random-models` feature.
#[cfg(feature = "random-models")]
#[doc(hidden)]
pub mod contact_models {
    include!(concat!(
        env!("OUT_DIR"),
        "/contact_models/contact_models.rs"
    ));
}

/// The built-in models compiled with every parameter folded (`ParameterMode::FoldAll`) and
/// with every parameter read at run time (`ParameterMode::AllAtRunTime`), and the test models
/// of `tests/parameter_models/`: what `tests/suite/parameters.rs` compares. Compiled only with the
/// `parameter-modes` feature, which this package's tests turn on.
#[cfg(feature = "parameter-modes")]
#[doc(hidden)]
pub mod parameter_modes {
    /// Every parameter folded.
    pub mod folded {
        include!(concat!(env!("OUT_DIR"), "/folded/models.rs"));
    }
    /// Every parameter read at run time.
    pub mod all_at_run_time {
        include!(concat!(env!("OUT_DIR"), "/all_at_run_time/models.rs"));
    }
    /// The test models of parameter checks.
    pub mod checks {
        include!(concat!(env!("OUT_DIR"), "/parameter_models/models.rs"));
    }
}

/// The published reference solution of `andrews_squeezer` at t = 0.03 s: the Test Set for
/// IVP Solvers (W. M. Lioen, J. J. B. de Swart, CWI 1999; F. Mazzia, C. Magherini, University
/// of Bari, release 2.4, 2008), problem `andrews`, file `andrews.f` (revision 1.2, 2006),
/// subroutine `solut` ("computed at Cray C90 … PSIDE, rtol = atol = 1d-14"), as packaged in
/// the R package deTestSet (`src/Ex_andrews.f`, `andsoln`). The tests compare with it and
/// `camchain bench loops` measures the error against it.
pub mod andrews_reference {
    /// The test set's angles in its order (β, Θ, γ, Φ, δ, Ω, ε): the model's coordinate
    /// names.
    pub const ANGLES: [&str; 7] = ["beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"];

    /// `solut`: y(1..7), the angles at t = 0.03 s (rad).
    pub const Q_REF: [f64; 7] = [
        0.1581077119629904e2,
        -0.1575637105984298e2,
        0.4082224013073101e-1,
        -0.5347301163226948e0,
        0.5244099658805304e0,
        0.5347301163226948e0,
        0.1048080741042263e1,
    ];
}
