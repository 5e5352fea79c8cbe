//! Model and table files are read with a bound on their size (16 MiB): a path naming a
//! device without end (`/dev/zero`) or a huge file is refused with an error naming the file
//! and the limit, instead of being read until memory runs out.

use camchain_codegen::schema::{MAX_FILE_BYTES, load_model};
use camchain_codegen::{generate_file, read_model_file};
use std::fs;
use std::path::{Path, PathBuf};

/// A fresh directory under the system's temporary directory.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("camchain-{test}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("a temporary directory");
    dir
}

/// A sparse file of `len` bytes (no disk space taken, nothing to read quickly).
fn sparse(path: &Path, len: u64) {
    fs::File::create(path)
        .and_then(|f| f.set_len(len))
        .expect("a sparse file");
}

#[test]
fn a_model_file_beyond_the_size_limit_is_refused_with_its_name_and_the_limit() {
    let dir = scratch("huge-model");
    let path = dir.join("huge.ron");
    let len = MAX_FILE_BYTES as u64 * 64;
    sparse(&path, len);
    let shown = Path::new("models/huge.ron");
    let from_build = read_model_file(&path, shown).expect_err("refused");
    let from_ops = generate_file(&path, shown).expect_err("refused");
    let from_schema = load_model(&path).expect_err("refused");
    for (e, file) in [
        (from_build, shown.to_path_buf()),
        (from_ops, shown.to_path_buf()),
        (from_schema, path.clone()),
    ] {
        assert_eq!(e.file, file);
        let message = e.to_string();
        assert!(
            message.contains(&format!("it is {len} bytes long, more than 16 MiB")),
            "{message}"
        );
    }
    fs::remove_dir_all(&dir).expect("cleaned up");
}

#[cfg(unix)]
#[test]
fn dev_zero_as_a_model_file_is_refused_after_the_limit() {
    let e = generate_file(Path::new("/dev/zero"), Path::new("/dev/zero")).expect_err("refused");
    let message = e.to_string();
    assert!(
        message.starts_with("/dev/zero: ") && message.contains("more than 16 MiB"),
        "{message}"
    );
}

#[test]
fn a_table_file_beyond_the_size_limit_is_refused_at_its_field() {
    let dir = scratch("huge-table");
    fs::create_dir_all(dir.join("tables")).expect("a directory");
    let model = dir.join("table_cam.ron");
    let source =
        fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/table_cam.ron"))
            .expect("the built-in model");
    fs::write(&model, source).expect("written");
    sparse(
        &dir.join("tables/cycloidal_roller_profile.csv"),
        MAX_FILE_BYTES as u64 + 1,
    );
    let e = load_model(&model).expect_err("refused");
    assert_eq!(e.field, "contacts[0].table.file");
    assert!(
        e.message.contains("cycloidal_roller_profile.csv")
            && e.message.contains("more than 16 MiB"),
        "{e}"
    );
    fs::remove_dir_all(&dir).expect("cleaned up");
}
