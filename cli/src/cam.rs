//! `camchain cam MODEL`: the cam designer's view of a cam designed from its follower's
//! motion law (`law:` in a contact), at its nominal speed ω.
//!
//! 1. The design: segments, circles, follower, turning sense; the follower's peak velocity,
//!    acceleration and jerk at ω, the pressure angle, the radius of curvature, the undercut
//!    margin or the face width, the joints where the motion jumps ([`analysis`]).
//! 2. The dynamics ([`dynamics`]): the contact force over a turn at ω with the follower held
//!    on the cam; for a mechanism without a degree of freedom, the jump speed predicted from
//!    N(θ, ω) = A + Bω + Cω² fitted to three bilateral runs; a one-sided run over several
//!    turns that shows where the follower really lifts off.
//! 3. The files, in `DIR/<model>_cam/`: `svaj`, `pressure_curvature`, `profile` and `force`
//!    (PNG and SVG, [`figures`]) and `design.csv` ([`report`]); with `--table FILE` the
//!    profile as a table of points that a model reads back.
//!
//! Everything that can be checked before a run is checked first (the model, the contact,
//! the speed and how to set it, the output directory and the table's destination), so that
//! a usage error costs no simulation and writes nothing. Every file goes through
//! [`crate::output::write_file`].

/// The design's checks at the nominal speed.
mod analysis;
/// The bilateral turns, the jump speed they predict, the one-sided run.
mod dynamics;
/// The figures.
mod figures;
/// The printed summary and `design.csv`.
mod report;
/// The model, the contact, the speed and how to set it.
mod setup;

use crate::CliError;
use crate::args::CamArgs;
use crate::output;
use analysis::Analysis;
use dynamics::{OneSided, Prediction, Probe, Turn};
use setup::SpeedControl;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Prints on standard output without panicking when the reader has gone (`| head`).
fn say(text: &str) {
    let _ = std::io::stdout().write_all(text.as_bytes());
}

/// Runs the `cam` command.
pub fn run(args: &CamArgs) -> Result<(), CliError> {
    let subject = setup::load(&args.model)?;
    let model = &subject.model;
    let index = setup::pick_contact(model, &subject.label, args.contact.as_deref())?;
    let contact = &model.contacts[index];
    let design = contact
        .design
        .as_ref()
        .ok_or_else(|| CliError::Failed(format!("contact `{}` has no design", contact.name)))?;
    let speed = setup::nominal_speed(design, args.speed, &contact.name)?;
    let control = SpeedControl::new(model, design, &contact.name)?;
    // The model at the nominal speed: a value its checks refuse is the user's (--speed) or
    // the file's.
    let value = control.value_for(speed).map_err(CliError::Failed)?;
    let nominal = subject.build(&control, value).map_err(|e| {
        let message = format!(
            "the model at {speed} rad/s ({} = {value}): {e}",
            control.describe()
        );
        if args.speed.is_some() {
            CliError::Usage(format!("--speed {speed}: {message}"))
        } else {
            CliError::Failed(message)
        }
    })?;
    let info = nominal.info();
    let runtime_contact = info.contact_index(&contact.name).ok_or_else(|| {
        CliError::Failed(format!(
            "the runtime's model has no contact `{}`",
            contact.name
        ))
    })?;
    let follower = model
        .markers
        .get(contact.marker)
        .and_then(|m| model.bodies.get(m.body))
        .and_then(|b| info.coordinate_index(&b.joint.coordinate));
    let probe = Probe {
        contact: runtime_contact,
        cam: info.contacts[runtime_contact].cam_coordinate,
        sigma: design.senses.turning,
        follower,
    };
    dynamics::check_drive(nominal.as_ref(), &probe, speed)
        .map_err(|e| CliError::Failed(format!("{}: {e}", subject.label)))?;
    let designed = model.contacts.iter().filter(|c| c.design.is_some()).count();
    let dir = args.out.join(if designed > 1 {
        format!("{}_{}_cam", subject.label, contact.name)
    } else {
        format!("{}_cam", subject.label)
    });
    let _table_lock = match &args.table {
        Some(table) => output::claim(table).map_err(CliError::Failed)?,
        None => None,
    };
    // Held until the report's files are written.
    let _lock = output::create_dir(&dir).map_err(CliError::Failed)?;
    for warning in &subject.warnings {
        eprintln!("warning: {}: {warning}", subject.label);
    }

    let analysis = Analysis::new(design, speed, args.samples);
    let source = match args.speed {
        Some(_) => format!("--speed, set through {}", control.describe()),
        None => format!("the law's speed, through {}", control.describe()),
    };
    say(&format!(
        "{}: cam of contact `{}` designed from a motion law\n{}",
        subject.label,
        contact.name,
        report::design_summary(design, &analysis, args.samples, &source)
    ));

    let dof = dynamics::degrees_of_freedom(nominal.as_ref());
    let restitution = args.restitution.or(info.restitution).unwrap_or(0.0);
    let n = args.samples;
    let speeds: Vec<f64> = if dof == 0 {
        vec![0.5 * speed, speed, 2.0 * speed]
    } else {
        vec![speed]
    };
    if subject.numeric {
        eprintln!(
            "note: {} runs on the numeric recursive reference (a model file): {} runs of {} \
             outputs a turn take seconds where a built-in model's generated code takes a \
             fraction of one; fewer --samples run faster",
            subject.label,
            speeds.len() + 1,
            n
        );
    }
    let one_sided_samples = args.turns.saturating_mul(n);
    if one_sided_samples > crate::args::MAX_CAM_SAMPLES {
        return Err(CliError::Usage(format!(
            "--turns {} × --samples {n} = {one_sided_samples} samples in the one-sided run, more \
             than {}: fewer turns or samples",
            args.turns,
            crate::args::MAX_CAM_SAMPLES
        )));
    }
    let (turns, one_sided) = rayon::join(
        || {
            use rayon::prelude::*;
            speeds
                .par_iter()
                .map(|&w| dynamics::bilateral_turn(&subject, &control, &probe, w, n))
                .collect::<Vec<Result<Turn, String>>>()
        },
        || {
            if info.n_contacts() == 1 {
                dynamics::one_sided(&nominal, &probe, speed, args.turns, n, restitution)
            } else {
                Err(format!(
                    "skipped: one-sided contact needs a model with exactly one contact, and {} \
                     has {}",
                    subject.label,
                    info.n_contacts()
                ))
            }
        },
    );
    let turns: Vec<Turn> = turns
        .into_iter()
        .collect::<Result<_, _>>()
        .map_err(|e| CliError::Failed(format!("{}: {e}", subject.label)))?;
    let prediction = match turns.as_slice() {
        [a, b, c] => Some(Prediction::new([a, b, c])),
        _ => None,
    };
    let nominal_turn = turns
        .get(turns.len() / 2)
        .ok_or_else(|| CliError::Failed("no bilateral run".into()))?;
    let unit = report::units(design)[1];
    let all: Vec<&Turn> = turns.iter().collect();
    say(&report::dynamics_summary(
        subject.engine(),
        dof,
        &all,
        prediction.as_ref(),
        &format!("`{}`", control.name),
        &one_sided,
        unit,
    ));
    let written = write_outputs(&Outputs {
        dir: &dir,
        name: &subject.label,
        contact: &contact.name,
        designed,
        design,
        analysis: &analysis,
        nominal: nominal_turn,
        prediction: prediction.as_ref(),
        one_sided: one_sided.as_ref().ok(),
        probe: &probe,
        table: args.table.as_deref().map(|t| (t, args.points)),
    });
    let written = written.map_err(CliError::Failed)?;
    say(&format!("  wrote {}\n", output::list_files(&written)));
    match one_sided {
        Err(why) if info.n_contacts() == 1 => {
            Err(CliError::Failed(format!("{}: {why}", subject.label)))
        }
        _ => Ok(()),
    }
}

