//! The reference's contacts: every kind evaluated numerically, by routes of its own.
//!
//! - The follower seen from the cam: positions, velocities and convective accelerations of
//!   both bodies from the full recursions (every joint, common ancestors included), then the
//!   moving-frame formulas Ṗ = R_Cᵀ(ṙ − ω_C × r), P̈° = R_Cᵀ(r̈° − α_C° × r − 2ω_C × ṙ +
//!   ω_C × (ω_C × r)); Jacobian columns from the motion at q̇ = e_j.
//! - The profile: c(s), c′(s), c″(s) by forward-mode differentiation ([`crate::jet`]) of
//!   the curve itself (a polar profile as r(θ)·cos θ in jet arithmetic), its expressions
//!   evaluated as one tape ([`crate::tape`]).
//! - Contact points: the nearest point, or the flat face's support point, by a scan of the
//!   range refined by golden-section search and polished by Newton's method: the global
//!   optimum, where the generated code tracks a local one from a guess.
//! - A flat face's convective term from the general three-dimensional rotation of its
//!   normal (the generator uses the planar form).
//! - A cam surface z = f(x, y) ([`surface`]): its gradient and Hessian from jets along
//!   lines, its curvature from the shape operator's invariants; a surface of revolution
//!   ([`revolution`]) likewise in three dimensions.

mod ball;
mod revolution;
mod surface;

use crate::jet::Jet2;
use crate::motion::{Motion, Pose, Vec3, vec3};
use crate::tape::Tape;
use camchain_model::model::{Contact, Follower, JointKind, Model, Profile};
use camchain_runtime::kinds::Outline;
use camchain_runtime::{ContactGeometry, ContactKinematics};

/// Samples of the range compared before the golden-section refinement.
const SCAN: usize = 512;

/// The identity of the next contact built (so that a reused search is this contact's).
static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A search's result to reuse: ((contact, its inputs' bits), the parameter).
type Search = ((u64, [u64; 2]), f64);

thread_local! {
    /// The last contact-parameter search on this thread.
    static LAST_SEARCH: std::cell::Cell<Option<Search>> = const { std::cell::Cell::new(None) };
}

/// The constant data of one contact.
#[derive(Debug, Clone)]
pub(crate) struct ContactConst {
    /// Unique among the contacts built by this process (the key of a reused search).
    id: u64,
    /// The follower's body and its point (the marker, or a circular outline's centre) in that
    /// body's frame.
    body: usize,
    marker: Vec3,
    /// The follower body's own joint.
    own_joint: JointKind,
    cam_body: Option<usize>,
    /// The cam frame in the cam body's frame.
    origin: Vec3,
    x_axis: Vec3,
    y_axis: Vec3,
    follower: Follower,
    /// The profile; a face cam's groove centre line.
    profile: Profile,
    /// In a face cam's groove, the roller's radius (0 for a knife edge): its centre is on
    /// `profile`, it touches the inner flank that far in.
    groove: Option<f64>,
    /// A tapered roller's half-angle in a barrel's groove (0: straight): its geometry then
    /// carries the radial direction.
    taper: f64,
    /// The profile's expressions (f, r, or x and y) as one tape, for the many evaluations of
    /// the search.
    tape: Tape,
    range: (f64, f64),
}

/// The follower seen from the cam at one state: cam-frame components.
#[derive(Debug, Clone, Copy)]
struct Seen {
    /// The follower point P.
    p: [f64; 2],
    /// Ṗ.
    v: [f64; 2],
    /// The velocity-product part of P̈.
    a: [f64; 2],
    /// The same three along the cam's axis: Z, Ż and the velocity-product part of Z̈.
    height: [f64; 3],
    /// A flat face's unit normal m (from the cam into the follower), ṁ and m̈°.
    m: [f64; 2],
    m_dot: [f64; 2],
    m_acc: [f64; 2],
    /// The follower's spin relative to the cam about the cam's axis.
    spin: f64,
}

/// The cam frame in ground coordinates at one configuration.
#[derive(Debug, Clone, Copy)]
struct CamFrame {
    origin: Vec3,
    x: Vec3,
    y: Vec3,
    axis: Vec3,
}

