//! The symbolic derivation, evaluated by its interpreter (no compilation), against the
//! numeric recursive reference on the paper chain and a spatial tree with a branch.

// The hand-built models shared with the codegen tests (one source of truth).
#[path = "../../../codegen/tests/common/mod.rs"]
mod models;

use camchain_codegen::Derivation;
use camchain_codegen::model::Model;
use camchain_reference::NumericModel;
use camchain_runtime::Dynamics;

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// |a − b| ≤ tol·max(1, |b|): both routes are O(1)-conditioned double-precision sums of at
/// most a few hundred terms, so rounding differences stay near 1e-14; 1e-12 leaves margin.
fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-12 * b.abs().max(1.0),
        "{what}: {a:e} vs {b:e}"
    );
}

fn compare(model: Model) {
    let d = Derivation::new(&model);
    let numeric = NumericModel::new(model.clone());
    let n = model.n();
    let mut seed = 12345u64;
    for _ in 0..100 {
        let q: Vec<f64> = (0..n).map(|_| 3.0 * lcg(&mut seed) - 1.5).collect();
        let qd: Vec<f64> = (0..n).map(|_| 4.0 * lcg(&mut seed) - 2.0).collect();
        let mut m = vec![0.0; n * n];
        numeric.mass_matrix(&q, &mut m);
        let sym: Vec<f64> = d.eval(&d.dynamics.mass.concat(), 0.0, &q, &qd);
        for (k, (a, b)) in sym.iter().zip(&m).enumerate() {
            close(*a, *b, &format!("M[{k}]"));
        }
        let mut f = vec![0.0; n];
        numeric.inertial_forces(&q, &qd, &mut f);
        for (a, b) in d.eval(&d.dynamics.inertial, 0.0, &q, &qd).iter().zip(&f) {
            close(*a, *b, "F");
        }
        numeric.applied_forces(0.0, &q, &qd, &mut f);
        for (a, b) in d.eval(&d.dynamics.applied, 0.0, &q, &qd).iter().zip(&f) {
            close(*a, *b, "Q");
        }
        for (k, c) in d.contacts.iter().enumerate() {
            let r = numeric.contact_kinematics(&q, &qd, k);
            let rel = &c.relative;
            let ids = [
                rel.xy[0],
                rel.xy[1],
                rel.convective[0],
                rel.convective[1],
                c.force_scale,
                c.curvature,
                c.h,
                c.bias,
            ];
            let mut h = vec![0.0; d.contacts.len()];
            numeric.constraint(&q, &mut h);
            let mut bias = vec![0.0; d.contacts.len()];
            numeric.constraint_bias(&q, &qd, &mut bias);
            let want = [
                r.x,
                r.y,
                r.conv1,
                r.conv2,
                r.geometry.force_scale,
                r.geometry.curvature,
                h[k],
                bias[k],
            ];
            for (a, b) in d.eval(&ids, 0.0, &q, &qd).iter().zip(want) {
                close(*a, b, "contact");
            }
            let j1: Vec<_> = rel.columns.iter().map(|c| c[0]).collect();
            let j2: Vec<_> = rel.columns.iter().map(|c| c[1]).collect();
            for (a, b) in d.eval(&j1, 0.0, &q, &qd).iter().zip(&r.j1) {
                close(*a, *b, "J1");
            }
            for (a, b) in d.eval(&j2, 0.0, &q, &qd).iter().zip(&r.j2) {
                close(*a, *b, "J2");
            }
        }
    }
}

#[test]
fn paper_chain_interpreted_equals_numeric() {
    compare(models::paper_concave());
}

#[test]
fn spatial_tree_interpreted_equals_numeric() {
    compare(models::spatial_tree());
}
