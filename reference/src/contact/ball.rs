//! A ball (a `Roller` on a surface) on a cam surface z = f(x, y), by the reference's own
//! routes (docs/method.md §13.8): the foot point S nearest the ball's centre C by a damped
//! two-dimensional Newton descent of |C − S|²/2 from (X, Y), its gradient and Hessian from
//! the surface's jets ([`ContactConst::local`]); the foot point's rate ṡ from the
//! implicit-function theorem on that gradient, and the convective term as N·C̈° + Ṅ·Ċ with
//! Ṅ differentiated from N = (−∇f, 1)/W along ṡ (the generator takes the Weingarten form
//! −aᵀ L ṡ). On a surface of revolution the foot point is in the centre's meridian plane,
//! found by Newton on the meridian, and Ṅ follows from the azimuth's and the foot's rates in
//! three dimensions (the generator takes the planar roller in the (r, Z) half-plane).

use super::surface::{larger_principal_curvature, spatial, tangential_speed};
use super::{CamFrame, ContactConst, Evaluated, Seen};
use crate::motion::Vec3;
use camchain_runtime::ContactGeometry;

/// Newton steps allowed for the foot point.
const STEPS: usize = 100;

impl ContactConst {
    /// The foot point (u, v) of C = (X, Y, Z) on the surface: a stationary point of
    /// φ = |C − S|²/2 reached by Newton steps halved until φ decreases.
    fn foot(&self, c: [f64; 3]) -> [f64; 2] {
        let phi = |s: [f64; 2]| {
            let f = self.local(s).f;
            0.5 * ((c[0] - s[0]).powi(2) + (c[1] - s[1]).powi(2) + (c[2] - f).powi(2))
        };
        let mut s = [c[0], c[1]];
        let scale = c[0].abs().max(c[1].abs()).max(1e-3);
        for _ in 0..STEPS {
            let l = self.local(s);
            let [fu, fv] = l.gradient;
            let [fuu, fuv, fvv] = l.hessian;
            let gap = c[2] - l.f;
            let grad = [-(c[0] - s[0]) - gap * fu, -(c[1] - s[1]) - gap * fv];
            let h = [
                1.0 + fu * fu - gap * fuu,
                fu * fv - gap * fuv,
                1.0 + fv * fv - gap * fvv,
            ];
            let det = h[0] * h[2] - h[1] * h[1];
            let step = [
                -(h[2] * grad[0] - h[1] * grad[1]) / det,
                -(h[0] * grad[1] - h[1] * grad[0]) / det,
            ];
            if !(step[0].is_finite() && step[1].is_finite()) {
                return [f64::NAN; 2];
            }
            // Steps are halved while φ grows, far from the root only: near it φ's changes
            // are rounding, and Newton's full step is what converges.
            let size = step[0].hypot(step[1]);
            let before = phi(s);
            let mut t = 1.0;
            let mut next = [s[0] + step[0], s[1] + step[1]];
            while size * t > 1e-6 * scale && phi(next) > before && t > 1e-6 {
                t *= 0.5;
                next = [s[0] + t * step[0], s[1] + t * step[1]];
            }
            s = next;
            if size <= 1e-15 * scale {
                break;
            }
        }
        s
    }

    /// h, J, c and the outputs of a ball of radius ρ on this contact's surface.
    pub(super) fn on_ball(
        &self,
        seen: &Seen,
        columns: &[Seen],
        frame: &CamFrame,
        point: Vec3,
        direction: Vec3,
    ) -> Evaluated {
        let c = [seen.p[0], seen.p[1], seen.height[0]];
        let s = self.foot(c);
        let l = self.local(s);
        let [fu, fv] = l.gradient;
        let [fuu, fuv, fvv] = l.hessian;
        let w = (1.0 + fu * fu + fv * fv).sqrt();
        let unit = [-fu / w, -fv / w, 1.0 / w];
        let foot = [s[0], s[1], l.f];
        let velocity = [seen.v[0], seen.v[1], seen.height[1]];
        // The gradient of φ vanishes at the foot: its derivative along the motion gives the
        // foot's rate, (G − (Z − f) Hess f) ṡ = (Ẋ + f_u Ż, Ẏ + f_v Ż).
        let above = c[2] - l.f;
        let m = [
            1.0 + fu * fu - above * fuu,
            fu * fv - above * fuv,
            1.0 + fv * fv - above * fvv,
        ];
        let b = [
            velocity[0] + fu * velocity[2],
            velocity[1] + fv * velocity[2],
        ];
        let det = m[0] * m[2] - m[1] * m[1];
        let rate = [
            (m[2] * b[0] - m[1] * b[1]) / det,
            (m[0] * b[1] - m[1] * b[0]) / det,
        ];
        // Ṅ from N = (−f_u, −f_v, 1)/W with (ḟ_u, ḟ_v) = Hess f · ṡ.
        let gu = fuu * rate[0] + fuv * rate[1];
        let gv = fuv * rate[0] + fvv * rate[1];
        let w_dot = (fu * gu + fv * gv) / w;
        let unit_dot = [
            -gu / w + fu * w_dot / (w * w),
            -gv / w + fv * w_dot / (w * w),
            -w_dot / (w * w),
        ];
        let at = Foot {
            point: foot,
            unit,
            unit_dot,
            parameter: foot[0],
            curvature: larger_principal_curvature([fu, fv], l.hessian),
        };
        self.ball_at(at, (seen, columns), frame, (point, direction))
    }

