"""Mohr-Coulomb fits of peak strength against normal stress, and a robust peak."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from poro2d.errors import InputError
from poro2d.shear.parts import MohrCoulombFit


def mohr_coulomb(sigma_kpa, tau_kpa, through_origin: bool = False) -> MohrCoulombFit:
    """Least-squares Mohr-Coulomb line through (normal stress, peak shear stress) points.

    Needs two points with different normal stresses (one with ``through_origin``).
    """
    s = np.asarray(sigma_kpa, float).ravel()
    t = np.asarray(tau_kpa, float).ravel()
    if s.shape != t.shape:
        raise InputError("Mohr-Coulomb points", f"{s.size} stresses, {t.size} strengths", "as many of each")
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(t))):
        raise InputError("Mohr-Coulomb points", "non-finite values", "finite stresses")
    need = 1 if through_origin else 2
    if np.unique(s).size < need or s.size < need:
        raise InputError(
            "normal stresses", s.tolist(), f"at least {need} different value(s) for a Mohr-Coulomb fit"
        )
    if through_origin:
        slope = float(np.dot(s, t) / np.dot(s, s))
        c = 0.0
    else:
        slope, c = (float(v) for v in np.polyfit(s, t, 1))
    pred = c + slope * s
    ss_res = float(np.sum((t - pred) ** 2))
    ss_tot = float(np.sum((t - t.mean()) ** 2))
    r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else (1.0 if ss_res == 0 else 0.0)
    phi = math.degrees(math.atan(slope))
    # tan_phi as the files have always kept it: the tangent of the angle, not the fitted slope
    # (the two can differ in the last bits)
    return MohrCoulombFit(phi, c, r2, int(s.size), through_origin, math.tan(math.radians(phi)))


def smooth(x, y, window: float) -> np.ndarray:
    """Centred moving average of ``y(x)`` over ``|x' - x| <= window / 2`` (truncated at the ends).

    ``x`` must be non-decreasing; ``window = 0`` returns ``y`` unchanged.
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    if window <= 0 or y.size == 0:
        return y.copy()
    c = np.concatenate([[0.0], np.cumsum(y)])
    lo = np.searchsorted(x, x - 0.5 * window, side="left")
    hi = np.searchsorted(x, x + 0.5 * window, side="right")
    return (c[hi] - c[lo]) / (hi - lo)


class Peak(NamedTuple):
    """The maximum of a smoothed curve: its record's ``index``, where it lies (``x``) and its ``value``."""

    index: int
    x: float
    value: float


def peak(x, y, window: float) -> Peak:
    """The maximum of ``y`` smoothed over ``window`` (see :func:`smooth`)."""
    ys = smooth(x, y, window)
    if ys.size == 0:
        raise InputError("curve", "empty", "at least one point")
    k = int(np.argmax(ys))
    return Peak(k, float(np.asarray(x, float)[k]), float(ys[k]))


__all__ = ["MohrCoulombFit", "Peak", "mohr_coulomb", "peak", "smooth"]
