"""Laboratory biaxial (or plane-strain) curves from CSV: the user's own data, overlaid on the figure.

poro2d ships no laboratory data. The header names the columns (extra columns are ignored,
lines starting with ``#`` are comments, UTF-8 text):

* ``axial_strain``: the axial strain as a fraction (0.05 for 5 %), rising from row to row;
* ``stress_ratio``: (sigma_1 - sigma_3) / (sigma_1 + sigma_3), or both ``sigma_1_kpa`` and
  ``sigma_3_kpa`` from which it is computed;
* ``volumetric_strain`` (optional): a fraction, compression positive.

Data that cannot be right are refused before any work: a strain outside [0, 1) or stepping
back, a stress ratio outside [0, 1), fewer than two rows.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poro2d.errors import InputError
from poro2d.io_utils import check_input_file, read_utf8


@dataclass(frozen=True)
class LabCurve:
    """A laboratory curve: axial strain, stress ratio and (or None) volumetric strain, as arrays."""

    source: str
    axial_strain: np.ndarray
    stress_ratio: np.ndarray
    volumetric_strain: np.ndarray | None

    def peak_friction_angle_deg(self) -> float:
        return math.degrees(math.asin(float(self.stress_ratio.max())))

    def end_friction_angle_deg(self) -> float:
        return math.degrees(math.asin(float(self.stress_ratio[-1])))


def _number(path: Path, line: int, column: str, text: str) -> float:
    try:
        v = float(text) if "_" not in text else math.nan
    except ValueError:
        v = math.nan
    if not math.isfinite(v):
        raise InputError(f"lab {column} (line {line} of {path})", text, "a finite number")
    return v


def read_lab_curve(path: str | os.PathLike) -> LabCurve:
    """Read and check a laboratory biaxial CSV (the columns are the module's)."""
    p = Path(path)
    if p.exists():
        check_input_file("lab", p)
    if not p.is_file():
        raise InputError("lab", str(p), "an existing CSV file")
    text = read_utf8("lab", p, "a UTF-8 CSV file")
    lines = [
        (k + 1, ln)
        for k, ln in enumerate(text.splitlines())
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if len(lines) < 3:
        raise InputError("lab", str(p), "a CSV with a header and at least two data rows")
    rows = list(csv.reader([ln for _, ln in lines]))
    header = [h.strip().lower() for h in rows[0]]
    by_stresses = "sigma_1_kpa" in header and "sigma_3_kpa" in header
    if "axial_strain" not in header or not ("stress_ratio" in header or by_stresses):
        raise InputError(
            "lab columns", ",".join(header),
            "axial_strain with stress_ratio (or sigma_1_kpa and sigma_3_kpa), volumetric_strain optional",
        )  # fmt: skip
    wanted = ["axial_strain"] + (
        ["stress_ratio"] if "stress_ratio" in header else ["sigma_1_kpa", "sigma_3_kpa"]
    )
    if "volumetric_strain" in header:
        wanted.append("volumetric_strain")
    data = []
    for (line, _), row in zip(lines[1:], rows[1:], strict=True):
        if len(row) != len(header):
            raise InputError(
                f"lab row (line {line} of {p})", ",".join(row), f"{len(header)} columns, as the header"
            )
        data.append({c: _number(p, line, c, row[header.index(c)].strip()) for c in wanted})
    e1 = np.array([d["axial_strain"] for d in data])
    if "stress_ratio" in wanted:
        ratio = np.array([d["stress_ratio"] for d in data])
    else:
        s1 = np.array([d["sigma_1_kpa"] for d in data])
        s3 = np.array([d["sigma_3_kpa"] for d in data])
        if np.any(s3 <= 0) or np.any(s1 < s3):
            raise InputError("lab sigma_1_kpa, sigma_3_kpa", str(p), "sigma_1 >= sigma_3 > 0 on every row")
        ratio = (s1 - s3) / (s1 + s3)
    if np.any(e1 < 0) or np.any(e1 >= 1) or np.any(np.diff(e1) < 0):
        raise InputError("lab axial_strain", str(p), "fractions in [0, 1), rising from row to row")
    if np.any(ratio < 0) or np.any(ratio >= 1):
        raise InputError("lab stress_ratio", str(p), "[0, 1): (sigma_1 - sigma_3) / (sigma_1 + sigma_3)")
    ev = np.array([d["volumetric_strain"] for d in data]) if "volumetric_strain" in wanted else None
    if ev is not None and np.any(np.abs(ev) >= 1):
        raise InputError("lab volumetric_strain", str(p), "fractions in (-1, 1)")
    return LabCurve(str(p), e1, ratio, ev)


__all__ = ["LabCurve", "read_lab_curve"]
