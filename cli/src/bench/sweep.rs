//! The sweep benchmark (issue 12 §3), side by side in one run:
//!
//! - the whole-run overhead of `paper_concave` (10 s): a metrics run (what a sweep keeps)
//!   and a full run (1001 samples) against the right-hand sides they evaluate times the time
//!   of one reduced right-hand side at a new state;
//! - sweep throughput: `camchain sweep` itself (plan, workers, the CSV written) over a grid
//!   of `swing` and `k3` near the paper's values, with 1 and 2 workers, at two tolerances;
//! - memory: the peak resident memory of `camchain sweep` processes of 1 000 to 100 000
//!   runs (the rows are streamed: it must not grow with the number of runs).

use super::timing::median;
use crate::CliError;
use crate::args::SweepArgs;
use crate::interrupt::Interrupt;
use crate::sweep;
use camchain_models as models;
use camchain_runtime::{Dynamics, MetricsOptions, SimSettings, Simulate, State};
use std::fmt::Write;
use std::hint::black_box;
use std::time::Instant;

/// The tolerances measured (rtol = atol).
const TOLERANCES: [f64; 2] = [1e-6, 1e-8];

/// Runs the benchmark and returns its section of the report.
pub fn run(quick: bool) -> Result<String, CliError> {
    let model = models::by_name("paper_concave")
        .ok_or_else(|| CliError::Failed("paper_concave is not built in".into()))?;
    let mut text = String::new();
    let _ = writeln!(text, "## Sweeps: whole-run overhead, throughput, memory\n");
    let _ = writeln!(
        text,
        "Measured by `cargo run --release -- bench sweep` in one run (medians; the machine's \
         two cores). `paper_concave`, 10 s runs, DOP853 with rtol = atol = the tolerance \
         given.\n"
    );
    eprintln!("sweep: overhead");
    text.push_str(&overhead(model, quick)?);
    eprintln!("sweep: throughput");
    text.push_str(&throughput(quick)?);
    eprintln!("sweep: memory");
    text.push_str(&memory(quick)?);
    Ok(text)
}

fn settings(model: &dyn Dynamics, tolerance: f64) -> SimSettings {
    SimSettings {
        rtol: tolerance,
        atol: tolerance,
        ..model.info().defaults.clone()
    }
}

/// One reduced right-hand side at a new state (ns): `derivative` at 8 states 0.5 s apart
/// along a run, each state's cache cleared before the call so that nothing of the last
/// call at that state is reused, minus the time of the clearing alone.
fn reduced_rhs_ns(model: &dyn Dynamics, quick: bool) -> Result<f64, CliError> {
    let failed = |e: String| CliError::Failed(format!("paper_concave: {e}"));
    let mut state = model.assemble(0.0).map_err(|e| failed(e.to_string()))?;
    let mut states: Vec<State> = Vec::new();
    for _ in 0..8 {
        model
            .step(&mut state, 0.5)
            .map_err(|e| failed(e.to_string()))?;
        states.push(state.clone());
    }
    let mut dy = vec![0.0; states[0].integrated_len()];
    for s in &mut states {
        model
            .derivative(s, &mut dy)
            .map_err(|e| failed(e.to_string()))?;
    }
    let (calls, batches) = if quick { (20_000, 5) } else { (200_000, 31) };
    let (mut with, mut without) = (Vec::new(), Vec::new());
    for _ in 0..batches {
        for (evaluate, times) in [(true, &mut with), (false, &mut without)] {
            let start = Instant::now();
            for k in 0..calls {
                let s = &mut states[k % 8];
                s.clear_evaluation_cache();
                if evaluate {
                    let _ = model.derivative(s, &mut dy);
                    black_box(&dy);
                }
            }
            times.push(start.elapsed().as_nanos() as f64 / calls as f64);
        }
    }
    Ok(median(&mut with) - median(&mut without))
}

/// Median wall time (µs) and right-hand sides of `run`.
fn timed(
    repeats: usize,
    mut run: impl FnMut() -> Result<usize, String>,
) -> Result<(f64, usize), CliError> {
    let mut times = Vec::with_capacity(repeats);
    let mut rhs = 0;
    for _ in 0..repeats {
        let start = Instant::now();
        rhs = run().map_err(CliError::Failed)?;
        times.push(start.elapsed().as_secs_f64() * 1e6);
    }
    Ok((median(&mut times), rhs))
}

