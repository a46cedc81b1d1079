"""Laboratory direct shear data that cannot be right are refused before any work.

A lab file is the target of a calibration and the overlay of Fig. 8: a typo in it (a column
in Pa where kPa is meant, a peak of 0, a curve pasted twice) would otherwise be fitted, and
its answer printed as if it were identified. The checks here are physical, not statistical:

* every normal stress lies in the range a shear test can be run at
  (:data:`~poro2d.shear.settings.NORMAL_STRESS_RANGE_KPA`);
* every peak's stress ratio tau/sigma lies in (0, :data:`MAX_STRESS_RATIO`]: a soil with
  no strength has no peak, and 2.5 is a friction angle of 68 degrees, past any sand or
  gravel at the stresses of a direct shear box (:data:`poro2d.lab_table.MAX_TAN_PHI`);
* a shear displacement lies in [0, :data:`MAX_DISPLACEMENT_MM`] mm: the largest shear boxes
  (1 m rockfill boxes) are sheared by a fifth of their length, 200 mm; more is a column in
  micrometres or a typing mistake;
* the top plate's vertical displacement of a curve (optional), within
  +-:data:`MAX_VERTICAL_MM` mm: a plate rises or sinks by a fraction of the specimen's height,
  which is under half a metre even in the largest boxes; more is a column in micrometres;
* a reading of a curve is at least :data:`MIN_READING_RATIO` times its normal stress: at the
  start of a test the shear stress may dip below zero (the halves settle, a load cell's zero
  drifts; poro2d's own tests read down to -0.05 sigma in their first 0.1 mm), while a curve far
  below zero has its sign or its column wrong;
* a curve is a test: displacements rise from row to row (a step back or a repeat is a
  curve pasted twice or sorted by another column), with at least :data:`MIN_CURVE_POINTS`
  readings, so that a peak and what follows it are measured.

Each refusal names the file, the line and the column (``InputError``: one line at the CLI).
The same checks hold for :class:`~poro2d.shear.lab.LabData` made in Python, where the peak or
curve is named by its normal stress instead.
"""

from __future__ import annotations

import math

import numpy as np

from poro2d.errors import InputError, is_number
from poro2d.lab_table import MAX_TAN_PHI, MIN_CURVE_POINTS
from poro2d.shear.settings import NORMAL_STRESS_RANGE_KPA

#: largest peak stress ratio tau/sigma accepted (a friction angle of 68 degrees)
MAX_STRESS_RATIO = MAX_TAN_PHI
#: largest shear displacement of a laboratory reading (mm)
MAX_DISPLACEMENT_MM = 300.0
#: largest rise or fall of the top plate in a laboratory reading (mm): a specimen dilates or
#: contracts by a few percent of its height, and the tallest boxes (1 m rockfill boxes) hold
#: specimens under half a metre high, so 100 mm is past any soil; more is a unit mistake
MAX_VERTICAL_MM = 100.0
#: lowest shear stress of a curve's reading, as a fraction of its normal stress
MIN_READING_RATIO = -0.1


def check_reading(where: str, sigma: float, tau: float) -> None:
    """A reading of a curve (kPa) no lower than :data:`MIN_READING_RATIO` times its normal stress."""
    if not tau >= MIN_READING_RATIO * sigma:
        raise InputError(
            f"lab shear_stress_kpa ({where})", tau,
            f"at least {MIN_READING_RATIO:g} times the normal stress ({MIN_READING_RATIO * sigma:g} kPa)",
            "a curve may dip below zero at its start, not further: is the sign or the column right?",
        )  # fmt: skip


def check_normal_stress(where: str, sigma: float) -> None:
    """A normal stress (kPa) a shear test can be run at; ``where`` names the cell."""
    lo, hi = NORMAL_STRESS_RANGE_KPA
    if not lo <= sigma <= hi:
        raise InputError(
            f"lab normal_stress_kpa ({where})", sigma, f"[{lo:g}, {hi:g}] kPa",
            "the range of normal stresses a shear test runs at; is the column in kPa?",
        )  # fmt: skip


def check_peak(where: str, column: str, sigma: float, tau: float) -> None:
    """A peak shear stress whose ratio to its normal stress is in (0, MAX_STRESS_RATIO]."""
    ratio = tau / sigma
    if not 0.0 < ratio <= MAX_STRESS_RATIO:
        raise InputError(
            f"lab {column} ({where})", tau,
            f"(0, {MAX_STRESS_RATIO:g}] times the normal stress ({sigma:g} kPa)",
            f"tau/sigma = {ratio:.3g}: no soil is that {'weak' if ratio <= 0.0 else 'strong'}",
        )  # fmt: skip


