//! Cams on moving bodies with roller and flat-faced followers, checked against closed forms:
//!
//! - an eccentric disc (radius R, eccentricity e) turning at ω under a translating flat face:
//!   the face's height is R + e cos θ (simple harmonic motion), and the normal force is the
//!   follower's equation of motion m s̈ + c ṡ + k (s − s_free) + m g;
//! - the same disc under an in-line roller of radius ρ: the roller's centre is at
//!   s(θ) = e cos θ + √((R + ρ)² − e² sin² θ) above the camshaft (Norton, "Cam Design and
//!   Manufacturing Handbook", eccentric cam with roller follower), and the normal force along
//!   the line of centres satisfies N n_y = m s̈ + c ṡ + k (s − s_free) + m g;
//! - a roller of radius ρ on the disc moves exactly like a knife edge on the disc of radius
//!   R + ρ (the offset of a circle is a circle);
//! - the jump speed of the flat-faced follower: with no damping the normal force is least at
//!   θ = 0, N_min = −m e ω² + k (R + e − s_free) + m g, zero at
//!   ω_jump = √((k (R + e − s_free) + m g)/(m e)); bisection on the camshaft's speed for the
//!   first simulated run whose normal force goes negative finds it to 1e-6;
//! - the motor-driven camshaft with its flywheel: energy + dissipated − work of the motor and
//!   of the drives constant, and the follower lifting off once the camshaft is fast enough.

use camchain::runtime::events::EventKind;
use camchain::runtime::{Dynamics, SimSettings, Simulate, Trajectory};
use camchain_codegen::model::ParameterMode;
use camchain_models as models;
use camchain_reference::NumericModel;
use std::f64::consts::TAU;
use std::path::Path;

/// The eccentric models' dimensions (their files' values).
const R: f64 = 0.04;
const E: f64 = 0.01;
const RHO: f64 = 0.0125;
const M: f64 = 0.5;
const K: f64 = 2000.0;
const FREE: f64 = 0.0;
const C: f64 = 2.0;
const G: f64 = 9.81;
const OMEGA: f64 = 20.0;

fn run(model: &dyn Dynamics, settings: &SimSettings) -> Trajectory {
    let state = model.assemble(0.0).expect("assembles");
    model
        .simulate(state, settings)
        .unwrap_or_else(|f| panic!("{f}"))
}

/// Three revolutions at the file's tolerance (DOP853, rtol 1e-10).
fn three_revolutions(model: &dyn Dynamics) -> Trajectory {
    run(model, &model.info().defaults)
}

#[test]
fn flat_faced_follower_on_an_eccentric_disc_moves_harmonically() {
    let model = models::by_name("eccentric_flat").expect("built in");
    let trajectory = three_revolutions(model);
    let mut worst = (0.0f64, 0.0f64);
    for s in &trajectory.samples {
        let theta = OMEGA * s.t;
        let lift = R + E * theta.cos();
        // The face's height: Newton solves the contact to rounding, 1e-10 of R is the
        // issue's bound (measured ~1e-17).
        let error = (s.q[1] - lift).abs();
        worst.0 = worst.0.max(error);
        assert!(error < 1e-10 * R, "t = {}: lift {} vs {lift}", s.t, s.q[1]);
        // The follower's equation of motion along the slide, which is the face's normal.
        let (v, a) = (-E * OMEGA * theta.sin(), -E * OMEGA * OMEGA * theta.cos());
        let force = M * a + C * v + K * (lift - FREE) + M * G;
        // λ from the reduced equations, ~100 N: 1e-9 relative.
        let error = (s.normal_force[0] - force).abs() / force.abs();
        worst.1 = worst.1.max(error);
        assert!(
            error < 1e-9,
            "t = {}: N {} vs {force}",
            s.t,
            s.normal_force[0]
        );
        // The contact is at the disc's highest point, straight below the face.
        let g = &s.contacts[0];
        assert!((g.normal[1] - 1.0).abs() < 1e-12 && g.pressure_angle().abs() < 1e-12);
    }
    eprintln!(
        "flat face: lift error {:.1e} m, normal force {:.1e}",
        worst.0, worst.1
    );
}

/// s(θ), ṡ/ω and s̈/ω² of the in-line roller follower.
fn roller_lift(theta: f64) -> (f64, f64, f64) {
    let (sn, cs) = theta.sin_cos();
    let a = (R + RHO).powi(2);
    let root = (a - E * E * sn * sn).sqrt();
    let s = E * cs + root;
    // d/dθ √(a − e² sin²θ) = −e² sin θ cos θ / √…; twice: −e² cos 2θ/√… − e⁴ sin²θ cos²θ/√…³.
    let ds = -E * sn - E * E * sn * cs / root;
    let dds =
        -E * cs - E * E * (cs * cs - sn * sn) / root - E.powi(4) * sn * sn * cs * cs / root.powi(3);
    (s, ds, dds)
}