/// Everything the reference computes of a contact.
#[derive(Debug, Clone)]
pub(crate) struct Evaluated {
    pub h: f64,
    pub jacobian: Vec<f64>,
    pub bias: f64,
    pub geometry: ContactGeometry,
    pub kinematics: ContactKinematics,
}

/// c, c′, c″ of a profile at s.
#[derive(Debug, Clone, Copy)]
struct CurvePoint {
    c: [f64; 2],
    d1: [f64; 2],
    d2: [f64; 2],
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// a turned a quarter turn counterclockwise.
fn perp(a: [f64; 2]) -> [f64; 2] {
    [-a[1], a[0]]
}

impl ContactConst {
    pub(crate) fn new(model: &Model, contact: &Contact) -> Self {
        let marker = &model.markers[contact.marker];
        Self {
            id: NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            body: marker.body,
            // The follower point: the marker, or the centre of a circular outline the radius
            // away from it (a curved face's apex is the marker).
            marker: match contact.follower.centre_direction() {
                Some(direction) => {
                    vec3(&marker.position)
                        + vec3(&direction) * contact.follower.radius().copied().unwrap_or(0.0)
                }
                None => vec3(&marker.position),
            },
            own_joint: model.bodies[marker.body].joint.kind,
            cam_body: contact.cam_body,
            origin: vec3(&contact.origin),
            x_axis: vec3(&contact.x_axis),
            y_axis: vec3(&contact.y_axis),
            follower: contact.follower,
            profile: contact.profile.curve().clone(),
            groove: match contact.profile {
                Profile::Face { .. } => Some(contact.follower.radius().copied().unwrap_or(0.0)),
                _ => None,
            },
            taper: contact.taper,
            tape: match contact.profile.curve() {
                Profile::Explicit { f, .. }
                | Profile::Surface { f, .. }
                | Profile::Barrel { f, .. } => Tape::new(&[f]),
                Profile::Revolution { g, .. } => Tape::new(&[g]),
                Profile::Polar { r, .. } => Tape::new(&[r]),
                Profile::Parametric { x, y, .. } => Tape::new(&[x, y]),
                // `curve()` is never a face.
                Profile::Face { .. } => Tape::new(&[]),
            },
            range: contact.range.unwrap_or((0.0, std::f64::consts::TAU)),
        }
    }

    fn frame(&self, poses: &[Pose]) -> CamFrame {
        let axis = self.x_axis.cross(&self.y_axis);
        match self.cam_body {
            None => CamFrame {
                origin: self.origin,
                x: self.x_axis,
                y: self.y_axis,
                axis,
            },
            Some(c) => {
                let r = poses[c].rot;
                CamFrame {
                    origin: poses[c].origin + r * self.origin,
                    x: r * self.x_axis,
                    y: r * self.y_axis,
                    axis: r * axis,
                }
            }
        }
    }

    /// The follower point, ground coordinates.
    fn point(&self, poses: &[Pose]) -> Vec3 {
        poses[self.body].origin + poses[self.body].rot * self.marker
    }

    /// The follower seen from the cam for the body motions `motions` (velocities and the
    /// accelerations they give at q̈ = 0).
    fn seen(&self, poses: &[Pose], motions: &[Motion], rest: &Motion) -> Seen {
        let f = self.frame(poses);
        let point = self.point(poses);
        let follower = &motions[self.body];
        let offset = point - poses[self.body].origin;
        let (v_p, a_p) = (
            follower.point_velocity(&offset),
            follower.point_acceleration(&offset),
        );
        let cam = self.cam_body.map_or(rest, |c| &motions[c]);
        let cam_offset = match self.cam_body {
            Some(c) => f.origin - poses[c].origin,
            None => Vec3::zeros(),
        };
        let (v_o, a_o) = (
            cam.point_velocity(&cam_offset),
            cam.point_acceleration(&cam_offset),
        );
        let (w, al) = (cam.omega, cam.alpha);
        let r = point - f.origin;
        let r_dot = v_p - v_o;
        let r_acc = a_p - a_o;
        let rel_v = r_dot - w.cross(&r);
        let rel_a = r_acc - al.cross(&r) - w.cross(&r_dot) * 2.0 + w.cross(&w.cross(&r));
        let cam2 = |v: Vec3| [f.x.dot(&v), f.y.dot(&v)];
        // A flat face's normal (from the cam into the follower), its rate and acceleration
        // seen from the cam: d/dt (R_Cᵀ m) = R_Cᵀ (ṁ − ω_C × m).
        let face = match (self.follower.kind().outline(), self.follower.normal()) {
            (Outline::Line, Some(normal)) => -(poses[self.body].rot * vec3(normal)),
            (Outline::Point | Outline::Circle | Outline::Line, _) => Vec3::zeros(),
        };
        let w_rel = follower.omega - w;
        let m_dot = w_rel.cross(&face);
        let m_rate = follower.omega.cross(&face);
        let a_rel = follower.alpha - al;
        let m_acc = a_rel.cross(&face) + w_rel.cross(&m_rate) - w.cross(&m_dot);
        Seen {
            p: cam2(r),
            v: cam2(rel_v),
            a: cam2(rel_a),
            height: [r, rel_v, rel_a].map(|v| f.axis.dot(&v)),
            m: cam2(face),
            m_dot: cam2(m_dot),
            m_acc: cam2(m_acc),
            spin: f.axis.dot(&w_rel),
        }
    }

