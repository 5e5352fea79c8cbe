//! The integration engine: the [`State`] a run advances, one step of RK4 or of an adaptive
//! method on the reduced equations, and the bookkeeping after an accepted step.
//!
//! Only the independent coordinates are integrated: the integrated state is
//! y = (u, u̇, dissipated energy, driven work, v, v̇), of which (u, u̇) are error-controlled
//! (everything, when the drives alone move the mechanism: no u),
//! the two energies are quadratures, and (v, v̇) ride along uncontrolled as Newton's
//! starting point (at a Runge–Kutta stage they are accurate to the stage's order, so
//! Newton usually converges at its first evaluation). At every right-hand side evaluation the
//! dependent coordinates are recovered by Newton (15) and the velocity relation (16), so the
//! constraint holds to Newton's tolerance at all times (no drift), and ü comes from the
//! reduced dynamics (17, 18). After each accepted step the partition's conditioning is
//! checked and the dependent coordinates are re-chosen when it has degraded.
//!
//! An adaptive step can also keep the contact multipliers of every stage it evaluates
//! (the stage log): what the in-step scan of the normal forces reads.

mod rhs;

pub(crate) use rhs::{evaluate_rhs, load_state};

use crate::dynamics::{CoordinateInfo, Dynamics, IntegratorKind, SimSettings};
use crate::error::SimError;
use crate::integrators::{Adaptive, Counters, Dop853, Dopri5, Rk4, Tolerances};
use crate::partition::{
    NEWTON_SLACK_PER_RTOL, Partition, REPARTITION_RATIO, Workspace, choose_dependent, conditioning,
    independent_rows,
};

/// A step ending within this fraction of a step before an output time is stretched to land
/// on it (avoids a useless sliver step caused by round-off in t + h). The round-off
/// accumulated over the steps of one output interval must fit: at t ≈ 1000 s with h = 1 ms,
/// 100 steps of up to ulp(t)/2 ≈ 6e-14 s each reach ~1e-11 s = 1e-8·h. Stretching a step by
/// 1e-6 of itself changes its local error by a relative 5e-6 (RK4), nothing measurable.
const LANDING_SLACK: f64 = 1e-6;

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
    pub(crate) dissipated: f64,
    pub(crate) driven_work: f64,
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
    /// The contact multipliers at the stages of the adaptive step being taken.
    pub(crate) stages: StageLog,
}

/// The right-hand sides an adaptive step evaluates, with −λ of every contact at each, when
/// switched on (a run that watches the normal forces): the last
/// [`Adaptive::EVALUATIONS_PER_ATTEMPT`] entries after an accepted step are that step's own
/// stages, in order, the last one at its end.
#[derive(Debug, Clone, Default)]
pub(crate) struct StageLog {
    /// Logging on.
    pub(crate) on: bool,
    contacts: usize,
    times: Vec<f64>,
    /// −λ of contacts 0…contacts − 1 at each entry, one row per entry.
    values: Vec<f64>,
}

impl StageLog {
    /// Logs −λ of the first `contacts` constraint rows (the contacts'), or nothing when
    /// `contacts` is zero.
    pub(crate) fn watch(&mut self, contacts: usize) {
        self.on = contacts > 0;
        self.contacts = contacts;
        self.clear();
    }

    /// Forgets the entries of the last step.
    fn clear(&mut self) {
        self.times.clear();
        self.values.clear();
    }

    fn push(&mut self, t: f64, ws: &Workspace) {
        self.times.push(t);
        for k in 0..self.contacts {
            self.values.push(-ws.contact_lambda(k));
        }
    }

    /// The last `count` entries: (time, −λ of every contact).
    pub(crate) fn last(&self, count: usize) -> impl Iterator<Item = (f64, &[f64])> {
        let first = self.times.len().saturating_sub(count);
        let width = self.contacts.max(1);
        self.times[first..]
            .iter()
            .zip(self.values[first * self.contacts..].chunks(width))
            .map(|(&t, v)| (t, v))
    }

    /// Entries logged since the last step started.
    pub(crate) fn len(&self) -> usize {
        self.times.len()
    }
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
            stages: StageLog::default(),
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

