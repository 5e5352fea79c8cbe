//! One-sided contact: the follower may leave the cam and land on it again.
//!
//! The paper's contact is bilateral: the cam may pull as well as push. A real follower held
//! on the cam by gravity or a spring is one-sided. [`crate::Simulate::simulate_unilateral`]
//! integrates in phases:
//!
//! - **in contact** the constrained equations (13)–(18) run as usual and the normal force N
//!   is watched, inside every step too (`scan`); where it reaches zero from above
//!   (located to 1e-9 s on the dense output) the follower **lifts off**;
//! - **in flight** the same chain runs without the constraint (the model seen through
//!   [`Detached`]) and the gap h(q) (3), positive above the cam, is checked along every step
//!   in pieces short enough for the cam's turn; where it first reaches zero the follower
//!   **lands** (located until |h| is below max(atol, 1e-12)·L, L the model's length scale);
//! - at landing the **impact law** applies: a frictionless impulse along the contact normal
//!   (Jᵀ Λ, on the free coordinates only: driven joints keep their prescribed velocity) such
//!   that the normal velocity reverses with Newton's coefficient of restitution e:
//!   J q̇⁺ = −e J q̇⁻, i.e. q̇⁺_f = q̇⁻_f − (1 + e) M_ff⁻¹ J_fᵀ (J q̇⁻) / (J_f M_ff⁻¹ J_fᵀ).
//!   The kinetic energy the impact removes is added to the dissipated energy and the
//!   drives' impulsive work to the driven work, so that the energy balance still closes.
//!   A rebound slower than [`RESTING_SPEED`] ends in contact (e taken as 0), which stops the
//!   infinite sequence of ever shorter bounces a rigid model would otherwise make.
//!
//! Outputs stay on the run's grid; in flight the samples report N = 0 and the gap as h.

use crate::SimSettings;
use crate::assembly::state_at;
use crate::clearance::Clearance;
use crate::dynamics::VelocityTerms;
use crate::dynamics::{ContactGeometry, ContactKinematics, Dynamics, ModelInfo};
use crate::error::SimError;
use crate::events::{ContactEvent, EventKind};
use crate::phase::{GapReading, Grid, Phase, Recorder, Stop, Watch, landing_tolerance};
use crate::sample::{Sample, SampleLevel};
use crate::stepping::{State, add_phase_counters, phase_counters, validate_run};
use nalgebra::{DMatrix, DVector};
use std::cell::RefCell;

/// Slowest rebound (m/s of the normal velocity J q̇) with which the follower flies off again
/// after an impact; slower rebounds end in contact.
pub const RESTING_SPEED: f64 = 1e-4;

/// Most contact events a unilateral run accepts before it reports chattering.
pub const MAX_EVENTS: usize = 100_000;

/// The contact law of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactLaw {
    /// The paper's bilateral contact: the cam pushes and pulls; sign changes of the normal
    /// force are reported as events.
    Bilateral,
    /// One-sided contact with Newton's coefficient of restitution e ∈ [0, 1] at landing.
    Unilateral {
        /// Coefficient of restitution.
        restitution: f64,
    },
}

/// A model seen without its cam contacts (a flying follower): same bodies, joints, drives
/// and forces, no constraint.
pub struct Detached<'a, D: ?Sized> {
    inner: &'a D,
    info: ModelInfo,
    /// h, J and c of the inner model, computed alongside and ignored.
    scratch: RefCell<(Vec<f64>, Vec<f64>, Vec<f64>)>,
}

impl<'a, D: Dynamics + ?Sized> Detached<'a, D> {
    /// `inner` without its contacts.
    pub fn new(inner: &'a D) -> Self {
        let mut info = inner.info().clone();
        let (n, nc) = (info.n(), info.n_contacts());
        info.contacts.clear();
        Detached {
            inner,
            info,
            scratch: RefCell::new((vec![0.0; nc], vec![0.0; nc * n], vec![0.0; nc])),
        }
    }
}

