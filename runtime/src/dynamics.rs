//! The contract between a model (generated, or the numeric reference) and the runtime.
//!
//! Everything is expressed in the paper's form (13)–(14):
//! `M(q) q̈ + F(q, q̇) + Q(q, q̇, t) + Jᵀ λ = 0`: the tree dynamics M, F, Q, and one scalar
//! constraint `h(q) = 0` per contact with its acceleration form `J q̈ + c(q, q̇) = 0` (7, 8).
//! Every contact kind (a knife edge, a roller or a flat face on a cam profile carried by the
//! ground or by any body) supplies its h, J and c and describes itself through
//! [`ContactGeometry`]: the runtime sees constraints and normals, never a profile.
//! Matrices are dense row-major slices so that generated code can write them without
//! allocation.

pub use crate::kinds::{FollowerKind, Formulation, IntegratorKind, JointKind, LoopKind};

/// Description of one generalised coordinate.
#[derive(Debug, Clone, PartialEq)]
pub struct CoordinateInfo {
    /// Name from the model file, e.g. `q3`.
    pub name: String,
    /// The kind of its joint: revolute (an angle) or prismatic (a displacement).
    pub kind: JointKind,
    /// True when the joint's motion is prescribed (a driven joint).
    pub driven: bool,
}

/// Simulation settings (the model file's defaults, overridable by the caller).
#[derive(Debug, Clone, PartialEq)]
pub struct SimSettings {
    /// End time (s).
    pub t_end: f64,
    /// Output interval (s).
    pub dt_out: f64,
    /// Integrator.
    pub integrator: IntegratorKind,
    /// Fixed step of RK4, initial step of adaptive integrators (s).
    pub dt: f64,
    /// Relative tolerance (adaptive integrators).
    pub rtol: f64,
    /// Absolute tolerance (adaptive integrators).
    pub atol: f64,
}

/// Initial guess and which coordinates assembly must keep.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialGuess {
    /// Guessed coordinates.
    pub q: Vec<f64>,
    /// Guessed velocities.
    pub qd: Vec<f64>,
    /// `hold[i]`: assembly keeps coordinate i at its guess.
    pub hold: Vec<bool>,
    /// `given_q[i]`: the model file gives coordinate i's guess (else it defaults to 0);
    /// assembly warns when it has to move a given value far or a drive overrides it.
    pub given_q: Vec<bool>,
    /// `given_qd[i]`: the model file gives velocity i's guess.
    pub given_qd: Vec<bool>,
}

/// The form of a contact's cam profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ProfileKind {
    /// y = f(x).
    Explicit,
    /// r(θ): a disc cam.
    Polar,
    /// (x(s), y(s)).
    Parametric,
    /// A surface z = f(x, y) over the cam plane (a spatial cam).
    Surface,
    /// A barrel cam's pitch surface z = g(θ) on a cylinder about the cam's axis.
    Barrel,
    /// A surface of revolution r = g(z) about the cam's axis.
    Revolution,
    /// A face cam's groove in the cam plane: the follower point on its centre line.
    Face,
}

impl ProfileKind {
    /// True for a surface over the cam plane, false for a plane curve.
    pub fn is_surface(self) -> bool {
        match self {
            ProfileKind::Surface | ProfileKind::Barrel | ProfileKind::Revolution => true,
            ProfileKind::Explicit
            | ProfileKind::Polar
            | ProfileKind::Parametric
            | ProfileKind::Face => false,
        }
    }
}

