//! `camchain fmu` given bad input: a one-line error and its exit code, found before any
//! build starts, and no file written. (Exports themselves are checked against FMPy by the
//! Python suite, `python/tests/test_fmu.py`.)

use crate::common::{camchain, scratch};
use std::fs;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn bad_input_gives_one_line_and_writes_nothing() {
    let dir = scratch("fmu-bad-input");
    fs::write(dir.join("broken.ron"), "(name: \"broken\", bodies: [").expect("file");
    fs::write(dir.join("not_a_library.so"), "text").expect("file");
    // (arguments, exit code, what the message must say)
    let cases: [(&[&str], i32, &str); 6] = [
        (&["fmu"], 2, "<MODEL>"),
        (
            &["fmu", "no_such_model"],
            2,
            "unknown model `no_such_model`",
        ),
        (&["fmu", "broken.ron"], 1, "broken.ron:1:"),
        (
            &["fmu", "cycloidal_roller", "--out", "missing/dir/x.fmu"],
            1,
            "missing/dir",
        ),
        (&["fmu", "--library", "nowhere.so"], 1, "no such library"),
        (
            &["fmu", "--library", "not_a_library.so"],
            1,
            "not_a_library.so",
        ),
    ];
    for (args, code, says) in cases {
        let out = camchain(&dir, args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert_eq!(
            err.trim_end().lines().count(),
            1,
            "{args:?}: one line: {err}"
        );
    }
    let mut left: Vec<String> = fs::read_dir(&dir)
        .expect("dir")
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["broken.ron", "not_a_library.so"], "nothing written");
    let _ = fs::remove_dir_all(&dir);
}
