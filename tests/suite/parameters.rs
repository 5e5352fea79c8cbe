//! Run-time parameters (issue 12 §1), checked three ways:
//!
//! - against the folded code: every built-in model (n_four_bar, forty copies of four_bar,
//!   paper_surface, paper_concave's chain on a turret, and paper_convex_text and
//!   driven_convex, the same code as paper_convex and driven_concave, apart) compiled with every
//!   parameter read at run
//!   time (`ParameterMode::AllAtRunTime`) computes what the same model compiled with every
//!   parameter folded (`ParameterMode::FoldAll`) computes, at 100 random states, to 1e-13;
//! - against the numeric reference at other parameter values: the reference resolves the
//!   values while it validates the file (no symbolic parameter anywhere), the generated code
//!   reads them at run time, and both must agree to the tolerance of
//!   `generated_vs_numeric.rs`;
//! - against the build's validation: a bad value given at run time gets, word for word, the
//!   error the numeric reference (the build's validator) gives for the same value.

use crate::common;

use camchain::runtime::{Dynamics, Simulate};
use camchain_codegen::ParameterMode;
use camchain_models as models;
use camchain_models::parameter_modes::{all_at_run_time, checks, folded};
use camchain_reference::NumericModel;
use common::compare_dynamics;
use std::path::Path;

/// Agreement of the run-time and folded code, relative to max(1, |value|): the two compute
/// the same expressions, the run-time code from stored parameter values where the folded
/// code has constants; only constant folding differs (e.g. m·(c² − c c) formed in f64 by
/// the generator for the folded code, by the program for the run-time code), a few
/// roundings of O(1) values: ~1e-15. 1e-13 is the bound.
const SAME_CODE: f64 = 1e-13;

/// Generated against numeric, as in `generated_vs_numeric.rs` (see its justification).
const REFERENCE: f64 = 1e-12;

fn source(name: &str) -> String {
    let path = format!("{}/models/{name}.ron", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path).expect("the model file")
}

fn by_name<'a>(
    table: &'a [(&'static str, &'static (dyn Dynamics + Sync))],
    name: &str,
) -> &'a (dyn Dynamics + Sync) {
    table
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, m)| *m)
        .unwrap_or_else(|| panic!("{name} is compiled"))
}

#[test]
fn every_parameter_read_at_run_time_gives_the_folded_code() {
    // Every built-in model but n_four_bar, forty copies of four_bar, paper_surface,
    // paper_concave's chain on a turret, and paper_convex_text and driven_convex, the same
    // code as paper_convex and driven_concave in each mode (build.rs).
    assert_eq!(all_at_run_time::ALL.len(), models::ALL.len() - 4);
    assert!(by_name(&all_at_run_time::ALL, "four_bar").info().n() > 0);
    for (name, runtime) in all_at_run_time::ALL.iter() {
        let folded = by_name(&folded::ALL, name);
        assert!(folded.info().parameters.is_empty(), "{name}: all folded");
        assert!(
            !runtime.info().parameters.is_empty(),
            "{name}: read at run time"
        );
        let worst = compare_dynamics(name, *runtime, folded, SAME_CODE);
        assert_eq!(runtime.info().initial, folded.info().initial, "{name}");
        println!(
            "{name}: {} parameters at run time, largest relative difference from the folded \
             code {worst:.2e}",
            runtime.info().parameters.len()
        );
    }
}

/// Every run-time parameter of `info` moved off its default (within its bounds).
fn moved(info: &camchain::runtime::ModelInfo) -> Vec<(String, f64)> {
    info.parameters
        .iter()
        .map(|p| {
            let mut v = 1.1 * p.default + 0.01;
            if let Some(max) = p.max {
                v = v.min(max);
            }
            (p.name.clone(), v)
        })
        .collect()
}

