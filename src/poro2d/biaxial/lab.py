"""Laboratory biaxial (or plane-strain) curves from CSV: the user's own data, overlaid on the figure.

poro2d ships no laboratory data. The header names the columns (extra columns are ignored,
lines starting with ``#`` are comments, UTF-8 text):

* ``axial_strain``: the axial strain as a fraction (0.05 for 5 %), rising from row to row;
* ``stress_ratio``: (sigma_1 - sigma_3) / (sigma_1 + sigma_3), or both ``sigma_1_kpa`` and
  ``sigma_3_kpa`` from which it is computed;
* ``volumetric_strain`` (optional): a fraction, compression positive.

A calibration against biaxial tests (``poro2d calibrate --biaxial-lab``) reads the same columns
with ``confining_stress_kpa``, the sigma_3 of each row's test (:func:`read_lab_tests`: one file
per test, or several tests in one file).

The file is read as every laboratory file is (:mod:`poro2d.lab_table`: a byte order mark is
read, numbers with underscores or not finite are refused, each refusal names the file, line and
column). Data that cannot be right are refused before any work: fewer than five rows, an axial
strain outside [0, 0.5] or not rising strictly from row to row (a repeat is a row pasted twice),
a volumetric strain outside [-0.5, 0.5] (a column in percent), a stress ratio outside [0, 1] or
a peak ratio of 0 (an all-zero curve) or above sin 68 degrees (the largest friction angle the
direct shear files accept), stresses outside the confining range a biaxial test runs at.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from poro2d.biaxial.settings import CONFINING_RANGE_KPA
from poro2d.errors import InputError
from poro2d.lab_table import (
    MAX_TAN_PHI,
    MIN_CURVE_POINTS,
    LabTable,
    check_enough_points,
    check_rising,
    read_lab_table,
)
from poro2d.typed_result import NOT_IN_FILE, TypedResult

#: largest peak (sigma_1 - sigma_3) / (sigma_1 + sigma_3): sin of the direct shear files' largest
#: friction angle (atan 2.5, 68 degrees), one bound for both kinds of laboratory file
MAX_SIN_PHI = math.sin(math.atan(MAX_TAN_PHI))
#: largest sigma_1 / sigma_3 (the same angle: (1 + sin phi) / (1 - sin phi))
MAX_PRINCIPAL_RATIO = (1.0 + MAX_SIN_PHI) / (1.0 - MAX_SIN_PHI)
#: largest axial or volumetric strain (a fraction): a biaxial specimen is not sheared past half its height
MAX_STRAIN = 0.5


@dataclass(eq=False)
class LabCurve(TypedResult):
    """A laboratory curve: axial strain, stress ratio and (or None) volumetric strain, as arrays.

    A biaxial study's file keeps it as its ``lab``: where it came from, its rows and the friction
    angles of its peak and last ratios, set from the arrays when made from them; a curve read back
    from that file has no arrays.
    """

    source: str
    axial_strain: np.ndarray | None = field(default=None, metadata=NOT_IN_FILE)
    stress_ratio: np.ndarray | None = field(default=None, metadata=NOT_IN_FILE)
    volumetric_strain: np.ndarray | None = field(default=None, metadata=NOT_IN_FILE)
    rows: int | None = None
    peak_friction_angle_deg: float | None = None
    end_friction_angle_deg: float | None = None

    def __post_init__(self) -> None:
        if self.axial_strain is not None and self.rows is None:  # made from its arrays
            self.rows = int(self.axial_strain.size)
            self.peak_friction_angle_deg = math.degrees(math.asin(float(self.stress_ratio.max())))
            self.end_friction_angle_deg = math.degrees(math.asin(float(self.stress_ratio[-1])))
        super().__post_init__()


def read_lab_curve(path: str | os.PathLike) -> LabCurve:
    """Read and check a laboratory biaxial CSV (the columns are the module's)."""
    table = read_lab_table(path)
    rows = np.arange(len(table.rows))
    e1, ratio, ev = _columns(table)
    return _curve(table, rows, e1, ratio, ev, "curve")


def _columns(table: LabTable) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The axial strain, the stress ratio and (or None) the volumetric strain of every row, each
    value checked on its own (the checks of a whole curve are :func:`_curve`'s)."""
    by_stresses = table.has("sigma_1_kpa", "sigma_3_kpa")
    if not table.has("axial_strain") or not (table.has("stress_ratio") or by_stresses):
        raise InputError(
            "lab columns", ",".join(table.header),
            "axial_strain with stress_ratio (or sigma_1_kpa and sigma_3_kpa), volumetric_strain optional",
        )  # fmt: skip
    if len(table.rows) == 0:
        raise InputError("lab", table.path, f"a CSV with a header and at least {MIN_CURVE_POINTS} data rows")
    e1 = table.column("axial_strain", 0.0, MAX_STRAIN, "(a fraction)", "is the column in percent?")
    ratio = _stress_ratio(table) if not table.has("stress_ratio") else table.column("stress_ratio", 0.0, 1.0)
    ev = None
    if table.has("volumetric_strain"):
        ev = table.column(
            "volumetric_strain", -MAX_STRAIN, MAX_STRAIN, "(a fraction)", "is the column in percent?"
        )
    return e1, ratio, ev


def _curve(table: LabTable, rows: np.ndarray, e1, ratio, ev, what: str) -> LabCurve:
    """The curve of ``rows`` (in file order): enough readings, a rising axial strain, a peak of a soil."""
    check_enough_points(table, rows, what)
    check_rising(table, "axial_strain", e1[rows], rows, "the axial strain")
    _check_peak_ratio(table, ratio, rows)
    return LabCurve(table.path, e1[rows], ratio[rows], None if ev is None else ev[rows])


#: the column that names each row's test in a file of several tests (:func:`read_lab_tests`)
CONFINING_COLUMN = "confining_stress_kpa"


@dataclass(frozen=True)
class LabTests:
    """Laboratory biaxial tests at several confining stresses: a :class:`LabCurve` per sigma_3 (kPa)."""

    sources: tuple[str, ...]
    curves: dict[float, LabCurve]

    @property
    def source(self) -> str:
        return ", ".join(self.sources)

    def confining_stresses(self) -> list[float]:
        return sorted(self.curves)


def read_lab_tests(paths) -> LabTests:
    """Read laboratory biaxial tests from one CSV or several: each row names its test's confining
    stress in ``confining_stress_kpa`` (one file per test, or every test in one file); each test's
    rows are a curve as :func:`read_lab_curve` checks it. A confining stress given twice is refused."""
    paths = [paths] if isinstance(paths, str | os.PathLike) else list(paths)
    if not paths:
        raise InputError("--biaxial-lab", "nothing", "one laboratory CSV or more")
    curves: dict[float, LabCurve] = {}
    for path in paths:
        table = read_lab_table(path)
        if not table.has(CONFINING_COLUMN):
            raise InputError(
                "lab columns", ",".join(table.header), f"{CONFINING_COLUMN} beside the curve's columns",
                "the confining stress sigma_3 each test was run at",
            )  # fmt: skip
        e1, ratio, ev = _columns(table)
        lo, hi = CONFINING_RANGE_KPA
        s3 = table.column(CONFINING_COLUMN, lo, hi, "kPa", "the confining stresses a biaxial test runs at")
        for sigma in np.unique(s3):
            rows = np.flatnonzero(s3 == sigma)  # rows in file order, never re-sorted
            if float(sigma) in curves:
                raise InputError(
                    f"lab {CONFINING_COLUMN} ({table.where(int(rows[0]), CONFINING_COLUMN)})", float(sigma),
                    "each confining stress in one test",
                    f"a test at {sigma:g} kPa was read from {curves[float(sigma)].source}",
                )  # fmt: skip
            curves[float(sigma)] = _curve(table, rows, e1, ratio, ev, f"curve at {sigma:g} kPa")
    return LabTests(tuple(str(p) for p in paths), curves)


def _stress_ratio(table: LabTable) -> np.ndarray:
    """(sigma_1 - sigma_3) / (sigma_1 + sigma_3) of each row, from stresses a test runs at."""
    lo, hi = CONFINING_RANGE_KPA
    s3 = table.column("sigma_3_kpa", lo, hi, "kPa", "the confining stresses a biaxial test runs at")
    s1 = table.column("sigma_1_kpa", lo, math.inf, "kPa")
    for i in range(len(s1)):
        if not s3[i] <= s1[i] <= MAX_PRINCIPAL_RATIO * s3[i]:
            raise InputError(
                f"lab sigma_1_kpa ({table.where(i, 'sigma_1_kpa')})", float(s1[i]),
                f"[1, {MAX_PRINCIPAL_RATIO:.3g}] times sigma_3 ({s3[i]:g} kPa)",
                "the major stress of a soil sheared at this confining stress",
            )  # fmt: skip
    return (s1 - s3) / (s1 + s3)


def _check_peak_ratio(table: LabTable, ratio: np.ndarray, rows: np.ndarray) -> None:
    """The peak stress ratio of ``rows`` is sin(phi) of a soil: above 0 and at most :data:`MAX_SIN_PHI`."""
    k = int(rows[np.argmax(ratio[rows])])
    if not 0.0 < ratio[k] <= MAX_SIN_PHI:
        name = "stress_ratio" if table.has("stress_ratio") else "sigma_1_kpa"
        raise InputError(
            f"lab {name} (the curve's peak, {table.where(k, name)})", float(ratio[k]),
            f"a peak stress ratio in (0, {MAX_SIN_PHI:.3f}]",
            f"sin(phi) = {ratio[k]:.3g}: no soil is that {'weak' if ratio[k] <= 0.0 else 'strong'}",
        )  # fmt: skip


__all__ = ["CONFINING_COLUMN", "LabCurve", "LabTests", "read_lab_curve", "read_lab_tests"]
