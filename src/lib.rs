//! camchain: multibody chains whose tip slides on a fixed cam.
//!
//! Every `models/*.ron` file is turned at build time into a module of [`models`] holding a
//! `Model` type that implements [`runtime::Dynamics`].

pub use camchain_runtime as runtime;
