//! The sweep's CSV: a few `#` lines that say what the sweep was, a header, one row per run.
//!
//! ```text
//! # camchain sweep of paper_concave (generated code): 63 runs
//! # shard 1/1
//! # parameters: swing=-0.5:0.5:21 k3=20,40,80
//! # settings: dop853 rtol 1e-6 atol 1e-6 t_end 10 s, metrics at the step ends
//! run,swing,k3,status,max_normal_force,min_normal_force,first_lift_off,…,error
//! 0,-0.5,20.0,ok,23.1,22.0,,…,
//! ```
//!
//! The `#` lines are what `camchain merge` checks (every shard of one sweep has the same
//! first, third and fourth lines, and its own shard line); CSV readers skip them
//! (`pandas.read_csv(path, comment='#')`). Numbers use Rust's shortest round-trip form; a
//! failed run has `status` `failed`, the error in `error`, and empty metrics but for how
//! far it got (`t_reached`) and the work it did. [`rows`] reads rows back and accepts only
//! what this module writes (what `camchain merge` checks of every row).

pub mod rows;

use camchain_runtime::RunMetrics;
use std::io::{self, Write};

/// The metric columns, in order, with their units (for the documentation and figures).
pub const METRICS: [(&str, &str); 13] = [
    ("max_normal_force", "N"),
    ("min_normal_force", "N"),
    ("first_lift_off", "s"),
    ("lift_off_contact", ""),
    ("max_residual", "m"),
    ("energy_drift", "J"),
    ("relative_energy_drift", ""),
    ("steps", ""),
    ("rejected", ""),
    ("rhs_evaluations", ""),
    ("repartitions", ""),
    ("t_reached", "s"),
    ("wall_time", "s"),
];

/// The metric columns that hold counts: whole numbers, written without a decimal point.
pub const COUNTERS: [&str; 5] = [
    "lift_off_contact",
    "steps",
    "rejected",
    "rhs_evaluations",
    "repartitions",
];

/// The metrics a failed run keeps (how far it got and the work it did); its other metric
/// cells are empty. A run that failed before its integration started (the model refused
/// the values, assembly failed) has these empty too.
pub const KEPT_WHEN_FAILED: [&str; 5] = [
    "steps",
    "rejected",
    "rhs_evaluations",
    "repartitions",
    "t_reached",
];

/// The metrics a completed run may leave empty: the normal forces (not a number when the
/// model has no contact force) and the first lift-off's time and contact (both empty when
/// the follower never lifts off).
pub const OPTIONAL_WHEN_OK: [&str; 4] = [
    "max_normal_force",
    "min_normal_force",
    "first_lift_off",
    "lift_off_contact",
];

/// The metrics a figure may show (`--metric`), all but the work counters.
pub const PLOTTABLE: [&str; 8] = [
    "max_normal_force",
    "min_normal_force",
    "first_lift_off",
    "max_residual",
    "energy_drift",
    "relative_energy_drift",
    "rhs_evaluations",
    "wall_time",
];

/// The metrics drawn when `--metric` is not given.
pub const DEFAULT_PLOTTED: [&str; 4] = [
    "max_normal_force",
    "min_normal_force",
    "first_lift_off",
    "energy_drift",
];

/// What the `#` lines say.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Preamble {
    /// `camchain sweep of <model> (<path>): <n> runs`.
    pub sweep: String,
    /// Shard index (1-based) and count.
    pub shard: (usize, usize),
    /// The parameters' specs.
    pub parameters: String,
    /// The integrator, tolerances, end time and sampling.
    pub settings: String,
}

impl Preamble {
    /// The total number of runs of the sweep (from the first line).
    pub fn runs(&self) -> Option<usize> {
        self.sweep
            .rsplit_once(": ")
            .and_then(|(_, n)| n.strip_suffix(" runs"))
            .and_then(|n| n.parse().ok())
    }

    /// The model's name and the path that ran it (`generated code`, `numeric reference`),
    /// from the first line, `camchain sweep of <model> (<path>): <n> runs`; None when the
    /// line is not of that form. The name is the model's as written, which may hold any
    /// character (a model file's `name:`): it is data, never a path.
    pub fn model(&self) -> Option<(&str, &str)> {
        let rest = self.sweep.strip_prefix("camchain sweep of ")?;
        let (head, _) = rest.rsplit_once(": ")?;
        let (model, path) = head.strip_suffix(')')?.rsplit_once(" (")?;
        (!model.is_empty() && !path.is_empty()).then_some((model, path))
    }

