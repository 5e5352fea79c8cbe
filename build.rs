//! Turns every `models/*.ron` into a generated Rust module under `OUT_DIR/models/`, and, with
//! the `random-models` feature, every `tests/random_models/*.ron` (random models of the
//! property tests, not user-facing) into one under `OUT_DIR/random_models/`.
//!
//! A model that does not validate stops the build with `file:line:column: field: message`
//! lines (no panic backtrace). Output is deterministic: models are processed in file-name
//! order and the generated text depends only on the model file.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn main() -> ExitCode {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").unwrap_or_default());
    let mut sets = vec![("models", manifest.join("models"))];
    // Set by cargo when the `random-models` feature is on (this package's own tests).
    if std::env::var_os("CARGO_FEATURE_RANDOM_MODELS").is_some() {
        sets.push((
            "random_models",
            manifest.join("tests").join("random_models"),
        ));
    }
    let built = sets.iter().try_for_each(|(set, dir)| {
        println!("cargo:rerun-if-changed={}", dir.display());
        generate_all(&manifest, dir, &out_dir, set)
    });
    match built {
        Ok(()) => ExitCode::SUCCESS,
        Err(messages) => {
            for m in messages {
                eprintln!("error: {m}");
            }
            ExitCode::FAILURE
        }
    }
}

fn model_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    files.sort();
    Ok(files)
}

/// Generates one module per model file of `dir` under `OUT_DIR/<set>/` and the index
/// `OUT_DIR/<set>.rs`.
fn generate_all(manifest: &Path, dir: &Path, out_dir: &Path, set: &str) -> Result<(), Vec<String>> {
    let files = model_files(dir).map_err(|e| vec![e])?;
    let module_dir = out_dir.join(set);
    std::fs::create_dir_all(&module_dir)
        .map_err(|e| vec![format!("{}: {e}", module_dir.display())])?;
    let mut errors = Vec::new();
    let mut modules = Vec::new();
    let mut sources = std::collections::HashMap::new();
    for file in &files {
        println!("cargo:rerun-if-changed={}", file.display());
        let display = file.strip_prefix(manifest).unwrap_or(file);
        match camchain_codegen::generate_file(file, display) {
            Ok(generated) => {
                let name = generated.name.clone();
                if let Some(first) = sources.get(&name) {
                    errors.push(format!(
                        "{}: model name `{name}` is already used by {first}; give this file its \
                         own `name:` (or remove the field to use the file name)",
                        display.display(),
                    ));
                    continue;
                }
                sources.insert(name.clone(), generated.source.clone());
                let target = module_dir.join(format!("{name}.rs"));
                if let Err(e) = write_if_changed(&target, &generated.code) {
                    errors.push(format!("{}: {e}", target.display()));
                }
                modules.push((name, target, generated.summary()));
            }
            Err(e) => errors.push(e.to_string()),
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let index = module_index(&modules);
    write_if_changed(&out_dir.join(format!("{set}.rs")), &index).map_err(|e| vec![e.to_string()])
}

/// The index: one `pub mod` per model and the table of all of them.
fn module_index(modules: &[(String, PathBuf, String)]) -> String {
    let mut text = String::new();
    for (name, path, summary) in modules {
        text.push_str(&format!(
            "#[doc = {summary:?}]\n#[path = {:?}]\npub mod {name};\n",
            path.display().to_string()
        ));
    }
    text.push_str("/// Every model of this set by name, in file-name order.\n");
    text.push_str("pub static ALL: &[(&str, &(dyn ::camchain_runtime::Dynamics + Sync))] = &[\n");
    for (name, _, _) in modules {
        text.push_str(&format!("    ({name:?}, &{name}::Model),\n"));
    }
    text.push_str("];\n");
    text.push_str(
        "/// Operation counts of every built-in model's generated functions, by model name \
         (add/sub, mul, div, sin/cos, sqrt, other).\n",
    );
    text.push_str(
        "/// One generated function's operation counts: its name and add/sub, mul, div, \
         sin/cos, sqrt, other.\npub type OpCountRow = (&'static str, [usize; 6]);\n",
    );
    text.push_str("pub static OP_COUNTS: &[(&str, &[OpCountRow])] = &[\n");
    for (name, _, _) in modules {
        text.push_str(&format!("    ({name:?}, {name}::OP_COUNTS),\n"));
    }
    text.push_str("];\n");
    text
}

/// Writes only when the content differs, so unchanged models do not trigger recompilation.
fn write_if_changed(path: &Path, content: &str) -> std::io::Result<()> {
    if std::fs::read_to_string(path).is_ok_and(|old| old == content) {
        return Ok(());
    }
    std::fs::write(path, content)
}
