"""Draws, with matplotlib, a USB cable (w = 50) held by two grippers beside the weightless rod
through the same grippers, and the same cable as it gets heavier. Usage:

    python examples/python/heavy_cable.py [output.png]
"""

from __future__ import annotations

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import rod_ig


def main(path: str) -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.8))
    # Tip gripper 0.7 rod lengths away, 0.1 below, tilted down 0.3 rad; gravity along -y.
    target = [0.7, -0.1, -0.3]
    for weight, style in [(0.0, dict(color="grey", ls="--")), (50.0, dict(color="C0", lw=2))]:
        s = rod_ig.solve(target, weight=weight, objective="least_energy")
        p = rod_ig.shape(s.a, samples=200, weight=weight)
        left.plot(p[:, 0], p[:, 1], label=f"w = {weight:g}: energy {float(s.energy):.1f}", **style)
    left.set_title("least-energy rods through the same grippers")
    # The cable held level 0.8 apart as it gets heavier (a Tracker follows the branch).
    colours = plt.cm.viridis(np.linspace(0, 1, 5))
    # (The search reaches w = 300 here; at w = 1000 it finds none: docs/weight.md.)
    for k, w in enumerate([1.0, 10.0, 30.0, 100.0, 300.0]):
        s = rod_ig.solve([0.8, 0.0, 0.0], weight=w, objective="least_energy", deadline_ms=5000)
        if not bool(s.success):
            continue
        p = rod_ig.shape(s.a, samples=200, weight=w)
        right.plot(p[:, 0], p[:, 1], color=colours[k], label=f"w = {w:g}")
    right.set_title("a cable held level, heavier and heavier")
    for ax in (left, right):
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_xlabel("x (rod lengths)")
    left.set_ylabel("y (rod lengths; gravity along -y)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "heavy_cable.png")
