//! Spatial cams, side by side in one run:
//!
//! - the reduced right-hand side of `paper_surface` (the paper's chain on a turret, its tip
//!   on a saddle surface) generated against the numeric reference, on the same states;
//! - the reduced right-hand side of `barrel_indexer` (a barrel cam designed from a cycloidal
//!   program) against that of `cycloidal_roller` (a disc cam from the same program), batches
//!   of the two interleaved (goal: within 1.3×);
//! - the operation counts of the paper's chain with its cam written as a surface z = f(x)
//!   (`tests/contact_models/paper_on_surface.ron`) against `paper_concave`'s: the same chain,
//!   the surface contact against the planar one (goal: within 1.5×), derived now.

use super::cams::{consecutive_states, derivative_along};
use super::evaluations::{derivative, states_along_a_run};
use super::timing::side_by_side;
use crate::CliError;
use crate::source::builtin_description;
use camchain_codegen::{EmitOptions, generate_source};
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::Dynamics;
use std::fmt::Write;
use std::path::Path;

/// The barrel cam and the disc cam of the same program.
const BARREL: &str = "barrel_indexer";
const DISC: &str = "cycloidal_roller";

/// Goal: the barrel's right-hand side within this factor of the disc cam's.
const BARREL_GOAL: f64 = 1.3;

/// Goal: the surface contact's operations within this factor of the planar contact's.
const SURFACE_GOAL: f64 = 1.5;

/// The paper's cam as a surface: the test model, embedded when the command line is built.
const PAPER_ON_SURFACE: &str = include_str!("../../../tests/contact_models/paper_on_surface.ron");

/// The functions a reduced right-hand side evaluates.
const RHS_FUNCTIONS: [&str; 2] = ["position_terms", "velocity_terms"];

/// What is measured.
struct Measured {
    /// `paper_surface`: (generated, numeric) at a new state.
    surface: (f64, f64),
    /// `barrel_indexer` against `cycloidal_roller`: at a new state and along a run.
    new_state: (f64, f64),
    along: (f64, f64),
    /// Operations of the right-hand side's functions: (paper_on_surface, paper_concave),
    /// per function and in all.
    ops: Vec<(String, usize, usize)>,
}

/// Measures and returns the report section.
pub fn run(quick: bool) -> Result<String, CliError> {
    let (calls, batches) = if quick { (2_000, 5) } else { (20_000, 31) };
    eprintln!("surfaces: paper_surface, generated and numeric");
    let generated = builtin("paper_surface")?;
    let numeric = NumericModel::new(builtin_description("paper_surface")?);
    let states = states_along_a_run(generated)?;
    let surface = side_by_side(
        derivative(generated, &states)?,
        derivative(&numeric, &states)?,
        calls / 10,
        batches,
    );
    eprintln!("surfaces: right-hand sides of {BARREL} and {DISC}");
    let (barrel, disc) = (builtin(BARREL)?, builtin(DISC)?);
    let new_state = side_by_side(
        derivative(barrel, &states_along_a_run(barrel)?)?,
        derivative(disc, &states_along_a_run(disc)?)?,
        calls,
        batches,
    );
    let along = side_by_side(
        derivative_along(barrel, &consecutive_states(barrel)?)?,
        derivative_along(disc, &consecutive_states(disc)?)?,
        calls,
        batches,
    );
    Ok(render(
        &Measured {
            surface,
            new_state,
            along,
            ops: operation_counts()?,
        },
        calls,
        batches,
    ))
}

fn builtin(name: &str) -> Result<&'static dyn Dynamics, CliError> {
    match models::by_name(name) {
        Some(model) => Ok(model),
        None => Err(CliError::Failed(format!("{name} is not built in"))),
    }
}