/// Static description of one contact.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactInfo {
    /// Name (its marker's, unless the model file names it).
    pub name: String,
    /// The follower's shape.
    pub follower: FollowerKind,
    /// The profile's form.
    pub profile: ProfileKind,
    /// The coordinate of the cam body's own joint when it is revolute (the cam's angle is
    /// that coordinate); `None` for a cam on the ground or on a sliding body.
    pub cam_coordinate: Option<usize>,
    /// The cam is carried by a moving body (a camshaft, a slide), not fixed to the ground:
    /// it drives the follower, and the pressure angle is defined. A chain's point sliding
    /// along a fixed cam (the paper's) has none.
    pub cam_moves: bool,
    /// A barrel or face cam's groove wider than its roller by this much (m): the roller moves
    /// freely between the flanks and touches one at a time ([`crate::clearance`]); 0 for a
    /// closed groove (the roller held on the centre line both ways) and for every other cam.
    pub backlash: f64,
    /// The half-angle γ (rad) of a tapered roller in a barrel's groove, its apex on the cam's
    /// axis (γ = atan(ρ/R)): the force on the roller leans outward by γ
    /// ([`ContactGeometry::flank_force`]); 0 for a straight roller and every other cam.
    pub taper: f64,
}

/// A flank of a barrel or face cam's groove.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flank {
    /// The flank a positive normal force of the closed groove presses the roller against:
    /// a face cam's inner flank, a barrel's lower one.
    Inner,
    /// The other: a face cam's outer flank, a barrel's upper one.
    Outer,
}

impl ContactInfo {
    /// A knife edge on an explicit profile fixed to the ground: the paper's contact.
    pub fn knife(name: &str) -> Self {
        ContactInfo {
            name: name.to_string(),
            follower: FollowerKind::Knife,
            profile: ProfileKind::Explicit,
            cam_coordinate: None,
            cam_moves: false,
            backlash: 0.0,
            taper: 0.0,
        }
    }
}

/// Static description of one loop: its rows of h follow the contacts' and the
/// loops listed before it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopInfo {
    /// Name from the model file.
    pub name: String,
    /// The cut joint's kind.
    pub kind: LoopKind,
    /// The names of its equations, one per row of h (`x`, `y`, `normal`, `tilt_1`, …):
    /// the suffixes of its CSV columns.
    pub equations: Vec<String>,
}

/// Static description of a model.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelInfo {
    /// Model name, e.g. `paper_concave`.
    pub name: String,
    /// Free text from the model file.
    pub description: String,
    /// The generalised coordinates, in order.
    pub coordinates: Vec<CoordinateInfo>,
    /// The contacts (one constraint each, the first rows of h), in order.
    pub contacts: Vec<ContactInfo>,
    /// The loops (their equations are the rows of h after the contacts'), in order.
    pub loops: Vec<LoopInfo>,
    /// False for a planar model (contact z coordinates are always 0 and not reported).
    pub spatial: bool,
    /// Initial guess.
    pub initial: InitialGuess,
    /// Default settings.
    pub defaults: SimSettings,
    /// The model file's contact law: `None` for bilateral contact (the follower held on its
    /// cam: a negative normal force is reported, not acted on), `Some(e)` for one-sided
    /// contact with impacts of restitution e ([`crate::unilateral`]), what a run uses unless
    /// told otherwise.
    pub restitution: Option<f64>,
    /// The run-time parameters (those not folded at build time), in file order; their
    /// current values are [`Dynamics::parameter_values`].
    pub parameters: Vec<crate::parameters::ParameterInfo>,
}

impl ModelInfo {
    /// Number of generalised coordinates.
    pub fn n(&self) -> usize {
        self.coordinates.len()
    }

    /// Number of cam contacts (the first [`Self::n_contacts`] rows of h).
    pub fn n_contacts(&self) -> usize {
        self.contacts.len()
    }

    /// Number of scalar constraints m: one per contact, then every loop's equations.
    pub fn n_constraints(&self) -> usize {
        self.contacts.len() + self.loops.iter().map(|l| l.equations.len()).sum::<usize>()
    }

    /// The first row of h of each loop, in order.
    pub fn loop_rows(&self) -> impl Iterator<Item = (usize, &LoopInfo)> {
        let mut row = self.contacts.len();
        self.loops.iter().map(move |l| {
            let first = row;
            row += l.equations.len();
            (first, l)
        })
    }

