//! A point outside a surface of revolution r = g(z), by the reference's own route (docs/method.md
//! §13.5): F(P) = √(x² + y²) − g(z) evaluated in jet arithmetic along lines through the
//! follower point, which gives its gradient (along the axes) and Hessian (along the axes and
//! their sums) without any formula of the generator's; the convective term is F's second
//! derivative along Ṗ itself; the principal curvatures are those of the level set F = 0, the
//! eigenvalues of the Hessian restricted to the tangent plane over |∇F|.

use super::surface::{spatial, tangential_speed};
use super::{CamFrame, ContactConst, Evaluated, Seen};
use crate::jet::Jet2;
use crate::motion::Vec3;
use camchain_runtime::ContactGeometry;

impl ContactConst {
    /// F along the line P + t d: its value and first two derivatives in t.
    fn revolution_along(&self, p: [f64; 3], d: [f64; 3]) -> Jet2 {
        let line = |k: usize| Jet2 {
            v: p[k],
            d1: d[k],
            d2: 0.0,
        };
        let (x, y, z) = (line(0), line(1), line(2));
        (x * x + y * y).sqrt() - self.tape.eval_jet(z)[0]
    }

    /// h, J, c and the outputs of a point outside this contact's surface of revolution.
    pub(super) fn on_revolution(
        &self,
        seen: &Seen,
        columns: &[Seen],
        frame: &CamFrame,
        point: Vec3,
        direction: Vec3,
    ) -> Evaluated {
        let p = [seen.p[0], seen.p[1], seen.height[0]];
        let axis = |k: usize| -> [f64; 3] { std::array::from_fn(|i| f64::from(u8::from(i == k))) };
        let along_axes: Vec<Jet2> = (0..3).map(|k| self.revolution_along(p, axis(k))).collect();
        let h = along_axes[0].v;
        let gradient: [f64; 3] = std::array::from_fn(|k| along_axes[k].d1);
        let mut hessian = [[0.0; 3]; 3];
        for i in 0..3 {
            hessian[i][i] = along_axes[i].d2;
        }
        for i in 0..3 {
            for j in (i + 1)..3 {
                let both: [f64; 3] = std::array::from_fn(|k| f64::from(u8::from(k == i || k == j)));
                let mixed =
                    0.5 * (self.revolution_along(p, both).d2 - hessian[i][i] - hessian[j][j]);
                hessian[i][j] = mixed;
                hessian[j][i] = mixed;
            }
        }
        let dot = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| a[k] * b[k]).sum::<f64>();
        let motion = |s: &Seen| [s.v[0], s.v[1], s.height[1]];
        let jacobian: Vec<f64> = columns.iter().map(|c| dot(gradient, motion(c))).collect();
        let acceleration = [seen.a[0], seen.a[1], seen.height[2]];
        let velocity = motion(seen);
        let bias = dot(gradient, acceleration) + self.revolution_along(p, velocity).d2;
        let stretch = dot(gradient, gradient).sqrt();
        let unit: [f64; 3] = gradient.map(|g| g / stretch);
        let normal = frame.x * unit[0] + frame.y * unit[1] + frame.axis * unit[2];
        let sliding = tangential_speed(velocity, unit);
        // The surface's point on the follower point's radius, at its height.
        let g = self.tape.eval(p[2])[0];
        let r = p[0].hypot(p[1]);
        let contact = [p[0] * g / r, p[1] * g / r, p[2]];
        let position =
            frame.origin + frame.x * contact[0] + frame.y * contact[1] + frame.axis * contact[2];
        let geometry = ContactGeometry {
            position: position.into(),
            x: contact[0],
            y: contact[1],
            z: contact[2],
            follower: point.into(),
            normal: normal.into(),
            axis: frame.axis.into(),
            force_scale: stretch,
            parameter: p[2],
            curvature: larger_curvature(unit, &hessian, stretch),
            direction: direction.into(),
            sliding_speed: sliding,
            radial: [0.0; 3],
        };
        spatial(h, jacobian, bias, geometry, seen, columns)
    }
}

/// The larger principal curvature of the level set F = 0 with unit normal n = ∇F/|∇F|,
/// positive where hollow seen from the side n points to: −(the smaller eigenvalue of the
/// Hessian on the tangent plane)/|∇F|.
fn larger_curvature(n: [f64; 3], hessian: &[[f64; 3]; 3], stretch: f64) -> f64 {
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    // A tangent direction: n crossed with the coordinate axis least aligned with it.
    let least = (0..3)
        .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(0);
    let e: [f64; 3] = std::array::from_fn(|k| f64::from(u8::from(k == least)));
    let t1 = {
        let c = cross(n, e);
        let norm = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        c.map(|x| x / norm)
    };
    let t2 = cross(n, t1);
    let form = |a: [f64; 3], b: [f64; 3]| {
        (0..3)
            .map(|i| (0..3).map(|j| a[i] * hessian[i][j] * b[j]).sum::<f64>())
            .sum::<f64>()
    };
    let (a, b, c) = (form(t1, t1), form(t1, t2), form(t2, t2));
    let smaller = 0.5 * (a + c) - (0.25 * (a - c) * (a - c) + b * b).sqrt();
    -smaller / stretch
}
