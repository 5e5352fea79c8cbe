//! Profiles from tables of points and from motion laws, side by side in one run:
//!
//! - the reduced right-hand side of `table_cam` (the cam of `cycloidal_roller` as a table of
//!   720 points) against that of `cycloidal_roller` (the same cam designed from its law),
//!   batches of the two interleaved: the cost of the spline look-up against the law's closed
//!   form (goal: within 1.3×);
//! - the look-ups alone: the runtime's spline on that table and the law's segments, at the
//!   same cam angles;
//! - one camshaft revolution at rtol = atol = 1e-10 of the designed cams and the table cam,
//!   their follower against the law.

use super::cams::{consecutive_states, derivative_along};
use super::evaluations::{derivative, states_along_a_run};
use super::timing::side_by_side;
use crate::CliError;
use crate::source::builtin_description;
use camchain_codegen::design::CamDesign;
use camchain_codegen::profile::{Scalar, TabulatedFunction};
use camchain_models as models;
use camchain_runtime::{Dynamics, IntegratorKind, SimSettings, Simulate};
use std::fmt::Write;
use std::hint::black_box;

/// The law's cam and its table.
const LAW: &str = "cycloidal_roller";
const TABLE: &str = "table_cam";

/// Goal: the table's right-hand side within this factor of the law's.
const GOAL_RATIO: f64 = 1.3;

/// rtol = atol of the revolution runs.
const TOLERANCE: f64 = 1e-10;

/// One revolution of one model.
struct Revolution {
    model: &'static str,
    seconds: f64,
    steps: usize,
    rejected: usize,
    rhs: usize,
    /// The largest difference of the follower's coordinate from the law's (m or rad).
    error: f64,
    /// The law's lift (m or rad), for the error's scale.
    lift: f64,
}

/// What is measured.
struct Measured {
    new_state: (f64, f64),
    along: (f64, f64),
    spline_ns: f64,
    law_ns: f64,
    points: usize,
    revolutions: Vec<Revolution>,
}

