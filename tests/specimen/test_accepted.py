"""Only specimens the criterion accepted are sheared: the check export makes, read beside the file."""

import shutil

import pytest

from poro2d.errors import InputError
from poro2d.specimen.accepted import accepted_file
from poro2d.specimen.saved import Specimen
from poro2d.store import Store


def _beside(specimen, folder, name: str, record: dict):
    folder.mkdir()
    shutil.copyfile(specimen, folder / name)
    Store(folder).write_json("trial.json" if name != "specimen.npz" else "result.json", record)
    return folder / name


def test_a_refused_trials_checkpoint_is_refused(specimen, tmp_path):
    path = _beside(specimen, tmp_path / "trial", "after_plate.npz", {"accepted": False})
    with pytest.raises(InputError, match="accepted = False"):
        Specimen.read(path)


def test_the_specimen_of_a_criterion_that_did_not_converge_is_refused(specimen, tmp_path):
    folder = _beside(
        specimen, tmp_path / "crit", "specimen.npz", {"converged": False, "iterations": []}
    ).parent
    with pytest.raises(InputError, match="converged = False"):
        accepted_file(folder)


def test_accepted_specimens_and_bare_checkpoints_are_taken(specimen, tmp_path):
    accepted = _beside(specimen, tmp_path / "trial", "after_plate.npz", {"accepted": True})
    assert accepted_file(accepted) == accepted
    crit = _beside(specimen, tmp_path / "crit", "specimen.npz",
                   {"converged": True, "iterations": [{"accepted": True}]}).parent  # fmt: skip
    assert Specimen.read(crit).digest == Specimen.read(specimen).digest
