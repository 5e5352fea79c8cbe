//! The build-script API on real files: what `compile_models` writes, how `Config` changes it,
//! and what a bad model does to a build (one located line per problem, nothing written).

use camchain_build::{Config, EntryPoints};
use std::path::{Path, PathBuf};

/// A fresh directory for one test, with the models it names copied from `models/`.
fn scratch(test: &str, models: &[&str]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("camchain-build-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("models")).expect("a scratch directory");
    for name in models {
        let from = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../models/{name}.ron"));
        std::fs::copy(&from, dir.join(format!("models/{name}.ron"))).expect("a model copy");
    }
    dir
}

fn config(out: &Path) -> Config {
    let mut config = Config::new();
    config.out_dir(out).emit_rerun_if_changed(false);
    config
}

#[test]
fn a_directory_compiles_every_model_in_name_order() {
    let dir = scratch(
        "directory",
        &["paper_convex", "double_pendulum", "paper_concave"],
    );
    let out = dir.join("out");
    let compiled = config(&out)
        .compile_models(&[dir.join("models")])
        .unwrap_or_else(|e| panic!("{e}"));
    let modules: Vec<&str> = compiled.iter().map(|c| c.module.as_str()).collect();
    assert_eq!(
        modules,
        ["double_pendulum", "paper_concave", "paper_convex"]
    );
    for model in &compiled {
        let code = std::fs::read_to_string(&model.output).expect("written");
        assert!(code.contains("pub struct Model"), "{}", model.module);
        assert!(
            code.contains("use ::camchain::runtime as rt;"),
            "the facade's runtime"
        );
        assert!(
            !code.contains("#!["),
            "no inner attribute: include! must accept the file"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_model_stops_the_build_with_located_lines_and_writes_nothing() {
    let dir = scratch("bad", &["paper_concave", "double_pendulum"]);
    let text = std::fs::read_to_string(dir.join("models/paper_concave.ron")).expect("copied");
    let broken = text.replacen("mass: \"m2\",", "mass: -0.5,", 1);
    assert_ne!(broken, text, "the edit applies");
    std::fs::write(dir.join("models/paper_concave.ron"), &broken).expect("written");
    // A second problem in another file: both are reported, not only the first.
    std::fs::write(dir.join("models/typo.ron"), "(bodies: [)").expect("written");
    let out = dir.join("out");
    let error = config(&out)
        .compile_models(&[dir.join("models")])
        .expect_err("a negative mass fails");
    let lines: Vec<String> = error.to_string().lines().map(String::from).collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    // Where the edited value is, found in the text (1-based line and column).
    let line = broken
        .lines()
        .position(|l| l.contains("mass: -0.5"))
        .expect("the edit")
        + 1;
    let column = broken
        .lines()
        .nth(line - 1)
        .and_then(|l| l.find("-0.5"))
        .expect("value")
        + 1;
    let file = dir.join("models/paper_concave.ron");
    assert_eq!(
        lines[0],
        format!(
            "{}:{line}:{column}: bodies[1].mass: mass must be positive and finite, got -0.5",
            file.display()
        )
    );
    assert!(lines[1].contains("typo.ron:1:"), "{}", lines[1]);
    // `fn main() -> Result<(), Box<dyn Error>>` prints Debug: the same lines.
    assert_eq!(format!("{error:?}"), error.to_string());
    assert_eq!(error.model_errors().count(), 2);
    assert!(!out.exists(), "nothing written when a model fails");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_output_is_deterministic_and_rewritten_only_when_it_changes() {
    let dir = scratch("deterministic", &["driven_convex"]);
    let out = dir.join("out");
    let model = dir.join("models/driven_convex.ron");
    let first = config(&out).compile_models(&[&model]).expect("compiles");
    let bytes = std::fs::read(&first[0].output).expect("written");
    let modified = std::fs::metadata(&first[0].output)
        .and_then(|m| m.modified())
        .expect("time");
    std::thread::sleep(std::time::Duration::from_millis(20));
    let second = config(&out).compile_models(&[&model]).expect("compiles");
    assert_eq!(std::fs::read(&second[0].output).expect("written"), bytes);
    let again = std::fs::metadata(&second[0].output)
        .and_then(|m| m.modified())
        .expect("time");
    assert_eq!(
        modified, again,
        "an unchanged module is not rewritten (no recompilation)"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn config_sets_runtime_path_module_names_index_and_embedded_source() {
    let dir = scratch("config", &["paper_concave", "double_pendulum"]);
    let out = dir.join("out");
    let compiled = config(&out)
        .runtime_path("::camchain_runtime")
        .module_name("paper_concave", "concave")
        .include_file("all.rs")
        .embed_model_source(true)
        .compile_models(&[dir.join("models")])
        .unwrap_or_else(|e| panic!("{e}"));
    let concave = compiled
        .iter()
        .find(|c| c.name == "paper_concave")
        .expect("compiled");
    assert_eq!(concave.module, "concave");
    assert_eq!(concave.output, out.join("concave.rs"));
    let code = std::fs::read_to_string(&concave.output).expect("written");
    assert!(code.contains("use ::camchain_runtime as rt;"));
    let source = std::fs::read_to_string(dir.join("models/paper_concave.ron")).expect("copied");
    assert!(code.contains(&format!("pub const MODEL_SOURCE: &str = r#\"{source}\"#;")));
    let index = std::fs::read_to_string(out.join("all.rs")).expect("the index");
    assert!(index.contains("pub mod concave {\n    include!(\"concave.rs\");\n}"));
    assert!(index.contains("(\"paper_concave\", &*concave::DEFAULT as"));
    assert!(index.contains("(\"paper_concave\", concave::boxed)"));
    assert!(index.contains("dyn ::camchain_runtime::Dynamics + Sync"));
    assert!(index.contains("(\"double_pendulum\", double_pendulum::MODEL_SOURCE)"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_module_name_that_is_not_an_identifier_or_is_taken_twice_is_refused() {
    let dir = scratch("names", &["paper_concave", "double_pendulum"]);
    let out = dir.join("out");
    let error = config(&out)
        .module_name("paper_concave", "fn")
        .compile_models(&[dir.join("models")])
        .expect_err("`fn` is a keyword");
    assert!(
        error.to_string().contains("not a Rust identifier"),
        "{error}"
    );
    let error = config(&out)
        .module_name("paper_concave", "double_pendulum")
        .compile_models(&[dir.join("models")])
        .expect_err("two models, one module");
    assert!(
        error.to_string().contains("already generated from"),
        "{error}"
    );
    let error = config(&out)
        .module_name("no_such_model", "x")
        .compile_models(&[dir.join("models")])
        .expect_err("a rename of nothing");
    assert!(error.to_string().contains("no_such_model"), "{error}");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn entry_points_choose_between_own_expressions_and_calls_of_the_fused_pair() {
    let dir = scratch("entry-points", &["paper_concave"]);
    let model = dir.join("models/paper_concave.ron");
    let code = |entry: EntryPoints, out: &str| {
        let compiled = config(&dir.join(out))
            .entry_points(entry)
            .compile_models(&[&model])
            .expect("compiles");
        std::fs::read_to_string(&compiled[0].output).expect("written")
    };
    let standalone = code(EntryPoints::Standalone, "a");
    let fused = code(EntryPoints::ViaFusedPair, "b");
    // The paper model is small: Auto gives every entry point its own expressions.
    assert_eq!(code(EntryPoints::Auto, "c"), standalone);
    assert!(!standalone.contains("self.position_terms(q, h, j, &mut cache)"));
    assert!(fused.contains("self.position_terms(q, h, j, &mut cache)"));
    assert!(fused.len() < standalone.len(), "the fused form is smaller");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn without_out_dir_or_a_build_script_the_error_says_what_to_do() {
    if std::env::var_os("OUT_DIR").is_some() {
        return; // only meaningful outside a build script
    }
    let error = Config::new()
        .emit_rerun_if_changed(false)
        .compile_models(&["models/none.ron"])
        .expect_err("no OUT_DIR");
    assert!(error.to_string().contains("OUT_DIR is not set"), "{error}");
}

#[test]
fn a_missing_file_is_named() {
    let dir = scratch("missing", &[]);
    let error = config(&dir.join("out"))
        .compile_models(&[dir.join("models/absent.ron")])
        .expect_err("no such file");
    let file = dir.join("models/absent.ron");
    let expected = format!("{}: cannot read the file: ", file.display());
    assert!(error.to_string().starts_with(&expected), "{error}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_value_that_looks_like_degrees_is_a_located_warning_not_an_error() {
    let dir = scratch("degrees", &["double_pendulum"]);
    let path = dir.join("models/double_pendulum.ron");
    let text = std::fs::read_to_string(&path).expect("copied");
    let edited = text.replacen("\"q2\": \"q2_start\"", "\"q2\": 45.0", 1);
    assert_ne!(edited, text);
    std::fs::write(&path, &edited).expect("written");
    let compiled = config(&dir.join("out"))
        .compile_models(&[&path])
        .unwrap_or_else(|e| panic!("a warning does not fail the build: {e}"));
    let line = edited
        .lines()
        .position(|l| l.contains("45.0"))
        .expect("edited")
        + 1;
    // Located at the entry `"q2": 45.0`, as an error in it would be.
    let column = edited
        .lines()
        .nth(line - 1)
        .and_then(|l| l.find("\"q2\""))
        .expect("key")
        + 1;
    assert_eq!(compiled[0].warnings.len(), 1, "{:?}", compiled[0].warnings);
    let warning = &compiled[0].warnings[0];
    assert!(
        warning.starts_with(&format!(
            "{}:{line}:{column}: initial.q[\"q2\"]: ",
            path.display()
        )),
        "{warning}"
    );
    assert!(
        warning.contains("45 rad") && warning.contains("degrees?"),
        "{warning}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A model whose profile is a table in a CSV file beside it: the build reads the file from the
/// model's own directory (not from where the build runs, nor from the path messages show),
/// writes the table's points into the module, embeds the file's text beside the model's with
/// `embed_model_source`, and a bad cell stops the build at the CSV's line and column.
#[test]
fn a_table_beside_the_model_is_read_from_the_models_directory_and_embedded() {
    let dir = scratch("table", &["table_cam"]);
    let tables = dir.join("models/tables");
    std::fs::create_dir_all(&tables).expect("a tables directory");
    let csv =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/tables/cycloidal_roller_profile.csv");
    std::fs::copy(&csv, tables.join("cycloidal_roller_profile.csv")).expect("the table");
    let out = dir.join("out");
    let compiled = config(&out)
        .embed_model_source(true)
        .compile_models(&[dir.join("models/table_cam.ron")])
        .unwrap_or_else(|e| panic!("{e}"));
    let code = std::fs::read_to_string(&compiled[0].output).expect("written");
    // The table's constants (721 points, one of them written out) and its evaluation.
    assert!(
        code.contains("const ROLLER_TABLE_X_X: [f64; 721]"),
        "the x table"
    );
    assert!(code.contains("fn eval_roller_table_y("), "the y evaluation");
    assert!(
        code.contains("0.0003490614199349575"),
        "a point of the file"
    );
    let files = code
        .find("pub const MODEL_FILES")
        .map(|at| &code[at..])
        .expect("MODEL_FILES");
    assert!(
        files.contains("\"tables/cycloidal_roller_profile.csv\""),
        "the file embedded by the path the model writes: {}",
        &files[..files.len().min(200)]
    );
    // A cell that is not a number: located in the CSV.
    let text = std::fs::read_to_string(tables.join("cycloidal_roller_profile.csv")).expect("it");
    std::fs::write(
        tables.join("cycloidal_roller_profile.csv"),
        text.replacen("0.0003490614199349575", "0.000349x", 1),
    )
    .expect("the edit");
    let error = config(&out)
        .compile_models(&[dir.join("models/table_cam.ron")])
        .expect_err("a bad cell")
        .to_string();
    assert!(
        error.contains("cycloidal_roller_profile.csv:5:1: contacts[0].table.file: `0.000349x` is not a number (x)"),
        "{error}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
