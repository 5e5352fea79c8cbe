//! Cams on moving bodies, side by side in one run:
//!
//! - the reduced right-hand side of the cam models on moving bodies (`eccentric_roller`,
//!   `paper_rotating`) against that of the fixed-cam paper model (`paper_concave`), batches of
//!   the two interleaved;
//! - one full camshaft revolution at rtol = atol = 1e-10 (DOP853) of the camshaft models: run
//!   time, steps, right-hand sides, and the error against the closed form where there is one.

use super::evaluations::{STATES, derivative, states_along_a_run};
use super::timing::{median_seconds, side_by_side};
use crate::CliError;
use crate::source::builtin_description;
use camchain_models as models;
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, IntegratorKind, SimSettings, Simulate, State, Stats, Trajectory};
use std::f64::consts::TAU;
use std::fmt::Write;
use std::hint::black_box;

/// The fixed-cam yardstick of the right-hand side.
const YARDSTICK: &str = "paper_concave";

/// Cam models on moving bodies whose right-hand side is set against the yardstick's.
const MOVING: [&str; 2] = ["eccentric_roller", "paper_rotating"];

/// Goal: a moving-cam right-hand side within this factor of the yardstick's.
const RHS_GOAL_RATIO: f64 = 1.5;

/// Goal: the absolute figure for the right-hand side (ns).
const RHS_GOAL_NS: f64 = 250.0;

/// Goal: one revolution at `TOLERANCE` within this wall time (s).
const REVOLUTION_GOAL: f64 = 1e-3;

/// rtol = atol of the revolution runs.
const TOLERANCE: f64 = 1e-10;

/// What a revolution's coordinates are checked against.
#[derive(Clone, Copy)]
enum Check {
    /// The flat face on the eccentric disc: s = R + e cos θ (simple harmonic motion).
    Flat,
    /// The in-line roller on the eccentric disc: s = e cos θ + √((R + ρ)² − e² sin² θ).
    Roller,
    /// No closed form: the numeric reference (`reference/src/numeric.rs`), same settings.
    Numeric,
    /// No closed form, a free camshaft: the same model at rtol = atol = 1e-13.
    Tight,
}

/// The camshaft models of the revolution runs.
const REVOLUTIONS: [(&str, Check); 4] = [
    ("eccentric_flat", Check::Flat),
    ("eccentric_roller", Check::Roller),
    ("rocker_roller", Check::Numeric),
    ("camshaft_flywheel", Check::Tight),
];

/// One reduced right-hand side against the yardstick's, measured interleaved: at a new
/// state (cache cleared) and along a run (consecutive states through one state object).
struct RhsRow {
    model: &'static str,
    ns: f64,
    yardstick_ns: f64,
    along_ns: f64,
    yardstick_along_ns: f64,
}

/// Spacing (s) of the consecutive states of the right-hand side along a run.
const ALONG_SPACING: f64 = 1e-3;

/// One revolution of one model.
struct Revolution {
    model: &'static str,
    period: f64,
    samples: usize,
    seconds: f64,
    end_only_seconds: f64,
    /// Right-hand sides of the run to the end state alone.
    end_only_rhs: usize,
    stats: Stats,
    error: f64,
    check: Check,
}

/// Measures both parts and returns the report section.
pub fn run(quick: bool) -> Result<String, CliError> {
    let (calls, batches) = if quick { (2_000, 5) } else { (20_000, 31) };
    let yardstick = builtin(YARDSTICK)?;
    let yardstick_states = states_along_a_run(yardstick)?;
    let yardstick_consecutive = consecutive_states(yardstick)?;
    let mut rhs = Vec::new();
    for name in MOVING {
        eprintln!("cams: right-hand side of {name}");
        let model = builtin(name)?;
        let states = states_along_a_run(model)?;
        let (ns, yardstick_ns) = side_by_side(
            derivative(model, &states)?,
            derivative(yardstick, &yardstick_states)?,
            calls,
            batches,
        );
        let (along_ns, yardstick_along_ns) = side_by_side(
            derivative_along(model, &consecutive_states(model)?)?,
            derivative_along(yardstick, &yardstick_consecutive)?,
            calls,
            batches,
        );
        rhs.push(RhsRow {
            model: name,
            ns,
            yardstick_ns,
            along_ns,
            yardstick_along_ns,
        });
    }
    let mut revolutions = Vec::new();
    for (name, check) in REVOLUTIONS {
        eprintln!("cams: one revolution of {name}");
        revolutions.push(revolution(name, check, quick)?);
    }
    Ok(render(&rhs, &revolutions, calls, batches))
}

