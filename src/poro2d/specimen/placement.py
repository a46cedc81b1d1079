"""Non-overlapping random placement of disks in a rectangular band.

A layer of the multilayer specimen needs a solid fraction near 0.86 in its band; random
sequential placement jams far below that (around 0.55 for polydisperse disks). So the
default is *random placement at reduced radius*: every radius is multiplied by one factor
``s < 1`` chosen so that the reduced disks fill about ``target_fraction`` (0.40) of the band,
the disks are placed from the largest down, each at the first of up to ``max_attempts``
uniform random positions that overlaps nothing, and if a disk finds no free spot the whole
band is restarted with ``s`` reduced by ``shrink`` (3 %). The engine then grows the disks
back to full size inside the confined band. When the band is loose enough
(``target_fraction`` or less at full size) ``s`` is 1; ``full_size=True`` insists on ``s = 1``.

Overlap checks use a cell grid (cells at least one largest diameter wide, a linked list of
the disks in each cell), so each check looks at the 3 x 3 cells around the candidate. The
whole placement of one attempt runs in one compiled function.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from poro2d.errors import InputError, check_range

__all__ = ["Band", "Placement", "place_disks", "solid_fraction"]


@dataclass(frozen=True)
class Band:
    """The rectangle [x0, x1] x [y0, y1] (metres) that the disks must lie fully inside."""

    x0: float
    x1: float
    y0: float
    y1: float

    def __post_init__(self) -> None:
        for name in ("x0", "x1", "y0", "y1"):
            v = check_range(f"band.{name}", getattr(self, name))
            if not math.isfinite(v):
                raise InputError(f"band.{name}", getattr(self, name), "a finite number")
            object.__setattr__(self, name, v)
        if self.x1 <= self.x0:
            raise InputError("band.x1", self.x1, f"> band.x0 = {self.x0}")
        if self.y1 <= self.y0:
            raise InputError("band.y1", self.y1, f"> band.y0 = {self.y0}")

    @property
    def width(self) -> float:
        return self.x1 - self.x0

    @property
    def height(self) -> float:
        return self.y1 - self.y0

    @property
    def area(self) -> float:
        return self.width * self.height


@dataclass(frozen=True)
class Placement:
    """Result of :func:`place_disks`, in the order of the radii passed in.

    ``positions`` (N, 2) are disk centres; ``radii`` are the placed radii, i.e. the input
    radii times ``scale``; ``restarts`` counts how often ``scale`` was reduced.
    """

    positions: np.ndarray
    radii: np.ndarray
    scale: float
    restarts: int


def _as_band(band: Band | tuple[float, float, float, float] | Any) -> Band:
    if isinstance(band, Band):
        return band
    try:
        x0, x1, y0, y1 = band
    except (TypeError, ValueError):
        raise InputError("band", band, "a Band or a tuple (x0, x1, y0, y1)") from None
    return Band(x0, x1, y0, y1)


def _as_radii(radii: Any) -> np.ndarray:
    try:
        r = np.asarray(radii, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError("radii", radii, "a list of radii in m") from None
    if r.ndim != 1 or r.size == 0:
        raise InputError("radii", getattr(r, "shape", radii), "a non-empty 1-D list of radii")
    if not np.all(np.isfinite(r)) or np.any(r <= 0.0):
        raise InputError("radii", float(r.min()), "finite radii > 0")
    return r


def solid_fraction(radii: Any, band: Band | tuple[float, float, float, float]) -> float:
    """Total disk area over the band area."""
    r = _as_radii(radii)
    return float(np.sum(np.pi * r * r)) / _as_band(band).area


@njit(cache=True)
def _place_kernel(
    r: np.ndarray,
    x0: float,
    x1: float,
    y0: float,
    y1: float,
    max_attempts: int,
    rng: np.random.Generator,
    out: np.ndarray,
) -> int:
    """Random sequential placement of r (largest first) in the band; returns #placed.

    Writes centres into out[:, 0:2]. Stops at the first disk that finds no free position.
    """
    n = r.shape[0]
    rmax = 0.0
    for i in range(n):
        if r[i] > rmax:
            rmax = r[i]
    w = x1 - x0
    h = y1 - y0
    nx = max(1, int(w / (2.0 * rmax)))
    ny = max(1, int(h / (2.0 * rmax)))
    cw = w / nx  # >= 2 rmax, so any overlapping neighbour is in the 3 x 3 block
    ch = h / ny
    head = np.full(nx * ny, -1, dtype=np.int64)
    nxt = np.full(n, -1, dtype=np.int64)
    for i in range(n):
        ri = r[i]
        lox = x0 + ri
        spanx = w - 2.0 * ri
        loy = y0 + ri
        spany = h - 2.0 * ri
        placed = False
        for _ in range(max_attempts):
            x = lox + spanx * rng.random()
            y = loy + spany * rng.random()
            cx = min(int((x - x0) / cw), nx - 1)
            cy = min(int((y - y0) / ch), ny - 1)
            ok = True
            for gy in range(max(cy - 1, 0), min(cy + 2, ny)):
                for gx in range(max(cx - 1, 0), min(cx + 2, nx)):
                    j = head[gy * nx + gx]
                    while j >= 0:
                        dx = x - out[j, 0]
                        dy = y - out[j, 1]
                        s = ri + r[j]
                        if dx * dx + dy * dy < s * s:
                            ok = False
                            break
                        j = nxt[j]
                    if not ok:
                        break
                if not ok:
                    break
            if ok:
                out[i, 0] = x
                out[i, 1] = y
                c = cy * nx + cx
                nxt[i] = head[c]
                head[c] = i
                placed = True
                break
        if not placed:
            return i
    return n


def _restart_rng(seed: int, restart: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed, restart]))


def _check_options(
    seed: Any, target_fraction: Any, shrink: Any, max_attempts: Any, max_restarts: Any
) -> tuple[float, float]:
    """Refuse bad options before any disk is placed; returns (target_fraction, shrink) as floats."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise InputError("seed", seed, "an integer >= 0")
    target = check_range("target_fraction", target_fraction, 0.0, 0.8, lo_open=True)
    shrink_f = check_range("shrink", shrink, 0.0, 1.0, lo_open=True, hi_open=True)
    if isinstance(max_attempts, bool) or not isinstance(max_attempts, int | np.integer):
        raise InputError("max_attempts", max_attempts, "an integer >= 1")
    if max_attempts < 1:
        raise InputError("max_attempts", max_attempts, "an integer >= 1")
    if isinstance(max_restarts, bool) or not isinstance(max_restarts, int | np.integer):
        raise InputError("max_restarts", max_restarts, "an integer >= 0")
    if max_restarts < 0:
        raise InputError("max_restarts", max_restarts, "an integer >= 0")
    return target, shrink_f


