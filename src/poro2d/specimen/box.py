"""The box a specimen is prepared in, read back from its walls.

``Walls.box`` (:mod:`poro2d.dem.state`) builds the box from four walls named and ordered
by ``BOX_WALLS``, each segment extended past the corners; so a box is read from the wall
lines (a wall's first point), never from the segment ends. The split shear box, the shear
test's specimen file and the exported specimen all read the box here.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from poro2d.dem.state import BOX_WALLS
from poro2d.errors import InputError


def box_faces(
    names: Sequence[str], p0: np.ndarray, parameter: str = "walls", hint: str = ""
) -> tuple[float, float, float, float]:
    """(xlo, xhi, ylo, yhi): the lines of the left, right, bottom and top walls.

    ``names`` and ``p0`` (one first point per wall) as ``Walls`` holds them; a set of walls
    without the four of a box is refused, naming ``parameter``.
    """
    names = list(names)
    if not set(BOX_WALLS) <= set(names):
        raise InputError(parameter, names, f"a box of walls named {', '.join(BOX_WALLS)}", hint)
    first = {name: p0[names.index(name)] for name in BOX_WALLS}
    return (
        float(first["left"][0]),
        float(first["right"][0]),
        float(first["bottom"][1]),
        float(first["top"][1]),
    )


__all__ = ["BOX_WALLS", "box_faces"]
