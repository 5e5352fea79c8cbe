//! The workspace's structure, checked on every test run (ARCHITECTURE.md, "Where things
//! live"):
//!
//! - no source file holds more than [`MAX_CODE_LINES`] lines of code (blank lines, comments
//!   and `#[cfg(test)]` items apart; files of tests apart);
//! - no circle among the modules of a crate: a module's uses of another (`crate::a::b`,
//!   `super::x`, a child's name) are edges; a child counts as part of its parent, so an edge
//!   between two modules is projected onto the two siblings under their common ancestor, and
//!   those edges must have no cycle.
//!
//! The scanner reads the sources as text (paths after `crate::`/`super::`, `use` groups,
//! re-exports of the crate root and of a module's `pub use`), which the project's code style
//! keeps sufficient; a test below checks that it sees the edges it must see.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The most lines of code a source file may hold.
const MAX_CODE_LINES: usize = 800;

/// The crates' source directories, from the workspace root.
const CRATES: [&str; 7] = [
    "src",
    "runtime/src",
    "codegen/src",
    "build/src",
    "camchain/src",
    "reference/src",
    "cli/src",
];

type ModPath = Vec<String>;

/// The lines of `text` without its `#[cfg(test)]` items (a module or function up to its
/// closing brace, or a one-line item).
fn without_tests(text: &str) -> Vec<&str> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim_start().starts_with("#[cfg(test)]") {
            let mut j = i + 1;
            let mut depth = 0i64;
            let mut opened = false;
            while j < lines.len() {
                let l = lines[j];
                if !opened && l.trim_end().ends_with(';') && !l.contains('{') {
                    break;
                }
                depth += l.matches('{').count() as i64 - l.matches('}').count() as i64;
                opened |= l.contains('{');
                if opened && depth <= 0 {
                    break;
                }
                j += 1;
            }
            i = j + 1;
            continue;
        }
        out.push(lines[i]);
        i += 1;
    }
    out
}

