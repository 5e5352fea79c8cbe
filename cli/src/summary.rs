//! The short table printed after each run.
//!
//! It gives the range and max |·| of every coordinate, the range of each contact's position
//! and normal force, each drive's load, max |h|, how well `energy + dissipated − driven
//! work` stayed constant, the integrator's work (steps, rejected steps, right-hand sides,
//! re-partitions) and the wall time, and warns when a normal force becomes negative: a
//! real, one-sided follower would lift off the cam there.

use super::args::integrator_name;
use camchain_runtime::events::{ContactEvent, EventKind};
use camchain_runtime::{CoordinateKind, IntegratorKind, ModelInfo, Sample, SimSettings, Stats};
use std::fmt::Write;
use std::time::Duration;

/// What the summary describes.
pub struct RunReport<'a> {
    /// The run's name.
    pub label: &'a str,
    /// Generated code or numeric reference.
    pub engine: &'a str,
    /// The model.
    pub info: &'a ModelInfo,
    /// The settings used.
    pub settings: &'a SimSettings,
    /// The samples (all of them, or those computed before a failure).
    pub samples: &'a [Sample],
    /// Contact events located during the run (adaptive integrators).
    pub events: &'a [ContactEvent],
    /// The integrator's work.
    pub stats: Stats,
    /// Assembly plus simulation.
    pub wall: Duration,
}

/// The first time a contact's normal force becomes negative, where a one-sided follower
/// would lift off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiftOff {
    /// Estimated crossing time (linear interpolation between the two samples around it).
    pub t: f64,
    /// True when the force is already negative at the first sample.
    pub from_start: bool,
}

/// Where the normal force of contact `k` first turns negative, if it does.
pub fn lift_off(samples: &[Sample], k: usize) -> Option<LiftOff> {
    let force = |s: &Sample| s.normal_force.get(k).copied().unwrap_or(0.0);
    let index = samples.iter().position(|s| force(s) < 0.0)?;
    if index == 0 {
        return Some(LiftOff {
            t: samples[0].t,
            from_start: true,
        });
    }
    let (a, b) = (&samples[index - 1], &samples[index]);
    let (fa, fb) = (force(a), force(b));
    let t = a.t + (b.t - a.t) * fa / (fa - fb);
    Some(LiftOff {
        t,
        from_start: false,
    })
}

/// The unit of a coordinate.
pub fn unit(kind: CoordinateKind) -> &'static str {
    match kind {
        CoordinateKind::Revolute => "rad",
        CoordinateKind::Prismatic => "m",
    }
}

/// The unit of the load a drive exerts on a coordinate.
fn drive_unit(kind: CoordinateKind) -> &'static str {
    match kind {
        CoordinateKind::Revolute => "N m",
        CoordinateKind::Prismatic => "N",
    }
}

/// A number in about 7 significant digits: fixed for ordinary magnitudes, scientific for
/// very small and very large ones.
pub fn number(x: f64) -> String {
    let magnitude = x.abs();
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e6).contains(&magnitude) {
        format!("{x:.6}")
    } else {
        format!("{x:.3e}")
    }
}

