//! A ball (a `Roller` on a surface) of radius ρ on a cam surface z = f(x, y): its centre C =
//! (X, Y, Z) ([`Relative`], cam frame) stays at the distance ρ from the surface, on the
//! offset surface (docs/method.md §13.8). The contact point is the foot point S = (u, v,
//! f(u, v)) nearest C, where C − S is along the surface's normal:
//!
//! ```text
//! F1 = (X − u) + (Z − f) f_u = 0,   F2 = (Y − v) + (Z − f) f_v = 0            (B1)
//! ```
//!
//! (half the gradient of |C − S|² with its sign changed). The generator solves them as two
//! nested contact parameters: v*(u) from F2 for a trial u, then u* from F1(u, v*(u)), whose
//! slope is F1_u − F1_v²/F2_v by the implicit-function theorem (F2_u = F1_v); each Newton
//! solve is the one of the planar contacts ([`Implicit`]). With N the unit normal at S (the
//! follower's side), D = N·(C − S), G = I + ∇f∇fᵀ and L = Hess f / W the surface's
//! fundamental forms in (u, v), b = (S_u·Ċ, S_v·Ċ):
//!
//! ```text
//! h = D − ρ                                                                      (B2)
//! J = N·∂C/∂q                            (the envelope theorem: ∂h/∂(u, v) = 0)    (B3)
//! c = N·C̈° − aᵀ L ṡ,   a = G⁻¹ b,   ṡ = (G − D L)⁻¹ b                           (B4)
//! ```
//!
//! ṡ = (u̇, v̇) is the foot point's rate; Ṅ·Ċ = −aᵀ L ṡ. At D = 0 (a point) c is (S3)
//! divided by W.
//!
//! On a surface of revolution r = g(z) ([`on_revolution`]) the foot point lies in the
//! centre's meridian half-plane: the ball is the planar roller (C7)–(C9) on the meridian
//! curve (g(t), t), seen in the coordinates (r, Z) ([`Relative::meridian`]), §13.8.

use super::relative::Relative;
use super::surface::{
    Derivatives, derivatives, dot, principal_curvature, sliding_speed, to_ground_vector,
};
use super::{ContactTerms, Formulas};
use crate::expr::{Graph, Guess, Id, Implicit};
use crate::kinematics::{Symbols, vec3};
use crate::model::{Field, Model};

/// The interval of each cam-plane coordinate scanned when Newton from the ball centre's own
/// (X, Y) fails (m).
const DEFAULT_SPAN: (f64, f64) = (-1.0, 1.0);

/// The terms of contact `index`: a ball of radius `radius` on its surface.
pub fn ball(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
    radius: f64,
) -> ContactTerms {
    let contact = &model.contacts[index];
    let name = contact.name.clone();
    let (span_x, span_y) = (DEFAULT_SPAN, DEFAULT_SPAN);
    let centre = [rel.xy[0], rel.xy[1], rel.height];
    // v*(u; C) from F2, on placeholders of its own.
    let inner = {
        let name = name.clone();
        let u = g.var(&format!("__ball_{name}_inner_u"));
        let v = g.var(&format!("__ball_{name}_inner_v"));
        let c = ["x", "y", "z"].map(|k| g.var(&format!("__ball_{name}_inner_c{k}")));
        let d = derivatives(g, model, s, index, [u, v]);
        let gap = g.sub(c[2], d.f);
        let residual = {
            let along = g.sub(c[1], v);
            let tilt = g.mul(gap, d.fy);
            g.add(along, tilt)
        };
        let derivative = second(g, gap, d.fy, d.fyy);
        let objective = distance2(g, c, [u, v, d.f]);
        move |g: &mut Graph, what: &str, inputs: [Id; 4]| {
            g.implicit(
                &format!("{name}_foot_{what}"),
                Implicit {
                    description: format!(
                        "contact {name}: the y of the surface point nearest the ball's centre, \
                         for a trial x"
                    ),
                    unknown: v,
                    placeholders: vec![u, c[0], c[1], c[2]],
                    input_names: vec!["u", "x", "y", "z"],
                    inputs: inputs.to_vec(),
                    residual,
                    derivative,
                    objective,
                    guess: Guess::Input(2),
                    range: span_y,
                },
            )
        }
    };
    // u*(C) from F1(u, v*(u)).
    let u = g.var(&format!("__ball_{name}_u"));
    let c = ["x", "y", "z"].map(|k| g.var(&format!("__ball_{name}_c{k}")));
    let v_of_u = inner(g, "y_of_x", [u, c[0], c[1], c[2]]);
    let d = derivatives(g, model, s, index, [u, v_of_u]);
    let gap = g.sub(c[2], d.f);
    let residual = {
        let along = g.sub(c[0], u);
        let tilt = g.mul(gap, d.fx);
        g.add(along, tilt)
    };
    let derivative = {
        let f1u = second(g, gap, d.fx, d.fxx);
        let f2v = second(g, gap, d.fy, d.fyy);
        let f1v = {
            let cross = g.mul(d.fx, d.fy);
            let bend = g.mul(gap, d.fxy);
            g.sub(bend, cross)
        };
        let sq = g.mul(f1v, f1v);
        let q = g.div(sq, f2v);
        g.sub(f1u, q)
    };
    let objective = distance2(g, c, [u, v_of_u, d.f]);
    let foot_x = g.implicit(
        &format!("{name}_parameter"),
        Implicit {
            description: format!(
                "contact {name}: the x of the surface point nearest the ball's centre"
            ),
            unknown: u,
            placeholders: c.to_vec(),
            input_names: vec!["x", "y", "z"],
            inputs: centre.to_vec(),
            residual,
            derivative,
            objective,
            guess: Guess::Input(0),
            range: span_x,
        },
    );
    let foot_y = inner(g, "y", [foot_x, centre[0], centre[1], centre[2]]);
    let d = derivatives(g, model, s, index, [foot_x, foot_y]);
    terms(g, model, s, index, rel, radius, [foot_x, foot_y], &d)
}