    /// The name of constraint row k: the contact's name, or `<loop>.<equation>`.
    pub fn constraint_name(&self, k: usize) -> String {
        if let Some(c) = self.contacts.get(k) {
            return c.name.clone();
        }
        for (first, l) in self.loop_rows() {
            if let Some(e) = l.equations.get(k.wrapping_sub(first)) {
                return format!("{}.{e}", l.name);
            }
        }
        format!("row {k}")
    }

    /// Index of a coordinate by name.
    pub fn coordinate_index(&self, name: &str) -> Option<usize> {
        self.coordinates.iter().position(|c| c.name == name)
    }

    /// Index of a contact by name.
    pub fn contact_index(&self, name: &str) -> Option<usize> {
        self.contacts.iter().position(|c| c.name == name)
    }

    /// Index of a run-time parameter by name.
    pub fn parameter_index(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p.name == name)
    }
}

/// Where and how a contact touches: what every contact kind reports, at (q, q̇).
///
/// `#[repr(C)]` (every field an f64): a model compiled by the Python package's
/// `camchain.compile` fills it across a C boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct ContactGeometry {
    /// The contact point on the cam profile, ground coordinates.
    pub position: [f64; 3],
    /// The contact point's x in the cam frame (the cam plane, carried by the cam body).
    pub x: f64,
    /// The contact point's y in the cam frame.
    pub y: f64,
    /// The contact point's z in the cam frame, along the cam's axis: the height of a cam
    /// surface z = f(x, y) there; 0 for a plane profile, whose points are given in its plane.
    pub z: f64,
    /// The follower point (the knife edge, the centre of a roller or of a curved face's arc,
    /// the marker on the flat face), ground coordinates.
    pub follower: [f64; 3],
    /// Unit normal at the contact, ground coordinates, pointing from the cam into the
    /// follower: the direction of the force the cam exerts.
    pub normal: [f64; 3],
    /// The cam's axis (the normal of the cam plane), ground coordinates.
    pub axis: [f64; 3],
    /// |∂h/∂(displacement along the normal)|: the normal force is `−λ · force_scale`
    /// ([`crate::partition::normal_force`]); √(1 + f′²) for a knife edge on y = f(x), 1 for
    /// the kinds whose h is a distance.
    pub force_scale: f64,
    /// The profile's parameter at the contact point (x, θ or s). A caller that passes the
    /// previous call's values back lets the solve start there.
    pub parameter: f64,
    /// Curvature of the profile at the contact point (1/m): positive where the profile is
    /// hollow seen from the follower (a roller must be smaller than 1/curvature there).
    pub curvature: f64,
    /// Unit direction in which the follower body's own joint moves the follower point,
    /// ground coordinates: the slide of a translating follower, the arc's tangent of a rocker.
    pub direction: [f64; 3],
    /// Sliding speed (m/s): the tangential velocity, relative to the cam, of the follower
    /// body's material at the contact point (a roller rolls: for it this is the rim speed
    /// of its spin relative to the follower, the slip a seized roller would have).
    pub sliding_speed: f64,
    /// For a barrel cam's groove that takes a tapered roller ([`ContactInfo::taper`]): the
    /// unit vector from the cam's axis towards the follower point, perpendicular to the axis,
    /// ground coordinates. Zero otherwise.
    pub radial: [f64; 3],
}

impl Default for ContactGeometry {
    fn default() -> Self {
        ContactGeometry {
            position: [0.0; 3],
            x: 0.0,
            y: 0.0,
            z: 0.0,
            follower: [0.0; 3],
            normal: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            force_scale: 1.0,
            // Not a solved parameter: a solve starts from its own guess.
            parameter: f64::NAN,
            curvature: 0.0,
            direction: [0.0; 3],
            sliding_speed: 0.0,
            radial: [0.0; 3],
        }
    }
}

