//! Simulation of a model under its constraints: the [`Simulate`] trait every model gets
//! (assembly, `step`, `simulate` and its variants), trajectories and failures.
//!
//! The integration engine is in [`crate::stepping`], the phases of a run (outputs, in-step
//! events) in `phase`, what a run reports while it goes in [`crate::control`], the
//! samples in [`crate::sample`]; this module ties them into runs.

use crate::clearance::Clearance;
use crate::control::{Monitor, OnSample, Unmonitored};
use crate::dynamics::{Dynamics, SimSettings};
use crate::error::SimError;
use crate::events::ContactEvent;
use crate::metrics::{MetricsFailure, MetricsOptions, RunMetrics};
use crate::partition::all_finite;
use crate::phase::{Grid, Phase, Recorder, Watch, output_intervals, output_time};
use crate::sample::{SampleLevel, compute_sample, sample_in_place};
use crate::stepping::{
    Engine, add_counters_since, advance, all_counters, check_belongs, check_finite_state,
    evaluate_rhs, invalid, positive, validate_integration, validate_run,
};
use crate::unilateral::ContactLaw;

pub use crate::assembly::AssemblyReport;
pub use crate::control::Observed;
pub use crate::sample::Sample;
pub use crate::settings::MAX_STEPS_PER_CALL;
pub use crate::stepping::{State, Stats};

/// Samples at the output times and the work done.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trajectory {
    /// Samples in time order: all of them, or only the last when the run's monitor keeps
    /// none ([`Monitor::keep_samples`]).
    pub samples: Vec<Sample>,
    /// How many samples the run computed (at the output times, plus the last accepted state
    /// after a failure), kept or not: `samples.len()` when every sample is kept.
    pub sample_count: usize,
    /// Contact events in time order: sign changes of the normal forces (runs of the
    /// adaptive integrators with full samples), lift-offs and impacts (unilateral runs).
    pub events: Vec<ContactEvent>,
    /// Work counters of the whole run.
    pub stats: Stats,
}

/// A simulation that stopped early: the error and everything computed until then.
#[derive(Clone, PartialEq, thiserror::Error)]
#[error("simulation stopped after {} samples: {error}", partial.sample_count)]
pub struct SimFailure {
    /// Why the simulation stopped.
    pub error: SimError,
    /// Samples at the output times reached, plus one at the last accepted state when it
    /// lies past the last output time (only the last of them when the monitor keeps none);
    /// work counters until the failure.
    pub partial: Trajectory,
}

/// Constrained simulation of any [`Dynamics`] (blanket implementation).
pub trait Simulate: Dynamics {
    /// The model as a trait object: every method below runs the runtime's engine compiled
    /// once, in this crate, for `dyn Dynamics`, rather than once more per model type in the
    /// crate that calls it (22 built-in models made 22 copies of the engine, most of their
    /// crate's compile time).
    #[doc(hidden)]
    fn as_dynamics(&self) -> &dyn Dynamics;

    /// Initial assembly (docs/method.md §5.9) at time `t0` from the model's initial guess: coordinates with
    /// `hold = true` keep their guess, driven ones take their prescribed value at t0; the
    /// dependent coordinates are chosen among the others by largest |J_i| and solved by
    /// Newton (15), with a backtracking Newton as fallback. Velocities: the free guesses are
    /// kept, the dependent ones solve J q̇ = 0 (16). Then the integration partition is chosen
    /// among all non-driven coordinates.
    fn assemble(&self, t0: f64) -> Result<State, SimError> {
        crate::assembly::assemble(self.as_dynamics(), t0).map(|(state, _)| state)
    }

    /// [`Simulate::assemble`], with a report of what assembly changed in the model's guess
    /// (solved coordinates, values set by drives, velocities from J q̇ = 0) and how it chose
    /// among the roots of h = 0 (the one nearest the guess, for one contact).
    fn assemble_reported(&self, t0: f64) -> Result<(State, AssemblyReport), SimError> {
        crate::assembly::assemble(self.as_dynamics(), t0)
    }

    /// A state at time `t` from given coordinates and velocities (e.g. to restart from a
    /// saved configuration): driven coordinates take their prescribed motion, the dependent
    /// ones are re-solved by Newton (15) from the given values (which should be on the cam)
    /// and their velocities from (16); the others are kept.
    fn state_at(&self, t: f64, q: &[f64], qd: &[f64]) -> Result<State, SimError> {
        crate::assembly::state_at(self.as_dynamics(), t, (q, qd))
    }

    /// Advances `state` by `dt` with the model's default settings.
    fn step(&self, state: &mut State, dt: f64) -> Result<Stats, SimError> {
        self.step_with(state, dt, &self.info().defaults)
    }

