"""TOML configuration files: strict keys, clear errors, presets."""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from poro2d.errors import InputError


def load_toml(path: str | os.PathLike) -> dict:
    p = Path(path)
    if not p.is_file():
        raise InputError("config", str(p), "an existing TOML file")
    try:
        return tomllib.loads(p.read_text())
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
    """Build a dataclass from a config table, rejecting unknown keys."""
    table = dict(table or {})
    names = {f.name for f in dataclasses.fields(cls) if f.name != "extra"}
    check_keys(section, table, names)
    table.update({k: v for k, v in overrides.items() if v is not None})
    try:
        return cls(**table)
    except TypeError as exc:
        raise InputError(section, table, "values of the right type", str(exc)) from None


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
