//! Random valid models for the property tests.
//!
//! [`model_spec`] is a proptest strategy for a [`ModelSpec`]: 1..=12 bodies in a random tree,
//! revolute and prismatic joints with random axes (exactly axis-aligned ones among them, so
//! the structural-zero folding of the generator is exercised), random anchors, centres of
//! mass, masses, physically valid inertia tensors, optional spring-dampers and drives,
//! gravity on or off, and 0, 1 or 2 cam contacts with random polynomial / transcendental
//! profiles in random cam planes. [`ModelSpec::ron`] writes it out as a model file, which the
//! tests read back through the real loader (`schema::parse_model`), so the loader is
//! exercised too.
//!
//! Every profile is shifted so that it passes through its marker's position at the initial
//! guess (computed here by an independent forward-kinematics routine), so h(q₀) = 0: the
//! loader itself does not ask for an assembled initial state, but the build-time assembly
//! check of `build.rs` does, and any generated model can then be compiled as it is.

#![allow(dead_code)]

use camchain_codegen::profile::parse_expression;
use proptest::prelude::*;
use std::fmt::Write as _;

/// Largest number of bodies.
pub const MAX_BODIES: usize = 12;

/// A joint axis.
#[derive(Debug, Clone, PartialEq)]
pub enum Axis {
    /// ±x, ±y or ±z exactly: index of the axis and the sign.
    Aligned(usize, bool),
    /// A general direction (spherical angles), written with a length `scale` ≠ 1 so the
    /// loader's normalisation is exercised.
    Free { theta: f64, phi: f64, scale: f64 },
}

/// How the inertia tensor is written in the file.
#[derive(Debug, Clone, PartialEq)]
pub enum InertiaSpec {
    /// `Izz(v)`: a lamina.
    Izz(f64),
    /// `Diagonal(a, b, c)`: principal moments along the body axes.
    Diagonal([f64; 3]),
    /// `Full(..)`: R diag(moments) Rᵀ for the rotation vector `rotation`.
    Rotated {
        moments: [f64; 3],
        rotation: [f64; 3],
    },
}

/// One body and its joint.
#[derive(Debug, Clone, PartialEq)]
pub struct BodySpec {
    /// In [0, 1): picks the ground or one of the earlier bodies.
    pub parent: f64,
    /// Prismatic instead of revolute.
    pub prismatic: bool,
    /// Joint axis.
    pub axis: Axis,
    /// Joint anchor in the parent frame.
    pub anchor: [f64; 3],
    /// Centre of mass in the body frame.
    pub com: [f64; 3],
    /// Mass, 0.1..10 kg.
    pub mass: f64,
    /// Inertia about the centre of mass.
    pub inertia: InertiaSpec,
    /// Optional spring-damper: stiffness, damping, rest.
    pub spring: Option<[f64; 3]>,
    /// Optional drive q(t) = q0 + amplitude·sin(ω t): (amplitude, ω).
    pub drive: Option<(f64, f64)>,
    /// Initial guess of the coordinate.
    pub q0: f64,
    /// Initial guess of the velocity.
    pub qd0: f64,
}

/// An elementary function term of a profile: `b·f(w x + φ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Extra {
    /// `u.sin()`
    Sin,
    /// `u.cos()`
    Cos,
    /// `u.atan()`
    Atan,
    /// `u.tanh()`
    Tanh,
    /// `(1 + u²).sqrt()`
    SqrtQuad,
    /// `(1 + u²).ln()`
    LnQuad,
    /// `u.exp()` (with w/6 instead of w, so it stays moderate)
    Exp,
}

/// A cam profile y = c₀ + a₁x + a₂x² + a₃x³ + b·f(wx + φ), c₀ chosen at rendering.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileSpec {
    /// a₁, a₂, a₃.
    pub poly: [f64; 3],
    /// The optional function term: function, b, w, φ.
    pub extra: Option<(Extra, f64, f64, f64)>,
}

/// A cam contact.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactSpec {
    /// In [0, 1): picks the body carrying the marker.
    pub body: f64,
    /// Marker position in the body frame.
    pub marker: [f64; 3],
    /// Profile.
    pub profile: ProfileSpec,
    /// Cam frame: origin, x-axis angles (θ, φ), a raw vector orthogonalised into the y axis.
    /// `None`: the default frame (ground axes), not written in the file.
    pub frame: Option<([f64; 3], [f64; 2], [f64; 3])>,
}

