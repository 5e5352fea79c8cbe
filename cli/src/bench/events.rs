//! Section `events` of BENCHMARKS.md: what finding events inside steps costs.
//!
//! Every built-in model with a contact runs its default settings twice, side by side: with
//! full samples (the normal forces watched inside every step: the stages' multipliers, the
//! prediction, and where it comes near zero a search on the dense output) and with states
//! only (nothing watched). The difference in right-hand sides, plus the force evaluations
//! inside steps (each about a right-hand side), is the work of the event scan; the wall
//! times are medians of interleaved runs. Then the one-sided runs of issue 24, where the
//! scans find lift-offs, landings and impacts: the closed-form jump speeds of the eccentric
//! flat face and the cycloidal roller just above, and the eccentric roller hit by a cam at
//! 1000 to 5000 rad/s.

use super::timing::median;
use crate::CliError;
use camchain_models as models;
use camchain_runtime::{Dynamics, SimSettings, Simulate, Stats};
use std::fmt::Write;
use std::time::Instant;

/// One model's bilateral run, watched and not.
struct Bilateral {
    name: &'static str,
    watched: Stats,
    unwatched: Stats,
    /// Median wall times (s): watched, unwatched.
    seconds: (f64, f64),
}

/// A one-sided run.
struct OneSided {
    label: String,
    events: usize,
    stats: Stats,
    seconds: f64,
}

/// Runs the section's measurements and returns its Markdown.
///
/// # Errors
/// A model that fails to assemble or to run.
pub fn run(quick: bool) -> Result<String, CliError> {
    let repeats = if quick { 3 } else { 9 };
    let mut bilateral = Vec::new();
    for &(name, model) in models::ALL.iter() {
        if model.info().n_contacts() == 0 {
            continue;
        }
        bilateral.push(measure_bilateral(name, model, repeats)?);
    }
    let mut one_sided = Vec::new();
    let flat_jump = eccentric_flat_jump()?;
    for delta in [1e-3, 1e-2] {
        let omega = flat_jump * (1.0 + delta);
        let model = models::eccentric_flat::Model::with(&[("omega", omega)])
            .map_err(|e| CliError::Failed(e.to_string()))?;
        let turns = 22.0 * std::f64::consts::TAU / omega;
        let label = format!("eccentric_flat, 22 turns at ω_j (1 + {delta:e})");
        one_sided.push(measure_one_sided(label, &model, turns, repeats)?);
    }
    for omega in [1000.0, 2000.0, 5000.0] {
        let model = models::eccentric_roller::Model::with(&[("omega", omega)])
            .map_err(|e| CliError::Failed(e.to_string()))?;
        let t_end = model.default_settings().t_end;
        let label = format!("eccentric_roller at {omega} rad/s");
        one_sided.push(measure_one_sided(label, &model, t_end, repeats)?);
    }
    Ok(render(&bilateral, &one_sided, flat_jump))
}

/// The jump speed of eccentric_flat from its file's parameters (tests/suite/unilateral.rs
/// derives it): e² ((m ω² − k)² + c² ω²) = (m g + k (R − s_free))².
fn eccentric_flat_jump() -> Result<f64, CliError> {
    let name = "eccentric_flat";
    let source = models::source(name).ok_or_else(|| failed(name, "not built in"))?;
    let file = std::path::PathBuf::from(format!("models/{name}.ron"));
    let model =
        camchain_codegen::schema::parse_model(source, &file).map_err(|e| failed(name, e))?;
    let p = |wanted: &str| {
        model
            .parameters
            .iter()
            .find(|p| p.name == wanted)
            .map(|p| p.default)
            .ok_or_else(|| failed(name, format!("no parameter {wanted}")))
    };
    let (m, g, k, c) = (p("m")?, p("g")?, p("k")?, p("c")?);
    let (r, e, free) = (p("R")?, p("e")?, p("free")?);
    let a = m * g + k * (r - free);
    let (qa, qb, qc) = (m * m, c * c - 2.0 * m * k, k * k - (a / e) * (a / e));
    Ok(((-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa)).sqrt())
}

