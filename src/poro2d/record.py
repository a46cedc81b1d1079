"""Records: frozen dataclasses that say, in one table, which keys they write and in which order.

Many small values of poro2d (a trial's wall forces, its plate stage, a laboratory state)
are written as flat keys into a row of a file (``trial.json``, ``iterations.csv``), often
under names that are not their fields' (``plate_steps`` for a plate stage's ``steps``), and
a row is made of several parts in a fixed order. Instead of each class writing its dict by
hand, a :class:`Record` declares its row in ``ROW`` and one function,
:meth:`Record.to_dict`, writes every record's:

* ``"name"``: the field ``name`` under its own key;
* ``("key", "path")``: the value at ``path`` (a field, or a part's field: ``"forces.f_top_n_per_m"``)
  under ``key``;
* ``Spliced("part")``: the part's own row, in place (nothing when the part is None; a tuple
  of parts: each one's row in turn);
* ``Fixed("key", value)``: ``key`` with the same value in every row (a former field's key,
  still written so that files keep their keys).

``OMITTED`` names the keys left out while their value is the one given (a key recorded only
when it happens, such as an over-full box's ``overfull_m``). A record whose row has two
shapes declares both and says which one applies in :meth:`Record.layout`. A value that is a
record is written as its dict (a nested table, such as a trial's ``checks``), an array as a
list (a row is written as JSON).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np


@dataclass(frozen=True)
class Spliced:
    """A row entry: the part in field ``name`` writes its own keys here (none when it is None; a
    tuple of parts writes each one's keys in turn)."""

    name: str


@dataclass(frozen=True)
class Fixed:
    """A row entry: ``key`` with ``value`` in every row (each row gets its own copy)."""

    key: str
    value: Any


def _at(obj: Any, path: str) -> Any:
    """The value at a dotted ``path`` of ``obj`` (None once a part on the way is None)."""
    for name in path.split("."):
        if obj is None:
            return None
        obj = getattr(obj, name)
    return obj


def _plain(value: Any) -> Any:
    """A record as its row, an array as a list; anything else as it is."""
    if isinstance(value, Record):
        return value.to_dict()
    return value.tolist() if isinstance(value, np.ndarray) else value


def _omitted(value: Any, when: Any) -> bool:
    return value is None if when is None else value is not None and value == when


class Record:
    """Mixin of frozen dataclasses written as rows: ``ROW`` declares the keys, :meth:`to_dict` writes them."""

    #: the row's entries in order (module docstring); empty: every field under its own name
    ROW: ClassVar[tuple] = ()
    #: key -> the value at which the key is left out of the row
    OMITTED: ClassVar[dict[str, Any]] = {}

    def layout(self) -> tuple:
        """The entries of this record's row: ``ROW`` (a record of two shapes picks one)."""
        return self.ROW or tuple(f.name for f in fields(self))  # type: ignore[arg-type]

    @classmethod
    def from_dict(cls, data: dict[str, Any]):
        """A record read back from its row, for a record whose row is every field under its own
        name (no ``ROW`` of its own); a key the row lacks reads as None."""
        if cls.ROW:
            raise TypeError(f"{cls.__name__} writes a row of its own shape: it reads it back itself")
        return cls(**{f.name: data.get(f.name) for f in fields(cls)})  # type: ignore[arg-type]

    def to_dict(self) -> dict[str, Any]:
        """The record's row: its keys in the order of :meth:`layout`, parts as their rows."""
        row: dict[str, Any] = {}
        for entry in self.layout():
            if isinstance(entry, Spliced):
                part = getattr(self, entry.name)
                for each in part if isinstance(part, tuple) else () if part is None else (part,):
                    row.update(each.to_dict())
                continue
            if isinstance(entry, Fixed):
                row[entry.key] = copy.copy(entry.value)
                continue
            key, path = (entry, entry) if isinstance(entry, str) else entry
            value = _at(self, path)
            if key in self.OMITTED and _omitted(value, self.OMITTED[key]):
                continue
            row[key] = _plain(value)
        return row


__all__ = ["Fixed", "Record", "Spliced"]
