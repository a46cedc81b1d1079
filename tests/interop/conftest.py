"""The specimen the export, import and LAMMPS tests share, built once per session."""

import pytest

from poro2d.dem import checkpoint
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen


@pytest.fixture(scope="session")
def saved(tmp_path_factory):
    """A small specimen (0.06 m x 0.03 m) at n = 0.21 whose top plate carries a force (about
    1.3 % of G), saved as ``specimen.npz`` alone in its folder, as ``poro2d export`` takes it.
    Seed 210001: the plate of seed 210000, the seed before, carries 17 % of G since the
    engine fuses its products and sums (round-off that the preparation carries far)."""
    sim, _ = prepare_specimen(
        SpecimenSpec(width=0.06, height=0.03, layers=2), paper_grading(), 0.21, seed=210001
    )
    path = tmp_path_factory.mktemp("specimen") / "specimen.npz"
    checkpoint.save(sim, path)
    return path
