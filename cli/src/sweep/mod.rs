//! `camchain sweep`: a model run over a grid or a Latin hypercube of its run-time
//! parameters, in parallel; `camchain merge`: the shards of a sweep joined.
//!
//! Everything that can be checked is checked before the first run (the model, every
//! parameter's name and every value against its declared bounds, the settings, the shard,
//! the output); then `--jobs` workers take the runs in index order from a shared counter,
//! and the main thread writes each row as soon as every earlier one is written (at most a
//! few rows wait: memory does not grow with the number of runs). A run that fails is a row
//! with its error. Figures are drawn at the end from the rows kept for them (at most
//! [`PLOTTED_RUNS`]).

pub mod figures;
mod merge;
mod progress;
mod resolve;
mod sink;
pub mod spec;
pub mod table;

pub use merge::run as merge;

use super::CliError;
use super::args::SweepArgs;
use super::interrupt::Interrupt;
use super::output;
use camchain_codegen::ParameterMode;
use camchain_codegen::schema::Files;
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::{Cancel, Dynamics, MetricsOptions, SimError, SimSettings, Simulate};
use sink::Sink;
use spec::{Design, Runs, Shard};
use std::collections::BTreeMap;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use table::{Preamble, Row};

/// Above this many runs no figure is drawn (their data would not stay small); the CSV has
/// everything.
pub const PLOTTED_RUNS: usize = 200_000;

/// Builds a run's model from its parameter values ([`Factory::Custom`]).
pub type Builder = std::sync::Arc<
    dyn Fn(&[(&str, f64)]) -> Result<Box<dyn Dynamics + Send + Sync>, String> + Send + Sync,
>;

/// Where each run's model comes from.
pub enum Factory {
    /// Generated code, built with other parameter values by its constructor.
    Generated {
        /// Its constructor (`camchain_models::WITH_PARAMETERS`).
        constructor: models::Constructor,
    },
    /// Any other way of building a run's model: a model file compiled by the Python
    /// package's `camchain.compile` into a library of its own.
    Custom {
        /// The model with the run's values, or why the values are refused.
        build: Builder,
        /// How summaries name the path.
        describe: &'static str,
    },
    /// The numeric reference, the model file validated again with the run's values.
    Numeric {
        /// The file's text.
        source: String,
        /// The file as messages name it.
        file: PathBuf,
        /// Where the files it names are read from.
        files: Files<'static>,
    },
}

impl Factory {
    /// The model with these values.
    pub fn build(&self, values: &[(&str, f64)]) -> Result<Box<dyn Dynamics + Send + Sync>, String> {
        match self {
            Factory::Generated { constructor, .. } => {
                constructor(values).map_err(|e| e.to_string())
            }
            Factory::Custom { build, .. } => build(values),
            Factory::Numeric {
                source,
                file,
                files,
            } => {
                let owned: Vec<(String, f64)> =
                    values.iter().map(|(n, v)| (n.to_string(), *v)).collect();
                let mode = ParameterMode::AllAtRunTime;
                NumericModel::from_source_in(source, file, &owned, mode, *files)
                    .map(|m| Box::new(m) as Box<dyn Dynamics + Send + Sync>)
                    .map_err(|e| e.to_string().replace('\n', " "))
            }
        }
    }

    /// How summaries name the path.
    fn describe(&self) -> &'static str {
        match self {
            Factory::Generated { .. } => "generated code",
            Factory::Numeric { .. } => "numeric reference",
            Factory::Custom { describe, .. } => describe,
        }
    }
}

/// Most workers a sweep starts (`--jobs`): each is a thread holding its own model.
pub const MAX_JOBS: usize = 1024;

/// Everything a sweep needs, checked.
pub struct Plan {
    /// The model's name.
    pub model: String,
    /// The run's label in file names (`paper_concave`, `paper_concave_numeric`, a file stem).
    pub label: String,
    /// The model of each run.
    pub factory: Factory,
    /// The runs.
    pub runs: Runs,
    /// This process's slice.
    pub shard: Shard,
    /// Integration settings.
    pub settings: SimSettings,
    /// Where the metrics are evaluated.
    pub options: MetricsOptions,
    /// Workers.
    pub jobs: usize,
    /// Where the CSV goes (`None`: standard output).
    pub csv: Option<PathBuf>,
    /// Where the figures go, if anywhere.
    pub figures: Option<PathBuf>,
    /// The metrics drawn.
    pub plotted: Vec<String>,
    /// No summary, no progress.
    pub quiet: bool,
    /// The destinations' locks, held until the sweep ends: no other run writes them.
    pub _locks: Vec<output::Lock>,
}

