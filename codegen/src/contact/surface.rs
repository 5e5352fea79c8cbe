//! A point (knife edge) on a cam surface z = f(x, y): the paper's contact with one more
//! argument (docs/method.md §13). With (X, Y, Z) the follower point in the cam frame
//! ([`Relative`], Z along the cam's axis x̂ × ŷ):
//!
//! ```text
//! h = Z − f(X, Y)                                                         (S1)
//! J = J3 − f_x J1 − f_y J2                                                (S2)
//! c = c3 − f_x c1 − f_y c2 − (f_xx Ẋ² + 2 f_xy Ẋ Ẏ + f_yy Ẏ²)             (S3)
//! ```
//!
//! As for y = f(x), h is not a distance: |∇h| = √(1 + f_x² + f_y²) is the factor between λ
//! and the normal force. The gradient and Hessian of f are derived symbolically from the
//! expression, like f′ and f″ of a plane profile.
//!
//! A barrel cam's pitch surface z = g(θ), θ the point's angle about the cam's axis, is the
//! same contact with f(x, y) = g(θ(x, y)) (§13.4): θ is the contact parameter (the polar
//! angle, by the generated code's Newton solve started from atan2, exact at once), g′ and
//! g″ are symbolic, and the chain rule through θ_x = −y/r², θ_y = x/r² gives ∇f and the
//! Hessian. A roller in the groove has its centre on the pitch surface: the same h, its
//! contact point the radius away on the flank below.

use super::relative::Relative;
use super::{ContactTerms, Formulas};
use crate::expr::scalar::{scalar_to_expr_in, value_and_derivatives};
use crate::expr::{Graph, Guess, Id, Implicit};
use crate::kinematics::{Symbols, V3, vec3};
use crate::model::{Field, Model, Profile};

/// f and its derivatives at a point (x, y) of the cam plane.
pub(super) struct Derivatives {
    pub f: Id,
    pub fx: Id,
    pub fy: Id,
    pub fxx: Id,
    pub fxy: Id,
    pub fyy: Id,
}

/// A barrel's pitch surface at the follower point: the derivatives of f(x, y) = g(θ), and
/// what its outputs read.
struct Barrel {
    /// The point's angle θ about the axis (the contact parameter).
    angle: Id,
    /// The developed pitch curve's curvature at the point's radius r: (g″/r²)/(1 + (g′/r)²)^{3/2}.
    curvature: Id,
}

/// f, ∇f and the Hessian of contact `index`'s surface at (x, y), symbolic; for a barrel
/// also its angle and developed curvature.
fn surface_at(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    xy: [Id; 2],
) -> (Derivatives, Option<Barrel>) {
    match &model.contacts[index].profile {
        Profile::Barrel { .. } => {
            let (d, b) = barrel(g, model, s, index, xy);
            (d, Some(b))
        }
        Profile::Surface { .. }
        | Profile::Explicit { .. }
        | Profile::Polar { .. }
        | Profile::Parametric { .. }
        | Profile::Revolution { .. }
        | Profile::Face { .. } => (derivatives(g, model, s, index, xy), None),
    }
}

