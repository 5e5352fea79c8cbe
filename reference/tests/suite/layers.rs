//! The reference's modules import each other without a circle: the kinematics the
//! recursion, the cam contacts and the loops share (poses, motions, vectors) live in
//! `motion`, which imports none of them, and `contact` and `loops` do not reach back into
//! `numeric`, which uses both. Asserted on the sources' `crate::` paths (comments apart):
//! `contact` and `loops` (then `closure`) used to take `Pose`, `Motion` and `vec3` from `numeric`.

use std::path::Path;

/// The modules of the crate that `file` (in src/) names by a `crate::` path, in order of
/// appearance, comments apart.
fn imports(file: &str) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(file);
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = Vec::new();
    for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
        for (at, _) in line.match_indices("crate::") {
            let module: String = line[at + "crate::".len()..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !out.contains(&module) {
                out.push(module);
            }
        }
    }
    out
}

#[test]
fn the_shared_kinematics_import_none_of_their_users() {
    assert!(
        imports("motion.rs").is_empty(),
        "{:?}",
        imports("motion.rs")
    );
}

#[test]
fn contacts_and_loops_do_not_import_the_recursion() {
    // The recursion does import both (so the check below is on real import lines).
    let numeric = imports("numeric.rs");
    assert!(numeric.contains(&"contact".to_string()) && numeric.contains(&"loops".to_string()));
    for file in ["contact.rs", "loops.rs"] {
        let found = imports(file);
        assert!(found.contains(&"motion".to_string()), "{file}: {found:?}");
        assert!(!found.contains(&"numeric".to_string()), "{file}: {found:?}");
    }
}
