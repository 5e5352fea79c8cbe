//! `camchain bench`: the measurements behind `BENCHMARKS.md`, each taken side by side in one
//! run on this machine.
//!
//! - `work-precision`: run time against error for every integrator over a ladder of steps
//!   and tolerances, on the reference models, against a checked reference solution;
//! - `evaluations`: one evaluation of M+F+Q, the constraint terms, the reduced right-hand
//!   side and one RK4 step, generated code against the numeric recursion, on the same states;
//!   then (section `cams`) the reduced right-hand side of the cams on moving bodies against
//!   the fixed-cam paper model's, and one full camshaft revolution at 1e-10 of the camshaft
//!   models; then (section `designs`) the reduced right-hand side of a cam given as a table of
//!   points against the same cam given by its motion law, and revolutions of the designed cams;
//!   then (section `loops`) the reduced right-hand side of loop models, Andrews' squeezer's
//!   work against precision, and the IFToMM benchmarks A02 and A04; then (section
//!   `surfaces`, also alone as `surfaces`) the spatial cams: a saddle surface generated
//!   against numeric, a barrel cam against the disc cam of the same program, the surface
//!   contact's operations against the planar one's;
//! - `events`: what finding events inside steps costs on the built-in models (right-hand
//!   sides per step watched and not), and the one-sided runs where the scans find every
//!   lift-off and impact;
//! - `sweep`: the whole-run overhead of a metrics run, the throughput of `camchain sweep` with
//!   1 and 2 workers, and its memory against the number of runs;
//! - `scaling-figure`: the figure of the scaling study from the CSV of
//!   `cargo run --release -p camchain-codegen --example scaling -- OUTDIR --build`.
//!
//! Timings are medians over batches, generated and numeric batches interleaved so that
//! machine noise hits both alike. No timing is asserted anywhere (see the tests).

mod a02;
mod cams;
mod designs;
mod evaluations;
mod events;
mod loops;
mod markdown;
mod scaling;
mod surfaces;
mod sweep;
mod timing;
mod work_precision;

use super::CliError;
use super::args::{BenchArgs, BenchWhat};

/// Runs the benchmarks `args` asks for and updates their sections of the report.
pub fn run(args: &BenchArgs) -> Result<(), CliError> {
    let report = &args.report;
    // Say so before minutes of measuring rather than after.
    let directory = report.parent().filter(|d| !d.as_os_str().is_empty());
    if directory.is_some_and(|d| !d.is_dir()) {
        return Err(CliError::Usage(format!(
            "--report {}: the directory does not exist",
            report.display()
        )));
    }
    if matches!(args.what, BenchWhat::Evaluations | BenchWhat::All) {
        let section = evaluations::run(args.quick)?;
        markdown::replace_section(report, "evaluations", &section)?;
        println!("updated {} (section evaluations)", report.display());
        let section = cams::run(args.quick)?;
        markdown::replace_section(report, "cams", &section)?;
        println!("updated {} (section cams)", report.display());
        let section = designs::run(args.quick)?;
        markdown::replace_section(report, "designs", &section)?;
        println!("updated {} (section designs)", report.display());
    }
    if matches!(
        args.what,
        BenchWhat::Evaluations | BenchWhat::Loops | BenchWhat::All
    ) {
        let section = loops::run(args.quick)?;
        markdown::replace_section(report, "loops", &section)?;
        println!("updated {} (section loops)", report.display());
    }
    if matches!(
        args.what,
        BenchWhat::Evaluations | BenchWhat::Surfaces | BenchWhat::All
    ) {
        let section = surfaces::run(args.quick)?;
        markdown::replace_section(report, "surfaces", &section)?;
        println!("updated {} (section surfaces)", report.display());
    }
    if let BenchWhat::ScalingFigure = args.what {
        let csv = args.scaling_csv.as_deref().ok_or_else(|| {
            CliError::Usage(
                "scaling-figure needs --scaling-csv FILE (written by the scaling example)".into(),
            )
        })?;
        scaling::run(csv, &args.figures)?;
        println!("wrote {}/scaling.png and .svg", args.figures.display());
        return Ok(());
    }
    if matches!(args.what, BenchWhat::Events | BenchWhat::All) {
        let section = events::run(args.quick)?;
        markdown::replace_section(report, "events", &section)?;
        println!("updated {} (section events)", report.display());
    }
    if matches!(args.what, BenchWhat::Sweep | BenchWhat::All) {
        let section = sweep::run(args.quick)?;
        markdown::replace_section(report, "sweep", &section)?;
        println!("updated {} (section sweep)", report.display());
    }
    if matches!(args.what, BenchWhat::WorkPrecision | BenchWhat::All) {
        let section = work_precision::run(args.quick, &args.figures)?;
        markdown::replace_section(report, "work-precision", &section)?;
        println!("updated {} (section work-precision)", report.display());
    }
    Ok(())
}
