//! Properties of the emitted code: deterministic, parseable, and free of the operations a
//! scene does not need.

use crate::common;

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
    // `q2.cos()` on the variable itself, not as the tail of a name like `angle_q1_q2.cos()`.
    let calls = |text: &str, call: &str| {
        text.match_indices(call)
            .filter(|(at, _)| {
                let before = text[..*at].chars().next_back();
                !before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')
            })
            .count()
    };
    for function in g.code.split("\n    fn ") {
        assert!(calls(function, "q2.cos()") <= 1, "cos q2 once per function");
        assert!(calls(function, "q2.sin()") <= 1, "sin q2 once per function");
    }
}

/// Every model file of the repository, generated with the default options.
/// Every model file's generated code, generated once for the tests that read it.
fn every_model() -> &'static [(String, camchain_codegen::emit::Generated)] {
    static GENERATED: std::sync::OnceLock<Vec<(String, camchain_codegen::emit::Generated)>> =
        std::sync::OnceLock::new();
    GENERATED.get_or_init(generate_every_model)
}

fn generate_every_model() -> Vec<(String, camchain_codegen::emit::Generated)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("models/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    files.sort();
    assert!(files.len() >= 7, "the built-in models");
    files
        .into_iter()
        .map(|path| {
            let generated =
                camchain_codegen::generate_file(&path, &path).unwrap_or_else(|e| panic!("{e}"));
            (path.display().to_string(), generated)
        })
        .collect()
}

/// The `let` names of a generated module.
fn bindings(code: &str) -> Vec<&str> {
    code.lines()
        .filter_map(|l| l.trim_start().strip_prefix("let "))
        .filter_map(|l| l.split([' ', ':']).next())
        .collect()
}

#[test]
fn intermediates_are_named_after_what_they_hold() {
    for (file, g) in every_model() {
        let names = bindings(&g.code);
        let by_id: Vec<&&str> = names
            .iter()
            .filter(|n| {
                n.strip_prefix('x').is_some_and(|rest| {
                    !rest.is_empty() && rest.chars().all(|c| c.is_ascii_digit())
                })
            })
            .collect();
        assert!(by_id.is_empty(), "{file}: named by node id: {by_id:?}");
        // The rest are quantities (`acc_body3_y`, `m_q1_q2`, `s_q1_q2`, …) or the k-th
        // unnamed term of one (`a_arm_q2_x_t1`); the latter stay a small minority. The
        // subexpressions of a user's profile and of its symbolic derivatives (`face_dr_t3`,
        // `roller_ddcx_t1`) have no meaning of their own: they are counted apart.
        let profile_terms = names
            .iter()
            .filter(|n| is_term_name(n) && is_profile_term(n))
            .count();
        let terms = names.iter().filter(|n| is_term_name(n)).count() - profile_terms;
        assert!(
            terms * 5 <= names.len() - profile_terms,
            "{file}: {terms} of {} bindings are terms of a named quantity",
            names.len() - profile_terms
        );
    }
}

/// `<quantity>_t<k>`.
/// A term of a profile's value or derivatives (`<contact>_r`, `_dr`, `_ddr` of a polar one,
/// `_cx`, `_dcx`, `_ddcx` … of any curve).
fn is_profile_term(name: &str) -> bool {
    let Some((stem, _)) = name.rsplit_once("_t") else {
        return false;
    };
    let stem = stem.trim_start_matches("neg_");
    [
        "_r", "_dr", "_ddr", "_cx", "_cy", "_dcx", "_dcy", "_ddcx", "_ddcy", "_tx", "_ty",
    ]
    .iter()
    .any(|suffix| stem.ends_with(suffix))
}

fn is_term_name(name: &str) -> bool {
    name.rsplit_once("_t")
        .is_some_and(|(_, k)| !k.is_empty() && k.chars().all(|c| c.is_ascii_digit()))
}

#[test]
fn section_comments_name_the_terms_below_them() {
    // The energy expressions are only needed by `energy`: no other function's bindings may
    // sit under that heading (the trigonometric rewriting once left M and F under it).
    for (file, g) in every_model() {
        // The methods of the `Dynamics` implementation (free functions such as `derive`,
        // which computes the parameters' share of every term once, keep the headings of the
        // terms they serve).
        let start = g
            .code
            .find("impl rt::Dynamics for Model {")
            .expect("the impl");
        let end = start + g.code[start..].find("\n}\n").expect("its end");
        for function in g.code[start..end].split("\n    fn ").skip(1) {
            let name = function.split('(').next().unwrap_or_default();
            if name != "energy" {
                assert!(
                    !function.contains("// energy"),
                    "{file}: {name} has an energy section"
                );
            }
        }
    }
}

#[test]
fn functions_called_per_step_do_not_allocate() {
    // Everything the runtime calls lives in `impl rt::Dynamics for Model` and the contact
    // helpers after it; only the static description (`INFO`, built once) allocates.
    for (file, g) in every_model() {
        let (_, functions) = g
            .code
            .split_once("impl rt::Dynamics for Model")
            .expect("the Dynamics impl");
        for token in [
            "vec!",
            "Vec::",
            "to_vec",
            "Box::",
            "String",
            "to_string",
            "format!",
            "collect",
        ] {
            assert!(
                !functions.contains(token),
                "{file}: `{token}` in the generated functions"
            );
        }
    }
}