    /// h = N·(C − S) − ρ, J = N·∂C/∂q, c = N·C̈° + Ṅ·Ċ and the outputs of a ball whose foot
    /// point is `at`.
    fn ball_at(
        &self,
        at: Foot,
        (seen, columns): (&Seen, &[Seen]),
        frame: &CamFrame,
        (point, direction): (Vec3, Vec3),
    ) -> Evaluated {
        let rho = self.follower.radius().copied().unwrap_or(0.0);
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (foot, unit) = (at.point, at.unit);
        let c = [seen.p[0], seen.p[1], seen.height[0]];
        let gap: [f64; 3] = std::array::from_fn(|k| c[k] - foot[k]);
        let h = dot(unit, gap) - rho;
        let jacobian: Vec<f64> = columns
            .iter()
            .map(|col| dot(unit, [col.v[0], col.v[1], col.height[1]]))
            .collect();
        let velocity = [seen.v[0], seen.v[1], seen.height[1]];
        let convective = [seen.a[0], seen.a[1], seen.height[2]];
        let bias = dot(unit, convective) + dot(at.unit_dot, velocity);
        let normal = frame.x * unit[0] + frame.y * unit[1] + frame.axis * unit[2];
        let position = frame.origin + frame.x * foot[0] + frame.y * foot[1] + frame.axis * foot[2];
        let geometry = ContactGeometry {
            position: position.into(),
            x: foot[0],
            y: foot[1],
            z: foot[2],
            follower: point.into(),
            normal: normal.into(),
            axis: frame.axis.into(),
            force_scale: 1.0,
            parameter: at.parameter,
            curvature: at.curvature,
            direction: direction.into(),
            sliding_speed: tangential_speed(velocity, unit),
            radial: [0.0; 3],
        };
        spatial(h, jacobian, bias, geometry, seen, columns)
    }
}

/// A ball's foot point S with the unit normal N there and its rate Ṅ (cam frame), the
/// contact parameter and the surface's larger principal curvature at S.
struct Foot {
    point: [f64; 3],
    unit: [f64; 3],
    unit_dot: [f64; 3],
    parameter: f64,
    curvature: f64,
}

impl ContactConst {
    /// The meridian foot point t* of the centre at (r, Z) on (g(t), t): Newton on
    /// ψ(t) = g′(t)(r − g) + (Z − t) from t = Z, g's jets from the tape.
    fn meridian_foot(&self, r: f64, z: f64) -> f64 {
        let distance2 = |t: f64| {
            let g = self.tape.eval(t)[0];
            (r - g).powi(2) + (z - t).powi(2)
        };
        let start = if distance2(z).is_finite() {
            z
        } else {
            // The centre's height is off the meridian's domain: the best of a scan of the
            // contact's range.
            let (a, b) = self.range;
            (0..=512)
                .map(|k| a + (b - a) * k as f64 / 512.0)
                .min_by(|&s, &t| distance2(s).total_cmp(&distance2(t)))
                .unwrap_or(z)
        };
        let mut t = start;
        let scale = z.abs().max(r).max(1e-3);
        for _ in 0..STEPS {
            let g = self.tape.eval_jet(crate::jet::Jet2::variable(t))[0];
            let psi = g.d1 * (r - g.v) + (z - t);
            let slope = g.d2 * (r - g.v) - g.d1 * g.d1 - 1.0;
            let step = psi / slope;
            if !step.is_finite() {
                return f64::NAN;
            }
            t -= step;
            if step.abs() <= 1e-15 * scale {
                break;
            }
        }
        t
    }

    /// h, J, c and the outputs of a ball outside this contact's surface of revolution, in
    /// three dimensions: the foot point lies in the centre's meridian plane at the azimuth
    /// φ; N = (cos φ, sin φ, −g′)/W there; Ṅ from φ̇ = (X Ẏ − Y Ẋ)/r² and the foot's rate
    /// ṫ = −(g′ ṙ + Ż)/ψ′ (the implicit-function theorem on ψ).
    pub(super) fn on_ball_revolution(
        &self,
        seen: &Seen,
        columns: &[Seen],
        frame: &CamFrame,
        point: Vec3,
        direction: Vec3,
    ) -> Evaluated {
        let [x, y] = seen.p;
        let z = seen.height[0];
        let r = x.hypot(y);
        let (cos, sin) = (x / r, y / r);
        let t = self.meridian_foot(r, z);
        let g = self.tape.eval_jet(crate::jet::Jet2::variable(t))[0];
        let w = (1.0 + g.d1 * g.d1).sqrt();
        let unit = [cos / w, sin / w, -g.d1 / w];
        let foot = [g.v * cos, g.v * sin, t];
        let velocity = [seen.v[0], seen.v[1], seen.height[1]];
        let r_dot = cos * velocity[0] + sin * velocity[1];
        let phi_dot = (x * velocity[1] - y * velocity[0]) / (r * r);
        let slope = g.d2 * (r - g.v) - g.d1 * g.d1 - 1.0;
        let t_dot = -(g.d1 * r_dot + velocity[2]) / slope;
        // N = (cos φ / W, sin φ / W, −g′/W), W = √(1 + g′²), g′ = g′(t).
        let w_dot = g.d1 * g.d2 * t_dot / w;
        let radial = 1.0 / w;
        let radial_dot = -w_dot / (w * w);
        let up_dot = -(g.d2 * t_dot) / w + g.d1 * w_dot / (w * w);
        let unit_dot = [
            -sin * phi_dot * radial + cos * radial_dot,
            cos * phi_dot * radial + sin * radial_dot,
            up_dot,
        ];
        // Principal curvatures of the surface at the foot, positive where hollow seen from
        // outside: the meridian's g″/W³, the parallel's −1/(g W).
        let (along, across) = (g.d2 / w.powi(3), -1.0 / (g.v * w));
        let at = Foot {
            point: foot,
            unit,
            unit_dot,
            parameter: t,
            curvature: along.max(across),
        };
        self.ball_at(at, (seen, columns), frame, (point, direction))
    }
}
