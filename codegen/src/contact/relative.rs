//! The follower seen from the cam: its point in the cam frame, carried by any body, with the
//! Jacobian and the velocity-product part of its acceleration (docs/method.md §9.1).
//!
//! Everything is formed in ground axes, where a planar chain's absolute angles keep the
//! closed forms short, and projected on the cam frame's axes at the end. Only the joints
//! between the follower's body and the cam's body move one relative to the other: those
//! below their deepest common ancestor A. The motion of A and above cancels, so it is left
//! out altogether (their rates taken as zero, which is exact for a quantity that does not
//! depend on them): a fixed cam (A the ground) gives the paper's terms (1)–(8) unchanged.
//!
//! With r = p − o_C the follower point seen from the cam frame's origin, P = R_Cᵀ r its
//! cam-frame coordinates,
//!
//! ```text
//! Ṗ = R_Cᵀ (ṙ − ω_C × r) = R_Cᵀ Σ_j s_j col_j(p) q̇_j
//! P̈ = J q̈ + R_Cᵀ (r̈° − α°_C × r − 2 ω_C × ṙ + ω_C × (ω_C × r))
//! ```
//!
//! where col_j(p) = u_j × (p − o_j) for a revolute joint and u_j for a prismatic one, s_j = +1
//! on the follower's side, −1 on the cam's, and ° marks velocity-product parts.

use crate::expr::scalar::dot_list;
use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Rotation, Symbols, V3, vec3};
use crate::model::{Contact, Field, JointKind, Model};

/// The follower of one contact in the cam frame.
#[derive(Debug, Clone)]
pub struct Relative {
    /// The follower point (the marker), ground coordinates.
    pub point: V3,
    /// Its cam-frame coordinates (X, Y) (eq. 1: f1, f2).
    pub xy: [Id; 2],
    /// ∂X/∂q_j and ∂Y/∂q_j for every coordinate (J1, J2).
    pub columns: Vec<[Id; 2]>,
    /// The velocity-product parts of Ẍ and Ÿ ((J1 q̇)_q q̇, (J2 q̇)_q q̇).
    pub convective: [Id; 2],
    /// (Ẋ, Ẏ) = (J1 q̇, J2 q̇).
    pub velocity: [Id; 2],
    /// The cam frame's origin, ground coordinates.
    pub origin: V3,
    /// The cam frame's x axis, ground coordinates.
    pub x_axis: V3,
    /// The cam frame's y axis, ground coordinates.
    pub y_axis: V3,
    /// The cam's axis x̂ × ŷ, ground coordinates.
    pub axis: V3,
    /// The follower point's coordinate along the cam's axis Z (0 in a planar model).
    pub height: Id,
    /// ∂Z/∂q_j for every coordinate (J3: what a cam surface z = f(x, y) needs beside J1, J2).
    pub height_columns: Vec<Id>,
    /// The velocity-product part of Z̈ ((J3 q̇)_q q̇).
    pub height_convective: Id,
    /// Ż = J3 q̇.
    pub height_rate: Id,
    /// ∂ω_r/∂q̇_j: the follower's angular velocity relative to the cam, about the cam's
    /// axis, per unit rate of joint j.
    pub spin_columns: Vec<Id>,
    /// ω_r = Σ spin_columns_j q̇_j.
    pub spin: Id,
    /// The direction (not normalised) in which the follower body's own joint moves the
    /// follower point, ground coordinates.
    pub direction: V3,
    /// The follower body's rotation body → ground applied to what the follower carries.
    follower_body: usize,
}

impl Relative {
    /// A vector given in the follower body's frame, in ground coordinates.
    pub fn follower_vector(&self, g: &mut Graph, kin: &[BodyKinematics], v: V3) -> V3 {
        kin[self.follower_body].rotation.apply(g, v)
    }

    /// The cam-frame components (x̂·v, ŷ·v) of a ground vector.
    pub fn in_cam_frame(&self, g: &mut Graph, v: V3) -> [Id; 2] {
        [vec3::dot(g, self.x_axis, v), vec3::dot(g, self.y_axis, v)]
    }

    /// The ground point of cam-frame coordinates (x, y) at the follower point's height
    /// along the cam's axis (where a cylindrical cam touches the follower).
    pub fn to_ground(&self, g: &mut Graph, xy: [Id; 2]) -> V3 {
        let x = vec3::scale(g, xy[0], self.x_axis);
        let y = vec3::scale(g, xy[1], self.y_axis);
        let z = vec3::scale(g, self.height, self.axis);
        let v = vec3::add(g, x, y);
        let v = vec3::add(g, v, z);
        vec3::add(g, self.origin, v)
    }

