//! The numeric recursive Newton–Euler reference (Fisette–Samin, eqs. 9–13).
//!
//! [`NumericModel`] evaluates a [`Model`] directly with nalgebra, body by body: a forward
//! recursion (ground → leaves) of rotations, origins, angular and linear velocities and
//! accelerations (9), Newton's and Euler's equations per body (10, 11), and a backward
//! recursion (leaves → ground) of the loads carried by every joint (12), projected on the
//! joint axes. It shares no algorithm with the symbolic generator, so it serves as an
//! independent cross-check of the generated code, and lets a model file be simulated
//! without rebuilding.
//!
//! - `M(q)` (13): column j is the inverse dynamics with q̇ = 0, q̈ = e_j, no gravity, no
//!   springs (the unit-vector method).
//! - `F(q, q̇)` (13): inverse dynamics with q̈ = 0, no gravity, no springs.
//! - `Q(q, q̇, t)` (13): inverse dynamics with q̇ = q̈ = 0 and gravity only, plus
//!   `k (q − rest) + c q̇` of the joint spring-dampers.
//! - The contact point (1)–(8): position from the forward recursion, Jacobian columns from
//!   the joint axes, convective acceleration from the acceleration recursion with q̈ = 0,
//!   profile derivatives from [`crate::jet`].

use crate::contact::{ContactConst, Evaluated};
use crate::jet::{eval_jet, eval_with};
use crate::loops::{LoopConst, LoopEval};
use crate::motion::{Mat3, Motion, Pose, Vec3, vec3};
use camchain_model::ModelError;
use camchain_model::model::{Body, Contact, JointKind, Loop, Model, ParameterMode, Profile};
use camchain_model::schema::{Files, load_model, parse_model_from};
use camchain_runtime::{
    ContactGeometry, ContactInfo, ContactKinematics, CoordinateInfo, Dynamics, Energy,
    InitialGuess, LoopInfo, ModelInfo, ParameterInfo, ProfileKind, SimSettings,
};
use nalgebra::{Rotation3, Unit};
use std::path::Path;

/// Builds the static description of a model: coordinates (name, kind, driven flag),
/// contact names, whether it is spatial, the initial guess and the default settings.
pub fn model_info(model: &Model) -> ModelInfo {
    ModelInfo {
        name: model.name.clone(),
        description: model.description.clone(),
        coordinates: model.bodies.iter().map(coordinate_info).collect(),
        contacts: model
            .contacts
            .iter()
            .map(|c| contact_info(model, c))
            .collect(),
        loops: model.loops.iter().map(loop_info).collect(),
        spatial: !model.is_planar(),
        initial: InitialGuess {
            q: model.initial.q.clone(),
            qd: model.initial.qd.clone(),
            hold: model.initial.hold.clone(),
            given_q: model.initial.given_q.clone(),
            given_qd: model.initial.given_qd.clone(),
        },
        defaults: SimSettings {
            t_end: model.simulation.t_end,
            dt_out: model.simulation.dt_out,
            integrator: model.simulation.integrator,
            dt: model.simulation.dt,
            rtol: model.simulation.rtol,
            atol: model.simulation.atol,
        },
        restitution: model.simulation.restitution,
        parameters: model
            .runtime_parameters()
            .map(|(_, p)| ParameterInfo {
                name: p.name.clone(),
                unit: p.unit.clone(),
                default: p.default,
                min: p.min,
                max: p.max,
                description: p.description.clone(),
            })
            .collect(),
    }
}

/// The runtime's description of a contact.
pub fn contact_info(model: &Model, c: &Contact) -> ContactInfo {
    ContactInfo {
        name: c.name.clone(),
        follower: c.follower.kind(),
        profile: match c.profile {
            Profile::Explicit { .. } => ProfileKind::Explicit,
            Profile::Polar { .. } => ProfileKind::Polar,
            Profile::Parametric { .. } => ProfileKind::Parametric,
            Profile::Surface { .. } => ProfileKind::Surface,
            Profile::Barrel { .. } => ProfileKind::Barrel,
            Profile::Revolution { .. } => ProfileKind::Revolution,
            Profile::Face { .. } => ProfileKind::Face,
        },
        cam_coordinate: c
            .cam_body
            .filter(|&b| model.bodies[b].joint.kind == JointKind::Revolute),
        cam_moves: c.cam_body.is_some(),
        backlash: c.backlash,
        taper: c.taper,
    }
}

/// The runtime's description of a loop cut.
pub fn loop_info(cut: &Loop) -> LoopInfo {
    LoopInfo {
        name: cut.name.clone(),
        kind: cut.kind,
        equations: cut.equations().iter().map(|e| e.to_string()).collect(),
    }
}

fn coordinate_info(body: &Body) -> CoordinateInfo {
    CoordinateInfo {
        name: body.joint.coordinate.clone(),
        kind: body.joint.kind,
        driven: body.joint.prescribed.is_some(),
    }
}

fn mat3(a: &[[f64; 3]; 3]) -> Mat3 {
    Mat3::from_fn(|r, c| a[r][c])
}

/// The constant data of one body and its joint, converted to nalgebra once.
#[derive(Debug, Clone)]
struct BodyConst {
    parent: Option<usize>,
    kind: JointKind,
    /// Joint axis in the parent's frame.
    axis: Unit<Vec3>,
    /// Joint point in the parent's frame.
    anchor: Vec3,
    mass: f64,
    /// Centre of mass in the body frame.
    com: Vec3,
    /// Inertia about the centre of mass, body axes.
    inertia: Mat3,
}

impl BodyConst {
    fn new(body: &Body) -> Self {
        Self {
            parent: body.parent,
            kind: body.joint.kind,
            axis: Unit::new_normalize(vec3(&body.joint.axis)),
            anchor: vec3(&body.joint.anchor),
            mass: body.mass,
            com: vec3(&body.com),
            inertia: mat3(&body.inertia),
        }
    }

    /// Pose of this body given its parent's pose and its joint coordinate.
    fn pose(&self, parent: &Pose, q: f64) -> Pose {
        let axis = parent.rot * self.axis.into_inner();
        let (rot, origin) = match self.kind {
            JointKind::Revolute => (
                parent.rot * Rotation3::from_axis_angle(&self.axis, q).into_inner(),
                parent.origin + parent.rot * self.anchor,
            ),
            JointKind::Prismatic => (
                parent.rot,
                parent.origin + parent.rot * (self.anchor + self.axis.into_inner() * q),
            ),
        };
        Pose {
            rot,
            origin,
            axis,
            lever: origin - parent.origin,
            com_offset: rot * self.com,
            inertia: rot * self.inertia * rot.transpose(),
        }
    }

