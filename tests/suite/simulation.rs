//! Simulations of the generated models: the constraint holds along whole runs, the
//! partitioned accelerations equal those of the full Lagrange-multiplier system, energy
//! balances, and the paper's contrast between the cams shows.

use crate::common;

use camchain::runtime::{Dynamics, Sample, SimSettings, Simulate, Trajectory};
use camchain_models as models;
use nalgebra::{DMatrix, DVector};

fn run(model: &dyn Dynamics, settings: &SimSettings) -> Trajectory {
    let state = model
        .assemble(0.0)
        .unwrap_or_else(|e| panic!("assembly: {e}"));
    model
        .simulate(state, settings)
        .unwrap_or_else(|f| panic!("simulation: {}", f.error))
}

fn run_default(name: &str) -> (Trajectory, &'static (dyn Dynamics + Sync)) {
    let model = models::by_name(name).unwrap_or_else(|| panic!("{name} is built in"));
    (run(model, &model.info().defaults), model)
}

fn max_abs(t: &Trajectory, f: impl Fn(&Sample) -> f64) -> f64 {
    t.samples.iter().map(|s| f(s).abs()).fold(0.0, f64::max)
}

/// q̈ and λ from the full system [M Jᵀ; J 0] [q̈; λ] = [−F − Q + τ; −c], with the drive
/// loads τ on prescribed coordinates replaced by their known accelerations.
fn full_system(model: &dyn Dynamics, s: &Sample) -> (Vec<f64>, Vec<f64>) {
    let info = model.info();
    let (n, nc) = (info.n(), info.n_constraints());
    let (mut m, mut f, mut qa) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    model.equations(s.t, &s.q, &s.qd, &mut m, &mut f, &mut qa);
    let (mut j, mut c) = (vec![0.0; nc * n], vec![0.0; nc]);
    model.constraint_terms(&s.q, &s.qd, &mut j, &mut c);
    let (mut pq, mut pv, mut pa) = (s.q.clone(), s.qd.clone(), vec![0.0; n]);
    model.prescribed(s.t, &mut pq, &mut pv, &mut pa);
    let size = n + nc;
    let mut a = DMatrix::zeros(size, size);
    let mut b = DVector::zeros(size);
    for i in 0..n {
        if info.coordinates[i].driven {
            a[(i, i)] = 1.0;
            b[i] = pa[i];
            continue;
        }
        for k in 0..n {
            a[(i, k)] = m[i * n + k];
        }
        for r in 0..nc {
            a[(i, n + r)] = j[r * n + i];
        }
        b[i] = -f[i] - qa[i];
    }
    for r in 0..nc {
        for k in 0..n {
            a[(n + r, k)] = j[r * n + k];
        }
        b[n + r] = -c[r];
    }
    let x = a.lu().solve(&b).expect("the full system is regular");
    (
        x.rows(0, n).iter().copied().collect(),
        x.rows(n, nc).iter().copied().collect(),
    )
}

#[test]
fn paper_trajectories_keep_the_constraint_and_match_the_full_system() {
    for name in [
        "paper_concave",
        "paper_convex",
        "paper_convex_text",
        "driven_concave",
        "driven_convex",
    ] {
        let (t, model) = run_default(name);
        let n = model.info().n();
        let end = t.samples.last().map_or(0.0, |s| s.t);
        assert!(
            (end - model.info().defaults.t_end).abs() < 1e-12,
            "{name} reaches t_end"
        );
        for s in &t.samples {
            // Newton solves h to 1e-12 and v̇ exactly from J q̇ = 0 at every right-hand side:
            // the bound 1e-10 leaves two orders for rounding.
            assert!(s.h[0].abs() < 1e-10, "{name} t={}: h = {:e}", s.t, s.h[0]);
            let mut j = vec![0.0; n];
            model.constraint_jacobian(&s.q, &mut j);
            let jqd: f64 = j.iter().zip(&s.qd).map(|(a, b)| a * b).sum();
            assert!(jqd.abs() < 1e-10, "{name} t={}: J q̇ = {jqd:e}", s.t);
        }
        for s in t.samples.iter().step_by(50) {
            let (qdd, lambda) = full_system(model, s);
            // Two exact eliminations of the same regular system (partitioned Cholesky vs LU
            // of the bordered matrix); condition numbers ~1e3 here: 1e-9 relative.
            common::assert_close(&s.qdd, &qdd, 1e-9, &format!("{name} t={} q̈", s.t));
            common::assert_close(&s.lambda, &lambda, 1e-9, &format!("{name} t={} λ", s.t));
        }
    }
}

