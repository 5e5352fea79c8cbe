//! What the timing examples (`scaling`, `formulations`) share: building a throwaway crate.

use std::path::Path;
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
