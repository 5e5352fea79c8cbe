//! Generated model code built into a shared library with the user's cargo: what
//! `camchain.compile` (the Python package) and `camchain fmu` (an FMU's binary) share.
//!
//! The crate written for a model depends on copies of the runtime's and the FMU crate's
//! sources that this crate carries ([`sources`], written once per version under the cache
//! root), with the workspace's `Cargo.lock`, so nothing but crates.io's thiserror (and
//! nalgebra, for an FMU, which runs the engine) is fetched, at the versions the workspace
//! pins. Every directory is written through one of the process's own and renamed into place
//! ([`write_atomically`]), so that two processes compiling at once never read each other's
//! half-written files and nothing another run wrote is replaced. cargo runs as a child
//! process ([`build`]), its progress on standard error, stopped when the caller says so.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

include!(concat!(env!("OUT_DIR"), "/sources.rs"));

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Failure {
    /// cargo could not be started.
    NoCargo(String),
    /// cargo ran and failed (its messages went to standard error).
    Build(String),
    /// Writing or reading the cache failed.
    Cache(String),
    /// The caller asked to stop while cargo ran; cargo was stopped.
    Interrupted,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Failure::NoCargo(m) | Failure::Build(m) | Failure::Cache(m) => f.write_str(m),
            Failure::Interrupted => f.write_str("interrupted while cargo ran; cargo was stopped"),
        }
    }
}

impl std::error::Error for Failure {}

