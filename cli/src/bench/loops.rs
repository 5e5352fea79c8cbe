//! Closed loops, side by side in one run:
//!
//! - the reduced right-hand side of `four_bar`, `andrews_squeezer` and `cam_rocker_linkage`,
//!   generated code against the numeric recursion, at the same consistent states;
//! - Andrews' squeezing mechanism to t = 0.03 s at a ladder of tolerances, DOP853 and
//!   Dopri5: median run time against the largest error of the seven angles from the Test
//!   Set for IVP Solvers' reference solution (its `andrews.f`, subroutine `solut`);
//! - the IFToMM benchmarks A02 (`n_four_bar`, N = 40, 20 s) and A04 (`bricard`, 10 s) at
//!   their model files' tolerances: CPU time, energy drift, constraint violation and the
//!   reported point at the end;
//! - A02 at a ladder of tolerances against its exact one-degree-of-freedom reduction
//!   (`a02.rs`): the error of the point B0 and the wall time.

use super::a02;
use super::evaluations::{derivative, numeric_states, states_along_a_run};
use super::timing::side_by_side;
use crate::CliError;
use crate::source::builtin_description;
use camchain_models as models;
use camchain_models::andrews_reference::{ANGLES, Q_REF};
use camchain_reference::NumericModel;
use camchain_runtime::{Dynamics, IntegratorKind, SimSettings, Simulate, Trajectory};
use std::fmt::Write;
use std::time::Instant;

/// The models whose right-hand side is timed.
const RHS_MODELS: [&str; 3] = ["four_bar", "andrews_squeezer", "cam_rocker_linkage"];

/// One rung of the Andrews ladder.
struct Rung {
    integrator: &'static str,
    rtol: f64,
    seconds: f64,
    error: f64,
    steps: usize,
    rhs: usize,
}

/// One IFToMM run.
struct Benchmark {
    name: &'static str,
    seconds: f64,
    drift: f64,
    energy: f64,
    max_h: f64,
    point: String,
    steps: usize,
    repartitions: usize,
}

/// Measures and returns the report section.
pub fn run(quick: bool) -> Result<String, CliError> {
    let (calls, batches) = if quick { (200, 5) } else { (5_000, 21) };
    let mut rhs = Vec::new();
    for name in RHS_MODELS {
        eprintln!("loops: right-hand side of {name}");
        let generated = builtin(name)?;
        let numeric = NumericModel::new(builtin_description(name)?);
        let states = states_along_a_run(generated)?;
        let numeric_states = numeric_states(&numeric, &states)?;
        let (g, n) = side_by_side(
            derivative(generated, &states)?,
            derivative(&numeric, &numeric_states)?,
            calls,
            batches,
        );
        rhs.push((name, g, n));
    }
    eprintln!("loops: Andrews' squeezer at a ladder of tolerances");
    let rungs = andrews_ladder(quick)?;
    let mut benchmarks = Vec::new();
    for name in ["n_four_bar", "bricard"] {
        eprintln!("loops: {name}");
        benchmarks.push(iftomm(name, if quick { 1 } else { 3 })?);
    }
    eprintln!("loops: n_four_bar against its exact reduction");
    let a02 = a02_ladder(quick)?;
    let mut text = render(&rhs, &rungs, &benchmarks, calls, batches);
    render_a02(&mut text, &a02);
    Ok(text)
}

fn builtin(name: &str) -> Result<&'static dyn Dynamics, CliError> {
    models::by_name(name)
        .map(|m| m as &dyn Dynamics)
        .ok_or_else(|| CliError::Failed(format!("{name} is not built in")))
}

/// A run of `model` with `settings`, and its wall time.
fn timed_run(model: &dyn Dynamics, settings: &SimSettings) -> Result<(Trajectory, f64), CliError> {
    let failed = |e: String| CliError::Failed(format!("{}: {e}", model.info().name));
    let start = Instant::now();
    let state = model.assemble(0.0).map_err(|e| failed(e.to_string()))?;
    let run = model
        .simulate(state, settings)
        .map_err(|f| failed(f.error.to_string()))?;
    Ok((run, start.elapsed().as_secs_f64()))
}

/// The median of `repeats` wall times of the same run, and the run.
fn median_run(
    model: &dyn Dynamics,
    settings: &SimSettings,
    repeats: usize,
) -> Result<(Trajectory, f64), CliError> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let (run, seconds) = timed_run(model, settings)?;
        times.push(seconds);
        last = Some(run);
    }
    times.sort_by(f64::total_cmp);
    let run = last.ok_or_else(|| CliError::Failed("no run".into()))?;
    Ok((run, times[times.len() / 2]))
}

