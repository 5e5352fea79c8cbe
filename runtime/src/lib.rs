//! Runtime of camchain: links a model's dynamics (generated at build time, or the numeric
//! recursive reference loaded from RON at run time) with the cam constraint, generalised
//! coordinate partitioning (Haug & Yen) and the integrators.
//!
//! Module map:
//! - [`dynamics`]: the [`Dynamics`] trait every model implements (eqs. 3–8, 13).
//! - [`partition`]: choice of the dependent coordinates and the reduced dynamics (15–18).
//! - [`integrators`]: fixed-step RK4 and adaptive Dormand–Prince 5(4).
//! - [`simulate`]: assembly, `step`, `simulate`, trajectories with contact forces.
//! - [`unilateral`]: one-sided contact: lift-off, flight, impact with restitution.
//! - [`reference`](mod@reference): the numeric recursive Newton–Euler reference (nalgebra).
//! - [`jet`]: second-order forward-mode evaluation of profile expressions.
//! - [`events`]: contact events (force sign changes, lift-off, impact) and their location.
//! - [`error`]: simulation errors with time and state.

pub mod dynamics;
pub mod error;
pub mod events;
pub mod integrators;
pub mod jet;
pub mod partition;
pub mod reference;
pub mod simulate;
pub mod unilateral;

pub use dynamics::*;
pub use error::SimError;
pub use simulate::{Sample, SimFailure, Simulate, State, Stats, Trajectory};
