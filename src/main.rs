//! `cargo run --release`: simulates the built-in reference models with their default
//! settings and prints a short summary of each run.

use camchain::models;
use camchain::runtime::{Dynamics, Simulate, Trajectory};
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let mut failed = false;
    for (name, model) in models::ALL {
        match run(*model) {
            Ok((trajectory, seconds)) => print_summary(name, *model, &trajectory, seconds),
            Err(message) => {
                eprintln!("{name}: {message}");
                failed = true;
            }
        }
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

fn run(model: &(dyn Dynamics + Sync)) -> Result<(Trajectory, f64), String> {
    let settings = model.info().defaults.clone();
    let start = Instant::now();
    let state = model.assemble(0.0).map_err(|e| e.to_string())?;
    let trajectory = model
        .simulate(state, &settings)
        .map_err(|f| f.error.to_string())?;
    Ok((trajectory, start.elapsed().as_secs_f64()))
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

fn print_summary(name: &str, model: &(dyn Dynamics + Sync), t: &Trajectory, seconds: f64) {
    let info = model.info();
    let s = &t.samples;
    let t_end = s.last().map_or(0.0, |x| x.t);
    println!(
        "{name}: {} s simulated in {:.1} ms ({} steps, {} rejected, {} right-hand sides, {} re-partitions)",
        t_end,
        seconds * 1e3,
        t.stats.steps,
        t.stats.rejected,
        t.stats.rhs_evaluations,
        t.stats.repartitions
    );
    for (i, c) in info.coordinates.iter().enumerate() {
        let (lo, hi) = range(s.iter().map(|x| x.q[i]));
        let max_abs = lo.abs().max(hi.abs());
        println!(
            "  {:<10} range [{lo:+.5}, {hi:+.5}]  max |·| {max_abs:.5}",
            c.name
        );
    }
    for (k, c) in info.contacts.iter().enumerate() {
        let (xlo, xhi) = range(s.iter().map(|x| x.contacts[k].position[0]));
        let (nlo, nhi) = range(s.iter().map(|x| x.normal_force[k]));
        let max_h = s.iter().map(|x| x.h[k].abs()).fold(0.0, f64::max);
        println!("  {c}_x       range [{xlo:+.5}, {xhi:+.5}] m");
        println!("  {c} normal force [{nlo:+.4}, {nhi:+.4}] N, max |h| {max_h:.2e} m");
        if nlo < 0.0 && nhi > 0.0 {
            let first = s
                .iter()
                .zip(s.iter().skip(1))
                .find(|(a, b)| a.normal_force[k].signum() != b.normal_force[k].signum());
            if let Some((_, b)) = first {
                println!(
                    "  warning: the normal force of {c} changes sign near t = {:.3} s (a one-sided follower would lift off)",
                    b.t
                );
            }
        }
    }
}
