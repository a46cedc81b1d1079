"""Whether a saved specimen is one the criterion accepted: the one check every command makes.

The criterion keeps every trial's checkpoint, refused ones too, and a run that did not
converge still leaves its last specimen. A shear test, a strength study, a calibration or
an export given one of those would report numbers of a packing the paper's Fig. 3 loop
turned down, so each asks :func:`check_accepted` (or takes its file through
:func:`accepted_file`) before any work, and refuses on one line naming the record that says no.
"""

from __future__ import annotations

import os
from pathlib import Path

from poro2d.errors import InputError
from poro2d.io_utils import CHECKPOINT_FILE_LIMIT, check_input_file
from poro2d.store import Store


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
    result = _record(path, folder, "result.json")
    if result is not None and "converged" in result:
        trials = result.get("iterations") if isinstance(result.get("iterations"), list) else []
        accepted = any(isinstance(row, dict) and row.get("accepted") is True for row in trials)
        if result["converged"] is not True or not accepted:
            state = (
                "no accepted trial" if result["converged"] is True else f"converged = {result['converged']}"
            )
            _refuse_unaccepted(path, folder.root / "result.json", state)
    trial = _record(path, folder, "trial.json")
    if trial is not None and "accepted" in trial and trial["accepted"] is not True:
        _refuse_unaccepted(path, folder.root / "trial.json", f"accepted = {trial['accepted']}")


def _record(path: str | os.PathLike, folder: Store, name: str) -> dict | None:
    """The JSON object ``name`` beside the specimen as it is (a file of any poro2d: its keys are checked
    where read), None if there is none (or it holds something else)."""
    if not folder.has(name):
        return None
    check_input_file("SPECIMEN", folder.root / name)
    data = folder.read_json(name)
    if data is None:
        why = "it changed since poro2d wrote it" if not folder.intact(name) else "it is not valid JSON"
        raise InputError("SPECIMEN", str(path), f"a specimen with a readable {name}", why) from None
    return data if isinstance(data, dict) else None


def _refuse_unaccepted(path: str | os.PathLike, record: Path, state: str) -> None:
    raise InputError(
        "SPECIMEN", str(path), "a specimen the criterion accepted", f"{record} says {state}; nothing written"
    )


__all__ = ["accepted_file", "check_accepted"]