impl<D: Dynamics + ?Sized> Dynamics for Detached<'_, D> {
    fn info(&self) -> &ModelInfo {
        &self.info
    }
    crate::dynamics::forward_free_motion!(inner);
    fn constraint(&self, _q: &[f64], _h: &mut [f64]) {}
    fn constraint_jacobian(&self, _q: &[f64], _j: &mut [f64]) {}
    fn constraint_bias(&self, _q: &[f64], _qd: &[f64], _c: &mut [f64]) {}
    fn contact_geometry(&self, _q: &[f64], _qd: &[f64], _out: &mut [ContactGeometry]) {}
    fn contact_kinematics_into(
        &self,
        q: &[f64],
        qd: &[f64],
        k: usize,
        out: &mut ContactKinematics,
    ) {
        self.inner.contact_kinematics_into(q, qd, k, out);
    }
    fn position_terms(&self, q: &[f64], _h: &mut [f64], _j: &mut [f64], cache: &mut [f64]) {
        let mut scratch = self.scratch.borrow_mut();
        let (h, j, _) = &mut *scratch;
        self.inner.position_terms(q, h, j, cache);
    }
    fn velocity_terms(&self, t: f64, q: &[f64], qd: &[f64], cache: &[f64], out: VelocityTerms) {
        let mut scratch = self.scratch.borrow_mut();
        let inner_out = VelocityTerms {
            mass: out.mass,
            inertial: out.inertial,
            applied: out.applied,
            bias: &mut scratch.2,
        };
        self.inner.velocity_terms(t, q, qd, cache, inner_out);
    }
}

/// Velocities after an impact, and the bookkeeping of the event.
struct Impact {
    qd: Vec<f64>,
    normal_velocity: f64,
    rebound: f64,
    stays: bool,
    /// Kinetic energy removed by the impact (J, ≥ 0 up to round-off).
    loss: f64,
    /// Work of the drives' impulsive reactions (J).
    drive_work: f64,
}

/// The impact law of the module documentation at (q, q̇⁻) for contact `k`.
fn impact(
    model: &dyn Dynamics,
    t: f64,
    (q, qd): (&[f64], &[f64]),
    k: usize,
    restitution: f64,
) -> Result<Impact, SimError> {
    let info = model.info();
    let (n, nc) = (info.n(), info.n_contacts());
    let free: Vec<usize> = (0..n).filter(|&i| !info.coordinates[i].driven).collect();
    let mut m = vec![0.0; n * n];
    model.mass_matrix(q, &mut m);
    let mut j = vec![0.0; nc * n];
    model.constraint_jacobian(q, &mut j);
    let row = &j[k * n..(k + 1) * n];
    let normal_velocity: f64 = row.iter().zip(qd).map(|(a, b)| a * b).sum();
    let m_ff = DMatrix::from_fn(free.len(), free.len(), |a, b| m[free[a] * n + free[b]]);
    let j_f = DVector::from_iterator(free.len(), free.iter().map(|&i| row[i]));
    // A landing point is on the cam: a singular M_ff or zero J_f there locks the impact.
    let singular = || SimError::SingularConstraint {
        t,
        q: q.to_vec(),
        residual: 0.0,
        on_cam: true,
    };
    let x = m_ff.cholesky().ok_or_else(singular)?.solve(&j_f);
    let denominator = j_f.dot(&x);
    if !(denominator > 0.0 && denominator.is_finite()) {
        return Err(singular());
    }
    // A "landing" that does not approach (a take-off too short to resolve, the rebound
    // re-found at once) ends the flight plastically: the follower stays on the cam.
    let stays = normal_velocity >= 0.0 || restitution * normal_velocity.abs() < RESTING_SPEED;
    let e = if stays { 0.0 } else { restitution };
    let impulse = -(1.0 + e) * normal_velocity / denominator;
    let mut after = qd.to_vec();
    for (a, &i) in free.iter().enumerate() {
        after[i] += x[a] * impulse;
    }
    let rebound: f64 = row.iter().zip(&after).map(|(a, b)| a * b).sum();
    let kinetic = |v: &[f64]| model.energy(q, v).kinetic;
    let delta_qd: Vec<f64> = after.iter().zip(qd).map(|(a, b)| a - b).collect();
    // The drives' impulsive reactions P_d = (M Δq̇)_d − J_d Λ (what the contact impulse
    // does not supply on a driven coordinate) act at the constant velocities q̇_d.
    let drive_work: f64 = (0..n)
        .filter(|&d| info.coordinates[d].driven)
        .map(|d| {
            let p: f64 = (0..n).map(|c| m[d * n + c] * delta_qd[c]).sum();
            (p - row[d] * impulse) * qd[d]
        })
        .sum();
    let loss = drive_work - (kinetic(&after) - kinetic(qd));
    Ok(Impact {
        qd: after,
        normal_velocity,
        rebound,
        stays,
        loss,
        drive_work,
    })
}

