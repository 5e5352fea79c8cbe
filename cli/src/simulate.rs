//! `camchain simulate`: runs each model, then writes its CSV and figures and prints its
//! summary; finally draws the concave and convex runs of a pair side by side.
//!
//! Everything that can be checked before simulating is checked first (model names and
//! files, `--coords`, `--csv` with one model, output directories), so that a usage error
//! or an unwritable destination costs no simulation. A run that fails does not stop the
//! others; the command then exits with code 1.

use super::CliError;
use super::args::{DEFAULT_MODELS, SimulateArgs};
use super::figures::{self, RunView};
use super::output::{self, CsvTarget, Saved};
use super::plots::Figure;
use super::progress::Progress;
use super::source::{self, LoadedModel};
use super::summary::{self, RunReport};
use camchain_runtime::simulate::MAX_STEPS_PER_CALL;
use camchain_runtime::{Dynamics, IntegratorKind, SimSettings, Simulate, Trajectory};
use std::collections::HashSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Prints summaries and notes: on standard output, or on standard error when the CSV goes
/// to standard output; nothing with `--quiet`.
struct Console {
    quiet: bool,
    to_stderr: bool,
}

impl Console {
    fn say(&self, text: &str) {
        if self.quiet {
            return;
        }
        // Written without `print!`, which panics when the reader has gone (`| head`).
        let _ = if self.to_stderr {
            std::io::stderr().write_all(text.as_bytes())
        } else {
            std::io::stdout().write_all(text.as_bytes())
        };
    }
}

/// One model to run and where its results go.
struct Job {
    model: LoadedModel,
    /// Coordinates of the time-history figure (indices).
    coords: Vec<usize>,
    csv: CsvTarget,
    /// Directory of its figures, if figures are written.
    figures: Option<PathBuf>,
}

/// A completed run, kept for the side-by-side figures.
struct Done {
    job: usize,
    trajectory: Trajectory,
}

/// Runs the `simulate` command.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let jobs = plan(args)?;
    let console = Console {
        quiet: args.quiet,
        to_stderr: args.csv_to_stdout(),
    };
    let mut failed = false;
    let mut done = Vec::new();
    for (index, job) in jobs.iter().enumerate() {
        match run_job(job, args, &console) {
            Ok(trajectory) => done.push(Done {
                job: index,
                trajectory,
            }),
            Err(()) => failed = true,
        }
    }
    if let (Some(dir), false) = (args.out_dir(), args.no_plots) {
        failed |= !draw_pairs(&jobs, &done, &dir, args, &console);
    }
    if failed {
        Err(CliError::Reported)
    } else {
        Ok(())
    }
}

/// Resolves the models and checks the options and destinations.
fn plan(args: &SimulateArgs) -> Result<Vec<Job>, CliError> {
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
    let mut labels = HashSet::new();
    let mut jobs = Vec::new();
    for name in &names {
        let model = source::load(name, args.numeric)?;
        if !labels.insert(model.label.clone()) {
            return Err(CliError::Usage(format!("{} is given twice", model.label)));
        }
        check_step_budget(&model, args)?;
        let coords = coordinates(&model, &args.coords)?;
        jobs.push(Job {
            coords,
            csv: CsvTarget::Stdout,
            figures: None,
            model,
        });
    }
    for job in &mut jobs {
        let label = &job.model.label;
        let dir = args.out_dir().map(|d| d.join(label));
        if let Some(dir) = &dir {
            output::create_dir(dir).map_err(CliError::Failed)?;
        }
        job.csv = match (&args.csv, &dir) {
            (Some(_), _) if args.csv_to_stdout() => CsvTarget::Stdout,
            (Some(path), _) => {
                output::check_csv_destination(path).map_err(CliError::Failed)?;
                CsvTarget::File(path.clone())
            }
            (None, Some(dir)) => CsvTarget::File(dir.join(format!("{label}.csv"))),
            (None, None) => CsvTarget::Stdout,
        };
        job.figures = dir.filter(|_| !args.no_plots);
    }
    Ok(jobs)
}

