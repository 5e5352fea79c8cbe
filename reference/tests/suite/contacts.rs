//! Every contact kind on every chain (the scenes of `codegen/tests/common/scenes.rs`): the
//! numeric reference (full recursions, jets of the profile, a global search for the contact
//! point, the three-dimensional rotation of a flat face) against the code generator's
//! derivation run by the interpreter, at random states near the cam; and the reference's
//! own J and c against finite differences of its h.

#[path = "../../../codegen/tests/common/scenes.rs"]
mod scenes;

use camchain_codegen::Derivation;
use camchain_codegen::expr::Id;
use camchain_codegen::schema::parse_model;
use camchain_reference::NumericModel;
use camchain_runtime::Dynamics;
use scenes::{KINDS, Rng, chains, scene, state};
use std::path::Path;

/// The interpreter's outputs in the reference's order: h, J, c, then the geometry.
fn derived(d: &Derivation, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let c = &d.contacts[0];
    let r = &c.relative;
    let mut ids: Vec<Id> = vec![c.h];
    ids.extend(&c.jacobian);
    ids.push(c.bias);
    ids.extend(c.position);
    ids.extend(c.cam_point);
    ids.extend(r.point);
    ids.extend(c.normal);
    ids.extend(r.axis);
    ids.extend([c.force_scale, c.parameter, c.curvature, c.sliding]);
    ids.extend(r.xy);
    ids.extend(r.convective);
    ids.extend(r.columns.iter().flatten());
    // A surface's height there and the follower point's Z, J3 and convective term (written
    // for a surface only: 0 otherwise, as the reference gives them).
    if c.cam_height.is_some() {
        ids.extend(c.cam_height);
        ids.extend([r.height, r.height_convective]);
        ids.extend(&r.height_columns);
    }
    let mut v = d.eval(&ids, 0.0, q, qd);
    if c.cam_height.is_none() {
        v.extend(std::iter::repeat_n(0.0, 3 + r.height_columns.len()));
    }
    // The direction of the follower's own joint, normalised as the outputs give it.
    let dir = d.eval(&r.direction, 0.0, q, qd);
    let norm = dir.iter().map(|x| x * x).sum::<f64>().sqrt();
    v.extend(dir.iter().map(|x| x / norm));
    v
}

/// The same numbers from the reference.
fn numeric(m: &NumericModel, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let n = q.len();
    let (mut h, mut j, mut c) = ([0.0], vec![0.0; n], [0.0]);
    m.constraint(q, &mut h);
    m.constraint_jacobian(q, &mut j);
    m.constraint_bias(q, qd, &mut c);
    let k = m.contact_kinematics(q, qd, 0);
    let g = k.geometry;
    let mut v = vec![h[0]];
    v.extend(&j);
    v.push(c[0]);
    v.extend(g.position);
    v.extend([g.x, g.y]);
    v.extend(g.follower);
    v.extend(g.normal);
    v.extend(g.axis);
    v.extend([g.force_scale, g.parameter, g.curvature, g.sliding_speed]);
    v.extend([k.x, k.y, k.conv1, k.conv2]);
    for i in 0..n {
        v.extend([k.j1[i], k.j2[i]]);
    }
    v.extend([g.z, k.z, k.conv3]);
    v.extend(&k.j3);
    v.extend(g.direction);
    v
}

#[test]
fn every_kind_agrees_with_the_interpreted_derivation() {
    let mut rng = Rng(0x5851_f42d_4c95_7f2d);
    let mut worst = 0.0f64;
    for kind in &KINDS {
        for chain in chains(kind) {
            let model = parse_model(&scene(kind, chain), Path::new("scene.ron")).expect("parses");
            let d = Derivation::new(&model);
            let reference = NumericModel::new(model);
            // The polar and parametric test profiles are closed curves of period 2π: their
            // contact point's parameter is defined modulo 2π.
            let period = (!kind.profile.starts_with("profile")).then_some(std::f64::consts::TAU);
            // h, J (n), c, position (3), cam point (2), follower, normal, axis (3 each), force
            // scale: the parameter comes next.
            let parameter = 1 + d.symbols.q.len() + 1 + 3 + 2 + 3 * 3 + 1;
            for _ in 0..20 {
                let (q, qd) = state(kind, chain, &mut rng);
                let (mut a, b) = (derived(&d, &q, &qd), numeric(&reference, &q, &qd));
                if let Some(p) = period {
                    a[parameter] = b[parameter]
                        + (a[parameter] - b[parameter] + 0.5 * p).rem_euclid(p)
                        - 0.5 * p;
                }
                for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                    // Independent routes to quantities of order 0.001 … 10: rounding of a
                    // few hundred operations, and a contact parameter each solves to about
                    // 1e-15 of its range: 1e-9 absolute plus 1e-9 relative.
                    let error = (x - y).abs();
                    worst = worst.max(error / (1e-3 + y.abs()));
                    assert!(
                        error < 1e-9 * (1.0 + y.abs()),
                        "{} on {chain:?}, q = {q:?}, qd = {qd:?}: value {i}: interpreter {x} vs \
                         reference {y}",
                        kind.name
                    );
                }
            }
        }
    }
    eprintln!("largest relative difference interpreter vs reference: {worst:.1e}");
}

#[test]
fn the_reference_jacobian_and_convective_term_match_its_own_differences() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for kind in &KINDS {
        for chain in chains(kind) {
            let model = parse_model(&scene(kind, chain), Path::new("scene.ron")).expect("parses");
            let m = NumericModel::new(model);
            let n = m.info().n();
            for _ in 0..5 {
                let (q, qd) = state(kind, chain, &mut rng);
                let h = |x: &[f64]| {
                    let mut h = [0.0];
                    m.constraint(x, &mut h);
                    h[0]
                };
                let along = |dir: &[f64], s: f64| -> Vec<f64> {
                    q.iter().zip(dir).map(|(a, b)| a + s * b).collect()
                };
                let mut j = vec![0.0; n];
                m.constraint_jacobian(&q, &mut j);
                for (k, &jk) in j.iter().enumerate() {
                    let e: Vec<f64> = (0..n).map(|i| f64::from(u8::from(i == k))).collect();
                    let step = 1e-6;
                    let fd = (h(&along(&e, step)) - h(&along(&e, -step))) / (2.0 * step);
                    // As in the generator's test: 1e-7 on entries of order 0.1 … 1 (the
                    // reference's golden-section search leaves 1e-9 of the range, polished
                    // by Newton).
                    assert!((jk - fd).abs() < 1e-7, "{}: J[{k}] {jk} vs {fd}", kind.name);
                }
                // A grid's third derivatives jump across its knot lines: as in the
                // generator's test, c is compared only where the follower's point (with
                // 1.5 mm for a ball's foot) crosses none.
                let point = |s: f64| {
                    let k = m.contact_kinematics(&along(&qd, s), &qd, 0);
                    [k.x, k.y]
                };
                if kind.crosses_a_knot(point(-2e-4), point(2e-4)) {
                    continue;
                }
                let mut c = [0.0];
                m.constraint_bias(&q, &qd, &mut c);
                let plain = |tau: f64| {
                    (h(&along(&qd, tau)) - 2.0 * h(&along(&qd, 0.0)) + h(&along(&qd, -tau)))
                        / (tau * tau)
                };
                // Richardson from τ = 2e-4 and 1e-4: 1e-6 relative (see the generator's test).
                let fd = (4.0 * plain(1e-4) - plain(2e-4)) / 3.0;
                assert!(
                    (c[0] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                    "{} on {chain:?}: c {} vs {fd}",
                    kind.name,
                    c[0]
                );
            }
        }
    }
}
