//! What the command line guarantees about a user's files and time, one test per guarantee:
//! nothing is lost (every setting is checked before a file is touched; a failed, refused or
//! interrupted run leaves an existing result byte for byte; a complete result replaces an
//! older one only whole; a run directory never mixes two runs), problems are found before
//! running and diagnosed for what they are, and runs from files do not collide.

use crate::common;

use common::{camchain, scratch};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A built-in model's file text.
fn model_text(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../models/{name}.ron"));
    std::fs::read_to_string(path).expect("a built-in model file")
}

/// `text` with `old` replaced by `new` (which must occur).
fn edit(text: &str, old: &str, new: &str) -> String {
    assert!(text.contains(old), "`{old}` is not in the text");
    text.replacen(old, new, 1)
}

/// Writes a file in `dir` and returns its path.
fn write(dir: &Path, name: &str, content: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, content).expect("a file in the scratch directory");
    path
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_dir() {
                pending.push(path);
            } else {
                files.insert(path.clone(), std::fs::read(&path).expect("readable"));
            }
        }
    }
    files
}

const PRECIOUS: &str = "precious results, kept by hand\n";

/// `precious.csv` holding [`PRECIOUS`] in `dir`.
fn precious(dir: &Path) -> PathBuf {
    write(dir, "precious.csv", PRECIOUS)
}

fn assert_precious(path: &Path) {
    assert_eq!(
        std::fs::read_to_string(path).expect("still there"),
        PRECIOUS,
        "{} changed",
        path.display()
    );
}

// ---------------------------------------------------------------------------------------
// 1. Never lose a user's data.

/// The paper model with only q4 left to solve and the cam 10 m below: the tip's circle
/// about joint 4 (0.3 m) cannot reach it.
fn out_of_reach() -> String {
    let paper = model_text("paper_concave");
    let held = edit(
        &paper,
        "hold: [\"q1\", \"q2\", \"q4\"]",
        "hold: [\"q1\", \"q2\", \"q3\"]",
    );
    edit(&held, "profile: \"a1*x", "profile: \"-10.0 + a1*x")
}

#[test]
fn restitution_with_rk4_is_refused_before_the_run_and_the_csv_survives() {
    let dir = scratch("trust-restitution");
    let csv = precious(&dir);
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--restitution",
            "0.5",
            "--integrator",
            "rk4",
            "--csv",
            "precious.csv",
        ],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.starts_with("error: --restitution needs an adaptive integrator"),
        "{stderr}"
    );
    assert_precious(&csv);
    assert!(!dir.join("precious.partial.csv").exists());
}

#[test]
fn a_model_that_cannot_be_assembled_leaves_the_csv_as_it_was() {
    let dir = scratch("trust-assembly");
    let csv = precious(&dir);
    let model = write(&dir, "far.ron", &out_of_reach());
    let out = camchain(
        &dir,
        &["simulate", model.to_str().unwrap(), "--csv", "precious.csv"],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("far.ron:") && stderr.contains(": initial: "),
        "{stderr}"
    );
    assert_precious(&csv);
    assert!(!dir.join("precious.partial.csv").exists());
}

#[test]
fn a_typo_in_dt_out_or_t_end_is_refused_and_the_previous_run_survives() {
    let dir = scratch("trust-typo");
    let good = camchain(&dir, &["simulate", "paper_concave", "--t-end", "0.3", "-q"]);
    assert_eq!(good.status.code(), Some(0), "{}", text(&good.stderr));
    let before = snapshot(&dir.join("out"));
    assert!(
        before.len() >= 7,
        "the CSV and six figures: {:?}",
        before.keys()
    );
    for (flag, value) in [("--dt-out", "1e-9"), ("--t-end", "1e12")] {
        let out = camchain(&dir, &["simulate", "paper_concave", flag, value, "-q"]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag}: {stderr}");
        assert!(stderr.starts_with(&format!("error: {flag}: ")), "{stderr}");
        // A run that streams its CSV keeps no trajectory (issue 25): held to the billion
        // samples a streamed run may have.
        assert!(
            stderr.contains("samples, more than the 1e9 a run streams"),
            "{stderr}"
        );
        assert_eq!(
            snapshot(&dir.join("out")),
            before,
            "{flag} {value} touched out/"
        );
    }
}

