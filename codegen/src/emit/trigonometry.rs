//! Sines and cosines of joint angles: their names (`s_q1`, `c_q1_q2`), the pairs the
//! position level keeps in the cache for the velocity level, and the velocity level's
//! sines and cosines of other angles rebuilt from them by the addition theorems.

use super::names::{id_at, sanitize};
use crate::expr::{Graph, Id, Node};
use crate::profile::Func;
use std::collections::HashMap;

/// The coordinates summed in an angle `q_a + q_b + …` (sorted variable indices), if `id` is
/// such a sum.
pub(super) fn angle_vars(g: &Graph, id: Id, out: &mut Vec<u32>) -> bool {
    let mut ok = true;
    angle_terms(g, id, |k| out.push(k), &mut ok);
    ok
}

/// Calls `leaf` with the variable index of every term of the sum of variables `id`, left to
/// right, and clears `ok` (stopping there) at the first term that is not a variable. An
/// absolute joint angle of a planar chain is a sum through every joint below it, so the
/// walk keeps its own stack instead of recursing.
pub(super) fn angle_terms(g: &Graph, id: Id, mut leaf: impl FnMut(u32), ok: &mut bool) {
    let mut stack = vec![id];
    while let Some(id) = stack.pop() {
        match g.node(id) {
            Node::Var(k) => leaf(k),
            Node::Add(a, b) => {
                stack.push(b);
                stack.push(a);
            }
            _ => {
                *ok = false;
                return;
            }
        }
    }
}

/// Rewrites, in the velocity-level outputs, the sine and cosine of every angle the position
/// level does not compute but can be written as the sum or difference of two angles whose
/// sine and cosine it does (the relative joint angles of M and F, from the absolute angles
/// of the contact kinematics): sin(A − B) = sA cB − cA sB and so on. Four multiplications and
/// two additions replace a sine and a cosine, and the velocity level then reads every
/// trigonometric value from the cache.
pub(super) fn reuse_position_trigonometry(
    g: &mut Graph,
    position: &[Id],
    velocity: &mut [(String, Id)],
) {
    let in_position = g.reachable(position);
    // Angles whose sine and cosine the position level both computes.
    let mut known: HashMap<Vec<u32>, (Id, Id)> = HashMap::new();
    let mut half: HashMap<Vec<u32>, (Option<Id>, Option<Id>)> = HashMap::new();
    for (i, &needed) in in_position.iter().enumerate() {
        let id = id_at(g, i);
        let Some((f, _, vars)) = angle_trig(g, id).filter(|_| needed) else {
            continue;
        };
        let entry = half.entry(vars).or_default();
        if f == Func::Sin {
            entry.0 = Some(id);
        } else {
            entry.1 = Some(id);
        }
    }
    for (vars, pair) in half {
        if let (Some(s), Some(c)) = pair {
            known.insert(vars, (s, c));
        }
    }
    let roots: Vec<Id> = velocity.iter().map(|o| o.1).collect();
    let in_velocity = g.reachable(&roots);
    let mut replacements = Vec::new();
    for (i, (&velocity_needs, &position_has)) in in_velocity.iter().zip(&in_position).enumerate() {
        let id = id_at(g, i);
        let Some((f, arg, vars)) = angle_trig(g, id).filter(|_| velocity_needs && !position_has)
        else {
            continue;
        };
        let rebuilt = g.rebuild_as(id, |g| trig_from_known(g, f, &vars, &known).unwrap_or(id));
        if rebuilt != id {
            // Named like the call it replaces (`c_q2` for cos q2).
            if let Some(name) = trig_name(g, f, arg) {
                g.label(rebuilt, name);
            }
            replacements.push((id, rebuilt));
        }
    }
    let map: HashMap<Id, Id> = replacements.into_iter().collect();
    let mut roots: Vec<Id> = velocity.iter().map(|o| o.1).collect();
    g.replace_nodes(&mut roots, &map);
    for (output, root) in velocity.iter_mut().zip(roots) {
        output.1 = root;
    }
}