    /// Writes the four lines.
    pub fn write(&self, out: &mut dyn Write) -> io::Result<()> {
        writeln!(out, "# {}", self.sweep)?;
        writeln!(out, "# shard {}/{}", self.shard.0, self.shard.1)?;
        writeln!(out, "# parameters: {}", self.parameters)?;
        writeln!(out, "# settings: {}", self.settings)
    }

    /// Reads the four lines (with their `# `); the error gives the line's number (1-based)
    /// and what is wrong with it.
    pub fn parse(lines: &[&str]) -> Result<Self, (usize, String)> {
        let line = |k: usize, prefix: &str| -> Result<String, (usize, String)> {
            lines
                .get(k)
                .and_then(|l| l.strip_prefix("# "))
                .and_then(|l| l.strip_prefix(prefix))
                .map(str::to_string)
                .ok_or_else(|| {
                    (
                        k + 1,
                        format!("not `# {prefix}…`: not a CSV written by camchain sweep"),
                    )
                })
        };
        let sweep = format!("camchain sweep{}", line(0, "camchain sweep")?);
        let shard = line(1, "shard ")?;
        let shard = super::spec::parse_shard(&shard).map_err(|e| (2, e))?;
        Ok(Preamble {
            sweep,
            shard: (shard.index, shard.count),
            parameters: line(2, "parameters: ")?,
            settings: line(3, "settings: ")?,
        })
    }
}

/// The header's columns: `run`, the swept parameters, `status`, the metrics, `error`.
pub fn header(parameters: &[String]) -> Vec<String> {
    let mut columns = vec!["run".to_string()];
    columns.extend(parameters.iter().cloned());
    columns.push("status".to_string());
    columns.extend(METRICS.iter().map(|(name, _)| name.to_string()));
    columns.push("error".to_string());
    columns
}

/// One run's row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The run's index in the whole sweep.
    pub run: usize,
    /// The swept parameters' values.
    pub values: Vec<f64>,
    /// The metrics, complete or up to the failure.
    pub metrics: Option<RunMetrics>,
    /// Why the run failed (None: it completed).
    pub error: Option<String>,
    /// Wall time of the run (s): building the model, assembly and the integration.
    pub wall_time: f64,
}

impl Row {
    /// The metric values in the order of [`METRICS`] (None: an empty cell). A failed run
    /// keeps only how far it got and the work it did.
    pub fn metric_values(&self) -> [Option<f64>; METRICS.len()] {
        let mut values = [None; METRICS.len()];
        if let Some(m) = &self.metrics {
            let finite = |v: f64| (!v.is_nan()).then_some(v);
            values = [
                finite(m.max_normal_force),
                finite(m.min_normal_force),
                m.first_lift_off.map(|(t, _)| t),
                m.first_lift_off.map(|(_, c)| c as f64),
                Some(m.max_residual),
                Some(m.energy_drift),
                Some(m.relative_energy_drift()),
                Some(m.stats.steps as f64),
                Some(m.stats.rejected as f64),
                Some(m.stats.rhs_evaluations as f64),
                Some(m.stats.repartitions as f64),
                Some(m.t),
                None,
            ];
            if self.error.is_some() {
                for (k, (name, _)) in METRICS.iter().enumerate() {
                    if !KEPT_WHEN_FAILED.contains(name) {
                        values[k] = None;
                    }
                }
            }
        }
        values[METRICS.len() - 1] = Some(self.wall_time);
        values
    }

    /// The row's cells, in the order of [`header`].
    pub fn cells(&self) -> Vec<String> {
        let mut cells = vec![self.run.to_string()];
        cells.extend(self.values.iter().map(|v| number(*v)));
        cells.push(if self.error.is_none() { "ok" } else { "failed" }.to_string());
        for (value, (name, _)) in self.metric_values().iter().zip(METRICS) {
            let counter = COUNTERS.contains(&name);
            cells.push(match value {
                None => String::new(),
                Some(v) if counter => format!("{}", *v as u64),
                Some(v) => number(*v),
            });
        }
        cells.push(quoted(self.error.as_deref().unwrap_or("")));
        cells
    }