/// A copy of the two-link scenario (`cli/scenarios/unreachable.ron`) that runs `t_end`
/// seconds: complete for t_end < π/3, failing at π/3 beyond.
fn arm(t_end: f64) -> String {
    let text = include_str!("../../scenarios/unreachable.ron");
    edit(text, "t_end: 2.0", &format!("t_end: {t_end:?}"))
}

#[test]
fn a_failed_run_keeps_the_previous_complete_run_and_later_runs_never_touch_its_rows() {
    let dir = scratch("trust-mix");
    let model = write(&dir, "arm.ron", &arm(0.5));
    let path = model.to_str().unwrap();
    let first = camchain(&dir, &["simulate", path, "-q"]);
    assert_eq!(first.status.code(), Some(0), "{}", text(&first.stderr));
    let run_dir = dir.join("out/arm");
    let complete = snapshot(&run_dir);
    assert!(complete.contains_key(&run_dir.join("arm.csv")));
    // The same run name, now failing at t = π/3: the complete run stays as it was, the
    // failed run's rows sit beside it under a name that says they are partial.
    write(&dir, "arm.ron", &arm(2.0));
    let failed = camchain(&dir, &["simulate", path, "-q"]);
    let stderr = text(&failed.stderr);
    assert_eq!(failed.status.code(), Some(1), "{stderr}");
    let partial = run_dir.join("arm.partial.csv");
    let mut after = snapshot(&run_dir);
    let rows = after.remove(&partial).expect("the failed run's rows");
    assert_eq!(after, complete, "the earlier complete run was changed");
    assert!(
        text(&rows).lines().count() > 100,
        "rows up to t = π/3 (0.01 s apart)"
    );
    assert!(
        stderr.contains("are in out/arm/arm.partial.csv"),
        "{stderr}"
    );
    // A complete run again: it replaces arm.csv and touches nothing it did not create,
    // neither the kept rows nor the earlier figures (it draws none with --no-plots).
    write(&dir, "arm.ron", &arm(0.5));
    let again = camchain(&dir, &["simulate", path, "-q", "--no-plots"]);
    assert_eq!(again.status.code(), Some(0), "{}", text(&again.stderr));
    assert_eq!(std::fs::read(&partial).expect("kept"), rows);
    let mut now = snapshot(&run_dir);
    now.remove(&partial);
    let csv = run_dir.join("arm.csv");
    assert!(now.remove(&csv).is_some());
    let mut earlier = complete.clone();
    earlier.remove(&csv);
    assert_eq!(now, earlier, "the earlier figures are as they were");
}

/// The lines of standard error of a running child, as they come.
fn stderr_lines(child: &mut std::process::Child) -> mpsc::Receiver<String> {
    let stderr = child.stderr.take().expect("piped");
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    receive
}

