//! The validated model: what the derivation and the numeric reference work from.
//!
//! [`crate::schema`] parses the RON file into these types and checks them, so everything
//! here is physically valid: positive masses, symmetric positive-definite inertias obeying
//! the triangle inequality, unit joint axes, a tree whose bodies are listed parents-first,
//! parsed profile and drive expressions.

use crate::profile::Scalar;
pub use camchain_runtime::{FollowerKind, Formulation, IntegratorKind, JointKind, LoopKind};
use serde::Deserialize;

mod cam_profile;
pub use cam_profile::Profile;

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

/// A generalised force applied in a joint (a motor torque, a force on a slider), positive in
/// the direction of the joint's coordinate: an expression of the time `t`, the coordinates
/// and their rates (`q1`, `q1_dot`) and the parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLoad {
    /// The expression as written in the model file.
    pub source: String,
    /// The parsed expression: its variable is t; [`Scalar::Param`] `i` is the model's
    /// parameter i for `i < np` (every one resolved to its value here, the run-time ones kept
    /// in [`Model::symbolic`] under [`Field::Load`]), coordinate `k` for `i = np + k` and its
    /// rate for `i = np + n + k` (np parameters, n coordinates).
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
    /// Optional applied load (not on a prescribed joint).
    pub load: Option<JointLoad>,
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

/// The shape a follower presents to its cam (docs/model-format.md, "Contacts"): its kind
/// ([`FollowerKind`], the project's one list of follower kinds, with their names) and the
/// kind's dimensions. `N` is how a dimension is given: a number (`f64`, the validated
/// model) or, in the model file as read, a number or a run-time parameter's name.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Follower<N = f64> {
    /// The marker itself touches the profile: the paper's knife edge (eq. 1–3).
    #[default]
    Knife,
    /// A circle of radius `radius` (m, > 0) centred on the marker: its centre stays on the
    /// profile's offset (pitch) curve. A cylinder whose axis is parallel to the cam's, or a
    /// ball: both touch the cam at the in-plane distance `radius`. Massless, rolling without
    /// slip: its spin does not enter the dynamics.
    Roller {
        /// Radius (m).
        radius: N,
    },
    /// A flat face through the marker, tangent to the profile; the contact point slides
    /// along it. `normal` is the face's unit normal in the follower body's frame, pointing
    /// from the face towards the cam; it must lie in the cam plane and the follower may turn
    /// relative to the cam only about the cam's axis.
    Flat {
        /// Unit normal, follower body frame.
        normal: [N; 3],
    },
    /// A curved (mushroom) face: a circular arc of radius `radius` (m, > 0) whose apex is the
    /// marker, its centre `radius` from the marker against `normal` (the face's unit normal
    /// at the apex, follower body frame, pointing towards the cam, in the cam plane). The
    /// face is rigid on the follower: the contact point slides on both surfaces.
    Mushroom {
        /// Radius of the face's arc (m).
        radius: N,
        /// Unit normal at the apex, follower body frame.
        normal: [N; 3],
    },
}

impl<N> Follower<N> {
    /// The follower's kind.
    pub fn kind(&self) -> FollowerKind {
        match self {
            Follower::Knife => FollowerKind::Knife,
            Follower::Roller { .. } => FollowerKind::Roller,
            Follower::Flat { .. } => FollowerKind::Flat,
            Follower::Mushroom { .. } => FollowerKind::Mushroom,
        }
    }

    /// The radius of a circular outline (a roller's), if the kind has one.
    pub fn radius(&self) -> Option<&N> {
        match self {
            Follower::Roller { radius } | Follower::Mushroom { radius, .. } => Some(radius),
            Follower::Knife | Follower::Flat { .. } => None,
        }
    }

    /// The face's normal (follower body frame), if the kind has a face.
    pub fn normal(&self) -> Option<&[N; 3]> {
        match self {
            Follower::Flat { normal } | Follower::Mushroom { normal, .. } => Some(normal),
            Follower::Knife | Follower::Roller { .. } => None,
        }
    }