/// Measures and returns the report section.
pub fn run(quick: bool) -> Result<String, CliError> {
    let (calls, batches) = if quick { (2_000, 5) } else { (20_000, 31) };
    let (law, table) = (builtin(LAW)?, builtin(TABLE)?);
    eprintln!("designs: right-hand sides of {TABLE} and {LAW}");
    let (law_states, table_states) = (states_along_a_run(law)?, states_along_a_run(table)?);
    let new_state = side_by_side(
        derivative(table, &table_states)?,
        derivative(law, &law_states)?,
        calls,
        batches,
    );
    let along = side_by_side(
        derivative_along(table, &consecutive_states(table)?)?,
        derivative_along(law, &consecutive_states(law)?)?,
        calls,
        batches,
    );
    let (spline_ns, law_ns, points) = lookups(calls, batches)?;
    let mut revolutions = Vec::new();
    for name in [LAW, TABLE, "polynomial_rocker"] {
        eprintln!("designs: one revolution of {name}");
        revolutions.push(revolution(name, quick)?);
    }
    Ok(render(
        &Measured {
            new_state,
            along,
            spline_ns,
            law_ns,
            points,
            revolutions,
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

/// The design of a built-in model's first designed contact.
fn design(name: &str) -> Result<CamDesign, CliError> {
    builtin_description(name)?
        .contacts
        .iter()
        .find_map(|c| c.design.clone())
        .ok_or_else(|| CliError::Failed(format!("{name} has no cam designed from a law")))
}

/// The per-call time (ns) of the spline look-up on `table_cam`'s x table and of the law's
/// evaluation, at 64 angles of a turn (the spline at the chord lengths where those angles
/// fall), and the table's number of points.
fn lookups(calls: usize, batches: usize) -> Result<(f64, f64, usize), CliError> {
    let described = builtin_description(TABLE)?;
    let spline = described
        .contacts
        .first()
        .and_then(|c| match c.profile_expression() {
            Scalar::Table(t, _, _) => match &t.function {
                TabulatedFunction::Spline(s) => Some(s.clone()),
                TabulatedFunction::Law(_) => None,
            },
            _ => None,
        })
        .ok_or_else(|| CliError::Failed(format!("{TABLE}'s profile is not a table")))?;
    let program = design(LAW)?.program;
    let length = spline.abscissas().last().copied().unwrap_or(1.0);
    let at: Vec<f64> = (0..64).map(|k| (k as f64 + 0.37) / 64.0).collect();
    let mut k = 0;
    let mut j = 0;
    let (spline_ns, law_ns) = side_by_side(
        || {
            k = (k + 1) % at.len();
            black_box(spline.eval(black_box(at[k] * length)));
        },
        || {
            j = (j + 1) % at.len();
            black_box(program.eval(black_box(at[j] * std::f64::consts::TAU)));
        },
        calls * 10,
        batches,
    );
    Ok((spline_ns, law_ns, spline.abscissas().len()))
}

/// One revolution at `TOLERANCE`, its follower coordinate against the law's.
fn revolution(name: &'static str, quick: bool) -> Result<Revolution, CliError> {
    let model = builtin(name)?;
    let failed = |e: String| CliError::Failed(format!("{name}: {e}"));
    let law = design(if name == TABLE { LAW } else { name })?;
    let omega = law
        .speed
        .ok_or_else(|| failed("the law gives no speed".into()))?;
    let start = model.assemble(0.0).map_err(|e| failed(e.to_string()))?;
    let settings = SimSettings {
        integrator: IntegratorKind::Dop853,
        rtol: TOLERANCE,
        atol: TOLERANCE,
        t_end: std::f64::consts::TAU / omega,
        ..model.info().defaults.clone()
    };
    let run = model
        .simulate_states(start.clone(), &settings)
        .map_err(|f| failed(f.to_string()))?;
    // The follower's coordinate (index 1: the camshaft is body 0) and its value at the base
    // circle, the first sample's (every law here starts at lift 0).
    let base = run.samples.first().map_or(0.0, |s| s.q[1]);
    let sign = if law.senses.swing < 0.0 { -1.0 } else { 1.0 };
    let error = run
        .samples
        .iter()
        .map(|s| (s.q[1] - base - sign * law.program.eval(omega * s.t)[0]).abs())
        .fold(0.0, f64::max);
    let lift = law
        .program
        .segments()
        .iter()
        .fold(0.0f64, |m, s| m.max(s.lift.abs()));
    let (budget, most) = if quick { (0.05, 7) } else { (0.3, 31) };
    let once = super::timing::median_seconds(|| model.simulate_states(start.clone(), &settings), 1);
    let repeats = ((budget / once.max(1e-6)) as usize).clamp(3, most);
    let seconds =
        super::timing::median_seconds(|| model.simulate_states(start.clone(), &settings), repeats);
    Ok(Revolution {
        model: name,
        seconds,
        steps: run.stats.steps,
        rejected: run.stats.rejected,
        rhs: run.stats.rhs_evaluations,
        error,
        lift,
    })
}

fn render(m: &Measured, calls: usize, batches: usize) -> String {
    let mut out = String::new();
    let ratio = |(a, b): (f64, f64)| {
        let r = a / b;
        format!(
            "{r:.2}× ({})",
            if r <= GOAL_RATIO { "met" } else { "missed" }
        )
    };
    let _ = writeln!(
        out,
        "## Profiles from tables and motion laws\n\n\
         ### The table's spline against the law's closed form\n\n\
         `{TABLE}` is `{LAW}` with its cam given as a table of {} points (720 and the first \
         repeated; a closed chord-length spline read from a CSV file) instead of the law it \
         was designed from; the two models are otherwise the same file. `derivative` of the \
         generated code at a new state (8 consistent states along each model's run, the \
         evaluation cache cleared before each call, so each contact parameter is found from a \
         scan of the profile) and along a run (8 consecutive states 1 ms apart through one \
         state object, Newton warm-started). Median of {batches} batches of {calls} calls, a \
         batch of each model in turn (goal: the table within {GOAL_RATIO}× of the law).\n\n\
         | | `{TABLE}` [ns] | `{LAW}` [ns] | ratio |\n|---|---:|---:|---|\n\
         | new state | {:.0} | {:.0} | {} |\n\
         | along a run | {:.0} | {:.0} | {} |\n\n\
         The look-ups alone, at 64 cam angles in turn (median of {batches} batches): the spline \
         `rt::spline::evaluate` on the {}-point table (a branchless bisection for the segment and a cubic with its \
         three derivatives) {:.1} ns, the law `rt::motion_law::evaluate` (a walk over 4 segments and \
         a cycloid's sine and cosine) {:.1} ns.",
        m.points,
        m.new_state.0,
        m.new_state.1,
        ratio(m.new_state),
        m.along.0,
        m.along.1,
        ratio(m.along),
        m.points,
        m.spline_ns,
        m.law_ns,
    );
    let _ = writeln!(
        out,
        "\n### One camshaft revolution at rtol = atol = {TOLERANCE:.0e}\n\n\
         DOP853 from the assembled state over one turn at the law's nominal speed, the model \
         file's outputs, through `Simulate::simulate_states`; median wall time of 3 to 31 \
         runs. Error: the largest difference over the outputs of the follower's coordinate \
         (its lift above the base circle: m, or rad for the rocker) from the law, relative to \
         the law's largest lift.\n\n\
         | model | time [ms] | steps | rejected | right-hand sides | max error / lift |\n\
         |---|---:|---:|---:|---:|---:|"
    );
    for r in &m.revolutions {
        let _ = writeln!(
            out,
            "| {} | {:.3} | {} | {} | {} | {:.1e} |",
            r.model,
            r.seconds * 1e3,
            r.steps,
            r.rejected,
            r.rhs,
            r.error / r.lift.max(f64::MIN_POSITIVE)
        );
    }
    let _ = writeln!(
        out,
        "\n**Against the goal.** The table's reduced right-hand side at a new state is {} of \
         the law's, along a run {}.\n\n\
         Reproduce: `cargo run --release -- bench evaluations` (rewrites this section with the \
         sections \"Generated code against the numeric recursion\" and \"Cams on moving \
         bodies\").",
        ratio(m.new_state),
        ratio(m.along),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_section_renders_the_ratios_and_their_verdicts() {
        let text = render(
            &Measured {
                new_state: (260.0, 200.0),
                along: (150.0, 100.0),
                spline_ns: 12.0,
                law_ns: 20.0,
                points: 721,
                revolutions: vec![Revolution {
                    model: "table_cam",
                    seconds: 1e-3,
                    steps: 60,
                    rejected: 20,
                    rhs: 1000,
                    error: 1.2e-12,
                    lift: 0.012,
                }],
            },
            10,
            3,
        );
        assert!(
            text.contains("| new state | 260 | 200 | 1.30× (met) |"),
            "{text}"
        );
        assert!(
            text.contains("| along a run | 150 | 100 | 1.50× (missed) |"),
            "{text}"
        );
        assert!(
            text.contains("| table_cam | 1.000 | 60 | 20 | 1000 | 1.0e-10 |"),
            "{text}"
        );
    }
}
