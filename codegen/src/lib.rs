//! camchain-codegen: from a RON chain description to specialised Rust.
//!
//! Module map:
//! - [`schema`]: the RON file format, parsing and validation with file/line/field errors.
//! - [`model`]: the validated model.
//! - [`profile`]: one-variable expressions (cam profiles, drives) parsed with `syn`.
//! - [`expr`]: the hash-consed symbolic expression DAG: folding, differentiation,
//!   interpretation and emission as `let` bindings.
//! - [`kinematics`]: forward recursion of rotations, positions, velocities, accelerations;
//!   contact point f1, f2, J1, J2 and convective terms (eqs. 1–8).
//! - [`dynamics`]: backward Newton–Euler recursion giving M, F, Q (eqs. 9–13).
//! - [`emit`]: the generated Rust module.

pub mod error;
pub mod model;
pub mod profile;
pub mod schema;

pub use error::ModelError;
pub use model::Model;
