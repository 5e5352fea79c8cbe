//! Assembly, stepping and simulation of a model under its cam constraints.
//!
//! Only the independent coordinates are integrated: the integrated state is
//! y = (u, u̇, dissipated energy, driven work, v, v̇), of which (u, u̇) are error-controlled
//! (everything, when the drives alone move the mechanism: no u),
//! the two energies are quadratures, and (v, v̇) ride along uncontrolled as Newton's
//! starting point (at a Runge–Kutta stage they are accurate to the stage's order, so
//! Newton usually converges at its first evaluation). At every right-hand side evaluation the dependent
//! coordinates are recovered by Newton (15) and the velocity relation (16), so the
//! constraint holds to Newton's tolerance at all times (no drift), and ü comes from the
//! reduced dynamics (17, 18). After each accepted step the partition's conditioning is
//! checked and the dependent coordinates are re-chosen when it has degraded.

use crate::dynamics::{ContactGeometry, Dynamics, Energy, IntegratorKind, SimSettings};
use crate::error::SimError;
use crate::events::{ContactEvent, EVENT_TIME_TOLERANCE, EventKind, changes_sign, locate_root};
use crate::integrators::{Adaptive, Counters, Dop853, Dopri5, Rk4, Tolerances};
use crate::metrics::{MetricsFailure, MetricsOptions, RunMetrics};
use crate::partition::{
    NEWTON_SLACK_PER_RTOL, Partition, REPARTITION_RATIO, Workspace, choose_dependent, conditioning,
    independent_rows, normal_force,
};

/// A step ending within this fraction of a step before an output time is stretched to land
/// on it (avoids a useless sliver step caused by round-off in t + h). The round-off
/// accumulated over the steps of one output interval must fit: at t ≈ 1000 s with h = 1 ms,
/// 100 steps of up to ulp(t)/2 ≈ 6e-14 s each reach ~1e-11 s = 1e-8·h. Stretching a step by
/// 1e-6 of itself changes its local error by a relative 5e-6 (RK4), nothing measurable.
const LANDING_SLACK: f64 = 1e-6;

pub use crate::assembly::AssemblyReport;
pub use crate::settings::MAX_STEPS_PER_CALL;

/// Simulation state: time, full coordinates and velocities, and the private machinery
/// (partition, workspace, integrator buffers) sized for its model.
///
/// `t`, `q` and `qd` may be changed between steps; the next step then restarts from them
/// (the dependent coordinates are re-solved from the independent ones at the first
/// evaluation).
#[derive(Debug, Clone)]
pub struct State {
    /// Time (s).
    pub t: f64,
    /// Generalised coordinates.
    pub q: Vec<f64>,
    /// Generalised velocities.
    pub qd: Vec<f64>,
    pub(crate) partition: Partition,
    dissipated: f64,
    driven_work: f64,
    pub(crate) engine: Engine,
}

/// Integration buffers of a [`State`].
#[derive(Debug, Clone)]
pub(crate) struct Engine {
    pub(crate) ws: Workspace,
    /// y = (u, u̇, dissipated, driven work).
    pub(crate) y: Vec<f64>,
    rk4: Rk4,
    dopri: Dopri5,
    dop853: Dop853,
    /// Step proposed by the adaptive integrator's controller.
    h_next: Option<f64>,
    /// The workspace holds the solved state at the end of the last accepted step (the
    /// step's last right-hand side was evaluated there and nothing since).
    pub(crate) at_step_end: bool,
    /// (t, q, q̇) as last written by a step: a difference means the user changed the state.
    synced_t: f64,
    synced_q: Vec<f64>,
    synced_qd: Vec<f64>,
}

impl State {
    pub(crate) fn new(t: f64, ws: Workspace, partition: Partition) -> Self {
        let nu = partition.independent().len();
        let dim = integrated_len(&partition);
        let engine = Engine {
            y: vec![0.0; dim],
            rk4: Rk4::new(dim),
            dopri: Dopri5::new(dim, controlled_len(nu, dim)),
            dop853: Dop853::new(dim, controlled_len(nu, dim)),
            h_next: None,
            at_step_end: false,
            synced_t: t,
            synced_q: ws.q().to_vec(),
            synced_qd: ws.qd().to_vec(),
            ws,
        };
        let mut state = Self {
            t,
            q: engine.synced_q.clone(),
            qd: engine.synced_qd.clone(),
            partition,
            dissipated: 0.0,
            driven_work: 0.0,
            engine,
        };
        state.load_integrated_state();
        state
    }

    /// Length of the integrated vector y = (u, u̇, dissipated, driven work, v, v̇).
    pub fn integrated_len(&self) -> usize {
        integrated_len(&self.partition)
    }

    /// Forgets the values the last right-hand side left for the next one (the sines and
    /// cosines of the joint angles a generated model keeps in its cache, see
    /// [`crate::sin_cos_memo`]), so that the next evaluation computes everything afresh: for
    /// benchmarks of one right-hand side at a new state. Results are the same either way.
    pub fn clear_evaluation_cache(&mut self) {
        self.engine.ws.clear_cache();
    }

    /// Dependent coordinates v of the current partition (one per contact).
    pub fn dependent(&self) -> &[usize] {
        self.partition.dependent()
    }

    /// Independent coordinates u of the current partition (the integrated ones).
    pub fn independent(&self) -> &[usize] {
        self.partition.independent()
    }

    /// The model's length scale found at assembly (the largest contact-point coordinate,
    /// at least 1), which scales Newton's tolerance.
    pub fn length_scale(&self) -> f64 {
        self.engine.ws.length_scale()
    }

    /// Energy dissipated by the joint dampers since assembly, ∫ Σ c q̇² dt (J).
    pub fn dissipated(&self) -> f64 {
        self.dissipated
    }

    /// Work done by the drives and the applied joint loads since assembly,
    /// ∫ (Σ τ_d q̇_d + Σ τ_i q̇_i) dt (J).
    pub fn driven_work(&self) -> f64 {
        self.driven_work
    }

    /// Sets the dissipated energy and driven work carried by the state (a new phase of a
    /// unilateral run continues the balance of the previous one).
    pub(crate) fn set_quadratures(&mut self, (dissipated, driven_work): (f64, f64)) {
        self.dissipated = dissipated;
        self.driven_work = driven_work;
        self.engine.synced_t = f64::NAN;
    }

    /// Imposes the dependent coordinates (one per contact, not driven). The partition is
    /// still re-chosen after a step if its conditioning is below [`REPARTITION_RATIO`].
    pub fn set_dependent(&mut self, dependent: &[usize]) -> Result<(), SimError> {
        self.partition.set_dependent(dependent)?;
        self.engine.synced_t = f64::NAN;
        Ok(())
    }

    /// y ← (q_u, q̇_u, dissipated, driven work, v, v̇) from the public fields; restarts
    /// the adaptive integrators.
    fn load_integrated_state(&mut self) {
        let nu = self.partition.independent().len();
        let y = &mut self.engine.y;
        for (a, &u) in self.partition.independent().iter().enumerate() {
            y[a] = self.q[u];
            y[nu + a] = self.qd[u];
        }
        y[2 * nu] = self.dissipated;
        y[2 * nu + 1] = self.driven_work;
        store_dependent(&self.partition, y, &self.q, &self.qd);
        self.engine.ws.set_state(&self.q, &self.qd);
        self.engine.at_step_end = false;
        self.set_newton_anchor();
        self.engine.dopri.invalidate_fsal();
        self.engine.dop853.invalidate_fsal();
        self.remember_synced();
    }

    fn set_newton_anchor(&mut self) {
        let ws = &mut self.engine.ws;
        for (anchor, &v) in ws.v_anchor.iter_mut().zip(self.partition.dependent()) {
            *anchor = self.q[v];
        }
    }

    fn remember_synced(&mut self) {
        self.engine.synced_t = self.t;
        self.engine.synced_q.copy_from_slice(&self.q);
        self.engine.synced_qd.copy_from_slice(&self.qd);
    }

    fn modified_since_last_step(&self) -> bool {
        let e = &self.engine;
        self.t != e.synced_t || self.q != e.synced_q || self.qd != e.synced_qd
    }
}

/// Work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted integration steps.
    pub steps: usize,
    /// Rejected step attempts (adaptive integrator).
    pub rejected: usize,
    /// Right-hand side evaluations (each: Newton (15), velocities (16), reduced dynamics
    /// (17, 18)).
    pub rhs_evaluations: usize,
    /// Changes of the dependent coordinates.
    pub repartitions: usize,
}

impl Stats {
    fn add_counters(&mut self, after: Counters, before: Counters) {
        self.steps += after.steps - before.steps;
        self.rejected += after.rejected - before.rejected;
        self.rhs_evaluations += after.rhs_evaluations - before.rhs_evaluations;
    }
}

/// All outputs at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Coordinates q.
    pub q: Vec<f64>,
    /// Velocities q̇.
    pub qd: Vec<f64>,
    /// Accelerations q̈ (16)–(18).
    pub qdd: Vec<f64>,
    /// Multipliers λ of (14), one per contact.
    pub lambda: Vec<f64>,
    /// Contact normal forces N = −λ √(1 + f3'²) (N), positive when the cam pushes the
    /// point towards +y of the cam plane.
    pub normal_force: Vec<f64>,
    /// Constraint residuals h(q) (3).
    pub h: Vec<f64>,
    /// Geometry of every contact.
    pub contacts: Vec<ContactGeometry>,
    /// Drive loads τ (length n, zero on free coordinates): the torque/force each driven
    /// joint must exert to follow its prescribed motion.
    pub drive: Vec<f64>,
    /// Kinetic and potential energies.
    pub energy: Energy,
    /// Energy dissipated by the dampers since assembly (J).
    pub dissipated: f64,
    /// Work done by the drives and the applied joint loads since assembly (J).
    pub driven_work: f64,
    /// Dependent coordinates at this instant (shared by the samples of one partition).
    pub dependent: std::sync::Arc<[usize]>,
}

/// Samples at the output times and the work done.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trajectory {
    /// Samples in time order.
    pub samples: Vec<Sample>,
    /// Contact events in time order: sign changes of the normal forces (runs of the
    /// adaptive integrators with full samples), lift-offs and impacts (unilateral runs).
    pub events: Vec<ContactEvent>,
    /// Work counters of the whole run.
    pub stats: Stats,
}

/// A simulation that stopped early: the error and everything computed until then.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("simulation stopped after {} samples: {error}", partial.samples.len())]
pub struct SimFailure {
    /// Why the simulation stopped.
    pub error: SimError,
    /// Samples at the output times reached, plus one at the last accepted state when it
    /// lies past the last output time; work counters until the failure.
    pub partial: Trajectory,
}

/// Constrained simulation of any [`Dynamics`] (blanket implementation).
pub trait Simulate: Dynamics {
    /// Initial assembly (docs/method.md §5.9) at time `t0` from the model's initial guess: coordinates with
    /// `hold = true` keep their guess, driven ones take their prescribed value at t0; the
    /// dependent coordinates are chosen among the others by largest |J_i| and solved by
    /// Newton (15), with a backtracking Newton as fallback. Velocities: the free guesses are
    /// kept, the dependent ones solve J q̇ = 0 (16). Then the integration partition is chosen
    /// among all non-driven coordinates.
    fn assemble(&self, t0: f64) -> Result<State, SimError> {
        crate::assembly::assemble(self, t0).map(|(state, _)| state)
    }

