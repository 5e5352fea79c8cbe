//! A cam profile as a plane curve c(s) with c′(s) and c″(s), symbolic in s, for every
//! profile form: explicit (s = x), polar (s = θ) and parametric.
//!
//! The follower's side of the curve is fixed per form: above an explicit profile (to the
//! left of increasing x), outside a polar one (to the right of increasing θ), to the right
//! of a parametric one. [`Frame`] gives the unit tangent, the unit normal towards the
//! follower and the curvature signed so that it is positive where the profile is hollow seen
//! from the follower.

use crate::expr::scalar::{scalar_to_expr_in, value_and_derivatives};
use crate::expr::{Graph, Id};
use crate::kinematics::Symbols;
use crate::model::{Field, Model, Profile};
use crate::profile::Scalar;

/// A point of the profile with its first two derivatives, cam-frame components.
#[derive(Debug, Clone, Copy)]
pub struct CurvePoint {
    /// c(s).
    pub point: [Id; 2],
    /// c′(s).
    pub d1: [Id; 2],
    /// c″(s).
    pub d2: [Id; 2],
}

/// c, c′, c″ of contact `index`'s profile at the expression `at`.
pub fn curve_at(g: &mut Graph, model: &Model, s: &Symbols, index: usize, at: Id) -> CurvePoint {
    let contact = &model.contacts[index];
    let first = s.expression(model, Field::Profile(index), contact.profile_expression());
    let second = match contact.profile.curve() {
        Profile::Parametric { y, .. } => Some(s.expression(model, Field::ProfileY(index), y)),
        _ => None,
    };
    curve(
        g,
        &contact.profile,
        first,
        second,
        &contact.name,
        at,
        &s.params,
    )
}

/// c, c′, c″ at `at` of a profile of `profile`'s form whose expressions are `first` (f, r or
/// x(s)) and `second` (y(s) of a parametric one); `name` keeps the placeholders apart.
pub fn curve(
    g: &mut Graph,
    profile: &Profile,
    first: &Scalar,
    second: Option<&Scalar>,
    name: &str,
    at: Id,
    params: &[Id],
) -> CurvePoint {
    match profile {
        // A surface's trace on its plane y = 0, (x, f(x, 0)) in that plane's (x, z)
        // components: what the model's samples give too (`camchain_model::samples`). The
        // contacts on a surface do not read it (their own module does).
        Profile::Surface { .. } => {
            let x = g.var(&format!("__cam_{name}"));
            let zero = g.zero();
            let f = scalar_to_expr_in(g, first, &[x, zero], params);
            let d1 = g.diff(f, x);
            let d2 = g.diff(d1, x);
            let [f, d1, d2] = [f, d1, d2].map(|e| g.substitute(e, x, at));
            let one = g.one();
            CurvePoint {
                point: [at, f],
                d1: [one, d1],
                d2: [zero, d2],
            }
        }
        // A surface of revolution's meridian (g(z), z), as the model's samples give it.
        Profile::Revolution { .. } => {
            let placeholder = format!("__cam_{name}");
            let [r, d1, d2] = value_and_derivatives(g, first, &placeholder, at, params);
            let (zero, one) = (g.zero(), g.one());
            CurvePoint {
                point: [r, at],
                d1: [d1, one],
                d2: [d2, zero],
            }
        }
        // A barrel's pitch curve developed on the plane at its radius R, (R θ, g(θ)), as the
        // model's samples give it.
        Profile::Barrel { radius, .. } => {
            let placeholder = format!("__cam_{name}");
            let [f, d1, d2] = value_and_derivatives(g, first, &placeholder, at, params);
            let (zero, r) = (g.zero(), g.constant(*radius));
            CurvePoint {
                point: [g.mul(r, at), f],
                d1: [r, d1],
                d2: [zero, d2],
            }
        }
        Profile::Explicit { .. } => {
            let placeholder = format!("__cam_{name}");
            let [f, d1, d2] = value_and_derivatives(g, first, &placeholder, at, params);
            let (zero, one) = (g.zero(), g.one());
            CurvePoint {
                point: [at, f],
                d1: [one, d1],
                d2: [zero, d2],
            }
        }
        Profile::Polar { .. } => {
            let placeholder = format!("__cam_{name}_r");
            let [r, r1, r2] = value_and_derivatives(g, first, &placeholder, at, params);
            for (id, what) in [(r, "r"), (r1, "dr"), (r2, "ddr")] {
                g.label(id, format!("{name}_{what}"));
            }
            let (cos, sin) = (g.cos(at), g.sin(at));
            let radial = [cos, sin];
            let neg_sin = g.neg(sin);
            let tangential = [neg_sin, cos];
            // c = r e_r, c′ = r′ e_r + r e_θ, c″ = (r″ − r) e_r + 2 r′ e_θ.
            let point = radial.map(|e| g.mul(r, e));
            let d1 = combine(g, r1, radial, r, tangential);
            let r2_minus_r = g.sub(r2, r);
            let two_r1 = g.scale(2.0, r1);
            let d2 = combine(g, r2_minus_r, radial, two_r1, tangential);
            CurvePoint { point, d1, d2 }
        }
        Profile::Parametric { .. } => {
            let zero = Scalar::Const(0.0);
            let y_expr = second.unwrap_or(&zero);
            let px = format!("__cam_{name}_x");
            let py = format!("__cam_{name}_y");
            let [x0, x1, x2] = value_and_derivatives(g, first, &px, at, params);
            let [y0, y1, y2] = value_and_derivatives(g, y_expr, &py, at, params);
            CurvePoint {
                point: [x0, y0],
                d1: [x1, y1],
                d2: [x2, y2],
            }
        }
        // A face cam's groove: its centre line (polar or parametric), whose expressions
        // `first` and `second` are.
        Profile::Face { centre } => curve(g, centre, first, second, name, at, params),
    }
}

