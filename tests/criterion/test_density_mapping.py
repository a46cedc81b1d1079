"""The arithmetic of density-controlled preparation: Dr mapping, monotone fit, inversion."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poro2d.criterion.density import (
    Calibration,
    isotonic_increasing,
    lab_relative_density,
    state_target,
    target_porosity_2d,
)
from poro2d.errors import InputError
from poro2d.porosity import porosity_from_void_ratio, void_ratio


def test_paper_state_is_dense():
    assert lab_relative_density(0.3434, 0.4571, 0.3253) == pytest.approx(0.886, abs=5e-4)


def test_mapping_ends_and_linearity_in_void_ratio():
    assert target_porosity_2d(0.0, 0.22, 0.17) == pytest.approx(0.22)
    assert target_porosity_2d(1.0, 0.22, 0.17) == pytest.approx(0.17)
    mid = target_porosity_2d(0.5, 0.22, 0.17)
    assert void_ratio(mid) == pytest.approx(0.5 * (void_ratio(0.22) + void_ratio(0.17)))
    assert porosity_from_void_ratio(void_ratio(0.3)) == pytest.approx(0.3)


@pytest.mark.parametrize(
    ("n_lab", "n_max", "n_min", "name"),
    [(0.30, 0.4571, 0.3253, "n_lab"), (0.47, 0.4571, 0.3253, "n_lab"), (0.4, 0.33, 0.40, "n_min")],
)
def test_lab_state_outside_its_extremes_is_refused(n_lab, n_max, n_min, name):
    with pytest.raises(InputError, match=name):
        lab_relative_density(n_lab, n_max, n_min)


def _brute_isotonic(y):
    """Best non-decreasing fit by trying every partition into constant runs (small n only)."""
    n = len(y)
    best, best_err = None, np.inf
    for cuts in itertools.product([0, 1], repeat=n - 1):
        fit, start = [], 0
        for i in range(n):
            if i == n - 1 or cuts[i]:
                fit += [np.mean(y[start : i + 1])] * (i + 1 - start)
                start = i + 1
        fit = np.array(fit)
        if np.all(np.diff(fit) >= -1e-12):
            err = np.sum((fit - y) ** 2)
            if err < best_err:
                best, best_err = fit, err
    return best


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.1, 0.3), min_size=2, max_size=6))
def test_isotonic_fit_is_the_least_squares_monotone_fit(ys):
    y = np.array(ys)
    fit = isotonic_increasing(y)
    assert np.all(np.diff(fit) >= -1e-12)
    np.testing.assert_allclose(fit, _brute_isotonic(y), atol=1e-12)


def test_inversion_returns_the_friction_of_each_calibrated_point():
    cal = Calibration([0.0, 0.1, 0.5], [[0.17, 0.171], [0.19, 0.189], [0.22, 0.221]])
    for mu, m in zip(cal.mus, cal.mean, strict=True):
        assert cal.mu_for(m) == pytest.approx(mu)
    assert 0.1 < cal.mu_for(0.2) < 0.5
    with pytest.raises(InputError, match="looser than the loosest"):
        cal.mu_for(0.25)
    with pytest.raises(InputError, match="denser than the densest"):
        cal.mu_for(0.15)


def test_noise_is_pooled_but_a_real_reversal_is_refused():
    noisy = Calibration([0.0, 0.05, 0.5], [[0.180, 0.186], [0.182, 0.181], [0.22, 0.22]])
    noisy.check()  # 0.183 -> 0.1815 is within the seeds' scatter
    assert noisy.fitted[0] == noisy.fitted[1]
    reversed_ = Calibration([0.0, 0.05, 0.5], [[0.20, 0.2001], [0.18, 0.1801], [0.22, 0.22]])
    with pytest.raises(InputError, match="does not fall"):
        reversed_.check()
    flat = Calibration([0.0, 0.5], [[0.2, 0.2], [0.2, 0.2]])
    with pytest.raises(InputError, match="raise the largest mu_prep"):
        flat.check()


def test_unconverged_seeds_are_counted_and_a_friction_without_any_is_refused():
    cal = Calibration([0.0, 0.5], [[0.17, None, 0.172], [0.22, 0.221, 0.219]])
    assert cal.failed == [1, 0]
    assert cal.mean[0] == pytest.approx(0.171)
    with pytest.raises(InputError, match="at least two frictions"):
        Calibration([0.0, 0.5], [[None], [0.22]]).check()


def test_a_friction_that_could_not_be_prepared_is_left_out():
    """Frictionless layers that never settle give no sample: the extremes are those of the
    frictions that were prepared, and the left-out friction is recorded."""
    cal = Calibration([0.0, 0.05, 0.2, 0.5], [[None, None], [0.19, 0.188], [0.19, 0.192], [0.21, 0.209]])
    cal.check()
    assert cal.dropped == [0.0]
    assert cal.n2d_min == pytest.approx(0.189) and cal.n2d_max == pytest.approx(0.2095)
    assert 0.2 < cal.mu_for(0.2) < 0.5
    d = cal.to_dict()  # the row as files hold it: no fit where no seed was accepted
    assert d["dropped"] == [0.0] and np.isnan(cal.fitted[0]) and d["fitted"][0] is None
    t = state_target(0.3253, 0.4571, 0.3253, cal)  # the densest laboratory state: the densest prepared
    assert t.mu_prep == pytest.approx(0.05) and t.n2d_target == pytest.approx(0.189)


def test_state_target_round_trip():
    cal = Calibration([0.0, 0.1, 0.5], [[0.17], [0.19], [0.22]])
    t = state_target(0.3434, 0.4571, 0.3253, cal)
    assert t.relative_density == pytest.approx(0.886, abs=5e-4)
    assert 0.17 < t.n2d_target < 0.19
    assert 0.0 < t.mu_prep < 0.1
    again = Calibration.from_dict(cal.to_dict())
    assert again.mu_for(t.n2d_target) == pytest.approx(t.mu_prep)
