//! Runtime of camchain: links a model's dynamics (generated at build time by
//! `camchain-build`, or the numeric recursive reference of `camchain-reference`) with the cam
//! constraints, generalised coordinate partitioning (Haug & Yen) and the integrators.
//!
//! This is the crate a program that simulates links; its only dependencies are nalgebra and
//! thiserror. Most programs reach it through the `camchain` facade as `camchain::runtime`.
//!
//! Its feature `engine` (on by default) holds everything that runs a model: assembly,
//! partitioning, the integrators, events, sampling and the simulation loop, and brings
//! nalgebra. Without it the crate is the contract alone (the [`Dynamics`] trait and its
//! types, parameters and their checks, contact geometry, motion laws and splines), which is
//! all that generated code emitted with `EmitOptions::simulation_methods` off calls: what a
//! model compiled from Python links, so that its cold build does not wait for nalgebra.
//!
//! Module map:
//! - [`assembly`]: a consistent initial state, and the report of what assembly changed.
//! - [`dynamics`]: the [`Dynamics`] trait every model implements (eqs. 3–8, 13).
//! - [`parameters`]: run-time parameters: declarations, checks and located errors.
//! - [`partition`]: choice of the dependent coordinates and the reduced dynamics (15–18).
//! - [`integrators`]: fixed-step RK4, adaptive Dormand–Prince 5(4) and 8(5,3) with dense
//!   output.
//! - [`settings`]: the ranges of the settings a run accepts, checked before it starts.
//! - [`simulate`]: assembly, `step`, `simulate`, trajectories with contact forces.
//! - [`stepping`]: the integration engine: the state, one step, the bookkeeping after it.
//! - `phase`: the phases of a run: outputs on a grid, events located inside steps.
//! - `scan`: in-step scans of the watched forces and gaps (no event missed inside a
//!   step).
//! - [`sample`]: every output at one instant.
//! - [`columns`]: those outputs as named columns with units (the CSV's, an FMU's).
//! - [`control`]: what a run reports while it goes ([`control::Monitor`]), cancellation,
//!   and the watchdog that stops a stalled run.
//! - [`motion_law`]: follower motion laws (dwell, cycloidal, harmonic, polynomials,
//!   modified trapezoid and sine) in closed form, and programs of them over a turn.
//! - [`spline`]: C² cubic splines through tables of points (profiles given as points).
//! - [`surface_spline`]: C² bicubic spline surfaces z(x, y) through grids of points (spatial
//!   cams given as points, `table: (form: Surface, …)`).
//! - [`contact`]: contact parameters (Newton on the profile) and the checks that a
//!   follower can follow its profile.
//! - [`metrics`]: runs that keep a summary (extreme forces, lift-off, drift) instead of a
//!   trajectory, for parameter sweeps.
//! - [`unilateral`]: one-sided contact: lift-off, flight, impact with restitution.
//! - [`clearance`]: grooves with backlash, seen by the one-sided run as contacts on the
//!   nearer flank.
//! - [`events`]: contact events (force sign changes, lift-off, impact) and their location.
//! - [`error`]: simulation errors with time and state.

#[cfg(feature = "engine")]
pub mod assembly;
#[cfg(feature = "engine")]
pub mod clearance;
#[cfg(feature = "engine")]
pub mod columns;
pub mod contact;
#[cfg(feature = "engine")]
pub mod control;
pub mod dynamics;
pub mod error;
#[cfg(feature = "engine")]
pub mod events;
#[cfg(feature = "engine")]
pub mod integrators;
pub mod kinds;
#[cfg(feature = "engine")]
pub mod metrics;
pub mod motion_law;
pub mod parameters;
#[cfg(feature = "engine")]
pub mod partition;
#[cfg(feature = "engine")]
pub(crate) mod phase;
#[cfg(feature = "engine")]
pub mod sample;
#[cfg(feature = "engine")]
pub(crate) mod scan;
pub mod settings;
#[cfg(feature = "engine")]
pub mod simulate;
pub mod spline;
#[cfg(feature = "engine")]
pub mod stepping;
pub mod surface_spline;
pub mod trig;
#[cfg(feature = "engine")]
pub mod unilateral;

#[cfg(feature = "engine")]
pub use control::{Cancel, Monitor, Observed, Progress};
pub use dynamics::*;
pub use error::SimError;
#[cfg(feature = "engine")]
pub use metrics::{MetricsFailure, MetricsOptions, RunMetrics};
pub use parameters::{ParameterError, ParameterInfo};
pub use settings::InvalidSetting;
#[cfg(feature = "engine")]
pub use simulate::{Sample, SimFailure, Simulate, State, Stats, Trajectory};
#[cfg(feature = "engine")]
pub use unilateral::ContactLaw;

// Beside the type's definition in `simulate.rs` when that file is next changed; here (the
// crate's root) it adds no edge between the modules.
#[cfg(feature = "engine")]
impl std::fmt::Debug for SimFailure {
    /// The one-line message of `Display` (the samples reached and the error), not the
    /// partial trajectory: what a `main` returning `Result<(), Box<dyn std::error::Error>>`
    /// prints after `Error: `. The fields stay public for a program that needs them.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Display::fmt(self, f)
    }
}
