//! IFToMM A02 (`n_four_bar`, N = 40, 20 s, DOP853) at rtol = atol = 10^e for the exponents
//! given (default -8 -9 -10 -11): the largest error of B0 against the exact reduction
//! (`cli/src/bench/a02.rs`), the minimum wall time of 3 runs, steps, rejections and
//! right-hand sides. `cargo run --release -p camchain-cli --example a02_ladder -- -8 -10`.

#[path = "../src/bench/a02.rs"]
mod a02;

use camchain_runtime::Simulate;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let mut exponents = Vec::new();
    for a in std::env::args().skip(1) {
        match a.parse::<i32>() {
            Ok(e) if (-15..=0).contains(&e) => exponents.push(e),
            _ => {
                eprintln!("error: `{a}` is not a tolerance exponent (an integer from -15 to 0)");
                eprintln!("usage: a02_ladder [EXPONENT ...]   (rtol = atol = 10^EXPONENT)");
                return ExitCode::from(2);
            }
        }
    }
    let exponents = if exponents.is_empty() {
        vec![-8, -9, -10, -11]
    } else {
        exponents
    };
    let Some(model) = camchain_models::by_name("n_four_bar") else {
        eprintln!("error: n_four_bar is not among the built-in models");
        return ExitCode::FAILURE;
    };
    println!("| rtol = atol | B0 error | at t | wall time | steps | rejected | right-hand sides |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for e in exponents {
        let tolerance = 10f64.powi(e);
        let mut settings = model.info().defaults.clone();
        (settings.rtol, settings.atol) = (tolerance, tolerance);
        let mut best = f64::INFINITY;
        let mut last = None;
        for _ in 0..3 {
            let start = Instant::now();
            let state = match model.assemble(0.0) {
                Ok(state) => state,
                Err(e) => {
                    eprintln!("error: n_four_bar does not assemble: {e}");
                    return ExitCode::FAILURE;
                }
            };
            let run = model.simulate(state, &settings);
            best = best.min(start.elapsed().as_secs_f64());
            last = Some(run);
        }
        let Some(last) = last else {
            continue;
        };
        match last {
            Ok(run) => {
                let (error, at) = a02::largest_error(&run);
                println!(
                    "| {tolerance:.0e} | {error:.2e} m | {at:.2} s | {best:.3} s | {} | {} | {} |",
                    run.stats.steps, run.stats.rejected, run.stats.rhs_evaluations
                );
            }
            Err(f) => {
                let (error, at) = a02::largest_error(&f.partial);
                println!(
                    "| {tolerance:.0e} | failed at t = {:.3} s ({}); B0 error so far {error:.2e} m at {at:.2} s | {best:.3} s | {} | {} | {} |",
                    f.partial.samples.last().map_or(0.0, |s| s.t),
                    f.error,
                    f.partial.stats.steps,
                    f.partial.stats.rejected,
                    f.partial.stats.rhs_evaluations
                );
            }
        }
    }
    ExitCode::SUCCESS
}