/// f = g(θ(x, y)) of a barrel cam, by the chain rule through the polar angle.
fn barrel(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    [x, y]: [Id; 2],
) -> (Derivatives, Barrel) {
    let contact = &model.contacts[index];
    let name = &contact.name;
    // θ: the root of ψ(u) = y cos u − x sin u with ψ′ = −(x cos u + y sin u) = −r < 0,
    // the maximum of x cos u + y sin u.
    let u = g.var(&format!("__barrel_{name}_u"));
    let (px, py) = (
        g.var(&format!("__barrel_{name}_px")),
        g.var(&format!("__barrel_{name}_py")),
    );
    let (cos, sin) = (g.cos(u), g.sin(u));
    let (xc, ys, xs, yc) = (
        g.mul(px, cos),
        g.mul(py, sin),
        g.mul(px, sin),
        g.mul(py, cos),
    );
    let residual = g.sub(yc, xs);
    let along = g.add(xc, ys);
    let derivative = g.neg(along);
    let angle = g.implicit(
        &format!("{name}_parameter"),
        Implicit {
            description: format!(
                "contact {name}: the follower point's angle about the barrel's axis"
            ),
            unknown: u,
            placeholders: vec![px, py],
            input_names: vec!["x", "y"],
            inputs: vec![x, y],
            residual,
            derivative,
            objective: derivative,
            guess: Guess::Angle { x: 0, y: 1 },
            range: (0.0, std::f64::consts::TAU),
        },
    );
    let expression = s.expression(model, Field::Profile(index), contact.profile_expression());
    let [value, g1, g2] =
        value_and_derivatives(g, expression, &format!("__barrel_{name}"), angle, &s.params);
    for (id, what) in [(g1, "dg"), (g2, "ddg")] {
        g.label(id, format!("{name}_{what}"));
    }
    // θ_x = −y/r², θ_y = x/r²; θ_xx = 2xy/r⁴ = −θ_yy, θ_xy = (y² − x²)/r⁴.
    let r2 = {
        let a = g.mul(x, x);
        let b = g.mul(y, y);
        g.add(a, b)
    };
    g.label(r2, format!("{name}_radius_sq"));
    let r4 = g.mul(r2, r2);
    let tx = {
        let n = g.neg(y);
        g.div(n, r2)
    };
    let ty = g.div(x, r2);
    let xy2 = {
        let p = g.mul(x, y);
        g.scale(2.0, p)
    };
    let txx = g.div(xy2, r4);
    let tyy = g.neg(txx);
    let txy = {
        let a = g.mul(y, y);
        let b = g.mul(x, x);
        let d = g.sub(a, b);
        g.div(d, r4)
    };
    let fx = g.mul(g1, tx);
    let fy = g.mul(g1, ty);
    let second = |g: &mut Graph, a: Id, b: Id, ab: Id| {
        let p = g.mul(a, b);
        let t1 = g.mul(g2, p);
        let t2 = g.mul(g1, ab);
        g.add(t1, t2)
    };
    let fxx = second(g, tx, tx, txx);
    let fxy = second(g, tx, ty, txy);
    let fyy = second(g, ty, ty, tyy);
    for (id, what) in [
        (fx, "fx"),
        (fy, "fy"),
        (fxx, "fxx"),
        (fxy, "fxy"),
        (fyy, "fyy"),
    ] {
        g.label(id, format!("{name}_{what}"));
    }
    // The developed pitch curve (r θ, g(θ)) at radius r: slope g′/r, curvature
    // (g″/r²)/(1 + (g′/r)²)^{3/2}, positive where hollow seen from above.
    let curvature = {
        let one = g.one();
        let slope2 = {
            let a = g.mul(g1, g1);
            g.div(a, r2)
        };
        let stretch2 = g.add(one, slope2);
        let stretch = g.sqrt(stretch2);
        let cube = g.mul(stretch2, stretch);
        let bend = g.div(g2, r2);
        g.div(bend, cube)
    };
    (
        Derivatives {
            f: value,
            fx,
            fy,
            fxx,
            fxy,
            fyy,
        },
        Barrel { angle, curvature },
    )
}

/// f, ∇f and the Hessian of contact `index`'s surface z = f(x, y) at (x, y), symbolic.
pub(super) fn derivatives(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    [x, y]: [Id; 2],
) -> Derivatives {
    let contact = &model.contacts[index];
    let name = &contact.name;
    let expression = s.expression(model, Field::Profile(index), contact.profile_expression());
    let (px, py) = (
        g.var(&format!("__surface_{name}_x")),
        g.var(&format!("__surface_{name}_y")),
    );
    let f = scalar_to_expr_in(g, expression, &[px, py], &s.params);
    let fx = g.diff(f, px);
    let fy = g.diff(f, py);
    let fxx = g.diff(fx, px);
    let fxy = g.diff(fx, py);
    let fyy = g.diff(fy, py);
    let mut at = |e: Id| {
        let e = g.substitute(e, px, x);
        g.substitute(e, py, y)
    };
    let d = Derivatives {
        f: at(f),
        fx: at(fx),
        fy: at(fy),
        fxx: at(fxx),
        fxy: at(fxy),
        fyy: at(fyy),
    };
    for (id, what) in [
        (d.fx, "fx"),
        (d.fy, "fy"),
        (d.fxx, "fxx"),
        (d.fxy, "fxy"),
        (d.fyy, "fyy"),
    ] {
        g.label(id, format!("{name}_{what}"));
    }
    d
}

