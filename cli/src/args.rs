//! Command-line syntax (clap derive): `camchain [simulate [MODEL]... [OPTIONS] | list | ops
//! [MODEL]... | cam MODEL [OPTIONS] | …]`.
//!
//! Values are checked here, so a bad one is a usage error (exit code 2) before anything
//! runs: times must be positive and finite, tolerances positive, the integrator one of the
//! runtime's.
// The doc comments below are also clap's help text, where `DIR/<model>_sweep.csv` is
// literal text, not an HTML tag.
#![allow(rustdoc::invalid_html_tags)]

use camchain_runtime::{IntegratorKind, SimSettings};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

/// The models run when `simulate` is given none: the paper's two cams.
pub const DEFAULT_MODELS: [&str; 2] = ["paper_concave", "paper_convex"];

/// The output directory used when neither `--out` nor `--csv` is given.
pub const DEFAULT_OUT: &str = "out";

/// `camchain`: simulate cam mechanisms from model files; sweep, design and benchmark them.
#[derive(Debug, Parser)]
#[command(
    name = "camchain",
    version,
    about = "Simulate cam mechanisms from model files: chains, trees and closed loops of rigid bodies whose knife-edge, roller or flat followers touch fixed or moving cams.",
    long_about = "Simulate cam mechanisms from model files: chains, trees and closed loops of rigid bodies whose knife-edge, roller or flat followers touch fixed or moving cams.\n\n\
                  Without a command, runs `simulate` (same options): by default the paper's \
                  concave and convex cams, a summary on the terminal, CSV and figures in out/."
)]
#[command(args_conflicts_with_subcommands = true, allow_negative_numbers = true)]
pub struct Cli {
    /// What to do (default: `simulate`).
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The options of `simulate`, for `camchain [OPTIONS] [MODEL]...` without a command.
    #[command(flatten)]
    pub simulate: SimulateArgs,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate models; write CSV and figures; print a summary of each run.
    #[command(
        long_about = "Simulate models; write CSV and figures; print a summary of each run.\n\n\
                      Files: without --csv, each run writes DIR/<run>/<run>.csv and its figures \
                      (histories, snapshots, contact; .png and .svg) under --out DIR (default \
                      out/), and when both cams of a pair ran (e.g. paper_concave and \
                      paper_convex), DIR/paper_concave_vs_convex.png/.svg side by side. A run \
                      on the numeric path is named <model>_numeric. With --csv FILE only that \
                      file is written, unless --out is given too.\n\n\
                      Ctrl-C or SIGTERM stops a run within one step and keeps its rows in \
                      <name>.partial.csv; a run that stalls (steps collapsed at a singular \
                      point, or too short to finish) stops with its diagnosis.\n\n\
                      Exit codes: 0 success, 1 a model file or a run failed or a file could not \
                      be written, 2 a usage error (bad option or value, unknown model name), 130 \
                      interrupted by Ctrl-C, 143 stopped by SIGTERM.",
        after_help = "Examples:\n  \
                      camchain simulate                         # both paper cams, files in out/\n  \
                      camchain simulate paper_convex --coords q4,q3 --t-end 4\n  \
                      camchain simulate my_cam.ron --out results  # a model file, no rebuild\n  \
                      camchain simulate paper_concave --numeric --csv -  # CSV on stdout"
    )]
    Simulate(SimulateArgs),
    /// List the built-in models with their coordinates, contacts and default settings.
    List,
    /// Print the operation count of every generated function (add/sub, mul, div, sin/cos,
    /// sqrt, other, total): the table of the generated file's header.
    #[command(after_help = "Examples:\n  \
                      camchain ops                      # every built-in model\n  \
                      camchain ops paper_concave\n  \
                      camchain ops my_cam.ron           # derived now, without rebuilding")]
    Ops {
        /// Built-in model names or paths to .ron model files [default: every built-in model]
        #[arg(value_name = "MODEL")]
        models: Vec<String>,
    },
    /// Measure: run time against error of every integrator, and generated code against
    /// the numeric recursion; writes the sections of BENCHMARKS.md.
    Bench(BenchArgs),
    /// Run the numerical stability stress suite; write STRESS.md and its figures.
    #[command(
        long_about = "Run the numerical stability stress suite and write STRESS.md and its \
                      figures.\n\n\
                      Scenarios (variants of the reference models, on the numeric reference): \
                      1000 s runs without dampers, stiff springs, tiny and large masses, fast \
                      motion, re-partitioning, steep/flat/inflected/wavy profiles, a cam out of \
                      reach, NaN and infinity. Each runs with RK4 at several steps and each \
                      adaptive integrator at several tolerances; a failing run is reported in \
                      its table. Takes a few minutes in release (--quick: under a minute).",
        after_help = "Examples:\n  \
                      cargo run --release -- stress                 # STRESS.md, docs/stress/\n  \
                      cargo run --release -- stress --quick --out /tmp/STRESS.md"
    )]
    Stress(StressArgs),
    /// Run a model over a grid or a Latin hypercube of its run-time parameters, in parallel;
    /// one CSV row of metrics per run, figures of each metric against the parameters.
    #[command(
        long_about = "Run a model over a grid or a Latin hypercube of its run-time parameters \
                      (those `camchain list` shows), in parallel over every core; each run's \
                      metrics are one CSV row, streamed as the runs finish (nothing else of a \
                      run is kept), and each metric is drawn against the swept parameters (a \
                      heat map for two).\n\n\
                      VALUES: a:b:n (n values from a to b), a:b:n:log (in log scale), a,b,c (a \
                      list), a (one value), or a:b with --samples (an interval of the Latin \
                      hypercube).\n\n\
                      Every value is checked against the parameter's declared bounds, every \
                      option and the output before any run starts. A run that fails (Newton, \
                      step size, a value the model's own checks refuse) is a row with its \
                      error; the sweep goes on. --shard I/N runs every N-th run from the I-th \
                      (for a batch array on a cluster); `camchain merge` joins the shards.\n\n\
                      Exit codes: 0 every run completed; 3 + (failed runs - 1), at most 127, \
                      when runs failed; 1 a file could not be written; 2 a usage error; 130 \
                      interrupted by Ctrl-C, 143 stopped by SIGTERM (the runs in flight are \
                      cancelled at once; the rows so far stay in <name>.partial.csv).",
        after_help = "Examples:\n  \
                      camchain sweep paper_concave --param swing=-0.5:0.5:21 --param k3=20,40,80\n  \
                      camchain sweep driven_convex --param period=1:8:50 --metric first_lift_off\n  \
                      camchain sweep paper_concave --param k2=5:30 --param k4=5:30 --samples 2000 --seed 3\n  \
                      camchain sweep paper_concave --numeric --param m4=0.5:2:16   # a folded parameter\n  \
                      camchain sweep my_cam.ron --param k=10:100:10 --shard 3/8 --csv part-3.csv"
    )]
    Sweep(SweepArgs),
    /// Join the CSVs of the shards of one sweep (`camchain sweep --shard I/N`), checking
    /// that none is missing, repeated or from another sweep; write the whole CSV and its
    /// figures.
    #[command(after_help = "Examples:\n  \
                      camchain merge shards/*.csv --out results\n  \
                      camchain merge part-*.csv --csv sweep.csv --no-plots")]
    Merge(MergeArgs),
    /// Export a model as an FMU (FMI 3.0 Co-Simulation) for system-simulation tools.
    #[command(
        long_about = "Export a model as an FMU (FMI 3.0 Co-Simulation) for system-simulation \
                      tools (FMPy, Modelica tools, Simulink).\n\n\
                      The model's code is generated, built with your cargo into a library that \
                      links the runtime and the FMI functions (never the code generator), and \
                      packed with its modelDescription.xml: the run-time parameters as \
                      parameters with their units and bounds, the integrator's tolerances and \
                      step (solver.rtol, solver.atol, solver.dt), and every column of \
                      `camchain simulate --csv` as an output under the same name. Built \
                      libraries are cached (--cache) by the model's text and the version, so \
                      a second export of the same model runs no cargo. See docs/fmu.md.\n\n\
                      Exit codes: 0 written, 1 the model, the build or the file failed, 2 a \
                      usage error, 130 interrupted by Ctrl-C.",
        after_help = "Examples:\n  \
                      camchain fmu cycloidal_roller                # cycloidal_roller.fmu here\n  \
                      camchain fmu my_cam.ron --out fmus/my_cam.fmu"
    )]
    Fmu(FmuArgs),
    /// Analyse a cam designed from its follower's motion law (`law:` in a contact): the
    /// design's peaks, pressure angle, curvature and joints; figures, a CSV and the profile
    /// as a table; the jump speed the dynamics predict, checked by a one-sided run.
    #[command(
        long_about = "Analyse a cam designed from its follower's motion law (`law:` in a contact \
                      of the model file) at its nominal speed ω (--speed, else the law's \
                      `speed`).\n\n\
                      Printed: the segments, base and prime circles, the follower and the \
                      turning sense; the follower's peak velocity, acceleration and jerk at ω \
                      (both signs, refined between samples by golden-section search, segment \
                      joints included) with the cam angles where they occur; the largest \
                      pressure angle either way against its limit; the smallest radius of \
                      curvature where the profile is convex and where it is concave; the \
                      undercut margin of a roller or the face width a flat face needs; the \
                      joints where the acceleration or the jerk jumps.\n\n\
                      Dynamics: with the camshaft driven and the follower held on the cam (no \
                      degree of freedom in bilateral contact), the contact force is exactly \
                      N(θ, ω) = A(θ) + B(θ) ω + C(θ) ω²; three bilateral runs of one turn (at \
                      ω/2, ω and 2ω, set through the parameter the law's speed names) give A, B \
                      and C at every sampled angle, and the jump speed is the smallest speed at \
                      which the least force over a turn reaches zero. A one-sided run over \
                      --turns turns at ω then shows where the follower really lifts off and \
                      lands, or its smallest contact force.\n\n\
                      Files, in DIR/<model>_cam/ (DIR/<model>_<contact>_cam/ when the model has \
                      several designed cams): svaj, pressure_curvature, profile and force \
                      (.png and .svg each) and design.csv (one row per sample: cam_angle_deg, \
                      s, v, a, j at ω, pressure_angle_deg, radius_of_curvature, profile_x, \
                      profile_y, pitch_x, pitch_y, normal_force of the bilateral run at ω; SI \
                      units, rad for an oscillating follower's motion). --table FILE also \
                      writes the profile as a CSV table of points that a model reads back \
                      with `table: (form: Parametric, file: \"FILE\")`.\n\n\
                      Exit codes: 0 success; 1 a model file invalid, a run failed, the speed \
                      cannot be set, or a file could not be written; 2 a usage error (bad \
                      option or value, unknown model or contact, a model without a designed \
                      cam, no speed).",
        after_help = "Examples:\n  \
                      camchain cam cycloidal_roller                 # at the law's 50 rad/s, files in out/cycloidal_roller_cam/\n  \
                      camchain cam cycloidal_roller --speed 70      # above the jump speed: the follower lifts off\n  \
                      camchain cam polynomial_rocker --turns 5 --restitution 0.3\n  \
                      camchain cam cycloidal_roller --table profile.csv --points 1440\n  \
                      camchain cam my_cams.ron --contact intake --samples 7200 --out results"
    )]
    Cam(CamArgs),
}

/// Options of `cam`.
#[derive(Debug, Clone, Args)]
pub struct CamArgs {
    /// A built-in model's name or a path to a .ron model file (which runs on the numeric
    /// reference), with a contact designed from a motion law (`law:`)
    #[arg(value_name = "MODEL")]
    pub model: String,

    /// The contact whose cam is analysed, by name (needed when the model has several
    /// designed from a law) [default: the model's only one]
    #[arg(long, value_name = "NAME")]
    pub contact: Option<String>,

    /// The cam's nominal speed ω in rad/s, positive [default: the law's `speed`]
    #[arg(long, value_name = "RAD_PER_S", value_parser = positive_speed, allow_hyphen_values = true)]
    pub speed: Option<f64>,

    /// Samples over a turn: rows of design.csv and figures, output angles of the runs, the
    /// grid the peaks are refined from; 1 to 1000000
    #[arg(long, value_name = "N", default_value_t = 3600, value_parser = cam_samples)]
    pub samples: usize,

    /// Turns of the camshaft in the one-sided run at ω, 1 to 10000 (and at most 1000000
    /// samples in all: turns × --samples)
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = cam_turns)]
    pub turns: usize,

    /// Coefficient of restitution of the one-sided run (0 plastic … 1 elastic) [default:
    /// the model file's `simulation.restitution`, else 0]
    #[arg(long, value_name = "E", value_parser = restitution)]
    pub restitution: Option<f64>,

    /// Directory of the figures and design.csv, one subdirectory per cam
    #[arg(long, value_name = "DIR", default_value = DEFAULT_OUT)]
    pub out: PathBuf,

    /// Also write the cam's profile as a CSV table of points (x,y in the cam frame, m) to
    /// FILE, for `table: (form: Parametric, file: "FILE")`
    #[arg(long, value_name = "FILE")]
    pub table: Option<PathBuf>,

    /// Points of the --table profile (at evenly spaced cam angles, the first repeated at
    /// the end), 3 to 1000000
    #[arg(long, value_name = "N", default_value_t = 720, value_parser = table_points, requires = "table")]
    pub points: usize,
}

/// Options of `bench`.
#[derive(Debug, Clone, Args)]
pub struct BenchArgs {
    /// Which benchmark [default: all]
    #[arg(value_enum, default_value = "all")]
    pub what: BenchWhat,
    /// Fewer models, rungs and repeats (a smoke run, not for the report)
    #[arg(long)]
    pub quick: bool,
    /// The report whose sections are rewritten
    #[arg(long, value_name = "FILE", default_value = "BENCHMARKS.md")]
    pub report: PathBuf,
    /// Directory of the figures
    #[arg(long, value_name = "DIR", default_value = "docs")]
    pub figures: PathBuf,
    /// The CSV of the scaling example (for `scaling-figure`)
    #[arg(long, value_name = "FILE")]
    pub scaling_csv: Option<PathBuf>,
}

/// The benchmarks of `bench`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BenchWhat {
    /// Both.
    All,
    /// Run time against error over a ladder of steps and tolerances, every integrator.
    WorkPrecision,
    /// One evaluation of each term, generated against numeric, side by side; the reduced
    /// right-hand side of the cams on moving bodies against the fixed-cam paper model, and one
    /// camshaft revolution at 1e-10.
    Evaluations,
    /// Closed loops alone: the loop models' right-hand sides, Andrews' squeezer's work
    /// against precision, the IFToMM benchmarks A02 and A04 (also part of `evaluations`).
    Loops,
    /// Spatial cams alone: a saddle surface generated against numeric, a barrel cam against
    /// the disc cam of the same program, the surface contact's operations against the
    /// planar one's (also part of `evaluations`).
    Surfaces,
    /// What finding events inside steps costs: right-hand sides per step of every built-in
    /// model with a contact, watched and not; one-sided runs near the jump speed and at high
    /// cam speeds.
    Events,
    /// Whole-run overhead, sweep throughput with 1 and 2 workers, sweep memory.
    Sweep,
    /// Draw the scaling figure from the scaling example's CSV (--scaling-csv).
    ScalingFigure,
}

/// Options of `stress`.
#[derive(Debug, Clone, Args)]
pub struct StressArgs {
    /// Shorter long runs (100 s instead of 1000 s) and fewer RK4 steps in them
    #[arg(long)]
    pub quick: bool,

    /// The report to write
    #[arg(long, value_name = "FILE", default_value = "STRESS.md")]
    pub out: PathBuf,

    /// Directory of the figures (PNG and SVG) [default: docs/stress beside the report]
    #[arg(long, value_name = "DIR")]
    pub figures: Option<PathBuf>,
}

/// Options of `sweep`.
#[derive(Debug, Clone, Default, Args)]
#[command(allow_negative_numbers = true)]
pub struct SweepArgs {
    /// A built-in model's name or a path to a .ron model file (which runs on the numeric
    /// reference)
    #[arg(value_name = "MODEL")]
    pub model: String,

    /// A parameter and its values, NAME=VALUES (repeat for several; see above)
    #[arg(
        long = "param",
        value_name = "NAME=VALUES",
        required = true,
        allow_hyphen_values = true
    )]
    pub params: Vec<String>,

    /// Draw this many runs as a Latin hypercube over the intervals a:b of the parameters
    /// [default: every combination of the values]
    #[arg(long, value_name = "N")]
    pub samples: Option<usize>,

    /// Seed of the Latin hypercube (the same seed gives the same runs)
    #[arg(long, value_name = "SEED", default_value_t = 1, requires = "samples")]
    pub seed: u64,

    /// Metrics drawn in the figures, comma-separated [default:
    /// max_normal_force,min_normal_force,first_lift_off,energy_drift]
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub metric: Vec<String>,

    /// Runs at a time, at most 1024 and never more than the runs [default: the number of
    /// cores]
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,

    /// Run only the I-th of N disjoint slices of the sweep (every N-th run from the I-th)
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,

    /// Run a built-in model on the numeric reference: every parameter can then be swept,
    /// also those its generated code folds
    #[arg(long)]
    pub numeric: bool,

    /// Also evaluate the metrics at every output time t0 + k·dt_out (extremes as in a full
    /// run's CSV; about twice the work) [default: at the integrator's steps]
    #[arg(long)]
    pub grid: bool,

    /// End time, output interval (for --grid), integrator, step and tolerances.
    #[command(flatten)]
    pub integration: IntegrationArgs,

    /// Write the CSV to FILE (`-`: standard output); nothing else is written unless --out
    /// is given too [default: DIR/<model>_sweep/<model>_sweep.csv]
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,

    /// Directory for the CSV and figures [default: out, or none with --csv]
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Write no figures
    #[arg(long)]
    pub no_plots: bool,

    /// Print nothing but errors
    #[arg(long, short)]
    pub quiet: bool,
}

/// The options of a run's integration, shared by `simulate` and `sweep`.
#[derive(Debug, Clone, Default, Args)]
pub struct IntegrationArgs {
    /// End time in seconds [default: the model's, see `camchain list`]
    #[arg(long, value_name = "SECONDS", value_parser = positive_time, allow_hyphen_values = true)]
    pub t_end: Option<f64>,

    /// Output interval in seconds: one CSV row per interval, and one plotted point up to
    /// 20 000 of them (a longer run's figures are drawn from every k-th); at most 1e9
    /// intervals (1e6 with --csv -, whose rows are kept until the run ends). For a sweep,
    /// the grid of --grid [default: the model's]
    #[arg(long, value_name = "SECONDS", value_parser = positive_time, allow_hyphen_values = true)]
    pub dt_out: Option<f64>,

    /// Integrator, in any letter case as in model files: rk4 (fixed step --dt), dopri5 or
    /// dop853 (adaptive, --rtol/--atol, first step --dt; dop853 is the fastest at tight
    /// tolerances) [default: the model's]
    #[arg(long, value_name = "NAME", ignore_case = true, value_parser = integrator_parser())]
    pub integrator: Option<IntegratorKind>,

    /// Step in seconds: fixed step of rk4, first step of dopri5 and dop853 [default: the
    /// model's]
    #[arg(long, value_name = "SECONDS", value_parser = positive_time, allow_hyphen_values = true)]
    pub dt: Option<f64>,

    /// Relative tolerance of dopri5 and dop853, in [1e-14, 0.1] [default: the model's]
    #[arg(long, value_name = "TOL", value_parser = relative_tolerance, allow_hyphen_values = true)]
    pub rtol: Option<f64>,

    /// Absolute tolerance of dopri5 and dop853 (rad, m, rad/s, m/s), in [1e-18, 1]
    /// [default: the model's]
    #[arg(long, value_name = "TOL", value_parser = absolute_tolerance, allow_hyphen_values = true)]
    pub atol: Option<f64>,
}

impl IntegrationArgs {
    /// The model's default settings overridden by the options that were given.
    pub fn settings(&self, defaults: &SimSettings) -> SimSettings {
        SimSettings {
            t_end: self.t_end.unwrap_or(defaults.t_end),
            dt_out: self.dt_out.unwrap_or(defaults.dt_out),
            integrator: self.integrator.unwrap_or(defaults.integrator),
            dt: self.dt.unwrap_or(defaults.dt),
            rtol: self.rtol.unwrap_or(defaults.rtol),
            atol: self.atol.unwrap_or(defaults.atol),
        }
    }
}

impl SweepArgs {
    /// The model's default settings overridden by the options that were given.
    pub fn settings(&self, defaults: &SimSettings) -> SimSettings {
        self.integration.settings(defaults)
    }
}

/// Options of `fmu`.
#[derive(Debug, Clone, Default, Args)]
pub struct FmuArgs {
    /// Built-in model name or path to a .ron model file
    #[arg(value_name = "MODEL", required_unless_present = "library")]
    pub model: Option<String>,

    /// Pack this library instead of building one: a cdylib of your crate whose root calls
    /// `camchain::fmu::export!` (its modelIdentifier is the file's name without `lib` and
    /// `.so`)
    #[arg(long, value_name = "FILE", conflicts_with = "model")]
    pub library: Option<PathBuf>,

    /// The FMU's path [default: <model>.fmu in the current directory]
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,

    /// Where built libraries are kept [default: $CAMCHAIN_CACHE, else
    /// $XDG_CACHE_HOME/camchain, else ~/.cache/camchain]
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,

    /// Print nothing but errors (cargo's progress included)
    #[arg(long, short)]
    pub quiet: bool,

    /// Print the FMU's modelDescription.xml on standard output and write no FMU (a
    /// built-in model's needs no build; a model file's is read from its built library)
    #[arg(long)]
    pub describe: bool,
}

/// Options of `merge`.
#[derive(Debug, Clone, Default, Args)]
pub struct MergeArgs {
    /// The shards' CSV files (every shard of one sweep, in any order)
    #[arg(value_name = "FILE", required = true)]
    pub files: Vec<PathBuf>,

    /// Write the merged CSV to FILE (`-`: standard output); nothing else is written unless
    /// --out is given too [default: DIR/<model>_sweep.csv, the model's name made a plain
    /// file name]
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,

    /// Directory for the merged CSV and figures [default: out, or none with --csv]
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Metrics drawn, comma-separated [default: as in sweep]
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub metric: Vec<String>,

    /// Write no figures
    #[arg(long)]
    pub no_plots: bool,

    /// Print nothing but errors
    #[arg(long, short)]
    pub quiet: bool,
}

/// Options of `simulate`.
#[derive(Debug, Clone, Default, Args)]
#[command(allow_negative_numbers = true)]
pub struct SimulateArgs {
    /// Built-in model names (see `camchain list`) or paths to .ron model files; a path runs
    /// on the numeric recursive reference, without rebuilding [default: paper_concave
    /// paper_convex]
    #[arg(value_name = "MODEL")]
    pub models: Vec<String>,

    /// Run built-in models on the numeric recursive reference instead of their generated
    /// code (to compare the two) [default: generated code]
    #[arg(long)]
    pub numeric: bool,

    /// Give a run-time parameter another value than the model file's, NAME=VALUE (repeat
    /// for several; `camchain list` shows them); checked as the build checks the file. On
    /// the numeric path every parameter can be set, also those the generated code folds
    #[arg(long = "param", value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub params: Vec<String>,

    /// End time, output interval, integrator, step and tolerances.
    #[command(flatten)]
    pub integration: IntegrationArgs,

    /// One-sided contact: the follower lifts off where the normal force reaches zero and
    /// lands with this coefficient of restitution (0 plastic … 1 elastic); needs an adaptive
    /// integrator and one contact [default: the model file's `simulation.restitution`, or
    /// bilateral contact, as in the paper]
    #[arg(long, value_name = "E", value_parser = restitution, conflicts_with = "bilateral")]
    pub restitution: Option<f64>,

    /// Bilateral contact (the follower held on its cam, a negative normal force reported)
    /// even where the model file asks for one-sided contact
    #[arg(long)]
    pub bilateral: bool,

    /// Coordinates plotted in the time-history figure, comma-separated, e.g. q4,q3 (the
    /// paper's figures 3 and 5) [default: all, from the tip to the base]
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub coords: Vec<String>,

    /// Write the CSV of the (single) model to FILE, `-` for standard output; nothing else is
    /// written unless --out is given too [default: DIR/<run>/<run>.csv]
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,

    /// Directory for the CSV and figures, one subdirectory per run [default: out, or none
    /// with --csv]
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Write no figures (the CSV is still written) [default: figures are written]
    #[arg(long)]
    pub no_plots: bool,

    /// Print nothing but errors: no summary, no progress bar, no notes
    #[arg(long, short)]
    pub quiet: bool,
}

impl SimulateArgs {
    /// The `--param NAME=VALUE` pairs, checked: each a number, no name twice.
    pub fn parameter_values(&self) -> Result<Vec<(String, f64)>, String> {
        let mut out: Vec<(String, f64)> = Vec::new();
        for text in &self.params {
            let Some((name, value)) = text.split_once('=') else {
                return Err(format!("--param `{text}` is not NAME=VALUE (e.g. k3=60)"));
            };
            let (name, value) = (name.trim(), value.trim());
            let number: f64 = value
                .parse()
                .map_err(|_| format!("--param {name}: `{value}` is not a number"))?;
            if name.is_empty() {
                return Err(format!("--param `{text}`: the name is missing before `=`"));
            }
            if out.iter().any(|(n, _)| n == name) {
                return Err(format!("--param {name} is given twice"));
            }
            out.push((name.to_string(), number));
        }
        Ok(out)
    }

    /// The model's default settings overridden by the options that were given.
    pub fn settings(&self, defaults: &SimSettings) -> SimSettings {
        self.integration.settings(defaults)
    }

    /// The contact law of the run: `--restitution`, else bilateral with `--bilateral`, else
    /// the model file's.
    pub fn restitution(&self, model_default: Option<f64>) -> Option<f64> {
        match (self.restitution, self.bilateral) {
            (Some(e), _) => Some(e),
            (None, true) => None,
            (None, false) => model_default,
        }
    }

    /// True when the CSV goes to standard output (`--csv -`).
    pub fn csv_to_stdout(&self) -> bool {
        self.csv.as_deref().is_some_and(|p| p.as_os_str() == "-")
    }

    /// The output directory, if files other than `--csv` are to be written.
    pub fn out_dir(&self) -> Option<PathBuf> {
        match (&self.out, &self.csv) {
            (Some(dir), _) => Some(dir.clone()),
            (None, Some(_)) => None,
            (None, None) => Some(PathBuf::from(DEFAULT_OUT)),
        }
    }
}

/// `--integrator`: the runtime's integrators by name, in any letter case, each with its help
/// line.
fn integrator_parser() -> impl TypedValueParser<Value = IntegratorKind> {
    PossibleValuesParser::new(
        IntegratorKind::ALL
            .iter()
            .map(|k| PossibleValue::new(k.name()).help(k.spec().about)),
    )
    .try_map(|name| {
        IntegratorKind::parse(&name).ok_or_else(|| format!("unknown integrator `{name}`"))
    })
}

/// A coefficient of restitution: a number in [0, 1].
fn restitution(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    if (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!("{value} is not in [0, 1]"))
    }
}

/// A positive, finite number; `what` names it in messages.
fn positive(text: &str, what: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number ({what} is expected)"))?;
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(format!("{what} must be positive and finite, got {text}"))
    }
}

/// A tolerance in `range` (the runtime's, `camchain_runtime::settings`).
fn tolerance(text: &str, (low, high): (f64, f64)) -> Result<f64, String> {
    let value = positive(text, "a tolerance")?;
    if (low..=high).contains(&value) {
        Ok(value)
    } else {
        Err(format!(
            "{value:e} is outside [{low:e}, {high:e}]: below, the error estimate is round-off \
             (the steps shrink until the run fails); above, there is no accuracy left"
        ))
    }
}

/// A relative tolerance in the runtime's range.
fn relative_tolerance(text: &str) -> Result<f64, String> {
    tolerance(text, camchain_runtime::settings::RTOL_RANGE)
}

/// An absolute tolerance in the runtime's range.
fn absolute_tolerance(text: &str) -> Result<f64, String> {
    tolerance(text, camchain_runtime::settings::ATOL_RANGE)
}

/// A positive, finite time in seconds.
fn positive_time(text: &str) -> Result<f64, String> {
    positive(text, "a time in seconds")
}

/// A positive, finite speed in rad/s.
fn positive_speed(text: &str) -> Result<f64, String> {
    positive(text, "a speed in rad/s")
}

/// A whole number of at least `least`.
fn count(text: &str, least: usize) -> Result<usize, String> {
    let value: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a whole number"))?;
    if value >= least {
        Ok(value)
    } else {
        Err(format!("{value} is too small: at least {least} is needed"))
    }
}

/// Points of a profile table: at least 3 (a closed curve), at most [`MAX_CAM_SAMPLES`].
fn table_points(text: &str) -> Result<usize, String> {
    bounded(count(text, 3)?, MAX_CAM_SAMPLES)
}

/// Most samples a turn `camchain cam` takes (`--samples`, `--points`): each is a row
/// of every curve the report keeps in memory (about 200 bytes), so a million is 200 MB.
pub const MAX_CAM_SAMPLES: usize = 1_000_000;

/// Most turns of `camchain cam`'s one-sided run.
pub const MAX_CAM_TURNS: usize = 10_000;

/// `value`, or an error when it is above `most`.
fn bounded(value: usize, most: usize) -> Result<usize, String> {
    if value <= most {
        Ok(value)
    } else {
        Err(format!("{value} is too large: at most {most}"))
    }
}

/// `cam --samples`: 1 to [`MAX_CAM_SAMPLES`].
fn cam_samples(text: &str) -> Result<usize, String> {
    bounded(count(text, 1)?, MAX_CAM_SAMPLES)
}

/// `cam --turns`: 1 to [`MAX_CAM_TURNS`].
fn cam_turns(text: &str) -> Result<usize, String> {
    bounded(count(text, 1)?, MAX_CAM_TURNS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn times_must_be_positive() {
        assert_eq!(positive_time("2.5"), Ok(2.5));
        for bad in ["-1", "0", "nan", "inf", "abc", ""] {
            assert!(positive_time(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn options_override_the_model_defaults() {
        let defaults = SimSettings {
            t_end: 10.0,
            dt_out: 0.01,
            integrator: IntegratorKind::Dopri5,
            dt: 1e-3,
            rtol: 1e-10,
            atol: 1e-12,
        };
        let cli = Cli::try_parse_from([
            "camchain",
            "simulate",
            "--t-end",
            "2",
            "--integrator",
            "rk4",
        ])
        .unwrap();
        let Some(Command::Simulate(args)) = cli.command else {
            panic!("simulate expected");
        };
        let settings = args.settings(&defaults);
        assert_eq!(settings.t_end, 2.0);
        assert_eq!(settings.integrator, IntegratorKind::Rk4);
        assert_eq!(settings.dt_out, 0.01);
        assert_eq!(args.out_dir(), Some(PathBuf::from("out")));
    }

    #[test]
    fn stress_writes_stress_md_unless_told_otherwise() {
        let cli = Cli::try_parse_from(["camchain", "stress"]).unwrap();
        let Some(Command::Stress(args)) = cli.command else {
            panic!("stress expected");
        };
        assert!(!args.quick && args.figures.is_none());
        assert_eq!(args.out, PathBuf::from("STRESS.md"));
        let cli =
            Cli::try_parse_from(["camchain", "stress", "--quick", "--out", "r/S.md"]).unwrap();
        let Some(Command::Stress(args)) = cli.command else {
            panic!("stress expected");
        };
        assert!(args.quick);
        assert_eq!(args.out, PathBuf::from("r/S.md"));
        assert!(Cli::try_parse_from(["camchain", "stress", "paper_concave"]).is_err());
    }

    #[test]
    fn csv_alone_writes_no_directory() {
        let cli = Cli::try_parse_from(["camchain", "simulate", "--csv", "-"]).unwrap();
        let Some(Command::Simulate(args)) = cli.command else {
            panic!("simulate expected");
        };
        assert!(args.csv_to_stdout());
        assert_eq!(args.out_dir(), None);
    }
}
