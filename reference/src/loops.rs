//! Loops evaluated numerically (docs/method.md §11), by a route of their own: the
//! points and directions of a loop are placed by the nalgebra pose recursion, their rates
//! are the body velocities of the motion recursion (9) at q̇ (a Jacobian column is the rate
//! at q̇ = e_j), and their velocity-product accelerations come from the same recursion at
//! q̈ = 0. An equation is a product X·Y of two such vectors, differentiated by the product
//! rule: J_j = Ẋ(e_j)·Y + X·Ẏ(e_j), c = Ẍ°·Y + 2 Ẋ·Ẏ + X·Ÿ°.

use crate::motion::{Motion, Pose, Vec3, vec3};
use camchain_model::model::normal_pair;
use camchain_model::model::{Loop, LoopKind};

/// A vector of a loop: a point or a direction carried by a body (`None`: the ground), or
/// the gap between the loop's two points.
#[derive(Debug, Clone, Copy)]
enum Item {
    Point(Option<usize>, Vec3),
    Direction(Option<usize>, Vec3),
    Gap([(Option<usize>, Vec3); 2]),
    Axis(usize),
}

impl Item {
    /// Its value at the poses.
    fn value(&self, poses: &[Pose]) -> Vec3 {
        match *self {
            Item::Point(None, p) | Item::Direction(None, p) => p,
            Item::Point(Some(b), p) => poses[b].origin + poses[b].rot * p,
            Item::Direction(Some(b), d) => poses[b].rot * d,
            Item::Gap([a, b]) => {
                Item::Point(a.0, a.1).value(poses) - Item::Point(b.0, b.1).value(poses)
            }
            Item::Axis(k) => Vec3::from_fn(|i, _| f64::from(u8::from(i == k))),
        }
    }

    /// Its rate (with `motions` at q̇, q̈ = 0) and its acceleration (the velocity-product
    /// part when the motions have q̈ = 0).
    fn rates(&self, poses: &[Pose], motions: &[Motion]) -> (Vec3, Vec3) {
        match *self {
            Item::Point(None, _) | Item::Direction(None, _) | Item::Axis(_) => {
                (Vec3::zeros(), Vec3::zeros())
            }
            Item::Point(Some(b), p) => {
                let r = poses[b].rot * p;
                (
                    motions[b].point_velocity(&r),
                    motions[b].point_acceleration(&r),
                )
            }
            Item::Direction(Some(b), d) => {
                let v = poses[b].rot * d;
                let m = &motions[b];
                let w_v = m.omega.cross(&v);
                (w_v, m.alpha.cross(&v) + m.omega.cross(&w_v))
            }
            Item::Gap([a, b]) => {
                let (va, aa) = Item::Point(a.0, a.1).rates(poses, motions);
                let (vb, ab) = Item::Point(b.0, b.1).rates(poses, motions);
                (va - vb, aa - ab)
            }
        }
    }
}

/// One loop's constant data: the vector pairs whose products are its equations.
#[derive(Debug, Clone)]
pub(crate) struct LoopConst {
    equations: Vec<(Item, Item)>,
    points: [(Option<usize>, Vec3); 2],
}

/// h, J, c of one loop at (q, q̇), and its points.
#[derive(Debug, Clone)]
pub(crate) struct LoopEval {
    pub(crate) h: Vec<f64>,
    pub(crate) jacobian: Vec<Vec<f64>>,
    pub(crate) bias: Vec<f64>,
    pub(crate) points: [[f64; 3]; 2],
}

impl LoopConst {
    pub(crate) fn new(cut: &Loop) -> Self {
        let [a, b] = cut.sides.map(|s| (s.body, vec3(&s.point)));
        let gap = Item::Gap([a, b]);
        let along_b = |v: [f64; 3]| Item::Direction(b.0, vec3(&v));
        let along_a = |v: [f64; 3]| Item::Direction(a.0, vec3(&v));
        let components = |k: usize| (0..k).map(|i| (gap, Item::Axis(i))).collect::<Vec<_>>();
        let d = cut.axis;
        let equations = match (cut.kind, cut.planar) {
            (LoopKind::Revolute, true) => components(2),
            (LoopKind::Spherical, _) => components(3),
            (LoopKind::Revolute, false) => {
                let mut e = components(3);
                for perpendicular in normal_pair(d) {
                    e.push((along_a(cut.axis_a), along_b(perpendicular)));
                }
                e
            }
            (LoopKind::Prismatic, _) => {
                let normal = [-d[1], d[0], 0.0];
                vec![
                    (gap, along_b(normal)),
                    (along_a(cut.axis_a), along_b(normal)),
                ]
            }
            (LoopKind::PointOnLine, true) => vec![(gap, along_b([-d[1], d[0], 0.0]))],
            (LoopKind::PointOnLine, false) => normal_pair(d)
                .into_iter()
                .map(|e| (gap, along_b(e)))
                .collect(),
        };
        LoopConst {
            equations,
            points: [a, b],
        }
    }

    /// Evaluates the loop: `motions` at (q̇, q̈ = 0), `unit(j)` the motions at q̇ = e_j.
    pub(crate) fn evaluate(
        &self,
        poses: &[Pose],
        motions: &[Motion],
        units: &[Vec<Motion>],
    ) -> LoopEval {
        let mut out = LoopEval {
            h: Vec::new(),
            jacobian: Vec::new(),
            bias: Vec::new(),
            points: self.points.map(|(b, p)| {
                let v = Item::Point(b, p).value(poses);
                [v.x, v.y, v.z]
            }),
        };
        for (x, y) in &self.equations {
            let (xv, yv) = (x.value(poses), y.value(poses));
            out.h.push(xv.dot(&yv));
            let column = |unit: &Vec<Motion>| {
                let (xr, _) = x.rates(poses, unit);
                let (yr, _) = y.rates(poses, unit);
                xr.dot(&yv) + xv.dot(&yr)
            };
            out.jacobian.push(units.iter().map(column).collect());
            let (xr, xa) = x.rates(poses, motions);
            let (yr, ya) = y.rates(poses, motions);
            out.bias.push(xa.dot(&yv) + 2.0 * xr.dot(&yr) + xv.dot(&ya));
        }
        out
    }
}
