//! Re-partitioning on a real model (the numeric runtime path, model loaded from RON): the
//! dependent coordinate's Jacobian entry passes through zero mid-run; the runtime hands the
//! dependent role to the other coordinate and the trajectory goes through smoothly, equal to
//! a run that used the other partition from the start.

use approx::relative_eq;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, Simulate, Trajectory};

fn fixture() -> NumericModel {
    let model =
        camchain_cli::scenarios::scenario(camchain_cli::scenarios::REPARTITION, "repartition.ron")
            .expect("the scenario validates");
    NumericModel::new(model)
}

/// |a_i − b_i| ≤ tol · max(1, |a_i|, |b_i|) for every entry (relative above 1, absolute
/// below).
fn assert_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths differ");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            relative_eq!(*x, *y, epsilon = tol, max_relative = tol),
            "{what}[{i}]: {x:e} vs {y:e} (tolerance {tol:e})"
        );
    }
}

fn run(model: &NumericModel, dependent: Option<usize>) -> Trajectory {
    let mut state = model.assemble(0.0).expect("assembles");
    if let Some(v) = dependent {
        state.set_dependent(&[v]).expect("a valid partition");
    }
    let settings = model.info().defaults.clone();
    model
        .simulate(state, &settings)
        .unwrap_or_else(|f| panic!("{}", f.error))
}

#[test]
fn a_vanishing_jacobian_entry_is_crossed_by_re_partitioning() {
    let model = fixture();
    let state = model.assemble(0.0).expect("assembles");
    assert_eq!(
        state.dependent(),
        &[0],
        "q1 has the largest |J_i| at the start"
    );
    let automatic = run(&model, None);
    assert!(
        automatic.stats.repartitions >= 1,
        "the run must re-partition"
    );
    // ∂h/∂q1 = cos q1 + cos(q1 + q2) changes sign during the swing: the first partition
    // would have had to divide by zero.
    let j1: Vec<f64> = automatic
        .samples
        .iter()
        .map(|s| {
            let mut j = vec![0.0; 2];
            model.constraint_jacobian(&s.q, &mut j);
            j[0]
        })
        .collect();
    assert!(
        j1.iter().any(|&v| v > 0.1) && j1.iter().any(|&v| v < -0.1),
        "J_1 changes sign"
    );
    let other = run(&model, Some(1));
    assert_eq!(
        other.stats.repartitions, 0,
        "q2 stays well conditioned throughout"
    );
    let e0 = automatic.samples[0].energy.total();
    for (a, b) in automatic.samples.iter().zip(&other.samples) {
        // Both runs integrate the same ODE on different charts at rtol 1e-10: their
        // difference is bounded by the global error, ~1e-8 here; 1e-6 is the bound.
        assert_close(&a.q, &b.q, 1e-6, &format!("q at t={}", a.t));
        assert_close(&a.qd, &b.qd, 1e-6, &format!("q̇ at t={}", a.t));
        assert_close(&a.qdd, &b.qdd, 1e-5, &format!("q̈ at t={}", a.t));
        assert!(a.h[0].abs() < 1e-10, "h = {:e} at t={}", a.h[0], a.t);
        // Frictionless contact, no damper: energy is conserved to the integration error.
        assert!(
            (a.energy.total() - e0).abs() < 1e-7,
            "energy drift at t={}",
            a.t
        );
    }
}

#[test]
fn re_partitioning_on_a_wavy_cam_is_smooth() {
    // The same arm on the cam y = −1.5 + 0.2 sin 2x: the profile's slope changes sign
    // along the swing, so ∂h/∂q1 = J2_1 − f′ J1_1 and ∂h/∂q2 both pass through zero and the
    // dependent role goes back and forth.
    let model = NumericModel::new(
        camchain_cli::scenarios::with_profile(
            fixture().model().clone(),
            0,
            "-1.5 + 0.2*(2.0*x).sin()",
        )
        .expect("the profile parses"),
    );
    let state = model.assemble(0.0).expect("assembles");
    assert_eq!(state.dependent(), &[0]);
    let automatic = run(&model, None);
    let other = run(&model, Some(1));
    // Measured: 4 re-partitions from q1, 3 from q2.
    assert!(automatic.stats.repartitions >= 2 && other.stats.repartitions >= 2);
    let e0 = automatic.samples[0].energy.total();
    for (a, b) in automatic.samples.iter().zip(&other.samples) {
        // Different charts, same ODE, rtol 1e-10: measured difference 1.8e-9 rad;
        // bound 1e-7. A re-partition that lost the velocity or restarted from a stale
        // state would jump by far more (the swing speed is ~3 rad/s).
        assert_close(&a.q, &b.q, 1e-7, &format!("q at t={}", a.t));
        assert_close(&a.qd, &b.qd, 1e-6, &format!("q̇ at t={}", a.t));
        assert_close(&a.qdd, &b.qdd, 1e-5, &format!("q̈ at t={}", a.t));
        assert!(a.h[0].abs() < 1e-12, "h = {:e} at t={}", a.h[0], a.t);
        // Measured energy drift 2.9e-10 J; bound 1e-8.
        assert!(
            (a.energy.total() - e0).abs() < 1e-8,
            "energy drift at t={}",
            a.t
        );
    }
}