/// `STATES` consecutive states `ALONG_SPACING` apart, from 0.5 s into the model's run.
pub(super) fn consecutive_states(model: &dyn Dynamics) -> Result<Vec<State>, CliError> {
    let failed = |e: String| CliError::Failed(format!("{}: {e}", model.info().name));
    let mut state = model.assemble(0.0).map_err(|e| failed(e.to_string()))?;
    model
        .step(&mut state, 0.5)
        .map_err(|e| failed(e.to_string()))?;
    let mut states = Vec::with_capacity(STATES);
    for _ in 0..STATES {
        model
            .step(&mut state, ALONG_SPACING)
            .map_err(|e| failed(e.to_string()))?;
        states.push(state.clone());
    }
    Ok(states)
}

/// `derivative` at `states` in turn through one state object, as an integrator evaluates
/// along a run: its t, q and q̇ set to the next state's before each call, so that the sines
/// and cosines are computed afresh while a contact parameter's Newton starts from the last
/// call's solution, `ALONG_SPACING` away (from `STATES − 1` spacings back at the wrap).
pub(super) fn derivative_along<'a>(
    model: &'a dyn Dynamics,
    states: &'a [State],
) -> Result<impl FnMut() + 'a, CliError> {
    let mut current = states[0].clone();
    let mut dy = vec![0.0; current.integrated_len()];
    let mut k = 0;
    let mut call = move || {
        let next = &states[k % STATES];
        k += 1;
        current.t = next.t;
        current.q.copy_from_slice(&next.q);
        current.qd.copy_from_slice(&next.qd);
        let result = model.derivative(&mut current, &mut dy);
        black_box(&dy);
        result
    };
    // Every state once outside the timing: they are consistent, so the measured calls
    // cannot fail.
    for _ in 0..STATES {
        call().map_err(|e| CliError::Failed(format!("{}: {e}", model.info().name)))?;
    }
    Ok(move || {
        let _ = call();
    })
}

fn builtin(name: &str) -> Result<&'static dyn Dynamics, CliError> {
    match models::by_name(name) {
        Some(model) => Ok(model),
        None => Err(CliError::Failed(format!("{name} is not built in"))),
    }
}

/// A parameter's value in the model file (folded ones included).
fn parameter(name: &str, parameter: &str) -> Result<f64, CliError> {
    builtin_description(name)?
        .parameters
        .iter()
        .find(|p| p.name == parameter)
        .map(|p| p.value)
        .ok_or_else(|| CliError::Failed(format!("{name} has no parameter {parameter}")))
}

fn coordinate(model: &dyn Dynamics, name: &str) -> Result<usize, CliError> {
    model
        .info()
        .coordinate_index(name)
        .ok_or_else(|| CliError::Failed(format!("{} has no coordinate {name}", model.info().name)))
}

/// The run: bilateral, or one-sided with the model file's restitution.
fn simulate(
    model: &dyn Dynamics,
    start: &State,
    settings: &SimSettings,
) -> Result<Trajectory, CliError> {
    let run = match model.info().restitution {
        Some(e) => model.simulate_unilateral(start.clone(), settings, e),
        None => model.simulate_states(start.clone(), settings),
    };
    run.map_err(|f| CliError::Failed(format!("{}: {f}", model.info().name)))
}