fn code_lines(lines: &[&str]) -> usize {
    lines
        .iter()
        .filter(|l| {
            let t = l.trim();
            !t.is_empty() && !t.starts_with("//")
        })
        .count()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module a file defines, relative to its crate's `src`.
fn module_of(src: &Path, file: &Path) -> ModPath {
    let rel = file
        .strip_prefix(src)
        .expect("under src")
        .with_extension("");
    let mut parts: ModPath = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.len() == 1 && (parts[0] == "lib" || parts[0] == "main") {
        parts.clear();
    } else if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts
}

fn is_test_file(module: &ModPath) -> bool {
    module.iter().any(|p| p == "tests")
}

fn ident_end(s: &str) -> usize {
    s.find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(s.len())
}

/// Every path written after `crate::`, `super::` or `self::` in `code`, resolved to absolute
/// module paths (segments beyond the module are kept: resolution trims them), with `use`
/// groups expanded one level.
fn paths(code: &str, module: &ModPath) -> Vec<ModPath> {
    let mut found = Vec::new();
    for head in ["crate::", "super::", "self::"] {
        let mut rest = code;
        while let Some(at) = rest.find(head) {
            let before = rest[..at].chars().last();
            rest = &rest[at + head.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let mut base: ModPath = match head {
                "crate::" => Vec::new(),
                "super::" => module[..module.len().saturating_sub(1)].to_vec(),
                _ => module.clone(),
            };
            let mut tail = rest;
            loop {
                if let Some(r) = tail.strip_prefix("super::") {
                    base.pop();
                    tail = r;
                    continue;
                }
                if tail.starts_with('{') {
                    let close = tail.find('}').unwrap_or(tail.len());
                    for part in tail[1..close].split(',') {
                        let part = part.trim();
                        let mut p = base.clone();
                        p.extend(
                            part.split(" as ")
                                .next()
                                .unwrap_or("")
                                .split("::")
                                .map(|s| s.trim().to_string())
                                .filter(|s| !s.is_empty() && s != "{"),
                        );
                        found.push(p);
                    }
                    break;
                }
                let end = ident_end(tail);
                if end == 0 {
                    found.push(base.clone());
                    break;
                }
                base.push(tail[..end].to_string());
                match tail[end..].strip_prefix("::") {
                    Some(r) => tail = r,
                    None => {
                        found.push(base.clone());
                        break;
                    }
                }
            }
        }
    }
    found
}

struct Crate {
    modules: BTreeMap<ModPath, String>,
    /// (module, name) → the path a `pub use` re-exports under that name.
    reexports: BTreeMap<(ModPath, String), ModPath>,
    /// module → glob-re-exported modules.
    globs: BTreeMap<ModPath, Vec<ModPath>>,
}

impl Crate {
    fn resolve(&self, full: &[String], depth: usize) -> Option<ModPath> {
        for k in (0..=full.len()).rev() {
            let prefix: ModPath = full[..k].to_vec();
            if !self.modules.contains_key(&prefix) {
                continue;
            }
            if k < full.len() && depth < 8 {
                let name = &full[k];
                if let Some(target) = self.reexports.get(&(prefix.clone(), name.clone())) {
                    let mut next = target.clone();
                    next.extend(full[k + 1..].iter().cloned());
                    if next.as_slice() != full {
                        return self.resolve(&next, depth + 1);
                    }
                }
                for glob in self.globs.get(&prefix).into_iter().flatten() {
                    let Some(source) = self.resolve(glob, depth + 1) else {
                        continue;
                    };
                    let defines = self.modules.get(&source).is_some_and(|text| {
                        [
                            "fn ", "struct ", "enum ", "trait ", "type ", "const ", "static ",
                        ]
                        .iter()
                        .any(|kw| text.contains(&format!("{kw}{name}")))
                    });
                    if defines {
                        let mut next = source.clone();
                        next.extend(full[k..].iter().cloned());
                        return self.resolve(&next, depth + 1);
                    }
                }
            }
            return Some(prefix);
        }
        None
    }
}

fn load(src: &Path) -> Crate {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut modules = BTreeMap::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a source file");
        modules.insert(module_of(src, file), text);
    }
    let mut reexports = BTreeMap::new();
    let mut globs: BTreeMap<ModPath, Vec<ModPath>> = BTreeMap::new();
    for (module, text) in &modules {
        let code = without_tests(text).join("\n");
        for stmt in code.split(';') {
            let stmt = stmt.trim();
            let Some(spec) = stmt
                .strip_prefix("pub use ")
                .or_else(|| stmt.strip_prefix("pub(crate) use "))
            else {
                continue;
            };
            let spec: String = spec.split_whitespace().collect::<Vec<_>>().join(" ");
            let (base, items): (&str, Vec<&str>) = match spec.find("::{") {
                Some(at) => (
                    &spec[..at],
                    spec[at + 3..].trim_end_matches('}').split(',').collect(),
                ),
                None => match spec.rfind("::") {
                    Some(at) => (&spec[..at], vec![&spec[at + 2..]]),
                    None => continue,
                },
            };
            let mut start: ModPath = module.clone();
            let mut segs: Vec<&str> = base.split("::").collect();
            match segs.first() {
                Some(&"crate") => {
                    start.clear();
                    segs.remove(0);
                }
                Some(&"super") => {
                    start.pop();
                    segs.remove(0);
                }
                Some(&"self") => {
                    segs.remove(0);
                }
                _ => {}
            }
            let mut target = start;
            target.extend(segs.iter().map(|s| s.to_string()));
            for item in items {
                let item = item.trim();
                if item.is_empty() {
                    continue;
                }
                if item == "*" {
                    globs
                        .entry(module.clone())
                        .or_default()
                        .push(target.clone());
                    continue;
                }
                let original = item.split(" as ").next().unwrap_or(item).trim();
                let name = item.rsplit(" as ").next().unwrap_or(item).trim();
                let mut path = target.clone();
                path.extend(original.split("::").map(str::to_string));
                reexports.insert((module.clone(), name.to_string()), path);
            }
        }
    }
    Crate {
        modules,
        reexports,
        globs,
    }
}

/// The edges between sibling modules, projected as described in the module docs.
fn sibling_edges(krate: &Crate) -> BTreeMap<ModPath, BTreeSet<ModPath>> {
    let mut edges: BTreeMap<ModPath, BTreeSet<ModPath>> = BTreeMap::new();
    for (module, text) in &krate.modules {
        if is_test_file(module) {
            continue;
        }
        let code: String = without_tests(text)
            .into_iter()
            .filter(|l| {
                let t = l.trim_start();
                !t.starts_with("//") && !t.starts_with("mod ") && !t.starts_with("pub mod ")
            })
            .collect::<Vec<_>>()
            .join("\n");
        let mut targets: Vec<ModPath> = paths(&code, module)
            .iter()
            .filter_map(|p| krate.resolve(p, 0))
            .collect();
        // A parent naming its child directly (`child::f()`).
        for child in krate.modules.keys() {
            if child.len() == module.len() + 1 && child.starts_with(module) {
                let name = &child[module.len()];
                let pattern = format!("{name}::");
                let used = code.match_indices(&pattern).any(|(at, _)| {
                    !code[..at]
                        .chars()
                        .last()
                        .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':')
                });
                if used {
                    targets.push(child.clone());
                }
            }
        }
        for target in targets {
            let common = module
                .iter()
                .zip(&target)
                .take_while(|(a, b)| a == b)
                .count();
            if common == module.len() || common == target.len() {
                continue; // between a module and its ancestor
            }
            edges
                .entry(module[..=common].to_vec())
                .or_default()
                .insert(target[..=common].to_vec());
        }
    }
    edges
}

