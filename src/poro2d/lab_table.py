"""A laboratory CSV as a checked table: the one reader of every laboratory file.

Direct shear (``shear --lab``, ``calibrate --lab``, the case study) and biaxial (``biaxial
--lab``) files differ in their columns and in what their numbers may be, not in how they are
read. Reading them one way keeps one set of rules for all of them:

* the file is a regular UTF-8 file of a sane size; a byte order mark at its start is dropped
  (spreadsheets write one);
* blank lines and lines starting with ``#`` are comments; the first other line is the header,
  whose names are matched without case or surrounding spaces; extra columns are ignored;
* every data row has as many cells as the header;
* a number is digits, a sign, a point and an exponent: ``1_000``, which Python's ``float``
  reads, is refused (no spreadsheet writes it, so it is a typing mistake), and so are
  ``nan`` and ``inf``; each column also has a range, given by the caller.

Every refusal is an :class:`~poro2d.errors.InputError` naming the file, the line and the
column, so the user can find the cell.

The physical bounds shared by the readers live here too: :data:`MAX_TAN_PHI`, the largest
peak stress ratio tau/sigma accepted (a friction angle of 68 degrees), and
:data:`MIN_CURVE_POINTS`, the fewest readings of a whole curve.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass

import numpy as np

from poro2d.errors import InputError
from poro2d.io_utils import read_user_text

#: Largest peak tau/sigma accepted: tan(68.2 degrees). Bolton (1986, Geotechnique 36(1)) bounds
#: the peak angle of sands by the critical-state angle (at most about 40 degrees for angular
#: grains) plus 5 I_R with I_R <= 4, i.e. under 60 degrees; rockfill at the lowest stresses of a
#: shear box stays under about 65 degrees (Barton and Kjaernsli 1981). A larger ratio is a unit
#: or column mistake, not a soil.
MAX_TAN_PHI = 2.5
#: Fewest readings of a whole laboratory curve: a rise, a peak and what follows it.
MIN_CURVE_POINTS = 5


@dataclass(frozen=True)
class LabTable:
    """The data rows of a laboratory CSV, as text, with the file line of each row."""

    path: str
    header: tuple[str, ...]
    lines: tuple[int, ...]
    rows: tuple[tuple[str, ...], ...]

    def has(self, *names: str) -> bool:
        """Whether the header names every one of ``names``."""
        return all(n in self.header for n in names)

    def where(self, row: int, name: str) -> str:
        """Where a cell is, as a refusal names it: line and column (from 1) of the file."""
        return f"line {self.lines[row]}, column {self.header.index(name) + 1} of {self.path}"

    def column(self, name: str, lo: float, hi: float, unit: str = "", why: str = "") -> np.ndarray:
        """The column ``name`` as numbers, each in [lo, hi] (in ``unit``, named in a refusal)."""
        k = self.header.index(name)
        allowed = f"[{lo:g}, {hi:g}{')' if hi == math.inf else ']'}" + (f" {unit}" if unit else "")
        values = np.empty(len(self.rows))
        for i, row in enumerate(self.rows):
            v = _number(self, i, name, row[k].strip())
            if not lo <= v <= hi:
                raise InputError(f"lab {name} ({self.where(i, name)})", v, allowed, why)
            values[i] = v
        return values


def _number(table: LabTable, row: int, name: str, text: str) -> float:
    return parse_number(text, f"lab {name} ({table.where(row, name)})")


def parse_number(text: str, parameter: str) -> float:
    """A cell as a finite number written as spreadsheets write numbers; ``parameter`` names the
    cell in a refusal (file, line and column)."""
    text = text.strip()
    if "_" in text:  # Python's float() reads 1_000; a spreadsheet never writes it
        raise InputError(parameter, text, "a number (digits, sign, point, exponent)")
    try:
        v = float(text)
    except ValueError:
        raise InputError(parameter, text, "a number") from None
    if not math.isfinite(v):
        raise InputError(parameter, text, "a finite number")
    return v


def read_lab_table(path: str | os.PathLike) -> LabTable:
    """Read a laboratory CSV's header and data rows (the rules are the module's)."""
    p, text = read_user_text("lab", path, "CSV")
    numbered = [
        (k + 1, ln)
        for k, ln in enumerate(text.splitlines())
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not numbered:
        raise InputError("lab", str(p), "a CSV with a header and data rows")
    # each line on its own: a stray quote must not join the lines after it into one row
    rows = [next(csv.reader([ln])) for _, ln in numbered]
    header = tuple(h.strip().lower() for h in rows[0])
    for (line, _), row in zip(numbered[1:], rows[1:], strict=True):
        if len(row) != len(header):  # a cell too many is as unclear as one too few: which column moved?
            where = f"line {line}, column {min(len(row), len(header)) + 1} of {p}"
            raise InputError(f"lab row ({where})", ",".join(row), f"{len(header)} columns, as the header")
    lines = tuple(line for line, _ in numbered[1:])
    return LabTable(str(p), header, lines, tuple(tuple(r) for r in rows[1:]))


def check_rising(table: LabTable, name: str, values: np.ndarray, rows: np.ndarray, what: str) -> None:
    """``values`` (the column ``name`` at ``rows``, in file order) rise strictly from row to row:
    a step back or a repeat is a curve pasted twice or sorted by another column."""
    steps = np.diff(values)
    if np.any(steps <= 0.0):
        k = int(np.argmax(steps <= 0.0)) + 1
        raise InputError(
            f"lab {name} ({table.where(int(rows[k]), name)})", float(values[k]),
            f"more than {float(values[k - 1]):g} (line {table.lines[int(rows[k - 1])]}): {what} "
            "rises from row to row",
        )  # fmt: skip


def check_enough_points(table: LabTable, rows: np.ndarray, what: str) -> None:
    """A whole curve has at least :data:`MIN_CURVE_POINTS` readings."""
    if len(rows) < MIN_CURVE_POINTS:
        raise InputError(
            f"lab {what} (line {table.lines[int(rows[0])]} of {table.path})", f"{len(rows)} reading(s)",
            f"at least {MIN_CURVE_POINTS} readings (a peak and what follows it)",
        )  # fmt: skip


__all__ = [
    "MAX_TAN_PHI",
    "MIN_CURVE_POINTS",
    "LabTable",
    "check_enough_points",
    "check_rising",
    "parse_number",
    "read_lab_table",
]
