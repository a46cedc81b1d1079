"""The disks a measurement reads: their centres and radii checked, the box, their median diameter.

Every measurement of a specimen's porosity (its free surface, measurement circles, Laguerre
cells) takes the disks as arrays and checks them here once, so that all of them refuse the
same inputs with the same message.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from poro2d.errors import InputError, as_float_array, check_range


def check_disks(pos: Any, radius: Any) -> tuple[np.ndarray, np.ndarray]:
    """Centres as a C-contiguous (n, 2) array and radii as (n,), all finite, radii > 0."""
    pos = as_float_array("pos", pos)
    if pos.ndim != 2 or pos.shape[1] != 2 or pos.shape[0] == 0:
        raise InputError("pos", f"array of shape {pos.shape}", "an (n, 2) array of disk centres, n >= 1")
    radius = as_float_array("radius", radius)
    if radius.shape != (pos.shape[0],):
        raise InputError(
            "radius", f"array of shape {radius.shape}", f"one radius per disk: shape ({len(pos)},)"
        )
    if not np.all(np.isfinite(pos)):
        raise InputError("pos", "non-finite values", "finite coordinates (m)")
    if not (np.all(np.isfinite(radius)) and np.all(radius > 0)):
        raise InputError("radius", float(np.nanmin(radius)), "finite radii > 0 (m)")
    return np.ascontiguousarray(pos), np.ascontiguousarray(radius)


def check_specimen(
    pos: Any, radius: Any, width: Any, plate_y: Any
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The disks and the box they stand in, checked: :func:`check_disks`, then :func:`check_box`."""
    pos, radius = check_disks(pos, radius)
    return pos, radius, *check_box(pos, width, plate_y)


def check_box(pos: np.ndarray, width: Any, plate_y: Any) -> tuple[float, float]:
    """The box [0, width] x [0, plate_y], with every disk centre strictly inside it.

    The tessellation needs it: a centre outside the box would leave part of the box to the
    mirror image of a disk (see :func:`poro2d.measure.laguerre.laguerre_cells`).
    """
    width = check_range("width", width, 0.0, lo_open=True)
    plate_y = check_range("plate_y", plate_y, 0.0, lo_open=True)
    x, y = pos[:, 0], pos[:, 1]
    outside = np.nonzero(~((x > 0) & (x < width) & (y > 0) & (y < plate_y)))[0]
    if outside.size:
        k = int(outside[0])
        raise InputError(
            "pos",
            (float(x[k]), float(y[k])),
            f"disk centres inside the box (0, {width:g}) x (0, {plate_y:g}) m",
            f"disk {k} and {outside.size - 1} more are outside",
        )
    return width, plate_y


def check_d50(d50: Any, radius: np.ndarray) -> float:
    """The median diameter a measure is scaled by: the one given, else the disks' own (:func:`mass_d50`)."""
    return mass_d50(radius) if d50 is None else check_range("d50", d50, 0.0, lo_open=True)


def mass_d50(radius: Any) -> float:
    """Median diameter by area (the 2D mass) fraction of the actual disks (m).

    The diameter at which the disks of that diameter or smaller first make up half of the
    total disk area: the d50 of a sieve curve, read off the disks themselves so that
    margins and circle sizes follow the specimen measured, not the grading it was drawn
    from. For equal disks it is their diameter.
    """
    radius = as_float_array("radius", radius).ravel()
    if radius.size == 0 or not (np.all(np.isfinite(radius)) and np.all(radius > 0)):
        raise InputError("radius", "empty or non-positive radii", "finite radii > 0 (m), at least one")
    r = np.sort(radius)
    cum = np.cumsum(r * r)
    k = int(np.searchsorted(cum, 0.5 * cum[-1]))
    return float(2.0 * r[min(k, r.size - 1)])


__all__ = ["check_box", "check_d50", "check_disks", "check_specimen", "mass_d50"]