    /// c, c′, c″ of the profile at s, by jets of the curve.
    fn curve(&self, s: f64) -> CurvePoint {
        let at = Jet2::variable(s);
        let values = self.tape.eval_jet(at);
        let [x, y] = match &self.profile {
            // A surface's trace on its plane y = 0 (the model's samples give the same); its
            // contacts do not read it ([`surface`]).
            Profile::Explicit { .. } => [at, values[0]],
            // A barrel's pitch curve developed at its radius, (R θ, g(θ)).
            Profile::Barrel { radius, .. } => [at * Jet2::constant(*radius), values[0]],
            // A surface of revolution's meridian (g(z), z).
            Profile::Revolution { .. } => [values[0], at],
            Profile::Surface { .. } => {
                let on_trace = self.tape.eval_jet_at(&[at, Jet2::constant(0.0)]);
                [at, on_trace[0]]
            }
            Profile::Polar { .. } => {
                let r = values[0];
                [r * at.cos(), r * at.sin()]
            }
            // (`profile` is a face cam's centre line, never the face itself.)
            Profile::Parametric { .. } | Profile::Face { .. } => [values[0], values[1]],
        };
        CurvePoint {
            c: [x.v, y.v],
            d1: [x.d1, y.d1],
            d2: [x.d2, y.d2],
        }
    }

    /// c(s) alone, in plain arithmetic (what the search compares).
    fn profile_point(&self, s: f64) -> [f64; 2] {
        match &self.profile {
            Profile::Surface { .. } => return [s, self.tape.eval_at(&[s, 0.0])[0]],
            Profile::Explicit { .. }
            | Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Barrel { .. }
            | Profile::Revolution { .. }
            | Profile::Face { .. } => {}
        }
        let values = self.tape.eval(s);
        match &self.profile {
            Profile::Explicit { .. } | Profile::Surface { .. } => [s, values[0]],
            Profile::Barrel { radius, .. } => [radius * s, values[0]],
            Profile::Revolution { .. } => [values[0], s],
            Profile::Polar { .. } => [values[0] * s.cos(), values[0] * s.sin()],
            Profile::Parametric { .. } | Profile::Face { .. } => [values[0], values[1]],
        }
    }

    /// +1 when the follower is on the left of increasing s (explicit), −1 otherwise.
    fn side(&self) -> f64 {
        match self.profile {
            Profile::Explicit { .. } | Profile::Surface { .. } | Profile::Barrel { .. } => 1.0,
            Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Revolution { .. }
            | Profile::Face { .. } => -1.0,
        }
    }

    /// Unit tangent, unit normal towards the follower, curvature (positive where hollow
    /// seen from the follower).
    fn frenet(&self, c: &CurvePoint) -> ([f64; 2], [f64; 2], f64) {
        let speed = dot(c.d1, c.d1).sqrt();
        let t = [c.d1[0] / speed, c.d1[1] / speed];
        let side = self.side();
        let n = [-side * t[1], side * t[0]];
        let kappa = side * (c.d1[0] * c.d2[1] - c.d1[1] * c.d2[0]) / speed.powi(3);
        (t, n, kappa)
    }

