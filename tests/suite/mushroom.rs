//! The curved-face (mushroom) follower against closed forms: an in-line translating follower
//! whose face is a circular arc of radius ρ_f, apex on the follower's marker, on an eccentric
//! disc cam (radius R, eccentricity e) turning at ω (`eccentric_mushroom`).
//!
//! The arc's centre, ρ_f above the apex, stays at the distance R + ρ_f from the disc's centre
//! (the offset of a circle is a circle), so the apex's height above the camshaft is
//!
//! ```text
//! s(θ) = e cos θ + √((R + ρ_f)² − e² sin² θ) − ρ_f
//! ```
//!
//! (Norton, "Cam Design and Manufacturing Handbook": the eccentric cam with a roller, whose
//! centre this is, less the face's radius). The contact point lies on the line of centres,
//! R from the disc's centre; the face is rigid on the follower, so its material there moves
//! at ṡ ŷ and the cam's at ω ẑ × C: the sliding speed is t·(ṡ ŷ − ω ẑ × C), both surfaces'
//! velocities at the contact point, taken here from the geometry alone.

use camchain::runtime::{Dynamics, Simulate, Trajectory};
use camchain_models as models;

/// The model file's values.
const R: f64 = 0.04;
const E: f64 = 0.01;
const RHO_F: f64 = 0.05;
const M: f64 = 0.5;
const K: f64 = 2000.0;
const FREE: f64 = 0.0;
const C: f64 = 2.0;
const G: f64 = 9.81;
const OMEGA: f64 = 20.0;

/// Three revolutions at the file's settings (DOP853, rtol 1e-10).
fn three_revolutions(model: &dyn Dynamics) -> Trajectory {
    let state = model.assemble(0.0).expect("assembles");
    model
        .simulate(state, &model.info().defaults)
        .unwrap_or_else(|f| panic!("{f}"))
}

/// s(θ), ṡ/ω and s̈/ω² of the apex.
fn apex_lift(theta: f64) -> (f64, f64, f64) {
    let (sn, cs) = theta.sin_cos();
    let root = ((R + RHO_F).powi(2) - E * E * sn * sn).sqrt();
    let s = E * cs + root - RHO_F;
    let ds = -E * sn - E * E * sn * cs / root;
    let dds =
        -E * cs - E * E * (cs * cs - sn * sn) / root - E.powi(4) * sn * sn * cs * cs / root.powi(3);
    (s, ds, dds)
}

