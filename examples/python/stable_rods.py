"""Draws, with matplotlib, every stable rod found for one gripper pose and a snap-through
sequence (the buckled rod whose tip gripper turns). Usage:

    python examples/python/stable_rods.py [output.png]
"""

from __future__ import annotations

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import rod_ig


def main(path: str) -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 5))
    # Every distinct stable rod whose tip gripper is at (0.3, 0.4), tangent 2 rad.
    target = [0.3, 0.4, 2.0]
    s = rod_ig.solve(target, all=True)
    rods = s.solutions[()]
    energy = rod_ig.forward(rods).energy
    for a, e in zip(rods, energy):
        p = rod_ig.shape(a, samples=200)
        left.plot(p[:, 0], p[:, 1], label=f"a = ({a[0]:.1f}, {a[1]:.1f}, {a[2]:.1f}), E = {e:.1f}")
    left.set_title(f"{len(rods)} stable rods reaching x=0.3, y=0.4, θ=2")
    # Snap-through: the buckled rod (grippers 0.8 apart) with its tip gripper turning.
    b = rod_ig.solve([0.8, 0.0, 0.0], all=True).solutions[()]
    mid = rod_ig.shape(b, samples=3)[:, 1, 1]
    up = b[np.argmin(np.where(mid > 0, rod_ig.forward(b).energy, np.inf))]
    tracker = rod_ig.Tracker(a0=up)
    colours = plt.cm.viridis(np.linspace(0, 1, 30))
    for k, th in enumerate(np.arange(1, 31) * 0.05):
        m = tracker.move([0.8, 0.0, th])
        p = rod_ig.shape(m.a, samples=200)
        style = dict(color="red", lw=2.5) if m.event == "snap" else dict(color=colours[k], lw=1)
        right.plot(p[:, 0], p[:, 1], **style)
    right.set_title("tip gripper turning 0 → 1.5 rad: the bump snaps (red)")
    for ax in (left, right):
        ax.set_aspect("equal")
        ax.set_xlim(-0.6, 1.1)
        ax.set_ylim(-0.7, 0.9)
        ax.plot([0], [0], "ks")
        ax.grid(alpha=0.3)
    left.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=90)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "stable_rods.png")