/// The terms of contact `index`, a point (or a roller's centre, `radius` its radius, in a
/// barrel's groove) on a surface z = f(x, y).
pub fn point(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
    radius: Option<f64>,
) -> ContactTerms {
    let name = model.contacts[index].name.clone();
    let [x, y] = rel.xy;
    let (d, barrel) = surface_at(g, model, s, index, [x, y]);
    let h = g.sub(rel.height, d.f);
    let jacobian = rel
        .columns
        .iter()
        .zip(&rel.height_columns)
        .map(|(&[j1, j2], &j3)| {
            let a = g.mul(d.fx, j1);
            let b = g.mul(d.fy, j2);
            let ab = g.add(a, b);
            g.sub(j3, ab)
        })
        .collect();
    let [vx, vy] = rel.velocity;
    let bias = {
        let a = g.mul(d.fx, rel.convective[0]);
        let b = g.mul(d.fy, rel.convective[1]);
        let xx = {
            let sq = g.mul(vx, vx);
            g.mul(d.fxx, sq)
        };
        let xy = {
            let p = g.mul(vx, vy);
            let p = g.mul(d.fxy, p);
            g.scale(2.0, p)
        };
        let yy = {
            let sq = g.mul(vy, vy);
            g.mul(d.fyy, sq)
        };
        let subtracted = g.sum([a, b, xx, xy, yy]);
        g.sub(rel.height_convective, subtracted)
    };
    // What the outputs report (S4)–(S6): the unit normal (−f_x, −f_y, 1)/W with
    // W = √(1 + f_x² + f_y²), the larger principal curvature, the sliding speed.
    let one = g.one();
    let gradient2 = {
        let a = g.mul(d.fx, d.fx);
        let b = g.mul(d.fy, d.fy);
        g.add(a, b)
    };
    let stretch2 = g.add(one, gradient2);
    let stretch = g.sqrt(stretch2);
    g.label(stretch, format!("{name}_stretch"));
    let unit = [g.neg(d.fx), g.neg(d.fy), one].map(|c| g.div(c, stretch));
    for (&id, axis) in unit.iter().zip(["x", "y", "z"]) {
        g.label(id, format!("{name}_cam_normal_{axis}"));
    }
    let normal = to_ground_vector(g, &rel, unit);
    let curvature = match &barrel {
        Some(b) => b.curvature,
        None => principal_curvature(g, &d, stretch, &name),
    };
    let sliding = sliding_speed(g, [vx, vy, rel.height_rate], unit, &name);
    // The point on the surface over (X, Y); a roller's centre is on the pitch surface and
    // its contact point the radius below it along the normal, on the flank under it.
    let mut position = {
        let in_plane = rel.to_ground(g, [x, y]);
        let lift = g.sub(d.f, rel.height);
        let lift = vec3::scale(g, lift, rel.axis);
        vec3::add(g, in_plane, lift)
    };
    let mut cam_point = [x, y];
    let mut cam_height = d.f;
    if let Some(rho) = radius {
        // The roller's radius may be read at run time.
        let rho = s.field(g, model, Field::Radius(index), rho);
        let down = vec3::scale(g, rho, normal);
        position = vec3::sub(g, position, down);
        let [a, b, c] = unit.map(|k| g.mul(rho, k));
        cam_point = [g.sub(x, a), g.sub(y, b)];
        cam_height = g.sub(d.f, c);
    }
    vec3::label(g, position, &format!("{name}_contact"));
    // A tapered roller leans its force outward from the cam's axis: the runtime turns the
    // normal along e_r = (X x̂ + Y ŷ)/r (`ContactGeometry::flank_force`).
    let radial = (barrel.is_some() && model.contacts[index].taper > 0.0).then(|| {
        g.set_section(format!(
            "contact {name}: the radial direction of a tapered roller"
        ));
        let (xx, yy) = (g.mul(x, x), g.mul(y, y));
        let r2 = g.add(xx, yy);
        let r = g.sqrt(r2);
        let (u, v) = (g.div(x, r), g.div(y, r));
        let along_x = vec3::scale(g, u, rel.x_axis);
        let along_y = vec3::scale(g, v, rel.y_axis);
        vec3::add(g, along_x, along_y)
    });
    ContactTerms {
        h,
        jacobian,
        bias,
        position,
        cam_point,
        cam_height: Some(cam_height),
        normal,
        force_scale: stretch,
        parameter: barrel.as_ref().map_or(x, |b| b.angle),
        curvature,
        sliding,
        relative: rel,
        radial,
        formulas: Formulas {
            kind: match (&barrel, radius) {
                (None, _) => "a point on a surface z = f(x, y)".to_string(),
                (Some(_), None) => "a point on a barrel cam's pitch surface z = g(θ)".to_string(),
                (Some(_), Some(_)) => {
                    "a roller in a barrel cam's groove, its centre on z = g(θ)".to_string()
                }
            },
            h: "h = Z − f(X, Y), eq. (S1)",
            jacobian: "J = J3 − f_x J1 − f_y J2, eq. (S2)",
            bias: "eq. (S3)",
        },
    }
}

