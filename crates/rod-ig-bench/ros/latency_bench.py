#!/usr/bin/env python3
"""Latency benchmark of rod_ig_node, measured from an rclpy client.

For each of N targets (a smooth sweep, so the node warm-starts as when tracking a moving
gripper) the client publishes a PoseStamped on /rod/target and waits for the /rod/path with
the same stamp; latency = time of the Path callback − time just before publish. Targets are
sent one at a time (ping-pong), so the figure is the per-target round trip, not throughput.

Baseline: the same client against `rod_ig_echo` (a tiny Rust binary of this package: same
middleware set-up, topics and QoS, answers each target at once with a Path of the same size,
no solving). The difference of the two is what rod_ig_node adds (solve + shape + the extra
RodSolution / Marker messages).

With --large: the large-message and concurrency figures instead. A Path of 10,000 and of
100,000 poses from target to an rclpy raw subscription (the delivery of the serialized
message; rclpy's own conversion to Python objects is timed apart, on the same bytes), the
same sizes as /rod/solve replies (whole call, conversion included), and a 5-pose call made
while a 100,000-pose call from another process is in flight. Medians and worst of --runs.

Usage (after scripts/setup/setup-env.sh and `source scripts/setup/env.sh`):
    python crates/rod-ig-bench/ros/latency_bench.py [--n 1200] [--rounds 3] [--samples 100] [--warmup 100]
    python crates/rod-ig-bench/ros/latency_bench.py --large [--runs 8]
"""
import argparse
import statistics
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests"))  # rodig_harness
import rodig_harness as h  # noqa: E402


def percentile(xs, q):
    xs = sorted(xs)
    k = (len(xs) - 1) * q
    lo, hi = int(k), min(int(k) + 1, len(xs) - 1)
    return xs[lo] + (xs[hi] - xs[lo]) * (k - lo)


def run(binary_name, args, n, warmup):
    domain = h.free_domain()
    node = h.NodeProcess(domain, args, binary_name=binary_name)
    client = h.Client(domain, name="rod_ig_latency_bench", keep=10, path_only=True)
    arrivals = {}
    got = threading.Event()
    waiting = [None]

    def on_path(msg):
        key = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        arrivals[key] = time.perf_counter()
        if key == waiting[0]:
            got.set()

    client.on_path = on_path
    try:
        if not client.wait_connected_topics():
            raise SystemExit(f"{binary_name}: no connection; log {node.log_path}")
        lat = []
        lost = 0
        for i in range(warmup + n):
            u = (i % 500) / 499
            u = 2 * u if u < 0.5 else 2 - 2 * u  # back and forth
            seq = h.next_seq()
            t = client.make_target(0.75 - 0.3 * u, 0.1 + 0.35 * u, 0.2 + 1.2 * u, seq)
            key = (t.header.stamp.sec, t.header.stamp.nanosec)
            got.clear()
            waiting[0] = key
            t0 = time.perf_counter()
            client.pub.publish(t)
            if not got.wait(2.0):
                lost += 1
                continue
            if i >= warmup:
                lat.append((arrivals.pop(key) - t0) * 1e3)
        return lat, lost
    finally:
        client.close()
        node.stop()


def first_target(starts, follow=100):
    """For `starts` fresh nodes: the round trip (publish -> RodSolution seen by rclpy) and the
    node's solve_time of the first target after "ready", and the medians of both over the
    `follow` targets after it (the same sweep, tracked)."""
    first_rt, first_solve, steady_rt, steady_solve = [], [], [], []
    for _ in range(starts):
        domain = h.free_domain()
        node = h.NodeProcess(domain, [])
        client = h.Client(domain, name="rod_ig_first_target_bench")
        try:
            if not client.wait_connected():
                raise SystemExit(f"no connection; log {node.log_path}")
            rts, solves = [], []
            for i in range(follow + 1):
                u = i / follow
                seq = h.next_seq()
                t0 = time.perf_counter()
                client.pub.publish(client.make_target(0.75 - 0.3 * u, 0.1 + 0.35 * u, 0.2 + 1.2 * u, seq))
                sol = client.solution_for(seq, timeout=5.0)
                if sol is None:
                    raise SystemExit(f"target {i} not answered; log {node.log_path}")
                rts.append(time.perf_counter() - t0)
                solves.append(sol.solve_time)
            first_rt.append(rts[0])
            first_solve.append(solves[0])
            steady_rt.append(statistics.median(rts[1:]))
            steady_solve.append(statistics.median(solves[1:]))
        finally:
            client.close()
            node.stop()
    return first_rt, first_solve, steady_rt, steady_solve


