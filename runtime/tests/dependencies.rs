//! The runtime a user's program links stays lean: its normal dependencies are nalgebra (with
//! what nalgebra itself needs) and thiserror, and the `camchain` facade adds nothing but
//! itself. Asserted on `cargo tree` of the workspace, so that a dependency cannot creep back
//! into every user binary unnoticed (before the crates were split, a 7-line program that
//! simulated a model compiled about 70 crates: clap, plotters, png, dejavu, indicatif, syn,
//! ron, …).

use std::collections::BTreeSet;
use std::process::Command;

/// What nalgebra 0.35 (without default features, `std` only) links.
const NALGEBRA: &[&str] = &[
    "nalgebra",
    "approx",
    "bytemuck",
    "matrixmultiply",
    "num-complex",
    "num-integer",
    "num-rational",
    "num-traits",
    "rawpointer",
    "safe_arch",
    "simba",
    "typenum",
    "wide",
];

/// Crates that must never reach a program that only simulates: the code generator and its
/// parsers and formatter, and the command line's dependencies.
const FORBIDDEN: &[&str] = &[
    "camchain-codegen",
    "camchain-build",
    "camchain-reference",
    "camchain-models",
    "camchain-cli",
    "ron",
    "serde",
    "prettyplease",
    "clap",
    "plotters",
    "png",
    "dejavu",
    "indicatif",
    "proptest",
];

/// Package names in `cargo tree -p <package> -e <edges>` (offline: the lock file decides).
fn tree(package: &str, edges: &str) -> BTreeSet<String> {
    tree_with(package, edges, &[])
}

/// [`tree`] with `features` of the package on; `"-default"` among them turns the default
/// features off.
fn tree_with(package: &str, edges: &str, features: &[&str]) -> BTreeSet<String> {
    let defaults_off = features.contains(&"-default");
    let features: Vec<&str> = features
        .iter()
        .copied()
        .filter(|f| *f != "-default")
        .collect();
    let features = features.join(",");
    let mut command = Command::new(env!("CARGO"));
    command.args(["tree", "--offline", "-p", package, "-e", edges]);
    if defaults_off {
        command.arg("--no-default-features");
    }
    if !features.is_empty() {
        command.args(["--features", &features]);
    }
    let output = command
        .args(["--prefix", "none", "--format", "{p}"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(
        output.status.success(),
        "cargo tree -p {package} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

fn expected(own: &[&str]) -> BTreeSet<String> {
    own.iter()
        .chain(NALGEBRA)
        .chain(&["thiserror"])
        .map(|s| s.to_string())
        .collect()
}

#[test]
fn the_runtime_links_nalgebra_and_thiserror_only() {
    let linked = tree("camchain-runtime", "normal,no-proc-macro");
    assert_eq!(linked, expected(&["camchain-runtime"]));
}

/// Without its `engine` feature the runtime is the `Dynamics` contract and what generated code
/// calls: no nalgebra, so that a model compiled from Python builds without waiting for it
/// (with it, nalgebra's chain was most of a cold `camchain.compile`).
#[test]
fn the_contract_alone_links_thiserror_only() {
    let linked = tree_with("camchain-runtime", "normal,no-proc-macro", &["-default"]);
    let want: BTreeSet<String> = ["camchain-runtime", "thiserror"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(linked, want);
}

#[test]
fn the_facade_adds_only_itself() {
    let linked = tree("camchain", "normal,no-proc-macro");
    assert_eq!(linked, expected(&["camchain", "camchain-runtime"]));
}

#[test]
fn no_code_generator_parser_or_command_line_dependency_reaches_a_program() {
    // With the proc-macro crates (thiserror's derive, compiled for the host only) as well.
    for package in ["camchain-runtime", "camchain"] {
        let all = tree(package, "normal");
        let found: Vec<&&str> = FORBIDDEN
            .iter()
            .filter(|name| all.contains(**name))
            .collect();
        assert!(found.is_empty(), "{package} depends on {found:?}");
    }
}

/// What the reference adds to a program (the facade's `reference` feature): itself and the
/// model crate with the model file's readers (serde; the RON reader and the parser of profile
/// expressions are the model crate's own), never the emitter (camchain-codegen,
/// prettyplease): 20 crates (27 while the model crate read RON with ron, which brought ron,
/// bitflags, typeid and unicode-ident, and parsed expressions with syn, quote and proc-macro2).
#[test]
fn the_reference_feature_adds_the_model_file_but_no_emitter() {
    let linked = tree_with("camchain", "normal,no-proc-macro", &["reference"]);
    let model_file = [
        "camchain",
        "camchain-runtime",
        "camchain-reference",
        "camchain-model",
        "serde",
        "serde_core",
    ];
    assert_eq!(linked, expected(&model_file));
    assert_eq!(linked.len(), 20);
}
