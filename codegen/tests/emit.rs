//! Properties of the emitted code: deterministic, parseable, and free of the operations a
//! scene does not need.

mod common;

use camchain_codegen::emit::generate;

fn count(g: &camchain_codegen::emit::Generated, function: &str) -> usize {
    g.op_counts
        .iter()
        .find(|(n, _)| n == function)
        .map_or(usize::MAX, |(_, c)| c.total())
}

#[test]
fn same_model_gives_the_same_bytes() {
    let model = common::spatial_tree();
    let a = generate(&model, "models/spatial.ron").expect("generates");
    let b = generate(&model, "models/spatial.ron").expect("generates");
    assert_eq!(a.code, b.code);
    syn::parse_file(&a.code).expect("the emitted module is valid Rust");
}

#[test]
fn a_scene_without_drives_springs_or_gravity_carries_none_of_their_operations() {
    let mut model = common::paper_concave();
    let full = generate(&model, "m.ron").expect("generates");
    assert_eq!(
        count(&full, "prescribed"),
        0,
        "no driven joint: nothing to compute"
    );
    assert!(count(&full, "damper_power") > 0);
    for b in &mut model.bodies {
        b.joint.spring = None;
    }
    model.gravity = [0.0; 3];
    let bare = generate(&model, "m.ron").expect("generates");
    assert_eq!(count(&bare, "damper_power"), 0, "no dampers");
    assert!(
        count(&bare, "applied_forces") == 0,
        "no gravity, no springs: Q is structurally zero"
    );
    assert!(count(&bare, "equations") < count(&full, "equations"));
}

#[test]
fn sines_and_cosines_are_computed_once_per_angle() {
    let model = common::paper_concave();
    let g = generate(&model, "m.ron").expect("generates");
    // Three relative angles (q1, q2, q4) in the body-frame recursion; the absolute angles
    // (q1+q2, q1+q2+q4) are only needed for positions, not in M, F, Q.
    let (_, c) = g
        .op_counts
        .iter()
        .find(|(n, _)| n == "mass_matrix")
        .expect("present");
    assert!(c.sin_cos <= 6, "mass matrix uses {} sin/cos", c.sin_cos);
    for function in g.code.split("\n    fn ") {
        assert!(
            function.matches("q2.cos()").count() <= 1,
            "cos q2 once per function"
        );
        assert!(
            function.matches("q2.sin()").count() <= 1,
            "sin q2 once per function"
        );
    }
}
