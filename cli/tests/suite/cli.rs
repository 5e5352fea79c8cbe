//! End-to-end tests of the `camchain` binary: the CSV it writes (header, values equal to
//! the library's, energy balance), the files and figures, and one-line errors with their
//! exit codes for bad input.

use crate::common;
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, Sample, SimSettings, Simulate};

use common::{camchain, scratch};
use std::path::Path;

const PAPER_HEADER: &str = "t,q1,q2,q3,q4,q1_dot,q2_dot,q3_dot,q4_dot,A_x,A_y,A_cam_x,A_cam_y,\
                            A_normal_force,A_sliding_speed,A_h,energy,\
                            dissipated,driven_work";
const DRIVEN_HEADER: &str = "t,q1,q2,q3,q4,q1_dot,q2_dot,q3_dot,q4_dot,A_x,A_y,A_cam_x,A_cam_y,\
                             A_normal_force,A_sliding_speed,A_h,q1_drive,\
                             energy,dissipated,driven_work";

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Header and rows of a CSV; every value parsed with `f64::from_str`.
fn parse_csv(csv: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = csv.lines();
    let header = lines
        .next()
        .expect("a header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|line| {
            line.split(',')
                .map(|v| v.parse().unwrap_or_else(|_| panic!("not a number: {v}")))
                .collect()
        })
        .collect();
    (header, rows)
}

/// The value a column must hold, by its documented meaning.
fn expected(info: &camchain_runtime::ModelInfo, sample: &Sample, column: &str) -> f64 {
    if column == "t" {
        return sample.t;
    }
    match column {
        "energy" => return sample.energy.total(),
        "dissipated" => return sample.dissipated,
        "driven_work" => return sample.driven_work,
        _ => {}
    }
    for (i, c) in info.coordinates.iter().enumerate() {
        if column == c.name {
            return sample.q[i];
        }
        if column == format!("{}_dot", c.name) {
            return sample.qd[i];
        }
        if column == format!("{}_drive", c.name) {
            return sample.drive[i];
        }
    }
    for (k, contact) in info.contacts.iter().enumerate() {
        let geometry = &sample.contacts[k];
        let position = &geometry.position;
        match column.strip_prefix(contact.name.as_str()) {
            Some("_x") => return position[0],
            Some("_y") => return position[1],
            Some("_z") => return position[2],
            Some("_cam_x") => return geometry.x,
            Some("_cam_y") => return geometry.y,
            Some("_cam_angle") => {
                return sample.q[contact.cam_coordinate.expect("a turning cam")];
            }
            Some("_normal_force") => return sample.normal_force[k],
            Some("_pressure_angle") => return geometry.pressure_angle(),
            Some("_sliding_speed") => return geometry.sliding_speed,
            Some("_h") => return sample.h[k],
            _ => {}
        }
    }
    panic!("undocumented column {column}");
}

/// Asserts that the CSV holds exactly the samples of the library's `simulate`.
fn assert_csv_is_the_library_run(csv: &str, model: &dyn Dynamics, settings: &SimSettings) {
    let state = model.assemble(0.0).unwrap();
    let samples = model.simulate(state, settings).unwrap().samples;
    let (header, rows) = parse_csv(csv);
    assert_eq!(rows.len(), samples.len());
    for (row, sample) in rows.iter().zip(&samples) {
        assert_eq!(row.len(), header.len());
        for (value, column) in row.iter().zip(&header) {
            // Same code path (`simulate_observed` is `simulate` with an observer) and
            // shortest round-trip printing: the numbers are identical, bit for bit.
            let want = expected(model.info(), sample, column);
            assert_eq!(
                value.to_bits(),
                want.to_bits(),
                "{column} at t = {}",
                sample.t
            );
        }
    }
}

fn settings_with_t_end(model: &dyn Dynamics, t_end: f64) -> SimSettings {
    SimSettings {
        t_end,
        ..model.info().defaults.clone()
    }
}

