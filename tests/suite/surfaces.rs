//! Cam surfaces z = f(x, y) (docs/method.md §13) against closed forms and the planar
//! contact they generalise:
//!
//! - planar equivalence: the paper's concave scenario with its cam written as a surface that
//!   does not depend on y (`tests/contact_models/paper_on_surface.ron`) reproduces
//!   `paper_concave` (generated code both);
//! - a particle on the paraboloid z = c (x² + y²) (`models/paraboloid_orbit.ron`) started on
//!   the circular orbit at ω = √(2 c g): radius, height, angular momentum and energy, against
//!   that closed form, over ten revolutions;
//! - a barrel cam designed from a cycloidal program (`models/barrel_indexer.ron`) moves its
//!   roller follower exactly by the law, at the pressure angle atan(S′/R), and one-sided it
//!   lifts off the groove's flank at the jump speed and angle of the law's closed form;
//! - generated against numeric for the surface models (beyond the 100 random states of
//!   `generated_vs_numeric.rs`): whole runs.

use crate::cycloidal::Cycloidal;
use crate::eccentric::file_parameters;
use camchain::runtime::events::EventKind;
use camchain::runtime::{Dynamics, SimSettings, Simulate};
use camchain_models as models;
use camchain_models::contact_models;
use camchain_reference::NumericModel;
use std::f64::consts::{PI, TAU};

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
pub(crate) fn orbit(m: &dyn Dynamics) -> Vec<camchain::runtime::Sample> {
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

/// barrel_indexer's follower and program, from its file: the same dwell 60°, cycloidal rise
/// over 120°, dwell 60°, cycloidal return over 120° as cycloidal_roller's, the roller's centre
/// at `base` + S(φ) along the axis. Its equation of motion along the axis,
/// m z̈ = N cos α − m g − k (z − free) − c ż (α the pressure angle), gives the sign of the
/// normal force as that of `Cycloidal::force` with R_b + ρ replaced by `base`.
fn barrel_law() -> Cycloidal {
    let p = file_parameters("barrel_indexer");
    Cycloidal {
        m: p("m"),
        g: p("g"),
        k: p("k"),
        c: p("c"),
        free: p("free"),
        base: p("base"),
        lift: p("h"),
    }
}

#[test]
fn the_barrel_cam_moves_its_follower_by_the_law() {
    let model = models::by_name("barrel_indexer").expect("built in");
    let p = file_parameters("barrel_indexer");
    let (omega, radius, lift) = (p("omega"), p("R"), p("h"));
    let cam = barrel_law();
    let settings = model.info().defaults.clone();
    let run = model
        .simulate(model.assemble(0.0).expect("assembles"), &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let lift_index = model
        .info()
        .coordinates
        .iter()
        .position(|c| c.name == "lift")
        .expect("lift");
    let [mut s_err, mut v_err, mut a_err, mut angle_err] = [0.0f64; 4];
    for sample in &run.samples {
        let phi = omega * sample.t;
        let (s, v, a) = cam.law(phi);
        s_err = s_err.max((sample.q[lift_index] - (cam.base + s)).abs() / lift);
        v_err = v_err.max((sample.qd[lift_index] - omega * v).abs() / (lift * omega));
        a_err =
            a_err.max((sample.qdd[lift_index] - omega * omega * a).abs() / (lift * omega * omega));
        // The normal of the developed pitch curve against the axis: atan(S′/R), unsigned
        // (the follower's direction is the cam's axis itself).
        let expected = (v / radius).atan().abs();
        angle_err = angle_err.max((sample.contacts[0].pressure_angle() - expected).abs());
    }
    println!(
        "barrel_indexer against its law over three turns: displacement {s_err:.1e}, velocity \
         {v_err:.1e}, acceleration {a_err:.1e} (of h, hω, hω²), pressure angle {angle_err:.1e} rad"
    );
    // The demands: the law to 1e-9 of the lift, the pressure angle to 1e-12 rad. The
    // follower has no freedom here (its coordinate is the dependent one, set by the
    // constraint to round-off each step), so the law holds to rounding, not to the tolerance.
    assert!(s_err < 1e-9 && v_err < 1e-9 && a_err < 1e-9);
    assert!(angle_err < 1e-12, "pressure angle {angle_err:e}");
    // The largest pressure angle, at the rise's and the return's middles: atan(2h/(βR)),
    // β = 120°. No sample exceeds it (beyond rounding), and the outputs, 0.01 rad of cam
    // angle apart, come within half a spacing of the peak, where the angle's curvature is
    // (dα/ds′)(2π)²h/β³ ≈ 13.6 · 0.129 ≈ 1.8 rad/rad²: 1.8/2 · 0.005² ≈ 2.2e-5 rad at most.
    let largest = run
        .samples
        .iter()
        .map(|s| s.contacts[0].pressure_angle())
        .fold(0.0, f64::max);
    let closed = (2.0 * lift / (TAU / 3.0) / radius).atan();
    assert!(largest <= closed + 1e-12, "{largest} above {closed}");
    assert!(closed - largest < 2.3e-5, "{largest} vs {closed}");
}

#[test]
fn the_barrel_follower_leaves_its_flank_at_the_jump_speed() {
    let cam = barrel_law();
    let (jump, _) = cam.jump_speed();
    println!("barrel_indexer: jump speed {jump:.6} rad/s (closed form)");
    for delta in [1e-3, -1e-3] {
        let omega = jump * (1.0 + delta);
        let model = models::barrel_indexer::Model::with(&[("omega", omega)]).expect("valid");
        let turns = 4;
        let settings = SimSettings {
            t_end: turns as f64 * TAU / omega,
            ..model.default_settings()
        };
        let state = Simulate::assemble(&model, 0.0).expect("assembly");
        let run = model
            .simulate_unilateral(state, &settings, 0.5)
            .unwrap_or_else(|f| panic!("δ = {delta}: {f}"));
        let lift_offs: Vec<f64> = run
            .events
            .iter()
            .filter(|e| e.kind == EventKind::LiftOff)
            .map(|e| (omega * e.t).rem_euclid(TAU))
            .collect();
        let (_, closed) = cam.least_and_lift_off(omega);
        match closed {
            None => assert!(lift_offs.is_empty(), "below the jump speed: {lift_offs:?}"),
            Some(down) => {
                // One lift-off per turn at least (after each, the follower lands again), the
                // first of each at the closed form's angle: located to 1e-9 s by the event
                // search on a run at rtol 1e-10 (as for the planar cams, unilateral.rs).
                assert!(lift_offs.len() >= turns, "{lift_offs:?}");
                let first = lift_offs[0];
                let off = (first - down + PI).rem_euclid(TAU) - PI;
                println!(
                    "  at ω_j (1 + {delta:e}): {} lift-offs, the first {off:.1e} rad from the \
                     closed form's angle {down:.6}",
                    lift_offs.len()
                );
                assert!(
                    off.abs() < 1e-6,
                    "lift-off at {first} rad, closed form {down}"
                );
            }
        }
    }
}

#[test]
fn a_bilateral_barrel_run_reports_each_flank_change_where_the_law_says() {
    // Above the jump speed the groove's upper flank must pull the follower down over part of
    // each turn: the bilateral normal force changes sign there, where the closed form
    // F(φ, ω) does, and the run reports each change as an event.
    let cam = barrel_law();
    let (jump, _) = cam.jump_speed();
    let omega = 1.3 * jump;
    let model = models::barrel_indexer::Model::with(&[("omega", omega)]).expect("valid");
    let settings = SimSettings {
        t_end: 2.0 * TAU / omega,
        ..model.default_settings()
    };
    let run = model
        .simulate(
            Simulate::assemble(&model, 0.0).expect("assembly"),
            &settings,
        )
        .unwrap_or_else(|f| panic!("{}", f.error));
    let changes: Vec<(EventKind, f64)> = run
        .events
        .iter()
        .map(|e| (e.kind, (omega * e.t).rem_euclid(TAU)))
        .collect();
    // As many changes per turn as the closed form has sign changes (sampled every 1e-4 rad),
    // alternating, the first to the upper flank (the run starts in a dwell, N > 0).
    let samples = (TAU / 1e-4) as usize;
    let per_turn = (0..samples)
        .filter(|&i| {
            let (a, b) = (i as f64 * 1e-4, (i + 1) as f64 * 1e-4);
            (cam.force(a, omega) > 0.0) != (cam.force(b, omega) > 0.0)
        })
        .count();
    assert!(per_turn >= 2, "no stretch on the upper flank at 1.3 ω_j");
    assert_eq!(changes.len(), 2 * per_turn, "{changes:?}");
    for (k, change) in changes.iter().enumerate() {
        let expected = if k % 2 == 0 {
            EventKind::ForceBecameNegative
        } else {
            EventKind::ForceBecamePositive
        };
        assert_eq!(change.0, expected, "change {k}");
    }
    println!(
        "barrel_indexer at 1.3 ω_j, bilateral: {} flank changes in two turns",
        changes.len()
    );
    for (kind, angle) in changes {
        // The closed form changes sign within 1e-6 rad of each reported angle (located to
        // 1e-9 s, ω·1e-9 ≈ 8e-8 rad), the way the event says.
        let (before, after) = (
            cam.force(angle - 1e-6, omega),
            cam.force(angle + 1e-6, omega),
        );
        let expected = match kind {
            EventKind::ForceBecameNegative => before > 0.0 && after < 0.0,
            EventKind::ForceBecamePositive => before < 0.0 && after > 0.0,
            EventKind::LiftOff | EventKind::Impact { .. } => false,
        };
        assert!(
            expected,
            "{kind:?} at {angle} rad: F {before:e} → {after:e}"
        );
    }
}

#[test]
fn a_particle_leaves_a_sphere_where_the_closed_form_says() {
    // tests/contact_models/sphere_slide.ron: the sphere of radius a as the surface of
    // revolution r = √(a² − z²), the particle started at rest θ₀ from the top. It leaves where
    // m g cos θ = m v²/a with v² = 2 g a (cos θ₀ − cos θ): cos θ* = (2/3) cos θ₀, on the
    // generated code and on the numeric reference alike.
    let generated = &*contact_models::sphere_slide::DEFAULT;
    let numeric = numeric("tests/contact_models/sphere_slide.ron");
    let (a, theta0) = (0.5, 0.1);
    let expected = 2.0 / 3.0 * f64::cos(theta0);
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
            .find(|e| e.kind == EventKind::LiftOff)
            .unwrap_or_else(|| panic!("{engine}: no lift-off in {:?}", run.events));
        let (x, z) = (lift_off.q[0], lift_off.q[2]);
        // The point is on the sphere there, and its height gives the angle: located to
        // 1e-9 s at a speed of ~1.8 m/s (2e-9 m); the force's zero itself to rtol 1e-10.
        let on_sphere = (x.hypot(z) - a).abs();
        let cos = z / a;
        println!(
            "sphere_slide ({engine}): leaves at cos θ = {cos:.12}, closed form {expected:.12} \
             ({:.1e}); t = {:.9} s",
            cos - expected,
            lift_off.t
        );
        assert!(on_sphere < 1e-12, "{engine}: {on_sphere:e} off the sphere");
        assert!(
            (cos - expected).abs() < 1e-8,
            "{engine}: cos θ* = {cos}, closed form {expected}"
        );
    }
}

#[test]
fn surface_models_run_alike_generated_and_numeric_and_keep_their_energy() {
    for (generated, path) in [
        (
            models::by_name("barrel_indexer").expect("built in") as &dyn Dynamics,
            "models/barrel_indexer.ron",
        ),
        (
            models::by_name("paraboloid_orbit").expect("built in") as &dyn Dynamics,
            "models/paraboloid_orbit.ron",
        ),
        (
            models::by_name("paper_surface").expect("built in") as &dyn Dynamics,
            "models/paper_surface.ron",
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
        // Energy balance: the kinetic and potential energy, plus what the dampers
        // dissipated, minus what the drives did, stays constant. The constraint forces do
        // no work on a fixed surface (the normal is orthogonal to the point's velocity) nor
        // on a turning barrel (their work on the camshaft is the drive's). At rtol 1e-10 the
        // integration error of a 2 s run is ~1e-10 of the energy scale; 1e-8 is the margin.
        let balance =
            |s: &camchain::runtime::Sample| s.energy.total() + s.dissipated - s.driven_work;
        let first = balance(&a.samples[0]);
        let scale = a
            .samples
            .iter()
            .map(|s| s.energy.kinetic.abs() + s.energy.gravity.abs() + s.energy.spring.abs())
            .fold(0.0, f64::max);
        let drift = a
            .samples
            .iter()
            .map(|s| (balance(s) - first).abs())
            .fold(0.0, f64::max);
        println!(
            "{path}: energy balance drift {:.1e} of the scale {scale:.3} J",
            drift / scale
        );
        assert!(drift < 1e-8 * scale, "{path}: energy drifts by {drift:e} J");
    }
}

#[test]
fn a_tapered_roller_moves_as_the_straight_one_and_leans_its_force_outward() {
    // tests/contact_models/barrel_tapered.ron is barrel_indexer with `tapered: true`: the same
    // motion, and each flank's force F = N/cos γ along cos γ n + sign(N) sin γ e_r, with
    // γ = atan(ρ/R) and e_r the outward radial direction at the roller, which is the ground's
    // x axis here (the follower's guide runs parallel to the camshaft at (R, 0)). At 80 rad/s,
    // above the spring's jump speed (59 rad/s), the upper flank drives the roller for part of
    // each turn (N < 0), so both flanks' leanings are met.
    let omega = [("omega", 80.0)];
    let straight = models::barrel_indexer::Model::with(&omega).expect("valid");
    let tapered = contact_models::barrel_tapered::Model::with(&omega).expect("valid");
    let path = format!(
        "{}/tests/contact_models/barrel_tapered.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).expect("the test model");
    let numeric = NumericModel::from_source_with(
        &text,
        std::path::Path::new(&path),
        &[("omega".to_string(), 80.0)],
        camchain_codegen::ParameterMode::AsDeclared,
    )
    .expect("valid");
    let p = file_parameters("barrel_indexer");
    let gamma = (p("rho") / p("R")).atan();
    assert_eq!(tapered.info().contacts[0].taper, gamma);
    let mut settings = straight.info().defaults.clone();
    settings.t_end = 0.7;
    let run = |m: &dyn Dynamics| {
        m.simulate(m.assemble(0.0).expect("assembles"), &settings)
            .unwrap_or_else(|f| panic!("{}", f.error))
    };
    let (a, b, c) = (run(&straight), run(&tapered), run(&numeric));
    let (mut motion, mut force, mut normal, mut apart) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut pulled = 0;
    for ((s, t), u) in a.samples.iter().zip(&b.samples).zip(&c.samples) {
        for (x, y) in s.q.iter().zip(&t.q) {
            motion = motion.max((x - y).abs());
        }
        let (n0, n1) = (s.normal_force[0], t.normal_force[0]);
        force = force.max((n1 - n0 / gamma.cos()).abs() / n0.abs().max(1.0));
        let side = if n0 < 0.0 { -1.0 } else { 1.0 };
        pulled += usize::from(n0 < 0.0);
        let (g0, g1) = (&s.contacts[0], &t.contacts[0]);
        let expected = [
            gamma.cos() * g0.normal[0] + side * gamma.sin(),
            gamma.cos() * g0.normal[1],
            gamma.cos() * g0.normal[2],
        ];
        // Independently of (T1): the cone's apex is on the camshaft's axis (the ground's z)
        // at the roller centre's height, and its normal at the contact point (reported on
        // the lower flank) is perpendicular to the generator from the apex, on the lower
        // flank's side (N > 0).
        if n0 > 0.0 {
            let generator = [
                g1.position[0],
                g1.position[1],
                g1.position[2] - g1.follower[2],
            ];
            let length = generator.iter().map(|v| v * v).sum::<f64>().sqrt();
            let cosine = (0..3).map(|k| generator[k] * g1.normal[k]).sum::<f64>() / length;
            // Products of lengths of 0.06 m with unit vectors: rounding ~1e-17.
            assert!(cosine.abs() < 1e-14, "normal off the cone's by {cosine:e}");
        }
        for (k, e) in expected.iter().enumerate() {
            normal = normal.max((g1.normal[k] - e).abs());
            apart = apart.max((u.contacts[0].normal[k] - g1.normal[k]).abs());
        }
        apart = apart.max((u.normal_force[0] - n1).abs() / n1.abs().max(1.0));
    }
    println!(
        "tapered barrel: motion {motion:.1e}, N/cos γ {force:.1e}, normal {normal:.1e}, \
         generated vs numeric {apart:.1e}; {pulled} samples on the upper flank"
    );
    assert!(
        pulled > 10,
        "the upper flank drives at {pulled} samples only"
    );
    // The same generated functions of the motion: identical runs (the taper changes outputs
    // only).
    assert_eq!(motion, 0.0, "the taper changed the motion");
    // One division and a few products of order-1 numbers.
    assert!(force < 1e-14, "N/cos γ to {force:e}");
    assert!(normal < 1e-15, "the leaning normal to {normal:e}");
    // Generated against numeric, both with their own radial direction: runs agreeing to
    // ~1e-10 at rtol 1e-10 (as surface_models_run_alike…).
    assert!(apart < 1e-8, "generated vs numeric {apart:e}");
}

#[test]
fn a_tapered_roller_that_could_move_radially_is_refused_at_the_start() {
    // barrel_tapered with its follower's guide tilted in the plane of the axis and the roller,
    // (0.6, 0, 0.8): the lift moves the roller outward at 0.6 m per m, which the flanks'
    // outward push would drive.
    let path = format!(
        "{}/tests/contact_models/barrel_tapered.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path)
        .expect("the test model")
        .replace(
            "axis: (0.0, 0.0, 1.0),\n                anchor: (\"R\", 0.0, 0.0),",
            "axis: (0.6, 0.0, 0.8),\n                anchor: (\"R\", 0.0, 0.0),",
        );
    assert!(
        text.contains("axis: (0.6, 0.0, 0.8)"),
        "the guide is tilted"
    );
    let m = NumericModel::from_source_with(
        &text,
        std::path::Path::new(&path),
        &[],
        camchain_codegen::ParameterMode::AsDeclared,
    )
    .expect("valid");
    let error = m
        .simulate(m.assemble(0.0).expect("assembles"), &m.info().defaults)
        .map(|_| ())
        .expect_err("refused")
        .error
        .to_string();
    assert!(
        error.contains("coordinate lift moves it towards or away from the cam's axis")
            && error.contains("∂r/∂lift = 6.000000e-1"),
        "{error}"
    );
}
