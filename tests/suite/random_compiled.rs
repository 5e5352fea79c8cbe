//! The emitted Rust itself (not only the interpreter of `runtime/tests/random_models.rs`) on
//! random models: the fixed set `tests/random_models/*.ron`, drawn by that file's generator and
//! compiled by `build.rs` into `camchain_models::random_models` (feature `random-models`, on for this
//! package's tests), against the numeric reference loaded from the same files.
//!
//! The set: `random_planar` (5 bodies, planar, one cam in a rotated plane), `random_tree`
//! (8 bodies, spatial tree with prismatic joints, a driven joint and one cam in a tilted plane),
//! `random_two_cams` (4 bodies, spatial, two cams in tilted planes), `random_free` (5 bodies,
//! spatial, no cam); skew axes, full inertia tensors, springs and gravity throughout, bodies
//! written children first in some files. Regenerate them with
//! `cargo test -p camchain-reference --test suite random_models -- --ignored write_compiled_models`.
//! Compiling them adds ~8 s to a test-profile build of the library (mostly `random_two_cams`,
//! ~4100 generated lines), which is why they sit behind a feature instead of in `models/`.

use crate::common;

use camchain::runtime::{Dynamics, Simulate};
use camchain_models::random_models;
use camchain_reference::NumericModel;
use common::{compare_dynamics, max_rel_diff};
use std::path::Path;

/// Relative agreement demanded, against max(1, |value|) of the reference, as in
/// `generated_vs_numeric.rs`. These models are larger than the built-in ones (up to 8 bodies
/// of up to 10 kg, full inertia tensors and skew axes), so values reach ~1e2 and each is a sum
/// of more terms; the rounding differences measured stay below 3e-14 relative (printed by the
/// test), so 1e-12 leaves a factor of ~30 while catching any wrong term (the smallest
/// physical term is ~1e-4).
const TOL: f64 = 1e-12;

fn numeric(name: &str) -> NumericModel {
    let path = format!(
        "{}/tests/random_models/{name}.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    NumericModel::load(Path::new(&path)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_compiled_random_model_agrees_with_the_numeric_recursion() {
    let names: Vec<&str> = random_models::ALL.iter().map(|(n, _)| *n).collect();
    assert_eq!(
        names,
        [
            "chain16",
            "random_free",
            "random_planar",
            "random_tree",
            "random_two_cams"
        ],
        "the fixed set of tests/random_models/ (chain16: the large-model entry points)"
    );
    for (name, generated) in random_models::ALL.iter() {
        let numeric = numeric(name);
        assert_eq!(
            generated.info(),
            numeric.info(),
            "{name}: model information"
        );
        let worst = compare_dynamics(name, *generated, &numeric, TOL);
        println!("{name}: largest relative difference generated vs numeric {worst:.2e}");
    }
}

#[test]
fn a_random_model_simulates_alike_on_both_paths() {
    for name in ["random_planar", "random_tree", "random_two_cams"] {
        let generated = random_models::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, m)| *m)
            .expect("compiled");
        let numeric = numeric(name);
        // The model's defaults: Dormand–Prince 5(4), rtol 1e-10, atol 1e-12, 1 s.
        let settings = generated.info().defaults.clone();
        let run = |m: &dyn Dynamics| {
            let state = m.assemble(0.0).expect("assembles");
            m.simulate(state, &settings)
                .unwrap_or_else(|f| panic!("{name}: {}", f.error))
        };
        let (a, b) = (run(generated), run(&numeric));
        assert_eq!(a.samples.len(), b.samples.len());
        assert!(a.samples.len() > 100, "{name}: 1 s sampled every 10 ms");
        let mut worst: f64 = 0.0;
        for (x, y) in a.samples.iter().zip(&b.samples) {
            // The right-hand sides agree to ~1e-14 (test above); the adaptive steps may then
            // differ marginally, so the trajectories differ at the level of the integration
            // tolerance (rtol 1e-10) times the error growth over 1 s: 1e-7 is ample.
            common::assert_close(&x.q, &y.q, 1e-7, &format!("{name} q at t={}", x.t));
            common::assert_close(
                &x.normal_force,
                &y.normal_force,
                1e-6,
                &format!("{name} normal force at t={}", x.t),
            );
            // On the cam all along: the partitioned integration solves the dependent
            // coordinates by Newton to |h| <= 1e-12 m (partition::NEWTON_RESIDUAL_TOLERANCE);
            // 1e-10 m leaves margin, as in simulation.rs.
            for h in x.h.iter().chain(&y.h) {
                assert!(h.abs() < 1e-10, "{name}: |h| = {h:e} at t={}", x.t);
            }
            worst = worst.max(max_rel_diff(&x.q, &y.q));
        }
        // The markers slide along their cams (the models were drawn so that the contacts do
        // not freeze them): a range of cam x over 1 s well above rounding, on both paths.
        for k in 0..generated.info().n_contacts() {
            for samples in [&a.samples, &b.samples] {
                let xs = samples.iter().map(|s| s.contacts[k].x);
                let range = xs.clone().fold(f64::MIN, f64::max) - xs.fold(f64::MAX, f64::min);
                assert!(
                    range > 1e-3,
                    "{name}: contact {k} moves by {range:e} m only"
                );
            }
        }
        println!("{name}: generated vs numeric trajectory, largest difference in q {worst:.2e}");
    }
}
