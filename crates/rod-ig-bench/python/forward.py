"""rod_ig's speed goals, measured in one run (issue 22): a one-thread batch `forward` per rod
against the Rust call it wraps (goal <= 1.2x + 50 ns), and all cores against one thread (goal
>= 0.8 x cores). Medians of several rounds on the paper's box; run `python crates/rod-ig-bench/python/forward.py`."""

from __future__ import annotations

import os
import statistics
import time

import numpy as np

import rod_ig
from rod_ig import _rod_ig


def median_seconds(f: "object", rounds: int) -> float:
    times = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        f()  # type: ignore[operator]
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    n = int(os.environ.get("ROD_IG_BENCH_RODS", "200000"))
    rounds = int(os.environ.get("ROD_IG_BENCH_ROUNDS", "7"))
    a = np.random.default_rng(0).uniform([-10, -100, -100], [10, 100, 100], size=(n, 3))
    flat = np.ascontiguousarray(a).reshape(-1)
    rod_ig.forward(a[:1000])  # page in
    rust = statistics.median(_rod_ig._time_evaluate(flat) for _ in range(rounds)) / n
    one = median_seconds(lambda: rod_ig.forward(a, threads=1), rounds) / n
    cores = os.cpu_count() or 1
    every = median_seconds(lambda: rod_ig.forward(a), rounds) / n
    print(f"rods per round {n}, rounds {rounds}, cores {cores}")
    print(f"Rust planar::evaluate loop      {rust * 1e9:8.0f} ns/rod")
    print(f"rod_ig.forward, 1 thread        {one * 1e9:8.0f} ns/rod   "
          f"ratio {(one - 50e-9) / rust:.3f} after 50 ns (goal <= 1.2)")
    print(f"rod_ig.forward, {cores} threads       {every * 1e9:8.0f} ns/rod   "
          f"speed-up {one / every:.2f} = {one / every / cores:.2f} x cores (goal >= 0.8)")


if __name__ == "__main__":
    main()
