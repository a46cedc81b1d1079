"""The criterion's two porosities: the paper's box n' and the specimen's interior porosity."""

import pytest

from poro2d.criterion.protocol import POROSITY_KEYS, porosity_numbers
from poro2d.grading import paper_grading
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen


@pytest.fixture(scope="module")
def quick():
    spec = SpecimenSpec(width=0.08, height=0.04, layers=2)
    sim, rep = prepare_specimen(spec, paper_grading(), 0.2, seed=0)
    assert rep.converged
    return spec, sim


def test_a_trial_carries_both_porosities(quick):
    spec, sim = quick
    row = porosity_numbers(sim, spec.width, spec.height).to_dict()
    assert set(row) == set(POROSITY_KEYS)
    assert row["box_porosity"] == pytest.approx(0.2, abs=1e-12)  # the trial's own disks, plate at H
    # the interior leaves out the loose wall layers and the gap under the plate
    assert 0.12 < row["interior_porosity"] < row["box_porosity"]
    assert row["interior_regions"] >= 3 and row["interior_porosity_std"] > 0.0
    assert 0.0 <= row["plate_contact_fraction"] <= 1.0


def test_a_specimen_too_small_to_measure_says_why_instead_of_failing():
    spec = SpecimenSpec(width=0.04, height=0.02, layers=1)
    sim, rep = prepare_specimen(spec, paper_grading(), 0.2, seed=1)
    row = porosity_numbers(sim, spec.width, spec.height).to_dict()
    assert row["interior_porosity"] is None
    assert "margin_d50" in row["interior_porosity_note"]
    assert row["box_porosity"] == pytest.approx(0.2, abs=1e-12)