    /// The ground vector of cam-frame components (x, y).
    pub fn vector_to_ground(&self, g: &mut Graph, xy: [Id; 2]) -> V3 {
        let x = vec3::scale(g, xy[0], self.x_axis);
        let y = vec3::scale(g, xy[1], self.y_axis);
        vec3::add(g, x, y)
    }

    /// The follower point seen in its meridian half-plane, for a cam symmetric about the
    /// cam's axis (a surface of revolution): the plane coordinates (r, Z), r = √(X² + Y²) the
    /// distance from the axis, with their Jacobian columns, rates and convective parts
    /// (r̈ has the turning meridian's (|Ṗ_xy|² − ṙ²)/r besides u·P̈_xy, u = (X, Y)/r), its
    /// axes the radial direction and the cam's axis in ground coordinates (so that
    /// `to_ground` of a meridian point is the point of space). The follower's spin about the
    /// cam's axis moves no point of the half-plane: it is zero there. Also returns u.
    pub fn meridian(&self, g: &mut Graph) -> (Relative, [Id; 2]) {
        let [x, y] = self.xy;
        let r = {
            let xx = g.mul(x, x);
            let yy = g.mul(y, y);
            let s = g.add(xx, yy);
            g.sqrt(s)
        };
        let u = [g.div(x, r), g.div(y, r)];
        let along = |g: &mut Graph, v: [Id; 2]| {
            let a = g.mul(u[0], v[0]);
            let b = g.mul(u[1], v[1]);
            g.add(a, b)
        };
        let columns = self
            .columns
            .iter()
            .zip(&self.height_columns)
            .map(|(&c, &j3)| [along(g, c), j3])
            .collect();
        let rate = along(g, self.velocity);
        let bend = {
            let [vx, vy] = self.velocity;
            let speed2 = {
                let a = g.mul(vx, vx);
                let b = g.mul(vy, vy);
                g.add(a, b)
            };
            let rate2 = g.mul(rate, rate);
            let across = g.sub(speed2, rate2);
            g.div(across, r)
        };
        let radial_convective = {
            let a = along(g, self.convective);
            g.add(a, bend)
        };
        let radial = {
            let a = vec3::scale(g, u[0], self.x_axis);
            let b = vec3::scale(g, u[1], self.y_axis);
            vec3::add(g, a, b)
        };
        let zero = g.zero();
        let n = self.columns.len();
        let meridian = Relative {
            point: self.point,
            xy: [r, self.height],
            columns,
            convective: [radial_convective, self.height_convective],
            velocity: [rate, self.height_rate],
            origin: self.origin,
            x_axis: radial,
            y_axis: self.axis,
            axis: vec3::zero(g),
            height: zero,
            height_columns: vec![zero; n],
            height_convective: zero,
            height_rate: zero,
            spin_columns: vec![zero; n],
            spin: zero,
            direction: self.direction,
            follower_body: self.follower_body,
        };
        (meridian, u)
    }
}

/// The bodies whose joints move `body`, tip first (empty for the ground).
fn path_to_root(model: &Model, body: Option<usize>) -> Vec<usize> {
    let mut path = Vec::new();
    let mut at = body;
    while let Some(j) = at {
        path.push(j);
        at = model.bodies[j].parent;
    }
    path
}

/// A point fixed on a body, moving relative to an ancestor taken as fixed.
pub(crate) struct PointMotion {
    /// Ground position: `base + arm`.
    pub position: V3,
    /// The ground position of the joint point of the path's root (its anchor, moved by any
    /// sliding joints the segments cross at the root; the point itself for the ground).
    pub base: V3,
    /// The point relative to `base`: the sum of `segments`, each O(the body's size)
    /// however far the mechanism sits from the ground's origin.
    pub arm: V3,
    /// The terms of `arm`, tip first: each a vector fixed in a body turned by that body's
    /// rotation.
    pub segments: Vec<Segment>,
    /// ∂p/∂q_j (ground) for the joints that move it relative to the ancestor.
    pub columns: Vec<Option<V3>>,
    /// Velocity-product part of its acceleration relative to the ancestor.
    pub convective: V3,
    /// The body's angular velocity relative to the ancestor.
    pub omega: V3,
    /// Velocity-product part of that angular velocity's rate.
    pub alpha: V3,
}

