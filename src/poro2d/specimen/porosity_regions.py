"""The porosity of the specimen itself, measured away from its walls and its free surface.

The paper's box porosity n' = 1 - sum(pi r^2) / (W H_plate) counts the whole box under the
top plate. The plate rests on a few high disks, so the band just under it is mostly gap
(its porosity is about twice the interior's), and flat walls loosen the layer of disks
against them. Both are properties of the box, not of the sand: a user who wants the
porosity of the packing, as a field measurement would give it, needs it measured where
neither reaches. This module gives:

- the free surface of the packing, h(x), and how the plate sits on it (mean and largest
  gap, the share of the plate's width in contact, the disks touching it);
- the porosity of measurement circles (PFC's measurement circles) tiling an interior
  region that keeps ``margin_d50`` median diameters from every wall and from the lowest
  level of the free surface, with the porosity of the whole interior rectangle as a
  second estimate;
- the Laguerre (power, radical) tessellation of the disks in the box: one convex cell per
  disk, tiling the box exactly, giving a local porosity per disk and a third interior
  estimate;
- :func:`measure_specimen`, all of it in one :class:`SpecimenPorosity` (its figure is
  :func:`poro2d.report.specimen_figures.plot_local_porosity`).

Disks are clipped exactly at the edges of every region (no counting of centres), so a
value does not depend on where centres happen to fall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from poro2d.dem.measure import porosity_circle, porosity_rect
from poro2d.errors import InputError, as_float_array, check_int, check_range

#: distance kept from the walls and the free surface, in median diameters (see interior_regions)
DEFAULT_MARGIN_D50 = 2.0
#: radius of a measurement circle, in median diameters
DEFAULT_CIRCLE_D50 = 4.0
#: the smallest circle a small specimen's circles may shrink to (about 15 disks of the paper grading)
MIN_CIRCLE_D50 = 1.5
#: samples of the surface profile per median diameter
PROFILE_SAMPLES_PER_D50 = 16
#: width of the running mean that takes the grain-scale valleys out of the surface, in d50
SURFACE_SMOOTHING_D50 = 2.0
#: a disk whose top is this close below the plate (in d50) touches it: floating-point rounding only
TOUCH_TOL_D50 = 1e-9
#: the Laguerre cells must tile the box to this relative precision, else the tessellation failed
TILING_TOL = 1e-6
_PAIRS_PER_CHUNK = 1 << 21


# --------------------------------------------------------------------------- inputs


def _check_disks(pos: Any, radius: Any) -> tuple[np.ndarray, np.ndarray]:
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


def _check_box(pos: np.ndarray, width: Any, plate_y: Any) -> tuple[float, float]:
    """The box [0, width] x [0, plate_y], with every disk centre strictly inside it.

    The tessellation needs it: a centre outside the box would leave part of the box to the
    mirror image of a disk (see :func:`laguerre_cells`).
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


def _check_d50(d50: Any, radius: np.ndarray) -> float:
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


# --------------------------------------------------------------------------- free surface


def _profile_bins(width: float, d50: float) -> int:
    """Enough samples to resolve a d50 disk's cap: PROFILE_SAMPLES_PER_D50 per d50."""
    return max(2, min(10_000_000, math.ceil(PROFILE_SAMPLES_PER_D50 * width / d50)))


