//! A ball (a `Roller` on a cam surface, docs/method.md §13.8) against closed forms.
//!
//! `tests/contact_models/ball_on_plane.ron`: a ball of radius ρ on the inclined plane
//! z = a x + b y under gravity, its centre carried by three perpendicular slides. Its centre
//! stays on the parallel plane ρ W above (W = √(1 + a² + b²)) and moves there as a point
//! does, uniformly accelerated by gravity's tangential part, pressed on by N = m g/W; the
//! point on that parallel plane (`tests/numeric_models/point_on_offset_plane.ron`, read by
//! the numeric reference) runs alike.

use camchain::runtime::{Dynamics, Simulate, Trajectory};
use camchain_models::contact_models;
use camchain_reference::NumericModel;

const A: f64 = 0.3;
const B: f64 = -0.2;
const RHO: f64 = 0.02;
const M: f64 = 0.5;
const G: f64 = 9.81;

fn run(model: &dyn Dynamics) -> Trajectory {
    let settings = model.info().defaults.clone();
    model
        .simulate(model.assemble(0.0).expect("assembles"), &settings)
        .unwrap_or_else(|f| panic!("{}", f.error))
}

#[test]
fn a_ball_on_a_plane_moves_like_a_point_on_the_parallel_plane() {
    let w = (1.0 + A * A + B * B).sqrt();
    let normal = [-A / w, -B / w, 1.0 / w];
    // Gravity less its normal part: g_t = (0, 0, −g) + (g/W) n.
    let accel = [G / w * normal[0], G / w * normal[1], -G + G / w * normal[2]];
    let (x0, v0) = ([0.0, 0.0, RHO * w], [0.5, 0.3, 0.5 * A + 0.3 * B]);
    let ball = run(&*contact_models::ball_on_plane::DEFAULT);
    let path = format!(
        "{}/tests/numeric_models/point_on_offset_plane.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let point = NumericModel::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let point = run(&point);
    assert_eq!(ball.samples.len(), 201, "2 s at dt_out 0.01");
    assert_eq!(point.samples.len(), ball.samples.len());
    let [mut closed, mut twin, mut force, mut contact] = [0.0f64; 4];
    for (s, p) in ball.samples.iter().zip(&point.samples) {
        let t = s.t;
        for k in 0..3 {
            let expected = x0[k] + v0[k] * t + 0.5 * accel[k] * t * t;
            closed = closed.max((s.q[k] - expected).abs());
            twin = twin.max((s.q[k] - p.q[k]).abs());
            twin = twin.max((s.qd[k] - p.qd[k]).abs());
        }
        force = force.max((s.normal_force[0] - M * G / w).abs());
        // The contact point is the centre moved ρ against the normal.
        let c = &s.contacts[0];
        for (k, n) in normal.iter().enumerate() {
            contact = contact.max((c.position[k] - (s.q[k] - RHO * n)).abs());
        }
    }
    println!(
        "ball on a plane over 2 s: centre against the closed form {closed:.1e} m, against the \
         point on the parallel plane {twin:.1e}, normal force {force:.1e} N, contact point \
         {contact:.1e} m"
    );
    // The demand: 1e-12. The motion is quadratic in t, which Dormand–Prince 8(5,3)
    // integrates exactly: what remains is rounding over 4 m of travel (~1e-15 relative),
    // and the carriages' 1e-15 of the ball's mass.
    assert!(closed < 1e-12, "closed form {closed:e} m");
    assert!(twin < 1e-12, "point on the parallel plane {twin:e}");
    assert!(force < 1e-12, "normal force {force:e} N");
    assert!(contact < 1e-12, "contact point {contact:e} m");
}

#[test]
fn a_ball_in_a_bowl_keeps_its_circular_orbit_generated_and_numeric() {
    // tests/contact_models/ball_in_bowl.ron: the ball touches z = c (x² + y²) at the foot
    // radius rf, the normal leaning by α (tan α = 2 c rf); the centre circles at R = rf − ρ
    // sin α, height c rf² + ρ cos α, at ω² = g tan α / R, pressed by N = m g / cos α.
    let (c, rf, rho, m, g): (f64, f64, f64, f64, f64) = (2.0, 0.1, 0.02, 0.5, 9.81);
    let alpha = (2.0 * c * rf).atan();
    let radius = rf - rho * alpha.sin();
    let height = c * rf * rf + rho * alpha.cos();
    let omega = (g * alpha.tan() / radius).sqrt();
    let force = m * g / alpha.cos();
    let path = format!(
        "{}/tests/contact_models/ball_in_bowl.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let numeric = NumericModel::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let generated = run(&*contact_models::ball_in_bowl::DEFAULT);
    let numeric = run(&numeric);
    assert_eq!(generated.samples.len(), 901, "9 s at dt_out 0.01");
    assert_eq!(numeric.samples.len(), generated.samples.len());
    for (engine, trajectory) in [("generated", &generated), ("numeric", &numeric)] {
        let [mut r_err, mut z_err, mut phase, mut n_err] = [0.0f64; 4];
        for s in &trajectory.samples {
            let (x, y, z) = (s.q[0], s.q[1], s.q[2]);
            r_err = r_err.max((x.hypot(y) - radius).abs() / radius);
            z_err = z_err.max((z - height).abs());
            let turned = y.atan2(x);
            let expected = (omega * s.t + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            let d = (turned - expected + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            phase = phase.max(d.abs());
            n_err = n_err.max((s.normal_force[0] - force).abs() / force);
        }
        println!(
            "ball in a bowl, {engine}, {:.1} revolutions: radius {r_err:.1e} of R, height \
             {z_err:.1e} m, phase {phase:.1e} rad, normal force {n_err:.1e}",
            omega * 9.0 / std::f64::consts::TAU
        );
        // As the particle on the paraboloid (surfaces.rs): circular to 1e-9; the phase
        // drifts with the integration (rtol 1e-10) over 58 rad, to 1e-8.
        assert!(
            r_err < 1e-9 && z_err < 1e-9,
            "{engine}: {r_err:e} {z_err:e}"
        );
        assert!(phase < 1e-8, "{engine}: phase {phase:e} rad");
        assert!(n_err < 1e-9, "{engine}: normal force {n_err:e}");
    }
    // The generated code's nested Newton solves (warm-started from the last foot point)
    // against the reference's two-dimensional descent, over the whole run.
    let mut worst = 0.0f64;
    for (a, b) in generated.samples.iter().zip(&numeric.samples) {
        for k in 0..3 {
            worst = worst
                .max((a.q[k] - b.q[k]).abs())
                .max((a.qd[k] - b.qd[k]).abs());
        }
        let (pa, pb) = (a.contacts[0].position, b.contacts[0].position);
        for k in 0..3 {
            worst = worst.max((pa[k] - pb[k]).abs());
        }
    }
    println!("ball in a bowl: generated against numeric {worst:.1e}");
    // Two routes to the same dynamics, the integrators' step choices amplifying rounding
    // over 9 s: 1e-9 (measured ~1e-12).
    assert!(worst < 1e-9, "{worst:e}");
}

#[test]
fn a_ball_leaves_a_sphere_where_its_centre_would_as_a_particle() {
    // tests/contact_models/ball_slide.ron: a ball of radius ρ on the sphere r = √(a² − z²)
    // (a surface of revolution), started at rest with its centre θ₀ from the top: the centre
    // moves on the sphere of radius a + ρ and leaves it at cos θ* = (2/3) cos θ₀.
    let path = format!(
        "{}/tests/contact_models/ball_slide.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let numeric = NumericModel::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let generated = &*contact_models::ball_slide::DEFAULT;
    let (a, rho, theta0) = (0.4, 0.1, 0.5f64);
    let expected = 2.0 / 3.0 * theta0.cos();
    for (engine, model) in [
        ("generated", generated as &dyn Dynamics),
        ("numeric", &numeric as &dyn Dynamics),
    ] {
        let settings = model.info().defaults.clone();
        let run = model
            .simulate_unilateral(model.assemble(0.0).expect("assembles"), &settings, 0.0)
            .unwrap_or_else(|f| panic!("{engine}: {f}"));
        let lift_off = run
            .events
            .iter()
            .find(|e| e.kind == camchain::runtime::events::EventKind::LiftOff)
            .unwrap_or_else(|| panic!("{engine}: no lift-off in {:?}", run.events));
        let (x, z) = (lift_off.q[0], lift_off.q[2]);
        let on_sphere = (x.hypot(z) - (a + rho)).abs();
        let cos = z / (a + rho);
        println!(
            "ball_slide ({engine}): the centre leaves at cos θ = {cos:.12}, closed form \
             {expected:.12} ({:.1e}); t = {:.9} s",
            cos - expected,
            lift_off.t
        );
        // As the particle on a sphere (surfaces.rs): the event located to 1e-9 s at ~2 m/s,
        // the force's zero to the integration's rtol 1e-10.
        assert!(
            on_sphere < 1e-12,
            "{engine}: {on_sphere:e} off the centre's sphere"
        );
        assert!(
            (cos - expected).abs() < 1e-8,
            "{engine}: cos θ* = {cos}, closed form {expected}"
        );
    }
}

#[test]
fn the_compiled_balls_agree_with_the_numeric_reference_at_random_states() {
    // 100 states within 0.02 m (and 2 m/s) of each model's assembled configuration: the
    // generated code's nested (or meridian) Newton solves against the reference's own
    // descents, every `Dynamics` function (M, F, Q, h, J, c, the contact's outputs).
    for (name, generated) in [
        (
            "ball_on_plane",
            &*contact_models::ball_on_plane::DEFAULT as &dyn Dynamics,
        ),
        ("ball_in_bowl", &*contact_models::ball_in_bowl::DEFAULT),
        ("ball_slide", &*contact_models::ball_slide::DEFAULT),
    ] {
        let path = format!(
            "{}/tests/contact_models/{name}.ron",
            env!("CARGO_MANIFEST_DIR")
        );
        let numeric =
            NumericModel::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
        let start = generated.assemble(0.0).expect("assembles");
        let states = crate::common::states_near(&start.q, 0.02, 100, 0xba11);
        // As for the built-in models (generated_vs_numeric.rs): 1e-12 relative to
        // max(1, |·|); the foot points are Newton's to rounding on both sides (measured
        // 7e-15 on the bowl).
        let worst = crate::common::compare_dynamics_at(name, generated, &numeric, 1e-12, &states);
        println!("{name}: largest relative difference generated vs numeric {worst:.2e}");
    }
}
