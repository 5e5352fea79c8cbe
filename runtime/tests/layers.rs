//! The runtime's modules form layers, with no circle among them: the stepping engine
//! (`stepping`, `phase`, `scan`, `sample`, over `partition`, `integrators`, `control`,
//! `events`) knows nothing of the runs built on it; `assembly` and `metrics` use the engine
//! only; `unilateral` uses the engine and `assembly` (it re-assembles the state at every
//! lift-off and landing); `simulate`, the [`Simulate`](camchain_runtime::Simulate) facade,
//! ties them together and is imported by none of them. Asserted on the sources, from the
//! `crate::` paths of their non-test code (a re-export at the crate root counts as the module
//! it re-exports), so that a circle cannot come back unnoticed: `unilateral` used to reach
//! `simulate` for `Simulate::state_at` while `simulate` called `unilateral::run_phases`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The runs built on the engine, from the lowest layer up.
const RUNS: &[&str] = &["assembly", "metrics", "unilateral", "simulate"];

/// The engine's modules, and the lower modules it is built on.
const ENGINE: &[&str] = &[
    "stepping",
    "phase",
    "scan",
    "sample",
    "partition",
    "integrators",
    "control",
    "events",
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The source of module `name` (`name.rs`, or every file under `name/` but tests.rs),
/// without comments and without its `#[cfg(test)]` tests module.
fn code(name: &str) -> String {
    let file = src().join(format!("{name}.rs"));
    let mut files = vec![file.clone()];
    let dir = src().join(name);
    if dir.is_dir() {
        let mut inner: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|entry| entry.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "rs") && !p.ends_with("tests.rs"))
            .collect();
        inner.sort();
        files.extend(inner);
    }
    let mut out = String::new();
    for path in files.iter().filter(|p| p.is_file()) {
        let text = std::fs::read_to_string(path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for (k, line) in lines.iter().enumerate() {
            let next = lines.get(k + 1).map_or("", |l| l.trim());
            if line.trim() == "#[cfg(test)]" && next.starts_with("mod tests") {
                break;
            }
            if !line.trim_start().starts_with("//") {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    out
}

/// What the crate root re-exports, by name: `pub use module::{A, B};` maps A and B to
/// `module` (a glob maps "*").
fn root_exports() -> BTreeMap<String, String> {
    let lib = std::fs::read_to_string(src().join("lib.rs")).unwrap();
    let mut out = BTreeMap::new();
    for line in lib.lines().filter(|l| l.starts_with("pub use ")) {
        let spec = line["pub use ".len()..].trim_end_matches(';');
        let (module, names) = spec.split_once("::").unwrap();
        for name in names.trim_matches(|c| c == '{' || c == '}').split(',') {
            out.insert(name.trim().to_string(), module.to_string());
        }
    }
    out
}

/// The crate's modules that module `name` names by a `crate::` path.
fn imports(name: &str) -> BTreeSet<String> {
    let exports = root_exports();
    let text = code(name);
    let mut out = BTreeSet::new();
    let mut rest = text.as_str();
    while let Some(at) = rest.find("crate::") {
        rest = &rest[at + "crate::".len()..];
        let heads: Vec<&str> = if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap();
            group[..end].split(',').collect()
        } else {
            vec![rest]
        };
        for head in heads {
            let first: String = head
                .trim()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let module = exports.get(&first).cloned().unwrap_or(first);
            if module != name && !module.is_empty() {
                out.insert(module);
            }
        }
    }
    out
}

/// The modules of `among` that module `name` imports.
fn imported(name: &str, among: &[&str]) -> Vec<String> {
    let all = imports(name);
    among
        .iter()
        .filter(|m| all.contains(**m))
        .map(|m| m.to_string())
        .collect()
}

#[test]
fn the_engine_imports_none_of_the_runs_built_on_it() {
    for module in ENGINE {
        let found = imported(module, RUNS);
        assert!(found.is_empty(), "{module} imports {found:?}");
    }
}

#[test]
fn each_run_imports_only_the_runs_below_it() {
    // `imports` sees through the crate root's re-exports: check that it does, so that the
    // assertions below cannot pass by missing a path.
    assert!(imports("unilateral").contains("dynamics"));
    assert!(imports("simulate").contains("unilateral"));
    let allowed: &[(&str, &[&str])] = &[
        ("assembly", &[]),
        ("metrics", &[]),
        ("unilateral", &["assembly"]),
        ("simulate", &["assembly", "metrics", "unilateral"]),
    ];
    for (module, below) in allowed {
        let found: Vec<String> = imported(module, RUNS)
            .into_iter()
            .filter(|m| !below.contains(&m.as_str()))
            .collect();
        assert!(found.is_empty(), "{module} imports {found:?}");
    }
}