    /// [`Simulate::assemble`], with a report of what assembly changed in the model's guess
    /// (solved coordinates, values set by drives, velocities from J q̇ = 0) and how it chose
    /// among the roots of h = 0 (the one nearest the guess, for one contact).
    fn assemble_reported(&self, t0: f64) -> Result<(State, AssemblyReport), SimError> {
        crate::assembly::assemble(self, t0)
    }

    /// A state at time `t` from given coordinates and velocities (e.g. to restart from a
    /// saved configuration): driven coordinates take their prescribed motion, the dependent
    /// ones are re-solved by Newton (15) from the given values (which should be on the cam)
    /// and their velocities from (16); the others are kept.
    fn state_at(&self, t: f64, q: &[f64], qd: &[f64]) -> Result<State, SimError> {
        let hold = vec![false; self.info().n()];
        crate::assembly::assemble_from(self, t, (q, qd), &hold).map(|(state, _)| state)
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
        advance(self, state, state.t + dt, settings, &mut stats)?;
        Ok(stats)
    }

    /// One reduced right-hand side at the state (Newton (15), velocities (16), reduced
    /// dynamics (17, 18)): writes the derivative of the integrated vector
    /// y = (u, u̇, dissipated, driven work, v, v̇) into `dy` (length
    /// [`State::integrated_len`]). For custom integrators and benchmarks.
    fn derivative(&self, state: &mut State, dy: &mut [f64]) -> Result<(), SimError> {
        check_belongs(self, state)?;
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
        evaluate_rhs(self, &state.partition, ws, state.t, y, dy)
    }

    /// All outputs at the state: accelerations, multipliers, normal and drive loads,
    /// constraint residuals, contact geometry and energies.
    fn sample(&self, state: &State) -> Result<Sample, SimError> {
        check_belongs(self, state)?;
        check_finite_state(state)?;
        let mut ws = state.engine.ws.clone();
        compute_sample(self, state, &mut ws, SampleLevel::Full)
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
        run(self, state, settings, SampleLevel::Full, &mut |_| {
            Observed::Continue(())
        })
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
        run(self, state, settings, SampleLevel::State, &mut |_| {
            Observed::Continue(())
        })
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
        crate::metrics::run_metrics(self, state, settings, options)
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
        crate::unilateral::simulate_unilateral(self, state, settings, restitution, &mut |_| {
            Observed::Continue(())
        })
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
        crate::unilateral::simulate_unilateral(self, state, settings, restitution, observe)
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
        run(self, state, settings, SampleLevel::Full, observe)
    }
}

impl<D: Dynamics + ?Sized> Simulate for D {}

/// How many leading components of y the adaptive integrators control: (u, u̇); when there
/// is no independent coordinate (a mechanism moved only by its drives, y = (dissipated,
/// driven work, v, v̇)), the two energy quadratures, which then set the step (nothing would
/// bound it otherwise; v and v̇ are solved exactly at every evaluation).
fn controlled_len(nu: usize, _dim: usize) -> usize {
    if nu == 0 { 2 } else { 2 * nu }
}

/// The first closing of a gap that opens at `t0` (where it is zero) and is negative at `t1`:
/// an interval [a, b] with g(a) > 0 ≥ g(b), found on 32 points of [t0, t1], then of
/// [t0, first point], three levels deep; `None` when the gap never opens measurably.
#[allow(clippy::type_complexity)]
fn bracket_landing(
    g: &mut impl FnMut(f64) -> Result<f64, SimError>,
    t0: f64,
    (t1, g1): (f64, f64),
) -> Result<Option<((f64, f64), (f64, f64))>, SimError> {
    const POINTS: usize = 32;
    let mut end = (t1, g1);
    for _ in 0..3 {
        let mut previous: Option<(f64, f64)> = None;
        for i in 1..=POINTS {
            let t = t0 + (end.0 - t0) * i as f64 / POINTS as f64;
            let value = if i == POINTS { end.1 } else { g(t)? };
            if value <= 0.0 {
                if let Some(open) = previous {
                    return Ok(Some((open, (t, value))));
                }
                // Closed already at the first point: look closer to the take-off.
                end = (t, value);
                break;
            }
            previous = Some((t, value));
        }
    }
    Ok(None)
}

/// Length of the integrated vector y = (u, u̇, dissipated, driven work, v, v̇).
fn integrated_len(partition: &Partition) -> usize {
    2 * partition.independent().len() + 2 + 2 * partition.dependent().len()
}

/// Writes v and v̇ into their (uncontrolled) slots of y.
fn store_dependent(partition: &Partition, y: &mut [f64], q: &[f64], qd: &[f64]) {
    let nu = partition.independent().len();
    let nc = partition.dependent().len();
    for (k, &v) in partition.dependent().iter().enumerate() {
        y[2 * nu + 2 + k] = q[v];
        y[2 * nu + 2 + nc + k] = qd[v];
    }
}

pub(crate) fn invalid(message: String) -> SimError {
    SimError::InvalidSettings { message }
}

fn positive(name: &str, value: f64) -> Result<(), SimError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(invalid(format!(
            "{name} must be positive and finite, got {value}"
        )))
    }
}

fn validate_integration(settings: &SimSettings) -> Result<(), SimError> {
    settings.validate_integration().map_err(setting_error)
}

fn validate_output(settings: &SimSettings, t0: f64) -> Result<(), SimError> {
    settings.validate_output(t0).map_err(setting_error)
}

fn setting_error(e: crate::settings::InvalidSetting) -> SimError {
    invalid(e.to_string())
}

fn check_belongs<D: Dynamics + ?Sized>(model: &D, state: &State) -> Result<(), SimError> {
    let n = model.info().n();
    let fits = state.q.len() == n && state.qd.len() == n && state.partition.n() == n;
    if fits && state.dependent().len() <= model.info().n_constraints() {
        Ok(())
    } else {
        Err(invalid(format!(
            "the state does not belong to model {}",
            model.info().name
        )))
    }
}

/// A NaN or infinite coordinate or velocity in the state (e.g. set by the caller) is
/// reported as `q` or `q̇`, rather than as the first quantity computed from it.
fn check_finite_state(state: &State) -> Result<(), SimError> {
    let quantity = if state.q.iter().any(|x| !x.is_finite()) {
        "q"
    } else if state.qd.iter().any(|x| !x.is_finite()) {
        "q̇"
    } else {
        return Ok(());
    };
    Err(SimError::NonFinite {
        t: state.t,
        quantity,
        q: state.q.clone(),
        qd: state.qd.clone(),
    })
}

/// Where a run hands each sample as soon as it is computed; an error (the observer asked to
/// stop) ends the run with the samples emitted so far.
pub(crate) type Emit<'e> = dyn FnMut(Sample) -> Result<(), SimError> + 'e;

/// What an observer of [`Simulate::simulate_observed`] tells the run after each sample.
pub type Observed = std::ops::ControlFlow<()>;

/// What a sample holds beyond t, q, q̇ and the quadratures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SampleLevel {
    /// Everything [`Sample`] describes.
    Full,
    /// Only t, q, q̇, the quadratures and the partition: no accelerations, forces,
    /// residuals, contact geometry or energies (they are not computed).
    State,
}

/// The simulation loop of [`Simulate::simulate`]: samples at t0, then integrates; adaptive
/// integrators step freely and interpolate the output times (dense output), RK4 lands on
/// them.
fn run<D: Dynamics + ?Sized>(
    model: &D,
    mut state: State,
    settings: &SimSettings,
    level: SampleLevel,
    observe: &mut dyn FnMut(&Sample) -> Observed,
) -> Result<Trajectory, Box<SimFailure>> {
    let mut trajectory = Trajectory::default();
    if settings.dt_out > 0.0 && settings.t_end.is_finite() && state.t.is_finite() {
        // One sample per output time plus the start, capped (the count itself is checked
        // below; a reservation for a run that then fails the checks is harmless).
        let expected = output_intervals(state.t, settings).saturating_add(1);
        trajectory.samples.reserve_exact(expected.min(1 << 16));
    }
    let mut events = Vec::new();
    let checks = validate_run(model, &state, settings);
    let outcome = checks.map_err(|e| (e, Stats::default())).and_then(|()| {
        let mut emit = |sample: Sample| {
            let flow = observe(&sample);
            let t = sample.t;
            trajectory.samples.push(sample);
            match flow {
                Observed::Continue(()) => Ok(()),
                Observed::Break(()) => Err(SimError::Interrupted { t }),
            }
        };
        if settings.integrator.is_adaptive() {
            run_dense(model, &mut state, settings, level, &mut emit, &mut events)
        } else {
            run_landing(model, &mut state, settings, level, &mut emit)
        }
    });
    trajectory.events = events;
    match outcome {
        Ok(stats) => {
            trajectory.stats = stats;
            Ok(trajectory)
        }
        Err((error, stats)) => {
            trajectory.stats = stats;
            append_last_state(model, &mut state, &mut trajectory, level);
            Err(Box::new(SimFailure {
                error,
                partial: trajectory,
            }))
        }
    }
}

/// A failure inside a run, with the work done until then.
type RunResult = Result<Stats, (SimError, Stats)>;

/// Fixed steps that land on every output time.
fn run_landing<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    settings: &SimSettings,
    level: SampleLevel,
    emit: &mut Emit,
) -> RunResult {
    let mut stats = Stats::default();
    let t0 = state.t;
    let intervals = output_intervals(t0, settings);
    for k in 0..=intervals {
        let target = output_time(t0, k, intervals, settings);
        let outcome = advance(model, state, target, settings, &mut stats)
            .and_then(|()| sample_in_place(model, state, level))
            .and_then(&mut *emit);
        if let Err(error) = outcome {
            return Err((error, stats));
        }
    }
    Ok(stats)
}

/// Free adaptive steps (only the last is clipped, to end on t_end); the output times inside
/// a step are interpolated by the integrator's dense output and completed by Newton (15)
/// and (16) from the interpolated u, u̇ and the interpolated v as starting point.
fn run_dense<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    settings: &SimSettings,
    level: SampleLevel,
    emit: &mut Emit,
    events: &mut Vec<ContactEvent>,
) -> RunResult {
    let before = all_counters(&state.engine);
    let mut stats = Stats::default();
    let outcome = dense_loop(model, state, settings, level, emit, &mut stats, events);
    add_counters_since(&mut stats, &state.engine, before);
    match outcome {
        Ok(()) => Ok(stats),
        Err(error) => {
            // As in `advance`: realign the integrated vector with the last accepted state.
            state.load_integrated_state();
            Err((error, stats))
        }
    }
}

fn dense_loop<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    settings: &SimSettings,
    level: SampleLevel,
    emit: &mut Emit,
    stats: &mut Stats,
    events: &mut Vec<ContactEvent>,
) -> Result<(), SimError> {
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
        emit,
        stats,
        events,
    };
    phase.run(model, state)?;
    Ok(())
}