    /// The integrated vector y = (u, u̇, dissipated, driven work, v, v̇) of the state, in the
    /// layout [`crate::Simulate::derivative_at`] reads: u the independent coordinates
    /// ([`Self::independent`]), v the dependent ones ([`Self::dependent`]), both in that
    /// order, from the state's q and q̇ as they are now.
    pub fn integrated(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.integrated_len()];
        let quadratures = (self.dissipated, self.driven_work);
        write_integrated(&self.partition, &self.q, &self.qd, quadratures, &mut y);
        y
    }

    /// What entry `k` of the integrated vector holds, e.g. "u̇ of q2", for messages.
    pub(crate) fn integrated_slot(&self, k: usize, coordinates: &[CoordinateInfo]) -> String {
        let (u, v) = (self.partition.independent(), self.partition.dependent());
        let (nu, nc) = (u.len(), v.len());
        let name = |set: &[usize], i: usize| {
            let coordinate = set.get(i).and_then(|&c| coordinates.get(c));
            coordinate.map_or("?", |c| c.name.as_str()).to_string()
        };
        match k {
            k if k < nu => format!("u of {}", name(u, k)),
            k if k < 2 * nu => format!("u̇ of {}", name(u, k - nu)),
            k if k == 2 * nu => "the dissipated energy".to_string(),
            k if k == 2 * nu + 1 => "the driven work".to_string(),
            k if k < 2 * nu + 2 + nc => format!("v of {}", name(v, k - 2 * nu - 2)),
            k => format!("v̇ of {}", name(v, k - 2 * nu - 2 - nc)),
        }
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
    pub(crate) fn load_integrated_state(&mut self) {
        let quadratures = (self.dissipated, self.driven_work);
        let y = &mut self.engine.y;
        write_integrated(&self.partition, &self.q, &self.qd, quadratures, y);
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

    pub(crate) fn modified_since_last_step(&self) -> bool {
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
    /// Evaluations of the normal forces at interior times of accepted steps, to find and
    /// locate events (each about as costly as a right-hand side: dense output, Newton (15),
    /// the reduced accelerations and the multipliers), not counted in `rhs_evaluations`.
    pub event_evaluations: usize,
    /// Evaluations of a flying follower's gap at interior times of accepted steps (dense
    /// output and positions only: the constraint, its Jacobian and the contact point; no
    /// dynamics), to check every step for a landing and to locate it.
    pub gap_evaluations: usize,
}

impl Stats {
    fn add_counters(&mut self, after: Counters, before: Counters) {
        self.steps += after.steps - before.steps;
        self.rejected += after.rejected - before.rejected;
        self.rhs_evaluations += after.rhs_evaluations - before.rhs_evaluations;
    }
}

/// How many leading components of y the adaptive integrators control: (u, u̇); when there
/// is no independent coordinate (a mechanism moved only by its drives, y = (dissipated,
/// driven work, v, v̇)), the two energy quadratures, which then set the step (nothing would
/// bound it otherwise; v and v̇ are solved exactly at every evaluation).
fn controlled_len(nu: usize, _dim: usize) -> usize {
    if nu == 0 { 2 } else { 2 * nu }
}

/// Length of the integrated vector y = (u, u̇, dissipated, driven work, v, v̇).
fn integrated_len(partition: &Partition) -> usize {
    2 * partition.independent().len() + 2 + 2 * partition.dependent().len()
}

/// y = (u, u̇, dissipated, driven work, v, v̇) from q, q̇ and the two quadratures.
fn write_integrated(
    partition: &Partition,
    q: &[f64],
    qd: &[f64],
    (dissipated, driven_work): (f64, f64),
    y: &mut [f64],
) {
    let nu = partition.independent().len();
    let (positions, velocities) = y[..2 * nu].split_at_mut(nu);
    for ((y_q, y_qd), &u) in positions
        .iter_mut()
        .zip(velocities)
        .zip(partition.independent())
    {
        (*y_q, *y_qd) = (q[u], qd[u]);
    }
    (y[2 * nu], y[2 * nu + 1]) = (dissipated, driven_work);
    store_dependent(partition, y, q, qd);
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

pub(crate) fn positive(name: &str, value: f64) -> Result<(), SimError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(invalid(format!(
            "{name} must be positive and finite, got {value}"
        )))
    }
}

pub(crate) fn validate_integration(settings: &SimSettings) -> Result<(), SimError> {
    settings.validate_integration().map_err(setting_error)
}

/// The output settings of a run from `t0` that keeps its samples (`keep`) or streams them.
fn validate_output(settings: &SimSettings, t0: f64, keep: bool) -> Result<(), SimError> {
    if keep {
        settings.validate_output(t0)
    } else {
        settings.validate_streamed_output(t0)
    }
    .map_err(setting_error)
}

fn setting_error(e: crate::settings::InvalidSetting) -> SimError {
    invalid(e.to_string())
}

pub(crate) fn check_belongs(model: &dyn Dynamics, state: &State) -> Result<(), SimError> {
    let info = model.info();
    let n = info.n();
    let fits = state.q.len() == n && state.qd.len() == n && state.partition.n() == n;
    if fits && state.dependent().len() <= info.n_constraints() {
        Ok(())
    } else {
        Err(invalid(format!(
            "the state does not belong to model {}",
            info.name
        )))
    }
}

/// A NaN or infinite coordinate or velocity in the state (e.g. set by the caller) is
/// reported as `q` or `q̇`, rather than as the first quantity computed from it.
pub(crate) fn check_finite_state(state: &State) -> Result<(), SimError> {
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

/// Integrates until `state.t == t_target`, adding the work done to `stats` (also on error).
pub(crate) fn advance(
    model: &dyn Dynamics,
    state: &mut State,
    t_target: f64,
    settings: &SimSettings,
    stats: &mut Stats,
    after_step: &mut dyn FnMut(f64, f64) -> Result<(), SimError>,
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
    let result = advance_steps(model, state, t_target, settings, stats, after_step);
    add_counters_since(stats, &state.engine, before);
    if result.is_err() {
        // The integrated vector may be ahead of the last accepted state (a step whose
        // write-back failed): realign it so that the state can be stepped again.
        state.load_integrated_state();
    }
    result
}

fn advance_steps(
    model: &dyn Dynamics,
    state: &mut State,
    t_target: f64,
    settings: &SimSettings,
    stats: &mut Stats,
    after_step: &mut dyn FnMut(f64, f64) -> Result<(), SimError>,
) -> Result<(), SimError> {
    while state.t < t_target {
        let t_old = state.t;
        let t_new = match settings.integrator {
            IntegratorKind::Rk4 => rk4_step(model, state, t_target, settings.dt)?,
            IntegratorKind::Dopri5 | IntegratorKind::Dop853 => {
                adaptive_step(model, state, t_target, settings)?
            }
        };
        if finish_step(model, state, t_new)? {
            stats.repartitions += 1;
        }
        after_step(t_new, t_new - t_old)?;
    }
    Ok(())
}

/// Step of the fixed step `dt`, shortened to land on `t_target`; returns the new time.
pub(crate) fn rk4_step(
    model: &dyn Dynamics,
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
    let mut rhs =
        |t: f64, y: &[f64], dy: &mut [f64]| evaluate_rhs(model, partition, ws, t, y, dy, false);
    rk4.step(&mut rhs, state.t, y, h)?;
    dopri.invalidate_fsal();
    dop853.invalidate_fsal();
    Ok(if lands { t_target } else { state.t + h })
}

/// One accepted step of the chosen adaptive integrator towards `t_target` (clipped to land
/// on it); returns the new time and keeps the controller's proposal for the next step.
pub(crate) fn adaptive_step(
    model: &dyn Dynamics,
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
        stages,
        ..
    } = &mut state.engine;
    ws.set_newton_slack(NEWTON_SLACK_PER_RTOL * settings.rtol);
    stages.clear();
    let parts = StepParts {
        model,
        partition: &state.partition,
        ws,
        y,
        h_next,
        stages,
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
struct StepParts<'a> {
    model: &'a dyn Dynamics,
    partition: &'a Partition,
    ws: &'a mut Workspace,
    y: &'a mut Vec<f64>,
    h_next: &'a mut Option<f64>,
    stages: &'a mut StageLog,
}

impl StepParts<'_> {
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
        let (model, partition, ws, stages) = (self.model, self.partition, self.ws, self.stages);
        let log = stages.on;
        let mut rhs = |t: f64, y: &[f64], dy: &mut [f64]| {
            evaluate_rhs(model, partition, ws, t, y, dy, log)?;
            if log {
                stages.push(t, ws);
            }
            Ok(())
        };
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

/// The checks every run makes before it starts; `keep`: the run keeps its samples (at most
/// `MAX_SAMPLES` of them) rather than streaming them or keeping none.
pub(crate) fn validate_run(
    model: &dyn Dynamics,
    state: &State,
    settings: &SimSettings,
    keep: bool,
) -> Result<(), SimError> {
    check_belongs(model, state)
        .and_then(|()| check_finite_state(state))
        .and_then(|()| validate_integration(settings))
        .and_then(|()| validate_output(settings, state.t, keep))
        .and_then(|()| {
            crate::clearance::tapered_rollers_hold_their_radius(model, &state.q, &state.qd)
        })
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
pub(crate) fn interpolate_last_step(
    model: &dyn Dynamics,
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
    let mut rhs =
        |t: f64, y: &[f64], dy: &mut [f64]| evaluate_rhs(model, partition, ws, t, y, dy, false);
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

/// After an accepted step: writes t, q, q̇ and the quadratures back to the state, then
/// re-chooses the dependent coordinates if the partition's conditioning fell below
/// [`REPARTITION_RATIO`]. Returns true on a re-partition.
pub(crate) fn finish_step(
    model: &dyn Dynamics,
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
fn repartition_if_needed(model: &dyn Dynamics, state: &mut State) -> bool {
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
