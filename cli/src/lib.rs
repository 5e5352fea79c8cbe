//! camchain-cli: the `camchain` command line (its binary is `src/main.rs`), with every
//! dependency only it needs (clap, plotters, png, dejavu, indicatif).
//!
//! Modules (private but for [`scenarios`], which the stress tests use, and [`args`], [`csv`],
//! [`summary`], [`sweep`] and [`cam`], which the Python package uses for the same settings,
//! columns, summaries, sweeps and cam reports):
//! - `args`: the syntax (clap) and the settings it overrides;
//! - `source`: which model a MODEL argument names, generated or numeric;
//! - `plan`: what `simulate` checks before it runs or writes anything;
//! - `simulate`: the `simulate` command, run by run;
//! - `progress`, `summary`, `csv`, `output`: what a run shows and writes; `interrupt`:
//!   Ctrl-C during a run;
//! - `kinematics`, `figures`, `plots`: the figures after the paper's figures 3–6;
//! - `list`: the `list` command;
//! - `ops`: the `ops` command (operation counts of the generated functions);
//! - `stress`: the `stress` command (numerical stability stress suite, `STRESS.md`), over the
//!   scenarios of [`scenarios`];
//! - `bench`: the `bench` command (the measurements of `BENCHMARKS.md`);
//! - `sweep`: the `sweep` and `merge` commands (parameter studies, in parallel and in
//!   shards);
//! - `cam`: the `cam` command (a cam designed from a motion law: its design's checks and
//!   figures, the jump speed its dynamics predict, a one-sided run);
//! - `fmu`: the `fmu` command (the model as an FMI 3.0 Co-Simulation FMU).
//!
//! Every problem is reported as one line on standard error, `error: …`, with exit code 2
//! for a usage error (bad option or value, unknown model name), 130 for a run interrupted
//! by Ctrl-C and 143 for one stopped by SIGTERM, 3 and up for a sweep some of whose runs failed (3 + failed − 1, at most 127),
//! and 1 for anything else (a model file missing or invalid, a failed run, a file that could
//! not be written).

pub mod args;
mod bench;
pub mod cam;
pub mod csv;
mod figures;
mod fmu;
mod interrupt;
mod kinematics;
mod list;
mod ops;
mod output;
mod plan;
mod plots;
mod progress;
pub mod scenarios;
mod simulate;
mod source;
mod stress;
pub mod summary;
pub mod sweep;

use args::{Cli, Command};
use clap::Parser;
use std::io::Write;
use std::process::ExitCode;

/// `1 run`, `2 runs`: a count and its noun, in the plural unless the count is one (`noun`
/// is the singular; every noun printed with a count here takes an `s`).
pub(crate) fn counted(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// Why the command failed.
#[derive(Debug)]
pub enum CliError {
    /// The command line is wrong (exit code 2).
    Usage(String),
    /// Something else went wrong (exit code 1).
    Failed(String),
    /// Failures already reported as they happened (exit code 1).
    Reported,
    /// Interrupted by Ctrl-C (exit code 130) or SIGTERM (143), already reported.
    Interrupted {
        /// The exit code.
        code: u8,
    },
    /// This many runs of a sweep failed, reported in their rows and the summary (exit code
    /// 3 + (failed − 1), at most 127).
    RunsFailed(usize),
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CliError::Usage(message) | CliError::Failed(message) => f.write_str(message),
            CliError::Reported => f.write_str("failed (reported above)"),
            CliError::Interrupted { .. } => f.write_str("interrupted (reported above)"),
            CliError::RunsFailed(n) => write!(f, "{} failed", counted(*n, "run")),
        }
    }
}

impl CliError {
    fn exit_code(&self) -> ExitCode {
        match self {
            CliError::Usage(_) => ExitCode::from(2),
            CliError::Failed(_) | CliError::Reported => ExitCode::from(1),
            CliError::Interrupted { code } => ExitCode::from(*code),
            CliError::RunsFailed(n) => ExitCode::from(sweep_exit_code(*n)),
        }
    }
}

/// The exit code of a sweep whose `failed` runs failed: 3 for one, one more per failure, at
/// most 127 (below 130 and 143, the signals').
pub fn sweep_exit_code(failed: usize) -> u8 {
    (3 + failed.saturating_sub(1)).min(127) as u8
}