    /// The profile parameter minimising `objective` over the range: a scan, then
    /// golden-section search around the best sample, then Newton on `stationary` (its
    /// value and derivative) while it improves. The objective depends on the state only
    /// through `inputs` (the follower point, or the face's normal, in the cam frame): the
    /// last search of this contact on this thread for the same inputs is reused (the
    /// constraint, its Jacobian, its bias and the outputs of one configuration each ask).
    fn optimum(
        &self,
        inputs: [f64; 2],
        objective: impl Fn(f64) -> f64,
        stationary: impl Fn(f64) -> (f64, f64),
    ) -> f64 {
        let key = (self.id, inputs.map(f64::to_bits));
        if let Some(s) = LAST_SEARCH.with(|last| last.get().filter(|(k, _)| *k == key)) {
            return s.1;
        }
        let s = self.search(objective, stationary);
        LAST_SEARCH.with(|last| last.set(Some((key, s))));
        s
    }

    /// [`ContactConst::optimum`]'s search itself.
    fn search(
        &self,
        objective: impl Fn(f64) -> f64,
        stationary: impl Fn(f64) -> (f64, f64),
    ) -> f64 {
        let (a, b) = self.range;
        let step = (b - a) / SCAN as f64;
        let best = (0..=SCAN)
            .map(|k| {
                let s = a + step * k as f64;
                (s, objective(s))
            })
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map_or(a, |(s, _)| s);
        let (mut lo, mut hi) = (best - step, best + step);
        let ratio = 0.5 * (5f64.sqrt() - 1.0);
        while hi - lo > 1e-9 * (b - a) {
            let (x1, x2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
            if objective(x1) < objective(x2) {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        let mut s = 0.5 * (lo + hi);
        for _ in 0..4 {
            let (value, slope) = stationary(s);
            let next = s - value / slope;
            if !next.is_finite() || (next - s).abs() > 1e-6 * (b - a) {
                break;
            }
            s = next;
        }
        s
    }

    /// h, J, c and the outputs of this contact at (q, q̇). `unit` gives the body motions for
    /// q̇ = e_j (the Jacobian columns).
    pub(crate) fn evaluate(
        &self,
        poses: &[Pose],
        motions: &[Motion],
        unit: &dyn Fn(usize) -> Vec<Motion>,
        n: usize,
    ) -> Evaluated {
        let rest = Motion::rest();
        let seen = self.seen(poses, motions, &rest);
        let columns: Vec<Seen> = (0..n).map(|j| self.seen(poses, &unit(j), &rest)).collect();
        let frame = self.frame(poses);
        let point = self.point(poses);
        let direction = {
            let own = &unit(self.body)[self.body];
            let d = match self.own_joint {
                JointKind::Revolute => own.point_velocity(&(point - poses[self.body].origin)),
                JointKind::Prismatic => own.vel,
            };
            d / d.norm()
        };
        match (&self.profile, &self.follower) {
            (Profile::Surface { .. }, Follower::Roller { .. }) => {
                return self.on_ball(&seen, &columns, &frame, point, direction);
            }
            (Profile::Revolution { .. }, Follower::Roller { .. }) => {
                return self.on_ball_revolution(&seen, &columns, &frame, point, direction);
            }
            _ => {}
        }
        match &self.profile {
            Profile::Surface { .. } | Profile::Barrel { .. } => {
                return self.on_surface(&seen, &columns, &frame, point, direction);
            }
            Profile::Revolution { .. } => {
                return self.on_revolution(&seen, &columns, &frame, point, direction);
            }
            Profile::Explicit { .. }
            | Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Face { .. } => {}
        }
        let x = seen.p;
        // The contact point sits at the follower point's height along the cam's axis.
        let height = frame.axis.dot(&(point - frame.origin));
        let to_ground =
            |c: [f64; 2]| frame.origin + frame.x * c[0] + frame.y * c[1] + frame.axis * height;
        let vector = |c: [f64; 2]| frame.x * c[0] + frame.y * c[1];
        let (h, jacobian, bias, contact, normal, scale, parameter, kappa, tangent) =
            match (&self.follower, &self.profile) {
                (Follower::Knife, Profile::Explicit { .. }) => {
                    let c = self.curve(x[0]);
                    let (slope, second) = (c.d1[1], c.d2[1]);
                    let h = x[1] - c.c[1];
                    let jac = columns.iter().map(|s| s.v[1] - slope * s.v[0]).collect();
                    let bias = seen.a[1] - slope * seen.a[0] - second * seen.v[0].powi(2);
                    let stretch = (1.0 + slope * slope).sqrt();
                    let (t, n, kappa) = self.frenet(&c);
                    (h, jac, bias, x, n, stretch, x[0], kappa, t)
                }
                (Follower::Knife | Follower::Roller { .. } | Follower::Mushroom { .. }, _) => {
                    let rho = self.follower.radius().copied().unwrap_or(0.0);
                    let p = seen.p;
                    let s = self.optimum(
                        p,
                        |s| {
                            let d = sub(p, self.profile_point(s));
                            dot(d, d)
                        },
                        |s| {
                            let c = self.curve(s);
                            let d = sub(p, c.c);
                            (dot(c.d1, d), dot(c.d2, d) - dot(c.d1, c.d1))
                        },
                    );
                    let c = self.curve(s);
                    let (t, n, kappa) = self.frenet(&c);
                    let distance = dot(n, sub(p, c.c));
                    let jac = columns.iter().map(|col| dot(n, col.v)).collect();
                    let along = dot(t, seen.v);
                    let bias = dot(n, seen.a) - kappa * along * along / (1.0 - kappa * distance);
                    match self.groove {
                        None => (distance - rho, jac, bias, c.c, n, 1.0, s, kappa, t),
                        // In a face cam's groove the centre is on the centre line; the inner
                        // flank, ρ in, has the signed radius of curvature 1/κ + ρ.
                        Some(rho) => {
                            let flank = [c.c[0] - rho * n[0], c.c[1] - rho * n[1]];
                            let flank_kappa = 1.0 / (1.0 / kappa + rho);
                            (distance, jac, bias, flank, n, 1.0, s, flank_kappa, t)
                        }
                    }
                }
                (Follower::Flat { .. }, _) => {
                    let m = seen.m;
                    let s = self.optimum(
                        m,
                        |s| -dot(m, self.profile_point(s)),
                        |s| {
                            let c = self.curve(s);
                            (dot(m, c.d1), dot(m, c.d2))
                        },
                    );
                    let c = self.curve(s);
                    let (t, _, kappa) = self.frenet(&c);
                    let gap = sub(seen.p, c.c);
                    let h = dot(m, gap);
                    let jac = columns
                        .iter()
                        .map(|col| dot(col.m_dot, gap) + dot(m, col.v))
                        .collect();
                    let tilt = dot(seen.m_dot, c.d1);
                    let bias = dot(seen.m_acc, gap)
                        + 2.0 * dot(seen.m_dot, seen.v)
                        + dot(m, seen.a)
                        + tilt * tilt / dot(m, c.d2);
                    (h, jac, bias, c.c, m, 1.0, s, kappa, t)
                }
            };
        // The follower's material at the contact point, relative to the cam.
        let material = {
            let arm = sub(contact, seen.p);
            let swing = perp(arm);
            [
                seen.v[0] + seen.spin * swing[0],
                seen.v[1] + seen.spin * swing[1],
            ]
        };
        let normal3 = vector(normal);
        let geometry = ContactGeometry {
            position: to_ground(contact).into(),
            x: contact[0],
            y: contact[1],
            z: 0.0,
            follower: point.into(),
            normal: normal3.into(),
            axis: frame.axis.into(),
            force_scale: scale,
            parameter,
            curvature: kappa,
            direction: direction.into(),
            sliding_speed: dot(tangent, material),
            radial: [0.0; 3],
        };
        let kinematics = ContactKinematics {
            geometry,
            x: seen.p[0],
            y: seen.p[1],
            j1: columns.iter().map(|c| c.v[0]).collect(),
            j2: columns.iter().map(|c| c.v[1]).collect(),
            conv1: seen.a[0],
            conv2: seen.a[1],
            // Written for a cam surface only, as the generated code does.
            z: 0.0,
            j3: vec![0.0; n],
            conv3: 0.0,
        };
        Evaluated {
            h,
            jacobian,
            bias,
            geometry,
            kinematics,
        }
    }
}