/// |v − (v·n) n|: the magnitude of the follower point's velocity `v` relative to the cam in
/// the tangent plane of unit normal `unit` (cam-frame components), (S6).
pub(super) fn sliding_speed(g: &mut Graph, v: [Id; 3], unit: [Id; 3], name: &str) -> Id {
    let along = dot(g, v, unit);
    g.label(along, format!("{name}_normal_speed"));
    let tangential: Vec<Id> = (0..3)
        .map(|k| {
            let n = g.mul(along, unit[k]);
            g.sub(v[k], n)
        })
        .collect();
    for (&id, axis) in tangential.iter().zip(["x", "y", "z"]) {
        g.label(id, format!("{name}_slip_{axis}"));
    }
    let squares: Vec<Id> = tangential.iter().map(|&t| g.mul(t, t)).collect();
    let sum = g.sum(squares);
    g.sqrt(sum)
}

pub(super) fn dot(g: &mut Graph, a: [Id; 3], b: [Id; 3]) -> Id {
    let products: Vec<Id> = (0..3).map(|k| g.mul(a[k], b[k])).collect();
    g.sum(products)
}

/// The ground vector of cam-frame components (x, y, z).
pub(super) fn to_ground_vector(g: &mut Graph, rel: &Relative, [x, y, z]: [Id; 3]) -> V3 {
    let in_plane = rel.vector_to_ground(g, [x, y]);
    let up = vec3::scale(g, z, rel.axis);
    vec3::add(g, in_plane, up)
}

/// The larger principal curvature of the surface (S5), positive where it is hollow seen from
/// above (from the follower): the larger eigenvalue of G⁻¹ II, with the first fundamental
/// form G = I + ∇f ∇fᵀ and the second II = Hess f / W. With G = L Lᵀ (Cholesky) the
/// eigenvalues are those of the symmetric A = L⁻¹ II L⁻ᵀ, whose discriminant
/// ((A11 − A22)/2)² + A12² is a sum of squares: never negative by round-off.
pub(super) fn principal_curvature(g: &mut Graph, d: &Derivatives, stretch: Id, name: &str) -> Id {
    let one = g.one();
    // L = [[l11, 0], [l21, l22]]: l11 = √(1 + f_x²), l21 = f_x f_y / l11, l22 = W / l11.
    let fx2 = g.mul(d.fx, d.fx);
    let g11 = g.add(one, fx2);
    let l11 = g.sqrt(g11);
    let fxfy = g.mul(d.fx, d.fy);
    let l21 = g.div(fxfy, l11);
    let l22 = g.div(stretch, l11);
    // L⁻¹ = [[u, 0], [v, w]].
    let u = g.div(one, l11);
    let w = g.div(one, l22);
    let v = {
        let p = g.mul(l11, l22);
        let r = g.div(l21, p);
        g.neg(r)
    };
    let [a, b, c] = [d.fxx, d.fxy, d.fyy].map(|e| g.div(e, stretch));
    let a11 = {
        let uu = g.mul(u, u);
        g.mul(uu, a)
    };
    let a12 = {
        let va = g.mul(v, a);
        let wb = g.mul(w, b);
        let s = g.add(va, wb);
        g.mul(u, s)
    };
    let a22 = {
        let vv = g.mul(v, v);
        let t1 = g.mul(vv, a);
        let vw = g.mul(v, w);
        let t2 = g.mul(vw, b);
        let t2 = g.scale(2.0, t2);
        let ww = g.mul(w, w);
        let t3 = g.mul(ww, c);
        g.sum([t1, t2, t3])
    };
    let mean = {
        let s = g.add(a11, a22);
        g.scale(0.5, s)
    };
    let half_gap = {
        let s = g.sub(a11, a22);
        g.scale(0.5, s)
    };
    let discriminant = {
        let p = g.mul(half_gap, half_gap);
        let q = g.mul(a12, a12);
        g.add(p, q)
    };
    for (id, what) in [
        (g11, "g11"),
        (l11, "l11"),
        (l21, "l21"),
        (l22, "l22"),
        (u, "inv_l11"),
        (v, "inv_l21"),
        (w, "inv_l22"),
        (a11, "shape_11"),
        (a12, "shape_12"),
        (a22, "shape_22"),
        (mean, "mean_curvature"),
        (half_gap, "curvature_half_gap"),
        (discriminant, "curvature_discriminant"),
    ] {
        g.label(id, format!("{name}_{what}"));
    }
    let root = g.sqrt(discriminant);
    g.add(mean, root)
}
