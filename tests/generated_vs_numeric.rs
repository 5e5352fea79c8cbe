//! Generated code against the numeric recursive reference, for every built-in model, at
//! 100 random states each: M, F, Q, h, J, c, the contact kinematics, the energies and the
//! prescribed motions.
//!
//! The two routes share only the model file: the generated code comes from symbolic
//! expressions in body frames (forward/backward recursion, symbolic differentiation of the
//! profile); the reference runs the recursions numerically with nalgebra, builds M column
//! by column from unit accelerations, J from the geometric point Jacobian, and f3', f3''
//! by forward-mode automatic differentiation.

mod common;

use camchain::models;
use camchain::runtime::reference::NumericModel;
use camchain::runtime::{Dynamics, Simulate};
use common::{Rng, max_rel_diff};
use std::cell::Cell;

/// Relative agreement demanded, against max(1, |value|) of the reference. Both routes
/// evaluate the same physics in double precision with different operation orders; for
/// these O(1)-conditioned chains of ≤ 5 bodies the rounding differences stay within
/// ~1e-14·(number of terms); 1e-12 leaves two orders of margin and still catches any
/// wrong term (the smallest physical term, e.g. a 0.01 kg·m² inertia times a rate of 1e-2,
/// is ~1e-4).
const TOL: f64 = 1e-12;

/// Asserts agreement within [`TOL`] and records the largest relative difference seen.
fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str, worst: &Cell<f64>) {
    common::assert_close(a, b, tol, what);
    worst.set(worst.get().max(max_rel_diff(a, b)));
}

/// Compares every function of the trait; returns the largest relative difference.
fn compare_model(name: &str, generated: &dyn Dynamics, numeric: &NumericModel) -> f64 {
    let worst = Cell::new(0.0);
    let n = generated.info().n();
    let nc = generated.info().n_contacts();
    assert_eq!(numeric.info().n(), n);
    let mut rng = Rng::new(name.len() as u64 * 7919 + 17);
    for _ in 0..100 {
        let q = rng.vec(n, -1.5, 1.5);
        let qd = rng.vec(n, -2.0, 2.0);
        let t = rng.uniform(0.0, 10.0);
        let both = |f: &dyn Fn(&dyn Dynamics) -> Vec<f64>| (f(generated), f(numeric));
        let (a, b) = both(&|m| {
            let mut out = vec![0.0; n * n];
            m.mass_matrix(&q, &mut out);
            out
        });
        assert_close(&a, &b, TOL, &format!("{name}: M"), &worst);
        let (a, b) = both(&|m| {
            let mut out = vec![0.0; n];
            m.inertial_forces(&q, &qd, &mut out);
            out
        });
        assert_close(&a, &b, TOL, &format!("{name}: F"), &worst);
        let (a, b) = both(&|m| {
            let mut out = vec![0.0; n];
            m.applied_forces(t, &q, &qd, &mut out);
            out
        });
        assert_close(&a, &b, TOL, &format!("{name}: Q"), &worst);
        let (a, b) = both(&|m| {
            let (mut mm, mut f, mut qa) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
            m.equations(t, &q, &qd, &mut mm, &mut f, &mut qa);
            [mm, f, qa].concat()
        });
        assert_close(
            &a,
            &b,
            TOL,
            &format!("{name}: equations (M, F, Q together)"),
            &worst,
        );
        let (a, b) = both(&|m| {
            let (mut h, mut j, mut c) = (vec![0.0; nc], vec![0.0; nc * n], vec![0.0; nc]);
            m.constraint(&q, &mut h);
            m.constraint_jacobian(&q, &mut j);
            m.constraint_bias(&q, &qd, &mut c);
            [h, j, c].concat()
        });
        assert_close(&a, &b, TOL, &format!("{name}: h, J, c"), &worst);
        let (a, b) = both(&|m| {
            let (mut j, mut c) = (vec![0.0; nc * n], vec![0.0; nc]);
            m.constraint_terms(&q, &qd, &mut j, &mut c);
            [j, c].concat()
        });
        assert_close(&a, &b, TOL, &format!("{name}: constraint_terms"), &worst);
        // The fused pair a right-hand side calls: the velocity level reads the cache the
        // position level filled (the numeric model's default ignores the cache).
        let (a, b) = both(&|m| {
            let (mut h, mut j) = (vec![0.0; nc], vec![0.0; nc * n]);
            let mut cache = vec![f64::NAN; m.cache_len()];
            m.position_terms(&q, &mut h, &mut j, &mut cache);
            let (mut mm, mut f, mut qa, mut c) =
                (vec![0.0; n * n], vec![0.0; n], vec![0.0; n], vec![0.0; nc]);
            let out = camchain::runtime::VelocityTerms {
                mass: &mut mm,
                inertial: &mut f,
                applied: &mut qa,
                bias: &mut c,
            };
            m.velocity_terms(t, &q, &qd, &cache, out);
            [h, j, mm, f, qa, c].concat()
        });
        assert_close(
            &a,
            &b,
            TOL,
            &format!("{name}: position_terms then velocity_terms"),
            &worst,
        );
        for k in 0..nc {
            let (a, b) = both(&|m| {
                let ck = m.contact_kinematics(&q, &qd, k);
                let g = ck.geometry;
                let mut v = vec![g.x, g.y, g.slope, g.curvature, ck.conv1, ck.conv2];
                v.extend(g.position);
                v.extend(ck.j1);
                v.extend(ck.j2);
                v
            });
            assert_close(
                &a,
                &b,
                TOL,
                &format!("{name}: contact {k} kinematics"),
                &worst,
            );
        }
        let (a, b) = both(&|m| {
            let e = m.energy(&q, &qd);
            vec![e.kinetic, e.gravity, e.spring, m.damper_power(&qd)]
        });
        assert_close(&a, &b, TOL, &format!("{name}: energies"), &worst);
        let (a, b) = both(&|m| {
            let (mut pq, mut pv, mut pa) = (q.clone(), qd.clone(), vec![0.0; n]);
            m.prescribed(t, &mut pq, &mut pv, &mut pa);
            [pq, pv, pa].concat()
        });
        assert_close(&a, &b, TOL, &format!("{name}: prescribed motion"), &worst);
    }
    worst.get()
}

#[test]
fn every_generated_model_agrees_with_the_numeric_recursion() {
    assert!(
        models::ALL.len() >= 7,
        "the five paper models, the double pendulum, the spatial arm"
    );
    for (name, generated) in models::ALL {
        let path = format!("{}/models/{name}.ron", env!("CARGO_MANIFEST_DIR"));
        let numeric = NumericModel::load(std::path::Path::new(&path))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let worst = compare_model(name, *generated, &numeric);
        println!("{name}: largest relative difference generated vs numeric {worst:.2e}");
    }
}

#[test]
fn generated_and_numeric_trajectories_coincide() {
    for name in ["paper_concave", "driven_convex", "spatial_arm"] {
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
    for (name, model) in models::ALL {
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
