//! Wall-clock measurement for `rod-ig bench`: medians over rounds, so that a noisy neighbour on
//! a shared machine moves the figure less than a mean would.

use std::hint::black_box;
use std::time::Instant;

/// Per-call timing of one benchmarked function.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    /// Median over rounds of the mean time per call within a round (ns).
    pub median_ns: f64,
    /// Mean time per call over all rounds (ns).
    pub mean_ns: f64,
}

/// Times `f` over every input, `rounds` times; each round is one pass over `inputs`.
pub fn measure<T, R>(inputs: &[T], rounds: usize, mut f: impl FnMut(&T) -> R) -> Timing {
    // One untimed pass warms caches and any lazily built tables.
    for x in inputs {
        black_box(f(black_box(x)));
    }
    let mut per_call = Vec::with_capacity(rounds);
    for _ in 0..rounds.max(1) {
        let start = Instant::now();
        for x in inputs {
            black_box(f(black_box(x)));
        }
        per_call.push(start.elapsed().as_nanos() as f64 / inputs.len().max(1) as f64);
    }
    let mean_ns = per_call.iter().sum::<f64>() / per_call.len() as f64;
    Timing {
        median_ns: median(&mut per_call),
        mean_ns,
    }
}

/// Median of a slice (sorts it); NaN-free input assumed, 0 for an empty slice.
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(|a, b| a.total_cmp(b));
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_odd_even_empty() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&mut []), 0.0);
    }

    #[test]
    fn measure_counts_every_call() {
        let mut calls = 0;
        let t = measure(&[1, 2, 3], 4, |x| {
            calls += 1;
            *x
        });
        assert_eq!(calls, 3 * 5); // warm-up pass + 4 rounds
        assert!(t.median_ns >= 0.0 && t.mean_ns >= 0.0);
    }
}