impl ContactGeometry {
    /// The normal force of a contact whose constraint force along the groove's normal is
    /// `along` (N = −λ · force_scale), and the normal turned to the flank that exerts it, for
    /// a tapered roller of half-angle `taper` (rad) in a barrel's groove: either flank pushes
    /// the roller along its cone's normal, cos γ n + sign(N) sin γ e_r (e_r [`Self::radial`]),
    /// with the force N / cos γ, whose part along n is the constraint's and whose radial part,
    /// N tan γ outward, the follower's guide takes. A straight roller (γ = 0) is unchanged.
    pub fn flank_force(&mut self, taper: f64, along: f64) -> f64 {
        if taper == 0.0 {
            return along;
        }
        let (sin, cos) = taper.sin_cos();
        let side = if along < 0.0 { -1.0 } else { 1.0 };
        for (n, r) in self.normal.iter_mut().zip(self.radial) {
            *n = cos * *n + side * sin * r;
        }
        along / cos
    }

    /// The pressure angle (rad): the angle between the contact normal and the follower's
    /// direction of motion, in [−π/2, π/2], positive when the normal is turned from the
    /// direction counterclockwise about the cam's axis. On a cam surface the normal need not
    /// lie in a plane with the direction and the axis: the magnitude is then the angle in
    /// space between the two, its sign that of the turn about the axis (positive when there
    /// is none).
    pub fn pressure_angle(&self) -> f64 {
        let (n, a) = (self.normal, self.axis);
        let mut d = self.direction;
        if dot3(d, n) < 0.0 {
            d = d.map(|c| -c);
        }
        let cross = [
            d[1] * n[2] - d[2] * n[1],
            d[2] * n[0] - d[0] * n[2],
            d[0] * n[1] - d[1] * n[0],
        ];
        let about_axis = dot3(cross, a);
        let magnitude = dot3(cross, cross).sqrt();
        let sign = if about_axis < 0.0 { -1.0 } else { 1.0 };
        (sign * magnitude).atan2(dot3(d, n))
    }
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// First- and second-order kinematics of a contact's follower point in the cam frame
/// (diagnostics and tests): X, Y its cam-frame coordinates, J1 = ∂X/∂q, J2 = ∂Y/∂q, and the
/// velocity-product parts of Ẍ and Ÿ; on a cam surface also Z, J3 = ∂Z/∂q and that of Z̈.
/// For a cam on a moving body these are the relative kinematics the constraint is written
/// with.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ContactKinematics {
    /// Geometry at (q, q̇).
    pub geometry: ContactGeometry,
    /// X: the follower point's x in the cam frame.
    pub x: f64,
    /// Y: the follower point's y in the cam frame.
    pub y: f64,
    /// J1 = ∂X/∂q.
    pub j1: Vec<f64>,
    /// J2 = ∂Y/∂q.
    pub j2: Vec<f64>,
    /// Z: the follower point's height along the cam's axis (written for a cam surface).
    pub z: f64,
    /// J3 = ∂Z/∂q (written for a cam surface).
    pub j3: Vec<f64>,
    /// (J1 q̇)_q q̇: convective part of Ẍ.
    pub conv1: f64,
    /// (J2 q̇)_q q̇: convective part of Ÿ.
    pub conv2: f64,
    /// (J3 q̇)_q q̇: convective part of Z̈ (written for a cam surface).
    pub conv3: f64,
}

impl ContactKinematics {
    /// Zero kinematics with J1, J2 and J3 of length `n` (the number of coordinates), ready for
    /// [`Dynamics::contact_kinematics_into`].
    pub fn new(n: usize) -> Self {
        ContactKinematics {
            j1: vec![0.0; n],
            j2: vec![0.0; n],
            j3: vec![0.0; n],
            ..Default::default()
        }
    }
}

/// Mechanical energy split by origin.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Energy {
    /// ½ Σ (m v·v + ω·I ω), summed from the body velocities.
    pub kinetic: f64,
    /// −Σ m g·p_com.
    pub gravity: f64,
    /// Σ ½ k (q − rest)².
    pub spring: f64,
}

