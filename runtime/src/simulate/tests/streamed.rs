//! Runs whose monitor keeps no samples (issue 25): the trajectory holds the last sample and
//! the count, the monitor sees exactly the samples of a run that keeps them, and the
//! output times are held to the streamed runs' cap, not to that of kept samples.

use super::*;
use crate::control::Progress;
use crate::settings::{MAX_SAMPLES, MAX_STREAMED_SAMPLES};

/// A monitor that copies every sample it is shown and keeps none in the run (or all, with
/// `keep`), stopping the run after `stop_after` samples if given.
struct Copying {
    seen: Vec<Sample>,
    keep: bool,
    stop_after: Option<usize>,
}

impl Copying {
    fn new(keep: bool) -> Self {
        Copying {
            seen: Vec::new(),
            keep,
            stop_after: None,
        }
    }
}

impl Monitor for Copying {
    fn sample(&mut self, sample: &Sample) -> Observed {
        self.seen.push(sample.clone());
        if self.stop_after.is_some_and(|n| self.seen.len() >= n) {
            Observed::Break(())
        } else {
            Observed::Continue(())
        }
    }

    fn step(&mut self, _progress: &Progress) -> Observed {
        Observed::Continue(())
    }

    fn keep_samples(&self) -> bool {
        self.keep
    }
}

#[test]
fn a_streamed_run_keeps_only_its_last_sample() {
    // The finding: a run whose samples all went to its monitor (a streamed CSV) still kept
    // every one of them. Both integrator families, with a contact whose forces are watched.
    let arm = Arm::new(true, true).with_spring_damper(5.0, 0.3);
    for integrator in [IntegratorKind::Rk4, IntegratorKind::Dop853] {
        let settings = settings(integrator, 2.0, 0.01, 1e-3, 1e-9);
        let whole = run(&arm, &settings);
        let mut monitor = Copying::new(false);
        let state = arm.assemble(0.0).unwrap();
        let streamed = arm
            .simulate_monitored(state, &settings, ContactLaw::Bilateral, &mut monitor)
            .unwrap();
        assert_eq!(whole.samples.len(), 201);
        assert_eq!(whole.sample_count, 201);
        // The monitor saw every sample of the kept run, bit for bit; the run kept the last.
        assert_eq!(monitor.seen, whole.samples, "{integrator:?}");
        assert_eq!(streamed.samples.len(), 1);
        assert_eq!(streamed.samples.last(), whole.samples.last());
        assert_eq!(streamed.sample_count, 201);
        assert_eq!(streamed.events, whole.events);
        assert_eq!(streamed.stats, whole.stats);
    }
}

#[test]
fn a_failed_streamed_run_keeps_its_last_state_and_count() {
    // As `unreachable_cam_gives_newton_failed_with_time_and_state`: eleven samples, the
    // outputs reached and (DOP853, whose steps shrink onto the failure just before an
    // output time) the last accepted state, which the monitor is not shown.
    let bead = Bead::lifted(0.8);
    let state = bead.assemble(0.0).unwrap();
    for settings in [rk4(1.0, 0.01), dopri(1.0, 1e-8)] {
        let kept = bead.simulate(state.clone(), &settings).unwrap_err();
        let mut monitor = Copying::new(false);
        let streamed = bead
            .simulate_monitored(
                state.clone(),
                &settings,
                ContactLaw::Bilateral,
                &mut monitor,
            )
            .unwrap_err();
        assert_eq!(streamed.error, kept.error);
        assert_eq!(kept.partial.sample_count, 11);
        assert_eq!(streamed.partial.sample_count, 11);
        assert_eq!(streamed.partial.samples.len(), 1);
        assert_eq!(streamed.partial.samples.last(), kept.partial.samples.last());
        let shown = monitor.seen.len();
        assert!(shown == 10 || shown == 11, "{shown}");
        assert_eq!(monitor.seen[..], kept.partial.samples[..shown]);
        assert!(
            streamed.to_string().contains("after 11 samples"),
            "{streamed}"
        );
    }
}

#[test]
fn a_streamed_run_is_not_held_to_the_kept_samples_cap() {
    // Twice the samples a run may keep: refused when kept, accepted when streamed (stopped
    // here by the monitor after three samples, not by the settings' check).
    let arm = Arm::new(true, false);
    let state = arm.assemble(0.0).unwrap();
    let settings = settings(
        IntegratorKind::Dop853,
        2.0 * MAX_SAMPLES * 1e-3,
        1e-3,
        1e-3,
        1e-8,
    );
    let refused = arm.simulate(state.clone(), &settings).unwrap_err();
    assert!(
        matches!(refused.error, SimError::InvalidSettings { ref message }
            if message.contains("t_end/dt_out") && message.contains("a run keeps")),
        "{}",
        refused.error
    );
    let mut monitor = Copying {
        stop_after: Some(3),
        ..Copying::new(false)
    };
    let stopped = arm
        .simulate_monitored(
            state.clone(),
            &settings,
            ContactLaw::Bilateral,
            &mut monitor,
        )
        .unwrap_err();
    assert!(
        matches!(stopped.error, SimError::Interrupted { .. }),
        "{}",
        stopped.error
    );
    assert_eq!(stopped.partial.sample_count, 3);
    // Beyond the streamed cap, a streamed run is refused too.
    let beyond = SimSettings {
        t_end: 2.0 * MAX_STREAMED_SAMPLES * settings.dt_out,
        ..settings.clone()
    };
    let mut monitor = Copying::new(false);
    let refused = arm
        .simulate_monitored(state, &beyond, ContactLaw::Bilateral, &mut monitor)
        .unwrap_err();
    assert!(
        matches!(refused.error, SimError::InvalidSettings { ref message }
            if message.contains("a run streams")),
        "{}",
        refused.error
    );
    assert!(monitor.seen.is_empty());
}

#[test]
fn a_sweep_run_is_not_held_to_the_kept_samples_cap() {
    // The finding: a sweep refused more than a million output times although a metrics run
    // keeps no trajectory. A metrics run of 2e6 output intervals of 1 µs: the run completes.
    let arm = Arm::new(true, false);
    let state = arm.assemble(0.0).unwrap();
    let settings = settings(IntegratorKind::Dop853, 2.0, 1e-6, 1e-3, 1e-8);
    assert!(arm.simulate(state.clone(), &settings).is_err());
    let metrics = arm
        .simulate_metrics(state, &settings, crate::MetricsOptions::default())
        .unwrap();
    assert_eq!(metrics.t, 2.0);
}
