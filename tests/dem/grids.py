"""Starting arrangements shared by the engine's tests."""

from __future__ import annotations

import math

import numpy as np


def staggered_rows(
    nx: int, ny: int, r: float, rng: np.random.Generator, spacing: float = 2.02, offset: float = 0.5,
    jitter: float = 0.1,
) -> np.ndarray:  # fmt: skip
    """Centres of ``ny`` staggered rows of ``nx`` disks of radius up to ``r``, ``spacing`` r apart.

    Row j starts ``offset + 0.5 (j % 2)`` spacings from x = 0; each centre moves sideways by a
    uniform draw in [-jitter, jitter) r, drawn row by row from ``rng``.
    """
    s = spacing * r
    h = s * math.sqrt(3) / 2
    return np.array(
        [
            (s * (i + offset + 0.5 * (j % 2)) + rng.uniform(-jitter, jitter) * r, s / 2 + h * j)
            for j in range(ny)
            for i in range(nx)
        ]
    )
