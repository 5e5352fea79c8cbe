//! The summary as it was rendered from the whole trajectory before issue 25, kept verbatim
//! (but for its imports and names) as the oracle of the tests: the summary from a
//! [`super::Digest`] must be the same text, to the byte.

use super::{
    LISTED_EVENTS, LISTED_LOOPS, LiftOff, contact_kind, drive_unit, material_side, number,
    render_events, settings_text, unit, wall_time,
};
use camchain_runtime::events::ContactEvent;
use camchain_runtime::{ModelInfo, Sample, SimSettings, Stats};
use std::fmt::Write;
use std::time::Duration;

/// What the old summary described: a `RunReport` with the samples instead of a digest.
pub struct SliceReport<'a> {
    pub label: &'a str,
    pub engine: &'a str,
    pub info: &'a ModelInfo,
    pub settings: &'a SimSettings,
    pub samples: &'a [Sample],
    pub events: &'a [ContactEvent],
    pub stats: Stats,
    pub wall: Duration,
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

fn range(samples: &[Sample], value: impl Fn(&Sample) -> f64) -> (f64, f64) {
    samples
        .iter()
        .map(value)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// Contact k is closed in the sample (always in a bilateral run; not while a one-sided
/// follower flies).
fn touching(sample: &Sample, k: usize) -> bool {
    sample.in_contact.get(k).copied().unwrap_or(true)
}

/// The range of `value` over the samples where contact k is closed; `None` if there is none.
fn range_in_contact(
    samples: &[Sample],
    k: usize,
    value: impl Fn(&Sample) -> f64,
) -> Option<(f64, f64)> {
    let closed: Vec<f64> = samples
        .iter()
        .filter(|s| touching(s, k))
        .map(value)
        .collect();
    (!closed.is_empty()).then(|| {
        closed
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            })
    })
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
    for (k, contact) in info.contacts.iter().enumerate() {
        let name = &contact.name;
        for (a, axis) in axes.iter().enumerate() {
            let (lo, hi) = range(samples, |s| s.contacts[k].position[a]);
            rows.push((format!("{name}_{axis} [m]"), lo, hi));
        }
        let (lo, hi) = range(samples, |s| s.normal_force[k]);
        rows.push((format!("{name}_normal_force [N]"), lo, hi));
        // In contact only: a flying follower has no pressure angle or sliding speed, and a
        // fixed cam drives nothing (no pressure angle either).
        let angle = |s: &Sample| s.contacts[k].pressure_angle();
        if let Some((lo, hi)) = range_in_contact(samples, k, angle).filter(|_| contact.cam_moves) {
            rows.push((format!("{name}_pressure_angle [rad]"), lo, hi));
        }
        if let Some((lo, hi)) = range_in_contact(samples, k, |s| s.contacts[k].sliding_speed) {
            rows.push((format!("{name}_sliding_speed [m/s]"), lo, hi));
        }
    }
    // Each loop's reactions, unless there are too many loops to list (an N-four-bar): then
    // the largest reaction over all of them.
    if info.loops.len() > LISTED_LOOPS {
        let (lo, hi) = range(samples, |s| {
            s.lambda
                .iter()
                .skip(info.n_contacts())
                .fold(0.0_f64, |m, l| m.max(l.abs()))
        });
        rows.push((
            format!("largest loop reaction, {} loops [N]", info.loops.len()),
            lo,
            hi,
        ));
    }
    for (first, l) in info
        .loop_rows()
        .take_while(|_| info.loops.len() <= LISTED_LOOPS)
    {
        for (e, equation) in l.equations.iter().enumerate() {
            let unit = if equation.starts_with("turn") || equation.starts_with("tilt") {
                "N m"
            } else {
                "N"
            };
            let (lo, hi) = range(samples, |s| {
                -s.lambda.get(first + e).copied().unwrap_or(f64::NAN)
            });
            rows.push((format!("{}_{equation}_reaction [{unit}]", l.name), lo, hi));
        }
    }
    for (i, c) in info.coordinates.iter().enumerate() {
        if c.driven {
            let (lo, hi) = range(samples, |s| s.drive[i]);
            rows.push((format!("{}_drive [{}]", c.name, drive_unit(c.kind)), lo, hi));
        }
    }
    rows
}

