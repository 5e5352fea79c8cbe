//! Runs that report a summary instead of a trajectory: what a design study (a parameter
//! sweep over thousands of runs) keeps of each run.
//!
//! The quantities are evaluated at the start and at the end of every accepted step, where
//! the integrator has just evaluated the right-hand side (the last stage of DOP853 and
//! Dopri5 is the derivative at the new point): the normal forces then cost one small solve
//! for the multipliers (14), the energies one evaluation. No dense output is prepared unless
//! a normal force changes sign (the first lift-off is then located to
//! [`EVENT_TIME_TOLERANCE`] on the interpolant) or a grid is asked for
//! ([`MetricsOptions::grid`]: also at t0 + k·dt_out, the times of a full run's samples, so
//! that the extremes are those of its CSV). Nothing grows with the length of the run.

use crate::control::{Monitor, Progress, Watchdog};
use crate::dynamics::{ContactGeometry, Dynamics, SimSettings};
use crate::error::SimError;
use crate::events::{EVENT_TIME_TOLERANCE, locate_root};
use crate::integrators::stage_quadrature;
use crate::partition::{Partition, Workspace, normal_force};
use crate::phase::Grid;
use crate::sample::{Sample, SampleLevel, sample_in_place};
use crate::scan::{ForceStep, excursion_guess, find_excursion};
use crate::stepping::{
    State, Stats, adaptive_step, add_counters_since, all_counters, finish_step,
    interpolate_last_step, load_state, rk4_step, validate_run,
};
use std::fmt;

/// What a run reports of itself when its trajectory is not kept.
#[derive(Debug, Clone, PartialEq)]
pub struct RunMetrics {
    /// The time reached (t_end, or where the run stopped).
    pub t: f64,
    /// Largest normal force over the contacts and the evaluated times (N); NaN without a
    /// contact.
    pub max_normal_force: f64,
    /// Smallest normal force (N); negative where the cam would have to pull the follower.
    pub min_normal_force: f64,
    /// The first time a normal force reaches zero from above (a one-sided follower lifts
    /// off there), located to [`EVENT_TIME_TOLERANCE`], with the contact's index.
    pub first_lift_off: Option<(f64, usize)>,
    /// Largest |h| (m).
    pub max_residual: f64,
    /// Largest |(E + dissipated − driven work)(t) − (…)(t0)| (J).
    pub energy_drift: f64,
    /// The largest kinetic energy plus the range of the potential energy (J): what the
    /// drift is relative to.
    pub energy_scale: f64,
    /// Number of times the quantities were evaluated.
    pub points: usize,
    /// Work counters.
    pub stats: Stats,
}

impl RunMetrics {
    /// The energy drift relative to the energy scale (0 when the scale is 0).
    pub fn relative_energy_drift(&self) -> f64 {
        if self.energy_scale > 0.0 {
            self.energy_drift / self.energy_scale
        } else {
            0.0
        }
    }
}

/// Where a metrics run evaluates its quantities besides the step ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MetricsOptions {
    /// Also at the output times t0 + k·dt_out (dense output, Newton and a solve per time:
    /// about one right-hand side each), so that extremes are those of a full run's samples.
    pub grid: bool,
}

/// A metrics run that stopped early: the error and the metrics until then.
#[derive(Clone, PartialEq, thiserror::Error)]
#[error("simulation stopped at t = {} s: {error}", partial.t)]
pub struct MetricsFailure {
    /// Why the run stopped.
    pub error: SimError,
    /// The metrics of the part that was computed.
    pub partial: RunMetrics,
}

impl fmt::Debug for MetricsFailure {
    /// The one-line message of `Display`, so that a `main` returning
    /// `Result<(), Box<dyn std::error::Error>>` prints it as it is after `Error: `. The
    /// fields stay public for a program that needs them.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// Running extremes.
#[derive(Debug, Clone)]
struct Accumulator {
    metrics: RunMetrics,
    /// (E + D − W) at the start.
    balance0: Option<f64>,
    kinetic_max: f64,
    potential: (f64, f64),
    /// The normal forces at the last evaluated point.
    last_forces: Vec<f64>,
    last_t: f64,
}

impl Accumulator {
    fn new(t0: f64) -> Self {
        Accumulator {
            metrics: RunMetrics {
                t: t0,
                max_normal_force: f64::NAN,
                min_normal_force: f64::NAN,
                first_lift_off: None,
                max_residual: 0.0,
                energy_drift: 0.0,
                energy_scale: 0.0,
                points: 0,
                stats: Stats::default(),
            },
            balance0: None,
            kinetic_max: 0.0,
            potential: (f64::INFINITY, f64::NEG_INFINITY),
            last_forces: Vec::new(),
            last_t: t0,
        }
    }

