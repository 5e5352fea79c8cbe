//! `camchain stress`: the numerical stability stress suite. Runs every scenario of
//! [`crate::scenarios`] with every integrator configuration and writes `STRESS.md` (one
//! table per scenario) and its figures.
//!
//! The scenarios: long undamped runs (1000 s, `--quick`: 100 s), stiff springs, extreme
//! masses and inertias, fast motion, re-partitioning through a vanishing Jacobian entry,
//! steep, flat, inflected and wavy profiles, an unreachable cam and non-finite values. A
//! failing run is a result, not an error of the command: its message goes into the table.
//!
//! One module per concept: [`case`] runs a model with every integration, [`tables`] and
//! [`charts`] turn results into markdown and figures, and one module per group of scenarios
//! ([`long`], [`extremes`], [`geometry`], [`non_finite`]) writes its section.

mod case;
mod charts;
mod extremes;
mod geometry;
mod long;
mod non_finite;
mod tables;

use super::CliError;
use super::args::StressArgs;
use super::plots::Figure;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A section of the report.
struct Section {
    heading: String,
    text: String,
}

/// Runs the `stress` command.
pub fn run(args: &StressArgs) -> Result<(), CliError> {
    let out_dir = args.out.parent().map(Path::to_path_buf).unwrap_or_default();
    let figures = args
        .figures
        .clone()
        .unwrap_or_else(|| out_dir.join("docs").join("stress"));
    // Both destinations checked and held before the first of the suite's minutes.
    let _report_lock = crate::output::claim(&args.out).map_err(CliError::Failed)?;
    let _figures_lock = crate::output::create_dir(&figures).map_err(CliError::Failed)?;
    let link_dir = figures
        .strip_prefix(&out_dir)
        .map(Path::to_path_buf)
        .unwrap_or_else(|_| figures.clone());
    let ctx = Context {
        quick: args.quick,
        figures,
        link_dir,
        started: Instant::now(),
    };
    let sections = vec![
        long::long_runs(&ctx)?,
        extremes::stiff_springs(&ctx)?,
        extremes::masses(&ctx)?,
        extremes::fast_motion(&ctx)?,
        geometry::repartition(&ctx)?,
        geometry::profiles(&ctx)?,
        geometry::unreachable(&ctx)?,
        non_finite::non_finite(&ctx)?,
    ];
    let report = render(&ctx, &sections);
    crate::output::write_bytes(&args.out, report.as_bytes()).map_err(CliError::Failed)?;
    say(&format!(
        "wrote {} and its figures in {} ({:.0} s)\n",
        args.out.display(),
        ctx.figures.display(),
        ctx.started.elapsed().as_secs_f64()
    ));
    Ok(())
}

struct Context {
    quick: bool,
    figures: PathBuf,
    link_dir: PathBuf,
    started: Instant,
}

impl Context {
    /// Saves a figure and returns its markdown image line.
    fn figure(&self, figure: &Figure, stem: &str, caption: &str) -> Result<String, CliError> {
        figure
            .save(&self.figures, stem)
            .map_err(|e| CliError::Failed(format!("figure {stem}: {e}")))?;
        let link = self.link_dir.join(format!("{stem}.png"));
        Ok(format!(
            "![{caption}]({})\n\n*{caption}*\n\n",
            link.display().to_string().replace('\\', "/")
        ))
    }
}

fn say(text: &str) {
    let _ = std::io::stdout().write_all(text.as_bytes());
}

fn failed(message: String) -> CliError {
    CliError::Failed(message)
}

/// The whole report.
fn render(ctx: &Context, sections: &[Section]) -> String {
    let mut text = String::from(
        "# Numerical stability stress report\n\n\
         Written by `cargo run --release -- stress` (see the README); every number below comes \
         from that run. Variants of the reference models are built in memory \
         (`camchain_cli::scenarios`) and run on the numeric recursive reference; the unmodified \
         paper models also run their generated code. Integrations: RK4 with a fixed step \
         (`rk4 dt=…`) and each adaptive integrator at several tolerances (`dopri5 rtol=…`, \
         atol = rtol/100). Columns: *outcome* `ok` or the error the run stopped with \
         (its variant and message); *steps*, *rejected*, *RHS* (right-hand side evaluations), \
         *re-partitions*: the runtime's counters; *max |h|*: the largest constraint residual \
         at the output times; *energy drift*: the largest change of energy + dissipated − \
         driven work; *max |q − q_ref|*: the largest coordinate difference from the \
         reference run named in the section, at the output times. Fast checks of the same \
         properties run in `cargo test` (`cli/tests/suite/stress.rs`, `cli/tests/suite/repartition.rs`).\n\n",
    );
    if ctx.quick {
        text.push_str("**This is a `--quick` run: long runs last 100 s, not 1000 s.**\n\n");
    }
    text.push_str("## Contents\n\n");
    for section in sections {
        let anchor: String = section
            .heading
            .to_lowercase()
            .chars()
            .filter_map(|c| match c {
                'a'..='z' | '0'..='9' | '-' | '_' => Some(c),
                ' ' => Some('-'),
                _ => None,
            })
            .collect();
        let _ = writeln!(text, "- [{}](#{anchor})", section.heading);
    }
    text.push('\n');
    for section in sections {
        let _ = write!(text, "## {}\n\n{}", section.heading, section.text);
    }
    text
}