#[test]
fn energy_plus_dissipation_minus_drive_work_is_constant() {
    for name in [
        "paper_concave",
        "paper_convex",
        "driven_concave",
        "driven_convex",
    ] {
        let (t, _) = run_default(name);
        let balance = |s: &Sample| s.energy.total() + s.dissipated - s.driven_work;
        let first = balance(&t.samples[0]);
        let scale = t
            .samples
            .iter()
            .map(|s| s.energy.total().abs() + s.dissipated.abs())
            .fold(1.0, f64::max);
        let drift = max_abs(&t, |s| balance(s) - first);
        // Dormand–Prince at rtol 1e-10 over ~10 s: the energy error grows like the state
        // error, ~1e-8 of the energy scale; 1e-6 relative leaves margin and would still
        // catch a missing term (a wrong damper or drive power shows at the 1e-2 level).
        assert!(
            drift < 1e-6 * scale,
            "{name}: energy balance drifts by {drift:e} (scale {scale})"
        );
    }
}

#[test]
fn double_pendulum_without_dampers_conserves_energy() {
    let (t, _) = run_default("double_pendulum");
    let e0 = t.samples[0].energy.total();
    let drift = max_abs(&t, |s| s.energy.total() - e0);
    // No contact, no damper: the total energy (about 5 J) is invariant; Dormand–Prince at
    // the model's tolerance keeps it to 2e-10 J over 10 s (measured); 1e-8 J is the bound.
    assert!(drift < 1e-8, "energy drift {drift:e} J");
}

#[test]
fn the_paper_contrast_shows_joint_4_bends_on_the_convex_cam_only() {
    let q4 = |name: &str| {
        let (t, model) = run_default(name);
        let i = model.info().coordinate_index("q4").expect("q4");
        (max_abs(&t, |s| s.q[i]), t)
    };
    let (concave, tc) = q4("paper_concave");
    let (convex, tv) = q4("paper_convex");
    // docs/method.md §7.5: concave about 0.015 rad, convex about 0.16 rad.
    assert!(concave < 0.05, "concave max |q4| = {concave}");
    assert!(convex > 0.08, "convex max |q4| = {convex}");
    assert!(convex > 5.0 * concave, "contrast {convex} vs {concave}");
    for t in [&tc, &tv] {
        assert!(
            t.samples.iter().all(|s| s.normal_force[0] > 0.0),
            "the contact stays compressive"
        );
    }
    let (dc, _) = {
        let (t, m) = run_default("driven_concave");
        let i = m.info().coordinate_index("q4").expect("q4");
        (max_abs(&t, |s| s.q[i]), ())
    };
    let (dv, _) = {
        let (t, m) = run_default("driven_convex");
        let i = m.info().coordinate_index("q4").expect("q4");
        (max_abs(&t, |s| s.q[i]), ())
    };
    assert!(
        dc < 0.01 && dv > 3.0 * dc,
        "driven: concave {dc}, convex {dv}"
    );
}

#[test]
fn stepping_the_generated_model_follows_the_simulated_trajectory() {
    use camchain_models::paper_convex::Model;
    let model = Model::default();
    let mut state = model.assemble().expect("assembles");
    let mut settings = model.default_settings();
    settings.t_end = 1.0;
    settings.dt_out = 0.1;
    let reference = model
        .simulate(model.assemble().expect("assembles"), &settings)
        .expect("runs");
    for sample in reference.samples.iter().skip(1) {
        model.step(&mut state, 0.1).expect("steps");
        assert!((state.t - sample.t).abs() < 1e-12);
        // Both advance with the same integrator and tolerances to the same output times;
        // the step sequences may differ slightly (step() starts each call afresh), so the
        // states agree to the integration tolerance (rtol 1e-10) times error growth: 1e-7.
        common::assert_close(&state.q, &sample.q, 1e-7, &format!("q at t={}", sample.t));
    }
}
