//! The markdown of the report's tables: one row per integration, and the verdict lines.

use super::case::{CaseResult, error_time, kind};
use std::fmt::Write as _;

/// `1.23e-5`, or `0` for an exact zero, `—` when not available.
pub(super) fn sci(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.2e}")
    }
}

/// A time with at most 6 decimals, trailing zeros dropped (`1.047198`, `10`).
pub(super) fn time(t: f64) -> String {
    if t.is_nan() {
        return "—".into();
    }
    let fixed = format!("{t:.6}");
    fixed
        .trim_end_matches('0')
        .trim_end_matches('.')
        .to_string()
}

/// Markdown-safe cell text.
pub(super) fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

/// The table of a case: one row per integration.
pub(super) fn table(result: &CaseResult) -> String {
    let mut text = String::new();
    let _ = writeln!(text, "**{}**\n", result.title);
    let _ = writeln!(
        text,
        "| integration | outcome | t reached [s] | steps | rejected | RHS | re-partitions | \
         wall [ms] | max \\|h\\| [m] | energy drift [J] | max \\|q − q_ref\\| |"
    );
    let _ = writeln!(text, "|---|---|---|---|---|---|---|---|---|---|---|");
    for record in &result.records {
        let stats = record.stats();
        let outcome = match &record.error {
            None => "ok".to_string(),
            Some(e) => format!("**{}**: {}", kind(e), cell(&e.to_string())),
        };
        let error = match &result.reference {
            Some(reference) if !record.trajectory.samples.is_empty() => {
                sci(record.difference(reference))
            }
            _ => "—".into(),
        };
        let _ = writeln!(
            text,
            "| {} | {outcome} | {} | {} | {} | {} | {} | {:.1} | {} | {} | {error} |",
            record.label,
            time(record.t_reached()),
            stats.steps,
            stats.rejected,
            stats.rhs_evaluations,
            stats.repartitions,
            1e3 * record.wall.as_secs_f64(),
            sci(record.max_h()),
            sci(record.energy_drift()),
        );
    }
    text.push('\n');
    text
}

/// One line per failed run: `label: Kind at t = … s`; or that all runs completed.
pub(super) fn verdict(result: &CaseResult) -> String {
    let failures: Vec<String> = result
        .records
        .iter()
        .filter_map(|r| {
            r.error.as_ref().map(|e| {
                format!(
                    "{} stops with {} at t = {} s",
                    r.label,
                    kind(e),
                    time(error_time(e))
                )
            })
        })
        .collect();
    if failures.is_empty() {
        format!("- {}: every run completes.\n", result.title)
    } else {
        format!("- {}: {}.\n", result.title, failures.join("; "))
    }
}
