//! Positions of the body frames and markers (forward kinematics), for drawing the mechanism.
//!
//! The `Dynamics` contract reports only the contact points, so the snapshots are drawn from
//! the validated model description: at q = 0 a body's frame is its parent's frame moved to
//! the joint's `anchor`; a revolute joint then turns it by q about `axis`, a prismatic joint
//! moves it by q·`axis` (both in the parent's frame); a marker sits at its `position` in its
//! body's frame. Everything is projected on the plane of the first cam as it lies at q = 0
//! (the ground x–y plane when there is no cam). Each cam is drawn where its body carries it:
//! a profile fixed to the ground as y = f(x) across the picture, a disc cam (polar profile)
//! as its closed outline with its base circle, a parametric one along its `range`; rollers
//! as circles and flat faces as segments on their followers.

use camchain_codegen::model::{Contact, Follower, JointKind, Model, Profile};
use camchain_codegen::profile::Scalar;
use camchain_runtime::kinds::Outline as FollowerOutline;
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

/// A plane with an origin and two orthonormal in-plane axes (a cam's frame), and what its
/// axes are called on a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    origin: Vec3,
    x_axis: Vec3,
    y_axis: Vec3,
    /// The axes' labels ([`Plane::axis_labels`]).
    labels: (&'static str, &'static str),
}

impl Plane {
    /// The ground x–y plane.
    fn ground() -> Self {
        Plane {
            origin: Vec3::zeros(),
            x_axis: Vec3::x(),
            y_axis: Vec3::y(),
            labels: ("x [m]", "y [m]"),
        }
    }

    /// True for the ground x–y plane (the cam coordinates are ground coordinates).
    pub fn is_ground(&self) -> bool {
        let ground = Plane::ground();
        (self.origin, self.x_axis, self.y_axis) == (ground.origin, ground.x_axis, ground.y_axis)
    }

