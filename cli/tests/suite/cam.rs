//! End-to-end tests of `camchain cam`: the design's peaks against the textbook closed forms,
//! the predicted jump speed against an independent route (bisection on the speed of the
//! least contact force of bilateral runs of the generated model), the one-sided run below
//! and above it, the profile table read back by a model, and bad input with its exit codes.
//!
//! Everything that simulates uses the built-in models' generated code (the numeric
//! reference is far slower on a cam designed from a law).

use crate::common;

use camchain_codegen::ParameterMode;
use camchain_codegen::model::Profile;
use camchain_codegen::schema::{Files, parse_model_from};
use camchain_models::cycloidal_roller;
use camchain_runtime::{Dynamics, SimSettings, Simulate};
use common::{camchain, scratch};
use std::f64::consts::{PI, TAU};
use std::path::Path;
use std::process::Output;
use std::time::Instant;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Runs `camchain cam` in `dir`, which must succeed; returns its standard output.
fn cam(dir: &Path, args: &[&str]) -> String {
    let start = Instant::now();
    let mut all = vec!["cam"];
    all.extend(args);
    let out = camchain(dir, &all);
    eprintln!("camchain {} took {:.2?}", all.join(" "), start.elapsed());
    assert!(
        out.status.success(),
        "camchain {all:?} failed: {}\n{}",
        text(&out.stderr),
        text(&out.stdout)
    );
    text(&out.stdout)
}

/// The number after `key` on the summary's line that starts (trimmed) with `line_start`.
fn value_after(stdout: &str, line_start: &str, key: &str) -> f64 {
    let line = stdout
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with(line_start))
        .unwrap_or_else(|| panic!("no line starting with `{line_start}` in\n{stdout}"));
    let rest = line
        .split_once(key)
        .unwrap_or_else(|| panic!("no `{key}` in `{line}`"))
        .1;
    let word = rest.split_whitespace().next().unwrap_or_default();
    word.parse()
        .unwrap_or_else(|_| panic!("`{word}` after `{key}` in `{line}` is not a number"))
}

/// max and min of a peak line (`velocity [m/s]  max … at …°   min … at …°`).
fn peak(stdout: &str, quantity: &str) -> (f64, f64) {
    (
        value_after(stdout, quantity, "max "),
        value_after(stdout, quantity, "min "),
    )
}

/// The file values of built-in model `model`'s parameters, by name.
fn parameters_of(model: &str) -> impl Fn(&str) -> f64 {
    let parameters = parse_model_from(
        camchain_models::source(model).expect("built in"),
        Path::new(&format!("models/{model}.ron")),
        &[],
        ParameterMode::AsDeclared,
        Files::Embedded(camchain_models::files(model)),
    )
    .expect("valid")
    .parameters;
    move |name: &str| {
        parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.default)
            .unwrap_or_else(|| panic!("no parameter {name}"))
    }
}

fn relative(got: f64, expected: f64) -> f64 {
    (got - expected).abs() / expected.abs()
}

