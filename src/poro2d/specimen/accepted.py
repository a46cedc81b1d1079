"""Whether a saved specimen is one the criterion accepted: the one check every command makes.

The criterion keeps every trial's checkpoint, refused ones too, and a run that did not
converge still leaves its last specimen. A shear test, a strength study, a calibration or
an export given one of those would report numbers of a packing the paper's Fig. 3 loop
turned down, so each asks :func:`check_accepted` (or takes its file through
:func:`accepted_file`) before any work, and refuses on one line naming the record that says no.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from poro2d.errors import InputError
from poro2d.io_utils import CHECKPOINT_FILE_LIMIT, check_input_file
from poro2d.json_fields import accepted_rows, int_at, said_at, value_at
from poro2d.store import Store


@dataclass(frozen=True)
class Flag:
    """A yes-or-no key of a record: its value as a message quotes it (``said``; None: the key is
    absent) and whether that value is JSON's true."""

    said: str | None
    true: bool

    @classmethod
    def at(cls, data: dict, key: str) -> Flag:
        return cls(said_at(data, key), data.get(key) is True)

    def refuses(self) -> bool:
        """The record says it, and not true."""
        return self.said is not None and not self.true


@dataclass(frozen=True)
class CriterionOutcome:
    """A criterion's ``result.json`` as far as acceptance goes: ``converged`` (its ``said`` None:
    not a criterion's result), ``accepted_trial`` (``iterations`` holds an accepted trial), the
    run's own ``message`` (``"None"`` when missing) and its seed, when ``names_seed``."""

    converged: Flag
    accepted_trial: bool
    message: str
    names_seed: bool
    seed: int | None

    @classmethod
    def from_json(cls, data: dict) -> CriterionOutcome:
        return cls(
            Flag.at(data, "converged"),
            accepted_rows(data.get("iterations")),
            str(data.get("message")),
            "seed" in data,
            int_at(data, "seed"),
        )


def _result_says(data: dict) -> str:
    """What a criterion's ``result.json`` says against its specimen ('' when nothing)."""
    outcome = CriterionOutcome.from_json(data)
    if outcome.converged.refuses():
        return f"converged = {outcome.converged.said}"
    return "no accepted trial" if outcome.converged.true and not outcome.accepted_trial else ""


def _trial_says(data: dict) -> str:
    """What a trial's ``trial.json`` says against its checkpoint ('' when nothing)."""
    accepted = Flag.at(data, "accepted")
    return f"accepted = {accepted.said}" if accepted.refuses() else ""


def _check_says(data: dict) -> str:
    """What an import's ``check.json`` (``poro2d import``) says against its specimen: the check it failed."""
    passes = Flag.at(data, "passes")
    if not passes.refuses():
        return ""
    if value_at(data, "equilibrium", "converged") is not True:
        failed = f"no equilibrium (ratio {said_at(data, 'equilibrium', 'max_ratio')})"
    else:
        f_top, limit = said_at(data, "f_top_n_per_m"), said_at(data, "force_limit_n_per_m")
        failed = f"F_top = {f_top} N/m outside the window 0 < F_top < {limit} N/m"
    return f"passes = {passes.said}: {failed}"


#: the records beside a specimen that may refuse it, in the order they are read, and what each says
VERDICTS = (("result.json", _result_says), ("trial.json", _trial_says), ("check.json", _check_says))


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
    """Refuse a specimen that the record beside it says was not accepted.

    A criterion folder (or the folder of the checkpoint given) holds ``result.json``;
    when it says ``converged = false`` or lists no accepted trial, the specimen must not
    leave as if valid. A trial's checkpoint has ``trial.json`` beside it, which must say
    ``accepted = true``; an import's folder ``check.json``, which must say ``passes = true``
    (false: the specimen failed the criterion's check as it stood). A checkpoint with none of them
    beside it (a shear test's) is taken as it is.
    """
    p = Path(path)
    folder = Store(p if p.is_dir() else p.parent, parameter="SPECIMEN")
    for name, says in VERDICTS:
        data = _record(path, folder, name)
        state = says(data) if data is not None else ""
        if state:
            why = f"{folder.root / name} says {state}; nothing written"
            raise InputError("SPECIMEN", str(path), "a specimen the criterion accepted", why)


def _record(path: str | os.PathLike, folder: Store, name: str) -> dict | None:
    """The JSON object of the record ``name`` beside the specimen (a file of any poro2d), None if
    there is none (or it holds something else)."""
    if not folder.has(name):
        return None
    check_input_file("SPECIMEN", folder.root / name)
    data = folder.read_json(name)
    if data is None:
        why = "it changed since poro2d wrote it" if not folder.intact(name) else "it is not valid JSON"
        raise InputError("SPECIMEN", str(path), f"a specimen with a readable {name}", why) from None
    return data if isinstance(data, dict) else None


__all__ = ["CriterionOutcome", "Flag", "accepted_file", "check_accepted"]
