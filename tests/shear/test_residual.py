"""The residual read where dilation has stopped: on curves whose answer is known, and on a real test."""

import json
import math

import numpy as np
import pytest

from poro2d.shear import run_shear
from poro2d.shear.residual import DILATION_RATE_LIMIT, dilation_rate, dilation_stopped_residual, tail_residual
from poro2d.shear.results import ShearTestResult
from poro2d.store import Store

STEP_MM = 0.05


def curve(plate_mm, x_mm, tau=30.0, sigma=100.0, plane=80.0, wall=4.0) -> dict:
    """A curve of the columns the residual reads: the plate's rise given, the stresses constant."""
    x = np.asarray(x_mm, float)
    full = np.ones_like(x)
    return {
        "shear_displacement_mm": x,
        "plate_displacement_mm": np.asarray(plate_mm, float),
        "shear_stress_kpa": tau * full,
        "normal_stress_kpa": sigma * full,
        "plane_normal_stress_kpa": plane * full,
        "upper_wall_friction_kpa": wall * full,
    }


def test_the_rate_of_a_straight_rise_is_its_slope():
    x = np.arange(0.0, 20.0 + 1e-9, STEP_MM)
    centre, rate = dilation_rate(curve(0.07 * x, x), 4e-3)
    assert centre[0] == pytest.approx(2.0) and centre[-1] == pytest.approx(18.0)
    assert np.allclose(rate, 0.07)


def test_a_curve_that_flattens_is_read_from_where_its_rate_falls_below_the_limit():
    # plate rise a (1 - exp(-x / L)): rate (a / L) exp(-x / L), below the limit from L ln(a / (L limit))
    a, length = 3.0, 6.0
    x = np.arange(0.0, 50.0 + 1e-9, STEP_MM)
    tau = np.where(x < 25.0, 60.0, 30.0)  # the window's mean must hold only what lies inside it
    c = curve(a * (1.0 - np.exp(-x / length)), x)
    c["shear_stress_kpa"] = tau
    r = dilation_stopped_residual(c, peak_window_m=2e-3)
    expected = length * math.log(a / (length * DILATION_RATE_LIMIT))
    assert r.reached and r.rate_window_m == pytest.approx(4e-3)
    # a secant over 4 mm of a convex curve reads a little steeper than the tangent: at most 0.3 mm later
    assert expected <= r.start_mm <= expected + 0.3
    inside = x >= r.start_mm
    assert r.shear_stress_kpa == pytest.approx(tau[inside].mean())
    assert r.stress_ratio == pytest.approx(tau[inside].mean() / 100.0)
    assert r.plane_stress_ratio == pytest.approx(tau[inside].mean() / 80.0)
    assert r.plane_share == pytest.approx(0.8) and r.upper_wall_friction_kpa == pytest.approx(4.0)
    assert r.max_abs_dilation_rate <= DILATION_RATE_LIMIT and r.end_mm == pytest.approx(50.0)
    assert "from" in r.status and r.end_dilation_rate == pytest.approx(
        a / length * math.exp(-48.0 / length), rel=0.05
    )


def test_a_curve_still_rising_at_its_end_has_no_residual():
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    r = dilation_stopped_residual(curve(0.05 * x, x))
    assert not r.reached and r.stress_ratio is None and r.plane_stress_ratio is None and r.start_mm is None
    assert r.status.startswith("not reached") and "0.050" in r.status
    # the mean over the last fifth is still a number: it just is not a residual
    assert tail_residual(curve(0.05 * x, x)) == pytest.approx(0.3)


def test_a_contracting_end_is_no_residual_either():
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    assert not dilation_stopped_residual(curve(-0.03 * x, x)).reached


def test_a_curve_flat_only_over_its_last_millimetres_is_not_reached():
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    # flat from 26.5 mm; the 4 mm secant reads it flat from about 27.7 mm: under one rate window of curve
    plate = np.minimum(0.1 * x, 2.65)
    r = dilation_stopped_residual(curve(plate, x))
    assert not r.reached and "less than 4 mm" in r.status


