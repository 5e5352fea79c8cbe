//! Assembly of the initial state (camchain-runtime), run on small models loaded from their
//! text: the root nearest the guess, the report of what changed, the diagnosis of a dead
//! point, and Newton's tolerance on a model written in millimetres. Expected values are
//! closed forms of the two-link arm (tip height y = l1 sin q1 + l2 sin(q1 + q2)).

use camchain_codegen::schema::parse_model;
use camchain_reference::NumericModel;
use camchain_runtime::assembly::{ChangeCause, RootChoice};
use camchain_runtime::{Dynamics, SimError, Simulate};
use std::path::Path;

/// A planar two-link arm (links of 1 m) hinged at the origin, its tip on the flat cam
/// y = `cam`; `extra` adds fields to the second joint, `initial` is the initial section.
fn arm(cam: f64, joint1: &str, initial: &str) -> NumericModel {
    let text = format!(
        r#"(
    name: "arm",
    bodies: [
        (name: "upper", parent: "ground", mass: 1.0, com: (0.5, 0.0, 0.0), inertia: Izz(0.08),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (0.0, 0.0, 0.0),
                 coordinate: "q1", {joint1})),
        (name: "lower", parent: "upper", mass: 1.0, com: (0.5, 0.0, 0.0), inertia: Izz(0.08),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (1.0, 0.0, 0.0),
                 coordinate: "q2")),
    ],
    markers: [(name: "tip", body: "lower", position: (1.0, 0.0, 0.0))],
    contacts: [(marker: "tip", profile: "{cam:?} + 0.0*x")],
    initial: {initial},
)"#
    );
    let model = parse_model(&text, Path::new("arm.ron")).unwrap_or_else(|e| panic!("{e}"));
    NumericModel::new(model)
}