    /// Takes in one evaluated point.
    fn add(&mut self, point: &Point) {
        let m = &mut self.metrics;
        m.points += 1;
        m.t = m.t.max(point.t);
        for &n in &point.forces {
            m.max_normal_force = m.max_normal_force.max(n);
            m.min_normal_force = m.min_normal_force.min(n);
        }
        for &h in &point.residuals {
            m.max_residual = m.max_residual.max(h.abs());
        }
        let balance = point.energy + point.dissipated - point.driven_work;
        let first = *self.balance0.get_or_insert(balance);
        m.energy_drift = m.energy_drift.max((balance - first).abs());
        self.kinetic_max = self.kinetic_max.max(point.kinetic);
        self.potential.0 = self.potential.0.min(point.potential);
        self.potential.1 = self.potential.1.max(point.potential);
        m.energy_scale = self.kinetic_max + (self.potential.1 - self.potential.0).max(0.0);
    }

    /// Remembers the forces of a step end (for the next sign check).
    fn remember(&mut self, point: &Point) {
        self.last_forces.clone_from(&point.forces);
        self.last_t = point.t;
    }

    /// The first contact whose force went from above zero to zero or below between the last
    /// remembered point and `point`, if no lift-off was recorded yet.
    fn lift_off_candidate(&self, point: &Point) -> Option<usize> {
        if self.metrics.first_lift_off.is_some() {
            return None;
        }
        self.last_forces
            .iter()
            .zip(&point.forces)
            .position(|(&before, &now)| before > 0.0 && now <= 0.0)
    }

    fn finish(mut self, stats: Stats) -> RunMetrics {
        self.metrics.stats = stats;
        self.metrics
    }
}

/// The quantities at one time.
#[derive(Debug, Clone, Default)]
struct Point {
    t: f64,
    geometry: Vec<ContactGeometry>,
    forces: Vec<f64>,
    residuals: Vec<f64>,
    energy: f64,
    kinetic: f64,
    potential: f64,
    dissipated: f64,
    driven_work: f64,
}

impl Point {
    fn of_sample(s: &Sample) -> Self {
        Point {
            t: s.t,
            geometry: s.contacts.clone(),
            forces: s.normal_force.clone(),
            residuals: s.h.clone(),
            energy: s.energy.total(),
            kinetic: s.energy.kinetic,
            potential: s.energy.gravity + s.energy.spring,
            dissipated: s.dissipated,
            driven_work: s.driven_work,
        }
    }
}

/// The quantities at the state the workspace holds after a right-hand side at (t, q, q̇)
/// (accelerations solved), into `point` (its vectors reused): multipliers, normal forces,
/// residuals, energies.
fn point_from_workspace(
    model: &dyn Dynamics,
    partition: &Partition,
    ws: &mut Workspace,
    (t, dissipated, driven_work): (f64, f64, f64),
    point: &mut Point,
) -> Result<(), SimError> {
    let nc = partition.dependent().len();
    ws.solve_multipliers(partition, t)?;
    point.geometry.resize(nc, ContactGeometry::default());
    model.contact_geometry(ws.q(), ws.qd(), &mut point.geometry);
    point.forces.clear();
    point.forces.extend(
        ws.lambda()
            .iter()
            .zip(point.geometry.iter_mut())
            // A loop's rows after the contacts' have no taper.
            .zip(
                model
                    .info()
                    .contacts
                    .iter()
                    .map(|c| c.taper)
                    .chain(std::iter::repeat(0.0)),
            )
            .map(|((&l, g), taper)| g.flank_force(taper, normal_force(l, g.force_scale))),
    );
    point.residuals.resize(nc, 0.0);
    model.constraint(ws.q(), &mut point.residuals);
    let energy = model.energy(ws.q(), ws.qd());
    point.t = t;
    point.energy = energy.total();
    point.kinetic = energy.kinetic;
    point.potential = energy.gravity + energy.spring;
    point.dissipated = dissipated;
    point.driven_work = driven_work;
    Ok(())
}

/// The quantities at time `t` inside the last accepted step, from its dense output.
fn point_interpolated(
    model: &dyn Dynamics,
    state: &mut State,
    settings: &SimSettings,
    (ws, y): (&mut Workspace, &mut [f64]),
    t: f64,
    point: &mut Point,
) -> Result<(), SimError> {
    interpolate_last_step(model, state, settings, t, y)?;
    load_state(model, &state.partition, ws, t, y)?;
    ws.solve_accelerations(model, &state.partition, t)?;
    let nu = state.partition.independent().len();
    let (dissipated, driven_work) = (y[2 * nu], y[2 * nu + 1]);
    point_from_workspace(
        model,
        &state.partition,
        ws,
        (t, dissipated, driven_work),
        point,
    )
}

/// [`crate::Simulate::simulate_metrics`] and
/// [`crate::Simulate::simulate_metrics_monitored`].
pub(crate) fn run_metrics(
    model: &dyn Dynamics,
    mut state: State,
    settings: &SimSettings,
    options: MetricsOptions,
    monitor: &mut dyn Monitor,
) -> Result<RunMetrics, Box<MetricsFailure>> {
    let mut acc = Accumulator::new(state.t);
    let before = all_counters(&state.engine);
    let mut pace = Pace {
        watchdog: Watchdog::new(state.t, settings.rtol, settings.atol),
        monitor,
        steps: 0,
        t_end: settings.t_end,
    };
    // A metrics run keeps no samples: held to the streamed runs' cap on its output times.
    // A metrics run is bilateral: it cannot follow a groove with backlash.
    let outcome = validate_run(model, &state, settings, false)
        .and_then(|()| crate::clearance::held_both_ways(model))
        .and_then(|()| {
            if settings.integrator.is_adaptive() {
                state.engine.stages.watch(model.info().n_contacts());
                let outcome =
                    adaptive_run(model, &mut state, settings, options, &mut acc, &mut pace);
                state.engine.stages.watch(0);
                outcome
            } else {
                fixed_run(model, &mut state, settings, &mut acc, &mut pace)
            }
        });
    let mut stats = Stats::default();
    add_counters_since(&mut stats, &state.engine, before);
    stats.repartitions = acc.metrics.stats.repartitions;
    stats.event_evaluations = acc.metrics.stats.event_evaluations;
    match outcome {
        Ok(()) => Ok(acc.finish(stats)),
        Err(error) => Err(Box::new(MetricsFailure {
            error,
            partial: acc.finish(stats),
        })),
    }
}

/// The stall watchdog and the monitor of a metrics run, called after every step. A metrics
/// run has no output times: its budget runs to t_end.
struct Pace<'m> {
    watchdog: Watchdog,
    monitor: &'m mut dyn Monitor,
    steps: usize,
    t_end: f64,
}

