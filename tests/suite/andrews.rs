//! Andrews' squeezing mechanism against the published reference solution of the Test Set for
//! IVP Solvers (problem `andrews`; W. M. Lioen and J. J. B. de Swart, "Test Set for Initial
//! Value Problem Solvers", CWI 1999; F. Mazzia and C. Magherini, release 2.4, University of
//! Bari 2008). The values are copied from the test set's problem file `andrews.f`
//! (revision `$Id: andrews.F,v 1.2 2006/10/02`), subroutines `init` (consistent initial
//! values, 30 digits) and `solut` (the solution at t = 0.03 s, "computed at Cray C90, using
//! Cray double precision, ... PSIDE, rtol = atol = 1d-14"), as packaged in the R package
//! deTestSet (Soetaert, Cash, Mazzia), file `src/Ex_andrews.f`, subroutines `andfunc` and
//! `andsoln`.

// The reference values are written with every digit the test set prints, not rounded to f64.
#![allow(clippy::excessive_precision)]

use camchain::runtime::{Dynamics, Sample, Simulate};
use camchain_models as models;
use camchain_models::andrews_reference::{ANGLES, Q_REF};
use camchain_reference::NumericModel;
use std::path::Path;

/// `solut`: y(8..14), the angular velocities at t = 0.03 s.
const QD_REF: [f64; 7] = [
    0.1139920302151208e4,
    -0.1424379294994111e4,
    0.1103291221937134e2,
    0.1929337464421385e2,
    0.5735699284790808e0,
    -0.1929337464421385e2,
    0.3231791658026955e0,
];

/// `solut`: y(22..27), the multipliers at t = 0.03 s.
const LAMBDA_REF: [f64; 6] = [
    0.1991753333731910e3,
    -0.2975531228015052e2,
    0.2306654119098399e2,
    0.3145271365475927e2,
    0.2264249232082739e2,
    0.1161740700019673e2,
];

/// `init`: y(15), y(16) (β̈, Θ̈ at t = 0; the other accelerations are 0) and y(22), y(23)
/// (λ1, λ2; the others are 0).
const QDD_0: [f64; 2] = [
    14222.4439199541138705911625887,
    -10666.8329399655854029433719415,
];
const LAMBDA_0: [f64; 2] = [
    98.5668703962410896057654982170,
    -6.12268834425566265503114393122,
];

/// The model's values in the test set's order.
fn in_test_set_order(model: &dyn Dynamics, values: &[f64]) -> Vec<f64> {
    ANGLES
        .iter()
        .map(|name| values[model.info().coordinate_index(name).expect("angle")])
        .collect()
}

fn run_to(model: &dyn Dynamics, rtol: f64) -> (Sample, Sample) {
    let state = model
        .assemble(0.0)
        .expect("the test set's initial state assembles");
    let mut settings = model.info().defaults.clone();
    settings.rtol = rtol;
    settings.atol = rtol * 1e-2;
    settings.dt_out = 0.03;
    let run = model
        .simulate(state, &settings)
        .unwrap_or_else(|f| panic!("{}", f.error));
    let first = run.samples.first().expect("t = 0").clone();
    let last = run.samples.last().expect("t = 0.03").clone();
    assert!((last.t - 0.03).abs() < 1e-15);
    (first, last)
}

#[test]
fn initial_accelerations_and_multipliers_are_the_test_sets() {
    // q̈ and λ at t = 0 follow from one linear solve at the test set's initial state, whose
    // 30-digit values are rounded to f64 (1e-16 relative); the terms of the equations are of
    // order 1e4 (β̈) with entries of M ~1e-6: 1e-9 relative to the largest value is round-off.
    let model = models::by_name("andrews_squeezer").expect("built in");
    let (first, _) = run_to(model, 1e-6);
    let qdd = in_test_set_order(model, &first.qdd);
    let scale = QDD_0[0].abs();
    let expected_qdd = [QDD_0[0], QDD_0[1], 0.0, 0.0, 0.0, 0.0, 0.0];
    for (k, (a, b)) in qdd.iter().zip(expected_qdd).enumerate() {
        assert!(
            (a - b).abs() < 1e-9 * scale,
            "{}'' = {a}, test set {b}",
            ANGLES[k]
        );
    }
    let expected_lambda = [LAMBDA_0[0], LAMBDA_0[1], 0.0, 0.0, 0.0, 0.0];
    for (k, (a, b)) in first.lambda.iter().zip(expected_lambda).enumerate() {
        assert!(
            (a - b).abs() < 1e-9 * LAMBDA_0[0],
            "λ{} = {a}, test set {b}",
            k + 1
        );
    }
}

#[test]
fn the_angles_at_0_03_s_match_the_test_set_reference() {
    // The issue asks for 1e-8 in every coordinate at tight tolerances. The reference is good
    // to ~1e-13 (PSIDE at 1e-14); at rtol 1e-12 DOP853 on the reduced equations lands within
    // a few 1e-10 of it (measured, see BENCHMARKS.md "Closed loops").
    let model = models::by_name("andrews_squeezer").expect("built in");
    let (_, last) = run_to(model, 1e-12);
    let q = in_test_set_order(model, &last.q);
    let qd = in_test_set_order(model, &last.qd);
    let mut worst: f64 = 0.0;
    for k in 0..7 {
        let error = (q[k] - Q_REF[k]).abs();
        println!(
            "{:8}: {:+.16e}  reference {:+.16e}  error {error:.2e}",
            ANGLES[k], q[k], Q_REF[k]
        );
        worst = worst.max(error);
    }
    assert!(worst < 1e-8, "largest angle error {worst:e} rad");
    // Velocities reach 1.4e3 rad/s: 1e-8 relative to the largest.
    for k in 0..7 {
        assert!(
            (qd[k] - QD_REF[k]).abs() < 1e-8 * QD_REF[1].abs(),
            "{}' = {}, reference {}",
            ANGLES[k],
            qd[k],
            QD_REF[k]
        );
    }
    // Multipliers up to 2e2: 1e-7 relative (they carry the accelerations' sensitivity).
    for (k, (a, b)) in last.lambda.iter().zip(LAMBDA_REF).enumerate() {
        assert!(
            (a - b).abs() < 1e-7 * LAMBDA_REF[0],
            "λ{} = {a}, reference {b}",
            k + 1
        );
    }
}

#[test]
fn the_numeric_reference_reaches_the_same_angles() {
    // The numeric recursion integrated through the same runtime: 1e-8 of the test set at
    // rtol 1e-11 (slower, so a little looser than the generated run's tolerance).
    let path = format!("{}/models/andrews_squeezer.ron", env!("CARGO_MANIFEST_DIR"));
    let numeric = NumericModel::load(Path::new(&path)).expect("loads");
    let (_, last) = run_to(&numeric, 1e-11);
    let q = in_test_set_order(&numeric, &last.q);
    for k in 0..7 {
        assert!(
            (q[k] - Q_REF[k]).abs() < 1e-8,
            "{} = {}, reference {}",
            ANGLES[k],
            q[k],
            Q_REF[k]
        );
    }
}