    /// Advances `state` by `dt` with `settings` (integrator, RK4 step / initial adaptive
    /// step, tolerances); lands exactly on `state.t + dt`.
    fn step_with(
        &self,
        state: &mut State,
        dt: f64,
        settings: &SimSettings,
    ) -> Result<Stats, SimError> {
        positive("dt", dt)?;
        validate_integration(settings)?;
        let mut stats = Stats::default();
        let target = state.t + dt;
        let mut watchdog = crate::control::Watchdog::new(state.t, settings.rtol, settings.atol);
        let mut after_step = |t: f64, h: f64| watchdog.step(t, h, (target, target));
        advance(
            self.as_dynamics(),
            state,
            target,
            settings,
            &mut stats,
            &mut after_step,
        )?;
        Ok(stats)
    }

    /// One reduced right-hand side at the state (Newton (15), velocities (16), reduced
    /// dynamics (17, 18)): writes the derivative of the integrated vector
    /// y = (u, u̇, dissipated, driven work, v, v̇) into `dy` (length
    /// [`State::integrated_len`]). For custom integrators and benchmarks.
    fn derivative(&self, state: &mut State, dy: &mut [f64]) -> Result<(), SimError> {
        check_belongs(self.as_dynamics(), state)?;
        if dy.len() != state.integrated_len() {
            return Err(invalid(format!(
                "dy has {} entries, the integrated vector {}",
                dy.len(),
                state.integrated_len()
            )));
        }
        if state.modified_since_last_step() {
            state.load_integrated_state();
        }
        let Engine {
            ws, y, at_step_end, ..
        } = &mut state.engine;
        *at_step_end = false;
        evaluate_rhs(
            self.as_dynamics(),
            &state.partition,
            ws,
            state.t,
            y,
            dy,
            false,
        )
    }

    /// The reduced right-hand side f(t, y) at any integrated vector y of the state's
    /// partition, laid out as [`State::integrated`] gives it: what a custom integrator
    /// evaluates at its stages, and what Pinocchio's `aba(model, data, q, v, τ)` is timed
    /// against (`scripts/bench/pinocchio`). Writes dy as [`Simulate::derivative`] does;
    /// Newton (15) starts from y's v.
    ///
    /// The state lends its partition and its scratch space and is otherwise left as it was:
    /// its t, q, q̇ and quadratures are not read or changed, and a later `step` or `sample`
    /// gives what it would have given without this call. At `t = state.t` and
    /// `y = state.integrated()` the result is `derivative`'s.
    fn derivative_at(
        &self,
        state: &mut State,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
    ) -> Result<(), SimError> {
        check_belongs(self.as_dynamics(), state)?;
        let len = state.integrated_len();
        if y.len() != len || dy.len() != len {
            return Err(invalid(format!(
                "y has {} entries and dy {}, the integrated vector {len}",
                y.len(),
                dy.len()
            )));
        }
        if !t.is_finite() {
            return Err(invalid(format!("the time t = {t} is not finite")));
        }
        // One pass without a branch per entry; the entry is looked for only on failure.
        if !all_finite(y)
            && let Some(k) = y.iter().position(|v| !v.is_finite())
        {
            let slot = state.integrated_slot(k, &self.as_dynamics().info().coordinates);
            return Err(invalid(format!(
                "y[{k}] ({slot}) = {} is not finite (t = {t})",
                y[k]
            )));
        }
        let Engine {
            ws, at_step_end, ..
        } = &mut state.engine;
        *at_step_end = false;
        evaluate_rhs(self.as_dynamics(), &state.partition, ws, t, y, dy, false)
    }

    /// All outputs at the state: accelerations, multipliers, normal and drive loads,
    /// constraint residuals, contact geometry and energies.
    fn sample(&self, state: &State) -> Result<Sample, SimError> {
        check_belongs(self.as_dynamics(), state)?;
        check_finite_state(state)?;
        let mut ws = state.engine.ws.clone();
        compute_sample(self.as_dynamics(), state, &mut ws, SampleLevel::Full)
    }

    /// Simulates from `state` to `settings.t_end`, sampling at t0, t0 + dt_out, … and
    /// exactly at t_end. On failure, returns the error with the samples computed so far.
    /// The failure is boxed: it carries the partial trajectory and is built once, on the
    /// cold path.
    fn simulate(
        &self,
        state: State,
        settings: &SimSettings,
    ) -> Result<Trajectory, Box<SimFailure>> {
        run(
            self.as_dynamics(),
            state,
            settings,
            (SampleLevel::Full, ContactLaw::Bilateral),
            &mut Unmonitored,
        )
    }