/// One term of a point's arm: `rotation` applied to `local`, which is `value`.
#[derive(Clone)]
pub(crate) struct Segment {
    /// The body's rotation, body → ground.
    pub rotation: Rotation,
    /// The vector in the body's frame.
    pub local: V3,
    /// rotation · local, ground coordinates.
    pub value: V3,
}

/// What names the labels of a point's terms (`A` for the follower of contact A, `A_cam` for
/// its cam's origin).
pub(crate) struct Labels<'a> {
    /// The prefix of the labels.
    pub name: &'a str,
}

/// The motion of the point `local` of `body`, relative to the common ancestor: only the
/// joints in `moving` count (the recursion of eq. 9 along one path, in ground axes).
/// `project` is called with each joint's column as soon as it is known (so that a fixed
/// cam's projections are formed where the paper's were).
#[allow(clippy::too_many_arguments)]
pub(crate) fn point_motion(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
    body: Option<usize>,
    local: V3,
    moving: &[bool],
    labels: &Labels,
    mut project: impl FnMut(&mut Graph, usize, V3),
) -> PointMotion {
    let n = model.n();
    let qd = &s.qd;
    let path = path_to_root(model, body);
    let name = labels.name;
    // Angular velocity and the velocity-product part of the angular acceleration of every
    // body on the path, ground frame (from the ancestor out).
    let zero3 = vec3::zero(g);
    let (mut omega, mut alpha) = (vec![zero3; n], vec![zero3; n]);
    let (mut w, mut a) = (zero3, zero3);
    let mut coriolis = zero3;
    for &j in path.iter().rev().filter(|&&j| moving[j]) {
        let k = &kin[j];
        match model.bodies[j].joint.kind {
            JointKind::Revolute => {
                let rate = vec3::scale(g, qd[j], k.axis_ground);
                let w_e = vec3::cross(g, w, rate);
                a = vec3::add(g, a, w_e);
                w = vec3::add(g, w, rate);
            }
            JointKind::Prismatic => {
                // 2 ω × e q̇ of the sliding joint point, as (2 q̇ ω) × e: scalars first.
                let two = g.constant(2.0);
                let two_qd = g.mul(two, qd[j]);
                let tw = vec3::scale(g, two_qd, w);
                let cor = vec3::cross(g, tw, k.axis_ground);
                coriolis = vec3::add(g, coriolis, cor);
            }
        }
        let coordinate = &model.bodies[j].joint.coordinate;
        vec3::label(g, w, &format!("{name}_omega_{coordinate}"));
        vec3::label(g, a, &format!("{name}_alpha_{coordinate}"));
        omega[j] = w;
        alpha[j] = a;
    }
    vec3::label(g, coriolis, &format!("{name}_coriolis"));
    // From the tip down: p − o_j for the Jacobian columns, and the convective acceleration
    // α × s + ω × (ω × s) of each segment s. Across a prismatic joint the two bodies turn
    // together, so their segments are summed in the common frame before being rotated
    // (`pending`, in the frame of `body`): (l2 + q3 + l3) once instead of two segments.
    let mut pending = local;
    let mut done = zero3;
    let mut accel = coriolis;
    let mut columns = vec![None; n];
    let mut segments = Vec::new();
    for &j in &path {
        let k = &kin[j];
        let coordinate = &model.bodies[j].joint.coordinate;
        let column = match model.bodies[j].joint.kind {
            JointKind::Revolute => {
                let seg = k.rotation.apply(g, pending);
                segments.push(Segment {
                    rotation: k.rotation.clone(),
                    local: pending,
                    value: seg,
                });
                if moving[j] {
                    vec3::label(g, seg, &format!("{name}_segment_{coordinate}"));
                    let a_s = vec3::cross(g, alpha[j], seg);
                    vec3::label(g, a_s, &format!("{name}_tangential_{coordinate}"));
                    let w_w_s = vec3::omega_omega(g, omega[j], seg);
                    vec3::label(g, w_w_s, &format!("{name}_centripetal_{coordinate}"));
                    let w_s = vec3::dot(g, omega[j], seg);
                    g.label(w_s, format!("{name}_omega_dot_segment_{coordinate}"));
                    accel = vec3::add(g, accel, a_s);
                    accel = vec3::add(g, accel, w_w_s);
                }
                done = vec3::add(g, seg, done);
                pending = k.offset;
                moving[j].then(|| vec3::cross(g, k.axis_ground, done))
            }
            JointKind::Prismatic => {
                // No rotation at this joint: the segment continues in the same frame.
                pending = vec3::add(g, k.offset, pending);
                moving[j].then_some(k.axis_ground)
            }
        };
        if let Some(column) = column {
            vec3::label(g, done, &format!("{name}_arm_{coordinate}"));
            project(g, j, column);
            columns[j] = Some(column);
        }
    }
    // The root's segment is fixed in the ground.
    let (position, base, arm) = match path.last() {
        Some(_) => (vec3::add(g, pending, done), pending, done),
        None => (local, local, zero3),
    };
    PointMotion {
        position,
        base,
        arm,
        segments,
        columns,
        convective: accel,
        omega: w,
        alpha: a,
    }
}