/// Parses the command line, runs the command and returns the process's exit code.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_error(&e),
    };
    let result = match cli.command {
        None => simulate::run(&cli.simulate),
        Some(Command::Simulate(args)) => simulate::run(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::Ops { models }) => ops::render(&models).map(|text| {
            let _ = std::io::stdout().write_all(text.as_bytes());
        }),
        Some(Command::Stress(args)) => stress::run(&args),
        Some(Command::Sweep(args)) => sweep::run(&args),
        Some(Command::Merge(args)) => sweep::merge(&args),
        Some(Command::Cam(args)) => cam::run(&args),
        Some(Command::Fmu(args)) => fmu::run(&args, &interrupt::Interrupt::install()),
        Some(Command::List) => {
            // A closed pipe (`camchain list | head`) is not an error worth a panic.
            let _ = std::io::stdout().write_all(list::render().as_bytes());
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            match &error {
                CliError::Usage(message) | CliError::Failed(message) => {
                    eprintln!("error: {message}");
                }
                CliError::Reported | CliError::Interrupted { .. } => {}
                CliError::RunsFailed(n) => {
                    eprintln!("error: {} failed (see their rows)", counted(*n, "run"));
                }
            }
            error.exit_code()
        }
    }
}

/// Help and version go to standard output with exit code 0; a usage error is shortened to
/// one line (clap's first line and the possible values, if it lists them).
fn clap_error(e: &clap::Error) -> ExitCode {
    if !e.use_stderr() {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    eprintln!("{}", one_line(&e.render().to_string()));
    ExitCode::from(2)
}

/// `error: invalid value 'euler' for '--integrator <NAME>' [possible values: rk4,
/// dopri5]`, followed by where to find help.
fn one_line(rendered: &str) -> String {
    let mut lines = rendered.lines().map(str::trim).filter(|l| !l.is_empty());
    let mut text = lines
        .next()
        .unwrap_or("error: invalid command line")
        .to_string();
    // "the following required arguments were not provided:" and the arguments, one a line.
    if text.ends_with(':') {
        let missing: Vec<&str> = lines
            .by_ref()
            .take_while(|l| !l.starts_with("Usage:"))
            .collect();
        text.push(' ');
        text.push_str(&missing.join(", "));
    }
    if let Some(values) = lines.find(|l| l.starts_with("[possible values")) {
        text.push(' ');
        text.push_str(values);
    }
    text.push_str(" (see `camchain --help`)");
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clap_errors_fit_on_one_line() {
        let error =
            Cli::try_parse_from(["camchain", "simulate", "--integrator", "euler"]).unwrap_err();
        let text = one_line(&error.render().to_string());
        assert!(!text.contains('\n'));
        assert!(
            text.contains("euler") && text.contains("rk4, dopri5"),
            "{text}"
        );
        let error = Cli::try_parse_from(["camchain", "simulate", "--t-end", "-1"]).unwrap_err();
        let text = one_line(&error.render().to_string());
        assert!(text.contains("must be positive"), "{text}");
    }

    #[test]
    fn the_following_required_arguments_are_named() {
        for (args, missing) in [
            (&["camchain", "sweep", "paper_concave"][..], "--param"),
            (&["camchain", "cam"][..], "<MODEL>"),
            (&["camchain", "merge", "--csv", "m.csv"][..], "<FILE>"),
        ] {
            let error = Cli::try_parse_from(args).unwrap_err();
            let text = one_line(&error.render().to_string());
            assert!(
                text.contains("not provided: ") && text.contains(missing),
                "{args:?}: {text}"
            );
        }
    }

    #[test]
    fn cam_sizes_that_meet_memory_are_refused_before_running() {
        for args in [
            &[
                "camchain",
                "cam",
                "cycloidal_roller",
                "--samples",
                "1000000000000",
            ][..],
            &[
                "camchain",
                "cam",
                "cycloidal_roller",
                "--turns",
                "1000000000",
            ][..],
            &[
                "camchain",
                "cam",
                "cycloidal_roller",
                "--table",
                "t.csv",
                "--points",
                "1000000000",
            ][..],
        ] {
            let error = Cli::try_parse_from(args).unwrap_err();
            assert!(
                one_line(&error.render().to_string()).contains("too large: at most"),
                "{args:?}"
            );
        }
    }
}