    /// Velocities and accelerations of this body (9) from its parent's, its joint rate
    /// `qd` and joint acceleration `qdd`.
    fn motion(&self, pose: &Pose, parent: &Motion, qd: f64, qdd: f64) -> Motion {
        let (w, r, e) = (parent.omega, pose.lever, pose.axis);
        let carried = Motion {
            omega: w,
            alpha: parent.alpha,
            vel: parent.vel + w.cross(&r),
            acc: parent.acc + parent.alpha.cross(&r) + w.cross(&w.cross(&r)),
        };
        match self.kind {
            JointKind::Revolute => Motion {
                omega: carried.omega + e * qd,
                alpha: carried.alpha + e * qdd + w.cross(&e) * qd,
                ..carried
            },
            JointKind::Prismatic => Motion {
                vel: carried.vel + e * qd,
                acc: carried.acc + e * qdd + w.cross(&e) * (2.0 * qd),
                ..carried
            },
        }
    }

    /// The body's own inertial minus applied load (10, 11): force `m a_com − m g` and its
    /// moment about the body origin `I α + ω × I ω + c × (m a_com − m g)`.
    fn own_load(&self, pose: &Pose, motion: &Motion, gravity: &Vec3) -> Load {
        let c = pose.com_offset;
        let a_com = motion.point_acceleration(&c);
        let force = (a_com - gravity) * self.mass;
        let i_w = pose.inertia * motion.omega;
        let moment = pose.inertia * motion.alpha + motion.omega.cross(&i_w) + c.cross(&force);
        Load { force, moment }
    }

    /// Kinetic energy ½ (m v_com·v_com + ω·I ω).
    fn kinetic_energy(&self, pose: &Pose, motion: &Motion) -> f64 {
        let v_com = motion.point_velocity(&pose.com_offset);
        let w = motion.omega;
        0.5 * (self.mass * v_com.norm_squared() + w.dot(&(pose.inertia * w)))
    }
}

/// A force and its moment about a body's origin.
#[derive(Debug, Clone, Copy)]
struct Load {
    force: Vec3,
    moment: Vec3,
}

/// A model evaluated numerically by recursive Newton–Euler: the reference implementation of
/// [`Dynamics`].
///
/// Every call runs the recursions afresh from `q` (and `q̇`); nothing is cached between
/// calls. Allocation is limited to a few per-body vectors per call.
#[derive(Debug, Clone)]
pub struct NumericModel {
    model: Model,
    info: ModelInfo,
    /// The values of the run-time parameters (`info.parameters` order).
    values: Vec<f64>,
    bodies: Vec<BodyConst>,
    contacts: Vec<ContactConst>,
    loops: Vec<LoopConst>,
}

impl NumericModel {
    /// Wraps a validated model (as produced by [`camchain_model::schema`]: parents listed
    /// before children, unit axes, marker and body indices in range).
    ///
    /// # Panics
    /// When a marker or parent index is out of range, which validation rules out.
    pub fn new(model: Model) -> Self {
        let bodies = model.bodies.iter().map(BodyConst::new).collect();
        let contacts = model
            .contacts
            .iter()
            .map(|c| ContactConst::new(&model, c))
            .collect();
        let loops = model.loops.iter().map(LoopConst::new).collect();
        Self {
            info: model_info(&model),
            values: model.runtime_parameters().map(|(_, p)| p.value).collect(),
            model,
            bodies,
            contacts,
            loops,
        }
    }

    /// Reads, validates and wraps a RON model file.
    pub fn load(path: &Path) -> Result<Self, ModelError> {
        load_model(path).map(Self::new)
    }

    /// Reads, validates and wraps a RON model file with parameters given other values than
    /// the file's (`(name, value)` pairs): each is checked against its declared bounds and
    /// every field it changes, exactly as the file's values are, with the same located
    /// errors as the generated code's `Model::new`. `mode` says which parameters may be
    /// given values: those the generated code reads at run time
    /// ([`ParameterMode::AsDeclared`]), or every one a field that must be constant does not
    /// use ([`ParameterMode::AllAtRunTime`]: the numeric path has nothing folded).
    pub fn load_with(
        path: &Path,
        overrides: &[(String, f64)],
        mode: ParameterMode,
    ) -> Result<Self, ModelError> {
        let source = camchain_model::read_model_file(path, path)?;
        Self::from_source_with(&source, path, overrides, mode)
    }

    /// [`NumericModel::load_with`] on the text of a model file (`file` names it in errors;
    /// the files it names are read beside it).
    pub fn from_source_with(
        source: &str,
        file: &Path,
        overrides: &[(String, f64)],
        mode: ParameterMode,
    ) -> Result<Self, ModelError> {
        Self::from_source_in(source, file, overrides, mode, Files::BesideModel)
    }

    /// [`NumericModel::from_source_with`] reading the files the model names (its tables of
    /// points) from `files` (a built-in model's, embedded in the program).
    pub fn from_source_in(
        source: &str,
        file: &Path,
        overrides: &[(String, f64)],
        mode: ParameterMode,
        files: Files,
    ) -> Result<Self, ModelError> {
        parse_model_from(source, file, overrides, mode, files).map(Self::new)
    }

