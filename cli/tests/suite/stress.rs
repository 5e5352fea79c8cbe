//! Numerical stability stress checks (short versions of the scenarios of `camchain stress`,
//! see `STRESS.md`): long undamped runs, stiff springs, extreme masses, fast motion, steep,
//! flat and wavy profiles, an unreachable cam and non-finite values. Variants of the paper
//! models are built in memory (`camchain_cli::scenarios`) and run on the numeric reference.

use camchain_cli::scenarios::{self as stress, Integration, Record};
use camchain_reference::NumericModel;
use camchain_runtime::partition::NEWTON_RESIDUAL_TOLERANCE;
use camchain_runtime::{IntegratorKind, SimError, Simulate, Trajectory};

const DOPRI5: IntegratorKind = IntegratorKind::Dopri5;

fn paper(name: &str) -> camchain_codegen::model::Model {
    stress::builtin_model(name).unwrap_or_else(|e| panic!("{e}"))
}

fn integration(label: &str, settings: camchain_runtime::SimSettings) -> Integration {
    Integration {
        label: label.to_string(),
        settings,
    }
}

/// Runs from the assembled initial state.
fn run(model: &NumericModel, integration: &Integration) -> Record {
    let state = stress::assemble(model).unwrap_or_else(|e| panic!("{e}"));
    stress::run(model, &state, integration)
}

/// Runs and requires success.
fn run_ok(model: &NumericModel, integration: &Integration) -> Trajectory {
    let record = run(model, integration);
    if let Some(error) = &record.error {
        panic!("{}: {}", integration.label, error);
    }
    record.trajectory
}

/// Every sample's |h| is within Newton's convergence tolerance: the partitioned
/// formulation re-solves the dependent coordinates at every evaluation, so the residual
/// cannot accumulate, however long the run.
fn assert_on_cam(trajectory: &Trajectory, what: &str) {
    for sample in &trajectory.samples {
        for h in &sample.h {
            assert!(
                h.abs() <= NEWTON_RESIDUAL_TOLERANCE,
                "{what}: |h| = {h:e} at t = {}",
                sample.t
            );
        }
    }
}

#[test]
fn long_undamped_runs_conserve_energy_without_constraint_drift() {
    // Measured drifts over 100 s at rtol 1e-10: 1.1e-10 J (concave), 3.6e-9 J (convex);
    // Dormand–Prince is not symplectic, so the energy error grows with time (about
    // linearly; STRESS.md has the 1000 s runs). Bounds: about 100× the measurement. A wrong
    // term in the reduced dynamics or in the energy would drift by 1e-3 J or more (the
    // swing exchanges ~0.1 J between kinetic and potential energy).
    for (name, bound) in [("paper_concave", 1e-8), ("paper_convex", 4e-7)] {
        let model = stress::numeric(stress::without_dampers(paper(name)));
        let trajectory = run_ok(
            &model,
            &integration("dopri5", stress::adaptive(DOPRI5, 100.0, 0.1, 1e-10)),
        );
        let drift = stress::energy_drift(&trajectory);
        assert!(drift < bound, "{name}: energy drift {drift:e} J");
        assert_on_cam(&trajectory, name);
        // No secular growth of |h|: the last tenth of the run is no worse than the
        // tolerance that the first tenth also meets (checked sample by sample above), and
        // the swing is still going (an integrator that had damped it out would conserve
        // energy trivially at rest).
        let late = stress::max_residual_between(&trajectory, 0.9, 1.0);
        assert!(
            late <= NEWTON_RESIDUAL_TOLERANCE,
            "{name}: late |h| {late:e}"
        );
        let late_speed = trajectory
            .samples
            .iter()
            .filter(|s| s.t > 90.0)
            .map(|s| s.qd[0].abs())
            .fold(0.0, f64::max);
        assert!(
            late_speed > 0.1,
            "{name}: still swinging, |q̇1| {late_speed}"
        );
    }
}