/// `camchain sweep`.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    let plan = plan(args)?;
    let interrupt = Interrupt::install();
    execute(&plan, &interrupt)
}

/// Checks everything and decides the files, before any run.
pub fn plan(args: &SweepArgs) -> Result<Plan, CliError> {
    let usage = CliError::Usage;
    let (model, label, factory, declared, folded, defaults) = resolve::resolve_model(args)?;
    let mut swept = args
        .params
        .iter()
        .map(|p| spec::parse_param(p).map_err(|e| usage(format!("--param {e}"))))
        .collect::<Result<Vec<_>, _>>()?;
    for s in &mut swept {
        resolve::check_parameter(&model, s, &declared, &folded, args.numeric)?;
        s.unit = declared
            .iter()
            .find(|p| p.name == s.name)
            .map_or_else(String::new, |p| p.unit.clone());
    }
    let design = match args.samples {
        Some(samples) => Design::LatinHypercube {
            samples,
            seed: args.seed,
        },
        None => Design::Product,
    };
    let runs = Runs::new(swept, design).map_err(usage)?;
    let shard = match &args.shard {
        Some(text) => spec::parse_shard(text).map_err(|e| usage(format!("--shard {e}")))?,
        None => Shard::ALL,
    };
    let settings = args.settings(&defaults);
    // A sweep's runs keep no samples: held to the streamed runs' cap, not to a kept
    // trajectory's.
    settings
        .validate_streamed(0.0)
        .map_err(|e| usage(format!("settings: {e}")))?;
    let jobs = match args.jobs {
        Some(0) => return Err(usage("--jobs must be at least 1".to_string())),
        Some(n) if n > MAX_JOBS => {
            return Err(usage(format!(
                "--jobs {n}: at most {MAX_JOBS} workers (each is a thread with its own model)"
            )));
        }
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    }
    // No more workers than runs: an idle worker is only a thread.
    .min(shard.len(runs.len()).max(1));
    let plotted = plotted_metrics(&args.metric)?;
    let stem = match (shard.count, &args.shard) {
        (1, _) | (_, None) => format!("{label}_sweep"),
        _ => format!("{label}_sweep.shard-{}-of-{}", shard.index, shard.count),
    };
    let (csv, figures, locks) = destinations(args, &label, &stem)?;
    Ok(Plan {
        model,
        label,
        factory,
        runs,
        shard,
        settings,
        options: MetricsOptions { grid: args.grid },
        jobs,
        csv,
        figures,
        plotted,
        quiet: args.quiet,
        _locks: locks,
    })
}

/// `--metric` names, checked.
pub(crate) fn plotted_metrics(given: &[String]) -> Result<Vec<String>, CliError> {
    if given.is_empty() {
        return Ok(table::DEFAULT_PLOTTED
            .iter()
            .map(|s| s.to_string())
            .collect());
    }
    for name in given {
        if !table::PLOTTABLE.contains(&name.as_str()) {
            return Err(CliError::Usage(format!(
                "--metric: unknown metric `{name}`; the metrics are {}",
                table::PLOTTABLE.join(", ")
            )));
        }
    }
    Ok(given.to_vec())
}

/// A sweep's CSV path (`None`: standard output), figures' directory and their locks.
type Destinations = (Option<PathBuf>, Option<PathBuf>, Vec<output::Lock>);

/// The CSV's path (`None`: standard output) and the figures' directory, checked writable and
/// locked for this sweep.
fn destinations(args: &SweepArgs, label: &str, stem: &str) -> Result<Destinations, CliError> {
    let mut locks = Vec::new();
    let dir = match (&args.out, &args.csv) {
        (Some(dir), _) => Some(dir.join(format!("{label}_sweep"))),
        (None, Some(_)) => None,
        (None, None) => {
            Some(PathBuf::from(super::args::DEFAULT_OUT).join(format!("{label}_sweep")))
        }
    };
    if let Some(dir) = &dir {
        locks.push(output::create_dir(dir).map_err(CliError::Failed)?);
    }
    let csv = match &args.csv {
        Some(path) if path.as_os_str() == "-" => None,
        Some(path) => {
            locks.extend(output::claim(path).map_err(CliError::Failed)?);
            Some(path.clone())
        }
        None => dir.as_ref().map(|d| d.join(format!("{stem}.csv"))),
    };
    let figures = if args.no_plots { None } else { dir };
    Ok((csv, figures, locks))
}