/// The follower of `contact` (index `index`) seen from its cam: [`Relative`].
pub fn relative(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    s: &Symbols,
    index: usize,
) -> Relative {
    let contact: &Contact = &model.contacts[index];
    let name = &contact.name;
    let n = model.n();
    let marker = &model.markers[contact.marker];
    let follower_path = path_to_root(model, Some(marker.body));
    let cam_path = path_to_root(model, contact.cam_body);
    let on_follower_side: Vec<bool> = (0..n)
        .map(|j| follower_path.contains(&j) && !cam_path.contains(&j))
        .collect();
    let on_cam_side: Vec<bool> = (0..n)
        .map(|j| cam_path.contains(&j) && !follower_path.contains(&j))
        .collect();
    // The cam frame's axes in ground coordinates.
    let (x_local, y_local) = (
        vec3::constant(g, contact.x_axis),
        vec3::constant(g, contact.y_axis),
    );
    let axis_local = vec3::constant(g, contact.axis());
    let cam_rotation = contact.cam_body.map(|c| kin[c].rotation.clone());
    let [x_axis, y_axis, axis] = [x_local, y_local, axis_local].map(|v| match &cam_rotation {
        Some(r) => r.apply(g, v),
        None => v,
    });
    if contact.cam_body.is_some() {
        vec3::label(g, x_axis, &format!("{name}_cam_x_axis"));
        vec3::label(g, y_axis, &format!("{name}_cam_y_axis"));
    }
    let mut columns = vec![[g.zero(); 2]; n];
    let mut height_columns = vec![g.zero(); n];
    let marker_local = s.field3(
        g,
        model,
        |k| Field::Marker(contact.marker, k),
        marker.position,
    );
    // The follower point: the marker, or the centre of a circular outline placed the radius
    // away from it (a curved face, whose apex the marker is).
    let local = match contact.follower.centre_direction() {
        Some(direction) => {
            let radius = contact.follower.radius().copied().unwrap_or(0.0);
            let rho = s.field(g, model, Field::Radius(index), radius);
            let direction = vec3::constant(g, direction);
            let offset = vec3::scale(g, rho, direction);
            vec3::add(g, marker_local, offset)
        }
        None => marker_local,
    };
    let follower = point_motion(
        g,
        model,
        kin,
        s,
        Some(marker.body),
        local,
        &on_follower_side,
        &Labels { name },
        |g, j, column| {
            let coordinate = &model.bodies[j].joint.coordinate;
            let (j1, j2) = (vec3::dot(g, x_axis, column), vec3::dot(g, y_axis, column));
            g.label(j1, format!("{name}_j1_{coordinate}"));
            g.label(j2, format!("{name}_j2_{coordinate}"));
            columns[j] = [j1, j2];
            height_columns[j] = vec3::dot(g, axis, column);
        },
    );
    let origin_local = s.field3(g, model, |k| Field::Origin(index, k), contact.origin);
    let point = follower.position;
    let (origin, r, accel) = match contact.cam_body {
        None => {
            let r = vec3::sub(g, point, origin_local);
            let accel = if long_path(model, &follower_path) {
                body_frame_convective(g, &kin[marker.body], local)
            } else {
                follower.convective
            };
            (origin_local, r, accel)
        }
        Some(cam) => {
            let cam_name = format!("{name}_cam");
            let motion = point_motion(
                g,
                model,
                kin,
                s,
                Some(cam),
                origin_local,
                &on_cam_side,
                &Labels { name: &cam_name },
                |_, _, _| {},
            );
            let r = vec3::sub(g, point, motion.position);
            vec3::label(g, r, &format!("{name}_from_cam"));
            // Columns of the cam's joints: −u_j × (p − o_j) = −(u_j × (o_C − o_j) + u_j × r)
            // for a revolute joint, −u_j for a prismatic one.
            for j in (0..n).filter(|&j| on_cam_side[j]) {
                let Some(cam_column) = motion.columns[j] else {
                    continue;
                };
                let column = match model.bodies[j].joint.kind {
                    JointKind::Revolute => {
                        let u_r = vec3::cross(g, kin[j].axis_ground, r);
                        vec3::add(g, cam_column, u_r)
                    }
                    JointKind::Prismatic => cam_column,
                };
                let coordinate = &model.bodies[j].joint.coordinate;
                let (j1, j2) = (vec3::dot(g, x_axis, column), vec3::dot(g, y_axis, column));
                let (j1, j2) = (g.neg(j1), g.neg(j2));
                g.label(j1, format!("{name}_j1_{coordinate}"));
                g.label(j2, format!("{name}_j2_{coordinate}"));
                columns[j] = [j1, j2];
                let j3 = vec3::dot(g, axis, column);
                height_columns[j] = g.neg(j3);
            }
            // ṙ = Σ col_f q̇ − Σ col_c(o_C) q̇, then the moving frame's terms.
            let mut r_dot = vec3::zero(g);
            for j in 0..n {
                let column = if on_follower_side[j] {
                    follower.columns[j]
                } else if on_cam_side[j] {
                    motion.columns[j].map(|c| [0, 1, 2].map(|k| g.neg(c[k])))
                } else {
                    None
                };
                if let Some(c) = column {
                    let term = vec3::scale(g, s.qd[j], c);
                    r_dot = vec3::add(g, r_dot, term);
                }
            }
            vec3::label(g, r_dot, &format!("{name}_rate_from_cam"));
            let w = motion.omega;
            let mut accel = vec3::sub(g, follower.convective, motion.convective);
            let a_r = vec3::cross(g, motion.alpha, r);
            accel = vec3::sub(g, accel, a_r);
            let w_rdot = vec3::cross(g, w, r_dot);
            let two = g.constant(2.0);
            let coriolis = vec3::scale(g, two, w_rdot);
            accel = vec3::sub(g, accel, coriolis);
            let w_w_r = vec3::omega_omega(g, w, r);
            accel = vec3::add(g, accel, w_w_r);
            (motion.position, r, accel)
        }
    };
    let xy = [vec3::dot(g, x_axis, r), vec3::dot(g, y_axis, r)];
    let height = vec3::dot(g, axis, r);
    let height_convective = vec3::dot(g, axis, accel);
    let height_rate = dot_list(g, &height_columns, &s.qd);
    let convective = [vec3::dot(g, x_axis, accel), vec3::dot(g, y_axis, accel)];
    let j1: Vec<Id> = columns.iter().map(|c| c[0]).collect();
    let j2: Vec<Id> = columns.iter().map(|c| c[1]).collect();
    let velocity = [dot_list(g, &j1, &s.qd), dot_list(g, &j2, &s.qd)];
    g.label(xy[0], format!("{name}_x"));
    g.label(xy[1], format!("{name}_y"));
    g.label(velocity[0], format!("{name}_x_rate"));
    vec3::label(g, point, &format!("{name}_pos"));
    vec3::label(g, accel, &format!("{name}_convective"));
    g.label(convective[0], format!("{name}_conv1"));
    g.label(convective[1], format!("{name}_conv2"));
    // The relative spin about the cam's axis.
    let spin_columns: Vec<Id> = (0..n)
        .map(|j| {
            let sign = if on_follower_side[j] {
                1.0
            } else if on_cam_side[j] {
                -1.0
            } else {
                return g.zero();
            };
            match model.bodies[j].joint.kind {
                JointKind::Revolute => {
                    let d = vec3::dot(g, axis, kin[j].axis_ground);
                    g.scale(sign, d)
                }
                JointKind::Prismatic => g.zero(),
            }
        })
        .collect();
    let spin = dot_list(g, &spin_columns, &s.qd);
    let direction = own_joint_direction(g, model, kin, marker.body, point);
    Relative {
        point,
        xy,
        columns,
        convective,
        velocity,
        origin,
        x_axis,
        y_axis,
        axis,
        height,
        height_columns,
        height_convective,
        height_rate,
        spin_columns,
        spin,
        direction,
        follower_body: marker.body,
    }
}

