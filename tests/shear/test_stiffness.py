"""The disks' stiffness as shear settings: replaced in the split box, the time step chosen from the
stiffness used, and absent from every record (so from every cache key) when not given."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.calibration.units import unit_key
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.shear import DirectShearTest, ShearCase, ShearSettings, build_split_box


def test_split_box_replaces_the_disks_stiffness_and_shortens_the_step(specimen):
    own, _ = build_split_box(checkpoint.load(specimen), 0.01)
    kn = 4.0 * float(own.particles.kn.max())
    stiff, _ = build_split_box(checkpoint.load(specimen), 0.01, particle_kn=kn, particle_ks=kn)
    assert np.all(stiff.particles.kn == kn) and np.all(stiff.particles.ks == kn)
    # the critical step of a leapfrog spring goes as 1 / sqrt(k): four times stiffer, half the step
    # (the walls, stiffer still than the disks of Table 1, add their share through series springs)
    ratio = stiff.dt / own.dt
    assert 0.45 < ratio < 0.55
    assert math.isclose(stiff.dt, stiff.dt_safety * stiff.dt_critical)


def test_split_box_keeps_the_specimens_stiffness_when_not_given(specimen):
    spec = checkpoint.load(specimen)
    sim, _ = build_split_box(spec, 0.01, particle_ks=1e5)
    assert np.array_equal(np.sort(sim.particles.kn), np.sort(spec.particles.kn))
    assert np.all(sim.particles.ks == 1e5)


@pytest.mark.parametrize("name", ["particle_kn", "particle_ks"])
@pytest.mark.parametrize("value", [0.0, 10.0, 1e11, float("nan"), float("inf")])
def test_settings_refuse_a_stiffness_out_of_range(name, value):
    with pytest.raises(InputError, match=name):
        ShearSettings(**{name: value})


def test_a_stiffness_not_given_is_absent_from_the_record_and_the_key():
    record = ShearSettings().to_dict()
    assert "particle_kn" not in record and "particle_ks" not in record
    given = ShearSettings(particle_kn=2e6).to_dict()
    assert given["particle_kn"] == 2e6 and "particle_ks" not in given
    assert unit_key("abc", 50.0, given) != unit_key("abc", 50.0, record)


def test_a_shear_test_runs_on_the_stiffness_of_its_settings(specimen):
    settings = ShearSettings(max_displacement=0.002, particle_kn=1e6, particle_ks=2e5)
    sim, _ = DirectShearTest(ShearCase.of(specimen, 50, settings)).consolidate()
    assert np.all(sim.particles.kn == 1e6) and np.all(sim.particles.ks == 2e5)
