//! Everything `simulate` checks before it touches a file: the models (a model file is
//! checked as the build checks it), the runs' names (no two runs may write the same files),
//! the settings each run will use (the runtime's ranges, the option or model field at
//! fault named), the combination of options, the coordinates to plot and the destinations.
//! A problem here is an error before any simulation and before any file is written.

use super::CliError;
use super::args::{DEFAULT_MODELS, SimulateArgs};
use super::output::{self, CsvTarget};
use super::source::{self, LoadedModel};
use camchain_runtime::{InvalidSetting, SimSettings};
use std::collections::HashMap;
use std::path::PathBuf;

/// One model to run and where its results go.
pub struct Job {
    /// The model and its origin.
    pub model: LoadedModel,
    /// The settings of its run, checked.
    pub settings: SimSettings,
    /// Coordinates of the time-history figure (indices).
    pub coords: Vec<usize>,
    /// Where its CSV goes.
    pub csv: CsvTarget,
    /// Its directory (`--out DIR/<run>`), if it has one.
    pub dir: Option<PathBuf>,
    /// Directory of its figures, if figures are written.
    pub figures: Option<PathBuf>,
    /// Its destinations' locks, held until the command ends: no other run writes them.
    pub locks: Vec<output::Lock>,
}

/// Resolves the models and checks every option, setting and destination.
pub fn plan(args: &SimulateArgs) -> Result<Vec<Job>, CliError> {
    let names: Vec<String> = if args.models.is_empty() {
        DEFAULT_MODELS.iter().map(|s| s.to_string()).collect()
    } else {
        args.models.clone()
    };
    if args.csv.is_some() && names.len() != 1 {
        return Err(CliError::Usage(format!(
            "--csv writes the CSV of one model, but {} are to run (give one MODEL, or use \
             --out DIR for several)",
            names.len()
        )));
    }
    let values = args.parameter_values().map_err(CliError::Usage)?;
    let mut origins: HashMap<String, String> = HashMap::new();
    let mut jobs = Vec::new();
    for name in &names {
        let model = source::load_with(name, args.numeric, &values)?;
        if let Some(first) = origins.insert(model.label.clone(), model.origin.clone()) {
            return Err(given_twice(&model, &first));
        }
        let settings = checked_settings(&model, args)?;
        let coords = coordinates(&model, &args.coords)?;
        jobs.push(Job {
            model,
            settings,
            coords,
            csv: CsvTarget::Stdout,
            dir: None,
            figures: None,
            locks: Vec::new(),
        });
    }
    destinations(&mut jobs, args)?;
    Ok(jobs)
}

/// Two arguments that would write the same run.
fn given_twice(model: &LoadedModel, first: &str) -> CliError {
    let label = &model.label;
    if first == model.origin {
        CliError::Usage(format!("{first} is given twice"))
    } else {
        CliError::Usage(format!(
            "{first} and {} would both be run `{label}` and write the same files: rename one \
             file, or run them one at a time with different --out",
            model.origin
        ))
    }
}

/// The run's settings: the model's defaults overridden by the options, within the
/// runtime's ranges (those of a run that streams its samples, or, for a CSV written to
/// standard output at the end, of one that keeps them); `--restitution` only where
/// one-sided contact can run.
fn checked_settings(model: &LoadedModel, args: &SimulateArgs) -> Result<SimSettings, CliError> {
    let info = model.engine.dynamics().info();
    let settings = args.settings(&info.defaults);
    if args.csv_to_stdout() {
        settings.validate(0.0)
    } else {
        settings.validate_streamed(0.0)
    }
    .map_err(|e| setting_error(&e, args, model))?;
    if args.restitution(info.restitution).is_some() {
        if !settings.integrator.is_adaptive() {
            return Err(CliError::Usage(format!(
                "--restitution needs an adaptive integrator (dopri5 or dop853), which locates \
                 lift-off and landing on its dense output; {} would run rk4{}",
                model.label,
                if args.integration.integrator.is_some() {
                    " (--integrator rk4)"
                } else {
                    ", its default: add --integrator dop853"
                }
            )));
        }
        if info.n_contacts() != 1 {
            return Err(CliError::Usage(format!(
                "--restitution needs a model with exactly one cam contact; {} has {}",
                model.label,
                info.n_contacts()
            )));
        }
    }
    Ok(settings)
}

/// A setting out of range, attributed to the options that set it or to the model file.
fn setting_error(e: &InvalidSetting, args: &SimulateArgs, model: &LoadedModel) -> CliError {
    let given = |flag: &str| match flag {
        "--t-end" => args.integration.t_end.is_some(),
        "--dt-out" => args.integration.dt_out.is_some(),
        "--dt" => args.integration.dt.is_some(),
        "--rtol" => args.integration.rtol.is_some(),
        "--atol" => args.integration.atol.is_some(),
        _ => false,
    };
    let flags: &[&str] = match e.field {
        "t_end" => &["--t-end"],
        "dt_out" => &["--dt-out"],
        "t_end/dt_out" => &["--t-end", "--dt-out"],
        "dt" => &["--dt", "--dt-out"],
        "rtol" => &["--rtol"],
        "atol" => &["--atol"],
        _ => &[],
    };
    let named: Vec<&str> = flags.iter().copied().filter(|f| given(f)).collect();
    if named.is_empty() {
        CliError::Failed(format!(
            "{}: the model's simulation settings: {e} (set the option to override it)",
            model.origin
        ))
    } else {
        CliError::Usage(format!("{}: {}", named.join(" with "), e.message))
    }
}

/// The coordinates of the time-history figure: those named by `--coords`, or all from
/// the tip to the base.
fn coordinates(model: &LoadedModel, names: &[String]) -> Result<Vec<usize>, CliError> {
    let info = model.engine.dynamics().info();
    if names.is_empty() {
        return Ok((0..info.n()).rev().collect());
    }
    names
        .iter()
        .map(|name| {
            if name.trim().is_empty() {
                return Err(CliError::Usage(
                    "--coords: empty coordinate name; give names separated by commas, e.g. \
                     --coords q4,q3"
                        .to_string(),
                ));
            }
            info.coordinate_index(name.trim()).ok_or_else(|| {
                let known: Vec<&str> = info.coordinates.iter().map(|c| c.name.as_str()).collect();
                CliError::Usage(format!(
                    "--coords: {} has no coordinate `{name}` (its coordinates: {})",
                    model.name,
                    known.join(", ")
                ))
            })
        })
        .collect()
}

/// The CSV and figure destinations of every job, checked (and the output directories
/// created, empty, so that an unwritable one is found before any run).
fn destinations(jobs: &mut [Job], args: &SimulateArgs) -> Result<(), CliError> {
    for job in jobs {
        let label = &job.model.label;
        let dir = args.out_dir().map(|d| d.join(label));
        if let Some(dir) = &dir {
            job.locks
                .push(output::create_dir(dir).map_err(CliError::Failed)?);
        }
        job.csv = match (&args.csv, &dir) {
            (Some(_), _) if args.csv_to_stdout() => CsvTarget::Stdout,
            (Some(path), _) => {
                job.locks
                    .extend(output::claim(path).map_err(CliError::Failed)?);
                CsvTarget::File(path.clone())
            }
            (None, Some(dir)) => CsvTarget::File(dir.join(format!("{label}.csv"))),
            (None, None) => CsvTarget::Stdout,
        };
        job.figures = dir.clone().filter(|_| !args.no_plots);
        job.dir = dir;
    }
    Ok(())
}
