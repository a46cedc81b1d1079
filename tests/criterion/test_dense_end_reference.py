"""The criterion's dense end against the independent frictionless jamming reference.

The dense end is the criterion run with frictionless preparation (mu_prep = 0, layers that
end once settled, trials refined to 0.002), its interior porosity measured 2 d50 clear of the
walls and of the surface. The reference is the jamming porosity of the same grading in a
periodic cell (:mod:`poro2d.oracles.jamming`), which shares no code with the engine or the
compaction. A 0.12 m x 0.06 m box of two layers keeps the suite short; on the paper's box the
paper grading gives 0.152-0.154 against 0.153 (docs/jamming.md).
"""

import numpy as np
import pytest

from poro2d.criterion.protocol import CriterionSettings, PorosityCriterion
from poro2d.grading import log_linear_grading, paper_grading, preset_grading
from poro2d.oracles.jamming import jamming_reference
from poro2d.specimen.compaction import SpecimenSpec

pytestmark = pytest.mark.scenario

BOX = {"width": 0.12, "height": 0.06, "layers": 2}


def _dense_end(grading, seeds) -> float:
    """Mean interior porosity of the accepted frictionless specimens over ``seeds``."""
    values = []
    for seed in seeds:
        spec = SpecimenSpec(**BOX, friction_prep=0.0, settle_drift=1e-3)
        settings = CriterionSettings(trial_porosity=0.14, force_fraction=0.05, refine_tolerance=0.002,
                                     max_iterations=12)  # fmt: skip
        res = PorosityCriterion(spec, grading, settings, seed=seed).run()
        assert res.converged, res.message
        assert res.interior_porosity is not None
        values.append(res.interior_porosity)
    return float(np.mean(values))


def _reference(grading) -> float:
    ref = jamming_reference(grading, n_disks=600, seeds=(0, 1))
    assert ref.converged
    return ref.porosity_mean


GRADINGS = {
    "paper": lambda: paper_grading(),
    "log-linear Cu 2": lambda: log_linear_grading(2.0, paper_grading().mean_disk_area()),
    "wide_cu4": lambda: preset_grading("wide_cu4"),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(GRADINGS))
def test_dense_end_interior_matches_the_jamming_reference(name):
    grading = GRADINGS[name]()
    dense, ref = _dense_end(grading, seeds=(0, 1)), _reference(grading)
    assert abs(dense - ref) < 0.01, (dense, ref)


CU_2_5_GAP = (
    "log-linear Cu 2.5: the criterion reaches the dense end from the loose side, and its "
    "gravity-settled frictionless packing is 0.010-0.015 looser than the compressed one "
    "(0.148 and 0.151 against 0.1375; from the dense side 0.138; docs/jamming.md)"
)


@pytest.mark.slow
def test_dense_end_of_a_log_linear_cu_2_5_grading_is_looser_than_the_reference():
    """The known gap, measured: a change of protocol that closes it fails here, to be noticed."""
    grading = log_linear_grading(2.5, paper_grading().mean_disk_area())
    gap = _dense_end(grading, seeds=(0,)) - _reference(grading)
    assert gap >= 0.01, (gap, CU_2_5_GAP)