/// The cycles of `edges` (strongly connected components of more than one module).
fn cycles(edges: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<ModPath>> {
    // Kosaraju: order by finishing time, then walk the reversed graph.
    let nodes: BTreeSet<ModPath> = edges
        .iter()
        .flat_map(|(a, bs)| std::iter::once(a.clone()).chain(bs.iter().cloned()))
        .collect();
    let mut order = Vec::new();
    let mut seen = BTreeSet::new();
    for start in &nodes {
        if seen.contains(start) {
            continue;
        }
        let mut stack = vec![(start.clone(), false)];
        while let Some((node, done)) = stack.pop() {
            if done {
                order.push(node);
                continue;
            }
            if !seen.insert(node.clone()) {
                continue;
            }
            stack.push((node.clone(), true));
            for next in edges.get(&node).into_iter().flatten() {
                if !seen.contains(next) {
                    stack.push((next.clone(), false));
                }
            }
        }
    }
    let mut reversed: BTreeMap<ModPath, Vec<ModPath>> = BTreeMap::new();
    for (a, bs) in edges {
        for b in bs {
            reversed.entry(b.clone()).or_default().push(a.clone());
        }
    }
    let mut assigned = BTreeSet::new();
    let mut found = Vec::new();
    for root in order.iter().rev() {
        if assigned.contains(root) {
            continue;
        }
        let mut component = Vec::new();
        let mut stack = vec![root.clone()];
        while let Some(node) = stack.pop() {
            if !assigned.insert(node.clone()) {
                continue;
            }
            component.push(node.clone());
            for prev in reversed.get(&node).into_iter().flatten() {
                stack.push(prev.clone());
            }
        }
        if component.len() > 1 {
            found.push(component);
        }
    }
    found
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn no_source_file_holds_more_than_800_lines_of_code() {
    let mut long = Vec::new();
    let mut counted = 0;
    for dir in CRATES {
        let src = root().join(dir);
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        for file in files {
            if is_test_file(&module_of(&src, &file)) {
                continue;
            }
            let text = std::fs::read_to_string(&file).expect("a source file");
            let n = code_lines(&without_tests(&text));
            counted += 1;
            if n > MAX_CODE_LINES {
                let shown = file.strip_prefix(root()).unwrap_or(&file);
                long.push(format!("{}: {n} lines of code", shown.display()));
            }
        }
    }
    assert!(
        counted > 100,
        "the scan reads the workspace's sources ({counted} files)"
    );
    assert!(
        long.is_empty(),
        "split these files by concept:\n{}",
        long.join("\n")
    );
}

#[test]
fn no_module_imports_back_a_module_that_imports_it() {
    let mut found = Vec::new();
    for dir in CRATES {
        let krate = load(&root().join(dir));
        for cycle in cycles(&sibling_edges(&krate)) {
            let names: Vec<String> = cycle
                .iter()
                .map(|m| {
                    if m.is_empty() {
                        "lib".into()
                    } else {
                        m.join("::")
                    }
                })
                .collect();
            found.push(format!("{dir}: {}", names.join(" ↔ ")));
        }
    }
    assert!(found.is_empty(), "module circles:\n{}", found.join("\n"));
}

/// The scanner sees the edges it must: the runtime's `simulate` uses `unilateral`, the
/// command line's `sweep` its child `merge` through the parent, and a made-up pair of
/// modules that import each other is a circle.
#[test]
fn the_scanner_sees_known_edges_and_a_planted_circle() {
    let runtime = load(&root().join("runtime/src"));
    let edges = sibling_edges(&runtime);
    let simulate = vec!["simulate".to_string()];
    assert!(edges[&simulate].contains(&vec!["unilateral".to_string()]));
    assert!(edges[&simulate].contains(&vec!["dynamics".to_string()]));

    let module = |name: &str, text: &str| (vec![name.to_string()], text.to_string());
    let planted = Crate {
        modules: BTreeMap::from([
            (
                Vec::new(),
                "mod a;\nmod b;\nmod c;\npub use a::Thing;".to_string(),
            ),
            module("a", "use crate::b::helper;\npub struct Thing;"),
            module("b", "pub fn helper() { crate::Thing; }"),
            module("c", "use super::a;"),
        ]),
        reexports: BTreeMap::from([(
            (Vec::new(), "Thing".to_string()),
            vec!["a".to_string(), "Thing".to_string()],
        )]),
        globs: BTreeMap::new(),
    };
    let found = cycles(&sibling_edges(&planted));
    assert_eq!(
        found.len(),
        1,
        "a ↔ b through the root's re-export: {found:?}"
    );
    assert_eq!(found[0].len(), 2);
}
