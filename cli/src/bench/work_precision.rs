//! Run time against error for every integrator on the reference models (docs/method.md §7).

use super::timing::median_seconds;
use crate::CliError;
use crate::plots::{Figure, LinePanel, Panel, Row, Series};
use camchain_models as models;
use camchain_runtime::{Dynamics, IntegratorKind, SimSettings, Simulate, State, Trajectory};
use plotters::style::RGBColor;
use std::fmt::Write;
use std::path::Path;

/// The reference models and their durations (s): the paper's 10 s free swings and the 8 s
/// driven runs.
const MODELS: [(&str, f64); 5] = [
    ("paper_concave", 10.0),
    ("paper_convex", 10.0),
    ("paper_convex_text", 10.0),
    ("driven_concave", 8.0),
    ("driven_convex", 8.0),
];

/// Tolerance of the reference solution (DOP853, rtol = atol): the tightest at which its
/// steps still resolve (below, round-off in the error estimate dominates).
const REFERENCE_TOLERANCE: f64 = 1e-14;

/// One run of the ladder.
struct Point {
    integrator: IntegratorKind,
    /// The rung: RK4 step or tolerance.
    setting: f64,
    seconds: f64,
    steps: usize,
    rhs: usize,
    /// max over the output times of max_i |q_i − q_ref,i|.
    max_error: f64,
    end_error: f64,
    pareto: bool,
}

/// Runs the ladders, draws the figure into `figures`, returns the report section.
pub fn run(quick: bool, figures: &Path) -> Result<String, CliError> {
    let mut out = String::from(HEADER);
    let mut panels = Vec::new();
    let mut goals = Vec::new();
    let models: &[(&str, f64)] = if quick { &MODELS[..2] } else { &MODELS };
    for &(name, t_end) in models {
        eprintln!("work-precision: {name}");
        let model = models::by_name(name)
            .ok_or_else(|| CliError::Failed(format!("{name} is not built in")))?;
        let start = model
            .assemble(0.0)
            .map_err(|e| CliError::Failed(format!("{name}: {e}")))?;
        let base = SimSettings {
            t_end,
            ..model.info().defaults.clone()
        };
        let (reference, reference_error) = reference(model, &start, &base)?;
        let mut points = ladder(model, &start, &base, &reference, quick)?;
        mark_pareto(&mut points);
        write_table(&mut out, name, t_end, &base, reference_error, &points);
        goals.push((
            name,
            best_time_below(&points, 1e-8),
            best_time_below(&points, 1e-12),
        ));
        panels.push(panel(name, &points));
    }
    write_goals(&mut out, &goals);
    let figure = figure(panels);
    std::fs::create_dir_all(figures)
        .map_err(|e| CliError::Failed(format!("{}: {e}", figures.display())))?;
    let written = figure
        .save(figures, "work_precision")
        .map_err(|e| CliError::Failed(format!("work-precision figure: {e}")))?;
    let png = written
        .iter()
        .find(|p| p.extension().is_some_and(|e| e == "png"))
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    let _ = writeln!(
        out,
        "\n![work-precision diagrams]({png})\n\n*`{png}`: log10 of the largest error in q over \
         the run against log10 of the median run time; one line per integrator, the Pareto front \
         in black.*\n\nReproduce: `cargo run --release -- bench work-precision` (rewrites this \
         section and the figure)."
    );
    Ok(out)
}

const HEADER: &str = "## Run time against error (work-precision)\n\n\
Each run simulates the whole scenario from the assembled initial state with outputs every \
`dt_out` of the model (0.01 s: 1001 samples over 10 s), computing only q and q̇ at the outputs \
(`Simulate::simulate_states`). Time: median wall time of several runs of the whole simulation \
on one core. Error: the largest |q_i − q_ref,i| over all outputs and coordinates (rad or m), \
and at the end time, against a reference computed by DOP853 at rtol = atol = 1e-14 and checked \
by an independent Dopri5 run at rtol = atol = 1e-13 (the difference of the two is quoted as \
the reference's own error). Pareto-optimal rungs (no other rung is both faster and more \
accurate) are marked ★.\n\n";

/// The reference trajectory and its error estimate (difference to an independent run).
fn reference(
    model: &dyn Dynamics,
    start: &State,
    base: &SimSettings,
) -> Result<(Trajectory, f64), CliError> {
    let tight = |integrator, tolerance| SimSettings {
        integrator,
        rtol: tolerance,
        atol: tolerance,
        ..base.clone()
    };
    let reference = simulate(
        model,
        start,
        &tight(IntegratorKind::Dop853, REFERENCE_TOLERANCE),
    )?;
    let check = simulate(model, start, &tight(IntegratorKind::Dopri5, 1e-13))?;
    let (error, _) = errors(&check, &reference);
    Ok((reference, error))
}

