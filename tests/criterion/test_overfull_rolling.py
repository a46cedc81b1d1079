"""An over-full or dense first trial with rolling friction: the plate rises and every disk stays in the box.

Rolling friction locks an over-dense packing: as the plate rose, the specimen rose as a plug
wedged between the side walls, and disks stayed pressed into them (measured at rolling friction
0.5: 5 disks past the in-box check, the trial refused, the command's exit 1 after 40 s). The
plate now first rises with rolling friction off (docs/criterion.md, over-full trials).
"""

import pytest

from poro2d.criterion.config import build
from poro2d.criterion.servo import PlateSettle, rises_free_to_roll


def test_a_free_rise_and_the_settling_after_it_are_one_plate_record():
    free = PlateSettle(True, 100, 2, 1e-3, 0.004, 0.045)
    later = PlateSettle(True, 30, 1, 2e-5, -0.0002, 0.0448)
    both = free.then(later)
    assert both == PlateSettle(True, 130, 3, 2e-5, pytest.approx(0.0038), 0.0448)
    assert not free.then(PlateSettle(False, 5, 1, 0.1, 0.0, 0.045)).settled


def test_the_plate_rises_free_to_roll_whenever_it_rises_over_rolling_disks():
    """G = 70 N/m, window 5 %: the limit is 3.5 N/m."""
    assert rises_free_to_roll(2.0e4, 70.0, 0.05, False, 1.0)  # dense, not over-full: it rises
    assert rises_free_to_roll(3.5, 70.0, 0.05, False, 0.1)  # at the limit it rises too
    assert rises_free_to_roll(0.0, 70.0, 0.05, True, 0.4)  # over-full
    assert not rises_free_to_roll(2.0, 70.0, 0.05, False, 1.0)  # in the window: the plate stays
    assert not rises_free_to_roll(0.0, 70.0, 0.05, False, 1.0)  # loose: the plate moves down
    assert not rises_free_to_roll(2.0e4, 70.0, 0.05, True, 0.0)  # disks free to roll already


@pytest.mark.scenario  # a whole criterion run of a dense box (about a minute)
def test_a_dense_trial_short_of_overfull_with_rolling_friction_keeps_every_disk_in_the_box(tmp_path):
    """Trial 0.12 of the wide grading (n_J 0.110: dense, not over-full) at rolling friction 1.0:
    F_top 2.0e4 N/m, 277 G. The plate rose with rolling friction on, the side stress stayed locked
    and a fine disk (r 0.74 mm) stayed pressed 5.1 % of its radius into the right wall: trial
    refused, exit 1 (at trial 0.14 too). Rising free to roll: plate up 2.4 mm, n' 0.171, no disk
    outside, then trial 0.17 accepted (n' 0.166)."""
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.store import Store

    cfg = {
        "grading": {"preset": "wide_cu4"},
        "specimen": {"width": 0.08, "height": 0.04, "layers": 2, "rolling_friction": 1.0},
        "criterion": {"trial_porosity": 0.12, "force_fraction": 0.05, "max_iterations": 2},
    }
    spec, grading, settings, seed = build(cfg)
    res = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(tmp_path / "c")).run()
    first = res.iterations[0].to_dict()  # the trial's row
    assert first["f_top_n_per_m"] > 1e4 and first["plate_moved"] == "up" and first["plate_settled"]
    for row in (t.to_dict() for t in res.iterations):
        assert row["disks_outside_box"] == 0 and row["checks"]["disks_inside_box"], row["reason"]
        assert not row["refused"], row["reason"]
    assert res.failed_trial is None


@pytest.mark.scenario  # two whole criterion runs of an over-full box (a minute each)
@pytest.mark.parametrize("rolling", [0.4, 1.0])
def test_an_overfull_first_trial_with_rolling_friction_keeps_every_disk_in_the_box(tmp_path, rolling):
    """Trial 0.07 of the wide grading in a small box (over-full by 1.5 mm), rolling friction 0.4
    and 1.0: the plate moves up, no disk is outside the box and no trial is refused (measured at
    0.5 and 1.0: n' 0.199 and 0.202, then trial 0.20; about 40 s each)."""
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.store import Store

    cfg = {
        "grading": {"preset": "wide_cu4"},
        "specimen": {"width": 0.08, "height": 0.04, "layers": 2, "rolling_friction": rolling},
        "criterion": {"trial_porosity": 0.07, "force_fraction": 0.05, "max_iterations": 2},
    }
    spec, grading, settings, seed = build(cfg)
    res = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(tmp_path / "c")).run()
    first = res.iterations[0].to_dict()  # the trial's row
    assert first["overfull_m"] > 0.0 and first["plate_moved"] == "up" and first["plate_settled"]
    assert first["new_porosity"] > 0.07 and "over-full box" in first["reason"]
    for row in (t.to_dict() for t in res.iterations):
        assert row["disks_outside_box"] == 0 and row["checks"]["disks_inside_box"], row["reason"]
        assert not row["refused"], row["reason"]
    assert res.iterations[1].trial_porosity > 0.07
    assert res.failed_trial is None