/// A whole random model.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelSpec {
    /// Every revolute axis along ±z, prismatic axes, anchors, centres of mass, markers, cam
    /// planes and gravity in the x-y plane: a planar model (the generator's planar path).
    pub planar: bool,
    /// Gravity: `None` off; otherwise a direction (θ, φ) of magnitude 9.81 m/s².
    pub gravity: Option<[f64; 2]>,
    /// Bodies in spec order (parents before children).
    pub bodies: Vec<BodySpec>,
    /// 0, 1 or 2 contacts.
    pub contacts: Vec<ContactSpec>,
    /// Write the bodies in reverse order (children before parents) to exercise the loader's
    /// parents-first sorting.
    pub reversed: bool,
}

fn vec3(range: f64) -> impl Strategy<Value = [f64; 3]> {
    [-range..range, -range..range, -range..range]
}

fn axis() -> impl Strategy<Value = Axis> {
    prop_oneof![
        (0usize..3, any::<bool>()).prop_map(|(k, neg)| Axis::Aligned(k, neg)),
        (0.0..std::f64::consts::PI, -3.2..3.2, 0.5..2.0)
            .prop_map(|(theta, phi, scale)| Axis::Free { theta, phi, scale }),
    ]
}

/// Principal moments (kg·m²) that obey the triangle inequality with a margin: two moments
/// in [0.002, 1]·m, the third strictly between their difference and their sum.
fn moments(mass: f64) -> impl Strategy<Value = [f64; 3]> {
    (0.002..1.0f64, 0.002..1.0f64, 0.05..0.95f64).prop_map(move |(a, b, s)| {
        let (a, b) = (a * mass, b * mass);
        let (lo, hi) = ((a - b).abs(), a + b);
        [a, b, lo + s * (hi - lo)]
    })
}

fn inertia(mass: f64) -> impl Strategy<Value = InertiaSpec> {
    prop_oneof![
        1 => (0.002..1.0f64).prop_map(move |v| InertiaSpec::Izz(v * mass)),
        1 => moments(mass).prop_map(InertiaSpec::Diagonal),
        3 => (moments(mass), vec3(3.0))
            .prop_map(|(moments, rotation)| InertiaSpec::Rotated { moments, rotation }),
    ]
}

fn body() -> impl Strategy<Value = BodySpec> {
    (0.1..10.0f64).prop_flat_map(|mass| {
        (
            (0.0..1.0, prop::bool::weighted(0.3), axis()),
            (vec3(0.5), vec3(0.3), Just(mass), inertia(mass)),
            (
                prop::option::weighted(0.5, (0.0..50.0, 0.0..2.0, -0.5..0.5)),
                prop::option::weighted(0.1, (0.05..0.5, 0.5..3.0)),
                -1.0..1.0,
                -1.0..1.0,
            ),
        )
            .prop_map(
                |((parent, prismatic, axis), (anchor, com, mass, inertia), extras)| {
                    let (spring, drive, q0, qd0) = extras;
                    BodySpec {
                        parent,
                        prismatic,
                        axis,
                        anchor,
                        com,
                        mass,
                        inertia,
                        spring: spring.map(|(k, c, r)| [k, c, r]),
                        drive,
                        q0,
                        qd0,
                    }
                },
            )
    })
}

fn profile() -> impl Strategy<Value = ProfileSpec> {
    let extra = prop_oneof![
        Just(Extra::Sin),
        Just(Extra::Cos),
        Just(Extra::Atan),
        Just(Extra::Tanh),
        Just(Extra::SqrtQuad),
        Just(Extra::LnQuad),
        Just(Extra::Exp),
    ];
    (
        [-1.0..1.0, -0.5..0.5, -0.2..0.2],
        prop::option::weighted(0.7, (extra, -0.5..0.5, 0.2..3.0, -3.2..3.2)),
    )
        .prop_map(|(poly, extra)| ProfileSpec { poly, extra })
}

fn contact() -> impl Strategy<Value = ContactSpec> {
    (
        0.0..1.0,
        vec3(0.4),
        profile(),
        prop::option::weighted(
            0.7,
            (vec3(1.0), [0.0..std::f64::consts::PI, -3.2..3.2], vec3(1.0)),
        ),
    )
        .prop_map(|(body, marker, profile, frame)| ContactSpec {
            body,
            marker,
            profile,
            frame,
        })
}

/// The strategy for a whole random model.
pub fn model_spec() -> impl Strategy<Value = ModelSpec> {
    (
        prop::bool::weighted(0.25),
        prop::option::weighted(0.7, [0.0..std::f64::consts::PI, -3.2..3.2]),
        prop::collection::vec(body(), 1..=MAX_BODIES),
        prop::collection::vec(contact(), 0..=2),
        any::<bool>(),
    )
        .prop_map(|(planar, gravity, bodies, contacts, reversed)| ModelSpec {
            planar,
            gravity,
            bodies,
            contacts,
            reversed,
        })
}

