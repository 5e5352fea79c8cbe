//! A knife edge on an explicit profile y = f(x): the paper's contact, eqs. (1)–(8), in closed
//! form. With (X, Y) the edge in the cam frame ([`Relative`]):
//!
//! ```text
//! h = Y − f(X)                                   (3)
//! J = J2 − f′(X) J1                              (5b)
//! c = (J2 q̇)_q q̇ − f′ (J1 q̇)_q q̇ − f″ (J1 q̇)²   (7, 8)
//! ```
//!
//! h is not a distance: |∇h| = √(1 + f′²), the factor between λ and the normal force.

use super::curve::{CurvePoint, curve_at};
use super::relative::Relative;
use super::{ContactTerms, Formulas};
use crate::expr::Graph;
use crate::kinematics::Symbols;
use crate::model::Model;

/// The terms of contact `index`, a knife edge on an explicit profile.
pub fn explicit(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
) -> ContactTerms {
    let name = &model.contacts[index].name;
    let [x, y] = rel.xy;
    let CurvePoint { point, d1, d2 } = curve_at(g, model, s, index, x);
    let (f, slope, second) = (point[1], d1[1], d2[1]);
    let h = g.sub(y, f);
    let jacobian = rel
        .columns
        .iter()
        .map(|&[j1, j2]| {
            let s = g.mul(slope, j1);
            g.sub(j2, s)
        })
        .collect();
    let x_rate = rel.velocity[0];
    let bias = {
        let t1 = g.mul(slope, rel.convective[0]);
        let sq = g.powi(x_rate, 2);
        let t2 = g.mul(second, sq);
        let b = g.sub(rel.convective[1], t1);
        g.sub(b, t2)
    };
    g.label(slope, format!("{name}_slope"));
    g.label(second, format!("{name}_fxx"));
    // What the outputs report: the normal (−f′, 1)/√(1 + f′²), the geometric curvature
    // f″/(1 + f′²)^(3/2), the sliding speed t·Ṗ.
    let one = g.one();
    let slope_sq = g.mul(slope, slope);
    let stretch2 = g.add(one, slope_sq);
    let stretch = g.sqrt(stretch2);
    g.label(stretch, format!("{name}_stretch"));
    let neg_slope = g.neg(slope);
    let normal_xy = [g.div(neg_slope, stretch), g.div(one, stretch)];
    let normal = rel.vector_to_ground(g, normal_xy);
    let cube = g.mul(stretch2, stretch);
    let curvature = g.div(second, cube);
    let along = {
        let a = g.mul(slope, rel.velocity[1]);
        g.add(rel.velocity[0], a)
    };
    let sliding = g.div(along, stretch);
    ContactTerms {
        h,
        jacobian,
        bias,
        position: rel.point,
        cam_point: rel.xy,
        cam_height: None,
        normal,
        force_scale: stretch,
        parameter: x,
        curvature,
        sliding,
        relative: rel,
        radial: None,
        formulas: Formulas {
            kind: "a knife edge on y = f(x)".to_string(),
            h: "h = f2 − f3(f1), eq. (3)",
            jacobian: "J = J2 − f3′ J1, eq. (5b)",
            bias: "eqs. (7, 8)",
        },
    }
}
