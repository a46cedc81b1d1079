"""Disk numbering: which order of the disks in memory suits the engine.

The order of the disks is a memory layout, not physics: any order gives the same
motion up to round-off. It matters for speed in two ways.

* Neighbours in space should be near in memory, so that a disk's row of partners
  is read from cache (:mod:`poro2d.dem.neighbors` keeps only partners ``j > i``).
* The engine splits the disks into contiguous index ranges, one per thread
  (:mod:`poro2d.dem.partition`). The pairs that cross from one range into the next
  are the *cross band*: their second disks wait for a second phase and their data
  travel between the cores. A cut that runs across the short side of the packing
  makes that band as short as it can be.

:func:`strip_order` numbers the disks strip by strip, the strips running across the
short side of the packing (columns in a wide box, rows in a tall one), and along each
strip. Measured on the paper's 0.305 m x 0.124 m specimen (2565 disks): numbered in
rows, 81 disks wait for the second phase; in columns, 37, and two threads ran 8-12 %
faster in paired runs (one thread: no change beyond the +-3 % noise).
"""

from __future__ import annotations

import numpy as np

from poro2d.errors import InputError


def strip_order(pos: np.ndarray, radius: np.ndarray, width: float | None = None) -> np.ndarray:
    """Indices that number the disks strip by strip across the short side of the packing.

    pos (N, 2), radius (N,)
        disk centres and radii (m);
    width
        strip width (m), default four largest radii (two largest diameters): narrow
        enough that a disk's partners lie in its own or the next strip, wide enough
        that a strip is more than a thin line of disks.

    Returns ``order`` such that ``pos[order]`` is the new numbering (the argument of
    :meth:`poro2d.dem.Simulation.reorder`). Ties keep the current order, so the
    result is the same on every machine.
    """
    pos = np.asarray(pos, dtype=float)
    radius = np.asarray(radius, dtype=float)
    n = pos.shape[0] if pos.ndim == 2 else -1
    if pos.ndim != 2 or pos.shape[1] != 2:
        raise InputError("positions", f"shape {pos.shape}", "shape (N, 2)")
    if radius.shape != (n,):
        raise InputError("radius", f"shape {radius.shape}", f"shape ({n},)")
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    if width is None:
        width = 4.0 * float(radius.max())
    if not (width > 0.0 and np.isfinite(width)):
        raise InputError("strip width", width, "(0, inf) m")
    lo = pos.min(axis=0)
    span = pos.max(axis=0) - lo
    # strips run across the short side: in a wide packing they are columns (x fixed)
    across = 0 if span[0] >= span[1] else 1
    along = 1 - across
    strip = np.floor((pos[:, across] - lo[across]) / width)
    return np.lexsort((pos[:, along], strip)).astype(np.int64)


def is_permutation(order: np.ndarray, n: int) -> bool:
    """True when ``order`` holds each of 0 .. n-1 exactly once."""
    order = np.asarray(order)
    if order.shape != (n,) or not np.issubdtype(order.dtype, np.integer):
        return False
    seen = np.zeros(n, dtype=bool)
    if n and (order.min() < 0 or order.max() >= n):
        return False
    seen[order] = True
    return bool(seen.all())


__all__ = ["is_permutation", "strip_order"]