    /// The axes' labels on a figure: ground ones for the ground x–y plane.
    pub fn axis_labels(&self) -> (&'static str, &'static str) {
        if self.is_ground() {
            Plane::ground().labels
        } else {
            self.labels
        }
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
    /// (body, position in the body frame) of every marker, then of every loop's cut point
    /// on a body (drawn as a link from the body's joint and a pin).
    markers: Vec<(usize, Vec3)>,
    /// Index in `markers` of the first loop point.
    pub loop_points_from: usize,
    /// Body names, in coordinate order.
    pub body_names: Vec<String>,
    /// The drawing plane: the first cam's, or the ground x–y plane.
    pub plane: Plane,
    /// The first cam's profile y = f(x) in its plane, with its source text, when that cam is
    /// fixed to the ground (drawn once across the picture).
    pub profile: Option<(Scalar, String)>,
    /// Every contact's cam and follower shape, in contact order.
    cams: Vec<CamShape>,
    /// Every contact's cam surface (`None` for a plane profile), in contact order: what the
    /// figure of its contact path draws (`figures::surface`).
    pub surfaces: Vec<Option<SurfaceShape>>,
}

/// A contact's cam surface with every parameter at its value, for the figure of the contact
/// path over it.
#[derive(Debug, Clone)]
pub enum SurfaceShape {
    /// z = f(x, y) of the cam frame.
    Graph(Scalar),
    /// A barrel cam's pitch surface z = g(θ) on the radius R; the roller's radius ρ (0 for a
    /// knife edge).
    Barrel {
        /// g(θ).
        g: Scalar,
        /// R (m).
        radius: f64,
        /// ρ (m).
        roller: f64,
    },
    /// A surface of revolution r = g(z).
    Revolution(Scalar),
}

impl SurfaceShape {
    fn of(contact: &Contact, values: &[f64]) -> Option<Self> {
        match &contact.profile {
            Profile::Surface { f, .. } => Some(SurfaceShape::Graph(f.resolve_all(values))),
            Profile::Barrel { f, radius, .. } => Some(SurfaceShape::Barrel {
                g: f.resolve_all(values),
                radius: *radius,
                roller: contact.follower.radius().copied().unwrap_or(0.0),
            }),
            Profile::Revolution { g, .. } => Some(SurfaceShape::Revolution(g.resolve_all(values))),
            Profile::Explicit { .. }
            | Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Face { .. } => None,
        }
    }
}

/// Points of a drawn closed profile, or of an open one along its range.
const OUTLINE_POINTS: usize = 720;

/// A contact's cam profile and follower shape, for drawing.
#[derive(Debug, Clone)]
struct CamShape {
    /// The body carrying the cam (`None`: the ground).
    body: Option<usize>,
    /// The cam frame in that body's frame: origin, x axis, y axis.
    origin: Vec3,
    x_axis: Vec3,
    y_axis: Vec3,
    outline: Outline,
    /// The base circle's radius (a polar profile's least radius), about the frame's origin.
    base_radius: Option<f64>,
    /// The follower's kind and dimensions (its outline is drawn).
    follower: Follower,
    /// The marker: the knife edge, the roller's centre, a point of the flat face.
    marker: usize,
    /// The follower's body.
    follower_body: usize,
    /// Half the drawn length of a flat face (m).
    face_half_length: f64,
}

/// A profile as drawn, in its cam frame.
#[derive(Debug, Clone)]
enum Outline {
    /// y = f(x): sampled over the range the follower visits when drawn.
    Explicit(Scalar),
    /// A closed curve (a disc cam): its material inside.
    Closed(Vec<(f64, f64)>),
    /// An open curve along its range.
    Open(Vec<(f64, f64)>),
    /// A face cam's groove: its inner flank (closed, the material inside it drawn as a disc
    /// cam's) and its outer flank.
    Groove {
        inner: Vec<(f64, f64)>,
        outer: Vec<(f64, f64)>,
    },
}

/// One contact's drawing at one instant, in plane coordinates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CamPicture {
    /// The profile (closed: a polygon filled as the cam's material).
    pub outline: Vec<(f64, f64)>,
    /// True for a closed outline, whose inside is the cam.
    pub closed: bool,
    /// For an explicit profile on a moving body: a band of the cam's material below the
    /// curve, as a polygon.
    pub material: Vec<(f64, f64)>,
    /// The base circle, when the profile is polar.
    pub base_circle: Vec<(f64, f64)>,
    /// The cam frame's origin (the centre of a disc cam).
    pub centre: (f64, f64),
    /// The roller's rim.
    pub roller: Vec<(f64, f64)>,
    /// The flat face.
    pub face: Vec<(f64, f64)>,
    /// A face cam groove's outer flank (its inner flank is `outline`).
    pub outer_flank: Vec<(f64, f64)>,
}

/// A circle of `radius` about `centre` in the plane spanned by `u`, `v`, as ground points.
fn circle(centre: Vec3, u: Vec3, v: Vec3, radius: f64, points: usize) -> Vec<Vec3> {
    (0..=points)
        .map(|i| std::f64::consts::TAU * i as f64 / points as f64)
        .map(|a| centre + radius * (a.cos() * u + a.sin() * v))
        .collect()
}