    /// The model this reference evaluates.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Generalised joint loads `M q̈ + F + Q` (13) in a single recursive pass with gravity,
    /// springs and dampers: the drive loads that produce the accelerations `qdd`.
    pub fn inverse_dynamics(&self, q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64]) {
        let poses = self.poses(q);
        let motions = self.motions(&poses, |i| qd[i], |i| qdd[i]);
        self.joint_loads(&poses, &motions, &self.gravity(), out);
        self.add_spring_dampers(q, qd, out);
    }

    fn n(&self) -> usize {
        self.bodies.len()
    }

    fn gravity(&self) -> Vec3 {
        vec3(&self.model.gravity)
    }

    /// Forward recursion of the body poses (rotations and origins).
    fn poses(&self, q: &[f64]) -> Vec<Pose> {
        let mut poses: Vec<Pose> = Vec::with_capacity(self.n());
        for (i, body) in self.bodies.iter().enumerate() {
            let parent = body.parent.map_or_else(Pose::ground, |p| poses[p]);
            poses.push(body.pose(&parent, q[i]));
        }
        poses
    }

    /// Forward recursion of velocities and accelerations (9) for joint rates `qd(i)` and
    /// joint accelerations `qdd(i)`.
    fn motions(
        &self,
        poses: &[Pose],
        qd: impl Fn(usize) -> f64,
        qdd: impl Fn(usize) -> f64,
    ) -> Vec<Motion> {
        let mut motions: Vec<Motion> = Vec::with_capacity(self.n());
        for (i, body) in self.bodies.iter().enumerate() {
            let parent = body.parent.map_or_else(Motion::rest, |p| motions[p]);
            motions.push(body.motion(&poses[i], &parent, qd(i), qdd(i)));
        }
        motions
    }

    /// Backward recursion (12): the load carried by joint i is the sum over the subtree of
    /// i of the inertial minus applied loads, its moment taken about the joint's body
    /// origin (a point of a revolute axis); projected on the joint axis it gives `out[i]`.
    fn joint_loads(&self, poses: &[Pose], motions: &[Motion], gravity: &Vec3, out: &mut [f64]) {
        let mut loads: Vec<Load> = self
            .bodies
            .iter()
            .zip(poses.iter().zip(motions))
            .map(|(b, (pose, motion))| b.own_load(pose, motion, gravity))
            .collect();
        for (i, body) in self.bodies.iter().enumerate().rev() {
            let load = loads[i];
            out[i] = match body.kind {
                JointKind::Revolute => poses[i].axis.dot(&load.moment),
                JointKind::Prismatic => poses[i].axis.dot(&load.force),
            };
            if let Some(p) = body.parent {
                loads[p].force += load.force;
                loads[p].moment += load.moment + poses[i].lever.cross(&load.force);
            }
        }
    }

    /// Adds the spring-damper loads `k (q − rest) + c q̇` (sign of (13), see [`Dynamics`]).
    fn add_spring_dampers(&self, q: &[f64], qd: &[f64], out: &mut [f64]) {
        for (i, body) in self.model.bodies.iter().enumerate() {
            if let Some(s) = &body.joint.spring {
                out[i] += s.stiffness * (q[i] - s.rest) + s.damping * qd[i];
            }
        }
    }

    /// Σ ½ k (q − rest)².
    fn spring_energy(&self, q: &[f64]) -> f64 {
        self.model
            .bodies
            .iter()
            .zip(q)
            .filter_map(|(b, qi)| {
                b.joint
                    .spring
                    .map(|s| 0.5 * s.stiffness * (qi - s.rest).powi(2))
            })
            .sum()
    }

    /// Every contact evaluated at (q, q̇): h, J, c and the outputs ([`crate::contact`]).
    fn contacts_at(&self, q: &[f64], qd: &[f64]) -> Vec<Evaluated> {
        let poses = self.poses(q);
        let motions = self.motions(&poses, |i| qd[i], |_| 0.0);
        let unit = |j: usize| self.motions(&poses, |i| f64::from(u8::from(i == j)), |_| 0.0);
        self.contacts
            .iter()
            .map(|c| c.evaluate(&poses, &motions, &unit, self.n()))
            .collect()
    }

    /// Every loop evaluated at (q, q̇): h, J, c and its points ([`crate::loops`]).
    fn loops_at(&self, q: &[f64], qd: &[f64]) -> Vec<LoopEval> {
        if self.loops.is_empty() {
            return Vec::new();
        }
        let poses = self.poses(q);
        let motions = self.motions(&poses, |i| qd[i], |_| 0.0);
        let units: Vec<Vec<Motion>> = (0..self.n())
            .map(|j| self.motions(&poses, |i| f64::from(u8::from(i == j)), |_| 0.0))
            .collect();
        self.loops
            .iter()
            .map(|l| l.evaluate(&poses, &motions, &units))
            .collect()
    }

    /// The applied joint loads τ(t, q, q̇) (zero where a joint has none).
    fn joint_loads_applied(&self, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let np = self.model.parameters.len();
        let mut values = vec![f64::NAN; np];
        values.extend(q);
        values.extend(qd);
        self.model
            .bodies
            .iter()
            .map(|b| {
                b.joint
                    .load
                    .as_ref()
                    .map_or(0.0, |load| eval_with(&load.expr, t, &values))
            })
            .collect()
    }
}

impl Dynamics for NumericModel {
    fn info(&self) -> &ModelInfo {
        &self.info
    }

    fn parameter_values(&self) -> &[f64] {
        &self.values
    }

    /// Unit-vector method: column j is the inverse dynamics with q̇ = 0, q̈ = e_j, no
    /// gravity, no springs.
    fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {
        let n = self.n();
        let poses = self.poses(q);
        let mut column = vec![0.0; n];
        for j in 0..n {
            let motions = self.motions(&poses, |_| 0.0, |i| if i == j { 1.0 } else { 0.0 });
            self.joint_loads(&poses, &motions, &Vec3::zeros(), &mut column);
            for (i, value) in column.iter().enumerate() {
                m[i * n + j] = *value;
            }
        }
    }

    /// Inverse dynamics with q̈ = 0, no gravity, no springs.
    fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {
        let poses = self.poses(q);
        let motions = self.motions(&poses, |i| qd[i], |_| 0.0);
        self.joint_loads(&poses, &motions, &Vec3::zeros(), f);
    }