/// a·u + b·v for scalars a, b and 2-vectors u, v.
fn combine(g: &mut Graph, a: Id, u: [Id; 2], b: Id, v: [Id; 2]) -> [Id; 2] {
    [0, 1].map(|k| {
        let x = g.mul(a, u[k]);
        let y = g.mul(b, v[k]);
        g.add(x, y)
    })
}

/// +1 when the follower is on the left of the direction of increasing s (explicit
/// profiles), −1 on the right (polar and parametric ones).
pub fn follower_side(profile: &Profile) -> f64 {
    match profile {
        Profile::Explicit { .. } | Profile::Surface { .. } | Profile::Barrel { .. } => 1.0,
        Profile::Revolution { .. } => -1.0,
        Profile::Polar { .. } | Profile::Parametric { .. } => -1.0,
        Profile::Face { centre } => follower_side(centre),
    }
}

/// The Frenet frame of the profile at a point, oriented towards the follower.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// Unit tangent c′/|c′|.
    pub tangent: [Id; 2],
    /// Unit normal pointing to the follower's side.
    pub normal: [Id; 2],
    /// Curvature, positive where the profile bends towards the follower (hollow seen from
    /// it): side · (c′ × c″)/|c′|³.
    pub curvature: Id,
}

/// The residual's unknowns of contact `index` called `name`: a trial parameter
/// `__<name>_s`, two placeholders `__<name>_<p>` for the inputs, and the profile at the trial
/// parameter (named `trial_…`).
pub fn trial_point(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    name: &str,
    placeholders: [&str; 2],
) -> (Id, [Id; 2], CurvePoint) {
    let u = g.var(&format!("__{name}_s"));
    let p = placeholders.map(|p| g.var(&format!("__{name}_{p}")));
    let at = curve_at(g, model, s, index, u);
    label_curve(g, &at, "trial");
    (u, p, at)
}

/// The profile at the solved contact parameter (named after the contact) and the follower
/// point's offset from it, `<name>_offset_x`, `<name>_offset_y`.
pub fn solved_point(
    g: &mut Graph,
    model: &Model,
    s: &Symbols,
    index: usize,
    name: &str,
    (parameter, follower): (Id, [Id; 2]),
) -> (CurvePoint, [Id; 2]) {
    let at = curve_at(g, model, s, index, parameter);
    label_curve(g, &at, name);
    let offset = sub2(g, follower, at.point);
    g.label(offset[0], format!("{name}_offset_x"));
    g.label(offset[1], format!("{name}_offset_y"));
    (at, offset)
}

/// Names the point and its derivatives for the emitted code: `<label>_cx`, `<label>_dcx`,
/// `<label>_ddcx`, … (the first label a node gets stays).
pub fn label_curve(g: &mut Graph, c: &CurvePoint, label: &str) {
    for (k, axis) in ["x", "y"].iter().enumerate() {
        g.label(c.point[k], format!("{label}_c{axis}"));
        g.label(c.d1[k], format!("{label}_dc{axis}"));
        g.label(c.d2[k], format!("{label}_ddc{axis}"));
    }
}

/// The frame of the profile at `c` for a follower on `side` ([`follower_side`]), its terms
/// named after `label`.
pub fn labelled_frame(g: &mut Graph, c: &CurvePoint, side: f64, label: &str) -> Frame {
    let f = frame(g, c, side);
    g.label(f.tangent[0], format!("{label}_tx"));
    g.label(f.tangent[1], format!("{label}_ty"));
    g.label(f.curvature, format!("{label}_kappa"));
    f
}