impl Energy {
    /// Kinetic + potential.
    pub fn total(&self) -> f64 {
        self.kinetic + self.gravity + self.spring
    }
}

/// The functions a model provides to the runtime.
///
/// Implemented by every generated model (the `Model` type of a module that `camchain-build`
/// generated) and by the numeric reference (`camchain_reference::NumericModel`), so both run
/// through the same integrators.
/// Slices have the lengths given by [`ModelInfo`]: `n` coordinates, `m` constraints
/// ([`ModelInfo::n_constraints`]: `nc` contacts, then the loops' equations).
pub trait Dynamics {
    /// Static description.
    fn info(&self) -> &ModelInfo;

    /// The values of the run-time parameters this instance was built with, in the order of
    /// [`ModelInfo::parameters`] (empty for a model without run-time parameters).
    fn parameter_values(&self) -> &[f64] {
        &[]
    }

    /// M(q), eq. (13): row-major n×n into `m`.
    fn mass_matrix(&self, q: &[f64], m: &mut [f64]);

    /// F(q, q̇), eq. (13): the velocity-dependent inertial terms, into `f` (length n).
    fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]);

    /// Q(q, q̇, t), eq. (13): gravity, springs and dampers with the sign of the equation
    /// `M q̈ + F + Q = joint drive loads` (so a spring contributes `+k (q − rest)`).
    fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]);

    /// The two points of every loop's cut joint (A then B, ground coordinates) at q, into `out`
    /// (length 2 × the number of loops): what figures draw. Does nothing without loops.
    fn loop_points(&self, q: &[f64], out: &mut [[f64; 3]]) {
        let _ = (q, out);
    }

    /// h(q), one entry per contact then one per loop equation: for a contact positive when the follower is clear of the cam
    /// (h = f2 − f3(f1) for a knife edge on y = f(x), eq. 3; a distance for the other kinds).
    fn constraint(&self, q: &[f64], h: &mut [f64]);

    /// J(q) = ∂h/∂q, eq. (5b): row-major m×n into `j`.
    fn constraint_jacobian(&self, q: &[f64], j: &mut [f64]);

    /// c(q, q̇) = (J q̇)_q q̇, eqs. (7, 8), so that the acceleration-level constraint reads
    /// `J q̈ + c = 0`. One entry per constraint.
    fn constraint_bias(&self, q: &[f64], qd: &[f64], c: &mut [f64]);

    /// Geometry of every contact at (q, q̇) (length nc). Entries of `out` hold the previous
    /// call's values or defaults: a contact whose point is solved for starts from
    /// `out[k].parameter` when it is finite.
    fn contact_geometry(&self, q: &[f64], qd: &[f64], out: &mut [ContactGeometry]);

    /// The follower point's cam-frame kinematics and the geometry of contact `k`
    /// (diagnostics, tests), written into `out` without allocating: `out.j1` and `out.j2`
    /// must have length n (as made by [`ContactKinematics::new`]). For `k` ≥ nc, `out` is
    /// left unchanged.
    fn contact_kinematics_into(&self, q: &[f64], qd: &[f64], k: usize, out: &mut ContactKinematics);

    /// [`Dynamics::contact_kinematics_into`] into a new value (allocates J1 and J2).
    fn contact_kinematics(&self, q: &[f64], qd: &[f64], k: usize) -> ContactKinematics {
        let mut out = ContactKinematics::new(self.info().n());
        self.contact_kinematics_into(q, qd, k, &mut out);
        out
    }

    /// Prescribed motion at time t: for every driven coordinate i, writes `q[i]`, `qd[i]` and
    /// `qdd[i]`; other entries are left untouched.
    fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]);

    /// Kinetic energy from the body velocities, and the potential energies.
    fn energy(&self, q: &[f64], qd: &[f64]) -> Energy;

    /// Power dissipated by the joint dampers, Σ c q̇² (W, >= 0).
    fn damper_power(&self, qd: &[f64]) -> f64;

    /// Power of the applied joint loads (motor torques given as expressions of t, q, q̇),
    /// Σ τ_i q̇_i (W): with the drives' power, the work done on the system from outside.
    fn load_power(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
        let _ = (t, q, qd);
        0.0
    }

    /// The flank of contact `k`'s groove that the roller is nearer at q when the groove has
    /// backlash (as the one-sided run sees it, [`crate::clearance::Clearance`]); `None` for
    /// every other contact.
    fn groove_flank(&self, q: &[f64], k: usize) -> Option<Flank> {
        let _ = (q, k);
        None
    }

    /// M, F and Q in one call. Generated models override it so that the kinematics shared by
    /// the three (sines, cosines, body velocities) are computed once.
    fn equations(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        m: &mut [f64],
        f: &mut [f64],
        applied: &mut [f64],
    ) {
        self.mass_matrix(q, m);
        self.inertial_forces(q, qd, f);
        self.applied_forces(t, q, qd, applied);
    }

    /// J and c in one call (the velocity and acceleration levels of the constraint, 5b, 8).
    /// Generated models override it to share the contact kinematics.
    fn constraint_terms(&self, q: &[f64], qd: &[f64], j: &mut [f64], c: &mut [f64]) {
        self.constraint_jacobian(q, j);
        self.constraint_bias(q, qd, c);
    }

    /// Length of the cache that [`Dynamics::position_terms`] fills for
    /// [`Dynamics::velocity_terms`] (0 unless overridden).
    fn cache_len(&self) -> usize {
        0
    }

    /// Everything a right-hand side needs at the position level, in one call: h (3) and
    /// J (5b) at q, for Newton (15) and the velocity relation (16). Generated models also
    /// write into `cache` the q-only quantities (sines, cosines, profile values) that
    /// [`Dynamics::velocity_terms`] reuses at the same q, so that no sine is computed twice
    /// per right-hand side, and read back the sines and cosines of joint angles that have
    /// not changed since the last call with this cache ([`sin_cos_memo`]): Newton moving a
    /// sliding coordinate evaluates again without trigonometry. Give each state its own
    /// cache (the runtime's workspace does).
    fn position_terms(&self, q: &[f64], h: &mut [f64], j: &mut [f64], cache: &mut [f64]) {
        let _ = cache;
        self.constraint(q, h);
        self.constraint_jacobian(q, j);
    }

    /// Everything a right-hand side needs at the velocity level: M, F, Q (13) and c (8) at
    /// (t, q, q̇), reading `cache` as filled by [`Dynamics::position_terms`] at the same q.
    fn velocity_terms(&self, t: f64, q: &[f64], qd: &[f64], cache: &[f64], out: VelocityTerms) {
        let _ = cache;
        self.equations(t, q, qd, out.mass, out.inertial, out.applied);
        self.constraint_bias(q, qd, out.bias);
    }

    /// For each row of M, the columns [start, end) outside which it is zero at every state,
    /// when the model knows them: generated models whose M has many zeros (chained loops).
    /// [`Dynamics::velocity_terms`] then writes each row of M within them only and leaves the
    /// rest of the buffer as it is, so the buffer must be zero there: freshly zeroed, and
    /// written by nothing but this model (the runtime's buffers are). The runtime takes
    /// these extents instead of finding them by reading all of M at every evaluation.
    /// `None` (the default): `velocity_terms` writes all of M.
    fn mass_rows(&self) -> Option<&'static [(usize, usize)]> {
        None
    }

    /// The same for the rows of J, which [`Dynamics::position_terms`] writes.
    fn jacobian_rows(&self) -> Option<&'static [(usize, usize)]> {
        None
    }

    /// The length of the factors [`Dynamics::articulated_terms`] writes; 0 (the default)
    /// when the model does not provide the articulated-body forward dynamics, whose two
    /// functions are then never called.
    fn articulated_len(&self) -> usize {
        0
    }

    /// How many constraint rows [`Dynamics::articulated_terms`] solves within its sweeps when
    /// given them ([`ArticulatedTerms::row`]): 1 for a generated model on the articulated route
    /// with one constraint row, 0 (the default) otherwise, when the runtime forms each row's
    /// response with [`Dynamics::articulated_response`].
    fn articulated_rows(&self) -> usize {
        0
    }

    /// The articulated-body forward dynamics at (t, q, q̇) without constraint forces (docs/
    /// method.md §14), or with the model's one row's when given it ([`ArticulatedTerms::row`],
    /// §14.6), reading `cache` as filled by [`Dynamics::position_terms`] at the same q: see
    /// [`ArticulatedTerms`]. Provided by generated models whose
    /// [`Dynamics::articulated_len`] is not 0; the default writes NaN.
    fn articulated_terms(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        cache: &[f64],
        out: ArticulatedTerms<'_>,
    ) {
        let _ = (t, q, qd, cache);
        out.qdd.fill(f64::NAN);
        out.drive.fill(f64::NAN);
    }

    /// For a generalised force τ (length n, driven entries ignored): x = M_ff⁻¹ τ_f on the
    /// free coordinates into `qdd`, and M_df x on the driven ones into `drive` (other
    /// entries unchanged), M at the q of the `articulated_terms` call that wrote `factors`.
    /// The default writes NaN.
    fn articulated_response(
        &self,
        factors: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
        drive: &mut [f64],
    ) {
        let _ = (factors, tau);
        qdd.fill(f64::NAN);
        drive.fill(f64::NAN);
    }
}

