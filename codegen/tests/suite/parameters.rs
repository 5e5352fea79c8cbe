//! Parameters cost nothing where they are folded (issue 12 §1): every built-in model, whose
//! numbers are now parameters, generates with every parameter folded
//! (`ParameterMode::FoldAll`) exactly the operation counts of the same model with the numbers
//! written in place. `plain_models/` holds those files as they were before the models
//! declared parameters (the repository's model files of that commit, unchanged).
//!
//! The paper model's folded code is moreover under review as a golden copy
//! (`build/tests/golden/paper_concave_folded.rs`, checked by `build/tests/suite/golden.rs`); when
//! parameters came in, every one of its generated functions was byte-identical to the
//! golden copy of the model with its numbers written in place.

use camchain_codegen::schema::{parse_model, parse_model_with};
use camchain_codegen::{Generated, ParameterMode, emit};
use std::path::Path;

fn generate(text: &str, file: &str, mode: ParameterMode) -> Generated {
    let model =
        parse_model_with(text, Path::new(file), &[], mode).unwrap_or_else(|e| panic!("{e}"));
    emit::generate(&model, file).unwrap_or_else(|e| panic!("{e}"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

const MODELS: [&str; 7] = [
    "double_pendulum",
    "driven_concave",
    "driven_convex",
    "paper_concave",
    "paper_convex",
    "paper_convex_text",
    "spatial_arm",
];

#[test]
fn folded_parameters_keep_the_operation_counts_of_numbers_written_in_place() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in MODELS {
        let with_parameters = read(&root.join(format!("../models/{name}.ron")));
        assert!(
            with_parameters.contains("parameters: ["),
            "{name} declares parameters"
        );
        let plain = read(&root.join(format!("tests/plain_models/{name}.ron")));
        assert!(
            !plain.contains("parameters: ["),
            "{name}: the plain copy has none"
        );
        let folded = generate(&with_parameters, name, ParameterMode::FoldAll);
        let written = generate(&plain, name, ParameterMode::AsDeclared);
        assert_eq!(folded.op_counts, written.op_counts, "{name}");
        // Only the model's own numbers differ where an expression of parameters rounds
        // differently from the decimal written (the double pendulum's m l²/12).
        let model = parse_model(&plain, Path::new(name)).expect("valid");
        let total: usize = written.op_counts.iter().map(|(_, c)| c.total()).sum();
        println!(
            "{name}: {} functions, {total} operations, equal folded and written in place ({} bodies)",
            written.op_counts.len(),
            model.n()
        );
    }
}

#[test]
fn parameters_read_at_run_time_add_only_what_folding_removed() {
    // As declared, a paper model reads its springs, dampers and start at run time. Its
    // right-hand side then costs what the folded one costs except where a folded value was
    // special: a damping of exactly 1 multiplies for free (c·q̇ → q̇), and a stored c does not;
    // the spring rest of 0 stays folded. Three multiplications in Q (and in the damper
    // power), nothing anywhere else.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = read(&root.join("../models/paper_concave.ron"));
    let declared = generate(&text, "paper_concave", ParameterMode::AsDeclared);
    let folded = generate(&text, "paper_concave", ParameterMode::FoldAll);
    for ((name, a), (other, b)) in declared.op_counts.iter().zip(&folded.op_counts) {
        assert_eq!(name, other);
        let extra = a.total() as i64 - b.total() as i64;
        let expected = match name.as_str() {
            "applied_forces" | "equations" | "velocity_terms" | "damper_power" => 3,
            _ => 0,
        };
        assert_eq!(extra, expected, "{name}: {a} against {b}");
    }
    let derive = declared.op_counts.last().expect("a row");
    assert_eq!(
        derive.0, "derive",
        "the once-per-parameter-set work is counted apart"
    );
}
