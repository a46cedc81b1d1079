"""What a biaxial curve says: peak and critical-state friction angles, dilatancy.

Definitions (docs/biaxial.md):

* mobilized friction: sin(phi) = (sigma_1 - sigma_3) / (sigma_1 + sigma_3), smoothed by a
  moving mean over ``smoothing_strain`` of axial strain (a small specimen's record is
  jagged: contact chains build and buckle);
* peak: the largest smoothed sin(phi) and the axial strain where it lies;
* critical state: the mean sin(phi) over the last ``critical_window`` of the test's axial
  strain, counted as critical only if the volumetric strain has nearly stopped changing
  there: the least-squares slope d eps_v / d eps_1 over that window within
  ``critical_rate_limit`` of 0 (the dilatancy angle over the window, from the slopes of eps_v
  and eps_s, is reported beside it). Otherwise the test says "not yet at critical state" and
  the angle is the end value, not a critical-state one;
* dilatancy: sin(psi) = -d eps_v / d eps_s with eps_s = eps_1 - eps_3 (positive: the
  specimen dilates), each increment a secant over ``smoothing_strain`` of axial strain;
  its largest value gives psi_max;
* plastic dilatancy: the same of the plastic strains, the elastic part C (sigma_1 - sigma_1,0)
  taken out (:mod:`poro2d.biaxial.elastic`), over the same windows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d.biaxial.curve import BiaxialCurve
from poro2d.typed_result import TypedResult


def smoothed(x: np.ndarray, y: np.ndarray, window: float) -> np.ndarray:
    """The mean of ``y`` over the rows whose ``x`` lies within ``window / 2`` of each row's (x sorted)."""
    if window <= 0 or y.size < 3:
        return y.copy()
    lo = np.searchsorted(x, x - 0.5 * window, side="left")
    hi = np.searchsorted(x, x + 0.5 * window, side="right")
    total = np.concatenate(([0.0], np.cumsum(y)))
    return (total[hi] - total[lo]) / (hi - lo)


def _asin_deg(s: float) -> float:
    return math.degrees(math.asin(min(1.0, max(-1.0, s))))


@dataclass(eq=False)
class Angles(TypedResult):
    """The angles of one curve at its confining stress (degrees; strains as fractions; kPa): the
    first keys of a test's ``result.json`` (:class:`~poro2d.biaxial.results.BiaxialTestResult`)."""

    confining_stress_kpa: float
    peak_friction_angle_deg: float
    peak_sin_phi: float
    axial_strain_at_peak: float
    critical_state_friction_angle_deg: float
    critical_state_sin_phi: float
    critical_state_mean_stress_kpa: float
    critical_window: list[float]
    end_dilatancy_rate: float
    end_dilatancy_angle_deg: float
    critical_state_reached: bool
    critical_state_note: str
    max_dilatancy_angle_deg: float
    axial_strain_at_max_dilatancy: float
    end_volumetric_strain: float
    min_volumetric_strain: float


def read_angles(
    curve: BiaxialCurve, confining_kpa: float, smoothing_strain: float, critical_window: float,
    rate_limit: float,
) -> Angles:  # fmt: skip
    """The angles of ``curve``, sheared at ``confining_kpa`` (see the module's definitions)."""
    e1 = curve.axial_strain
    ev = curve.volumetric_strain
    es = curve.shear_strain
    sin_phi = smoothed(e1, curve.sin_phi, smoothing_strain)
    k = int(np.nanargmax(sin_phi))
    end = float(e1[-1])
    tail = _tail(e1, critical_window)
    rate, shear_rate = _end_rates(e1, ev, es, tail)
    s_cs = float(np.mean(curve.sin_phi[tail]))
    reached = abs(rate) <= rate_limit
    note = (
        "critical state: the volumetric strain has stopped changing"
        if reached
        else f"not yet at critical state: d eps_v / d eps_1 = {rate:+.3f} over the last "
        f"{100 * critical_window:g} % of the strain (limit {rate_limit:g}); the angle is the end value"
    )
    psi, at = _max_dilatancy(e1, ev, es, smoothing_strain)
    return Angles(
        confining_stress_kpa=confining_kpa,
        peak_friction_angle_deg=_asin_deg(float(sin_phi[k])),
        peak_sin_phi=float(sin_phi[k]),
        axial_strain_at_peak=float(e1[k]),
        critical_state_friction_angle_deg=_asin_deg(s_cs),
        critical_state_sin_phi=s_cs,
        critical_state_mean_stress_kpa=float(np.mean(curve.mean_stress_kpa[tail])),
        critical_window=[float(e1[tail][0]), end],
        end_dilatancy_rate=rate,
        end_dilatancy_angle_deg=_end_angle(rate, shear_rate),
        critical_state_reached=bool(reached),
        critical_state_note=note,
        max_dilatancy_angle_deg=psi,
        axial_strain_at_max_dilatancy=at,
        end_volumetric_strain=float(ev[-1]),
        min_volumetric_strain=float(ev.min()),
    )


