//! Positions of the body frames and markers (forward kinematics), for drawing the mechanism.
//!
//! The `Dynamics` contract reports only the contact points, so the snapshots are drawn from
//! the validated model description: at q = 0 a body's frame is its parent's frame moved to
//! the joint's `anchor`; a revolute joint then turns it by q about `axis`, a prismatic joint
//! moves it by q·`axis` (both in the parent's frame); a marker sits at its `position` in its
//! body's frame. Everything is projected on the plane of the first cam (the ground x–y
//! plane when there is no cam), where the profile y = f(x) is drawn.

use camchain_codegen::model::{JointKind, Model, Profile};
use camchain_codegen::profile::Scalar;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

type Vec3 = Vector3<f64>;

/// One joint of the tree, in its parent's frame.
#[derive(Debug, Clone)]
struct JointFrame {
    parent: Option<usize>,
    kind: JointKind,
    axis: Unit<Vec3>,
    anchor: Vec3,
    /// The body's centre of mass in its frame.
    com: Vec3,
}

/// A plane with an origin and two orthonormal in-plane axes (a cam's frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    origin: Vec3,
    x_axis: Vec3,
    y_axis: Vec3,
}

impl Plane {
    /// The ground x–y plane.
    fn ground() -> Self {
        Plane {
            origin: Vec3::zeros(),
            x_axis: Vec3::x(),
            y_axis: Vec3::y(),
        }
    }

    /// True for the ground x–y plane (the cam coordinates are ground coordinates).
    pub fn is_ground(&self) -> bool {
        *self == Plane::ground()
    }

    /// In-plane coordinates of a ground point.
    pub fn project(&self, p: &[f64; 3]) -> (f64, f64) {
        let d = Vec3::from(*p) - self.origin;
        (self.x_axis.dot(&d), self.y_axis.dot(&d))
    }
}

/// Everything needed to draw a model: its joint tree, markers, drawing plane and cam.
#[derive(Debug, Clone)]
pub struct Geometry {
    joints: Vec<JointFrame>,
    /// (body, position in the body frame) of every marker.
    markers: Vec<(usize, Vec3)>,
    /// Body names, in coordinate order.
    pub body_names: Vec<String>,
    /// The drawing plane: the first cam's, or the ground x–y plane.
    pub plane: Plane,
    /// The first cam's profile y = f(x) in its plane, with its source text.
    pub profile: Option<(Scalar, String)>,
}

/// The drawable state of the mechanism at one instant, in ground coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Origin of every body frame (on its joint).
    pub origins: Vec<[f64; 3]>,
    /// Every marker.
    pub markers: Vec<[f64; 3]>,
    /// The centre of mass of every body.
    pub coms: Vec<[f64; 3]>,
}

impl Geometry {
    /// The geometry of a validated model, or why it cannot be drawn.
    pub fn new(model: &Model) -> Result<Self, String> {
        let joints = model
            .bodies
            .iter()
            .map(|b| JointFrame {
                parent: b.parent,
                kind: b.joint.kind,
                axis: Unit::new_normalize(Vec3::from(b.joint.axis)),
                anchor: Vec3::from(b.joint.anchor),
                com: Vec3::from(b.com),
            })
            .collect();
        let markers = model
            .markers
            .iter()
            .map(|m| (m.body, Vec3::from(m.position)))
            .collect();
        let (plane, profile) = match model.contacts.first() {
            Some(c) => (
                Plane {
                    origin: Vec3::from(c.origin),
                    x_axis: Vec3::from(c.x_axis),
                    y_axis: Vec3::from(c.y_axis),
                },
                match &c.profile {
                    Profile::Explicit { f, source } => Some((f.clone(), source.clone())),
                    _ => None,
                },
            ),
            None => (Plane::ground(), None),
        };
        let geometry = Geometry {
            joints,
            markers,
            body_names: model.bodies.iter().map(|b| b.name.clone()).collect(),
            plane,
            profile,
        };
        if geometry.consistent() {
            Ok(geometry)
        } else {
            Err("the model's body or marker indices are out of order".into())
        }
    }