#[test]
fn cycloidal_peaks_are_the_textbook_ones_and_the_follower_stays_on_at_50() {
    let dir = scratch("cam-cycloidal");
    let stdout = cam(&dir, &["cycloidal_roller"]);
    // models/cycloidal_roller.ron: a cycloidal rise of h = 12 mm over β = 120° at 50 rad/s.
    let (h, beta, w) = (0.012, 120f64.to_radians(), 50.0);
    let (v_max, v_min) = peak(&stdout, "velocity [m/s]");
    let (a_max, a_min) = peak(&stdout, "acceleration [m/s²]");
    let v = 2.0 * h * w / beta;
    let a = 2.0 * PI * h * w * w / (beta * beta);
    eprintln!(
        "cycloidal: v {v_max} ({:.1e}), {v_min} ({:.1e}); a {a_max} ({:.1e}), {a_min} ({:.1e})",
        relative(v_max, v),
        relative(-v_min, v),
        relative(a_max, a),
        relative(-a_min, a)
    );
    // The peaks are refined to rounding (a smooth peak: an error δ in the angle costs δ² in
    // the value) and printed to 12 significant digits (5e-13 relative): 1e-9 is the task's
    // requirement, with a wide margin.
    for (got, expected) in [(v_max, v), (-v_min, v), (a_max, a), (-a_min, a)] {
        assert!(
            relative(got, expected) < 1e-9,
            "{got} against {expected}\n{stdout}"
        );
    }
    assert!(
        stdout.contains("stays on the cam"),
        "at 50 rad/s (below the jump speed) the follower stays on the cam:\n{stdout}"
    );
    // design.csv: a header and one row per sample (3600 + 1), the velocity column at ω.
    let csv = std::fs::read_to_string(dir.join("out/cycloidal_roller_cam/design.csv"))
        .expect("design.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    assert_eq!(header[0], "cam_angle_deg");
    assert_eq!(header.last(), Some(&"normal_force"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().expect("a number")).collect())
        .collect();
    assert_eq!(rows.len(), 3601);
    // The sampled velocity never exceeds the refined peak (to rounding: 1e-12 relative).
    let v_column = header.iter().position(|c| *c == "v").expect("a v column");
    assert!(rows.iter().all(|r| r[v_column].abs() <= v * (1.0 + 1e-12)));
    // Every row has the force of the bilateral run (finite, positive at 50 rad/s).
    assert!(rows.iter().all(|r| r[11].is_finite() && r[11] > 0.0));
    for stem in ["svaj", "pressure_curvature", "profile", "force"] {
        for ext in ["png", "svg"] {
            let path = dir.join(format!("out/cycloidal_roller_cam/{stem}.{ext}"));
            assert!(path.is_file(), "{} missing", path.display());
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn polynomial_peaks_are_the_textbook_ones() {
    let dir = scratch("cam-rocker");
    let stdout = cam(&dir, &["polynomial_rocker", "--samples", "720"]);
    // models/polynomial_rocker.ron: a 3-4-5 swing of h = 0.15 rad over β = 100° at 30 rad/s.
    let (h, beta, w) = (0.15, 100f64.to_radians(), 30.0);
    let (v_max, v_min) = peak(&stdout, "velocity [rad/s]");
    let (a_max, a_min) = peak(&stdout, "acceleration [rad/s²]");
    let (v, a) = (1.875 * h * w / beta, 5.7735 * h * w * w / (beta * beta));
    eprintln!(
        "3-4-5: v {v_max} ({:.1e}); a {a_max} ({:.1e}), {a_min} ({:.1e})",
        relative(v_max, v),
        relative(a_max, a),
        relative(-a_min, a)
    );
    // C_v = 15/8 exactly: to the printing's 12 digits (1e-9, as the cycloidal peaks).
    assert!(relative(v_max, v) < 1e-9 && relative(-v_min, v) < 1e-9);
    // C_a = 10√3/3 = 5.77350269…: the textbook's 5.7735 has 5 digits (4.7e-7 off), so 1e-5
    // against it, and 1e-9 against the exact factor.
    let exact = 10.0 * 3f64.sqrt() / 3.0 * h * w * w / (beta * beta);
    for got in [a_max, -a_min] {
        assert!(relative(got, a) < 1e-5, "{got} against {a}");
        assert!(relative(got, exact) < 1e-9, "{got} against {exact}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The least contact force over one turn of the generated cycloidal_roller at `w` rad/s
/// (bilateral): a turn sampled every 0.5°, then the ±0.5° around its least sample every
/// 0.005° (the least of a smooth minimum on that grid is within ½|N″|(Δθ/2)² ≈ 3e-7 N of
/// the true one: N″ ≈ 320 N/rad² near the jump speed).
fn least_force(w: f64) -> f64 {
    let model = cycloidal_roller::Model::with(&[("omega", w)]).expect("omega is run-time");
    let info = model.info();
    let contact = 0;
    let run = |t0: f64, t1: f64, outputs: usize| {
        let settings = SimSettings {
            t_end: t1,
            dt_out: (t1 - t0) / outputs as f64,
            ..info.defaults.clone()
        };
        let state = Simulate::assemble(&model, t0).expect("assembles");
        model.simulate(state, &settings).expect("runs").samples
    };
    let coarse = run(0.0, TAU / w, 720);
    let k = (0..coarse.len())
        .min_by(|&a, &b| {
            coarse[a].normal_force[contact].total_cmp(&coarse[b].normal_force[contact])
        })
        .expect("samples");
    let (a, b) = (k.saturating_sub(1), (k + 1).min(coarse.len() - 1));
    let fine = run(coarse[a].t, coarse[b].t, 200);
    fine.iter()
        .map(|s| s.normal_force[contact])
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn the_predicted_jump_speed_is_where_bisection_finds_it() {
    let dir = scratch("cam-jump");
    let stdout = cam(&dir, &["cycloidal_roller"]);
    let predicted = value_after(&stdout, "predicted jump speed", "speed ");
    // Bisection on the speed between 50 rad/s (the follower held) and 70 (pulled off), to
    // 20 rad/s / 2³⁰ ≈ 2e-8 rad/s.
    let start = Instant::now();
    let (mut lo, mut hi) = (50.0, 70.0);
    assert!(least_force(lo) > 0.0 && least_force(hi) < 0.0);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if least_force(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let bisected = 0.5 * (lo + hi);
    eprintln!(
        "jump speed: predicted {predicted} rad/s, bisected {bisected} rad/s ({:.1e} relative; \
         bisection {:.2?})",
        relative(predicted, bisected),
        start.elapsed()
    );
    // The bisection's grid error (3e-7 N, see `least_force`) over dN/dω ≈ 1.1 N per rad/s
    // at the jump is 3e-7 rad/s, its bracket 2e-8 rad/s; the command's error (A, B, C exact
    // to Newton's tolerance, the root refined between 0.1° samples by a parabola) is smaller:
    // 1e-7 relative (6e-6 rad/s) leaves a margin of 20.
    assert!(
        relative(predicted, bisected) < 1e-7,
        "predicted {predicted}, bisected {bisected}"
    );
    // The model file's comment: about 64 rad/s.
    assert!((60.0..70.0).contains(&predicted));
    // The closed form from the file's parameters and the cycloidal law (issue 24): the
    // command prints 12 significant digits; its A, B, C are the dynamics' to Newton's
    // tolerance and its root is refined between samples 0.1° apart by a parabola, whose
    // error there (the fourth derivative of the root over θ times 0.1°⁴) is below 1e-9.
    let p = parameters_of("cycloidal_roller");
    let closed = cycloidal::Cycloidal {
        m: p("m"),
        g: p("g"),
        k: p("k"),
        c: p("c"),
        free: p("free"),
        base: p("R_b") + p("rho"),
        lift: p("h"),
    }
    .jump_speed()
    .0;
    eprintln!(
        "jump speed: closed form {closed} rad/s ({:.1e} relative to the prediction)",
        relative(predicted, closed)
    );
    assert!(
        relative(predicted, closed) < 1e-8,
        "predicted {predicted}, closed form {closed}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// The closed form of the jump speed; its run-time helpers serve the models' tests only.
#[allow(dead_code)]
#[path = "../../../tests/support/cycloidal.rs"]
mod cycloidal;

#[test]
fn above_the_jump_speed_the_follower_lifts_off() {
    let dir = scratch("cam-70");
    let stdout = cam(&dir, &["cycloidal_roller", "--speed", "70", "--turns", "2"]);
    assert!(
        stdout.contains("the follower lifts off") && stdout.contains("lifts off at t = "),
        "at 70 rad/s (above the jump speed, about 64.6) the one-sided follower leaves the \
         cam:\n{stdout}"
    );
    // It lands again on the cam (a preloaded spring pulls it back), within the turn.
    assert!(stdout.contains("; lands at t = "), "{stdout}");
    // The bilateral force at 70 rad/s goes negative: the design says so too.
    let least = value_after(&stdout, "contact force at ω", "least ");
    assert!(least < 0.0, "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_profile_table_is_read_back_by_a_model() {
    let dir = scratch("cam-table");
    cam(
        &dir,
        &[
            "cycloidal_roller",
            "--samples",
            "360",
            "--table",
            "profile.csv",
        ],
    );
    let table = std::fs::read_to_string(dir.join("profile.csv")).expect("the table");
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| !l.starts_with('#') && *l != "x,y")
        .collect();
    // 720 points and the first again: a closed curve, its ends the same numbers exactly.
    assert_eq!(rows.len(), 721);
    assert_eq!(rows.first(), rows.last());
    // The built-in table_cam reads the committed table, written by this command: the same
    // bytes.
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let committed = std::fs::read_to_string(models.join("tables/cycloidal_roller_profile.csv"))
        .expect("the committed table");
    assert_eq!(table, committed);
    // table_cam's model file reading this table instead parses and validates, and its
    // profile starts at the table's first point.
    let source = std::fs::read_to_string(models.join("table_cam.ron"))
        .expect("table_cam.ron")
        .replace("tables/cycloidal_roller_profile.csv", "profile.csv");
    let file = dir.join("read_back.ron");
    std::fs::write(&file, &source).expect("writes the model");
    let model = parse_model_from(
        &source,
        &file,
        &[],
        ParameterMode::AsDeclared,
        Files::BesideModel,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let Profile::Parametric { x, y, .. } = &model.contacts[0].profile else {
        panic!("a parametric profile");
    };
    let first: Vec<f64> = rows[0]
        .split(',')
        .map(|v| v.parse().expect("a number"))
        .collect();
    // The spline interpolates its points: exact at the first to rounding.
    assert!((x.eval(0.0) - first[0]).abs() < 1e-15 && (y.eval(0.0) - first[1]).abs() < 1e-15);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A failing run: its exit code and its one error line.
fn fails(dir: &Path, args: &[&str]) -> (i32, String) {
    let mut all = vec!["cam"];
    all.extend(args);
    let out: Output = camchain(dir, &all);
    let stderr = text(&out.stderr);
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "one error line for {all:?}: {stderr}");
    (out.status.code().unwrap_or(-1), errors[0].to_string())
}

#[test]
fn bad_input_gives_one_line_and_its_exit_code() {
    let dir = scratch("cam-bad");
    let designs = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/contact_models/designs.ron")
        .display()
        .to_string();
    let bad = dir.join("bad.ron");
    let source = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/cycloidal_roller.ron"),
    )
    .expect("cycloidal_roller.ron")
    .replace("Dwell(degrees: 60),", "Dwell(degrees: 61),");
    std::fs::write(&bad, &source).expect("writes");
    // A law whose speed is not the camshaft's drive (`omega*t`): the runs would be mislabelled.
    let twice = dir.join("twice.ron");
    std::fs::write(
        &twice,
        source
            .replace("Dwell(degrees: 61),", "Dwell(degrees: 60),")
            .replace("speed: \"omega\",", "speed: \"2*omega\","),
    )
    .expect("writes");
    let twice = twice.display().to_string();
    std::fs::write(dir.join("blocker"), "a file").expect("writes");
    let bad = bad.display().to_string();
    let cases: [(&[&str], i32, &str); 13] = [
        (&["no_such_model"], 2, "unknown model `no_such_model`"),
        (&["paper_concave"], 2, "no cam designed from a motion law"),
        (&[&designs], 2, "choose one with --contact"),
        (&[&designs, "--contact", "nope"], 2, "no contact `nope`"),
        (&[&designs, "--contact", "tk"], 2, "give one with --speed"),
        (
            &[&designs, "--contact", "tk", "--speed", "12"],
            1,
            "cannot be run at other speeds",
        ),
        (&["cycloidal_roller", "--speed", "0"], 2, "must be positive"),
        (
            &["cycloidal_roller", "--speed", "inf"],
            2,
            "must be positive",
        ),
        (&["cycloidal_roller", "--samples", "0"], 2, "at least 1"),
        (&[&bad], 1, "bad.ron:63:27: contacts[0].law.segments"),
        (&[&twice], 1, "its drive does not follow the law's `speed`"),
        (
            &["cycloidal_roller", "--out", "blocker"],
            1,
            "cannot create output directory",
        ),
        (
            &["cycloidal_roller", "--table", "missing/dir/t.csv"],
            1,
            "does not exist",
        ),
    ];
    for (args, code, message) in cases {
        let (got, line) = fails(&dir, args);
        assert_eq!(got, code, "{args:?}: {line}");
        assert!(
            line.contains(message),
            "{args:?}: `{line}` lacks `{message}`"
        );
    }
    // Nothing was written by the failures (the output directory is made after the checks).
    assert!(!dir.join("out").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_barrel_cam_design_reports_its_law_groove_and_jump_speed() {
    // models/barrel_indexer.ron: a groove designed from cycloidal rise and return of h = 30 mm
    // over β = 120° each (dwells of 60°), pitch radius R = 60 mm, roller ρ = 10 mm, at 10 rad/s.
    let dir = scratch("cam-barrel");
    let table = dir.join("groove.csv");
    let table_arg = table.to_string_lossy().into_owned();
    let stdout = cam(&dir, &["barrel_indexer", "--table", &table_arg]);
    let (h, beta, w, radius, rho, base) = (0.03, 120f64.to_radians(), 10.0, 0.06, 0.01, 0.02);
    let (v_max, _) = peak(&stdout, "velocity [m/s]");
    let (a_max, _) = peak(&stdout, "acceleration [m/s²]");
    // The textbook peaks 2hω/β and 2πhω²/β², as for the disc cam (printed to 12 digits).
    assert!(
        relative(v_max, 2.0 * h * w / beta) < 1e-9,
        "{v_max}\n{stdout}"
    );
    assert!(
        relative(a_max, 2.0 * PI * h * w * w / (beta * beta)) < 1e-9,
        "{a_max}"
    );
    // The pressure angle of a follower translating along the axis, atan(s′/R), largest at the
    // rise's middle: atan(2h/(βR)), printed in degrees to 3 decimals.
    let line = stdout
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with("pressure angle:"))
        .expect("a pressure angle line");
    let largest: f64 = line
        .split_once("max ")
        .and_then(|(_, rest)| rest.split('°').next())
        .and_then(|word| word.parse().ok())
        .unwrap_or_else(|| panic!("no largest pressure angle in `{line}`"));
    let closed = (2.0 * h / (beta * radius)).atan().to_degrees();
    assert!(
        (largest - closed).abs() < 6e-4,
        "{largest}° against {closed}°"
    );
    // The developed pitch curve's radius of curvature (R² + s′²)^{3/2}/(R |s″|) from the
    // cycloidal law's closed form, at its least over a rise (sampled every 1e-6 of β; the
    // report refines by golden-section search), less ρ: both flanks' undercut margins,
    // printed to the micrometre.
    let least = (1..1_000_000)
        .map(|k| {
            let x = k as f64 / 1e6;
            let s1 = h / beta * (1.0 - (2.0 * PI * x).cos());
            let s2 = 2.0 * PI * h / (beta * beta) * (2.0 * PI * x).sin();
            (radius * radius + s1 * s1).powf(1.5) / (radius * s2.abs())
        })
        .fold(f64::INFINITY, f64::min);
    let lower = value_after(&stdout, "undercut margin:", "margin: ");
    let upper = value_after(&stdout, "the groove's upper flank:", "margin ");
    for margin in [lower, upper] {
        assert!(
            (margin - (least - rho)).abs() < 1e-6,
            "{margin} against {}",
            least - rho
        );
    }
    // The jump speed predicted from bilateral runs against the closed form (the spring
    // holds the follower on the lower flank; surfaces.rs checks lift-off there).
    let predicted = value_after(&stdout, "predicted jump speed", "speed ");
    let p = parameters_of("barrel_indexer");
    let law = cycloidal::Cycloidal {
        m: p("m"),
        g: p("g"),
        k: p("k"),
        c: p("c"),
        free: p("free"),
        base: p("base"),
        lift: p("h"),
    };
    let closed = law.jump_speed().0;
    assert!(
        relative(predicted, closed) < 1e-8,
        "predicted {predicted}, closed form {closed}"
    );
    // The groove table: z = base + s(φ) at the cam-frame angle θ, φ = −θ for a cam turning
    // counterclockwise.
    let text = std::fs::read_to_string(&table).expect("the table");
    let rows: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && *l != "theta,z")
        .map(|l| {
            let (t, z) = l.split_once(',').expect("two columns");
            (t.parse().expect("θ"), z.parse().expect("z"))
        })
        .collect();
    assert_eq!(rows.len(), 721, "720 points and the first again");
    for (theta, z) in rows {
        let expected = base + law.law((-theta).rem_euclid(TAU)).0;
        assert!(
            (z - expected).abs() < 1e-15,
            "θ = {theta}: {z} against {expected}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_face_cam_design_reports_both_flanks_of_its_groove() {
    // models/face_cam.ron: the groove's centre line is the pitch curve of a modified sine
    // law for an oscillating roller (ρ = 10 mm). The report's radii come from the design's
    // closed forms; here the centre line's curvature comes from forward-mode jets of the
    // model's own expressions (`camchain_model::samples`), sampled every 0.01° (the smallest
    // radius is smooth there: off by ~R″Δθ²/2 ≈ 1e-9 m).
    let dir = scratch("cam-face");
    let stdout = cam(&dir, &["face_cam"]);
    let model = parse_model_from(
        camchain_models::source("face_cam").expect("built in"),
        Path::new("models/face_cam.ron"),
        &[],
        ParameterMode::AsDeclared,
        Files::Embedded(camchain_models::files("face_cam")),
    )
    .expect("valid");
    let Profile::Face { centre } = &model.contacts[0].profile else {
        panic!("a face cam: {:?}", model.contacts[0].profile)
    };
    let rho = 0.01;
    let samples = camchain_codegen::samples::profile_samples(centre, (0.0, TAU), 36_000);
    // Positive curvature is hollow seen from the follower's side (outside the centre line).
    let hollow = samples
        .iter()
        .map(|s| s.curvature)
        .fold(f64::NEG_INFINITY, f64::max);
    let sharpest = samples
        .iter()
        .filter(|s| s.curvature < 0.0)
        .map(|s| -1.0 / s.curvature)
        .fold(f64::INFINITY, f64::min);
    assert!(
        hollow <= 0.0,
        "the centre line is hollow somewhere: {hollow}"
    );
    assert!(
        stdout.contains("the groove's outer flank: the pitch curve is concave nowhere"),
        "{stdout}"
    );
    // The inner flank's margin: the centre line's smallest convex radius less ρ, printed to
    // the micrometre.
    let margin = value_after(&stdout, "undercut margin:", "margin: ");
    assert!(
        (margin - (sharpest - rho)).abs() < 1e-6,
        "{margin} against {}",
        sharpest - rho
    );
    let _ = std::fs::remove_dir_all(&dir);
}
