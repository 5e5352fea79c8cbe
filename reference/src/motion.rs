//! The kinematics the recursions share: a body's pose and motion in ground coordinates,
//! and the vector types they are written in. The Newton–Euler recursion (`numeric`)
//! computes them body by body; the cam contacts and the loops read them.

use nalgebra::{Matrix3, Vector3};

/// A vector in ground or body coordinates.
pub(crate) type Vec3 = Vector3<f64>;
/// A 3×3 matrix (rotations, inertia tensors).
pub(crate) type Mat3 = Matrix3<f64>;

/// A vector from a model file's `[x, y, z]`.
pub(crate) fn vec3(a: &[f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Position and orientation of a body, in ground coordinates.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pose {
    /// Rotation ground ← body.
    pub(crate) rot: Mat3,
    /// Origin of the body frame (on the joint axis of a revolute joint).
    pub(crate) origin: Vec3,
    /// Joint axis.
    pub(crate) axis: Vec3,
    /// Vector from the parent's origin to this body's origin.
    pub(crate) lever: Vec3,
    /// Vector from the body origin to its centre of mass.
    pub(crate) com_offset: Vec3,
    /// Inertia about the centre of mass, ground axes: R I Rᵀ.
    pub(crate) inertia: Mat3,
}

impl Pose {
    /// The ground frame: identity rotation at the origin.
    pub(crate) fn ground() -> Self {
        Self {
            rot: Mat3::identity(),
            origin: Vec3::zeros(),
            axis: Vec3::zeros(),
            lever: Vec3::zeros(),
            com_offset: Vec3::zeros(),
            inertia: Mat3::zeros(),
        }
    }
}

/// Velocity state of a body: angular velocity and acceleration, velocity and acceleration
/// of the body origin, all in ground coordinates.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Motion {
    pub(crate) omega: Vec3,
    pub(crate) alpha: Vec3,
    pub(crate) vel: Vec3,
    pub(crate) acc: Vec3,
}

impl Motion {
    /// The ground is at rest.
    pub(crate) fn rest() -> Self {
        Self {
            omega: Vec3::zeros(),
            alpha: Vec3::zeros(),
            vel: Vec3::zeros(),
            acc: Vec3::zeros(),
        }
    }

    /// Velocity of the body point at offset `r` from the origin.
    pub(crate) fn point_velocity(&self, r: &Vec3) -> Vec3 {
        self.vel + self.omega.cross(r)
    }

    /// Acceleration of the body point at offset `r` from the origin.
    pub(crate) fn point_acceleration(&self, r: &Vec3) -> Vec3 {
        self.acc + self.alpha.cross(r) + self.omega.cross(&self.omega.cross(r))
    }
}