/// A random state (q, q̇, t) for up to [`MAX_BODIES`] coordinates.
pub type StateSpec = (Vec<f64>, Vec<f64>, f64);

/// `count` random states: q in [−1.5, 1.5], q̇ in [−2, 2], t in [0, 5].
pub fn states(count: usize) -> impl Strategy<Value = Vec<StateSpec>> {
    prop::collection::vec(
        (
            prop::collection::vec(-1.5..1.5, MAX_BODIES),
            prop::collection::vec(-2.0..2.0, MAX_BODIES),
            0.0..5.0,
        ),
        count,
    )
}

type V3 = [f64; 3];
type M3 = [[f64; 3]; 3];

fn direction(theta: f64, phi: f64) -> V3 {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

fn scale(a: V3, s: f64) -> V3 {
    a.map(|x| x * s)
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalise(a: V3) -> V3 {
    scale(a, 1.0 / dot(a, a).sqrt())
}

fn mat_vec(m: &M3, v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for (r, row) in c.iter_mut().enumerate() {
        for (k, value) in row.iter_mut().enumerate() {
            *value = (0..3).map(|j| a[r][j] * b[j][k]).sum();
        }
    }
    c
}

/// Rotation by `angle` about the unit vector `u` (Rodrigues).
fn rotation(u: V3, angle: f64) -> M3 {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = u;
    [
        [c + t * x * x, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, c + t * y * y, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, c + t * z * z],
    ]
}

const IDENTITY: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn fmt3(v: V3) -> String {
    format!("({:?}, {:?}, {:?})", v[0], v[1], v[2])
}

impl BodySpec {
    /// Index of the parent among `index` earlier bodies, `None` for the ground.
    fn parent_index(&self, index: usize) -> Option<usize> {
        let k = (self.parent * (index + 1) as f64) as usize;
        k.min(index).checked_sub(1)
    }

    /// The axis as written in the file.
    fn raw_axis(&self, planar: bool) -> V3 {
        match (&self.axis, planar) {
            (Axis::Aligned(_, neg), true) if !self.prismatic => {
                [0.0, 0.0, if *neg { -1.0 } else { 1.0 }]
            }
            (Axis::Aligned(k, neg), false) => {
                let mut a = [0.0; 3];
                a[*k] = if *neg { -1.0 } else { 1.0 };
                a
            }
            (Axis::Aligned(k, neg), true) => {
                let mut a = [0.0; 3];
                a[k % 2] = if *neg { -1.0 } else { 1.0 };
                a
            }
            (Axis::Free { phi, .. }, true) if !self.prismatic => {
                [0.0, 0.0, if *phi < 0.0 { -1.0 } else { 1.0 }]
            }
            (Axis::Free { phi, scale: s, .. }, true) => [s * phi.cos(), s * phi.sin(), 0.0],
            (
                Axis::Free {
                    theta,
                    phi,
                    scale: s,
                },
                false,
            ) => scale(direction(*theta, *phi), *s),
        }
    }

    fn inertia_text(&self) -> String {
        match &self.inertia {
            InertiaSpec::Izz(v) => format!("Izz({v:?})"),
            InertiaSpec::Diagonal([a, b, c]) => format!("Diagonal({a:?}, {b:?}, {c:?})"),
            InertiaSpec::Rotated {
                moments,
                rotation: r,
            } => {
                let angle = dot(*r, *r).sqrt();
                let rot = if angle > 1e-3 {
                    rotation(scale(*r, 1.0 / angle), angle)
                } else {
                    IDENTITY
                };
                let d = [
                    [moments[0], 0.0, 0.0],
                    [0.0, moments[1], 0.0],
                    [0.0, 0.0, moments[2]],
                ];
                let rt = [0, 1, 2].map(|i| [0, 1, 2].map(|j| rot[j][i]));
                let m = mat_mul(&mat_mul(&rot, &d), &rt);
                // The products are written once each, so the tensor is exactly symmetric.
                format!(
                    "Full(ixx: {:?}, iyy: {:?}, izz: {:?}, ixy: {:?}, ixz: {:?}, iyz: {:?})",
                    m[0][0], m[1][1], m[2][2], m[0][1], m[0][2], m[1][2]
                )
            }
        }
    }
}

fn planar_point(p: V3, planar: bool) -> V3 {
    if planar { [p[0], p[1], 0.0] } else { p }
}

impl ContactSpec {
    /// Index of the marker's body among `n` bodies.
    fn body_index(&self, n: usize) -> usize {
        ((self.body * n as f64) as usize).min(n - 1)
    }

    /// Origin, x axis and y axis of the cam frame (unit, orthogonal).
    fn frame(&self, planar: bool) -> (V3, V3, V3) {
        match (&self.frame, planar) {
            (None, _) => ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            (Some((origin, [_, phi], _)), true) => {
                let x = [phi.cos(), phi.sin(), 0.0];
                (planar_point(*origin, true), x, [-x[1], x[0], 0.0])
            }
            (Some((origin, [theta, phi], raw)), false) => {
                let x = direction(*theta, *phi);
                let mut y = sub(*raw, scale(x, dot(*raw, x)));
                if dot(y, y) < 1e-4 {
                    // Nearly parallel: any vector orthogonal to x.
                    y = [-x[1], x[0], 0.0];
                    if dot(y, y) < 1e-4 {
                        y = [0.0, -x[2], x[1]];
                    }
                }
                let y = normalise(y);
                // One more Gram–Schmidt pass brings x·y down to rounding.
                let y = normalise(sub(y, scale(x, dot(y, x))));
                (*origin, x, y)
            }
        }
    }
}

impl ProfileSpec {
    /// The profile text without its constant term.
    fn variable_part(&self) -> String {
        let [a1, a2, a3] = self.poly;
        let mut text = format!("{a1:?}*x + {a2:?}*x*x + {a3:?}*x.powi(3)");
        if let Some((f, b, w, phi)) = self.extra {
            let u = format!("({w:?}*x + {phi:?})");
            let term = match f {
                Extra::Sin => format!("{u}.sin()"),
                Extra::Cos => format!("{u}.cos()"),
                Extra::Atan => format!("{u}.atan()"),
                Extra::Tanh => format!("{u}.tanh()"),
                Extra::SqrtQuad => format!("(1.0 + {u}*{u}).sqrt()"),
                Extra::LnQuad => format!("(1.0 + {u}.powi(2)).ln()"),
                Extra::Exp => format!("({:?}*x + {phi:?}).exp()", w / 6.0),
            };
            let _ = write!(text, " + {b:?}*{term}");
        }
        text
    }
}

/// Pose of every body at `q` (spec order): rotation ground ← body and origin.
fn poses(spec: &ModelSpec, q: &[f64]) -> Vec<(M3, V3)> {
    let mut out: Vec<(M3, V3)> = Vec::with_capacity(spec.bodies.len());
    for (i, b) in spec.bodies.iter().enumerate() {
        let (rot_p, origin_p) = b.parent_index(i).map_or((IDENTITY, [0.0; 3]), |p| out[p]);
        let axis = normalise(b.raw_axis(spec.planar));
        let anchor = planar_point(b.anchor, spec.planar);
        out.push(if b.prismatic {
            (
                rot_p,
                add(origin_p, mat_vec(&rot_p, add(anchor, scale(axis, q[i])))),
            )
        } else {
            (
                mat_mul(&rot_p, &rotation(axis, q[i])),
                add(origin_p, mat_vec(&rot_p, anchor)),
            )
        });
    }
    out
}

impl ModelSpec {
    /// Number of bodies.
    pub fn n(&self) -> usize {
        self.bodies.len()
    }

    /// The initial guess in spec order (a driven coordinate starts at q0 too).
    pub fn initial_q(&self) -> Vec<f64> {
        self.bodies.iter().map(|b| b.q0).collect()
    }

    /// Ground position of contact `k`'s marker at `q` (spec order), by forward kinematics
    /// written here, independently of the crates under test.
    pub fn marker_position(&self, k: usize, q: &[f64]) -> V3 {
        let c = &self.contacts[k];
        let (rot, origin) = poses(self, q)[c.body_index(self.n())];
        add(origin, mat_vec(&rot, planar_point(c.marker, self.planar)))
    }

    /// Joints without a drive between the ground and the markers of the contacts `ks`.
    fn free_joints(&self, ks: impl Iterator<Item = usize>) -> Vec<usize> {
        let mut joints = Vec::new();
        for k in ks {
            let mut body = Some(self.contacts[k].body_index(self.n()));
            while let Some(i) = body {
                if self.bodies[i].drive.is_none() && !joints.contains(&i) {
                    joints.push(i);
                }
                body = self.bodies[i].parent_index(i);
            }
        }
        joints
    }

    /// True when the markers can slide along their cams: every marker has at least two joints
    /// without a drive between it and the ground, and all markers together have more such
    /// joints than there are contacts (otherwise the contacts freeze them where they start).
    pub fn markers_can_slide(&self) -> bool {
        let nc = self.contacts.len();
        (0..nc).all(|k| self.free_joints(std::iter::once(k)).len() >= 2)
            && (nc == 0 || self.free_joints(0..nc).len() > nc)
    }

    /// The model file, named `name`.
    pub fn ron(&self, name: &str) -> String {
        let n = self.n();
        let mut s = String::new();
        let _ = writeln!(
            s,
            "// A random model drawn by runtime/tests/random/mod.rs (the files of\n// \
             tests/random_models/ are rewritten by `cargo test -p camchain-reference --test \
             random_models -- --ignored write_compiled_models`)."
        );
        let _ = writeln!(s, "(\n    name: {name:?},");
        if let Some([theta, phi]) = self.gravity {
            let g = if self.planar {
                [9.81 * phi.cos(), 9.81 * phi.sin(), 0.0]
            } else {
                scale(direction(theta, phi), 9.81)
            };
            let _ = writeln!(s, "    gravity: {},", fmt3(g));
        }
        let _ = writeln!(s, "    bodies: [");
        let order: Vec<usize> = if self.reversed {
            (0..n).rev().collect()
        } else {
            (0..n).collect()
        };
        for i in order {
            let b = &self.bodies[i];
            let parent = b
                .parent_index(i)
                .map_or_else(|| "ground".to_string(), |p| format!("b{p}"));
            let _ = writeln!(
                s,
                "        (\n            name: \"b{i}\", parent: {parent:?}, mass: {:?},\n            \
                 com: {},\n            inertia: {},",
                b.mass,
                fmt3(planar_point(b.com, self.planar)),
                b.inertia_text(),
            );
            let kind = if b.prismatic { "Prismatic" } else { "Revolute" };
            let _ = write!(
                s,
                "            joint: (\n                kind: {kind}, axis: {}, anchor: {}, \
                 coordinate: \"q{i}\",",
                fmt3(b.raw_axis(self.planar)),
                fmt3(planar_point(b.anchor, self.planar)),
            );
            if let Some([k, c, rest]) = b.spring {
                let _ = write!(
                    s,
                    "\n                spring: (stiffness: {k:?}, damping: {c:?}, rest: {rest:?}),"
                );
            }
            if let Some((amplitude, omega)) = b.drive {
                let _ = write!(
                    s,
                    "\n                prescribed: \"{:?} + {amplitude:?}*({omega:?}*t).sin()\",",
                    b.q0
                );
            }
            let _ = writeln!(s, "\n            ),\n        ),");
        }
        let _ = writeln!(s, "    ],");
        let q0 = self.initial_q();
        let mut markers = String::new();
        let mut contacts = String::new();
        for (k, c) in self.contacts.iter().enumerate() {
            let _ = writeln!(
                markers,
                "        (name: \"P{k}\", body: \"b{}\", position: {}),",
                c.body_index(n),
                fmt3(planar_point(c.marker, self.planar))
            );
            let (origin, x_axis, y_axis) = c.frame(self.planar);
            // Shift the profile so that it passes through the marker at the initial guess.
            let p = self.marker_position(k, &q0);
            let (x0, y0) = (dot(x_axis, sub(p, origin)), dot(y_axis, sub(p, origin)));
            let variable = c.profile.variable_part();
            let g0 = parse_expression(&variable, "x").map_or(f64::NAN, |e| e.eval(x0));
            let _ = write!(
                contacts,
                "        (\n            marker: \"P{k}\",\n            profile: \"{:?} + {variable}\",",
                y0 - g0
            );
            if c.frame.is_some() {
                let _ = write!(
                    contacts,
                    "\n            frame: (origin: {}, x_axis: {}, y_axis: {}),",
                    fmt3(origin),
                    fmt3(x_axis),
                    fmt3(y_axis)
                );
            }
            let _ = writeln!(contacts, "\n        ),");
        }
        if !markers.is_empty() {
            let _ = writeln!(s, "    markers: [\n{markers}    ],");
            let _ = writeln!(s, "    contacts: [\n{contacts}    ],");
        }
        let values = |v: &dyn Fn(&BodySpec) -> f64| {
            self.bodies
                .iter()
                .enumerate()
                .map(|(i, b)| format!("\"q{i}\": {:?}", v(b)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(
            s,
            "    initial: (\n        q: {{{}}},\n        qd: {{{}}},\n    ),",
            values(&|b| b.q0),
            values(&|b| b.qd0)
        );
        let _ = writeln!(
            s,
            "    simulation: (t_end: 1.0, dt_out: 0.01, integrator: Dopri5, dt: 1e-3, rtol: 1e-10, \
             atol: 1e-12),\n)"
        );
        s
    }
}