    /// The same follower with its dimensions converted: `radius` takes the radius,
    /// `normal` the face's normal (each with its field's name under `follower`).
    pub fn try_map<M, E>(
        &self,
        radius: impl FnOnce(&N, &'static str) -> Result<M, E>,
        normal: impl FnOnce(&[N; 3], &'static str) -> Result<[M; 3], E>,
    ) -> Result<Follower<M>, E> {
        Ok(match self {
            Follower::Knife => Follower::Knife,
            Follower::Roller { radius: r } => Follower::Roller {
                radius: radius(r, "radius")?,
            },
            Follower::Flat { normal: n } => Follower::Flat {
                normal: normal(n, "normal")?,
            },
            Follower::Mushroom {
                radius: r,
                normal: n,
            } => Follower::Mushroom {
                radius: radius(r, "radius")?,
                normal: normal(n, "normal")?,
            },
        })
    }

    /// `knife`, `roller` or `flat`: the kind's name in messages and output.
    pub fn kind_name(&self) -> &'static str {
        self.kind().name()
    }
}

impl Follower<f64> {
    /// Where a circular outline is centred: `None` on the marker (a roller, whose centre the
    /// marker is); `Some(u)`, a unit vector of the follower body's frame, when the centre is
    /// the radius away from the marker along `u`. The derivation, the reference and the
    /// drawings place the circle through this alone.
    pub fn centre_direction(&self) -> Option<[f64; 3]> {
        match self {
            Follower::Knife | Follower::Roller { .. } | Follower::Flat { .. } => None,
            Follower::Mushroom { normal, .. } => Some(normal.map(|c| -c)),
        }
    }
}

/// A follower on a body touching a cam profile on another body (or the ground), eqs. (1)–(8)
/// generalised: the contact family of docs/method.md §9.
///
/// The cam plane is fixed to the cam body: its origin and axes are given in that body's
/// frame. The cam coordinates of a point p are `x = x̂·(p − o)`, `y = ŷ·(p − o)` with o, x̂,
/// ŷ carried by the cam body; the cam is the cylinder swept by the profile along `x̂ × ŷ`.
/// The constraint h is positive when the follower is clear of the cam and the normal force
/// positive when the cam pushes the follower.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Name of the contact (the marker's name unless the file gives one), e.g. `A`.
    pub name: String,
    /// Index into [`Model::markers`]: the knife edge, the roller's centre, or a point of the
    /// flat face.
    pub marker: usize,
    /// The follower's shape.
    pub follower: Follower,
    /// The cam profile.
    pub profile: Profile,
    /// The body carrying the cam (sorted index), `None` for the ground.
    pub cam_body: Option<usize>,
    /// Origin of the cam frame in the cam body's frame.
    pub origin: [f64; 3],
    /// Unit x axis of the cam plane, in the cam body's frame.
    pub x_axis: [f64; 3],
    /// Unit y axis of the cam plane, orthogonal to `x_axis`.
    pub y_axis: [f64; 3],
    /// The interval of the profile's variable the follower may touch: where undercutting is
    /// checked, and where a contact point is first searched for a parametric profile.
    /// `[0, 2π]` for a polar profile unless given.
    pub range: Option<(f64, f64)>,
    /// The motion law and follower the profile was designed for, when the file gives the
    /// cam as a `law` (its profile is then the synthesised [`Profile::Parametric`]).
    pub design: Option<crate::design::CamDesign>,
    /// How much wider than the roller a barrel or face cam's groove is (m): the roller moves
    /// freely between the flanks and touches one at a time (one-sided, with the model's
    /// restitution); 0 for a closed groove and for every other cam.
    pub backlash: f64,
    /// The half-angle (rad) of a tapered roller in a barrel's groove (`tapered: true`), its
    /// apex on the cam's axis: atan(ρ/R), ρ the roller's radius at the pitch radius R; 0 for a
    /// straight roller and every other cam.
    pub taper: f64,
}

