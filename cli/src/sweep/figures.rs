//! The figures of a sweep: each plotted metric against the swept parameters.
//!
//! - one parameter on a grid: a line per metric against it (`metrics.png`), failed runs
//!   leave gaps;
//! - two parameters on a grid: a heat map per metric (`heatmaps.png`), failed runs grey;
//! - otherwise (a Latin hypercube, three or more parameters): every metric against every
//!   parameter as points (`scatter.png`), runs without a value as crosses on the axis.

use super::PlotData;
use super::spec::{Design, Runs, Swept};
use super::table::METRICS;
use crate::plots::{Figure, HeatPanel, LinePanel, Panel, PointsPanel, Row, Series};
use std::path::{Path, PathBuf};

/// Draws the figures of `plot` in `dir` (PNG and SVG); returns the files written.
pub fn draw(dir: &Path, plan: &super::Plan, plot: &PlotData) -> Result<Vec<PathBuf>, String> {
    draw_runs(dir, &plan.model, &plan.runs, plot)
}

/// [`draw`] for a sweep known by its model name and runs (what `merge` has).
pub fn draw_runs(
    dir: &Path,
    model: &str,
    runs: &Runs,
    plot: &PlotData,
) -> Result<Vec<PathBuf>, String> {
    if plot.rows.is_empty() || plot.metrics.is_empty() {
        return Ok(Vec::new());
    }
    let grid = runs.design == Design::Product;
    let varying: Vec<usize> = (0..runs.swept.len())
        .filter(|&k| {
            let first = plot.rows[0].0[k];
            plot.rows.iter().any(|(v, _)| v[k] != first)
        })
        .collect();
    let (figure, stem) = match (grid, varying.as_slice()) {
        (true, [k]) => (lines(model, runs, plot, *k), "metrics"),
        (true, [a, b]) => (heat_maps(model, runs, plot, *a, *b), "heatmaps"),
        _ => (scatter(model, runs, plot, &varying), "scatter"),
    };
    figure.save(dir, stem).map_err(|e| e.to_string())
}

/// `max_normal_force [N]`.
fn label(metric: &str) -> String {
    let unit = METRICS
        .iter()
        .find(|(n, _)| *n == metric)
        .map_or("", |(_, u)| *u);
    if unit.is_empty() {
        metric.to_string()
    } else {
        format!("{metric} [{unit}]")
    }
}

/// `k [N/m]`: a swept parameter's axis, with its unit when the model declares one.
fn axis(swept: &Swept) -> String {
    if swept.unit.is_empty() {
        swept.name.clone()
    } else {
        format!("{} [{}]", swept.name, swept.unit)
    }
}

/// What a panel without a single value says: the metric is missing from every run.
fn no_value(metric: &str) -> String {
    match metric {
        "first_lift_off" => "no lift-off in any run".to_string(),
        _ => format!("no {metric} in any run"),
    }
}

/// The range of `values`, widened a little (and around a single value); values that are
/// all non-negative get no range below zero.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else if lo != 0.0 {
        0.05 * lo.abs()
    } else {
        0.5
    };
    let low = if lo >= 0.0 {
        (lo - pad).max(0.0)
    } else {
        lo - pad
    };
    (low, hi + pad)
}

fn lines(model: &str, runs: &Runs, plot: &PlotData, k: usize) -> Figure {
    let name = &runs.swept[k].name;
    let x_label = axis(&runs.swept[k]);
    let mut order: Vec<usize> = (0..plot.rows.len()).collect();
    order.sort_by(|&a, &b| plot.rows[a].0[k].total_cmp(&plot.rows[b].0[k]));
    let x_range = range(plot.rows.iter().map(|(v, _)| v[k]));
    let rows = plot
        .metrics
        .iter()
        .enumerate()
        .map(|(m, metric)| {
            // A failed run breaks the line.
            let mut series = Vec::new();
            let mut current = Vec::new();
            for &i in &order {
                let (values, metrics) = &plot.rows[i];
                match metrics[m] {
                    Some(y) => current.push((values[k], y)),
                    None if !current.is_empty() => series.push(std::mem::take(&mut current)),
                    None => {}
                }
            }
            if !current.is_empty() {
                series.push(current);
            }
            let y_range = range(series.iter().flatten().map(|p| p.1));
            let title = if series.is_empty() {
                format!("{metric} against {name}: {}", no_value(metric))
            } else {
                format!("{metric} against {name}")
            };
            Row {
                height: 300,
                panels: vec![Panel::Lines(LinePanel {
                    title,
                    x_label: x_label.clone(),
                    y_label: label(metric),
                    x_range,
                    y_range,
                    series: series
                        .into_iter()
                        .map(|points| Series {
                            label: None,
                            color: plotters::style::RGBColor(31, 119, 180),
                            points,
                        })
                        .collect(),
                    zero_line: true,
                    markers: Vec::new(),
                })],
            }
        })
        .collect();
    Figure {
        title: format!(
            "{model}: sweep of {name} ({})",
            crate::counted(plot.rows.len(), "run")
        ),
        width: 1100,
        rows,
    }
}

