"""The residual strength of a direct shear test, read only where the specimen has stopped dilating.

A residual is the strength of a specimen that shears at constant volume. While the plate
still rises the shear stress holds a dilatancy part: by Taylor's energy balance
tau/sigma = mu + dy/dx, so a plate still rising at dy/dx = 0.05 adds 0.05 to tau/sigma. The
mean over the last part of a curve (``poro2d strength``'s window) is therefore no residual
unless the curve has flattened by then. Here the dilation rate is measured along the curve as
the secant slope of the plate's height over ``rate_window`` of shear displacement (the
plate's record is servo noise from row to row), and the residual is the mean over the final
stretch where that rate stays below :data:`DILATION_RATE_LIMIT`: by Taylor's balance the
dilatancy left in it is below that limit in tau/sigma. When the stretch is shorter than
``rate_window`` the test says "not reached" and gives no number.

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

#: the largest |d(plate height) / d(shear displacement)| of a stretch read as "dilation stopped":
#: by Taylor's balance the dilatancy left in its tau/sigma is below this
DILATION_RATE_LIMIT = 0.02
#: the secant window of the dilation rate, in peak windows of the test (2 x 2 mm by default)
RATE_WINDOW_PEAK_WINDOWS = 2.0
#: the part of each test's shear displacement, at its end, that the strength study's residual averages
TAIL_FRACTION = 0.2


@dataclass(eq=False)
class ResidualAtRest(TypedResult):
    """A test's residual read where the plate has stopped rising (a test's ``residual_dilation_stopped``).

    ``reached``: whether the curve ends in a stretch at least ``rate_window_m`` long whose
    dilation rate stays within ``rate_limit``; ``status`` says so in words. The stretch runs
    from ``start_mm`` to ``end_mm`` of shear displacement; over it, the means of the shear
    stress, the plate's and the plane's normal stress and the upper walls' upward friction
    (kPa), the shear stress over each normal stress (``stress_ratio``: the plate's,
    ``plane_stress_ratio``: the plane's), the plane's share of the plate's stress and the
    largest |rate| in it. The numbers are None when it was not reached (and the plane's
    when the curve has no plane record, an earlier poro2d's).
    """

    reached: bool
    status: str
    rate_limit: float
    rate_window_m: float
    start_mm: float | None
    end_mm: float
    shear_stress_kpa: float | None
    normal_stress_kpa: float | None
    plane_normal_stress_kpa: float | None
    upper_wall_friction_kpa: float | None
    stress_ratio: float | None
    plane_stress_ratio: float | None
    plane_share: float | None
    max_abs_dilation_rate: float | None
    end_dilation_rate: float | None


def dilation_rate(curve: Mapping[str, np.ndarray], window_m: float) -> tuple[np.ndarray, np.ndarray]:
    """(centres in mm, d(plate)/d(shear)) as secants over ``window_m`` centred on every record at
    least half a window from either end (empty arrays for a curve shorter than the window)."""
    x = np.asarray(curve["shear_displacement_mm"], float)
    y = np.asarray(curve["plate_displacement_mm"], float)
    half = 0.5e3 * window_m
    centre = x[(x >= x[0] + half) & (x <= x[-1] - half)]
    rise = np.interp(centre + half, x, y) - np.interp(centre - half, x, y)
    return centre, rise / (2.0 * half)


def stopped_from(centre: np.ndarray, rate: np.ndarray, limit: float) -> float | None:
    """The first centre from which |rate| stays within ``limit`` to the end (None: not at the end)."""
    over = np.flatnonzero(np.abs(rate) > limit)
    if rate.size == 0 or (over.size and over[-1] == rate.size - 1):
        return None
    return float(centre[over[-1] + 1]) if over.size else float(centre[0])


def _mean(values: np.ndarray) -> float | None:
    m = float(np.mean(values))
    return m if math.isfinite(m) else None


def dilation_stopped_residual(
    curve: Mapping[str, np.ndarray], peak_window_m: float = 2e-3, limit: float = DILATION_RATE_LIMIT
) -> ResidualAtRest:
    """The residual over the final stretch of ``curve`` where the dilation rate stays within ``limit``.

    The rate is a secant over ``RATE_WINDOW_PEAK_WINDOWS`` peak windows; the stretch must be at
    least that long, else the result says "not reached" and holds no numbers.
    """
    window = RATE_WINDOW_PEAK_WINDOWS * peak_window_m
    x = np.asarray(curve["shear_displacement_mm"], float)
    centre, rate = dilation_rate(curve, window)
    start = stopped_from(centre, rate, limit)
    end = float(x[-1])
    last = float(rate[-1]) if rate.size else None
    if start is None or end - start < 1e3 * window:
        status = (f"not reached: the plate still moves at {abs(last):.3f} per unit of shear at the end"
                  if start is None and last is not None else
                  f"not reached: the curve is flat over less than {1e3 * window:g} mm")  # fmt: skip
        return ResidualAtRest(False, status, limit, window, start, end, *([None] * 8), last)
    inside = x >= start
    tau = float(np.mean(np.asarray(curve["shear_stress_kpa"], float)[inside]))
    sigma = float(np.mean(np.asarray(curve["normal_stress_kpa"], float)[inside]))
    plane = _mean(np.asarray(curve["plane_normal_stress_kpa"], float)[inside])
    return ResidualAtRest(
        reached=True,
        status=f"|dy/dx| <= {limit:g} from {start:.1f} to {end:.1f} mm",
        rate_limit=limit,
        rate_window_m=window,
        start_mm=start,
        end_mm=end,
        shear_stress_kpa=tau,
        normal_stress_kpa=sigma,
        plane_normal_stress_kpa=plane,
        upper_wall_friction_kpa=_mean(np.asarray(curve["upper_wall_friction_kpa"], float)[inside]),
        stress_ratio=tau / sigma,
        plane_stress_ratio=tau / plane if plane else None,
        plane_share=plane / sigma if plane is not None else None,
        max_abs_dilation_rate=float(np.max(np.abs(rate[centre >= start]))),
        end_dilation_rate=last,
    )


def tail_residual(curve: Mapping[str, np.ndarray], fraction: float = TAIL_FRACTION) -> float:
    """Mean tau over mean plate stress over the last ``fraction`` of the shear displacement,
    whether or not the plate still rises there (the strength study's residual, for comparison)."""
    x = np.asarray(curve["shear_displacement_mm"], float)
    tail = x >= (1.0 - fraction) * x[-1]
    return float(np.mean(curve["shear_stress_kpa"][tail]) / np.mean(curve["normal_stress_kpa"][tail]))


__all__ = [
    "DILATION_RATE_LIMIT", "RATE_WINDOW_PEAK_WINDOWS", "ResidualAtRest", "dilation_rate",
    "dilation_stopped_residual", "stopped_from", "tail_residual",
]  # fmt: skip
