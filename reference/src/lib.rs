//! camchain-reference: the numeric recursive Newton–Euler reference.
//!
//! [`NumericModel`] reads a model file at run time and evaluates its dynamics body by body
//! with nalgebra (eqs. 9–13 of the method, `docs/method.md`), the cam constraints (1–8) with
//! profile derivatives from [`jet`] (forward-mode differentiation), and implements
//! [`camchain_runtime::Dynamics`] like a generated model. It shares no algorithm with the
//! symbolic generator of `camchain-codegen`, so it is the independent route the tests compare
//! the generated code against; and it lets a model file be simulated without rebuilding (the
//! command line's `camchain simulate path.ron`).
//!
//! It depends on the model file's reader (`camchain-model`, with its own RON reader and
//! expression parser, and serde), which is why it is a crate of its own and not part of the runtime a simulating program links. A program reaches
//! it as `camchain::reference` with the `camchain` facade's `reference` feature.
//!
//! ```no_run
//! use camchain_reference::NumericModel;
//! use camchain_runtime::{Dynamics, Simulate};
//!
//! let model = NumericModel::load("models/paper_concave.ron".as_ref())?;
//! let state = model.assemble(0.0)?;
//! let run = model.simulate(state, &model.info().defaults)?;
//! println!("{} samples", run.samples.len());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod contact;
pub mod grid;
pub mod jet;
mod loops;
mod motion;
mod numeric;
pub mod spline;
pub mod tape;

pub use numeric::{NumericModel, contact_info, model_info};