/// Generated code built with other values, against the numeric reference loaded with them.
fn check_against_reference(
    name: &str,
    table: &[(&str, models::Constructor)],
    mode: ParameterMode,
    defaults: &camchain::runtime::ModelInfo,
) {
    let values = moved(defaults);
    let pairs: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    let constructor = table
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, c)| *c)
        .expect("compiled");
    let generated = constructor(&pairs).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(generated.parameter_values().len(), values.len());
    let file = format!("models/{name}.ron");
    let files = camchain_codegen::schema::Files::Embedded(models::files(name));
    let numeric =
        NumericModel::from_source_in(&source(name), Path::new(&file), &values, mode, files)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
    let tolerance = common::for_tables(&numeric, REFERENCE);
    let worst = compare_dynamics(name, &*generated, &numeric, tolerance);
    assert_eq!(generated.info().initial, numeric.info().initial, "{name}");
    // Not vacuous: the values changed the model.
    let defaults_model = constructor(&[]).expect("the defaults");
    let q = vec![0.3; defaults.n()];
    let qd = vec![0.7; defaults.n()];
    let all = |m: &dyn Dynamics| {
        let n = m.info().n();
        let (mut mm, mut f, mut qa) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
        m.equations(1.3, &q, &qd, &mut mm, &mut f, &mut qa);
        let mut h = vec![0.0; m.info().n_constraints()];
        m.constraint(&q, &mut h);
        let mut p = (q.clone(), qd.clone(), vec![0.0; n]);
        m.prescribed(1.3, &mut p.0, &mut p.1, &mut p.2);
        [mm, f, qa, h, p.0, m.info().initial.q.clone()].concat()
    };
    assert_ne!(all(&*generated), all(&*defaults_model), "{name}");
    println!(
        "{name}: {} parameters moved; generated vs numeric {worst:.2e}",
        values.len()
    );
}

#[test]
fn other_parameter_values_agree_with_the_numeric_reference() {
    for (name, model) in models::ALL.iter() {
        check_against_reference(
            name,
            models::WITH_PARAMETERS,
            ParameterMode::AsDeclared,
            model.info(),
        );
    }
    // Every parameter at run time: masses, lengths, inertias, gravity and cam coefficients
    // too (the folded paper models read only springs, dampers and the start).
    for (name, model) in all_at_run_time::ALL.iter() {
        check_against_reference(
            name,
            all_at_run_time::WITH_PARAMETERS,
            ParameterMode::AllAtRunTime,
            model.info(),
        );
    }
}

#[test]
fn a_run_with_other_values_follows_the_reference() {
    let values = [("k3", 60.0), ("c2", 0.5), ("swing", 0.3)];
    let generated = models::paper_concave::Model::with(&values).expect("valid values");
    assert_eq!(generated.parameters().k3, 60.0);
    assert_eq!(
        generated.info().initial.q[0],
        -std::f64::consts::FRAC_PI_2 - 0.3,
        "the start follows `swing`"
    );
    let owned: Vec<(String, f64)> = values.iter().map(|(n, v)| (n.to_string(), *v)).collect();
    let numeric = NumericModel::from_source_with(
        &source("paper_concave"),
        Path::new("models/paper_concave.ron"),
        &owned,
        ParameterMode::AsDeclared,
    )
    .expect("valid values");
    let mut settings = generated.default_settings();
    settings.t_end = 2.0;
    let run = |m: &dyn Dynamics| {
        let state = m.assemble(0.0).expect("assembles");
        m.simulate(state, &settings)
            .unwrap_or_else(|f| panic!("{}", f.error))
    };
    let (a, b) = (run(&generated), run(&numeric));
    let default_run = run(&models::paper_concave::Model::default());
    assert_eq!(a.samples.len(), b.samples.len());
    for (x, y) in a.samples.iter().zip(&b.samples) {
        // As in generated_vs_numeric.rs: equal right-hand sides, steps that may differ at
        // the integration tolerance (rtol 1e-10) times the error growth over 2 s.
        common::assert_close(&x.q, &y.q, 1e-7, &format!("q at t = {}", x.t));
    }
    let last = |t: &camchain::runtime::Trajectory| t.samples.last().map(|s| s.q.clone());
    let moved = common::max_rel_diff(&last(&a).expect("q"), &last(&default_run).expect("q"));
    assert!(moved > 1e-3, "the values change the motion ({moved:.1e})");
}

/// The model file of `checks::checked`, as its build shows it.
const CHECKED: &str = "tests/parameter_models/checked.ron";

