#!/usr/bin/env python3
"""The peer `rod-ig bench` measures long cables against (issue 51, item 7): scipy's
`solve_bvp` on the heavy planar rod held level, tip (d, 0, 0), gravity -y, weight w.

State (x, y, theta, kappa), unknown parameters n(0) = (a4, a5); kappa' = n_x sin - n_y cos with
n(t) = n(0) - w t g (the model of docs/weight.md). The hanging rod is reached by continuation
in w from the weightless rod that sags (a sine-shaped first guess), each solve started from the
previous one, as a user of scipy would. Prints one JSON line: seconds, sag, a, nodes, status.

    python3 crates/rod-ig-bench/peers/level_cable_bvp.py [W] [D] [TOL]
"""
import json
import sys
import time

import numpy as np
from scipy.integrate import solve_bvp


def solve(w_final: float, d: float, tol: float) -> dict:
    g = np.array([0.0, -1.0])

    def run(w, t, y, p):
        def f(t, y, p):
            nx = p[0] - w * t * g[0]
            ny = p[1] - w * t * g[1]
            s, c = np.sin(y[2]), np.cos(y[2])
            return np.vstack((c, s, y[3], nx * s - ny * c))

        def bc(ya, yb, p):
            return np.array([ya[0], ya[1], ya[2], yb[0] - d, yb[1], yb[2]])

        return solve_bvp(f, bc, t, y, p=p, tol=tol, max_nodes=200_000)

    t = np.linspace(0.0, 1.0, 201)
    # The weightless rod held d apart that sags: theta = -A sin(2 pi t).
    amp = np.sqrt(max(1.0 - d, 1e-3) * 8.0) / np.pi
    theta = -amp * np.sin(2.0 * np.pi * t)
    kappa = -amp * 2.0 * np.pi * np.cos(2.0 * np.pi * t)
    x = np.cumsum(np.cos(theta)) / len(t)
    y = np.cumsum(np.sin(theta)) / len(t)
    guess = np.vstack((x, y, theta, kappa))
    p = np.array([-4.0 * np.pi**2, 0.0])
    start = time.perf_counter()
    weights = np.concatenate(([0.0], np.geomspace(1.0, w_final, 40)))
    status = 0
    for w in weights:
        sol = run(w, t, guess, p)
        status = sol.status
        if not sol.success:
            break
        t, guess, p = sol.x, sol.y, sol.p
    seconds = time.perf_counter() - start
    tt = np.linspace(0.0, 1.0, 20001)
    sag = float(-sol.sol(tt)[1].min())
    return {
        "seconds": seconds,
        "sag": sag,
        "a": [float(sol.y[3][0]), float(p[0]), float(p[1])],
        "nodes": int(len(sol.x)),
        "status": int(status),
        "success": bool(sol.success),
        "weight": w_final,
        "d": d,
        "tol": tol,
    }


if __name__ == "__main__":
    w = float(sys.argv[1]) if len(sys.argv) > 1 else 2000.0
    d = float(sys.argv[2]) if len(sys.argv) > 2 else 0.8
    tol = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-8
    print(json.dumps(solve(w, d, tol)))
