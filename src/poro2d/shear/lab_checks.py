"""Laboratory direct shear data that cannot be right are refused before any work.

A lab file is the target of a calibration and the overlay of Fig. 8: a typo in it (a column
in Pa where kPa is meant, a peak of 0, a curve pasted twice) would otherwise be fitted, and
its answer printed as if it were identified. The checks here are physical, not statistical:

* every normal stress lies in the range a shear test can be run at
  (:data:`~poro2d.shear.settings.NORMAL_STRESS_RANGE_KPA`);
* every peak's stress ratio tau/sigma lies in (0, :data:`MAX_STRESS_RATIO`]: a soil with
  no strength has no peak, and 2.5 is a friction angle of 68 degrees, past any sand or
  gravel at the stresses of a direct shear box (rough rock joints stay below it too);
* a curve is a test: displacements rise from row to row (a step back or a repeat is a
  curve pasted twice or sorted by another column), with at least :data:`MIN_CURVE_POINTS`
  readings, so that a peak and what follows it are measured.

Each refusal names the file, the line and the column (``InputError``: one line at the CLI).
"""

from __future__ import annotations

import numpy as np

from poro2d.errors import InputError
from poro2d.shear.settings import NORMAL_STRESS_RANGE_KPA

#: largest peak stress ratio tau/sigma accepted (a friction angle of 68 degrees)
MAX_STRESS_RATIO = 2.5
#: fewest readings of a whole curve
MIN_CURVE_POINTS = 5


def check_normal_stress(path: str, line: int, sigma: float) -> None:
    """A normal stress (kPa) a shear test can be run at."""
    lo, hi = NORMAL_STRESS_RANGE_KPA
    if not lo <= sigma <= hi:
        raise InputError(
            f"lab normal_stress_kpa (line {line} of {path})", sigma, f"[{lo:g}, {hi:g}] kPa",
            "the range of normal stresses a shear test runs at; is the column in kPa?",
        )  # fmt: skip


def check_peak(path: str, line: int, column: str, sigma: float, tau: float) -> None:
    """A peak shear stress whose ratio to its normal stress is in (0, MAX_STRESS_RATIO]."""
    ratio = tau / sigma
    if not 0.0 < ratio <= MAX_STRESS_RATIO:
        raise InputError(
            f"lab {column} (line {line} of {path})", tau,
            f"(0, {MAX_STRESS_RATIO:g}] times the normal stress ({sigma:g} kPa)",
            f"tau/sigma = {ratio:.3g}: no soil is that {'weak' if ratio <= 0.0 else 'strong'}",
        )  # fmt: skip


def check_curve(path: str, sigma: float, lines: np.ndarray, displacement: np.ndarray) -> None:
    """One curve's rows in file order: enough of them, displacement strictly rising."""
    if len(displacement) < MIN_CURVE_POINTS:
        raise InputError(
            f"lab curve at {sigma:g} kPa (line {int(lines[0])} of {path})", f"{len(displacement)} reading(s)",
            f"at least {MIN_CURVE_POINTS} readings (a peak and what follows it)",
        )  # fmt: skip
    steps = np.diff(displacement)
    if np.any(steps <= 0.0):
        k = int(np.argmax(steps <= 0.0)) + 1
        raise InputError(
            f"lab shear_displacement_mm (line {int(lines[k])} of {path})", float(displacement[k]),
            f"more than {float(displacement[k - 1]):g} (line {int(lines[k - 1])}): a curve's "
            "displacement rises from row to row",
        )  # fmt: skip


__all__ = ["MAX_STRESS_RATIO", "MIN_CURVE_POINTS", "check_curve", "check_normal_stress", "check_peak"]