#[test]
fn in_line_roller_on_an_eccentric_disc_follows_the_closed_form() {
    let model = models::by_name("eccentric_roller").expect("built in");
    let trajectory = three_revolutions(model);
    let mut worst = (0.0f64, 0.0f64);
    for s in &trajectory.samples {
        let theta = OMEGA * s.t;
        let (lift, ds, dds) = roller_lift(theta);
        let error = (s.q[1] - lift).abs();
        worst.0 = worst.0.max(error);
        assert!(error < 1e-10 * R, "t = {}: lift {} vs {lift}", s.t, s.q[1]);
        // The normal runs along the line of centres: n_y = √((R+ρ)² − e² sin²θ)/(R + ρ).
        let n_y = (lift - E * theta.cos()) / (R + RHO);
        let along_slide = M * dds * OMEGA * OMEGA + C * ds * OMEGA + K * (lift - FREE) + M * G;
        let error = (s.normal_force[0] * n_y - along_slide).abs() / along_slide.abs();
        worst.1 = worst.1.max(error);
        assert!(
            error < 1e-9,
            "t = {}: N n_y {} vs {along_slide}",
            s.t,
            s.normal_force[0] * n_y
        );
        assert!((s.contacts[0].normal[1] - n_y).abs() < 1e-12);
    }
    eprintln!(
        "roller: lift error {:.1e} m, normal force {:.1e}",
        worst.0, worst.1
    );
}

/// The outputs a cam designer reads, against the geometry of the eccentric disc: the contact
/// point in the cam frame (which turns with the camshaft; its axes are the ground's y and −x
/// at θ = 0), the pressure angle (for an in-line roller sin φ = e sin θ / (R + ρ), the
/// normal running through the disc's centre) and the sliding speed (the flat face does not
/// move sideways: the cam's material slides under it at ω times the face's height; the
/// roller's rim against a cam point C: t·(ṡ ŷ − ω ẑ × C)).
#[test]
fn contact_outputs_follow_the_disc_geometry() {
    for (name, roller) in [("eccentric_flat", false), ("eccentric_roller", true)] {
        let model = models::by_name(name).expect("built in");
        let trajectory = three_revolutions(model);
        for s in &trajectory.samples {
            let (theta, lift, lift_dot) = (s.q[0], s.q[1], s.qd[1]);
            let g = &s.contacts[0];
            // The cam-frame point turned by θ is the ground point. Rounding of ~0.05 m
            // lengths: 1e-15 m; 1e-14 leaves room for the rotation's few operations.
            let (sn, cs) = theta.sin_cos();
            let (x_axis, y_axis) = ([-sn, cs], [-cs, -sn]);
            for a in 0..2 {
                let turned = g.x * x_axis[a] + g.y * y_axis[a];
                assert!((turned - g.position[a]).abs() < 1e-14, "{name} t = {}", s.t);
            }
            let centre = [-E * sn, E * cs];
            let (pressure, sliding) = if roller {
                // The normal from the disc's centre to the roller's centre (0, s).
                let n = [-centre[0] / (R + RHO), (lift - centre[1]) / (R + RHO)];
                let c = [centre[0] + R * n[0], centre[1] + R * n[1]];
                let t = [-n[1], n[0]];
                let relative = [OMEGA * c[1], lift_dot - OMEGA * c[0]];
                (
                    (E * (-sn) / (R + RHO)).asin(),
                    t[0] * relative[0] + t[1] * relative[1],
                )
            } else {
                (0.0, OMEGA * lift)
            };
            // Angles from unit vectors of rounding 1e-16: 1e-12 rad; speeds ~1 m/s: 1e-12.
            assert!(
                (g.pressure_angle().abs() - pressure.abs()).abs() < 1e-12,
                "{name} t = {}: pressure angle {} vs {pressure}",
                s.t,
                g.pressure_angle()
            );
            assert!(
                (g.sliding_speed.abs() - sliding.abs()).abs() < 1e-12,
                "{name} t = {}: sliding speed {} vs {sliding}",
                s.t,
                g.sliding_speed
            );
        }
    }
}

#[test]
fn a_roller_moves_like_a_knife_edge_on_the_offset_curve() {
    // The same model with the roller replaced by a knife edge on the disc of radius R + ρ
    // (the numeric reference, built from the edited file, against the generated roller).
    let source = models::source("eccentric_roller").expect("built in");
    let knife = source
        .replace("follower: Roller(radius: \"rho\"),", "")
        .replace(
            "(R*R - e*e*theta.sin().powi(2))",
            "((R + rho)*(R + rho) - e*e*theta.sin().powi(2))",
        );
    assert_ne!(knife, source, "the edit applies");
    let knife = NumericModel::from_source_with(
        &knife,
        Path::new("eccentric_knife.ron"),
        &[],
        ParameterMode::AsDeclared,
    )
    .expect("the knife-edge variant loads");
    let roller = models::by_name("eccentric_roller").expect("built in");
    let (a, b) = (three_revolutions(roller), three_revolutions(&knife));
    assert_eq!(a.samples.len(), b.samples.len());
    let mut worst = 0.0f64;
    for (x, y) in a.samples.iter().zip(&b.samples) {
        // Two exact formulations of one motion, integrated independently at rtol 1e-10
        // (a prescribed motion: only the quadratures are integrated): 1e-12 m.
        worst = worst.max((x.q[1] - y.q[1]).abs());
        assert!((x.q[1] - y.q[1]).abs() < 1e-12, "t = {}", x.t);
        assert!((x.normal_force[0] - y.normal_force[0]).abs() < 1e-9 * x.normal_force[0].abs());
    }
    eprintln!("roller vs knife on the offset circle: {worst:.1e} m");
}

