//! Runs that cannot progress say so and stop, and signals are answered at once (issue 24):
//! a run whose steps collapse ends with the stall diagnosis and keeps its partial CSV; Ctrl-C
//! (SIGINT) and SIGTERM stop a run between its outputs and a sweep's runs in flight within a
//! second, keep what was computed, and exit with 130 and 143.
//!
//! The tests of this file run one at a time (a lock): a signal's answer time is measured,
//! and a run of n_four_bar beside it would slow it down.

use crate::common;

use common::{camchain, scratch};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// One test at a time in this binary.
static ALONE: Mutex<()> = Mutex::new(());

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn spawn(dir: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_camchain"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts")
}

/// Sends `signal` (`INT` or `TERM`) to the child and returns how long it took to exit, its
/// exit code and standard error.
fn signal_and_wait(child: Child, signal: &str) -> (Duration, Option<i32>, String) {
    let sent = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success());
    let start = Instant::now();
    let output = child.wait_with_output().expect("it ends");
    (start.elapsed(), output.status.code(), text(&output.stderr))
}

#[test]
fn a_run_whose_steps_collapse_ends_with_the_stall_diagnosis() {
    let _alone = ALONE.lock().unwrap_or_else(|e| e.into_inner());
    let dir = scratch("stall");
    // The tip body of the paper's chain nearly massless: its steps collapse towards
    // t = 0.2757 s (issue 24: no error, no progress line, for minutes).
    let start = Instant::now();
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--numeric",
            "--param",
            "m4=1e-12",
            "--param",
            "J4=1e-12",
            "--no-plots",
            "--csv",
            "tiny.csv",
        ],
    );
    let err = text(&out.stderr);
    eprintln!("tiny mass: ended after {:.2?}", start.elapsed());
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("has stalled") && err.contains("collapsed") && err.contains("rtol 1e-10"),
        "{err}"
    );
    assert!(err.contains("are in tiny.partial.csv"), "{err}");
    let partial = std::fs::read_to_string(dir.join("tiny.partial.csv")).expect("kept");
    assert!(
        partial.lines().count() > 20,
        "the rows until the stall are kept"
    );
    // A bound against a hang, not a timing: the run stalls after 0.2 s of simulated time
    // and the watchdog needs 500 steps to see it (measured: under a second).
    assert!(start.elapsed() < Duration::from_secs(60));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn n_four_bar_at_tight_tolerances_completes_or_reports_its_stall() {
    let _alone = ALONE.lock().unwrap_or_else(|e| e.into_inner());
    let dir = scratch("n-four-bar");
    // IFToMM A02 at rtol 1e-11 and 1e-12 (issue 24: printed nothing for 250 s and 600 s).
    // The steps collapse at a horizontal (singular) position; the run must either pass it
    // or stop there with the diagnosis, within seconds of reaching it.
    let runs: Vec<_> = [("1e-11", "1e-13"), ("1e-12", "1e-14")]
        .iter()
        .map(|&(rtol, atol)| {
            let csv = format!("nfb_{rtol}.csv");
            let args = [
                "simulate",
                "n_four_bar",
                "--rtol",
                rtol,
                "--atol",
                atol,
                "--no-plots",
                "-q",
                "--csv",
                &csv,
            ];
            (rtol, Instant::now(), spawn(&dir, &args))
        })
        .collect();
    for (rtol, start, child) in runs {
        let output = child.wait_with_output().expect("it ends");
        let err = text(&output.stderr);
        eprintln!(
            "n_four_bar at rtol {rtol}: ended after {:.2?}",
            start.elapsed()
        );
        match output.status.code() {
            Some(0) => assert!(dir.join(format!("nfb_{rtol}.csv")).exists()),
            Some(1) => {
                assert!(err.contains("has stalled"), "{err}");
                assert!(dir.join(format!("nfb_{rtol}.partial.csv")).exists());
            }
            code => panic!("rtol {rtol}: exit code {code:?}: {err}"),
        }
        // Against a hang: the 20 s run takes ~5 s of steps before any stall.
        assert!(start.elapsed() < Duration::from_secs(120));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ctrl_c_and_sigterm_stop_a_run_between_its_outputs_within_a_second() {
    let _alone = ALONE.lock().unwrap_or_else(|e| e.into_inner());
    let dir = scratch("signals-run");
    for (signal, code, name) in [("INT", 130, "Ctrl-C"), ("TERM", 143, "SIGTERM")] {
        let csv = format!("run_{signal}.csv");
        // Outputs 1000 s apart: the signal arrives between two, where the run was deaf to
        // it before (only looked at at output times).
        let child = spawn(
            &dir,
            &[
                "simulate",
                "paper_concave",
                "--numeric",
                "--t-end",
                "100000",
                "--dt-out",
                "1000",
                "--rtol",
                "1e-12",
                "--no-plots",
                "--csv",
                &csv,
            ],
        );
        let partial = dir.join(format!("run_{signal}.partial.csv"));
        let start = Instant::now();
        // The first row (t = 0) is written at once; wait for it, then a little longer.
        while std::fs::read_to_string(&partial).map_or(0, |t| t.lines().count()) < 2 {
            assert!(start.elapsed() < Duration::from_secs(30), "no first row");
            std::thread::sleep(Duration::from_millis(50));
        }
        std::thread::sleep(Duration::from_millis(500));
        let (took, status, err) = signal_and_wait(child, signal);
        eprintln!("{name}: the run ended {took:.2?} after the signal");
        assert_eq!(status, Some(code), "{err}");
        assert!(
            took < Duration::from_secs(1),
            "{name} answered after {took:.2?}"
        );
        assert!(
            err.contains(&format!("paper_concave_numeric: stopped by {name} at t = ")),
            "{err}"
        );
        assert!(
            err.contains(&format!("are in run_{signal}.partial.csv")),
            "{err}"
        );
        let content = std::fs::read_to_string(&partial).expect("the partial CSV");
        assert!(content.ends_with('\n') && content.lines().count() >= 2);
        assert!(!dir.join(&csv).exists(), "no complete result was claimed");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ctrl_c_and_sigterm_cancel_a_sweeps_runs_in_flight_within_a_second() {
    let _alone = ALONE.lock().unwrap_or_else(|e| e.into_inner());
    let dir = scratch("signals-sweep");
    for (signal, code, name) in [("INT", 130, "Ctrl-C"), ("TERM", 143, "SIGTERM")] {
        let csv = format!("sweep_{signal}.csv");
        // Eight runs of 1e5 s each: none finishes before the signal; before, the sweep
        // waited for every run in flight.
        let child = spawn(
            &dir,
            &[
                "sweep",
                "paper_concave",
                "--param",
                "k3=20:80:8",
                "--t-end",
                "100000",
                "--dt-out",
                "1000",
                "--rtol",
                "1e-12",
                "--jobs",
                "2",
                "--csv",
                &csv,
            ],
        );
        std::thread::sleep(Duration::from_millis(1500));
        let (took, status, err) = signal_and_wait(child, signal);
        eprintln!("{name}: the sweep ended {took:.2?} after the signal");
        assert_eq!(status, Some(code), "{err}");
        assert!(
            took < Duration::from_secs(1),
            "{name} answered after {took:.2?}"
        );
        assert!(
            err.contains(&format!("stopped by {name} after 0 of 8 runs")),
            "{err}"
        );
        // No run finished: the partial file this sweep created holds no row and is removed
        // (nothing else is: the directory holds what it held before).
        let partial = dir.join(format!("sweep_{signal}.partial.csv"));
        assert!(!partial.exists(), "a partial CSV without a row is left");
        assert!(!err.contains("rows so far"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
