"""TOML configuration files: strict keys, clear errors, presets."""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
import types
import typing
from typing import Any

import numpy as np

from poro2d.errors import InputError, is_integer, is_number
from poro2d.io_utils import read_user_text


def load_toml(path: str | os.PathLike) -> dict:
    """The raw tables of the TOML file at ``path``: read at the edge, where each command turns them
    into its settings and cases once."""
    p, text = read_user_text("config", path, "TOML")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError("config", str(p), "valid TOML", str(exc)) from None


def check_keys(section: str, table: dict, allowed: set[str] | list[str]) -> None:
    """Unknown keys are errors: a typo must not silently fall back to a default."""
    if not isinstance(table, dict):
        raise InputError(section, table, "a table of key = value pairs")
    extra = sorted(set(table) - set(allowed))
    if extra:
        raise InputError(
            f"{section}.{extra[0]}", table[extra[0]], f"known keys: {', '.join(sorted(allowed))}"
        )


def dataclass_from_table(cls, section: str, table: dict | None, **overrides: Any):
    """Build a dataclass from a config table, rejecting unknown keys and values of the wrong type."""
    table = {} if table is None else table
    names = {f.name for f in dataclasses.fields(cls)}
    check_keys(section, table, names)
    table = dict(table)
    check_types(cls, section, table)
    given = {k: v for k, v in overrides.items() if v is not None}
    table.update(given)
    try:
        return cls(**table)
    except TypeError as exc:
        raise InputError(section, table, "values of the right type", str(exc)) from None
    except InputError as exc:  # a field's own check: named as the key the user typed in the file
        if exc.parameter not in table or exc.parameter in given:
            raise
        raise InputError(f"{section}.{exc.parameter}", exc.value, exc.allowed, exc.hint) from None


# what a config value of each field type must be, and how the error names it
_KINDS: dict[type, tuple[Any, str]] = {
    float: (is_number, "a number"),
    int: (is_integer, "an integer"),
    bool: (lambda v: isinstance(v, bool), "true or false"),
    str: (lambda v: isinstance(v, str), "a string"),
    dict: (lambda v: isinstance(v, dict), "a table"),
    list: (lambda v: isinstance(v, list), "a list"),
}


def check_types(cls, section: str, table: dict) -> None:
    """Refuse config values whose type does not match the dataclass field they set.

    TOML keeps ``"0.33"`` a string and ``true`` a boolean; a dataclass would store them
    as they are (a string porosity, ``layers = true`` taken as 1 because bool is an int in
    Python). Numbers are strict here: a float field takes an integer or a float, an int
    field only an integer, and neither takes a boolean or text.
    """
    hints = typing.get_type_hints(cls)
    for key, value in table.items():
        kinds = _field_kinds(hints.get(key))
        if not kinds or (value is None and type(None) in kinds):
            continue
        checks = [_KINDS[k] for k in kinds if k in _KINDS]
        if checks and not any(ok(value) for ok, _ in checks):
            raise InputError(f"{section}.{key}", value, " or ".join(what for _, what in checks))


def _field_kinds(hint: Any) -> tuple:
    """The plain types a field annotation allows (``float | None`` -> (float, NoneType))."""
    if hint is None:
        return ()
    if isinstance(hint, types.UnionType) or typing.get_origin(hint) is typing.Union:
        return tuple(k for a in typing.get_args(hint) for k in _field_kinds(a))
    origin = typing.get_origin(hint)
    return (origin,) if origin is not None else (hint,)


def check_finite(section: str, value: Any) -> None:
    """Every number in ``value`` (nested tables and lists) must be finite.

    TOML accepts ``inf`` and ``nan``, and a range check with an open end lets an
    infinity through; neither has a meaning in a config, nor a JSON spelling.
    """
    if isinstance(value, dict):
        for k, v in value.items():
            check_finite(f"{section}.{k}" if section else str(k), v)
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            check_finite(f"{section}[{i}]", v)
    elif isinstance(value, float):  # integers are always finite
        if not math.isfinite(value):
            raise InputError(section, value, "a finite number")
    elif isinstance(value, (np.generic, np.ndarray)) and np.issubdtype(np.asarray(value).dtype, np.number):
        if not np.all(np.isfinite(value)):
            raise InputError(section, np.asarray(value).tolist(), "finite numbers")


def check_number_list(
    parameter: str,
    values: Any,
    lo: float,
    hi: float,
    *,
    min_items: int = 1,
    max_items: int = 50,
    lo_open: bool = False,
    increasing: bool = False,
    what: str = "numbers",
) -> list[float]:
    """A list of ``min_items`` to ``max_items`` numbers, each in ``[lo, hi]``; or InputError.

    TOML hands over what was written: a scalar (``mu_prep = 0.1``), a boolean, a string
    (which would iterate as its letters) or an empty list are mistakes in the list's shape,
    refused here with the range a value must lie in, not fallen back on or iterated.
    ``increasing``: the values must rise strictly (a calibration's frictions, densest first).
    """
    lo_s = "(" if lo_open else "["
    allowed = f"a list of {min_items} to {max_items} {what} in {lo_s}{lo:g}, {hi:g}]"
    if increasing:
        allowed += ", strictly increasing"
    if not isinstance(values, list | tuple) or not min_items <= len(values) <= max_items:
        raise InputError(parameter, values, allowed)
    out = []
    for v in values:
        if not is_number(v):
            raise InputError(parameter, values, allowed, f"{v!r} is not a number")
        if not (math.isfinite(float(v)) and (lo < v if lo_open else lo <= v) and v <= hi):
            raise InputError(parameter, values, allowed, f"{v!r} is out of range")
        out.append(float(v))
    if increasing and any(b <= a for a, b in zip(out, out[1:], strict=False)):
        raise InputError(parameter, values, allowed)
    return out