#[test]
fn stiff_springs_blow_up_rk4_with_a_clear_error_and_dopri5_copes() {
    let model = stress::numeric(stress::stiffer(paper("paper_concave"), 1e4));
    // RK4 at 10 ms is far beyond the stability limit of the stiffest mode (k4 = 1.8e5
    // N·m/rad on body 4): the state grows by orders of magnitude per step until a computed
    // quantity overflows, or Newton cannot put the point back on the cam from the wild
    // state (the integrated v that seeds it has blown up too). The runtime stops there with
    // the time and the state, and says the integration diverged.
    let coarse = run(&model, &integration("rk4", stress::rk4(1.0, 0.01, 1e-2)));
    let t = match &coarse.error {
        Some(SimError::NonFinite { t, .. } | SimError::NewtonFailed { t, .. }) => t,
        other => panic!("expected NonFinite or NewtonFailed, got {other:?}"),
    };
    assert!(*t < 0.1, "diverges within a few steps, t = {t}");
    let message = coarse.error.as_ref().map(ToString::to_string);
    assert!(
        message.as_deref().is_some_and(|m| m.contains("diverged")),
        "{message:?}"
    );
    assert!(
        !coarse.trajectory.samples.is_empty(),
        "the partial run is kept"
    );

    // Dormand–Prince finds the stability limit by itself: no failure, many short steps.
    let span = 0.5;
    let adaptive = run_ok(
        &model,
        &integration("dopri5", stress::adaptive(DOPRI5, span, 0.01, 1e-6)),
    );
    let nominal = run_ok(
        &stress::numeric(paper("paper_concave")),
        &integration("dopri5", stress::adaptive(DOPRI5, span, 0.01, 1e-6)),
    );
    // Measured: 2415 steps against 53 for the nominal springs over 0.5 s.
    assert!(
        adaptive.stats.steps > 10 * nominal.stats.steps,
        "{} vs {} steps",
        adaptive.stats.steps,
        nominal.stats.steps
    );
    assert_on_cam(&adaptive, "stiff dopri5");
    // RK4 at 0.1 ms (inside its stability region) converges to a tight Dormand–Prince run:
    // measured differences 4.0e-7 rad at dt = 1e-4 and 2.5e-8 at 5e-5 (dopri5 at rtol
    // 1e-10 is within 1e-11 of rtol 1e-12). Bound 4e-6 at 1e-4, and the fourth order must
    // show: halving the step divides the error by more than 10 (theory 16).
    let tight = run_ok(
        &model,
        &integration("dopri5", stress::adaptive(DOPRI5, span, 0.01, 1e-10)),
    );
    let fine = run_ok(&model, &integration("rk4", stress::rk4(span, 0.01, 1e-4)));
    let finer = run_ok(&model, &integration("rk4", stress::rk4(span, 0.01, 5e-5)));
    let (e1, e2) = (
        stress::difference(&fine, &tight),
        stress::difference(&finer, &tight),
    );
    assert!(e1 < 4e-6, "rk4 vs dopri5: {e1:e}");
    assert!(e1 > 10.0 * e2, "fourth order: {e1:e} then {e2:e}");
}

#[test]
fn scaling_every_mass_and_load_leaves_the_motion_unchanged() {
    // M, F, Q all scale with the factor (gravity loads are proportional to the masses,
    // springs and dampers are scaled too), so q(t) is the nominal one: only round-off in
    // the scaled equations differs. Measured difference ≤ 2.2e-14 rad over 10 s at rtol
    // 1e-10; bound 1e-9, well below the integration error (~1e-8), so a mass-dependent
    // mistake (e.g. an unscaled term in the reduced dynamics) would show.
    let settings = stress::adaptive(DOPRI5, 10.0, 0.01, 1e-10);
    let nominal = run_ok(
        &stress::numeric(paper("paper_concave")),
        &integration("nominal", settings.clone()),
    );
    for factor in [1e-4, 1e4] {
        let model = stress::numeric(stress::scaled(paper("paper_concave"), factor));
        let scaled = run_ok(&model, &integration("scaled", settings.clone()));
        let difference = stress::difference(&scaled, &nominal);
        assert!(difference < 1e-9, "factor {factor}: {difference:e}");
        assert_eq!(scaled.samples.len(), nominal.samples.len());
        // Energies scale with the factor: relative agreement to round-off (1e-9).
        let (a, b) = (
            scaled.samples.last().map(|s| s.energy.total()),
            nominal.samples.last().map(|s| s.energy.total() * factor),
        );
        let (Some(a), Some(b)) = (a, b) else {
            panic!("samples")
        };
        assert!((a - b).abs() <= 1e-9 * b.abs(), "{a} vs {b}");
    }
}