/// The flight samples of the detached model, completed with the contact's view: the gap
/// as h, N = 0, the geometry under the point.
fn complete_flight_sample(model: &dyn Dynamics, sample: &mut Sample) {
    let nc = model.info().n_contacts();
    let mut h = vec![0.0; nc];
    model.constraint(&sample.q, &mut h);
    let mut contacts = vec![ContactGeometry::default(); nc];
    model.contact_geometry(&sample.q, &sample.qd, &mut contacts);
    sample.h = h;
    sample.contacts = contacts;
    sample.normal_force = vec![0.0; nc];
    sample.lambda = vec![0.0; nc];
    sample.in_contact = vec![false; nc];
}

/// Where a one-sided run is: its state, of the model while the follower is on the cam and
/// of the model seen through [`Detached`] while it flies, and the landing tolerance fixed at
/// the start.
struct Progress {
    state: State,
    flying: bool,
    tolerance: f64,
}

impl Progress {
    /// The start of a run from `state`: in contact, unless a roller in a groove with backlash
    /// starts between the flanks ([`crate::clearance`]): in flight unless it touches one.
    fn start(model: &dyn Dynamics, state: State, settings: &SimSettings) -> Result<Self, SimError> {
        let tolerance = landing_tolerance(settings, state.length_scale());
        let n = model.info().n();
        let start = gap_reading(model, n, &state.q, &state.qd).g;
        if Clearance::applies_to(model) && start > tolerance {
            let detached = Detached::new(model);
            let mut flying = state_at(&detached, state.t, (&state.q, &state.qd))?;
            flying.set_quadratures((state.dissipated, state.driven_work));
            return Ok(Progress {
                state: flying,
                flying: true,
                tolerance,
            });
        }
        Ok(Progress {
            state,
            flying: false,
            tolerance,
        })
    }
}

fn validate_unilateral(
    model: &dyn Dynamics,
    state: &State,
    settings: &SimSettings,
    (restitution, keep): (f64, bool),
) -> Result<(), SimError> {
    validate_run(model, state, settings, keep)?;
    let invalid = |message: String| Err(SimError::InvalidSettings { message });
    if !model.info().loops.is_empty() {
        return invalid(format!(
            "unilateral contact is not available in a model with loops yet; {} has {}",
            model.info().name,
            model.info().loops.len()
        ));
    }
    if model.info().n_contacts() != 1 {
        return invalid(format!(
            "unilateral contact needs a model with exactly one cam contact; {} has {}",
            model.info().name,
            model.info().n_contacts()
        ));
    }
    if !settings.integrator.is_adaptive() {
        return invalid(
            "unilateral contact needs an adaptive integrator (dopri5 or dop853): lift-off \
             and landing are located on its dense output"
                .into(),
        );
    }
    if !(0.0..=1.0).contains(&restitution) {
        return invalid(format!(
            "the coefficient of restitution must lie in [0, 1], got {restitution}"
        ));
    }
    Ok(())
}

/// Runs `state` of `model` (one cam contact) to `settings.t_end` with one-sided contact and
/// restitution `restitution` (see the module documentation), recording into `record`.
/// Needs an adaptive integrator (events are located on its dense output).
pub(crate) fn run_phases(
    model: &dyn Dynamics,
    state: State,
    settings: &SimSettings,
    restitution: f64,
    record: &mut Recorder,
) -> Result<(), SimError> {
    let keep = record.keeps_samples();
    validate_unilateral(model, &state, settings, (restitution, keep))?;
    let mut grid = Grid::new(state.t, settings);
    let mut progress = Progress::start(model, state, settings)?;
    phases(
        model,
        &mut progress,
        (settings, restitution),
        &mut grid,
        record,
        0,
    )
}