impl Contact {
    /// What lies between a groove's centre line and its flanks, as messages name it: the
    /// roller's radius, plus half the backlash where there is one.
    pub fn groove_label(&self) -> &'static str {
        groove_label(self.follower.kind(), self.backlash)
    }

    /// The distance from a groove's centre line to its flanks (m): the roller's radius (0
    /// for a knife edge) plus half the backlash.
    pub fn groove_half_width(&self) -> f64 {
        self.follower.radius().copied().unwrap_or(0.0) + 0.5 * self.backlash
    }

    /// The profile's expression of the field `Field::Profile(c)` (f, r, x(s), or a
    /// surface's f(x, y)).
    pub fn profile_expression(&self) -> &Scalar {
        self.profile.expression()
    }

    /// The cam plane's normal x̂ × ŷ, cam body frame.
    pub fn axis(&self) -> [f64; 3] {
        let (a, b) = (self.x_axis, self.y_axis);
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }
}

/// A point fixed on a body, or on the ground, where a loop is cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopPoint {
    /// The body (sorted index), `None` for the ground.
    pub body: Option<usize>,
    /// The point in that body's frame (m).
    pub point: [f64; 3],
}

/// One loop, closed by a cut joint between a point A of one body and a point B of
/// another.
#[derive(Debug, Clone, PartialEq)]
pub struct Loop {
    /// Unique name among contacts and loops (CSV columns `loop_<name>_<equation>`).
    pub name: String,
    /// The cut joint's kind.
    pub kind: LoopKind,
    /// A and B.
    pub sides: [LoopPoint; 2],
    /// Unit vector in B's body frame: the pin's axis (spatial revolute), the line of a
    /// slider or of a slot.
    pub axis: [f64; 3],
    /// Unit vector in A's body frame: the pin's axis carried by A (spatial revolute) or the
    /// slider's direction carried by A (prismatic); equal to B's at assembly.
    pub axis_a: [f64; 3],
    /// True when the model is planar: a revolute cut is then 2 equations, not 5.
    pub planar: bool,
}

impl Loop {
    /// The names of its equations, in the order of its rows of h (CSV column suffixes):
    /// `x`, `y`, `z` for the components of A − B in ground axes, `normal` (`normal_1`,
    /// `normal_2`) for A − B across the line, `turn` for A's direction across B's line,
    /// `tilt_1`, `tilt_2` for A's axis across B's.
    pub fn equations(&self) -> &'static [&'static str] {
        self.kind.equations(self.planar)
    }
}

/// Default simulation settings stored with the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// End time (s), > 0.
    pub t_end: f64,
    /// Output interval (s), > 0.
    pub dt_out: f64,
    /// Integrator.
    pub integrator: IntegratorKind,
    /// Fixed step for RK4 / initial step for adaptive integrators (s), > 0.
    pub dt: f64,
    /// Relative tolerance of adaptive integrators.
    pub rtol: f64,
    /// Absolute tolerance of adaptive integrators.
    pub atol: f64,
    /// One-sided contact with this coefficient of restitution (in [0, 1]), or `None` for
    /// bilateral contact.
    pub restitution: Option<f64>,
    /// How the generated code solves for the accelerations (default: by operation count).
    pub formulation: Formulation,
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

/// A named number of the model file that fields and expressions use (`parameters:`).
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Unique name (a Rust identifier).
    pub name: String,
    /// The value this model was built with: the file's default, or the value a run gave.
    pub value: f64,
    /// The file's value.
    pub default: f64,
    /// The unit, as free text (`"N/m"`), for documentation and output headers.
    pub unit: String,
    /// Smallest value accepted (inclusive), if declared.
    pub min: Option<f64>,
    /// Largest value accepted (inclusive), if declared.
    pub max: Option<f64>,
    /// Folded into the generated code at build time (`constant: true`) instead of being
    /// read at run time.
    pub constant: bool,
    /// Free text from the file.
    pub description: String,
    /// Where its `constant` field is (or would be) written: errors about giving a constant
    /// parameter a value point there.
    pub constant_at: FieldLocation,
}