def raw_path_times(samples, runs):
    """Target publish -> raw (serialized) /rod/path of `samples` poses at an rclpy subscriber."""
    domain = h.free_domain()
    node = h.NodeProcess(domain, ["-p", f"path_samples:={samples}"])
    client, got, ready = h.raw_path_client(domain, name="rod_ig_large_bench")
    try:
        if not client.wait_connected_topics():
            raise SystemExit(f"no connection; log {node.log_path}")
        times, rss = [], []
        for i in range(runs + 1):
            ready.clear()
            t = client.make_target(0.6 - 0.01 * (i % 10), 0.3, 0.5, h.next_seq())
            t0 = time.perf_counter()
            client.pub.publish(t)
            if not ready.wait(30):
                raise SystemExit(f"no path of {samples} poses; log {node.log_path}")
            if i > 0:  # the first one after matching is not steady state
                times.append(got[-1][0] - t0)
            rss.append(h.rss_kib(node.pid))
            time.sleep(0.1)
        return times, got[-1][1], max(rss)
    finally:
        client.close()
        node.stop()


def solve_call_times(samples, runs):
    """Whole /rod/solve calls with `samples` path poses, rclpy's conversion included."""
    node, client = h.start_node_and_client(name="rod_ig_large_bench")
    try:
        times = []
        for i in range(runs + 1):
            t = client.make_target(0.6 - 0.01 * (i % 10), 0.3, 0.5, h.next_seq())
            t0 = time.perf_counter()
            r = client.solve(t, path_samples=samples, timeout=60)
            if r is None or len(r.path.poses) != samples:
                raise SystemExit(f"no reply of {samples} poses; log {node.log_path}")
            if i > 0:
                times.append(time.perf_counter() - t0)
        return times
    finally:
        h.stop_node_and_client(node, client)


def small_call_during_large(runs, delay):
    """A 5-pose /rod/solve call made `delay` s after a 100,000-pose one (from another process)."""
    domain = h.free_domain()
    node = h.NodeProcess(domain, [])
    client = h.Client(domain, name="rod_ig_small_caller")
    times = []
    try:
        if not client.wait_connected():
            raise SystemExit(f"no connection; log {node.log_path}")
        client.solve(client.make_target(0.6, 0.3, 0.5, h.next_seq()), path_samples=8)
        for _ in range(runs):
            big = h.LargeCaller(domain, 100_000)
            if not big.start():
                raise SystemExit("the large caller did not connect")
            big.call()
            time.sleep(delay)
            t0 = time.perf_counter()
            r = client.solve(client.make_target(0.5, 0.3, 0.5, h.next_seq()), path_samples=5)
            times.append(time.perf_counter() - t0)
            if r is None:
                raise SystemExit(f"small call unanswered; log {node.log_path}")
            big.result()
        return times
    finally:
        h.stop_node_and_client(node, client)