fn distinct(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

fn heat_maps(model: &str, runs: &Runs, plot: &PlotData, a: usize, b: usize) -> Figure {
    let (xa, xb) = (&runs.swept[a].name, &runs.swept[b].name);
    let xs = distinct(plot.rows.iter().map(|(v, _)| v[a]));
    let ys = distinct(plot.rows.iter().map(|(v, _)| v[b]));
    let index = |values: &[f64], x: f64| values.binary_search_by(|v| v.total_cmp(&x)).ok();
    let panels: Vec<Panel> = plot
        .metrics
        .iter()
        .enumerate()
        .map(|(m, metric)| {
            let mut z = vec![vec![None; ys.len()]; xs.len()];
            for (values, metrics) in &plot.rows {
                if let (Some(i), Some(j)) = (index(&xs, values[a]), index(&ys, values[b])) {
                    z[i][j] = metrics[m];
                }
            }
            Panel::Heat(HeatPanel {
                title: metric.clone(),
                x_label: axis(&runs.swept[a]),
                y_label: axis(&runs.swept[b]),
                z_label: label(metric),
                x: xs.clone(),
                y: ys.clone(),
                z,
                empty: no_value(metric),
                path: Vec::new(),
            })
        })
        .collect();
    let mut rows = Vec::new();
    let mut panels = panels.into_iter().peekable();
    while panels.peek().is_some() {
        rows.push(Row {
            height: 420,
            panels: panels.by_ref().take(2).collect(),
        });
    }
    Figure {
        title: format!(
            "{model}: sweep of {xa} and {xb} ({}; grey: no value)",
            crate::counted(plot.rows.len(), "run")
        ),
        width: 1400,
        rows,
    }
}

fn scatter(model: &str, runs: &Runs, plot: &PlotData, varying: &[usize]) -> Figure {
    let params: Vec<usize> = if varying.is_empty() {
        (0..runs.swept.len()).take(1).collect()
    } else {
        varying.iter().copied().take(4).collect()
    };
    let rows = plot
        .metrics
        .iter()
        .enumerate()
        .map(|(m, metric)| {
            let panels = params
                .iter()
                .map(|&k| {
                    let name = &runs.swept[k].name;
                    let points: Vec<(f64, f64)> = plot
                        .rows
                        .iter()
                        .filter_map(|(v, ms)| ms[m].map(|y| (v[k], y)))
                        .collect();
                    let missing = plot
                        .rows
                        .iter()
                        .filter(|(_, ms)| ms[m].is_none())
                        .map(|(v, _)| v[k])
                        .collect();
                    let title = if points.is_empty() {
                        format!("{metric} against {name}: {}", no_value(metric))
                    } else {
                        format!("{metric} against {name}")
                    };
                    Panel::Points(PointsPanel {
                        title,
                        x_label: axis(&runs.swept[k]),
                        y_label: label(metric),
                        x_range: range(plot.rows.iter().map(|(v, _)| v[k])),
                        y_range: range(points.iter().map(|p| p.1)),
                        points,
                        missing,
                    })
                })
                .collect();
            Row {
                height: 320,
                panels,
            }
        })
        .collect();
    Figure {
        title: format!(
            "{model}: sweep ({})",
            crate::counted(plot.rows.len(), "run")
        ),
        width: 550 * params.len().max(1) as u32,
        rows,
    }
}