    /// [`Simulate::simulate`] that computes only t, q, q̇ and the quadratures at the output
    /// times: accelerations, multipliers, forces, residuals, contact geometry and energies
    /// are not computed (their vectors are empty and the energies NaN). For runs that only
    /// need the motion (benchmarks, long runs).
    fn simulate_states(
        &self,
        state: State,
        settings: &SimSettings,
    ) -> Result<Trajectory, Box<SimFailure>> {
        run(
            self.as_dynamics(),
            state,
            settings,
            (SampleLevel::State, ContactLaw::Bilateral),
            &mut Unmonitored,
        )
    }

    /// A run that keeps a summary instead of its trajectory (what a parameter sweep keeps):
    /// extreme normal forces, the first lift-off, the largest constraint residual, the
    /// energy drift and the work done, evaluated at the start and at every accepted step
    /// (and at the output times with [`MetricsOptions::grid`]); see [`crate::metrics`].
    fn simulate_metrics(
        &self,
        state: State,
        settings: &SimSettings,
        options: MetricsOptions,
    ) -> Result<RunMetrics, Box<MetricsFailure>> {
        crate::metrics::run_metrics(
            self.as_dynamics(),
            state,
            settings,
            options,
            &mut Unmonitored,
        )
    }

    /// [`Simulate::simulate_metrics`] watched by `monitor` after every step (progress; a
    /// cancelled sweep stops its runs in flight through [`crate::control::Cancel`]).
    fn simulate_metrics_monitored(
        &self,
        state: State,
        settings: &SimSettings,
        options: MetricsOptions,
        monitor: &mut dyn Monitor,
    ) -> Result<RunMetrics, Box<MetricsFailure>> {
        crate::metrics::run_metrics(self.as_dynamics(), state, settings, options, monitor)
    }

    /// [`Simulate::simulate`] with one-sided contact: the follower lifts off where the
    /// normal force reaches zero, flies, and lands with Newton's coefficient of restitution
    /// `restitution` (see [`crate::unilateral`]). Lift-offs and impacts are in the
    /// trajectory's events. One cam contact, adaptive integrator.
    fn simulate_unilateral(
        &self,
        state: State,
        settings: &SimSettings,
        restitution: f64,
    ) -> Result<Trajectory, Box<SimFailure>> {
        let law = ContactLaw::Unilateral { restitution };
        run(
            self.as_dynamics(),
            state,
            settings,
            (SampleLevel::Full, law),
            &mut Unmonitored,
        )
    }

    /// [`Simulate::simulate_unilateral`] with an observer, as in
    /// [`Simulate::simulate_observed`].
    fn simulate_unilateral_observed(
        &self,
        state: State,
        settings: &SimSettings,
        restitution: f64,
        observe: &mut dyn FnMut(&Sample) -> Observed,
    ) -> Result<Trajectory, Box<SimFailure>> {
        let law = ContactLaw::Unilateral { restitution };
        run(
            self.as_dynamics(),
            state,
            settings,
            (SampleLevel::Full, law),
            &mut OnSample(observe),
        )
    }

    /// [`Simulate::simulate`] that also hands the sample at every output time to `observe`
    /// as soon as it is computed, in time order (progress reports, streaming output). The
    /// trajectory, and every number in it, is the same as that of `simulate`. When `observe`
    /// returns `ControlFlow::Break(())` (the user interrupted, a streamed file could not be
    /// written) the run stops there with [`SimError::Interrupted`] and the samples so far.
    fn simulate_observed(
        &self,
        state: State,
        settings: &SimSettings,
        observe: &mut dyn FnMut(&Sample) -> Observed,
    ) -> Result<Trajectory, Box<SimFailure>> {
        run(
            self.as_dynamics(),
            state,
            settings,
            (SampleLevel::Full, ContactLaw::Bilateral),
            &mut OnSample(observe),
        )
    }

    /// The general run: `law` bilateral or one-sided, `monitor` shown every sample as soon as
    /// it is computed and called after every accepted step (progress, interrupts: a monitor
    /// that returns `Observed::Break(())` stops the run within one step, with
    /// [`SimError::Interrupted`] and everything computed so far). A monitor that keeps no
    /// samples ([`Monitor::keep_samples`]) gets a trajectory with the last sample only, and a
    /// run whose memory does not grow with its length. Every other `simulate` method is this
    /// one with a fixed law or monitor.
    fn simulate_monitored(
        &self,
        state: State,
        settings: &SimSettings,
        law: ContactLaw,
        monitor: &mut dyn Monitor,
    ) -> Result<Trajectory, Box<SimFailure>> {
        run(
            self.as_dynamics(),
            state,
            settings,
            (SampleLevel::Full, law),
            monitor,
        )
    }
}

impl<D: Dynamics> Simulate for D {
    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

impl Simulate for dyn Dynamics + '_ {
    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

impl Simulate for dyn Dynamics + Sync + '_ {
    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

impl Simulate for dyn Dynamics + Send + '_ {
    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

impl Simulate for dyn Dynamics + Send + Sync + '_ {
    fn as_dynamics(&self) -> &dyn Dynamics {
        self
    }
}