def test_servo_jitter_below_the_limit_does_not_hide_a_flat_curve():
    rng = np.random.default_rng(0)
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    plate = 1.0 + 0.01 * rng.standard_normal(x.size)  # +-0.01 mm: rates of at most ~0.007 over 4 mm
    r = dilation_stopped_residual(curve(plate, x))
    assert r.reached and r.start_mm == pytest.approx(2.0)


def test_a_curve_without_the_plane_record_gives_the_plate_ratio_only():
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    c = curve(np.zeros_like(x), x, plane=math.nan, wall=math.nan)
    r = dilation_stopped_residual(c)
    assert r.reached and r.stress_ratio == pytest.approx(0.3)
    assert r.plane_stress_ratio is None and r.plane_share is None and r.upper_wall_friction_kpa is None


def test_a_real_test_reads_its_residual_into_its_result_and_the_series(specimen, tmp_path):
    res = run_shear(specimen, [100], {"max_displacement": 0.006, "peak_window": 5e-4, "stop_after_peak": 0.0},
                    store=Store(tmp_path / "s"), progress=False)  # fmt: skip
    summary = res.tests[0]
    r = summary.residual_dilation_stopped
    assert r is not None and r.rate_window_m == pytest.approx(1e-3)
    # the test's own result.json holds the same reading, and it is the one its curve gives
    stored = json.loads((tmp_path / "s" / "sn100kPa" / "result.json").read_text())
    assert stored["residual_dilation_stopped"] == r.to_dict()
    again = dilation_stopped_residual(res.curves[100.0], 5e-4)
    assert again.to_dict() == r.to_dict()
    if r.reached:
        assert 0.0 < r.stress_ratio < 2.0 and 0.0 < r.plane_stress_ratio < 2.0
        assert r.start_mm >= 0.0 and r.end_mm == pytest.approx(6.0, abs=0.06)
    else:
        assert r.stress_ratio is None and r.status.startswith("not reached")


def test_a_test_written_before_the_residual_reading_still_reads():
    from pathlib import Path

    data = json.loads(
        (Path(__file__).parents[1] / "data" / "before_typed_results" / "shear_test_result.json").read_text()
    )
    assert "residual_dilation_stopped" not in data
    old = ShearTestResult.from_dict(data)
    assert old.residual_dilation_stopped is None and old.to_dict() == data


def test_poro2d_shear_prints_the_residual_beside_the_end_values_with_its_label(specimen, tmp_path, capsys):
    from poro2d.cli import main

    main(["shear", "--specimen", str(specimen), "-n", "100", "--max-displacement", "0.004",
          "--stop-after-peak", "0", "-p", "1", "--quiet", "--out", str(tmp_path / "o")])  # fmt: skip
    out = capsys.readouterr().out
    assert "resid." in out and "plate" in out and "plane" in out
    assert "the residual tau/sigma where dilation stopped" in out and "100 kPa: " in out


def test_the_table_cells_say_not_reached_and_leave_earlier_tests_blank():
    from poro2d.cli.shear import residual_cells
    from poro2d.cli.strength import _stopped

    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    assert residual_cells(dilation_stopped_residual(curve(0.05 * x, x))) == ("not reached", "not reached")
    assert residual_cells(dilation_stopped_residual(curve(0.0 * x, x))) == ("0.300", "0.375")
    assert residual_cells(None) == ("-", "-")
    assert _stopped({"tests_dilation_stopped": 0}) == "not reached" and _stopped({}) == "-"
    case = {"tests_dilation_stopped": 2, "residual_dilation_stopped_ratio_mean": 0.31,
            "residual_dilation_stopped_plane_ratio_mean": 0.29}  # fmt: skip
    assert _stopped(case) == "0.310 / 0.290 (2)"
