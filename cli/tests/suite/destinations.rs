//! The files runs share (issue 25 §1–3, §6): two runs never write one destination, a kept
//! partial file is never touched by a later run, links are resolved before the run, a full
//! disk never leaves a torn row. Each test is named after the finding it answers.

use crate::common;

use common::{camchain, scratch};
use std::fs;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::Path;
use std::process::{Child, Command, Stdio};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn start(dir: &Path, args: &[String]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_camchain"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts")
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

/// A file's content without the sweep CSV's `wall_time` cells (the one column that differs
/// between two runs of the same sweep).
fn comparable(content: &str) -> String {
    let mut wall = None;
    let mut out = String::new();
    for line in content.lines() {
        let cells: Vec<&str> = line.split(',').collect();
        if line.starts_with("run,") {
            wall = cells.iter().position(|c| *c == "wall_time");
        }
        let kept: Vec<&str> = cells
            .iter()
            .enumerate()
            .filter(|(k, _)| Some(*k) != wall || line.starts_with('#'))
            .map(|(_, c)| *c)
            .collect();
        out.push_str(&kept.join(","));
        out.push('\n');
    }
    out
}

/// The commands of one trial: 4 runs of `simulate` with different parameters and 2 pairs
/// of sweep shards, all to `same.csv`.
fn contenders() -> Vec<Vec<String>> {
    let mut commands = Vec::new();
    for k3 in ["20", "40", "60", "80"] {
        commands.push(strings(&[
            "simulate",
            "paper_concave",
            "--param",
            &format!("k3={k3}"),
            "--t-end",
            "5",
            "-q",
            "--csv",
            "same.csv",
        ]));
    }
    for values in ["k3=20,40,60,80", "k3=30,50,70,90"] {
        for shard in ["1/2", "2/2"] {
            commands.push(strings(&[
                "sweep",
                "paper_concave",
                "--param",
                values,
                "--t-end",
                "1",
                "--shard",
                shard,
                "-q",
                "--csv",
                "same.csv",
            ]));
        }
    }
    commands
}

#[test]
fn two_runs_one_output_give_one_runs_complete_file_never_a_mix() {
    let dir = scratch("dest-race");
    // Each command's complete output, alone (deterministic but for sweeps' wall times).
    let commands = contenders();
    let alone: Vec<String> = commands
        .iter()
        .map(|args| {
            let out = Command::new(env!("CARGO_BIN_EXE_camchain"))
                .args(args)
                .current_dir(&dir)
                .output()
                .expect("runs");
            assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
            comparable(&fs::read_to_string(dir.join("same.csv")).expect("written"))
        })
        .collect();
    fs::remove_file(dir.join("same.csv")).expect("removed");
    let mut refused = 0;
    for trial in 0..20 {
        let children: Vec<Child> = commands.iter().map(|args| start(&dir, args)).collect();
        let results: Vec<(Option<i32>, String)> = children
            .into_iter()
            .map(|child| {
                let out = child.wait_with_output().expect("waited");
                (out.status.code(), text(&out.stderr))
            })
            .collect();
        let succeeded: Vec<usize> = (0..results.len())
            .filter(|&k| results[k].0 == Some(0))
            .collect();
        for (code, stderr) in &results {
            assert!(
                *code == Some(0) || stderr.contains("being written by another camchain run"),
                "trial {trial}: a run failed for another reason ({code:?}): {stderr}"
            );
        }
        assert!(!succeeded.is_empty(), "trial {trial}: no run completed");
        refused += results.len() - succeeded.len();
        let content = comparable(&fs::read_to_string(dir.join("same.csv")).expect("a file"));
        assert!(
            succeeded.iter().any(|&k| alone[k] == content),
            "trial {trial}: same.csv is not the complete output of a run that exited 0 \
             ({succeeded:?})"
        );
        // Nothing left behind: no partial, temporary or lock file.
        let mut names: Vec<String> = fs::read_dir(&dir)
            .expect("listed")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["same.csv"], "trial {trial}");
    }
    // The trials did put runs in each other's way (8 started together, each lasting many
    // times the time to start the next).
    assert!(
        refused > 0,
        "no run was ever refused: the test raced nothing"
    );
    eprintln!("{refused} of {} runs refused", 20 * commands.len());
    let _ = fs::remove_dir_all(&dir);
}

