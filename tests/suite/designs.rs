//! Cams designed from motion laws reproduce their laws (issue 14, §4).
//!
//! `tests/contact_models/designs.ron` (compiled with the `random-models` feature) holds one
//! cam per follower kind (knife edge, roller, flat face; translating and oscillating), each
//! designed from the same program of the five standard laws that start and end at rest
//! without acceleration, on camshafts driven at constant speed ω, every follower held on its
//! cam: no degree of freedom. At every output point of a simulated turn each follower's
//! coordinate must be the law's: a translating follower's height y₀ + s(θ), an oscillating
//! arm's angle φ₀ + κ s(θ), with velocity s′ω and acceleration s″ω² (times κ).
//!
//! The expected values come from the follower's geometry by its own formulas (the law of
//! cosines for the arms' base angles, Pythagoras for the guides' base heights), not from the
//! synthesis, and from the law's closed forms (checked against Norton's tables and
//! numerical integration in `camchain_runtime::motion_law`).

use camchain::runtime::Dynamics;
use camchain::runtime::motion_law::{Law, MotionProgram, Segment};
use camchain_models::contact_models;
use std::f64::consts::TAU;

const OMEGA: f64 = 12.0;
const H: f64 = 0.004;
const SWING: f64 = 0.08;
const SWING_FLAT: f64 = 0.03;
const BASE: f64 = 0.04;
const ROLLER: f64 = 0.008;

/// The program of the model file with the lift `h`.
fn program(h: f64) -> MotionProgram {
    let d = |deg: f64| deg.to_radians();
    let seg = |law, degrees, lift| Segment {
        law,
        angle: d(degrees),
        lift,
    };
    MotionProgram::new(&[
        seg(Law::Cycloidal, 50.0, h),
        seg(Law::Dwell, 20.0, h),
        seg(Law::Polynomial345, 50.0, 0.0),
        seg(Law::Polynomial4567, 50.0, h),
        seg(Law::ModifiedTrapezoid, 50.0, 0.0),
        seg(Law::ModifiedSine, 50.0, h),
        seg(Law::Dwell, 20.0, h),
        seg(Law::Cycloidal, 50.0, 0.0),
        seg(Law::Dwell, 20.0, 0.0),
    ])
    .expect("the model's program")
}

/// An arm pivoted at `pivot` whose follower point at `arm` from it is at `reach` from the
/// cam's centre: its angle, turned from the direction towards the centre by κ times the
/// angle the law of cosines gives.
fn arm_angle(pivot: [f64; 2], arm: f64, reach: f64, kappa: f64) -> f64 {
    let d = pivot[0].hypot(pivot[1]);
    let towards = (-pivot[1]).atan2(-pivot[0]);
    towards + kappa * ((d * d + arm * arm - reach * reach) / (2.0 * d * arm)).acos()
}

/// A flat face through the pivot tangent to the base circle: the arm turned from the
/// direction towards the centre by κ·asin(R_b/d).
fn face_angle(pivot: [f64; 2], kappa: f64) -> f64 {
    let d = pivot[0].hypot(pivot[1]);
    (-pivot[1]).atan2(-pivot[0]) + kappa * (BASE / d).asin()
}

/// One follower: its coordinate, its value on the base circle, κ, and its program.
struct Expected {
    coordinate: &'static str,
    base: f64,
    sign: f64,
    program: MotionProgram,
    /// The lift, for the tolerance.
    lift: f64,
}

fn followers() -> Vec<Expected> {
    let (translating, oscillating, flat) = (program(H), program(SWING), program(SWING_FLAT));
    vec![
        Expected {
            coordinate: "y_knife",
            base: (BASE * BASE - 0.01 * 0.01).sqrt(),
            sign: 1.0,
            program: translating.clone(),
            lift: H,
        },
        Expected {
            coordinate: "y_roller",
            base: ((BASE + ROLLER).powi(2) - 0.005 * 0.005).sqrt(),
            sign: 1.0,
            program: translating.clone(),
            lift: H,
        },
        Expected {
            coordinate: "y_flat",
            base: BASE,
            sign: 1.0,
            program: translating,
            lift: H,
        },
        Expected {
            coordinate: "phi_knife",
            base: arm_angle([0.07, 0.05], 0.06, BASE, 1.0),
            sign: 1.0,
            program: oscillating.clone(),
            lift: SWING,
        },
        Expected {
            coordinate: "phi_roller",
            base: arm_angle([-0.07, 0.05], 0.06, BASE + ROLLER, -1.0),
            sign: -1.0,
            program: oscillating,
            lift: SWING,
        },
        Expected {
            coordinate: "phi_flat",
            base: face_angle([0.07, 0.05], 1.0),
            sign: 1.0,
            program: flat,
            lift: SWING_FLAT,
        },
    ]
}

