"""rod-ig as a cosseratbench solver (issue 52, item 3): the entry point ``rod-ig`` of the
group ``cosseratbench.solvers``.

rod-ig computes static equilibria of an inextensible, unshearable Kirchhoff rod in a plane:
a scenario it covers (one rod, ``quasi_static``, no obstacle or driven end, gravity and end
loads in one plane with the rod's held ends) is answered by the least-energy stable
equilibrium, in SI units. Any other scenario raises ``NotImplementedError`` saying why, which
the suite reports as unsupported. Frame 0 is the scenario's initial shape and every later
frame the equilibrium (a static solver has no transient).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

import rod_ig

FloatArray = npt.NDArray[np.float64]

# Deadline of one static solve (ms): generous, since the suite runs one scenario at a time.
DEADLINE_MS = 10_000.0
# Largest dimensionless weight rod-ig accepts.
MAX_WEIGHT = 1e4


@dataclass(frozen=True)
class _Planar:
    """A scenario posed in rod-ig's units: base frame (origin, x, y), conditions, loads."""

    origin: FloatArray
    x: FloatArray
    y: FloatArray
    length: float
    base: str
    tip: str
    weight: float
    gravity: tuple[float, float]
    tip_load: tuple[float, float] | None
    target: tuple[float, ...] | None
    flipped: bool


def _unit(v: FloatArray) -> FloatArray:
    return v / float(np.linalg.norm(v))


def _refuse(why: str) -> NotImplementedError:
    return NotImplementedError(f"rod-ig: {why}")


def _check_supported(scenario: Any) -> Any:
    """The scenario's one rod, or ``NotImplementedError`` saying what rod-ig does not model."""
    if len(scenario.rods) != 1:
        raise _refuse("one rod only (no rod-rod contact)")
    if scenario.obstacles:
        raise _refuse("no obstacles (no contact model)")
    if not getattr(scenario, "quasi_static", False):
        raise _refuse("static equilibria only (no dynamics): the scenario is not quasi-static")
    rod = scenario.rods[0]
    if rod.start_motion is not None or rod.end_motion is not None:
        raise _refuse("no driven ends (static grippers)")
    return rod


def _oriented(rod: Any) -> tuple[FloatArray, str, str, list[Any], bool]:
    """The centerline from the held end (a free start is the same rod seen from its end)."""
    from cosseratbench.scenario import End, EndCondition  # the suite is an optional dependency

    names = {EndCondition.CLAMPED: "clamped", EndCondition.PINNED: "pinned", EndCondition.FREE: "free"}
    start, end = names[rod.start], names[rod.end]
    points = np.asarray(rod.centerline, dtype=float)
    loads = list(rod.loads)
    flipped = start == "free"
    if flipped:
        points, start, end = points[::-1].copy(), end, start
        loads = [
            type(p)(force=p.force, at=End.START if p.at is End.END else End.END) for p in loads
        ]
    if start == "free":
        raise _refuse("both ends free: nothing holds the rod")
    if start == "pinned" and end == "free":
        raise _refuse("pinned at one end and free at the other: a free pendulum")
    if any(p.at is End.START for p in loads):
        raise _refuse("a load on a held end is taken by its support")
    if loads and end != "free":
        raise _refuse("end loads on a free end only")
    return points, start, end, loads, flipped


def _pose(scenario: Any) -> _Planar:
    """``scenario`` in rod-ig's units, or ``NotImplementedError`` saying what it lacks."""
    rod = _check_supported(scenario)
    points, base, tip, loads, flipped = _oriented(rod)
    length = rod.length
    ei = rod.material.youngs_modulus * rod.second_moment_of_area
    g = np.asarray(scenario.gravity, dtype=float)
    load = np.sum([np.asarray(p.force, float) for p in loads], axis=0) if loads else np.zeros(3)
    origin = points[0]
    chord = points[-1] - origin
    x = _unit(points[1] - origin) if base == "clamped" else _unit(chord)
    # The plane: the base tangent and whatever bends the rod (gravity, the load, the chord).
    candidates = [g, load, chord, points[-1] - points[-2]]
    across = [c - np.dot(c, x) * x for c in candidates]
    best = max(across, key=lambda v: float(np.linalg.norm(v)))
    if float(np.linalg.norm(best)) < 1e-12 * max(1.0, float(np.linalg.norm(g))):
        y = _unit(np.cross(np.asarray(rod.normal, float), x))
    else:
        y = _unit(best)
    normal = np.cross(x, y)
    scale = max(float(np.linalg.norm(c)) for c in candidates) or 1.0
    if any(abs(float(np.dot(c, normal))) > 1e-9 * scale for c in candidates):
        raise _refuse("gravity, loads and held ends out of one plane (rod-ig's ends are planar)")

    def local(v: FloatArray) -> tuple[float, float]:
        return float(np.dot(v, x)), float(np.dot(v, y))

    weight_per_length = rod.material.density * rod.area * float(np.linalg.norm(g))
    weight = weight_per_length * length**3 / ei
    if weight > MAX_WEIGHT:
        raise _refuse(f"weight w = rho*A*g*L^3/EI = {weight:.4g} beyond rod-ig's {MAX_WEIGHT:g}")
    direction = local(g) if weight > 0 else (0.0, -1.0)
    target: tuple[float, ...] | None = None
    if tip != "free":
        tx, ty = local(chord / length)
        if tip == "clamped":
            tangent = local(points[-1] - points[-2])
            target = (tx, ty, float(np.arctan2(tangent[1], tangent[0])))
        else:
            target = (tx, ty)
    tip_load = None
    if np.any(load):
        fx, fy = local(load * length**2 / ei)
        tip_load = (fx, fy)
    return _Planar(origin, x, y, length, base, tip, weight, direction, tip_load, target, flipped)