fn overhead(model: &dyn Dynamics, quick: bool) -> Result<String, CliError> {
    let repeats = if quick { 21 } else { 201 };
    let rhs_ns = reduced_rhs_ns(model, quick)?;
    let start = model
        .assemble(0.0)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let mut text = format!(
        "**Whole-run overhead**: the time of one run divided by (right-hand sides evaluated × \
         the time of one reduced right-hand side). One reduced right-hand side at a new state \
         (`derivative` at 8 states along a run, each state's cache cleared before the call, \
         the clearing's own time subtracted): **{rhs_ns:.0} ns** in this run. A metrics run \
         is what `camchain sweep` runs (no trajectory kept, the metrics read at every step's \
         end); a full run keeps 1001 samples (`simulate`).\n\n\
         | tolerance | run | time [µs] | right-hand sides | rhs × {rhs_ns:.0} ns [µs] | overhead |\n\
         |---|---|---:|---:|---:|---:|\n"
    );
    for tolerance in TOLERANCES {
        let s = settings(model, tolerance);
        let metrics = timed(repeats, || {
            model
                .simulate_metrics(start.clone(), &s, MetricsOptions::default())
                .map(|m| m.stats.rhs_evaluations)
                .map_err(|e| e.to_string())
        })?;
        let grid = timed(repeats, || {
            model
                .simulate_metrics(start.clone(), &s, MetricsOptions { grid: true })
                .map(|m| m.stats.rhs_evaluations)
                .map_err(|e| e.to_string())
        })?;
        let full = timed(repeats, || {
            model
                .simulate(start.clone(), &s)
                .map(|t| t.stats.rhs_evaluations)
                .map_err(|e| e.to_string())
        })?;
        for (name, (us, rhs)) in [
            ("metrics (sweep)", metrics),
            ("metrics with --grid", grid),
            ("full, 1001 samples", full),
        ] {
            let ideal = rhs as f64 * rhs_ns * 1e-3;
            let _ = writeln!(
                text,
                "| {tolerance:e} | {name} | {us:.0} | {rhs} | {ideal:.0} | {:.2} |",
                us / ideal
            );
        }
    }
    text.push('\n');
    Ok(text)
}

/// `camchain sweep` arguments for the benchmark grid of `n × n` runs.
fn sweep_args(n: usize, tolerance: f64, jobs: usize, csv: &std::path::Path) -> SweepArgs {
    SweepArgs {
        model: "paper_concave".into(),
        params: vec![format!("swing=0.05:0.15:{n}"), format!("k3=30:50:{n}")],
        jobs: Some(jobs),
        integration: crate::args::IntegrationArgs {
            rtol: Some(tolerance),
            atol: Some(tolerance),
            ..Default::default()
        },
        csv: Some(csv.to_path_buf()),
        no_plots: true,
        quiet: true,
        ..SweepArgs::default()
    }
}

fn throughput(quick: bool) -> Result<String, CliError> {
    let (n, repeats) = if quick { (20, 1) } else { (50, 3) };
    let dir = std::env::temp_dir().join(format!("camchain-bench-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| CliError::Failed(e.to_string()))?;
    let csv = dir.join("bench.csv");
    let interrupt = Interrupt::install();
    let mut text = format!(
        "**Sweep throughput**: `camchain sweep paper_concave --param swing=0.05:0.15:{n} \
         --param k3=30:50:{n} --rtol TOL --atol TOL --jobs J --csv FILE --no-plots -q` ({} \
         runs of 10 s each, the CSV written), in the process (the same code as the command), \
         median of {repeats}; configurations interleaved.\n\n\
         | tolerance | runs/s, 1 worker | runs/s, 2 workers | speed-up |\n|---|---:|---:|---:|\n",
        n * n
    );
    for tolerance in TOLERANCES {
        let mut rates = [Vec::new(), Vec::new()];
        for _ in 0..repeats {
            for (k, jobs) in [1, 2].into_iter().enumerate() {
                let plan = sweep::plan(&sweep_args(n, tolerance, jobs, &csv))?;
                let start = Instant::now();
                sweep::execute(&plan, &interrupt)?;
                rates[k].push((n * n) as f64 / start.elapsed().as_secs_f64());
            }
        }
        let (one, two) = (median(&mut rates[0]), median(&mut rates[1]));
        let _ = writeln!(
            text,
            "| {tolerance:e} | {one:.0} | {two:.0} | {:.2} |",
            two / one
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    text.push('\n');
    Ok(text)
}

fn memory(quick: bool) -> Result<String, CliError> {
    let exe = std::env::current_exe().map_err(|e| CliError::Failed(e.to_string()))?;
    let dir = std::env::temp_dir().join(format!("camchain-bench-memory-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| CliError::Failed(e.to_string()))?;
    let sizes: &[usize] = if quick { &[10, 30] } else { &[32, 100, 317] };
    let mut text = String::from(
        "**Memory**: peak resident memory (VmHWM) of `camchain sweep paper_concave --param \
         swing=0.05:0.15:N --param k3=30:50:N --t-end 1 --rtol 1e-6 --atol 1e-6 --no-plots \
         --csv FILE`, each sweep a process of its own:\n\n\
         | runs | peak memory [MB] | CSV [MB] |\n|---:|---:|---:|\n",
    );
    for &n in sizes {
        let csv = dir.join(format!("m{n}.csv"));
        let output = std::process::Command::new(&exe)
            .args(["sweep", "paper_concave", "--param"])
            .arg(format!("swing=0.05:0.15:{n}"))
            .arg("--param")
            .arg(format!("k3=30:50:{n}"))
            .args([
                "--t-end",
                "1",
                "--rtol",
                "1e-6",
                "--atol",
                "1e-6",
                "--no-plots",
                "--csv",
            ])
            .arg(&csv)
            .output()
            .map_err(|e| CliError::Failed(format!("cannot run {}: {e}", exe.display())))?;
        let summary = String::from_utf8_lossy(&output.stdout);
        let peak = summary
            .lines()
            .find_map(|l| l.trim().strip_prefix("peak memory "))
            .and_then(|l| l.split(' ').next())
            .and_then(|v| v.parse::<f64>().ok());
        let size = std::fs::metadata(&csv).map_or(0.0, |m| m.len() as f64 / 1e6);
        let peak = peak.map_or("(not reported)".to_string(), |p| format!("{p:.1}"));
        let _ = writeln!(text, "| {} | {peak} | {size:.1} |", n * n);
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(text)
}