/// Buffers of [`Dynamics::articulated_terms`].
#[derive(Debug)]
pub struct ArticulatedTerms<'a> {
    /// In: q̈ of the driven coordinates. Out: q̈ of the free ones (independent and
    /// dependent) without constraint forces, i.e. solving the free rows of
    /// `M q̈ + F + Q = 0` (13); with [`ArticulatedTerms::row`] given, with that row's force.
    pub qdd: &'a mut [f64],
    /// Out: the driven coordinates' rows of `M q̈ + F + Q` at those accelerations (the load
    /// the drive supplies before the constraint forces). Other entries are left unchanged.
    pub drive: &'a mut [f64],
    /// Out: c(q, q̇), eqs. (7, 8), one entry per constraint.
    pub bias: &'a mut [f64],
    /// Out: what [`Dynamics::articulated_response`] reads (length
    /// [`Dynamics::articulated_len`]); empty when the response will not be called (generated
    /// models then skip writing them: for a model of one row solved within the sweeps, 6 % of
    /// the 16-body chain's right-hand side).
    pub factors: &'a mut [f64],
    /// In, for a model that solves its one constraint row within the sweeps
    /// ([`Dynamics::articulated_rows`] = 1): that row of J (length n) to solve it, `qdd` and
    /// `drive` then with the row's force; empty not to (other models ignore it).
    pub row: &'a [f64],
    /// Out, for such a model given `row`: its multiplier and J M_ff⁻¹ Jᵀ (both 0 without it).
    pub solved: &'a mut SolvedRow,
}