/// The output times of a run, t0 + k·dt_out and t_end, shared by its phases.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Grid {
    t0: f64,
    intervals: usize,
    /// Index of the next output to emit.
    pub(crate) next: usize,
}

impl Grid {
    /// The grid of `settings` from t0, nothing emitted yet.
    pub(crate) fn new(t0: f64, settings: &SimSettings) -> Self {
        Grid {
            t0,
            intervals: output_intervals(t0, settings),
            next: 0,
        }
    }

    fn time(&self, k: usize, settings: &SimSettings) -> f64 {
        output_time(self.t0, k, self.intervals, settings)
    }

    /// The next output time, if any is left.
    fn pending(&self, settings: &SimSettings) -> Option<f64> {
        (self.next <= self.intervals).then(|| self.time(self.next, settings))
    }

    /// [`Grid::pending`] for the other modules of the crate.
    pub(crate) fn pending_time(&self, settings: &SimSettings) -> Option<f64> {
        self.pending(settings)
    }
}

/// What a phase of a run watches for at every step (see [`crate::events`]).
pub(crate) enum Watch<'a> {
    /// Nothing.
    Nothing,
    /// Sign changes of the normal forces, recorded as events; with `stop`, the first one
    /// to zero or below ends the phase (a unilateral follower lifts off).
    Forces {
        /// End the phase when a force reaches zero from above.
        stop: bool,
    },
    /// The gap h(q) of a contact (a flying follower), computed by `gap`: its reaching zero
    /// from above ends the phase (the follower lands).
    Gap {
        /// h of the contact at q.
        gap: &'a dyn Fn(&[f64]) -> f64,
    },
}

/// Where and why a phase ended before t_end.
#[derive(Debug, Clone)]
pub(crate) struct Stop {
    pub(crate) t: f64,
    pub(crate) contact: usize,
    pub(crate) q: Vec<f64>,
    pub(crate) qd: Vec<f64>,
    /// Dissipated energy and driven work at t.
    pub(crate) quadratures: (f64, f64),
}

/// One phase of a run: free adaptive steps with dense output, outputs on the shared grid,
/// events located inside the steps.
pub(crate) struct Phase<'p, 'w> {
    pub(crate) settings: &'p SimSettings,
    pub(crate) level: SampleLevel,
    pub(crate) watch: &'p Watch<'w>,
    pub(crate) grid: &'p mut Grid,
    pub(crate) emit: &'p mut Emit<'p>,
    pub(crate) stats: &'p mut Stats,
    pub(crate) events: &'p mut Vec<ContactEvent>,
}

impl Phase<'_, '_> {
    /// Integrates until the grid is done or the watch stops the phase.
    pub(crate) fn run<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
        state: &mut State,
    ) -> Result<Option<Stop>, SimError> {
        if state.modified_since_last_step() {
            state.load_integrated_state();
        }
        let settings = self.settings;
        if self.grid.next == 0 {
            (self.emit)(sample_in_place(model, state, self.level)?)?;
            self.grid.next = 1;
        }
        let mut sample_ws = state.engine.ws.clone();
        let mut y_out = state.engine.y.clone();
        let y_start = state.engine.y.clone();
        let mut watched = self.watch_values(model, state, &mut sample_ws, state.t, &y_start)?;
        if let Watch::Gap { .. } = self.watch {
            // A flight starts on the cam (gap 0 up to Newton's tolerance): count it as
            // above, so that a landing within the first step is not missed.
            for g in &mut watched {
                *g = g.max(f64::MIN_POSITIVE);
            }
        }
        if let Some(stop) = self.stop_at_start(model, state, &watched)? {
            return Ok(Some(stop));
        }
        let mut steps_since_output = 0;
        while self.grid.pending(settings).is_some() {
            if steps_since_output == MAX_STEPS_PER_CALL {
                return Err(SimError::TooManySteps { t: state.t });
            }
            let t_old = state.t;
            let t_new = adaptive_step(model, state, settings.t_end, settings)?;
            steps_since_output += 1;
            sample_ws
                .v_anchor
                .copy_from_slice(&state.engine.ws.v_anchor);
            let now = if matches!(self.watch, Watch::Nothing) {
                Vec::new()
            } else {
                // The step's end through the interpolant: in the step's own partition (the
                // state may re-partition when the step is finished).
                interpolate_last_step(model, state, settings, t_new, &mut y_out)?;
                self.watch_values(model, state, &mut sample_ws, t_new, &y_out)?
            };
            let stop = self.locate_events(
                model,
                state,
                &mut sample_ws,
                (t_old, &watched),
                (t_new, &now),
            )?;
            let limit = stop.as_ref().map_or(t_new, |s| s.t);
            while let Some(t_out) = self.grid.pending(settings) {
                let inside = t_out < limit || (stop.is_some() && t_out <= limit);
                if !inside {
                    break;
                }
                interpolate_last_step(model, state, settings, t_out, &mut y_out)?;
                let sample =
                    sample_interpolated(model, state, &mut sample_ws, t_out, &y_out, self.level)?;
                (self.emit)(sample)?;
                self.grid.next += 1;
                steps_since_output = 0;
            }
            if stop.is_some() {
                return Ok(stop);
            }
            if finish_step(model, state, t_new)? {
                self.stats.repartitions += 1;
            }
            if self
                .grid
                .pending(settings)
                .is_some_and(|t_out| t_out <= t_new)
            {
                (self.emit)(sample_in_place(model, state, self.level)?)?;
                self.grid.next += 1;
                steps_since_output = 0;
            }
            watched = now;
        }
        Ok(None)
    }

    /// The watched quantities at (t, y) of the current step's partition.
    fn watch_values<D: Dynamics + ?Sized>(
        &self,
        model: &D,
        state: &State,
        ws: &mut Workspace,
        t: f64,
        y: &[f64],
    ) -> Result<Vec<f64>, SimError> {
        if matches!(self.watch, Watch::Nothing) {
            return Ok(Vec::new());
        }
        let partition = &state.partition;
        load_state(model, partition, ws, t, y)?;
        match self.watch {
            Watch::Nothing => Ok(Vec::new()),
            Watch::Forces { .. } => {
                ws.solve_accelerations(model, partition, t)?;
                ws.solve_multipliers(partition, t)?;
                let mut contacts = vec![ContactGeometry::default(); model.info().n_contacts()];
                model.contact_geometry(ws.q(), ws.qd(), &mut contacts);
                Ok(ws
                    .full_lambda()
                    .iter()
                    .zip(&contacts)
                    .map(|(&l, g)| normal_force(l, g.force_scale))
                    .collect())
            }
            Watch::Gap { gap } => Ok(vec![gap(ws.q())]),
        }
    }

    /// A phase that must stop at once: a unilateral contact starting with a pulling force.
    fn stop_at_start<D: Dynamics + ?Sized>(
        &self,
        model: &D,
        state: &State,
        watched: &[f64],
    ) -> Result<Option<Stop>, SimError> {
        let Watch::Forces { stop: true } = self.watch else {
            return Ok(None);
        };
        let _ = model;
        Ok(watched.iter().position(|&n| n <= 0.0).map(|contact| Stop {
            t: state.t,
            contact,
            q: state.q.clone(),
            qd: state.qd.clone(),
            quadratures: (state.dissipated, state.driven_work),
        }))
    }

    /// Sign changes of the watched quantities inside the step, located by root finding on
    /// the dense output; records them as events and returns the first one that stops the
    /// phase (with q, q̇ there).
    fn locate_events<D: Dynamics + ?Sized>(
        &mut self,
        model: &D,
        state: &mut State,
        ws: &mut Workspace,
        (t0, before): (f64, &[f64]),
        (t1, after): (f64, &[f64]),
    ) -> Result<Option<Stop>, SimError> {
        let mut found: Vec<(f64, usize, bool)> = Vec::new();
        for (k, (&g0, &g1)) in before.iter().zip(after).enumerate() {
            // A gap only matters when it closes.
            let gap = matches!(self.watch, Watch::Gap { .. });
            if !changes_sign(g0, g1) || (gap && g0 <= 0.0) {
                continue;
            }
            let stops = match self.watch {
                Watch::Nothing => false,
                Watch::Forces { stop } => *stop && g0 > 0.0,
                Watch::Gap { .. } => g0 > 0.0,
            };
            let mut y = vec![0.0; state.engine.y.len()];
            let mut g = |t: f64| -> Result<f64, SimError> {
                interpolate_last_step(model, state, self.settings, t, &mut y)?;
                let values = self.watch_values(model, state, ws, t, &y)?;
                Ok(values[k])
            };
            // A flight that starts on the cam (its gap counted as just above zero) and lands
            // within its first step: the gap rises, then falls through zero. Bracket the
            // landing from a point where the gap is really open, not from the take-off.
            let (mut a, mut b) = ((t0, g0), (t1, g1));
            if gap && g0 <= f64::MIN_POSITIVE {
                match bracket_landing(&mut g, t0, (t1, g1))? {
                    Some(bracket) => (a, b) = bracket,
                    None => {
                        // A hop shorter than a 32768th of the step: the follower never
                        // really left the cam; it lands where it took off.
                        found.push((t0, k, stops));
                        continue;
                    }
                }
            }
            let t = locate_root(g, a, b, EVENT_TIME_TOLERANCE)?;
            found.push((t, k, stops));
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        let first_stop = found.iter().find(|e| e.2).map(|e| e.0);
        let mut stop = None;
        for (t, k, stops) in found {
            if first_stop.is_some_and(|ts| t > ts) {
                break;
            }
            let mut y = vec![0.0; state.engine.y.len()];
            interpolate_last_step(model, state, self.settings, t, &mut y)?;
            load_state(model, &state.partition, ws, t, &y)?;
            let kind = match self.watch {
                Watch::Gap { .. } => EventKind::Impact {
                    normal_velocity: f64::NAN,
                    rebound: f64::NAN,
                    stays: false,
                    loss: f64::NAN,
                },
                _ if stops => EventKind::LiftOff,
                _ if before[k] > 0.0 => EventKind::ForceBecameNegative,
                _ => EventKind::ForceBecamePositive,
            };
            let (q, qd) = (ws.q().to_vec(), ws.qd().to_vec());
            if stops {
                // The driver records the stopping event (it completes impacts).
                let nu = state.partition.independent().len();
                let quadratures = (y[2 * nu], y[2 * nu + 1]);
                stop = Some(Stop {
                    t,
                    contact: k,
                    q,
                    qd,
                    quadratures,
                });
                break;
            }
            self.events.push(ContactEvent {
                t,
                contact: k,
                kind,
                q,
                qd,
            });
        }
        Ok(stop)
    }
}

/// The sample at an interpolated y inside the last step (the partition of that step).
fn sample_interpolated<D: Dynamics + ?Sized>(
    model: &D,
    state: &State,
    ws: &mut Workspace,
    t: f64,
    y: &[f64],
    level: SampleLevel,
) -> Result<Sample, SimError> {
    let partition = &state.partition;
    let nu = partition.independent().len();
    load_state(model, partition, ws, t, y)?;
    let quadratures = (y[2 * nu], y[2 * nu + 1]);
    complete_sample(model, partition, ws, t, quadratures, level)
}

