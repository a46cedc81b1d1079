"""Whether a saved specimen is one the criterion accepted: the one check every command makes.

The criterion keeps every trial's checkpoint, refused ones too, and a run that did not
converge still leaves its last specimen. A shear test, a strength study, a calibration or
an export given one of those would report numbers of a packing the paper's Fig. 3 loop
turned down, so each asks :func:`check_accepted` (or takes its file through
:func:`accepted_file`) before any work, and refuses on one line naming the record that says no.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

from poro2d.errors import InputError
from poro2d.io_utils import CHECKPOINT_FILE_LIMIT, check_input_file
from poro2d.json_fields import accepted_rows, int_at, said_at
from poro2d.store import Store

R = TypeVar("R")


@dataclass(frozen=True)
class CriterionOutcome:
    """A criterion's ``result.json`` as far as acceptance goes.

    ``converged_said``: the ``converged`` value as written (None: the file has no such key,
    it is not a criterion's result); ``converged``: that value is true; ``accepted_trial``:
    ``iterations`` holds a trial with ``accepted = true``; ``message``: the run's own words
    (``str`` of it, ``"None"`` when missing); ``seed``: the seed, when ``names_seed``.
    """

    converged_said: str | None
    converged: bool
    accepted_trial: bool
    message: str
    names_seed: bool
    seed: int | None

    @classmethod
    def from_json(cls, data: dict) -> CriterionOutcome:
        return cls(
            converged_said=said_at(data, "converged"),
            converged=data.get("converged") is True,
            accepted_trial=accepted_rows(data.get("iterations")),
            message=str(data.get("message")),
            names_seed="seed" in data,
            seed=int_at(data, "seed"),
        )


@dataclass(frozen=True)
class TrialVerdict:
    """A trial's ``trial.json``: whether it says ``accepted`` (``accepted_said``, as written) and true."""

    accepted_said: str | None
    accepted: bool

    @classmethod
    def from_json(cls, data: dict) -> TrialVerdict:
        return cls(said_at(data, "accepted"), data.get("accepted") is True)


def accepted_file(path: str | os.PathLike) -> Path:
    """A checkpoint file, or a criterion output folder holding ``specimen.npz``, that was accepted.

    A refused trial's checkpoint (``trial.json`` beside it says not accepted) or the specimen
    of a criterion that did not converge (its ``result.json``) is refused on one line
    (:func:`check_accepted`); a missing or oversized file too.
    """
    p = Path(path)
    if p.is_dir():
        p = p / "specimen.npz"
    if not p.is_file():
        # a file poro2d wrote there (a preset's kept specimen) and lost since: said as such
        Store(p.parent, parameter="specimen").check_intact(p.name)
        raise InputError(
            "specimen",
            str(path),
            "a specimen checkpoint (.npz) or a criterion output folder with specimen.npz",
        )
    checked = check_input_file("specimen", p, CHECKPOINT_FILE_LIMIT)
    check_accepted(checked)
    return checked


def check_accepted(path: str | os.PathLike) -> None:
    """Refuse a specimen that the criterion beside it did not accept.

    A criterion folder (or the folder of the checkpoint given) holds ``result.json``;
    when it says ``converged = false`` or lists no accepted trial, the specimen must not
    leave as if valid. A trial's checkpoint has ``trial.json`` beside it, which must say
    ``accepted = true``. A checkpoint with neither beside it (a shear test's, an imported
    one) is taken as it is.
    """
    p = Path(path)
    folder = Store(p if p.is_dir() else p.parent, parameter="SPECIMEN")
    result = _record(path, folder, "result.json", CriterionOutcome.from_json)
    if result is not None and result.converged_said is not None:
        if not result.converged or not result.accepted_trial:
            state = "no accepted trial" if result.converged else f"converged = {result.converged_said}"
            _refuse_unaccepted(path, folder.root / "result.json", state)
    trial = _record(path, folder, "trial.json", TrialVerdict.from_json)
    if trial is not None and trial.accepted_said is not None and not trial.accepted:
        _refuse_unaccepted(path, folder.root / "trial.json", f"accepted = {trial.accepted_said}")


def _record(path: str | os.PathLike, folder: Store, name: str, parse: Callable[[dict], R]) -> R | None:
    """The record ``name`` beside the specimen, read by ``parse`` from its JSON object (a file of any
    poro2d: ``parse`` keeps what it needs), None if there is none (or it holds something else)."""
    if not folder.has(name):
        return None
    check_input_file("SPECIMEN", folder.root / name)
    data = folder.read_json(name)
    if data is None:
        why = "it changed since poro2d wrote it" if not folder.intact(name) else "it is not valid JSON"
        raise InputError("SPECIMEN", str(path), f"a specimen with a readable {name}", why) from None
    return parse(data) if isinstance(data, dict) else None


def _refuse_unaccepted(path: str | os.PathLike, record: Path, state: str) -> None:
    raise InputError(
        "SPECIMEN", str(path), "a specimen the criterion accepted", f"{record} says {state}; nothing written"
    )


__all__ = ["CriterionOutcome", "TrialVerdict", "accepted_file", "check_accepted"]