impl Pace<'_> {
    fn stepped(&mut self, t: f64, h: f64) -> Result<(), SimError> {
        self.watchdog.step(t, h, (self.t_end, self.t_end))?;
        self.steps += 1;
        let progress = Progress {
            t,
            h,
            steps: self.steps,
        };
        if self.monitor.step(&progress).is_break() {
            return Err(SimError::Interrupted { t });
        }
        Ok(())
    }
}

/// The start, then every accepted step's end (and the grid, if asked); inside a step, a
/// normal force that changes sign or may cross zero and come back is searched on the dense
/// output for the first lift-off.
fn adaptive_run(
    model: &dyn Dynamics,
    state: &mut State,
    settings: &SimSettings,
    options: MetricsOptions,
    acc: &mut Accumulator,
    pace: &mut Pace,
) -> Result<(), SimError> {
    let start = Point::of_sample(&sample_in_place(model, state, SampleLevel::Full)?);
    acc.add(&start);
    acc.remember(&start);
    let mut grid = Grid::new(state.t, settings);
    grid.next = 1;
    let mut ws = state.engine.ws.clone();
    let mut y = state.engine.y.clone();
    let (mut end, mut probe) = (start.clone(), start.clone());
    // −λ of every contact (the sign of its normal force) at the last step's end.
    let mut last_p: Vec<f64> = start
        .forces
        .iter()
        .zip(&start.geometry)
        .map(|(&n, g)| n / g.force_scale)
        .collect();
    let (evaluations, quadrature) = stage_quadrature(settings.integrator);
    while state.t < settings.t_end {
        let t_old = state.t;
        let t_new = adaptive_step(model, state, settings.t_end, settings)?;
        // The step's last stage was the right-hand side at its end: the workspace holds q,
        // q̇ and q̈ there, under the step's partition.
        let nu = state.partition.independent().len();
        let (dissipated, driven_work) = (state.engine.y[2 * nu], state.engine.y[2 * nu + 1]);
        let point = (t_new, dissipated, driven_work);
        point_from_workspace(
            model,
            &state.partition,
            &mut state.engine.ws,
            point,
            &mut end,
        )?;
        ws.v_anchor.copy_from_slice(&state.engine.ws.v_anchor);
        let steps = StepStages::of(state, (evaluations, quadrature), &last_p, t_new);
        if acc.metrics.first_lift_off.is_none() {
            let candidate = acc.lift_off_candidate(&end).map(|k| (k, None)).or_else(|| {
                (0..last_p.len()).find_map(|k| steps.guess(k).map(|guess| (k, Some(guess))))
            });
            if let Some((contact, guess)) = candidate {
                let before = acc.last_forces[contact];
                let after = end.forces[contact];
                let mut searched = Vec::new();
                let mut force = |t: f64| -> Result<f64, SimError> {
                    point_interpolated(model, state, settings, (&mut ws, &mut y), t, &mut probe)?;
                    searched.push(probe.clone());
                    Ok(probe.forces[contact])
                };
                let bracket = match guess {
                    None => Some(((t_old, before), (t_new, after))),
                    Some(guess) => {
                        find_excursion(&mut force, (t_old, before), (t_new, after), guess)?
                            .map(|excursion| excursion.leaves)
                    }
                };
                if let Some((a, b)) = bracket {
                    let t = locate_root(&mut force, a, b, EVENT_TIME_TOLERANCE)?;
                    acc.metrics.first_lift_off = Some((t, contact));
                }
                acc.metrics.stats.event_evaluations += searched.len();
                for point in &searched {
                    acc.add(point);
                }
            }
        }
        last_p = steps.end;
        if options.grid {
            while let Some(t_out) = grid.pending(settings).filter(|&t| t < t_new) {
                point_interpolated(model, state, settings, (&mut ws, &mut y), t_out, &mut probe)?;
                acc.add(&probe);
                grid.next += 1;
            }
            if grid.pending(settings).is_some_and(|t| t <= t_new) {
                grid.next += 1;
            }
        }
        acc.add(&end);
        acc.remember(&end);
        if finish_step(model, state, t_new)? {
            acc.metrics.stats.repartitions += 1;
        }
        pace.stepped(t_new, t_new - t_old)?;
    }
    Ok(())
}

