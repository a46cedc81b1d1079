"""A job and what comes back from it: the values every backend of the executor shares.

A job is a small frozen value: a module-level function (a worker imports it by name, or
Dask pickles it), its arguments and a label that names it in progress lines and errors.
What comes back is the function's return value or, when it raised, a :class:`Failed`
value in its place: one job's failure never stops the others, and each caller decides
what a failure means (an error row of a sweep, a calibration test left out of the fit, a
shear series that cannot be fitted).
"""

from __future__ import annotations

import traceback as traceback_module
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from poro2d.errors import InputError


@dataclass(frozen=True)
class Job:
    """``func(*args)``, or ``func(*args, report)`` when ``reports``: one unit of work.

    ``report(phase, *rest)`` sends a live message to the command (local processes and
    inline only; on Dask it goes nowhere). ``key`` names the Dask task (the label when
    None) and ``retries`` is how often Dask resubmits it when its worker dies.
    """

    func: Callable[..., Any]
    args: tuple = ()
    label: str = ""
    key: str | None = None
    retries: int = 0
    reports: bool = False

    def run(self, report: Callable[..., None] | None = None) -> Any:
        """The job's result, computed here (in whichever process runs it)."""
        if self.reports:
            return self.func(*self.args, report if report is not None else _ignore)
        return self.func(*self.args)


@dataclass(frozen=True)
class Failed:
    """A job that raised: its label, the error and the traceback's frames as text."""

    label: str
    error: BaseException
    traceback: str = ""

    @classmethod
    def of(cls, job: Job, error: BaseException, tb=None) -> Failed:
        """The failure of ``job``; ``tb`` a traceback object (default: the error's own)."""
        frames = traceback_module.format_tb(tb if tb is not None else error.__traceback__)
        return cls(job.label, error, "".join(frames))


class JobsFailed(RuntimeError):
    """Jobs that raised, each named with its error: ``2 direct shear test(s) failed: 50 kPa: ...``."""

    def __init__(self, what: str, errors: list[tuple[str, BaseException]]) -> None:
        self.errors = errors
        details = "; ".join(f"{name}: {exc}" for name, exc in errors)
        super().__init__(f"{len(errors)} {what} failed: {details}")


def results_or_raise(outcomes: Sequence[Any], what: str = "job(s)") -> list:
    """``outcomes`` when no job failed; else the first :class:`InputError` (in job order) as it is,
    any other failures together as :class:`JobsFailed` (``what``: how the jobs are counted).
    """
    failed = [o for o in outcomes if isinstance(o, Failed)]
    if not failed:
        return list(outcomes)
    first_input = next((f.error for f in failed if isinstance(f.error, InputError)), None)
    if first_input is not None:
        raise first_input
    raise JobsFailed(what, [(f.label, f.error) for f in failed])


def _ignore(*_msg) -> None:
    pass


__all__ = ["Failed", "Job", "JobsFailed", "results_or_raise"]