/// Revolute joints on a follower's path from the ground from which the point's convective
/// acceleration is taken from its body's kinematics ([`body_frame_convective`], a fixed ~45
/// operations) instead of summed segment by segment in ground axes (~48 operations per
/// revolute joint). Short paths, those of every built-in model, keep the segment sums, the
/// paper's form (eq. 9 along the path), whose operation counts docs/method.md compares with
/// the hand-derived formulas.
const LONG_PATH: usize = 6;

/// Whether a path has at least [`LONG_PATH`] revolute joints.
fn long_path(model: &Model, path: &[usize]) -> bool {
    let revolute = path
        .iter()
        .filter(|&&j| model.bodies[j].joint.kind == JointKind::Revolute)
        .count();
    revolute >= LONG_PATH
}

/// The velocity-product part of the acceleration of the point `local` of a body (q̈ = 0),
/// ground axes, from the body's own kinematics: R (a⁰ + α⁰ × p + ω × (ω × p)), a⁰ and α⁰
/// those of the forward recursion, which the dynamics already needs.
fn body_frame_convective(g: &mut Graph, k: &BodyKinematics, local: V3) -> V3 {
    let tangential = vec3::cross(g, k.alpha, local);
    let centripetal = vec3::omega_omega(g, k.omega, local);
    let rest = vec3::add(g, tangential, centripetal);
    let own = vec3::add(g, k.accel, rest);
    k.rotation.apply(g, own)
}