/// Number of output intervals: the last one may be shorter and ends at t_end. A remainder
/// below 1e-9·dt_out is round-off, not an interval.
fn output_intervals(t0: f64, settings: &SimSettings) -> usize {
    let span = settings.t_end - t0;
    if span <= 0.0 {
        return 0;
    }
    (span / settings.dt_out - 1e-9).ceil().max(1.0) as usize
}

/// t0 + k·dt_out (computed by multiplication: no accumulated round-off), t_end for the last.
fn output_time(t0: f64, k: usize, intervals: usize, settings: &SimSettings) -> f64 {
    if k == intervals && k > 0 {
        settings.t_end
    } else {
        t0 + k as f64 * settings.dt_out
    }
}

pub(crate) fn sample_in_place<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    level: SampleLevel,
) -> Result<Sample, SimError> {
    state.engine.at_step_end = false;
    let mut ws = std::mem::replace(&mut state.engine.ws, Workspace::new(0, 0, 0));
    let sample = compute_sample(model, state, &mut ws, level);
    state.engine.ws = ws;
    sample
}

/// After a failure: keeps the last accepted state as a final sample when it is newer than
/// the last output (best effort: a failing sample is dropped).
fn append_last_state<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    trajectory: &mut Trajectory,
    level: SampleLevel,
) {
    let newer = trajectory
        .samples
        .last()
        .is_none_or(|last| state.t > last.t);
    if newer && !state.modified_since_last_step() {
        if let Ok(sample) = sample_in_place(model, state, level) {
            trajectory.samples.push(sample);
        }
    }
}

fn compute_sample<D: Dynamics + ?Sized>(
    model: &D,
    state: &State,
    ws: &mut Workspace,
    level: SampleLevel,
) -> Result<Sample, SimError> {
    let (t, partition) = (state.t, &state.partition);
    ws.set_state(&state.q, &state.qd);
    model.prescribed(t, &mut ws.q, &mut ws.qd, &mut ws.qdd);
    ws.factor_jacobian(model, partition.dependent(), t)?;
    let quadratures = (state.dissipated, state.driven_work);
    complete_sample(model, partition, ws, t, quadratures, level)
}

/// The sample at the consistent q, q̇ held in `ws` (position level evaluated there).
fn complete_sample<D: Dynamics + ?Sized>(
    model: &D,
    partition: &Partition,
    ws: &mut Workspace,
    t: f64,
    (dissipated, driven_work): (f64, f64),
    level: SampleLevel,
) -> Result<Sample, SimError> {
    let mut sample = Sample {
        t,
        q: ws.q().to_vec(),
        qd: ws.qd().to_vec(),
        qdd: Vec::new(),
        lambda: Vec::new(),
        normal_force: Vec::new(),
        h: Vec::new(),
        contacts: Vec::new(),
        drive: Vec::new(),
        energy: Energy {
            kinetic: f64::NAN,
            gravity: f64::NAN,
            spring: f64::NAN,
        },
        dissipated,
        driven_work,
        dependent: partition.dependent_shared(),
    };
    if level == SampleLevel::State {
        return Ok(sample);
    }
    ws.solve_accelerations(model, partition, t)?;
    ws.solve_multipliers(partition, t)?;
    let info = model.info();
    let mut h = vec![0.0; info.n_constraints()];
    model.constraint(&ws.q, &mut h);
    let mut contacts = vec![ContactGeometry::default(); info.n_contacts()];
    model.contact_geometry(ws.q(), ws.qd(), &mut contacts);
    let lambda = ws.full_lambda();
    sample.normal_force = lambda
        .iter()
        .zip(&contacts)
        .map(|(&l, g)| normal_force(l, g.force_scale))
        .collect();
    sample.qdd = ws.qdd().to_vec();
    sample.lambda = lambda;
    sample.h = h;
    sample.contacts = contacts;
    sample.drive = ws.drive().to_vec();
    sample.energy = model.energy(ws.q(), ws.qd());
    Ok(sample)
}

/// Integrates until `state.t == t_target`, adding the work done to `stats` (also on error).
fn advance<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    t_target: f64,
    settings: &SimSettings,
    stats: &mut Stats,
) -> Result<(), SimError> {
    check_belongs(model, state)?;
    if !state.t.is_finite() {
        return Err(invalid(format!(
            "the state's time t = {} is not finite",
            state.t
        )));
    }
    check_finite_state(state)?;
    if state.modified_since_last_step() {
        state.load_integrated_state();
    }
    let before = all_counters(&state.engine);
    let result = advance_steps(model, state, t_target, settings, stats);
    add_counters_since(stats, &state.engine, before);
    if result.is_err() {
        // The integrated vector may be ahead of the last accepted state (a step whose
        // write-back failed): realign it so that the state can be stepped again.
        state.load_integrated_state();
    }
    result
}

fn advance_steps<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    t_target: f64,
    settings: &SimSettings,
    stats: &mut Stats,
) -> Result<(), SimError> {
    let mut steps = 0;
    while state.t < t_target {
        if steps == MAX_STEPS_PER_CALL {
            return Err(SimError::TooManySteps { t: state.t });
        }
        let t_new = match settings.integrator {
            IntegratorKind::Rk4 => rk4_step(model, state, t_target, settings.dt)?,
            IntegratorKind::Dopri5 | IntegratorKind::Dop853 => {
                adaptive_step(model, state, t_target, settings)?
            }
        };
        if finish_step(model, state, t_new)? {
            stats.repartitions += 1;
        }
        steps += 1;
    }
    Ok(())
}

/// Step of the fixed step `dt`, shortened to land on `t_target`; returns the new time.
pub(crate) fn rk4_step<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    t_target: f64,
    dt: f64,
) -> Result<f64, SimError> {
    let remaining = t_target - state.t;
    let lands = remaining <= dt * (1.0 + LANDING_SLACK);
    // No error control to absorb a looser Newton: the strict test.
    state.engine.ws.set_newton_slack(0.0);
    state.engine.at_step_end = false;
    let h = if lands { remaining } else { dt };
    let Engine {
        ws,
        y,
        rk4,
        dopri,
        dop853,
        ..
    } = &mut state.engine;
    let partition = &state.partition;
    let mut rhs = |t: f64, y: &[f64], dy: &mut [f64]| evaluate_rhs(model, partition, ws, t, y, dy);
    rk4.step(&mut rhs, state.t, y, h)?;
    dopri.invalidate_fsal();
    dop853.invalidate_fsal();
    Ok(if lands { t_target } else { state.t + h })
}

/// One accepted step of the chosen adaptive integrator towards `t_target` (clipped to land
/// on it); returns the new time and keeps the controller's proposal for the next step.
pub(crate) fn adaptive_step<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    t_target: f64,
    settings: &SimSettings,
) -> Result<f64, SimError> {
    let Engine {
        ws,
        y,
        dopri,
        dop853,
        h_next,
        ..
    } = &mut state.engine;
    ws.set_newton_slack(NEWTON_SLACK_PER_RTOL * settings.rtol);
    let parts = StepParts {
        model,
        partition: &state.partition,
        ws,
        y,
        h_next,
    };
    let t_new = if settings.integrator == IntegratorKind::Dop853 {
        parts.step(dop853, state.t, t_target, settings)
    } else {
        parts.step(dopri, state.t, t_target, settings)
    };
    // Both methods end an accepted step with f(t + h, y_new) (first same as last).
    state.engine.at_step_end = t_new.is_ok();
    t_new
}

/// What an adaptive step works on, borrowed from a [`State`].
struct StepParts<'a, D: Dynamics + ?Sized> {
    model: &'a D,
    partition: &'a Partition,
    ws: &'a mut Workspace,
    y: &'a mut Vec<f64>,
    h_next: &'a mut Option<f64>,
}

impl<D: Dynamics + ?Sized> StepParts<'_, D> {
    fn step<I: Adaptive>(
        self,
        integrator: &mut I,
        t: f64,
        t_target: f64,
        settings: &SimSettings,
    ) -> Result<f64, SimError> {
        let remaining = t_target - t;
        let h_wanted = self.h_next.unwrap_or(settings.dt);
        let h_try = clip_to_target(h_wanted, remaining);
        let tolerances = Tolerances {
            rtol: settings.rtol,
            atol: settings.atol,
        };
        let (model, partition, ws) = (self.model, self.partition, self.ws);
        let mut rhs =
            |t: f64, y: &[f64], dy: &mut [f64]| evaluate_rhs(model, partition, ws, t, y, dy);
        let accepted = integrator.step(&mut rhs, t, self.y, h_try, tolerances)?;
        let lands = h_try == remaining && accepted.h == h_try;
        // A step shortened to reach an output time says little about the step the solution
        // allows: resume with the larger of the proposal and the step wanted before clipping.
        *self.h_next = Some(if h_try < h_wanted && accepted.h == h_try {
            accepted.h_next.max(h_wanted)
        } else {
            accepted.h_next
        });
        Ok(if lands { t_target } else { t + accepted.h })
    }
}

/// The counters of a state's integrators (before a phase).
pub(crate) fn phase_counters(state: &State) -> [Counters; 3] {
    all_counters(&state.engine)
}

/// Adds the work a phase did on `state` since `before`.
pub(crate) fn add_phase_counters(stats: &mut Stats, state: &State, before: [Counters; 3]) {
    add_counters_since(stats, &state.engine, before);
}

/// The checks every run makes before it starts.
pub(crate) fn validate_run<D: Dynamics + ?Sized>(
    model: &D,
    state: &State,
    settings: &SimSettings,
) -> Result<(), SimError> {
    check_belongs(model, state)
        .and_then(|()| check_finite_state(state))
        .and_then(|()| validate_integration(settings))
        .and_then(|()| validate_output(settings, state.t))
}

/// The counters of the three integrators of an engine.
pub(crate) fn all_counters(engine: &Engine) -> [Counters; 3] {
    [
        engine.rk4.counters,
        engine.dopri.counters,
        engine.dop853.counters,
    ]
}

/// Adds to `stats` the work the engine's integrators did since `before`.
pub(crate) fn add_counters_since(stats: &mut Stats, engine: &Engine, before: [Counters; 3]) {
    for (after, before) in all_counters(engine).into_iter().zip(before) {
        stats.add_counters(after, before);
    }
}

/// Interpolates y at `t` inside the state's last accepted adaptive step (preparing the
/// interpolant first: DOP853 spends three right-hand sides on it, once per step).
pub(crate) fn interpolate_last_step<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    settings: &SimSettings,
    t: f64,
    out: &mut [f64],
) -> Result<(), SimError> {
    let Engine {
        ws,
        dopri,
        dop853,
        at_step_end,
        ..
    } = &mut state.engine;
    *at_step_end = false;
    let partition = &state.partition;
    let mut rhs = |t: f64, y: &[f64], dy: &mut [f64]| evaluate_rhs(model, partition, ws, t, y, dy);
    if settings.integrator == IntegratorKind::Dop853 {
        dop853.prepare_dense(&mut rhs)?;
        dop853.interpolate(t, out);
    } else {
        dopri.prepare_dense(&mut rhs)?;
        dopri.interpolate(t, out);
    }
    Ok(())
}

