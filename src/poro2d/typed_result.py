"""Typed results: dataclasses that are written to, and read back from, a run's JSON files.

A result class lists the keys of its file as dataclass fields, in the file's order, so
code and readers see in one place what a file holds and of which type. The files do not
change: :meth:`TypedResult.to_dict` gives exactly the keys written before results were
typed, and :meth:`TypedResult.from_dict` reads any such file back so that writing it again
gives the same dict. Keys a class does not model are kept in ``extra`` (a file of a newer
or older poro2d, a key added by another tool); keys it models that a file lacks stay
absent; keys listed in ``OPTIONAL`` are written only when set (parts a run has only with
an option, such as a shear series' ``rate_check``). A field declared with
``field(metadata=NOT_IN_FILE)`` (and a default) is not a key of the file: it carries what a
run hands its caller beside the file (a replicate study's per-specimen series), and
``from_dict`` leaves it at its default.

Results are values: two results of one class are equal when their files are (``to_dict()``),
and code reads their fields as attributes (``result.final_porosity``), never by key.

Several result classes may share an ordered group of fields that stands at another place in
each of their files (a study's ``settings``, ``processes``, ``wall_time_s``, ``config``,
``provenance``): the group is declared once as a plain dataclass, and :func:`with_fields`
puts its fields into each class at its place, as if typed there::

    @dataclass
    class StudyTail:
        processes: int
        wall_time_s: float

    @dataclass(eq=False)
    @with_fields(StudyTail, after="replicates")  # below @dataclass: it runs first
    class MyResult(TypedResult):
        replicates: int
        note: str  # the file's keys: replicates, processes, wall_time_s, note
"""

from __future__ import annotations

import typing
from collections.abc import Callable, Mapping
from dataclasses import MISSING, dataclass, field, fields
from functools import cache
from typing import Any, ClassVar, Self, TypeVar

from poro2d.json_types import as_json
from poro2d.record import Record

#: the metadata of a field that is not a key of the result's file
NOT_IN_FILE = {"in_file": False}

R = TypeVar("R", bound="TypedResult")


@cache
def _keys(cls: type) -> tuple[str, ...]:
    """The file keys a result class models: its fields but ``extra`` and those not in the file."""
    return tuple(f.name for f in fields(cls) if f.name != "extra" and f.metadata.get("in_file", True))


def _plain(value: Any) -> Any:
    """A typed part (a result or a :class:`~poro2d.record.Record`) as the dict of its file, a list
    of them as a list of dicts, a map of them as a map of dicts; anything else as it is."""
    if isinstance(value, TypedResult | Record):
        return value.to_dict()
    if isinstance(value, list) and any(isinstance(v, TypedResult | Record) for v in value):
        return [_plain(v) for v in value]
    if isinstance(value, dict) and any(isinstance(v, TypedResult | Record) for v in value.values()):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _as_stored(value: Any) -> Any:
    """``value`` as its file reads back: NumPy numbers and arrays as plain ones, tuples as lists,
    NaN and infinities as None (:func:`poro2d.json_types.as_json`); a typed part as it is (it holds
    its own values so already), a list or map of them with each one so."""
    if isinstance(value, TypedResult | Record):
        return value
    if isinstance(value, list | tuple) and any(isinstance(v, TypedResult | Record) for v in value):
        return [_as_stored(v) for v in value]
    if isinstance(value, dict) and any(isinstance(v, TypedResult | Record) for v in value.values()):
        return {k: _as_stored(v) for k, v in value.items()}
    return as_json(value)


def _typed(kind: Any, value: Any) -> Any:
    """``value`` of a field whose ``PARTS`` entry is ``kind``: the dict of a part (or each dict of
    a list of them, or each value of a :class:`Keyed` map) read as the part; else as it is."""
    if isinstance(kind, Keyed):
        return kind.read(value)
    if isinstance(kind, type) and issubclass(kind, TypedResult | Record):  # not a decoder of its own
        return [part(kind, v) for v in value] if isinstance(value, list) else part(kind, value)
    return value


def part(cls: type[R], value: Any) -> Any:
    """``value`` as the part ``cls`` when it is the dict of one (as read from a file), else as it is."""
    if isinstance(value, Mapping) and not isinstance(value, cls):
        return cls.from_dict(value)
    return value


@dataclass(frozen=True)
class Keyed:
    """A ``PARTS`` entry for a field that maps names to parts of one class (a file's object whose
    values are the objects of ``kind``, such as a calibration's surrogate per observable): its
    names are data (they vary from run to run), its values are typed."""

    kind: type[TypedResult] | type[Record]

    def read(self, value: Any) -> Any:
        """``value`` with each of its values read as ``kind`` (as it is when not a map)."""
        if not isinstance(value, Mapping):
            return value
        return {k: part(self.kind, v) for k, v in value.items()}