def large(runs):
    from nav_msgs.msg import Path as PathMsg
    from rclpy.serialization import deserialize_message
    ms = lambda xs: f"median {statistics.median(xs) * 1e3:7.1f} ms, worst {max(xs) * 1e3:7.1f} ms"  # noqa: E731
    print(f"large messages over loopback to rclpy (Fast DDS), {runs} runs each:")
    for samples, goal in ((10_000, 0.05), (100_000, 0.5)):
        times, raw, rss = raw_path_times(samples, runs)
        t0 = time.perf_counter()
        deserialize_message(raw, PathMsg)
        convert = time.perf_counter() - t0
        worst = max(times)
        print(f"  /rod/path {samples:>7} poses ({len(raw) / 1e6:.1f} MB) target->raw delivery: {ms(times)} "
              f"(goal <= {goal * 1e3:.0f} ms: {'met' if worst <= goal else 'NOT met'}); node RSS max "
              f"{rss / 1024:.0f} MB; rclpy's conversion of it to Python objects alone {convert * 1e3:.0f} ms")
    for samples in (10_000, 100_000):
        print(f"  /rod/solve {samples:>7} poses, whole call (conversion included): "
              f"{ms(solve_call_times(samples, max(2, runs // 2)))}")
    for delay in (0.2, 0.05):
        times = small_call_during_large(max(2, runs // 2), delay)
        print(f"  5-pose /rod/solve {delay * 1e3:.0f} ms after a 100,000-pose call from another "
              f"client: {ms(times)} (goal <= 50 ms: {'met' if max(times) <= 0.05 else 'NOT met'})")


def summary(name, lat, lost):
    return (f"{name:<28} n={len(lat):5d} lost={lost:3d}  p50={percentile(lat, 0.5):7.3f} ms  "
            f"p90={percentile(lat, 0.9):7.3f} ms  p99={percentile(lat, 0.99):7.3f} ms  "
            f"mean={statistics.fmean(lat):7.3f} ms")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=1200, help="measured targets per binary, in total (default 1200)")
    ap.add_argument("--warmup", type=int, default=100, help="unmeasured targets first (default 100)")
    ap.add_argument("--samples", type=int, default=100, help="path_samples (default 100)")
    ap.add_argument("--starts", type=int, default=3,
                    help="fresh node starts for the first-target figure (default 3)")
    ap.add_argument("--rounds", type=int, default=3,
                    help="alternate echo and node runs this many times, pooling the samples, so "
                         "drifting machine load affects both alike (default 3)")
    ap.add_argument("--large", action="store_true", help="the large-message figures instead")
    ap.add_argument("--runs", type=int, default=8, help="runs per large-message figure (default 8)")
    a = ap.parse_args()
    if a.large:
        large(a.runs)
        return

    first_rt, first_solve, steady_rt, steady_solve = first_target(a.starts)
    us = lambda xs: ", ".join(f"{x * 1e6:.0f}" for x in xs)  # noqa: E731
    ratio = max(f / s for f, s in zip(first_rt, steady_rt))
    print(f"first target after start, {a.starts} fresh nodes: round trip {us(first_rt)} us "
          f"vs median of the next 100 {us(steady_rt)} us, worst ratio {ratio:.2f} "
          f"(goal <= 3: {'met' if ratio <= 3 else 'NOT met'}); node solve_time {us(first_solve)} us "
          f"(a cold start: every stable solution near the target, the best-conditioned kept) vs "
          f"{us(steady_solve)} us tracked")

    echo, node, echo_lost, node_lost = [], [], 0, 0
    per_round = max(1, a.n // a.rounds)
    for _ in range(a.rounds):
        lat, lost = run("rod_ig_echo", [str(a.samples)], per_round, a.warmup)
        echo += lat
        echo_lost += lost
        lat, lost = run("rod_ig_node", ["-p", f"path_samples:={a.samples}"], per_round, a.warmup)
        node += lat
        node_lost += lost
    print(f"target -> /rod/path round trip seen by rclpy, {a.samples} path poses, "
          f"{a.rounds} alternating rounds of {per_round} targets each:")
    print(summary("rod_ig_echo (Rust, no solve)", echo, echo_lost))
    print(summary("rod_ig_node", node, node_lost))
    d50 = percentile(node, 0.5) - percentile(echo, 0.5)
    d99 = percentile(node, 0.99) - percentile(echo, 0.99)
    print(f"node adds: p50 {d50 * 1e3:+.0f} us, p99 {d99 * 1e3:+.0f} us "
          f"(goal: <= +300 us at p50: {'met' if d50 <= 0.3 else 'NOT met'})")


if __name__ == "__main__":
    main()