/// The duration of one revolution: 2π/ω for a camshaft driven at ω; for a free camshaft the
/// time its angle first reaches 2π, interpolated between the samples of a run at 0.1 ms.
fn period(name: &str, model: &dyn Dynamics, start: &State) -> Result<f64, CliError> {
    if model.info().parameter_index("omega").is_some() {
        return Ok(TAU / parameter(name, "omega")?);
    }
    let angle = coordinate(model, "cam_angle")?;
    let settings = SimSettings {
        integrator: IntegratorKind::Dop853,
        rtol: TOLERANCE,
        atol: TOLERANCE,
        dt_out: 1e-4,
        ..model.info().defaults.clone()
    };
    let run = simulate(model, start, &settings)?;
    let turn = start.q[angle] + TAU;
    run.samples
        .windows(2)
        .find(|w| w[0].q[angle] < turn && w[1].q[angle] >= turn)
        .map(|w| {
            let (a, b) = (&w[0], &w[1]);
            a.t + (turn - a.q[angle]) / (b.q[angle] - a.q[angle]) * (b.t - a.t)
        })
        .ok_or_else(|| {
            CliError::Failed(format!(
                "{name}: the camshaft does not turn once in {} s",
                settings.t_end
            ))
        })
}

fn revolution(name: &'static str, check: Check, quick: bool) -> Result<Revolution, CliError> {
    let model = builtin(name)?;
    let failed = |e: String| CliError::Failed(format!("{name}: {e}"));
    let start = model.assemble(0.0).map_err(|e| failed(e.to_string()))?;
    let period = period(name, model, &start)?;
    // The model file's outputs (every 1 ms), and the end state alone.
    let settings = SimSettings {
        integrator: IntegratorKind::Dop853,
        rtol: TOLERANCE,
        atol: TOLERANCE,
        t_end: period,
        ..model.info().defaults.clone()
    };
    let end_only = SimSettings {
        dt_out: period,
        ..settings.clone()
    };
    let run = simulate(model, &start, &settings)?;
    let end_only_rhs = simulate(model, &start, &end_only)?.stats.rhs_evaluations;
    let error = error(name, model, &start, &settings, &run, check)?;
    let time = |settings: &SimSettings| {
        // ~0.3 s of measurement (quick: 0.05 s), 3 to 31 runs.
        let (budget, most) = if quick { (0.05, 7) } else { (0.3, 31) };
        let once = median_seconds(|| simulate(model, &start, settings), 1);
        let repeats = ((budget / once.max(1e-6)) as usize).clamp(3, most);
        median_seconds(|| simulate(model, &start, settings), repeats)
    };
    let (seconds, end_only_seconds) = (time(&settings), time(&end_only));
    Ok(Revolution {
        model: name,
        period,
        samples: run.samples.len(),
        seconds,
        end_only_seconds,
        end_only_rhs,
        stats: run.stats,
        error,
        check,
    })
}

/// The largest difference over the output times of the run's coordinates from what `check`
/// compares them with (m for the lift of the eccentric followers; rad or m otherwise).
fn error(
    name: &str,
    model: &dyn Dynamics,
    start: &State,
    settings: &SimSettings,
    run: &Trajectory,
    check: Check,
) -> Result<f64, CliError> {
    let largest = |values: &mut dyn Iterator<Item = f64>| values.fold(0.0, f64::max);
    let against = |other: &Trajectory| {
        largest(
            &mut run
                .samples
                .iter()
                .zip(&other.samples)
                .flat_map(|(a, b)| a.q.iter().zip(&b.q).map(|(x, y)| (x - y).abs())),
        )
    };
    match check {
        Check::Flat | Check::Roller => {
            let lift = coordinate(model, "lift")?;
            let (r, e, omega) = (
                parameter(name, "R")?,
                parameter(name, "e")?,
                parameter(name, "omega")?,
            );
            let rho = match check {
                Check::Roller => parameter(name, "rho")?,
                _ => 0.0,
            };
            let exact = |t: f64| {
                let (sin, cos) = (omega * t).sin_cos();
                match check {
                    Check::Flat => r + e * cos,
                    _ => e * cos + ((r + rho).powi(2) - e * e * sin * sin).sqrt(),
                }
            };
            Ok(largest(
                &mut run.samples.iter().map(|s| (s.q[lift] - exact(s.t)).abs()),
            ))
        }
        Check::Numeric => {
            let numeric = NumericModel::new(builtin_description(name)?);
            let start = numeric
                .assemble(0.0)
                .map_err(|e| CliError::Failed(format!("{name} (numeric): {e}")))?;
            Ok(against(&simulate(&numeric, &start, settings)?))
        }
        Check::Tight => {
            let tight = SimSettings {
                rtol: 1e-13,
                atol: 1e-13,
                ..settings.clone()
            };
            Ok(against(&simulate(model, start, &tight)?))
        }
    }
}