/// The least normal force of one simulated revolution of the undamped flat-faced follower at
/// camshaft speed `omega`, over the samples of its second revolution (the first sample of
/// which is θ = 2π, where the force is least).
fn least_normal_force(omega: f64) -> f64 {
    let model = models::eccentric_flat::Model::with(&[("omega", omega), ("c", 0.0)])
        .expect("valid parameters");
    let period = TAU / omega;
    let settings = SimSettings {
        t_end: 2.0 * period,
        dt_out: period / 360.0,
        ..model.default_settings()
    };
    let trajectory = run(&model, &settings);
    trajectory
        .samples
        .iter()
        .filter(|s| s.t >= period * (1.0 - 1e-12))
        .map(|s| s.normal_force[0])
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn the_jump_speed_matches_the_closed_form() {
    let predicted = ((K * (R + E - FREE) + M * G) / (M * E)).sqrt();
    let (mut low, mut high) = (0.5 * predicted, 1.5 * predicted);
    assert!(least_normal_force(low) > 0.0 && least_normal_force(high) < 0.0);
    while (high - low) > 1e-8 * predicted {
        let mid = 0.5 * (low + high);
        if least_normal_force(mid) < 0.0 {
            high = mid;
        } else {
            low = mid;
        }
    }
    let found = 0.5 * (low + high);
    let error = (found - predicted).abs() / predicted;
    eprintln!("jump speed: predicted {predicted} rad/s, simulated {found} rad/s ({error:.1e})");
    assert!(error < 1e-6, "{found} vs {predicted}");
}

#[test]
fn the_motor_driven_camshaft_keeps_its_energy_balance_and_its_follower_jumps() {
    let model = models::by_name("camshaft_flywheel").expect("built in");
    let info = model.info();
    let restitution = info.restitution.expect("the model is one-sided");
    let state = model.assemble(0.0).expect("assembles");
    let run = model
        .simulate_unilateral(state, &info.defaults, restitution)
        .unwrap_or_else(|f| panic!("{f}"));
    // E + dissipated − work of the motor and the drives, through flights and impacts
    // (rtol 1e-9 over 2 s and ~70 events; the energy scale is ~170 J): 1e-5 J.
    let balance: Vec<f64> = run
        .samples
        .iter()
        .map(|s| s.energy.total() + s.dissipated - s.driven_work)
        .collect();
    let drift = balance
        .iter()
        .map(|b| (b - balance[0]).abs())
        .fold(0.0, f64::max);
    assert!(drift < 1e-5, "energy balance drifts by {drift:e} J");
    // The camshaft spins up and varies within a revolution; the follower lifts off once the
    // speed is past the jump speed of its spring (about 63 rad/s), never below it.
    let jump = ((300.0 * (R + E) + M * G) / (M * E)).sqrt();
    let lift_off = run
        .events
        .iter()
        .find(|e| matches!(e.kind, EventKind::LiftOff))
        .expect("the follower jumps");
    let speed = lift_off.qd[0];
    assert!(
        speed > jump * 0.95 && speed < jump * 1.3,
        "lift-off at {speed} rad/s, jump speed {jump}"
    );
    // Every landing approaches the cam and rebounds by Newton's law (or stays): a rebound
    // re-found at its own take-off once counted as a landing that flipped it back.
    for event in &run.events {
        if let EventKind::Impact {
            normal_velocity,
            rebound,
            stays,
            ..
        } = event.kind
        {
            assert!(
                normal_velocity < 0.0,
                "t = {}: lands at {normal_velocity}",
                event.t
            );
            let expected = if stays {
                0.0
            } else {
                -restitution * normal_velocity
            };
            // Newton's law on the impulse, rounding of ~1e-16 m/s.
            assert!((rebound - expected).abs() < 1e-12, "t = {}", event.t);
        }
    }
    let speeds: Vec<f64> = run.samples.iter().map(|s| s.qd[0]).collect();
    assert!(speeds.iter().cloned().fold(0.0, f64::max) > jump);
    eprintln!(
        "flywheel: lift-off at t = {:.6} s at {speed:.3} rad/s (jump speed {jump:.3}); energy \
         balance {drift:.1e} J; {} events",
        lift_off.t,
        run.events.len()
    );
}