#[test]
fn a_very_light_tip_body_needs_small_steps() {
    // Body 4 at 1e-4 times its mass and inertia: its spring (18 N·m/rad on 1e-5 kg·m²)
    // oscillates at ~1300 rad/s. RK4 at 1 ms is unstable: the state blows up and Newton
    // fails on a diverged state, which the message says. Dopri5 shortens its steps and
    // completes with the energy conserved.
    let model = stress::numeric(stress::heavier(paper("paper_concave"), 1e-4, |i| i == 3));
    let coarse = run(&model, &integration("rk4", stress::rk4(1.0, 0.01, 1e-3)));
    let message = coarse
        .error
        .as_ref()
        .map(ToString::to_string)
        .unwrap_or_default();
    assert!(message.contains("diverged"), "{message}");
    let adaptive = run_ok(
        &model,
        &integration("dopri5", stress::adaptive(DOPRI5, 1.0, 0.01, 1e-8)),
    );
    // Measured balance error 1.1e-11 J over 1 s (energy ~12 J); bound 1e-8.
    let drift = stress::energy_drift(&adaptive);
    assert!(drift < 1e-8, "{drift:e}");
    assert_on_cam(&adaptive, "light tip");
}

#[test]
fn fast_motion_stays_on_the_cam() {
    // q̇1(0) = 5.5 rad/s, ten times the largest speed of the nominal swing (0.55 rad/s):
    // the arm swings far up the cam and back; dampers on, so the balance
    // energy + dissipated is what is conserved.
    let model =
        stress::numeric(stress::with_velocity(paper("paper_concave"), "q1", 5.5).expect("q1"));
    let trajectory = run_ok(
        &model,
        &integration("dopri5", stress::adaptive(DOPRI5, 10.0, 0.01, 1e-10)),
    );
    assert_on_cam(&trajectory, "fast");
    let speed = trajectory
        .samples
        .iter()
        .map(|s| s.qd[0].abs())
        .fold(0.0, f64::max);
    assert!(speed >= 5.5, "max |q̇1| = {speed}");
    // Measured balance error 3.2e-10 J against 11 J dissipated; bound 1e-7.
    let drift = stress::energy_drift(&trajectory);
    assert!(drift < 1e-7, "{drift:e}");
}

#[test]
fn steep_flat_and_wavy_profiles_conserve_energy() {
    let nominal = stress::numeric(paper("paper_concave"));
    let state = stress::assemble(&nominal).unwrap_or_else(|e| panic!("{e}"));
    let start = nominal.sample(&state).expect("sample").contacts[0];
    for (name, profile) in stress::profile_variants(start.x, start.y) {
        let variant =
            stress::with_profile(stress::without_dampers(paper("paper_concave")), 0, &profile)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        let model = stress::numeric(variant);
        let trajectory = run_ok(
            &model,
            &integration("dopri5", stress::adaptive(DOPRI5, 5.0, 0.01, 1e-10)),
        );
        assert_on_cam(&trajectory, name);
        // Measured drifts ≤ 6.8e-10 J over 5 s; bound 1e-8.
        let drift = stress::energy_drift(&trajectory);
        assert!(drift < 1e-8, "{name}: {drift:e}");
        let slopes: Vec<f64> = trajectory
            .samples
            .iter()
            // The normal (−f′, 1)/√(1 + f′²): its x has the sign of −f′.
            .map(|s| -s.contacts[0].normal[0])
            .collect();
        let curvatures: Vec<f64> = trajectory
            .samples
            .iter()
            .map(|s| s.contacts[0].curvature)
            .collect();
        let changes = |v: &[f64]| v.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
        if name.starts_with("wavy") {
            assert!(changes(&slopes) >= 2, "{name}: the slope changes sign");
        }
        if name.starts_with("inflection") {
            assert!(changes(&curvatures) >= 2, "{name}: crosses the inflection");
        }
    }
}