/// Which parameters the generated code reads at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ParameterMode {
    /// As the file declares: `constant: true` ones are folded, the others read at run time.
    #[default]
    AsDeclared,
    /// Every parameter folded: the generated code is what it would be with the numbers
    /// written in place (no `Parameters`, nothing read at run time).
    FoldAll,
    /// Every parameter read at run time, except those a field that must be constant uses
    /// (a joint axis, a cam plane's axes): for tests that compare it with [`FoldAll`].
    ///
    /// [`FoldAll`]: ParameterMode::FoldAll
    AllAtRunTime,
}

/// Where a field is written in the model file (1-based; 0 when it cannot be located).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FieldLocation {
    /// Dotted path of the field (`bodies[0].mass`).
    pub field: String,
    /// Line.
    pub line: usize,
    /// Column.
    pub column: usize,
}

/// A check the generated code makes when it is given parameter values, in the order the
/// build's validator makes it, so that a bad value gets the error the file would get.
#[derive(Debug, Clone, PartialEq)]
pub enum RuntimeCheck {
    /// A run-time parameter within its declared range (finite; `min`, `max`).
    Bounds {
        /// Index into [`Model::parameters`].
        parameter: usize,
        /// `parameters[i].value`, `.min` and `.max`.
        at: [FieldLocation; 3],
    },
    /// The value of a field is finite.
    Finite(Field, FieldLocation),
    /// The value of a field is positive (`what` names it in the message).
    Positive(Field, &'static str, FieldLocation),
    /// The value of a field is non-negative.
    NonNegative(Field, &'static str, FieldLocation),
    /// The inertia tensor of a body (sorted index) is physical.
    Inertia(usize, FieldLocation),
    /// Contact c's follower can follow its profile (no undercutting roller, a flat face on a
    /// convex profile, a positive polar radius): `camchain_runtime::contact::followable`,
    /// or for a face cam's groove `camchain_runtime::contact::groove_fits` and for a barrel's
    /// `developed_groove_fits` and `groove_on_cylinder`, reported at the roller's radius, the
    /// follower (a barrel's `length`, which barrels' followers never need) and the profile
    /// (in that order).
    Followable(usize, [FieldLocation; 3]),
}

/// What lies between a groove's centre line and its flanks, as messages name it: the
/// follower of kind `kind` (a roller), or with a backlash the groove's half-width.
pub fn groove_label(kind: FollowerKind, backlash: f64) -> &'static str {
    match backlash > 0.0 {
        true => "groove's half-width (the roller's radius and half the backlash)",
        false => kind.label(),
    }
}

/// A numeric field of the model, by position (body and coordinate indices are the sorted,
/// parents-first ones): the key of [`Model::symbolic`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Field {
    /// Component k of gravity.
    Gravity(usize),
    /// Mass of body i.
    Mass(usize),
    /// Component k of body i's centre of mass.
    Com(usize, usize),
    /// Entry (r, c) of body i's inertia tensor.
    Inertia(usize, usize, usize),
    /// Component k of joint i's anchor.
    Anchor(usize, usize),
    /// Spring stiffness of joint i.
    Stiffness(usize),
    /// Damping of joint i.
    Damping(usize),
    /// Spring rest value of joint i.
    Rest(usize),
    /// The prescribed motion of joint i (an expression of t).
    Drive(usize),
    /// Component k of marker m's position.
    Marker(usize, usize),
    /// Component k of contact c's cam-frame origin.
    Origin(usize, usize),
    /// Component k of loop l's point on side s (0 for A, 1 for B).
    LoopPoint(usize, usize, usize),
    /// The profile of contact c: f(x), r(θ), x(s) of a parametric one, or a surface's
    /// f(x, y).
    Profile(usize),
    /// y(s) of contact c's parametric profile.
    ProfileY(usize),
    /// The roller radius of contact c.
    Radius(usize),
    /// The applied load of joint i (an expression of t, the coordinates and their rates).
    Load(usize),
    /// The initial guess of coordinate i.
    InitialQ(usize),
    /// The initial guess of velocity i.
    InitialQd(usize),
}