#[test]
fn every_follower_kind_reproduces_its_law_over_a_turn() {
    let model = &*contact_models::designs::DEFAULT;
    let info = model.info();
    let index = |name: &str| {
        info.coordinates
            .iter()
            .position(|c| c.name == name)
            .unwrap_or_else(|| panic!("coordinate {name}"))
    };
    let state = model.assemble().expect("the designed followers assemble");
    let run = model
        .simulate(state, &info.defaults)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(run.samples.len() > 1000, "a turn of output points");
    let mut worst = [0.0f64; 3];
    for f in followers() {
        let k = index(f.coordinate);
        let mut errors = [0.0f64; 3];
        for sample in &run.samples {
            // Both camshafts turn by ωt, one each way; the law's angle is the turn.
            let theta = OMEGA * sample.t;
            let law = f.program.eval(theta);
            let expected = [
                f.base + f.sign * law[0],
                f.sign * law[1] * OMEGA,
                f.sign * law[2] * OMEGA * OMEGA,
            ];
            let got = [sample.q[k], sample.qd[k], sample.qdd[k]];
            for order in 0..3 {
                // Relative to the lift at the cam's speed: h, hω, hω².
                let scale = f.lift * OMEGA.powi(order as i32);
                let error = (got[order] - expected[order]).abs() / scale;
                errors[order] = errors[order].max(error);
            }
        }
        eprintln!(
            "{}: largest errors relative to the lift: displacement {:.1e}, velocity {:.1e}, \
             acceleration {:.1e}",
            f.coordinate, errors[0], errors[1], errors[2]
        );
        // The bound: 1e-9 of the lift (measured: rounding and Newton's stop).
        for (order, error) in errors.iter().enumerate() {
            assert!(
                *error < 1e-9,
                "{}: derivative {order} off the law by {error:e} of the lift",
                f.coordinate
            );
            worst[order] = worst[order].max(*error);
        }
    }
    assert!((run.samples[run.samples.len() - 1].t * OMEGA - TAU).abs() < 1e-9);
    eprintln!(
        "worst over every follower: {:.1e}, {:.1e}, {:.1e}",
        worst[0], worst[1], worst[2]
    );
}

/// The one law the compiled model leaves out, the simple harmonic (its acceleration jumps
/// against a dwell, so a model with it draws warnings): `cycloidal_roller` with harmonic
/// rise and return, on the numeric reference. At 36 cam angles the assembled follower's
/// height, velocity and acceleration are the law's (1e-9 of the lift at ω, the issue's
/// bound), and the build warns of the four acceleration jumps with the textbook size
/// (π²/2)·h/β² (Norton: the harmonic's acceleration at its ends).
#[test]
fn a_simple_harmonic_cam_reproduces_its_law_and_warns_of_its_jumps() {
    use camchain::runtime::Simulate;
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/cycloidal_roller.ron");
    let source = std::fs::read_to_string(&file)
        .expect("cycloidal_roller.ron")
        .replace("law: Cycloidal", "law: SimpleHarmonic");
    let mode = camchain_codegen::model::ParameterMode::AsDeclared;
    let model = camchain_reference::NumericModel::from_source_with(&source, &file, &[], mode)
        .unwrap_or_else(|e| panic!("{e}"));
    let (h, beta, omega, base) = (0.012, 120f64.to_radians(), 50.0, 0.04 + 0.0125);
    let seg = |law, degrees: f64, lift| Segment {
        law,
        angle: degrees.to_radians(),
        lift,
    };
    let program = MotionProgram::new(&[
        seg(Law::Dwell, 60.0, 0.0),
        seg(Law::SimpleHarmonic, 120.0, h),
        seg(Law::Dwell, 60.0, h),
        seg(Law::SimpleHarmonic, 120.0, 0.0),
    ])
    .expect("the file's program");
    let mut worst = [0.0f64; 3];
    for k in 0..36 {
        let theta = (10.0 * k as f64 + 3.7).to_radians();
        let state = model.assemble(theta / omega).expect("assembles");
        let sample = model.sample(&state).expect("a sample");
        let law = program.eval(theta);
        let expected = [base + law[0], law[1] * omega, law[2] * omega * omega];
        let got = [sample.q[1], sample.qd[1], sample.qdd[1]];
        for order in 0..3 {
            let error = (got[order] - expected[order]).abs() / (h * omega.powi(order as i32));
            worst[order] = worst[order].max(error);
        }
    }
    eprintln!("simple harmonic against its law, relative to the lift: {worst:?}");
    assert!(worst.iter().all(|e| *e < 1e-9), "{worst:?}");
    let parsed = camchain_codegen::schema::parse_model(&source, &file).expect("valid");
    let warnings = camchain_codegen::lint::warnings(&parsed);
    let jump = std::f64::consts::PI.powi(2) / 2.0 * h / (beta * beta);
    let jumps: Vec<&str> = warnings
        .iter()
        .filter(|w| w.message.contains("acceleration jumps"))
        .map(|w| w.field.as_str())
        .collect();
    assert_eq!(
        jumps,
        [
            "contacts[0].law.segments[0]",
            "contacts[0].law.segments[1]",
            "contacts[0].law.segments[2]",
            "contacts[0].law.segments[3]"
        ],
        "{warnings:?}"
    );
    assert!(
        warnings
            .iter()
            .any(|w| w.message.contains(&format!("{jump:.4e} per rad²"))),
        "the size (π²/2)h/β² = {jump:.4e}: {warnings:?}"
    );
}
