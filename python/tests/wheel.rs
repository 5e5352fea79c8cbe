//! The Python package's tests (`tests/test_*.py`), run by `cargo test` against the wheel,
//! built and installed as a user installs it:
//!
//! 1. a virtual environment for the build backend (maturin, `requirements-build.txt`);
//! 2. `maturin build` of the wheel, in the dev profile, which is the test profile (see the
//!    workspace's Cargo.toml): it links the crates `cargo test` has just compiled, with the
//!    features that build gave them, so no crate of the workspace is compiled twice;
//! 3. a fresh virtual environment with the wheel and `requirements-test.txt` (numpy,
//!    pytest), and nothing of the source tree on its path;
//! 4. pytest on `tests/`, told where the command line is (the tests compare the package's
//!    results with the CLI's CSV) and where the repository's models are.
//!
//! Everything is made under a directory of this run's own (`target/python-tests/<pid>`),
//! removed at the end, so that two runs at once do not meet. It needs `python3` (3.9 or
//! later, with `venv` and `pip`) and the package registry; without python3 the test fails
//! saying so, unless `CAMCHAIN_SKIP_PYTHON=1` asks to skip it (then it says that it did).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The directory the command's runs have in common, and the repository.
fn places() -> (PathBuf, PathBuf) {
    let package = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let repository = package
        .parent()
        .map_or_else(|| package.clone(), Path::to_path_buf);
    (package, repository)
}

/// The target directory's profile directory (`target/debug`): where this test binary's
/// `deps/` directory is.
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap_or_default();
    exe.parent()
        .and_then(Path::parent)
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

/// The features `cargo test --workspace` gives the models' crate (through its own tests'
/// dev-dependency on itself).
const MODEL_FEATURES: &str = "camchain-models/random-models,camchain-models/parameter-modes";

fn run(what: &str, command: &mut Command) {
    eprintln!("python tests: {what}");
    let status = command
        .status()
        .unwrap_or_else(|e| panic!("{what}: cannot start {command:?}: {e}"));
    assert!(status.success(), "{what} failed ({status}): {command:?}");
}

/// Removes the run's own directory when the test ends, whichever way.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn python_suite_against_the_installed_wheel() {
    if std::env::var_os("CAMCHAIN_SKIP_PYTHON").is_some_and(|v| v == "1") {
        eprintln!("python tests: skipped (CAMCHAIN_SKIP_PYTHON=1)");
        return;
    }
    let python = std::env::var_os("PYTHON").unwrap_or_else(|| "python3".into());
    let found = Command::new(&python).arg("--version").output();
    assert!(
        found.as_ref().is_ok_and(|o| o.status.success()),
        "the Python tests need python3 (3.9 or later) on the PATH, or PYTHON=path; \
         CAMCHAIN_SKIP_PYTHON=1 skips them"
    );
    let (package, repository) = places();
    let profile = profile_dir();
    let target = profile.parent().map(Path::to_path_buf).unwrap_or_default();
    let scratch = Scratch(
        target
            .join("python-tests")
            .join(std::process::id().to_string()),
    );
    let _ = std::fs::remove_dir_all(&scratch.0);
    std::fs::create_dir_all(&scratch.0).expect("the run's directory");
    let tools = scratch.0.join("tools");
    let env = scratch.0.join("env");
    let wheels = scratch.0.join("wheels");
    let bin = |venv: &Path, name: &str| venv.join("bin").join(name);

    run(
        "a virtual environment for maturin",
        Command::new(&python).args(["-m", "venv"]).arg(&tools),
    );
    run(
        "installing maturin",
        Command::new(bin(&tools, "pip"))
            .args(["install", "--quiet", "--disable-pip-version-check", "-r"])
            .arg(package.join("requirements-build.txt")),
    );
    // The command line the tests compare with, built as `cargo test --workspace` built it
    // (nothing to do after that command's build).
    run(
        "the command line",
        Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
            .current_dir(&repository)
            .args([
                "build",
                "--quiet",
                "-p",
                "camchain-cli",
                "--features",
                MODEL_FEATURES,
            ]),
    );
    // With the features the workspace's test build gave the models' crate: the same build,
    // not a second one without them.
    run(
        "building the wheel",
        Command::new(bin(&tools, "maturin"))
            .current_dir(&package)
            .args(["build", "--quiet", "--profile", "dev", "--features"])
            .arg(MODEL_FEATURES)
            .arg("--interpreter")
            .arg(bin(&tools, "python"))
            .arg("--out")
            .arg(&wheels),
    );
    let wheel = std::fs::read_dir(&wheels)
        .expect("maturin's output")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|e| e == "whl"))
        .expect("maturin wrote a wheel");
    run(
        "a fresh virtual environment for the package",
        Command::new(&python).args(["-m", "venv"]).arg(&env),
    );
    run(
        "installing the wheel",
        Command::new(bin(&env, "pip"))
            .args(["install", "--quiet", "--disable-pip-version-check"])
            .arg(&wheel)
            .arg("-r")
            .arg(package.join("requirements-test.txt")),
    );
    // Run from the scratch directory, so that `import camchain` finds the installed package
    // and not the source tree's `python/camchain`.
    run(
        "pytest",
        Command::new(bin(&env, "python"))
            .current_dir(&scratch.0)
            .args([
                "-m",
                "pytest",
                "-q",
                "-p",
                "no:cacheprovider",
                "--import-mode=importlib",
            ])
            .arg(package.join("tests"))
            .env("CAMCHAIN_CLI", profile.join("camchain"))
            .env("CAMCHAIN_REPOSITORY", &repository)
            .env("CAMCHAIN_SCRATCH", &scratch.0),
    );
}
