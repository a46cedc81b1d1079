"""A direct shear case as a value: the specimen read once, the record's digest pinned, jobs that pickle."""

import pickle
from dataclasses import replace

import numpy as np
import pytest

from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.shear import ShearCase, ShearSettings, Specimen
from poro2d.shear.pool import ShearJob
from poro2d.shear.single import DirectShearTest
from poro2d.store import Store, stage


def test_the_specimen_value_is_its_file(specimen):
    value = Specimen.read(specimen.parent)  # a folder holding specimen.npz
    assert value.source == str(specimen) and value.digest == checkpoint.state_digest(specimen)
    sim = value.simulation()
    on_file = checkpoint.load(specimen)
    np.testing.assert_array_equal(sim.particles.pos, on_file.particles.pos)
    sim.particles.pos[0, 0] += 1.0  # a run changes its simulation, never the value
    np.testing.assert_array_equal(value.simulation().particles.pos, on_file.particles.pos)
    W, H = value.box()
    assert W == pytest.approx(0.06) and H > 0.0
    assert Specimen.of(value) is value


def test_the_record_digest_of_a_fixed_case_is_pinned(specimen):
    """Test folders are bound by this digest: a change would make finished tests look like others."""
    value = replace(Specimen.read(specimen), digest="abc")
    case = ShearCase(value, 100.0, ShearSettings(max_displacement=0.002, particle_friction=0.5))
    pinned = "eed86443ff03ed15dce5838cd0ab6fac659036a3698cd8c1bdb00200ca988b0f"
    assert stage.Fingerprint(case.record().to_dict(), tables={"settings": ShearSettings}).digest == pinned
    half = case.with_settings(
        velocity=0.5 * case.settings.velocity, rolling_friction=0.1, particle_friction=None
    )
    pinned = "a92c202b3337b524fdff86231bd65dd93bb032d56d259c13674b7475a27f9c6a"
    assert stage.Fingerprint(half.record().to_dict(), tables={"settings": ShearSettings}).digest == pinned
    assert case.at(50.0).normal_stress_kpa == 50.0 and case.normal_stress_kpa == 100.0


def test_a_case_is_checked_against_its_specimen(specimen):
    value = Specimen.read(specimen)
    with pytest.raises(InputError, match="normal stress"):
        ShearCase(value, 0.5, ShearSettings())
    with pytest.raises(InputError, match="max_displacement"):
        ShearCase(value, 50.0, ShearSettings(max_displacement=0.05))
    with pytest.raises(InputError, match="gap"):
        ShearCase(value, 50.0, ShearSettings(gap=0.02))


def test_a_job_pickles_with_its_case_and_makes_its_store(specimen, tmp_path):
    case = ShearCase.of(specimen, 50.0, ShearSettings(max_displacement=0.002))
    job = ShearJob(("test", 50.0), case, str(tmp_path / "sn50kPa"), keep_peak=False, series="a")
    back = pickle.loads(pickle.dumps(job))
    assert back.label == "a: 50 kPa" and back.case.specimen.digest == case.specimen.digest
    test = back.test()
    assert isinstance(test, DirectShearTest) and test.store == Store(tmp_path / "sn50kPa")
    assert test.stored() is None