fn simulate(
    model: &dyn Dynamics,
    start: &State,
    settings: &SimSettings,
) -> Result<Trajectory, CliError> {
    model
        .simulate_states(start.clone(), settings)
        .map_err(|f| CliError::Failed(format!("{}: {f}", model.info().name)))
}

/// (max error over the outputs, error at the end) of `run` against `reference`.
fn errors(run: &Trajectory, reference: &Trajectory) -> (f64, f64) {
    let difference = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    let max = run
        .samples
        .iter()
        .zip(&reference.samples)
        .map(|(a, b)| difference(&a.q, &b.q))
        .fold(0.0, f64::max);
    let end = match (run.samples.last(), reference.samples.last()) {
        (Some(a), Some(b)) => difference(&a.q, &b.q),
        _ => f64::NAN,
    };
    (max, end)
}

/// The rungs of every integrator.
fn rungs(quick: bool) -> Vec<(IntegratorKind, f64)> {
    let mut rungs = Vec::new();
    let rk4: &[f64] = if quick {
        &[1e-2, 1e-3]
    } else {
        &[1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4]
    };
    rungs.extend(rk4.iter().map(|&dt| (IntegratorKind::Rk4, dt)));
    let (first, last) = if quick { (4, 8) } else { (3, 12) };
    for e in first..=last {
        rungs.push((IntegratorKind::Dopri5, 10f64.powi(-e)));
    }
    // DOP853, the default and the fastest, gets half-decade rungs (1e-k and 3e-(k+1)) so
    // that its front is drawn finely enough to read off the cost of a given error, and one
    // rung further: it still gains there.
    let end = last + i32::from(!quick);
    for e in first..=end {
        rungs.push((IntegratorKind::Dop853, 10f64.powi(-e)));
        if e < end && !quick {
            rungs.push((IntegratorKind::Dop853, 3.0 * 10f64.powi(-e - 1)));
        }
    }
    rungs
}

fn ladder(
    model: &dyn Dynamics,
    start: &State,
    base: &SimSettings,
    reference: &Trajectory,
    quick: bool,
) -> Result<Vec<Point>, CliError> {
    let mut points = Vec::new();
    for (integrator, setting) in rungs(quick) {
        let settings = if integrator.is_adaptive() {
            SimSettings {
                integrator,
                rtol: setting,
                atol: setting,
                ..base.clone()
            }
        } else {
            SimSettings {
                integrator,
                dt: setting,
                ..base.clone()
            }
        };
        let run = simulate(model, start, &settings)?;
        let (max_error, end_error) = errors(&run, reference);
        // Repeat short runs more often: ~0.3 s of measurement per rung, 3 to 31 runs.
        let once = median_seconds(|| model.simulate_states(start.clone(), &settings), 1);
        let repeats = ((0.3 / once.max(1e-6)) as usize).clamp(3, 31);
        let seconds = median_seconds(|| model.simulate_states(start.clone(), &settings), repeats);
        points.push(Point {
            integrator,
            setting,
            seconds,
            steps: run.stats.steps,
            rhs: run.stats.rhs_evaluations,
            max_error,
            end_error,
            pareto: false,
        });
    }
    Ok(points)
}

/// Marks the rungs no other rung beats in both time and error.
fn mark_pareto(points: &mut [Point]) {
    let snapshot: Vec<(f64, f64)> = points.iter().map(|p| (p.seconds, p.max_error)).collect();
    for p in points.iter_mut() {
        p.pareto = !snapshot.iter().any(|&(s, e)| {
            s <= p.seconds && e <= p.max_error && (s < p.seconds || e < p.max_error)
        });
    }
}

/// The fastest run whose max error is at most `error`.
fn best_time_below(points: &[Point], error: f64) -> Option<(f64, String)> {
    points
        .iter()
        .filter(|p| p.max_error <= error)
        .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
        .map(|p| (p.seconds, rung_name(p.integrator, p.setting)))
}

fn rung_name(integrator: IntegratorKind, setting: f64) -> String {
    match integrator {
        IntegratorKind::Rk4 => format!("rk4 dt {setting:.0e}"),
        IntegratorKind::Dopri5 => format!("dopri5 tol {setting:.0e}"),
        IntegratorKind::Dop853 => format!("dop853 tol {setting:.0e}"),
    }
}

