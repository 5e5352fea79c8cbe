//! A sweep CSV's rows read back (what `camchain merge` does with every row of a shard): each
//! cell is checked against what `camchain sweep` writes for that run (module [`super`])
//! so that a truncated, widened or altered row is an error naming its column, never a row
//! passed on.
//!
//! A row is accepted only in the one form the sweep writes it:
//! - as many cells as the header has columns, in RFC 4180 syntax, only the `error` cell
//!   quoted, and that only when it holds a comma or a quote;
//! - `run` the expected index in decimal, each parameter exactly the value the sweep's
//!   definition gives that run, in the shortest round-trip form the sweep writes;
//! - `status` `ok` (and `error` empty) or `failed` (and `error` not empty);
//! - each metric empty or a number in that same form (`NaN` and `inf` included), the
//!   counters whole numbers; which metrics may be empty follows from the status
//!   ([`OPTIONAL_WHEN_OK`], [`KEPT_WHEN_FAILED`]), and
//!   `wall_time` is never empty.
//!
//! A metric altered into another well-formed number, or a failed run's message into another
//! message, cannot be told from the real one: the format carries no checksum.

use super::{self as table, COUNTERS, KEPT_WHEN_FAILED, METRICS, OPTIONAL_WHEN_OK};
use crate::sweep::spec::Runs;
use std::borrow::Cow;
use std::fmt::Write;

/// The most characters of a file's text that a message quotes.
const SHOWN_CHARS: usize = 40;

/// Text from a file as a message shows it: control characters escaped (a message is one
/// line and sends nothing to the terminal), at most a few dozen characters.
pub fn shown(text: &str) -> String {
    escaped(text, SHOWN_CHARS)
}

/// `text` with its control characters escaped, cut after `limit` characters (`…`).
pub fn escaped(text: &str, limit: usize) -> String {
    let mut out = String::new();
    for (k, c) in text.chars().enumerate() {
        if k == limit {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    out
}

/// One cell as split: its text (quotes removed) and whether it was quoted.
pub(super) struct Cell<'a> {
    /// The text, quotes removed (borrowed from the line unless it held doubled quotes).
    pub(super) text: Cow<'a, str>,
    /// Whether it was quoted.
    pub(super) quoted: bool,
}

/// Splits a line into at most `limit` cells (RFC 4180), strictly: a quote only opens a cell
/// and closes it (doubled inside it); the error says which cell (0-based) is malformed.
pub(super) fn split(line: &str, limit: usize) -> Result<Vec<Cell<'_>>, (usize, String)> {
    let bytes = line.as_bytes();
    let mut cells = Vec::with_capacity(limit.min(64));
    // The start of the cell being read (a comma and a quote are single bytes in UTF-8, so
    // every index here is at a character's boundary).
    let mut start = 0;
    loop {
        let k = cells.len();
        if k == limit {
            return Err((k, format!("more than {limit} cells")));
        }
        let end = if bytes.get(start) == Some(&b'"') {
            let mut text = String::new();
            let mut from = start + 1;
            let close = loop {
                let Some(q) = bytes[from..].iter().position(|&b| b == b'"') else {
                    return Err((k, "a quote that is never closed".to_string()));
                };
                text.push_str(&line[from..from + q]);
                if bytes.get(from + q + 1) == Some(&b'"') {
                    text.push('"');
                    from += q + 2;
                } else {
                    break from + q;
                }
            };
            if !matches!(bytes.get(close + 1), None | Some(b',')) {
                return Err((k, "text after a closing quote".to_string()));
            }
            cells.push(Cell {
                text: Cow::Owned(text),
                quoted: true,
            });
            close + 1
        } else {
            let end = bytes[start..]
                .iter()
                .position(|&b| b == b',' || b == b'"')
                .map_or(bytes.len(), |p| start + p);
            if bytes.get(end) == Some(&b'"') {
                return Err((k, "a quote inside an unquoted cell".to_string()));
            }
            cells.push(Cell {
                text: Cow::Borrowed(&line[start..end]),
                quoted: false,
            });
            end
        };
        // What follows a cell is a comma (another cell follows) or the line's end.
        if end == bytes.len() {
            return Ok(cells);
        }
        start = end + 1;
    }
}