/// The simulation loop of every run: samples at t0, then integrates; adaptive integrators
/// step freely and interpolate the output times (dense output), RK4 lands on them; a
/// one-sided law alternates phases in contact and in flight ([`crate::unilateral`]).
fn run(
    model: &dyn Dynamics,
    state: State,
    settings: &SimSettings,
    (level, law): (SampleLevel, ContactLaw),
    monitor: &mut dyn Monitor,
) -> Result<Trajectory, Box<SimFailure>> {
    let mut record = Recorder::new(monitor, settings, state.t);
    let keep = record.keeps_samples();
    if keep && settings.dt_out > 0.0 && settings.t_end.is_finite() && state.t.is_finite() {
        // One sample per output time plus the start, capped (the count itself is checked
        // below; a reservation for a run that then fails the checks is harmless).
        let expected = output_intervals(state.t, settings).saturating_add(1);
        record.samples.reserve_exact(expected.min(1 << 16));
    }
    let outcome = match law {
        ContactLaw::Bilateral => {
            let mut state = state;
            let outcome = validate_run(model, &state, settings, keep)
                .and_then(|()| crate::clearance::held_both_ways(model))
                .and_then(|()| {
                    if settings.integrator.is_adaptive() {
                        run_dense(model, &mut state, settings, level, &mut record)
                    } else {
                        run_landing(model, &mut state, settings, level, &mut record)
                    }
                });
            if outcome.is_err() {
                append_last_state(model, &mut state, &mut record, level);
            }
            outcome
        }
        ContactLaw::Unilateral { restitution } if Clearance::applies_to(model) => {
            let clearance = Clearance::new(model);
            crate::unilateral::run_phases(&clearance, state, settings, restitution, &mut record)
        }
        ContactLaw::Unilateral { restitution } => {
            crate::unilateral::run_phases(model, state, settings, restitution, &mut record)
        }
    };
    let trajectory = Trajectory {
        samples: record.samples,
        sample_count: record.count,
        events: record.events,
        stats: record.stats,
    };
    match outcome {
        Ok(()) => Ok(trajectory),
        Err(error) => Err(Box::new(SimFailure {
            error,
            partial: trajectory,
        })),
    }
}

/// Fixed steps that land on every output time.
fn run_landing(
    model: &dyn Dynamics,
    state: &mut State,
    settings: &SimSettings,
    level: SampleLevel,
    record: &mut Recorder,
) -> Result<(), SimError> {
    let t0 = state.t;
    let intervals = output_intervals(t0, settings);
    for k in 0..=intervals {
        let target = output_time(t0, k, intervals, settings);
        let mut stats = std::mem::take(&mut record.stats);
        let mut after_step = |t: f64, h: f64| record.stepped(t, h, target);
        let advanced = advance(model, state, target, settings, &mut stats, &mut after_step);
        record.stats = stats;
        advanced
            .and_then(|()| sample_in_place(model, state, level))
            .and_then(|sample| record.emit(sample))?;
    }
    Ok(())
}

/// Free adaptive steps (only the last is clipped, to end on t_end); the output times inside
/// a step are interpolated by the integrator's dense output and completed by Newton (15)
/// and (16) from the interpolated u, u̇ and the interpolated v as starting point. Runs that
/// compute full samples watch the normal forces (events, inside steps too).
fn run_dense(
    model: &dyn Dynamics,
    state: &mut State,
    settings: &SimSettings,
    level: SampleLevel,
    record: &mut Recorder,
) -> Result<(), SimError> {
    let before = all_counters(&state.engine);
    let mut grid = Grid::new(state.t, settings);
    let watch = match level {
        SampleLevel::Full if model.info().n_contacts() > 0 => Watch::Forces { stop: false },
        _ => Watch::Nothing,
    };
    let mut phase = Phase {
        settings,
        level,
        watch: &watch,
        grid: &mut grid,
        record,
        complete: None,
    };
    let outcome = phase.run(model, state).map(|_| ());
    add_counters_since(&mut record.stats, &state.engine, before);
    if outcome.is_err() {
        // Realign the integrated vector with the last accepted state.
        state.load_integrated_state();
    }
    outcome
}

/// After a failure: keeps the last accepted state as a final sample when it is newer than
/// the last output (best effort: a failing sample is dropped).
fn append_last_state(
    model: &dyn Dynamics,
    state: &mut State,
    record: &mut Recorder,
    level: SampleLevel,
) {
    let newer = record.samples.last().is_none_or(|last| state.t > last.t);
    if newer && !state.modified_since_last_step() {
        if let Ok(sample) = sample_in_place(model, state, level) {
            record.keep_sample(sample);
        }
    }
}

#[cfg(test)]
mod tests;
