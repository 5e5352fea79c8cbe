//! `camchain simulate`: runs each model, then writes its CSV and figures and prints its
//! summary; finally draws the concave and convex runs of a pair side by side.
//!
//! Everything that can be checked before simulating is checked first ([`super::plan`]), so
//! that a usage error or an unwritable destination costs no simulation and touches no file.
//! A run streams its CSV rows to `<name>.partial.csv` and renames it when complete; a run
//! that fails keeps what it computed there and changes nothing else (an earlier result at
//! the destination stays as it was); Ctrl-C or SIGTERM stops the running simulation within
//! one step, keeps the partial CSV, says where, and exits with 130 or 143. A run that fails
//! does not stop the others; the command then exits with code 1.
//!
//! A run keeps no trajectory (issue 25): each sample goes, as it is computed, to the CSV
//! stream, to the summary's [`Digest`] and, when figures are drawn, to their bounded copy
//! ([`decimated`]); its memory does not grow with its length. Only a CSV written at the end
//! (to standard output or a special file) keeps every sample, and is held to the runtime's
//! cap on kept samples.

mod decimated;

use super::CliError;
use super::args::SimulateArgs;
use super::figures::{self, RunView};
use super::interrupt::Interrupt;
use super::output::{CsvSink, Saved};
use super::plan::{Job, plan};
use super::plots::Figure;
use super::progress::Progress;
use super::summary::{self, Digest, LiftOff, RunReport};
use camchain_runtime::{
    Cancel, ContactLaw, Monitor, Observed, Progress as StepProgress, Sample, SimError, Simulate,
    Trajectory,
};
use decimated::Decimated;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Prints summaries and notes: on standard output, or on standard error when the CSV goes
/// to standard output; nothing with `--quiet`. Warnings go to standard error.
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

    fn warn(&self, label: &str, warning: &str) {
        if !self.quiet {
            eprintln!("warning: {label}: {warning}");
        }
    }
}

/// What the figures of a complete run are drawn from.
struct Drawn {
    /// The decimated copy of its samples.
    samples: Vec<Sample>,
    /// Where each contact's normal force first turned negative.
    lift_offs: Vec<Option<LiftOff>>,
}

/// A completed run, kept for the side-by-side figures.
struct Done {
    job: usize,
    drawn: Drawn,
}

/// How one run ended.
enum Outcome {
    /// Complete, with what its figures are drawn from.
    Done(Drawn),
    /// Failed (reported).
    Failed,
    /// Stopped by Ctrl-C (reported).
    Interrupted,
}

