//! Embeds the runtime's sources and the workspace's `Cargo.lock` in the extension module:
//! `camchain.compile` writes them out for the crate it builds a user's model in, so that the
//! model links the same runtime, at the same pinned versions, as the package itself.

use std::fmt::Write;
use std::path::{Path, PathBuf};

fn files(dir: &Path, base: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            files(&path, base, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    let _ = base;
}

fn main() {
    let package = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let root = package.parent().map(Path::to_path_buf).unwrap_or_default();
    let runtime = root.join("runtime");
    let source = runtime.join("src");
    let mut found = Vec::new();
    files(&source, &source, &mut found);
    let mut code = String::from("/// The runtime's source files: (path under `src/`, text).\n");
    code.push_str("pub const RUNTIME_FILES: &[(&str, &str)] = &[\n");
    for path in &found {
        let relative = path.strip_prefix(&source).unwrap_or(path);
        let _ = writeln!(
            code,
            "    ({:?}, include_str!({:?})),",
            relative.to_string_lossy().replace('\\', "/"),
            path.display().to_string()
        );
    }
    code.push_str("];\n");
    let _ = writeln!(
        code,
        "/// The workspace's lock file: the pinned versions.\npub const LOCKFILE: &str = include_str!({:?});",
        root.join("Cargo.lock").display().to_string()
    );
    let version = std::env::var("CARGO_PKG_VERSION").unwrap_or_default();
    let _ = writeln!(
        code,
        "/// The runtime's manifest, standalone.\npub const RUNTIME_MANIFEST: &str = {:?};",
        format!(
            "[package]\nname = \"camchain-runtime\"\nversion = \"{version}\"\nedition = \"2024\"\n\
             publish = false\n\n# The contract alone: a compiled model never runs the engine, the package \
             does.\n[features]\nengine = []\n\n[dependencies]\nthiserror = \"2\"\n"
        )
    );
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap_or_default());
    let _ = std::fs::write(out.join("runtime_sources.rs"), code);
    println!("cargo:rerun-if-changed={}", source.display());
    println!(
        "cargo:rerun-if-changed={}",
        root.join("Cargo.lock").display()
    );
    println!(
        "cargo:rerun-if-changed={}",
        runtime.join("Cargo.toml").display()
    );
}
