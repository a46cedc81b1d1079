"""The Laguerre (power) tessellation of the disks in a box: a local porosity per disk.

One convex cell per disk tiles the box exactly; disk area over cell area is each disk's local
porosity, and over the disks centred in a region a third estimate of its porosity.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from poro2d.errors import InputError
from poro2d.measure.disks import check_specimen

#: the Laguerre cells must tile the box to this relative precision, else the tessellation failed
TILING_TOL = 1e-6


@dataclass(frozen=True)
class LaguerreCells:
    """The Laguerre (power) cells of the disks, clipped to the box.

    Cell i is the polygon ``vertices[offsets[i]:offsets[i + 1]]`` (counter-clockwise, m;
    consecutive vertices may coincide where four or more disks meet at one point).
    ``area``: (n,) cell areas; ``local_porosity``: 1 - pi r^2 / area, NaN for an empty cell.
    ``empty``: how many disks have no cell (see :func:`laguerre_cells`).
    """

    vertices: np.ndarray = field(repr=False)
    offsets: np.ndarray = field(repr=False)
    area: np.ndarray = field(repr=False)
    local_porosity: np.ndarray = field(repr=False)
    empty: int

    def polygons(self) -> list[np.ndarray]:
        """One (k, 2) vertex array per disk, empty ones included (shape (0, 2))."""
        return np.split(self.vertices, self.offsets[1:-1])


def laguerre_cells(pos: Any, radius: Any, width: Any, plate_y: Any) -> LaguerreCells:
    """The Laguerre tessellation of the disks in the box [0, width] x [0, plate_y].

    In a power diagram a point belongs to the disk of least power |p - c|^2 - r^2, so the
    boundary between two disks of different size is their radical line, not the mid-line
    of the centres: a big disk gets a cell in proportion to its size, and for disks that do
    not overlap every disk lies inside its own cell. A Voronoi diagram of the centres would
    cut big disks and hand their area to small neighbours; for equal disks the two agree.

    The diagram is the dual of the regular triangulation, the lower convex hull of the
    points lifted to (x, y, x^2 + y^2 - r^2). Each disk is mirrored across the four sides of
    the box: a disk and its image have equal power on the side itself, which therefore
    bounds the disk's cell, and no image is nearer in power than its original to a point of
    the box, so the originals' cells tile the box exactly. Only a disk overlapping others a
    lot (a small disk mostly inside a big one, or two at the same place) can lose its cell
    entirely; it then gets area 0 and local porosity NaN, and its solid is counted in its
    neighbours' cells. Raises RuntimeError if the cells do not tile the box to TILING_TOL.
    """
    from scipy.spatial import ConvexHull

    pos, radius, width, plate_y = check_specimen(pos, radius, width, plate_y)
    n = pos.shape[0]
    # centred and scaled to O(1), so the lifted coordinates keep their precision in qhull
    origin, scale = np.array([0.5 * width, 0.5 * plate_y]), max(width, plate_y)
    pts, rad = _mirrored(pos, radius, width, plate_y)
    p = (pts - origin) / scale
    w = (rad / scale) ** 2
    hull = ConvexHull(np.column_stack([p, np.einsum("ij,ij->i", p, p) - w]))
    tri = hull.simplices[hull.equations[:, 2] < -1e-10]  # the lower hull: the regular triangulation
    tri = tri[np.any(tri < n, axis=1)]
    vert = _power_vertices(p, w, tri)
    vertices, offsets, area = _cells(tri, vert, n)
    vertices = vertices * scale + origin
    area = area * scale * scale
    _check_tiling(area, width * plate_y)
    with np.errstate(divide="ignore", invalid="ignore"):
        local = np.where(area > 0, 1.0 - np.pi * radius**2 / area, np.nan)
    return LaguerreCells(
        vertices=vertices, offsets=offsets, area=area, local_porosity=local, empty=int(np.sum(area <= 0))
    )


def _mirrored(pos: np.ndarray, radius: np.ndarray, width: float, top: float) -> tuple[np.ndarray, np.ndarray]:
    """The disks, then their images across the left, right, bottom and top sides of the box."""
    x, y = pos[:, 0], pos[:, 1]
    images = [
        pos,
        np.column_stack([-x, y]),
        np.column_stack([2.0 * width - x, y]),
        np.column_stack([x, -y]),
        np.column_stack([x, 2.0 * top - y]),
    ]
    return np.vstack(images), np.tile(radius, len(images))


def _power_vertices(p: np.ndarray, w: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """The point of equal power to the three disks of each triangle.

    Solved relative to the first vertex, q = v - p_a: 2 q . (p_b - p_a) = |p_b - p_a|^2 -
    w_b + w_a, and the same for c; the differences keep the digits that the plane equation
    of the lifted facet would lose.
    """
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    d1, d2 = p[b] - p[a], p[c] - p[a]
    r1 = 0.5 * (np.einsum("ij,ij->i", d1, d1) - w[b] + w[a])
    r2 = 0.5 * (np.einsum("ij,ij->i", d2, d2) - w[c] + w[a])
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    qx = (r1 * d2[:, 1] - r2 * d1[:, 1]) / det
    qy = (d1[:, 0] * r2 - d2[:, 0] * r1) / det
    return p[a] + np.column_stack([qx, qy])


def _cells(tri: np.ndarray, vert: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each original disk's cell from the power vertices of its triangles, and its area.

    A disk's cell is the convex polygon of the power vertices of the triangles around it,
    in order of angle about their mean (inside a convex polygon, so the order is the
    polygon's). The area is the shoelace sum over each ring, all disks at once.
    """
    owner = tri.ravel()
    corner = np.repeat(np.arange(tri.shape[0]), 3)
    keep = owner < n
    owner, v = owner[keep], vert[corner[keep]]
    count = np.bincount(owner, minlength=n)
    safe = np.maximum(count, 1)
    mx = np.bincount(owner, v[:, 0], n) / safe
    my = np.bincount(owner, v[:, 1], n) / safe
    angle = np.arctan2(v[:, 1] - my[owner], v[:, 0] - mx[owner])
    order = np.lexsort((angle, owner))
    owner, v = owner[order], v[order]
    offsets = np.concatenate([[0], np.cumsum(count)])
    nxt = np.arange(owner.size) + 1
    last = offsets[1:][count > 0] - 1
    nxt[last] = offsets[:-1][count > 0]
    # coordinates relative to the ring's mean: the same area, fewer digits cancelled
    rx, ry = v[:, 0] - mx[owner], v[:, 1] - my[owner]
    cross = rx * ry[nxt] - rx[nxt] * ry
    area = 0.5 * np.bincount(owner, cross, n)
    area[count < 3] = 0.0
    return v, offsets, area