#[test]
fn a_long_run_streams_its_rows_reports_progress_and_stops_cleanly_on_ctrl_c() {
    if !cfg!(unix) {
        return;
    }
    let dir = scratch("trust-interrupt");
    let csv = write(&dir, "run.csv", PRECIOUS);
    // The numeric reference at a tight tolerance: about 100 s of work for 1e5 s of motion.
    let mut child = Command::new(env!("CARGO_BIN_EXE_camchain"))
        .args([
            "simulate",
            "paper_concave",
            "--numeric",
            "--t-end",
            "100000",
        ])
        .args(["--dt-out", "0.1", "--rtol", "1e-12", "--csv", "run.csv"])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let lines = stderr_lines(&mut child);
    let partial = dir.join("run.partial.csv");
    // Rows reach the partial file while the run goes on (flushed every second).
    let start = Instant::now();
    let streamed = loop {
        let rows = std::fs::read_to_string(&partial).map_or(0, |t| t.lines().count());
        if rows > 10 || start.elapsed() > Duration::from_secs(20) {
            break rows;
        }
        std::thread::sleep(Duration::from_millis(200));
    };
    assert!(streamed > 10, "rows streamed within 20 s: {streamed}");
    // Without a terminal, a progress line after about 10 s.
    let progress = lines
        .recv_timeout(Duration::from_secs(30))
        .expect("a progress line within 30 s");
    assert!(
        progress.starts_with("paper_concave_numeric: t = ") && progress.contains(" %), "),
        "{progress}"
    );
    let pid = child.id().to_string();
    let sent = Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .expect("kill runs");
    assert!(sent.success());
    let deadline = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(status) = child.try_wait().expect("waits") {
            break status;
        }
        assert!(Instant::now() < deadline, "still running 30 s after Ctrl-C");
        std::thread::sleep(Duration::from_millis(100));
    };
    assert_eq!(status.code(), Some(130));
    let rest: Vec<String> = lines.try_iter().collect();
    assert!(
        rest.iter()
            .any(|l| l.starts_with("paper_concave_numeric: stopped by Ctrl-C at t = ")),
        "{rest:?}"
    );
    assert!(
        rest.iter().any(|l| l.ends_with("are in run.partial.csv")),
        "{rest:?}"
    );
    assert_precious(&csv);
    // The partial file is complete up to its last row: header, then increasing times.
    let content = std::fs::read_to_string(&partial).expect("the partial CSV");
    assert!(content.ends_with('\n'), "the last row is whole");
    let times: Vec<f64> = content
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap_or("").parse().expect("a time"))
        .collect();
    assert!(times.len() > 10 && times.windows(2).all(|w| w[1] > w[0]));
}

// ---------------------------------------------------------------------------------------
// 2. Check everything before running, the same way everywhere.