#[test]
fn paper_csv_has_the_documented_header_and_the_library_values() {
    let dir = scratch("paper-csv");
    let out = camchain(
        &dir,
        &["simulate", "paper_concave", "--t-end", "0.5", "--csv", "-"],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let csv = text(&out.stdout);
    assert_eq!(csv.lines().next(), Some(PAPER_HEADER));
    assert!(
        text(&out.stderr).contains("paper_concave — generated code"),
        "the summary goes to stderr when the CSV takes stdout"
    );
    let model = models::by_name("paper_concave").unwrap();
    assert_csv_is_the_library_run(&csv, model, &settings_with_t_end(model, 0.5));
    assert!(!dir.join("out").exists(), "--csv alone writes nothing else");
}

#[test]
fn driven_csv_reports_the_drive_and_obeys_the_overrides() {
    let dir = scratch("driven-csv");
    let args = [
        "simulate",
        "driven_convex",
        "--t-end",
        "0.3",
        "--dt-out",
        "0.05",
        "--integrator",
        "rk4",
        "--dt",
        "0.002",
        "--csv",
        "driven.csv",
        "--quiet",
    ];
    let out = camchain(&dir, &args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(out.stdout.is_empty() && out.stderr.is_empty(), "--quiet");
    let csv = std::fs::read_to_string(dir.join("driven.csv")).unwrap();
    assert_eq!(csv.lines().next(), Some(DRIVEN_HEADER));
    let model = models::by_name("driven_convex").unwrap();
    let settings = SimSettings {
        t_end: 0.3,
        dt_out: 0.05,
        integrator: camchain_runtime::IntegratorKind::Rk4,
        dt: 0.002,
        ..model.info().defaults.clone()
    };
    assert_csv_is_the_library_run(&csv, model, &settings);
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "no temporary file is left behind");
}

#[test]
fn numeric_path_matches_the_reference_loaded_from_its_file() {
    let dir = scratch("numeric");
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/paper_convex.ron");
    let by_file = camchain(
        &dir,
        &[
            "simulate",
            file.to_str().unwrap(),
            "--t-end",
            "0.2",
            "--csv",
            "-",
        ],
    );
    assert!(by_file.status.success(), "{}", text(&by_file.stderr));
    assert!(text(&by_file.stderr).contains("numeric recursive reference"));
    let reference = NumericModel::load(&file).unwrap();
    let csv = text(&by_file.stdout);
    assert_csv_is_the_library_run(&csv, &reference, &settings_with_t_end(&reference, 0.2));
    let forced = camchain(
        &dir,
        &[
            "simulate",
            "paper_convex",
            "--numeric",
            "--t-end",
            "0.2",
            "--csv",
            "-",
        ],
    );
    assert!(forced.status.success(), "{}", text(&forced.stderr));
    assert_eq!(
        text(&forced.stdout),
        csv,
        "--numeric runs the same reference"
    );
}

#[test]
fn energy_balance_holds_in_the_csv() {
    // energy + dissipated − driven_work must stay at its initial value. The runs use the
    // models' defaults (Dopri5, rtol 1e-10, atol 1e-12); the dissipated and driven works are
    // quadratures integrated with the motion, and the summary reports 4e-11 J (paper_convex,
    // energies of 10–30 J) and 3e-12 J (driven_convex, works of about 1 J) of drift. The
    // bound 1e-8 J leaves a margin of 250 while an error in any column (a missing damper
    // term, a drive work of the wrong sign) would show at 1e-3 J or more.
    let dir = scratch("energy");
    for name in ["paper_convex", "driven_convex"] {
        let out = camchain(&dir, &["simulate", name, "--csv", "-", "--quiet"]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let (header, rows) = parse_csv(&text(&out.stdout));
        let column = |name: &str| header.iter().position(|c| c == name).unwrap();
        let (e, d, w) = (
            column("energy"),
            column("dissipated"),
            column("driven_work"),
        );
        let balance: Vec<f64> = rows.iter().map(|r| r[e] + r[d] - r[w]).collect();
        let drift = balance
            .iter()
            .map(|b| (b - balance[0]).abs())
            .fold(0.0, f64::max);
        assert!(drift < 1e-8, "{name}: drift {drift:e} J");
        let last = rows.last().unwrap();
        assert!(last[d] > 0.1, "{name}: the dampers dissipate");
        if name == "driven_convex" {
            assert!(last[w].abs() > 1e-3, "the drive works");
        }
    }
}

#[test]
fn the_default_run_writes_csv_and_figures_of_both_cams() {
    let dir = scratch("default");
    let out = camchain(&dir, &["--t-end", "0.5"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    for name in ["paper_concave", "paper_convex"] {
        assert!(
            stdout.contains(&format!("{name} — generated code")),
            "{stdout}"
        );
        let run = dir.join("out").join(name);
        let csv = std::fs::read_to_string(run.join(format!("{name}.csv"))).unwrap();
        assert_eq!(csv.lines().next(), Some(PAPER_HEADER));
        assert_eq!(csv.lines().count(), 1 + 51);
        for figure in ["histories", "snapshots", "contact"] {
            assert_png(&run.join(format!("{figure}.png")));
            let svg = std::fs::read_to_string(run.join(format!("{figure}.svg"))).unwrap();
            assert!(svg.starts_with("<svg"), "{figure}.svg");
        }
    }
    assert_png(&dir.join("out/paper_concave_vs_convex.png"));
    for line in ["max |·|", "max |A_h|", "right-hand sides", "wall time"] {
        assert!(stdout.contains(line), "summary line {line}: {stdout}");
    }
}

#[test]
fn a_turning_cam_writes_its_contact_columns_and_the_follower_figure() {
    let dir = scratch("turning-cam");
    let out = camchain(
        &dir,
        &[
            "simulate",
            "eccentric_roller",
            "--t-end",
            "0.4",
            "--out",
            "runs",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let run = dir.join("runs/eccentric_roller");
    let csv = std::fs::read_to_string(run.join("eccentric_roller.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.contains(
            "roller_x,roller_y,roller_cam_x,roller_cam_y,roller_cam_angle,roller_normal_force,\
             roller_pressure_angle,roller_sliding_speed,roller_h"
        ),
        "{header}"
    );
    let model = models::by_name("eccentric_roller").unwrap();
    assert_csv_is_the_library_run(&csv, model, &settings_with_t_end(model, 0.4));
    for figure in ["snapshots", "contact", "follower"] {
        assert_png(&run.join(format!("{figure}.png")));
    }
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains(
            "roller: roller on a polar profile r(θ) turned by cam_angle; largest pressure angle"
        ),
        "{stdout}"
    );
}

fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{}",
        path.display()
    );
    assert!(bytes.len() > 10_000, "{} is not empty", path.display());
}

#[test]
fn list_names_every_model_with_its_coordinates_and_defaults() {
    let out = camchain(&std::env::temp_dir(), &["list"]);
    assert!(out.status.success());
    let listing = text(&out.stdout);
    for (name, model) in models::ALL.iter() {
        assert!(listing.contains(name));
        for c in &model.info().coordinates {
            assert!(listing.contains(&c.name));
        }
    }
    assert!(listing.contains("contacts:    A"));
    assert!(listing.contains("--t-end 8"));
}

/// Runs a bad command: it must fail with `code` and one line on stderr that contains
/// `message`, without a panic.
fn assert_one_line_error(dir: &Path, args: &[&str], code: i32, message: &str) {
    let out = camchain(dir, args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
    assert!(stderr.contains(message), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
}

#[test]
fn bad_input_gets_one_line_and_an_exit_code() {
    let dir = scratch("bad-input");
    let malformed = dir.join("malformed.ron");
    let source = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/paper_concave.ron"),
    )
    .unwrap()
    .replace("mass: \"m2\",", "mass: -0.5,");
    std::fs::write(&malformed, source).unwrap();
    std::fs::write(dir.join("a_file"), "not a directory").unwrap();
    let cases: [(&[&str], i32, &str); 9] = [
        (
            &["simulate", "paper_concav"],
            2,
            "unknown model `paper_concav`",
        ),
        (
            &["simulate", "missing.ron"],
            1,
            "cannot read model file missing.ron",
        ),
        (&["simulate", "malformed.ron"], 1, "malformed.ron:"),
        (&["simulate", "--t-end", "-1"], 2, "must be positive"),
        (&["simulate", "--t-end", "0"], 2, "must be positive"),
        (
            &["simulate", "--integrator", "euler"],
            2,
            "possible values: rk4, dopri5",
        ),
        (
            &["simulate", "--out", "a_file/out"],
            1,
            "cannot create output directory",
        ),
        (
            &["simulate", "--csv", "x.csv"],
            2,
            "--csv writes the CSV of one model",
        ),
        (
            &["simulate", "paper_concave", "--coords", "q9"],
            2,
            "no coordinate `q9`",
        ),
    ];
    for (args, code, message) in cases {
        assert_one_line_error(&dir, args, code, message);
    }
    assert!(!dir.join("out").exists(), "nothing ran");
}

#[test]
fn a_failed_run_keeps_the_older_result_and_its_own_rows_beside_it() {
    let dir = scratch("failed-run");
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/unreachable.ron");
    let csv = dir.join("result.csv");
    std::fs::write(&csv, "an older, complete result\n").unwrap();
    let out = camchain(
        &dir,
        &["simulate", fixture.to_str().unwrap(), "--csv", "result.csv"],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    // The run is named after its file; one error line, one line saying where the rows are.
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 2, "{stderr}");
    assert!(
        lines[0].starts_with("error: unreachable: at t = 1.04"),
        "{stderr}"
    );
    assert!(lines[1].ends_with("are in result.partial.csv"), "{stderr}");
    assert!(!stderr.contains("panicked"));
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        "an older, complete result\n",
        "the older result survives byte for byte"
    );
    let partial = std::fs::read_to_string(dir.join("result.partial.csv")).unwrap();
    let (header, rows) = parse_csv(&partial);
    assert_eq!(header.last().map(String::as_str), Some("driven_work"));
    let last_t = rows.last().unwrap()[0];
    assert!(
        last_t > 1.0 && last_t < 1.1,
        "stopped near t = pi/3: {last_t}"
    );
    // Standard output gets no CSV at all from a failed run.
    let piped = camchain(&dir, &["simulate", fixture.to_str().unwrap(), "--csv", "-"]);
    assert_eq!(piped.status.code(), Some(1));
    assert!(piped.stdout.is_empty());
}

/// More bad invocations than `bad_input_gets_one_line_and_an_exit_code`: every numeric
/// option with each kind of bad value, unknown flags, directories and unreadable files
/// where files are expected, and a corpus model (`tests/bad_models/`) run from its file.
/// Each must exit with the code, print one `error:` line naming the option or file and
/// every listed phrase, and not panic.
#[test]
fn bad_options_and_files_name_the_flag_and_the_problem() {
    let dir = scratch("bad-options");
    std::fs::create_dir(dir.join("adir")).unwrap();
    std::fs::write(dir.join("a_file"), "not a directory").unwrap();
    std::fs::write(dir.join("empty.ron"), "").unwrap();
    std::fs::write(dir.join("binary.ron"), [0xff, 0xfe, 0x00, 0x28]).unwrap();
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../reference/tests/bad_models");
    let exit_call = corpus.join("profile_process_exit.ron");
    let exit_call = exit_call.to_str().unwrap();
    let positive = "must be positive and finite";
    let mut cases: Vec<(Vec<&str>, i32, Vec<&str>)> = vec![
        (
            vec!["--frobnicate"],
            2,
            vec!["unexpected argument '--frobnicate'"],
        ),
        (
            vec!["list", "extra"],
            2,
            vec!["unexpected argument 'extra'"],
        ),
        (
            vec!["simulate", "driven_convex", "--restitution", "1.5"],
            2,
            vec!["'--restitution <E>'", "not in [0, 1]"],
        ),
        (
            vec![
                "simulate",
                "double_pendulum",
                "--restitution",
                "0.5",
                "--out",
                "runs",
                "-q",
            ],
            2,
            vec!["--restitution", "exactly one cam contact"],
        ),
        (
            vec!["bench", "evaluations", "--report", "/nonexistent/dir/B.md"],
            2,
            vec!["--report", "the directory does not exist"],
        ),
        (
            vec!["bench", "scaling-figure"],
            2,
            vec!["needs --scaling-csv"],
        ),
        (
            vec!["simulate", "--t-end"],
            2,
            vec!["a value is required for '--t-end"],
        ),
        (
            vec!["simulate", "--dt", "abc"],
            2,
            vec!["'--dt <SECONDS>'", "`abc` is not a number"],
        ),
        (
            vec!["simulate", "--integrator", "Euler"],
            2,
            vec!["'--integrator <NAME>'", "possible values: rk4, dopri5"],
        ),
        (
            vec!["simulate", "paper_concave", "--coords", "q4,,q3"],
            2,
            vec!["--coords", "empty coordinate name"],
        ),
        (
            vec!["simulate", "paper_concave", "paper_concave"],
            2,
            vec!["paper_concave is given twice"],
        ),
        (
            vec!["simulate", "adir/"],
            1,
            vec!["cannot read model file adir/", "it is a directory"],
        ),
        (
            vec!["simulate", "binary.ron"],
            1,
            vec!["cannot read model file binary.ron", "UTF-8"],
        ),
        (
            vec!["simulate", "empty.ron"],
            1,
            vec!["error: empty.ron:1:1: <top level>: "],
        ),
        (
            vec!["simulate", exit_call],
            1,
            vec![
                "profile_process_exit.ron:68:54: contacts[0].profile",
                "`std::process::exit` is not a known math function",
            ],
        ),
        (
            vec!["simulate", "paper_concave", "--csv", "adir"],
            1,
            vec!["cannot write adir", "it is a directory"],
        ),
        (
            vec!["simulate", "paper_concave", "--csv", "nowhere/x.csv"],
            1,
            vec![
                "cannot write nowhere/x.csv",
                "directory nowhere does not exist",
            ],
        ),
        (
            // 0.01 s / 1e-300 s steps per output interval: refused before running.
            vec!["simulate", "--integrator", "rk4", "--dt", "1e-300"],
            2,
            vec!["--dt", "rk4 step of 1e-300 s", "steps per output interval"],
        ),
        (
            vec!["simulate", "paper_concave", "--out", "a_file"],
            1,
            vec!["cannot create output directory a_file"],
        ),
    ];
    // Every numeric option with each kind of bad value: zero, negative (in exponent form,
    // which clap would otherwise take for a flag), NaN, infinities.
    for flag in ["--t-end", "--dt", "--dt-out", "--rtol", "--atol"] {
        for value in ["0", "-1e-3", "NaN", "inf", "-inf"] {
            cases.push((vec!["simulate", flag, value], 2, vec![flag, positive]));
        }
    }
    let mut failures = Vec::new();
    for (args, code, phrases) in &cases {
        let out = camchain(&dir, args);
        let stderr = text(&out.stderr);
        let mut problems = Vec::new();
        if out.status.code() != Some(*code) {
            problems.push(format!("exit code {:?}, want {code}", out.status.code()));
        }
        if stderr.lines().count() != 1 || !stderr.starts_with("error: ") {
            problems.push("not one `error:` line".to_string());
        }
        if stderr.contains("panicked") {
            problems.push("panicked".to_string());
        }
        for phrase in phrases {
            if !stderr.contains(phrase) {
                problems.push(format!("lacks `{phrase}`"));
            }
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{args:?}: {} — stderr: {stderr}",
                problems.join("; ")
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(!dir.join("out").exists(), "nothing ran");
}

/// `--help`'s first line says what the tool does now: cam mechanisms from model files with
/// their kinds of follower and cam, not only a tip sliding on a fixed cam.
#[test]
fn help_first_line_describes_the_tool_of_today() {
    let dir = scratch("help-first-line");
    let out = camchain(&dir, &["--help"]);
    assert_eq!(out.status.code(), Some(0));
    let help = text(&out.stdout);
    let first = help.lines().next().unwrap_or_default();
    assert!(!first.contains("fixed cam"), "{first}");
    for kind in [
        "model files",
        "closed loops",
        "roller",
        "flat",
        "moving cams",
    ] {
        assert!(first.contains(kind), "{kind} missing from: {first}");
    }
}
