//! The reduced right-hand side of N-four-bars against N (BENCHMARKS.md, "A02: chained loops
//! in O(N)"): `derivative` at 10 states 0.5 s apart along each model's run, each state's
//! evaluation cache cleared before the call, median of 11 batches, µs per call.

use camchain::runtime::{Simulate, State};
use std::time::Instant;

mod nbar10 {
    camchain::include_model!("nbar10");
}
mod nbar20 {
    camchain::include_model!("nbar20");
}
mod nbar40 {
    camchain::include_model!("nbar40");
}
mod nbar80 {
    camchain::include_model!("nbar80");
}

fn median_rhs(model: &dyn Simulate, states: &mut [State]) -> Result<f64, String> {
    let mut dy = vec![0.0; states[0].integrated_len()];
    for s in states.iter_mut() {
        model.derivative(s, &mut dy).map_err(|e| e.to_string())?;
    }
    let n = model.info().n();
    let calls = (200_000 / (n * n)).max(20);
    let mut batches = Vec::new();
    for _ in 0..11 {
        let start = Instant::now();
        for k in 0..calls {
            let s = &mut states[k % states.len()];
            s.clear_evaluation_cache();
            model.derivative(s, &mut dy).map_err(|e| e.to_string())?;
            std::hint::black_box(&dy);
        }
        batches.push(start.elapsed().as_secs_f64() / calls as f64);
    }
    batches.sort_by(f64::total_cmp);
    Ok(batches[batches.len() / 2] * 1e6)
}

fn main() -> Result<(), String> {
    let models: [(usize, &dyn Simulate); 4] = [
        (10, &nbar10::Model),
        (20, &nbar20::Model),
        (40, &nbar40::Model),
        (80, &nbar80::Model),
    ];
    println!("| N | n | loop rows | rhs [µs] |\n|---:|---:|---:|---:|");
    for (n_bars, model) in models {
        let mut state = model.assemble(0.0).map_err(|e| e.to_string())?;
        let mut states = Vec::new();
        for _ in 0..10 {
            model.step(&mut state, 0.5).map_err(|e| e.to_string())?;
            states.push(state.clone());
        }
        let rhs = median_rhs(model, &mut states)?;
        let info = model.info();
        println!(
            "| {n_bars} | {} | {} | {rhs:.2} |",
            info.n(),
            info.n_constraints()
        );
    }
    Ok(())
}
