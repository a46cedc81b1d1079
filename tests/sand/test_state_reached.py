"""Where the specimens landed: the relative density they reached and the interior porosity at the
target itself, against the void-ratio mapping worked by hand."""

import math

import pytest

from poro2d.criterion.density import Calibration, target_error, target_porosity_2d
from poro2d.sand.reached import StateReached

MUS = [0.0, 0.05, 0.1, 1.0]
CAL = Calibration(MUS, [[0.1630, 0.1634], [0.1722, 0.1728], [0.1776, 0.1790], [0.2190, 0.2210]])
DR = 0.8
WALLS = 0.0028  # the walls' share the full box loses against the calibration box


def _e(n):
    return n / (1.0 - n)


def _dr(n, n_max, n_min):
    """Dr by hand: (e_max - e) / (e_max - e_min)."""
    return (_e(n_max) - _e(n)) / (_e(n_max) - _e(n_min))


def _reached(boxes, interiors):
    target = target_porosity_2d(DR, CAL.n2d_max, CAL.n2d_min)
    return StateReached.of(DR, target, target - WALLS, CAL, boxes, interiors), target


def test_specimens_on_the_target_reached_the_asked_state():
    target = target_porosity_2d(DR, CAL.n2d_max, CAL.n2d_min)
    box = target - WALLS
    got, _ = _reached([box - 0.0004, box, box + 0.0004], [box - 0.0040, box - 0.0036, box - 0.0032])
    assert got.relative_density_reached == pytest.approx(DR, abs=1e-9)
    assert got.interior_at_target == pytest.approx(box - 0.0036, abs=1e-12)
    assert got.walls_offset == pytest.approx(0.0036) and got.walls_offset_sd == pytest.approx(0.0, abs=1e-12)


def test_specimens_denser_than_asked_say_so_and_the_target_corrects_them():
    # three specimens 0.0012 below the full box's target (a friction read low): Dr above the one
    # asked, by the void-ratio mapping onto the calibration's extremes; the interior at the target
    # is their interior porosity moved back by the same 0.0012
    target = target_porosity_2d(DR, CAL.n2d_max, CAL.n2d_min)
    boxes = [target - WALLS - 0.0012 + d for d in (-0.0003, 0.0, 0.0003)]
    offsets = [0.0034, 0.0036, 0.0038]
    got, _ = _reached(boxes, [b - o for b, o in zip(boxes, offsets, strict=True)])
    by_hand = _dr(target - 0.0012, CAL.n2d_max, CAL.n2d_min)
    assert got.relative_density_reached == pytest.approx(by_hand, abs=1e-9)
    assert got.relative_density_reached > DR + 0.015  # 0.0012 in n' is about 0.02 in Dr here
    interior_mean = sum(b - o for b, o in zip(boxes, offsets, strict=True)) / 3
    assert got.interior_at_target == pytest.approx(interior_mean + 0.0012, abs=1e-12)
    assert got.walls_offset_sd == pytest.approx(0.0002)
    se = math.hypot(0.0002 / math.sqrt(3), target_error(DR, CAL))
    assert got.interior_at_target_se == pytest.approx(se)
    assert "Dr 0.8" in got.text() and "asked 0.800" in got.text()


def test_the_targets_error_is_the_mapping_derivative_times_the_ends_errors():
    # n = e / (1 + e), e = e_max - Dr (e_max - e_min): dn/dn_max = (1 - n)^2 (1 - Dr) / (1 - n_max)^2,
    # dn/dn_min = (1 - n)^2 Dr / (1 - n_min)^2; only the ends move the target
    target = target_porosity_2d(DR, CAL.n2d_max, CAL.n2d_min)
    se_min, se_max = 0.0004 / 2, 0.0020 / 2  # two seeds: sd / sqrt 2 = half their difference
    d_max = (1 - target) ** 2 * (1 - DR) / (1 - CAL.n2d_max) ** 2
    d_min = (1 - target) ** 2 * DR / (1 - CAL.n2d_min) ** 2
    assert target_error(DR, CAL) == pytest.approx(math.hypot(d_max * se_max, d_min * se_min), rel=1e-6)


def test_one_specimen_has_no_spread_and_none_has_no_state():
    target = target_porosity_2d(DR, CAL.n2d_max, CAL.n2d_min)
    one, _ = _reached([target - WALLS], [target - WALLS - 0.0035])
    assert one.walls_offset_sd is None and one.interior_at_target_se is None
    assert one.interior_at_target == pytest.approx(target - WALLS - 0.0035)
    assert "standard error" not in one.text()
    assert _reached([None, math.nan], [0.17, 0.17])[0] is None
    # a box too small for an interior region: the Dr reached, no interior porosity at the target
    bare, _ = _reached([target - WALLS, target - WALLS], [None, None])
    assert bare.relative_density_reached == pytest.approx(DR) and bare.interior_at_target is None
    assert "no interior porosity" in bare.text() and "wide grading" not in bare.text()


def test_a_wide_grading_says_its_target_leans_on_the_walls_model():
    target = target_porosity_2d(DR, CAL.n2d_max, CAL.n2d_min)
    boxes, interiors = [target - WALLS] * 2, [target - WALLS - 0.012] * 2
    wide = StateReached.of(DR, target, target - WALLS, CAL, boxes, interiors, wide=True)
    narrow = StateReached.of(DR, target, target - WALLS, CAL, boxes, interiors)
    assert wide.wide_grading and "wide grading" in wide.text() and "G1-1" in wide.text()
    assert wide.interior_at_target == narrow.interior_at_target and "wide" not in narrow.text()