fn range(samples: &[Sample], value: impl Fn(&Sample) -> f64) -> (f64, f64) {
    samples
        .iter()
        .map(value)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

fn settings_text(settings: &SimSettings) -> String {
    let name = integrator_name(settings.integrator);
    match settings.integrator {
        IntegratorKind::Rk4 => format!("{name} (dt {} s)", settings.dt),
        IntegratorKind::Dopri5 | IntegratorKind::Dop853 => format!(
            "{name} (rtol {:e}, atol {:e})",
            settings.rtol, settings.atol
        ),
    }
}

/// The table rows (name with unit, min, max, max |·|).
fn rows(info: &ModelInfo, samples: &[Sample]) -> Vec<(String, f64, f64)> {
    let mut rows = Vec::new();
    for (i, c) in info.coordinates.iter().enumerate() {
        let (lo, hi) = range(samples, |s| s.q[i]);
        rows.push((format!("{} [{}]", c.name, unit(c.kind)), lo, hi));
    }
    let axes: &[&str] = if info.spatial {
        &["x", "y", "z"]
    } else {
        &["x", "y"]
    };
    for (k, name) in info.contacts.iter().enumerate() {
        for (a, axis) in axes.iter().enumerate() {
            let (lo, hi) = range(samples, |s| s.contacts[k].position[a]);
            rows.push((format!("{name}_{axis} [m]"), lo, hi));
        }
        let (lo, hi) = range(samples, |s| s.normal_force[k]);
        rows.push((format!("{name}_normal_force [N]"), lo, hi));
    }
    for (i, c) in info.coordinates.iter().enumerate() {
        if c.driven {
            let (lo, hi) = range(samples, |s| s.drive[i]);
            rows.push((format!("{}_drive [{}]", c.name, drive_unit(c.kind)), lo, hi));
        }
    }
    rows
}

/// max over the samples of |(E + D − W)(t) − (E + D − W)(0)|.
pub fn energy_drift(samples: &[Sample]) -> f64 {
    let balance = |s: &Sample| s.energy.total() + s.dissipated - s.driven_work;
    let Some(first) = samples.first().map(balance) else {
        return 0.0;
    };
    samples
        .iter()
        .map(|s| (balance(s) - first).abs())
        .fold(0.0, f64::max)
}

/// The summary text (several lines, each ending in a newline).
pub fn render(report: &RunReport) -> String {
    let RunReport {
        label,
        engine,
        info,
        settings,
        samples,
        events,
        stats,
        wall,
    } = report;
    let mut text = String::new();
    let span = match (samples.first(), samples.last()) {
        (Some(a), Some(b)) => format!("t = {} to {} s, {} samples", a.t, b.t, samples.len()),
        _ => "no samples".into(),
    };
    let _ = writeln!(
        text,
        "{label} — {engine}, {}, {span}",
        settings_text(settings)
    );
    if !samples.is_empty() {
        let _ = writeln!(
            text,
            "  {:<24}{:>14}{:>14}{:>14}",
            "quantity", "min", "max", "max |·|"
        );
        for (name, lo, hi) in rows(info, samples) {
            let _ = writeln!(
                text,
                "  {name:<24}{:>14}{:>14}{:>14}",
                number(lo),
                number(hi),
                number(lo.abs().max(hi.abs()))
            );
        }
        let mut checks = Vec::new();
        for (k, name) in info.contacts.iter().enumerate() {
            // In flight (one-sided contact, no dependent coordinate) h is the gap, not a
            // residual.
            let max_h = samples
                .iter()
                .filter(|s| !s.dependent.is_empty())
                .map(|s| s.h[k].abs())
                .fold(0.0, f64::max);
            checks.push(format!("max |{name}_h| {max_h:.2e} m"));
        }
        checks.push(format!(
            "energy + dissipated − driven_work constant to {:.2e} J",
            energy_drift(samples)
        ));
        let _ = writeln!(text, "  {}", checks.join("; "));
    }
    let _ = writeln!(
        text,
        "  {} steps, {} rejected, {} right-hand sides, {} re-partitions; wall time {}",
        stats.steps,
        stats.rejected,
        stats.rhs_evaluations,
        stats.repartitions,
        wall_time(*wall)
    );
    if !events.is_empty() || settings.integrator.is_adaptive() {
        text.push_str(&render_events(info, events));
        return text;
    }
    // RK4 runs locate no events: the sign change is interpolated between outputs.
    for (k, name) in info.contacts.iter().enumerate() {
        match lift_off(samples, k) {
            Some(l) if l.from_start => {
                let _ = writeln!(
                    text,
                    "  warning: the normal force on {name} is negative from the start: a \
                     one-sided follower would not stay on the cam"
                );
            }
            Some(l) => {
                let _ = writeln!(
                    text,
                    "  warning: the normal force on {name} changes sign at t ≈ {:.4} s: a \
                     one-sided follower would lift off the cam there",
                    l.t
                );
            }
            None => {}
        }
    }
    text
}

/// Most events listed one by one in the summary.
const LISTED_EVENTS: usize = 8;

/// One line per contact event (the first [`LISTED_EVENTS`], then a count).
fn render_events(info: &ModelInfo, events: &[ContactEvent]) -> String {
    let mut text = String::new();
    for event in events.iter().take(LISTED_EVENTS) {
        let name = info.contacts.get(event.contact).map_or("?", String::as_str);
        let what = match event.kind {
            EventKind::ForceBecameNegative => format!(
                "warning: the normal force on {name} becomes negative: a one-sided follower \
                 would lift off the cam here"
            ),
            EventKind::ForceBecamePositive => {
                format!("the normal force on {name} becomes positive again")
            }
            EventKind::LiftOff => format!("{name} lifts off the cam"),
            EventKind::Impact {
                normal_velocity,
                rebound,
                stays,
                loss,
            } => format!(
                "{name} lands at {:.3e} m/s, {}; impact loss {loss:.2e} J",
                -normal_velocity,
                if stays {
                    "stays on the cam".to_string()
                } else {
                    format!("rebounds at {rebound:.3e} m/s")
                }
            ),
        };
        let _ = writeln!(text, "  t = {:.9} s: {what}", event.t);
    }
    if events.len() > LISTED_EVENTS {
        let _ = writeln!(
            text,
            "  … and {} more contact events (the last at t = {:.9} s)",
            events.len() - LISTED_EVENTS,
            events.last().map_or(f64::NAN, |e| e.t)
        );
    }
    text
}

fn wall_time(wall: Duration) -> String {
    let seconds = wall.as_secs_f64();
    if seconds < 1.0 {
        format!("{:.1} ms", seconds * 1e3)
    } else {
        format!("{seconds:.2} s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_runtime::{ContactGeometry, Energy};

    fn sample(t: f64, force: f64) -> Sample {
        Sample {
            t,
            q: vec![0.0],
            qd: vec![0.0],
            qdd: vec![0.0],
            lambda: vec![0.0],
            normal_force: vec![force],
            h: vec![0.0],
            contacts: vec![ContactGeometry::default()],
            drive: vec![0.0],
            energy: Energy::default(),
            dissipated: 0.0,
            driven_work: 0.0,
            dependent: vec![0].into(),
        }
    }

    #[test]
    fn lift_off_is_interpolated() {
        let samples = [sample(0.0, 2.0), sample(1.0, 1.0), sample(2.0, -3.0)];
        let l = lift_off(&samples, 0).unwrap();
        assert!(!l.from_start && (l.t - 1.25).abs() < 1e-15);
        assert!(lift_off(&samples[..2], 0).is_none());
        assert!(lift_off(&samples[2..], 0).unwrap().from_start);
    }

    #[test]
    fn numbers_are_compact() {
        assert_eq!(number(0.0), "0");
        assert_eq!(number(-1.5), "-1.500000");
        assert_eq!(number(6.94e-17), "6.940e-17");
    }
}
