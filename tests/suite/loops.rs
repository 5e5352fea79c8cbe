//! Closed loops (docs/method.md §11), checked against closed forms and by independent routes:
//!
//! - the loop terms h, J, c of the generated code against the numeric reference (its own pose
//!   and motion recursions), and J and c against finite differences of h;
//! - the slider-crank driven at constant crank speed: the piston at
//!   x = r cos θ + √(l² − r² sin² θ) (the textbook kinematics of the in-line slider-crank);
//! - the four-bar: energy balance (kinetic + potential − the motor's work constant);
//! - generated and numeric trajectories of the loop models coincide.

use crate::common;

use camchain::runtime::{Dynamics, Simulate, Trajectory};
use camchain_models as models;
use camchain_reference::NumericModel;
use std::path::Path;

fn numeric(name: &str) -> NumericModel {
    let path = format!("{}/models/{name}.ron", env!("CARGO_MANIFEST_DIR"));
    NumericModel::load(Path::new(&path)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn run(model: &dyn Dynamics) -> Trajectory {
    let state = model
        .assemble(0.0)
        .unwrap_or_else(|e| panic!("assembles: {e}"));
    let settings = model.info().defaults.clone();
    model
        .simulate(state, &settings)
        .unwrap_or_else(|f| panic!("{}", f.error))
}

/// `n_four_bar`'s gaps are parallelograms' pairs of equal links, formed as (K7) of
/// docs/method.md §11.4; the others' are plain differences with the anchors folded.
const LOOP_MODELS: [&str; 6] = [
    "four_bar",
    "slider_crank",
    "andrews_squeezer",
    "bricard",
    "cam_rocker_linkage",
    "n_four_bar",
];

/// h at q, for finite differences.
fn h_at(model: &dyn Dynamics, q: &[f64]) -> Vec<f64> {
    let mut h = vec![0.0; model.info().n_constraints()];
    model.constraint(q, &mut h);
    h
}

#[test]
fn loop_jacobian_and_bias_match_finite_differences_of_h() {
    // Central differences with step 1e-5 have truncation error ~ε²|h‴| ≈ 1e-10 and round-off
    // ~1e-16/1e-5 = 1e-11 for lengths of order 0.1 m; the second difference for c (J q̇ along
    // the path q + s q̇) has truncation ~1e-10 and round-off ~1e-16/1e-10 = 1e-6: 1e-6 on J
    // and 1e-4 on c (relative to max(1, |value|)) leave a margin of 100.
    for name in LOOP_MODELS {
        let model = models::by_name(name).expect("built in");
        let (n, m) = (model.info().n(), model.info().n_constraints());
        let mut rng = common::Rng::new(41);
        for _ in 0..20 {
            let q = rng.vec(n, -1.5, 1.5);
            let qd = rng.vec(n, -2.0, 2.0);
            let mut j = vec![0.0; m * n];
            model.constraint_jacobian(&q, &mut j);
            let mut c = vec![0.0; m];
            model.constraint_bias(&q, &qd, &mut c);
            let eps = 1e-5;
            for i in 0..n {
                let (mut plus, mut minus) = (q.clone(), q.clone());
                plus[i] += eps;
                minus[i] -= eps;
                let (hp, hm) = (h_at(model, &plus), h_at(model, &minus));
                let column: Vec<f64> = (0..m).map(|k| (hp[k] - hm[k]) / (2.0 * eps)).collect();
                let ours: Vec<f64> = (0..m).map(|k| j[k * n + i]).collect();
                common::assert_close(&ours, &column, 1e-6, &format!("{name}: J column {i}"));
            }
            // c = d²h/ds² along q + s q̇ at s = 0.
            let s = 1e-4;
            let along = |k: f64| -> Vec<f64> {
                let p: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + k * s * b).collect();
                h_at(model, &p)
            };
            let (hp, h0, hm) = (along(1.0), along(0.0), along(-1.0));
            let second: Vec<f64> = (0..m)
                .map(|k| (hp[k] - 2.0 * h0[k] + hm[k]) / (s * s))
                .collect();
            common::assert_close(&c, &second, 1e-4, &format!("{name}: c"));
        }
    }
}

#[test]
fn loop_models_agree_with_the_numeric_reference() {
    // Both evaluate the same formulas by different recursions: round-off only (1e-12
    // relative is ~10⁴ ε).
    for name in LOOP_MODELS {
        let generated = models::by_name(name).expect("built in");
        let worst = common::compare_dynamics(name, generated, &numeric(name), 1e-12);
        println!("{name}: generated vs numeric {worst:.2e}");
    }
}

#[test]
fn slider_crank_piston_follows_the_closed_form() {
    // Newton (15) leaves |h| ≤ 1e-12 m before its polishing step and the integration has no
    // free coordinate to drift: every sample's piston is where the kinematics put it. 1e-10 m
    // is the bound, 100 times the solve's tolerance.
    let model = models::by_name("slider_crank").expect("built in");
    let trajectory = run(model);
    let (r, l) = (0.05_f64, 0.2_f64);
    let mut worst: f64 = 0.0;
    for s in &trajectory.samples {
        let theta = s.q[0];
        let x = r * theta.cos() + (l * l - (r * theta.sin()).powi(2)).sqrt();
        worst = worst.max((s.q[2] - x).abs());
    }
    println!("slider_crank: piston against r cos θ + √(l² − r² sin² θ): {worst:.2e} m");
    assert!(worst < 1e-10, "piston off the closed form by {worst:e} m");
    assert!(trajectory.samples.len() > 200);
}

#[test]
fn four_bar_energy_balances_the_motor_work() {
    // No damper: kinetic + potential − work of the motor torque is constant. DOP853 at
    // rtol 1e-10 over ~10³ steps accumulates ~1e-9 of the energy exchanged (the motor's
    // ~400 J over 2 s): 1e-8 of it leaves a margin of 10.
    let model = models::by_name("four_bar").expect("built in");
    let trajectory = run(model);
    let first = &trajectory.samples[0];
    let balance = |s: &camchain::runtime::Sample| s.energy.total() - s.driven_work;
    let mut worst: f64 = 0.0;
    for s in &trajectory.samples {
        worst = worst.max((balance(s) - balance(first)).abs());
        assert!(
            s.h.iter().all(|h| h.abs() < 1e-10),
            "loop open at t = {}",
            s.t
        );
    }
    let last = trajectory.samples.last().expect("samples");
    println!(
        "four_bar: energy balance drift {worst:.2e} J, motor work {:.3} J, {} re-partitions",
        last.driven_work, trajectory.stats.repartitions
    );
    let scale = last.driven_work.abs() + balance(first).abs();
    assert!(
        worst < 1e-8 * scale,
        "energy balance drifts by {worst:e} J of {scale} J"
    );
}

fn loop_model(file: &str, overrides: &[(&str, f64)]) -> NumericModel {
    let path = format!("{}/tests/loop_models/{file}", env!("CARGO_MANIFEST_DIR"));
    let overrides: Vec<(String, f64)> =
        overrides.iter().map(|(n, v)| (n.to_string(), *v)).collect();
    NumericModel::load_with(
        Path::new(&path),
        &overrides,
        camchain_codegen::model::ParameterMode::AsDeclared,
    )
    .unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// The largest |q_k(t) − θ(t)| over the samples of a linkage and of its pendulum.
fn largest_difference(linkage: &Trajectory, pendulum: &Trajectory, k: usize) -> f64 {
    assert_eq!(linkage.samples.len(), pendulum.samples.len());
    linkage
        .samples
        .iter()
        .zip(&pendulum.samples)
        .map(|(a, b)| {
            assert_eq!(a.t, b.t);
            (a.q[k] - b.q[0]).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_parallelogram_swings_like_its_equivalent_pendulum() {
    // The parallelogram (3 coordinates, 2 loop equations) and the one-body pendulum with the
    // same kinetic and potential energy as functions of the crank angle (pendulum.ron) obey
    // the same equation of motion. Both at DOP853 rtol 1e-12 for 3 s (~1.3 periods): each
    // run is within ~1e-11 of the exact motion, so 1e-9 rad (the bound) leaves a
    // margin of 10 or more.
    let linkage = run(&loop_model("parallelogram.ron", &[]));
    let pendulum = run(&loop_model("pendulum.ron", &[]));
    let worst = largest_difference(&linkage, &pendulum, 0);
    println!("parallelogram against its pendulum: {worst:.2e} rad");
    assert!(worst < 1e-9, "the crank angle differs by {worst:e} rad");
    // The coupler does not turn (q1 + q2 = 0) and the rocker stays parallel (q3 = q1).
    for s in &linkage.samples {
        assert!((s.q[0] + s.q[1]).abs() < 1e-10 && (s.q[2] - s.q[0]).abs() < 1e-10);
    }
}

#[test]
fn a_redundant_bar_is_detected_and_the_motion_is_unchanged() {
    // braced.ron adds a third crank: 4 loop equations, 4 coordinates, 1 degree of freedom.
    // Assembly finds the Jacobian's rank 3, leaves one equation out (reported) and the run
    // must be the pendulum's with the third crank's mass and inertia added, to 1e-9 rad;
    // the equation left out must hold all along (it is implied by the others).
    let braced = loop_model("braced.ron", &[]);
    let (_, report) = braced.assemble_reported(0.0).expect("assembles");
    assert_eq!(
        report.redundant.len(),
        1,
        "redundant rows: {:?}",
        report.redundant
    );
    let linkage = run(&braced);
    let pendulum = run(&loop_model("pendulum.ron", &[("m4", 0.7)]));
    let worst = largest_difference(&linkage, &pendulum, 0);
    println!(
        "braced parallelogram ({} left out) against its pendulum: {worst:.2e} rad",
        report.redundant[0]
    );
    assert!(worst < 1e-9, "the crank angle differs by {worst:e} rad");
    let max_h = linkage
        .samples
        .iter()
        .flat_map(|s| s.h.iter())
        .fold(0.0_f64, |m, h| m.max(h.abs()));
    assert!(max_h < 1e-10, "a loop equation opened to {max_h:e} m");
    // The reactions: the left-out row's multiplier is 0, and together the others balance
    // the coupler (checked through the equations of motion by the runtime's own test of
    // the multipliers); here only that every reaction is finite.
    assert!(
        linkage
            .samples
            .iter()
            .all(|s| s.lambda.iter().all(|l| l.is_finite()))
    );
}

#[test]
fn the_n_four_bar_passes_its_singular_positions_like_its_pendulum() {
    // IFToMM A02 (N = 40, 81 links, 80 loop equations): every crank keeps the angle of the
    // first, and the first moves like the pendulum with 41 cranks and 40 couplers
    // (pendulum.ron: links of 1 m, m1 = 41, m2 = 40), started vertical at −1 rad/s. Over 20 s it passes
    // the horizontal singular positions (where the mechanism has 41 degrees of freedom)
    // 20 times. The linkage at the model's rtol 1e-9, the pendulum at 1e-13 as the
    // reference. The crank turns through ~90 rad in 20 s and the phase error of a run at
    // rtol 1e-9 grows along it: 8.1e-7 rad measured (1.2e-5 before the loop gap's form (K7)
    // and J evaluated again near the singular positions, docs/method.md §11.4), 1e-5 rad
    // asserted.
    let model = models::by_name("n_four_bar").expect("built in");
    let settings = model.info().defaults.clone();
    let state = model.assemble(0.0).expect("assembles");
    let linkage = model
        .simulate(state, &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let pendulum = loop_model(
        "pendulum.ron",
        &[
            ("a", 1.0),
            ("m1", 41.0),
            ("m2", 40.0),
            ("m3", 0.0),
            ("theta0", std::f64::consts::FRAC_PI_2),
            ("omega0", -1.0),
        ],
    );
    let state = pendulum.assemble(0.0).expect("assembles");
    let mut tight = settings.clone();
    (tight.rtol, tight.atol) = (1e-13, 1e-15);
    let reference = pendulum
        .simulate(state, &tight)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let worst = largest_difference(&linkage, &reference, 0);
    let info = model.info();
    let mut parallel: f64 = 0.0;
    let mut crossings = 0;
    for pair in linkage.samples.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.q[0].sin().signum() != b.q[0].sin().signum() {
            crossings += 1;
        }
        for (i, c) in info.coordinates.iter().enumerate() {
            if c.name.starts_with('c') {
                parallel = parallel.max((b.q[i] - b.q[0]).abs());
            }
        }
    }
    println!(
        "n_four_bar: crank 0 against its pendulum {worst:.2e} rad, cranks parallel to {parallel:.2e} rad, {crossings} singular positions passed, {} re-partitions",
        linkage.stats.repartitions
    );
    assert!(
        crossings >= 10,
        "only {crossings} horizontal positions passed"
    );
    assert!(worst < 1e-5, "crank 0 off its pendulum by {worst:e} rad");
    assert!(
        parallel < 1e-9,
        "the cranks drift apart by {parallel:e} rad"
    );
}

#[test]
fn the_two_four_bar_assembly_matches_exudyns_published_runs() {
    // A secondary, external check: Exudyn's A02 test model (J. Gerstmayr et al., EXUDYN,
    // `TestModels/fourBarMechanismIftomm.py`, N = 2, generalized-α) records the point B0 at
    // t = 10 s for steps 1e-3 … 1.25e-4 (x = 0.3284112372, 0.3284465114, 0.3284552113,
    // 0.3284573768; y = 0.9445348375, 0.9445225721, 0.9445195467, 0.9445187937), converging
    // at second order towards x ≈ 0.3284581, y ≈ 0.9445185 (Richardson). Our run at rtol
    // 1e-9 is far more accurate than those steps, so it must land within the last step's
    // distance from the extrapolated value: 2e-6.
    let model = loop_model("n_four_bar_2.ron", &[]);
    let mut settings = model.info().defaults.clone();
    settings.dt_out = 10.0;
    let state = model.assemble(0.0).expect("assembles");
    let run = model
        .simulate(state, &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let last = run.samples.last().expect("t = 10");
    let (x, y) = (last.q[0].cos(), last.q[0].sin());
    let (x_ref, y_ref) = (
        0.3284573768 + (0.3284573768 - 0.3284552113) / 3.0,
        0.9445187937 + (0.9445187937 - 0.9445195467) / 3.0,
    );
    println!(
        "n_four_bar_2: B0 at t = 10 s ({x:.10}, {y:.10}), Exudyn extrapolated ({x_ref:.10}, {y_ref:.10})"
    );
    assert!((x - x_ref).abs() < 2e-6 && (y - y_ref).abs() < 2e-6);
}

#[test]
fn bricard_keeps_its_energy_and_its_redundant_loop_closed() {
    // IFToMM A04: no damper, no load: kinetic + potential constant. DOP853 at rtol 1e-10
    // over 10 s keeps it to ~1e-9 of the energy exchanged (~10 J): 1e-7 J. The cut at F is 5
    // equations of rank 4: assembly leaves one out, and it must stay closed with the others
    // (1e-10 m, Newton's tolerance ×100). Generated and numeric runs agree to the
    // integration tolerance's growth over 10 s (1e-6 rad).
    let model = models::by_name("bricard").expect("built in");
    let (_, report) = model.assemble_reported(0.0).expect("assembles");
    assert_eq!(report.redundant.len(), 1, "{:?}", report.redundant);
    let generated = run(model);
    let reference = run(&numeric("bricard"));
    let first = generated.samples[0].energy.total();
    let mut drift: f64 = 0.0;
    for (a, b) in generated.samples.iter().zip(&reference.samples) {
        drift = drift.max((a.energy.total() - first).abs());
        assert!(
            a.h.iter().all(|h| h.abs() < 1e-10),
            "loop open at t = {}",
            a.t
        );
        common::assert_close(&a.q, &b.q, 1e-6, &format!("bricard q at t = {}", a.t));
    }
    let last = generated.samples.last().expect("t = 10");
    let info = model.info();
    let p3 = info.coordinate_index("qA").expect("qA");
    println!(
        "bricard: {} left out, energy drift {drift:.2e} J over 10 s, qA(10) = {:.9}",
        report.redundant[0], last.q[p3]
    );
    assert!(drift < 1e-7, "energy drifts by {drift:e} J");
}

#[test]
fn the_cam_driven_four_bar_closes_where_the_circles_meet() {
    // cam_rocker_linkage: the contact sets the rocker's swing, the loop the lever's angle.
    // Independently of the solver: from each sample's swing the coupler pin P is on the
    // rocker's crank, and the lever's tip is where the circles |B − P| = coupler and
    // |B − Q| = lever meet (the one right of Q). Newton leaves the pin within 1e-12 m,
    // 1.3e-11 rad over the lever's 80 mm: 1e-10 rad leaves a margin of 8.
    let model = models::by_name("cam_rocker_linkage").expect("built in");
    let trajectory = run(model);
    let info = model.info();
    let (swing, lever) = (
        info.coordinate_index("swing").expect("swing"),
        info.coordinate_index("lever_angle").expect("lever"),
    );
    let (pivot, q_pivot) = ([0.09, 0.045], [0.06, -0.075]);
    let (crank, coupler, lever_length) = (0.05_f64, 0.12_f64, 0.08_f64);
    let mut worst: f64 = 0.0;
    for s in &trajectory.samples {
        let p = [
            pivot[0] + crank * s.q[swing].cos(),
            pivot[1] + crank * s.q[swing].sin(),
        ];
        let (dx, dy) = (q_pivot[0] - p[0], q_pivot[1] - p[1]);
        let d = dx.hypot(dy);
        let along = (coupler * coupler - lever_length * lever_length + d * d) / (2.0 * d);
        let across = (coupler * coupler - along * along).sqrt();
        let base = [p[0] + along * dx / d, p[1] + along * dy / d];
        // The two meeting points; the lever's tip is the one on the right of Q.
        let candidates = [1.0, -1.0].map(|side: f64| {
            [
                base[0] - side * across * dy / d,
                base[1] + side * across * dx / d,
            ]
        });
        let tip = candidates
            .into_iter()
            .max_by(|a, b| a[0].total_cmp(&b[0]))
            .expect("two points");
        let angle = (tip[1] - q_pivot[1]).atan2(tip[0] - q_pivot[0]);
        worst = worst.max((angle - s.q[lever]).abs());
    }
    println!("cam_rocker_linkage: lever angle against the circles' intersection {worst:.2e} rad");
    assert!(worst < 1e-10, "the lever is off by {worst:e} rad");
}

#[test]
fn the_n_four_bars_reduced_acceleration_is_its_pendulums() {
    // At a consistent state of the linkage (every crank at θ, every coupler translating:
    // p = −θ, ṗ = −θ̇) every crank's acceleration is the pendulum's, θ̈ = −(g M r / I) cos θ
    // with I = 41/3 + 40 kg m² and M r = 41/2 + 40 kg m (pendulum.ron's formulas), for any θ̇
    // (I does not depend on θ: no velocity term). This exercises the whole right-hand side
    // of 80 loop rows (Newton, the band LU of J_v, B and b, M T) against the closed
    // form. Measured 1.7e-13 rad/s² (round-off of the 80-row solves); 1e-10 of the ~11 rad/s²
    // leaves a margin of 6e3, and also covers states 0.05 rad from the singular positions,
    // where these exactly symmetric states keep the round-off from growing (docs/method.md
    // §11.4).
    let model = models::by_name("n_four_bar").expect("built in");
    let info = model.info();
    let gain = 9.81 * (41.0 / 2.0 + 40.0) / (41.0 / 3.0 + 40.0);
    let mut state = model.assemble(0.0).expect("assembles");
    let mut worst: f64 = 0.0;
    for (theta, omega) in [
        (1.3, -1.0),
        (0.05, -4.6),
        (-2.0, -6.0),
        (3.1, -3.0),
        (-7.0, 2.0),
    ] {
        for (i, c) in info.coordinates.iter().enumerate() {
            let crank = c.name.starts_with('c');
            state.q[i] = if crank { theta } else { -theta };
            state.qd[i] = if crank { omega } else { -omega };
        }
        let mut dy = vec![0.0; state.integrated_len()];
        model.derivative(&mut state, &mut dy).expect("evaluates");
        // y = (u, u̇, …), u one crank's angle (the partition's choice: the last one's).
        let &[u] = state.independent() else {
            panic!("one independent coordinate, got {:?}", state.independent())
        };
        assert!(info.coordinates[u].name.starts_with('c'));
        let exact = -gain * theta.cos();
        worst = worst.max((dy[1] - exact).abs());
    }
    println!("n_four_bar: reduced acceleration against the pendulum's {worst:.2e} rad/s²");
    assert!(worst < 1e-10 * gain, "off by {worst:e} rad/s²");
}