    /// The value of a metric column by name (None when empty or unknown).
    pub fn metric(&self, name: &str) -> Option<f64> {
        let k = METRICS.iter().position(|(n, _)| *n == name)?;
        self.metric_values()[k]
    }
}

/// Shortest round-trip form.
pub fn number(v: f64) -> String {
    format!("{v:?}")
}

/// A text cell, quoted when it holds a comma, a quote or a line break (RFC 4180); line
/// breaks become spaces.
pub fn quoted(text: &str) -> String {
    let flat = text.replace(['\n', '\r'], " ");
    if flat.contains([',', '"']) {
        format!("\"{}\"", flat.replace('"', "\"\""))
    } else {
        flat
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use camchain_runtime::Stats;

    /// The cells of a line, as the strict reader splits them.
    fn split(line: &str) -> Vec<String> {
        rows::split(line, 100)
            .map(|cells| cells.into_iter().map(|c| c.text.into_owned()).collect())
            .unwrap_or_default()
    }

    fn metrics() -> RunMetrics {
        RunMetrics {
            t: 10.0,
            max_normal_force: 23.5,
            min_normal_force: -1.25,
            first_lift_off: Some((5.179772541, 0)),
            max_residual: 2e-16,
            energy_drift: 1e-9,
            energy_scale: 0.5,
            points: 90,
            stats: Stats {
                steps: 86,
                rejected: 14,
                rhs_evaluations: 1201,
                repartitions: 0,
                event_evaluations: 0,
                gap_evaluations: 0,
            },
        }
    }

    #[test]
    fn rows_have_a_cell_per_column_and_read_back() {
        let params = vec!["swing".to_string(), "k3".to_string()];
        let row = Row {
            run: 4,
            values: vec![-0.5, 40.0],
            metrics: Some(metrics()),
            error: None,
            wall_time: 2e-4,
        };
        let cells = row.cells();
        assert_eq!(cells.len(), header(&params).len());
        assert_eq!(cells[3], "ok");
        assert_eq!(row.metric("first_lift_off"), Some(5.179772541));
        assert_eq!(row.metric("relative_energy_drift"), Some(2e-9));
        let line = cells.join(",");
        assert_eq!(split(&line), cells);
    }

    #[test]
    fn a_failed_row_keeps_its_error_and_how_far_it_got() {
        let row = Row {
            run: 1,
            values: vec![0.3],
            metrics: Some(RunMetrics {
                t: 1.04,
                ..metrics()
            }),
            error: Some(
                "at t = 1.04 s the contact point cannot reach the cam, \"q\" = [1, 2]".into(),
            ),
            wall_time: 1e-3,
        };
        let cells = row.cells();
        assert_eq!(cells[2], "failed");
        assert_eq!(row.metric("max_normal_force"), None);
        assert_eq!(row.metric("t_reached"), Some(1.04));
        assert_eq!(row.metric("steps"), Some(86.0));
        // The error is quoted (it holds a comma and quotes) and reads back as it was.
        let back = split(&cells.join(","));
        assert_eq!(back.len(), cells.len());
        assert_eq!(back[..cells.len() - 1], cells[..cells.len() - 1]);
        assert_eq!(back.last(), row.error.as_ref());
    }

    #[test]
    fn the_preamble_reads_back() {
        let p = Preamble {
            sweep: "camchain sweep of paper_concave (generated code): 63 runs".into(),
            shard: (2, 4),
            parameters: "swing=-0.5:0.5:21 k3=20,40,80".into(),
            settings: "dop853 rtol 1e-6 atol 1e-6 t_end 10 s".into(),
        };
        let mut text = Vec::new();
        p.write(&mut text).expect("written");
        let text = String::from_utf8(text).expect("utf-8");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(Preamble::parse(&lines), Ok(p.clone()));
        assert_eq!(p.runs(), Some(63));
        assert_eq!(Preamble::parse(&lines[1..]).map_err(|(k, _)| k), Err(1));
        let bad_shard = [lines[0], "# shard 3/2", lines[2], lines[3]];
        assert_eq!(Preamble::parse(&bad_shard).map_err(|(k, _)| k), Err(2));
    }
}
