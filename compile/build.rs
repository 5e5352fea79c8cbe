//! Embeds the sources of the runtime and of the FMU crate, and the workspace's `Cargo.lock`:
//! the crates this package writes depend on those copies, so that a compiled model links the
//! same runtime, at the same pinned versions, as the program that compiled it.

use std::fmt::Write;
use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// 64-bit FNV-1a, fed with every embedded file's path and text.
fn feed(hash: &mut u64, bytes: &[u8]) {
    for &b in bytes.iter().chain(&[0xff]) {
        *hash ^= u64::from(b);
        *hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
}

/// `pub const NAME: &[(&str, &str)]`: (path under `src/`, text) of every `.rs` file.
fn embed(code: &mut String, name: &str, source: &Path, hash: &mut u64) {
    let mut found = Vec::new();
    files(source, &mut found);
    let _ = writeln!(code, "pub const {name}: &[(&str, &str)] = &[");
    for path in &found {
        let relative = path.strip_prefix(source).unwrap_or(path);
        feed(hash, relative.to_string_lossy().as_bytes());
        feed(hash, &std::fs::read(path).unwrap_or_default());
        let _ = writeln!(
            code,
            "    ({:?}, include_str!({:?})),",
            relative.to_string_lossy().replace('\\', "/"),
            path.display().to_string()
        );
    }
    code.push_str("];\n");
    println!("cargo:rerun-if-changed={}", source.display());
}

fn main() {
    let package = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default());
    let root = package.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut code = String::from("/// The runtime's source files: (path under `src/`, text).\n");
    let runtime = root.join("runtime").join("src");
    embed(&mut code, "RUNTIME_FILES", &runtime, &mut hash);
    code.push_str("/// The FMU crate's source files: (path under `src/`, text).\n");
    embed(
        &mut code,
        "FMU_FILES",
        &root.join("fmu").join("src"),
        &mut hash,
    );
    feed(
        &mut hash,
        &std::fs::read(root.join("Cargo.lock")).unwrap_or_default(),
    );
    let _ = writeln!(
        code,
        "/// A hash of every carried file and the lock file: the cache's directory changes with\n\
         /// them, so a build never links copies or libraries of other sources.\n\
         pub const SOURCES_HASH: &str = \"{hash:016x}\";"
    );
    let _ = writeln!(
        code,
        "/// The workspace's lock file: the pinned versions.\npub const LOCKFILE: &str = include_str!({:?});",
        root.join("Cargo.lock").display().to_string()
    );
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap_or_default());
    let _ = std::fs::write(out.join("sources.rs"), code);
    println!(
        "cargo:rerun-if-changed={}",
        root.join("Cargo.lock").display()
    );
}
