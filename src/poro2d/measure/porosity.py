"""Porosity of a region: disks clipped exactly by a rectangle or a circle, and the box's n'.

A region's porosity is 1 - (disk area inside it) / (its area). Disks are clipped exactly at
the region's edges (no counting of centres), so a value does not depend on where centres
happen to fall: :func:`porosity_rect` (band, interior rectangle), :func:`porosity_circle`
(measurement circles). :func:`box_porosity` is the paper's n' of a whole box under its top
plate: whole disks, overlaps not subtracted, the gap under the plate included.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from poro2d.errors import InputError, as_float_array, check_range


@njit(cache=True)
def _quadrant_area(r, a, b):
    """Area of the disk of radius r at the origin with X <= a and Y <= b."""
    if a <= -r or b <= -r:
        return 0.0
    a = min(a, r)
    # integrate h(x) = vertical extent of {Y <= b} within the disk, x in [-r, a]
    if b >= r:
        return _half_area_left(r, a) * 2.0
    c = math.sqrt(r * r - b * b)
    # |x| < c: h = b + s(x); |x| >= c: h = 2 s(x) when b >= 0, else 0
    lo = -r
    total = 0.0
    x1 = min(a, -c)
    if x1 > lo and b >= 0.0:
        total += 2.0 * (_s_int(r, x1) - _s_int(r, lo))
    x0 = max(lo, -c)
    x2 = min(a, c)
    if x2 > x0:
        total += b * (x2 - x0) + _s_int(r, x2) - _s_int(r, x0)
    if a > c and b >= 0.0:
        total += 2.0 * (_s_int(r, a) - _s_int(r, c))
    return total


@njit(inline="always", cache=True)
def _s_int(r, x):
    """Antiderivative of sqrt(r^2 - x^2)."""
    x = max(-r, min(r, x))
    return 0.5 * (x * math.sqrt(max(r * r - x * x, 0.0)) + r * r * math.asin(x / r))


@njit(inline="always", cache=True)
def _half_area_left(r, a):
    """Integral of sqrt(r^2 - x^2) from -r to a."""
    return _s_int(r, a) - _s_int(r, -r)


@njit(cache=True)
def disk_rect_areas(pos, radius, x0, y0, x1, y1):
    """Exact area of each disk clipped by the rectangle [x0, x1] x [y0, y1]."""
    n = pos.shape[0]
    out = np.empty(n)
    for i in range(n):
        cx = pos[i, 0]
        cy = pos[i, 1]
        r = radius[i]
        if cx + r <= x0 or cx - r >= x1 or cy + r <= y0 or cy - r >= y1:
            out[i] = 0.0
            continue
        ax0 = x0 - cx
        ax1 = x1 - cx
        ay0 = y0 - cy
        ay1 = y1 - cy
        out[i] = (
            _quadrant_area(r, ax1, ay1)
            - _quadrant_area(r, ax0, ay1)
            - _quadrant_area(r, ax1, ay0)
            + _quadrant_area(r, ax0, ay0)
        )
    return out


def _lens_area(d, r1, r2):
    """Area of the intersection of two circles at centre distance d (vectorised in d, r1)."""
    d = np.asarray(d, float)
    r1 = np.asarray(r1, float)
    out = np.zeros(np.broadcast(d, r1).shape)
    full = d <= np.abs(r2 - r1)
    out[full] = np.pi * np.minimum(r1, r2)[full] ** 2
    part = (~full) & (d < r1 + r2)
    dd, a = d[part], r1[part]
    c1 = np.clip((dd**2 + a**2 - r2**2) / (2 * dd * a), -1, 1)
    c2 = np.clip((dd**2 + r2**2 - a**2) / (2 * dd * r2), -1, 1)
    out[part] = (
        a**2 * np.arccos(c1)
        + r2**2 * np.arccos(c2)
        - 0.5 * np.sqrt(np.maximum((-dd + a + r2) * (dd + a - r2) * (dd - a + r2) * (dd + a + r2), 0))
    )
    return out


def porosity_rect(pos: np.ndarray, radius: np.ndarray, x0: float, y0: float, x1: float, y1: float) -> float:
    """Porosity of a rectangle: 1 - (disk area inside it) / (its area). Disks are clipped exactly."""
    if not (x1 > x0 and y1 > y0):
        raise InputError("rectangle", (x0, y0, x1, y1), "x1 > x0 and y1 > y0")
    solid = float(np.sum(disk_rect_areas(np.ascontiguousarray(pos), radius, x0, y0, x1, y1)))
    return 1.0 - solid / ((x1 - x0) * (y1 - y0))


def porosity_circle(pos: np.ndarray, radius: np.ndarray, cx: float, cy: float, R: float) -> float:
    """Porosity of a circular region of radius R; disks clipped exactly (lens areas)."""
    if not R > 0:
        raise InputError("circle radius", R, "(0, inf) m")
    d = np.hypot(pos[:, 0] - cx, pos[:, 1] - cy)
    solid = float(np.sum(_lens_area(d, radius, R)))
    return 1.0 - solid / (np.pi * R * R)


def disk_area(radius: Any) -> float:
    """The area of whole disks, sum(pi r^2) (m^2): overlaps are not subtracted."""
    return float(np.sum(np.pi * as_float_array("radius", radius) ** 2))


def box_porosity(solid_area: float, width: Any, height: Any) -> float:
    """The paper's n' = 1 - (area of the disks) / (W H): the box under its top plate.

    ``height`` is the plate's height above the floor, so the gap under the plate counts as
    void. The disk area is summed by its owner (:meth:`poro2d.dem.state.Particles.area` for
    a simulation, :func:`disk_area` for measured arrays): each keeps the order of its sum,
    so a porosity written before this function existed is reproduced to the last bit.
    """
    width = check_range("width", width, 0.0, lo_open=True)
    height = check_range("box height", height, 0.0, lo_open=True)
    return 1.0 - solid_area / (width * height)


__all__ = ["box_porosity", "disk_area", "disk_rect_areas", "porosity_circle", "porosity_rect"]
