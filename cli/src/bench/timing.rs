//! Median timings, side by side.

use std::time::Instant;

/// Medians (ns per call) of two routines measured in interleaved batches: batch k of `a`,
/// then batch k of `b`, so that slow phases of a shared machine affect both alike.
/// `calls` calls per batch, `batches` batches each.
pub fn side_by_side(
    mut a: impl FnMut(),
    mut b: impl FnMut(),
    calls: usize,
    batches: usize,
) -> (f64, f64) {
    let (mut ta, mut tb) = (Vec::with_capacity(batches), Vec::with_capacity(batches));
    for _ in 0..batches {
        ta.push(per_call(&mut a, calls));
        tb.push(per_call(&mut b, calls));
    }
    (median(&mut ta), median(&mut tb))
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
    use super::median;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&mut []).is_nan());
    }
}
