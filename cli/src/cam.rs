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
//!    (PNG and SVG, `figures`) and `design.csv` ([`report`]); with `--table FILE` the
//!    profile as a table of points that a model reads back.
//!
//! Everything that can be checked before a run is checked first (the model, the contact,
//! the speed and how to set it, the output directory and the table's destination), so that
//! a usage error costs no simulation and writes nothing. Every file goes through
//! `output::write_file`.

/// The design's checks at the nominal speed.
pub mod analysis;
/// The bilateral turns, the jump speed they predict, the one-sided run.
pub mod dynamics;
/// The figures.
mod figures;
/// The printed summary and `design.csv`.
pub mod report;
/// The model, the contact, the speed and how to set it.
pub mod setup;

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

/// A cam ready to study: the model, its contact and design, the nominal speed, and the model
/// built to run at it. Cheap to make: no run yet.
pub struct Prepared {
    /// The model.
    pub subject: setup::Subject,
    /// The contact's index among the model's contacts.
    pub index: usize,
    /// The nominal speed ω (rad/s).
    pub speed: f64,
    /// How the cam's speed is set.
    control: SpeedControl,
    /// The model at the nominal speed.
    nominal: setup::Runnable,
    /// Where the runs read the cam and the follower.
    probe: Probe,
    /// How many contacts of the model are designed from a law.
    pub designed: usize,
}

impl Prepared {
    /// The contact's name.
    pub fn contact(&self) -> &str {
        &self.subject.model.contacts[self.index].name
    }

    /// The contact's design.
    pub fn design(&self) -> Option<&camchain_codegen::design::CamDesign> {
        self.subject.model.contacts[self.index].design.as_ref()
    }
}

/// What `camchain cam` computes, before anything is written: the design's analysis at ω, the
/// bilateral turns, the jump speed they predict (for a mechanism without a degree of
/// freedom), the one-sided run.
pub struct Study {
    /// The design at ω: peaks, pressure angle, curvature, the sampled design.
    pub analysis: Analysis,
    /// The bilateral turns (at 0.5ω, ω and 2ω, or at ω alone).
    pub turns: Vec<Turn>,
    /// The jump speed predicted from three turns.
    pub prediction: Option<Prediction>,
    /// The one-sided run, or why it was not made or failed.
    pub one_sided: Result<OneSided, String>,
    /// The design's and the dynamics' summaries, as printed.
    pub text: String,
    /// The model's degrees of freedom in bilateral contact.
    pub dof: usize,
}

impl Study {
    /// The bilateral turn at the nominal speed.
    pub fn nominal(&self) -> Option<&Turn> {
        self.turns.get(self.turns.len() / 2)
    }

    /// `design.csv`'s text: one row per sampled angle.
    pub fn design_csv(&self) -> String {
        let mut out = Vec::new();
        let force = self.nominal().map_or(&[][..], |t| &t.force[..]);
        let _ = report::write_csv(&mut out, &self.analysis, force);
        String::from_utf8_lossy(&out).into_owned()
    }
}

/// Loads the model and picks the contact, its speed and the model at that speed: everything
/// `cam` checks before it runs or writes anything.
pub fn prepare(args: &CamArgs) -> Result<Prepared, CliError> {
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
    Ok(Prepared {
        subject,
        index,
        speed,
        control,
        nominal,
        probe,
        designed,
    })
}