/// Refuses, before running, an rk4 step so small that the runtime would give up only after
/// [`MAX_STEPS_PER_CALL`] steps in the first output interval (a minute or more of work).
fn check_step_budget(model: &LoadedModel, args: &SimulateArgs) -> Result<(), CliError> {
    let settings = args.settings(&model.engine.dynamics().info().defaults);
    let steps = settings.dt_out / settings.dt;
    if settings.integrator == IntegratorKind::Rk4 && steps > MAX_STEPS_PER_CALL as f64 {
        return Err(CliError::Usage(format!(
            "--dt: {}: an rk4 step of {:e} s needs {steps:.1e} steps per output interval \
             (--dt-out {:e} s), more than the {MAX_STEPS_PER_CALL} allowed",
            model.label, settings.dt, settings.dt_out
        )));
    }
    Ok(())
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

/// Assembles and simulates, with a progress bar; returns the trajectory (partial on
/// failure), the failure, if any, and the wall time.
fn integrate(
    model: &dyn Dynamics,
    label: &str,
    settings: &SimSettings,
    restitution: Option<f64>,
    quiet: bool,
) -> (Trajectory, Option<String>, Duration) {
    let start = Instant::now();
    let mut progress = Progress::new(label, 0.0, settings.t_end, !quiet);
    let outcome = match model.assemble(0.0) {
        Err(e) => (
            Trajectory::default(),
            Some(format!("assembly onto the cam failed: {e}")),
        ),
        Ok(state) => {
            let run = match restitution {
                // One-sided contact runs in phases; its progress is not reported.
                Some(e) => model.simulate_unilateral(state, settings, e),
                None => model.simulate_observed(state, settings, &mut |s| {
                    progress.update(s.t);
                    std::ops::ControlFlow::Continue(())
                }),
            };
            match run {
                Ok(trajectory) => (trajectory, None),
                Err(failure) => {
                    let message = failure.to_string();
                    (failure.partial, Some(message))
                }
            }
        }
    };
    progress.finish();
    (outcome.0, outcome.1, start.elapsed())
}

/// Runs one job: simulation, CSV, figures, summary. Problems are reported here.
fn run_job(job: &Job, args: &SimulateArgs, console: &Console) -> Result<Trajectory, ()> {
    let model = &job.model;
    let dynamics = model.engine.dynamics();
    let info = dynamics.info();
    let settings = args.settings(&info.defaults);
    let (trajectory, failure, wall) = integrate(
        dynamics,
        &model.label,
        &settings,
        args.restitution,
        args.quiet,
    );
    let mut ok = failure.is_none();
    if let Some(message) = &failure {
        eprintln!("error: {}: {message}", model.label);
    }
    let mut written = Vec::new();
    match output::save_csv(&job.csv, info, &trajectory.samples, ok) {
        Ok(Saved::Complete(Some(path))) => written.push(path),
        Ok(Saved::Complete(None) | Saved::Nothing) => {}
        Ok(Saved::Partial(path)) => eprintln!(
            "{}: the {} samples computed before the failure are in {}",
            model.label,
            trajectory.samples.len(),
            path.display()
        ),
        Err(message) => {
            eprintln!("error: {}: {message}", model.label);
            ok = false;
        }
    }
    if let (Some(dir), true) = (&job.figures, failure.is_none()) {
        match draw_run(job, &trajectory, dir, console) {
            Ok(paths) => written.extend(paths),
            Err(message) => {
                eprintln!("error: {}: {message}", model.label);
                ok = false;
            }
        }
    }
    console.say(&summary::render(&RunReport {
        label: &model.label,
        engine: model.engine.describe(),
        info,
        settings: &settings,
        samples: &trajectory.samples,
        events: &trajectory.events,
        stats: trajectory.stats,
        wall,
    }));
    if !written.is_empty() {
        console.say(&format!("  wrote {}\n", list_files(&written)));
    }
    if ok { Ok(trajectory) } else { Err(()) }
}

/// "out/paper_concave/: paper_concave.csv, histories.png, …".
fn list_files(paths: &[PathBuf]) -> String {
    let dir = paths.first().and_then(|p| p.parent());
    if dir.is_some() && paths.iter().all(|p| p.parent() == dir) {
        let names: Vec<String> = paths
            .iter()
            .filter_map(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .collect();
        let dir = dir.map(|d| d.display().to_string()).unwrap_or_default();
        format!("{dir}/: {}", names.join(", "))
    } else {
        let all: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        all.join(", ")
    }
}

fn view<'a>(job: &'a Job, trajectory: &'a Trajectory) -> RunView<'a> {
    RunView {
        label: &job.model.label,
        info: job.model.engine.dynamics().info(),
        samples: &trajectory.samples,
        geometry: job.model.geometry.as_ref().ok(),
    }
}

/// The figures of one run; a note when the snapshots cannot be drawn.
fn draw_run(
    job: &Job,
    trajectory: &Trajectory,
    dir: &Path,
    console: &Console,
) -> Result<Vec<PathBuf>, String> {
    let run = view(job, trajectory);
    let mut figures: Vec<(Figure, &str)> =
        vec![(figures::histories(&run, &job.coords), "histories")];
    match figures::snapshots(&run) {
        Ok(figure) => figures.push((figure, "snapshots")),
        Err(why) => console.say(&format!(
            "note: {}: snapshots skipped: {why}\n",
            job.model.label
        )),
    }
    if let Some(figure) = figures::contact(&run) {
        figures.push((figure, "contact"));
    }
    let mut paths = Vec::new();
    for (figure, stem) in &figures {
        paths.extend(figure.save(dir, stem).map_err(|e| e.to_string())?);
    }
    Ok(paths)
}

/// Side-by-side figures of every `<prefix>_concave` / `<prefix>_convex` pair that ran on
/// the same path. Returns false when one could not be written.
fn draw_pairs(
    jobs: &[Job],
    done: &[Done],
    dir: &Path,
    args: &SimulateArgs,
    console: &Console,
) -> bool {
    let mut ok = true;
    for a in done {
        let first = &jobs[a.job].model;
        let Some(prefix) = first.name.strip_suffix("_concave") else {
            continue;
        };
        let partner = done.iter().find(|b| {
            let second = &jobs[b.job].model;
            second.name == format!("{prefix}_convex")
                && second.engine.is_numeric() == first.engine.is_numeric()
        });
        let Some(b) = partner else {
            continue;
        };
        let coords: Vec<String> = if args.coords.is_empty() {
            let info = first.engine.dynamics().info();
            info.coordinates
                .iter()
                .rev()
                .map(|c| c.name.clone())
                .collect()
        } else {
            args.coords.iter().map(|c| c.trim().to_string()).collect()
        };
        let figure = figures::comparison(
            &view(&jobs[a.job], &a.trajectory),
            &view(&jobs[b.job], &b.trajectory),
            &coords,
        );
        let suffix = if first.engine.is_numeric() {
            "_numeric"
        } else {
            ""
        };
        let stem = format!("{prefix}_concave_vs_convex{suffix}");
        match figure.save(dir, &stem) {
            Ok(paths) => console.say(&format!("side by side: wrote {}\n", list_files(&paths))),
            Err(e) => {
                eprintln!("error: {stem}: {e}");
                ok = false;
            }
        }
    }
    ok
}
