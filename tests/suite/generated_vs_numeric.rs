//! Generated code against the numeric recursive reference, for every built-in model, at
//! 100 random states each: M, F, Q, h, J, c, the contact kinematics, the energies and the
//! prescribed motions.
//!
//! The two routes share only the model file: the generated code comes from symbolic
//! expressions in body frames (forward/backward recursion, symbolic differentiation of the
//! profile); the reference runs the recursions numerically with nalgebra, builds M column
//! by column from unit accelerations, J from the geometric point Jacobian, and f3', f3''
//! by forward-mode automatic differentiation.

use crate::common;

use camchain::runtime::{Dynamics, Simulate};
use camchain_models as models;
use camchain_reference::NumericModel;
use common::{Rng, compare_dynamics, max_rel_diff};

/// Relative agreement demanded, against max(1, |value|) of the reference. Both routes
/// evaluate the same physics in double precision with different operation orders; for
/// these O(1)-conditioned chains of ≤ 5 bodies the rounding differences stay within
/// ~1e-14·(number of terms); 1e-12 leaves two orders of margin and still catches any
/// wrong term (the smallest physical term, e.g. a 0.01 kg·m² inertia times a rate of 1e-2,
/// is ~1e-4).
const TOL: f64 = 1e-12;

#[test]
fn every_generated_model_agrees_with_the_numeric_recursion() {
    assert!(
        models::ALL.len() >= 7,
        "the five paper models, the double pendulum, the spatial arm"
    );
    for (name, generated) in models::ALL.iter() {
        let path = format!("{}/models/{name}.ron", env!("CARGO_MANIFEST_DIR"));
        let numeric = NumericModel::load(std::path::Path::new(&path))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let tol = common::for_tables(&numeric, TOL);
        let worst = compare_dynamics(name, *generated, &numeric, tol);
        println!("{name}: largest relative difference generated vs numeric {worst:.2e}");
    }
}

#[test]
fn generated_and_numeric_trajectories_coincide() {
    for name in [
        "paper_concave",
        "driven_convex",
        "spatial_arm",
        "paper_rotating",
        "rocker_roller",
        "eccentric_flat",
    ] {
        let generated = models::by_name(name).expect("built in");
        let path = format!("{}/models/{name}.ron", env!("CARGO_MANIFEST_DIR"));
        let numeric = NumericModel::load(std::path::Path::new(&path)).expect("loads");
        let mut settings = generated.info().defaults.clone();
        settings.t_end = settings.t_end.min(3.0);
        let run = |m: &dyn Dynamics| {
            let state = m.assemble(0.0).expect("assembles");
            m.simulate(state, &settings)
                .unwrap_or_else(|f| panic!("{}", f.error))
        };
        let (a, b) = (run(generated), run(&numeric));
        assert_eq!(a.samples.len(), b.samples.len());
        let mut worst: f64 = 0.0;
        for (x, y) in a.samples.iter().zip(&b.samples) {
            // The right-hand sides agree to ~1e-14 (test above); the adaptive integrator may
            // then take marginally different steps, so the trajectories differ at the level
            // of the integration tolerance (rtol 1e-9..1e-10) times the error growth over 3 s.
            common::assert_close(&x.q, &y.q, 1e-7, &format!("{name} q at t={}", x.t));
            common::assert_close(
                &x.normal_force,
                &y.normal_force,
                1e-6,
                &format!("{name} N at t={}", x.t),
            );
            worst = worst.max(max_rel_diff(&x.q, &y.q));
        }
        println!("{name}: generated vs numeric trajectory, largest difference in q {worst:.2e}");
    }
}

#[test]
fn generated_mass_matrices_are_spd_and_match_the_kinetic_energy() {
    for (name, model) in models::ALL.iter() {
        let n = model.info().n();
        let mut rng = Rng::new(99);
        for _ in 0..100 {
            let q = rng.vec(n, -1.5, 1.5);
            let qd = rng.vec(n, -2.0, 2.0);
            let mut m = vec![0.0; n * n];
            model.mass_matrix(&q, &mut m);
            let mat = nalgebra::DMatrix::from_row_slice(n, n, &m);
            // Symmetric up to the association of sums (both triangles come from one row
            // each of the recursion): 1e-13 relative.
            assert!(
                (&mat - mat.transpose()).amax() <= 1e-13 * mat.amax(),
                "{name}: M symmetric"
            );
            assert!(
                mat.clone().cholesky().is_some(),
                "{name}: M positive definite"
            );
            let v = nalgebra::DVector::from_column_slice(&qd);
            let quad = 0.5 * v.dot(&(&mat * &v));
            let kinetic = model.energy(&q, &qd).kinetic;
            // Body-velocity sum against the quadratic form: different sums of the same
            // terms, 1e-12 relative.
            assert!(
                (quad - kinetic).abs() <= 1e-12 * kinetic.max(1.0),
                "{name}: {quad} vs {kinetic}"
            );
        }
    }
}