/// The right-hand side's operations of the paper's chain on its cam as a surface and as a
/// plane curve, both derived now by the code generator.
fn operation_counts() -> Result<Vec<(String, usize, usize)>, CliError> {
    let count = |source: &str, file: &str| -> Result<Vec<(String, usize)>, CliError> {
        let generated = generate_source(source, Path::new(file), &EmitOptions::default())
            .map_err(|e| CliError::Failed(e.to_string()))?;
        Ok(generated
            .op_counts
            .iter()
            .map(|(name, c)| (name.clone(), c.total()))
            .collect())
    };
    let surface = count(
        PAPER_ON_SURFACE,
        "tests/contact_models/paper_on_surface.ron",
    )?;
    let planar_source = models::source("paper_concave")
        .ok_or_else(|| CliError::Failed("paper_concave is not built in".into()))?;
    let planar = count(planar_source, "models/paper_concave.ron")?;
    let total = |counts: &[(String, usize)], name: &str| {
        counts
            .iter()
            .find(|(n, _)| n == name)
            .map_or(0, |(_, total)| *total)
    };
    let mut rows: Vec<(String, usize, usize)> = ["constraint", "constraint_terms"]
        .iter()
        .chain(&RHS_FUNCTIONS)
        .map(|name| {
            (
                format!("`{name}`"),
                total(&surface, name),
                total(&planar, name),
            )
        })
        .collect();
    let sum = |counts: &[(String, usize)]| -> usize {
        RHS_FUNCTIONS.iter().map(|name| total(counts, name)).sum()
    };
    rows.push((
        "a right-hand side's (`position_terms` + `velocity_terms`)".to_string(),
        sum(&surface),
        sum(&planar),
    ));
    Ok(rows)
}

fn render(m: &Measured, calls: usize, batches: usize) -> String {
    let mut out = String::new();
    let verdict = |ratio: f64, goal: f64| if ratio <= goal { "met" } else { "missed" };
    let _ = writeln!(out, "## Spatial cams\n");
    let _ = writeln!(
        out,
        "`derivative` of the generated code (Newton on the dependent coordinates, their \
         velocities, the reduced dynamics) at a new state (8 consistent states along each \
         model's run, the evaluation cache cleared before each call) and along a run (8 \
         consecutive states 1 ms apart through one state object). Median of {batches} batches \
         of {calls} calls (the numeric reference: a tenth), the two sides' batches in turn.\n"
    );
    let (g, n) = m.surface;
    let _ = writeln!(
        out,
        "### The paper's chain on a saddle surface\n\n`paper_surface` (five bodies: the paper's \
         four on a turret; the tip on y = a (x² − z²) + b): generated {g:.0} ns, numeric \
         {n:.0} ns, {:.1}× faster.\n",
        n / g
    );
    let _ = writeln!(
        out,
        "### A barrel cam against the disc cam of the same program\n\n`{BARREL}` (a groove on \
         a cylinder, z = base + s(φ)) against `{DISC}` (a disc cam for a translating roller), \
         both designed from a cycloidal dwell–rise–dwell–return program (goal: within \
         {BARREL_GOAL}×).\n"
    );
    let _ = writeln!(
        out,
        "| | `{BARREL}` [ns] | `{DISC}` [ns] | ratio |\n|---|---:|---:|---|"
    );
    for (what, (a, b)) in [("new state", m.new_state), ("along a run", m.along)] {
        let r = a / b;
        let _ = writeln!(
            out,
            "| {what} | {a:.0} | {b:.0} | {r:.2}× ({}) |",
            verdict(r, BARREL_GOAL)
        );
    }
    let _ = writeln!(
        out,
        "\nThe barrel's contact point is the roller's centre on its pitch surface (no search \
         for the point nearest the roller, which the disc cam solves by Newton).\n"
    );
    let _ = writeln!(
        out,
        "### The surface contact against the planar one, on the same chain\n\nOperation \
         counts of the code generator (add/sub, mul, div, sin/cos, sqrt and others, each \
         shared node once), derived now: the paper's chain with its cam written as the \
         surface z = f(x) in a frame whose z axis is the ground's y \
         (`tests/contact_models/paper_on_surface.ron`, which reproduces `paper_concave`'s run \
         to 2.4e-14) against `paper_concave` (goal: within {SURFACE_GOAL}×).\n"
    );
    let _ = writeln!(
        out,
        "| function | surface | planar | ratio |\n|---|---:|---:|---|"
    );
    for (name, surface, planar) in &m.ops {
        let r = *surface as f64 / (*planar).max(1) as f64;
        let _ = writeln!(
            out,
            "| {name} | {surface} | {planar} | {r:.2}× ({}) |",
            verdict(r, SURFACE_GOAL)
        );
    }
    let _ = writeln!(
        out,
        "\nReproduce: `cargo run --release -- bench evaluations` (this section with the \
         others of `evaluations`) or `cargo run --release -- bench surfaces` (this one alone)."
    );
    out
}
