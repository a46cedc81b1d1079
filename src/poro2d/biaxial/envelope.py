"""The Mohr-Coulomb envelope of peak stress circles: phi and c from (sigma_1, sigma_3) at failure.

A line tau = c + sigma tan(phi) touches the circle of centre s = (sigma_1 + sigma_3) / 2 and
radius t = (sigma_1 - sigma_3) / 2 when t = c cos(phi) + s sin(phi): the circles' tops
(s, t) lie on a straight line whose slope is sin(phi) and whose intercept is c cos(phi). So
the envelope tangent to the circles is the least-squares line through their tops, with no
search for tangency (the "modified failure envelope" of triaxial practice). Through the origin
(c = 0) the slope is sum(s t) / sum(s^2). A test's peak gives its circle from sigma_3 (the
servoed confining stress) and the peak's mobilized friction: sigma_1 = sigma_3 (1 + sin phi) /
(1 - sin phi).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d.errors import InputError
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class EnvelopeRecord(TypedResult):
    """A Mohr-Coulomb envelope as a result file keeps it (degrees, kPa).

    ``r2``: of the line through the circles' tops (s, t); ``points``: the circles fitted (one per
    test); ``through_origin``: c held at 0.
    """

    friction_angle_deg: float | None
    cohesion_kpa: float
    r2: float
    points: int
    through_origin: bool


def peak_circle(sigma_3_kpa: float, sin_phi: float) -> tuple[float, float]:
    """(sigma_1, sigma_3) in kPa of a peak at mobilized friction ``sin_phi`` under ``sigma_3_kpa``."""
    return sigma_3_kpa * (1.0 + sin_phi) / (1.0 - sin_phi), sigma_3_kpa


def envelope(sigma_1_kpa, sigma_3_kpa, *, through_origin: bool = False) -> EnvelopeRecord:
    """The Mohr-Coulomb line tangent (in least squares) to the circles (sigma_1, sigma_3).

    Needs circles at two different sigma_3 (one through the origin). A slope of the tops at or
    above 1 has no angle (``friction_angle_deg`` None).
    """
    s1 = np.asarray(sigma_1_kpa, float).ravel()
    s3 = np.asarray(sigma_3_kpa, float).ravel()
    if s1.shape != s3.shape or not (np.all(np.isfinite(s1)) and np.all(np.isfinite(s3))):
        raise InputError(
            "peak circles", f"{s1.size} sigma_1, {s3.size} sigma_3", "as many finite values of each"
        )
    need = 1 if through_origin else 2
    if np.unique(s3).size < need:
        raise InputError(
            "confining stresses", s3.tolist(), f"at least {need} different value(s) for an envelope"
        )
    s = 0.5 * (s1 + s3)
    t = 0.5 * (s1 - s3)
    if through_origin:
        slope, intercept = float(np.dot(s, t) / np.dot(s, s)), 0.0
    else:
        slope, intercept = (float(v) for v in np.polyfit(s, t, 1))
    residual = float(np.sum((t - intercept - slope * s) ** 2))
    spread = float(np.sum((t - t.mean()) ** 2))
    r2 = 1.0 - residual / spread if spread > 0 else (1.0 if residual == 0 else 0.0)
    if not -1.0 < slope < 1.0:
        return EnvelopeRecord(None, math.nan, r2, int(s.size), through_origin)
    phi = math.asin(slope)
    return EnvelopeRecord(math.degrees(phi), intercept / math.cos(phi), r2, int(s.size), through_origin)


__all__ = ["EnvelopeRecord", "envelope", "peak_circle"]
