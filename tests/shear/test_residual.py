"""The residual read where dilation has stopped: on curves whose answer is known, and on a real test."""

import json
import math

import numpy as np
import pytest

from poro2d.execute import RunOptions
from poro2d.shear import ShearSeriesCase, run_shear
from poro2d.shear.residual import (
    DILATION_RATE_LIMIT,
    built_up_mm,
    dilation_stopped_residual,
    final_stretch_rates,
    tail_residual,
)
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


D_MEAN = 3.75e-3  # m: a minimum stretch of 4 d_mean = 15 mm


def test_the_rate_of_a_straight_rise_is_its_slope_over_every_stretch_and_half():
    x = np.arange(0.0, 40.0 + 1e-9, STEP_MM)
    start, whole, halves = final_stretch_rates(x, 0.07 * x + 1.0, 15.0)
    assert x[start[-1]] == pytest.approx(25.0) and start[0] == 0
    assert np.allclose(whole, 0.07) and np.allclose(halves, 0.07)


def _slopes(x, y, i):
    """The least-squares slopes over [x_i, end] and its two halves, by numpy's polyfit."""
    mid = i + (x.size - i) // 2
    return [np.polyfit(x[a:b], y[a:b], 1)[0] for a, b in ((i, x.size), (i, mid), (mid, x.size))]


def test_a_curve_that_flattens_is_read_from_the_first_stretch_whose_slopes_are_within_the_limit():
    # plate rise a (1 - exp(-x / L)): tangent slope (a / L) exp(-x / L), within the limit from
    # L ln(a / (L limit))
    a, length = 3.0, 6.0
    x = np.arange(0.0, 50.0 + 1e-9, STEP_MM)
    y = a * (1.0 - np.exp(-x / length))
    tau = np.where(x < 25.0, 60.0, 30.0)  # the stretch's mean must hold only what lies inside it
    c = curve(y, x)
    c["shear_stress_kpa"] = tau
    r = dilation_stopped_residual(c, D_MEAN)
    tangent_at_limit = length * math.log(a / (length * DILATION_RATE_LIMIT))
    assert r.reached and r.min_stretch_m == pytest.approx(0.015)
    i = int(np.flatnonzero(x == r.start_mm)[0])
    # the stretch from the start record passes, the one from the record before does not (slopes by polyfit)
    assert max(abs(v) for v in _slopes(x, y, i)) <= DILATION_RATE_LIMIT
    assert max(abs(v) for v in _slopes(x, y, i - 1)) > DILATION_RATE_LIMIT
    # the first half's slope lies between the tangents at its ends: the start lies before the tangent's
    # limit and its first half's middle after it
    assert r.start_mm <= tangent_at_limit <= r.start_mm + 0.5 * (50.0 - r.start_mm)
    inside = x >= r.start_mm
    assert r.shear_stress_kpa == pytest.approx(tau[inside].mean())
    assert r.stress_ratio == pytest.approx(tau[inside].mean() / 100.0)
    assert r.plane_stress_ratio == pytest.approx(tau[inside].mean() / 80.0)
    assert r.plane_share == pytest.approx(0.8) and r.upper_wall_friction_kpa == pytest.approx(4.0)
    assert r.dilation_rate == pytest.approx(_slopes(x, y, i)[0]) and r.end_mm == pytest.approx(50.0)
    assert "from" in r.status and 0.0 < r.end_rate < r.dilation_rate


def test_a_curve_still_rising_at_its_end_has_no_residual():
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    r = dilation_stopped_residual(curve(0.05 * x, x), D_MEAN)
    assert not r.reached and r.stress_ratio is None and r.plane_stress_ratio is None and r.start_mm is None
    assert r.status.startswith("not reached") and "+0.050" in r.status and r.end_rate == pytest.approx(0.05)
    # the mean over the last fifth is still a number: it just is not a residual
    assert tail_residual(curve(0.05 * x, x)) == pytest.approx(0.3)


def test_a_contracting_end_is_no_residual_either():
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    assert not dilation_stopped_residual(curve(-0.03 * x, x), D_MEAN).reached


def test_a_stretch_still_rising_in_its_first_half_is_not_at_rest():
    # up at 0.03 per unit of shear to 20 mm, flat to 45 mm: over [0, 45] the net slope is within the
    # limit, but the first half's is not: the stretch starts where the rise no longer dominates a half
    x = np.arange(0.0, 45.0 + 1e-9, STEP_MM)
    y = np.interp(x, [0.0, 20.0, 45.0], [0.0, 0.6, 0.6])
    assert abs(np.polyfit(x, y, 1)[0]) < DILATION_RATE_LIMIT
    r = dilation_stopped_residual(curve(y, x), D_MEAN)
    assert r.reached and r.start_mm > 5.0 and r.max_part_rate <= DILATION_RATE_LIMIT
    i = int(np.flatnonzero(x == r.start_mm)[0])
    assert max(abs(v) for v in _slopes(x, y, i - 1)) > DILATION_RATE_LIMIT


def test_a_curve_shorter_than_the_least_stretch_is_not_reached():
    x = np.arange(0.0, 12.0 + 1e-9, STEP_MM)
    r = dilation_stopped_residual(curve(0.0 * x, x), D_MEAN)
    assert not r.reached and "shorter than 15 mm" in r.status and r.end_rate is None