fn render(rhs: &[RhsRow], revolutions: &[Revolution], calls: usize, batches: usize) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "## Cams on moving bodies\n\n\
         ### Reduced right-hand side against the fixed-cam paper model\n\n\
         `derivative` of the generated code (Newton on the dependent coordinates, their \
         velocities, the reduced dynamics), two ways. At a new state, as in the section \
         \"Generated code against the numeric recursion\": 8 consistent states 0.5 s apart \
         along the model's run, each state's evaluation cache cleared before the call, so no \
         sine, cosine or contact parameter of the last call is reused (a roller's contact \
         parameter is solved by Newton from its cold start, the polar angle of the roller's \
         centre). Along a run: 8 consecutive states {:.0} ms apart through one state object, \
         as an integrator's stages: the sines and cosines are computed afresh, the contact \
         parameter's Newton starts from the previous state's solution. Median of {batches} \
         batches of {calls} calls, a batch of the model and one of `{YARDSTICK}` in turn \
         (goal: within {RHS_GOAL_RATIO}× of `{YARDSTICK}`).\n\n\
         | model | new state [ns] | `{YARDSTICK}` [ns] | ratio | along a run [ns] | `{YARDSTICK}` [ns] | ratio |\n\
         |---|---:|---:|---:|---:|---:|---:|",
        ALONG_SPACING * 1e3
    );
    let ratio = |a: f64, b: f64| {
        let r = a / b;
        format!("{r:.2}× ({})", verdict(r <= RHS_GOAL_RATIO))
    };
    for r in rhs {
        let _ = writeln!(
            out,
            "| {} | {:.0} | {:.0} | {} | {:.0} | {:.0} | {} |",
            r.model,
            r.ns,
            r.yardstick_ns,
            ratio(r.ns, r.yardstick_ns),
            r.along_ns,
            r.yardstick_along_ns,
            ratio(r.along_ns, r.yardstick_along_ns),
        );
    }
    let _ = writeln!(
        out,
        "\n### One camshaft revolution at rtol = atol = {TOLERANCE:.0e}\n\n\
         One full revolution from the assembled initial state, DOP853 at rtol = atol = \
         {TOLERANCE:.0e}, through `Simulate::simulate_states` (`simulate_unilateral` for the \
         one-sided contact of `camshaft_flywheel`, whose free camshaft spins up from rest: its \
         revolution ends where its angle first reaches 2π). Time: median wall time of 3 to 31 \
         whole runs (about 0.3 s of runs per figure), with the model file's outputs (every \
         1 ms; the goal is judged on this run; the one-sided run of `camshaft_flywheel` \
         computes full samples, forces included, at its outputs) and with the end state alone \
         (whose time per right-hand side is what one evaluation costs in a run, the \
         integrator's work included). Error: the largest difference over the outputs \
         of the follower's lift from the closed form (`eccentric_flat`: s = R + e cos θ, \
         harmonic motion of amplitude e; `eccentric_roller`: s = e cos θ + √((R + ρ)² − e² \
         sin² θ) above the camshaft's axis; R = 40 mm, e = 10 mm, ρ = 12.5 mm, θ = ωt at \
         ω = 20 rad/s, as in `tests/suite/cams.rs`), and where there is none of every \
         coordinate from the numeric reference at the same settings (`rocker_roller`) or from \
         the same model at rtol = atol = 1e-13 (`camshaft_flywheel`). These mechanisms have \
         no free coordinate (but `camshaft_flywheel`'s camshaft): the follower is solved by \
         Newton at every evaluation and the steps are set by the energy quadratures.\n\n\
         | model | revolution [s] | outputs | time [ms] | steps | rejected | right-hand sides | end state only: time [ms] | … per right-hand side [ns] | max error | against | goal < 1 ms |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|:-:|"
    );
    for r in revolutions {
        let against = match r.check {
            Check::Flat | Check::Roller => "closed form (lift, m)",
            Check::Numeric => "numeric reference (q)",
            Check::Tight => "DOP853 1e-13 (q)",
        };
        let _ = writeln!(
            out,
            "| {} | {:.4} | {} | {:.3} | {} | {} | {} | {:.3} | {:.0} | {:.1e} | {against} | {} |",
            r.model,
            r.period,
            r.samples,
            r.seconds * 1e3,
            r.stats.steps,
            r.stats.rejected,
            r.stats.rhs_evaluations,
            r.end_only_seconds * 1e3,
            r.end_only_seconds * 1e9 / r.end_only_rhs.max(1) as f64,
            r.error,
            verdict(r.seconds < REVOLUTION_GOAL)
        );
    }
    goals(&mut out, rhs, revolutions);
    let _ = writeln!(
        out,
        "\nReproduce: `cargo run --release -- bench evaluations` (rewrites this section and \
         the section \"Generated code against the numeric recursion\")."
    );
    out
}