/// The terms of contact `index`: a ball of radius `radius` outside its surface of revolution:
/// the nearest-point roller on the meridian curve in the (r, Z) half-plane, its outputs
/// taken back to space (the contact point, the normal, the larger principal curvature, the
/// centre's sliding speed along the tangent plane).
pub fn on_revolution(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
    radius: f64,
) -> ContactTerms {
    let name = model.contacts[index].name.clone();
    let (meridian, u) = rel.meridian(g);
    let mut terms = super::nearest::nearest(
        g,
        model,
        s,
        index,
        meridian.clone(),
        super::nearest::Rim::Roller(radius),
    );
    // The foot point (g(t*), t*) on the centre's radius, in the cam frame.
    let expression = s.expression(
        model,
        Field::Profile(index),
        model.contacts[index].profile_expression(),
    );
    let [foot_r, g1, g2] = crate::expr::scalar::value_and_derivatives(
        g,
        expression,
        &format!("__ball_{name}_meridian"),
        terms.parameter,
        &s.params,
    );
    let one = g.one();
    let stretch = {
        let sq = g.mul(g1, g1);
        let w2 = g.add(one, sq);
        g.sqrt(w2)
    };
    let unit = {
        let radial = g.div(one, stretch);
        let up = {
            let n = g.neg(g1);
            g.div(n, stretch)
        };
        [g.mul(u[0], radial), g.mul(u[1], radial), up]
    };
    for (&id, axis) in unit.iter().zip(["x", "y", "z"]) {
        g.label(id, format!("{name}_cam_normal_{axis}"));
    }
    terms.cam_point = [g.mul(u[0], foot_r), g.mul(u[1], foot_r)];
    terms.cam_height = Some(terms.parameter);
    // The surface's larger principal curvature at the foot point, as for a point on it.
    terms.curvature = super::revolution::larger_curvature(g, foot_r, g2, stretch);
    let velocity = [rel.velocity[0], rel.velocity[1], rel.height_rate];
    terms.sliding = sliding_speed(g, velocity, unit, &name);
    terms.relative = rel;
    terms.formulas = Formulas {
        kind: "a ball outside a surface of revolution r = g(z), its centre on the offset"
            .to_string(),
        h: "h = D − ρ in the meridian half-plane, eq. (C7)",
        jacobian: "J = n·∂(r, Z)/∂q, eq. (C8)",
        bias: "eq. (C9) with r̈ = u·P̈ + (|Ṗ_xy|² − ṙ²)/r",
    };
    terms
}

/// ∂F/∂w of F = (c − w) + (Z − f) f_w: −1 − f_w² + (Z − f) f_ww.
fn second(g: &mut Graph, gap: Id, fw: Id, fww: Id) -> Id {
    let one = g.one();
    let sq = g.mul(fw, fw);
    let flat = g.add(one, sq);
    let bend = g.mul(gap, fww);
    g.sub(bend, flat)
}

/// |c − p|².
fn distance2(g: &mut Graph, c: [Id; 3], p: [Id; 3]) -> Id {
    let squares: Vec<Id> = (0..3)
        .map(|k| {
            let d = g.sub(c[k], p[k]);
            g.mul(d, d)
        })
        .collect();
    g.sum(squares)
}