def check_lab_values(
    peaks: dict[float, float],
    curves: dict[float, tuple[np.ndarray, np.ndarray]],
    vertical: dict[float, np.ndarray] | None = None,
) -> None:
    """Peaks and curves given in Python (no file lines): the checks a file passes, each named by
    its normal stress. Curves hold displacement in m, as :class:`~poro2d.shear.lab.LabData` does,
    and so does ``vertical`` (the plate's rise along each curve, optional)."""
    if not peaks:
        raise InputError("lab peaks", peaks, "at least one normal stress")
    if curves and set(curves) != set(peaks):
        raise InputError("lab curves", sorted(curves), f"one curve per peak's normal stress {sorted(peaks)}")
    for sigma, tau in peaks.items():
        if not (is_number(sigma) and is_number(tau) and math.isfinite(sigma) and math.isfinite(tau)):
            raise InputError("lab peaks", {sigma: tau}, "finite numbers: normal stress (kPa) -> peak (kPa)")
        where = f"the peak at {sigma:g} kPa"
        check_normal_stress(where, float(sigma))
        check_peak(where, "peak_shear_stress_kpa", float(sigma), float(tau))
    for sigma, pair in curves.items():
        if not (isinstance(pair, tuple | list) and len(pair) == 2):
            raise InputError(
                f"lab curve at {sigma:g} kPa", type(pair).__name__, "a pair (displacement m, stress kPa)"
            )
        d, t = pair
        _check_curve_arrays(float(sigma), np.asarray(d, float), np.asarray(t, float))
        if float(np.max(t)) != float(peaks[sigma]):
            raise InputError(
                f"lab peak at {sigma:g} kPa", peaks[sigma], f"its curve's largest reading {np.max(t):g}"
            )
    _check_vertical(curves, vertical or {})


def _check_vertical(curves: dict, vertical: dict) -> None:
    """The plate's vertical displacement (m) of every curve or of none, one reading per reading
    of its curve, finite and within +-:data:`MAX_VERTICAL_MM`."""
    if not isinstance(vertical, dict):
        raise InputError("lab vertical", type(vertical).__name__, "a dict by normal stress, or None")
    if vertical and set(vertical) != set(curves):
        raise InputError("lab vertical", sorted(vertical), f"one per curve's normal stress {sorted(curves)}")
    top = MAX_VERTICAL_MM * 1e-3 * (1.0 + 1e-12)  # in m; the margin absorbs the mm -> m rounding
    for sigma, v in vertical.items():
        v = np.asarray(v, float)
        where = f"lab vertical displacement at {sigma:g} kPa"
        if v.shape != np.shape(curves[sigma][0]):
            raise InputError(where, v.shape, "one reading per reading of its curve")
        if not np.all(np.isfinite(v)) or np.max(np.abs(v)) > top:
            allowed = f"finite, within +-{MAX_VERTICAL_MM * 1e-3:g} m"
            raise InputError(where, "a reading out of range", allowed)


def _check_curve_arrays(sigma: float, d: np.ndarray, t: np.ndarray) -> None:
    where = f"lab curve at {sigma:g} kPa"
    if d.ndim != 1 or d.shape != t.shape:
        raise InputError(where, (d.shape, t.shape), "displacement and shear stress of one length")
    if len(t) < MIN_CURVE_POINTS:
        raise InputError(where, f"{len(t)} reading(s)", f"at least {MIN_CURVE_POINTS} readings")
    top = MAX_DISPLACEMENT_MM * 1e-3 * (1.0 + 1e-12)  # in m; the margin absorbs the mm -> m rounding
    if (
        not (np.all(np.isfinite(d)) and np.all(np.isfinite(t)))
        or d.min() < 0.0
        or d.max() > top
        or t.min() < MIN_READING_RATIO * sigma
    ):
        raise InputError(
            where,
            "a reading out of range",
            f"displacement in [0, {MAX_DISPLACEMENT_MM * 1e-3:g}] m,"
            f" shear stress >= {MIN_READING_RATIO:g} x sigma",
        )
    if np.any(np.diff(d) <= 0.0):
        raise InputError(
            where, "displacement that steps back or repeats", "displacement rising from row to row"
        )


__all__ = [
    "MAX_DISPLACEMENT_MM", "MAX_STRESS_RATIO", "MAX_VERTICAL_MM", "MIN_CURVE_POINTS", "check_lab_values",
    "check_normal_stress", "check_peak",
]  # fmt: skip
