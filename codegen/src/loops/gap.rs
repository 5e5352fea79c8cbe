//! The gap p_A − p_B of a loop's cut, formed so that its round-off follows the gap rather
//! than the size of the mechanism (docs/method.md §11.4).
//!
//! Each point is its root's anchor plus a sum of segments R_k ℓ_k (a vector ℓ_k fixed in a
//! body, turned by that body's rotation R_k). The anchors meet first: their difference is a
//! constant of the model, exact, where p_A − p_B taken whole would carry the round-off of
//! the points' distance from the origin (~ulp(40 m) = 7e-15 m in a chain of 40 four-bars).
//! Then two segments with the same vector about the same axis, one on each side (or one
//! segment and an anchor difference equal to its vector: R(0) ℓ), are taken together as
//!
//! ```text
//! R(α) ℓ − R(β) ℓ = 2 sin((α − β)/2) (cos m a × ℓ + sin m a × (a × ℓ)),   m = (α + β)/2
//! ```
//!
//! (Rodrigues: R(θ) = I + sin θ K + (1 − cos θ) K², K = a×), whose round-off is relative to
//! the difference itself, α − β being exact between nearby angles. A parallelogram's two
//! cranks, and its coupler against the ground link, are such pairs: near the positions
//! where it folds flat (its x gap then vanishes to first order in the crank's angle
//! difference, with a factor |sin θ|) cos α − cos β taken as a difference of cosines keeps
//! an absolute round-off ε ~ 2e-16 that Newton turns into ε / |sin θ| between the cranks,
//! and the acceleration level into ~ω² ε / |sin θ|³; as a product it keeps none. Loops
//! without such pairs get (base_A − base_B) + (arm_A − arm_B).

use crate::contact::relative::{PointMotion, Segment};
use crate::expr::Graph;
use crate::kinematics::{Rotation, V3, vec3};

/// p_A − p_B of the two sides' motions.
pub(super) fn closure_gap(g: &mut Graph, motions: &[PointMotion; 2]) -> V3 {
    let [a, b] = motions;
    let base = vec3::sub(g, a.base, b.base);
    // Root first: a chain's corresponding links pair up in order.
    let mut minus: Vec<Option<&Segment>> = b.segments.iter().rev().map(Some).collect();
    let mut pairs = Vec::new();
    let mut plus = Vec::new();
    for s in a.segments.iter().rev() {
        match minus
            .iter()
            .position(|m| m.is_some_and(|m| same_vector(g, s, m)))
        {
            Some(k) => pairs.push((s, minus[k].take())),
            None => plus.push(s),
        }
    }
    let minus: Vec<&Segment> = minus.into_iter().flatten().collect();
    // An unpaired segment against the anchors' difference: −ℓ on A's side, +ℓ on B's.
    let mut base_used = false;
    let mut terms = Vec::new();
    for s in plus {
        if !base_used && turns(s).is_some() && equal(g, base, s.local, -1.0) {
            base_used = true;
            terms.push(difference(g, s, None));
        } else {
            terms.push(s.value);
        }
    }
    for m in minus {
        if !base_used && turns(m).is_some() && equal(g, base, m.local, 1.0) {
            base_used = true;
            let d = difference(g, m, None);
            terms.push([0, 1, 2].map(|k| g.neg(d[k])));
        } else {
            terms.push([0, 1, 2].map(|k| g.neg(m.value[k])));
        }
    }
    if pairs.is_empty() && !base_used {
        let arms = vec3::sub(g, a.arm, b.arm);
        return vec3::add(g, base, arms);
    }
    let mut gap = if base_used { vec3::zero(g) } else { base };
    for (s, m) in pairs {
        let d = difference(g, s, m);
        gap = vec3::add(g, gap, d);
    }
    for t in terms {
        gap = vec3::add(g, gap, t);
    }
    gap
}

/// The axis and angle of a segment's rotation about a fixed axis.
fn turns(s: &Segment) -> Option<([f64; 3], crate::expr::Id)> {
    match &s.rotation {
        Rotation::Axis { axis, angle } => Some((*axis, *angle)),
        _ => None,
    }
}

/// Two segments with the same (nonzero) vector turned about the same axis.
fn same_vector(g: &Graph, s: &Segment, m: &Segment) -> bool {
    match (turns(s), turns(m)) {
        (Some((a, _)), Some((b, _))) => {
            a == b && s.local == m.local && !s.local.iter().all(|&x| g.is_zero(x))
        }
        _ => false,
    }
}

/// x = sign · y, componentwise and exactly (folded in the graph), y not zero.
fn equal(g: &mut Graph, x: V3, y: V3, sign: f64) -> bool {
    !y.iter().all(|&c| g.is_zero(c))
        && (0..3).all(|k| {
            let y = g.scale(sign, y[k]);
            let difference = g.sub(x[k], y);
            g.is_zero(difference)
        })
}

/// R(α) ℓ − R(β) ℓ for segment s (α) and m (β; 0 without one), as the product above.
fn difference(g: &mut Graph, s: &Segment, m: Option<&Segment>) -> V3 {
    let Some((axis, alpha)) = turns(s) else {
        unreachable!("only segments turning about a fixed axis are paired")
    };
    let beta = m.and_then(turns).map(|(_, beta)| beta);
    let d = match beta {
        Some(beta) => g.sub(alpha, beta),
        None => alpha,
    };
    let half = g.scale(0.5, d);
    let (sh, ch) = (g.sin(half), g.cos(half));
    // m = β + (α − β)/2: its cosine and sine from β's, which the kinematics has.
    let (cos_m, sin_m) = match beta {
        Some(beta) => {
            let (sb, cb) = (g.sin(beta), g.cos(beta));
            let cc = g.mul(cb, ch);
            let ss = g.mul(sb, sh);
            let sc = g.mul(sb, ch);
            let cs = g.mul(cb, sh);
            (g.sub(cc, ss), g.add(sc, cs))
        }
        None => (ch, sh),
    };
    let a = vec3::constant(g, axis);
    let k_l = vec3::cross(g, a, s.local);
    let kk_l = vec3::cross(g, a, k_l);
    let first = vec3::scale(g, cos_m, k_l);
    let second = vec3::scale(g, sin_m, kk_l);
    let bracket = vec3::add(g, first, second);
    let two_sh = g.scale(2.0, sh);
    vec3::scale(g, two_sh, bracket)
}