#[test]
fn an_unreachable_cam_stops_the_run_with_time_and_state() {
    let model = stress::numeric(
        stress::scenario(stress::UNREACHABLE, "unreachable.ron").expect("the scenario validates"),
    );
    // The elbow rises above the reach of link 2 at q1 = −π/6, i.e. t = π/3: there the arm
    // is stretched (a dead point, J = 0 with the tip on the cam), beyond it the tip cannot
    // reach the cam. A run stops at the dead point, or one step past it when a step lands
    // beyond (Newton then cannot make |h| small): each failure is named for what it is.
    let limit = std::f64::consts::FRAC_PI_3;
    for integration in stress::sweep(2.0, 0.01, &[1e-2, 1e-3], &[1e-8, 1e-10]) {
        let record = run(&model, &integration);
        let message = record
            .error
            .as_ref()
            .map(ToString::to_string)
            .unwrap_or_default();
        let (t, q) = match &record.error {
            Some(SimError::NewtonFailed { t, q, residual, .. }) => {
                assert!(*residual > 1e-12, "{}: {message}", integration.label);
                assert!(message.contains("cannot reach the cam"), "{message}");
                (*t, q)
            }
            Some(SimError::SingularConstraint { t, q, on_cam, .. }) => {
                assert!(*on_cam, "{}: {message}", integration.label);
                assert!(message.contains("locks at a dead point"), "{message}");
                (*t, q)
            }
            other => panic!(
                "{}: expected a stop at the limit, got {other:?}",
                integration.label
            ),
        };
        // The failure is within one step (10 ms) past the limit.
        assert!((t - limit).abs() < 0.011, "{}: t = {t}", integration.label);
        assert!(q.iter().all(|x| x.is_finite()));
        assert!(record.t_reached() <= t && record.t_reached() > 1.0);
    }
}

#[test]
fn non_finite_values_stop_the_run_and_name_the_quantity() {
    // A profile undefined for x < 0 (the convex cam plus 0·√x): the tip slides left and
    // reaches x = 0 near t = 0.39 s.
    let convex = paper("paper_convex");
    let camchain_codegen::model::Profile::Explicit { source, .. } = &convex.contacts[0].profile
    else {
        panic!("the paper's cam is explicit");
    };
    let profile = format!("{source} + 0.0*x.sqrt()");
    let model = stress::numeric(stress::with_profile(convex.clone(), 0, &profile).expect("parses"));
    for integration in stress::sweep(1.0, 0.01, &[1e-3], &[1e-8]) {
        let record = run(&model, &integration);
        let Some(SimError::NonFinite { t, quantity, .. }) = &record.error else {
            panic!(
                "{}: expected NonFinite, got {:?}",
                integration.label, record.error
            );
        };
        // h, J or q̈: at x = 0 the profile's value is finite but its slope (in J) and
        // curvature (in c, hence q̈) are not; which the run meets first depends on where
        // the steps land. All three are computed from the profile at the contact point.
        assert!(
            ["h", "J", "q̈"].contains(quantity),
            "{}: {quantity}",
            integration.label
        );
        assert!(*t > 0.3 && *t < 0.45, "t = {t}");
        let last = record.trajectory.samples.last().expect("partial samples");
        assert!(last.contacts[0].x >= 0.0 && last.contacts[0].x < 0.05);
    }

    // NaN or ∞ put into the state through its public fields.
    let model = stress::numeric(convex);
    let settings = stress::adaptive(DOPRI5, 1.0, 0.01, 1e-8);
    let state = stress::assemble(&model).unwrap_or_else(|e| panic!("{e}"));
    for (coordinate, velocity, value, expected) in [
        (None, Some(0), f64::NAN, "q̇"),
        (Some(0), None, f64::INFINITY, "q"),
        (Some(2), None, f64::NAN, "q"),
    ] {
        let mut bad = state.clone();
        if let Some(i) = coordinate {
            bad.q[i] = value;
        }
        if let Some(i) = velocity {
            bad.qd[i] = value;
        }
        let failure = model.simulate(bad, &settings).expect_err("must fail");
        assert!(
            matches!(&failure.error, SimError::NonFinite { quantity, t, .. }
                if *quantity == expected && *t == 0.0),
            "{}",
            failure.error
        );
        assert!(failure.partial.samples.is_empty());
    }
    let mut stepped = state.clone();
    model.step(&mut stepped, 0.25).expect("a normal step");
    stepped.qd[1] = f64::NAN;
    let error = model.step(&mut stepped, 0.25).expect_err("must fail");
    assert!(
        matches!(&error, SimError::NonFinite { quantity: "q̇", t, qd, .. }
            if *t == 0.25 && qd[1].is_nan()),
        "{error}"
    );
    assert!(model.sample(&stepped).is_err());
}