fn andrews_ladder(quick: bool) -> Result<Vec<Rung>, CliError> {
    let model = builtin("andrews_squeezer")?;
    let info = model.info();
    let index: Vec<usize> = ANGLES
        .iter()
        .map(|a| info.coordinate_index(a))
        .collect::<Option<_>>()
        .ok_or_else(|| CliError::Failed("andrews_squeezer: an angle is missing".into()))?;
    let exponents: &[i32] = if quick {
        &[-6, -10]
    } else {
        &[-4, -5, -6, -7, -8, -9, -10, -11, -12, -13]
    };
    let mut rungs = Vec::new();
    for (integrator, kind) in [
        ("dop853", IntegratorKind::Dop853),
        ("dopri5", IntegratorKind::Dopri5),
    ] {
        for &e in exponents {
            let rtol = 10f64.powi(e);
            if kind == IntegratorKind::Dopri5 && e < -11 {
                continue;
            }
            let mut settings = info.defaults.clone();
            (
                settings.integrator,
                settings.rtol,
                settings.atol,
                settings.dt_out,
            ) = (kind, rtol, rtol * 1e-2, 0.03);
            settings.dt = 1e-6;
            let (run, seconds) = median_run(model, &settings, if quick { 1 } else { 5 })?;
            let last = run
                .samples
                .last()
                .ok_or_else(|| CliError::Failed("no sample".into()))?;
            let error = index
                .iter()
                .zip(Q_REF)
                .map(|(&i, r)| (last.q[i] - r).abs())
                .fold(0.0, f64::max);
            rungs.push(Rung {
                integrator,
                rtol,
                seconds,
                error,
                steps: run.stats.steps,
                rhs: run.stats.rhs_evaluations,
            });
        }
    }
    Ok(rungs)
}

fn iftomm(name: &'static str, repeats: usize) -> Result<Benchmark, CliError> {
    let model = builtin(name)?;
    let settings = model.info().defaults.clone();
    let (run, seconds) = median_run(model, &settings, repeats)?;
    let first = run
        .samples
        .first()
        .ok_or_else(|| CliError::Failed("no sample".into()))?;
    let last = run
        .samples
        .last()
        .ok_or_else(|| CliError::Failed("no sample".into()))?;
    let total = |s: &camchain_runtime::Sample| s.energy.total() + s.dissipated - s.driven_work;
    let drift = run
        .samples
        .iter()
        .map(|s| (total(s) - total(first)).abs())
        .fold(0.0, f64::max);
    let max_h = run
        .samples
        .iter()
        .flat_map(|s| s.h.iter())
        .fold(0.0_f64, |m, h| m.max(h.abs()));
    let point = match name {
        // B0, the tip of the first crank (1 m long, from the origin).
        "n_four_bar" => format!(
            "B0 = ({:.6}, {:.6}) m at t = {} s",
            last.q[0].cos(),
            last.q[0].sin(),
            last.t
        ),
        // P3, the joint C: B = R_y(qA) (1, 0, 0), C = B + R_y(qA) R_z(qB) (0, −1, 0).
        _ => {
            let (a, b) = (last.q[0], last.q[1]);
            let (x, y) = (1.0 + b.sin(), -b.cos());
            format!(
                "P3 (joint C) = ({:.6}, {:.6}, {:.6}) m at t = {} s",
                x * a.cos(),
                y,
                -x * a.sin(),
                last.t
            )
        }
    };
    Ok(Benchmark {
        name,
        seconds,
        drift,
        energy: first.energy.kinetic.abs() + first.energy.gravity.abs(),
        max_h,
        point,
        steps: run.stats.steps,
        repartitions: run.stats.repartitions,
    })
}

/// One rung of the A02 ladder: rtol = atol.
struct A02Rung {
    tolerance: f64,
    error: f64,
    at: f64,
    seconds: f64,
    steps: usize,
    rejected: usize,
    rhs: usize,
}

/// A02 at rtol = atol = 1e-6 … 1e-11, B0 against the exact reduction.
fn a02_ladder(quick: bool) -> Result<Vec<A02Rung>, CliError> {
    let model = builtin("n_four_bar")?;
    let exponents: &[i32] = if quick {
        &[-8]
    } else {
        &[-6, -7, -8, -9, -10, -11]
    };
    let mut rungs = Vec::new();
    for &e in exponents {
        let tolerance = 10f64.powi(e);
        let mut settings = model.info().defaults.clone();
        (settings.rtol, settings.atol) = (tolerance, tolerance);
        let (run, seconds) = median_run(model, &settings, if quick { 1 } else { 3 })?;
        let (error, at) = a02::largest_error(&run);
        rungs.push(A02Rung {
            tolerance,
            error,
            at,
            seconds,
            steps: run.stats.steps,
            rejected: run.stats.rejected,
            rhs: run.stats.rhs_evaluations,
        });
    }
    Ok(rungs)
}