/// The frame of the profile at `c` for a follower on `side` ([`follower_side`]).
pub fn frame(g: &mut Graph, c: &CurvePoint, side: f64) -> Frame {
    let speed2 = {
        let a = g.mul(c.d1[0], c.d1[0]);
        let b = g.mul(c.d1[1], c.d1[1]);
        g.add(a, b)
    };
    let speed = g.sqrt(speed2);
    g.label(speed2, "speed_sq");
    let tangent = c.d1.map(|d| g.div(d, speed));
    // side · rot90(t): rot90(a, b) = (−b, a).
    let normal = [g.scale(-side, tangent[1]), g.scale(side, tangent[0])];
    let cross = {
        let a = g.mul(c.d1[0], c.d2[1]);
        let b = g.mul(c.d1[1], c.d2[0]);
        g.sub(a, b)
    };
    let cube = g.mul(speed2, speed);
    let kappa = g.div(cross, cube);
    Frame {
        tangent,
        normal,
        curvature: g.scale(side, kappa),
    }
}

/// a·b for 2-vectors.
pub fn dot2(g: &mut Graph, a: [Id; 2], b: [Id; 2]) -> Id {
    let x = g.mul(a[0], b[0]);
    let y = g.mul(a[1], b[1]);
    g.add(x, y)
}

/// a − b for 2-vectors.
pub fn sub2(g: &mut Graph, a: [Id; 2], b: [Id; 2]) -> [Id; 2] {
    [g.sub(a[0], b[0]), g.sub(a[1], b[1])]
}

/// rot90(a) = (−a_y, a_x): a turned a quarter turn counterclockwise about the cam's axis.
pub fn perp(g: &mut Graph, a: [Id; 2]) -> [Id; 2] {
    [g.neg(a[1]), a[0]]
}

/// a + k·b for 2-vectors a, b and a scalar k.
pub fn add_scaled(g: &mut Graph, a: [Id; 2], k: Id, b: [Id; 2]) -> [Id; 2] {
    [0, 1].map(|i| {
        let t = g.mul(k, b[i]);
        g.add(a[i], t)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::parse_expression;

    /// The schema's followability checks read a profile's curvature from the model crate
    /// (`camchain_model::samples`, forward-mode differentiation); the derivation's frame
    /// differentiates the same expressions symbolically here. Both are exact: they agree to
    /// rounding (relative 1e-12 of curvatures ~10–1000 1/m) on every form, with the side
    /// conventions of both.
    #[test]
    fn the_checks_curvature_is_the_derivations() {
        let parse = |text: &str, var: &str| parse_expression(text, var).expect("parses");
        let profiles = [
            Profile::Explicit {
                source: String::new(),
                f: parse("0.045 - 2.0*x*x + 0.3*x.powi(3)", "x"),
            },
            Profile::Polar {
                source: String::new(),
                r: parse(
                    "0.01*theta.cos() + (0.0016 - 0.0001*theta.sin().powi(2)).sqrt()",
                    "theta",
                ),
            },
            Profile::Parametric {
                x_source: String::new(),
                y_source: String::new(),
                x: parse("0.05*s.cos() + 0.004*(3.0*s).sin()", "s"),
                y: parse("0.042*s.sin()", "s"),
            },
            // Its trace on y = 0 is the explicit profile's.
            Profile::Surface {
                source: String::new(),
                f: crate::profile::parse_expression_in(
                    "0.045 - 2.0*x*x + 0.3*x.powi(3) + 0.7*x*y - (3.0*y).sin()",
                    &["x", "y"],
                    &[],
                )
                .expect("parses"),
            },
        ];
        for profile in &profiles {
            let mut g = Graph::new();
            let at = g.var("s");
            let (first, second) = match profile {
                Profile::Explicit { f, .. }
                | Profile::Surface { f, .. }
                | Profile::Barrel { f, .. } => (f, None),
                Profile::Revolution { g, .. } => (g, None),
                Profile::Polar { r, .. } => (r, None),
                Profile::Parametric { x, y, .. } => (x, Some(y)),
                Profile::Face { .. } => continue,
            };
            let c = curve(&mut g, profile, first, second, "check", at, &[]);
            let f = frame(&mut g, &c, follower_side(profile));
            let samples = camchain_model::samples::profile_samples(profile, (-0.2, 6.0), 97);
            for sample in samples {
                let mut vars = vec![f64::NAN; g.var_names().len()];
                vars[0] = sample.at;
                let symbolic = g.eval(&[f.curvature], &vars)[0];
                let scale = symbolic.abs().max(1.0);
                assert!(
                    (sample.curvature - symbolic).abs() < 1e-12 * scale,
                    "{} at {}: {} vs {symbolic}",
                    profile.kind_name(),
                    sample.at,
                    sample.curvature
                );
            }
        }
    }
}