/// What a checked row gives the merge.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    /// The run's parameter values.
    pub values: Vec<f64>,
    /// Every metric's value, in the order of [`METRICS`] (None: empty).
    pub metrics: Vec<Option<f64>>,
    /// Whether the run failed.
    pub failed: bool,
}

/// The checks of a sweep's rows: its runs and its columns.
pub struct RowCheck<'a> {
    runs: &'a Runs,
    columns: Vec<String>,
}

impl<'a> RowCheck<'a> {
    /// The checks of the rows of `runs` (the columns are those of [`table::header`]).
    pub fn new(runs: &'a Runs) -> Self {
        let names: Vec<String> = runs.swept.iter().map(|s| s.name.clone()).collect();
        RowCheck {
            runs,
            columns: table::header(&names),
        }
    }

    /// Checks `line` as the row of run `run`; the error names the column (column `k3`: …)
    /// or says what is wrong with the row as a whole (its number of cells).
    pub fn check(&self, line: &str, run: usize) -> Result<Checked, String> {
        let width = self.columns.len();
        let column = |k: usize| {
            self.columns
                .get(k)
                .map_or("(beyond the last)", String::as_str)
        };
        let at = |k: usize, message: String| format!("column `{}`: {message}", column(k));
        let cells = split(line, width).map_err(|(k, message)| {
            if k == width {
                format!("{message}: the sweep's rows have {width} (a widened row)")
            } else {
                at(k, message)
            }
        })?;
        // The run first: a row of another run (missing, repeated, out of order) says so.
        if cells[0].text != run.to_string() || cells[0].quoted {
            return Err(at(
                0,
                format!("expected run {run}, found `{}`", shown(&cells[0].text)),
            ));
        }
        if cells.len() != width {
            return Err(format!(
                "run {run}'s row has {} of its {width} cells (a truncated row)",
                cells.len()
            ));
        }
        let error_column = width - 1;
        if let Some((k, _)) = cells[..error_column]
            .iter()
            .enumerate()
            .find(|(_, c)| c.quoted)
        {
            return Err(at(k, "quoted, but only `error` may be".to_string()));
        }
        let values = self.runs.values(run);
        let mut form = String::with_capacity(32);
        for (k, value) in values.iter().enumerate() {
            let expected = written(&mut form, *value);
            if cells[1 + k].text != expected {
                return Err(at(
                    1 + k,
                    format!(
                        "`{}` is not run {run}'s value in this sweep, {expected}",
                        shown(&cells[1 + k].text)
                    ),
                ));
            }
        }
        let status = 1 + values.len();
        let failed = match cells[status].text.as_ref() {
            "ok" => false,
            "failed" => true,
            other => {
                return Err(at(
                    status,
                    format!("`{}` is neither `ok` nor `failed`", shown(other)),
                ));
            }
        };
        let error = &cells[error_column];
        if error.text.contains(['\r', '\n']) {
            return Err(at(
                error_column,
                "a line break inside the message".to_string(),
            ));
        }
        if error.quoted && !error.text.contains([',', '"']) {
            return Err(at(
                error_column,
                "quoted, but holds neither a comma nor a quote".to_string(),
            ));
        }
        match (failed, error.text.is_empty()) {
            (false, false) => {
                return Err(at(
                    error_column,
                    format!("`{}`, but the run's status is `ok`", shown(&error.text)),
                ));
            }
            (true, true) => {
                return Err(at(
                    error_column,
                    "empty, but the run's status is `failed`".to_string(),
                ));
            }
            _ => {}
        }
        let first_metric = status + 1;
        let mut metrics = Vec::with_capacity(METRICS.len());
        for (k, (name, _)) in METRICS.iter().enumerate() {
            let text = &cells[first_metric + k].text;
            metrics.push(metric(name, text, &mut form).map_err(|e| at(first_metric + k, e))?);
        }
        self.check_presence(run, failed, &metrics)
            .map_err(|(k, e)| at(first_metric + k, e))?;
        Ok(Checked {
            values,
            metrics,
            failed,
        })
    }

