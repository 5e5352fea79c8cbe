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

use crate::dynamics::{ContactGeometry, Dynamics, SimSettings};
use crate::error::SimError;
use crate::events::{EVENT_TIME_TOLERANCE, locate_root};
use crate::partition::{Partition, Workspace, normal_force};
use crate::simulate::{
    Grid, SampleLevel, Stats, adaptive_step, add_counters_since, all_counters, finish_step,
    interpolate_last_step, load_state, rk4_step, sample_in_place, validate_run,
};
use crate::{Sample, State};

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
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("simulation stopped at t = {} s: {error}", partial.t)]
pub struct MetricsFailure {
    /// Why the run stopped.
    pub error: SimError,
    /// The metrics of the part that was computed.
    pub partial: RunMetrics,
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
fn point_from_workspace<D: Dynamics + ?Sized>(
    model: &D,
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
            .zip(&point.geometry)
            .map(|(&l, g)| normal_force(l, g.force_scale)),
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
fn point_interpolated<D: Dynamics + ?Sized>(
    model: &D,
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

/// [`crate::Simulate::simulate_metrics`].
pub(crate) fn run_metrics<D: Dynamics + ?Sized>(
    model: &D,
    mut state: State,
    settings: &SimSettings,
    options: MetricsOptions,
) -> Result<RunMetrics, Box<MetricsFailure>> {
    let mut acc = Accumulator::new(state.t);
    let before = all_counters(&state.engine);
    let outcome = validate_run(model, &state, settings).and_then(|()| {
        if settings.integrator.is_adaptive() {
            adaptive_run(model, &mut state, settings, options, &mut acc)
        } else {
            fixed_run(model, &mut state, settings, &mut acc)
        }
    });
    let mut stats = Stats::default();
    add_counters_since(&mut stats, &state.engine, before);
    stats.repartitions = acc.metrics.stats.repartitions;
    match outcome {
        Ok(()) => Ok(acc.finish(stats)),
        Err(error) => Err(Box::new(MetricsFailure {
            error,
            partial: acc.finish(stats),
        })),
    }
}

/// The start, then every accepted step's end (and the grid, if asked).
fn adaptive_run<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    settings: &SimSettings,
    options: MetricsOptions,
    acc: &mut Accumulator,
) -> Result<(), SimError> {
    let start = Point::of_sample(&sample_in_place(model, state, SampleLevel::Full)?);
    acc.add(&start);
    acc.remember(&start);
    let mut grid = Grid::new(state.t, settings);
    grid.next = 1;
    let mut ws = state.engine.ws.clone();
    let mut y = state.engine.y.clone();
    let (mut end, mut probe) = (start.clone(), start);
    let mut steps = 0;
    while state.t < settings.t_end {
        if steps == crate::settings::MAX_STEPS_PER_CALL {
            return Err(SimError::TooManySteps { t: state.t });
        }
        steps += 1;
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
        if let Some(contact) = acc.lift_off_candidate(&end) {
            let before = acc.last_forces[contact];
            let after = end.forces[contact];
            let mut force = |t: f64| -> Result<f64, SimError> {
                point_interpolated(model, state, settings, (&mut ws, &mut y), t, &mut probe)?;
                Ok(probe.forces[contact])
            };
            let t = locate_root(
                &mut force,
                (t_old, before),
                (t_new, after),
                EVENT_TIME_TOLERANCE,
            )?;
            acc.metrics.first_lift_off = Some((t, contact));
        }
        if options.grid {
            while let Some(t_out) = grid.pending_time(settings).filter(|&t| t < t_new) {
                point_interpolated(model, state, settings, (&mut ws, &mut y), t_out, &mut probe)?;
                acc.add(&probe);
                grid.next += 1;
            }
            if grid.pending_time(settings).is_some_and(|t| t <= t_new) {
                grid.next += 1;
            }
        }
        acc.add(&end);
        acc.remember(&end);
        if finish_step(model, state, t_new)? {
            acc.metrics.stats.repartitions += 1;
        }
    }
    Ok(())
}

/// RK4: the start and the end of every step (a full evaluation each: RK4's last stage is
/// not at the new point).
fn fixed_run<D: Dynamics + ?Sized>(
    model: &D,
    state: &mut State,
    settings: &SimSettings,
    acc: &mut Accumulator,
) -> Result<(), SimError> {
    let start = Point::of_sample(&sample_in_place(model, state, SampleLevel::Full)?);
    acc.add(&start);
    acc.remember(&start);
    let mut steps = 0;
    while state.t < settings.t_end {
        if steps == crate::settings::MAX_STEPS_PER_CALL {
            return Err(SimError::TooManySteps { t: state.t });
        }
        steps += 1;
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
    }
    Ok(())
}