/// The phases of a one-sided run from where `progress` is to the end of `grid`: contact
/// until lift-off, flight until landing, the impact law, and again; `earlier` events were
/// recorded before (for the chattering limit).
fn phases(
    model: &dyn Dynamics,
    progress: &mut Progress,
    (settings, restitution): (&SimSettings, f64),
    grid: &mut Grid,
    record: &mut Recorder,
    earlier: usize,
) -> Result<(), SimError> {
    let detached = Detached::new(model);
    let tolerance = progress.tolerance;
    let n = model.info().n();
    let gap = |q: &[f64], qd: &[f64]| gap_reading(model, n, q, qd);
    let complete = |sample: &mut Sample| complete_flight_sample(model, sample);
    loop {
        if earlier + record.events.len() > MAX_EVENTS {
            return Err(SimError::InvalidSettings {
                message: format!(
                    "more than {MAX_EVENTS} contact events before t_end: the follower \
                     chatters on the cam"
                ),
            });
        }
        let flying = progress.flying;
        let stop = if flying {
            let watch = Watch::Gap {
                gap: &gap,
                tolerance,
            };
            let state = &mut progress.state;
            run_phase(
                &detached,
                state,
                settings,
                &watch,
                grid,
                record,
                Some(&complete),
            )?
        } else {
            let watch = Watch::Forces { stop: true };
            run_phase(
                model,
                &mut progress.state,
                settings,
                &watch,
                grid,
                record,
                None,
            )?
        };
        let Some(stop) = stop else {
            return Ok(());
        };
        let (dissipated, driven_work) = stop.quadratures;
        let (next, in_flight) = if flying {
            let hit = impact(
                model,
                stop.t,
                (&stop.q, &stop.qd),
                stop.contact,
                restitution,
            )?;
            record.events.push(ContactEvent {
                t: stop.t,
                contact: stop.contact,
                kind: EventKind::Impact {
                    normal_velocity: hit.normal_velocity,
                    rebound: hit.rebound,
                    stays: hit.stays,
                    loss: hit.loss,
                },
                q: stop.q.clone(),
                qd: stop.qd.clone(),
                flank: model.groove_flank(&stop.q, stop.contact),
            });
            let quadratures = (dissipated + hit.loss, driven_work + hit.drive_work);
            let mut next = if hit.stays {
                state_at(model, stop.t, (&stop.q, &hit.qd))?
            } else {
                state_at(&detached, stop.t, (&stop.q, &hit.qd))?
            };
            next.set_quadratures(quadratures);
            (next, !hit.stays)
        } else {
            record.events.push(ContactEvent {
                t: stop.t,
                contact: stop.contact,
                kind: EventKind::LiftOff,
                q: stop.q.clone(),
                qd: stop.qd.clone(),
                flank: model.groove_flank(&stop.q, stop.contact),
            });
            let mut next = state_at(&detached, stop.t, (&stop.q, &stop.qd))?;
            next.set_quadratures((dissipated, driven_work));
            (next, true)
        };
        progress.state = next;
        progress.flying = in_flight;
    }
}

/// A one-sided run advanced piece by piece, to one target time after another (what an
/// FMU's `fmi3DoStep` does): the phases, events and impact law of
/// [`crate::Simulate::simulate_unilateral`], resumed where the last piece ended, in contact
/// or in flight. The model is passed to each call (the same one every time).
pub struct OneSidedRun {
    progress: Progress,
    restitution: f64,
    events: Vec<ContactEvent>,
}

impl OneSidedRun {
    /// The run from `state` (assembled on `model`) with restitution `restitution`; the checks
    /// of `simulate_unilateral` (one contact, no loops, an adaptive integrator).
    pub fn start(
        model: &dyn Dynamics,
        state: State,
        settings: &SimSettings,
        restitution: f64,
    ) -> Result<Self, SimError> {
        let check = SimSettings {
            t_end: f64::MAX,
            dt_out: f64::MAX,
            ..settings.clone()
        };
        let progress = if Clearance::applies_to(model) {
            let clearance = Clearance::new(model);
            validate_unilateral(&clearance, &state, &check, (restitution, false))?;
            Progress::start(&clearance, state, settings)?
        } else {
            validate_unilateral(model, &state, &check, (restitution, false))?;
            Progress::start(model, state, settings)?
        };
        Ok(OneSidedRun {
            progress,
            restitution,
            events: Vec::new(),
        })
    }