/// The constraint row a model solves within its sweeps ([`ArticulatedTerms::row`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolvedRow {
    /// λ, eq. (14): M q̈ + F + Q + Jᵀ λ = τ with J q̈ + c = 0.
    pub lambda: f64,
    /// J_f M_ff⁻¹ J_fᵀ, positive unless the row vanishes on the free coordinates (a singular
    /// position).
    pub delassus: f64,
}

/// The weight generated code gives the row of [`ArticulatedTerms::row`]: 1 when it holds J's
/// row of `n` entries, 0 when it is empty.
///
/// # Panics
/// When `row` is neither empty nor `n` entries long: a caller's error.
#[inline]
pub fn row_weight(row: &[f64], n: usize) -> f64 {
    assert!(
        row.is_empty() || row.len() == n,
        "the constraint row has {} entries, not {n} (or none)",
        row.len()
    );
    if row.is_empty() { 0.0 } else { 1.0 }
}

/// Entry `k` of the row of [`ArticulatedTerms::row`] as generated code reads it: 0 when the
/// row is empty.
#[inline]
pub fn row_entry(row: &[f64], k: usize) -> f64 {
    row.get(k).copied().unwrap_or(0.0)
}

/// Output buffers of [`Dynamics::velocity_terms`]: M (n×n, row-major), F, Q (n) and c (m).
#[derive(Debug)]
pub struct VelocityTerms<'a> {
    /// M(q), eq. (13).
    pub mass: &'a mut [f64],
    /// F(q, q̇), eq. (13).
    pub inertial: &'a mut [f64],
    /// Q(q, q̇, t), eq. (13).
    pub applied: &'a mut [f64],
    /// c(q, q̇), eqs. (7, 8).
    pub bias: &'a mut [f64],
}

