//! `camchain sweep` and `camchain merge` (issue 12 §2, §4), run as a user runs them: rows in
//! run order with their parameters, metrics that agree with `camchain simulate` of the same
//! run, shards that merge into the unsharded sweep, failed runs as rows and in the exit
//! code, and every bad input refused before a run with one line naming it.

use crate::common;

use common::{camchain, scratch};
use std::path::Path;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The data rows of a sweep CSV (after the `#` lines and the header), split into cells.
fn rows(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let content =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = content.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines
        .next()
        .expect("a header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

#[test]
fn a_sweep_writes_one_row_per_run_in_order_with_its_parameter_values() {
    let dir = scratch("sweep-grid");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "paper_concave",
            "--param",
            "swing=0:0.2:3",
            "--param",
            "k3=30,60",
            "--t-end",
            "1",
            "--csv",
            "grid.csv",
            "--jobs",
            "2",
            "-q",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(out.stdout.is_empty() && out.stderr.is_empty(), "quiet");
    let (header, rows) = rows(&dir.join("grid.csv"));
    assert_eq!(&header[..4], ["run", "swing", "k3", "status"]);
    assert_eq!(rows.len(), 6);
    let expected = [
        ("0.0", "30.0"),
        ("0.0", "60.0"),
        ("0.1", "30.0"),
        ("0.1", "60.0"),
        ("0.2", "30.0"),
        ("0.2", "60.0"),
    ];
    for (k, (row, (swing, k3))) in rows.iter().zip(expected).enumerate() {
        assert_eq!(row[0], k.to_string(), "in run order");
        assert_eq!((row[1].as_str(), row[2].as_str()), (swing, k3));
        assert_eq!(row[3], "ok");
        let t: f64 = row[column(&header, "t_reached")].parse().expect("a number");
        assert_eq!(t, 1.0);
    }
    // The stiffer spring pushes harder: the metrics follow the parameters.
    let force =
        |r: &Vec<String>| -> f64 { r[column(&header, "max_normal_force")].parse().expect("N") };
    assert!(force(&rows[1]) > force(&rows[0]));
    assert!(!dir.join("grid.partial.csv").exists());
}

#[test]
fn a_run_of_the_sweep_is_the_run_simulate_makes_with_those_values() {
    // driven_convex lifts off (the bilateral force turns negative) at t = 5.18 s with the
    // file's values; with another drive period the time moves. The sweep's first_lift_off
    // for period = 4.5 s must be simulate's event with --param period=4.5, both located to
    // 1e-9 s on the dense output.
    let dir = scratch("sweep-vs-simulate");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "driven_convex",
            "--param",
            "period=3.5,4.5",
            "--csv",
            "s.csv",
            "-q",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let (header, rows) = rows(&dir.join("s.csv"));
    let lift = |k: usize| -> f64 {
        rows[k][column(&header, "first_lift_off")]
            .parse()
            .expect("a lift-off")
    };
    let out = camchain(
        &dir,
        &[
            "simulate",
            "driven_convex",
            "--param",
            "period=4.5",
            "--no-plots",
            "--out",
            "sim",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let summary = text(&out.stdout);
    assert!(
        summary.contains("generated code with period = 4.5"),
        "{summary}"
    );
    let event = summary
        .lines()
        .find(|l| l.contains("becomes negative"))
        .and_then(|l| l.trim().strip_prefix("t = "))
        .and_then(|l| l.split(' ').next())
        .and_then(|t| t.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("an event in {summary}"));
    assert!((lift(1) - event).abs() < 2e-9, "{} vs {event}", lift(1));
    assert!(
        (lift(0) - lift(1)).abs() > 0.1,
        "the period moves the lift-off"
    );
}

#[test]
fn shards_merge_into_the_unsharded_sweep() {
    let dir = scratch("sweep-shards");
    let common_args = [
        "sweep",
        "paper_concave",
        "--param",
        "swing=-0.2:0.2:5",
        "--param",
        "c3=0.5,1.5",
        "--t-end",
        "0.5",
        "-q",
    ];
    let run = |extra: &[&str]| {
        let args: Vec<&str> = common_args.iter().chain(extra).copied().collect();
        let out = camchain(&dir, &args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    };
    run(&["--csv", "whole.csv"]);
    for i in 1..=3 {
        run(&[
            "--shard",
            &format!("{i}/3"),
            "--csv",
            &format!("part{i}.csv"),
        ]);
    }
    let (_, part2) = rows(&dir.join("part2.csv"));
    let indices: Vec<&str> = part2.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(indices, ["1", "4", "7"], "every third run from the second");
    // In any order: merge sorts the shards itself.
    let out = camchain(
        &dir,
        &[
            "merge",
            "part3.csv",
            "part1.csv",
            "part2.csv",
            "--csv",
            "merged.csv",
            "--out",
            "figs",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(dir.join("figs/heatmaps.png").exists());
    // merge knows a built-in model's units too.
    let svg = std::fs::read_to_string(dir.join("figs/heatmaps.svg")).expect("the SVG");
    assert!(svg.contains("swing [rad]") && svg.contains("c3 [N s/m]"));
    let (h1, whole) = rows(&dir.join("whole.csv"));
    let (h2, merged) = rows(&dir.join("merged.csv"));
    assert_eq!(h1, h2);
    assert_eq!(whole.len(), 10);
    assert_eq!(merged.len(), 10);
    let wall = column(&h1, "wall_time");
    for (a, b) in whole.iter().zip(&merged) {
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            if k != wall {
                assert_eq!(x, y, "column {}", h1[k]);
            }
        }
    }
    let first = std::fs::read_to_string(dir.join("merged.csv")).expect("read");
    assert!(first.lines().nth(1) == Some("# shard 1/1"));
}

#[test]
fn merge_refuses_a_missing_repeated_truncated_or_foreign_shard() {
    let dir = scratch("sweep-merge-bad");
    let sweep = |param: &str, shard: &str, file: &str| {
        let out = camchain(
            &dir,
            &[
                "sweep",
                "paper_concave",
                "--param",
                param,
                "--t-end",
                "0.2",
                "--shard",
                shard,
                "--csv",
                file,
                "-q",
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    };
    sweep("k3=30:60:4", "1/2", "a1.csv");
    sweep("k3=30:60:4", "2/2", "a2.csv");
    sweep("k3=30:60:5", "2/2", "b2.csv");
    let content = std::fs::read_to_string(dir.join("a2.csv")).expect("read");
    let truncated: String = content.lines().take(6).map(|l| format!("{l}\n")).collect();
    std::fs::write(dir.join("cut.csv"), truncated).expect("write");
    let extra = format!("{content}{}", content.lines().last().unwrap_or_default());
    std::fs::write(dir.join("extra.csv"), extra).expect("write");
    for (files, phrase) in [
        (&["a1.csv"][..], "shard 2/2 of this sweep is missing"),
        (
            &["a1.csv", "a1.csv", "a2.csv"][..],
            "shard 1/2 is given twice",
        ),
        (&["a1.csv", "b2.csv"][..], "are not shards of one sweep"),
        (&["a1.csv", "cut.csv"][..], "run 3 is missing"),
        (&["a1.csv", "extra.csv"][..], "beyond the sweep's 4 runs"),
    ] {
        let mut args = vec!["merge"];
        args.extend(files);
        args.extend(["--csv", "merged.csv"]);
        let out = camchain(&dir, &args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{files:?}: {err}");
        assert!(err.contains(phrase), "{files:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!dir.join("merged.csv").exists(), "nothing written");
    }
}

/// The unreachable-cam fixture with the drive's rate as a parameter: from a rate of about
/// 0.52 rad/s the tip loses the cam before t = 2 s.
const RATE_MODEL: &str = r#"(
    name: "unreachable_rate",
    parameters: [(name: "rate", value: 0.2, unit: "rad/s", min: 0.0)],
    bodies: [
        (name: "link1", parent: "ground", mass: 1.0, com: (0.2, 0.0, 0.0), inertia: Izz(0.02),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (0.0, 0.5, 0.0), coordinate: "q1",
                 prescribed: "-PI/2 + rate*t")),
        (name: "link2", parent: "link1", mass: 0.5, com: (0.15, 0.0, 0.0), inertia: Izz(0.005),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (0.4, 0.0, 0.0), coordinate: "q2",
                 spring: (damping: 0.1))),
    ],
    markers: [(name: "A", body: "link2", position: (0.3, 0.0, 0.0))],
    contacts: [(marker: "A", profile: "0.0*x")],
    initial: (q: {"q1": -1.5707963267948966, "q2": 0.8}, hold: ["q1"]),
    simulation: (t_end: 2.0, dt_out: 0.01),
)"#;

#[test]
fn failed_runs_are_rows_with_their_error_and_the_exit_code_counts_them() {
    let dir = scratch("sweep-failures");
    std::fs::write(dir.join("rate.ron"), RATE_MODEL).expect("write");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "rate.ron",
            "--param",
            "rate=0.2,0.4,0.8,1.6",
            "--csv",
            "r.csv",
        ],
    );
    let err = text(&out.stderr);
    // Two failures: 3 + (2 − 1).
    assert_eq!(out.status.code(), Some(4), "{err}");
    assert!(err.contains("2 runs failed"), "{err}");
    let content = std::fs::read_to_string(dir.join("r.csv")).expect("the CSV is complete");
    let (header, rows) = rows(&dir.join("r.csv"));
    let status: Vec<&str> = rows
        .iter()
        .map(|r| r[column(&header, "status")].as_str())
        .collect();
    assert_eq!(status, ["ok", "ok", "failed", "failed"]);
    assert!(
        content.contains("dead point") || content.contains("cannot reach the cam"),
        "{content}"
    );
    // How far a failed run got: the tip leaves the cam at t = (π/3)/rate.
    let t: f64 = rows[2][column(&header, "t_reached")].parse().expect("t");
    let limit = std::f64::consts::FRAC_PI_3 / 0.8;
    assert!(t <= limit && t > limit - 0.2, "{t}");
    assert!(rows[2][column(&header, "max_normal_force")].is_empty());
}

#[test]
fn a_latin_hypercube_fills_its_intervals_and_repeats_with_its_seed() {
    let dir = scratch("sweep-lhs");
    let run = |seed: &str, file: &str| {
        let out = camchain(
            &dir,
            &[
                "sweep",
                "paper_concave",
                "--param",
                "k2=5:30",
                "--param",
                "k4=5:30",
                "--samples",
                "12",
                "--seed",
                seed,
                "--t-end",
                "0.2",
                "--csv",
                file,
                "-q",
            ],
        );
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        rows(&dir.join(file)).1
    };
    let (a, b, c) = (run("3", "a.csv"), run("3", "b.csv"), run("4", "c.csv"));
    assert_eq!(a.len(), 12);
    for row in &a {
        for cell in &row[1..3] {
            let v: f64 = cell.parse().expect("a value");
            assert!((5.0..=30.0).contains(&v), "{v}");
        }
    }
    let values =
        |rows: &[Vec<String>]| -> Vec<String> { rows.iter().map(|r| r[1].clone()).collect() };
    assert_eq!(values(&a), values(&b));
    assert_ne!(values(&a), values(&c));
}

#[test]
fn the_numeric_path_sweeps_a_parameter_the_generated_code_folds() {
    let dir = scratch("sweep-numeric");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "paper_concave",
            "--param",
            "m4=0.8,1.2",
            "--t-end",
            "0.3",
            "--csv",
            "n.csv",
        ],
    );
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("folded") && err.contains("--numeric"), "{err}");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "paper_concave",
            "--numeric",
            "--param",
            "m4=0.8,1.2",
            "--t-end",
            "0.3",
            "--csv",
            "n.csv",
            "-q",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let (header, rows) = rows(&dir.join("n.csv"));
    let force =
        |r: &Vec<String>| -> f64 { r[column(&header, "max_normal_force")].parse().expect("N") };
    assert_ne!(force(&rows[0]), force(&rows[1]));
}

#[test]
fn bad_input_is_refused_before_any_run_with_one_line() {
    let dir = scratch("sweep-bad");
    std::fs::write(dir.join("in_the_way"), "a file").expect("write");
    let cases: &[(&[&str], i32, &str)] = &[
        (
            &["--param", "kk=1,2"],
            2,
            "no run-time parameter `kk` (they are c2, c3, c4, k2, k3, k4, swing)",
        ),
        (
            &["--param", "k3=1:2:x"],
            2,
            "--param k3=1:2:x: the count `x` is not a number",
        ),
        (&["--param", "k3=abc"], 2, "`abc` is not a number"),
        (
            &["--param", "k3=-5:40:3"],
            2,
            "k3 = -5 is below the minimum 0 declared for `k3`",
        ),
        (
            &["--param", "swing=0:2:3"],
            2,
            "swing = 2 is above the maximum 1 declared for `swing`",
        ),
        (&["--param", "k3=1,2", "--param", "k3=3"], 2, "given twice"),
        (&["--param", "k3=10:20"], 2, "needs --samples"),
        (
            &["--param", "k3=1,2", "--samples", "5"],
            2,
            "every parameter is an interval",
        ),
        (
            &["--param", "k3=1,2", "--shard", "0/4"],
            2,
            "the shard must be from 1 to 4",
        ),
        (
            &["--param", "k3=1,2", "--shard", "5/4"],
            2,
            "the shard must be from 1 to 4",
        ),
        (&["--param", "k3=1,2", "--shard", "two"], 2, "is not I/N"),
        (
            &["--param", "k3=1,2", "--metric", "speed"],
            2,
            "unknown metric `speed`",
        ),
        (
            &["--param", "k3=1,2", "--jobs", "0"],
            2,
            "--jobs must be at least 1",
        ),
        (&["--param", "k3=1:2:1e12"], 2, "whole number from 1 to"),
        (
            &["--param", "k3=1,2", "--out", "in_the_way"],
            1,
            "cannot create output directory",
        ),
        (
            &["--param", "k3=1,2", "--csv", "no/such/dir/x.csv"],
            1,
            "does not exist",
        ),
    ];
    for (extra, code, phrase) in cases {
        let mut args = vec!["sweep", "paper_concave"];
        args.extend(*extra);
        let out = camchain(&dir, &args);
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(*code), "{extra:?}: {err}");
        assert!(err.contains(phrase), "{extra:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{extra:?}: {err}");
        assert!(out.stdout.is_empty(), "{extra:?}");
    }
    assert!(!dir.join("out").exists(), "nothing written");
    let out = camchain(&dir, &["sweep", "no_such_model", "--param", "k=1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("unknown model `no_such_model`"));
}

#[test]
fn simulate_takes_parameter_values_checked_as_the_file() {
    let dir = scratch("simulate-param");
    for (param, code, phrase) in [
        (
            "k3=-1",
            2,
            "models/paper_concave.ron:40:53: parameters[19].min: k3 = -1 is below the minimum 0",
        ),
        (
            "l1=0.4",
            2,
            "parameter `l1` is constant (folded into the generated code)",
        ),
        // Only the parameters `--param` can set are offered as known; those folded into the
        // code are named as constant, and the numeric path that can set them is pointed at.
        (
            "foo=1",
            2,
            "unknown parameter `foo`; known: c2, c3, c4, k2, k3, k4, swing (constant, folded \
             into the code: J1, J2, J3, J4, a1, a2, a3, bx, by, g, l1, l2, l3, l4, m1, m2, m3, \
             m4); the numeric reference (--numeric) sets the constant ones too",
        ),
        ("k3", 2, "is not NAME=VALUE"),
    ] {
        let out = camchain(
            &dir,
            &[
                "simulate",
                "paper_concave",
                "--param",
                param,
                "--t-end",
                "0.1",
            ],
        );
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{param}: {err}");
        assert!(err.contains(phrase), "{param}: {err}");
    }
    let out = camchain(
        &dir,
        &[
            "simulate",
            "paper_concave",
            "--numeric",
            "--param",
            "l1=0.4",
            "--t-end",
            "0.1",
            "--no-plots",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("with l1 = 0.4"));
}

#[test]
fn ctrl_c_keeps_the_rows_so_far_and_an_older_result_as_it_was() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let dir = scratch("sweep-interrupt");
    let precious = dir.join("big.csv");
    std::fs::write(&precious, "an older result\n").expect("write");
    let child = Command::new(env!("CARGO_BIN_EXE_camchain"))
        .args([
            "sweep",
            "paper_concave",
            "--param",
            "swing=-0.5:0.5:300",
            "--param",
            "k3=20:80:300",
            "--rtol",
            "1e-12",
            "--atol",
            "1e-12",
            "--csv",
            "big.csv",
        ])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary starts");
    let partial = dir.join("big.partial.csv");
    let start = Instant::now();
    let streamed = loop {
        let rows = std::fs::read_to_string(&partial).map_or(0, |t| t.lines().count());
        if rows > 20 || start.elapsed() > Duration::from_secs(30) {
            break rows;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(streamed > 20, "rows streamed within 30 s: {streamed}");
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(sent.success());
    let output = child.wait_with_output().expect("it ends");
    assert_eq!(output.status.code(), Some(130));
    let err = text(&output.stderr);
    assert!(
        err.contains("stopped by Ctrl-C after") && err.contains("big.partial.csv"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(&precious).expect("read"),
        "an older result\n",
        "the older result is untouched"
    );
    let content = std::fs::read_to_string(&partial).expect("the partial CSV");
    assert!(content.ends_with('\n'), "the last row is whole");
    let (_, rows) = rows(&partial);
    assert!(rows.len() >= 20);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row[0], k.to_string(), "rows in run order, none missing");
    }
}

/// The heat maps' axes name the swept parameters with their units (docs/model-format.md
/// promises them), and a metric no run has (no lift-off on the concave cam, whose contact
/// stays compressive) says so in its panel instead of an all-grey map with a 0–1 colour bar.
#[test]
fn heat_map_axes_have_units_and_an_empty_metric_says_so() {
    let dir = scratch("sweep-heat-units");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "paper_concave",
            "--param",
            "swing=0.05,0.1",
            "--param",
            "c3=0,1",
            "--metric",
            "max_normal_force",
            "--metric",
            "first_lift_off",
            "--t-end",
            "0.3",
            "--out",
            "figs",
            "-q",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let svg = std::fs::read_to_string(dir.join("figs/paper_concave_sweep/heatmaps.svg"))
        .expect("the SVG");
    assert!(svg.contains("swing [rad]"), "no unit on the swing axis");
    assert!(svg.contains("c3 [N s/m]"), "no unit on the c3 axis");
    assert!(svg.contains("no lift-off in any run"));
    // c3 swept over 0 and 1 (a damping, never negative): no tick below zero on its axis.
    assert!(
        !svg.contains(">-0.2<") && !svg.contains(">-0.4<"),
        "an axis below zero"
    );
}

/// A count of one is singular wherever the sweep prints counts: `1 run`, `1 worker`.
#[test]
fn a_sweep_of_one_run_says_1_run() {
    let dir = scratch("sweep-one-run");
    let out = camchain(
        &dir,
        &[
            "sweep",
            "paper_concave",
            "--param",
            "swing=0.1",
            "--t-end",
            "0.2",
            "--jobs",
            "1",
            "--csv",
            "one.csv",
        ],
    );
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(stdout.contains("1 run "), "{stdout}");
    assert!(stdout.contains("1 worker"), "{stdout}");
    // No count of one followed by a plural (`1851 runs/s` is a rate, not a count of one).
    let words: Vec<&str> = stdout.split_whitespace().collect();
    assert!(
        !words
            .windows(2)
            .any(|w| w[0] == "1" && (w[1].starts_with("runs") || w[1].starts_with("workers"))),
        "{stdout}"
    );
}