/// A model name that is no Rust identifier runs on the numeric path (the schema's tests) but
/// names no module: the build refuses it, at the `name` field when the file gives one (its
/// line) and unlocated when the name comes from the file's stem.
#[test]
fn the_build_refuses_a_model_name_that_names_no_module() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let text = std::fs::read_to_string(dir.join("double_pendulum.ron")).expect("the model");
    let options = camchain_codegen::EmitOptions::default();
    let keyword = text.replace("name: \"double_pendulum\"", "name: \"fn\"");
    assert_ne!(keyword, text, "the edit applies");
    let line = 1 + keyword
        .lines()
        .position(|l| l.contains("name: \"fn\""))
        .expect("the name's line");
    let path = std::path::Path::new("models/double_pendulum.ron");
    let e = match camchain_codegen::generate_source(&keyword, path, &options) {
        Ok(_) => panic!("`fn` names no module"),
        Err(e) => e,
    };
    assert_eq!((e.field.as_str(), e.line), ("name", line), "{e}");
    assert!(e.message.contains("not a valid Rust identifier"), "{e}");

    let unnamed: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("name: \"double_pendulum\""))
        .collect::<Vec<_>>()
        .join("\n");
    let stem = std::path::Path::new("dir/some chain-v2.ron");
    let e = match camchain_codegen::generate_source(&unnamed, stem, &options) {
        Ok(_) => panic!("`some chain-v2` names no module"),
        Err(e) => e,
    };
    assert_eq!((e.field.as_str(), e.line), ("name", 0));
    assert!(e.message.contains("some chain-v2"), "{e}");
}

/// A method of 4000 operations or more has its body in a module of its own, compiled as a
/// separate codegen unit (in parallel with the rest); the method calls it with every argument.
/// `tests/random_models/chain16.ron` on the articulated route (its sweeps: about 6900
/// operations) is compiled this way by the build's tests and checked against the numeric
/// recursion there (`tests/suite/random_compiled.rs`); the built-in models stay one module.
#[test]
fn a_large_method_body_gets_a_module_of_its_own() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/random_models/chain16.ron");
    let text = std::fs::read_to_string(&path).expect("the random chain");
    let options = camchain_codegen::EmitOptions {
        formulation: camchain_codegen::Formulation::Articulated,
        ..Default::default()
    };
    let g = camchain_codegen::generate_source(&text, &path, &options).expect("generates");
    assert!(count(&g, "articulated_terms") >= 4000);
    let method = g
        .code
        .split("\n    fn articulated_terms(")
        .nth(1)
        .expect("the method");
    let body =
        &method[method.find('{').expect("its body")..method.find("\n    }").expect("its end")];
    assert_eq!(
        body.split_whitespace().collect::<String>(),
        "{articulated_terms_body::run(self,t,q,qd,cache,out)",
        "the method only calls its body"
    );
    assert!(g.code.contains("mod articulated_terms_body {"));
    assert_eq!(
        g.code.matches("_body::run(").count(),
        g.code.matches("\nmod ").count()
    );
    syn::parse_file(&g.code).expect("valid Rust");
    for (file, g) in every_model() {
        assert!(!g.code.contains("_body::run("), "{file}: a body moved");
    }
}

/// With `fused_multiply_add` (a build for a processor with FMA), sums with a product are
/// written `x.mul_add(y, c)`: the paper's model gets them, its operation counts are those of
/// the plain code (the graph is the same), and the code is valid Rust; without the option
/// (the built-in models' copies) there are none. The values of code written this way are
/// checked where it is compiled: the random models, built with the option, against the
/// numeric recursion (`tests/suite/random_compiled.rs`).
#[test]
fn fused_multiply_add_writes_mul_add_and_counts_the_same() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/paper_concave.ron");
    let text = std::fs::read_to_string(&path).expect("the paper's model");
    let generate = |fused_multiply_add| {
        let options = camchain_codegen::EmitOptions {
            fused_multiply_add,
            ..Default::default()
        };
        camchain_codegen::generate_source(&text, &path, &options).expect("generates")
    };
    let (plain, fused) = (generate(false), generate(true));
    assert!(!plain.code.contains(".mul_add("));
    let velocity = fused
        .code
        .split("\n    fn velocity_terms(")
        .nth(1)
        .expect("the method");
    assert!(
        velocity.contains(".mul_add("),
        "velocity_terms fuses its sums"
    );
    assert_eq!(plain.op_counts, fused.op_counts);
    syn::parse_file(&fused.code).expect("valid Rust");
    for (file, g) in every_model() {
        assert!(!g.code.contains(".mul_add("), "{file}: fused by default");
    }
}

/// M and J of many zeros (A02's 81 × 81 M is 98 % zeros) are written by the fused pair within
/// their rows' extents only, and the model declares the extents (`mass_rows`,
/// `jacobian_rows`): a right-hand side neither clears nor scans n² entries. The paper's
/// models keep whole matrices.
#[test]
fn sparse_matrices_are_written_within_declared_row_extents() {
    let models = every_model();
    let code = |name: &str| {
        &models
            .iter()
            .find(|(file, _)| file.contains(name))
            .unwrap_or_else(|| panic!("{name}"))
            .1
            .code
    };
    let a02 = code("n_four_bar");
    assert!(a02.contains("fn mass_rows(&self)"));
    assert!(a02.contains("fn jacobian_rows(&self)"));
    // Crank i and its coupler (coordinates c_i, p_i adjacent) are M's only coupling.
    let rows: String = a02[a02.find("fn mass_rows").expect("declared")..]
        .split_whitespace()
        .take(20)
        .collect();
    assert!(rows.contains("Some(&[(0,2),(0,2),(2,4),(2,4),"), "{rows}");
    let pair: String = ["fn position_terms", "fn velocity_terms"]
        .iter()
        .map(|f| {
            let start = a02.find(f).expect("the fused pair");
            a02[start..start + a02[start..].find("\n    }").expect("its end")].to_string()
        })
        .collect();
    assert!(!pair.contains(".fill("), "neither array cleared whole");
    let paper = code("paper_concave");
    assert!(!paper.contains("fn mass_rows") && !paper.contains("fn jacobian_rows"));
}
