"""JSON's own types: NumPy numbers and arrays, tuples and paths as plain JSON values, NaN as null.

A ground-floor module (below the typed results, which hold their values this way from the
moment they are made, and below :mod:`poro2d.io_utils`, which writes them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any


def json_value(o):
    """One value JSON has no type for, as one it has (NumPy, a path, a typed result as its dict)."""
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    if callable(getattr(o, "to_dict", None)):  # a typed result or record: the dict of its file
        return o.to_dict()
    raise TypeError(f"not JSON serialisable: {type(o)}")


def to_json_types(obj: Any) -> Any:
    """``obj`` with NumPy scalars and arrays, tuples and paths as plain JSON types.

    A NumPy boolean becomes ``True``/``False`` (never the string ``"True"``), so a
    value reads back with the type it was written with.
    """
    if isinstance(obj, Mapping):
        return {_key(k): to_json_types(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_json_types(v) for v in obj]
    if isinstance(obj, (str, bool, int, float, type(None))):
        return obj
    return to_json_types(json_value(obj))


def _key(k: Any) -> Any:
    """A mapping key as JSON accepts it (json itself spells numbers and booleans as text)."""
    if isinstance(k, (str, bool, int, float, type(None))):
        return k
    return str(json_value(k)) if isinstance(k, Path) else json_value(k)


def _finite_or_null(obj: Any) -> Any:
    """NaN and infinities as ``None``: JSON has no token for them (``NaN`` is not JSON)."""
    if isinstance(obj, dict):
        return {k: _finite_or_null(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_finite_or_null(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def as_json(data: Any) -> Any:
    """``data`` as :func:`poro2d.io_utils.write_json` stores it and ``json.loads`` reads it back.

    Code that uses a result both fresh and, on a resumed run, from its file gets
    the same types either way (booleans, not NumPy booleans; ``None``, not NaN).
    """
    return _finite_or_null(to_json_types(data))


__all__ = ["as_json", "json_value", "to_json_types"]
