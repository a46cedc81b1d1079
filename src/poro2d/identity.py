"""What makes two runs the same run: one rule, one digest.

A run is described by what it was given: settings dataclasses (``SpecimenSpec``,
``ShearSettings``, ...), plain config tables, a seed, the digest of a specimen file. Two
descriptions name the same run when they are equal once every setting that changes how a
run goes, never what it computes, is left out: the thread count (the engine sums in the
same order on any number of threads), what a run shows while it goes. Such a field is
marked where it is declared, with :func:`outside_identity`, so the rule travels with the
field; nobody drops keys by hand.

Every place that asks "is this the same run?" asks here: a resumable folder's record
(:class:`poro2d.store.stage.Fingerprint`), a sweep case's id and folder, a cached
calibration, a calibration's shear test, the density checks that are calibration cases
already. :func:`identity_view` gives the description as compared (to name the keys that
differ), :func:`identity_digest` its SHA-256.

A plain config table carries no marks of its own: ``tables`` says which dataclass a table
of the description stands for (``{"config.specimen": SpecimenSpec}``), and that class's
marked fields are left out of it.

What a state *file* holds is another question: :func:`poro2d.dem.checkpoint.state_digest`
hashes the arrays a checkpoint stores, whichever run wrote them, so two runs that reach
the same state give the same digest. That content hash enters run descriptions as a value
(the specimen a shear test starts from); it is not a run identity itself.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Iterable, Mapping
from typing import Any, Literal

from poro2d.io_utils import as_json

#: the key of a field's metadata that marks it as outside the run's identity
IDENTITY = "poro2d.identity"

#: how the digest's text is spaced: "compact" for every key but two written before this
#: module; "spaced" (json's default separators) for the cached calibrations and calibration
#: units, whose folders are named by their digest and keep their names
_SEPARATORS = {"compact": (",", ":"), "spaced": (", ", ": ")}


def outside_identity(default: Any = dataclasses.MISSING, **kwargs: Any) -> Any:
    """A dataclass field that changes how a run goes (its speed, its display), never its numbers.

    Used as ``threads: int = outside_identity(1)``; the field is recorded with results as
    before, but two runs that differ only in it are the same run.
    """
    metadata = {**(kwargs.pop("metadata", None) or {}), IDENTITY: False}
    return dataclasses.field(default=default, metadata=metadata, **kwargs)


def outside_fields(cls: type) -> tuple[str, ...]:
    """The names of ``cls``'s fields marked with :func:`outside_identity`, in declaration order."""
    return tuple(f.name for f in dataclasses.fields(cls) if f.metadata.get(IDENTITY) is False)


def outside_keys(tables: Mapping[str, type]) -> tuple[str, ...]:
    """Dotted keys of each table's marked fields: ``{"specimen": SpecimenSpec}``: ``specimen.threads``."""
    return tuple(f"{path}.{name}" for path, cls in tables.items() for name in outside_fields(cls))


def _described(obj: Any) -> Any:
    """``obj`` with every dataclass instance in it as a dict of its fields inside the identity."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {
            f.name: _described(getattr(obj, f.name))
            for f in dataclasses.fields(obj)
            if f.metadata.get(IDENTITY, True)
        }
    if isinstance(obj, Mapping):
        return {k: _described(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_described(v) for v in obj]
    return obj


def _without(data: Any, path: list[str]) -> Any:
    """``data`` with the dotted ``path`` removed (a copy along the path; absent paths are fine)."""
    if not isinstance(data, Mapping) or path[0] not in data:
        return data
    if len(path) == 1:
        return {k: v for k, v in data.items() if k != path[0]}
    return {**data, path[0]: _without(data[path[0]], path[1:])}


def identity_view(
    description: Any, *, tables: Mapping[str, type] | None = None, ignore: Iterable[str] = ()
) -> Any:
    """The run ``description`` as JSON, with everything that does not change its results left out.

    Left out are the marked fields of dataclasses in it and of the tables named in
    ``tables`` (dotted path -> dataclass), and the dotted keys ``ignore`` (labels that a
    caller derives from the rest, such as a sweep case's id).
    """
    data = as_json(_described(description))
    for key in (*outside_keys(tables or {}), *ignore):
        data = _without(data, key.split("."))
    return data


def identity_digest(
    description: Any,
    *,
    tables: Mapping[str, type] | None = None,
    ignore: Iterable[str] = (),
    length: int | None = None,
    layout: Literal["compact", "spaced"] = "compact",
) -> str:
    """SHA-256 (hex) of :func:`identity_view` as sorted JSON: the same run, the same digest.

    ``length``: the first that many hex digits (folder names); ``layout``: the spacing of the
    hashed text, "spaced" only for the two kinds of key written that way before (see
    ``_SEPARATORS``).
    """
    view = identity_view(description, tables=tables, ignore=ignore)
    text = json.dumps(view, sort_keys=True, separators=_SEPARATORS[layout], default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:length]


__all__ = [
    "IDENTITY",
    "identity_digest",
    "identity_view",
    "outside_fields",
    "outside_identity",
    "outside_keys",
]