def _check_tiling(area: np.ndarray, box_area: float) -> None:
    err = abs(float(np.sum(area)) - box_area) / box_area
    if not err <= TILING_TOL:
        raise RuntimeError(
            f"Laguerre cells cover the box to a relative error of {err:.3g} (> {TILING_TOL:g}): "
            "the tessellation failed on these disks"
        )


def laguerre_porosity(
    cells: LaguerreCells, pos: np.ndarray, radius: np.ndarray, rect: tuple[float, float, float, float]
) -> float:
    """1 - (area of the disks) / (area of their cells), over the disks centred in ``rect``.

    Whole disks against whole cells: the cells of the disks centred in a region tile a
    region of nearly the same shape, so this estimate needs no clipping and does not mix a
    disk with its neighbours' voids. Disks with an empty cell count their solid (it lies
    in their neighbours' cells).
    """
    x0, y0, x1, y1 = rect
    x, y = pos[:, 0], pos[:, 1]
    inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    total = float(np.sum(cells.area[inside]))
    if total <= 0:
        raise InputError("rect", rect, "a region holding at least one disk centre")
    return 1.0 - float(np.sum(np.pi * radius[inside] ** 2)) / total


__all__ = ["TILING_TOL", "LaguerreCells", "laguerre_cells", "laguerre_porosity"]