/// The two-link scenario of `cli/scenarios/unreachable.ron`: fails at t = π/3 after rows.
fn failing_model(dir: &Path) -> String {
    let text = include_str!("../../scenarios/unreachable.ron");
    let path = dir.join("arm.ron");
    fs::write(&path, text).expect("written");
    path.to_string_lossy().into_owned()
}

#[test]
fn the_next_run_never_destroys_what_an_interrupted_run_kept() {
    let dir = scratch("dest-kept");
    let model = failing_model(&dir);
    // A failed run keeps its rows in res.partial.csv.
    let first = camchain(&dir, &["simulate", &model, "-q", "--csv", "res.csv"]);
    assert_eq!(first.status.code(), Some(1), "{}", text(&first.stderr));
    assert!(
        text(&first.stderr).contains("are in res.partial.csv"),
        "{}",
        text(&first.stderr)
    );
    let kept = fs::read(dir.join("res.partial.csv")).expect("kept rows");
    // The same run again: its rows go to a new name, the kept ones stay byte for byte.
    let second = camchain(&dir, &["simulate", &model, "-q", "--csv", "res.csv"]);
    assert_eq!(second.status.code(), Some(1));
    assert!(
        text(&second.stderr).contains("are in res.partial-2.csv"),
        "{}",
        text(&second.stderr)
    );
    assert_eq!(fs::read(dir.join("res.partial.csv")).expect("there"), kept);
    // A run that fails at once (a bad parameter) touches neither.
    let third = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--param",
            "k3=-1",
            "--csv",
            "res.csv",
        ],
    );
    assert_eq!(third.status.code(), Some(2), "{}", text(&third.stderr));
    assert_eq!(fs::read(dir.join("res.partial.csv")).expect("there"), kept);
    // A complete run writes res.csv and leaves both partial files.
    let fourth = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--t-end",
            "0.2",
            "-q",
            "--csv",
            "res.csv",
        ],
    );
    assert_eq!(fourth.status.code(), Some(0), "{}", text(&fourth.stderr));
    assert_eq!(fs::read(dir.join("res.partial.csv")).expect("there"), kept);
    assert!(dir.join("res.partial-2.csv").exists());
    // A user's own file of a partial-looking name is neither truncated nor renamed.
    fs::write(dir.join("report.partial.csv"), "mine\n").expect("written");
    let fifth = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--t-end",
            "0.2",
            "-q",
            "--csv",
            "report.csv",
        ],
    );
    assert_eq!(fifth.status.code(), Some(0), "{}", text(&fifth.stderr));
    assert_eq!(
        fs::read_to_string(dir.join("report.partial.csv")).expect("there"),
        "mine\n"
    );
    assert!(
        fs::read_to_string(dir.join("report.csv"))
            .expect("written")
            .starts_with("t,")
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_dangling_symlink_is_resolved_before_the_run_and_written_through() {
    let dir = scratch("dest-links");
    std::os::unix::fs::symlink(dir.join("created.csv"), dir.join("dang.csv")).expect("link");
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--t-end",
            "0.2",
            "-q",
            "--csv",
            "dang.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        fs::symlink_metadata(dir.join("dang.csv"))
            .expect("there")
            .file_type()
            .is_symlink()
    );
    assert!(
        fs::read_to_string(dir.join("created.csv"))
            .expect("the link's target")
            .starts_with("t,")
    );
    // A link into a directory that does not exist: refused before the run, naming it.
    std::os::unix::fs::symlink(dir.join("nowhere/x.csv"), dir.join("deep.csv")).expect("link");
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--t-end",
            "1000",
            "-q",
            "--csv",
            "deep.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("does not exist"),
        "{}",
        text(&out.stderr)
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_replaced_file_keeps_its_mode_and_owner_and_a_hard_link_is_refused() {
    let dir = scratch("dest-mode");
    let private = dir.join("private.csv");
    fs::write(&private, "older\n").expect("written");
    fs::set_permissions(&private, fs::Permissions::from_mode(0o600)).expect("chmod");
    // As root the owner can be given away and must come back; otherwise the file is ours.
    let root = fs::metadata(&dir).expect("there").uid() == 0;
    if root {
        std::os::unix::fs::chown(&private, Some(12345), Some(12345)).expect("chown");
    }
    std::os::unix::fs::symlink(&private, dir.join("link.csv")).expect("link");
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--t-end",
            "0.2",
            "-q",
            "--csv",
            "link.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let meta = fs::metadata(&private).expect("replaced");
    assert_eq!(meta.mode() & 0o7777, 0o600);
    if root {
        assert_eq!((meta.uid(), meta.gid()), (12345, 12345));
    }
    assert!(
        fs::read_to_string(&private)
            .expect("read")
            .starts_with("t,")
    );
    // A second name for the same file: refused before the run, both names unchanged.
    fs::hard_link(&private, dir.join("other.csv")).expect("hard link");
    let before = fs::read(&private).expect("read");
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--t-end",
            "1000",
            "-q",
            "--csv",
            "private.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("2 hard links"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(fs::read(&private).expect("read"), before);
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn on_a_full_disk_the_partial_csv_ends_with_a_complete_row_and_the_error_names_it() {
    let dir = scratch("dest-full");
    // A file size limit stands in for a full disk: writes beyond 1024 blocks (512 KiB or
    // 1 MiB, as the shell counts them) fail (EFBIG) as they do with ENOSPC, part of a write
    // landing first. SIGXFSZ is ignored so that the write fails instead of the process
    // being killed. 10 000 rows of ~400 bytes do not fit.
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f 1024; exec '{}' simulate paper_concave --t-end 100 -q \
             --no-plots --csv full.csv",
            env!("CARGO_BIN_EXE_camchain")
        ))
        .current_dir(&dir)
        .output()
        .expect("runs");
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("cannot write full.partial.csv"), "{stderr}");
    assert!(!dir.join("full.csv").exists(), "no complete file claimed");
    let content = fs::read_to_string(dir.join("full.partial.csv")).expect("the rows kept");
    assert!(content.ends_with('\n'), "a torn last row");
    let mut lines = content.lines();
    let columns = lines.next().expect("a header").split(',').count();
    let mut rows = 0;
    for line in lines {
        assert_eq!(line.split(',').count(), columns, "a torn row: {line}");
        rows += 1;
    }
    assert!(rows > 100, "the rows before the limit are kept ({rows})");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_sweep_to_a_full_device_names_the_file() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let dir = scratch("dest-devfull");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "paper_concave",
            "--param",
            "k3=20,40",
            "--t-end",
            "0.5",
            "-q",
            "--csv",
            "/dev/full",
        ],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("/dev/full"), "{stderr}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_directory_as_the_stress_report_is_refused_before_the_suite_runs() {
    let dir = scratch("dest-stress");
    fs::create_dir_all(dir.join("report")).expect("a directory");
    let out = camchain(&dir, &["stress", "--quick", "--out", "report"]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("is a directory"), "{stderr}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_csv_in_the_current_directory_is_reported_by_its_name() {
    let dir = scratch("dest-name");
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--t-end",
            "0.2",
            "--no-plots",
            "--csv",
            "n.csv",
        ],
    );
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(stdout.contains("wrote n.csv\n"), "{stdout}");
    let _ = fs::remove_dir_all(&dir);
}
