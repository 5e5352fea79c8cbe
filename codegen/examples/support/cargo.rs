//! What the timing examples (`scaling`, `formulations`) share: building a throwaway crate.

use std::path::Path;
use std::process::Command;

/// `cargo build --release` of the crate in `dir` into the shared `target` directory.
pub fn cargo_build(dir: &Path, target: &Path) -> Result<(), String> {
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(["build", "--release", "--quiet", "--manifest-path"])
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