/// h, J, c and the outputs at the foot point `foot` = (u*, v*), `d` the surface's
/// derivatives there (B2)–(B4).
#[allow(clippy::too_many_arguments)]
fn terms(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
    radius: f64,
    foot: [Id; 2],
    d: &Derivatives,
) -> ContactTerms {
    let name = model.contacts[index].name.clone();
    let one = g.one();
    let (fx2, fy2, fxfy) = (g.mul(d.fx, d.fx), g.mul(d.fy, d.fy), g.mul(d.fx, d.fy));
    let g11 = g.add(one, fx2);
    let g22 = g.add(one, fy2);
    let stretch = {
        let s2 = g.add(g11, fy2);
        g.sqrt(s2)
    };
    g.label(stretch, format!("{name}_stretch"));
    let unit = [g.neg(d.fx), g.neg(d.fy), one].map(|c| g.div(c, stretch));
    for (&id, axis) in unit.iter().zip(["x", "y", "z"]) {
        g.label(id, format!("{name}_cam_normal_{axis}"));
    }
    let centre = [rel.xy[0], rel.xy[1], rel.height];
    let foot_point = [foot[0], foot[1], d.f];
    let offset: [Id; 3] = std::array::from_fn(|k| g.sub(centre[k], foot_point[k]));
    let distance = dot(g, unit, offset);
    g.label(distance, format!("{name}_distance"));
    let rho = s.field(g, model, Field::Radius(index), radius);
    let h = g.sub(distance, rho);
    let jacobian = rel
        .columns
        .iter()
        .zip(&rel.height_columns)
        .map(|(&[j1, j2], &j3)| dot(g, unit, [j1, j2, j3]))
        .collect();
    let velocity = [rel.velocity[0], rel.velocity[1], rel.height_rate];
    let bias = {
        let along = dot(
            g,
            unit,
            [rel.convective[0], rel.convective[1], rel.height_convective],
        );
        // b = (S_u·Ċ, S_v·Ċ), S_u = (1, 0, f_u), S_v = (0, 1, f_v).
        let b = [
            {
                let t = g.mul(d.fx, velocity[2]);
                g.add(velocity[0], t)
            },
            {
                let t = g.mul(d.fy, velocity[2]);
                g.add(velocity[1], t)
            },
        ];
        let l = [d.fxx, d.fxy, d.fyy].map(|e| g.div(e, stretch));
        // a = G⁻¹ b (det G = W²).
        let det_g = g.mul(stretch, stretch);
        let a = solve2(g, [g11, fxfy, g22], det_g, b);
        // ṡ = (G − D L)⁻¹ b.
        let k = {
            let dl = l.map(|e| g.mul(distance, e));
            [g.sub(g11, dl[0]), g.sub(fxfy, dl[1]), g.sub(g22, dl[2])]
        };
        let det_k = {
            let p = g.mul(k[0], k[2]);
            let q = g.mul(k[1], k[1]);
            g.sub(p, q)
        };
        let rate = solve2(g, k, det_k, b);
        for (id, what) in [(rate[0], "foot_rate_x"), (rate[1], "foot_rate_y")] {
            g.label(id, format!("{name}_{what}"));
        }
        // aᵀ L ṡ.
        let turn = {
            let l_rate = [
                {
                    let p = g.mul(l[0], rate[0]);
                    let q = g.mul(l[1], rate[1]);
                    g.add(p, q)
                },
                {
                    let p = g.mul(l[1], rate[0]);
                    let q = g.mul(l[2], rate[1]);
                    g.add(p, q)
                },
            ];
            let p = g.mul(a[0], l_rate[0]);
            let q = g.mul(a[1], l_rate[1]);
            g.add(p, q)
        };
        g.sub(along, turn)
    };
    let normal = to_ground_vector(g, &rel, unit);
    let curvature = principal_curvature(g, d, stretch, &name);
    // The ball's centre moving over the surface: its speed along the tangent plane.
    let sliding = sliding_speed(g, velocity, unit, &name);
    let position = {
        let in_plane = rel.to_ground(g, foot);
        let lift = g.sub(d.f, rel.height);
        let lift = vec3::scale(g, lift, rel.axis);
        vec3::add(g, in_plane, lift)
    };
    vec3::label(g, position, &format!("{name}_contact"));
    ContactTerms {
        h,
        jacobian,
        bias,
        position,
        cam_point: foot,
        cam_height: Some(d.f),
        normal,
        force_scale: g.one(),
        parameter: foot[0],
        curvature,
        sliding,
        relative: rel,
        radial: None,
        formulas: Formulas {
            kind: "a ball on a surface z = f(x, y), its centre on the offset surface".to_string(),
            h: "h = N·(C − S) − ρ, eq. (B2)",
            jacobian: "J = N·∂C/∂q, eq. (B3)",
            bias: "eq. (B4)",
        },
    }
}

/// The solution of the symmetric 2 × 2 system [[m0, m1], [m1, m2]] x = b, det its
/// determinant.
fn solve2(g: &mut Graph, m: [Id; 3], det: Id, b: [Id; 2]) -> [Id; 2] {
    let x0 = {
        let p = g.mul(m[2], b[0]);
        let q = g.mul(m[1], b[1]);
        let n = g.sub(p, q);
        g.div(n, det)
    };
    let x1 = {
        let p = g.mul(m[0], b[1]);
        let q = g.mul(m[1], b[0]);
        let n = g.sub(p, q);
        g.div(n, det)
    };
    [x0, x1]
}