/// The generated code's and the numeric reference's errors for one value.
fn both_errors(name: &str, value: f64) -> (String, String) {
    let generated = checks::checked::Model::with(&[(name, value)])
        .map(|_| ())
        .expect_err("a bad value")
        .to_string();
    let text = std::fs::read_to_string(format!(
        "{}/tests/parameter_models/checked.ron",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("the test model");
    let numeric = NumericModel::from_source_with(
        &text,
        Path::new(CHECKED),
        &[(name.to_string(), value)],
        ParameterMode::AsDeclared,
    )
    .map(|_| ())
    .expect_err("a bad value")
    .to_string();
    (generated, numeric)
}

#[test]
fn a_bad_value_at_run_time_gets_the_error_the_build_gives() {
    // (parameter, value, what the error must say): the field the value breaks, with the
    // check's own words. The positions are those of the fields in checked.ron.
    let cases: [(&str, f64, &str); 10] = [
        (
            "m",
            -1.0,
            "checked.ron:23:19: bodies[0].mass: mass must be positive and finite, got -1",
        ),
        (
            "jz",
            0.05,
            "checked.ron:25:22: bodies[0].inertia: the principal moments 0.01, 0.01, 0.05 violate the triangle inequality",
        ),
        (
            "jx",
            -0.01,
            "checked.ron:25:22: bodies[0].inertia: the inertia tensor must be positive definite",
        ),
        (
            "k",
            -1.0,
            "checked.ron:30:37: bodies[0].joint.spring.stiffness: stiffness must be non-negative and finite, got -1",
        ),
        (
            "c",
            -0.5,
            "checked.ron:30:51: bodies[0].joint.spring.damping: damping must be non-negative and finite, got -0.5",
        ),
        (
            "len",
            f64::INFINITY,
            "checked.ron:10:30: parameters[1].value: len = inf is not a finite number",
        ),
        (
            "lift",
            0.7,
            "checked.ron:15:62: parameters[6].max: lift = 0.7 is above the maximum 0.5 declared for `lift`",
        ),
        (
            "lift",
            -0.1,
            "checked.ron:15:52: parameters[6].min: lift = -0.1 is below the minimum 0 declared for `lift`",
        ),
        (
            "g",
            1.0,
            "checked.ron:16:59: parameters[7].constant: parameter `g` is constant (folded into the generated code)",
        ),
        (
            "mass",
            1.0,
            "checked.ron:8:17: parameters: unknown parameter `mass`; known: c, jx, jz, k, len, lift, m (constant, folded into the code: g)",
        ),
    ];
    for (name, value, expected) in cases {
        let (generated, numeric) = both_errors(name, value);
        assert_eq!(generated, numeric, "{name} = {value}");
        assert!(generated.starts_with(CHECKED), "{generated}");
        assert!(
            generated.contains(expected),
            "{name} = {value}: `{generated}` lacks `{expected}`"
        );
    }
}

/// The model file of `checks::undercut`, as its build shows it.
const UNDERCUT: &str = "tests/parameter_models/undercut.ron";

#[test]
fn a_follower_that_cannot_follow_its_profile_is_refused_at_run_time() {
    // Run-time values that make the roller larger than its hollow (rho, or depth: the
    // hollow's radius of curvature is 1/(2 depth) = 0.1 m by default) or the polar cam's
    // radius negative (base < 0.01): the generated check samples the profile as the build
    // does, with the build's message and location.
    // The barrel's groove g = 0.02 + a sin 2θ (a = 5 mm) developed at R = 0.06 m bends with
    // the radius (R² + g′²)^{3/2}/(R |g″|); a roller of 0.2 m undercuts the lower flank
    // (g″ < 0) from the first of the check's 3600 angles where that radius is 0.2 m or less.
    let (a, radius) = (0.005f64, 0.06f64);
    let first = (0..3600)
        .map(|k| std::f64::consts::TAU * f64::from(k) / 3600.0)
        .find(|t| {
            let (d1, d2) = (2.0 * a * (2.0 * t).cos(), -4.0 * a * (2.0 * t).sin());
            (radius * radius + d1 * d1).powf(1.5) / (radius * d2.abs()) <= 0.2
        })
        .expect("the roller undercuts");
    let barrel = format!(
        "undercut.ron:44:48: contacts[3].follower.radius: contact `B`: the roller (0.2 m) \
         undercuts the groove's lower flank: at θ = {:.3}° the groove's pitch curve",
        first.to_degrees()
    );
    let cases: [(&str, f64, &str); 6] = [
        (
            "rho",
            0.2,
            "undercut.ron:40:48: contacts[0].follower.radius: contact `R`: the roller (radius 0.2 m) is larger than the profile's hollow at x = 0.000000, whose radius of curvature is 1.000000e-1 m",
        ),
        (
            "depth",
            50.0,
            "undercut.ron:40:48: contacts[0].follower.radius: contact `R`: the roller (radius 0.02 m) is larger than the profile's hollow at x = 0.000000, whose radius of curvature is 1.000000e-2 m",
        ),
        (
            "base",
            0.005,
            "undercut.ron:41:30: contacts[1].polar: contact `K`: the polar radius must be positive over the cam, but r(theta = 2.095418)",
        ),
        // The face cam's groove: a roller wider than the centre line's convex radius at
        // θ = 0, 1/κ = r³/(r² − r r″) = 0.055³/(0.055² + 0.055·0.045) = 0.03025 m.
        (
            "rg",
            0.04,
            "undercut.ron:42:48: contacts[2].follower.radius: contact `G`: the roller (0.04 m) undercuts the groove's inner flank: at θ = 0.0000 rad the centre line is convex with a radius of curvature of 0.030250 m",
        ),
        ("rb", 0.2, &barrel),
        // A roller of 0.03 m (no undercut: the groove bends with 0.18 m at least) whose
        // upper flank, 0.02 + 0.005 + 0.03 m at θ = 45°, leaves the 0.05 m cylinder.
        (
            "rb",
            0.03,
            "undercut.ron:45:83: contacts[3].barrel.length: the groove leaves the cylinder: its upper flank reaches z = 0.055000 m at θ = 45.000°, beyond its length",
        ),
    ];
    let text = std::fs::read_to_string(format!(
        "{}/tests/parameter_models/undercut.ron",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("the test model");
    for (name, value, expected) in cases {
        let generated = checks::undercut::Model::with(&[(name, value)])
            .map(|_| ())
            .expect_err("a follower that cannot follow")
            .to_string();
        let numeric = NumericModel::from_source_with(
            &text,
            Path::new(UNDERCUT),
            &[(name.to_string(), value)],
            ParameterMode::AsDeclared,
        )
        .map(|_| ())
        .expect_err("a follower that cannot follow")
        .to_string();
        assert_eq!(generated, numeric, "{name} = {value}");
        assert!(
            generated.contains(expected),
            "{name} = {value}: `{generated}` lacks `{expected}`"
        );
    }
    // Values that keep every follower on its profile are accepted.
    let fine = [("rho", 0.09), ("base", 0.011), ("rg", 0.03), ("rb", 0.015)];
    assert!(checks::undercut::Model::with(&fine).is_ok());
}

#[test]
fn a_field_error_at_run_time_is_the_files_own_error() {
    // The same value written into the file as the parameter's default: the build reports it
    // at the field, with the same words as the run-time check.
    let text = std::fs::read_to_string(format!(
        "{}/tests/parameter_models/checked.ron",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("the test model");
    for (name, default, bad) in [
        ("m", "1.0", "-1.0"),
        ("k", "10.0", "-2.5"),
        ("jz", "0.02", "0.05"),
    ] {
        let from = format!("(name: \"{name}\", value: {default},");
        assert!(text.contains(&from), "{from}");
        let edited = text.replace(&from, &format!("(name: \"{name}\", value: {bad},"));
        let build = camchain_codegen::schema::parse_model(&edited, Path::new(CHECKED))
            .map(|_| ())
            .expect_err("a bad default")
            .to_string();
        let value: f64 = bad.parse().expect("a number");
        let (generated, _) = both_errors(name, value);
        assert_eq!(generated, build, "{name} = {bad}");
    }
}

#[test]
fn parameters_are_set_by_name_and_read_back() {
    use models::paper_concave::{Model, Parameters};
    let mut p = Parameters::default();
    assert_eq!(
        Parameters::NAMES,
        ["k2", "k3", "k4", "c2", "c3", "c4", "swing"]
    );
    p.set("k4", 21.0).expect("known");
    assert_eq!(p.get("k4"), Some(21.0));
    assert_eq!(Parameters::from_values(p.values()), p);
    let model = Model::new(p).expect("valid");
    assert_eq!(model.parameter_values(), &p.values()[..]);
    assert_eq!(model.info().parameters[2].name, "k4");
    assert_eq!(model.info().parameters[2].default, 18.0);
    let bad = Model::new(Parameters {
        k3: -40.0,
        ..Parameters::default()
    });
    let message = bad.map(|_| ()).expect_err("negative").to_string();
    assert!(
        message.starts_with("models/paper_concave.ron:")
            && message.contains("parameters[19].min: k3 = -40 is below the minimum 0"),
        "{message}"
    );
    // Folded in this build: the paper's lengths.
    let folded = Model::with(&[("l1", 0.4)]).map(|_| ()).expect_err("folded");
    assert!(folded.to_string().contains("constant"), "{folded}");
}
