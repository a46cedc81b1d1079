"""The free surface of a packing and how the top plate (or a segmented lid) sits on it.

The gap between the plate and the surface is void that belongs to the box, not to the
packing: it is what separates the box porosity from the specimen's own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from poro2d.errors import check_int, check_range
from poro2d.measure.disks import check_disks, check_specimen, mass_d50

#: samples of the surface profile per median diameter
PROFILE_SAMPLES_PER_D50 = 16
#: width of the running mean that takes the grain-scale valleys out of the surface, in d50
SURFACE_SMOOTHING_D50 = 2.0
#: a disk whose top is this close below the plate (in d50) touches it: floating-point rounding only
TOUCH_TOL_D50 = 1e-9
_PAIRS_PER_CHUNK = 1 << 21


def profile_bins(width: float, d50: float) -> int:
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
    pos, radius = check_disks(pos, radius)
    width = check_range("width", width, 0.0, lo_open=True)
    if bins is None:
        bins = profile_bins(width, mass_d50(radius))
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
    pos, radius, width, plate_y = check_specimen(pos, radius, width, plate_y)
    d50 = check_range("d50", d50, 0.0, lo_open=True)
    tol = check_range("contact_tol_d50", contact_tol_d50, 0.0) * d50
    if bins is None:
        bins = profile_bins(width, d50)
    _, h = surface_profile(pos, radius, width, bins)
    return plate_from_profile(h, pos, radius, plate_y, d50, tol)


def plate_from_profile(h, pos, radius, plate_y, d50, tol, plate_at_disks=None) -> PlateSurface:
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


def lid_height_at(edges: np.ndarray, heights: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The height of the lid segment above each x."""
    k = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, heights.size - 1)
    return heights[k]


__all__ = [
    "PlateSurface",
    "lid_height_at",
    "plate_from_profile",
    "plate_surface",
    "profile_bins",
    "surface_level",
    "surface_profile",
]
