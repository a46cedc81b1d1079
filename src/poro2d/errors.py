"""One error type for bad input, so the CLI can print it as a single line."""

from __future__ import annotations

from typing import Any


class InputError(ValueError):
    """Bad user input: names the parameter, the value given and what is allowed.

    The CLI catches it and prints ``error: <message>`` with exit code 2, no traceback.
    """

    def __init__(self, parameter: str, value: Any, allowed: str, hint: str = "") -> None:
        self.parameter = parameter
        self.value = value
        self.allowed = allowed
        msg = f"{parameter} = {value!r} is invalid; allowed: {allowed}"
        if hint:
            msg += f" ({hint})"
        super().__init__(msg)


def check_range(
    parameter: str,
    value: float,
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """Validate a scalar against an interval; returns it as float or raises InputError."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(parameter, value, "a number") from None
    lo_s = "(" if lo_open else "["
    hi_s = ")" if hi_open else "]"
    allowed = f"{lo_s}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{hi_s}"
    if v != v:  # NaN
        raise InputError(parameter, value, allowed)
    if lo is not None and (v < lo or (lo_open and v == lo)):
        raise InputError(parameter, value, allowed)
    if hi is not None and (v > hi or (hi_open and v == hi)):
        raise InputError(parameter, value, allowed)
    return v


class Interrupted(Exception):
    """A command stopped by Ctrl-C (or SIGINT); the message says what was kept.

    Not a ``KeyboardInterrupt`` on purpose: the command line library turns those
    into a silent exit before :func:`poro2d.cli.main` could say anything.
    """
