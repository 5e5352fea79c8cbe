//! Turning a 3 × 3 block of an articulated inertia into the parent's frame, R M Rᵀ, with as
//! few operations as the joint's rotation allows (docs/method.md §14.1).

use crate::expr::{Graph, Id};
use crate::kinematics::{BodyKinematics, Rotation, V3, vec3};

/// The constant turn P about coordinate axis n taking e_k (k = n + 1) to a unit axis in the
/// plane normal to n: cos φ, sin φ, cos 2φ / 2 and sin 2φ / 2, from the axis's components,
/// so that a turn by π/4 has cos 2φ exactly 0.
type ConstantTurn = [f64; 4];

/// (n, k, P) for a unit axis with one zero component n (and not a coordinate axis).
fn in_coordinate_plane(axis: [f64; 3]) -> Option<(usize, usize, ConstantTurn)> {
    let n = (0..3).find(|&n| axis[n] == 0.0)?;
    let (i, j) = ((n + 1) % 3, (n + 2) % 3);
    let (a, b) = (axis[i], axis[j]);
    if a == 0.0 || b == 0.0 {
        return None;
    }
    let r2 = a * a + b * b;
    let r = r2.sqrt();
    Some((n, i, [a / r, b / r, 0.5 * (a * a - b * b) / r2, a * b / r2]))
}

/// R M Rᵀ for R the turn by `angle` about a unit `axis` in a coordinate plane (`None` for
/// another axis): R = P R_k Pᵀ, so three turns about coordinate axes (Pᵀ M P, then R_k,
/// then P), 48 operations for a symmetric M and 78 for a general one against 75 and 90
/// through R's entries.
pub(super) fn rotate_in_coordinate_plane(
    g: &mut Graph,
    m: &[V3; 3],
    axis: [f64; 3],
    angle: Id,
    symmetric: bool,
) -> Option<[V3; 3]> {
    let (n, k, [c, s, c2, s2]) = in_coordinate_plane(axis)?;
    let constant = |g: &mut Graph, x: f64| g.constant(x);
    let (cp, sp, c2p, s2p) = (
        constant(g, c),
        constant(g, s),
        constant(g, c2),
        constant(g, s2),
    );
    let (minus_sp, minus_s2p) = (constant(g, -s), constant(g, -s2));
    let back = turn_in_plane(g, m, n, (cp, minus_sp), (c2p, minus_s2p), symmetric);
    let (cq, sq) = (g.cos(angle), g.sin(angle));
    let turned = rotate_in_plane(g, &back, k, (cq, sq), symmetric);
    Some(turn_in_plane(
        g,
        &turned,
        n,
        (cp, sp),
        (c2p, s2p),
        symmetric,
    ))
}

/// R M Rᵀ for the child's joint rotation (the upper triangle only, mirrored, when M is
/// symmetric).
pub(super) fn rotate(
    g: &mut Graph,
    child: &BodyKinematics,
    m: &[V3; 3],
    symmetric: bool,
) -> [V3; 3] {
    if child.relative == crate::kinematics::Rotation::Identity {
        return *m;
    }
    let r = child.relative.matrix(g);
    if let Some((k, c, s)) = plane_rotation(g, &r) {
        return rotate_in_plane(g, m, k, (c, s), symmetric);
    }
    if let Rotation::Axis { axis, angle } = child.relative
        && let Some(turned) = rotate_in_coordinate_plane(g, m, axis, angle, symmetric)
    {
        return turned;
    }
    let rm: Vec<V3> = (0..3)
        .map(|a| [0, 1, 2].map(|j| vec3::dot(g, r[a], [m[0][j], m[1][j], m[2][j]])))
        .collect();
    let mut out = *m;
    for a in 0..3 {
        for b in 0..3 {
            if symmetric && b < a {
                continue;
            }
            let e = vec3::dot(g, rm[a], r[b]);
            out[a][b] = e;
            if symmetric {
                out[b][a] = e;
            }
        }
    }
    out
}

