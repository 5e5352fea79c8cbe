//! The linear-combination pass (`codegen/src/linear.rs`) on whole models: it keeps every
//! term's value and never costs operations, term group by term group (`Derivation::new`
//! keeps a group's rewrite only where it helps; this checks the result against the
//! recursions' own expressions).

use crate::chain;

use camchain_codegen::Derivation;
use camchain_codegen::expr::Id;
use camchain_codegen::model::Model;
use std::path::{Path, PathBuf};

/// Every model file the project ships or tests with: the reference models, the random
/// models compiled by the tests, and the scaling chains.
fn model_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["models", "tests/random_models"] {
        let mut found: Vec<PathBuf> = std::fs::read_dir(root.join(dir))
            .unwrap_or_else(|e| panic!("{dir}: {e}"))
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "ron"))
            .collect();
        found.sort();
        files.extend(found);
    }
    assert!(files.len() >= 8, "model files found: {files:?}");
    files
}

fn load(path: &Path) -> Model {
    camchain_codegen::schema::load_model(path).unwrap_or_else(|e| panic!("{e}"))
}

/// The term groups of a derivation, by name.
fn groups(d: &Derivation) -> Vec<(String, Vec<Id>)> {
    let dy = &d.dynamics;
    let mut out = vec![
        ("M".to_string(), dy.mass.concat()),
        ("F".to_string(), dy.inertial.clone()),
        ("Q".to_string(), dy.applied.clone()),
        (
            "energy".to_string(),
            vec![
                d.energy.kinetic,
                d.energy.gravity,
                d.energy.spring,
                d.energy.damper_power,
            ],
        ),
    ];
    for (k, c) in d.contacts.iter().enumerate() {
        let mut jc = c.jacobian.clone();
        jc.push(c.bias);
        out.push((format!("h{k}"), vec![c.h]));
        out.push((format!("J, c {k}"), jc));
    }
    out.push((
        "M, F, Q".to_string(),
        out[..3].iter().flat_map(|(_, ids)| ids.clone()).collect(),
    ));
    out
}

fn check(name: &str, model: &Model) {
    let before = Derivation::uncollected(model);
    let after = Derivation::new(model);
    let n = model.n();
    for ((group, old), (_, new)) in groups(&before).into_iter().zip(groups(&after)) {
        let (a, b) = (
            before.graph.op_count(&old).total(),
            after.graph.op_count(&new).total(),
        );
        assert!(
            b <= a,
            "{name}: {group}: {a} operations before the pass, {b} after"
        );
        // Same values at a few states: the pass only reassociates sums and pulls factors
        // out, so the two agree to a few ulps of the largest term (values here are
        // O(1..1e3)).
        for s in 0..3 {
            let q: Vec<f64> = (0..n).map(|i| 0.3 + 0.41 * (i + s) as f64).collect();
            let qd: Vec<f64> = (0..n).map(|i| -0.7 + 0.23 * (i * s) as f64).collect();
            let x = before.eval(&old, 0.3, &q, &qd);
            let y = after.eval(&new, 0.3, &q, &qd);
            for (u, v) in x.iter().zip(&y) {
                assert!(
                    (u - v).abs() <= 1e-12 * (1.0 + u.abs()),
                    "{name}: {group}: {u} before, {v} after"
                );
            }
        }
    }
}

#[test]
fn the_pass_keeps_values_and_never_costs_operations_on_the_model_files() {
    for path in model_files() {
        check(&path.display().to_string(), &load(&path));
    }
}

#[test]
fn the_pass_keeps_values_and_never_costs_operations_on_the_scaling_chains() {
    for n in [2, 5, 8] {
        let model =
            camchain_codegen::schema::parse_model(&chain::chain_ron(n), Path::new("chain.ron"))
                .unwrap_or_else(|e| panic!("{e}"));
        check(&format!("chain{n}"), &model);
    }
}
