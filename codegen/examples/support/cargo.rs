//! What the timing examples (`scaling`, `formulations`) share: writing and building a
//! throwaway crate.

use std::path::{Path, PathBuf};
use std::process::Command;

/// `cargo build --release` of the crate in `dir` into the shared `target` directory; with
/// `native`, for this machine's processor (`-C target-cpu=native`, what `-march=native` is
/// to a C++ compiler).
pub fn cargo_build(dir: &Path, target: &Path, native: bool) -> Result<(), String> {
    let mut command = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    command.args(["build", "--release", "--quiet"]);
    if native {
        command.args([
            "--config",
            "build.rustflags=[\"-C\", \"target-cpu=native\"]",
        ]);
    }
    let status = command
        .arg("--manifest-path")
        .arg(dir.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(target)
        .status()
        .map_err(|e| e.to_string())?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("cargo build failed in {}", dir.display()))
    }
}

/// A throwaway crate `package` in `out/crates/dir` that depends on the runtime at `runtime`
/// alone: its directory, with `src/` made and the manifest written.
pub fn new_crate(out: &Path, dir: &str, package: &str, runtime: &Path) -> Result<PathBuf, String> {
    let dir = out.join("crates").join(dir);
    std::fs::create_dir_all(dir.join("src")).map_err(|e| e.to_string())?;
    let manifest = format!(
        "[package]\nname = \"{package}\"\nversion = \"0.0.0\"\nedition = \"2024\"\n\
         [dependencies]\ncamchain-runtime = {{ path = {:?} }}\n[workspace]\n",
        runtime.display().to_string()
    );
    std::fs::write(dir.join("Cargo.toml"), manifest).map_err(|e| e.to_string())?;
    Ok(dir)
}
