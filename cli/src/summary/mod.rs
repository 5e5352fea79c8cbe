//! The short table printed after each run.
//!
//! It gives the range and max |·| of every coordinate, the range of each contact's position,
//! normal force, pressure angle and sliding speed, each drive's load, max |h|, where each
//! contact's pressure angle is largest (in degrees, with the cam's angle there), how well `energy + dissipated − driven
//! work` stayed constant, the integrator's work (steps, rejected steps, right-hand sides,
//! re-partitions) and the wall time, and warns when a normal force becomes negative: a
//! real, one-sided follower would lift off the cam there.
//!
//! Everything it says of the samples comes from a [`Digest`], which takes them in one at a
//! time as the run computes them: a run's summary costs memory that does not grow with its
//! length.

mod digest;
#[cfg(test)]
mod legacy;
#[cfg(test)]
mod tests;

pub use digest::Digest;

use camchain_runtime::assembly::{AssemblyReport, ChangeCause, RootChoice};
use camchain_runtime::events::{ContactEvent, EventKind};
use camchain_runtime::{
    ContactInfo, Flank, IntegratorKind, JointKind, ModelInfo, ProfileKind, SimSettings, Stats,
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
    /// What the summary needs of the run's samples, taken in as they were computed.
    pub digest: &'a Digest,
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

/// The unit of a coordinate (the joint kind's, from the registry).
pub fn unit(kind: JointKind) -> &'static str {
    kind.unit()
}

/// The unit of the load a drive exerts on a coordinate.
pub(crate) fn drive_unit(kind: JointKind) -> &'static str {
    kind.spec().load_unit
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

