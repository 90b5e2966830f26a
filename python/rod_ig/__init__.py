"""rod-ig: equilibria, stability and inverse geometry of an elastic rod held by two grippers.

The rod has unit length and unit bending stiffness; its base gripper is the identity frame
(REP 103: x forward along the base tangent, y left, angles in radians, counter-clockwise).
A planar equilibrium is parametrised by a = (a3, a4, a5), the base moment and force (paper
Roussel, Renaud, Taix 2015); a 3-D one by a in R^6. Scale lengths by your rod's length L,
forces by EI/L^2 and moments by EI/L.

Every batch function takes float64 arrays with any leading batch shape ``(...)``, runs on all
cores by default (``threads=1`` for one), releases the GIL while it works and can be
interrupted with Ctrl-C. A target that cannot be solved is data (``success`` False and a
``termination`` string), never an exception; bad input (wrong shape, dtype, NaN) raises
``ValueError`` / ``TypeError`` naming the argument.

>>> import rod_ig
>>> r = rod_ig.forward([[2.0, -10.0, 5.0]])
>>> bool(r.stable[0])
True
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Any, Literal, Sequence

import numpy as np
import numpy.typing as npt

from . import _rod_ig

__version__: str = _rod_ig.__version__

__all__ = [
    "__version__",
    "forward",
    "is_stable",
    "shape",
    "solve",
    "forward3d",
    "solve3d",
    "wrenches",
    "wrenches3d",
    "warm_up",
    "Tracker",
    "Planner",
    "Wrench",
    "ForwardResult",
    "Forward3dResult",
    "SolveResult",
    "MoveResult",
    "PlanResult",
]

FloatArray = npt.NDArray[np.float64]
Objective = Literal["first", "least_energy"]
"""The objective of a solve: the first stable rod found, or the least energetic one."""
Method = Literal["robust", "newton"]
EndName = Literal["clamped", "pinned", "free"]
"""The solver: the robust search, or the paper's alpha-Newton."""


