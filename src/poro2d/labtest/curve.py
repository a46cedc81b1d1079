"""A test's curve: rows of named columns, recorded as rows and held as one array per column.

A test records one :class:`CurveRow` per interval (a row of its ``curve.csv``); once recorded,
the rows are held as a :class:`ColumnCurve`, one float array per column, that reads and
writes the rows one way for every test: every value through ``float`` as the CSV file
stores it, so a curve in memory and one read back from its file are the same arrays.
Columns added after a test's first files are of two kinds: ``LATER`` ones read as NaN where
a row lacks them (the curve always has them), ``OPTIONAL`` ones are the curve's only where
every row has them (None otherwise, and not written).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, fields, make_dataclass
from typing import Any, ClassVar, Self

import numpy as np

from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class CurveRow(TypedResult):
    """Base of one recorded row of a test's curve: its fields the columns, in the file's order."""

    JSON_VALUES: ClassVar[bool] = False  # a row of a CSV table: NaN stays NaN ("nan")


def _as_read(cls: type[ColumnCurve], row: CurveRow | Mapping) -> Mapping:
    """A row as its curve reads it: a recorded row's None (NaN held so, or a column an earlier
    checkpoint's row lacks) as NaN, and a ``LATER`` column a row of an earlier file lacks as NaN."""
    if isinstance(row, CurveRow):
        given = row.to_dict()
        return {**given, **{k: math.nan for k in cls.COLUMNS if given.get(k) is None}}
    return {**row, **{k: math.nan for k in cls.LATER if k not in row}}


def _given(value: Any) -> bool:
    """Whether a row holds a value (a CSV file's empty field, or a row's None, holds none)."""
    return value is not None and value != ""


@dataclass(frozen=True, eq=False)
class ColumnCurve(Mapping):
    """Base of a recorded curve: one float array per column, and a read-only mapping of the
    columns it has to their arrays, in the file's order.

    A subclass declares one field per column, in order, and names them: ``COLUMNS`` (every
    curve has them), ``LATER`` (among ``COLUMNS``: read as NaN where a row lacks them) and
    ``OPTIONAL`` (after ``COLUMNS``: None where a row lacks them).
    """

    COLUMNS: ClassVar[tuple[str, ...]] = ()
    LATER: ClassVar[tuple[str, ...]] = ()
    OPTIONAL: ClassVar[tuple[str, ...]] = ()

    @property
    def columns(self) -> tuple[str, ...]:
        """The columns this curve has, in the file's order."""
        return self.COLUMNS + tuple(k for k in self.OPTIONAL if getattr(self, k) is not None)

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.columns:
            raise KeyError(name)
        return getattr(self, name)

    def __iter__(self) -> Iterator[str]:
        return iter(self.columns)

    def __len__(self) -> int:
        return len(self.columns)

    @classmethod
    def of_rows(cls, rows: list[CurveRow] | list[Mapping]) -> Self:
        """The rows (recorded, or read from the CSV file) as columns, every value through ``float``;
        a row of the file lacking a column that is not ``LATER`` is no row of this curve (KeyError)."""
        rows = [_as_read(cls, r) for r in rows]
        kept = [k for k in cls.OPTIONAL if rows and all(_given(r.get(k)) for r in rows)]
        return cls(**{k: np.array([float(r[k]) for r in rows]) for k in (*cls.COLUMNS, *kept)})

    def rows(self) -> list[dict[str, float]]:
        """The curve as rows of Python floats (for its CSV file)."""
        names = self.columns
        cols = [self[k].tolist() for k in names]
        return [dict(zip(names, values, strict=True)) for values in zip(*cols, strict=True)]


def curve_of(
    row: type[CurveRow], name: str, module: str, doc: str | None = None, *, later: tuple[str, ...] = (),
    optional: tuple[str, ...] = (),
) -> type[ColumnCurve]:  # fmt: skip
    """The curve class of the rows ``row``, named ``name`` in ``module``: a float array per field of
    the row, in its order, ``later`` ones among them read as NaN where a row lacks them; ``optional``
    ones last, None where a row lacks them (the row's, then those a curve is given afterwards).
    Its columns are declared once, as the row's fields."""
    required = tuple(f.name for f in fields(row) if f.name not in (*optional, "extra"))
    columns = [
        *((k, np.ndarray) for k in required),
        *((k, np.ndarray | None, field(default=None)) for k in optional),
    ]
    namespace = {
        "__doc__": doc,
        "__module__": module,
        "COLUMNS": required,
        "LATER": later,
        "OPTIONAL": optional,
    }
    return make_dataclass(name, columns, bases=(ColumnCurve,), namespace=namespace, frozen=True, eq=False)


__all__ = ["ColumnCurve", "CurveRow", "curve_of"]