fn settings_text(settings: &SimSettings) -> String {
    let name = settings.integrator.name();
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

/// What a contact is, in words: `roller on a polar profile turned by cam_angle`.
pub fn contact_kind(info: &ModelInfo, contact: &ContactInfo) -> String {
    // A roller on a surface is a ball.
    let follower = match (contact.follower, contact.profile) {
        (
            camchain_runtime::kinds::FollowerKind::Roller,
            ProfileKind::Surface | ProfileKind::Revolution,
        ) => "ball",
        _ => contact.follower.label(),
    };
    let profile = match contact.profile {
        ProfileKind::Explicit => "an explicit profile y = f(x)",
        ProfileKind::Polar => "a polar profile r(θ)",
        ProfileKind::Parametric => "a parametric profile (x(s), y(s))",
        ProfileKind::Surface => "a surface z = f(x, y)",
        ProfileKind::Barrel => "a barrel cam's groove z = g(θ)",
        ProfileKind::Revolution => "a surface of revolution r = g(z)",
        ProfileKind::Face => "a face cam's groove",
    };
    let turned = contact
        .cam_coordinate
        .and_then(|i| info.coordinates.get(i))
        .map_or_else(String::new, |c| format!(" turned by {}", c.name));
    let on = match contact.profile {
        ProfileKind::Face => "in",
        ProfileKind::Explicit
        | ProfileKind::Polar
        | ProfileKind::Parametric
        | ProfileKind::Surface
        | ProfileKind::Barrel
        | ProfileKind::Revolution => "on",
    };
    format!("{follower} {on} {profile}{turned}")
}

/// One line per contact: its kind and where its pressure angle is largest (degrees, the
/// designer's unit), over the samples in contact; a fixed cam drives nothing, and its line
/// says that the pressure angle is not defined.
fn contact_lines(info: &ModelInfo, digest: &Digest) -> Vec<String> {
    let mut lines = Vec::new();
    for (k, contact) in info.contacts.iter().enumerate() {
        let mut line = format!("{}: {}", contact.name, contact_kind(info, contact));
        if !contact.cam_moves {
            line.push_str(
                "; the cam is fixed: it drives no follower, so no pressure angle is defined",
            );
        } else if let Some(steepest) = digest.steepest(k) {
            let _ = write!(
                line,
                "; largest pressure angle {:.2}° at t = {} s",
                steepest.angle.to_degrees(),
                number(steepest.t)
            );
            if let Some(cam_angle) = steepest.cam_angle {
                let _ = write!(
                    line,
                    " (cam angle {:.1}°)",
                    cam_angle.to_degrees().rem_euclid(360.0)
                );
            }
        }
        lines.push(line);
    }
    lines
}

/// `generated code, k3 = 60, swing = 0.3`: the path and the run-time parameters whose values
/// differ from the model file's.
pub fn with_changed_parameters(path: &str, model: &dyn camchain_runtime::Dynamics) -> String {
    let changed: Vec<String> = model
        .info()
        .parameters
        .iter()
        .zip(model.parameter_values())
        .filter(|(p, v)| p.default != **v)
        .map(|(p, v)| format!("{} = {v}", p.name))
        .collect();
    if changed.is_empty() {
        path.to_string()
    } else {
        format!("{path} with {}", changed.join(", "))
    }
}

/// The summary text (several lines, each ending in a newline).
pub fn render(report: &RunReport) -> String {
    let RunReport {
        label,
        engine,
        info,
        settings,
        digest,
        events,
        stats,
        wall,
    } = report;
    let mut text = String::new();
    let span = match digest.span() {
        Some((first, last)) => format!(
            "t = {first} to {last} s, {}",
            crate::counted(digest.count(), "sample")
        ),
        None => "no samples".into(),
    };
    let _ = writeln!(
        text,
        "{label} — {engine}, {}, {span}",
        settings_text(settings)
    );
    if digest.count() > 0 {
        let rows = digest.rows();
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
        for line in contact_lines(info, digest) {
            let _ = writeln!(text, "  {line}");
        }
        let mut checks = Vec::new();
        for (k, name) in info.contacts.iter().map(|c| &c.name).enumerate() {
            // In flight (one-sided contact, no dependent coordinate) h is the gap, not a
            // residual.
            checks.push(format!("max |{name}_h| {:.2e} m", digest.max_h(k)));
        }
        if info.loops.len() > LISTED_LOOPS {
            let max_h = digest.loop_h().first().copied().unwrap_or(0.0);
            checks.push(format!(
                "max |h| of the {} loops {max_h:.2e}",
                info.loops.len()
            ));
        } else {
            for (l, max_h) in info.loops.iter().zip(digest.loop_h()) {
                checks.push(format!("max |{}_h| {max_h:.2e}", l.name));
            }
        }
        let (drift, scale) = (digest.energy_drift(), digest.energy_scale());
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
    text.push_str(&render_repartitions(info, digest));
    if !events.is_empty() || settings.integrator.is_adaptive() {
        text.push_str(&render_events(info, events));
        return text;
    }
    // RK4 runs locate no events: the sign change is interpolated between outputs.
    for (k, name) in info.contacts.iter().map(|c| &c.name).enumerate() {
        match digest.lift_offs().get(k).copied().flatten() {
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
pub fn render_repartitions(info: &ModelInfo, digest: &Digest) -> String {
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
    // events, not re-partitions (the digest counts only changes between samples in contact).
    let (listed, count) = digest.repartitions();
    let mut text = String::new();
    for change in listed {
        let (a, b) = change.between;
        let _ = writeln!(
            text,
            "  re-partitioned between t = {} and {} s: {} now independent, {} dependent",
            number(a),
            number(b),
            names(&change.from, &change.to),
            names(&change.to, &change.from)
        );
    }
    if count > LISTED_EVENTS {
        let _ = writeln!(
            text,
            "  … and {} more re-partitions between outputs",
            count - LISTED_EVENTS
        );
    }
    text
}

/// Most loops whose reactions and residuals the summary lists one by one.
pub const LISTED_LOOPS: usize = 6;

/// Most events listed one by one in the summary.
pub const LISTED_EVENTS: usize = 8;

/// One line per contact event (the first [`LISTED_EVENTS`], then a count).
fn render_events(info: &ModelInfo, events: &[ContactEvent]) -> String {
    let mut text = String::new();
    for event in events.iter().take(LISTED_EVENTS) {
        let name = info
            .contacts
            .get(event.contact)
            .map_or("?", |c| c.name.as_str());
        // A barrel or face cam's groove holds its roller both ways: a sign change of the
        // normal force is the roller changing flanks.
        let groove = info
            .contacts
            .get(event.contact)
            .and_then(|c| match c.profile {
                ProfileKind::Barrel => Some(("upper", "lower")),
                ProfileKind::Face => Some(("outer", "inner")),
                ProfileKind::Explicit
                | ProfileKind::Polar
                | ProfileKind::Parametric
                | ProfileKind::Surface
                | ProfileKind::Revolution => None,
            });
        // A groove with backlash: which flank the roller leaves or lands on.
        let flank = match (event.flank, groove) {
            (Some(Flank::Inner), Some((_, own))) => format!(" the groove's {own} flank"),
            (Some(Flank::Outer), Some((other, _))) => format!(" the groove's {other} flank"),
            _ => " the cam".to_string(),
        };
        let what = match (event.kind, groove) {
            (EventKind::ForceBecameNegative, Some((other, own))) => format!(
                "{name} changes flanks: the groove's {other} flank takes over (a follower on the \
                 {own} flank alone would lift off here)"
            ),
            (EventKind::ForceBecamePositive, Some((_, own))) => {
                format!("{name} changes flanks: back on the groove's {own} flank")
            }
            (EventKind::ForceBecameNegative, None) => format!(
                "warning: the normal force on {name} becomes negative: a one-sided follower \
                 would lift off the cam here"
            ),
            (EventKind::ForceBecamePositive, None) => {
                format!("the normal force on {name} becomes positive again")
            }
            (EventKind::LiftOff, _) => format!("{name} lifts off{flank}"),
            (
                EventKind::Impact {
                    normal_velocity,
                    rebound,
                    stays,
                    loss,
                },
                _,
            ) => format!(
                "{name} lands{} at {:.3e} m/s, {}; impact loss {loss:.2e} J",
                match event.flank {
                    Some(_) => format!(" on{flank}"),
                    None => String::new(),
                },
                -normal_velocity,
                if stays {
                    format!("stays on{flank}")
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
    // What assembly solved for: the contacts' points onto their cams, the loops closed.
    let purpose = match (info.n_contacts(), info.loops.len()) {
        (0, _) => "to close the loops",
        (1, 0) => "to put the contact point on its cam",
        (_, 0) => "to put the contact points on their cams",
        _ => "to put the contact points on their cams and close the loops",
    };
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
                    JointKind::Revolute => MOVED_ANGLE,
                    JointKind::Prismatic => MOVED_LENGTH * length_scale,
                };
                ((c.to - c.from).abs() > limit).then(|| {
                    format!(
                        "{field} = {from} had to move to {to} {} (by {}) {purpose}: check \
                         the guess and initial.hold",
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
pub fn result_warnings(info: &ModelInfo, digest: &Digest, one_sided: bool) -> Vec<String> {
    let mut out = Vec::new();
    if digest.count() == 0 || one_sided {
        return out;
    }
    for (k, contact) in info.contacts.iter().enumerate() {
        let name = &contact.name;
        let (negative, in_contact) = digest.negative_share(k);
        let share = negative as f64 / in_contact.max(1) as f64;
        let at_start = digest.negative_at_start(k);
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
        ProfileKind::Surface => {
            "the cam lies below its surface, z < f(x, y) in its frame, and pushes towards +z"
        }
        ProfileKind::Barrel => {
            "the groove's lower flank pushes towards +z; its upper flank pulls (a groove holds \
             the follower both ways)"
        }
        ProfileKind::Revolution => {
            "the cam is the region r < g(z) about its axis and pushes outwards"
        }
        ProfileKind::Face => {
            "the groove's inner flank pushes outwards; its outer flank pulls (a groove holds \
             the follower both ways)"
        }
        ProfileKind::Parametric => {
            "the cam lies on the left of its curve as s increases (inside a curve traced \
             counterclockwise) and pushes to the right"
        }
    }
}
