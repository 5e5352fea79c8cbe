//! Samples: every output of a run at one instant (accelerations, multipliers, normal and
//! drive loads, constraint residuals, contact geometry, energies), computed at a step's end
//! or at an interpolated time inside the last step.

use crate::dynamics::{ContactGeometry, Dynamics, Energy};
use crate::error::SimError;
use crate::partition::{Partition, Workspace, normal_force};
use crate::stepping::{State, load_state};

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
    /// Whether each contact is closed at this instant: always in a bilateral run; false
    /// while a one-sided follower flies (its normal force is then zero and `h` its gap).
    pub in_contact: Vec<bool>,
}

/// What a sample holds beyond t, q, q̇ and the quadratures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SampleLevel {
    /// Everything [`Sample`] describes.
    Full,
    /// Only t, q, q̇, the quadratures and the partition: no accelerations, forces,
    /// residuals, contact geometry or energies (they are not computed).
    State,
}

/// The sample at an interpolated y inside the last step (the partition of that step).
pub(crate) fn sample_interpolated(
    model: &dyn Dynamics,
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

pub(crate) fn sample_in_place(
    model: &dyn Dynamics,
    state: &mut State,
    level: SampleLevel,
) -> Result<Sample, SimError> {
    state.engine.at_step_end = false;
    let mut ws = std::mem::replace(&mut state.engine.ws, Workspace::new(0, 0, 0));
    let sample = compute_sample(model, state, &mut ws, level);
    state.engine.ws = ws;
    sample
}

pub(crate) fn compute_sample(
    model: &dyn Dynamics,
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
pub(crate) fn complete_sample(
    model: &dyn Dynamics,
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
        in_contact: vec![true; model.info().n_contacts()],
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
        .zip(&mut contacts)
        .zip(&info.contacts)
        .map(|((&l, g), c)| g.flank_force(c.taper, normal_force(l, g.force_scale)))
        .collect();
    sample.qdd = ws.qdd().to_vec();
    sample.lambda = lambda;
    sample.h = h;
    sample.contacts = contacts;
    sample.drive = ws.drive().to_vec();
    sample.energy = model.energy(ws.q(), ws.qd());
    Ok(sample)
}