/// One line per contact: its kind and where its pressure angle is largest (degrees, the
/// designer's unit), over the samples in contact; a fixed cam drives nothing, and its line
/// says that the pressure angle is not defined.
fn contact_lines(info: &ModelInfo, samples: &[Sample]) -> Vec<String> {
    let mut lines = Vec::new();
    for (k, contact) in info.contacts.iter().enumerate() {
        let steepest = samples
            .iter()
            .filter(|s| touching(s, k))
            .map(|s| (s, s.contacts[k].pressure_angle().abs()))
            .filter(|(_, a)| a.is_finite())
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let mut line = format!("{}: {}", contact.name, contact_kind(info, contact));
        if !contact.cam_moves {
            line.push_str(
                "; the cam is fixed: it drives no follower, so no pressure angle is defined",
            );
        } else if let Some((s, angle)) = steepest {
            let _ = write!(
                line,
                "; largest pressure angle {:.2}° at t = {} s",
                angle.to_degrees(),
                number(s.t)
            );
            if let Some(i) = contact.cam_coordinate {
                let _ = write!(
                    line,
                    " (cam angle {:.1}°)",
                    s.q[i].to_degrees().rem_euclid(360.0)
                );
            }
        }
        lines.push(line);
    }
    lines
}

/// The scale the energy drift is measured against: the largest kinetic energy plus the
/// range of the potential energy over the run (the energy that moves around; the total
/// itself has an arbitrary zero).
pub fn energy_scale(samples: &[Sample]) -> f64 {
    let kinetic = samples.iter().map(|s| s.energy.kinetic).fold(0.0, f64::max);
    let potential = |s: &Sample| s.energy.gravity + s.energy.spring;
    let (lo, hi) = range(samples, potential);
    kinetic + (hi - lo).max(0.0)
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
pub fn render(report: &SliceReport) -> String {
    let SliceReport {
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
        (Some(a), Some(b)) => format!(
            "t = {} to {} s, {}",
            a.t,
            b.t,
            crate::counted(samples.len(), "sample")
        ),
        _ => "no samples".into(),
    };
    let _ = writeln!(
        text,
        "{label} — {engine}, {}, {span}",
        settings_text(settings)
    );
    if !samples.is_empty() {
        let rows = rows(info, samples);
        // The names' column: 24 characters, wider when a name needs it.
        let width = rows
            .iter()
            .map(|(name, _, _)| name.chars().count() + 2)
            .fold(24, usize::max);
        let _ = writeln!(
            text,
            "  {:<width$}{:>14}{:>14}{:>14}",
            "quantity", "min", "max", "max |·|"
        );
        for (name, lo, hi) in rows {
            let _ = writeln!(
                text,
                "  {name:<width$}{:>14}{:>14}{:>14}",
                number(lo),
                number(hi),
                number(lo.abs().max(hi.abs()))
            );
        }
        for line in contact_lines(info, samples) {
            let _ = writeln!(text, "  {line}");
        }
        let mut checks = Vec::new();
        for (k, name) in info.contacts.iter().map(|c| &c.name).enumerate() {
            // In flight (one-sided contact, no dependent coordinate) h is the gap, not a
            // residual.
            let max_h = samples
                .iter()
                .filter(|s| !s.dependent.is_empty())
                .map(|s| s.h[k].abs())
                .fold(0.0, f64::max);
            checks.push(format!("max |{name}_h| {max_h:.2e} m"));
        }
        if info.loops.len() > LISTED_LOOPS {
            let max_h = samples
                .iter()
                .flat_map(|s| s.h.iter().skip(info.n_contacts()))
                .fold(0.0_f64, |m, h| m.max(h.abs()));
            checks.push(format!(
                "max |h| of the {} loops {max_h:.2e}",
                info.loops.len()
            ));
        }
        for (first, l) in info
            .loop_rows()
            .take_while(|_| info.loops.len() <= LISTED_LOOPS)
        {
            let max_h = samples
                .iter()
                .flat_map(|s| s.h.iter().skip(first).take(l.equations.len()))
                .fold(0.0_f64, |m, h| m.max(h.abs()));
            checks.push(format!("max |{}_h| {max_h:.2e}", l.name));
        }
        let (drift, scale) = (energy_drift(samples), energy_scale(samples));
        let relative = if scale > 0.0 {
            format!(
                " ({:.1e} of the energy scale {} J)",
                drift / scale,
                number(scale)
            )
        } else {
            String::new()
        };
        checks.push(format!(
            "energy + dissipated − driven_work constant to {drift:.2e} J{relative}"
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
    text.push_str(&render_repartitions(info, samples));
    if !events.is_empty() || settings.integrator.is_adaptive() {
        text.push_str(&render_events(info, events));
        return text;
    }
    // RK4 runs locate no events: the sign change is interpolated between outputs.
    for (k, name) in info.contacts.iter().map(|c| &c.name).enumerate() {
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

/// The changes of the dependent coordinates seen between consecutive samples, one line each
/// (the first [`LISTED_EVENTS`], then a count): `between t = a and b s: {q2, q3} → {q1, q3}`.
/// Empty when the partition never changed between outputs.
pub fn render_repartitions(info: &ModelInfo, samples: &[Sample]) -> String {
    // What left the dependent set and what joined it (the whole sets of an 80-equation
    // model would fill the screen).
    let names = |from: &[usize], to: &[usize]| -> String {
        let list: Vec<&str> = from
            .iter()
            .filter(|i| !to.contains(i))
            .map(|&i| info.coordinates[i].name.as_str())
            .collect();
        list.join(", ")
    };
    // A one-sided follower's take-off and landing change the dependent set too; they are
    // events, not re-partitions.
    let closed = |s: &Sample| s.in_contact.iter().all(|&c| c);
    let changes: Vec<(f64, f64, String, String)> = samples
        .windows(2)
        .filter(|w| closed(&w[0]) && closed(&w[1]) && w[0].dependent != w[1].dependent)
        .map(|w| {
            let (a, b) = (&w[0].dependent, &w[1].dependent);
            (w[0].t, w[1].t, names(a, b), names(b, a))
        })
        .collect();
    let mut text = String::new();
    for (a, b, left, joined) in changes.iter().take(LISTED_EVENTS) {
        let _ = writeln!(
            text,
            "  re-partitioned between t = {} and {} s: {left} now independent, {joined} dependent",
            number(*a),
            number(*b)
        );
    }
    if changes.len() > LISTED_EVENTS {
        let _ = writeln!(
            text,
            "  … and {} more re-partitions between outputs",
            changes.len() - LISTED_EVENTS
        );
    }
    text
}

/// Warnings about results that are almost surely a modelling mistake: a normal force
/// negative at the start or for most of the run (the cam pulls the follower), over the
/// samples in contact. A one-sided run is not warned about: its follower lifts off where the
/// force would turn negative, as it should.
pub fn result_warnings(info: &ModelInfo, samples: &[Sample], one_sided: bool) -> Vec<String> {
    let mut out = Vec::new();
    let Some(first) = samples.first() else {
        return out;
    };
    if one_sided {
        return out;
    }
    for (k, contact) in info.contacts.iter().enumerate() {
        let name = &contact.name;
        let in_contact: Vec<&Sample> = samples.iter().filter(|s| touching(s, k)).collect();
        let negative = in_contact
            .iter()
            .filter(|s| s.normal_force[k] < 0.0)
            .count();
        let share = negative as f64 / in_contact.len().max(1) as f64;
        let at_start = first.normal_force.get(k).is_some_and(|f| *f < 0.0);
        if at_start || share > 0.5 {
            out.push(format!(
                "the normal force on {name} is negative {} ({:.0} % of the samples): the cam \
                 pulls the follower. Check which side of the profile the material is on: {}",
                if at_start {
                    "from the start"
                } else {
                    "for most of the run"
                },
                100.0 * share,
                material_side(contact.profile)
            ));
        }
    }
    out
}
