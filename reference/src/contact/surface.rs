//! A point on a cam surface z = f(x, y), by the reference's own routes (docs/method.md §13):
//!
//! - the follower point's Z, Ż and the velocity-product part of Z̈ come from the full
//!   recursions like X and Y ([`Seen`]);
//! - f's gradient and Hessian from forward-mode jets of f along lines through (X, Y): along
//!   x̂ and ŷ for f_x, f_xx, f_y, f_yy, along x̂ + ŷ for f_xy; the convective term's
//!   Ẋᵀ H Ẋ as the second derivative of f along the velocity itself;
//! - the principal curvature from the shape operator G⁻¹ II's mean and Gaussian curvatures
//!   (the generator takes a Cholesky route);
//! - a barrel's f(x, y) = g(θ(x, y)) by the same jets, θ = atan2(y, x) evaluated in jet
//!   arithmetic along the line (the generator takes the chain rule through θ_x, θ_y).

use super::{CamFrame, ContactConst, Evaluated, Seen};
use crate::jet::Jet2;
use crate::motion::Vec3;
use camchain_model::model::Profile;
use camchain_runtime::{ContactGeometry, ContactKinematics};

/// atan2(y, x) of two jets: atan(y/x) or ∓atan(x/y) (whichever quotient is at most 1 in
/// magnitude) for the derivatives, the value from atan2.
fn angle(x: Jet2, y: Jet2) -> Jet2 {
    let value = y.v.atan2(x.v);
    let (d1, d2) = if x.v.abs() >= y.v.abs() {
        let a = (y / x).atan();
        (a.d1, a.d2)
    } else {
        let a = (x / y).atan();
        (-a.d1, -a.d2)
    };
    Jet2 { v: value, d1, d2 }
}

/// f, ∇f and the Hessian [f_xx, f_xy, f_yy] at a point.
pub(super) struct Local {
    pub f: f64,
    pub gradient: [f64; 2],
    pub hessian: [f64; 3],
}

impl ContactConst {
    /// f along the line (x, y) + t (dx, dy): the value and the first two derivatives in t.
    fn along(&self, [x, y]: [f64; 2], [dx, dy]: [f64; 2]) -> Jet2 {
        let line = |at: f64, d: f64| Jet2 {
            v: at,
            d1: d,
            d2: 0.0,
        };
        let (x, y) = (line(x, dx), line(y, dy));
        match &self.profile {
            Profile::Barrel { .. } => self.tape.eval_jet(angle(x, y))[0],
            // Not a graph over the plane: its own route (`revolution.rs`).
            Profile::Revolution { .. } => Jet2::constant(f64::NAN),
            Profile::Surface { .. }
            | Profile::Explicit { .. }
            | Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Face { .. } => self.tape.eval_jet_at(&[x, y])[0],
        }
    }

    pub(super) fn local(&self, p: [f64; 2]) -> Local {
        let (ex, ey, diagonal) = (
            self.along(p, [1.0, 0.0]),
            self.along(p, [0.0, 1.0]),
            self.along(p, [1.0, 1.0]),
        );
        Local {
            f: ex.v,
            gradient: [ex.d1, ey.d1],
            hessian: [ex.d2, 0.5 * (diagonal.d2 - ex.d2 - ey.d2), ey.d2],
        }
    }