    /// Which metrics are empty: as the run's status says (the error: the metric's index).
    fn check_presence(
        &self,
        run: usize,
        failed: bool,
        metrics: &[Option<f64>],
    ) -> Result<(), (usize, String)> {
        let index = |name: &str| METRICS.iter().position(|(n, _)| *n == name).unwrap_or(0);
        let wall = METRICS.len() - 1;
        if metrics[wall].is_none() {
            return Err((wall, "empty, but every run has its wall time".to_string()));
        }
        if failed {
            if let Some(k) = (0..wall)
                .find(|&k| metrics[k].is_some() && !KEPT_WHEN_FAILED.contains(&METRICS[k].0))
            {
                return Err((
                    k,
                    format!(
                        "a value, but run {run} failed and a failed run keeps only {}",
                        KEPT_WHEN_FAILED.join(", ")
                    ),
                ));
            }
            let kept: Vec<usize> = KEPT_WHEN_FAILED.iter().map(|n| index(n)).collect();
            let present = kept.iter().filter(|&&k| metrics[k].is_some()).count();
            if present != 0 && present != kept.len() {
                let k = kept.iter().copied().find(|&k| metrics[k].is_none());
                return Err((
                    k.unwrap_or(0),
                    format!(
                        "empty, but the failed run's {} are either all given or all empty",
                        KEPT_WHEN_FAILED.join(", ")
                    ),
                ));
            }
        } else {
            if let Some(k) = (0..wall)
                .find(|&k| metrics[k].is_none() && !OPTIONAL_WHEN_OK.contains(&METRICS[k].0))
            {
                return Err((k, format!("empty, but run {run} completed")));
            }
            let (t, contact) = (index("first_lift_off"), index("lift_off_contact"));
            if metrics[t].is_some() != metrics[contact].is_some() {
                let k = if metrics[t].is_none() { t } else { contact };
                return Err((
                    k,
                    "empty, but first_lift_off and lift_off_contact are either both given or \
                     both empty"
                        .to_string(),
                ));
            }
        }
        Ok(())
    }
}

/// `v` as [`table::number`] writes it, in `form` (one buffer for a row's numbers).
fn written(form: &mut String, v: impl std::fmt::Debug) -> &str {
    form.clear();
    // Writing to a String cannot fail.
    let _ = write!(form, "{v:?}");
    form
}