fn failed(name: &str, e: impl std::fmt::Display) -> CliError {
    CliError::Failed(format!("{name}: {e}"))
}

fn measure_bilateral(
    name: &'static str,
    model: &(dyn Dynamics + Sync),
    repeats: usize,
) -> Result<Bilateral, CliError> {
    let settings = &model.info().defaults;
    let state = model.assemble(0.0).map_err(|e| failed(name, e))?;
    let (mut watched, mut unwatched) = (Stats::default(), Stats::default());
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..repeats {
        let start = Instant::now();
        watched = model
            .simulate(state.clone(), settings)
            .map_err(|f| failed(name, f))?
            .stats;
        a.push(start.elapsed().as_secs_f64());
        let start = Instant::now();
        unwatched = model
            .simulate_states(state.clone(), settings)
            .map_err(|f| failed(name, f))?
            .stats;
        b.push(start.elapsed().as_secs_f64());
    }
    Ok(Bilateral {
        name,
        watched,
        unwatched,
        seconds: (median(&mut a), median(&mut b)),
    })
}

fn measure_one_sided(
    label: String,
    model: &dyn Dynamics,
    t_end: f64,
    repeats: usize,
) -> Result<OneSided, CliError> {
    let settings = SimSettings {
        t_end,
        ..model.info().defaults.clone()
    };
    let state = model.assemble(0.0).map_err(|e| failed(&label, e))?;
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeats {
        let start = Instant::now();
        let run = model
            .simulate_unilateral(state.clone(), &settings, 0.5)
            .map_err(|f| failed(&label, f))?;
        times.push(start.elapsed().as_secs_f64());
        last = Some(run);
    }
    let run = last.ok_or_else(|| failed(&label, "no run"))?;
    Ok(OneSided {
        label,
        events: run.events.len(),
        stats: run.stats,
        seconds: median(&mut times),
    })
}

fn render(bilateral: &[Bilateral], one_sided: &[OneSided], flat_jump: f64) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Measured by `camchain bench events` (also part of `camchain bench`). Each model's \
         default run with full samples, whose normal forces are watched inside every step, \
         beside the same run with states only (nothing watched): right-hand sides per step, \
         force evaluations inside steps per step (each about one right-hand side), the extra \
         work of the watch as a share of the unwatched run's right-hand sides, and median wall \
         times of interleaved runs (the watched run also computes every sample's outputs).\n"
    );
    out.push_str(
        "| model | steps | rhs / step, states only | rhs / step, watched | force evaluations / step | extra work | wall time watched / states only |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for b in bilateral {
        let steps = b.watched.steps.max(1) as f64;
        let base = b.unwatched.rhs_evaluations.max(1) as f64;
        let extra =
            (b.watched.rhs_evaluations as f64 + b.watched.event_evaluations as f64 - base) / base;
        let _ = writeln!(
            out,
            "| {} | {} | {:.2} | {:.2} | {:.3} | {:+.1} % | {:.2} ms / {:.2} ms |",
            b.name,
            b.watched.steps,
            base / b.unwatched.steps.max(1) as f64,
            b.watched.rhs_evaluations as f64 / steps,
            b.watched.event_evaluations as f64 / steps,
            100.0 * extra,
            1e3 * b.seconds.0,
            1e3 * b.seconds.1,
        );
    }
    let _ = writeln!(
        out,
        "\nOne-sided runs (restitution 0.5) where the scans find every lift-off, landing and \
         impact (tests/suite/unilateral.rs checks them against the closed forms; ω_j = \
         {flat_jump:.9} rad/s for eccentric_flat). Gap evaluations are positions only (the \
         dense output, the constraint and its Jacobian, the contact point), far cheaper than a \
         right-hand side.\n"
    );
    out.push_str(
        "| run | events | steps | rhs | force evaluations | gap evaluations | wall time |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for o in one_sided {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {:.1} ms |",
            o.label,
            o.events,
            o.stats.steps,
            o.stats.rhs_evaluations,
            o.stats.event_evaluations,
            o.stats.gap_evaluations,
            1e3 * o.seconds
        );
    }
    out
}