/// The goals in one paragraph.
fn goals(out: &mut String, rhs: &[RhsRow], revolutions: &[Revolution]) {
    let mut text = format!(
        "\n**Against the goals.** Reduced right-hand side at a new state within \
         {RHS_GOAL_RATIO}× of `{YARDSTICK}`'s measured beside it (which the issue puts at \
         under about {RHS_GOAL_NS:.0} ns): "
    );
    let rows: Vec<String> = rhs
        .iter()
        .map(|r| {
            let ratio = r.ns / r.yardstick_ns;
            format!(
                "`{}` {:.0} ns, {ratio:.2}× ({}; under {RHS_GOAL_NS:.0} ns: {})",
                r.model,
                r.ns,
                verdict(ratio <= RHS_GOAL_RATIO),
                if r.ns < RHS_GOAL_NS { "yes" } else { "no" }
            )
        })
        .collect();
    text.push_str(&rows.join("; "));
    let slowest = revolutions
        .iter()
        .max_by(|a, b| a.seconds.total_cmp(&b.seconds));
    let all = revolutions.iter().all(|r| r.seconds < REVOLUTION_GOAL);
    if let Some(slowest) = slowest {
        let _ = write!(
            text,
            ". One revolution at {TOLERANCE:.0e} under {:.0} ms: {} (slowest `{}`, {:.3} ms).",
            REVOLUTION_GOAL * 1e3,
            if all { "met by every model" } else { "missed" },
            slowest.model,
            slowest.seconds * 1e3
        );
    }
    let _ = writeln!(out, "{text}");
}

fn verdict(met: bool) -> &'static str {
    if met { "met" } else { "missed" }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_section_renders_a_row_per_measurement_and_the_verdicts() {
        let rhs = [RhsRow {
            model: "eccentric_roller",
            ns: 360.0,
            yardstick_ns: 120.0,
            along_ns: 150.0,
            yardstick_along_ns: 100.0,
        }];
        let revolutions = [Revolution {
            model: "eccentric_flat",
            period: TAU / 20.0,
            samples: 316,
            seconds: 2e-3,
            end_only_seconds: 4e-4,
            end_only_rhs: 400,
            stats: Stats {
                steps: 40,
                rejected: 1,
                rhs_evaluations: 500,
                repartitions: 0,
                event_evaluations: 0,
                gap_evaluations: 0,
            },
            error: 1e-17,
            check: Check::Flat,
        }];
        let text = render(&rhs, &revolutions, 10, 3);
        assert!(text.contains(
            "| eccentric_roller | 360 | 120 | 3.00× (missed) | 150 | 100 | 1.50× (met) |"
        ));
        assert!(text.contains("| eccentric_flat | 0.3142 | 316 | 2.000 | 40 | 1 | 500 | 0.400 | 1000 | 1.0e-17 | closed form (lift, m) | missed |"));
    }
}
