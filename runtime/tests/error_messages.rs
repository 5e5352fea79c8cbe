//! The errors a user's program meets print their one-line message through `?`: a `main`
//! returning `Result<(), Box<dyn std::error::Error>>` prints the error's `Debug`, which must
//! be the located message of `Display`, not the struct's fields (`ParameterError { file: …`)
//! or the variant's (`TooManySteps { t: … }`).

use camchain_runtime::parameters::UnknownParameter;
use camchain_runtime::{
    InvalidSetting, MetricsFailure, ParameterError, RunMetrics, SimError, SimFailure, Stats,
    Trajectory,
};
use std::error::Error;

/// What `main` prints after `Error: ` when `error` comes out of it through `?`.
fn printed_by_main<E: Error + 'static>(error: E) -> String {
    let main = || -> Result<(), Box<dyn Error>> {
        Err(error)?;
        Ok(())
    };
    match main() {
        Err(boxed) => format!("{boxed:?}"),
        Ok(()) => String::new(),
    }
}

#[test]
fn parameter_error_debug_is_the_located_message() {
    let error = ParameterError {
        file: "models/follower.ron".into(),
        line: 12,
        column: 18,
        field: "parameters[0].max".into(),
        message: "k = -1 is below its minimum 0".into(),
    };
    let expected = "models/follower.ron:12:18: parameters[0].max: k = -1 is below its minimum 0";
    assert_eq!(format!("{error:?}"), expected);
    assert_eq!(printed_by_main(error), expected);
}

#[test]
fn unknown_parameter_debug_is_the_message() {
    let error = UnknownParameter {
        name: "kk".into(),
        message: "no run-time parameter `kk`; the model has k, c".into(),
    };
    assert_eq!(
        printed_by_main(error),
        "no run-time parameter `kk`; the model has k, c"
    );
}

#[test]
fn sim_error_debug_is_the_message() {
    let error = SimError::TooManySteps { t: 1.5 };
    assert_eq!(
        printed_by_main(error),
        "at t = 1.5 s the step budget of one call was exhausted"
    );
}

#[test]
fn sim_failure_debug_is_the_message_not_the_trajectory() {
    let failure = SimFailure {
        error: SimError::TooManySteps { t: 1.5 },
        partial: Trajectory {
            sample_count: 151,
            ..Trajectory::default()
        },
    };
    let expected = "simulation stopped after 151 samples: at t = 1.5 s the step budget of one call was exhausted";
    assert_eq!(format!("{failure:?}"), expected);
    // What the run methods return: a boxed failure.
    assert_eq!(printed_by_main(Box::new(failure)), expected);
}

#[test]
fn invalid_setting_debug_is_the_message() {
    let error = InvalidSetting {
        field: "dt_out",
        message: "must be positive and finite, not 0".into(),
    };
    assert_eq!(
        printed_by_main(error),
        "dt_out: must be positive and finite, not 0"
    );
}

#[test]
fn metrics_failure_debug_is_the_message() {
    let failure = MetricsFailure {
        error: SimError::TooManySteps { t: 2.0 },
        partial: RunMetrics {
            t: 2.0,
            max_normal_force: 10.0,
            min_normal_force: 1.0,
            first_lift_off: None,
            max_residual: 0.0,
            energy_drift: 0.0,
            energy_scale: 1.0,
            points: 3,
            stats: Stats::default(),
        },
    };
    assert_eq!(
        printed_by_main(Box::new(failure)),
        "simulation stopped at t = 2 s: at t = 2 s the step budget of one call was exhausted"
    );
}