/// What the files are made of.
struct Outputs<'a> {
    dir: &'a Path,
    name: &'a str,
    contact: &'a str,
    designed: usize,
    design: &'a camchain_codegen::design::CamDesign,
    analysis: &'a Analysis,
    nominal: &'a Turn,
    prediction: Option<&'a Prediction>,
    one_sided: Option<&'a OneSided>,
    probe: &'a Probe,
    table: Option<(&'a Path, usize)>,
}

/// Writes the figures, `design.csv` and the table; returns their paths.
fn write_outputs(o: &Outputs) -> Result<Vec<PathBuf>, String> {
    let name = if o.designed > 1 {
        format!("{} `{}`", o.name, o.contact)
    } else {
        o.name.to_string()
    };
    let one_sided_force: Vec<(f64, f64, f64)> = o
        .one_sided
        .map(|run| {
            run.trajectory
                .samples
                .iter()
                .map(|s| {
                    (
                        s.t,
                        o.probe.angle(o.analysis.speed, s.t, &s.q),
                        s.normal_force
                            .get(o.probe.contact)
                            .copied()
                            .unwrap_or(f64::NAN),
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    let figures = [
        (figures::svaj(&name, o.design, o.analysis), "svaj"),
        (
            figures::pressure_curvature(&name, o.design, o.analysis),
            "pressure_curvature",
        ),
        (figures::profile(&name, o.design, o.analysis), "profile"),
        (
            figures::force(&figures::ForceView {
                name: &name,
                analysis: o.analysis,
                nominal: o.nominal,
                prediction: o.prediction,
                one_sided: o.one_sided,
                one_sided_force,
            }),
            "force",
        ),
    ];
    let mut written = Vec::new();
    for (figure, stem) in &figures {
        written.extend(figure.save(o.dir, stem).map_err(|e| e.to_string())?);
    }
    let csv = o.dir.join("design.csv");
    output::write_file(&csv, |out| {
        report::write_csv(out, o.analysis, &o.nominal.force)
    })?;
    written.push(csv);
    if let Some((path, points)) = o.table {
        let what = if o.designed > 1 {
            format!(
                "{}'s cam `{}` (camchain cam {} --contact {} --table)",
                o.name, o.contact, o.name, o.contact
            )
        } else {
            format!("{}'s cam (camchain cam {} --table)", o.name, o.name)
        };
        let text = o.design.profile_table(points, &what);
        output::write_bytes(path, text.as_bytes())?;
        written.push(path.to_path_buf());
    }
    Ok(written)
}