def _fitting_fraction(r: np.ndarray, b: Band) -> float:
    """Solid fraction of the disks in the band, refusing a band that no placement could fill."""
    d_max = 2.0 * float(r.max())
    if d_max > b.height or d_max > b.width:
        raise InputError(
            "radii",
            f"largest diameter {d_max:.6g} m",
            f"diameters <= band height {b.height:.6g} m and width {b.width:.6g} m",
        )
    phi = float(np.sum(np.pi * r * r)) / b.area
    if phi >= 1.0:
        raise InputError("radii", f"solid fraction {phi:.4f}", "total disk area below the band area")
    return phi


def _no_placement(full_size: bool, phi: float, max_restarts: int, last_scale: float) -> InputError:
    """The error when every try failed: it says which option to change."""
    if full_size:
        return InputError(
            "full_size",
            True,
            "only for bands loose enough for random placement at full size",
            hint=f"solid fraction {phi:.3f} here; use full_size=False to place at reduced radius",
        )
    return InputError(
        "max_restarts",
        max_restarts,
        "enough restarts to find a reduction factor",
        hint=f"stopped at scale {last_scale:.3g}; lower target_fraction or raise max_attempts",
    )


def place_disks(
    radii: Any,
    band: Band | tuple[float, float, float, float],
    seed: int,
    *,
    full_size: bool = False,
    target_fraction: float = 0.40,
    max_attempts: int = 2000,
    shrink: float = 0.97,
    max_restarts: int = 60,
) -> Placement:
    """Place disks of ``radii`` [m] without overlap, fully inside ``band`` (x0, x1, y0, y1).

    Default: random placement at reduced radius (see the module docstring); the factor used
    is ``Placement.scale`` (1 when the band is loose enough). ``full_size=True`` places at
    scale 1 or raises InputError (it tries ``max_restarts`` + 1 seeds at most, but at most 5).
    Deterministic for a given integer ``seed``.
    """
    r = _as_radii(radii)
    b = _as_band(band)
    target, shrink_f = _check_options(seed, target_fraction, shrink, max_attempts, max_restarts)
    phi = _fitting_fraction(r, b)

    order = np.argsort(-r, kind="stable")
    r_sorted = np.ascontiguousarray(r[order])
    out = np.zeros((r.size, 2))
    if full_size:
        scale = 1.0
        tries = min(max_restarts, 4) + 1
    else:
        scale = min(1.0, math.sqrt(target / phi))
        tries = max_restarts + 1
    for k in range(tries):
        placed = _place_kernel(
            r_sorted * scale,
            b.x0,
            b.x1,
            b.y0,
            b.y1,
            int(max_attempts),
            _restart_rng(int(seed), k),
            out,
        )
        if placed == r.size:
            positions = np.empty_like(out)
            positions[order] = out
            return Placement(positions=positions, radii=r * scale, scale=scale, restarts=k)
        if not full_size:
            scale *= shrink_f
    raise _no_placement(full_size, phi, max_restarts, scale / shrink_f)
