//! Every contact kind (knife edge, roller, flat face on explicit, polar and parametric
//! profiles, cams on the ground, on a turning body, on a common moving base, planar and
//! spatial) checked with the interpreter against routes that do not use its formulas:
//!
//! - J against central differences of h (h itself through the contact parameter's Newton
//!   solve, so the envelope theorem behind J is checked, not assumed);
//! - c against the second difference of h along the straight path q + τ q̇ (q̈ = 0);
//! - the follower point's cam-frame J1, J2, J3 and convective terms against differences of
//!   X, Y and Z (Z along the cam's axis: what a cam surface z = f(x, y) will need);
//! - J against the symbolic derivative of h through the implicit contact parameter
//!   (ds*/dq by the implicit-function theorem: a third route, exact to rounding).

use crate::scenes;

use camchain_codegen::Derivation;
use camchain_codegen::expr::Id;
use camchain_codegen::schema::parse_model;
use scenes::{KINDS, Rng, chains, scene, state};
use std::path::Path;

fn shifted(q: &[f64], dir: &[f64], s: f64) -> Vec<f64> {
    q.iter().zip(dir).map(|(a, b)| a + s * b).collect()
}

fn unit(n: usize, k: usize) -> Vec<f64> {
    (0..n).map(|i| if i == k { 1.0 } else { 0.0 }).collect()
}

#[test]
fn every_kind_on_every_chain_agrees_with_finite_differences() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut worst = [0.0f64; 4];
    // The largest |∂Z/∂q| met: the spatial chains must make the J3 check a real one.
    let mut largest_height_column = 0.0f64;
    // States of the grid kinds whose convective terms were compared.
    let mut grid_states = 0;
    for kind in &KINDS {
        for chain in chains(kind) {
            let source = scene(kind, chain);
            let model = parse_model(&source, Path::new("scene.ron"))
                .unwrap_or_else(|e| panic!("{} on {chain:?}: {e}", kind.name));
            let d = Derivation::new(&model);
            let n = model.n();
            let c = &d.contacts[0];
            let r = &c.relative;
            for _ in 0..20 {
                let (q, qd) = state(kind, chain, &mut rng);
                let at = |ids: &[Id], q: &[f64]| d.eval(ids, 0.0, q, &qd);
                let what = format!("{} on {chain:?} at q = {q:?}", kind.name);
                let h0 = at(&[c.h], &q)[0];
                assert!(h0.is_finite(), "{what}: h = {h0}");
                // Central differences with step 1e-6 on lengths of 0.1 m: truncation
                // ~1e-12·|h'''| and rounding ~1e-17/1e-6: 1e-7 absolute on J entries of
                // order 0.1 … 1.
                let step = 1e-6;
                for k in 0..n {
                    let e = unit(n, k);
                    let fd = |f: Id| {
                        (at(&[f], &shifted(&q, &e, step))[0] - at(&[f], &shifted(&q, &e, -step))[0])
                            / (2.0 * step)
                    };
                    let pairs = [
                        (c.jacobian[k], c.h),
                        (r.columns[k][0], r.xy[0]),
                        (r.columns[k][1], r.xy[1]),
                        (r.height_columns[k], r.height),
                    ];
                    let j3 = at(&[r.height_columns[k]], &q)[0];
                    largest_height_column = largest_height_column.max(j3.abs());
                    for (j, (sym, f)) in pairs.into_iter().enumerate() {
                        let (s, f) = (at(&[sym], &q)[0], fd(f));
                        let error = (s - f).abs();
                        worst[j.min(1)] = worst[j.min(1)].max(error);
                        assert!(error < 1e-7, "{what}: ∂/∂q{k} (term {j}): {s} vs {f}");
                    }
                }
                // Second differences along q + τ q̇, Richardson-extrapolated from τ = 2e-4 and
                // 1e-4 (the plain difference errs by τ²/12 times the fourth derivative of h,
                // which reaches 7e4 where the follower point passes close to a turning cam):
                // truncation ~τ⁴, rounding ~1e-17/1e-8 = 1e-9: 1e-6 relative on terms of
                // order 1 … 10.
                // A grid's third derivatives jump across its knot lines: the second
                // differences are compared only where the follower's point (with 1.5 mm for a
                // ball's foot, which lies within ρ sin α of its centre) crosses none.
                if kind.knot_spacing().is_some() {
                    let point = |s: f64| {
                        let p = at(&[r.xy[0], r.xy[1]], &shifted(&q, &qd, s));
                        [p[0], p[1]]
                    };
                    if kind.crosses_a_knot(point(-2e-4), point(2e-4)) {
                        continue;
                    }
                    grid_states += 1;
                }
                let d2 = |f: Id| {
                    let v = |s: f64| at(&[f], &shifted(&q, &qd, s))[0];
                    let plain = |tau: f64| (v(tau) - 2.0 * v(0.0) + v(-tau)) / (tau * tau);
                    (4.0 * plain(1e-4) - plain(2e-4)) / 3.0
                };
                for (j, (sym, f)) in [
                    (c.bias, c.h),
                    (r.convective[0], r.xy[0]),
                    (r.convective[1], r.xy[1]),
                    (r.height_convective, r.height),
                ]
                .into_iter()
                .enumerate()
                {
                    let (s, f) = (at(&[sym], &q)[0], d2(f));
                    let error = (s - f).abs() / (1.0 + f.abs());
                    worst[2] = worst[2].max(error);
                    assert!(error < 1e-6, "{what}: convective term {j}: {s} vs {f}");
                }
            }
        }
    }
    eprintln!(
        "largest differences: J {:.1e}, J1/J2/J3 {:.1e}, convective {:.1e}",
        worst[0], worst[1], worst[2]
    );
    // 2 grid kinds × 4 chains × 20 states, about half of them clear of the knot lines.
    assert!(grid_states >= 40, "only {grid_states} grid states compared");
    // Joint columns of order 0.1 m per radian on the spatial chains' links.
    assert!(
        largest_height_column > 1e-2,
        "no chain moves the follower along the cam's axis: {largest_height_column}"
    );
}

#[test]
fn the_jacobian_equals_the_derivative_through_the_contact_parameter() {
    // J of the implicit kinds is formed by the envelope theorem (∂h/∂s* = 0); differentiating
    // h symbolically through s*(q) (implicit-function theorem) must give the same numbers.
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for kind in KINDS.iter().filter(|k| k.name != "knife on explicit")
    // closed form: no contact parameter
    {
        for chain in chains(kind) {
            let model = parse_model(&scene(kind, chain), Path::new("scene.ron")).expect("parses");
            let mut d = Derivation::new(&model);
            let n = model.n();
            let h = d.contacts[0].h;
            let q_vars = d.symbols.q.clone();
            let through: Vec<Id> = q_vars.iter().map(|&x| d.graph.diff(h, x)).collect();
            let jacobian = d.contacts[0].jacobian.clone();
            for _ in 0..10 {
                let (q, qd) = state(kind, chain, &mut rng);
                let a = d.eval(&through, 0.0, &q, &qd);
                let b = d.eval(&jacobian, 0.0, &q, &qd);
                for k in 0..n {
                    // Two exact formulas, different roundings: 1e-12 on entries ≤ 1.
                    assert!(
                        (a[k] - b[k]).abs() < 1e-12 * (1.0 + b[k].abs()),
                        "{} on {chain:?}: ∂h/∂q{k} {} vs J {}",
                        kind.name,
                        a[k],
                        b[k]
                    );
                }
            }
        }
    }
}