#[test]
fn curved_face_on_an_eccentric_disc_follows_the_closed_form() {
    let model = models::by_name("eccentric_mushroom").expect("built in");
    assert_eq!(model.info().contacts[0].follower.name(), "mushroom");
    let trajectory = three_revolutions(model);
    assert!(
        trajectory.samples.len() > 900,
        "three revolutions sampled every ms"
    );
    let mut worst = [0.0f64; 4];
    for s in &trajectory.samples {
        let theta = OMEGA * s.t;
        assert!((s.q[0] - theta).abs() < 1e-12, "the camshaft is driven");
        let (lift, ds, dds) = apex_lift(theta);
        // Newton projects the held contact to rounding after every step; lengths ~0.05 m:
        // 1e-12 m leaves two decades above rounding (measured below).
        let error = (s.q[1] - lift).abs();
        worst[0] = worst[0].max(error);
        assert!(error < 1e-12, "t = {}: lift {} vs {lift}", s.t, s.q[1]);
        // The follower's rate: ṡ = ω ds/dθ, from the velocity projection (1e-10 m/s of
        // ~0.2 m/s, the same projection's rounding).
        assert!((s.qd[1] - OMEGA * ds).abs() < 1e-10, "t = {}", s.t);

        // The line of centres from the disc's centre D to the arc's centre A (0, s + ρ_f).
        let (sn, cs) = theta.sin_cos();
        let disc = [-E * sn, E * cs];
        let centre = [0.0, lift + RHO_F];
        let n = [
            (centre[0] - disc[0]) / (R + RHO_F),
            (centre[1] - disc[1]) / (R + RHO_F),
        ];
        let g = &s.contacts[0];
        // Unit vectors from lengths of rounding 1e-17: 1e-12.
        assert!((g.normal[0] - n[0]).abs() < 1e-12 && (g.normal[1] - n[1]).abs() < 1e-12);
        // The contact point: R along n from the disc's centre (positions of ~0.05 m).
        let contact = [disc[0] + R * n[0], disc[1] + R * n[1]];
        worst[1] = worst[1].max((g.position[0] - contact[0]).abs());
        assert!(
            (g.position[0] - contact[0]).abs() < 1e-12
                && (g.position[1] - contact[1]).abs() < 1e-12,
            "t = {}: contact ({}, {}) vs {contact:?}",
            s.t,
            g.position[0],
            g.position[1]
        );
        // Sliding: the face's material at the contact point moves at ṡ ŷ, the cam's at
        // ω ẑ × C; their difference along the tangent t = (−n_y, n_x).
        let t = [-n[1], n[0]];
        let relative = [OMEGA * contact[1], OMEGA * ds - OMEGA * contact[0]];
        let sliding = t[0] * relative[0] + t[1] * relative[1];
        worst[2] = worst[2].max((g.sliding_speed.abs() - sliding.abs()).abs());
        // Speeds ~1 m/s from unit vectors and positions of rounding 1e-16: 1e-12.
        assert!(
            (g.sliding_speed.abs() - sliding.abs()).abs() < 1e-12,
            "t = {}: sliding speed {} vs {sliding}",
            s.t,
            g.sliding_speed
        );
        // The follower's equation of motion along the slide: N n_y balances it.
        let along = M * dds * OMEGA * OMEGA + C * ds * OMEGA + K * (lift - FREE) + M * G;
        let error = (s.normal_force[0] * n[1] - along).abs() / along.abs();
        worst[3] = worst[3].max(error);
        // λ from the reduced equations, ~100 N: 1e-9 relative, as for the roller.
        assert!(error < 1e-9, "t = {}: N n_y vs {along}", s.t);
    }
    eprintln!(
        "mushroom: lift {:.1e} m, contact point {:.1e} m, sliding {:.1e} m/s, force {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
}

/// The curved face of radius ρ_f moves exactly as a roller of radius ρ_f centred on the
/// arc's centre: the same model with the face replaced by a roller whose marker is that
/// centre (the numeric reference of the edited file), its lift less ρ_f.
#[test]
fn a_curved_face_moves_like_a_roller_on_its_centre() {
    let source = models::source("eccentric_mushroom").expect("built in");
    let roller = source
        .replace(
            "follower: Mushroom(radius: \"rho_f\", normal: (0.0, -1.0, 0.0)),",
            "follower: Roller(radius: \"rho_f\"),",
        )
        .replace(
            "position: (0.0, 0.0, 0.0)), // the face's apex",
            "position: (0.0, \"rho_f\", 0.0)),",
        );
    assert_ne!(roller, source, "the edit applies");
    let roller = camchain_reference::NumericModel::from_source_with(
        &roller,
        std::path::Path::new("eccentric_mushroom_as_roller.ron"),
        &[],
        camchain_codegen::model::ParameterMode::AsDeclared,
    )
    .expect("the roller variant loads");
    let mushroom = models::by_name("eccentric_mushroom").expect("built in");
    let (a, b) = (three_revolutions(mushroom), three_revolutions(&roller));
    assert_eq!(a.samples.len(), b.samples.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        // Two exact formulations of one prescribed motion: 1e-12 m, as roller against knife.
        assert!((x.q[1] - y.q[1]).abs() < 1e-12, "t = {}", x.t);
        assert!((x.normal_force[0] - y.normal_force[0]).abs() < 1e-9 * x.normal_force[0].abs());
        // The roller rolls, the face slides: the same contact point, different sliding.
        let (p, q) = (&x.contacts[0], &y.contacts[0]);
        assert!((p.position[0] - q.position[0]).abs() < 1e-12);
    }
}
