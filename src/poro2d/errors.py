"""One error type for bad input, so the CLI can print it as a single line, and the checks that raise it."""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np


class InputError(ValueError):
    """Bad user input: names the parameter, the value given and what is allowed.

    The CLI catches it and prints ``error: <message>`` with exit code 2, no traceback.
    """

    def __init__(self, parameter: str, value: Any, allowed: str, hint: str = "") -> None:
        self.parameter = parameter
        self.value = value
        self.allowed = allowed
        self.hint = hint
        msg = f"{parameter} = {value!r} is invalid; allowed: {allowed}"
        if hint:
            msg += f" ({hint})"
        super().__init__(msg)

    def __reduce__(self):
        # rebuilt from its fields, so that one raised in a worker process reaches the command whole
        return type(self), (self.parameter, self.value, self.allowed, self.hint)


def interval_text(lo: float | None, hi: float | None, *, lo_open: bool = False, hi_open: bool = False) -> str:
    """An interval as a refusal prints it: ``[0.0, 1.0]``, ``(0, inf)``; None is an open end."""
    lo_s = "(" if lo_open else "["
    hi_s = ")" if hi_open else "]"
    return f"{lo_s}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{hi_s}"


def check_range(
    parameter: str,
    value: float,
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """Validate a scalar against an interval; returns it as float or raises InputError.

    Any real number is accepted (int, float, NumPy scalars); text and booleans are not,
    even when they would convert: ``"0.3"`` or ``True`` given for a number is a mistake in
    the input, not a value.
    """
    if not is_number(value):
        raise InputError(parameter, value, "a number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(parameter, value, "a number") from None
    allowed = interval_text(lo, hi, lo_open=lo_open, hi_open=hi_open)
    if v != v:  # NaN
        raise InputError(parameter, value, allowed)
    if lo is not None and (v < lo or (lo_open and v == lo)):
        raise InputError(parameter, value, allowed)
    if hi is not None and (v > hi or (hi_open and v == hi)):
        raise InputError(parameter, value, allowed)
    return v


def is_number(value: Any) -> bool:
    """True for a real number (int, float, NumPy scalar or 0-d array); False for bool and text."""
    if isinstance(value, bool | np.bool_ | str | bytes):
        return False
    if isinstance(value, numbers.Real):
        return True
    return isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"


def is_integer(value: Any) -> bool:
    """True for an int or NumPy integer; False for bool (``True`` is not the integer 1 here)."""
    return isinstance(value, int | np.integer) and not isinstance(value, bool | np.bool_)


def check_int(parameter: str, value: Any, lo: int | None = None, hi: int | None = None) -> int:
    """Validate an integer against ``[lo, hi]``; returns it as int or raises InputError.

    Floats are refused even when whole (``4.0`` layers is a typo for 4 or for 4.5), and so
    are booleans and text.
    """
    if lo is not None and hi is not None:
        allowed = f"an integer in [{lo}, {hi}]"
    elif lo is not None:
        allowed = f"an integer >= {lo}"
    elif hi is not None:
        allowed = f"an integer <= {hi}"
    else:
        allowed = "an integer"
    if not is_integer(value):
        raise InputError(parameter, value, allowed)
    v = int(value)
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise InputError(parameter, value, allowed)
    return v


@dataclass(frozen=True)
class Real:
    """The interval a real setting must lie in: ``Real(0, None, lo_open=True)`` is (0, inf),
    the value always finite.

    ``or_none``: None is allowed too, for a setting that falls back on another when not given
    (a shear test's ``particle_friction`` takes the specimen's). The bounds are printed as
    written (``0`` or ``0.0``), as :func:`check_range` prints them.
    """

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    or_none: bool = False

    def check(self, parameter: str, value: Any) -> None:
        if value is None and self.or_none:
            return
        if is_number(value) and not math.isfinite(float(value)):  # an open end admits no infinity
            interval = interval_text(self.lo, self.hi, lo_open=self.lo_open, hi_open=self.hi_open)
            raise InputError(parameter, value, f"a finite number in {interval}")
        check_range(parameter, value, self.lo, self.hi, lo_open=self.lo_open, hi_open=self.hi_open)


@dataclass(frozen=True)
class Integer:
    """The closed range ``[lo, hi]`` an integer setting must lie in (None: no bound)."""

    lo: int | None = None
    hi: int | None = None

    def check(self, parameter: str, value: Any) -> None:
        check_int(parameter, value, self.lo, self.hi)


@dataclass(frozen=True)
class OneOf:
    """One of a few names (``quoted``: the allowed names printed as strings, ``'max'``)."""

    choices: tuple[str, ...]
    quoted: bool = False

    def check(self, parameter: str, value: Any) -> None:
        if value not in self.choices:
            names = [repr(c) for c in self.choices] if self.quoted else list(self.choices)
            raise InputError(parameter, value, "one of " + ", ".join(names))


#: a settings class's table of ranges: field name -> the rule its value keeps
Ranges = Mapping[str, Real | Integer | OneOf]


def check_fields(settings: Any, ranges: Ranges) -> None:
    """Check each field of ``settings`` named in ``ranges`` against its rule, in the table's order.

    A settings dataclass calls it first thing in ``__post_init__``, so that a value is checked
    however the settings were made (a config file, the Python API, ``dataclasses.replace``),
    and its table is the one place that says what each setting may be. The first field out of
    its range is reported, named as the field (``layers = 0 is invalid; ...``); checks that
    relate two fields stay in ``__post_init__`` after the table's.
    """
    for name, rule in ranges.items():
        rule.check(name, getattr(settings, name))


def as_float_array(parameter: str, values: Any) -> np.ndarray:
    """``values`` as a float64 array, or InputError naming ``parameter``.

    Only numbers are converted: text (``["1", "2"]``), booleans and ragged lists are refused
    rather than parsed, so a column read from the wrong place cannot pass as data.
    """
    try:
        raw = np.asarray(values)
    except (TypeError, ValueError):  # ragged nesting
        raise InputError(parameter, _short(values), "an array of numbers") from None
    if raw.dtype.kind == "O":
        flat = raw.ravel()
        if not all(is_number(v) for v in flat):
            bad = next(v for v in flat if not is_number(v))
            raise InputError(parameter, _short(values), "an array of numbers", f"found {bad!r}")
    elif raw.dtype.kind not in "iuf":
        raise InputError(parameter, _short(values), "an array of numbers", f"got {raw.dtype.name} data")
    try:
        return np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(parameter, _short(values), "an array of numbers") from None


def _short(values: Any, limit: int = 60) -> Any:
    """A value short enough for a one-line message (long arrays are summarised)."""
    text = repr(values)
    if len(text) <= limit:
        return values
    shape = getattr(values, "shape", None)
    return f"array of shape {shape}" if shape is not None else text[: limit - 3] + "..."


class Interrupted(Exception):
    """A command stopped by Ctrl-C (or SIGINT); the message says what was kept.

    Not a ``KeyboardInterrupt`` on purpose: the command line library turns those
    into a silent exit before :func:`poro2d.cli.main` could say anything.
    """
