"""Density states that behave like sand: a loose specimen contracts in shear, a dense one dilates.

The loose quick specimen is built with sliding friction 1.0 and rolling resistance 0.5 while its
layers are placed (the working values, f_p 0.5 and no rolling resistance, replace them before its
last equilibrium); the dense one is the ordinary quick specimen (friction 0.05 while built).
Frictional disks without rolling resistance reach a critical-state solid fraction of about 0.82
(docs/critical-state.md): a specimen below it must contract towards it, one above it dilate.
"""

import numpy as np
import pytest

from poro2d.biaxial import BiaxialCase, BiaxialSettings, run_biaxial
from poro2d.biaxial.quick import QuickSpecimen
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.measure.specimen_porosity import measure_specimen

#: the loose recipe of docs/biaxial.md
LOOSE = {"porosity": 0.25, "friction_prep": 1.0, "rolling_friction_prep": 0.5}
#: the critical-state solid fraction of these disks (f_p 0.5, no rolling), docs/critical-state.md
CRITICAL_SOLID_FRACTION = 0.820


def _interior_solid_fraction(q: QuickSpecimen) -> float:
    p = q.simulation().particles
    return 1.0 - measure_specimen(p.pos, p.radius, q.width, q.height).interior_porosity


def _volumetric_strain_at(q: QuickSpecimen, strain: float) -> tuple[float, float]:
    """(eps_v at ``strain``, largest sin phi) of a biaxial test at 100 kPa, contraction positive."""
    case = BiaxialCase(q, 100.0, BiaxialSettings(max_strain=strain, critical_window=0.34))
    c = run_biaxial(case, None, replicates=1, options=RunOptions(workers=1, progress=False)).tests[0].curve
    return float(c.volumetric_strain[-1]), float(np.max(c.sin_phi))


@pytest.mark.scenario
def test_a_loose_specimen_contracts_and_a_dense_one_dilates():
    loose, dense = QuickSpecimen(0, **LOOSE), QuickSpecimen(0)
    # the packings: loose below the critical state's solid fraction, dense above it
    assert _interior_solid_fraction(loose) < 0.79 < CRITICAL_SOLID_FRACTION < _interior_solid_fraction(dense)
    eps_loose, peak_loose = _volumetric_strain_at(loose, 0.08)
    eps_dense, peak_dense = _volumetric_strain_at(dense, 0.08)
    assert eps_loose > 0.005, eps_loose  # contracted (measured +0.011 at 5-10 % axial strain)
    assert eps_dense < -0.005, eps_dense  # dilated (measured -0.012 at 5 %)
    assert peak_dense > peak_loose + 0.05, (peak_dense, peak_loose)


def test_the_quick_specimens_identity_is_unchanged_by_the_preparation_fields():
    # the digest of the ordinary quick specimen, as results recorded it before the fields existed
    assert QuickSpecimen(0).digest == "d48700095dd61930df6ae979852bdad117bd72939ec9972f75e114c69d82afd0"
    assert QuickSpecimen(0).source == "quick specimen (seed 0)"
    loose = QuickSpecimen(0, **LOOSE)
    assert loose.digest != QuickSpecimen(0).digest
    assert "rolling_friction_prep 0.5" in loose.source
    assert loose.with_seed(3).rolling_friction_prep == 0.5


@pytest.mark.parametrize("field, value", [("rolling_friction_prep", 1.5), ("friction_prep", -0.1)])
def test_a_bad_preparation_value_is_refused_before_any_work(field, value):
    with pytest.raises(InputError, match=field):
        QuickSpecimen(0, **{field: value})