@dataclass(frozen=True)
class PlasticAngles:
    """The dilatancy of a curve's plastic strains (:mod:`poro2d.biaxial.elastic`), read as
    :func:`read_angles` reads the total ones (degrees; strains as fractions)."""

    plastic_max_dilatancy_angle_deg: float
    plastic_axial_strain_at_max_dilatancy: float
    plastic_end_dilatancy_angle_deg: float
    plastic_end_volumetric_strain: float


def read_plastic(
    curve: BiaxialCurve, smoothing_strain: float, critical_window: float
) -> PlasticAngles | None:
    """psi_max and the end dilatancy of ``curve``'s plastic strains (None: it has none), over the
    windows of the total ones (the axial strain the abscissa)."""
    ev, es = curve.plastic_volumetric_strain, curve.plastic_shear_strain
    if ev is None or es is None:
        return None
    e1 = curve.axial_strain
    psi, at = _max_dilatancy(e1, ev, es, smoothing_strain)
    rate, shear_rate = _end_rates(e1, ev, es, _tail(e1, critical_window))
    return PlasticAngles(psi, at, _end_angle(rate, shear_rate), float(ev[-1]))


def _tail(e1: np.ndarray, critical_window: float) -> np.ndarray:
    """The rows of the last ``critical_window`` of the axial strain (at least the last 3)."""
    tail = e1 >= (1.0 - critical_window) * float(e1[-1])
    if np.count_nonzero(tail) < 3:
        tail = np.zeros(e1.size, bool)
        tail[-3:] = True
    return tail


def _end_rates(e1: np.ndarray, ev: np.ndarray, es: np.ndarray, tail: np.ndarray) -> tuple[float, float]:
    """The least-squares slopes d eps_v / d eps_1 and d eps_s / d eps_1 over ``tail``."""
    return float(np.polyfit(e1[tail], ev[tail], 1)[0]), float(np.polyfit(e1[tail], es[tail], 1)[0])


def _end_angle(rate: float, shear_rate: float) -> float:
    """The dilatancy angle of the end slopes: sin(psi) = -(d eps_v) / (d eps_s)."""
    return _asin_deg(-rate / shear_rate) if shear_rate > 0 else math.nan


def _max_dilatancy(e1: np.ndarray, ev: np.ndarray, es: np.ndarray, window: float) -> tuple[float, float]:
    """(psi_max in degrees, the axial strain where it lies): secants of -d eps_v / d eps_s over ``window``."""
    w = window if window > 0 else float(e1[-1] - e1[0]) / 10.0
    centre = e1[(e1 >= e1[0] + 0.5 * w) & (e1 <= e1[-1] - 0.5 * w)]
    if centre.size == 0:
        centre = np.array([0.5 * (e1[0] + e1[-1])])
        w = float(e1[-1] - e1[0])
    dv = np.interp(centre + 0.5 * w, e1, ev) - np.interp(centre - 0.5 * w, e1, ev)
    ds = np.interp(centre + 0.5 * w, e1, es) - np.interp(centre - 0.5 * w, e1, es)
    sin_psi = -dv / ds
    k = int(np.argmax(sin_psi))
    return _asin_deg(float(sin_psi[k])), float(centre[k])


__all__ = ["Angles", "PlasticAngles", "read_angles", "read_plastic", "smoothed"]