/// The analysis and the runs; `say` gets each part of the report as soon as it is known
/// (the design's before the runs start).
pub fn study(p: &Prepared, args: &CamArgs, say: &mut dyn FnMut(&str)) -> Result<Study, CliError> {
    let design = p
        .design()
        .ok_or_else(|| CliError::Failed(format!("contact `{}` has no design", p.contact())))?;
    let (speed, info) = (p.speed, p.nominal.info());
    let analysis = Analysis::new(design, speed, args.samples);
    let source = match args.speed {
        Some(_) => format!("--speed, set through {}", p.control.describe()),
        None => format!("the law's speed, through {}", p.control.describe()),
    };
    let mut text = format!(
        "{}: cam of contact `{}` designed from a motion law\n{}",
        p.subject.label,
        p.contact(),
        report::design_summary(design, &analysis, args.samples, &source)
    );
    say(&text);

    let dof = dynamics::degrees_of_freedom(p.nominal.as_ref());
    let restitution = args.restitution.or(info.restitution).unwrap_or(0.0);
    let n = args.samples;
    let speeds: Vec<f64> = if dof == 0 {
        vec![0.5 * speed, speed, 2.0 * speed]
    } else {
        vec![speed]
    };
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
                .map(|&w| dynamics::bilateral_turn(&p.subject, &p.control, &p.probe, w, n))
                .collect::<Vec<Result<Turn, String>>>()
        },
        || {
            if info.n_contacts() == 1 {
                dynamics::one_sided(&p.nominal, &p.probe, speed, args.turns, n, restitution)
            } else {
                Err(format!(
                    "skipped: one-sided contact needs a model with exactly one contact, and {} \
                     has {}",
                    p.subject.label,
                    info.n_contacts()
                ))
            }
        },
    );
    let turns: Vec<Turn> = turns
        .into_iter()
        .collect::<Result<_, _>>()
        .map_err(|e| CliError::Failed(format!("{}: {e}", p.subject.label)))?;
    let prediction = match turns.as_slice() {
        [a, b, c] => Some(Prediction::new([a, b, c])),
        _ => None,
    };
    if turns.is_empty() {
        return Err(CliError::Failed("no bilateral run".into()));
    }
    let unit = report::units(design)[1];
    let all: Vec<&Turn> = turns.iter().collect();
    let dynamics_text = report::dynamics_summary(
        p.subject.engine(),
        dof,
        &all,
        prediction.as_ref(),
        &format!("`{}`", p.control.name),
        &one_sided,
        unit,
    );
    say(&dynamics_text);
    text.push_str(&dynamics_text);
    Ok(Study {
        analysis,
        turns,
        prediction,
        one_sided,
        text,
        dof,
    })
}

/// Runs the `cam` command.
pub fn run(args: &CamArgs) -> Result<(), CliError> {
    let prepared = prepare(args)?;
    let label = &prepared.subject.label;
    let contact = prepared.contact();
    let dir = args.out.join(if prepared.designed > 1 {
        format!("{label}_{contact}_cam")
    } else {
        format!("{label}_cam")
    });
    let _table_lock = match &args.table {
        Some(table) => output::claim(table).map_err(CliError::Failed)?,
        None => None,
    };
    // Held until the report's files are written.
    let _lock = output::create_dir(&dir).map_err(CliError::Failed)?;
    for warning in &prepared.subject.warnings {
        eprintln!("warning: {label}: {warning}");
    }
    if prepared.subject.numeric {
        let runs = if dynamics::degrees_of_freedom(prepared.nominal.as_ref()) == 0 {
            4
        } else {
            2
        };
        eprintln!(
            "note: {label} runs on the numeric recursive reference (a model file): {runs} runs \
             of {} outputs a turn take seconds where a built-in model's generated code takes a \
             fraction of one; fewer --samples run faster",
            args.samples
        );
    }
    let study = study(&prepared, args, &mut |text| say(text))?;
    let design = prepared
        .design()
        .ok_or_else(|| CliError::Failed(format!("contact `{contact}` has no design")))?;
    let nominal = study
        .nominal()
        .ok_or_else(|| CliError::Failed("no bilateral run".into()))?;
    let written = write_outputs(&Outputs {
        dir: &dir,
        name: label,
        contact,
        designed: prepared.designed,
        design,
        analysis: &study.analysis,
        nominal,
        prediction: study.prediction.as_ref(),
        one_sided: study.one_sided.as_ref().ok(),
        probe: &prepared.probe,
        table: args.table.as_deref().map(|t| (t, args.points)),
    });
    let written = written.map_err(CliError::Failed)?;
    say(&format!("  wrote {}\n", output::list_files(&written)));
    match &study.one_sided {
        Err(why) if prepared.nominal.info().n_contacts() == 1 => {
            Err(CliError::Failed(format!("{label}: {why}")))
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