fn write_table(
    out: &mut String,
    name: &str,
    t_end: f64,
    base: &SimSettings,
    reference_error: f64,
    points: &[Point],
) {
    let _ = writeln!(
        out,
        "### {name} ({t_end} s, outputs every {} s)\n\nReference error (DOP853 1e-14 against \
         Dopri5 1e-13): {reference_error:.1e}.\n\n\
         | integrator | step / tolerance | time [ms] | steps | right-hand sides | max error q | error q at t_end | Pareto |\n\
         |---|---:|---:|---:|---:|---:|---:|:-:|",
        base.dt_out
    );
    for p in points {
        let (kind, setting) = match p.integrator {
            IntegratorKind::Rk4 => ("rk4", format!("dt {:.0e}", p.setting)),
            IntegratorKind::Dopri5 => ("dopri5", format!("{:.0e}", p.setting)),
            IntegratorKind::Dop853 => ("dop853", format!("{:.0e}", p.setting)),
        };
        let _ = writeln!(
            out,
            "| {kind} | {setting} | {:.3} | {} | {} | {:.1e} | {:.1e} | {} |",
            p.seconds * 1e3,
            p.steps,
            p.rhs,
            p.max_error,
            p.end_error,
            if p.pareto { "★" } else { "" }
        );
    }
    out.push('\n');
}

/// Per model: the fastest run to 1e-8 and to 1e-12 (time, rung), if any.
type Goals<'a> = [(&'a str, Option<(f64, String)>, Option<(f64, String)>)];

fn write_goals(out: &mut String, goals: &Goals) {
    let cell = |best: &Option<(f64, String)>| match best {
        Some((s, rung)) => format!("{:.3} ms ({rung})", s * 1e3),
        None => "not reached".to_string(),
    };
    let _ = writeln!(
        out,
        "### Against the goals\n\nFastest run of the whole simulation reaching a max error in q \
         of 1e-8 (goal: under 1 ms) and of 1e-12 (goal: under 5 ms):\n\n\
         | model | max error ≤ 1e-8 | max error ≤ 1e-12 |\n|---|---|---|"
    );
    for (name, loose, tight) in goals {
        let _ = writeln!(out, "| {name} | {} | {} |", cell(loose), cell(tight));
    }
}

const COLORS: [(IntegratorKind, RGBColor, &str); 3] = [
    (IntegratorKind::Rk4, RGBColor(31, 119, 180), "rk4"),
    (IntegratorKind::Dopri5, RGBColor(255, 127, 14), "dopri5"),
    (IntegratorKind::Dop853, RGBColor(44, 160, 44), "dop853"),
];

fn panel(name: &str, points: &[Point]) -> Panel {
    let xy = |p: &Point| ((p.seconds * 1e3).log10(), p.max_error.max(1e-16).log10());
    let mut series: Vec<Series> = COLORS
        .iter()
        .map(|&(kind, color, label)| Series {
            label: Some(label.to_string()),
            color,
            points: points
                .iter()
                .filter(|p| p.integrator == kind)
                .map(xy)
                .collect(),
        })
        .collect();
    let mut front: Vec<(f64, f64)> = points.iter().filter(|p| p.pareto).map(xy).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    series.push(Series {
        label: Some("Pareto front".to_string()),
        color: RGBColor(0, 0, 0),
        points: front,
    });
    let all: Vec<(f64, f64)> = points.iter().map(xy).collect();
    let range = |f: fn(&(f64, f64)) -> f64| {
        let lo = all.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = all.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        (lo.floor() - 0.2, hi.ceil() + 0.2)
    };
    Panel::Lines(LinePanel {
        title: name.to_string(),
        x_label: "log10 run time [ms]".to_string(),
        y_label: "log10 max error in q".to_string(),
        x_range: range(|p| p.0),
        y_range: range(|p| p.1),
        series,
        zero_line: false,
        markers: Vec::new(),
    })
}

fn figure(panels: Vec<Panel>) -> Figure {
    let mut rows = Vec::new();
    let mut panels = panels.into_iter().peekable();
    while panels.peek().is_some() {
        rows.push(Row {
            height: 420,
            panels: panels.by_ref().take(2).collect(),
        });
    }
    Figure {
        title: "Run time against error: whole simulations of the reference models".to_string(),
        width: 1400,
        rows,
    }
}