/// The [`Dynamics`] methods of a view of a model that changes only its contacts (a flying
/// follower's, a groove's clearance): the inner model's M, F, Q, drives, energies, powers
/// and cache, forwarded to the field `$inner`. Written inside the view's `impl Dynamics`.
#[cfg(feature = "engine")]
macro_rules! forward_free_motion {
    ($inner:ident) => {
        fn parameter_values(&self) -> &[f64] {
            self.$inner.parameter_values()
        }
        fn mass_matrix(&self, q: &[f64], m: &mut [f64]) {
            self.$inner.mass_matrix(q, m);
        }
        fn inertial_forces(&self, q: &[f64], qd: &[f64], f: &mut [f64]) {
            self.$inner.inertial_forces(q, qd, f);
        }
        fn applied_forces(&self, t: f64, q: &[f64], qd: &[f64], out: &mut [f64]) {
            self.$inner.applied_forces(t, q, qd, out);
        }
        fn prescribed(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
            self.$inner.prescribed(t, q, qd, qdd);
        }
        fn energy(&self, q: &[f64], qd: &[f64]) -> $crate::dynamics::Energy {
            self.$inner.energy(q, qd)
        }
        fn damper_power(&self, qd: &[f64]) -> f64 {
            self.$inner.damper_power(qd)
        }
        fn load_power(&self, t: f64, q: &[f64], qd: &[f64]) -> f64 {
            self.$inner.load_power(t, q, qd)
        }
        fn equations(
            &self,
            t: f64,
            q: &[f64],
            qd: &[f64],
            m: &mut [f64],
            f: &mut [f64],
            applied: &mut [f64],
        ) {
            self.$inner.equations(t, q, qd, m, f, applied);
        }
        fn mass_rows(&self) -> Option<&'static [(usize, usize)]> {
            self.$inner.mass_rows()
        }
        fn cache_len(&self) -> usize {
            self.$inner.cache_len()
        }
    };
}
#[cfg(feature = "engine")]
pub(crate) use forward_free_motion;

/// sin and cos of `angle`, reusing `slot` = [angle, sin, cos] when it holds this very angle
/// (bit for bit) from an earlier call, and storing them there otherwise.
///
/// Generated `position_terms` computes the sines and cosines of the joint angles so: Newton
/// (15) evaluating again after moving a sliding coordinate, or a step's end evaluated once
/// more, then costs no trigonometry. A slot not written by this function (zeros, NaN) is
/// never taken for a stored result: its sine and cosine would not have a unit norm.
#[inline]
pub fn sin_cos_memo(angle: f64, slot: &mut [f64]) -> (f64, f64) {
    if let [stored, sin, cos] = slot {
        if stored.to_bits() == angle.to_bits() && (*sin * *sin + *cos * *cos - 1.0).abs() < 1e-12 {
            return (*sin, *cos);
        }
        let (s, c) = crate::trig::sin_cos(angle);
        (*stored, *sin, *cos) = (angle, s, c);
        (s, c)
    } else {
        crate::trig::sin_cos(angle)
    }
}