/// Runs the `simulate` command.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let jobs = plan(args)?;
    let console = Console {
        quiet: args.quiet,
        to_stderr: args.csv_to_stdout(),
    };
    let interrupt = Interrupt::install();
    let mut failed = false;
    let mut done = Vec::new();
    for (index, job) in jobs.iter().enumerate() {
        match run_job(job, args, &console, &interrupt) {
            Outcome::Done(drawn) => done.push(Done { job: index, drawn }),
            Outcome::Failed => failed = true,
            Outcome::Interrupted => return Err(interrupt.error()),
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

/// Runs one job: assembly, simulation with the CSV streamed, then (complete runs) the
/// figures and the summary. Problems are reported here.
fn run_job(job: &Job, args: &SimulateArgs, console: &Console, interrupt: &Interrupt) -> Outcome {
    let model = &job.model;
    let label = &model.label;
    for warning in &model.warnings {
        console.warn(label, warning);
    }
    let dynamics = model.engine.dynamics();
    let info = dynamics.info();
    let settings = &job.settings;
    let mut sink = match CsvSink::open(&job.csv, info) {
        Ok(sink) => sink,
        Err(message) => {
            eprintln!("error: {label}: {message}");
            return Outcome::Failed;
        }
    };
    let start = Instant::now();
    let assembled = dynamics.assemble_reported(0.0);
    let (state, report) = match assembled {
        Ok(assembled) => assembled,
        Err(e) => {
            let what = if info.loops.is_empty() {
                "assembly onto the cam failed"
            } else {
                "assembly failed"
            };
            eprintln!("error: {label}: {what}: {e}");
            let _ = sink.finish(info, &[], false);
            return Outcome::Failed;
        }
    };
    console.say(&summary::assembly(info, &report));
    for warning in summary::assembly_warnings(info, &report, state.length_scale()) {
        console.warn(label, &warning);
    }
    // A CSV written at the end needs every sample; one streamed to its file needs none.
    let keep = sink.partial().is_none();
    let mut watcher = Watcher {
        progress: Progress::new(label, 0.0, settings.t_end, !args.quiet),
        sink: &mut sink,
        info,
        write_error: None,
        cancel: Cancel(interrupt.flag()),
        digest: Digest::new(info),
        figures: job
            .figures
            .as_ref()
            .map(|_| Decimated::new(info.n_contacts())),
        keep,
    };
    let law = match args.restitution(info.restitution) {
        Some(restitution) => ContactLaw::Unilateral { restitution },
        None => ContactLaw::Bilateral,
    };
    let run = dynamics.simulate_monitored(state, settings, law, &mut watcher);
    let Watcher {
        progress,
        write_error,
        digest,
        figures: decimated,
        ..
    } = watcher;
    progress.finish();
    let wall = start.elapsed();
    let (trajectory, failure) = match run {
        Ok(trajectory) => (trajectory, None),
        Err(failure) => (failure.partial, Some(failure.error)),
    };
    let saved = sink.finish(info, &trajectory.samples, failure.is_none());
    if let Some(error) = failure {
        let signal = interrupt.signal_name();
        return report_failure(label, (&error, signal), write_error, &trajectory, saved);
    }
    let mut written = Vec::new();
    let mut ok = true;
    match saved {
        Ok(Saved::Complete(Some(path))) => written.push(path),
        Ok(_) => {}
        Err(message) => {
            eprintln!("error: {label}: {message}");
            ok = false;
        }
    }
    let drawn = Drawn {
        samples: decimated.map(Decimated::finish).unwrap_or_default(),
        lift_offs: digest.lift_offs().to_vec(),
    };
    // The samples a CSV written at the end needed: written, and freed before the figures.
    drop(trajectory.samples);
    if let Some(dir) = &job.figures {
        match draw_run(job, &drawn, dir, console) {
            Ok(paths) => written.extend(paths),
            Err(message) => {
                eprintln!("error: {label}: {message}");
                ok = false;
            }
        }
    }
    let engine = summary::with_changed_parameters(model.engine.describe(), dynamics);
    console.say(&summary::render(&RunReport {
        label,
        engine: &engine,
        info,
        settings,
        digest: &digest,
        events: &trajectory.events,
        stats: trajectory.stats,
        wall,
    }));
    for warning in
        summary::result_warnings(info, &digest, matches!(law, ContactLaw::Unilateral { .. }))
    {
        console.warn(label, &warning);
    }
    // The process's peak so far, as a sweep reports it: flat in the run's length.
    if let Some(peak) = super::sweep::peak_memory_mb() {
        console.say(&format!("  peak memory {peak:.1} MB\n"));
    }
    if !written.is_empty() {
        console.say(&format!(
            "  wrote {}\n",
            super::output::list_files(&written)
        ));
    }
    if ok {
        Outcome::Done(drawn)
    } else {
        Outcome::Failed
    }
}

/// What a run shows and writes while it goes: each sample's CSV row, the progress, the
/// summary's digest and the figures' copy; after every step, the progress and the interrupt
/// flag.
struct Watcher<'a> {
    progress: Progress,
    sink: &'a mut CsvSink,
    info: &'a camchain_runtime::ModelInfo,
    write_error: Option<String>,
    cancel: Cancel<'a>,
    /// What the summary needs of the samples.
    digest: Digest,
    /// What the figures are drawn from, when they are.
    figures: Option<Decimated>,
    /// Whether the run keeps every sample (for a CSV written at the end).
    keep: bool,
}

impl Monitor for Watcher<'_> {
    fn sample(&mut self, sample: &Sample) -> Observed {
        self.progress.update(sample.t);
        self.digest.add(sample);
        if let Some(figures) = &mut self.figures {
            figures.add(sample);
        }
        if let Err(e) = self.sink.row(self.info, sample) {
            let file = self.sink.partial().map(|p| p.display().to_string());
            self.write_error = Some(format!("cannot write {}: {e}", file.unwrap_or_default()));
            return Observed::Break(());
        }
        self.cancel.step(&StepProgress {
            t: sample.t,
            h: 0.0,
            steps: 0,
        })
    }

    fn step(&mut self, progress: &StepProgress) -> Observed {
        self.progress.update_step(progress.t, progress.h);
        self.cancel.step(progress)
    }

    fn keep_samples(&self) -> bool {
        self.keep
    }
}