def with_fields(group: type, *, after: str | None = None, optional: bool = False) -> Callable[[type], type]:
    """A class decorator, written below ``@dataclass``: the fields of the dataclass ``group``
    (names, types, defaults and metadata, in its order) become the decorated class's own, right
    after its field ``after`` (first when None). With ``optional`` each is ``T | None = None``
    instead (a group of values that a file of an earlier version, or a run without them, lacks).
    See the module's docstring."""
    hints = typing.get_type_hints(group)  # types, not their text: the class's module may not know them
    if optional:
        hints = {name: kind | None for name, kind in hints.items()}

    def insert(cls: type) -> type:
        own = dict(cls.__dict__.get("__annotations__", {}))
        names = list(own)
        at = 0 if after is None else names.index(after) + 1
        shared = {f.name: hints[f.name] for f in fields(group)}
        cls.__annotations__ = {**{k: own[k] for k in names[:at]}, **shared, **{k: own[k] for k in names[at:]}}
        for f in fields(group):
            default, factory = (None, MISSING) if optional else (f.default, f.default_factory)
            if default is not MISSING or factory is not MISSING:
                # keyword-only where the group says so, else as the class's own fields are
                only = True if f.kw_only else MISSING
                kinds = {"repr": f.repr, "compare": f.compare, "kw_only": only, "metadata": f.metadata}
                setattr(cls, f.name, field(default=default, default_factory=factory, **kinds))
        return cls

    return insert


@dataclass(eq=False)
class TypedResult:
    """Base of typed results; subclasses are ``@dataclass(eq=False)`` with one field per key."""

    #: keys written only when their value is not None
    OPTIONAL: ClassVar[tuple[str, ...]] = ()

    #: fields that are typed parts: field -> the TypedResult class (or a Record class with a
    #: ``from_dict``) its file's dict (or each dict of its file's list) is read as by
    #: :meth:`from_dict`, or :class:`Keyed` of it for a map of such parts; :meth:`to_dict` writes
    #: them back as dicts
    PARTS: ClassVar[Mapping[str, Any]] = {}

    #: False for a row of a CSV table, whose file tells NaN ("nan") from no value (empty): its
    #: values stay as given (a JSON file holds both as null, so a result of one is made so)
    JSON_VALUES: ClassVar[bool] = True

    #: keys of the file that the class does not model, written back after the modelled ones
    extra: dict[str, Any] = field(default_factory=dict, kw_only=True, repr=False)

    def __post_init__(self) -> None:
        # keys a file read by from_dict lacked: they stay out of to_dict() while unset
        self._absent: frozenset[str] = frozenset()
        if isinstance(self, Record) or not self.JSON_VALUES:  # a row of its own shape (ROW), or CSV's
            return
        # every value as its file holds it, typed parts typed, so that a fresh result equals the
        # one read back from its file
        for key in _keys(type(self)):
            setattr(self, key, _as_stored(_typed(self.PARTS.get(key), getattr(self, key))))
        self.extra = _as_stored(self.extra)

    def _present(self, key: str) -> bool:
        """Whether ``key`` is in the file: unless unset (None) where a file lacked it or it is optional."""
        return getattr(self, key) is not None or (key not in self._absent and key not in self.OPTIONAL)

    def to_dict(self) -> dict[str, Any]:
        """The keys and values of the file, in its order (a shallow copy: nested values are shared).

        A field holding a typed part (a record such as a file's provenance), or a list of them, is
        written as its dict(s).
        """
        out = {k: _plain(getattr(self, k)) for k in _keys(type(self)) if self._present(k)}
        out.update(self.extra)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Self:
        """A result from the dict of its file (``json.loads`` of it, or a result's ``to_dict()``)."""
        keys = _keys(cls)
        obj = cls(**{k: data.get(k) for k in keys}, extra={k: v for k, v in data.items() if k not in keys})
        obj._absent = frozenset(k for k in keys if k not in data)
        return obj

    def __eq__(self, other: object) -> bool:
        """Equal to a result of the same class whose file is the same."""
        if type(other) is not type(self):
            return NotImplemented
        return self.to_dict() == other.to_dict()  # type: ignore[attr-defined]

    __hash__ = None  # type: ignore[assignment]  # results are not frozen


__all__ = ["NOT_IN_FILE", "Keyed", "TypedResult", "part", "with_fields"]
