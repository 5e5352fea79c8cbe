//! The emitted Rust of the contact kinds the built-in models do not use (parametric profiles,
//! rollers and flat faces on explicit ones; `tests/contact_models/zoo.ron`, compiled with the
//! `random-models` feature) against the numeric reference: every `Dynamics` function near the
//! assembled configuration, and whole runs, which exercise the contact parameters' Newton
//! solves started from the values kept in the cache and in the geometry buffers.

use crate::common;

use camchain::runtime::{Dynamics, Simulate};
use camchain_models::contact_models;
use camchain_reference::NumericModel;
use common::{compare_dynamics_at, max_rel_diff};
use std::path::Path;

fn numeric() -> NumericModel {
    let path = format!(
        "{}/tests/contact_models/zoo.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    NumericModel::load(Path::new(&path)).expect("zoo loads")
}

#[test]
fn the_compiled_zoo_agrees_with_the_numeric_reference() {
    let generated = &*contact_models::zoo::DEFAULT;
    let numeric = numeric();
    assert_eq!(generated.info(), numeric.info(), "model information");
    let start = generated.assemble().expect("assembles");
    // Within 0.05 rad or m of the assembled configuration: each follower stays near its cam
    // (a flat face on the open cap has no support point once turned past its slopes).
    let states = common::states_near(&start.q, 0.05, 100, 0x5eed);
    // As for the built-in models (generated_vs_numeric.rs): 1e-12 relative to max(1, |·|).
    let worst = compare_dynamics_at("zoo", &generated.clone(), &numeric, 1e-12, &states);
    println!("zoo: largest relative difference generated vs numeric {worst:.2e}");
}

#[test]
fn the_compiled_zoo_runs_like_the_numeric_reference() {
    let generated = &*contact_models::zoo::DEFAULT;
    let numeric = numeric();
    let settings = generated.default_settings();
    let generated: &dyn Dynamics = generated;
    let run = |m: &dyn Dynamics| {
        m.simulate(m.assemble(0.0).expect("assembles"), &settings)
            .unwrap_or_else(|f| panic!("{f}"))
    };
    let (a, b) = (run(generated), run(&numeric));
    assert_eq!(a.samples.len(), b.samples.len());
    let mut worst: f64 = 0.0;
    for (x, y) in a.samples.iter().zip(&b.samples) {
        // Right-hand sides agreeing to ~1e-14, integrated at rtol 1e-10 over 1 s: the
        // trajectories agree to the integration tolerance times the error growth.
        common::assert_close(&x.q, &y.q, 1e-8, &format!("zoo q at t = {}", x.t));
        worst = worst.max(max_rel_diff(&x.q, &y.q));
    }
    println!("zoo: generated vs numeric trajectory, largest difference in q {worst:.2e}");
}