impl Field {
    /// True for the third (z) component of a point or of gravity.
    pub fn is_z(self) -> bool {
        matches!(
            self,
            Field::Gravity(2)
                | Field::Com(_, 2)
                | Field::Anchor(_, 2)
                | Field::Marker(_, 2)
                | Field::Origin(_, 2)
                | Field::LoopPoint(_, _, 2)
        )
    }
}

/// A complete, validated model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Model name (a Rust identifier; the file stem unless the file says otherwise).
    pub name: String,
    /// Free text from the file.
    pub description: String,
    /// The parameters, in file order; every numeric field below holds its value for
    /// these parameters' values.
    pub parameters: Vec<Parameter>,
    /// The fields that depend on a run-time (not `constant`) parameter, as expressions
    /// whose [`Scalar::Param`] leaves are those parameters
    /// (constant ones are already folded in): what the generated code computes at run time.
    /// Empty when the model has no run-time parameters.
    pub symbolic: std::collections::BTreeMap<Field, crate::profile::Scalar>,
    /// The checks of the values that depend on run-time parameters, in validation order.
    pub runtime_checks: Vec<RuntimeCheck>,
    /// Where the `parameters` list is written (for errors about unknown names).
    pub parameters_at: FieldLocation,
    /// Gravity vector in ground coordinates (m/s²).
    pub gravity: [f64; 3],
    /// Bodies, parents before children.
    pub bodies: Vec<Body>,
    /// Named points.
    pub markers: Vec<Marker>,
    /// Cam contacts: the first rows of h.
    pub contacts: Vec<Contact>,
    /// The loops: the rows of h after the contacts'.
    pub loops: Vec<Loop>,
    /// Initial guess.
    pub initial: Initial,
    /// Default simulation settings.
    pub simulation: Simulation,
    /// The files the model reads besides itself (tables of points), in the order read.
    pub files: Vec<ModelFile>,
}

/// A file a model names (a table of points), as it was read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelFile {
    /// The path as the model file writes it.
    pub written: String,
    /// Where it was read from (empty for a file embedded in the program).
    pub path: std::path::PathBuf,
    /// Its text.
    pub text: String,
}

impl Model {
    /// Number of generalised coordinates (= number of bodies = number of joints).
    pub fn n(&self) -> usize {
        self.bodies.len()
    }

    /// Number of scalar constraints: one per contact, then each loop's equations.
    pub fn n_constraints(&self) -> usize {
        self.contacts.len()
            + self
                .loops
                .iter()
                .map(|l| l.equations().len())
                .sum::<usize>()
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
            && !self.symbolic.keys().any(|f| f.is_z())
            && self.loops.iter().all(|l| l.planar)
    }

    /// Parses an expression of `variable` that may use the model's parameters, each
    /// replaced by its value (for a variant of the model built in memory).
    pub fn parse_expression(
        &self,
        source: &str,
        variable: &str,
    ) -> Result<crate::profile::Scalar, crate::profile::ExprError> {
        let names: Vec<&str> = self.parameters.iter().map(|p| p.name.as_str()).collect();
        let values: Vec<f64> = self.parameters.iter().map(|p| p.value).collect();
        crate::profile::parse_expression_with(source, Some(variable), &names)
            .map(|e| e.resolve_all(&values))
    }

    /// The parameters read at run time (not `constant`), with their indices.
    pub fn runtime_parameters(&self) -> impl Iterator<Item = (usize, &Parameter)> {
        self.parameters
            .iter()
            .enumerate()
            .filter(|(_, p)| !p.constant)
    }
}

/// Two unit vectors spanning the plane normal to the unit vector `a`: the directions of a
/// spatial loop's `normal_1` and `normal_2` equations, one convention for the derivation and
/// the reference.
pub fn normal_pair(a: [f64; 3]) -> [[f64; 3]; 2] {
    // Start from the ground axis least aligned with a.
    let k = (0..3)
        .min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let first = cross(a, e);
    let norm = first.iter().map(|x| x * x).sum::<f64>().sqrt();
    let first = first.map(|x| x / norm);
    [first, cross(a, first)]
}