def test_the_stretch_starts_once_the_stress_has_built_up():
    # no stress to 20 mm, 30 kPa after: smoothed over the 15 mm least stretch it reaches 90 % of 30 kPa
    # where 90 % of the window lies beyond 20 mm, at 26 mm; the loading before is no residual
    x = np.arange(0.0, 45.0 + 1e-9, STEP_MM)
    c = curve(0.0 * x, x)
    c["shear_stress_kpa"] = np.where(x < 20.0, 0.0, 30.0)
    assert built_up_mm(c, 0.015) == pytest.approx(26.0, abs=0.06)
    r = dilation_stopped_residual(c, D_MEAN)
    assert r.start_mm == pytest.approx(26.0, abs=0.06) and r.stress_ratio == pytest.approx(0.3)
    # 40 mm of it leave 14 mm after the build-up: under the least stretch
    short = {k: v[x <= 40.0] for k, v in c.items()}
    assert not dilation_stopped_residual(short, D_MEAN).reached


def test_servo_jitter_does_not_hide_a_flat_curve():
    rng = np.random.default_rng(0)
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    plate = 1.0 + 0.05 * rng.standard_normal(x.size)
    r = dilation_stopped_residual(curve(plate, x), D_MEAN)
    assert r.reached and r.start_mm == 0.0


def test_a_curve_without_the_plane_record_gives_the_plate_ratio_only():
    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    c = curve(np.zeros_like(x), x, plane=math.nan, wall=math.nan)
    r = dilation_stopped_residual(c, D_MEAN)
    assert r.reached and r.stress_ratio == pytest.approx(0.3)
    assert r.plane_stress_ratio is None and r.plane_share is None and r.upper_wall_friction_kpa is None


def test_a_real_test_reads_its_residual_into_its_result_and_the_series(specimen, tmp_path):
    res = run_shear(
        ShearSeriesCase(specimen, [100], {"max_displacement": 0.02, "stop_after_peak": 0.0}),
        Store(tmp_path / "s"),
        options=RunOptions(progress=False),
    )
    summary = res.tests[0]
    r = summary.residual_dilation_stopped
    d_mean = json.loads((tmp_path / "s" / "sn100kPa" / "result.json").read_text())["d_mean_m"]
    assert r is not None and r.min_stretch_m == pytest.approx(4 * d_mean)
    # the test's own result.json holds the same reading, and it is the one its curve gives
    stored = json.loads((tmp_path / "s" / "sn100kPa" / "result.json").read_text())
    assert stored["residual_dilation_stopped"] == r.to_dict()
    again = dilation_stopped_residual(res.curves[100.0], d_mean)
    assert again.to_dict() == r.to_dict()
    if r.reached:
        assert 0.0 < r.stress_ratio < 2.0 and 0.0 < r.plane_stress_ratio < 2.0
        assert r.start_mm >= 0.0 and r.end_mm == pytest.approx(20.0, abs=0.06)
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
          "--stop-after-peak", "0", "--workers", "1", "--quiet", "--out", str(tmp_path / "o")])  # fmt: skip
    out = capsys.readouterr().out
    assert "resid." in out and "plate" in out and "plane" in out
    assert "the residual tau/sigma where dilation stopped" in out and "100 kPa: " in out


def test_the_table_cells_say_not_reached_and_leave_earlier_tests_blank():
    from poro2d.cli.shear import residual_cells
    from poro2d.cli.strength import _stopped

    x = np.arange(0.0, 30.0 + 1e-9, STEP_MM)
    assert residual_cells(dilation_stopped_residual(curve(0.05 * x, x), D_MEAN)) == (
        "not reached",
        "not reached",
    )
    assert residual_cells(dilation_stopped_residual(curve(0.0 * x, x), D_MEAN)) == ("0.300", "0.375")
    assert residual_cells(None) == ("-", "-")
    assert _stopped({"tests_dilation_stopped": 0}) == "not reached" and _stopped({}) == "-"
    case = {"tests_dilation_stopped": 2, "residual_dilation_stopped_ratio_mean": 0.31,
            "residual_dilation_stopped_plane_ratio_mean": 0.29}  # fmt: skip
    assert _stopped(case) == "0.310 / 0.290 (2)"


def test_a_strength_case_averages_only_the_tests_that_reached_a_residual():
    from poro2d.shear.strength import dilation_stopped_means

    tests = [
        {"residual_dilation_stopped_ratio": 0.30, "residual_dilation_stopped_plane_ratio": 0.28},
        {"residual_dilation_stopped_ratio": None, "residual_dilation_stopped_plane_ratio": None},
        {"residual_dilation_stopped_ratio": 0.36, "residual_dilation_stopped_plane_ratio": 0.32},
    ]
    means = dilation_stopped_means(tests)
    assert means["tests_dilation_stopped"] == 2
    assert means["residual_dilation_stopped_ratio_mean"] == pytest.approx(0.33)
    assert means["residual_dilation_stopped_plane_ratio_mean"] == pytest.approx(0.30)
    none = dilation_stopped_means(tests[1:2])
    assert none["tests_dilation_stopped"] == 0 and none["residual_dilation_stopped_ratio_mean"] is None
    assert none["residual_dilation_stopped_plane_ratio_mean"] is None
