"""The residual strength of a direct shear test, read only where the specimen has stopped dilating.

A residual is the strength of a specimen that shears at constant volume. While the plate
still rises the shear stress holds a dilatancy part: by Taylor's energy balance, averaged over
a stretch of shear, mean(tau) / sigma = mu + (rise of the plate) / (shear displacement), so a
plate still rising at 0.05 mm per mm adds 0.05 to tau/sigma. The mean over the last part of a
curve (``poro2d strength``'s window) is therefore no residual unless the plate has stopped.

The plate of a box of a few thousand disks never stops still: it rises and falls by a few
tenths of a millimetre as force chains build and buckle, so its slope over a few millimetres
swings by +-0.05 to 0.1 long after the dilation has ended (measured on the paper's box,
docs/shear.md). What Taylor's balance needs is the plate's net rate over the stretch averaged.
So the rate here is the least-squares slope of the plate's height against shear displacement,
and the residual stretch is the longest final stretch of the curve, at least
:data:`MIN_STRETCH_DIAMETERS` mean disk diameters long, whose slope, and the slope of each of its
two halves (a rise followed by a fall is no rest), stay within :data:`DILATION_RATE_LIMIT`: the
dilatancy left in its tau/sigma is below that limit. A curve with no such stretch says "not
reached" and gives no number.

Beside tau over the plate's stress (what every result reports) it gives tau over the shear
plane's own normal stress (``plane_normal_stress_kpa`` of the curve): the side walls' friction
moves load between plate and plane (docs/shear.md, "What reaches the shear plane"), and a
material's friction is the ratio on the plane.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from poro2d.typed_result import TypedResult

#: the largest |net d(plate height) / d(shear displacement)| of a stretch read as "dilation stopped":
#: by Taylor's balance the dilatancy left in its mean tau/sigma is below this
DILATION_RATE_LIMIT = 0.02
#: the shortest residual stretch, in mean disk diameters: over shorter ones the plate's rise and
#: fall by a few tenths of a millimetre reads as a rate beyond the limit
MIN_STRETCH_DIAMETERS = 4.0
#: the part of each test's shear displacement, at its end, that the strength study's residual averages
TAIL_FRACTION = 0.2


@dataclass(eq=False)
class ResidualAtRest(TypedResult):
    """A test's residual read where the plate has stopped rising (a test's ``residual_dilation_stopped``).

    ``reached``: whether the curve ends in a stretch at least ``min_stretch_m`` long whose
    plate slope, and its halves' slopes, stay within ``rate_limit``; ``status`` says so in
    words. The stretch runs from ``start_mm`` to ``end_mm`` of shear displacement; over it, the
    means of the shear stress, the plate's and the plane's normal stress and the upper walls'
    upward friction (kPa), the shear stress over each normal stress (``stress_ratio``: the
    plate's, ``plane_stress_ratio``: the plane's), the plane's share of the plate's stress, and
    the plate's slope (``dilation_rate``) and the larger of its halves' (``max_part_rate``,
    absolute). ``end_rate``: the slope over the last ``min_stretch_m`` of the curve, reached or
    not. The numbers are None when it was not reached (the plane's when the curve has no plane
    record, an earlier poro2d's).
    """

    reached: bool
    status: str
    rate_limit: float
    min_stretch_m: float
    start_mm: float | None
    end_mm: float
    shear_stress_kpa: float | None
    normal_stress_kpa: float | None
    plane_normal_stress_kpa: float | None
    upper_wall_friction_kpa: float | None
    stress_ratio: float | None
    plane_stress_ratio: float | None
    plane_share: float | None
    dilation_rate: float | None
    max_part_rate: float | None
    end_rate: float | None


def _sums(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Prefix sums (count, x, y, xx, xy): row k holds the sums over records [0, k)."""
    terms = np.stack([np.ones_like(x), x, y, x * x, x * y], axis=1)
    return np.vstack([np.zeros(5), np.cumsum(terms, axis=0)])


def _slope(sums: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Least-squares slopes of y against x over records [a, b) (arrays of indices)."""
    n, sx, sy, sxx, sxy = (sums[b] - sums[a]).T
    return (n * sxy - sx * sy) / (n * sxx - sx * sx)


def final_stretch_rates(x_mm: np.ndarray, plate_mm: np.ndarray, min_mm: float) -> tuple[np.ndarray, ...]:
    """For every start record i whose final stretch [x_i, x_end] is at least ``min_mm`` long:
    (i, the plate's slope over the stretch, the larger absolute slope of its two halves)."""
    x, y = np.asarray(x_mm, float), np.asarray(plate_mm, float)
    sums = _sums(x - x[0], y)
    n = x.size
    start = np.flatnonzero(x[-1] - x >= min_mm)
    start = start[n - start >= 4]  # two records a half at least
    end = np.full(start.size, n)
    mid = start + (end - start) // 2
    whole = _slope(sums, start, end)
    return start, whole, np.maximum(np.abs(_slope(sums, start, mid)), np.abs(_slope(sums, mid, end)))


def _mean(values) -> float | None:
    m = float(np.mean(np.asarray(values, float)))
    return m if math.isfinite(m) else None


def dilation_stopped_residual(
    curve: Mapping[str, np.ndarray], d_mean_m: float, limit: float = DILATION_RATE_LIMIT
) -> ResidualAtRest:
    """The residual over the longest final stretch of ``curve`` (at least ``MIN_STRETCH_DIAMETERS``
    times ``d_mean_m`` long) whose plate slope and halves' slopes stay within ``limit``.

    Without such a stretch the result says "not reached" and holds no numbers.
    """
    min_m = MIN_STRETCH_DIAMETERS * d_mean_m
    x = np.asarray(curve["shear_displacement_mm"], float)
    start, whole, parts = final_stretch_rates(x, curve["plate_displacement_mm"], 1e3 * min_m)
    end = float(x[-1])
    if start.size == 0:
        status = (
            f"not reached: the curve is shorter than {1e3 * min_m:.3g} mm ({MIN_STRETCH_DIAMETERS:g} d_mean)"
        )
        return ResidualAtRest(False, status, limit, min_m, None, end, *([None] * 10))
    last = float(whole[-1])
    ok = np.flatnonzero((np.abs(whole) <= limit) & (parts <= limit))
    if ok.size == 0:
        status = (f"not reached: the plate still moves at {last:+.3f} per unit of shear over the last "
                  f"{1e3 * min_m:.3g} mm")  # fmt: skip
        return ResidualAtRest(False, status, limit, min_m, None, end, *([None] * 9), last)
    k = ok[0]
    i = int(start[k])
    tau = _mean(curve["shear_stress_kpa"][i:])
    sigma = _mean(curve["normal_stress_kpa"][i:])
    plane = _mean(curve["plane_normal_stress_kpa"][i:])
    return ResidualAtRest(
        reached=True,
        status=f"net |dy/dx| <= {limit:g} from {x[i]:.1f} to {end:.1f} mm",
        rate_limit=limit,
        min_stretch_m=min_m,
        start_mm=float(x[i]),
        end_mm=end,
        shear_stress_kpa=tau,
        normal_stress_kpa=sigma,
        plane_normal_stress_kpa=plane,
        upper_wall_friction_kpa=_mean(curve["upper_wall_friction_kpa"][i:]),
        stress_ratio=tau / sigma,
        plane_stress_ratio=tau / plane if plane else None,
        plane_share=plane / sigma if plane is not None else None,
        dilation_rate=float(whole[k]),
        max_part_rate=float(parts[k]),
        end_rate=last,
    )


def tail_residual(curve: Mapping[str, np.ndarray], fraction: float = TAIL_FRACTION) -> float:
    """Mean tau over mean plate stress over the last ``fraction`` of the shear displacement,
    whether or not the plate still rises there (the strength study's residual, for comparison)."""
    x = np.asarray(curve["shear_displacement_mm"], float)
    tail = x >= (1.0 - fraction) * x[-1]
    return float(np.mean(curve["shear_stress_kpa"][tail]) / np.mean(curve["normal_stress_kpa"][tail]))


__all__ = [
    "DILATION_RATE_LIMIT", "MIN_STRETCH_DIAMETERS", "TAIL_FRACTION", "ResidualAtRest",
    "dilation_stopped_residual", "final_stretch_rates", "tail_residual",
]  # fmt: skip