    /// Inverse dynamics with q̇ = q̈ = 0 under gravity, plus `k (q − rest) + c q̇`, minus the
    /// applied joint loads.
    fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
        let poses = self.poses(q);
        let motions = self.motions(&poses, |_| 0.0, |_| 0.0);
        self.joint_loads(&poses, &motions, &self.gravity(), out);
        self.add_spring_dampers(q, qd, out);
        for (o, tau) in out.iter_mut().zip(self.joint_loads_applied(t, q, qd)) {
            *o -= tau;
        }
    }

    fn constraint(&self, q: &[f64], h: &mut [f64]) {
        let zero = vec![0.0; self.n()];
        let contacts = self.contacts_at(q, &zero).into_iter().map(|e| e.h);
        let loops = self.loops_at(q, &zero).into_iter().flat_map(|l| l.h);
        for (hk, value) in h.iter_mut().zip(contacts.chain(loops)) {
            *hk = value;
        }
    }

    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]) {
        let n = self.n();
        let zero = vec![0.0; n];
        let contacts = self.contacts_at(q, &zero).into_iter().map(|e| e.jacobian);
        let loops = self.loops_at(q, &zero).into_iter().flat_map(|l| l.jacobian);
        for (k, row) in contacts.chain(loops).enumerate() {
            j[k * n..(k + 1) * n].copy_from_slice(&row);
        }
    }

    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]) {
        let contacts = self.contacts_at(q, qd).into_iter().map(|e| e.bias);
        let loops = self.loops_at(q, qd).into_iter().flat_map(|l| l.bias);
        for (ck, value) in c.iter_mut().zip(contacts.chain(loops)) {
            *ck = value;
        }
    }

    fn loop_points(&self, q: &[f64], out: &mut [[f64; 3]]) {
        let zero = vec![0.0; self.n()];
        let points = self.loops_at(q, &zero).into_iter().flat_map(|l| l.points);
        for (o, p) in out.iter_mut().zip(points) {
            *o = p;
        }
    }

    fn contact_geometry(&self, q: &[f64], qd: &[f64], out: &mut [ContactGeometry]) {
        for (g, e) in out.iter_mut().zip(self.contacts_at(q, qd)) {
            *g = e.geometry;
        }
    }

    fn contact_kinematics_into(
        &self,
        q: &[f64],
        qd: &[f64],
        k: usize,
        out: &mut ContactKinematics,
    ) {
        if k < self.contacts.len() {
            if let Some(e) = self.contacts_at(q, qd).into_iter().nth(k) {
                *out = e.kinematics;
            }
        }
    }

    fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        for (i, body) in self.model.bodies.iter().enumerate() {
            if let Some(drive) = &body.joint.prescribed {
                [q[i], qd[i], qdd[i]] = eval_jet(&drive.expr, t);
            }
        }
    }

    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy {
        let poses = self.poses(q);
        let motions = self.motions(&poses, |i| qd[i], |_| 0.0);
        let g = self.gravity();
        let mut energy = Energy::default();
        for (body, (pose, motion)) in self.bodies.iter().zip(poses.iter().zip(&motions)) {
            energy.kinetic += body.kinetic_energy(pose, motion);
            energy.gravity -= body.mass * g.dot(&(pose.origin + pose.com_offset));
        }
        energy.spring = self.spring_energy(q);
        energy
    }

    fn load_power(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        self.joint_loads_applied(t, q, qd)
            .iter()
            .zip(qd)
            .map(|(tau, v)| tau * v)
            .sum()
    }

    fn damper_power(&self, qd: &[f64]) -> f64 {
        self.model
            .bodies
            .iter()
            .zip(qd)
            .filter_map(|(b, v)| b.joint.spring.map(|s| s.damping * v * v))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use camchain_model::model::{
        Follower, Initial, Joint, Marker, Prescribed, Simulation, SpringDamper,
    };
    use camchain_model::profile::{Func, Scalar};
    use camchain_runtime::IntegratorKind;
    use nalgebra::DMatrix;
    use std::f64::consts::PI;

    // ---------------------------------------------------------------- model building

    fn joint(kind: JointKind, axis: [f64; 3], anchor: [f64; 3], name: &str) -> Joint {
        Joint {
            kind,
            axis,
            anchor,
            coordinate: name.to_string(),
            spring: None,
            prescribed: None,
            load: None,
        }
    }

    fn body(parent: Option<usize>, joint: Joint, mass: f64, com: [f64; 3]) -> Body {
        Body {
            name: format!("body_{}", joint.coordinate),
            parent,
            mass,
            com,
            inertia: planar_inertia(0.0),
            joint,
        }
    }

    /// A thin plate in the x-y plane: Ixx + Iyy = Izz (satisfies the triangle inequality).
    fn planar_inertia(izz: f64) -> [[f64; 3]; 3] {
        [
            [izz / 2.0, 0.0, 0.0],
            [0.0, izz / 2.0, 0.0],
            [0.0, 0.0, izz],
        ]
    }

    fn spring(stiffness: f64, damping: f64, rest: f64) -> Option<SpringDamper> {
        Some(SpringDamper {
            stiffness,
            damping,
            rest,
        })
    }

    fn model(bodies: Vec<Body>, gravity: [f64; 3]) -> Model {
        let n = bodies.len();
        Model {
            parameters: Vec::new(),
            symbolic: Default::default(),
            runtime_checks: Vec::new(),
            parameters_at: Default::default(),
            name: "test".into(),
            description: "built in a unit test".into(),
            gravity,
            bodies,
            markers: Vec::new(),
            contacts: Vec::new(),
            loops: Vec::new(),
            initial: Initial {
                q: vec![0.0; n],
                qd: vec![0.0; n],
                hold: vec![false; n],
                given_q: vec![false; n],
                given_qd: vec![false; n],
            },
            simulation: Simulation {
                t_end: 1.0,
                dt_out: 0.01,
                integrator: IntegratorKind::Dopri5,
                dt: 1e-3,
                rtol: 1e-8,
                atol: 1e-10,
                restitution: None,
                formulation: Default::default(),
            },
            files: Vec::new(),
        }
    }

    fn cam(name: &str, marker: usize, profile: Scalar, x_axis: Vec3, y_axis: Vec3) -> Contact {
        Contact {
            name: name.into(),
            marker,
            follower: Follower::Knife,
            profile: Profile::Explicit {
                source: String::new(),
                f: profile,
            },
            cam_body: None,
            origin: [0.0; 3],
            x_axis: [x_axis.x, x_axis.y, x_axis.z],
            y_axis: [y_axis.x, y_axis.y, y_axis.z],
            range: None,
            design: None,
            backlash: 0.0,
            taper: 0.0,
        }
    }

    fn var() -> Box<Scalar> {
        Box::new(Scalar::Var(0))
    }
    fn cst(c: f64) -> Box<Scalar> {
        Box::new(Scalar::Const(c))
    }
    fn add(a: Scalar, b: Scalar) -> Scalar {
        Scalar::Add(Box::new(a), Box::new(b))
    }
    fn mul(a: Scalar, b: Scalar) -> Scalar {
        Scalar::Mul(Box::new(a), Box::new(b))
    }

    /// Σ c_k x^k.
    fn polynomial(coefficients: &[f64]) -> Scalar {
        coefficients
            .iter()
            .enumerate()
            .map(|(k, c)| mul(Scalar::Const(*c), Scalar::Powi(var(), k as i32)))
            .reduce(add)
            .unwrap_or(Scalar::Const(0.0))
    }

    // ------------------------------------------------------------- dense accessors

    fn mass(m: &NumericModel, q: &[f64]) -> DMatrix<f64> {
        let n = q.len();
        let mut data = vec![0.0; n * n];
        m.mass_matrix(q, &mut data);
        DMatrix::from_row_slice(n, n, &data)
    }

    fn inertial(m: &NumericModel, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let mut f = vec![0.0; q.len()];
        m.inertial_forces(q, qd, &mut f);
        f
    }

    fn applied(m: &NumericModel, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let mut f = vec![0.0; q.len()];
        m.applied_forces(0.0, q, qd, &mut f);
        f
    }

    fn gaps(m: &NumericModel, q: &[f64]) -> Vec<f64> {
        let mut h = vec![0.0; m.info().n_contacts()];
        m.constraint(q, &mut h);
        h
    }

    fn jacobian(m: &NumericModel, q: &[f64]) -> DMatrix<f64> {
        let (nc, n) = (m.info().n_contacts(), q.len());
        let mut j = vec![0.0; nc * n];
        m.constraint_jacobian(q, &mut j);
        DMatrix::from_row_slice(nc, n, &j)
    }

    fn bias(m: &NumericModel, q: &[f64], qd: &[f64]) -> Vec<f64> {
        let mut c = vec![0.0; m.info().n_contacts()];
        m.constraint_bias(q, qd, &mut c);
        c
    }

    fn quadratic_form(m: &DMatrix<f64>, v: &[f64]) -> f64 {
        let v = nalgebra::DVector::from_column_slice(v);
        v.dot(&(m * &v))
    }

    fn shifted(q: &[f64], dir: &[f64], s: f64) -> Vec<f64> {
        q.iter().zip(dir).map(|(a, d)| a + s * d).collect()
    }

    fn unit(n: usize, i: usize) -> Vec<f64> {
        (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()
    }

    // ---------------------------------------------------------- finite differences
    //
    // Every finite difference below is central with step H = 1e-5 on quantities of order 1
    // (lengths 0.1–1 m, masses 0.5–2 kg, rates ~1/s): the truncation error is
    // H²/6·|f'''| ≈ 2e-11 and the rounding error ≈ 1e-16·|f|/H ≈ 1e-11, so FD_TOL = 1e-8
    // (scaled by 1 + the size of the compared quantity) has a ~100× margin, while a wrong
    // term (a missing Coriolis factor, a wrong sign, a wrong lever) errs at O(0.01–1).
    const H: f64 = 1e-5;
    const FD_TOL: f64 = 1e-8;

    /// d/ds f(q + s·dir) at s = 0.
    fn directional(f: impl Fn(&[f64]) -> Vec<f64>, q: &[f64], dir: &[f64]) -> Vec<f64> {
        let plus = f(&shifted(q, dir, H));
        let minus = f(&shifted(q, dir, -H));
        plus.iter()
            .zip(&minus)
            .map(|(p, m)| (p - m) / (2.0 * H))
            .collect()
    }

    /// ∂f/∂q_i for every i.
    fn gradient(f: impl Fn(&[f64]) -> f64, q: &[f64]) -> Vec<f64> {
        (0..q.len())
            .map(|i| directional(|x| vec![f(x)], q, &unit(q.len(), i))[0])
            .collect()
    }

    fn assert_close(got: &[f64], expected: &[f64], tol: f64, what: &str) {
        assert_eq!(got.len(), expected.len(), "{what}: lengths");
        let scale = 1.0 + expected.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for (i, (g, e)) in got.iter().zip(expected).enumerate() {
            assert!(
                (g - e).abs() <= tol * scale,
                "{what}[{i}]: got {g}, expected {e} (tol {tol} × {scale})"
            );
        }
    }

    // ---------------------------------------------------------------- generic checks

    /// Round-off in the recursions is ~1e-16 per operation over a few hundred operations:
    /// 1e-12 relative bounds it with a wide margin; model errors are O(1e-3) or more.
    const EXACT_TOL: f64 = 1e-12;

    fn check_mass_matrix_symmetric_positive_definite(m: &NumericModel, q: &[f64]) {
        let mm = mass(m, q);
        let asym = (&mm - mm.transpose()).amax();
        assert!(asym <= EXACT_TOL * mm.amax(), "M not symmetric: {asym}");
        assert!(
            mm.clone().cholesky().is_some(),
            "M not positive definite:\n{mm}"
        );
    }

    /// M_ij = T(e_i + e_j) − T(e_i) − T(e_j) with T the kinetic energy summed from the body
    /// velocities (no inverse dynamics involved): determines all of M.
    fn check_mass_matrix_by_energy_polarization(m: &NumericModel, q: &[f64]) {
        let n = q.len();
        let mm = mass(m, q);
        let kinetic = |qd: &[f64]| m.energy(q, qd).kinetic;
        for i in 0..n {
            for j in 0..n {
                let both = shifted(&unit(n, i), &unit(n, j), 1.0);
                let mij = kinetic(&both) - kinetic(&unit(n, i)) - kinetic(&unit(n, j));
                assert_relative_eq!(mm[(i, j)], mij, epsilon = EXACT_TOL, max_relative = 1e-10);
            }
        }
    }

    fn check_kinetic_energy_is_quadratic_form(m: &NumericModel, q: &[f64], qd: &[f64]) {
        let t = 0.5 * quadratic_form(&mass(m, q), qd);
        assert_relative_eq!(m.energy(q, qd).kinetic, t, max_relative = EXACT_TOL);
    }

    /// Lagrange: F = Ṁ q̇ − ½ ∂(q̇ᵀ M q̇)/∂q, i.e. F_i = Σ_jk Γ_ijk q̇_j q̇_k with the
    /// Christoffel symbols of M. Ṁ and the gradient by central differences of M.
    fn check_inertial_forces_by_christoffel(m: &NumericModel, q: &[f64], qd: &[f64]) {
        let mass_times_qd = |x: &[f64]| {
            (mass(m, x) * nalgebra::DVector::from_column_slice(qd))
                .iter()
                .copied()
                .collect::<Vec<_>>()
        };
        let m_dot_qd = directional(mass_times_qd, q, qd);
        let grad = gradient(|x| quadratic_form(&mass(m, x), qd), q);
        let expected: Vec<f64> = m_dot_qd
            .iter()
            .zip(&grad)
            .map(|(a, g)| a - 0.5 * g)
            .collect();
        assert_close(&inertial(m, q, qd), &expected, FD_TOL, "F vs Christoffel");
    }

    /// Q(q, 0) = ∂(V_gravity + V_spring)/∂q, and the damper adds c q̇.
    fn check_applied_forces_by_potential(m: &NumericModel, q: &[f64], qd: &[f64]) {
        let zero = vec![0.0; q.len()];
        let potential = |x: &[f64]| {
            let e = m.energy(x, &zero);
            e.gravity + e.spring
        };
        assert_close(
            &applied(m, q, &zero),
            &gradient(potential, q),
            FD_TOL,
            "Q vs ∇V",
        );
        let damper: Vec<f64> = applied(m, q, qd)
            .iter()
            .zip(applied(m, q, &zero))
            .map(|(a, b)| a - b)
            .collect();
        let damper_power: f64 = damper.iter().zip(qd).map(|(f, v)| f * v).sum();
        assert_relative_eq!(damper_power, m.damper_power(qd), max_relative = EXACT_TOL);
    }

    /// The one-pass inverse dynamics equals M q̈ + F + Q assembled from the three parts.
    fn check_inverse_dynamics_composes(m: &NumericModel, q: &[f64], qd: &[f64], qdd: &[f64]) {
        let mq = mass(m, q) * nalgebra::DVector::from_column_slice(qdd);
        let (f, g) = (inertial(m, q, qd), applied(m, q, qd));
        let expected: Vec<f64> = (0..q.len()).map(|i| mq[i] + f[i] + g[i]).collect();
        let mut got = vec![0.0; q.len()];
        m.inverse_dynamics(q, qd, qdd, &mut got);
        assert_close(&got, &expected, EXACT_TOL, "inverse dynamics");
    }

    /// J1, J2 against FD of f1, f2; J against FD of h; the convective terms against the
    /// directional derivative of J_k q̇ along q̇ (since d/ds [J(q + s q̇) q̇] = q̇ᵀ ∇²f q̇);
    /// c of (8) against the same for h.
    fn check_contact_kinematics_by_differences(m: &NumericModel, q: &[f64], qd: &[f64]) {
        let n = q.len();
        for k in 0..m.info().n_contacts() {
            let kin = m.contact_kinematics(q, qd, k);
            let f12 = |x: &[f64]| {
                let kin = m.contact_kinematics(x, qd, k);
                vec![kin.x, kin.y]
            };
            let (fd_j1, fd_j2): (Vec<f64>, Vec<f64>) = (0..n)
                .map(|i| {
                    let d = directional(f12, q, &unit(n, i));
                    (d[0], d[1])
                })
                .unzip();
            assert_close(&kin.j1, &fd_j1, FD_TOL, "J1");
            assert_close(&kin.j2, &fd_j2, FD_TOL, "J2");

            let j_row: Vec<f64> = jacobian(m, q).row(k).iter().copied().collect();
            let fd_j = gradient(|x| gaps(m, x)[k], q);
            assert_close(&j_row, &fd_j, FD_TOL, "J");

            let rates = |x: &[f64]| {
                let kin = m.contact_kinematics(x, qd, k);
                let dot = |row: &[f64]| row.iter().zip(qd).map(|(a, b)| a * b).sum::<f64>();
                let j_qd: f64 = jacobian(m, x)
                    .row(k)
                    .iter()
                    .zip(qd)
                    .map(|(a, b)| a * b)
                    .sum();
                vec![dot(&kin.j1), dot(&kin.j2), j_qd]
            };
            let conv = directional(rates, q, qd);
            assert_close(&[kin.conv1, kin.conv2], &conv[..2], FD_TOL, "convective");
            assert_close(&[bias(m, q, qd)[k]], &conv[2..], FD_TOL, "bias c");
        }
    }

    fn check_all(m: &NumericModel, q: &[f64], qd: &[f64], qdd: &[f64]) {
        check_mass_matrix_symmetric_positive_definite(m, q);
        check_mass_matrix_by_energy_polarization(m, q);
        check_kinetic_energy_is_quadratic_form(m, q, qd);
        check_inertial_forces_by_christoffel(m, q, qd);
        check_applied_forces_by_potential(m, q, qd);
        check_inverse_dynamics_composes(m, q, qd, qdd);
        check_contact_kinematics_by_differences(m, q, qd);
    }

    // ------------------------------------------------------------ closed-form cases

    const G: f64 = 9.81;

    #[test]
    fn single_pendulum_closed_form() {
        let (m1, d, izz) = (1.5, 0.4, 0.07);
        let j = joint(JointKind::Revolute, [0.0, 0.0, 1.0], [0.2, 0.5, 0.0], "q1");
        let mut b = body(None, j, m1, [d, 0.0, 0.0]);
        b.inertia = planar_inertia(izz);
        let nm = NumericModel::new(model(vec![b], [0.0, -G, 0.0]));
        let q = [0.6];
        assert_relative_eq!(
            mass(&nm, &q)[(0, 0)],
            izz + m1 * d * d,
            max_relative = EXACT_TOL
        );
        assert_close(&inertial(&nm, &q, &[2.0]), &[0.0], EXACT_TOL, "F");
        // Holding torque against gravity: m g d cos q.
        let torque = m1 * G * d * q[0].cos();
        assert_close(&applied(&nm, &q, &[2.0]), &[torque], EXACT_TOL, "Q");
    }

    fn double_pendulum() -> (NumericModel, [f64; 7]) {
        let (m1, l1, d1, i1) = (1.2, 0.5, 0.2, 0.03);
        let (m2, d2, i2) = (0.8, 0.25, 0.02);
        let j1 = joint(JointKind::Revolute, [0.0, 0.0, 1.0], [0.0; 3], "q1");
        let j2 = joint(JointKind::Revolute, [0.0, 0.0, 1.0], [l1, 0.0, 0.0], "q2");
        let mut b1 = body(None, j1, m1, [d1, 0.0, 0.0]);
        let mut b2 = body(Some(0), j2, m2, [d2, 0.0, 0.0]);
        b1.inertia = planar_inertia(i1);
        b2.inertia = planar_inertia(i2);
        let nm = NumericModel::new(model(vec![b1, b2], [0.0, -G, 0.0]));
        (nm, [m1, l1, d1, i1, m2, d2, i2])
    }

    #[test]
    fn double_pendulum_closed_form() {
        let (nm, [m1, l1, d1, i1, m2, d2, i2]) = double_pendulum();
        let (q, qd): ([f64; 2], [f64; 2]) = ([0.4, -1.1], [0.9, -1.7]);
        let c2 = q[1].cos();
        let m11 = i1 + i2 + m1 * d1 * d1 + m2 * (l1 * l1 + d2 * d2 + 2.0 * l1 * d2 * c2);
        let m12 = i2 + m2 * (d2 * d2 + l1 * d2 * c2);
        let m22 = i2 + m2 * d2 * d2;
        let mm = mass(&nm, &q);
        let expected = DMatrix::from_row_slice(2, 2, &[m11, m12, m12, m22]);
        assert_relative_eq!(mm, expected, max_relative = EXACT_TOL, epsilon = EXACT_TOL);

        let hh = m2 * l1 * d2 * q[1].sin();
        let f = [
            -hh * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]),
            hh * qd[0] * qd[0],
        ];
        assert_close(&inertial(&nm, &q, &qd), &f, EXACT_TOL, "Coriolis");

        let c1 = q[0].cos();
        let c12 = (q[0] + q[1]).cos();
        let g2 = m2 * d2 * G * c12;
        let g1 = (m1 * d1 + m2 * l1) * G * c1 + g2;
        assert_close(
            &applied(&nm, &q, &[0.0, 0.0]),
            &[g1, g2],
            EXACT_TOL,
            "gravity",
        );
    }

    /// A slider on a turning arm (polar coordinates θ, r): body 1 turns about z, body 2
    /// slides along body 1's x axis with its centre of mass at its origin.
    #[test]
    fn prismatic_slider_on_a_turning_arm_closed_form() {
        let (i1, m2, i2, k, c, rest) = (0.05, 0.7, 0.01, 30.0, 0.4, 0.25);
        let j1 = joint(JointKind::Revolute, [0.0, 0.0, 1.0], [0.0; 3], "theta");
        let mut j2 = joint(JointKind::Prismatic, [1.0, 0.0, 0.0], [0.0; 3], "r");
        j2.spring = spring(k, c, rest);
        let mut b1 = body(None, j1, 2.0, [0.0; 3]);
        let mut b2 = body(Some(0), j2, m2, [0.0; 3]);
        b1.inertia = planar_inertia(i1);
        b2.inertia = planar_inertia(i2);
        let nm = NumericModel::new(model(vec![b1, b2], [0.0, -G, 0.0]));
        let (q, qd): ([f64; 2], [f64; 2]) = ([0.7, 0.4], [1.3, -0.6]);
        let (th, r) = (q[0], q[1]);

        let expected = DMatrix::from_row_slice(2, 2, &[i1 + i2 + m2 * r * r, 0.0, 0.0, m2]);
        assert_relative_eq!(
            mass(&nm, &q),
            expected,
            max_relative = EXACT_TOL,
            epsilon = EXACT_TOL
        );
        let f = [2.0 * m2 * r * qd[1] * qd[0], -m2 * r * qd[0] * qd[0]];
        assert_close(&inertial(&nm, &q, &qd), &f, EXACT_TOL, "Coriolis");
        let g = [
            m2 * G * r * th.cos(),
            m2 * G * th.sin() + k * (r - rest) + c * qd[1],
        ];
        assert_close(&applied(&nm, &q, &qd), &g, EXACT_TOL, "Q");
        let e = nm.energy(&q, &qd);
        assert_relative_eq!(
            e.spring,
            0.5 * k * (r - rest).powi(2),
            max_relative = EXACT_TOL
        );
        assert_relative_eq!(e.gravity, m2 * G * r * th.sin(), max_relative = EXACT_TOL);
        assert_relative_eq!(
            nm.damper_power(&qd),
            c * qd[1] * qd[1],
            max_relative = EXACT_TOL
        );
        check_all(&nm, &q, &qd, &[0.3, -0.8]);
    }

    // ----------------------------------------------------------- the paper's chain

    const BASE: [f64; 2] = [0.38, 0.80];
    const LENGTHS: [f64; 4] = [0.3, 0.1, 0.3, 0.3];

    /// docs/method.md §7: revolute, revolute, prismatic, revolute; concave cam.
    fn paper_chain() -> NumericModel {
        let masses = [1.0, 0.5, 1.0, 1.0];
        let inertias = [0.10, 0.01, 0.10, 0.10];
        let z = [0.0, 0.0, 1.0];
        let x = [1.0, 0.0, 0.0];
        let [l1, l2, l3, l4] = LENGTHS;
        let mut joints = [
            joint(JointKind::Revolute, z, [BASE[0], BASE[1], 0.0], "q1"),
            joint(JointKind::Revolute, z, [l1, 0.0, 0.0], "q2"),
            joint(JointKind::Prismatic, x, [l2, 0.0, 0.0], "q3"),
            joint(JointKind::Revolute, z, [l3, 0.0, 0.0], "q4"),
        ];
        for (j, k) in joints.iter_mut().skip(1).zip([15.0, 40.0, 18.0]) {
            j.spring = spring(k, 1.0, 0.0);
        }
        let bodies = joints
            .into_iter()
            .enumerate()
            .map(|(i, j)| {
                let mut b = body(i.checked_sub(1), j, masses[i], [LENGTHS[i] / 2.0, 0.0, 0.0]);
                b.inertia = planar_inertia(inertias[i]);
                b
            })
            .collect();
        let mut m = model(bodies, [0.0, -G, 0.0]);
        m.markers.push(Marker {
            name: "A".into(),
            body: 3,
            position: [l4, 0.0, 0.0],
        });
        let concave = polynomial(&[0.0, -0.595, 0.5, 0.5]);
        m.contacts.push(cam("A", 0, concave, Vec3::x(), Vec3::y()));
        NumericModel::new(m)
    }

    const PAPER_Q: [f64; 4] = [-PI / 2.0 - 0.1, 0.3, 0.05, -0.2];
    const PAPER_QD: [f64; 4] = [0.7, -0.4, 0.3, 1.1];

    #[test]
    fn paper_chain_contact_point_closed_form() {
        let nm = paper_chain();
        let q = PAPER_Q;
        let [l1, l2, l3, l4] = LENGTHS;
        let reach = l2 + q[2] + l3;
        let (a1, a12, a124) = (q[0], q[0] + q[1], q[0] + q[1] + q[3]);
        let x = BASE[0] + l1 * a1.cos() + reach * a12.cos() + l4 * a124.cos();
        let y = BASE[1] + l1 * a1.sin() + reach * a12.sin() + l4 * a124.sin();
        let g = nm.contact_kinematics(&q, &PAPER_QD, 0).geometry;
        assert_relative_eq!(g.x, x, max_relative = EXACT_TOL);
        assert_relative_eq!(g.y, y, max_relative = EXACT_TOL);
        assert_eq!(g.position[2], 0.0);
        let (slope, second) = (-0.595 + x + 1.5 * x * x, 1.0 + 3.0 * x);
        let stretch = (1.0 + slope * slope).sqrt();
        assert_relative_eq!(g.force_scale, stretch, max_relative = EXACT_TOL);
        assert_relative_eq!(g.normal[0], -slope / stretch, max_relative = EXACT_TOL);
        assert_relative_eq!(g.normal[1], 1.0 / stretch, max_relative = EXACT_TOL);
        assert_relative_eq!(
            g.curvature,
            second / stretch.powi(3),
            max_relative = EXACT_TOL
        );
        let f3 = -0.595 * x + 0.5 * x * x + 0.5 * x.powi(3);
        assert_relative_eq!(gaps(&nm, &q)[0], y - f3, max_relative = EXACT_TOL);
        let mut geometry = [ContactGeometry::default()];
        nm.contact_geometry(&q, &PAPER_QD, &mut geometry);
        assert_eq!(geometry[0], g);
    }

    #[test]
    fn paper_chain_dynamics_and_contact_derivatives() {
        let nm = paper_chain();
        check_all(&nm, &PAPER_Q, &PAPER_QD, &[0.5, -1.0, 2.0, 0.1]);
        // A second configuration, bent the other way.
        check_all(
            &nm,
            &[-1.2, -0.5, -0.1, 0.6],
            &[-1.0, 0.8, -0.2, 0.5],
            &[0.0; 4],
        );
    }

    #[test]
    fn paper_chain_info() {
        let nm = paper_chain();
        let info = nm.info();
        assert_eq!(info.n(), 4);
        assert_eq!(info.contacts, vec![ContactInfo::knife("A")]);
        assert!(!info.spatial);
        assert_eq!(info.coordinate_index("q3"), Some(2));
        assert_eq!(info.coordinates[2].kind, JointKind::Prismatic);
        assert_eq!(info.coordinates[3].kind, JointKind::Revolute);
        assert!(info.coordinates.iter().all(|c| !c.driven));
        assert_eq!(info.defaults.integrator, IntegratorKind::Dopri5);
        assert_eq!(nm.model().name, "test");
    }

    #[test]
    fn prescribed_drive_of_the_driven_scenario() {
        let mut m = paper_chain().model().clone();
        // q1(t) = −π/2 + 0.45 sin(2πt/4)
        let omega = 2.0 * PI / 4.0;
        let expr = add(
            Scalar::Const(-PI / 2.0),
            mul(
                Scalar::Const(0.45),
                Scalar::Call(
                    Func::Sin,
                    Box::new(mul(Scalar::Const(omega), Scalar::Var(0))),
                ),
            ),
        );
        m.bodies[0].joint.prescribed = Some(Prescribed {
            source: "-PI/2 + 0.45*(2*PI*t/4).sin()".into(),
            expr,
        });
        let nm = NumericModel::new(m);
        assert!(nm.info().coordinates[0].driven);
        let t = 1.3;
        let (mut q, mut qd, mut qdd) = ([9.0; 4], [9.0; 4], [9.0; 4]);
        nm.prescribed(t, &mut q, &mut qd, &mut qdd);
        let s = (omega * t).sin();
        let c = (omega * t).cos();
        assert_relative_eq!(q[0], -PI / 2.0 + 0.45 * s, max_relative = EXACT_TOL);
        assert_relative_eq!(qd[0], 0.45 * omega * c, max_relative = EXACT_TOL);
        assert_relative_eq!(qdd[0], -0.45 * omega * omega * s, max_relative = EXACT_TOL);
        assert_eq!(
            (&q[1..], &qd[1..], &qdd[1..]),
            (&[9.0; 3][..], &[9.0; 3][..], &[9.0; 3][..])
        );
    }

    // ------------------------------------------------------------ a spatial tree

    fn normalized(v: [f64; 3]) -> [f64; 3] {
        let u = vec3(&v).normalize();
        [u.x, u.y, u.z]
    }

    /// An inertia with principal moments `p` (obeying the triangle inequality) rotated by
    /// `angle` about `axis`: symmetric positive definite, with products of inertia.
    fn full_inertia(p: [f64; 3], axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
        let r = Rotation3::from_axis_angle(&Unit::new_normalize(vec3(&axis)), angle);
        let i = r.matrix() * Mat3::from_diagonal(&vec3(&p)) * r.matrix().transpose();
        [0, 1, 2].map(|row| [0, 1, 2].map(|col| i[(row, col)]))
    }

    /// Five bodies: 0 turns about z; 1 (revolute, tilted axis) and 2 (prismatic, oblique
    /// axis) are both children of 0; 3 (revolute) hangs from the slider 2 and 4 (revolute)
    /// from 1. Two contacts on oblique cam planes, markers on the two leaves.
    fn spatial_tree() -> NumericModel {
        /// (parent, kind, axis, anchor, mass, com) of each body.
        type Spec = (Option<usize>, JointKind, [f64; 3], [f64; 3], f64, [f64; 3]);
        let specs: [Spec; 5] = [
            (
                None,
                JointKind::Revolute,
                [0.0, 0.0, 1.0],
                [0.1, -0.2, 0.3],
                2.0,
                [0.2, 0.05, -0.03],
            ),
            (
                Some(0),
                JointKind::Revolute,
                [1.0, 1.0, 0.5],
                [0.4, 0.0, 0.1],
                1.2,
                [0.15, 0.02, 0.04],
            ),
            (
                Some(0),
                JointKind::Prismatic,
                [0.3, -1.0, 0.6],
                [0.0, 0.2, -0.1],
                0.8,
                [0.05, -0.1, 0.02],
            ),
            (
                Some(2),
                JointKind::Revolute,
                [1.0, 0.2, -0.4],
                [0.1, 0.1, 0.2],
                0.6,
                [0.1, 0.0, 0.05],
            ),
            (
                Some(1),
                JointKind::Revolute,
                [0.0, 1.0, 0.0],
                [0.3, -0.1, 0.0],
                0.9,
                [0.2, 0.1, -0.1],
            ),
        ];
        let bodies = specs
            .iter()
            .enumerate()
            .map(|(i, (parent, kind, axis, anchor, m, com))| {
                let mut j = joint(*kind, normalized(*axis), *anchor, &format!("q{i}"));
                if i % 2 == 0 {
                    j.spring = spring(5.0 + i as f64, 0.3, 0.1 * i as f64);
                }
                let mut b = body(*parent, j, *m, *com);
                let p = [0.02 + 0.01 * i as f64, 0.03, 0.04];
                b.inertia = full_inertia(p, [1.0, -0.5, 0.3 * i as f64], 0.7 + 0.2 * i as f64);
                b
            })
            .collect();
        let mut m = model(bodies, [0.5, -G, -1.0]);
        m.markers.push(Marker {
            name: "A".into(),
            body: 3,
            position: [0.2, -0.1, 0.15],
        });
        m.markers.push(Marker {
            name: "B".into(),
            body: 4,
            position: [0.25, 0.05, -0.1],
        });
        let x_axis = Vec3::new(1.0, 0.3, 0.2).normalize();
        let y_raw = Vec3::new(-0.2, 1.0, 0.4);
        let y_axis = (y_raw - x_axis * x_axis.dot(&y_raw)).normalize();
        // 0.1 sin(2x) + 0.05 x² − 0.3
        let wavy = add(
            mul(
                Scalar::Const(0.1),
                Scalar::Call(Func::Sin, Box::new(mul(Scalar::Const(2.0), Scalar::Var(0)))),
            ),
            polynomial(&[-0.3, 0.0, 0.05]),
        );
        // 0.2 atan(x) + (x² + 1)^0.7 · exp(0.3 x) / 10
        let smooth = add(
            mul(Scalar::Const(0.2), Scalar::Call(Func::Atan, var())),
            Scalar::Div(
                Box::new(mul(
                    Scalar::Powf(Box::new(polynomial(&[1.0, 0.0, 1.0])), cst(0.7)),
                    Scalar::Call(Func::Exp, Box::new(mul(Scalar::Const(0.3), Scalar::Var(0)))),
                )),
                cst(10.0),
            ),
        );
        m.contacts.push(cam("A", 0, wavy, x_axis, y_axis));
        m.contacts
            .push(cam("B", 1, smooth, y_axis, x_axis.cross(&y_axis)));
        NumericModel::new(m)
    }

    #[test]
    fn spatial_tree_dynamics_and_contact_derivatives() {
        let nm = spatial_tree();
        assert!(nm.info().spatial);
        let q = [0.4, -0.7, 0.15, 1.1, 0.5];
        let qd = [0.8, -1.2, 0.5, 0.9, -0.6];
        check_all(&nm, &q, &qd, &[0.3, 0.2, -0.5, 1.0, 0.7]);
        check_all(
            &nm,
            &[-1.0, 2.0, -0.2, -0.4, 2.5],
            &[-0.3, 0.6, -1.0, 1.5, 0.2],
            &[0.0; 5],
        );
    }

    /// Joint i moves only its subtree: the contact on leaf 3 (path 0 → 2 → 3) has zero
    /// Jacobian entries for joints 1 and 4 of the other branch.
    #[test]
    fn spatial_tree_jacobian_follows_the_branches() {
        let nm = spatial_tree();
        let q = [0.4, -0.7, 0.15, 1.1, 0.5];
        let a = nm.contact_kinematics(&q, &[0.0; 5], 0);
        let b = nm.contact_kinematics(&q, &[0.0; 5], 1);
        assert_eq!((a.j1[1], a.j1[4], a.j2[1], a.j2[4]), (0.0, 0.0, 0.0, 0.0));
        assert_eq!((b.j1[2], b.j1[3], b.j2[2], b.j2[3]), (0.0, 0.0, 0.0, 0.0));
        assert!(a.j1[2].abs() > 0.1 && b.j1[4].abs() > 0.01);
    }
}
