"""Beyond one machine: rod_ig's batch API mapped over the chunks of a Dask array.

Each chunk is one native batch call (all cores of the worker that runs it, GIL released), so
the same code runs on the local threaded scheduler and on a ``dask.distributed`` cluster::

    import dask.array as da
    from rod_ig.dask import forward_blocks

    rods = da.random.uniform(-10, 10, size=(10_000_000, 3), chunks=(500_000, 3))
    tip, stable, margin = forward_blocks(rods)
    fraction_stable = stable.mean().compute()

Requires ``dask[array]`` (not a dependency of rod_ig itself).
"""

from __future__ import annotations

from typing import Any

import numpy as np

import rod_ig


def _tip(block: np.ndarray[Any, Any], threads: int | None) -> np.ndarray[Any, Any]:
    return rod_ig.forward(block, threads=threads).tip


def _stable(block: np.ndarray[Any, Any], threads: int | None) -> np.ndarray[Any, Any]:
    return rod_ig.forward(block, threads=threads).stable


def _margin(block: np.ndarray[Any, Any], threads: int | None) -> np.ndarray[Any, Any]:
    return rod_ig.forward(block, threads=threads).margin


def forward_blocks(rods: Any, threads: int | None = None) -> tuple[Any, Any, Any]:
    """The tips (n, 3), stability verdicts (n,) and margins (n,) of a Dask array of rods of
    shape (n, 3), chunked along n only, as lazy Dask arrays (one native call per chunk and
    output)."""
    import dask.array as da

    if rods.ndim != 2 or rods.shape[1] != 3 or len(rods.chunks[1]) != 1:
        raise ValueError(f"rods must be a Dask array of shape (n, 3) chunked along n, got {rods}")
    rods = rods.astype(np.float64)
    map_blocks: Any = da.map_blocks  # dask ships no type annotations
    tip = map_blocks(_tip, rods, threads, dtype=np.float64, chunks=rods.chunks)
    stable = map_blocks(
        _stable, rods, threads, dtype=bool, drop_axis=1, chunks=(rods.chunks[0],)
    )
    margin = map_blocks(
        _margin, rods, threads, dtype=np.float64, drop_axis=1, chunks=(rods.chunks[0],)
    )
    return tip, stable, margin
