//! The long runs: the paper models without dampers over 1000 s (100 s with `--quick`),
//! their constraint residual and energy error.

use super::case::{CaseResult, execute, generated_case, kind, numeric_case, paper};
use super::charts::{line_panel, log_points, series};
use super::tables::{cell, sci, verdict};
use super::{Context, Section, say};
use crate::CliError;
use crate::plots::{Figure, Row, Series};
use crate::scenarios as stress;
use std::fmt::Write as _;

pub(super) fn long_runs(ctx: &Context) -> Result<Section, CliError> {
    let t_end = if ctx.quick { 100.0 } else { 1000.0 };
    let steps: &[f64] = if ctx.quick { &[1e-2] } else { &[1e-2, 1e-3] };
    let sweep = stress::sweep(t_end, 0.1, steps, &[1e-6, 1e-8, 1e-10]);
    say(&format!("long runs ({t_end} s)\n"));
    let mut text = format!(
        "The paper models with every damper removed (numeric reference), released as in the \
         paper and run for {t_end} s; then the unmodified generated models (dampers on) for \
         the same time. Without dampers the mechanical energy is a constant of the motion, so \
         the energy drift is the integration error alone. The constraint is enforced by \
         Newton (15) at every evaluation, so |h| stays below the Newton tolerance (1e-12 m) \
         whatever the length of the run: the column *max |h|* and the figures show no \
         secular growth. The energy error of the (non-symplectic) Runge–Kutta methods does \
         grow, roughly linearly in time; *drift 1st / last tenth* compares the largest energy \
         error reached in the first and in the last tenth of the run.\n\n"
    );
    let mut verdicts = String::new();
    for name in ["paper_concave", "paper_convex"] {
        let case = numeric_case(
            &format!("{name}, dampers off ({t_end} s)"),
            stress::renamed(stress::without_dampers(paper(name)?), name),
            sweep.clone(),
            false,
        )?;
        let result = execute(&case);
        text.push_str(&long_table(&result));
        verdicts.push_str(&verdict(&result));
        let (h_series, e_series): (Vec<Series>, Vec<Series>) = result
            .records
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let samples = &r.trajectory.samples;
                let h = log_points(samples.iter().map(|s| (s.t, s.h[0])));
                let balance = stress::balance(&r.trajectory);
                let e0 = balance.first().map_or(0.0, |b| b.1);
                let e = log_points(balance.iter().map(|&(t, e)| (t, e - e0)));
                (series(&r.label, i, h), series(&r.label, i, e))
            })
            .unzip();
        let figure = Figure {
            title: format!(
                "{name} without dampers, {t_end} s: constraint residual and energy error"
            ),
            width: 1200,
            rows: vec![
                Row {
                    height: 360,
                    panels: vec![line_panel(
                        "|h| at the output times",
                        "log10 |h| [m]",
                        h_series,
                    )],
                },
                Row {
                    height: 360,
                    panels: vec![line_panel(
                        "energy error |E(t) − E(0)|",
                        "log10 |ΔE| [J]",
                        e_series,
                    )],
                },
            ],
        };
        text.push_str(&ctx.figure(
            &figure,
            &format!("long_{name}"),
            &format!("{name} without dampers: log10 |h| and log10 |E(t) − E(0)| against time"),
        )?);
    }
    let generated_sweep = stress::sweep(t_end, 0.1, &[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10]);
    for name in ["paper_concave", "paper_convex"] {
        let case = generated_case(
            &format!("{name}, generated code, dampers on ({t_end} s)"),
            name,
            generated_sweep.clone(),
        )?;
        let result = execute(&case);
        text.push_str(&long_table(&result));
        verdicts.push_str(&verdict(&result));
    }
    Ok(Section {
        heading: format!("Long runs ({t_end} s)"),
        text: format!("{verdicts}\n{text}"),
    })
}

/// The long-run table: the standard columns plus the energy drift in the first and last
/// tenth of the run.
pub(super) fn long_table(result: &CaseResult) -> String {
    let mut text = String::new();
    let _ = writeln!(text, "**{}**\n", result.title);
    let _ = writeln!(
        text,
        "| integration | outcome | steps | rejected | RHS | wall [ms] | max \\|h\\| [m] | \
         max \\|h\\|, last tenth [m] | energy drift [J] | drift 1st / last tenth [J] |"
    );
    let _ = writeln!(text, "|---|---|---|---|---|---|---|---|---|---|");
    for record in &result.records {
        let stats = record.stats();
        let outcome = match &record.error {
            None => "ok".to_string(),
            Some(e) => format!("**{}**: {}", kind(e), cell(&e.to_string())),
        };
        let balance = stress::balance(&record.trajectory);
        let e0 = balance.first().map_or(0.0, |b| b.1);
        let span = balance.last().map_or(0.0, |b| b.0);
        let tenth = |a: f64, b: f64| {
            balance
                .iter()
                .filter(|(t, _)| *t >= a * span && *t <= b * span)
                .fold(0.0_f64, |m, (_, e)| m.max((e - e0).abs()))
        };
        let _ = writeln!(
            text,
            "| {} | {outcome} | {} | {} | {} | {:.0} | {} | {} | {} | {} / {} |",
            record.label,
            stats.steps,
            stats.rejected,
            stats.rhs_evaluations,
            1e3 * record.wall.as_secs_f64(),
            sci(record.max_h()),
            sci(stress::max_residual_between(&record.trajectory, 0.9, 1.0)),
            sci(record.energy_drift()),
            sci(tenth(0.0, 0.1)),
            sci(tenth(0.9, 1.0)),
        );
    }
    text.push('\n');
    text
}
