//! The validated model: what the derivation and the numeric reference work from.
//!
//! [`crate::schema`] parses the RON file into these types and checks them, so everything
//! here is physically valid: positive masses, symmetric positive-definite inertias obeying
//! the triangle inequality, unit joint axes, a tree whose bodies are listed parents-first,
//! parsed profile and drive expressions.

use crate::profile::Scalar;

/// Kind of one-degree-of-freedom joint between a body and its parent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum JointKind {
    /// Rotation about `axis` through `anchor`; the coordinate is an angle in radians.
    Revolute,
    /// Translation along `axis`; the coordinate is a displacement in metres.
    Prismatic,
}

/// A linear spring-damper acting in a joint: generalised load `-k (q - rest) - c q̇`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringDamper {
    /// Stiffness k (N/m or N·m/rad), >= 0.
    pub stiffness: f64,
    /// Damping c (N·s/m or N·m·s/rad), >= 0.
    pub damping: f64,
    /// Value of the coordinate at which the spring is relaxed.
    pub rest: f64,
}

/// A prescribed joint motion q(t) (a driving constraint, the paper's guide).
#[derive(Debug, Clone, PartialEq)]
pub struct Prescribed {
    /// The expression as written in the model file (Rust syntax, variable `t`).
    pub source: String,
    /// The parsed expression, variable = t.
    pub expr: Scalar,
}

/// The joint that connects a body to its parent.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Unit axis in the parent's frame.
    pub axis: [f64; 3],
    /// Joint point in the parent's frame. At q = 0 the body's frame coincides with the
    /// parent's frame translated to this point (no constant rotation).
    pub anchor: [f64; 3],
    /// Name of the generalised coordinate (e.g. `q1`).
    pub coordinate: String,
    /// Optional spring-damper in the joint.
    pub spring: Option<SpringDamper>,
    /// Optional prescribed motion; the coordinate is then known and its drive load reported.
    pub prescribed: Option<Prescribed>,
}

/// A rigid body. Body `i` carries joint `i` and generalised coordinate `i`.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Unique name.
    pub name: String,
    /// Index of the parent body, `None` for the ground. Always smaller than this body's index.
    pub parent: Option<usize>,
    /// Mass in kg, > 0.
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass, body axes, row-major (kg·m²), SPD.
    pub inertia: [[f64; 3]; 3],
    /// The joint to the parent.
    pub joint: Joint,
}

/// A named point fixed on a body.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Unique name.
    pub name: String,
    /// Index of the body carrying it.
    pub body: usize,
    /// Position in the body frame (m).
    pub position: [f64; 3],
}

/// A fixed cam y = f(x) in a plane fixed to the ground, touched by a marker (eq. 1–3).
///
/// The cam coordinates of a ground point p are `x = x_axis·(p − origin)`,
/// `y = y_axis·(p − origin)`; the constraint is `h = y − f(x) = 0`. The cam is the
/// cylinder swept by the profile along `x_axis × y_axis`, its material on the side y < f(x),
/// so the normal force is positive when the cam pushes the marker towards +y.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Name of the contact = name of its marker (e.g. `A`).
    pub name: String,
    /// Index into [`Model::markers`].
    pub marker: usize,
    /// The profile as written (Rust syntax, variable `x`).
    pub profile_source: String,
    /// Parsed profile, variable = x.
    pub profile: Scalar,
    /// Origin of the cam frame in ground coordinates.
    pub origin: [f64; 3],
    /// Unit x axis of the cam plane, in ground coordinates.
    pub x_axis: [f64; 3],
    /// Unit y axis of the cam plane, orthogonal to `x_axis`.
    pub y_axis: [f64; 3],
}

/// Integrator named in the model's default settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntegratorChoice {
    /// Classical fixed-step Runge–Kutta 4.
    Rk4,
    /// Adaptive embedded Dormand–Prince 5(4).
    Dopri5,
    /// Adaptive Dormand–Prince 8(5,3) with dense output.
    Dop853,
}

/// Default simulation settings stored with the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// End time (s), > 0.
    pub t_end: f64,
    /// Output interval (s), > 0.
    pub dt_out: f64,
    /// Integrator.
    pub integrator: IntegratorChoice,
    /// Fixed step for RK4 / initial step for adaptive integrators (s), > 0.
    pub dt: f64,
    /// Relative tolerance of adaptive integrators.
    pub rtol: f64,
    /// Absolute tolerance of adaptive integrators.
    pub atol: f64,
}

/// Initial guess and assembly instructions.
#[derive(Debug, Clone, PartialEq)]
pub struct Initial {
    /// Guess for every coordinate, in body order (0 where the file gives none).
    pub q: Vec<f64>,
    /// Guess for every velocity, in body order (0 where the file gives none).
    pub qd: Vec<f64>,
    /// `hold[i]`: coordinate i keeps its guessed value during assembly.
    pub hold: Vec<bool>,
    /// `given_q[i]`: the file gives coordinate i's guess (otherwise it is 0).
    pub given_q: Vec<bool>,
    /// `given_qd[i]`: the file gives velocity i's guess (otherwise it is 0).
    pub given_qd: Vec<bool>,
}

/// A complete, validated model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Model name (a Rust identifier; the file stem unless the file says otherwise).
    pub name: String,
    /// Free text from the file.
    pub description: String,
    /// Gravity vector in ground coordinates (m/s²).
    pub gravity: [f64; 3],
    /// Bodies, parents before children.
    pub bodies: Vec<Body>,
    /// Named points.
    pub markers: Vec<Marker>,
    /// Cam contacts.
    pub contacts: Vec<Contact>,
    /// Initial guess.
    pub initial: Initial,
    /// Default simulation settings.
    pub simulation: Simulation,
}

impl Model {
    /// Number of generalised coordinates (= number of bodies = number of joints).
    pub fn n(&self) -> usize {
        self.bodies.len()
    }

    /// Coordinate names in order.
    pub fn coordinate_names(&self) -> Vec<&str> {
        self.bodies
            .iter()
            .map(|b| b.joint.coordinate.as_str())
            .collect()
    }

    /// True when every joint axis is along z and every anchor, centre of mass, marker and
    /// cam plane lies in the x-y plane: then the contact point has no z coordinate to report.
    pub fn is_planar(&self) -> bool {
        let z_axis = |a: &[f64; 3]| a[0] == 0.0 && a[1] == 0.0;
        let in_plane = |p: &[f64; 3]| p[2] == 0.0;
        self.bodies.iter().all(|b| match b.joint.kind {
            JointKind::Revolute => z_axis(&b.joint.axis) && in_plane(&b.joint.anchor),
            JointKind::Prismatic => in_plane(&b.joint.axis) && in_plane(&b.joint.anchor),
        }) && self.bodies.iter().all(|b| in_plane(&b.com))
            && self.markers.iter().all(|m| in_plane(&m.position))
            && self
                .contacts
                .iter()
                .all(|c| in_plane(&c.origin) && in_plane(&c.x_axis) && in_plane(&c.y_axis))
            && self.gravity[2] == 0.0
    }
}