/// Robotran's name of a sine or cosine of a coordinate or a sum of coordinates: `s_q1`,
/// `c_q1_q2`.
pub(super) fn trig_name(g: &Graph, f: Func, angle: Id) -> Option<String> {
    trig_name_of(f, &angle_name(g, angle)?)
}

/// `s_<angle>` for a sine, `c_<angle>` for a cosine.
pub(super) fn trig_name_of(f: Func, angle: &str) -> Option<String> {
    let prefix = match f {
        Func::Sin => "s",
        Func::Cos => "c",
        _ => return None,
    };
    Some(format!("{prefix}_{angle}"))
}

/// `q1_q2` for the angle q1 + q2 (the coordinates summed, in the expression's order).
pub(super) fn angle_name(g: &Graph, angle: Id) -> Option<String> {
    let mut names = Vec::new();
    let mut ok = true;
    angle_terms(
        g,
        angle,
        |k| names.push(g.var_names().get(k as usize)),
        &mut ok,
    );
    // The generator's own inputs (`__x_q1`, the joint rates M multiplies) are not angles.
    let internal = names.iter().flatten().any(|n| n.starts_with("__"));
    let names: Option<Vec<String>> = names.into_iter().map(|n| n.map(|n| sanitize(n))).collect();
    names.filter(|_| ok && !internal).map(|n| n.join("_"))
}

/// sin or cos of the angle `vars` from two known angles P, R with vars = P − R or P + R.
pub(super) fn trig_from_known(
    g: &mut Graph,
    f: Func,
    vars: &[u32],
    known: &HashMap<Vec<u32>, (Id, Id)>,
) -> Option<Id> {
    let mut keys: Vec<&Vec<u32>> = known.keys().collect();
    keys.sort();
    for p in &keys {
        for r in &keys {
            let (sp, cp) = known[*p];
            let (sr, cr) = known[*r];
            if multiset_difference(p, r).as_deref() == Some(vars) {
                // A − B
                let (x, y) = (g.mul(sp, cr), g.mul(cp, sr));
                let (u, w) = (g.mul(cp, cr), g.mul(sp, sr));
                return Some(if f == Func::Sin {
                    g.sub(x, y)
                } else {
                    g.add(u, w)
                });
            }
            if p <= r && multiset_sum(p, r) == vars {
                // A + B
                let (x, y) = (g.mul(sp, cr), g.mul(cp, sr));
                let (u, w) = (g.mul(cp, cr), g.mul(sp, sr));
                return Some(if f == Func::Sin {
                    g.add(x, y)
                } else {
                    g.sub(u, w)
                });
            }
        }
    }
    None
}

/// p − r as sorted multisets, when r ⊆ p and the difference is not empty.
pub(super) fn multiset_difference(p: &[u32], r: &[u32]) -> Option<Vec<u32>> {
    let mut rest = p.to_vec();
    for x in r {
        let at = rest.iter().position(|y| y == x)?;
        rest.remove(at);
    }
    (!rest.is_empty()).then_some(rest)
}

/// p + r as a sorted multiset.
pub(super) fn multiset_sum(p: &[u32], r: &[u32]) -> Vec<u32> {
    let mut all = [p, r].concat();
    all.sort_unstable();
    all
}

/// For a sine or cosine of a joint angle (a coordinate or a sum of them): the function,
/// the angle and its variables, sorted.
pub(super) fn angle_trig(g: &Graph, id: Id) -> Option<(Func, Id, Vec<u32>)> {
    let Node::Call(f @ (Func::Sin | Func::Cos), arg) = g.node(id) else {
        return None;
    };
    let mut vars = Vec::new();
    if !angle_vars(g, arg, &mut vars) {
        return None;
    }
    vars.sort_unstable();
    Some((f, arg, vars))
}