/// 64-bit FNV-1a of the parts (each followed by a 0xff separator): a stable hash for the
/// cache's directory names. Callers compare what they stored on every hit, so a collision
/// costs a rebuild, never a wrong model.
pub fn fnv(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for byte in part.iter().chain(&[0xff]) {
            h ^= u64::from(*byte);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// The cache directory: `cache`, else `$CAMCHAIN_CACHE`, else `$XDG_CACHE_HOME/camchain`,
/// else `~/.cache/camchain`; one subdirectory per version and [`SOURCES_HASH`] (the carried
/// sources: two builds of one version with other sources never share copies or libraries).
pub fn cache_root(cache: Option<PathBuf>) -> Result<PathBuf, Failure> {
    let base = cache
        .or_else(|| std::env::var_os("CAMCHAIN_CACHE").map(PathBuf::from))
        .or_else(|| std::env::var_os("XDG_CACHE_HOME").map(|d| PathBuf::from(d).join("camchain")))
        .or_else(|| {
            std::env::var_os("HOME").map(|d| PathBuf::from(d).join(".cache").join("camchain"))
        })
        .ok_or_else(|| Failure::Cache("no cache directory: set CAMCHAIN_CACHE (or HOME)".into()))?;
    Ok(base.join(format!(
        "{}-{}",
        env!("CARGO_PKG_VERSION"),
        &SOURCES_HASH[..8]
    )))
}

/// Writes `files` into `dir` through a directory of this process's own, renamed into place;
/// when another process put `dir` there first, its copy is kept. A directory is complete
/// once it holds `.complete`.
pub fn write_atomically(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<(), Failure> {
    if dir.join(".complete").is_file() {
        return Ok(());
    }
    let fail = |e: std::io::Error, what: &Path| Failure::Cache(format!("{}: {e}", what.display()));
    let parent = dir.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| fail(e, parent))?;
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let temp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&temp);
    for (path, bytes) in files {
        let path = temp.join(path);
        if let Some(p) = path.parent() {
            std::fs::create_dir_all(p).map_err(|e| fail(e, p))?;
        }
        std::fs::write(&path, bytes).map_err(|e| fail(e, &path))?;
    }
    std::fs::write(temp.join(".complete"), b"").map_err(|e| fail(e, &temp))?;
    if std::fs::rename(&temp, dir).is_err() {
        // Another process's copy is in place (or an incomplete one from a crash: replace
        // that, which no process can be reading, as it has no `.complete`).
        if dir.join(".complete").is_file() {
            let _ = std::fs::remove_dir_all(&temp);
        } else {
            let _ = std::fs::remove_dir_all(dir);
            std::fs::rename(&temp, dir).map_err(|e| fail(e, dir))?;
        }
    }
    Ok(())
}

/// A TOML basic string: quotes, backslashes and control characters escaped (a cache
/// directory may hold any of them).
pub fn toml_string(text: &str) -> String {
    let mut out = String::from('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A path as a TOML string (forward slashes).
fn toml_path(path: &Path) -> String {
    toml_string(&path.display().to_string().replace('\\', "/"))
}

/// Where the copies of the runtime and the FMU crate are.
#[derive(Debug, Clone)]
pub struct Sources {
    /// The runtime's copy (`camchain-runtime`; its feature `engine` brings nalgebra).
    pub runtime: PathBuf,
    /// The FMU crate's copy (`camchain-fmu`).
    pub fmu: PathBuf,
}

/// Writes the copies of the runtime and the FMU crate under `root` (once per version).
pub fn sources(root: &Path) -> Result<Sources, Failure> {
    let version = env!("CARGO_PKG_VERSION");
    let package = |name: &str| {
        format!(
            "[package]\nname = \"{name}\"\nversion = \"{version}\"\nedition = \"2024\"\n\
             publish = false\n\n"
        )
    };
    let runtime = root.join("runtime");
    let manifest = format!(
        "{}[features]\ndefault = []\nengine = [\"dep:nalgebra\"]\n\n[dependencies]\n\
         nalgebra = {{ version = \"0.35\", default-features = false, features = [\"std\"], \
         optional = true }}\nthiserror = \"2\"\n",
        package("camchain-runtime")
    );
    write_atomically(&runtime, &with_sources(RUNTIME_FILES, manifest))?;
    let fmu = root.join("fmu");
    let manifest = format!(
        "{}[dependencies]\ncamchain-runtime = {{ path = \"../runtime\", features = [\"engine\"] }}\n",
        package("camchain-fmu")
    );
    write_atomically(&fmu, &with_sources(FMU_FILES, manifest))?;
    Ok(Sources { runtime, fmu })
}

fn with_sources(files: &[(&str, &str)], manifest: String) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = files
        .iter()
        .map(|(path, text)| (format!("src/{path}"), text.as_bytes().to_vec()))
        .collect();
    out.push(("Cargo.toml".into(), manifest.into_bytes()));
    out
}

/// What a model's library links.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Links {
    /// The runtime's contract alone (no engine, no nalgebra): a library that only evaluates
    /// the model for a program that runs it (the Python package).
    Contract,
    /// The runtime with its engine and the FMU crate: a library that runs the model itself
    /// (an FMU's binary).
    Fmu,
}

/// The `Cargo.toml` of a model's library crate `name` (a `cdylib` from `src/lib.rs`);
/// `comment` says what it was written for.
pub fn manifest(name: &str, comment: &str, links: Links, sources: &Sources) -> String {
    let dependencies = match links {
        Links::Contract => format!(
            "camchain-runtime = {{ path = {} }}\n",
            toml_path(&sources.runtime)
        ),
        Links::Fmu => format!(
            "camchain-runtime = {{ path = {}, features = [\"engine\"] }}\n\
             camchain-fmu = {{ path = {} }}\n",
            toml_path(&sources.runtime),
            toml_path(&sources.fmu)
        ),
    };
    format!(
        "[package]\nname = \"{name}\"\nversion = \"0.1.0\"\nedition = \"2024\"\npublish = false\n\n\
         # Written by camchain for {comment}.\n[lib]\npath = \"src/lib.rs\"\ncrate-type = [\"cdylib\"]\n\n\
         [dependencies]\n{dependencies}\n\
         # The dev profile as the camchain workspace's (CAMCHAIN_COMPILE_PROFILE=dev, for\n\
         # its tests, which build many models and run each briefly): its dependencies are\n\
         # that build's; the copies and the model itself unoptimised.\n\
         [profile.dev]\nopt-level = 2\ndebug = false\n\
         [profile.dev.package.camchain-runtime]\nopt-level = 0\n\
         [profile.dev.package.camchain-fmu]\nopt-level = 0\n\
         [profile.dev.package.{name}]\nopt-level = 0\n\n[workspace]\n",
        comment = comment.replace(['\n', '\r'], " "),
    )
}

/// The target directory and profile of a build: `root/target` and release, unless
/// `CAMCHAIN_COMPILE_TARGET` and `CAMCHAIN_COMPILE_PROFILE` (`release` or `dev`) say
/// otherwise (the workspace's tests build in its own target directory and dev profile,
/// where the dependencies are already compiled).
pub fn target_and_profile(root: &Path) -> Result<(PathBuf, String), Failure> {
    let target = std::env::var_os("CAMCHAIN_COMPILE_TARGET")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let profile = std::env::var("CAMCHAIN_COMPILE_PROFILE").unwrap_or_else(|_| "release".into());
    if !["release", "dev"].contains(&profile.as_str()) {
        return Err(Failure::Build(format!(
            "CAMCHAIN_COMPILE_PROFILE={profile}: release or dev"
        )));
    }
    Ok((target, profile))
}

/// Runs `cargo build` on the crate in `crate_dir` (package `name`) and returns the built
/// library's path. cargo's progress goes to standard error (`quiet` hides it); `stop` is
/// polled every 50 ms while cargo runs, and cargo is killed when it says so.
pub fn build(
    crate_dir: &Path,
    name: &str,
    quiet: bool,
    root: &Path,
    stop: &mut dyn FnMut() -> bool,
) -> Result<PathBuf, Failure> {
    let (target, profile) = target_and_profile(root)?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut child = Command::new(&cargo)
        .args(["build", "--profile", &profile, "--manifest-path"])
        .arg(crate_dir.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(&target)
        .args(quiet.then_some("--quiet"))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .spawn()
        .map_err(|e| {
            Failure::NoCargo(format!(
                "building a model's library needs cargo (a Rust toolchain: https://rustup.rs), \
                 and `{}` could not be started: {e}",
                cargo.to_string_lossy()
            ))
        })?;
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) => {}
            Err(e) => return Err(Failure::Build(format!("waiting for cargo: {e}"))),
        }
        if stop() {
            let _ = child.kill();
            let _ = child.wait();
            return Err(Failure::Interrupted);
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    if !status.success() {
        return Err(Failure::Build(format!(
            "cargo build of {} failed ({status}); its messages are above",
            crate_dir.display()
        )));
    }
    let library = format!("lib{}.so", name.replace('-', "_"));
    Ok(target
        .join(if profile == "dev" { "debug" } else { "release" })
        .join(library))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_strings_escape_what_a_path_may_hold() {
        assert_eq!(toml_string("a\"b\\c\n"), "\"a\\\"b\\\\c\\u000A\"");
    }

    #[test]
    fn the_carried_sources_are_the_crates() {
        assert!(RUNTIME_FILES.iter().any(|(p, _)| *p == "lib.rs"));
        assert!(
            FMU_FILES
                .iter()
                .any(|(p, t)| *p == "lib.rs" && t.contains("macro_rules! export"))
        );
        assert!(LOCKFILE.contains("name = \"nalgebra\""));
    }

    #[test]
    fn fnv_separates_its_parts() {
        assert_ne!(fnv(&[b"ab", b"c"]), fnv(&[b"a", b"bc"]));
    }
}
