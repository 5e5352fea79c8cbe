//! Cam surfaces z = f(x, y) (docs/method.md §13) against closed forms and the planar
//! contact they generalise:
//!
//! - planar equivalence: the paper's concave scenario with its cam written as a surface that
//!   does not depend on y (`tests/contact_models/paper_on_surface.ron`) reproduces
//!   `paper_concave` (generated code both);
//! - a particle on the paraboloid z = c (x² + y²) (`models/paraboloid_orbit.ron`) started on
//!   the circular orbit at ω = √(2 c g): radius, height, angular momentum and energy, against
//!   that closed form, over ten revolutions;
//! - generated against numeric for the surface models (beyond the 100 random states of
//!   `generated_vs_numeric.rs`): whole runs.

use camchain::runtime::{Dynamics, SimSettings, Simulate};
use camchain_models as models;
use camchain_models::contact_models;
use camchain_reference::NumericModel;

fn numeric(path: &str) -> NumericModel {
    let path = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    NumericModel::load(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_paper_cam_as_a_surface_reproduces_the_planar_run() {
    let planar = models::by_name("paper_concave").expect("built in");
    let surface = &*contact_models::paper_on_surface::DEFAULT;
    let settings = planar.info().defaults.clone();
    let run = |m: &dyn Dynamics| {
        m.simulate(m.assemble(0.0).expect("assembles"), &settings)
            .unwrap_or_else(|f| panic!("{}", f.error))
    };
    let (a, b) = (run(planar), run(surface));
    assert_eq!(a.samples.len(), b.samples.len());
    assert_eq!(a.samples.len(), 1001, "10 s at dt_out 0.01");
    let mut worst = 0.0f64;
    for (x, y) in a.samples.iter().zip(&b.samples) {
        assert_eq!(x.t, y.t);
        // The two constraints are the same expression (h = Z − f(X) with Z the ground y):
        // the runs differ by the rounding of differently ordered operations, amplified by
        // the swing's 10 s (measured below 1e-13); 1e-12 is the demand.
        let pairs = [
            (&x.q, &y.q),
            (&x.qd, &y.qd),
            (&x.normal_force, &y.normal_force),
        ];
        for (p, r) in pairs {
            for (u, v) in p.iter().zip(r.iter()) {
                let d = (u - v).abs() / (1.0 + v.abs());
                worst = worst.max(d);
                assert!(d < 1e-12, "t = {}: planar {u} vs surface {v}", x.t);
            }
        }
        // The contact point (ground) and the normal, the planar one in the chain's plane.
        for k in 0..3 {
            let (p, s) = (&x.contacts[0], &y.contacts[0]);
            assert!((p.position[k] - s.position[k]).abs() < 1e-12, "t = {}", x.t);
            assert!((p.normal[k] - s.normal[k]).abs() < 1e-12, "t = {}", x.t);
        }
    }
    println!("paper as a surface: largest difference from the planar run {worst:.1e}");
}

/// Ten revolutions of the paraboloid orbit at tight tolerances.
fn orbit(m: &dyn Dynamics) -> Vec<camchain::runtime::Sample> {
    let mut settings: SimSettings = m.info().defaults.clone();
    settings.rtol = 1e-13;
    settings.atol = 1e-15;
    m.simulate(m.assemble(0.0).expect("assembles"), &settings)
        .unwrap_or_else(|f| panic!("{}", f.error))
        .samples
}

#[test]
fn a_particle_on_a_paraboloid_keeps_its_circular_orbit() {
    let model = models::by_name("paraboloid_orbit").expect("built in");
    let value = |name: &str| {
        model
            .info()
            .parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.default)
            .expect("declared")
    };
    // The file's values: c = 2 1/m, r0 = 0.1 m, g = 9.81 m/s² (constant, not listed as a
    // settable parameter).
    let (c, r0, g) = (value("c"), value("r0"), 9.81);
    let omega = (2.0 * c * g).sqrt();
    let samples = orbit(model);
    let t_end = samples.last().expect("samples").t;
    assert!(
        omega * t_end > 10.0 * std::f64::consts::TAU,
        "ten revolutions"
    );
    let [mut radius, mut height, mut phase, mut momentum, mut energy] = [0.0f64; 5];
    let e0 = samples[0].energy.total();
    let scale = 0.5 * (omega * r0).powi(2) + g * c * r0 * r0;
    for s in &samples {
        let [x, y, z] = [s.q[0], s.q[1], s.q[2]];
        let [vx, vy] = [s.qd[0], s.qd[1]];
        radius = radius.max((x.hypot(y) - r0).abs() / r0);
        height = height.max((z - c * r0 * r0).abs() / (c * r0 * r0));
        // The angle swept is ω t: the orbit keeps its speed as well as its shape.
        let angle = (y.atan2(x) - omega * s.t + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        phase = phase.max(angle.abs());
        momentum = momentum.max(((x * vy - y * vx) - r0 * omega * r0).abs() / (r0 * omega * r0));
        energy = energy.max((s.energy.total() - e0).abs() / scale);
    }
    println!(
        "paraboloid orbit over {:.1} revolutions: radius {radius:.1e}, height {height:.1e}, \
         phase {phase:.1e} rad, angular momentum {momentum:.1e}, energy {energy:.1e} (relative)",
        omega * t_end / std::f64::consts::TAU
    );
    // The demand: circular to 1e-9 over ten revolutions. The carriages' 1e-12 kg
    // (see the model file) perturb it by ~1e-12; the integration at rtol 1e-13 by less.
    assert!(radius < 1e-9, "radius drifts by {radius:e} of r0");
    assert!(height < 1e-9, "height drifts by {height:e}");
    // The phase error grows with time as the integrator's error does: 1e-8 rad after 63 rad.
    assert!(phase < 1e-8, "phase {phase:e} rad");
    // Angular momentum about the axis and energy: exact invariants of the particle (the
    // carriages break the symmetry by ~1e-12).
    assert!(momentum < 1e-9, "angular momentum {momentum:e}");
    assert!(energy < 1e-9, "energy {energy:e}");
}

#[test]
fn surface_models_run_alike_generated_and_numeric() {
    for (generated, path) in [
        (
            models::by_name("paraboloid_orbit").expect("built in") as &dyn Dynamics,
            "models/paraboloid_orbit.ron",
        ),
        (
            &*contact_models::paper_on_surface::DEFAULT as &dyn Dynamics,
            "tests/contact_models/paper_on_surface.ron",
        ),
    ] {
        let numeric = numeric(path);
        assert_eq!(generated.info(), numeric.info(), "{path}");
        let mut settings = generated.info().defaults.clone();
        settings.t_end = 2.0;
        let run = |m: &dyn Dynamics| {
            m.simulate(m.assemble(0.0).expect("assembles"), &settings)
                .unwrap_or_else(|f| panic!("{}", f.error))
        };
        let (a, b) = (run(generated), run(&numeric));
        assert_eq!(a.samples.len(), b.samples.len());
        for (x, y) in a.samples.iter().zip(&b.samples) {
            // Right-hand sides agreeing to ~1e-14 integrated at rtol 1e-10 over 2 s.
            let d =
                x.q.iter()
                    .zip(&y.q)
                    .map(|(u, v)| (u - v).abs() / (1.0 + v.abs()))
                    .fold(0.0, f64::max);
            assert!(d < 1e-8, "{path} at t = {}: {d:e}", x.t);
        }
    }
}
