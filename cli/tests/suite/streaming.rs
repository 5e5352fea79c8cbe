//! Long runs in bounded memory (issue 25): a run whose CSV streams to a file keeps no
//! trajectory, so its memory does not grow with its length, and neither it nor a sweep is
//! held to the million samples a kept trajectory may have; a CSV written at the end
//! (standard output, a special file) still keeps every sample and is held to that cap.

use crate::common;

use common::{camchain, scratch};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The `peak memory X MB` a run's summary ends with.
fn peak_memory(stdout: &str) -> f64 {
    let line = stdout
        .lines()
        .find_map(|l| l.trim().strip_prefix("peak memory "))
        .unwrap_or_else(|| panic!("no peak memory in {stdout}"));
    line.trim_end_matches(" MB")
        .parse()
        .unwrap_or_else(|e| panic!("{line}: {e}"))
}

/// `simulate paper_concave --no-plots` to `t_end` at its 0.01 s outputs: (peak memory in MB,
/// rows of the CSV, the summary).
fn streamed_run(dir: &Path, t_end: &str) -> (f64, usize, String) {
    let csv = format!("run-{t_end}.csv");
    let out = camchain(
        dir,
        &[
            "simulate",
            "paper_concave",
            "--no-plots",
            "--csv",
            &csv,
            "--t-end",
            t_end,
        ],
    );
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let rows = std::fs::read_to_string(dir.join(&csv))
        .expect("the CSV")
        .lines()
        .count()
        - 1;
    (peak_memory(&stdout), rows, stdout)
}

#[test]
fn a_long_no_plots_run_keeps_no_trajectory() {
    // The finding: a run with --no-plots and a streamed CSV kept every sample (about 780 MB
    // at a million samples of paper_concave, 88 MB at 1e5). Now 1e5 samples take what 1e3
    // take: the allowance of 16 MB is for the allocator and the CSV's buffers; the old code
    // needed some 75 MB more at 1e5 samples.
    let dir = scratch("streaming-memory");
    let (short, short_rows, _) = streamed_run(&dir, "10");
    let (long, long_rows, summary) = streamed_run(&dir, "1000");
    assert_eq!((short_rows, long_rows), (1001, 100_001));
    assert!(
        long <= short + 16.0,
        "1e5 samples: {long:.1} MB, 1e3 samples: {short:.1} MB"
    );
    assert!(long <= 50.0, "{long:.1} MB");
    assert!(
        summary.contains("t = 0 to 1000 s, 100001 samples"),
        "{summary}"
    );
}

#[test]
fn a_streamed_run_is_not_held_to_a_million_samples() {
    // Ten million samples (t_end 1e5 s at 0.01 s): refused before issue 25, now run; stopped
    // here by SIGTERM once its CSV has rows, which keeps them.
    let dir = scratch("streaming-long");
    let mut child = Command::new(env!("CARGO_BIN_EXE_camchain"))
        .args([
            "simulate",
            "paper_concave",
            "--no-plots",
            "--csv",
            "long.csv",
            "--t-end",
            "1e5",
            "-q",
        ])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let partial = dir.join("long.partial.csv");
    let start = Instant::now();
    while std::fs::metadata(&partial).map_or(0, |m| m.len()) < 100_000 {
        if let Ok(Some(status)) = child.try_wait() {
            panic!("ended early: {status}");
        }
        assert!(start.elapsed() < Duration::from_secs(120), "no rows");
        std::thread::sleep(Duration::from_millis(20));
    }
    let sent = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success());
    let out = child.wait_with_output().expect("it ends");
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(143), "{stderr}");
    assert!(stderr.contains("stopped by SIGTERM"), "{stderr}");
    assert!(!dir.join("long.csv").exists());
    // Beyond the streamed runs' cap, and beyond a kept trajectory's when the CSV is written
    // at the end (to standard output), the settings are refused before anything runs.
    for (args, cap) in [
        (
            &["--csv", "x.csv", "--dt-out", "1e-9"][..],
            "the 1e9 a run streams",
        ),
        (&["--csv", "-", "--t-end", "2e4"][..], "the 1e6 a run keeps"),
    ] {
        let mut all = vec!["simulate", "paper_concave", "--no-plots", "-q"];
        all.extend_from_slice(args);
        let out = camchain(&dir, &all);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(cap), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty());
    }
    // A special file gets its CSV at the end too: the run keeps its samples, and the
    // runtime refuses more than a kept trajectory may have, in one line, before a step.
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--no-plots",
            "-q",
            "--csv",
            "/dev/null",
            "--t-end",
            "2e4",
        ],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: paper_concave: ") && stderr.contains("the 1e6 a run keeps"),
        "{stderr}"
    );
}

#[test]
fn a_sweep_is_not_held_to_a_million_output_times() {
    // The finding: a sweep refused more than 1e6 output times although it keeps no
    // trajectory. Ten million (t_end 1 s at 1e-7 s) now run; beyond the streamed runs' cap
    // they are refused.
    let dir = scratch("streaming-sweep");
    let sweep = |dt_out: &str| {
        camchain(
            &dir,
            &[
                "sweep",
                "paper_concave",
                "--param",
                "swing=0.05,0.1",
                "--t-end",
                "1",
                "--dt-out",
                dt_out,
                "--no-plots",
                "--csv",
                "sweep.csv",
                "-q",
            ],
        )
    };
    let out = sweep("1e-7");
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let rows = std::fs::read_to_string(dir.join("sweep.csv")).expect("the sweep's CSV");
    let data: Vec<&str> = rows
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .collect();
    assert_eq!(data.len(), 2, "{rows}");
    assert!(data.iter().all(|r| r.contains(",ok,")), "{rows}");
    let out = sweep("1e-10");
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("the 1e9 a run streams"), "{stderr}");
}

/// `simulate driven_convex` to `t_end` with its figures: (peak memory in MB, the figures
/// written, the summary).
fn run_with_figures(dir: &Path, t_end: &str) -> (f64, Vec<String>, String) {
    let out_dir = format!("out-{t_end}");
    let out = camchain(
        dir,
        &[
            "simulate",
            "driven_convex",
            "--out",
            &out_dir,
            "--t-end",
            t_end,
        ],
    );
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let mut names: Vec<String> = std::fs::read_dir(dir.join(&out_dir).join("driven_convex"))
        .expect("the run's directory")
        .map(|e| {
            e.expect("an entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n.ends_with(".png"))
        .collect();
    names.sort();
    (peak_memory(&stdout), names, stdout)
}

#[test]
fn a_long_runs_figures_are_drawn_from_a_bounded_copy() {
    // 2e4 samples are drawn whole; 2e5 from a copy of at most 20 000 (every 16th, the
    // first and the last, and the two around the lift-off the contact figure marks). The
    // old code kept all 2e5 (some 150 MB more); the allowance of 16 MB is for the
    // allocator and the CSV's buffers, the copies being the same size.
    let dir = scratch("streaming-figures");
    let (short, short_figures, _) = run_with_figures(&dir, "200");
    let (long, long_figures, summary) = run_with_figures(&dir, "2000");
    assert_eq!(long_figures, short_figures);
    assert_eq!(
        long_figures,
        ["contact.png", "histories.png", "snapshots.png"]
    );
    assert!(
        long <= short + 16.0,
        "2e5 samples: {long:.1} MB, 2e4 samples: {short:.1} MB"
    );
    assert!(summary.contains("200001 samples"), "{summary}");
}
