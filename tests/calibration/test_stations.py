"""Readings of the curves as observables (``stations``) and the noise covariance's correction for
being estimated from a few replicates (Hartlap, Simon & Schneider 2007)."""

import numpy as np
import pytest

from poro2d.calibration import model
from poro2d.calibration.case import check_noise_dof, lab_targets, shear_base_settings
from poro2d.calibration.run import CalibrationCase, run_calibration
from poro2d.calibration.units import CurveReadings, UnitRow, observable_unit, parse_station, station
from poro2d.errors import InputError
from poro2d.shear import LabData

D = np.linspace(0.0, 0.012, 241)  # m: a reading every 0.05 mm
TAU = 80.0 * (1.0 - np.exp(-D / 0.002))  # kPa
RISE = 0.25 * D  # m: the plate rises at a quarter of the shear displacement


def _lab(vertical: bool) -> LabData:
    curves = {50.0: (D, 0.5 * TAU), 100.0: (D, TAU)}
    rises = {50.0: RISE, 100.0: 0.5 * RISE} if vertical else {}
    return LabData("mine", {50.0: float(0.5 * TAU.max()), 100.0: float(TAU.max())}, curves, rises)


def _window_mean(y, at, window=0.002):
    inside = (D >= at - window) & (D <= at)
    return float(np.mean(y[inside]))


def test_station_names_read_back_with_their_units():
    assert station("stress", 0.004) == "stress_at_4mm"
    assert parse_station("rise_at_2.5mm") == ("rise", pytest.approx(0.0025))
    assert parse_station("peak") is None and parse_station("end") is None
    assert observable_unit("stress_at_4mm") == "kPa" and observable_unit("rise_at_4mm") == "mm"
    assert observable_unit("dilation") == "mm" and observable_unit("peak") == "kPa"


def test_stations_read_the_lab_curves_at_evenly_spaced_displacements():
    base = shear_base_settings({"max_displacement": 0.012})
    targets = lab_targets(_lab(vertical=True), base, stations=3)
    names = [(obs, s) for obs, s, _ in targets]
    # peaks, ends and dilations first, as with one station: earlier files keep their order
    assert names[:6] == [(o, s) for o in ("peak", "end", "dilation") for s in (50.0, 100.0)]
    assert names[6:] == [
        ("stress_at_4mm", 50.0), ("rise_at_4mm", 50.0), ("stress_at_4mm", 100.0), ("rise_at_4mm", 100.0),
        ("stress_at_8mm", 50.0), ("rise_at_8mm", 50.0), ("stress_at_8mm", 100.0), ("rise_at_8mm", 100.0),
    ]  # fmt: skip
    values = {(obs, s): y for obs, s, y in targets}
    assert values["stress_at_4mm", 100.0] == pytest.approx(_window_mean(TAU, 0.004))
    assert values["rise_at_8mm", 50.0] == pytest.approx(1e3 * _window_mean(RISE, 0.008))  # in mm
    # one station is what a calibration did before: no readings
    assert len(lab_targets(_lab(vertical=True), base, stations=1)) == 6
    # without the plate's rise only the stresses are read
    assert [o for o, *_ in lab_targets(_lab(vertical=False), base, stations=2)][4:] == ["stress_at_6mm"] * 2


def test_a_unit_row_reads_its_own_curve_at_a_station_as_the_lab_is_read():
    readings = CurveReadings(D, {"stress": TAU, "rise": 1e3 * RISE}, 0.002)
    row = UnitRow("k", 100.0, 0.5, 0.1, "s", float(TAU.max()), float(TAU[-1]), 1.0, 3.0, readings)
    assert row.observable("stress_at_4mm") == pytest.approx(_window_mean(TAU, 0.004))
    assert row.observable("rise_at_6mm") == pytest.approx(1e3 * _window_mean(RISE, 0.006))
    assert row.observable("peak") == float(TAU.max())
    assert np.isnan(UnitRow("k", 100.0, 0.5, 0.1, "s", 1.0, 1.0, 1.0).observable("stress_at_4mm"))


def test_the_factor_makes_the_inverse_of_an_estimated_covariance_unbiased():
    """Estimate a known covariance from `dof` degrees of freedom many times: the mean of the
    inverse overstates the precision by dof / (dof - p - 1), which the factor removes."""
    rng = np.random.default_rng(3)
    p, dof, trials = 6, 20, 4000
    a = rng.normal(size=(p, p))
    sigma = a @ a.T + p * np.eye(p)
    chol = np.linalg.cholesky(sigma)
    mean_inverse = np.zeros((p, p))
    for _ in range(trials):
        x = rng.normal(size=(dof, p)) @ chol.T
        mean_inverse += np.linalg.inv(x.T @ x / dof) / trials
    truth = np.linalg.inv(sigma)
    ratio = np.trace(mean_inverse @ sigma) / p  # 1 for an unbiased precision
    assert ratio == pytest.approx(dof / (dof - p - 1), rel=0.03)
    corrected = model.precision_factor(dof, p) * mean_inverse
    assert np.abs(corrected - truth).max() < 0.05 * np.abs(truth).max()
    assert model.precision_factor(7, 6) == 0.0 and model.precision_factor(0, 1) == 0.0


def test_a_design_too_small_for_its_observables_is_refused_before_any_work():
    check_noise_dof(points=12, replicates=3, observables=18)  # 24 dof > 19
    with pytest.raises(InputError, match=r"--points.*at least 10 for 18 observables on 3 replicates"):
        check_noise_dof(points=9, replicates=3, observables=18)
    check_noise_dof(points=9, replicates=1, observables=50)  # one specimen: reported unknown, not refused


@pytest.mark.parametrize(
    "stations, words", [(0, r"--stations.*\[1, 10\]"), (11, r"--stations"), (2.5, "--stations")]
)
def test_stations_out_of_range_are_refused(specimen, stations, words):
    with pytest.raises(InputError, match=words):
        run_calibration(
            CalibrationCase.of(
                _lab(vertical=False), [specimen], stations=stations, settings={"max_displacement": 0.01}
            )
        )


def test_stations_need_lab_curves(specimen):
    peaks = LabData("mine", {50.0: 40.0, 100.0: 80.0})
    with pytest.raises(InputError, match=r"--stations.*1 with a peaks file"):
        run_calibration(
            CalibrationCase.of(peaks, [specimen], stations=2, settings={"max_displacement": 0.01})
        )
