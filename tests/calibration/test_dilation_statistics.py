"""Dilation as an observable, on known surfaces (no DEM): an observable whose dependence on
(f_p, mu_r) differs from the peaks' breaks the ridge that peaks alone leave; mixed units (kPa
and mm) give the same posterior as the stresses alone would in any unit; the laboratory's end
values are its means over the last peak window."""

import math

import numpy as np
import pytest

from poro2d.calibration import model
from poro2d.calibration.case import lab_targets, shear_base_settings
from poro2d.shear import LabData

RANGES = model.Ranges((0.3, 3.0), (0.0, 0.5))
TRUTH = (0.8, 0.2)


def _peak(level: float, slope: float):
    """A peak (kPa) that depends on u + v only: sliding and rolling friction trade one for one."""
    return lambda x: level + slope * (x[:, 0] + x[:, 1])


def _dilation(x: np.ndarray) -> np.ndarray:
    """A rise (mm) that grows with sliding friction and falls a little with rolling friction:
    a rolling grain slides past its neighbours less and climbs over them less."""
    return 0.3 + 0.6 * x[:, 0] - 0.15 * x[:, 1] + 0.1 * x[:, 0] ** 2


def _posterior(observables) -> model.Posterior:
    """The grid posterior of ``observables`` ((surface, seed scatter, unit) each) from a
    12-point design, two replicates at +-scatter, the laboratory exactly on each surface."""
    design = RANGES.to_unit(*np.array(model.space_filling(RANGES, 12, 0)).T)
    truth = RANGES.to_unit([TRUTH[0]], [TRUTH[1]])
    values = np.stack([np.column_stack([f(design) - sd, f(design) + sd]) for f, sd, _ in observables], axis=1)
    surrogates = [model.fit_surrogate(design, values[:, k]) for k in range(len(observables))]
    lab = [float(f(truth)[0]) for f, *_ in observables]
    units = [u for *_, u in observables]
    cov = model.noise_covariance(surrogates, model.seed_covariance(values), lab, 0.0, units)
    return model.posterior(RANGES, surrogates, lab, cov)


PEAKS = [(_peak(40.0, 30.0), 2.0, "kPa"), (_peak(80.0, 50.0), 3.0, "kPa")]
DILATION = [(_dilation, 0.03, "mm"), (lambda x: 0.7 * _dilation(x), 0.03, "mm")]


def _log_width(lo: float, hi: float) -> float:
    return math.log(hi / lo)


def test_dilation_breaks_the_ridge_that_peaks_alone_leave():
    peaks = _posterior(PEAKS)
    both = _posterior(PEAKS + DILATION)
    assert peaks.correlation() < -0.9  # a ridge: u + v fixed, each one free
    assert abs(both.correlation()) < abs(peaks.correlation())
    fp_p, fp_b = peaks.interval("fp", 0.95), both.interval("fp", 0.95)
    mr_p, mr_b = peaks.interval("mu_r", 0.95), both.interval("mu_r", 0.95)
    assert fp_b[0] <= TRUTH[0] <= fp_b[1] and mr_b[0] <= TRUTH[1] <= mr_b[1]
    # narrower by a factor of two (f_p) and three (mu_r) at least, in the searched coordinates
    assert _log_width(*fp_b) < _log_width(*fp_p) / 2 and mr_b[1] - mr_b[0] < (mr_p[1] - mr_p[0]) / 3
    assert mr_p[1] - mr_p[0] > 0.5 * 0.5 and mr_b[1] - mr_b[0] < 0.1
    assert both.best()[0] == pytest.approx(TRUTH[0], rel=0.1)
    assert both.best()[1] == pytest.approx(TRUTH[1], abs=0.03)


def test_a_dilation_that_trades_the_frictions_as_the_peaks_do_adds_no_identification():
    """The counter-case: a rise along u + v, as the peaks, leaves the ridge where it was."""
    along = [(lambda x: 0.2 + 0.4 * (x[:, 0] + x[:, 1]), 0.03, "mm")]
    both = _posterior(PEAKS + along)
    assert both.correlation() < -0.9
    lo, hi = both.interval("mu_r", 0.95)
    assert hi - lo > 0.5 * 0.5


def test_the_posterior_does_not_depend_on_the_unit_of_an_observable():
    """mm or m, the Mahalanobis distance is the same: the posterior is the same grid."""
    in_mm = _posterior(PEAKS + DILATION)
    in_m = _posterior(PEAKS + [(lambda x, f=f: 1e-3 * f(x), 1e-3 * sd, "m") for f, sd, _ in DILATION])
    assert np.allclose(in_mm.density, in_m.density, rtol=1e-6, atol=1e-12)


def test_the_ridge_added_to_the_covariance_is_per_unit():
    """Against a singular matrix a ridge of 1e-9 of the trace is added: per unit, so the mm^2 of
    the dilation get theirs and not the kPa^2's; the stresses alone get what they always got."""
    s = [model.Surrogate(np.zeros(6), 0.0, 0.0, 2) for _ in range(3)]
    seed = np.diag([400.0, 900.0, 1e-4])
    kpa_only = model.noise_covariance(s[:2], seed[:2, :2], [1.0, 1.0], 0.0)
    assert kpa_only == pytest.approx(seed[:2, :2] * 1.5 + np.eye(2) * 1e-9 * 1950.0, rel=1e-12)
    mixed = model.noise_covariance(s, seed, [1.0, 1.0, 1.0], 0.0, ["kPa", "kPa", "mm"])
    assert mixed[:2, :2] == pytest.approx(kpa_only, rel=1e-12)
    assert mixed[2, 2] - 1.5e-4 == pytest.approx(1e-9 * 1.5e-4, rel=1e-3)  # not 1e-9 of the kPa^2
    zero = model.noise_covariance(s[:1], np.zeros((1, 1)), [0.0], 0.0, ["mm"])
    assert zero[0, 0] == 1e-9  # a block of zeros still inverts


def test_lab_error_is_a_fraction_of_each_value_in_its_own_unit():
    s = [model.Surrogate(np.zeros(6), 0.0, 0.0, 2) for _ in range(2)]
    cov = model.noise_covariance(s, np.zeros((2, 2)), [100.0, 0.5], 0.1, ["kPa", "mm"])
    assert np.sqrt(np.diag(cov)) == pytest.approx([10.0, 0.05], rel=1e-6)


def test_the_laboratory_dilation_is_the_mean_rise_over_the_last_peak_window_in_mm():
    d = np.array([0.5, 1.0, 1.7, 2.0, 2.5]) * 1e-3
    lab = LabData(
        "lab.csv",
        {50.0: 40.0},
        {50.0: (d, np.array([40.0, 30.0, 22.0, 18.0, 5.0]))},
        {50.0: np.array([-0.01, 0.02, 0.10, 0.14, 0.3]) * 1e-3},
    )
    base = shear_base_settings({"max_displacement": 0.002, "peak_window": 5e-4})
    targets = lab_targets(lab, base)
    assert targets[:2] == [("peak", 50.0, 40.0), ("end", 50.0, 20.0)]
    # the readings at 1.7 and 2.0 mm lie within the window (1.5 to 2 mm): a rise of 0.12 mm
    assert targets[2][:2] == ("dilation", 50.0) and targets[2][2] == pytest.approx(0.12)
    plain = LabData("lab.csv", lab.peaks, lab.curves)
    assert lab_targets(plain, base) == targets[:2]