/// (k, c, s) when `r` turns about coordinate axis k only: rows i = k + 1 and j = k + 2
/// (mod 3) hold [[c, −s], [s, c]] in columns i, j, and row and column k are e_k.
pub(super) fn plane_rotation(g: &mut Graph, r: &[V3; 3]) -> Option<(usize, Id, Id)> {
    let (zero, one) = (g.zero(), g.one());
    (0..3).find_map(|k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let (c, s) = (r[i][i], r[j][i]);
        let fixed = r[k][k] == one && [r[k][i], r[k][j], r[i][k], r[j][k]] == [zero; 4];
        (fixed && r[j][j] == c && r[i][j] == g.neg(s)).then_some((k, c, s))
    })
}

/// R M Rᵀ for R turning by φ (cos φ = c, sin φ = s) in the plane (i, j) of coordinate axis
/// k, by the double angle: writing M's (i, j) block p 1 + m D + u E + v J (D = diag(1, −1),
/// E = [[0, 1], [1, 0]], J = [[0, 1], [−1, 0]]), the rotation leaves p and v and turns
/// (m, u) by 2φ; the entries between k and the plane turn by φ. 16 operations for a
/// symmetric M and 26 for a general one, against 27 and 36 as two matrix products, and 3
/// per joint for cos 2φ / 2 and sin 2φ / 2, shared by the three blocks of an inertia.
pub(super) fn rotate_in_plane(
    g: &mut Graph,
    m: &[V3; 3],
    k: usize,
    (c, s): (Id, Id),
    symmetric: bool,
) -> [V3; 3] {
    let half = g.constant(0.5);
    let ss = g.mul(s, s);
    let c2 = g.sub(half, ss); // cos 2φ / 2
    let s2 = g.mul(c, s); // sin 2φ / 2
    turn_in_plane(g, m, k, (c, s), (c2, s2), symmetric)
}

/// [`rotate_in_plane`] with cos 2φ / 2 and sin 2φ / 2 given.
fn turn_in_plane(
    g: &mut Graph,
    m: &[V3; 3],
    k: usize,
    (c, s): (Id, Id),
    (c2, s2): (Id, Id),
    symmetric: bool,
) -> [V3; 3] {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let half = g.constant(0.5);
    let (a, b, d, e) = (m[i][i], m[i][j], m[j][i], m[j][j]);
    let dm = g.sub(a, e); // 2 m
    let su = g.add(b, d); // 2 u
    let (x, y) = (g.mul(dm, c2), g.mul(su, s2));
    let m2 = g.sub(x, y); // m′ = m cos 2φ − u sin 2φ
    let (x, y) = (g.mul(dm, s2), g.mul(su, c2));
    let u2 = g.add(x, y); // u′ = m sin 2φ + u cos 2φ
    let sum = g.add(a, e);
    let p = g.mul(half, sum);
    let mut out = *m;
    out[i][i] = g.add(p, m2);
    out[j][j] = g.sub(p, m2);
    if symmetric {
        out[i][j] = u2;
        out[j][i] = u2;
    } else {
        let diff = g.sub(b, d);
        let v = g.mul(half, diff);
        out[i][j] = g.add(u2, v);
        out[j][i] = g.sub(u2, v);
    }
    // Column k: (R m)_{·k}; row k: (m Rᵀ)_{k·}.
    let turn = |g: &mut Graph, x: Id, y: Id| -> (Id, Id) {
        let (cx, sy) = (g.mul(c, x), g.mul(s, y));
        let (sx, cy) = (g.mul(s, x), g.mul(c, y));
        (g.sub(cx, sy), g.add(sx, cy))
    };
    (out[i][k], out[j][k]) = turn(g, m[i][k], m[j][k]);
    if symmetric {
        (out[k][i], out[k][j]) = (out[i][k], out[j][k]);
    } else {
        (out[k][i], out[k][j]) = turn(g, m[k][i], m[k][j]);
    }
    out
}