/// The A02 ladder's table, before the section's last line.
fn render_a02(text: &mut String, rungs: &[A02Rung]) {
    let mut table = String::from(
        "\n### A02 against its exact reduction\n\n`n_four_bar` (N = 40, 20 s, DOP853) at \
         rtol = atol: the largest distance of B0 from the exact motion (the pendulum of the \
         same energy, by quadrature: `cli/src/bench/a02.rs`) over the samples, and the median \
         wall time of 3 runs (assembly included).\n\n\
         | rtol = atol | B0 error | at t | wall time | steps | rejected | right-hand sides |\n\
         |---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rungs {
        let _ = writeln!(
            table,
            "| {:.0e} | {:.2e} m | {:.2} s | {:.3} s | {} | {} | {} |",
            r.tolerance, r.error, r.at, r.seconds, r.steps, r.rejected, r.rhs
        );
    }
    let at = text.rfind("\nReproduce:").unwrap_or(text.len());
    text.insert_str(at, &table);
}

fn render(
    rhs: &[(&str, f64, f64)],
    rungs: &[Rung],
    benchmarks: &[Benchmark],
    calls: usize,
    batches: usize,
) -> String {
    let mut text = String::from("## Closed loops\n\n### Reduced right-hand side\n\n");
    let _ = writeln!(
        text,
        "`derivative` (Newton (15), velocities (16), reduced equations (18)) at the \
         same consistent states, generated code and numeric recursion interleaved; medians of \
         {batches} batches of up to {calls} calls.\n"
    );
    let _ = writeln!(
        text,
        "| model | generated | numeric | numeric / generated |"
    );
    let _ = writeln!(text, "|---|---:|---:|---:|");
    for (name, g, n) in rhs {
        let _ = writeln!(
            text,
            "| `{name}` | {:.2} µs | {:.1} µs | {:.0}× |",
            g * 1e-3,
            n * 1e-3,
            n / g
        );
    }
    let _ = writeln!(
        text,
        "\n### Andrews' squeezing mechanism: run time against error\n\nGenerated code, from the test set's consistent initial \
         state to t = 0.03 s at rtol (atol = rtol/100): the largest error of the seven angles \
         against the test set's reference solution (`andrews.f`, `solut`), median wall time \
         of 5 runs. Below rtol 1e-10 the error stays at \
         1.4e-9 rad, on β and Θ (15.8 rad): 9e-11 relative, what to expect of a reference \
         computed at 1e-14 and printed to 16 digits.\n"
    );
    let _ = writeln!(
        text,
        "| integrator | rtol | error (rad) | wall time | steps | right-hand sides |"
    );
    let _ = writeln!(text, "|---|---:|---:|---:|---:|---:|");
    for r in rungs {
        let _ = writeln!(
            text,
            "| {} | {:.0e} | {:.2e} | {:.2} ms | {} | {} |",
            r.integrator,
            r.rtol,
            r.error,
            r.seconds * 1e3,
            r.steps,
            r.rhs
        );
    }
    let _ = writeln!(
        text,
        "\nThe test set's own figure is its reference run: PSIDE at rtol = atol = 1e-14, 1112 \
         steps, 26000 evaluations, 56.74 s on a Cray C90 (`andrews.f`). It is not compared \
         with the times above: a different machine of 1991, an index-3 DAE solver on all 27 \
         variables (q, q̇, q̈, λ) against coordinate partitioning on one, and no per-solver \
         tables of the test set's documentation were available to this project.\n"
    );
    let _ = writeln!(
        text,
        "### IFToMM benchmark problems\n\nAt their model files' settings (median wall time of the \
         runs, assembly included). A02 (`n_four_bar`, N = 40: 81 links, 80 loop equations, \
         passing the horizontal singular position 20 times in 20 s) reports the point B0; A04 \
         (`bricard`, one redundant equation left out) the point P3, the joint C. No \
         reference solution files of the library were available: A02 is checked against its \
         equivalent pendulum and, for N = 2, Exudyn's published runs (`tests/suite/loops.rs`).\n"
    );
    let _ = writeln!(
        text,
        "| problem | wall time | steps | re-partitions | energy drift | max |h| | at the end |"
    );
    let _ = writeln!(text, "|---|---:|---:|---:|---:|---:|---|");
    for b in benchmarks {
        let _ = writeln!(
            text,
            "| `{}` | {:.3} s | {} | {} | {:.1e} J ({:.1e} of {:.1} J) | {:.1e} | {} |",
            b.name,
            b.seconds,
            b.steps,
            b.repartitions,
            b.drift,
            b.drift / b.energy,
            b.energy,
            b.max_h,
            b.point
        );
    }
    let _ = writeln!(
        text,
        "\nReproduce: `cargo run --release -- bench loops` (also part of `bench evaluations`)."
    );
    text
}