    /// Parents listed before children and markers on existing bodies (validation ensures
    /// both; checked so that `pose` cannot index out of range).
    fn consistent(&self) -> bool {
        let parents = self
            .joints
            .iter()
            .enumerate()
            .all(|(i, j)| j.parent.is_none_or(|p| p < i));
        parents && self.markers.iter().all(|(b, _)| *b < self.joints.len())
    }

    /// Number of coordinates (= bodies).
    pub fn n(&self) -> usize {
        self.joints.len()
    }

    /// Parent of body `i` (`None` for the ground).
    pub fn parent(&self, i: usize) -> Option<usize> {
        self.joints.get(i).and_then(|j| j.parent)
    }

    /// True when body `i` has neither children nor markers: only its centre of mass shows
    /// where it extends.
    pub fn is_bare_leaf(&self, i: usize) -> bool {
        !self.joints.iter().any(|j| j.parent == Some(i))
            && !self.markers.iter().any(|(b, _)| *b == i)
    }

    /// Body carrying marker `k`.
    pub fn marker_body(&self, k: usize) -> Option<usize> {
        self.markers.get(k).map(|(b, _)| *b)
    }

    /// Body origins and marker positions at `q` (length [`Geometry::n`]).
    pub fn pose(&self, q: &[f64]) -> Pose {
        let mut rotations: Vec<Matrix3<f64>> = Vec::with_capacity(self.joints.len());
        let mut origins: Vec<Vec3> = Vec::with_capacity(self.joints.len());
        for (i, joint) in self.joints.iter().enumerate() {
            let (parent_rot, parent_origin) = match joint.parent {
                Some(p) => (rotations[p], origins[p]),
                None => (Matrix3::identity(), Vec3::zeros()),
            };
            let qi = q.get(i).copied().unwrap_or(0.0);
            let (rot, offset) = match joint.kind {
                JointKind::Revolute => (
                    parent_rot * Rotation3::from_axis_angle(&joint.axis, qi).into_inner(),
                    joint.anchor,
                ),
                JointKind::Prismatic => (parent_rot, joint.anchor + joint.axis.into_inner() * qi),
            };
            rotations.push(rot);
            origins.push(parent_origin + parent_rot * offset);
        }
        let markers = self
            .markers
            .iter()
            .map(|(b, p)| (origins[*b] + rotations[*b] * p).into())
            .collect();
        let coms = self
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| (origins[i] + rotations[i] * j.com).into())
            .collect();
        Pose {
            origins: origins.into_iter().map(Into::into).collect(),
            markers,
            coms,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::builtin_description;
    use camchain_models as models;
    use camchain_runtime::ContactGeometry;

    #[test]
    fn markers_are_where_the_generated_code_puts_the_contacts() {
        // Both compute the same chain of rotations and translations in a different order;
        // round-off of a few ulps of lengths ~1 m: 1e-12 m.
        for (name, model) in models::ALL.iter() {
            let geometry = Geometry::new(&builtin_description(name).unwrap()).unwrap();
            let info = model.info();
            let q: Vec<f64> = (0..info.n()).map(|i| 0.3 - 0.17 * i as f64).collect();
            let mut contacts = vec![ContactGeometry::default(); info.n_contacts()];
            model.contact_geometry(&q, &vec![0.0; q.len()], &mut contacts);
            let pose = geometry.pose(&q);
            for (k, c) in contacts.iter().enumerate() {
                for axis in 0..3 {
                    let difference = (pose.markers[k][axis] - c.follower[axis]).abs();
                    assert!(difference < 1e-12, "{name}: contact {k}, axis {axis}");
                }
            }
        }
    }

    #[test]
    fn the_paper_chain_in_closed_form() {
        let model = builtin_description("paper_concave").unwrap();
        let geometry = Geometry::new(&model).unwrap();
        assert!(geometry.plane.is_ground());
        let q = [-1.4, 0.2, 0.05, -0.3];
        let pose = geometry.pose(&q);
        let (a1, a12) = (q[0], q[0] + q[1]);
        let expected_3 = [
            0.38 + 0.3 * a1.cos() + (0.1 + q[2]) * a12.cos(),
            0.80 + 0.3 * a1.sin() + (0.1 + q[2]) * a12.sin(),
            0.0,
        ];
        for (got, want) in pose.origins[2].iter().zip(expected_3) {
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
        }
        assert_eq!(pose.origins[0], [0.38, 0.80, 0.0]);
    }
}