/// The sine–cosine pairs of joint angles (a coordinate or a sum of them) among the
/// `reachable` nodes, each given three cache entries in creation order.
pub(super) fn trig_pairs(g: &Graph, reachable: &[bool], params: &[Id]) -> Vec<TrigMemo> {
    let mut sines: HashMap<Id, Id> = HashMap::new();
    let mut cosines: HashMap<Id, Id> = HashMap::new();
    for (i, &needed) in reachable.iter().enumerate() {
        let id = id_at(g, i);
        let Some((f, arg, vars)) = angle_trig(g, id).filter(|_| needed) else {
            continue;
        };
        if vars.iter().any(|&k| params.contains(&g.var_id(k))) {
            continue;
        }
        if f == Func::Sin {
            sines.insert(arg, id);
        } else {
            cosines.insert(arg, id);
        }
    }
    let mut pairs: Vec<(Id, Id)> = sines
        .iter()
        .filter_map(|(arg, &sin)| cosines.get(arg).map(|&cos| (sin, cos)))
        .collect();
    pairs.sort_unstable();
    pairs
        .into_iter()
        .enumerate()
        .map(|(k, (sin, cos))| TrigMemo {
            sin,
            cos,
            slot: 3 * k,
        })
        .collect()
}

/// A sine and a cosine of one angle, kept in the cache entries `slot..slot + 3`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct TrigMemo {
    pub(super) sin: Id,
    pub(super) cos: Id,
    pub(super) slot: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trigonometric_names_follow_robotran() {
        let mut g = Graph::new();
        let (q1, q2) = (g.var("q1"), g.var("Q2"));
        let sum = g.add(q1, q2);
        assert_eq!(trig_name(&g, Func::Sin, q1).as_deref(), Some("s_q1"));
        assert_eq!(trig_name(&g, Func::Cos, sum).as_deref(), Some("c_q1_q2"));
        assert_eq!(trig_name_of(Func::Sqrt, "q1"), None);
        let twice = g.mul(q1, q1);
        assert_eq!(angle_name(&g, twice), None);
    }

    #[test]
    fn multisets_of_coordinates() {
        assert_eq!(multiset_difference(&[0, 1, 1], &[1]), Some(vec![0, 1]));
        assert_eq!(multiset_difference(&[0], &[0]), None);
        assert_eq!(multiset_difference(&[0], &[2]), None);
        assert_eq!(multiset_sum(&[2], &[0, 1]), vec![0, 1, 2]);
    }

    #[test]
    fn a_difference_of_angles_is_rebuilt_from_the_known_sines_and_cosines() {
        let mut g = Graph::new();
        let (a, b) = (g.var("a"), g.var("b"));
        let ab = g.add(a, b);
        let mut known = HashMap::new();
        let (sab, cab) = (g.sin(ab), g.cos(ab));
        let (sb, cb) = (g.sin(b), g.cos(b));
        known.insert(vec![0, 1], (sab, cab));
        known.insert(vec![1], (sb, cb));
        let sin_a = trig_from_known(&mut g, Func::Sin, &[0], &known).unwrap_or(sab);
        let cos_a = trig_from_known(&mut g, Func::Cos, &[0], &known).unwrap_or(sab);
        let (x, y) = (0.3, -1.1);
        let v = g.eval(&[sin_a, cos_a], &[x, y]);
        // sin((a + b) − b) and cos((a + b) − b): a few roundings of values below 1.
        assert!((v[0] - f64::sin(x)).abs() < 1e-15, "{}", v[0]);
        assert!((v[1] - f64::cos(x)).abs() < 1e-15, "{}", v[1]);
        assert_eq!(trig_from_known(&mut g, Func::Sin, &[2], &known), None);
    }

    #[test]
    fn pairs_of_sine_and_cosine_get_three_cache_slots_each() {
        let mut g = Graph::new();
        let (q1, q2) = (g.var("q1"), g.var("q2"));
        let ids = [g.sin(q1), g.cos(q1), g.sin(q2)];
        let reachable = g.reachable(&ids);
        let pairs = trig_pairs(&g, &reachable, &[]);
        assert_eq!(
            pairs,
            [TrigMemo {
                sin: ids[0],
                cos: ids[1],
                slot: 0
            }]
        );
        // A parameter's angle is computed once per parameter set, not memoised.
        assert!(trig_pairs(&g, &reachable, &[q1]).is_empty());
    }
}
