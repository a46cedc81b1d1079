"""Replicate specimens as one value: labels in order, files, digests once read; only accepted ones."""

import shutil

import pytest

from poro2d.dem.checkpoint import state_digest
from poro2d.errors import InputError
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store


def _criterion_folder(specimen, folder, converged: bool):
    """``specimen`` as a criterion folder keeps it, with the result.json a run of that outcome writes."""
    folder.mkdir(parents=True)
    shutil.copyfile(specimen, folder / "specimen.npz")
    trials = [{"accepted": converged}]
    Store(folder).write_json("result.json", {"converged": converged, "iterations": trials})
    return folder


def test_named_specimens_keep_their_order_and_get_unique_labels(specimen, tmp_path):
    crit = _criterion_folder(specimen, tmp_path / "a" / "crit", True)
    other = _criterion_folder(specimen, tmp_path / "b" / "crit", True)
    found = SpecimenSet.named([specimen, crit, other])
    assert list(found) == [specimen.parent.name, "crit", "crit-2"] and len(found) == 3  # folder names
    assert found["crit-2"] == other / "specimen.npz" and "crit" in found and "seed0" not in found
    with pytest.raises(KeyError):
        found["seed0"]


def test_a_specimen_the_criterion_did_not_accept_is_refused_naming_its_record(specimen, tmp_path):
    refused = _criterion_folder(specimen, tmp_path / "refused", False)
    with pytest.raises(InputError) as exc:
        SpecimenSet.accepted({"a": specimen, "b": refused}, "SPECIMEN")
    text = str(exc.value)
    assert len(text.splitlines()) == 1
    assert str(refused / "result.json") in text and "converged = False" in text
    trial = tmp_path / "trial"
    trial.mkdir()
    shutil.copyfile(specimen, trial / "after_plate.npz")
    Store(trial).write_json("trial.json", {"accepted": False})
    with pytest.raises(InputError, match="trial.json says accepted = False"):
        SpecimenSet.named([trial / "after_plate.npz"])


def test_no_specimen_is_refused(tmp_path):
    with pytest.raises(InputError, match="at least one specimen"):
        SpecimenSet.named([])
    with pytest.raises(InputError, match="at least one specimen"):
        SpecimenSet.accepted({})


def test_a_damaged_specimen_is_refused_when_read(specimen, tmp_path):
    garbage = tmp_path / "garbage.npz"
    garbage.write_bytes(b"PK\x03\x04" + bytes(range(256)) * 8)
    found = SpecimenSet.named([specimen, garbage])  # a bare checkpoint: no record says no
    with pytest.raises(InputError, match="garbage.npz"):
        found.read()


def test_reading_gives_each_specimen_and_the_digest_a_calibration_key_hashes(specimen, tmp_path):
    moved = tmp_path / "moved.npz"
    shutil.copyfile(specimen, moved)
    found = SpecimenSet.accepted({"a": specimen, "b": moved})
    with pytest.raises(ValueError, match="not read"):
        found.digest("a")
    with pytest.raises(ValueError, match="not read"):
        found.contents()
    assert found.specimen("a") == specimen  # a worker reads the file itself
    read = found.read()
    assert read.read() is read and list(read) == ["a", "b"] and read["b"] == moved
    # the digest of the file's state (state_digest), wherever the specimen lies
    assert read.digest("a") == read.digest("b") == state_digest(specimen)
    a, b = read.contents()
    assert read.specimen("a") is a and a.source == str(specimen) and b.source == str(moved)
    assert a.arrays["particles.radius"].size == b.arrays["particles.radius"].size > 0


def test_sets_join_in_order_and_labels_stay_unique(specimen, tmp_path):
    first = SpecimenSet.made([("seed0", specimen)])
    more = SpecimenSet.made([("seed1", tmp_path / "s1.npz"), ("seed2", tmp_path / "s2.npz")])
    joined = first + more
    assert list(joined) == ["seed0", "seed1", "seed2"] and joined["seed2"] == tmp_path / "s2.npz"
    with pytest.raises(ValueError, match="repeat"):
        joined + first
    with pytest.raises(ValueError, match="paths"):
        SpecimenSet(("a", "b"), (specimen,))