/// The step to try: `h` unless the target is within reach (then exactly the remainder) or
/// within two steps (then half the remainder, rather than a full step and a sliver).
fn clip_to_target(h: f64, remaining: f64) -> f64 {
    if remaining <= h * (1.0 + LANDING_SLACK) {
        remaining
    } else if remaining < 2.0 * h {
        0.5 * remaining
    } else {
        h
    }
}

/// The right-hand side on y = (u, u̇, dissipated, driven work): Newton (15), velocities
/// (16), reduced dynamics (17, 18), drive loads when there are driven coordinates.
fn evaluate_rhs<D: Dynamics + ?Sized>(
    model: &D,
    partition: &Partition,
    ws: &mut Workspace,
    t: f64,
    y: &[f64],
    dy: &mut [f64],
) -> Result<(), SimError> {
    let nu = partition.independent().len();
    load_state(model, partition, ws, t, y)?;
    ws.solve_accelerations(model, partition, t)?;
    let drive_power = if partition.driven().is_empty() {
        0.0
    } else {
        ws.solve_multipliers(partition, t)?;
        ws.drive_power(partition)
    };
    for (a, &u) in partition.independent().iter().enumerate() {
        dy[a] = ws.qd[u];
        dy[nu + a] = ws.qdd[u];
    }
    dy[2 * nu] = model.damper_power(ws.qd());
    dy[2 * nu + 1] = drive_power + model.load_power(t, ws.q(), ws.qd());
    let nc = partition.dependent().len();
    for (k, &v) in partition.dependent().iter().enumerate() {
        dy[2 * nu + 2 + k] = ws.qd[v];
        dy[2 * nu + 2 + nc + k] = ws.qdd[v];
    }
    if !dy[2 * nu].is_finite() {
        return Err(ws.non_finite(t, "damper power"));
    }
    Ok(())
}

/// Full q, q̇ at (t, y): prescribed motion, u and u̇ from y, v by Newton (15) and v̇ by
/// (16). Leaves J(q) evaluated and J_v factored in the workspace.
pub(crate) fn load_state<D: Dynamics + ?Sized>(
    model: &D,
    partition: &Partition,
    ws: &mut Workspace,
    t: f64,
    y: &[f64],
) -> Result<(), SimError> {
    let nu = partition.independent().len();
    model.prescribed(t, &mut ws.q, &mut ws.qd, &mut ws.qdd);
    for (a, &u) in partition.independent().iter().enumerate() {
        ws.q[u] = y[a];
        ws.qd[u] = y[nu + a];
    }
    let nc = partition.dependent().len();
    for (k, &v) in partition.dependent().iter().enumerate() {
        // The integrated v (uncontrolled, see `State`) is Newton's starting point.
        ws.q[v] = y[2 * nu + 2 + k];
    }
    if nc == 0 {
        ws.factor_jacobian(model, partition.dependent(), t)?;
    } else {
        // Newton ends with h, J, the cache and the factored J_v of the returned q.
        solve_positions_with_restart(model, partition.dependent(), ws, t)?;
        ws.polish_positions(partition.dependent());
    }
    ws.solve_velocities(partition.dependent());
    Ok(())
}

/// Newton (15) from the last evaluation's v; if that fails (e.g. after an overshooting
/// trial stage), once more from v at the last accepted step.
fn solve_positions_with_restart<D: Dynamics + ?Sized>(
    model: &D,
    dependent: &[usize],
    ws: &mut Workspace,
    t: f64,
) -> Result<(), SimError> {
    if dependent.is_empty() || ws.solve_positions(model, dependent, t).is_ok() {
        return Ok(());
    }
    for (k, &v) in dependent.iter().enumerate() {
        ws.q[v] = ws.v_anchor[k];
    }
    ws.solve_positions(model, dependent, t).map(|_| ())
}

/// After an accepted step: writes t, q, q̇ and the quadratures back to the state, then
/// re-chooses the dependent coordinates if the partition's conditioning fell below
/// [`REPARTITION_RATIO`]. Returns true on a re-partition.
pub(crate) fn finish_step<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    t_new: f64,
) -> Result<bool, SimError> {
    let nu = state.partition.independent().len();
    let Engine {
        ws, y, at_step_end, ..
    } = &mut state.engine;
    if !std::mem::replace(at_step_end, false) {
        load_state(model, &state.partition, ws, t_new, y)?;
    }
    state.t = t_new;
    state.q.copy_from_slice(ws.q());
    state.qd.copy_from_slice(ws.qd());
    state.dissipated = y[2 * nu];
    state.driven_work = y[2 * nu + 1];
    // Re-anchor the integrated v, v̇ on the solved values (they only predict).
    store_dependent(&state.partition, y, ws.q(), ws.qd());
    let repartitioned = repartition_if_needed(model, state);
    if repartitioned {
        state.load_integrated_state();
    } else {
        state.set_newton_anchor();
        state.remember_synced();
    }
    Ok(repartitioned)
}

/// Switches to the best-conditioned dependent set when the current one's conditioning is
/// below [`REPARTITION_RATIO`] and the new one is better. Uses J at the current q.
fn repartition_if_needed<D: Dynamics + ?Sized>(model: &D, state: &mut State) -> bool {
    let n = model.info().n();
    let ws = &state.engine.ws;
    let nc = ws.rows().len();
    let (jacobian, partition) = (&ws.jacobian, &state.partition);
    let eligible = partition.eligible();
    let current = conditioning(jacobian, nc, n, partition.dependent(), eligible);
    if current >= REPARTITION_RATIO {
        return false;
    }
    if ws.m() > nc {
        return reselect_rows(state, current, model.info().n_contacts());
    }
    let Some(better) = choose_dependent(jacobian, nc, n, eligible) else {
        return false;
    };
    let improves = conditioning(jacobian, nc, n, &better, eligible) > current;
    improves && better != partition.dependent() && state.partition.set_dependent(&better).is_ok()
}