/// The `#` lines of this sweep.
pub fn preamble(plan: &Plan) -> Preamble {
    let s = &plan.settings;
    let tolerances = if s.integrator.is_adaptive() {
        format!("rtol {:e} atol {:e}", s.rtol, s.atol)
    } else {
        format!("dt {:e} s", s.dt)
    };
    let sampling = if plan.options.grid {
        format!("metrics at the step ends and every {} s", s.dt_out)
    } else {
        "metrics at the step ends".to_string()
    };
    Preamble {
        sweep: format!(
            "camchain sweep of {} ({}): {}",
            plan.model,
            plan.factory.describe(),
            crate::counted(plan.runs.len(), "run")
        ),
        shard: (plan.shard.index, plan.shard.count),
        parameters: plan.runs.describe(),
        settings: format!(
            "{} {tolerances} t_end {} s, {sampling}",
            s.integrator.name(),
            s.t_end
        ),
    }
}

/// One run: the model with the run's values, assembly, a metrics run that stops within one
/// step once `cancel` is set. `None` when it was cancelled (the row is not the run's).
pub fn run_one(plan: &Plan, run: usize, cancel: &AtomicBool) -> Option<Row> {
    let start = Instant::now();
    let values = plan.runs.values(run);
    let names: Vec<&str> = plan.runs.swept.iter().map(|s| s.name.as_str()).collect();
    let pairs: Vec<(&str, f64)> = names.iter().copied().zip(values.iter().copied()).collect();
    let (metrics, error) = match plan.factory.build(&pairs) {
        Err(e) => (None, Some(e)),
        Ok(model) => match model.assemble(0.0) {
            Err(e) => (None, Some(format!("assembly: {e}"))),
            Ok(state) => {
                let mut monitor = Cancel(cancel);
                let settings = &plan.settings;
                match model.simulate_metrics_monitored(state, settings, plan.options, &mut monitor)
                {
                    Ok(m) => (Some(m), None),
                    Err(failure) if matches!(failure.error, SimError::Interrupted { .. }) => {
                        return None;
                    }
                    Err(failure) => (Some(failure.partial), Some(failure.error.to_string())),
                }
            }
        },
    };
    Some(Row {
        run,
        values,
        metrics,
        error,
        wall_time: start.elapsed().as_secs_f64(),
    })
}

/// The smallest and largest value of each plotted metric and the parameters of their runs,
/// kept as the rows go by (constant memory, whatever the number of runs).
pub struct Extremes {
    metrics: Vec<String>,
    /// Per metric, once it has a value.
    seen: Vec<Option<Extreme>>,
}

/// The extremes of one metric: the value and the run's parameter values, and how many runs
/// had a value.
type Extreme = ((f64, Vec<f64>), (f64, Vec<f64>), usize);

impl Extremes {
    fn new(metrics: &[String]) -> Self {
        Extremes {
            metrics: metrics.to_vec(),
            seen: vec![None; metrics.len()],
        }
    }

    fn add(&mut self, row: &Row) {
        for (k, metric) in self.metrics.iter().enumerate() {
            let Some(x) = row.metric(metric) else {
                continue;
            };
            match &mut self.seen[k] {
                None => self.seen[k] = Some(((x, row.values.clone()), (x, row.values.clone()), 1)),
                Some((lo, hi, count)) => {
                    *count += 1;
                    if x < lo.0 {
                        *lo = (x, row.values.clone());
                    }
                    if x > hi.0 {
                        *hi = (x, row.values.clone());
                    }
                }
            }
        }
    }
}

/// The rows kept for the figures (parameters and the plotted metrics), while there are few
/// enough.
pub struct PlotData {
    /// The plotted metrics' names.
    pub metrics: Vec<String>,
    /// Per run: its parameter values and the plotted metrics (None where empty).
    pub rows: Vec<(Vec<f64>, Vec<Option<f64>>)>,
    /// False once there were more than [`PLOTTED_RUNS`] rows.
    pub complete: bool,
}

impl PlotData {
    pub(crate) fn new(metrics: &[String]) -> Self {
        PlotData {
            metrics: metrics.to_vec(),
            rows: Vec::new(),
            complete: true,
        }
    }

    fn add(&mut self, row: &Row) {
        let metrics = self.metrics.iter().map(|m| row.metric(m)).collect();
        self.add_values(row.values.clone(), metrics);
    }

    /// Keeps one run's parameters and plotted metrics (until there are too many).
    pub(crate) fn add_values(&mut self, values: Vec<f64>, metrics: Vec<Option<f64>>) {
        if !self.complete {
            return;
        }
        if self.rows.len() == PLOTTED_RUNS {
            self.rows = Vec::new();
            self.complete = false;
            return;
        }
        self.rows.push((values, metrics));
    }
}