/// What the stage log of the last step says of each contact's −λ.
struct StepStages {
    t0: f64,
    t1: f64,
    start: Vec<f64>,
    end: Vec<f64>,
    mean: Vec<f64>,
    /// (t, −λ of every contact) at the interior stages.
    stages: Vec<(f64, Vec<f64>)>,
}

impl StepStages {
    fn of(
        state: &State,
        (evaluations, quadrature): (usize, &[f64]),
        start: &[f64],
        t1: f64,
    ) -> Self {
        let log = &state.engine.stages;
        let complete = log.len() >= evaluations;
        let mut mean: Vec<f64> = start.iter().map(|p| quadrature[0] * p).collect();
        let mut stages = Vec::with_capacity(evaluations);
        let mut end = vec![f64::NAN; start.len()];
        for ((t, values), b) in log.last(evaluations).zip(&quadrature[1..]) {
            for (m, v) in mean.iter_mut().zip(values) {
                *m += b * v;
            }
            if t < t1 {
                stages.push((t, values.to_vec()));
            } else {
                end.copy_from_slice(values);
            }
        }
        if !complete {
            mean.fill(f64::NAN);
        }
        StepStages {
            t0: state.t,
            t1,
            start: start.to_vec(),
            end,
            mean,
            stages,
        }
    }

    /// Where contact k's force may cross zero and come back inside the step.
    fn guess(&self, k: usize) -> Option<f64> {
        let stages: Vec<(f64, f64)> = self.stages.iter().map(|(t, v)| (*t, v[k])).collect();
        excursion_guess(&ForceStep {
            start: (self.t0, self.start[k]),
            end: (self.t1, self.end[k]),
            mean: self.mean[k],
            stages: &stages,
        })
        .filter(|_| self.start[k] > 0.0)
    }
}

/// RK4: the start and the end of every step (a full evaluation each: RK4's last stage is
/// not at the new point).
fn fixed_run(
    model: &dyn Dynamics,
    state: &mut State,
    settings: &SimSettings,
    acc: &mut Accumulator,
    pace: &mut Pace,
) -> Result<(), SimError> {
    let start = Point::of_sample(&sample_in_place(model, state, SampleLevel::Full)?);
    acc.add(&start);
    acc.remember(&start);
    while state.t < settings.t_end {
        let t_old = state.t;
        let t_new = rk4_step(model, state, settings.t_end, settings.dt)?;
        if finish_step(model, state, t_new)? {
            acc.metrics.stats.repartitions += 1;
        }
        let end = Point::of_sample(&sample_in_place(model, state, SampleLevel::Full)?);
        if let Some(contact) = acc.lift_off_candidate(&end) {
            // No interpolant: the sign change is placed by linear interpolation.
            let (a, b) = (acc.last_forces[contact], end.forces[contact]);
            let t = acc.last_t + (end.t - acc.last_t) * a / (a - b);
            acc.metrics.first_lift_off = Some((t, contact));
        }
        acc.add(&end);
        acc.remember(&end);
        pace.stepped(t_new, t_new - t_old)?;
    }
    Ok(())
}
