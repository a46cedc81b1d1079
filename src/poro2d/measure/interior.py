"""The specimen's interior porosity: measurement circles clear of the walls and the free surface.

The interior keeps a margin of median diameters from every wall and from the lowest level of
the free surface, where neither the loose layer against a flat wall nor the loose top of the
packing reaches; circles tiling it (PFC's measurement circles) give the porosity with its
spread, the whole interior rectangle a second estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from poro2d.errors import InputError, check_range
from poro2d.measure.disks import check_d50, check_specimen
from poro2d.measure.porosity import porosity_circle, porosity_rect
from poro2d.measure.surface import profile_bins, surface_level, surface_profile

#: distance kept from the walls and the free surface, in median diameters (see interior_regions)
DEFAULT_MARGIN_D50 = 2.0
#: radius of a measurement circle, in median diameters
DEFAULT_CIRCLE_D50 = 4.0
#: the smallest circle a small specimen's circles may shrink to (about 15 disks of the paper grading)
MIN_CIRCLE_D50 = 1.5


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
    pos, radius, width, plate_y = check_specimen(pos, radius, width, plate_y)
    d50 = check_d50(d50, radius)
    margin = check_range("margin_d50", margin_d50, 0.0) * d50
    R = check_range("circle_d50", circle_d50, 0.0, lo_open=True) * d50
    x, h = profile if profile is not None else surface_profile(pos, radius, width, profile_bins(width, d50))
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


__all__ = [
    "DEFAULT_CIRCLE_D50",
    "DEFAULT_MARGIN_D50",
    "MIN_CIRCLE_D50",
    "InteriorRegions",
    "circle_centres",
    "fitted_radius",
    "interior_rect",
    "interior_regions",
]
