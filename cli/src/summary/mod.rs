//! The short table printed after each run.
//!
//! It gives the range and max |·| of every coordinate, the range of each contact's position,
//! normal force, pressure angle and sliding speed, each drive's load, max |h|, where each
//! contact's pressure angle is largest (in degrees, with the cam's angle there), how well `energy + dissipated − driven
//! work` stayed constant, the integrator's work (steps, rejected steps, right-hand sides,
//! re-partitions) and the wall time, and warns when a normal force becomes negative: a
//! real, one-sided follower would lift off the cam there.

use super::args::integrator_name;
use camchain_runtime::assembly::{AssemblyReport, ChangeCause, RootChoice};
use camchain_runtime::events::{ContactEvent, EventKind};
use camchain_runtime::{
    ContactInfo, CoordinateKind, FollowerKind, IntegratorKind, ModelInfo, ProfileKind, Sample,
    SimSettings, Stats,
};
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

fn settings_text(settings: &SimSettings) -> String {
    let name = integrator_name(settings.integrator);
    match settings.integrator {
        IntegratorKind::Rk4 => match settings.rk4_landing_step() {
            None => format!("{name} (dt {} s)", settings.dt),
            Some((steps, last)) => format!(
                "{name} (dt {} s; each {} s output interval takes {steps} steps, the last \
                 shortened to {} s)",
                settings.dt,
                settings.dt_out,
                // 12 significant digits: 0.001, not 0.0009999999999999992.
                format!("{:.12e}", last).parse::<f64>().unwrap_or(last)
            ),
        },
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

/// What a contact is, in words: `roller on a polar profile turned by cam_angle`.
pub fn contact_kind(info: &ModelInfo, contact: &ContactInfo) -> String {
    let follower = match contact.follower {
        FollowerKind::Knife => "knife edge",
        FollowerKind::Roller => "roller",
        FollowerKind::Flat => "flat face",
    };
    let profile = match contact.profile {
        ProfileKind::Explicit => "an explicit profile y = f(x)",
        ProfileKind::Polar => "a polar profile r(θ)",
        ProfileKind::Parametric => "a parametric profile (x(s), y(s))",
    };
    let turned = contact
        .cam_coordinate
        .and_then(|i| info.coordinates.get(i))
        .map_or_else(String::new, |c| format!(" turned by {}", c.name));
    format!("{follower} on {profile}{turned}")
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

/// Most loops whose reactions and residuals the summary lists one by one.
const LISTED_LOOPS: usize = 6;

/// Most events listed one by one in the summary.
const LISTED_EVENTS: usize = 8;

/// One line per contact event (the first [`LISTED_EVENTS`], then a count).
fn render_events(info: &ModelInfo, events: &[ContactEvent]) -> String {
    let mut text = String::new();
    for event in events.iter().take(LISTED_EVENTS) {
        let name = info
            .contacts
            .get(event.contact)
            .map_or("?", |c| c.name.as_str());
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

/// The line saying what assembly changed in the model's initial guess, e.g.
/// `assembled: q3 0 → −0.07747 (the root of h nearest the guess); q1_dot …` (empty when it
/// changed nothing).
pub fn assembly(info: &ModelInfo, report: &AssemblyReport) -> String {
    let redundant = if report.redundant.is_empty() {
        String::new()
    } else {
        format!(
            "redundant constraint equations left out (implied by the others; their reactions \
             are carried by the rest): {}\n",
            report.redundant.join(", ")
        )
    };
    if report.changes.is_empty() {
        return redundant;
    }
    let parts: Vec<String> = report
        .changes
        .iter()
        .map(|c| {
            let coordinate = &info.coordinates[c.coordinate].name;
            let name = if c.velocity {
                format!("{coordinate}_dot")
            } else {
                coordinate.clone()
            };
            let how = match (c.cause, c.velocity) {
                (ChangeCause::Drive, _) => " (set by its drive)",
                (ChangeCause::Constraint, true) => " (from J q̇ = 0)",
                (ChangeCause::Constraint, false) => match report.root {
                    RootChoice::Nearest { .. } => " (the root of h nearest the guess)",
                    RootChoice::Newton { scanned: true } => {
                        " (Newton: no root found by a scan around the guess)"
                    }
                    RootChoice::Newton { scanned: false } => " (Newton from the guess)",
                    RootChoice::AtGuess | RootChoice::NoContact => "",
                },
            };
            format!("{name} {} → {}{how}", number(c.from), number(c.to))
        })
        .collect();
    format!("{redundant}assembled: {}\n", parts.join("; "))
}

/// A solved angle that moved this far from a value the model file gave (rad) is reported.
const MOVED_ANGLE: f64 = 0.5;

/// A solved displacement that moved this fraction of the model's length scale (its largest
/// contact-point coordinate) from a value the file gave is reported.
const MOVED_LENGTH: f64 = 0.5;

/// Warnings about values the model file gave that assembly had to override or move far.
pub fn assembly_warnings(
    info: &ModelInfo,
    report: &AssemblyReport,
    length_scale: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    for c in report.changes.iter().filter(|c| c.given) {
        let coordinate = &info.coordinates[c.coordinate];
        let field = if c.velocity {
            format!("initial.qd[{:?}]", coordinate.name)
        } else {
            format!("initial.q[{:?}]", coordinate.name)
        };
        let (from, to) = (number(c.from), number(c.to));
        let warning = match c.cause {
            ChangeCause::Drive => Some(format!(
                "{field} = {from} is overridden by the drive of {}: {to} at t = 0",
                coordinate.name
            )),
            ChangeCause::Constraint if c.velocity => Some(format!(
                "{field} = {from} is replaced by {to}: the velocity of a solved coordinate \
                 follows from the others (J q̇ = 0)"
            )),
            ChangeCause::Constraint => {
                let limit = match coordinate.kind {
                    CoordinateKind::Revolute => MOVED_ANGLE,
                    CoordinateKind::Prismatic => MOVED_LENGTH * length_scale,
                };
                ((c.to - c.from).abs() > limit).then(|| {
                    format!(
                        "{field} = {from} had to move to {to} {} (by {}) to put the contact \
                         point on its cam: check the guess and initial.hold",
                        unit(coordinate.kind),
                        number(c.to - c.from)
                    )
                })
            }
        };
        out.extend(warning);
    }
    out
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

/// Where a profile kind's material is, for the warning about a pulling cam.
fn material_side(profile: ProfileKind) -> &'static str {
    match profile {
        ProfileKind::Explicit => {
            "the cam lies on the side y < f(x) of its frame and pushes towards +y"
        }
        ProfileKind::Polar => "the cam is the region r < r(θ) of its frame and pushes outwards",
        ProfileKind::Parametric => {
            "the cam lies on the left of its curve as s increases (inside a curve traced \
             counterclockwise) and pushes to the right"
        }
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
            in_contact: vec![true],
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

    /// A driven eccentric with one-sided contact: `cam_angle` driven, `lift` dependent in
    /// contact and free in flight.
    fn one_sided_info(cam_moves: bool) -> ModelInfo {
        let coordinate = |name: &str, driven| camchain_runtime::CoordinateInfo {
            name: name.into(),
            kind: camchain_runtime::CoordinateKind::Revolute,
            driven,
        };
        let mut contact = camchain_runtime::ContactInfo::knife("face");
        contact.cam_moves = cam_moves;
        ModelInfo {
            name: "m".into(),
            description: String::new(),
            coordinates: vec![coordinate("cam_angle", true), coordinate("lift", false)],
            contacts: vec![contact],
            loops: Vec::new(),
            spatial: false,
            initial: camchain_runtime::InitialGuess {
                q: vec![0.0; 2],
                qd: vec![0.0; 2],
                hold: vec![false; 2],
                given_q: vec![false; 2],
                given_qd: vec![false; 2],
            },
            defaults: SimSettings {
                t_end: 1.0,
                dt_out: 0.1,
                integrator: IntegratorKind::Dop853,
                dt: 1e-3,
                rtol: 1e-9,
                atol: 1e-12,
            },
            restitution: None,
            parameters: Vec::new(),
        }
    }

    /// A sample of the one-sided eccentric at t: in contact (lift dependent) or flying.
    fn phase_sample(t: f64, force: f64, flying: bool) -> Sample {
        let mut s = sample(t, force);
        s.q = vec![0.0, 0.0];
        s.qd = vec![0.0, 0.0];
        s.dependent = if flying { vec![] } else { vec![1] }.into();
        s.in_contact = vec![!flying];
        s
    }

    #[test]
    fn a_one_sided_run_is_summarised_honestly() {
        // Issue 24: take-offs and landings were listed as re-partitions with a blank name,
        // the pressure angle was taken over flight samples and the cam was said to pull.
        let info = one_sided_info(true);
        let samples = [
            phase_sample(0.0, -0.07, false),
            phase_sample(0.1, 0.0, true),
            phase_sample(0.2, 12.0, false),
            phase_sample(0.3, 0.0, true),
        ];
        assert_eq!(render_repartitions(&info, &samples), "");
        assert!(result_warnings(&info, &samples, true).is_empty());
        // The same samples of a bilateral run that starts pulling are warned about.
        assert_eq!(result_warnings(&info, &samples, false).len(), 1);
        // A real re-partition between two samples in contact is still listed, by name.
        let mut moved = phase_sample(0.4, 10.0, false);
        moved.dependent = vec![0].into();
        let text = render_repartitions(&info, &[phase_sample(0.3, 10.0, false), moved]);
        assert!(
            text.contains("lift now independent, cam_angle dependent"),
            "{text}"
        );
    }

    #[test]
    fn a_fixed_cam_has_no_pressure_angle() {
        let samples = [phase_sample(0.0, 5.0, false), phase_sample(0.1, 6.0, false)];
        let fixed = contact_lines(&one_sided_info(false), &samples).join("\n");
        assert!(fixed.contains("no pressure angle is defined"), "{fixed}");
        let names: Vec<String> = rows(&one_sided_info(false), &samples)
            .into_iter()
            .map(|r| r.0)
            .collect();
        assert!(
            !names.iter().any(|n| n.contains("pressure_angle")),
            "{names:?}"
        );
        let moving = contact_lines(&one_sided_info(true), &samples).join("\n");
        assert!(moving.contains("largest pressure angle"), "{moving}");
    }

    #[test]
    fn numbers_are_compact() {
        assert_eq!(number(0.0), "0");
        assert_eq!(number(-1.5), "-1.500000");
        assert_eq!(number(6.94e-17), "6.940e-17");
    }
}
