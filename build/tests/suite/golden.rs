//! The generated source of `paper_concave` is checked in and must match what the generator
//! writes today, byte for byte, so that every change to the emitted code shows in a diff
//! under review: `tests/golden/paper_concave.rs` as the file declares its parameters (seven
//! read at run time) and `tests/golden/paper_concave_folded.rs` with every parameter folded
//! (`ParameterMode::FoldAll`: the code as if the numbers were written in place); and that of
//! `cycloidal_roller`, `tests/golden/cycloidal_roller.rs`, a cam designed from a motion law
//! (the law's segments as constants and their evaluation, the synthesised profile, a roller's
//! contact parameter solved by Newton); and that of `four_bar`, `tests/golden/four_bar.rs`, a
//! closed loop (the cut pin's two equations as rows of h, J and c, and the loop's points);
//! and `tests/golden/paper_concave_articulated.rs`, the folded paper model with the
//! articulated-body sweeps asked for (`Formulation::Articulated`: `articulated_terms` and
//! `articulated_response` beside the dense functions).
//! After an intended change, regenerate them:
//!
//! ```sh
//! CAMCHAIN_BLESS=1 cargo test -p camchain-build --test suite golden
//! ```
//!
//! and review the diff of `build/tests/golden/` with the change.

use camchain_build::{Formulation, ParameterMode};
use std::path::{Path, PathBuf};

fn golden_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/golden/{name}.rs"))
}

/// The module `compile_models` writes for the built-in paper model, default options but
/// the parameter mode.
fn generated(test: &str, mode: ParameterMode) -> String {
    generated_model("paper_concave", test, mode)
}

/// The module `compile_models` writes for the built-in model `name`.
fn generated_model(name: &str, test: &str, mode: ParameterMode) -> String {
    generated_with(name, test, mode, Formulation::Auto)
}

/// … with the formulation `formulation`.
fn generated_with(name: &str, test: &str, mode: ParameterMode, formulation: Formulation) -> String {
    let out = std::env::temp_dir().join(format!("camchain-golden-{test}-{}", std::process::id()));
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../models/{name}.ron"));
    let compiled = camchain_build::Config::new()
        .out_dir(&out)
        .emit_rerun_if_changed(false)
        .parameters(mode)
        .formulation(formulation)
        .compile_models(&[model])
        .unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(&compiled[0].output).expect("the generated file");
    let _ = std::fs::remove_dir_all(&out);
    text
}

#[test]
fn the_paper_model_generates_its_golden_source() {
    compare_with_golden(
        "paper_concave",
        &generated("compare", ParameterMode::AsDeclared),
    );
}

#[test]
fn the_folded_paper_model_generates_its_golden_source() {
    compare_with_golden(
        "paper_concave_folded",
        &generated("folded", ParameterMode::FoldAll),
    );
}

#[test]
fn the_cam_designed_from_a_law_generates_its_golden_source() {
    compare_with_golden(
        "cycloidal_roller",
        &generated_model("cycloidal_roller", "law", ParameterMode::AsDeclared),
    );
}

#[test]
fn the_four_bar_generates_its_golden_source() {
    compare_with_golden(
        "four_bar",
        &generated_model("four_bar", "loop", ParameterMode::AsDeclared),
    );
}

#[test]
fn the_articulated_paper_model_generates_its_golden_source() {
    compare_with_golden(
        "paper_concave_articulated",
        &generated_with(
            "paper_concave",
            "articulated",
            ParameterMode::FoldAll,
            Formulation::Articulated,
        ),
    );
}

fn compare_with_golden(name: &str, now: &str) {
    let path = golden_path(name);
    if std::env::var("CAMCHAIN_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, now).expect("the golden file is writable");
        return;
    }
    let golden = std::fs::read_to_string(&path).expect("the golden file exists");
    if now != golden {
        let first = now
            .lines()
            .zip(golden.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| now.lines().count().min(golden.lines().count()));
        panic!(
            "the generated code differs from tests/golden/{name}.rs from line {}:\n  now:    \
             {:?}\n  golden: {:?}\nIf the change is intended, run `CAMCHAIN_BLESS=1 cargo test \
             -p camchain-build --test suite golden` and commit the diff.",
            first + 1,
            now.lines().nth(first).unwrap_or("<end of file>"),
            golden.lines().nth(first).unwrap_or("<end of file>"),
        );
    }
}

#[test]
fn the_golden_source_names_its_model_file_relative_to_the_workspace() {
    // Run from the build crate, the model sits at ../models; messages and the header show
    // the path from the workspace root, where `cargo` runs.
    let now = generated("header", ParameterMode::AsDeclared);
    assert!(
        now.starts_with(
            "// Model `paper_concave`, generated by camchain-build from `models/paper_concave.ron`."
        ),
        "{}",
        now.lines().next().unwrap_or_default()
    );
}
