"""Laboratory direct shear data from CSV (optional user input; poro2d ships none).

Two layouts are accepted; the header decides which (extra columns of the header are
ignored, every row has as many cells as the header, lines starting with ``#`` are
comments; the file is UTF-8 text):

* curves: ``normal_stress_kpa, shear_displacement_mm, shear_stress_kpa``, one row
  per reading, one curve per normal stress;
* peaks: ``normal_stress_kpa, peak_shear_stress_kpa``, one row per test.

The peak of a curve is its largest shear stress as measured (laboratory curves
are smooth enough; no smoothing is applied). Data that cannot be right (a peak of 0 or
ten times its normal stress, a curve whose displacement steps back, a one-point curve)
are refused before any work (:mod:`poro2d.shear.lab_checks`).
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from poro2d.errors import InputError
from poro2d.io_utils import check_input_file, read_utf8
from poro2d.shear.lab_checks import check_curve, check_normal_stress, check_peak
from poro2d.shear.parts import LabPeak, LabRecord

CURVE_COLUMNS = ("normal_stress_kpa", "shear_displacement_mm", "shear_stress_kpa")
PEAK_COLUMNS = ("normal_stress_kpa", "peak_shear_stress_kpa")


@dataclass
class LabData:
    """Laboratory results: peaks per normal stress, and curves when the CSV had them."""

    source: str
    peaks: dict[float, float]
    curves: dict[float, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)

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


def _number(path: str, line: int, col: str, text: str) -> float:
    if "_" in text:  # Python's float() reads 1_000; a spreadsheet never writes it
        raise InputError(
            f"lab {col} (line {line} of {path})", text, "a number (digits, sign, point, exponent)"
        )
    try:
        v = float(text)
    except (TypeError, ValueError):
        raise InputError(f"lab {col} (line {line} of {path})", text, "a number") from None
    if not math.isfinite(v):
        raise InputError(f"lab {col} (line {line} of {path})", text, "a finite number")
    return v


def read_lab_csv(path: str | os.PathLike) -> LabData:
    """Read and validate a laboratory CSV (see the module docstring for the columns)."""
    p = Path(path)
    if p.exists():  # a device, a FIFO or a folder is named as such
        check_input_file("lab", p)
    if not p.is_file():
        raise InputError("lab", str(p), "an existing CSV file")
    text = read_utf8("lab", p, "a UTF-8 CSV file")
    lines = [
        (k + 1, ln)
        for k, ln in enumerate(text.splitlines())
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not lines:
        raise InputError("lab", str(p), "a CSV with a header and data rows")
    reader = csv.reader([ln for _, ln in lines])
    rows = list(reader)
    header = [h.strip().lower() for h in rows[0]]
    if all(c in header for c in CURVE_COLUMNS):
        cols, kind = CURVE_COLUMNS, "curves"
    elif all(c in header for c in PEAK_COLUMNS):
        cols, kind = PEAK_COLUMNS, "peaks"
    else:
        raise InputError(
            "lab columns", ",".join(header),
            f"the columns {','.join(CURVE_COLUMNS)} (curves) or {','.join(PEAK_COLUMNS)} (peaks)",
        )  # fmt: skip
    idx = [header.index(c) for c in cols]
    data, numbers = [], []
    for (line, _), row in zip(lines[1:], rows[1:], strict=True):
        if len(row) != len(header):  # a cell too many is as unclear as one too few: which column moved?
            where = f"line {line}, column {min(len(row), len(header)) + 1} of {p}"
            raise InputError(f"lab row ({where})", ",".join(row), f"{len(header)} columns, as the header")
        vals = [_number(str(p), line, c, row[i].strip()) for c, i in zip(cols, idx, strict=True)]
        for c, v in zip(cols, vals, strict=True):
            if v < 0:
                raise InputError(f"lab {c} (line {line} of {p})", v, "[0, inf)")
        check_normal_stress(str(p), line, vals[0])
        data.append(vals)
        numbers.append(line)
    if not data:
        raise InputError("lab", str(p), "at least one data row")
    a, at = np.array(data), np.array(numbers)
    if kind == "peaks":
        peaks: dict[float, float] = {}
        for (s, t), line in zip(a, at, strict=True):
            if float(s) in peaks:
                raise InputError("lab normal_stress_kpa", float(s), "each normal stress once in a peaks CSV")
            check_peak(str(p), int(line), "peak_shear_stress_kpa", float(s), float(t))
            peaks[float(s)] = float(t)
        return LabData(str(p), peaks)
    curves: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    for s in np.unique(a[:, 0]):
        m = a[:, 0] == s
        d, t = a[m, 1], a[m, 2]
        check_curve(str(p), float(s), at[m], d)  # rows in file order, displacement rising
        k = int(np.argmax(t))
        check_peak(str(p), int(at[m][k]), "shear_stress_kpa (the curve's peak)", float(s), float(t[k]))
        curves[float(s)] = (d * 1e-3, t)  # displacement in m
    peaks = {s: float(np.max(t)) for s, (_, t) in curves.items()}
    return LabData(str(p), peaks, curves)


__all__ = ["CURVE_COLUMNS", "PEAK_COLUMNS", "LabData", "read_lab_csv"]
