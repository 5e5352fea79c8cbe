//! A point (knife edge) on a surface of revolution r = g(z) about the cam's axis, outside it
//! (docs/method.md §13.5). With (X, Y, Z) the follower point in the cam frame and
//! r = √(X² + Y²) its distance from the axis:
//!
//! ```text
//! h = r − g(Z)                                                              (S8)
//! J = (X J1 + Y J2)/r − g′ J3                                               (S9)
//! c = (X c1 + Y c2)/r − g′ c3 + (Ẋ² + Ẏ²)/r − (X Ẋ + Y Ẏ)²/r³ − g″ Ż²      (S10)
//! ```
//!
//! h is a gap along the radius: |∇h| = √(1 + g′²) is the factor between λ and the normal
//! force. The point on the axis (r = 0) has no direction from it: the contact is undefined
//! there, as for a polar profile's centre.

use super::relative::Relative;
use super::surface::{sliding_speed, to_ground_vector};
use super::{ContactTerms, Formulas};
use crate::expr::scalar::value_and_derivatives;
use crate::expr::{Graph, Id};
use crate::kinematics::{Symbols, vec3};
use crate::model::{Field, Model};

/// The larger principal curvature of r = g(z) where g = `radius`, g″ = `g2` and
/// W = √(1 + g′²) = `stretch`, positive where hollow seen from outside: the meridian's
/// g″/W³ and the parallel circle's −1/(g W), the larger as (a + b + |a − b|)/2.
pub(super) fn larger_curvature(g: &mut Graph, radius: Id, g2: Id, stretch: Id) -> Id {
    let one = g.one();
    let w3 = {
        let p = g.mul(stretch, stretch);
        g.mul(p, stretch)
    };
    let meridian = g.div(g2, w3);
    let parallel = {
        let p = g.mul(radius, stretch);
        let q = g.div(one, p);
        g.neg(q)
    };
    let sum = g.add(meridian, parallel);
    let gap = g.sub(meridian, parallel);
    let gap2 = g.mul(gap, gap);
    let spread = g.sqrt(gap2);
    let total = g.add(sum, spread);
    g.scale(0.5, total)
}

/// The terms of contact `index`, a point outside a surface of revolution.
pub fn point(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    rel: Relative,
) -> ContactTerms {
    let contact = &model.contacts[index];
    let name = contact.name.clone();
    let [x, y] = rel.xy;
    let z = rel.height;
    let expression = s.expression(model, Field::Profile(index), contact.profile_expression());
    let [radius, g1, g2] =
        value_and_derivatives(g, expression, &format!("__revolution_{name}"), z, &s.params);
    for (id, what) in [(radius, "g"), (g1, "dg"), (g2, "ddg")] {
        g.label(id, format!("{name}_{what}"));
    }
    let r2 = {
        let a = g.mul(x, x);
        let b = g.mul(y, y);
        g.add(a, b)
    };
    let r = g.sqrt(r2);
    g.label(r, format!("{name}_axis_distance"));
    let h = g.sub(r, radius);
    // ∇h = (X/r, Y/r, −g′).
    let (ux, uy) = (g.div(x, r), g.div(y, r));
    let jacobian = rel
        .columns
        .iter()
        .zip(&rel.height_columns)
        .map(|(&[j1, j2], &j3)| {
            let a = g.mul(ux, j1);
            let b = g.mul(uy, j2);
            let c = g.mul(g1, j3);
            let ab = g.add(a, b);
            g.sub(ab, c)
        })
        .collect();
    let [vx, vy] = rel.velocity;
    let vz = rel.height_rate;
    let bias = {
        let a = g.mul(ux, rel.convective[0]);
        let b = g.mul(uy, rel.convective[1]);
        let c = g.mul(g1, rel.height_convective);
        // The radius's second derivative along Ṗ: (|Ṗ_xy|² − (u·Ṗ_xy)²)/r.
        let speed2 = {
            let p = g.mul(vx, vx);
            let q = g.mul(vy, vy);
            g.add(p, q)
        };
        let radial = {
            let p = g.mul(ux, vx);
            let q = g.mul(uy, vy);
            g.add(p, q)
        };
        g.label(radial, format!("{name}_radial_speed"));
        let radial2 = g.mul(radial, radial);
        let across = g.sub(speed2, radial2);
        let bend = g.div(across, r);
        let meridian = {
            let p = g.mul(vz, vz);
            g.mul(g2, p)
        };
        let plus = g.sum([a, b, bend]);
        let minus = g.add(c, meridian);
        g.sub(plus, minus)
    };
    let one = g.one();
    let stretch = {
        let p = g.mul(g1, g1);
        let q = g.add(one, p);
        g.sqrt(q)
    };
    g.label(stretch, format!("{name}_stretch"));
    let unit = {
        let n = g.neg(g1);
        [ux, uy, n].map(|c| g.div(c, stretch))
    };
    let normal = to_ground_vector(g, &rel, unit);
    let curvature = larger_curvature(g, radius, g2, stretch);
    let sliding = sliding_speed(g, [vx, vy, vz], unit, &name);
    // The surface's point on the follower point's radius: (X, Y) g/r at the height Z.
    let cam_point = {
        let k = g.div(radius, r);
        [g.mul(k, x), g.mul(k, y)]
    };
    let position = rel.to_ground(g, cam_point);
    vec3::label(g, position, &format!("{name}_contact"));
    ContactTerms {
        h,
        jacobian,
        bias,
        position,
        cam_point,
        cam_height: Some(z),
        normal,
        force_scale: stretch,
        parameter: z,
        curvature,
        sliding,
        relative: rel,
        radial: None,
        formulas: Formulas {
            kind: "a point outside a surface of revolution r = g(z)".to_string(),
            h: "h = √(X² + Y²) − g(Z), eq. (S8)",
            jacobian: "J = (X J1 + Y J2)/r − g′ J3, eq. (S9)",
            bias: "eq. (S10)",
        },
    }
}