#[test]
fn assembly_moves_to_the_root_nearest_the_guess() {
    // q1 = 0 held: the tip height is sin q2, and sin q2 = −0.5 has the roots −π/6 and
    // 7π/6 (≡ −5π/6). From q2 = 1.4, where sin is nearly flat, Newton's first step jumps
    // 8.7 rad away; the nearest root is −π/6 (1.92 rad away; 7π/6 is 2.27 away).
    let model = arm(-0.5, "", r#"(q: {"q1": 0.0, "q2": 1.4}, hold: ["q1"])"#);
    let (state, report) = model.assemble_reported(0.0).expect("assembles");
    let expected = -std::f64::consts::FRAC_PI_6;
    assert!((state.q[1] - expected).abs() < 1e-12, "q2 = {}", state.q[1]);
    match report.root {
        RootChoice::Nearest { distance } => assert!((distance - (1.4 - expected)).abs() < 1e-9),
        other => panic!("{other:?}"),
    }
    let change = &report.changes[0];
    assert_eq!((change.coordinate, change.velocity), (1, false));
    assert_eq!(change.cause, ChangeCause::Constraint);
    assert!(change.given && change.from == 1.4 && (change.to - expected).abs() < 1e-12);
}

#[test]
fn assembly_reports_values_set_by_a_drive_and_velocities_from_the_constraint() {
    // The drive q1(t) = 0.2 + 0.5 t overrides the given −1.9 rad and 0 rad/s; q2 is solved
    // so that sin q1 + sin(q1 + q2) = −0.5 (the root nearest the guess 0), and q̇2 from
    // J q̇ = 0 (the tip moves along the flat cam: cos q1 q̇1 + cos(q1 + q2)(q̇1 + q̇2) = 0),
    // overriding the given 5 rad/s.
    let model = arm(
        -0.5,
        r#"prescribed: "0.2 + 0.5*t""#,
        r#"(q: {"q1": -1.9, "q2": 0.0}, qd: {"q2": 5.0})"#,
    );
    let (state, report) = model.assemble_reported(0.0).expect("assembles");
    let q1: f64 = 0.2;
    let q2 = (-0.5 - q1.sin()).asin() - q1;
    let qd2 = -0.5 * (1.0 + q1.cos() / (q1 + q2).cos());
    assert!((state.q[1] - q2).abs() < 1e-12, "q2 = {}", state.q[1]);
    assert!((state.qd[1] - qd2).abs() < 1e-12, "q̇2 = {}", state.qd[1]);
    let find = |i: usize, velocity: bool| {
        report
            .changes
            .iter()
            .find(|c| c.coordinate == i && c.velocity == velocity)
            .unwrap_or_else(|| panic!("no change of {i}, velocity {velocity}: {report:?}"))
    };
    let q1 = find(0, false);
    assert_eq!(
        (q1.cause, q1.given, q1.from, q1.to),
        (ChangeCause::Drive, true, -1.9, 0.2)
    );
    let qd1 = find(0, true);
    assert_eq!(
        (qd1.cause, qd1.given, qd1.from, qd1.to),
        (ChangeCause::Drive, false, 0.0, 0.5)
    );
    let solved = find(1, true);
    assert_eq!(
        (solved.cause, solved.given, solved.from),
        (ChangeCause::Constraint, true, 5.0)
    );
    assert_eq!(solved.to, state.qd[1]);
}

#[test]
fn a_dead_point_is_called_a_dead_point_not_an_unreachable_cam() {
    // The arm hanging straight down reaches y = −2 in one configuration only, and there no
    // joint can move the tip vertically: J = 0 with the tip on the cam.
    let model = arm(
        -2.0,
        "",
        r#"(q: {"q1": -1.5707963267948966, "q2": 0.0}, hold: ["q1"])"#,
    );
    let error = model.assemble(0.0).expect_err("locked");
    match &error {
        SimError::SingularConstraint {
            on_cam, residual, ..
        } => {
            assert!(*on_cam && *residual < 1e-15, "{error}");
        }
        other => panic!("{other}"),
    }
    let message = error.to_string();
    assert!(message.contains("locks at a dead point"), "{message}");
    assert!(!message.contains("cannot reach"), "{message}");
    // Out of reach instead (y = −2.5): Newton's message.
    let model = arm(
        -2.5,
        "",
        r#"(q: {"q1": -1.5707963267948966, "q2": 0.3}, hold: ["q1"])"#,
    );
    let error = model.assemble(0.0).expect_err("unreachable");
    assert!(
        error.to_string().contains("cannot reach the cam"),
        "{error}"
    );
}

/// `models/paper_concave.ron` with every length (and gravity, an acceleration) multiplied
/// by `length`, inertias and the revolute springs and dampers by `length²`: the same
/// equations in another length unit, so the same motion, angles unchanged, q3 and the
/// contact point `length` times larger. With `length` = 10 000 it reads as a 4.6 m machine
/// written in millimetres.
fn paper_scaled(length: f64) -> NumericModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/paper_concave.ron");
    let text = std::fs::read_to_string(path).expect("the paper model");
    let mut model = parse_model(&text, Path::new("paper_concave.ron")).expect("valid");
    let scale3 = |v: [f64; 3]| v.map(|x| length * x);
    model.gravity = scale3(model.gravity);
    for body in &mut model.bodies {
        body.com = scale3(body.com);
        body.inertia = body.inertia.map(|row| row.map(|x| x * length * length));
        body.joint.anchor = scale3(body.joint.anchor);
        if let Some(spring) = &mut body.joint.spring {
            // A torque (kg·mm²/s²) per radian scales with length²; a force (kg·mm/s²) per
            // millimetre, N/m = kg/s², does not.
            if body.joint.kind == camchain_codegen::model::JointKind::Revolute {
                spring.stiffness *= length * length;
                spring.damping *= length * length;
            }
        }
    }
    for marker in &mut model.markers {
        marker.position = scale3(marker.position);
    }
    let profile = format!(
        "{length:?}*(-0.595*(x/{length:?}) + 0.5*(x/{length:?}).powi(2) + 0.5*(x/{length:?}).powi(3))"
    );
    model.contacts[0].profile = camchain_codegen::model::Profile::Explicit {
        f: camchain_codegen::profile::parse_expression(&profile, "x")
            .expect("the scaled profile parses"),
        source: profile,
    };
    NumericModel::new(model)
}

#[test]
fn a_large_model_in_millimetres_runs_like_the_same_model_in_metres() {
    // Newton's tolerance scales with the model: with an absolute 1e-12, h (round-off about
    // 1e-16 of the 4600 mm lengths, amplified through the chain) stalls above it and the run
    // stops with "the contact point cannot reach the cam".
    let length = 1e4;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/paper_concave.ron");
    let metres = NumericModel::load(&path).expect("the paper model");
    let millimetres = paper_scaled(length);
    let settings = metres.info().defaults.clone();
    let run = |m: &NumericModel| {
        let state = m.assemble(0.0).expect("assembles");
        m.simulate(state, &settings)
            .unwrap_or_else(|f| panic!("{}", f.error))
    };
    let (a, b) = (run(&metres), run(&millimetres));
    assert_eq!(a.samples.len(), b.samples.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        // The same ODE in other units, integrated to rtol 1e-10: angles agree to the
        // integration error (1e-8 rad), q3 to 1e-8 of the unit.
        for i in [0, 1, 3] {
            assert!((x.q[i] - y.q[i]).abs() < 1e-8, "q{} at t = {}", i + 1, x.t);
        }
        assert!(
            (length * x.q[2] - y.q[2]).abs() < 1e-8 * length,
            "q3 at t = {}",
            x.t
        );
        // Newton holds h to its tolerance times the length scale (about 4600 here).
        assert!(
            y.h[0].abs() < 1e-12 * 5000.0,
            "h = {} at t = {}",
            y.h[0],
            x.t
        );
    }
}
