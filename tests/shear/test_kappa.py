"""A direct shear test states how stiff its contacts are against its stress (elastic
strain is not dilatancy): kappa = kn / (sigma t) and the mean overlap over d at the peak."""

from __future__ import annotations

import pytest

from poro2d.measure.stiffness import contacts_of, mean_overlap_ratio, stiffness_number
from poro2d.shear.case import ShearCase
from poro2d.shear.settings import ShearSettings
from poro2d.shear.single import DirectShearTest
from poro2d.specimen.saved import Specimen


@pytest.fixture(scope="module")
def tests_at(specimen):
    value = Specimen.read(specimen)
    settings = ShearSettings(max_displacement=0.002, particle_friction=0.5)
    return {s: DirectShearTest(ShearCase(value, s, settings)).run() for s in (50.0, 200.0)}


def test_kappa_is_the_contact_stiffness_over_the_normal_stress(tests_at):
    # Table 1's disks: 4e5 N/m each, 2e5 N/m a contact in series; 8 mm thick
    for sigma, result in tests_at.items():
        assert result.stiffness_number == pytest.approx(2e5 / (sigma * 1e3 * 0.008))
        assert result.to_dict()["stiffness_number"] == result.stiffness_number


def test_the_overlap_at_the_peak_grows_as_kappa_falls(tests_at):
    low, high = tests_at[50.0], tests_at[200.0]
    assert 0.0 < low.mean_overlap_ratio_at_peak < high.mean_overlap_ratio_at_peak
    # the typical contact strain is of the order of 1 / kappa
    for r in (low, high):
        assert 0.2 / r.stiffness_number < r.mean_overlap_ratio_at_peak < 5.0 / r.stiffness_number


def test_the_overlap_ratio_reads_a_contact_set_by_hand():
    import numpy as np

    from poro2d.dem.contacts import ContactSet

    radius = np.array([1.0, 1.0, 2.0])
    z = np.zeros((3, 2))
    c = ContactSet(i=np.array([0, 1, 2]), j=np.array([1, 2, 0]), kind=np.array([0, 0, 1]), point=z,
                   normal=z, fn=np.ones(3), fs=np.zeros(3), force=z,
                   branch=np.array([[1.9, 0.0], [0.0, 2.8], [5.0, 0.0]]))  # fmt: skip
    # disk-disk rows only: overlaps 0.1 and 0.2 over reaches 2 and 3
    assert mean_overlap_ratio(contacts_of(c, radius)) == pytest.approx(0.15 / 2.5)
    assert stiffness_number(2e5, 1e5, 0.008) == pytest.approx(250.0)