/// With redundant rows left out: re-chooses the solved rows and the dependent coordinates
/// together from the full J (as many as before), when that improves the conditioning.
fn reselect_rows(state: &mut State, current: f64, contacts: usize) -> bool {
    let ws = &state.engine.ws;
    let (n, m, nc) = (ws.n_coordinates(), ws.m(), ws.rows().len());
    let eligible = state.partition.eligible().to_vec();
    let (rows, columns) =
        independent_rows(ws.full_jacobian(), m, n, &eligible, ws.jacobian_floor());
    let unchanged = rows == ws.rows() && columns == state.partition.dependent();
    // Only loop equations may be left out (a contact's row is never redundant).
    if rows.len() != nc || unchanged || (0..contacts).any(|k| !rows.contains(&k)) {
        return false;
    }
    let mut gathered = vec![0.0; nc * n];
    for (k, &row) in rows.iter().enumerate() {
        gathered[k * n..(k + 1) * n].copy_from_slice(&ws.full_jacobian()[row * n..(row + 1) * n]);
    }
    if conditioning(&gathered, nc, n, &columns, &eligible) <= current {
        return false;
    }
    if state.partition.set_dependent(&columns).is_err() {
        return false;
    }
    state.engine.ws.reselect_rows(&rows);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{
        ContactKinematics, CoordinateInfo, CoordinateKind, InitialGuess, ModelInfo,
    };
    use nalgebra::{DMatrix, DVector};

    const G: f64 = 9.81;

    fn settings(
        integrator: IntegratorKind,
        t_end: f64,
        dt_out: f64,
        dt: f64,
        rtol: f64,
    ) -> SimSettings {
        SimSettings {
            t_end,
            dt_out,
            integrator,
            dt,
            rtol,
            atol: rtol * 1e-2,
        }
    }

    fn coordinate(name: &str, kind: CoordinateKind, driven: bool) -> CoordinateInfo {
        CoordinateInfo {
            name: name.to_string(),
            kind,
            driven,
        }
    }

    /// A knife edge at `point` on a ground cam y = f(x) with f′ = `slope`, f″ = `second`.
    fn on_ground_cam(point: [f64; 2], slope: f64, second: f64) -> ContactGeometry {
        let stretch = (1.0 + slope * slope).sqrt();
        ContactGeometry {
            position: [point[0], point[1], 0.0],
            x: point[0],
            y: point[1],
            follower: [point[0], point[1], 0.0],
            normal: [-slope / stretch, 1.0 / stretch, 0.0],
            force_scale: stretch,
            parameter: point[0],
            curvature: second / stretch.powi(3),
            ..ContactGeometry::default()
        }
    }

    fn model_info(
        name: &str,
        coordinates: Vec<CoordinateInfo>,
        contacts: usize,
        initial: InitialGuess,
    ) -> ModelInfo {
        ModelInfo {
            name: name.to_string(),
            description: String::new(),
            coordinates,
            contacts: (0..contacts)
                .map(|k| crate::ContactInfo::knife(&format!("tip{k}")))
                .collect(),
            loops: Vec::new(),
            spatial: false,
            initial,
            defaults: settings(IntegratorKind::Dopri5, 1.0, 0.1, 1e-3, 1e-9),
            restitution: None,
            parameters: Vec::new(),
        }
    }

    // ------------------------------------------------------------------------------------
    // A bead of mass m on a wire y = f(x) in the vertical plane: coordinates (x, y), both
    // prismatic; M = m I, F = 0, Q = (c ẋ, m g + c ẏ); h = y − f(x), J = (−f', 1),
    // c = −f'' ẋ².

    #[derive(Debug, Clone, Copy)]
    enum Curve {
        /// y = a x².
        Parabola(f64),
        /// y = √(r² − x²): the upper half of a circle of radius r.
        UpperCircle(f64),
        /// y = 1 − x².
        Cap,
        /// y = atan x: Newton on x diverges from |x| ≳ 1.39.
        Arctan,
    }

    impl Curve {
        /// (f, f', f'') at x.
        fn eval(self, x: f64) -> (f64, f64, f64) {
            match self {
                Curve::Parabola(a) => (a * x * x, 2.0 * a * x, 2.0 * a),
                Curve::UpperCircle(r) => {
                    let y = (r * r - x * x).sqrt();
                    (y, -x / y, -r * r / (y * y * y))
                }
                Curve::Cap => (1.0 - x * x, -2.0 * x, -2.0),
                Curve::Arctan => {
                    let stretch = 1.0 + x * x;
                    (x.atan(), 1.0 / stretch, -2.0 * x / (stretch * stretch))
                }
            }
        }
    }

    struct Bead {
        info: ModelInfo,
        mass: f64,
        gravity: f64,
        damping: f64,
        curve: Curve,
        /// y is driven: 0 until t = 0.5, then 2 (out of reach of the cap y = 1 − x²).
        lifted: bool,
    }

    impl Bead {
        fn new(curve: Curve, x0: f64, xd0: f64) -> Self {
            let (y0, _, _) = curve.eval(x0);
            let initial = InitialGuess {
                q: vec![x0, y0 + 0.05],
                qd: vec![xd0, 0.0],
                hold: vec![true, false],
                given_q: vec![true; 2],
                given_qd: vec![true; 2],
            };
            let coordinates = vec![
                coordinate("x", CoordinateKind::Prismatic, false),
                coordinate("y", CoordinateKind::Prismatic, false),
            ];
            let info = model_info("bead", coordinates, 1, initial);
            Self {
                info,
                mass: 2.0,
                gravity: G,
                damping: 0.0,
                curve,
                lifted: false,
            }
        }

        fn lifted(x0: f64) -> Self {
            let mut bead = Self::new(Curve::Cap, x0, 0.0);
            bead.lifted = true;
            bead.info.coordinates[1].driven = true;
            bead.info.initial.hold = vec![false, false];
            bead
        }
    }

    impl Dynamics for Bead {
        fn info(&self) -> &ModelInfo {
            &self.info
        }
        fn mass_matrix(&self, _q: &[f64], m: &mut [f64]) {
            m.copy_from_slice(&[self.mass, 0.0, 0.0, self.mass]);
        }
        fn inertial_forces(&self, _q: &[f64], _qd: &[f64], f: &mut [f64]) {
            f.fill(0.0);
        }
        fn applied_forces(&self, _t: f64, _q: &[f64], qd: &[f64], out: &mut [f64]) {
            out[0] = self.damping * qd[0];
            out[1] = self.mass * self.gravity + self.damping * qd[1];
        }
        fn constraint(&self, q: &[f64], h: &mut [f64]) {
            h[0] = q[1] - self.curve.eval(q[0]).0;
        }
        fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
            j[0] = -self.curve.eval(q[0]).1;
            j[1] = 1.0;
        }
        fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
            c[0] = -self.curve.eval(q[0]).2 * qd[0] * qd[0];
        }
        fn contact_geometry(&self, q: &[f64], _qd: &[f64], out: &mut [ContactGeometry]) {
            let (_, slope, curvature) = self.curve.eval(q[0]);
            out[0] = on_ground_cam([q[0], q[1]], slope, curvature);
        }
        fn contact_kinematics_into(
            &self,
            q: &[f64],
            _qd: &[f64],
            _k: usize,
            out: &mut ContactKinematics,
        ) {
            let mut geometry = [ContactGeometry::default()];
            self.contact_geometry(q, _qd, &mut geometry);
            *out = ContactKinematics {
                geometry: geometry[0],
                x: q[0],
                y: q[1],
                j1: vec![1.0, 0.0],
                j2: vec![0.0, 1.0],
                conv1: 0.0,
                conv2: 0.0,
            };
        }
        fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
            if self.lifted {
                q[1] = if t > 0.5 { 2.0 } else { 0.0 };
                qd[1] = 0.0;
                qdd[1] = 0.0;
            }
        }
        fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
            let kinetic = 0.5 * self.mass * (qd[0] * qd[0] + qd[1] * qd[1]);
            Energy {
                kinetic,
                gravity: self.mass * self.gravity * q[1],
                spring: 0.0,
            }
        }
        fn damper_power(&self, qd: &[f64]) -> f64 {
            self.damping * (qd[0] * qd[0] + qd[1] * qd[1])
        }
    }

    // ------------------------------------------------------------------------------------
    // A two-link arm of point masses on a slider: coordinates (s, θ1, θ2); the base moves
    // along `axis` (s), link 1 has absolute angle θ1, link 2 relative angle θ2. Point masses
    // m0 at the base, m1 at the elbow, m2 at the tip. M = Σ m_k J_kᵀ J_k,
    // F = Σ m_k J_kᵀ (J̇_k q̇), Q = Σ m_k g J_k,yᵀ + (0, 0, k θ2 + c θ̇2). Optional contact of
    // the tip with the cam y = Σ c_i x^i; optional drive s(t) = A sin(ω t).

    const L1: f64 = 0.6;
    const L2: f64 = 0.5;
    const MASSES: [f64; 3] = [1.0, 0.8, 0.5];

    struct Arm {
        info: ModelInfo,
        axis: [f64; 2],
        gravity: f64,
        stiffness: f64,
        damping: f64,
        cam: Option<[f64; 4]>,
        drive: Option<(f64, f64)>,
    }

    /// Positions, Jacobians (2×3) and convective accelerations J̇ q̇ of the three masses.
    struct Points {
        position: [[f64; 2]; 3],
        jacobian: [[[f64; 3]; 2]; 3],
        convective: [[f64; 2]; 3],
    }

    impl Arm {
        fn new(cam: bool, drive: bool) -> Self {
            let coordinates = vec![
                coordinate("s", CoordinateKind::Prismatic, drive),
                coordinate("th1", CoordinateKind::Revolute, false),
                coordinate("th2", CoordinateKind::Revolute, false),
            ];
            let initial = InitialGuess {
                q: vec![0.0, -std::f64::consts::FRAC_PI_2 + 0.3, 0.4],
                qd: vec![0.3, 0.5, 0.0],
                hold: vec![true, true, false],
                given_q: vec![true; 3],
                given_qd: vec![true; 3],
            };
            let info = model_info("arm", coordinates, usize::from(cam), initial);
            Self {
                info,
                axis: [1.0, 0.0],
                gravity: G,
                stiffness: 0.0,
                damping: 0.0,
                cam: cam.then_some([-0.9, 0.0, 0.3, 0.0]),
                drive: drive.then_some((0.2, 2.0)),
            }
        }

        fn with_spring_damper(mut self, stiffness: f64, damping: f64) -> Self {
            self.stiffness = stiffness;
            self.damping = damping;
            self
        }

        fn points(&self, q: &[f64], qd: &[f64]) -> Points {
            let [ax, ay] = self.axis;
            let (a1, a12) = (q[1], q[1] + q[2]);
            let (w1, w12) = (qd[1], qd[1] + qd[2]);
            let base = [q[0] * ax, q[0] * ay];
            let elbow = [base[0] + L1 * a1.cos(), base[1] + L1 * a1.sin()];
            let tip = [elbow[0] + L2 * a12.cos(), elbow[1] + L2 * a12.sin()];
            let elbow_conv = [-L1 * a1.cos() * w1 * w1, -L1 * a1.sin() * w1 * w1];
            let tip_conv = [
                elbow_conv[0] - L2 * a12.cos() * w12 * w12,
                elbow_conv[1] - L2 * a12.sin() * w12 * w12,
            ];
            let (s1, c1, s12, c12) = (L1 * a1.sin(), L1 * a1.cos(), L2 * a12.sin(), L2 * a12.cos());
            Points {
                position: [base, elbow, tip],
                jacobian: [
                    [[ax, 0.0, 0.0], [ay, 0.0, 0.0]],
                    [[ax, -s1, 0.0], [ay, c1, 0.0]],
                    [[ax, -s1 - s12, -s12], [ay, c1 + c12, c12]],
                ],
                convective: [[0.0, 0.0], elbow_conv, tip_conv],
            }
        }

        /// (f3, f3', f3'') of the cam at x.
        fn cam_at(&self, x: f64) -> (f64, f64, f64) {
            let c = self.cam.unwrap_or_default();
            let f = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
            let slope = c[1] + x * (2.0 * c[2] + 3.0 * x * c[3]);
            (f, slope, 2.0 * c[2] + 6.0 * x * c[3])
        }
    }

    fn row_dot(row: &[f64; 3], x: &[f64]) -> f64 {
        row.iter().zip(x).map(|(a, b)| a * b).sum()
    }

    impl Dynamics for Arm {
        fn info(&self) -> &ModelInfo {
            &self.info
        }
        fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {
            let p = self.points(q, &[0.0; 3]);
            m.fill(0.0);
            for (k, mass) in MASSES.iter().enumerate() {
                for row in &p.jacobian[k] {
                    for i in 0..3 {
                        for j in 0..3 {
                            m[i * 3 + j] += mass * row[i] * row[j];
                        }
                    }
                }
            }
        }
        fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {
            let p = self.points(q, qd);
            f.fill(0.0);
            for (k, mass) in MASSES.iter().enumerate() {
                for (row, conv) in p.jacobian[k].iter().zip(p.convective[k]) {
                    for i in 0..3 {
                        f[i] += mass * row[i] * conv;
                    }
                }
            }
        }
        fn applied_forces(&self, _t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
            let p = self.points(q, qd);
            for (i, o) in out.iter_mut().enumerate() {
                *o = (0..3)
                    .map(|k| MASSES[k] * self.gravity * p.jacobian[k][1][i])
                    .sum();
            }
            out[2] += self.stiffness * q[2] + self.damping * qd[2];
        }
        fn constraint(&self, q: &[f64], h: &mut [f64]) {
            if let Some(h) = h.first_mut() {
                let tip = self.points(q, &[0.0; 3]).position[2];
                *h = tip[1] - self.cam_at(tip[0]).0;
            }
        }
        fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
            if self.cam.is_some() {
                let p = self.points(q, &[0.0; 3]);
                let slope = self.cam_at(p.position[2][0]).1;
                let [j1, j2] = p.jacobian[2];
                for i in 0..3 {
                    j[i] = j2[i] - slope * j1[i];
                }
            }
        }
        fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
            if let Some(c) = c.first_mut() {
                let p = self.points(q, qd);
                let (_, slope, curvature) = self.cam_at(p.position[2][0]);
                let [conv1, conv2] = p.convective[2];
                let x_rate = row_dot(&p.jacobian[2][0], qd);
                *c = conv2 - slope * conv1 - curvature * x_rate * x_rate;
            }
        }
        fn contact_geometry(&self, q: &[f64], _qd: &[f64], out: &mut [ContactGeometry]) {
            if let Some(out) = out.first_mut() {
                let [x, y] = self.points(q, &[0.0; 3]).position[2];
                let (_, slope, curvature) = self.cam_at(x);
                *out = on_ground_cam([x, y], slope, curvature);
            }
        }
        fn contact_kinematics_into(
            &self,
            q: &[f64],
            qd: &[f64],
            _k: usize,
            out: &mut ContactKinematics,
        ) {
            let p = self.points(q, qd);
            let mut geometry = [ContactGeometry::default()];
            self.contact_geometry(q, qd, &mut geometry);
            *out = ContactKinematics {
                geometry: geometry[0],
                x: p.position[2][0],
                y: p.position[2][1],
                j1: p.jacobian[2][0].to_vec(),
                j2: p.jacobian[2][1].to_vec(),
                conv1: p.convective[2][0],
                conv2: p.convective[2][1],
            };
        }
        fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
            if let Some((amplitude, omega)) = self.drive {
                q[0] = amplitude * (omega * t).sin();
                qd[0] = amplitude * omega * (omega * t).cos();
                qdd[0] = -amplitude * omega * omega * (omega * t).sin();
            }
        }
        fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
            let p = self.points(q, qd);
            let mut energy = Energy {
                spring: 0.5 * self.stiffness * q[2] * q[2],
                ..Energy::default()
            };
            for (k, mass) in MASSES.iter().enumerate() {
                let [vx, vy] = p.jacobian[k].map(|row| row_dot(&row, qd));
                energy.kinetic += 0.5 * mass * (vx * vx + vy * vy);
                energy.gravity += mass * self.gravity * p.position[k][1];
            }
            energy
        }
        fn damper_power(&self, qd: &[f64]) -> f64 {
            self.damping * qd[2] * qd[2]
        }
    }

    // ------------------------------------------------------------------------------------
    // The independent route: the full system
    //   [M    Jᵀ  −E_d] [q̈ ]   [−F − Q]
    //   [J    0    0  ] [λ ] = [−c    ]
    //   [E_dᵀ 0    0  ] [τ_d]  [q̈_d   ]
    // solved by nalgebra's LU. Returns (q̈, λ, τ with zeros on free coordinates).

    fn full_system<D: Dynamics>(
        model: &D,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let info = model.info();
        let (n, nc) = (info.n(), info.n_constraints());
        let driven: Vec<usize> = (0..n).filter(|&i| info.coordinates[i].driven).collect();
        let (mut m, mut f, mut applied) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
        let (mut j, mut c) = (vec![0.0; nc * n], vec![0.0; nc]);
        let (mut qp, mut qdp, mut qdd_d) = (q.to_vec(), qd.to_vec(), vec![0.0; n]);
        model.prescribed(t, &mut qp, &mut qdp, &mut qdd_d);
        model.mass_matrix(q, &mut m);
        model.inertial_forces(q, qd, &mut f);
        model.applied_forces(t, q, qd, &mut applied);
        model.constraint_jacobian(q, &mut j);
        model.constraint_bias(q, qd, &mut c);
        let size = n + nc + driven.len();
        let mut system = DMatrix::zeros(size, size);
        let mut rhs = DVector::zeros(size);
        for i in 0..n {
            for k in 0..n {
                system[(i, k)] = m[i * n + k];
            }
            rhs[i] = -f[i] - applied[i];
            for k in 0..nc {
                system[(i, n + k)] = j[k * n + i];
                system[(n + k, i)] = j[k * n + i];
            }
        }
        for k in 0..nc {
            rhs[n + k] = -c[k];
        }
        for (e, &d) in driven.iter().enumerate() {
            system[(d, n + nc + e)] = -1.0;
            system[(n + nc + e, d)] = 1.0;
            rhs[n + nc + e] = qdd_d[d];
        }
        let x = system.lu().solve(&rhs).expect("the full system is regular");
        let mut tau = vec![0.0; n];
        for (e, &d) in driven.iter().enumerate() {
            tau[d] = x[n + nc + e];
        }
        (
            x.as_slice()[..n].to_vec(),
            x.as_slice()[n..n + nc].to_vec(),
            tau,
        )
    }

    fn max_difference(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    fn run<D: Dynamics>(model: &D, settings: &SimSettings) -> Trajectory {
        let state = model.assemble(0.0).unwrap();
        model.simulate(state, settings).unwrap()
    }

    fn dopri(t_end: f64, rtol: f64) -> SimSettings {
        settings(IntegratorKind::Dopri5, t_end, 0.05, 1e-3, rtol)
    }

    fn rk4(t_end: f64, dt: f64) -> SimSettings {
        settings(IntegratorKind::Rk4, t_end, 0.05, dt, 1e-9)
    }

    fn arms() -> Vec<Arm> {
        vec![
            Arm::new(true, false),
            Arm::new(true, false).with_spring_damper(5.0, 0.3),
            Arm::new(true, true).with_spring_damper(5.0, 0.3),
            Arm::new(false, false),
            Arm::new(false, true),
        ]
    }

    #[test]
    fn partitioned_accelerations_match_the_full_system() {
        // Both routes solve the same linear equations at the same state; the saddle-point
        // system is well conditioned here (entries of order 1, κ ≲ 10³), so they agree to
        // round-off: 1e-10 relative is ≥ 100 times the expected discrepancy.
        for arm in arms() {
            let trajectory = run(&arm, &dopri(1.0, 1e-9));
            for sample in &trajectory.samples {
                let (qdd, lambda, tau) = full_system(&arm, sample.t, &sample.q, &sample.qd);
                let scale = 1.0
                    + qdd
                        .iter()
                        .chain(&lambda)
                        .chain(&tau)
                        .fold(0.0_f64, |m, x| m.max(x.abs()));
                assert!(
                    max_difference(&sample.qdd, &qdd) < 1e-10 * scale,
                    "t = {}",
                    sample.t
                );
                assert!(
                    max_difference(&sample.lambda, &lambda) < 1e-10 * scale,
                    "t = {}",
                    sample.t
                );
                assert!(
                    max_difference(&sample.drive, &tau) < 1e-10 * scale,
                    "t = {}",
                    sample.t
                );
            }
        }
    }

    #[test]
    fn constraint_holds_along_a_run() {
        // Every stored state went through Newton (15) to |h| ≤ 1e-12 and J q̇ = 0 (16) by a
        // direct solve; 1e-10 leaves a margin of 100 for h and for round-off in J q̇.
        for arm in arms().into_iter().filter(|arm| arm.cam.is_some()) {
            for settings in [dopri(2.0, 1e-8), rk4(2.0, 2e-3)] {
                let trajectory = run(&arm, &settings);
                assert_eq!(trajectory.samples.len(), 41);
                for sample in &trajectory.samples {
                    assert!(
                        sample.h[0].abs() < 1e-10,
                        "h = {} at t = {}",
                        sample.h[0],
                        sample.t
                    );
                    let mut j = [0.0; 3];
                    arm.constraint_jacobian(&sample.q, &mut j);
                    let velocity = row_dot(&j, &sample.qd);
                    assert!(
                        velocity.abs() < 1e-10,
                        "J q̇ = {velocity} at t = {}",
                        sample.t
                    );
                }
            }
        }
    }

    /// max_t |E(t) − E(0) − W_drive(t) + D(t)|: zero for exact solutions.
    fn energy_balance_error(trajectory: &Trajectory) -> f64 {
        let first = trajectory.samples[0].energy.total();
        trajectory
            .samples
            .iter()
            .map(|s| (s.energy.total() - first - s.driven_work + s.dissipated).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn energy_is_conserved_without_damping() {
        // Energies here are O(10) J. With rtol = 1e-10 the local error is ~1e-10 relative
        // per step; over ~500 steps the drift stays ≲ 1e-8 J (measured: bead 2.3e-9 J,
        // arms 1–2e-10 J). Bound: 1e-7 J, i.e. 1e-8 relative. The bead and the arm on the
        // cam also re-partition once on the way (see `repartition_…`), which must not
        // disturb the balance.
        let bead = Bead::new(Curve::Parabola(0.5), 1.0, 0.0);
        let trajectory = run(&bead, &dopri(5.0, 1e-10));
        assert!(
            energy_balance_error(&trajectory) < 1e-7,
            "bead: {}",
            energy_balance_error(&trajectory)
        );
        for arm in [Arm::new(true, false), Arm::new(false, false)] {
            let trajectory = run(&arm, &dopri(3.0, 1e-10));
            let error = energy_balance_error(&trajectory);
            assert!(
                error < 1e-7,
                "arm with {} contacts: {error}",
                arm.info.n_contacts()
            );
        }
    }

    #[test]
    fn energy_balance_holds_with_drive_and_damper() {
        // E(t) − E(0) = W_drive − D, with W_drive and D integrated as quadratures of Σ τ_d q̇_d
        // and Σ c q̇² alongside the motion. The quadratures are not error-controlled but use
        // the same fifth-order stages; with rtol = 1e-10 the balance closes to 7e-11 J
        // (measured); bound 1e-8 J against energies of O(10) J and works of O(0.1–1) J.
        for arm in [Arm::new(true, true), Arm::new(false, true)] {
            let arm = arm.with_spring_damper(5.0, 0.3);
            let trajectory = run(&arm, &dopri(3.0, 1e-10));
            let last = trajectory.samples.last().unwrap();
            assert!(last.dissipated > 1e-3 && last.driven_work.abs() > 1e-3);
            let error = energy_balance_error(&trajectory);
            assert!(
                error < 1e-8,
                "arm with {} contacts: {error}",
                arm.info.n_contacts()
            );
        }
    }

    /// N = m (g cos θ + v² κ) for a bead on y = f(x): cos θ = 1/√(1 + f'²), signed curvature
    /// κ = f''/(1 + f'²)^{3/2}, speed² v² = ẋ² + ẏ².
    fn closed_form_normal_force(bead: &Bead, q: &[f64], qd: &[f64]) -> f64 {
        let (_, slope, second) = bead.curve.eval(q[0]);
        let stretch = (1.0 + slope * slope).sqrt();
        let speed2 = qd[0] * qd[0] + qd[1] * qd[1];
        bead.mass * (bead.gravity / stretch + speed2 * second / stretch.powi(3))
    }

    #[test]
    fn normal_force_matches_the_closed_form() {
        // At the bottom of y = a x² with speed v: N = m (g + 2 a v²). The closed form and
        // the multiplier are evaluated at the same state, along the whole run too, so they
        // agree to round-off (measured 6e-16 relative); bound 1e-12 relative.
        let bead = Bead::new(Curve::Parabola(0.5), 0.0, 3.0);
        let state = bead.assemble(0.0).unwrap();
        let sample = bead.sample(&state).unwrap();
        let expected = bead.mass * (G + 2.0 * 0.5 * 9.0);
        assert!((sample.normal_force[0] - expected).abs() < 1e-12 * expected);
        let trajectory = bead.simulate(state, &dopri(3.0, 1e-9)).unwrap();
        for sample in &trajectory.samples {
            let expected = closed_form_normal_force(&bead, &sample.q, &sample.qd);
            assert!(
                (sample.normal_force[0] - expected).abs() < 1e-12 * expected,
                "t = {}",
                sample.t
            );
        }
    }

    /// A bead going over the top of a circle of radius 1: starts at x = 0.9 on the right
    /// flank moving up-left at 4 m/s, passes the top (where J_x = −f' = 0) near t ≈ 0.3 s.
    fn circle_bead() -> Bead {
        let slope = Curve::UpperCircle(1.0).eval(0.9).1;
        Bead::new(
            Curve::UpperCircle(1.0),
            0.9,
            -4.0 / (1.0 + slope * slope).sqrt(),
        )
    }

    #[test]
    fn repartition_passes_a_vanishing_pivot_smoothly() {
        let bead = circle_bead();
        let t_end = 0.6;
        let settings = dopri(t_end, 1e-10);
        let automatic = bead.assemble(0.0).unwrap();
        assert_eq!(
            automatic.dependent(),
            &[0],
            "x has the larger |J_i| on the flank"
        );
        let mut imposed = automatic.clone();
        imposed.set_dependent(&[1]).unwrap();
        let first = bead.simulate(automatic, &settings).unwrap();
        let second = bead.simulate(imposed, &settings).unwrap();

        assert_eq!(first.stats.repartitions, 1);
        assert_eq!(second.stats.repartitions, 0);
        let (a, b) = (
            first.samples.last().unwrap(),
            second.samples.last().unwrap(),
        );
        assert_eq!(a.dependent[..], [1]);
        assert!(a.q[0] < -0.3, "the bead is past the top: x = {}", a.q[0]);
        // The runs integrate different coordinates (x, then y, against y throughout), so
        // they differ by the sum of their global errors: ~10·rtol each over ~100 steps
        // (measured difference 1.2e-9 on q and q̇). Bound 1e-8: ten times the measurement,
        // yet a mishandled switch (a lost FSAL restart, stale u) would show at 1e-4 or more.
        for (sa, sb) in first.samples.iter().zip(&second.samples) {
            assert!(max_difference(&sa.q, &sb.q) < 1e-8, "t = {}", sa.t);
            assert!(max_difference(&sa.qd, &sb.qd) < 1e-8, "t = {}", sa.t);
            assert!(sa.h[0].abs() < 1e-10);
        }
        assert!(energy_balance_error(&first) < 1e-7);
        let rk4_run = run(&bead, &rk4(t_end, 1e-3));
        assert_eq!(rk4_run.stats.repartitions, 1);
        // RK4 with h = 1e-3: global error ~ C h⁴ with C ~ 10² for these derivatives
        // (measured difference 5e-10); bound 1e-8.
        assert!(max_difference(&rk4_run.samples.last().unwrap().q, &b.q) < 1e-8);
    }

    #[test]
    fn unreachable_cam_gives_newton_failed_with_time_and_state() {
        // y is lifted from 0 to 2 at t = 0.5; the cap y = 1 − x² never exceeds 1.
        let bead = Bead::lifted(0.8);
        let state = bead.assemble(0.0).unwrap();
        assert!(
            (state.q[0] - 1.0).abs() < 1e-12,
            "x solved onto the cap: {}",
            state.q[0]
        );
        for settings in [rk4(1.0, 0.01), dopri(1.0, 1e-8)] {
            let failure = bead.simulate(state.clone(), &settings).unwrap_err();
            let SimError::NewtonFailed {
                t,
                ref q,
                residual,
                iterations,
            } = failure.error
            else {
                panic!("expected NewtonFailed, got {}", failure.error);
            };
            assert!(t > 0.5 && t < 0.51, "t = {t}");
            assert_eq!(q[1], 2.0);
            assert!(q.iter().all(|x| x.is_finite()) && residual > 1e-3);
            assert!(iterations <= crate::partition::NEWTON_MAX_ITERATIONS);
            assert!(
                failure.to_string().contains("cannot reach the cam"),
                "{failure}"
            );
            // RK4 lands on the output time 0.5 where the point leaves the cap; Dopri5 steps
            // freely and its steps shrink onto that point: the last accepted state is kept
            // as the final sample, within round-off steps of 0.5.
            let last = failure.partial.samples.last().unwrap();
            assert!((last.t - 0.5).abs() < 1e-9, "last sample at {}", last.t);
            assert_eq!(failure.partial.samples.len(), 11);
        }
    }

    #[test]
    fn assembly_falls_back_to_damped_newton() {
        // y held at 0, x solved from atan x = 0 starting at x = 2, where plain Newton
        // diverges (x ← x − (1 + x²) atan x overshoots to −3.5, then further out).
        let mut bead = Bead::new(Curve::Arctan, 2.0, 0.0);
        bead.info.initial.q = vec![2.0, 0.0];
        bead.info.initial.hold = vec![false, true];
        let mut ws = Workspace::new(2, 1, 0);
        ws.set_state(&[2.0, 0.0], &[0.0, 0.0]);
        assert!(ws.solve_positions(&bead, &[0], 0.0).is_err());
        let state = bead.assemble(0.0).unwrap();
        // Converged to |h| ≤ 1e-12 with |J_x| = 1 at the root: |x| ≤ ~1e-12.
        assert!(
            state.q[0].abs() < 1e-11 && state.q[1] == 0.0,
            "{:?}",
            state.q
        );
    }

    #[test]
    fn non_finite_forces_are_reported_not_propagated() {
        let mut bead = Bead::new(Curve::Parabola(0.5), 0.5, 0.0);
        bead.gravity = f64::NAN;
        let state = bead.assemble(0.0).unwrap();
        let failure = bead.simulate(state, &dopri(1.0, 1e-8)).unwrap_err();
        assert!(
            matches!(
                failure.error,
                SimError::NonFinite {
                    quantity: "q̈", ..
                }
            ),
            "{}",
            failure.error
        );
        assert!(failure.partial.samples.is_empty());
    }

    #[test]
    fn chains_without_contact_are_plain_odes() {
        let arm = Arm::new(false, false);
        let state = arm.assemble(0.0).unwrap();
        assert!(state.dependent().is_empty());
        assert_eq!(state.independent(), &[0, 1, 2]);
        let trajectory = arm.simulate(state, &dopri(1.0, 1e-9)).unwrap();
        let sample = trajectory.samples.last().unwrap();
        assert!(sample.lambda.is_empty() && sample.h.is_empty() && sample.contacts.is_empty());
        assert_eq!(sample.drive, vec![0.0; 3]);
    }

    #[test]
    fn integrators_agree() {
        // RK4 with h = 1e-3 (global error ~ C h⁴, measured difference 2e-12) against
        // Dopri5 with rtol = 1e-11: bound 1e-9, which an order or landing mistake in either
        // integrator (errors ~h³ = 1e-9·C or worse) would exceed.
        let arm = Arm::new(true, true).with_spring_damper(5.0, 0.3);
        let fine = run(&arm, &dopri(1.0, 1e-11));
        let fixed = run(&arm, &rk4(1.0, 1e-3));
        let (a, b) = (fine.samples.last().unwrap(), fixed.samples.last().unwrap());
        assert!(max_difference(&a.q, &b.q) < 1e-9, "{:?} vs {:?}", a.q, b.q);
        assert_eq!(fixed.stats.rhs_evaluations, 4 * fixed.stats.steps);
        assert_eq!(fixed.stats.steps, 1000);
    }

    #[test]
    fn fixed_steps_stay_fixed_late_in_a_long_run() {
        // At t ≈ 1000 s each t + h rounds by up to ulp(1000)/2 ≈ 6e-14 s, which accumulates
        // over the 100 steps of an output interval to more than 1e-9·dt: the last step of
        // an interval must still land on the output time, not leave a sliver step.
        let arm = Arm::new(true, false);
        let state = arm.assemble(1000.0).unwrap();
        let mut settings = rk4(1010.0, 1e-3);
        settings.dt_out = 0.1;
        let trajectory = arm.simulate(state, &settings).unwrap();
        assert_eq!(trajectory.stats.steps, 10_000);
    }

    #[test]
    fn observed_samples_are_the_trajectory() {
        let arm = Arm::new(true, true).with_spring_damper(5.0, 0.3);
        let settings = dopri(1.0, 1e-9);
        let mut seen = Vec::new();
        let state = arm.assemble(0.0).unwrap();
        let observed = arm
            .simulate_observed(state, &settings, &mut |s| {
                seen.push(s.clone());
                Observed::Continue(())
            })
            .unwrap();
        assert_eq!(seen, observed.samples);
        assert_eq!(observed, run(&arm, &settings));
    }

    #[test]
    fn an_observer_that_breaks_stops_the_run_with_the_samples_so_far() {
        let arm = Arm::new(true, true).with_spring_damper(5.0, 0.3);
        for integrator in [IntegratorKind::Rk4, IntegratorKind::Dop853] {
            let settings = settings(integrator, 1.0, 0.1, 1e-3, 1e-9);
            let state = arm.assemble(0.0).unwrap();
            let mut count = 0;
            let failure = arm
                .simulate_observed(state, &settings, &mut |_| {
                    count += 1;
                    if count == 4 {
                        Observed::Break(())
                    } else {
                        Observed::Continue(())
                    }
                })
                .expect_err("stopped");
            // Samples at t = 0, 0.1, 0.2, 0.3: the fourth asked to stop.
            assert_eq!(
                failure.error,
                SimError::Interrupted {
                    t: 0.30000000000000004
                }
            );
            let times: Vec<f64> = failure.partial.samples.iter().map(|s| s.t).collect();
            assert_eq!(times[..4], [0.0, 0.1, 0.2, 0.30000000000000004]);
            let whole = run(&arm, &settings);
            assert_eq!(failure.partial.samples[..4], whole.samples[..4]);
        }
    }

    #[test]
    fn outputs_land_on_the_requested_times() {
        let arm = Arm::new(true, false);
        for integrator in [IntegratorKind::Rk4, IntegratorKind::Dopri5] {
            let settings = settings(integrator, 1.0, 0.3, 0.07, 1e-8);
            let trajectory = run(&arm, &settings);
            let times: Vec<f64> = trajectory.samples.iter().map(|s| s.t).collect();
            assert_eq!(times, vec![0.0, 0.3, 0.6, 0.3 * 3.0, 1.0]);
        }
        let mut state = arm.assemble(0.25).unwrap();
        let stats = arm.step(&mut state, 0.1).unwrap();
        assert_eq!(state.t, 0.25 + 0.1);
        assert!(stats.steps > 0 && stats.rhs_evaluations >= 6 * stats.steps);
        let stats = arm.step_with(&mut state, 0.05, &rk4(1.0, 0.02)).unwrap();
        assert_eq!(stats.steps, 3);
        assert_eq!(state.t, 0.25 + 0.1 + 0.05);
    }

    #[test]
    fn a_modified_state_restarts_consistently() {
        // Changing an independent velocity between steps: the dependent velocity is
        // re-solved, so J q̇ = 0 and h = 0 hold after the next step.
        let arm = Arm::new(true, false);
        let mut state = arm.assemble(0.0).unwrap();
        arm.step(&mut state, 0.1).unwrap();
        let u = state.independent()[0];
        state.qd[u] += 0.5;
        arm.step(&mut state, 0.1).unwrap();
        let sample = arm.sample(&state).unwrap();
        let mut j = [0.0; 3];
        arm.constraint_jacobian(&state.q, &mut j);
        assert!(row_dot(&j, &state.qd).abs() < 1e-10 && sample.h[0].abs() < 1e-10);
    }

    #[test]
    fn invalid_settings_are_rejected() {
        let arm = Arm::new(true, false);
        let state = arm.assemble(0.0).unwrap();
        let good = dopri(1.0, 1e-8);
        let cases = [
            SimSettings {
                dt: 0.0,
                ..good.clone()
            },
            SimSettings {
                dt_out: -1.0,
                ..good.clone()
            },
            SimSettings {
                t_end: -1.0,
                ..good.clone()
            },
            SimSettings {
                rtol: 0.0,
                ..good.clone()
            },
            SimSettings {
                atol: f64::NAN,
                ..good.clone()
            },
            SimSettings {
                t_end: f64::INFINITY,
                ..good.clone()
            },
        ];
        for settings in cases {
            let failure = arm.simulate(state.clone(), &settings).unwrap_err();
            assert!(
                matches!(failure.error, SimError::InvalidSettings { .. }),
                "{settings:?}"
            );
        }
        let mut state = state;
        assert!(matches!(
            arm.step(&mut state, -0.1),
            Err(SimError::InvalidSettings { .. })
        ));
        assert!(state.set_dependent(&[0, 1]).is_err());
    }
}
