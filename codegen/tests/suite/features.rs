//! Only the work a scene needs (issue 4 §3): starting from a model with gravity, joint
//! springs, joint dampers, a cam contact and a driven joint, each feature is removed in turn
//! (by editing the model file's text). The functions the feature feeds must lose operations,
//! the others must keep exactly theirs, and the emitted code of the functions it fed must no
//! longer mention it. The model is compiled with every parameter folded (its numbers in
//! place), so that a feature's constants show in the code as they would in a user's file.

use camchain_codegen::ParameterMode;
use camchain_codegen::emit::{Generated, generate};
use camchain_codegen::schema::parse_model_with;
use std::collections::BTreeMap;
use std::path::Path;

/// `models/driven_concave.ron` (springs, dampers, contact, driven q1) with gravity added.
fn full_text() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/driven_concave.ron");
    let text = std::fs::read_to_string(path).expect("the model file is readable");
    edit(
        &text,
        "gravity: (0.0, 0.0, 0.0),",
        "gravity: (0.0, -9.81, 0.0),",
    )
}

/// Replaces `from` (which must occur) by `to`.
fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "fixture edit: `{from}` not found");
    text.replace(from, to)
}

fn generate_text(text: &str) -> Generated {
    let model = parse_model_with(text, Path::new("features.ron"), &[], ParameterMode::FoldAll)
        .unwrap_or_else(|e| panic!("{e}"));
    generate(&model, "features.ron").expect("generates")
}

fn totals(g: &Generated) -> BTreeMap<String, usize> {
    g.op_counts
        .iter()
        .map(|(name, c)| (name.clone(), c.total()))
        .collect()
}

/// The text of one generated function (from its `fn` line to the next function).
fn function<'a>(g: &'a Generated, name: &str) -> &'a str {
    let start = g
        .code
        .find(&format!("fn {name}("))
        .unwrap_or_else(|| panic!("function {name} is emitted"));
    let rest = &g.code[start..];
    let end = rest[1..].find("\n    fn ").map_or(rest.len(), |e| e + 1);
    &rest[..end]
}

/// Removing a feature: the `fed` functions lose operations, every other one keeps its count.
fn check_removal(full: &Generated, without: &Generated, fed: &[&str], feature: &str) {
    let (a, b) = (totals(full), totals(without));
    for (name, &before) in &a {
        let after = b.get(name).copied().unwrap_or(0);
        if fed.contains(&name.as_str()) {
            assert!(
                after < before,
                "without {feature}, `{name}` should lose operations: {before} -> {after}"
            );
        } else {
            assert_eq!(
                after, before,
                "without {feature}, `{name}` should be unchanged: {before} -> {after}"
            );
        }
    }
}

#[test]
fn removing_gravity_removes_its_operations_and_constants() {
    let text = full_text();
    let full = generate_text(&text);
    let without = generate_text(&edit(
        &text,
        "gravity: (0.0, -9.81, 0.0),",
        "gravity: (0.0, 0.0, 0.0),",
    ));
    check_removal(
        &full,
        &without,
        &["applied_forces", "equations", "velocity_terms", "energy"],
        "gravity",
    );
    // Q is then springs and dampers only: no trigonometry, no 9.81 anywhere.
    let c = &without
        .op_counts
        .iter()
        .find(|(n, _)| n == "applied_forces");
    assert_eq!(c.map(|(_, c)| c.sin_cos), Some(0));
    // (With gravity, Q needs the sines and cosines of the body angles; g itself is folded
    // into the mass factors, so it is the trigonometry that shows it.)
    let with = full.op_counts.iter().find(|(n, _)| n == "applied_forces");
    assert!(with.is_some_and(|(_, c)| c.sin_cos > 0));
    assert!(!without.code.contains("9.81"), "no gravity constant left");
}

#[test]
fn removing_the_springs_removes_their_operations_and_stiffnesses() {
    let mut text = full_text();
    for (name, k) in [("k2", "15.0"), ("k3", "40.0"), ("k4", "18.0")] {
        text = edit(
            &text,
            &format!("(name: \"{name}\", value: {k},"),
            &format!("(name: \"{name}\", value: 0.0,"),
        );
    }
    let full = generate_text(&full_text());
    let without = generate_text(&text);
    check_removal(
        &full,
        &without,
        &["applied_forces", "equations", "velocity_terms", "energy"],
        "springs",
    );
    for stiffness in ["15.0", "40.0", "18.0"] {
        assert!(function(&full, "applied_forces").contains(stiffness));
        for f in ["applied_forces", "equations", "energy"] {
            assert!(
                !function(&without, f).contains(stiffness),
                "{f} still mentions {stiffness}"
            );
        }
    }
}

#[test]
fn removing_the_dampers_removes_their_operations() {
    let mut text = full_text();
    for name in ["c2", "c3", "c4"] {
        text = edit(
            &text,
            &format!("(name: \"{name}\", value: 1.0,"),
            &format!("(name: \"{name}\", value: 0.0,"),
        );
    }
    let full = generate_text(&full_text());
    let without = generate_text(&text);
    check_removal(
        &full,
        &without,
        &[
            "applied_forces",
            "equations",
            "velocity_terms",
            "damper_power",
        ],
        "dampers",
    );
    // No velocity enters Q any more, and the dissipated power is the constant 0.
    let applied = function(&without, "applied_forces");
    assert!(!applied.contains("qd["), "{applied}");
    assert!(function(&full, "applied_forces").contains("qd["));
    let power = function(&without, "damper_power");
    assert!(!power.contains("qd["), "{power}");
}

#[test]
fn removing_the_contact_empties_the_constraint_functions() {
    let text = full_text();
    let without = edit(
        &text,
        "(marker: \"A\", profile: \"a1*x + a2*x*x + a3*x.powi(3)\"),",
        "",
    );
    let full = generate_text(&text);
    let without = generate_text(&without);
    let fed = [
        "constraint",
        "constraint_jacobian",
        "constraint_bias",
        "constraint_terms",
        "contact_geometry",
        "contact_kinematics_0",
        "position_terms",
        "velocity_terms",
    ];
    check_removal(&full, &without, &fed, "the contact");
    for f in &fed[..5] {
        let body = function(&without, f);
        assert!(!body.contains(".cos()") && !body.contains("q["), "{body}");
    }
    // (The model's description, kept in the module's INFO, still quotes the profile.)
    let functions = without
        .code
        .split_once("impl ::camchain_runtime::Dynamics")
        .map_or("", |(_, f)| f);
    assert!(!functions.contains("0.595"), "no cam profile left");
    assert!(function(&full, "constraint").contains("0.595"));
}

#[test]
fn removing_the_drive_empties_prescribed() {
    let text = full_text();
    let without = edit(
        &text,
        "prescribed: \"-PI/2 + amplitude*(2.0*PI*t/period).sin()\",",
        "",
    );
    let full = generate_text(&text);
    let without = generate_text(&without);
    check_removal(&full, &without, &["prescribed"], "the drive");
    // A sine alone, or with its cosine from one call.
    let sine = |body: &str| body.contains(".sin()") || body.contains("sin_cos(");
    let body = function(&without, "prescribed");
    assert!(!body.contains("0.45") && !sine(body), "{body}");
    assert!(sine(function(&full, "prescribed")));
}