/// The column of the follower body's own joint at `point` (ground): u × (p − o) for a
/// revolute joint, u for a prismatic one.
fn own_joint_direction(
    g: &mut Graph,
    model: &Model,
    kin: &[BodyKinematics],
    body: usize,
    point: V3,
) -> V3 {
    let k = &kin[body];
    match model.bodies[body].joint.kind {
        JointKind::Revolute => {
            let arm = vec3::sub(g, point, k.origin);
            vec3::cross(g, k.axis_ground, arm)
        }
        JointKind::Prismatic => k.axis_ground,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Derivation;
    use crate::kinematics::forward;

    /// Two routes to the tip's convective acceleration of the 16-body random chain (12
    /// revolute joints on its path): from the tip body's own kinematics, as long paths now
    /// take it, and summed segment by segment in ground axes, the paper's form. At random
    /// states (joint rates up to 2 rad/s or m/s, so accelerations up to ~10² m/s²) they agree
    /// to 1e-12 of the largest magnitude: both are exact, and the differences are the
    /// rounding of sums over 16 bodies.
    #[test]
    fn a_long_paths_convective_acceleration_equals_the_segment_sums() {
        let file = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/random_models/chain16.ron"
        );
        let text = std::fs::read_to_string(file).expect("reads the model");
        let model = crate::schema::parse_model(&text, std::path::Path::new(file)).expect("parses");
        let mut d = Derivation::new(&model);
        let g = &mut d.graph;
        let kin = forward(g, &model, &d.symbols);
        let marker = &model.markers[0];
        assert!(long_path(&model, &path_to_root(&model, Some(marker.body))));
        let local = vec3::constant(g, marker.position);
        let moving = vec![true; model.n()];
        let labels = Labels { name: "check" };
        let sums = point_motion(
            g,
            &model,
            &kin,
            &d.symbols,
            Some(marker.body),
            local,
            &moving,
            &labels,
            |_, _, _| {},
        )
        .convective;
        let own = body_frame_convective(g, &kin[marker.body], local);
        let roots: Vec<Id> = sums.iter().chain(&own).copied().collect();
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..20 {
            let q: Vec<f64> = (0..model.n()).map(|_| next()).collect();
            let qd: Vec<f64> = (0..model.n()).map(|_| 2.0 * next()).collect();
            let v = d.eval(&roots, 0.0, &q, &qd);
            let scale = v.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
            for k in 0..3 {
                assert!(
                    (v[k] - v[k + 3]).abs() <= 1e-12 * scale,
                    "component {k}: {} against {} (scale {scale})",
                    v[k],
                    v[k + 3]
                );
            }
        }
    }
}