    /// h, J, c and the outputs of a point on this contact's surface.
    pub(super) fn on_surface(
        &self,
        seen: &Seen,
        columns: &[Seen],
        frame: &CamFrame,
        point: Vec3,
        direction: Vec3,
    ) -> Evaluated {
        let p = seen.p;
        let Local {
            f,
            gradient: [fx, fy],
            hessian,
        } = self.local(p);
        let h = seen.height[0] - f;
        let jacobian: Vec<f64> = columns
            .iter()
            .map(|c| c.height[1] - fx * c.v[0] - fy * c.v[1])
            .collect();
        let curve_of_path = self.along(p, seen.v).d2;
        let bias = seen.height[2] - fx * seen.a[0] - fy * seen.a[1] - curve_of_path;
        let stretch = (1.0 + fx * fx + fy * fy).sqrt();
        let unit = [-fx / stretch, -fy / stretch, 1.0 / stretch];
        let normal = frame.x * unit[0] + frame.y * unit[1] + frame.axis * unit[2];
        let velocity = [seen.v[0], seen.v[1], seen.height[1]];
        let sliding = tangential_speed(velocity, unit);
        // A roller's centre is on a barrel's pitch surface, its contact point the radius
        // below along the normal; a barrel's curvature is its developed pitch curve's at the
        // point's radius r, (g″/r²)/(1 + (g′/r)²)^{3/2}, a surface's the larger principal one.
        let rho = self.follower.radius().copied().unwrap_or(0.0);
        let on_surface = [p[0], p[1], f];
        let contact: [f64; 3] = std::array::from_fn(|k| on_surface[k] - rho * unit[k]);
        let position =
            frame.origin + frame.x * contact[0] + frame.y * contact[1] + frame.axis * contact[2];
        let (parameter, curvature) = match &self.profile {
            Profile::Barrel { .. } => {
                let theta = p[1].atan2(p[0]);
                let g = self.tape.eval_jet(Jet2::variable(theta))[0];
                let r2 = p[0] * p[0] + p[1] * p[1];
                let slope2 = g.d1 * g.d1 / r2;
                (theta, g.d2 / r2 / (1.0 + slope2).powf(1.5))
            }
            Profile::Surface { .. }
            | Profile::Explicit { .. }
            | Profile::Polar { .. }
            | Profile::Parametric { .. }
            | Profile::Revolution { .. }
            | Profile::Face { .. } => (p[0], larger_principal_curvature([fx, fy], hessian)),
        };
        let geometry = ContactGeometry {
            position: position.into(),
            x: contact[0],
            y: contact[1],
            z: contact[2],
            follower: point.into(),
            normal: normal.into(),
            axis: frame.axis.into(),
            force_scale: stretch,
            parameter,
            curvature,
            direction: direction.into(),
            sliding_speed: sliding,
            // A tapered roller leans its force outward from the cam's axis (the runtime
            // turns the normal, `ContactGeometry::flank_force`).
            radial: if self.taper > 0.0 {
                let r = p[0].hypot(p[1]);
                (frame.x * (p[0] / r) + frame.y * (p[1] / r)).into()
            } else {
                [0.0; 3]
            },
        };
        spatial(h, jacobian, bias, geometry, seen, columns)
    }
}

/// |v − (v·n) n|: the speed of the follower point relative to the cam in the tangent plane of
/// the unit normal n (cam-frame components).
pub(super) fn tangential_speed(v: [f64; 3], n: [f64; 3]) -> f64 {
    let along: f64 = (0..3).map(|k| v[k] * n[k]).sum();
    (0..3)
        .map(|k| (v[k] - along * n[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// A spatial cam's evaluation: h, J, c, the geometry, and the follower point's cam-frame
/// kinematics with its height (Z, J3, c3) from `seen` and the Jacobian `columns`.
pub(super) fn spatial(
    h: f64,
    jacobian: Vec<f64>,
    bias: f64,
    geometry: ContactGeometry,
    seen: &Seen,
    columns: &[Seen],
) -> Evaluated {
    let kinematics = ContactKinematics {
        geometry,
        x: seen.p[0],
        y: seen.p[1],
        j1: columns.iter().map(|c| c.v[0]).collect(),
        j2: columns.iter().map(|c| c.v[1]).collect(),
        conv1: seen.a[0],
        conv2: seen.a[1],
        z: seen.height[0],
        j3: columns.iter().map(|c| c.height[1]).collect(),
        conv3: seen.height[2],
    };
    Evaluated {
        h,
        jacobian,
        bias,
        geometry,
        kinematics,
    }
}

/// The larger eigenvalue of the shape operator G⁻¹ II of z = f(x, y) with the upward normal:
/// mean curvature H = tr/2 and Gaussian curvature K = det, κ = H + √(H² − K).
pub(super) fn larger_principal_curvature([fx, fy]: [f64; 2], [a, b, c]: [f64; 3]) -> f64 {
    let w2 = 1.0 + fx * fx + fy * fy;
    let w = w2.sqrt();
    // G = [[1 + fx², fx fy], [fx fy, 1 + fy²]], det G = w²; II = [[a, b], [b, c]] / w.
    let gaussian = (a * c - b * b) / (w2 * w2);
    let mean = ((1.0 + fy * fy) * a - 2.0 * fx * fy * b + (1.0 + fx * fx) * c) / (2.0 * w2 * w);
    mean + (mean * mean - gaussian).max(0.0).sqrt()
}
