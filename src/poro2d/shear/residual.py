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
and the residual stretch is the longest final stretch of the curve once the stress has built up
(:data:`BUILT_UP_FRACTION` of its largest value), at least
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

import numpy as np

from poro2d.shear.fit import smooth
from poro2d.shear.parts import ResidualAtRest

#: the largest |net d(plate height) / d(shear displacement)| of a stretch read as "dilation stopped":
#: by Taylor's balance the dilatancy left in its mean tau/sigma is below this
DILATION_RATE_LIMIT = 0.02
#: the shortest residual stretch, in mean disk diameters: over shorter ones the plate's rise and
#: fall by a few tenths of a millimetre reads as a rate beyond the limit
MIN_STRETCH_DIAMETERS = 4.0
#: the residual stretch starts once the smoothed shear stress has first reached this part of its
#: largest value: the loading before it is no residual, whatever the plate does there
BUILT_UP_FRACTION = 0.9
#: the part of each test's shear displacement, at its end, that the strength study's residual averages
TAIL_FRACTION = 0.2


def _sums(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Prefix sums (count, x, y, xx, xy): row k holds the sums over records [0, k)."""
    terms = np.stack([np.ones_like(x), x, y, x * x, x * y], axis=1)
    return np.vstack([np.zeros(5), np.cumsum(terms, axis=0)])


def _slope(sums: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Least-squares slopes of y against x over records [a, b) (arrays of indices)."""
    n, sx, sy, sxx, sxy = (sums[b] - sums[a]).T
    return (n * sxy - sx * sy) / (n * sxx - sx * sx)


def final_stretch_rates(
    x_mm: np.ndarray, plate_mm: np.ndarray, min_mm: float, after_mm: float = -math.inf
) -> tuple[np.ndarray, ...]:
    """For every start record i at or after ``after_mm`` whose final stretch [x_i, x_end] is at least
    ``min_mm`` long: (i, the plate's slope over the stretch, the larger absolute slope of its two halves)."""
    x, y = np.asarray(x_mm, float), np.asarray(plate_mm, float)
    sums = _sums(x - x[0], y)
    n = x.size
    start = np.flatnonzero((x[-1] - x >= min_mm) & (x >= after_mm))
    start = start[n - start >= 4]  # two records a half at least
    end = np.full(start.size, n)
    mid = start + (end - start) // 2
    whole = _slope(sums, start, end)
    return start, whole, np.maximum(np.abs(_slope(sums, start, mid)), np.abs(_slope(sums, mid, end)))


def _mean(values) -> float | None:
    m = float(np.mean(np.asarray(values, float)))
    return m if math.isfinite(m) else None


def built_up_mm(curve: Mapping[str, np.ndarray], window_m: float) -> float:
    """Where the shear stress, smoothed over ``window_m``, first reaches ``BUILT_UP_FRACTION`` of its
    largest smoothed value (mm of shear displacement)."""
    x = np.asarray(curve["shear_displacement_mm"], float)
    tau = smooth(x, curve["shear_stress_kpa"], 1e3 * window_m)
    return float(x[np.argmax(tau >= BUILT_UP_FRACTION * tau.max())])


def dilation_stopped_residual(
    curve: Mapping[str, np.ndarray], d_mean_m: float, limit: float = DILATION_RATE_LIMIT
) -> ResidualAtRest:
    """The residual over the longest final stretch of ``curve`` (at least ``MIN_STRETCH_DIAMETERS``
    times ``d_mean_m`` long, starting once the stress has built up: :func:`built_up_mm`, smoothed
    over that least stretch) whose plate slope and halves' slopes stay within ``limit``.

    The loading is no residual: a plate that sank while the stress built up and rose as much by
    the peak has a net slope of zero without any rest. The start is not the peak itself: in a box
    of a few thousand disks the largest stress may come late, in one of the stick-slip surges of
    the residual stretch, which the long smoothing evens out. Without such a stretch the result
    says "not reached" and holds no numbers.
    """
    min_m = MIN_STRETCH_DIAMETERS * d_mean_m
    x = np.asarray(curve["shear_displacement_mm"], float)
    start, whole, parts = final_stretch_rates(
        x, curve["plate_displacement_mm"], 1e3 * min_m, built_up_mm(curve, min_m)
    )
    end = float(x[-1])
    if start.size == 0:
        status = (
            f"not reached: the curve after the stress built up is shorter than {1e3 * min_m:.3g} mm "
            f"({MIN_STRETCH_DIAMETERS:g} d_mean)"
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
    "BUILT_UP_FRACTION", "DILATION_RATE_LIMIT", "MIN_STRETCH_DIAMETERS", "TAIL_FRACTION", "ResidualAtRest",
    "built_up_mm", "dilation_stopped_residual", "final_stretch_rates", "tail_residual",
]  # fmt: skip
