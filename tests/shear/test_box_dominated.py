"""A direct shear test that measured its box says so: the plane's load outside 0.7-1.3 times the
plate's at the peak, or a stress that never peaked (poro2d.shear.box_dominated)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from poro2d.cli.shear import box_warning, print_result
from poro2d.shear.box_dominated import PLANE_LOAD_BAND, RISE_FRACTION, box_dominated_count, box_verdict
from poro2d.shear.curve import CURVE_COLUMNS
from poro2d.shear.results import ShearSeriesResult, ShearTestResult
from poro2d.store import Store

DATA = Path(__file__).parents[1] / "data" / "before_typed_results"
WINDOW = 2e-3  # m, the default peak window
X_MM = np.linspace(0.05, 10.0, 200)


def _curve(tau: np.ndarray, plane_fraction: float = 1.0) -> dict[str, np.ndarray]:
    """A curve at 100 kPa whose plane carries ``plane_fraction`` of the plate's stress throughout."""
    sigma = np.full_like(X_MM, 100.0)
    return {
        "shear_displacement_mm": X_MM.copy(),
        "shear_stress_kpa": tau,
        "normal_stress_kpa": sigma,
        "plane_normal_stress_kpa": plane_fraction * sigma,
    }


def _peaked() -> np.ndarray:
    """A dense sand's curve: up to a peak of 70 kPa at 4 mm, then down to 50 kPa."""
    return np.where(X_MM < 4.0, 70.0 * X_MM / 4.0, 50.0 + 20.0 * np.exp(-(X_MM - 4.0)))


def test_a_curve_that_peaks_with_the_plane_carrying_the_plates_load_is_not_box_dominated():
    verdict = box_verdict(_curve(_peaked(), 1.0), WINDOW)
    assert not verdict.dominated
    assert "plane load 1.00" in verdict.note and "box-dominated" not in verdict.note


@pytest.mark.parametrize("fraction", [2.0, 0.5])
def test_a_plane_carrying_far_more_or_less_than_the_plate_is_box_dominated(fraction):
    verdict = box_verdict(_curve(_peaked(), fraction), WINDOW)
    assert verdict.dominated
    assert f"carries {fraction:.2f} times" in verdict.note and "no peak" not in verdict.note


def test_the_band_is_inclusive_at_its_ends():
    lo, hi = PLANE_LOAD_BAND
    assert not box_verdict(_curve(_peaked(), hi), WINDOW).dominated
    assert not box_verdict(_curve(_peaked(), lo), WINDOW).dominated
    assert box_verdict(_curve(_peaked(), hi + 0.01), WINDOW).dominated


def test_a_curve_still_rising_at_the_end_of_the_travel_did_not_peak():
    verdict = box_verdict(_curve(10.0 + 8.0 * X_MM, 1.0), WINDOW)
    assert verdict.dominated and "no peak" in verdict.note and "carries" not in verdict.note


def test_a_plateau_whose_largest_value_comes_last_has_peaked():
    # flat within 1 %: the smoothed maximum lies in the last window, but the stress no longer rises there
    tau = np.where(X_MM < 3.0, 60.0 * X_MM / 3.0, 60.0 + 0.06 * (X_MM - 3.0))
    verdict = box_verdict(_curve(tau, 1.0), WINDOW)
    assert not verdict.dominated, verdict.note
    # the same plateau rising by more than RISE_FRACTION over the last window has not
    steep = 2.0 * RISE_FRACTION * 60.0 / (1e3 * WINDOW)  # kPa per mm
    tau = np.where(X_MM < 3.0, 60.0 * X_MM / 3.0, 60.0 + steep * (X_MM - 3.0))
    assert box_verdict(_curve(tau, 1.0), WINDOW).dominated


def test_both_reasons_are_named_and_a_curve_of_an_earlier_poro2d_is_judged_on_its_peak():
    rising = _curve(10.0 + 8.0 * X_MM, 3.0)
    note = box_verdict(rising, WINDOW).note
    assert "carries 3.00 times" in note and "no peak" in note
    old = dict(_curve(_peaked()), plane_normal_stress_kpa=np.full_like(X_MM, math.nan))
    verdict = box_verdict(old, WINDOW)
    assert not verdict.dominated and "plane load not recorded" in verdict.note
    assert box_verdict(dict(old, shear_stress_kpa=10.0 + 8.0 * X_MM), WINDOW).dominated


def _write_curve(store: Store, curve: dict[str, np.ndarray]) -> None:
    n = X_MM.size
    full = {k: np.zeros(n) for k in CURVE_COLUMNS} | curve
    rows = [{k: float(full[k][i]) for k in CURVE_COLUMNS} for i in range(n)]
    store.write_csv("curve.csv", rows, header=CURVE_COLUMNS)


def test_a_test_written_before_the_flag_is_judged_from_its_stored_curve(tmp_path):
    stored = json.loads((DATA / "shear_test_result.json").read_text())
    assert "box_dominated" not in stored
    store = Store(tmp_path / "sn50kPa")
    store.write_json("result.json", stored)
    _write_curve(store, _curve(10.0 + 8.0 * X_MM, 1.0))
    result = ShearTestResult.read(store)
    assert result.box_dominated is True and "no peak" in result.box_note
    # the file's own numbers are what they were: the flag is a reading, added beside them
    written = result.to_dict()
    assert {k: v for k, v in written.items() if k not in ("box_dominated", "box_note")} == stored
    _write_curve(store, _curve(_peaked(), 1.0))
    assert ShearTestResult.read(store).box_dominated is False
    # without its curve there is nothing to judge: the verdict stays unknown
    store.remove("curve.csv")
    assert ShearTestResult.read(store).box_dominated is None


def _series(flags: list[bool | None]) -> ShearSeriesResult:
    data = json.loads((DATA / "shear_series_result.json").read_text())
    for test, flag in zip(data["tests"], flags, strict=True):
        if flag is not None:
            test["box_dominated"] = flag
            test["box_note"] = "box-dominated: no peak" if flag else "plane load 1.02 of the plate's"
    data["box_dominated_tests"] = box_dominated_count(data["tests"])
    return ShearSeriesResult.from_dict(data)


def test_a_series_counts_its_box_dominated_tests_and_an_earlier_one_does_not_know():
    assert _series([True, False]).box_dominated_tests == 1
    assert _series([False, False]).box_dominated_tests == 0
    assert box_dominated_count(_series([None, None]).tests) is None
    assert "box_dominated_tests" not in _series([None, None]).to_dict()


def test_the_command_warns_on_its_first_line_before_the_answer(capsys, tmp_path):
    series = _series([True, False])
    print_result(series, tmp_path)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("warning: 1 of 2 tests are box-dominated")
    sigma = series.tests[0].normal_stress_kpa
    assert f"{sigma:g} kPa: no peak" in lines[0]
    assert box_warning(_series([False, False]).tests) is None
    print_result(_series([False, False]), tmp_path)
    assert "box-dominated" not in capsys.readouterr().out
