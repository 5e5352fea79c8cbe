//! A profile's polar radius and signed curvature at evenly spaced points of its range, by
//! forward-mode differentiation ([`crate::jet`]): what the checks that a follower can follow
//! its profile read (`camchain_runtime::contact::followable`).
//!
//! The curve c(s) of each form and the follower's side are those of the derivation
//! (docs/method.md §9.1.2): explicit c = (x, f(x)), follower above (on the left of increasing
//! x); polar c = r(θ) (cos θ, sin θ), follower outside (on the right of increasing θ);
//! parametric (x(s), y(s)), follower on the right. The curvature is side · (c′ × c″)/|c′|³,
//! positive where the profile is hollow seen from the follower.

use crate::jet::{Jet2, eval_on, eval_on_all, own_tables};
use crate::model::Profile;
use camchain_runtime::contact::ProfileSample;

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

/// c, c′, c″ of `profile` at `s`, cam-frame components; for a surface z = f(x, y), its trace
/// on the plane y = 0, (x, f(x, 0)) in that plane's (x, z) components; for a barrel cam, its
/// pitch curve developed on the plane, (R θ, f(θ)); for a surface of revolution its meridian
/// (g(z), z).
pub fn curve(profile: &Profile, s: f64) -> [[f64; 2]; 3] {
    let at = Jet2::variable(s);
    match profile {
        Profile::Surface { f, .. } => {
            let z = eval_on_all(f, &[at, Jet2::constant(0.0)], &own_tables);
            [[s, z.v], [1.0, z.d1], [0.0, z.d2]]
        }
        Profile::Barrel { f, radius, .. } => {
            let z = eval_on(f, at, &own_tables);
            [[radius * s, z.v], [*radius, z.d1], [0.0, z.d2]]
        }
        // A surface of revolution's meridian (g(z), z) in its (r, z) half-plane, the
        // material on its left as z increases (towards the axis).
        Profile::Revolution { g, .. } => {
            let r = eval_on(g, at, &own_tables);
            [[r.v, s], [r.d1, 1.0], [r.d2, 0.0]]
        }
        Profile::Explicit { f, .. } => {
            let y = eval_on(f, at, &own_tables);
            [[s, y.v], [1.0, y.d1], [0.0, y.d2]]
        }
        Profile::Polar { r, .. } => {
            let r = eval_on(r, at, &own_tables);
            let (sin, cos) = s.sin_cos();
            let (radial, tangential) = ([cos, sin], [-sin, cos]);
            // c = r e_r, c′ = r′ e_r + r e_θ, c″ = (r″ − r) e_r + 2 r′ e_θ.
            let mix = |a: f64, b: f64| [0, 1].map(|k| a * radial[k] + b * tangential[k]);
            [mix(r.v, 0.0), mix(r.d1, r.v), mix(r.d2 - r.v, 2.0 * r.d1)]
        }
        Profile::Parametric { x, y, .. } => {
            let (x, y) = (eval_on(x, at, &own_tables), eval_on(y, at, &own_tables));
            [[x.v, y.v], [x.d1, y.d1], [x.d2, y.d2]]
        }
        // A face cam's groove: its centre line.
        Profile::Face { centre } => curve(centre, s),
    }
}

/// The curvature of `profile` at `s`, signed by the follower's side (positive where hollow).
pub fn curvature(profile: &Profile, s: f64) -> f64 {
    let [_, d1, d2] = curve(profile, s);
    let speed2 = d1[0] * d1[0] + d1[1] * d1[1];
    let cross = d1[0] * d2[1] - d1[1] * d2[0];
    follower_side(profile) * cross / (speed2 * speed2.sqrt())
}

/// `samples` + 1 evenly spaced samples of `profile` (its expressions with every parameter
/// resolved) over `range`: the polar radius (NaN for the other forms) and the curvature.
pub fn profile_samples(profile: &Profile, range: (f64, f64), samples: usize) -> Vec<ProfileSample> {
    (0..=samples)
        .map(|k| {
            let s = range.0 + (range.1 - range.0) * k as f64 / samples.max(1) as f64;
            let radius = match profile.curve() {
                Profile::Polar { r, .. } => r.eval(s),
                Profile::Explicit { .. }
                | Profile::Parametric { .. }
                | Profile::Surface { .. }
                | Profile::Barrel { .. }
                | Profile::Revolution { .. }
                | Profile::Face { .. } => f64::NAN,
            };
            ProfileSample {
                at: s,
                radius,
                curvature: curvature(profile, s),
            }
        })
        .collect()
}