def _equilibrium(p: _Planar, nodes: int) -> FloatArray:
    """The least-energy stable equilibrium's poses (nodes, 3) in rod-ig's units."""
    if p.base == "clamped" and p.tip == "clamped":
        assert p.target is not None
        r = rod_ig.solve(
            [p.target],
            weight=[p.weight],
            gravity=[p.gravity],
            objective="least_energy",
            deadline_ms=DEADLINE_MS,
        )
        if not bool(np.asarray(r.success).all()):
            raise RuntimeError(f"rod-ig found no stable equilibrium: {np.asarray(r.reason).ravel()[0]}")
        a = np.asarray(r.a).reshape(3)
        return np.asarray(rod_ig.shape(a, samples=nodes, weight=p.weight, gravity=p.gravity))
    r = rod_ig.solve(
        None if p.target is None else [p.target],
        base_condition=p.base,  # type: ignore[arg-type]
        tip_condition=p.tip,  # type: ignore[arg-type]
        weight=[p.weight],
        gravity=[p.gravity],
        tip_load=p.tip_load,
        samples=nodes,
        deadline_ms=DEADLINE_MS,
    )
    if not bool(np.asarray(r.success).all()) or r.shape is None:
        raise RuntimeError(f"rod-ig found no stable equilibrium: {np.asarray(r.reason).ravel()[0]}")
    return np.asarray(r.shape).reshape(nodes, 3)


class RodIg:
    """The cosseratbench adapter (module docs). ``time_step_scale`` is accepted and has no
    effect: a static solve has no time step."""

    name = "rod-ig"
    capabilities: frozenset[Any] = frozenset()
    backend_version = "rod-ig (static Kirchhoff elastica, multiple shooting)"

    def __init__(self, time_step_scale: float = 1.0) -> None:
        self.time_step_scale = time_step_scale

    def settings(self, scenario: Any, *, n_elements: int, n_frames: int) -> dict[str, Any]:
        """The numerical choices of a run: none that depend on the resolution."""
        return {
            "model": "inextensible, unshearable planar Kirchhoff rod; static equilibrium",
            "answer": "least-energy stable equilibrium",
            "deadline_ms": DEADLINE_MS,
        }

    def run(self, scenario: Any, *, n_elements: int, n_frames: int) -> Any:
        """The equilibrium of ``scenario`` at ``n_elements + 1`` nodes (module docs)."""
        from cosseratbench.scenario import parallel_transport
        from cosseratbench.trajectory import Trajectory

        p = _pose(scenario)
        rod = scenario.rods[0]
        nodes = n_elements + 1
        shape = _equilibrium(p, nodes)
        positions = (
            p.origin[None, :]
            + p.length * (shape[:, :1] * p.x[None, :] + shape[:, 1:2] * p.y[None, :])
        )
        if p.flipped:
            positions = positions[::-1].copy()
        initial = rod.nodes(n_elements)
        initial_directors = rod.directors(n_elements)
        # The material direction carried from the first element's initial one, untwisted.
        first = initial[1] - initial[0]
        extended = np.vstack([positions[0] - first, positions])
        directors = parallel_transport(extended, initial_directors[0])[1:]
        times = np.linspace(0.0, scenario.duration, n_frames)
        frames = np.repeat(positions[None], n_frames, axis=0)
        frame_directors = np.repeat(directors[None], n_frames, axis=0)
        frames[0], frame_directors[0] = initial, initial_directors
        return Trajectory(times, (frames,), (frame_directors,))