    /// Advances to `target` (after the current time) and returns the sample there; the
    /// events on the way are appended to [`OneSidedRun::events`].
    pub fn advance(
        &mut self,
        model: &dyn Dynamics,
        target: f64,
        settings: &SimSettings,
    ) -> Result<Sample, SimError> {
        let t0 = self.progress.state.t;
        if !(target > t0 && target.is_finite()) {
            return Err(SimError::InvalidSettings {
                message: format!("a step to t = {target} s from t = {t0} s"),
            });
        }
        let piece = SimSettings {
            t_end: target,
            dt_out: target - t0,
            ..settings.clone()
        };
        let mut monitor = crate::control::Unmonitored;
        let mut record = Recorder::new(&mut monitor, &piece, t0);
        let mut grid = Grid::new(t0, &piece);
        let earlier = self.events.len();
        let law = (&piece, self.restitution);
        let outcome = if Clearance::applies_to(model) {
            let clearance = Clearance::new(model);
            phases(
                &clearance,
                &mut self.progress,
                law,
                &mut grid,
                &mut record,
                earlier,
            )
        } else {
            phases(
                model,
                &mut self.progress,
                law,
                &mut grid,
                &mut record,
                earlier,
            )
        };
        self.events.append(&mut record.events);
        outcome?;
        record
            .samples
            .pop()
            .ok_or_else(|| SimError::InvalidSettings {
                message: format!("no sample at t = {target} s"),
            })
    }

    /// The lift-offs and impacts so far, in time order.
    pub fn events(&self) -> &[ContactEvent] {
        &self.events
    }

    /// The current time.
    pub fn time(&self) -> f64 {
        self.progress.state.t
    }

    /// Whether the follower is on its cam now.
    pub fn in_contact(&self) -> bool {
        !self.progress.flying
    }
}

/// The gap of the (only) contact at (q, q̇): h, ḣ = J q̇, how fast the cam turns relative to
/// the follower point (the point's speed in the cam frame over its distance from the frame's
/// origin, at least a micrometre), and a bound on |ḣ| from both.
fn gap_reading(model: &dyn Dynamics, n: usize, q: &[f64], qd: &[f64]) -> GapReading {
    let mut h = [0.0];
    model.constraint(q, &mut h);
    let mut j = vec![0.0; n];
    model.constraint_jacobian(q, &mut j);
    let rate = j.iter().zip(qd).map(|(a, b)| a * b).sum();
    let mut kinematics = ContactKinematics::new(n);
    model.contact_kinematics_into(q, qd, 0, &mut kinematics);
    let speed_x: f64 = kinematics.j1.iter().zip(qd).map(|(a, b)| a * b).sum();
    let speed_y: f64 = kinematics.j2.iter().zip(qd).map(|(a, b)| a * b).sum();
    let distance = kinematics.x.hypot(kinematics.y).max(1e-6);
    let point_speed = speed_x.hypot(speed_y);
    let turn_rate = point_speed / distance;
    // The cam's material at the contact point moves relative to the follower at most the
    // follower point's speed plus the turn rate times their distance (a rigid relative
    // motion, the turn rate standing for its spin).
    let geometry = &kinematics.geometry;
    let offset = (0..3)
        .map(|i| (geometry.position[i] - geometry.follower[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    GapReading {
        g: h[0],
        rate,
        turn_rate,
        speed: point_speed + turn_rate * offset,
    }
}

fn run_phase(
    model: &dyn Dynamics,
    state: &mut State,
    settings: &SimSettings,
    watch: &Watch,
    grid: &mut Grid,
    record: &mut Recorder,
    complete: Option<&dyn Fn(&mut Sample)>,
) -> Result<Option<Stop>, SimError> {
    let before = phase_counters(state);
    let mut phase = Phase {
        settings,
        level: SampleLevel::Full,
        watch,
        grid,
        record,
        complete,
    };
    let outcome = phase.run(model, state);
    add_phase_counters(&mut phase.record.stats, state, before);
    outcome
}
