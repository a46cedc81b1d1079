"""Whether a direct shear test measured its box rather than its material: read off its curve.

A direct shear box reports tau over the plate's stress. That is the material's stress ratio only
when the shear plane carries about the plate's load and the stress has built up to a peak. Two
things break it, both read here off a finished curve (a reading, like the residual of
:mod:`poro2d.shear.residual`: it changes no test, its numbers or its identity):

- **the plane's load.** The side walls' friction moves load between the plate and the plane
  (docs/shear.md, "What reaches the shear plane"). Laboratory boxes put 0.65-0.85 of the plate's
  load on the plane (Amsiejus et al. 2014), the paper's box 1.03-1.27 at f_p 0.5 (docs/shear.md); a
  test whose plane carries less than :data:`PLANE_LOAD_BAND`'s 0.7 or more than its 1.3 times the
  plate's stress at the peak reads a tau/sigma off by more than 30 %: the box's walls, jammed struts
  between them, decide it, not the soil;
- **no peak.** A curve whose smoothed stress is largest within the last ``peak_window`` of its
  travel and still rising there (by more than :data:`RISE_FRACTION` of that largest value over
  that window) has not peaked: its "peak" is where the travel ended. ``peak_window`` is the
  stop rule's own margin (:func:`poro2d.shear.curve.peak_passed` needs the smoothed peak that far
  behind the last record before a test may end past it).

Such a test is **box-dominated** (:class:`BoxVerdict`). Tests of an earlier poro2d, whose curves lack
the plane's normal stress, are judged on the peak alone (their note says so).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from poro2d.shear.curve import plane_load_fraction
from poro2d.shear.fit import peak

#: the plane's share of the plate's normal stress at the peak within which a test reads its
#: material: laboratory boxes hold 0.65-0.85 (Amsiejus et al. 2014) and the paper's box measured
#: 1.03-1.27 at f_p 0.5; outside it tau over the plate's stress is off by more than 30 % of the plane's ratio
PLANE_LOAD_BAND = (0.7, 1.3)
#: a curve whose smoothed peak lies in the last ``peak_window`` of its travel has not peaked when its
#: shear stress still rises there by more than this part of that peak over the window (least
#: squares): more than the few percent a plateau's stick-slip leans either way
RISE_FRACTION = 0.05
#: what a box-dominated test is, in words (a calibration's notes and refusals say it so)
MEANING = (
    f"a test whose shear plane carries outside {PLANE_LOAD_BAND[0]:g}-{PLANE_LOAD_BAND[1]:g} times the "
    "plate's load at the peak, or whose stress never peaked"
)


@dataclass(frozen=True)
class BoxVerdict:
    """Whether a test is box-dominated (``dominated``) and why, in words (``note``)."""

    dominated: bool
    note: str


def end_rise(x_m: np.ndarray, tau: np.ndarray, window_m: float) -> float:
    """The shear stress's rise over the last ``window_m`` of the travel (least-squares slope x window,
    kPa); 0 when fewer than three records lie there."""
    last = x_m >= x_m[-1] - window_m
    if np.count_nonzero(last) < 3 or np.ptp(x_m[last]) <= 0.0:
        return 0.0
    return float(np.polyfit(x_m[last], tau[last], 1)[0] * window_m)


def box_verdict(curve: Mapping[str, np.ndarray], window_m: float) -> BoxVerdict:
    """The verdict on a test's ``curve`` (the columns of ``curve.csv``; ``window_m``: its peak window)."""
    x = np.asarray(curve["shear_displacement_mm"], float) * 1e-3
    tau = np.asarray(curve["shear_stress_kpa"], float)
    k, x_peak, tau_peak = peak(x, tau, window_m)
    fraction = plane_load_fraction(x, curve, k, window_m)
    rise = end_rise(x, tau, window_m)
    reasons = []
    lo, hi = PLANE_LOAD_BAND
    if math.isfinite(fraction) and not lo <= fraction <= hi:
        reasons.append(f"the shear plane carries {fraction:.2f} times the plate's normal stress at the "
                       f"peak (outside {lo:g}-{hi:g})")  # fmt: skip
    if x_peak >= x[-1] - window_m and rise > RISE_FRACTION * abs(tau_peak):
        share = 100 * rise / abs(tau_peak)
        reasons.append(f"no peak: the shear stress still rises at the end of the travel "
                       f"(+{share:.0f} % over its last {1e3 * window_m:g} mm)")  # fmt: skip
    if reasons:
        return BoxVerdict(True, "box-dominated: " + "; ".join(reasons))
    plane = (
        f"plane load {fraction:.2f} of the plate's" if math.isfinite(fraction) else "plane load not recorded"
    )
    return BoxVerdict(False, f"{plane} at the peak, at {1e3 * x_peak:.2f} mm of {1e3 * x[-1]:.2f}")


def box_dominated_count(tests) -> int | None:
    """How many of ``tests`` (results or their summaries) are box-dominated; None when none was
    judged (every one of an earlier poro2d, its curve not at hand)."""
    flags = (t.get("box_dominated") if isinstance(t, dict) else t.box_dominated for t in tests)
    judged = [flag for flag in flags if flag is not None]
    return sum(judged) if judged else None


__all__ = [
    "MEANING",
    "PLANE_LOAD_BAND",
    "RISE_FRACTION",
    "BoxVerdict",
    "box_dominated_count",
    "box_verdict",
    "end_rise",
]