def _integer(name: str, value: Any, lo: int, hi: int) -> int:
    """``value`` as an int in [lo, hi]; ``TypeError``/``ValueError`` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    if not lo <= int(value) <= hi:
        raise ValueError(f"{name} must be in [{lo}, {hi}], got {value}")
    return int(value)


def _threads(threads: int | None) -> int | None:
    return None if threads is None else _integer("threads", threads, 1, 1 << 20)
BoolArray = npt.NDArray[np.bool_]


def _batch(name: str, value: npt.ArrayLike, width: int) -> tuple[FloatArray, tuple[int, ...]]:
    """``value`` as a C-contiguous float64 array of shape (..., width), checked."""
    arr = np.asarray(value)
    if arr.dtype.kind not in "fiu":
        raise TypeError(f"{name} must hold real numbers (float64), got dtype {arr.dtype}")
    if arr.ndim == 0 or arr.shape[-1] != width:
        raise ValueError(f"{name} must have shape (..., {width}), got {arr.shape}")
    arr = np.ascontiguousarray(arr, dtype=np.float64)
    bad = ~np.isfinite(arr)
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{name} is not finite at index {index}: {arr[index]}")
    return arr, arr.shape[:-1]


def _shaped(values: Any, shape: tuple[int, ...]) -> Any:
    """``values`` in the batch's shape; a single target's 0-d array becomes a numpy scalar
    (as numpy's own functions return for scalar input)."""
    r = np.asarray(values).reshape(shape)
    return r[()] if shape == () else r


def _broadcast(*arrays: FloatArray) -> tuple[list[FloatArray], tuple[int, ...]]:
    """Broadcasts the leading (batch) dimensions of arrays of shape (..., w_i)."""
    try:
        shape = np.broadcast_shapes(*(a.shape[:-1] for a in arrays))
    except ValueError as e:
        raise ValueError(f"batch shapes do not broadcast: {e}") from None
    out = [
        np.ascontiguousarray(np.broadcast_to(a, shape + a.shape[-1:])).reshape(-1) for a in arrays
    ]
    return out, shape


def _weight_arrays(
    weight: npt.ArrayLike | None, gravity: npt.ArrayLike | None, dim: int = 2
) -> list[FloatArray]:
    """``weight`` as (..., 1) and ``gravity`` as (..., dim) arrays to broadcast with the batch;
    [] when neither is given (the weightless models, bit for bit). Gravity defaults to -y in
    the plane, -z in 3-D."""
    if weight is None and gravity is None:
        return []
    w = np.asarray(0.0 if weight is None else weight)
    if w.dtype.kind not in "fiu":
        raise TypeError(f"weight must hold real numbers, got dtype {w.dtype}")
    # (ascontiguousarray would make a 0-d weight 1-d: a batch dimension of its own.)
    w = np.asarray(w, dtype=np.float64)[..., None]
    if not np.isfinite(w).all() or (w < 0).any() or (w > 1e4).any():
        raise ValueError("weight must be finite and in [0, 1e4]")
    default = (0.0, -1.0) if dim == 2 else (0.0, 0.0, -1.0)
    g, _ = _batch("gravity", default if gravity is None else gravity, dim)
    if (np.linalg.norm(g, axis=-1) == 0).any():
        raise ValueError("gravity must be a non-zero vector")
    return [w, g]


def _weight_kwargs(flat: list[FloatArray], start: int) -> dict[str, FloatArray]:
    """The native keyword arguments from the broadcast arrays ``flat[start:]``."""
    if len(flat) <= start:
        return {}
    return {"weight": flat[start], "gravity": flat[start + 1]}


@dataclass(frozen=True)
class Wrench:
    """A wrench the rod exerts on one gripper, in that gripper's own frame, about its grasp
    point: what a wrist force-torque sensor between flange and gripper reads (the gripper's
    weight aside). Unit rod: force in EI/L^2, moment in EI/L. The base's is ``a`` itself; the
    tip's is minus the internal wrench at the tip (docs/math.md §11)."""

    force: FloatArray
    """(..., 2) planar or (..., 3) 3-D."""
    moment: FloatArray
    """(...) planar (counter-clockwise) or (..., 3) 3-D."""


def _wrench(rows: FloatArray, shape: tuple[int, ...], dim: int) -> Wrench:
    """A batch of wrenches from flattened rows (force, moment): dim 2 (planar) or 3."""
    r = rows.reshape(shape + (6 if dim == 3 else 3,))
    if dim == 3:
        return Wrench(force=r[..., :3], moment=r[..., 3:])
    return Wrench(force=r[..., :2], moment=r[..., 2])


@dataclass(frozen=True)
class ForwardResult:
    """Planar forward map of a batch of rods (shape ``(...)``)."""

    tip: FloatArray
    """(..., 3): tip pose (x, y, theta) in the base frame, theta unwrapped (the integral of the
    curvature), in rod lengths and radians."""
    jacobian: FloatArray
    """(..., 3, 3): J(1, a), rows x, y, theta; columns a3, a4, a5."""
    stable: BoolArray
    """(...): the rod is a stable equilibrium (docs/math.md §5 test)."""
    margin: FloatArray
    """(...): normalised stability margin g_min (about 1 for a gently bent rod, < 0 unstable)."""
    uncertain: BoolArray
    """(...): the margin is within its rounding-error bound (``stable`` is then False)."""
    energy: FloatArray
    """(...): energy (unit stiffness): elastic, plus gravitational with ``weight``."""
    elastic_energy: FloatArray | None = None
    """(...): the elastic part of ``energy`` (equal to it without weight)."""
    base_wrench: Wrench | None = None
    """What the rod exerts on the base gripper, in the base frame (:class:`Wrench`)."""
    tip_wrench: Wrench | None = None
    """What the rod exerts on the tip gripper, in the tip frame (:class:`Wrench`)."""
    condition: FloatArray | None = None
    """(...): ||J(1)||_inf * max(1, ||a||_inf): the tip of an f64 ``a`` is uncertain by about
    this times 1.1e-16. Above 1e9 (long cables, w > 200) ``uncertain`` is True unless ``a`` is
    a solver's answer, evaluated from its node states (docs/weight.md)."""
    base_angle: FloatArray | None = None
    """(...): with pinned or free ends, the rod's angle at the base (0 unless pinned)."""
    turns: FloatArray | None = None
    """(...): with pinned or free ends, full turns of the tangent along the rod."""


@dataclass(frozen=True)
class Forward3dResult:
    """3-D forward map of a batch of rods (shape ``(...)``)."""

    position: FloatArray
    """(..., 3): tip position in the base frame (rod lengths)."""
    quaternion: FloatArray
    """(..., 4): tip orientation (x, y, z, w)."""
    jacobian: FloatArray
    """(..., 6, 6): J(1, a) as body twists, rows omega1 omega2 omega3 v1 v2 v3."""
    stable: BoolArray
    margin: FloatArray
    energy: FloatArray
    base_wrench: Wrench | None = None
    """What the rod exerts on the base gripper, in the base frame (:class:`Wrench`)."""
    tip_wrench: Wrench | None = None
    """What the rod exerts on the tip gripper, in the tip frame (:class:`Wrench`)."""
    uncertain: BoolArray | None = None
    """(...): the stability verdict is undecided (margin within its error, or the tip of this
    f64 ``a`` not determined: ``condition`` > 1e9); ``stable`` is then False."""
    condition: FloatArray | None = None
    """(...): ||J(1)||_inf * max(1, ||a||_inf), as :class:`ForwardResult`'s."""
    base_quaternion: FloatArray | None = None
    """With a pinned or free end: (..., 4) the base's orientation (x, y, z, w); the identity
    unless the base is pinned (its x axis is where the rod leaves the hook). ``jacobian``'s
    first three columns are then the base's turn (body twist), and ``condition`` is NaN."""
    elastic_energy: FloatArray | None = None
    """With a pinned or free end: (...) the elastic part of ``energy``."""


@dataclass(frozen=True)
class SolveResult:
    """Inverse geometry of a batch of targets (shape ``(...)``)."""

    success: BoolArray
    a: FloatArray
    """(..., 3) or (..., 6): the stable rod found (NaN where it failed)."""
    termination: npt.NDArray[np.str_]
    """(...): "converged", "deadline", "no_stable_solution", "unreachable", ... (the CLI's)."""
    reason: npt.NDArray[np.str_]
    """(...): why a solve failed, in words ("" where it succeeded): scipy's ``message``."""
    iterations: npt.NDArray[np.uint32]
    margin: FloatArray
    energy: FloatArray
    position_error: FloatArray
    orientation_error: FloatArray
    starts: npt.NDArray[np.uint32]
    """(...): starts tried by the search (branches followed included), also where it failed."""
    complete: BoolArray
    """(...): the search ran to its end; False where the deadline cut a least-energy search
    or the ``all`` list (the rod returned is stable and on target, but one of less energy, or
    more rods, may exist)."""
    solutions: npt.NDArray[np.object_] | None = None
    """With ``all=True``: (...) object array, each entry an (k, 3) or (k, 6) array of every
    distinct stable solution found, least energy first."""
    turns: npt.NDArray[np.int64] | None = None
    """With ``weight`` (planar): full turns of the tangent along the rod found, 0 for a
    loop-free cable (-1 where the solve failed), as the CLI's ``turns``."""
    base_wrench: Wrench | None = None
    """What the rod found exerts on the base gripper (NaN where the solve failed)."""
    tip_wrench: Wrench | None = None
    """What the rod found exerts on the tip gripper, in the tip frame."""
    base_angle: FloatArray | None = None
    """With a pinned or free end (``base_condition``/``tip_condition``): (...) the rod's angle
    at the base, theta(0) (0 for a clamped base; NaN where the solve failed)."""
    tip: FloatArray | None = None
    """With a pinned or free end: (..., 3) the tip pose (x, y, theta) of the rod found (a free
    or pinned tip's angle is part of the answer)."""
    shape: FloatArray | None = None
    """With a pinned or free end and ``samples``: (..., samples, 3) the rod found, poses
    (x, y, theta) from base to tip (3-D: (..., samples, 7), position and quaternion x y z w;
    NaN where the solve failed)."""
    base_quaternion: FloatArray | None = None
    """3-D with a pinned or free end: (..., 4) the base's orientation (x, y, z, w): the
    identity for a clamped base, a pinned base's own (NaN where the solve failed)."""


def _solve_result(
    d: dict[str, Any],
    shape: tuple[int, ...],
    dim: int,
    all: bool,
    wrenches: tuple[Wrench, Wrench] | None = None,
    turns: npt.NDArray[np.int64] | None = None,
) -> SolveResult:
    solutions = None
    if all:
        solutions = np.empty(len(d["solutions"]), dtype=object)
        for i, s in enumerate(d["solutions"]):
            solutions[i] = s.reshape(-1, dim)
        solutions = _shaped(solutions, shape)
    return SolveResult(
        success=_shaped(d["success"], shape),
        a=d["a"].reshape(shape + (dim,)),
        termination=_shaped(np.array(d["termination"], dtype=str), shape),
        reason=_shaped(np.array(d["reason"], dtype=str), shape),
        iterations=_shaped(d["iterations"], shape),
        margin=_shaped(d["margin"], shape),
        energy=_shaped(d["energy"], shape),
        position_error=_shaped(d["position_error"], shape),
        orientation_error=_shaped(d["orientation_error"], shape),
        starts=_shaped(d["starts"], shape),
        complete=_shaped(d["complete"], shape),
        solutions=solutions,
        turns=None if turns is None else _shaped(turns, shape),
        base_wrench=wrenches[0] if wrenches else None,
        tip_wrench=wrenches[1] if wrenches else None,
    )


def forward(
    a: npt.ArrayLike,
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
    base_condition: EndName = "clamped",
    tip_condition: EndName = "clamped",
    base_angle: npt.ArrayLike = 0.0,
    tip_load: tuple[float, float] | None = None,
) -> ForwardResult:
    """Planar forward map of rods ``a`` of shape (..., 3) = (a3, a4, a5): tip pose, J(1, a),
    stability verdict and margin, energy (closed forms, paper section 2). A rod that cannot be
    evaluated (beyond the certified domain) gets NaN, ``stable`` False, ``uncertain`` True.

    ``weight`` (dimensionless w = rho g A L^3 / EI, in [0, 1e4]) and ``gravity`` (its direction in
    the base frame, (..., 2), default (0, -1)) broadcast against the batch: the rod with weight
    (docs/weight.md).

    With a pinned or free end (``base_condition`` "clamped" | "pinned", ``tip_condition``
    "clamped" | "pinned" | "free"; docs/ends.md) the rod leaves its base at ``base_angle`` (a
    pinned base's a3 must be 0; a free tip's (a4, a5) must be w g + ``tip_load``): the verdict
    and margin are the second variation's with the natural conditions, J's first column is
    d/d base_angle at a pinned base, and ``base_angle`` and ``turns`` are filled. A rod the
    conditions refuse raises ValueError naming the argument."""
    if base_condition != "clamped" or tip_condition != "clamped":
        return _forward_held(a, weight, gravity, base_condition, tip_condition, base_angle,
                             tip_load)
    arr, _ = _batch("a", a, 3)
    flat, shape = _broadcast(arr, *_weight_arrays(weight, gravity))
    d = _rod_ig.forward(flat[0], threads=_threads(threads), **_weight_kwargs(flat, 1))
    return _forward_result(d, shape)


def _forward_result(d: dict[str, Any], shape: tuple[int, ...]) -> ForwardResult:
    """A :class:`ForwardResult` from the native arrays ``d`` (``base_angle`` and ``turns`` when
    the rod was held by pinned or free ends)."""
    held = "base_angle" in d
    return ForwardResult(
        tip=d["tip"].reshape(shape + (3,)),
        jacobian=d["jacobian"].reshape(shape + (3, 3)),
        stable=_shaped(d["stable"], shape),
        margin=_shaped(d["margin"], shape),
        uncertain=_shaped(d["uncertain"], shape),
        energy=_shaped(d["energy"], shape),
        elastic_energy=_shaped(d["elastic_energy"], shape),
        base_wrench=_wrench(d["base_wrench"], shape, 2),
        tip_wrench=_wrench(d["tip_wrench"], shape, 2),
        condition=_shaped(d["condition"], shape),
        base_angle=_shaped(d["base_angle"], shape) if held else None,
        turns=_shaped(d["turns"], shape) if held else None,
    )


def _forward_held(
    a: npt.ArrayLike,
    weight: npt.ArrayLike | None,
    gravity: npt.ArrayLike | None,
    base_condition: str,
    tip_condition: str,
    base_angle: npt.ArrayLike,
    tip_load: tuple[float, float] | None,
) -> ForwardResult:
    """:func:`forward` with pinned or free ends (``_rod_ig.forward_held``)."""
    arr, _ = _batch("a", a, 3)
    angle = np.asarray(base_angle, dtype=np.float64)
    flat, shape = _broadcast(arr, angle[..., None], *_weight_arrays(weight, gravity))
    load = None if tip_load is None else (float(tip_load[0]), float(tip_load[1]))
    d = _rod_ig.forward_held(flat[0], np.ascontiguousarray(flat[1].reshape(-1)), base_condition,
                             tip_condition, tip_load=load, **_weight_kwargs(flat, 2))
    return _forward_result(d, shape)


def is_stable(
    a: npt.ArrayLike,
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
) -> BoolArray | np.bool_:
    """Stability verdicts of rods ``a`` of shape (..., 3): True where the rod is established
    stable, the same as ``forward(a).stable``, without the margin ``forward`` refines. Where a
    theorem or the sign of det J(1) decides (about two rods in three of the paper's box) it
    skips the scan of det J(t): about three times as fast as ``forward`` on the paper's box.
    ``weight``, ``gravity``: as for ``forward``."""
    arr, _ = _batch("a", a, 3)
    flat, shape = _broadcast(arr, *_weight_arrays(weight, gravity))
    verdicts = _rod_ig.is_stable(flat[0], threads=_threads(threads), **_weight_kwargs(flat, 1))
    out: BoolArray | np.bool_ = _shaped(verdicts, shape)
    return out


def shape(
    a: npt.ArrayLike,
    samples: int = 100,
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
) -> FloatArray:
    """Poses (x, y, theta) of rods ``a`` (..., 3) at ``samples`` points from the base (the
    identity) to the tip: shape (..., samples, 3). ``weight``, ``gravity``: as for ``forward``."""
    samples = _integer("samples", samples, 2, 1_000_000)
    arr, _ = _batch("a", a, 3)
    flat, batch = _broadcast(arr, *_weight_arrays(weight, gravity))
    out = _rod_ig.shape(flat[0], int(samples), threads=_threads(threads), **_weight_kwargs(flat, 1))
    return out.reshape(batch + (int(samples), 3))


def solve(
    targets: npt.ArrayLike | None,
    a0: npt.ArrayLike | None = None,
    objective: Objective | None = None,
    method: Method = "robust",
    deadline_ms: float | None = None,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    alpha: float | None = None,
    all: bool = False,
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
    max_turns: int = 0,
    base_condition: EndName = "clamped",
    tip_condition: EndName = "clamped",
    tip_load: Sequence[float] | None = None,
    samples: int = 0,
) -> SolveResult:
    """Planar inverse geometry: for each target (x, y, theta) of shape (..., 3), a stable rod
    whose tip is there. ``a0`` (broadcast against the targets) starts the search and selects
    the branch; ``objective`` "first" | "least_energy" (default: "least_energy" with
    ``weight``, the hanging cable a user sees, else "first"); ``method`` "robust" | "newton"
    (the paper's alpha-Newton from ``a0``); ``deadline_ms`` per target (default 250);
    ``tolerance`` on the position (rod lengths) and angle (rad) errors, in [1e-14, 1e-2];
    ``max_iterations`` per start; ``all=True`` also lists every distinct stable solution
    found. ``weight``, ``gravity``: as for ``forward`` (the heavy rod's search:
    docs/weight.md); above weight 200 (long cables, solved by multiple shooting)
    ``max_turns`` full turns of the tangent are admitted (default 0: loop-free rods that do
    not cross themselves).

    ``base_condition`` ("clamped" | "pinned") and ``tip_condition`` ("clamped" | "pinned" |
    "free"): how each end is held (docs/ends.md). A pinned tip's targets are positions of
    shape (..., 2); a free tip has none (``targets=None``: the cable hanging from its base,
    one per weight). Such a solve answers the least-energy stable rod found (default deadline
    1000 ms) and fills ``base_angle`` (a pinned base's angle); ``a0``, ``method``,
    ``tolerance``, ``max_iterations`` and ``alpha`` apply to clamped ends only. ``tip_load``
    (fx, fy): a point force hanging from a free tip (base frame, units of EI/L^2);
    ``samples`` >= 2 fills ``shape`` with the rod found, base to tip (pinned or free ends)."""
    if base_condition != "clamped" or tip_condition != "clamped":
        if a0 is not None or method != "robust" or tolerance is not None:
            raise ValueError("a0, method and tolerance apply to clamped ends only")
        if max_iterations is not None or alpha is not None:
            raise ValueError("max_iterations and alpha apply to clamped ends only")
        return _solve_held(
            targets, base_condition, tip_condition, deadline_ms, all, threads,
            weight, gravity, max_turns, tip_load, samples,
        )
    if tip_load is not None or samples:
        raise ValueError("tip_load and samples apply to pinned or free ends only")
    if targets is None:
        raise ValueError("targets are required (only a free tip has none)")
    t, _ = _batch("targets", targets, 3)
    arrays = [t]
    if a0 is not None:
        arrays.append(_batch("a0", a0, 3)[0])
    heavy = _weight_arrays(weight, gravity)
    flat, batch = _broadcast(*arrays, *heavy)
    d = _rod_ig.solve(
        flat[0],
        a0=flat[1] if a0 is not None else None,
        objective=objective
        if objective is not None
        else ("least_energy" if weight is not None else "first"),
        method=method,
        deadline_ms=250.0 if deadline_ms is None else deadline_ms,
        tolerance=tolerance,
        max_iterations=None
        if max_iterations is None
        else _integer("max_iterations", max_iterations, 1, 100_000),
        alpha=alpha,
        all=all,
        threads=_threads(threads),
        max_turns=_integer("max_turns", max_turns, 0, 100),
        **_weight_kwargs(flat, len(arrays)),
    )
    kwargs = _weight_kwargs(flat, len(arrays))
    w = _rod_ig.wrenches(d["a"], threads=_threads(threads), **kwargs)
    pair = (_wrench(w["base"], batch, 2), _wrench(w["tip"], batch, 2))
    turns = _rod_ig.turns(d["a"], threads=_threads(threads), **kwargs) if heavy else None
    return _solve_result(d, batch, 3, all, pair, turns)


def _tip_load(tip_load: Sequence[float]) -> tuple[float, float]:
    """A free tip's point force (fx, fy), checked."""
    load = np.asarray(tip_load, dtype=np.float64)
    if load.shape != (2,) or not np.isfinite(load).all():
        raise ValueError(f"tip_load must be two finite numbers (fx, fy), got {tip_load!r}")
    return float(load[0]), float(load[1])


def _solve_held(
    targets: npt.ArrayLike | None,
    base_condition: str,
    tip_condition: str,
    deadline_ms: float | None,
    all: bool,
    threads: int | None,
    weight: npt.ArrayLike | None,
    gravity: npt.ArrayLike | None,
    max_turns: int,
    tip_load: Sequence[float] | None = None,
    samples: int = 0,
) -> SolveResult:
    """``solve`` with a pinned or free end (the native ``solve_held``)."""
    for field, value in (("base_condition", base_condition), ("tip_condition", tip_condition)):
        if value not in ("clamped", "pinned", "free"):
            raise ValueError(f'{field} must be "clamped", "pinned" or "free", got {value!r}')
    width = {"free": 0, "pinned": 2}.get(tip_condition, 3)
    arrays = []
    if width > 0 and targets is not None:
        arrays.append(_batch("targets", targets, width)[0])
    elif width == 0 and targets is not None:
        raise ValueError("targets: a free tip has no target (the cable hangs from its base)")
    heavy = _weight_arrays(weight, gravity)
    if not arrays and not heavy:
        heavy = _weight_arrays(0.0, None)
    flat, batch = _broadcast(*arrays, *heavy)
    n = int(np.prod(batch, dtype=np.int64))
    d = _rod_ig.solve_held(
        n,
        targets=flat[0] if arrays else None,
        base_condition=base_condition,
        tip_condition=tip_condition,
        all=all,
        deadline_ms=deadline_ms,
        max_turns=_integer("max_turns", max_turns, 0, 100),
        threads=_threads(threads),
        tip_load=None if tip_load is None else _tip_load(tip_load),
        samples=_integer("samples", samples, 0, 1_000_000),
        **_weight_kwargs(flat, len(arrays)),
    )
    return SolveResult(
        **_held_fields(d, batch, 3, all),
        turns=_shaped(d["turns"], batch),
        base_angle=_shaped(d["base_angle"], batch),
        tip=d["tip"].reshape(batch + (3,)),
        shape=_held_shapes(d["shapes"], batch, samples),
    )


def _held_fields(
    d: dict[str, Any], batch: tuple[int, ...], dim: int, all: bool
) -> dict[str, Any]:
    """The :class:`SolveResult` fields every held-ends search fills (planar ``dim`` 3, 3-D 6)
    from the native dict ``d``."""
    n = int(np.prod(batch, dtype=np.int64))
    solutions = None
    if all:
        solutions = np.empty(n, dtype=object)
        for i, sol in enumerate(d["solutions"]):
            solutions[i] = sol.reshape(-1, dim)
        solutions = _shaped(solutions, batch)
    width = 2 if dim == 3 else 3
    return dict(
        success=_shaped(d["success"], batch),
        a=d["a"].reshape(batch + (dim,)),
        termination=_shaped(np.array(d["termination"], dtype=str), batch),
        reason=_shaped(np.array(d["reason"], dtype=str), batch),
        iterations=_shaped(np.zeros(n, dtype=np.uint32), batch),
        margin=_shaped(d["margin"], batch),
        energy=_shaped(d["energy"], batch),
        position_error=_shaped(d["position_error"], batch),
        orientation_error=_shaped(np.full(n, np.nan), batch),
        starts=_shaped(d["starts"], batch),
        complete=_shaped(d["complete"], batch),
        solutions=solutions,
        base_wrench=_wrench(d["base_wrench"], batch, width),
        tip_wrench=_wrench(d["tip_wrench"], batch, width),
    )


def _held_shapes(
    rows: list[FloatArray], batch: tuple[int, ...], samples: int, width: int = 3
) -> FloatArray | None:
    """The rods' shapes (..., samples, width), NaN where a solve failed; None without
    samples."""
    if samples < 2:
        return None
    out = np.full((len(rows), samples, width), np.nan)
    for i, r in enumerate(rows):
        if len(r):
            out[i] = r.reshape(samples, width)
    return out.reshape(batch + (samples, width))


def forward3d(
    a: npt.ArrayLike,
    stiffness: tuple[float, float, float] = (1.0, 1.0, 1.0),
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
    base_condition: EndName = "clamped",
    tip_condition: EndName = "clamped",
    base_quaternion: npt.ArrayLike | None = None,
) -> Forward3dResult:
    """3-D forward map of rods ``a`` (..., 6) by numerical integration (docs/math.md §10), with
    stiffness (c1 torsion, c2, c3 bending) each in [1e-6, 1e6]. ``weight`` and ``gravity``
    ((..., 3), default (0, 0, -1)) broadcast against the batch: the 3-D rod with weight.

    ``base_condition`` / ``tip_condition`` (docs/ends.md, "3-D"): a clamped base with a pinned
    or free tip, or both pinned; the verdict is then the second variation's with the natural
    conditions. A pinned base (a_m = 0) leaves at ``base_quaternion`` ((..., 4), x y z w,
    default the identity); a free tip's force must be its weight."""
    if base_condition != "clamped" or tip_condition != "clamped":
        return _forward_held3d(
            a, stiffness, weight, gravity, base_condition, tip_condition, base_quaternion
        )
    if base_quaternion is not None:
        raise ValueError("base_quaternion applies to a pinned base only")
    arr, _ = _batch("a", a, 6)
    flat, batch = _broadcast(arr, *_weight_arrays(weight, gravity, 3))
    d = _rod_ig.forward3d(
        flat[0], stiffness=tuple(stiffness), threads=_threads(threads), **_weight_kwargs(flat, 1)
    )
    return Forward3dResult(
        position=d["position"].reshape(batch + (3,)),
        quaternion=d["quaternion"].reshape(batch + (4,)),
        jacobian=d["jacobian"].reshape(batch + (6, 6)),
        stable=d["stable"].reshape(batch),
        margin=d["margin"].reshape(batch),
        energy=d["energy"].reshape(batch),
        base_wrench=_wrench(d["base_wrench"], batch, 3),
        tip_wrench=_wrench(d["tip_wrench"], batch, 3),
        uncertain=d["uncertain"].reshape(batch),
        condition=d["condition"].reshape(batch),
    )


def _forward_held3d(
    a: npt.ArrayLike,
    stiffness: tuple[float, float, float],
    weight: npt.ArrayLike | None,
    gravity: npt.ArrayLike | None,
    base_condition: str,
    tip_condition: str,
    base_quaternion: npt.ArrayLike | None,
) -> Forward3dResult:
    """``forward3d`` with a pinned or free end (the native ``forward_held3d``)."""
    arrays = [_batch("a", a, 6)[0]]
    if base_quaternion is not None:
        arrays.append(_batch("base_quaternion", base_quaternion, 4)[0])
    heavy = _weight_arrays(weight, gravity, 3)
    flat, batch = _broadcast(*arrays, *heavy)
    d = _rod_ig.forward_held3d(
        flat[0],
        base_condition,
        tip_condition,
        base_quaternion=flat[1] if base_quaternion is not None else None,
        stiffness=tuple(stiffness),
        **_weight_kwargs(flat, len(arrays)),
    )
    n = int(np.prod(batch, dtype=np.int64))
    tip = d["tip"].reshape(batch + (7,))
    return Forward3dResult(
        position=tip[..., :3],
        quaternion=tip[..., 3:],
        jacobian=d["jacobian"].reshape(batch + (6, 6)),
        stable=_shaped(d["stable"], batch),
        margin=_shaped(d["margin"], batch),
        energy=_shaped(d["energy"], batch),
        base_wrench=_wrench(d["base_wrench"], batch, 3),
        tip_wrench=_wrench(d["tip_wrench"], batch, 3),
        uncertain=_shaped(d["uncertain"], batch),
        condition=_shaped(np.full(n, np.nan), batch),
        base_quaternion=d["base_quaternion"].reshape(batch + (4,)),
        elastic_energy=_shaped(d["elastic_energy"], batch),
    )


def _solve_held3d(
    position: npt.ArrayLike | None,
    base_condition: str,
    tip_condition: str,
    stiffness: tuple[float, float, float],
    deadline_ms: float | None,
    all: bool,
    threads: int | None,
    weight: npt.ArrayLike | None,
    gravity: npt.ArrayLike | None,
    max_turns: int,
    quaternion: npt.ArrayLike | None = None,
    samples: int = 0,
) -> SolveResult:
    """``solve3d`` with a pinned or free end (the native ``solve_held3d``)."""
    arrays = []
    if quaternion is not None:
        arrays.append(_batch("quaternion", quaternion, 4)[0])
    if tip_condition == "free":
        if position is not None:
            raise ValueError("position: a free tip has no target (the cable hangs from its base)")
    elif position is None:
        raise ValueError("position: a pinned tip needs its position (..., 3)")
    else:
        arrays.append(_batch("position", position, 3)[0])
    heavy = _weight_arrays(weight, gravity, 3)
    if not arrays and not heavy:
        heavy = _weight_arrays(0.0, None, 3)
    flat, batch = _broadcast(*arrays, *heavy)
    n = int(np.prod(batch, dtype=np.int64))
    pose = quaternion is not None
    d = _rod_ig.solve_held3d(
        n,
        positions=flat[1 if pose else 0] if arrays else None,
        quaternions=flat[0] if pose else None,
        samples=_integer("samples", samples, 0, 1_000_000),
        base_condition=base_condition,
        tip_condition=tip_condition,
        stiffness=tuple(stiffness),
        all=all,
        deadline_ms=deadline_ms,
        max_turns=_integer("max_turns", max_turns, 0, 100),
        threads=_threads(threads),
        **_weight_kwargs(flat, len(arrays)),
    )
    return SolveResult(
        **_held_fields(d, batch, 6, all),
        turns=_shaped(np.where(d["success"], d["turns"], -1).astype(np.int64), batch),
        tip=d["tip"].reshape(batch + (7,)),
        base_quaternion=d["base_quaternion"].reshape(batch + (4,)),
        shape=_held_shapes(d["shapes"], batch, samples, 7),
    )


def solve3d(
    position: npt.ArrayLike | None,
    quaternion: npt.ArrayLike | None = None,
    a0: npt.ArrayLike | None = None,
    objective: Objective = "first",
    method: Method = "robust",
    deadline_ms: float = 1000.0,
    tolerance: float | None = None,
    max_iterations: int | None = None,
    alpha: float | None = None,
    stiffness: tuple[float, float, float] = (1.0, 1.0, 1.0),
    all: bool = False,
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
    base_condition: EndName = "clamped",
    tip_condition: EndName = "clamped",
    max_turns: int = 0,
    samples: int = 0,
) -> SolveResult:
    """3-D inverse geometry: targets given by ``position`` (..., 3) and ``quaternion``
    (..., 4) as (x, y, z, w), broadcast together; the options of :func:`solve`; ``weight``
    and ``gravity`` as for :func:`forward3d`.

    ``base_condition`` / ``tip_condition`` (docs/ends.md, "3-D"; isotropic bending): a clamped
    base with a pinned tip (targets ``position`` alone, ``quaternion=None``: a hook) or a free
    one (``position=None``: the cable hanging from its gripper, one per weight), a pinned base
    with a pinned tip (a cable between two hooks) or a clamped one (its pose). Such a solve answers the least-energy stable rod found
    (default deadline 1000 ms; ``max_turns`` as for :func:`solve`) and fills ``tip`` (..., 7:
    position and quaternion) and ``base_quaternion``; ``samples`` >= 2 fills ``shape``
    (..., samples, 7: poses base to tip); ``a0``, ``method``, ``tolerance``,
    ``max_iterations`` and ``alpha`` apply to clamped ends only."""
    if base_condition != "clamped" or tip_condition != "clamped":
        if a0 is not None or method != "robust" or tolerance is not None:
            raise ValueError("a0, method and tolerance apply to clamped ends only")
        if max_iterations is not None or alpha is not None:
            raise ValueError("max_iterations and alpha apply to clamped ends only")
        if tip_condition == "clamped" and (position is None or quaternion is None):
            raise ValueError("position and quaternion: a clamped tip's target is a pose")
        if tip_condition != "clamped" and quaternion is not None:
            raise ValueError("quaternion: a pinned tip turns freely (its target is a position)")
        return _solve_held3d(
            position, base_condition, tip_condition, stiffness,
            deadline_ms, all, threads, weight, gravity,
            max_turns, quaternion, samples,
        )
    if position is None or quaternion is None:
        raise ValueError("position and quaternion are required (clamped ends)")
    if max_turns or samples:
        raise ValueError("max_turns and samples apply to pinned or free ends in 3-D")
    arrays = [_batch("position", position, 3)[0], _batch("quaternion", quaternion, 4)[0]]
    if a0 is not None:
        arrays.append(_batch("a0", a0, 6)[0])
    flat, batch = _broadcast(*arrays, *_weight_arrays(weight, gravity, 3))
    d = _rod_ig.solve3d(
        flat[0],
        flat[1],
        a0=flat[2] if a0 is not None else None,
        objective=objective,
        method=method,
        deadline_ms=deadline_ms,
        tolerance=tolerance,
        max_iterations=None
        if max_iterations is None
        else _integer("max_iterations", max_iterations, 1, 100_000),
        alpha=alpha,
        stiffness=tuple(stiffness),
        all=all,
        threads=_threads(threads),
        **_weight_kwargs(flat, len(arrays)),
    )
    w = _rod_ig.wrenches3d(
        d["a"],
        stiffness=tuple(stiffness),
        threads=_threads(threads),
        **_weight_kwargs(flat, len(arrays)),
    )
    pair = (_wrench(w["base"], batch, 3), _wrench(w["tip"], batch, 3))
    return _solve_result(d, batch, 6, all, pair)


def wrenches(
    a: npt.ArrayLike,
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
) -> tuple[Wrench, Wrench]:
    """The (base, tip) wrenches planar rods ``a`` (..., 3) exert on their grippers, each in its
    gripper's frame (:class:`Wrench`); ``weight`` and ``gravity`` as for :func:`forward`. NaN
    where a rod cannot be evaluated."""
    arr, _ = _batch("a", a, 3)
    flat, shape = _broadcast(arr, *_weight_arrays(weight, gravity))
    w = _rod_ig.wrenches(flat[0], threads=_threads(threads), **_weight_kwargs(flat, 1))
    return _wrench(w["base"], shape, 2), _wrench(w["tip"], shape, 2)


def wrenches3d(
    a: npt.ArrayLike,
    stiffness: tuple[float, float, float] = (1.0, 1.0, 1.0),
    threads: int | None = None,
    weight: npt.ArrayLike | None = None,
    gravity: npt.ArrayLike | None = None,
) -> tuple[Wrench, Wrench]:
    """The (base, tip) wrenches 3-D rods ``a`` (..., 6) exert on their grippers (3-vectors in
    each gripper's frame); the options of :func:`forward3d`."""
    arr, _ = _batch("a", a, 6)
    flat, shape = _broadcast(arr, *_weight_arrays(weight, gravity, 3))
    w = _rod_ig.wrenches3d(
        flat[0], stiffness=tuple(stiffness), threads=_threads(threads), **_weight_kwargs(flat, 1)
    )
    return _wrench(w["base"], shape, 3), _wrench(w["tip"], shape, 3)


def warm_up() -> int:
    """Builds the planar solver's atlases of stable rods now (about 0.45 s on two cores; done
    otherwise by the first solves that need them). Returns their number of seeds."""
    return _rod_ig.warm_up()


@dataclass(frozen=True)
class MoveResult:
    """One move of a :class:`Tracker`: the fields of :class:`SolveResult` for one target, and
    the branch event."""

    success: bool
    a: FloatArray
    termination: str
    iterations: int
    margin: float
    energy: float
    position_error: float
    orientation_error: float
    event: str
    """"none", "snap" (the branch folded: the rod jumped to another equilibrium) or "lost"."""
    critical: FloatArray | None = None
    """After a snap: the gripper pose (x, y, theta) where the branch folded."""
    critical_a: FloatArray | None = None
    energy_released: float | None = None
    reason: str | None = None
    base_angle: float | None = None
    """With held ends: the rod's angle at the base (0 unless the base is pinned)."""
    turns: int | None = None
    """With held ends: full turns of the tangent (-1 without a rod)."""


class Tracker:
    """Quasi-static motion: the rod follows its equilibrium branch as the tip gripper moves,
    and snaps where the branch folds. Safe to share between threads (moves are serialised by a
    lock); ``pickle`` and ``copy`` give a tracker holding the same rod.

    >>> t = Tracker()
    >>> t.move([0.6, 0.2, 0.4]).event
    'none'
    """

    def __init__(
        self,
        a0: Sequence[float] | None = None,
        deadline_ms: float = 250.0,
        tolerance: float | None = None,
        weight: float = 0.0,
        gravity: Sequence[float] = (0.0, -1.0),
        base_condition: str = "clamped",
        tip_condition: str = "clamped",
        tip_load: Sequence[float] | None = None,
        max_turns: int = 0,
    ) -> None:
        """``weight`` and ``gravity`` (2 components): the rod with weight (docs/weight.md).
        ``base_condition`` / ``tip_condition`` ("clamped", "pinned" or "free"), ``tip_load`` and
        ``max_turns``: a rod held by other ends (docs/ends.md), which follows its branch with
        the multiple-shooting cable: targets are (x, y, theta) for a clamped tip, (x, y) for a
        pinned one, ``None`` for a free one; ``a0`` and ``tolerance`` apply to clamped ends
        only."""
        start = None if a0 is None else [float(v) for v in _batch("a0", a0, 3)[0].reshape(3)]
        g = _batch("gravity", gravity, 2)[0].reshape(2)
        self._settings: dict[str, Any] = dict(
            deadline_ms=deadline_ms,
            tolerance=tolerance,
            weight=float(weight),
            gravity=(float(g[0]), float(g[1])),
        )
        self._held_settings: dict[str, Any] | None = None
        if (base_condition, tip_condition) != ("clamped", "clamped") or tip_load is not None:
            if a0 is not None or tolerance is not None:
                raise ValueError("a0 and tolerance apply to clamped ends only")
            self._held_settings = dict(
                base_condition=base_condition,
                tip_condition=tip_condition,
                deadline_ms=deadline_ms,
                weight=float(weight),
                gravity=(float(g[0]), float(g[1])),
                max_turns=_integer("max_turns", max_turns, 0, 100),
                tip_load=None if tip_load is None else _tip_load(tip_load),
            )
        self._lock = threading.Lock()
        self._inner: Any = self._native(start)

    def _native(self, start: list[float] | None) -> Any:
        if self._held_settings is not None:
            return _rod_ig.HeldTracker(**self._held_settings)
        return _rod_ig.Tracker(a0=start, **self._settings)

    def move(self, target: npt.ArrayLike | None = None) -> MoveResult:
        """Moves the tip gripper to ``target`` (x, y, theta; (x, y) for a pinned tip, ``None``
        for a free one) and returns the rod it holds."""
        if self._held_settings is not None:
            return self._move_held(target)
        if target is None:
            raise ValueError("target: a clamped tip needs (x, y, theta)")
        t = [float(v) for v in _batch("target", target, 3)[0].reshape(3)]
        with self._lock:
            return MoveResult(**self._inner.move(t))

    def _move_held(self, target: npt.ArrayLike | None) -> MoveResult:
        t = None if target is None else [float(v) for v in np.asarray(target, dtype=np.float64).ravel()]
        with self._lock:
            d = self._inner.move(t)
        tip = d["tip"].reshape(3)
        orientation_error = math.nan
        if t is not None and len(t) == 3 and d["success"][0]:
            orientation_error = abs(math.remainder(float(tip[2]) - t[2], math.tau))
        reason = str(d["reason"][0])
        return MoveResult(
            success=bool(d["success"][0]),
            a=d["a"].reshape(3),
            termination=str(d["termination"][0]),
            iterations=0,
            margin=float(d["margin"][0]),
            energy=float(d["energy"][0]),
            position_error=float(d["position_error"][0]),
            orientation_error=orientation_error,
            event=str(d["event"]),
            reason=reason or None,
            base_angle=float(d["base_angle"][0]),
            turns=int(d["turns"][0]),
        )

    @property
    def rod(self) -> FloatArray | None:
        """The rod held now (a3, a4, a5), None before the first move or after a loss (with
        held ends: (a3, a4, a5, base angle))."""
        with self._lock:
            r = self._inner.rod
        return None if r is None else np.array(r)

    def __getstate__(self) -> dict[str, Any]:
        # A held rod's node states stay in this process: its copy searches afresh.
        held = None if self._held_settings is not None else self.rod
        return {
            "settings": self._settings,
            "held_settings": self._held_settings,
            "rod": None if held is None else held.tolist(),
        }

    def __setstate__(self, state: dict[str, Any]) -> None:
        self._settings = state["settings"]
        self._held_settings = state.get("held_settings")
        self._lock = threading.Lock()
        self._inner = self._native(state["rod"])


@dataclass(frozen=True)
class PlanResult:
    """A plan: stable rods from the start to a rod whose tip is the goal."""

    success: bool
    rods: FloatArray
    """(n, 3): rods, consecutive ones within 0.1 (1 + |a|)."""
    gripper: FloatArray
    """(n, 3): the tip gripper's poses (x, y, theta)."""
    min_margin: float
    reason: str


class Planner:
    """Plans stable, collision-free gripper paths for the planar rod over a roadmap of stable
    rods, kept across calls. Obstacles are dicts ``{"type": "disc", "center": [x, y],
    "radius": r}`` or ``{"type": "polygon", "points": [[x, y], ...]}`` in rod lengths, within
    +-1e6. Safe to share between threads (plans are serialised by a lock); ``pickle`` and
    ``copy`` give a planner that rebuilds its roadmap on first use."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._inner = _rod_ig.Planner()

    def __getstate__(self) -> dict[str, Any]:
        # Not empty: an empty state would skip __setstate__ (the lock and the native planner).
        return {"roadmap": "rebuilt on first use"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__()  # type: ignore[misc]

    def plan(
        self,
        start: Sequence[float],
        goal: Sequence[float],
        obstacles: Sequence[dict[str, Any]] = (),
        deadline_ms: float = 500.0,
        weight: float = 0.0,
        gravity: Sequence[float] = (0.0, -1.0),
    ) -> PlanResult:
        """Plans from the rod ``start`` (a3, a4, a5) to a rod whose tip is ``goal`` (x, y,
        theta); ``weight`` and ``gravity`` (2 components): the rod with weight
        (docs/weight.md), whose margins, bodies and goal rods the plan then uses."""
        s = [float(v) for v in _batch("start", start, 3)[0]]
        g = [float(v) for v in _batch("goal", goal, 3)[0]]
        down = _batch("gravity", gravity, 2)[0].reshape(2)
        with self._lock:
            d = self._inner.plan(s, g, obstacles=list(obstacles), deadline_ms=deadline_ms,
                                 weight=float(weight), gravity=(float(down[0]), float(down[1])))
        return PlanResult(
            success=d["success"],
            rods=d["rods"].reshape(-1, 3),
            gripper=d["gripper"].reshape(-1, 3),
            min_margin=d["min_margin"],
            reason=d["reason"],
        )

    @property
    def roadmap_size(self) -> int:
        """Roadmap nodes (0 before the first plan)."""
        return self._inner.roadmap_size