/// Runs the plan: workers, the ordered writer, the summary, the figures.
pub fn execute(plan: &Plan, interrupt: &Interrupt) -> Result<(), CliError> {
    let preamble = preamble(plan);
    let names: Vec<String> = plan.runs.swept.iter().map(|s| s.name.clone()).collect();
    let mut head = Vec::new();
    preamble
        .write(&mut head)
        .and_then(|()| writeln!(head, "{}", table::header(&names).join(",")))
        .map_err(|e| CliError::Failed(format!("cannot format the CSV's header: {e}")))?;
    let mut sink = Sink::open(plan.csv.as_deref(), &head).map_err(CliError::Failed)?;
    let total = plan.shard.len(plan.runs.len());
    let mut progress =
        progress::Progress::new(&format!("{} sweep", plan.label), total, !plan.quiet);
    let start = Instant::now();
    // Rows are kept only for figures, and only up to PLOTTED_RUNS.
    let mut plot = PlotData::new(&plan.plotted);
    plot.complete = plan.figures.is_some();
    let mut extremes = Extremes::new(&plan.plotted);
    let mut written = 0;
    let mut failed = 0;
    let mut write_error: Option<String> = None;
    let stop = AtomicBool::new(false);
    let next = AtomicUsize::new(0);
    let runs: Vec<usize> = plan.shard.runs(plan.runs.len()).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(plan.jobs)
        .build()
        .map_err(|e| CliError::Failed(format!("cannot start {} workers: {e}", plan.jobs)))?;
    let (tx, rx) = mpsc::sync_channel::<(usize, Row)>(4 * plan.jobs);
    pool.in_place_scope(|scope| {
        for _ in 0..plan.jobs {
            let tx = tx.clone();
            let (next, stop, runs) = (&next, &stop, &runs);
            scope.spawn(move |_| {
                loop {
                    if stop.load(Ordering::Relaxed) {
                        break;
                    }
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&run) = runs.get(k) else {
                        break;
                    };
                    // A run cancelled in flight sends nothing: its row is not written.
                    let Some(row) = run_one(plan, run, stop) else {
                        break;
                    };
                    if tx.send((k, row)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        // Rows in run order: a finished row waits until every earlier one is written.
        let mut waiting: BTreeMap<usize, Row> = BTreeMap::new();
        let mut flushed = Instant::now();
        loop {
            // Waits for rows a tenth of a second at a time, so that an interrupt is passed on
            // to the runs in flight at once, not when the next row arrives.
            let (k, row) = match rx.recv_timeout(Duration::from_millis(100)) {
                Ok(received) => received,
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if interrupt.requested() {
                        stop.store(true, Ordering::Relaxed);
                    }
                    continue;
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            };
            waiting.insert(k, row);
            while let Some(row) = waiting.remove(&written) {
                if write_error.is_none()
                    && let Err(e) = sink.row(&row.cells().join(","))
                {
                    write_error = Some(e);
                    stop.store(true, Ordering::Relaxed);
                }
                failed += usize::from(row.error.is_some());
                plot.add(&row);
                extremes.add(&row);
                written += 1;
                progress.update(written, failed);
            }
            // What is computed reaches the file at least every second (a crash or a killed
            // batch job keeps it).
            if flushed.elapsed().as_secs() >= 1 && write_error.is_none() {
                if let Err(e) = sink.flush() {
                    write_error = Some(e);
                    stop.store(true, Ordering::Relaxed);
                }
                flushed = Instant::now();
            }
            if interrupt.requested() {
                stop.store(true, Ordering::Relaxed);
            }
        }
    });
    progress.finish();
    let elapsed = start.elapsed().as_secs_f64();
    if let Some(e) = write_error {
        let kept = sink.abandon();
        return Err(CliError::Failed(format!(
            "{e}{}",
            kept.map_or(String::new(), |p| format!(
                " (the complete rows before it are kept in {})",
                p.display()
            ))
        )));
    }
    if written < total {
        let kept = sink.abandon();
        eprintln!(
            "{} sweep: stopped by {} after {written} of {total} runs{}",
            plan.label,
            interrupt.signal_name(),
            kept.map_or(String::new(), |p| format!(
                "; the rows so far are in {}",
                p.display()
            ))
        );
        return Err(interrupt.error());
    }
    let saved = sink.finish().map_err(CliError::Failed)?;
    let drawn = match (&plan.figures, plot.complete) {
        (Some(dir), true) => figures::draw(dir, plan, &plot)
            .map_err(|e| CliError::Failed(format!("figures: {e}")))?,
        _ => Vec::new(),
    };
    if !plan.quiet {
        let too_many = plan.figures.is_some() && !plot.complete;
        let counts = (written, failed, elapsed);
        summary(plan, &extremes, too_many, counts, saved.as_deref(), &drawn);
    }
    if failed > 0 {
        return Err(CliError::RunsFailed(failed));
    }
    Ok(())
}

/// The process's peak resident memory (MB), where the system says (Linux: VmHWM).
pub fn peak_memory_mb() -> Option<f64> {
    let status = fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Six significant digits: plain for ordinary magnitudes, scientific for tiny or huge ones.
fn significant(v: f64) -> String {
    let magnitude = v.abs();
    if v == 0.0 || (1e-3..1e6).contains(&magnitude) {
        let decimals = (5 - magnitude.log10().floor().max(0.0) as i32).max(0) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.5e}")
    }
}

/// What the sweep did, on standard error when the CSV went to standard output.
fn summary(
    plan: &Plan,
    extremes: &Extremes,
    too_many: bool,
    (runs, failed, elapsed): (usize, usize, f64),
    csv: Option<&Path>,
    figures: &[PathBuf],
) {
    let mut text = String::new();
    let shard = if plan.shard.count > 1 {
        format!(", shard {} (every {}-th run)", plan.shard, plan.shard.count)
    } else {
        String::new()
    };
    text.push_str(&format!(
        "{} sweep — {}, {}{shard} over {}, {}\n",
        plan.model,
        plan.factory.describe(),
        crate::counted(runs, "run"),
        plan.runs.describe(),
        crate::counted(plan.jobs, "worker"),
    ));
    text.push_str(&format!(
        "  {} in {elapsed:.2} s ({:.0} runs/s); {failed} failed{}\n",
        crate::counted(runs, "run"),
        runs as f64 / elapsed.max(1e-9),
        if failed > 0 {
            " (their rows have the error)"
        } else {
            ""
        }
    ));
    let at = |v: &[f64]| {
        plan.runs
            .swept
            .iter()
            .zip(v)
            .map(|(s, x)| format!("{} = {x}", s.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (metric, seen) in extremes.metrics.iter().zip(&extremes.seen) {
        let Some(((lo, at_lo), (hi, at_hi), count)) = seen else {
            text.push_str(&format!("  {metric}: no value\n"));
            continue;
        };
        let unit = table::METRICS
            .iter()
            .find(|(n, _)| n == metric)
            .map_or("", |(_, u)| *u);
        text.push_str(&format!(
            "  {metric}: {} … {} {unit} (smallest at {}; largest at {}); {count} of {}\n",
            significant(*lo),
            significant(*hi),
            at(at_lo),
            at(at_hi),
            crate::counted(runs, "run"),
        ));
    }
    if too_many {
        text.push_str(&format!(
            "  no figures: more than {PLOTTED_RUNS} runs (plot the CSV)\n"
        ));
    }
    if let Some(peak) = peak_memory_mb() {
        text.push_str(&format!("  peak memory {peak:.1} MB\n"));
    }
    match csv {
        Some(path) => text.push_str(&format!("  wrote {}\n", path.display())),
        None if plan.csv.is_none() => {}
        None => {}
    }
    if let Some(dir) = figures.first().and_then(|p| p.parent()) {
        let names: Vec<String> = figures
            .iter()
            .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect();
        text.push_str(&format!(
            "  wrote {}/: {}\n",
            dir.display(),
            names.join(", ")
        ));
    }
    if plan.csv.is_none() {
        eprint!("{text}");
    } else {
        print!("{text}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::{Cli, Command};
    use clap::Parser;

    fn sweep_plan(jobs: &str) -> Result<Plan, CliError> {
        let cli = Cli::try_parse_from([
            "camchain",
            "sweep",
            "paper_concave",
            "--param",
            "k3=20:80:5",
            "--csv",
            "-",
            "--jobs",
            jobs,
        ])
        .expect("parsed");
        let Some(Command::Sweep(args)) = cli.command else {
            panic!("a sweep");
        };
        plan(&args)
    }

    #[test]
    fn sweep_jobs_are_capped_at_the_runs_and_a_documented_maximum() {
        // 5 runs: 1000 workers would be 995 idle threads.
        assert_eq!(sweep_plan("1000").map(|p| p.jobs).ok(), Some(5));
        assert_eq!(sweep_plan("2").map(|p| p.jobs).ok(), Some(2));
        match sweep_plan("100000") {
            Err(CliError::Usage(message)) => assert!(message.contains("at most 1024"), "{message}"),
            _ => panic!("--jobs 100000 is a usage error"),
        }
    }
}
