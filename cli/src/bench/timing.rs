//! Median timings, side by side.

use std::time::Instant;

/// Longest batch (s): a routine so slow that `calls` calls would take longer gets fewer
/// calls per batch (the numeric reference's roller contact scans its profile at every call,
/// some 0.7 ms).
pub const MAX_BATCH_SECONDS: f64 = 0.05;

/// Calls per batch are a multiple of this (the states the routines cycle through).
pub const CALL_MULTIPLE: usize = 8;

/// Medians (ns per call) of two routines measured in interleaved batches: batch k of `a`,
/// then batch k of `b`, so that slow phases of a shared machine affect both alike.
/// `calls` calls per batch (fewer for a routine whose batch would take longer than
/// [`MAX_BATCH_SECONDS`], see [`batch_calls`]), `batches` batches each.
pub fn side_by_side(
    mut a: impl FnMut(),
    mut b: impl FnMut(),
    calls: usize,
    batches: usize,
) -> (f64, f64) {
    let calls_a = batch_calls(per_call(&mut a, CALL_MULTIPLE), calls);
    let calls_b = batch_calls(per_call(&mut b, CALL_MULTIPLE), calls);
    let (mut ta, mut tb) = (Vec::with_capacity(batches), Vec::with_capacity(batches));
    for _ in 0..batches {
        ta.push(per_call(&mut a, calls_a));
        tb.push(per_call(&mut b, calls_b));
    }
    (median(&mut ta), median(&mut tb))
}

/// Calls per batch of a routine that takes `ns` per call: `calls`, or as many whole
/// multiples of [`CALL_MULTIPLE`] as fit in [`MAX_BATCH_SECONDS`] (at least one multiple).
pub fn batch_calls(ns: f64, calls: usize) -> usize {
    let fit = (MAX_BATCH_SECONDS * 1e9 / ns.max(1e-3)) as usize;
    let fit = (fit / CALL_MULTIPLE).max(1) * CALL_MULTIPLE;
    calls.min(fit)
}

/// Nanoseconds per call of one batch.
fn per_call(f: &mut impl FnMut(), calls: usize) -> f64 {
    let start = Instant::now();
    for _ in 0..calls {
        f();
    }
    start.elapsed().as_nanos() as f64 / calls as f64
}

/// Median wall time (s) of `f` over `repeats` runs (each run's result is discarded).
pub fn median_seconds<T>(mut f: impl FnMut() -> T, repeats: usize) -> f64 {
    let mut times: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(f());
            start.elapsed().as_secs_f64()
        })
        .collect();
    median(&mut times)
}

/// Median of the values (sorted in place).
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::{CALL_MULTIPLE, batch_calls, median};

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }

    #[test]
    fn slow_routines_get_fewer_calls_per_batch() {
        // 100 ns: 20 000 calls take 2 ms, all of them.
        assert_eq!(batch_calls(100.0, 20_000), 20_000);
        // 0.7 ms: 50 ms hold 71 calls, 64 of them a multiple of 8.
        assert_eq!(batch_calls(7e5, 20_000), 64);
        // Slower than a whole batch: one multiple still.
        assert_eq!(batch_calls(1e9, 20_000), CALL_MULTIPLE);
    }
}