/// One metric cell: empty, or a number exactly as the sweep writes it (`form`: a buffer).
fn metric(name: &str, text: &str, form: &mut String) -> Result<Option<f64>, String> {
    if text.is_empty() {
        return Ok(None);
    }
    if COUNTERS.contains(&name) {
        return match text.parse::<u64>() {
            Ok(n) if written(form, n) == text => Ok(Some(n as f64)),
            _ => Err(format!("`{}` is not a whole number", shown(text))),
        };
    }
    match text.parse::<f64>() {
        Ok(v) if written(form, v) == text => Ok(Some(v)),
        Ok(v) => Err(format!(
            "`{}` is not a number as the sweep writes it ({})",
            shown(text),
            table::number(v)
        )),
        Err(_) => Err(format!("`{}` is not a number", shown(text))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::spec::{Design, parse_param};
    use crate::sweep::table::Row;
    use camchain_runtime::{RunMetrics, Stats};

    fn runs() -> Runs {
        let swept = vec![
            parse_param("a=0:0.3:4").expect("a"),
            parse_param("b=10,20").expect("b"),
        ];
        Runs::new(swept, Design::Product).expect("runs")
    }

    fn metrics(lift_off: Option<(f64, usize)>) -> RunMetrics {
        RunMetrics {
            t: 0.5,
            max_normal_force: f64::NAN,
            min_normal_force: -1.25,
            first_lift_off: lift_off,
            max_residual: 2e-16,
            energy_drift: -1e-9,
            energy_scale: 0.0,
            points: 9,
            stats: Stats {
                steps: 86,
                rejected: 0,
                rhs_evaluations: 1201,
                repartitions: 0,
                event_evaluations: 0,
                gap_evaluations: 0,
            },
        }
    }

    /// Rows as the sweep writes them: completed (with and without a lift-off, a force that
    /// is not a number, a relative drift that is not finite), failed part-way and failed at
    /// once (an error with a comma and quotes).
    fn written() -> Vec<Row> {
        let runs = runs();
        let row = |run: usize, metrics: Option<RunMetrics>, error: Option<&str>| Row {
            run,
            values: runs.values(run),
            metrics,
            error: error.map(str::to_string),
            wall_time: 1.5e-4,
        };
        vec![
            row(0, Some(metrics(None)), None),
            row(1, Some(metrics(Some((0.25, 1)))), None),
            row(
                2,
                Some(metrics(None)),
                Some("at t = 0.1 s the follower, \"A\", fell"),
            ),
            row(3, None, Some("assembly: no solution")),
        ]
    }

    #[test]
    fn every_row_the_sweep_writes_reads_back() {
        let runs = runs();
        let check = RowCheck::new(&runs);
        for row in written() {
            let line = row.cells().join(",");
            let checked = check.check(&line, row.run).expect(&line);
            assert_eq!(checked.values, row.values);
            assert_eq!(checked.failed, row.error.is_some());
            let expected = row.metric_values();
            assert_eq!(checked.metrics.len(), expected.len());
            for (a, b) in checked.metrics.iter().zip(expected) {
                // NaN reads back as NaN: compare the bits.
                assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{line}");
            }
        }
    }

    #[test]
    fn a_changed_cell_is_refused_with_its_column() {
        let runs = runs();
        let check = RowCheck::new(&runs);
        let rows = written();
        let ok = rows[1].cells();
        let failed = rows[2].cells();
        let with = |cells: &[String], k: usize, text: &str| {
            let mut cells = cells.to_vec();
            cells[k] = text.to_string();
            cells.join(",")
        };
        // Columns: run, a, b, status, 13 metrics (4 … 16), error (17).
        for (line, run, phrase) in [
            (with(&ok, 0, "01"), 1, "column `run`: expected run 1"),
            (
                with(&ok, 1, "0.1"),
                1,
                "column `a`: `0.1` is not run 1's value",
            ),
            (with(&ok, 2, "20"), 1, "column `b`: `20` is not"),
            (
                with(&ok, 3, "GARBAGE"),
                1,
                "column `status`: `GARBAGE` is neither",
            ),
            (
                with(&ok, 4, "1.50"),
                1,
                "column `max_normal_force`: `1.50` is not a number as",
            ),
            (
                with(&ok, 8, "not_a_number"),
                1,
                "column `max_residual`: `not_a_number`",
            ),
            (
                with(&ok, 11, "8.5"),
                1,
                "column `steps`: `8.5` is not a whole number",
            ),
            (
                with(&ok, 8, ""),
                1,
                "column `max_residual`: empty, but run 1 completed",
            ),
            (with(&ok, 6, ""), 1, "column `first_lift_off`: empty, but"),
            (with(&ok, 16, ""), 1, "column `wall_time`: empty"),
            (
                with(&ok, 17, "boom"),
                1,
                "column `error`: `boom`, but the run's status is `ok`",
            ),
            (with(&ok, 17, "\"boom\""), 1, "column `error`: quoted, but"),
            (with(&ok, 9, "\"1.0\""), 1, "column `energy_drift`: quoted"),
            (
                with(&ok, 9, "1\"0"),
                1,
                "column `energy_drift`: a quote inside",
            ),
            (
                with(&failed, 17, ""),
                2,
                "column `error`: empty, but the run's status is `failed`",
            ),
            (
                with(&failed, 4, "3.0"),
                2,
                "column `max_normal_force`: a value, but run 2 failed",
            ),
            (
                with(&failed, 15, ""),
                2,
                "column `t_reached`: empty, but the failed run's",
            ),
            (
                with(&ok, 17, "\"x"),
                1,
                "column `error`: a quote that is never closed",
            ),
            (
                with(&ok, 16, "\"x\"y"),
                1,
                "column `wall_time`: text after a closing quote",
            ),
            (format!("{},", ok.join(",")), 1, "more than 18 cells"),
            (ok[..10].join(","), 1, "run 1's row has 10 of its 18 cells"),
            ("1".to_string(), 1, "run 1's row has 1 of its 18 cells"),
            (String::new(), 1, "column `run`: expected run 1, found ``"),
        ] {
            let e = check.check(&line, run).expect_err(&line);
            assert!(e.contains(phrase), "{line}\n{e}");
        }
    }

    #[test]
    fn messages_show_file_text_on_one_short_line() {
        assert_eq!(shown("a\u{1b}[31mb\nc"), "a\\u{1b}[31mb\\nc");
        let long = "x".repeat(1000);
        assert_eq!(shown(&long).chars().count(), SHOWN_CHARS + 1);
    }
}
