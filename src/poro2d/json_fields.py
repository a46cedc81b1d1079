"""Scalars read out of a JSON object that poro2d (any version) or a hand wrote: a value of another
shape reads as not said (None), so a caller refuses it or names it unknown in its own words.

The readers of records left beside specimens and runs (the acceptance check of
:mod:`poro2d.specimen.accepted`, the exporters' run records) share these few lookups.
"""

from __future__ import annotations

import math


def number_at(data: dict, *keys: str) -> float | None:
    """The finite number at ``keys`` (nested objects), None when absent or of another kind."""
    return finite_number(value_at(data, *keys))


def finite_number(value) -> float | None:
    """``value`` as a float when it is a finite number (not a bool), else None."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        return None
    return float(value)


def int_at(data: dict, *keys: str) -> int | None:
    """The whole number (not a bool) at ``keys``, None when absent or of another kind."""
    value = value_at(data, *keys)
    return value if isinstance(value, int) and not isinstance(value, bool) else None


def text_at(data: dict, *keys: str) -> str | None:
    """The string at ``keys``, None when absent or of another kind."""
    value = value_at(data, *keys)
    return value if isinstance(value, str) else None


def said_at(data: dict, *keys: str) -> str | None:
    """The value at ``keys`` as a message quotes it (``str``), None when the key is absent."""
    parent = value_at(data, *keys[:-1]) if len(keys) > 1 else data
    if not isinstance(parent, dict) or keys[-1] not in parent:
        return None
    return str(parent[keys[-1]])


def value_at(data: dict, *keys: str) -> bool | int | float | str | None:
    """The JSON scalar at ``keys``; None when a key is absent, a step is not an object, or the
    value is a list or an object (a caller of this module asks for scalars only)."""
    value = data
    for key in keys:
        if not isinstance(value, dict):
            return None
        value = value.get(key)
    return None if isinstance(value, dict | list) else value


def accepted_rows(rows) -> bool:
    """True when ``rows`` is a list with a row (an object) whose ``accepted`` is true."""
    return isinstance(rows, list) and any(isinstance(r, dict) and r.get("accepted") is True for r in rows)


__all__ = ["accepted_rows", "finite_number", "int_at", "number_at", "said_at", "text_at", "value_at"]