/// One `error:` line for a failed run (or one line for an interrupted one), and where its
/// partial CSV is; no summary.
fn report_failure(
    label: &str,
    (error, signal): (&SimError, &str),
    write_error: Option<String>,
    trajectory: &Trajectory,
    saved: Result<Saved, String>,
) -> Outcome {
    let interrupted = matches!(error, SimError::Interrupted { .. }) && write_error.is_none();
    match (&write_error, interrupted) {
        (Some(e), _) => eprintln!(
            "error: {label}: {e}; the run stopped at t = {} s",
            trajectory.samples.last().map_or(0.0, |s| s.t)
        ),
        (None, true) => eprintln!(
            "{label}: stopped by {signal} at t = {} s",
            error.time().unwrap_or(f64::NAN)
        ),
        (None, false) => eprintln!("error: {label}: {error}"),
    }
    let samples = trajectory.sample_count;
    match saved {
        Ok(Saved::Partial(path)) => eprintln!(
            "{label}: {} computed until then {} in {}",
            if samples == 1 {
                "the sample"
            } else {
                "the samples"
            },
            if samples == 1 { "is" } else { "are" },
            path.display()
        ),
        Ok(_) => {}
        Err(message) => eprintln!("error: {label}: {message}"),
    }
    if interrupted {
        Outcome::Interrupted
    } else {
        Outcome::Failed
    }
}

fn view<'a>(job: &'a Job, drawn: &'a Drawn) -> RunView<'a> {
    RunView {
        label: &job.model.label,
        info: job.model.engine.dynamics().info(),
        samples: &drawn.samples,
        lift_offs: &drawn.lift_offs,
        geometry: job.model.geometry.as_ref().ok(),
    }
}

/// The figures of one run; a note when the snapshots cannot be drawn.
fn draw_run(
    job: &Job,
    drawn: &Drawn,
    dir: &Path,
    console: &Console,
) -> Result<Vec<PathBuf>, String> {
    let run = view(job, drawn);
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
    if let Some(figure) = figures::follower(&run) {
        figures.push((figure, "follower"));
    }
    if let Some(figure) = figures::surface(&run) {
        figures.push((figure, "surface"));
    }
    // A spatial cam's mechanism seen from the side too: the second orthogonal projection.
    let side = run.geometry.and_then(|g| g.side_view());
    if let Some(side) = &side {
        let label = format!("{} seen from the side", run.label);
        let view = RunView {
            label: &label,
            geometry: Some(side),
            ..run
        };
        if let Ok(figure) = figures::snapshots(&view) {
            figures.push((figure, "side"));
        }
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
            &view(&jobs[a.job], &a.drawn),
            &view(&jobs[b.job], &b.drawn),
            &coords,
        );
        let suffix = if first.engine.is_numeric() {
            "_numeric"
        } else {
            ""
        };
        let stem = format!("{prefix}_concave_vs_convex{suffix}");
        match figure.save(dir, &stem) {
            Ok(paths) => console.say(&format!(
                "side by side: wrote {}\n",
                super::output::list_files(&paths)
            )),
            Err(e) => {
                eprintln!("error: {stem}: {e}");
                ok = false;
            }
        }
    }
    ok
}