impl CamShape {
    fn new(model: &Model, contact: &Contact, values: &[f64]) -> Self {
        let (outline, base_radius) = match &contact.profile {
            Profile::Explicit { f, .. } => (Outline::Explicit(f.resolve_all(values)), None),
            // A surface has no outline in a plane: the picture shows the follower on it.
            Profile::Surface { .. } | Profile::Barrel { .. } | Profile::Revolution { .. } => {
                (Outline::Open(Vec::new()), None)
            }
            Profile::Polar { r, .. } => {
                let r = r.resolve_all(values);
                let points: Vec<(f64, f64)> = (0..OUTLINE_POINTS)
                    .map(|i| std::f64::consts::TAU * i as f64 / OUTLINE_POINTS as f64)
                    .map(|t| (r.eval(t) * t.cos(), r.eval(t) * t.sin()))
                    .collect();
                let least = points
                    .iter()
                    .map(|(x, y)| x.hypot(*y))
                    .fold(f64::INFINITY, f64::min);
                (Outline::Closed(points), least.is_finite().then_some(least))
            }
            Profile::Face { centre } => {
                let rho = contact.follower.radius().copied().unwrap_or(0.0);
                let centre = centre.resolve_all(values);
                let side = camchain_codegen::samples::follower_side(&centre);
                // The flanks ρ either side of the centre line, along its normal n.
                let flank = |offset: f64| -> Vec<(f64, f64)> {
                    (0..OUTLINE_POINTS)
                        .map(|i| std::f64::consts::TAU * i as f64 / OUTLINE_POINTS as f64)
                        .map(|t| {
                            let [c, d1, _] = camchain_codegen::samples::curve(&centre, t);
                            let speed = d1[0].hypot(d1[1]);
                            let n = [-side * d1[1] / speed, side * d1[0] / speed];
                            (c[0] + offset * n[0], c[1] + offset * n[1])
                        })
                        .collect()
                };
                let inner = flank(-rho);
                let least = inner
                    .iter()
                    .map(|(x, y)| x.hypot(*y))
                    .fold(f64::INFINITY, f64::min);
                let outer = flank(rho);
                (
                    Outline::Groove { inner, outer },
                    least.is_finite().then_some(least),
                )
            }
            Profile::Parametric { x, y, .. } => {
                let (x, y) = (x.resolve_all(values), y.resolve_all(values));
                let (a, b) = contact.range.unwrap_or((0.0, 1.0));
                let points: Vec<(f64, f64)> = (0..=OUTLINE_POINTS)
                    .map(|i| a + (b - a) * i as f64 / OUTLINE_POINTS as f64)
                    .map(|s| (x.eval(s), y.eval(s)))
                    .collect();
                let (first, last) = (points[0], points[OUTLINE_POINTS]);
                let size = points.iter().map(|(x, y)| x.hypot(*y)).fold(0.0, f64::max);
                if (first.0 - last.0).hypot(first.1 - last.1) <= 1e-9 * size.max(1e-3) {
                    (Outline::Closed(points), None)
                } else {
                    (Outline::Open(points), None)
                }
            }
        };
        let size = match &outline {
            Outline::Closed(p) | Outline::Open(p) | Outline::Groove { outer: p, .. } => {
                p.iter().map(|(x, y)| x.hypot(*y)).fold(0.0, f64::max)
            }
            Outline::Explicit(_) => 0.05,
        };
        let follower = contact.follower;
        CamShape {
            body: contact.cam_body,
            origin: Vec3::from(contact.origin),
            x_axis: Vec3::from(contact.x_axis),
            y_axis: Vec3::from(contact.y_axis),
            outline,
            base_radius,
            follower,
            marker: contact.marker,
            follower_body: model.markers.get(contact.marker).map_or(0, |m| m.body),
            face_half_length: 0.8 * size,
        }
    }
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
        let mut markers: Vec<(usize, Vec3)> = model
            .markers
            .iter()
            .map(|m| (m.body, Vec3::from(m.position)))
            .collect();
        let loop_points_from = markers.len();
        markers.extend(model.loops.iter().flat_map(|l| {
            l.sides
                .iter()
                .filter_map(|side| side.body.map(|b| (b, Vec3::from(side.point))))
        }));
        let values: Vec<f64> = model.parameters.iter().map(|p| p.value).collect();
        let cams = model
            .contacts
            .iter()
            .map(|c| CamShape::new(model, c, &values))
            .collect();
        let surfaces = model
            .contacts
            .iter()
            .map(|c| SurfaceShape::of(c, &values))
            .collect();
        let profile = model.contacts.first().and_then(|c| match &c.profile {
            Profile::Explicit { f, source } if c.cam_body.is_none() => {
                Some((f.resolve_all(&values), source.clone()))
            }
            _ => None,
        });
        let mut geometry = Geometry {
            joints,
            markers,
            loop_points_from,
            body_names: model.bodies.iter().map(|b| b.name.clone()).collect(),
            plane: Plane::ground(),
            profile,
            cams,
            surfaces,
        };
        if !geometry.consistent() {
            return Err("the model's body or marker indices are out of order".into());
        }
        if let Some(cam) = geometry.cams.first() {
            // The first cam's plane where its body puts it at q = 0.
            let (rotations, origins) = geometry.transforms(&vec![0.0; geometry.n()]);
            let (rotation, offset) = cam.body.map_or((Matrix3::identity(), Vec3::zeros()), |b| {
                (rotations[b], origins[b])
            });
            let plane = Plane {
                origin: offset + rotation * cam.origin,
                x_axis: rotation * cam.x_axis,
                y_axis: rotation * cam.y_axis,
                labels: ("x in the cam plane [m]", "y in the cam plane [m]"),
            };
            // A cam turning in the ground's x–y plane is drawn in ground coordinates (y up),
            // whatever way its own frame is turned.
            let normal = plane.x_axis.cross(&plane.y_axis);
            if (normal.z.abs() - 1.0).abs() > 1e-12 || cam.body.is_none() {
                geometry.plane = plane;
            }
        }
        Ok(geometry)
    }

    /// For a model with a cam surface, the same geometry seen from the side: projected on the
    /// plane of the drawing plane's x axis and its normal (the cam's axis), the second
    /// orthogonal projection of a spatial mechanism. `None` for plane cams.
    pub fn side_view(&self) -> Option<Geometry> {
        if self.surfaces.iter().all(Option::is_none) {
            return None;
        }
        let mut side = self.clone();
        side.plane = Plane {
            origin: self.plane.origin,
            x_axis: self.plane.x_axis,
            y_axis: self.plane.x_axis.cross(&self.plane.y_axis),
            labels: ("x in the cam plane [m]", "along the cam's axis [m]"),
        };
        Some(side)
    }

    /// The body (= coordinate) carrying contact `k`'s follower point.
    pub fn follower_body(&self, k: usize) -> Option<usize> {
        self.cams.get(k).map(|c| c.follower_body)
    }

    /// True when some cam is carried by a body that moves.
    pub fn has_moving_cam(&self) -> bool {
        self.cams.iter().any(|c| c.body.is_some())
    }

    /// The drawing of contact `k`'s cam and follower at `q`, in plane coordinates; an
    /// explicit profile on a moving body is drawn over `x_range` of its frame. `None` for a
    /// cam fixed to the ground with an explicit profile (drawn once, from `profile`).
    pub fn cam_picture(&self, q: &[f64], k: usize, x_range: (f64, f64)) -> Option<CamPicture> {
        let cam = self.cams.get(k)?;
        let (rotations, origins) = self.transforms(q);
        let frames = (rotations.as_slice(), origins.as_slice());
        if cam.body.is_none() && matches!(cam.outline, Outline::Explicit(_)) {
            return self
                .follower_picture(frames, cam)
                .map(|(roller, face)| CamPicture {
                    roller,
                    face,
                    centre: (f64::NAN, f64::NAN),
                    ..CamPicture::default()
                });
        }
        let (rotation, offset) = cam.body.map_or((Matrix3::identity(), Vec3::zeros()), |b| {
            (rotations[b], origins[b])
        });
        let origin = offset + rotation * cam.origin;
        let (u, v) = (rotation * cam.x_axis, rotation * cam.y_axis);
        let to_plane = |(x, y): (f64, f64)| {
            let p: [f64; 3] = (origin + x * u + y * v).into();
            self.plane.project(&p)
        };
        let mut picture = CamPicture {
            centre: to_plane((0.0, 0.0)),
            ..CamPicture::default()
        };
        match &cam.outline {
            Outline::Explicit(f) => {
                let (x0, x1) = x_range;
                let curve: Vec<(f64, f64)> = (0..=OUTLINE_POINTS)
                    .map(|i| x0 + (x1 - x0) * i as f64 / OUTLINE_POINTS as f64)
                    .map(|x| (x, f.eval(x)))
                    .filter(|(_, y)| y.is_finite())
                    .collect();
                let depth = 0.25 * (x1 - x0);
                let floor = curve.iter().map(|p| p.1).fold(f64::INFINITY, f64::min) - depth;
                let mut band = curve.clone();
                band.extend([(x1, floor), (x0, floor)]);
                picture.outline = curve.into_iter().map(to_plane).collect();
                picture.material = band.into_iter().map(to_plane).collect();
            }
            Outline::Closed(points) | Outline::Open(points) => {
                picture.closed = matches!(cam.outline, Outline::Closed(_));
                picture.outline = points.iter().copied().map(to_plane).collect();
            }
            Outline::Groove { inner, outer } => {
                picture.closed = true;
                picture.outline = inner.iter().copied().map(to_plane).collect();
                picture.outer_flank = outer.iter().copied().map(to_plane).collect();
            }
        }
        if let Some(r) = cam.base_radius {
            picture.base_circle = circle(origin, u, v, r, 180)
                .iter()
                .map(|p| self.plane.project(&(*p).into()))
                .collect();
        }
        if let Some((roller, face)) = self.follower_picture(frames, cam) {
            (picture.roller, picture.face) = (roller, face);
        }
        Some(picture)
    }

    /// The roller's rim or the flat face of a contact's follower where the body frames
    /// ([`Geometry::transforms`]) put it, plane coordinates.
    #[allow(clippy::type_complexity)]
    fn follower_picture(
        &self,
        (rotations, origins): (&[Matrix3<f64>], &[Vec3]),
        cam: &CamShape,
    ) -> Option<(Vec<(f64, f64)>, Vec<(f64, f64)>)> {
        let (body, position) = self.markers.get(cam.marker)?;
        let rotation = rotations.get(*body)?;
        let marker = origins[*body] + rotation * position;
        let radius = cam.follower.radius().copied().unwrap_or(0.0);
        // A circular outline's centre: the marker, or the radius away from it.
        let centre = match cam.follower.centre_direction() {
            Some(direction) => marker + rotation * Vec3::from(direction) * radius,
            None => marker,
        };
        let (u, v) = (self.plane.x_axis, self.plane.y_axis);
        let project = |p: Vec3| self.plane.project(&p.into());
        let normal = cam
            .follower
            .normal()
            .map_or(Vec3::zeros(), |n| Vec3::from(*n));
        Some(match cam.follower.kind().outline() {
            FollowerOutline::Point => (Vec::new(), Vec::new()),
            FollowerOutline::Circle => (
                circle(centre, u, v, radius, 90)
                    .into_iter()
                    .map(project)
                    .collect(),
                Vec::new(),
            ),
            FollowerOutline::Line => {
                let n = rotations[cam.follower_body] * normal;
                let along = self.plane_axis().cross(&n);
                let half = cam.face_half_length * along;
                (
                    Vec::new(),
                    vec![project(centre - half), project(centre + half)],
                )
            }
        })
    }

    /// The drawing plane's normal.
    fn plane_axis(&self) -> Vec3 {
        self.plane.x_axis.cross(&self.plane.y_axis)
    }

    /// The rotation and origin of every body frame at `q`, ground coordinates.
    fn transforms(&self, q: &[f64]) -> (Vec<Matrix3<f64>>, Vec<Vec3>) {
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
        (rotations, origins)
    }

    /// Parents listed before children and markers on existing bodies (validation ensures
    /// both; checked so that `pose` cannot index out of range).
    fn consistent(&self) -> bool {
        let parents = self
            .joints
            .iter()
            .enumerate()
            .all(|(i, j)| j.parent.is_none_or(|p| p < i));
        let n = self.joints.len();
        let cams = self.cams.iter().all(|c| {
            c.body.is_none_or(|b| b < n) && c.follower_body < n && c.marker < self.markers.len()
        });
        parents && cams && self.markers.iter().all(|(b, _)| *b < n)
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
        let (rotations, origins) = self.transforms(q);
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
    use camchain_runtime::{ContactGeometry, Simulate};

    #[test]
    fn markers_are_where_the_generated_code_puts_the_contacts() {
        // Both compute the same chain of rotations and translations in a different order;
        // round-off of a few ulps of lengths ~1 m: 1e-12 m.
        // A circle centred off its marker (a curved face) has its centre as the follower
        // point: the radius away from the marker.
        for (name, model) in models::ALL.iter() {
            let description = builtin_description(name).unwrap();
            let geometry = Geometry::new(&description).unwrap();
            let info = model.info();
            let q: Vec<f64> = (0..info.n()).map(|i| 0.3 - 0.17 * i as f64).collect();
            let mut contacts = vec![ContactGeometry::default(); info.n_contacts()];
            model.contact_geometry(&q, &vec![0.0; q.len()], &mut contacts);
            let pose = geometry.pose(&q);
            for (k, c) in contacts.iter().enumerate() {
                let follower = &description.contacts[k].follower;
                if follower.centre_direction().is_some() {
                    let radius = follower.radius().copied().unwrap_or(0.0);
                    let apart = (0..3)
                        .map(|a| (pose.markers[k][a] - c.follower[a]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    assert!((apart - radius).abs() < 1e-12, "{name}: contact {k}");
                    continue;
                }
                for axis in 0..3 {
                    let difference = (pose.markers[k][axis] - c.follower[axis]).abs();
                    assert!(difference < 1e-12, "{name}: contact {k}, axis {axis}");
                }
            }
        }
    }

    #[test]
    fn a_spatial_cam_has_a_side_view_that_shows_the_height_along_its_axis() {
        // barrel_indexer: the cam's axis is the ground z, its plane the ground x-y: the side
        // view keeps x and shows z; plane cams have none.
        let geometry = Geometry::new(&builtin_description("barrel_indexer").unwrap()).unwrap();
        let side = geometry.side_view().expect("a barrel is spatial");
        let p = [0.06, 0.01, 0.035];
        assert_eq!(geometry.plane.project(&p), (0.06, 0.01));
        assert_eq!(side.plane.project(&p), (0.06, 0.035));
        assert_eq!(side.plane.axis_labels().1, "along the cam's axis [m]");
        for name in ["paper_concave", "face_cam", "cycloidal_roller"] {
            let plane = Geometry::new(&builtin_description(name).unwrap()).unwrap();
            assert!(plane.side_view().is_none(), "{name}");
        }
    }

    /// Distance from `p` to the polyline `line`.
    fn distance_to(line: &[(f64, f64)], p: (f64, f64)) -> f64 {
        line.windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                let t =
                    (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
                (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_turned_cam_is_drawn_through_the_contact_point() {
        // The drawing turns the profile with the model description's forward kinematics;
        // the generated code solves the contact. The contact point must lie on the drawn
        // disc and on the drawn roller, to the polylines' chord error: radius 0.04 m over
        // 720 chords, 5e-7 m; 0.0125 m over 90 chords, 8e-6 m.
        for (name, rim) in [
            ("eccentric_roller", Some(1e-5)),
            ("eccentric_flat", None),
            ("rocker_roller", Some(1e-5)),
        ] {
            let model = models::by_name(name).unwrap();
            let geometry = Geometry::new(&builtin_description(name).unwrap()).unwrap();
            assert!(geometry.has_moving_cam());
            let n = model.info().n();
            for j in 0..7 {
                // The camshaft turns by its drive (15 or 20 rad/s): 0.7 or 0.9 rad apart.
                let t = 0.045 * j as f64;
                let q = model.assemble(t).unwrap().q;
                assert!(q[0] > 0.6 * j as f64 - 1e-9, "{name}: the cam turns");
                let mut contacts = vec![ContactGeometry::default()];
                model.contact_geometry(&q, &vec![0.0; n], &mut contacts);
                let point = geometry.plane.project(&contacts[0].position);
                let picture = geometry.cam_picture(&q, 0, (0.0, 0.0)).unwrap();
                let mut outline = picture.outline.clone();
                outline.push(outline[0]);
                assert!(picture.closed, "{name}");
                assert!(distance_to(&outline, point) < 1e-6, "{name} at t = {t}");
                match rim {
                    Some(tol) => assert!(distance_to(&picture.roller, point) < tol, "{name}"),
                    // The face is a straight segment through the contact point: rounding of
                    // 0.05 m coordinates, 1e-12 m.
                    None => assert!(distance_to(&picture.face, point) < 1e-12, "{name}"),
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