def surface_profile(
    pos: Any, radius: Any, width: Any, bins: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The free surface of the packing: at ``bins`` x samples across the box, the highest
    point of any disk's outline, yc + sqrt(r^2 - (x - xc)^2).

    Returns the sample abscissae (bin centres, m) and the surface height h(x) (m). A sample
    no disk covers gets 0, the floor. The disks are expanded into (disk, sample) pairs in
    chunks of about two million, so memory stays bounded for any number of disks.
    ``bins`` defaults to PROFILE_SAMPLES_PER_D50 samples per median diameter.
    """
    pos, radius = _check_disks(pos, radius)
    width = check_range("width", width, 0.0, lo_open=True)
    if bins is None:
        bins = _profile_bins(width, mass_d50(radius))
    bins = check_int("bins", bins, 2, 10_000_000)
    dx = width / bins
    xc, yc = pos[:, 0], pos[:, 1]
    lo = np.maximum(np.ceil((xc - radius) / dx - 0.5), 0).astype(np.int64)
    hi = np.minimum(np.floor((xc + radius) / dx - 0.5), bins - 1).astype(np.int64)
    count = np.maximum(hi - lo + 1, 0)
    h = np.full(bins, -np.inf)
    for a, b in _chunks(count):
        _raise_profile(h, xc[a:b], yc[a:b], radius[a:b], lo[a:b], count[a:b], dx)
    h[~np.isfinite(h)] = 0.0
    return (np.arange(bins) + 0.5) * dx, h


def _chunks(count: np.ndarray) -> list[tuple[int, int]]:
    """Disk ranges [a, b) that each expand to about _PAIRS_PER_CHUNK (disk, sample) pairs."""
    csum = np.cumsum(count)
    if csum.size == 0 or csum[-1] == 0:
        return []
    cuts = np.searchsorted(csum, np.arange(_PAIRS_PER_CHUNK, csum[-1], _PAIRS_PER_CHUNK), side="right")
    edges = np.unique(np.concatenate([[0], cuts, [count.size]]))
    return list(zip(edges[:-1].tolist(), edges[1:].tolist(), strict=True))


def _raise_profile(h, xc, yc, r, lo, count, dx) -> None:
    """Raise h at each sample a disk covers to the disk's top there (in place)."""
    disk = np.repeat(np.arange(count.size), count)
    first = np.repeat(np.cumsum(count) - count, count)
    k = np.arange(disk.size) - first + lo[disk]
    dxk = (k + 0.5) * dx - xc[disk]
    top = yc[disk] + np.sqrt(np.maximum(r[disk] ** 2 - dxk * dxk, 0.0))
    np.maximum.at(h, k, top)


def surface_level(x: np.ndarray, h: np.ndarray, d50: float) -> float:
    """The lowest level of the free surface at the grain scale (m).

    The profile dips between neighbouring surface disks by up to a radius; those valleys
    are the surface's roughness, not a lower surface. A running mean over
    SURFACE_SMOOTHING_D50 median diameters averages them out (for a row of equal disks it
    is exactly the row's mean level), and its minimum is the deepest the surface really
    comes down: a margin kept below it keeps a region clear of the loose surface layer
    everywhere across the width, including in a broad hollow. A low quantile of the raw
    profile would instead catch a single deep valley between two disks.
    """
    dx = float(x[1] - x[0]) if x.size > 1 else 1.0
    window = max(1, int(round(SURFACE_SMOOTHING_D50 * d50 / dx)))
    if window >= h.size:
        return float(np.mean(h))
    csum = np.concatenate([[0.0], np.cumsum(h)])
    return float(np.min((csum[window:] - csum[:-window]) / window))


@dataclass(frozen=True)
class PlateSurface:
    """How the top plate sits on the free surface.

    ``gap_*``: plate height minus surface height over the plate's width (zero where a disk
    presses into the plate); ``contact_fraction``: the share of the width where that gap is
    below ``contact_tol_m``; ``touching_disks``: disks whose top reaches the plate
    (overlap >= 0, to rounding).
    """

    gap_mean_m: float
    gap_mean_d50: float
    gap_max_m: float
    contact_fraction: float
    touching_disks: int
    contact_tol_m: float


def plate_surface(
    pos: Any,
    radius: Any,
    width: Any,
    plate_y: Any,
    d50: Any,
    contact_tol_d50: Any = 0.05,
    *,
    bins: int | None = None,
) -> PlateSurface:
    """The gap between the top plate and the free surface, and where they touch.

    The mean gap is the gap area under the plate per unit width, the part of the box's
    void that belongs to no packing: it is what separates the box porosity from the
    specimen's. ``contact_tol_d50`` (in d50) sets how close the surface must come to the
    plate to count as in contact; ``bins`` as in :func:`surface_profile`.
    """
    pos, radius = _check_disks(pos, radius)
    width, plate_y = _check_box(pos, width, plate_y)
    d50 = check_range("d50", d50, 0.0, lo_open=True)
    tol = check_range("contact_tol_d50", contact_tol_d50, 0.0) * d50
    if bins is None:
        bins = _profile_bins(width, d50)
    _, h = surface_profile(pos, radius, width, bins)
    return _plate_from_profile(h, pos, radius, plate_y, d50, tol)


def _plate_from_profile(h, pos, radius, plate_y, d50, tol, plate_at_disks=None) -> PlateSurface:
    """Gap and contact of the surface ``h`` under a plate at ``plate_y`` (one height, or one
    per profile bin for a lid, with ``plate_at_disks`` its height above each disk)."""
    gap = np.maximum(plate_y - h, 0.0)
    over = plate_y if plate_at_disks is None else plate_at_disks
    touching = int(np.count_nonzero(pos[:, 1] + radius >= over - TOUCH_TOL_D50 * d50))
    return PlateSurface(
        gap_mean_m=float(gap.mean()),
        gap_mean_d50=float(gap.mean() / d50),
        gap_max_m=float(gap.max()),
        contact_fraction=float(np.mean(gap < tol)),
        touching_disks=touching,
        contact_tol_m=float(tol),
    )


# --------------------------------------------------------------------------- interior regions


@dataclass(frozen=True)
class InteriorRegions:
    """Measurement circles in the interior rectangle, and the rectangle's own porosity.

    ``rect``: (x0, y0, x1, y1) in m; ``centres``: (k, 2) circle centres; ``porosity``: (k,)
    the porosity of each circle; ``surface_level_m``: the surface level the top margin was
    kept from (:func:`surface_level`).
    """

    rect: tuple[float, float, float, float]
    circle_radius_m: float
    centres: np.ndarray = field(repr=False)
    porosity: np.ndarray = field(repr=False)
    rect_porosity: float
    surface_level_m: float

    @property
    def count(self) -> int:
        return int(self.porosity.size)

    @property
    def mean(self) -> float:
        return float(np.mean(self.porosity))

    @property
    def std(self) -> float:
        """Sample standard deviation (ddof = 1) over the circles: their spread, not an error."""
        return float(np.std(self.porosity, ddof=1))


def interior_rect(
    width: float, top: float, margin: float, circle_radius: float
) -> tuple[float, float, float, float]:
    """The rectangle keeping ``margin`` from the side walls, the floor and the level ``top``.

    Refuses (InputError naming ``margin_d50``) a rectangle with room for fewer than three
    circles: a porosity from one or two circles has no spread to judge it by.
    """
    rect = (margin, margin, width - margin, top - margin)
    nx, ny = _grid_shape(rect, circle_radius)
    if nx * ny < 3:
        wi, hi = rect[2] - rect[0], rect[3] - rect[1]
        raise InputError(
            "margin_d50",
            f"{margin:.4g} m",
            f"a margin leaving room for 3 circles of radius {circle_radius:.4g} m (circle_d50)",
            f"specimen too small for the margin: the interior is {max(wi, 0):.4g} m x {max(hi, 0):.4g} m "
            f"under a surface at {top:.4g} m in a box {width:.4g} m wide; fits {nx * ny} circle(s)",
        )
    return rect


def fitted_radius(rect: tuple[float, float, float, float], R: float, R_min: float) -> float:
    """The largest circle radius up to ``R`` (not below ``R_min``) that fits three circles in ``rect``.

    A small specimen (the quick box is 9 d50 tall) has no room for three circles of 4 d50:
    there the circles shrink, down to ``R_min``, rather than the measurement being refused.
    When even ``R_min`` does not fit three, ``R`` is returned and :func:`interior_rect` refuses.
    """
    wi, hi = rect[2] - rect[0], rect[3] - rect[1]
    if wi <= 0 or hi <= 0:
        return R
    # m rows of ceil(3 / m) circles: the radius each arrangement allows, the largest wins
    best = max(min(R, hi / (2.0 * m), wi / (2.0 * math.ceil(3 / m))) for m in (1, 2, 3))
    return best if best >= R_min else R


def _grid_shape(rect: tuple[float, float, float, float], R: float) -> tuple[int, int]:
    """How many circles of radius R fit side by side across and up the rectangle."""
    wi, hi = rect[2] - rect[0], rect[3] - rect[1]
    fit = 1.0 + 1e-12  # a rectangle exactly k diameters wide holds k circles despite rounding
    nx = int(math.floor(wi / (2.0 * R) * fit)) if wi > 0 else 0
    ny = int(math.floor(hi / (2.0 * R) * fit)) if hi > 0 else 0
    return nx, ny


def circle_centres(rect: tuple[float, float, float, float], R: float) -> np.ndarray:
    """Centres of as many non-overlapping circles of radius R as a square grid fits.

    The grid is spread evenly over the rectangle (spacing >= 2R) rather than packed into a
    corner, so the circles sample the whole interior.
    """
    nx, ny = _grid_shape(rect, R)
    x0, y0, x1, y1 = rect
    xs = x0 + (x1 - x0) / nx * (np.arange(nx) + 0.5)
    ys = y0 + (y1 - y0) / ny * (np.arange(ny) + 0.5)
    gx, gy = np.meshgrid(xs, ys)
    return np.column_stack([gx.ravel(), gy.ravel()])


def interior_regions(
    pos: Any,
    radius: Any,
    width: Any,
    plate_y: Any,
    d50: Any = None,
    margin_d50: Any = DEFAULT_MARGIN_D50,
    circle_d50: Any = DEFAULT_CIRCLE_D50,
    *,
    profile: tuple[np.ndarray, np.ndarray] | None = None,
) -> InteriorRegions:
    """Porosity of measurement circles tiling the interior, and of the interior rectangle.

    The interior keeps ``margin_d50`` median diameters from the left, right and bottom
    walls and from the free surface's lowest level (:func:`surface_level`). The default,
    2 d50: against a flat wall disks cannot interlock with a layer beyond it, so the first
    layer, 0.5-1 d thick, is loose; the top of the packing, under a plate that rests on a
    few disks, is loose over a similar depth. On the paper specimen the interior rectangle's
    porosity moves by less than 0.002 between margins of 0.5 and 4 d50, so 2 d50 clears the
    wall layers and leaves room for circles in the quick box (9 d50 tall). Each circle has radius
        ``circle_d50`` d50 (default 4: some 60 disks of the paper grading, enough for a stable
    value, small enough for several circles to show the spread), smaller where three such
    circles do not fit (:func:`fitted_radius`, not below ``MIN_CIRCLE_D50``). ``profile`` is (x, h) of
    :func:`surface_profile` if already computed. Disks are clipped exactly at each circle
    and at the rectangle.
    """
    pos, radius = _check_disks(pos, radius)
    width, plate_y = _check_box(pos, width, plate_y)
    d50 = _check_d50(d50, radius)
    margin = check_range("margin_d50", margin_d50, 0.0) * d50
    R = check_range("circle_d50", circle_d50, 0.0, lo_open=True) * d50
    x, h = profile if profile is not None else surface_profile(pos, radius, width, _profile_bins(width, d50))
    level = min(surface_level(x, h, d50), plate_y)
    R = fitted_radius((margin, margin, width - margin, level - margin), R, MIN_CIRCLE_D50 * d50)
    rect = interior_rect(width, level, margin, R)
    centres = circle_centres(rect, R)
    values = np.array([_circle_porosity(pos, radius, c, R) for c in centres])
    return InteriorRegions(
        rect=tuple(float(v) for v in rect),
        circle_radius_m=float(R),
        centres=centres,
        porosity=values,
        rect_porosity=porosity_rect(pos, radius, *rect),
        surface_level_m=float(level),
    )


def _circle_porosity(pos: np.ndarray, radius: np.ndarray, centre: np.ndarray, R: float) -> float:
    """porosity_circle on the disks whose bounding box reaches the circle (the rest add nothing)."""
    reach = R + radius
    near = (np.abs(pos[:, 0] - centre[0]) < reach) & (np.abs(pos[:, 1] - centre[1]) < reach)
    return porosity_circle(pos[near], radius[near], float(centre[0]), float(centre[1]), R)


# --------------------------------------------------------------------------- Laguerre tessellation


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

    pos, radius = _check_disks(pos, radius)
    width, plate_y = _check_box(pos, width, plate_y)
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


# --------------------------------------------------------------------------- summary


@dataclass(frozen=True)
class PorosityDetails:
    """The arrays behind a :class:`SpecimenPorosity`, for figures and further analysis.

    ``surface_x``/``surface_h``: the free surface profile (m); ``interior``: the measurement
    circles and the interior rectangle; ``cells``: the Laguerre cells with their local
    porosity.
    """

    surface_x: np.ndarray = field(repr=False)
    surface_h: np.ndarray = field(repr=False)
    interior: InteriorRegions
    cells: LaguerreCells


@dataclass(frozen=True)
class SpecimenPorosity:
    """Porosities of a specimen in a box under a top plate, and how the plate sits on it.

    - ``box_porosity``: the paper's n' = 1 - sum(pi r^2) / (W H_plate): whole disks, overlaps
      not subtracted, the gap under the plate included;
    - ``interior_porosity`` (mean over the measurement circles), with ``_std`` (ddof 1),
      ``_min``, ``_max`` and ``interior_regions`` (how many circles): the specimen's own
      porosity, ``margin_d50`` d50 away from walls and free surface;
    - ``interior_rect_porosity``: the whole interior rectangle (disks clipped exactly);
    - ``laguerre_interior_porosity``: disk area over Laguerre cell area, disks centred in the
      interior rectangle;
    - ``surface_*``, ``plate_*``: the gap between plate and free surface (m and d50), the
      share of the plate's width in contact, the disks touching the plate;
    - ``surface_level_m``: the free surface's lowest smoothed level, the interior's top plus
      the margin.

    ``details`` holds the arrays (not part of :meth:`to_dict`, nor of equality).
    """

    box_porosity: float
    interior_porosity: float
    interior_porosity_std: float
    interior_porosity_min: float
    interior_porosity_max: float
    interior_regions: int
    interior_rect_porosity: float
    laguerre_interior_porosity: float
    margin_d50: float
    circle_radius_m: float
    surface_gap_mean_m: float
    surface_gap_mean_d50: float
    surface_gap_max_m: float
    plate_contact_fraction: float
    plate_touching_disks: int
    d50_m: float
    surface_level_m: float
    details: PorosityDetails | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict[str, float | int]:
        """The numbers as plain Python floats and ints (JSON-ready; no arrays)."""
        out: dict[str, float | int] = {}
        for f in fields(self):
            if f.name == "details":
                continue
            value = getattr(self, f.name)
            out[f.name] = int(value) if f.type == "int" else float(value)
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SpecimenPorosity:
        """The numbers read back from :meth:`to_dict` (without the arrays)."""
        names = [f.name for f in fields(cls) if f.name != "details"]
        return cls(**{k: data[k] for k in names})


def box_porosity(radius: Any, width: Any, plate_y: Any) -> float:
    """The paper's n' = 1 - sum(pi r^2) / (W H_plate), exactly as it defines it."""
    radius = as_float_array("radius", radius)
    width = check_range("width", width, 0.0, lo_open=True)
    plate_y = check_range("plate_y", plate_y, 0.0, lo_open=True)
    return 1.0 - float(np.sum(np.pi * radius**2)) / (width * plate_y)


def measure_specimen(
    pos: Any,
    radius: Any,
    width: Any,
    plate_y: Any,
    d50: Any = None,
    margin_d50: Any = DEFAULT_MARGIN_D50,
    circle_d50: Any = DEFAULT_CIRCLE_D50,
    contact_tol_d50: Any = 0.05,
    lid: tuple[Any, Any] | None = None,
) -> SpecimenPorosity:
    """All porosity measures of a specimen in the box [0, width] x [0, plate_y].

    ``d50`` defaults to :func:`mass_d50` of the disks; ``margin_d50`` and ``circle_d50``
    as in :func:`interior_regions`, ``contact_tol_d50`` as in :func:`plate_surface`.
    ``lid``: (edges, heights) of a segmented lid under ``plate_y`` (the fill acceptance,
    :mod:`poro2d.criterion.lid`): the box porosity is then that of the area under the
    lid, and the gap and contact are measured to the lid instead of the flat plate.
    """
    pos, radius = _check_disks(pos, radius)
    width, plate_y = _check_box(pos, width, plate_y)
    d50 = _check_d50(d50, radius)
    margin_d50 = check_range("margin_d50", margin_d50, 0.0)
    tol = check_range("contact_tol_d50", contact_tol_d50, 0.0) * d50
    x, h = surface_profile(pos, radius, width, _profile_bins(width, d50))
    if lid is None:
        plate = _plate_from_profile(h, pos, radius, plate_y, d50, tol)
        box = box_porosity(radius, width, plate_y)
    else:
        edges, heights = _check_lid(lid, width, plate_y)
        plate = _plate_from_profile(
            h,
            pos,
            radius,
            lid_height_at(edges, heights, x),
            d50,
            tol,
            lid_height_at(edges, heights, pos[:, 0]),
        )
        box = 1.0 - float(np.sum(np.pi * radius**2)) / float(np.sum(np.diff(edges) * heights))
    interior = interior_regions(pos, radius, width, plate_y, d50, margin_d50, circle_d50, profile=(x, h))
    cells = laguerre_cells(pos, radius, width, plate_y)
    return SpecimenPorosity(
        box_porosity=box,
        interior_porosity=interior.mean,
        interior_porosity_std=interior.std,
        interior_porosity_min=float(np.min(interior.porosity)),
        interior_porosity_max=float(np.max(interior.porosity)),
        interior_regions=interior.count,
        interior_rect_porosity=float(interior.rect_porosity),
        laguerre_interior_porosity=laguerre_porosity(cells, pos, radius, interior.rect),
        margin_d50=float(margin_d50),
        circle_radius_m=interior.circle_radius_m,
        surface_gap_mean_m=plate.gap_mean_m,
        surface_gap_mean_d50=plate.gap_mean_d50,
        surface_gap_max_m=plate.gap_max_m,
        plate_contact_fraction=plate.contact_fraction,
        plate_touching_disks=plate.touching_disks,
        d50_m=float(d50),
        surface_level_m=interior.surface_level_m,
        details=PorosityDetails(surface_x=x, surface_h=h, interior=interior, cells=cells),
    )


def _check_lid(lid: tuple[Any, Any], width: float, plate_y: float) -> tuple[np.ndarray, np.ndarray]:
    """A lid's (edges, heights): K + 1 rising edges from 0 to the width, K heights in (0, plate_y]."""
    edges = as_float_array("lid edges", lid[0])
    heights = as_float_array("lid heights", lid[1])
    if edges.ndim != 1 or heights.shape != (edges.size - 1,) or heights.size < 1:
        raise InputError("lid", f"{edges.size} edges, {heights.size} heights", "K + 1 edges and K heights")
    if not (np.all(np.diff(edges) > 0) and np.isclose(edges[0], 0.0) and np.isclose(edges[-1], width)):
        raise InputError("lid edges", edges.tolist(), f"rising from 0 to the width {width:g} m")
    if not (np.all(heights > 0.0) and np.all(heights <= plate_y)):
        raise InputError("lid heights", heights.tolist(), f"(0, {plate_y:g}] m")
    return edges, heights


def lid_height_at(edges: np.ndarray, heights: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The height of the lid segment above each x."""
    k = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, heights.size - 1)
    return heights[k]


__all__ = [
    "DEFAULT_CIRCLE_D50",
    "DEFAULT_MARGIN_D50",
    "InteriorRegions",
    "LaguerreCells",
    "PlateSurface",
    "PorosityDetails",
    "SpecimenPorosity",
    "box_porosity",
    "circle_centres",
    "interior_rect",
    "interior_regions",
    "laguerre_cells",
    "laguerre_porosity",
    "mass_d50",
    "measure_specimen",
    "plate_surface",
    "surface_level",
    "surface_profile",
]
