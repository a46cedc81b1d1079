"""Laboratory direct shear data from CSV (optional user input; poro2d ships none).

Two layouts are accepted; the header decides which (extra columns of the header are
ignored, every row has as many cells as the header, lines starting with ``#`` are
comments; the file is UTF-8 text):

* curves: ``normal_stress_kpa, shear_displacement_mm, shear_stress_kpa``, one row
  per reading, one curve per normal stress, and optionally ``vertical_displacement_mm``:
  the top plate's rise (positive: the specimen dilates; the sign of poro2d's own
  ``plate_displacement_mm``), which a calibration fits as the dilation;
* peaks: ``normal_stress_kpa, peak_shear_stress_kpa``, one row per test.

The peak of a curve is its largest shear stress as measured (laboratory curves
are smooth enough; no smoothing is applied). Data that cannot be right (a peak of 0 or
ten times its normal stress, a curve whose displacement steps back, a one-point curve)
are refused before any work (:mod:`poro2d.shear.lab_checks`). The file is read as every
laboratory file is (:mod:`poro2d.lab_table`: a byte order mark is read, each refusal names
the file, line and column).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from poro2d.errors import InputError
from poro2d.lab_table import LabTable, check_enough_points, check_rising, read_lab_table
from poro2d.shear.lab_checks import (
    MAX_DISPLACEMENT_MM,
    MAX_VERTICAL_MM,
    check_lab_values,
    check_peak,
    check_reading,
)
from poro2d.shear.parts import LabPeak, LabRecord
from poro2d.shear.settings import NORMAL_STRESS_RANGE_KPA

CURVE_COLUMNS = ("normal_stress_kpa", "shear_displacement_mm", "shear_stress_kpa")
#: the optional column of a curves CSV: the top plate's rise (mm, positive: dilation)
VERTICAL_COLUMN = "vertical_displacement_mm"
PEAK_COLUMNS = ("normal_stress_kpa", "peak_shear_stress_kpa")


@dataclass(frozen=True)
class LabData:
    """Laboratory results: peaks per normal stress, and curves when the CSV had them.

    ``vertical``: per normal stress, the top plate's rise at each reading of its curve (m,
    positive: dilation), when the curves CSV had the column (else empty). Made in Python,
    the data pass the checks a file passes (:mod:`poro2d.shear.lab_checks`): a calibration
    handed a ``LabData`` is as safe as one handed a CSV."""

    source: str
    peaks: dict[float, float]
    curves: dict[float, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    vertical: dict[float, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.peaks, dict) or not isinstance(self.curves, dict):
            raise InputError("lab", type(self.peaks).__name__, "peaks and curves as dicts by normal stress")
        check_lab_values(self.peaks, self.curves, self.vertical)

    @property
    def kind(self) -> str:
        return "curves" if self.curves else "peaks"

    def normal_stresses(self) -> list[float]:
        return sorted(self.peaks)

    def peak_rows(self) -> list[LabPeak]:
        """The peaks as records (normal stress, peak shear stress), by normal stress."""
        return [LabPeak(normal_stress_kpa=s, peak_shear_stress_kpa=self.peaks[s]) for s in sorted(self.peaks)]

    def record(self) -> LabRecord:
        """The data as a result file keeps them: the source, the kind of CSV and the peaks."""
        return LabRecord(source=self.source, kind=self.kind, peaks=self.peak_rows())


def read_lab_csv(path: str | os.PathLike) -> LabData:
    """Read and validate a laboratory CSV (see the module docstring for the columns)."""
    table = read_lab_table(path)
    if table.has(*CURVE_COLUMNS):
        read = _curves
    elif table.has(*PEAK_COLUMNS):
        read = _peaks
    else:
        raise InputError(
            "lab columns", ",".join(table.header),
            f"the columns {','.join(CURVE_COLUMNS)} (curves) or {','.join(PEAK_COLUMNS)} (peaks)",
        )  # fmt: skip
    if not table.rows:
        raise InputError("lab", table.path, "at least one data row")
    return read(table)


def _normal_stresses(table: LabTable) -> np.ndarray:
    lo, hi = NORMAL_STRESS_RANGE_KPA
    why = "the range of normal stresses a shear test runs at; is the column in kPa?"
    return table.column("normal_stress_kpa", lo, hi, "kPa", why)


def _peaks(table: LabTable) -> LabData:
    sigma = _normal_stresses(table)
    tau = table.column("peak_shear_stress_kpa", 0.0, math.inf, "kPa")
    peaks: dict[float, float] = {}
    for i, (s, t) in enumerate(zip(sigma, tau, strict=True)):
        if float(s) in peaks:
            where = table.where(i, "normal_stress_kpa")
            raise InputError(
                f"lab normal_stress_kpa ({where})", float(s), "each normal stress once in a peaks CSV"
            )
        check_peak(table.where(i, "peak_shear_stress_kpa"), "peak_shear_stress_kpa", float(s), float(t))
        peaks[float(s)] = float(t)
    return LabData(table.path, peaks)


def _curves(table: LabTable) -> LabData:
    sigma = _normal_stresses(table)
    why = "a reading of a shear box; is the column in mm?"
    d = table.column("shear_displacement_mm", 0.0, MAX_DISPLACEMENT_MM, "mm", why)
    tau = table.column("shear_stress_kpa", -math.inf, math.inf, "kPa")
    for i, (s, t) in enumerate(zip(sigma, tau, strict=True)):
        check_reading(table.where(i, "shear_stress_kpa"), float(s), float(t))
    rise = _vertical(table)
    curves: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    vertical: dict[float, np.ndarray] = {}
    for s in np.unique(sigma):
        rows = np.flatnonzero(sigma == s)  # rows in file order, never re-sorted
        check_enough_points(table, rows, f"curve at {s:g} kPa")
        check_rising(table, "shear_displacement_mm", d[rows], rows, "a curve's displacement")
        k = int(rows[np.argmax(tau[rows])])
        check_peak(
            table.where(k, "shear_stress_kpa"), "shear_stress_kpa (the curve's peak)", float(s), float(tau[k])
        )
        curves[float(s)] = (d[rows] * 1e-3, tau[rows])  # displacement in m
        if rise is not None:
            vertical[float(s)] = rise[rows] * 1e-3
    peaks = {s: float(np.max(t)) for s, (_, t) in curves.items()}
    return LabData(table.path, peaks, curves, vertical)


def _vertical(table: LabTable) -> np.ndarray | None:
    """The optional column of the plate's rise (mm), or None when the file has none."""
    if not table.has(VERTICAL_COLUMN):
        return None
    top = MAX_VERTICAL_MM
    why = "the rise or fall of a shear box's top plate; is the column in mm?"
    return table.column(VERTICAL_COLUMN, -top, top, "mm", why)


__all__ = ["CURVE_COLUMNS", "PEAK_COLUMNS", "VERTICAL_COLUMN", "LabData", "read_lab_csv"]
