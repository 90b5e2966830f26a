"""Beyond one machine: rod_ig's batch API mapped over the chunks of a Dask array.

Each chunk is one native call that computes every output at once (tip, J, verdict, margin,
energy); Dask runs the chunks in parallel, so each call uses one thread by default (the
scheduler's workers already fill the cores). The same code runs on the local threaded
scheduler and on a ``dask.distributed`` cluster::

    import dask.array as da
    from rod_ig.dask import forward_blocks, forward_blocks_full

    rods = da.random.uniform(-10, 10, size=(10_000_000, 3), chunks=(500_000, 3))
    tip, stable, margin = forward_blocks(rods)
    fraction_stable = stable.mean().compute()
    full = forward_blocks_full(rods)          # tip, jacobian, stable, margin, energy

Requires ``dask[array]`` (not a dependency of rod_ig itself).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

import rod_ig

#: Columns of the packed block: tip (3), J (9, row-major), stable, margin, energy.
_COLUMNS = 15


def _packed(block: np.ndarray[Any, Any], threads: int | None) -> np.ndarray[Any, Any]:
    """Every output of one chunk from one native call, packed as (n, 15) float64."""
    r = rod_ig.forward(block, threads=threads)
    n = block.shape[0]
    out = np.empty((n, _COLUMNS))
    out[:, 0:3] = r.tip
    out[:, 3:12] = r.jacobian.reshape(n, 9)
    out[:, 12] = r.stable
    out[:, 13] = r.margin
    out[:, 14] = r.energy
    return out


@dataclass(frozen=True)
class DaskForward:
    """Lazy outputs of :func:`forward_blocks_full`, all from one native call per chunk."""

    tip: Any
    """(n, 3) float64."""
    jacobian: Any
    """(n, 3, 3) float64."""
    stable: Any
    """(n,) bool."""
    margin: Any
    """(n,) float64."""
    energy: Any
    """(n,) float64."""


def forward_blocks_full(rods: Any, threads: int | None = 1) -> DaskForward:
    """Tip, J, verdict, margin and energy of a Dask array of rods of shape (n, 3), chunked along
    n only, as lazy Dask arrays computed by one native call per chunk (``threads`` per call,
    1 by default: Dask already runs the chunks in parallel)."""
    import dask.array as da

    if rods.ndim != 2 or rods.shape[1] != 3 or len(rods.chunks[1]) != 1:
        raise ValueError(f"rods must be a Dask array of shape (n, 3) chunked along n, got {rods}")
    rods = rods.astype(np.float64)
    map_blocks: Any = da.map_blocks  # dask ships no type annotations
    packed = map_blocks(
        _packed,
        rods,
        threads,
        dtype=np.float64,
        chunks=(rods.chunks[0], (_COLUMNS,)),
        meta=np.empty((0, _COLUMNS)),  # no trial call on an empty block
    )
    n = rods.shape[0]
    return DaskForward(
        tip=packed[:, 0:3],
        jacobian=packed[:, 3:12].reshape((n, 3, 3)),
        stable=packed[:, 12] != 0,
        margin=packed[:, 13],
        energy=packed[:, 14],
    )


def forward_blocks(rods: Any, threads: int | None = 1) -> tuple[Any, Any, Any]:
    """The tips (n, 3), stability verdicts (n,) and margins (n,) of a Dask array of rods of
    shape (n, 3), chunked along n only, as lazy Dask arrays: one native call per chunk for all
    three (:func:`forward_blocks_full`)."""
    f = forward_blocks_full(rods, threads)
    return f.tip, f.stable, f.margin
