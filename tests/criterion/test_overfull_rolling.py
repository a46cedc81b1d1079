"""An over-full first trial with rolling friction: the plate rises and every disk stays in the box.

Rolling friction locks an over-dense packing: as the plate rose, the specimen rose as a plug
wedged between the side walls, and disks stayed pressed into them (measured at rolling friction
0.5: 5 disks past the in-box check, the trial refused, the command's exit 1 after 40 s). The
plate now first rises with rolling friction off (docs/criterion.md, over-full trials).
"""

import pytest

from poro2d.criterion.config import build
from poro2d.criterion.servo import PlateSettle


def test_a_free_rise_and_the_settling_after_it_are_one_plate_record():
    free = PlateSettle(True, 100, 2, 1e-3, 0.004, 0.045)
    later = PlateSettle(True, 30, 1, 2e-5, -0.0002, 0.0448)
    both = free.then(later)
    assert both == PlateSettle(True, 130, 3, 2e-5, pytest.approx(0.0038), 0.0448)
    assert not free.then(PlateSettle(False, 5, 1, 0.1, 0.0, 0.045)).settled


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
    res = PorosityCriterion(
        spec, grading, settings, seed=seed, store=Store(tmp_path / "c"), figures=False
    ).run()
    first = res.iterations[0]
    assert first["overfull_m"] > 0.0 and first["plate_moved"] == "up" and first["plate_settled"]
    assert first["new_porosity"] > 0.07 and "over-full box" in first["reason"]
    for row in res.iterations:
        assert row["disks_outside_box"] == 0 and row["checks"]["disks_inside_box"], row["reason"]
        assert not row["refused"], row["reason"]
    assert res.iterations[1]["trial_porosity"] > 0.07
    assert res.failed_trial is None