#[test]
fn tolerances_outside_a_sane_range_are_usage_errors_naming_the_flag() {
    let dir = scratch("trust-tolerances");
    for (flag, value) in [
        ("--rtol", "1e-20"),
        ("--rtol", "5"),
        ("--atol", "0"),
        ("--atol", "2"),
    ] {
        let out = camchain(&dir, &["simulate", "paper_concave", flag, value]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag} {value}: {stderr}");
        assert!(stderr.contains(&format!("'{flag} <TOL>'")), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
    }
    assert!(!dir.join("out").exists(), "nothing ran");
}

/// The located error of `camchain <command> FILE` (the line after `error: `).
fn located_error(dir: &Path, command: &str, file: &Path) -> String {
    let out = camchain(dir, &[command, file.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{command}: {}",
        text(&out.stderr)
    );
    let stderr = text(&out.stderr);
    stderr
        .strip_prefix("error: ")
        .unwrap_or_else(|| panic!("{stderr}"))
        .trim_end()
        .to_string()
}

#[test]
fn a_model_file_gets_the_same_located_diagnoses_as_the_build() {
    let dir = scratch("trust-diagnoses");
    let paper = model_text("paper_concave");
    let cases = [
        ("unreachable", out_of_reach(), "cannot reach the cam"),
        (
            "all_held",
            edit(
                &paper,
                "hold: [\"q1\", \"q2\", \"q4\"]",
                "hold: [\"q1\", \"q2\", \"q3\", \"q4\"]",
            ),
            "1 contact needs a coordinate that is neither held nor driven, and 0 are free",
        ),
        (
            "slider_out_of_plane",
            edit(
                &paper,
                "kind: Prismatic,\n                axis: (1.0, 0.0, 0.0)",
                "kind: Prismatic,\n                axis: (0.0, 0.0, 1.0)",
            ),
            "(q3) do not move the contact point across the cam",
        ),
        (
            "two_contacts_one_point",
            edit(
                &edit(
                    &edit(
                        &paper,
                        "hold: [\"q1\", \"q2\", \"q4\"]",
                        "hold: [\"q1\", \"q2\"]",
                    ),
                    "(name: \"A\", body: \"body4\", position: (\"l4\", 0.0, 0.0)),",
                    "(name: \"A\", body: \"body4\", position: (\"l4\", 0.0, 0.0)),\n        (name: \"B\", body: \"body4\", position: (0.3, 0.0, 0.0)),",
                ),
                "(marker: \"A\", profile: \"a1*x + a2*x*x + a3*x.powi(3)\"),",
                "(marker: \"A\", profile: \"a1*x + a2*x*x + a3*x.powi(3)\"),\n        (marker: \"B\", profile: \"-0.595*x + 0.5*x*x + 0.5*x.powi(3)\"),",
            ),
            "contacts A and B constrain the same motion",
        ),
    ];
    for (name, content, phrase) in cases {
        let file = write(&dir, &format!("{name}.ron"), &content);
        let simulate = located_error(&dir, "simulate", &file);
        // `camchain ops FILE` runs the build's own code path (generation included).
        let build = located_error(&dir, "ops", &file);
        assert_eq!(simulate, build, "{name}");
        let prefix = format!("{}:", file.display());
        assert!(
            simulate.starts_with(&prefix) && simulate.contains(": initial: "),
            "{simulate}"
        );
        assert!(simulate.contains(phrase), "{name}: {simulate}");
    }
}

#[test]
fn integrator_names_are_accepted_in_the_same_spelling_in_files_and_on_the_command_line() {
    let dir = scratch("trust-integrators");
    for name in ["DOP853", "Dop853", "dop853"] {
        let out = camchain(
            &dir,
            &[
                "simulate",
                "double_pendulum",
                "--integrator",
                name,
                "--t-end",
                "0.1",
                "--csv",
                "-",
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{name}: {}", text(&out.stderr));
        assert!(text(&out.stderr).contains("dop853 (rtol"), "{name}");
    }
    let model = edit(
        &model_text("double_pendulum"),
        "simulation: (",
        "simulation: (integrator: rk4, ",
    );
    let file = write(&dir, "lower_case.ron", &model);
    let out = camchain(
        &dir,
        &[
            "simulate",
            file.to_str().unwrap(),
            "--t-end",
            "0.1",
            "--csv",
            "-",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("rk4 (dt 0.001 s)"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn a_byte_order_mark_at_the_start_of_a_model_file_is_accepted() {
    let dir = scratch("trust-bom");
    let file = write(
        &dir,
        "bom.ron",
        &format!("\u{feff}{}", model_text("paper_concave")),
    );
    let out = camchain(
        &dir,
        &["simulate", file.to_str().unwrap(), "--t-end", "0.1", "-q"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    // An error in such a file is located as in the same file without the mark.
    let bad = edit(&model_text("paper_concave"), "mass: \"m2\",", "mass: -0.5,");
    let with = write(&dir, "with.ron", &format!("\u{feff}{bad}"));
    let without = write(&dir, "without.ron", &bad);
    let located = |file: &Path| {
        let message = located_error(&dir, "simulate", file);
        message
            .split_once(": ")
            .map(|(_, rest)| rest.to_string())
            .unwrap_or(message)
    };
    let (a, b) = (located(&with), located(&without));
    let position = |m: &str| m.split(':').take(2).collect::<Vec<_>>().join(":");
    assert_eq!(
        a.replace("with.ron", ""),
        b.replace("without.ron", ""),
        "{a} / {b}"
    );
    let _ = position;
}

// ---------------------------------------------------------------------------------------
// 3. Say what happened, and diagnose the real cause.

/// A two-link arm (1 m links) hinged at the origin with its tip on the flat cam y = −0.5,
/// with `joint1` added to its first joint and the given initial section.
fn two_links(joint1: &str, initial: &str) -> String {
    format!(
        r#"(
    name: "arm",
    bodies: [
        (name: "upper", parent: "ground", mass: 1.0, com: (0.5, 0.0, 0.0), inertia: Izz(0.08),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (0.0, 0.0, 0.0),
                 coordinate: "q1", {joint1})),
        (name: "lower", parent: "upper", mass: 1.0, com: (0.5, 0.0, 0.0), inertia: Izz(0.08),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (1.0, 0.0, 0.0),
                 coordinate: "q2", spring: (damping: 0.1))),
    ],
    markers: [(name: "tip", body: "lower", position: (1.0, 0.0, 0.0))],
    contacts: [(marker: "tip", profile: "-0.5 + 0.0*x")],
    initial: {initial},
    simulation: (t_end: 0.2, dt_out: 0.01),
)"#
    )
}

#[test]
fn assembly_reports_what_it_changed_and_takes_the_root_nearest_the_guess() {
    let dir = scratch("trust-assembled");
    // q1 = 0 held: sin q2 = −0.5, roots −π/6 (1.92 rad from the guess 1.4) and 7π/6.
    let file = write(
        &dir,
        "arm.ron",
        &two_links("", r#"(q: {"q1": 0.0, "q2": 1.4}, hold: ["q1"])"#),
    );
    let out = camchain(&dir, &["simulate", file.to_str().unwrap(), "--no-plots"]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        stdout.starts_with("assembled: q2 1.400000 → -0.523599 (the root of h nearest the guess)"),
        "{stdout}"
    );
    assert!(
        stderr.contains("warning: arm: initial.q[\"q2\"] = 1.400000 had to move to -0.523599 rad"),
        "{stderr}"
    );
    // A drive overrides a given value, and a given velocity of the solved coordinate is
    // replaced by the one J q̇ = 0 gives: both said.
    let file = write(
        &dir,
        "driven.ron",
        &two_links(
            r#"prescribed: "0.2 + 0.5*t""#,
            r#"(q: {"q1": -1.9}, qd: {"q2": 5.0})"#,
        ),
    );
    let out = camchain(&dir, &["simulate", file.to_str().unwrap(), "--no-plots"]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        stdout.contains("q1 -1.900000 → 0.200000 (set by its drive)"),
        "{stdout}"
    );
    assert!(
        stderr.contains("initial.q[\"q1\"] = -1.900000 is overridden by the drive of q1"),
        "{stderr}"
    );
    assert!(
        stderr.contains("initial.qd[\"q2\"] = 5.000000 is replaced by"),
        "{stderr}"
    );
}

#[test]
fn cannot_reach_only_when_h_has_not_converged_and_a_dead_point_is_named() {
    let dir = scratch("trust-dead-point");
    let file = write(&dir, "arm.ron", &arm(2.0));
    let path = file.to_str().unwrap();
    // Dormand–Prince stops at the dead point (the arm stretched, the tip on the cam).
    let adaptive = camchain(&dir, &["simulate", path, "--integrator", "dop853", "-q"]);
    let stderr = text(&adaptive.stderr);
    assert!(
        stderr.contains("locks at a dead point") && !stderr.contains("cannot reach"),
        "{stderr}"
    );
    // RK4's step lands beyond it, where |h| cannot be made small.
    let rk4 = camchain(
        &dir,
        &[
            "simulate",
            path,
            "--integrator",
            "rk4",
            "--dt",
            "0.01",
            "-q",
        ],
    );
    let stderr = text(&rk4.stderr);
    assert!(stderr.contains("cannot reach the cam"), "{stderr}");
    let residual: f64 = stderr
        .split("|h|∞ = ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|r| r.parse().ok())
        .expect("the residual in the message");
    assert!(residual > 1e-9, "h has not converged: {residual}");
}

#[test]
fn results_that_are_almost_surely_a_modelling_mistake_are_warned_about() {
    let dir = scratch("trust-warnings");
    let paper = model_text("paper_concave");
    // Gravity upwards: the arm pulls away from the cam, which holds it (a negative force).
    let upside = write(
        &dir,
        "upside.ron",
        &edit(
            &paper,
            "gravity: (0.0, \"-g\", 0.0)",
            "gravity: (0.0, \"g\", 0.0)",
        ),
    );
    let out = camchain(
        &dir,
        &[
            "simulate",
            upside.to_str().unwrap(),
            "--t-end",
            "1",
            "--no-plots",
        ],
    );
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("warning: upside: the normal force on A is negative from the start"),
        "{stderr}"
    );
    assert!(stderr.contains("the cam pulls the follower"), "{stderr}");
    // Degrees for radians, and a huge speed, located in the file.
    let degrees = edit(
        &paper,
        "\"q4\": 0.0}",
        "\"q4\": 30.0}, qd: {\"q1\": 5000.0}",
    );
    let file = write(&dir, "degrees.ron", &degrees);
    let out = camchain(
        &dir,
        &[
            "simulate",
            file.to_str().unwrap(),
            "--t-end",
            "0.01",
            "--no-plots",
        ],
    );
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("initial.q[\"q4\"]: the initial angle of q4 is 30 rad")
            && stderr.contains("degrees?"),
        "{stderr}"
    );
    assert!(
        stderr.contains("initial.qd[\"q1\"]: the initial speed of q1, 5000 rad/s, is huge"),
        "{stderr}"
    );
    // The summary gives the energy drift against the energy scale.
    let out = camchain(
        &dir,
        &["simulate", "paper_concave", "--t-end", "1", "--no-plots"],
    );
    assert!(
        text(&out.stdout).contains(" of the energy scale "),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn the_rk4_header_says_the_step_it_actually_takes() {
    let dir = scratch("trust-rk4");
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--integrator",
            "rk4",
            "--dt",
            "0.003",
            "--t-end",
            "0.1",
            "--no-plots",
        ],
    );
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains(
            "rk4 (dt 0.003 s; each 0.01 s output interval takes 4 steps, the \
        last shortened to 0.001 s)"
        ),
        "{stdout}"
    );
}

#[test]
fn help_texts_name_dop853_where_it_applies() {
    let dir = scratch("trust-help");
    let out = camchain(&dir, &["simulate", "--help"]);
    let help = text(&out.stdout);
    for option in ["--dt <SECONDS>", "--rtol <TOL>", "--atol <TOL>"] {
        let at = help.find(option).unwrap_or_else(|| panic!("{option}"));
        let paragraph = &help[at..help[at..].find("\n\n").map_or(help.len(), |e| at + e)];
        assert!(paragraph.contains("dop853"), "{paragraph}");
    }
}

// ---------------------------------------------------------------------------------------
// 4. Runs from files do not collide.

#[test]
fn runs_from_files_are_named_after_the_file_and_never_overwrite_each_other() {
    let dir = scratch("trust-names");
    let paper = model_text("paper_concave");
    std::fs::create_dir_all(dir.join("a")).expect("a/");
    std::fs::create_dir_all(dir.join("b")).expect("b/");
    write(&dir, "a/paper_concave.ron", &paper);
    write(&dir, "b/paper_concave.ron", &paper);
    let out = camchain(
        &dir,
        &["simulate", "a/paper_concave.ron", "b/paper_concave.ron"],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("a/paper_concave.ron and b/paper_concave.ron would both be run"),
        "{stderr}"
    );
    assert!(!dir.join("out").exists(), "nothing ran");
    // Any file name will do on the numeric path; the run takes it.
    write(&dir, "cam-v2 final.ron", &paper);
    write(&dir, "2cam.ron", &paper);
    let out = camchain(
        &dir,
        &[
            "simulate",
            "cam-v2 final.ron",
            "2cam.ron",
            "--t-end",
            "0.1",
            "--no-plots",
            "-q",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(dir.join("out/cam-v2 final/cam-v2 final.csv").is_file());
    assert!(dir.join("out/2cam/2cam.csv").is_file());
}

#[test]
fn a_failed_run_prints_one_error_line_and_where_its_rows_are_not_a_summary() {
    let dir = scratch("trust-failure-report");
    let file = write(&dir, "arm.ron", &arm(2.0));
    let out = camchain(&dir, &["simulate", file.to_str().unwrap(), "--no-plots"]);
    assert_eq!(out.status.code(), Some(1));
    let stdout = text(&out.stdout);
    assert!(
        !stdout.contains("quantity") && !stdout.contains("steps,"),
        "{stdout}"
    );
    let stderr = text(&out.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 2, "{stderr}");
    assert!(lines[0].starts_with("error: arm: at t = 1.04"), "{stderr}");
    assert!(
        lines[1].starts_with("arm: the ") && lines[1].ends_with("are in out/arm/arm.partial.csv"),
        "{stderr}"
    );
}
