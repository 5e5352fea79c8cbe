//! The Python package's tests (`tests/test_*.py`), run by `cargo test` against the wheel,
//! installed as a user installs it:
//!
//! 1. the wheel: the extension module that this very build compiled (the package's library,
//!    a dependency of this test, with the features the workspace's test build unifies) packed
//!    with the Python sources by `tests/pack_wheel.py`, as maturin lays a wheel out. With
//!    `CAMCHAIN_WHEEL=maturin` it is built by maturin (`requirements-build.txt`) in the dev
//!    profile instead, which compiles the workspace's crates again with the package's own
//!    features (minutes, not seconds): the path `pip install ./python` takes;
//! 2. a fresh virtual environment with the wheel and `requirements-test.txt` (numpy,
//!    pytest), and nothing of the source tree on its path;
//! 3. pytest on `tests/`, told where the command line is (the tests compare the package's
//!    results with the CLI's CSV; `cargo test --workspace` builds it for the command line's
//!    own tests), where the repository's models are, and where `camchain.compile` builds
//!    (this target directory, in the dev profile: only the runtime's copy and the models
//!    compile, their dependencies are this build's).
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
    let env = scratch.0.join("env");
    let wheels = scratch.0.join("wheels");
    let bin = |venv: &Path, name: &str| venv.join("bin").join(name);
    let cli = profile.join("camchain");
    assert!(
        cli.is_file(),
        "{} is missing: the Python tests compare with the command line, which `cargo test \
         --workspace` builds (or `cargo build -p camchain-cli`)",
        cli.display()
    );
    run(
        "a fresh virtual environment for the package",
        Command::new(&python).args(["-m", "venv"]).arg(&env),
    );
    let wheel = if std::env::var_os("CAMCHAIN_WHEEL").is_some_and(|v| v == "maturin") {
        maturin_wheel(&python, &package, &scratch.0, &wheels)
    } else {
        packed_wheel(&bin(&env, "python"), &package, &profile, &wheels)
    };
    run(
        "installing the wheel",
        Command::new(bin(&env, "pip"))
            .args(["install", "--quiet", "--disable-pip-version-check"])
            .arg(&wheel)
            .arg("-r")
            .arg(package.join("requirements-test.txt")),
    );
    run(
        "installing FMPy for the FMU tests",
        Command::new(bin(&env, "pip"))
            .args([
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "--no-deps",
                "-r",
            ])
            .arg(package.join("requirements-fmu.txt")),
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
            .env("CAMCHAIN_CLI", &cli)
            .env("CAMCHAIN_REPOSITORY", &repository)
            .env("CAMCHAIN_SCRATCH", &scratch.0)
            // `camchain.compile` builds the test models in this target directory and its
            // dev profile, where nalgebra and the other crates the runtime needs are
            // already compiled (the model's crate repeats the workspace's dev profile).
            .env("CAMCHAIN_COMPILE_TARGET", &target)
            .env("CAMCHAIN_COMPILE_PROFILE", "dev"),
    );
}

/// The extension module this build compiled, packed into a wheel.
fn packed_wheel(python: &Path, package: &Path, profile: &Path, wheels: &Path) -> PathBuf {
    // A cdylib needed by a test is built into deps/ (and copied up when built on its own).
    let library = [profile.join("deps"), profile.to_path_buf()]
        .iter()
        .map(|dir| dir.join("lib_camchain.so"))
        .filter(|p| p.is_file())
        .max_by_key(|p| p.metadata().and_then(|m| m.modified()).ok())
        .expect("the package's library (lib_camchain.so), built with this test");
    let output = Command::new(python)
        .arg(package.join("tests").join("pack_wheel.py"))
        .arg("--library")
        .arg(&library)
        .arg("--out")
        .arg(wheels)
        .output()
        .expect("pack_wheel.py runs");
    assert!(
        output.status.success(),
        "pack_wheel.py failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    PathBuf::from(String::from_utf8_lossy(&output.stdout).trim())
}

/// The wheel built by maturin, as `pip install ./python` builds it (in the dev profile).
fn maturin_wheel(
    python: &std::ffi::OsStr,
    package: &Path,
    scratch: &Path,
    wheels: &Path,
) -> PathBuf {
    let tools = scratch.join("tools");
    let bin = |name: &str| tools.join("bin").join(name);
    run(
        "a virtual environment for maturin",
        Command::new(python).args(["-m", "venv"]).arg(&tools),
    );
    run(
        "installing maturin",
        Command::new(bin("pip"))
            .args(["install", "--quiet", "--disable-pip-version-check", "-r"])
            .arg(package.join("requirements-build.txt")),
    );
    run(
        "building the wheel with maturin",
        Command::new(bin("maturin"))
            .current_dir(package)
            .args(["build", "--quiet", "--profile", "dev", "--interpreter"])
            .arg(bin("python"))
            .arg("--out")
            .arg(wheels),
    );
    std::fs::read_dir(wheels)
        .expect("maturin's output")
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|e| e == "whl"))
        .expect("maturin wrote a wheel")
}
