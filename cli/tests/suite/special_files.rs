//! Output to files that are not regular files: a FIFO and a character device node get the
//! data written directly and stay what they are (before, `--csv` replaced a FIFO by a regular
//! file, so its reader got nothing, and run as root turned a null device into a regular file
//! for the whole machine). The nodes are made in a temporary directory (`mkfifo`, `mknod`
//! where permitted; otherwise the device test says it is skipped), never the machine's own
//! null device.
#![cfg(unix)]

use crate::common;

use common::{camchain, scratch};
use std::fs;
use std::io::Read;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::Command;
use std::sync::mpsc;
use std::thread;
use std::time::Duration;

fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
}

/// A null device node (major 1, minor 3) at `path`, or `None` where this user may not make
/// device nodes.
fn mknod_null(path: &Path) -> Option<()> {
    let made = Command::new("mknod")
        .args(["-m", "666"])
        .arg(path)
        .args(["c", "1", "3"])
        .output()
        .ok()?;
    (made.status.success() && fs::metadata(path).ok()?.file_type().is_char_device()).then_some(())
}

/// Reads everything a FIFO delivers, on a thread (the writer's open blocks until a reader
/// has opened it, and the reader's until a writer has).
struct FifoReader(mpsc::Receiver<String>);

impl FifoReader {
    fn start(path: &Path) -> Self {
        let path = path.to_path_buf();
        let (send, receive) = mpsc::channel();
        thread::spawn(move || {
            let mut text = String::new();
            fs::File::open(&path)
                .and_then(|mut f| f.read_to_string(&mut text))
                .expect("the FIFO can be read");
            let _ = send.send(text);
        });
        FifoReader(receive)
    }

    /// What the reader got, once the writer has closed the FIFO. A reader still waiting
    /// after 30 s (a writer that never opened the FIFO, e.g. because it replaced it with a
    /// regular file) fails the test instead of hanging it; the blocked thread ends with
    /// the test process.
    fn received(self) -> String {
        self.0
            .recv_timeout(Duration::from_secs(30))
            .expect("the FIFO's reader got an end of data (the writer opened and closed it)")
    }
}

const RUN: &[&str] = &["simulate", "paper_concave", "--t-end", "0.2", "-q", "--csv"];

fn unreachable_scenario() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/unreachable.ron")
        .display()
        .to_string()
}

#[test]
fn a_csv_to_a_fifo_reaches_its_reader_and_the_fifo_stays() {
    let dir = scratch("fifo");
    let fifo = dir.join("rows.csv");
    mkfifo(&fifo);
    let reader = FifoReader::start(&fifo);
    let out = camchain(&dir, &[RUN, &["rows.csv"]].concat());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let received = reader.received();
    // The same run to a regular file: the reader must have got exactly these bytes.
    let regular = camchain(&dir, &[RUN, &["regular.csv"]].concat());
    assert_eq!(regular.status.code(), Some(0));
    let expected = fs::read_to_string(dir.join("regular.csv")).expect("a regular CSV");
    assert!(expected.starts_with("t,q1,q2,q3,q4,"), "{expected}");
    assert_eq!(received, expected);
    let kind = fs::symlink_metadata(&fifo)
        .expect("still there")
        .file_type();
    assert!(kind.is_fifo(), "the FIFO was replaced: {kind:?}");
    assert!(
        !dir.join(".rows.csv.tmp").exists(),
        "no temporary file beside it"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_failed_run_closes_a_fifo_without_data_or_files_beside_it() {
    let dir = scratch("fifo-failed");
    let fifo = dir.join("rows.csv");
    mkfifo(&fifo);
    let reader = FifoReader::start(&fifo);
    let scenario = unreachable_scenario();
    let out = camchain(&dir, &["simulate", &scenario, "-q", "--csv", "rows.csv"]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "the scenario's run fails at t = π/3"
    );
    assert_eq!(reader.received(), "", "no rows of a failed run");
    assert!(
        fs::symlink_metadata(&fifo)
            .expect("still there")
            .file_type()
            .is_fifo()
    );
    let names: Vec<String> = fs::read_dir(&dir)
        .expect("readable")
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    assert_eq!(
        names,
        ["rows.csv"],
        "no partial or temporary file beside the FIFO"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_device_node_is_written_and_kept_for_csv_figures_and_reports() {
    let dir = scratch("device");
    let node = dir.join("null");
    if mknod_null(&node).is_none() {
        eprintln!(
            "skipped: this user cannot make device nodes (mknod) in {}",
            dir.display()
        );
        let _ = fs::remove_dir_all(&dir);
        return;
    }
    let check = |what: &str| {
        let kind = fs::symlink_metadata(&node)
            .expect("still there")
            .file_type();
        assert!(
            kind.is_char_device(),
            "{what} replaced the device node: {kind:?}"
        );
    };
    let out = camchain(&dir, &[RUN, &["null"]].concat());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    check("a complete CSV");
    let scenario = unreachable_scenario();
    let failed = camchain(&dir, &["simulate", &scenario, "-q", "--csv", "null"]);
    assert_eq!(failed.status.code(), Some(1));
    check("a failed run");
    assert!(
        !dir.join("null.partial").exists(),
        "no partial file beside a device"
    );
    // A device in place of one of the figures of an output directory.
    let run_dir = dir.join("out").join("paper_concave");
    fs::create_dir_all(&run_dir).expect("a run directory");
    let figure = run_dir.join("contact.svg");
    assert!(mknod_null(&figure).is_some(), "mknod worked above");
    let plotted = camchain(&dir, &["simulate", "paper_concave", "--t-end", "0.2", "-q"]);
    assert_eq!(
        plotted.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&plotted.stderr)
    );
    let kind = fs::symlink_metadata(&figure)
        .expect("still there")
        .file_type();
    assert!(kind.is_char_device(), "the figure replaced the device node");
    assert!(
        run_dir.join("contact.png").is_file(),
        "the other figures are written"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_symbolic_link_to_a_regular_file_keeps_the_link_and_replaces_its_target() {
    let dir = scratch("symlink");
    let target = dir.join("target.csv");
    fs::write(&target, "older\n").expect("a target");
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&target, &link).expect("a symbolic link");
    let out = camchain(&dir, &[RUN, &["link.csv"]].concat());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        fs::symlink_metadata(&link)
            .expect("there")
            .file_type()
            .is_symlink()
    );
    let written = fs::read_to_string(&target).expect("the target");
    assert!(
        written.starts_with("t,q1,"),
        "the target holds the new CSV: {written}"
    );
    let _ = fs::remove_dir_all(&dir);
}
