"""The shear box against ASTM D3080 and the size-insensitive 2D box: ratios, shortfalls, labels."""

import numpy as np
import pytest

from poro2d.execute import RunOptions
from poro2d.shear.box_scale import BoxScale, box_scale


def test_ratios_are_the_box_in_largest_grains():
    radii = np.array([0.5e-3, 1.0e-3, 0.75e-3])  # d_max = 2 mm
    s = box_scale(0.08, 0.04, radii)
    assert s.d_max_m == pytest.approx(2e-3)
    assert (s.width_over_d_max, s.height_over_d_max, s.width_over_height) == pytest.approx((40.0, 20.0, 2.0))
    assert s.disks == 3


def test_each_astm_shortfall_is_named():
    radii = np.full(10, 1e-3)  # d_max = 2 mm
    s = box_scale(0.016, 0.01, radii)  # W = 8 d_max, H = 5 d_max, W/H = 1.6
    assert len(s.astm_shortfalls) == 3
    assert "W = 8.0 d_max < 10" in s.astm_shortfalls[0]
    assert "H = 5.0 d_max < 6" in s.astm_shortfalls[1]
    assert "W/H = 1.600 < 2" in s.astm_shortfalls[2]
    assert not s.meets_astm and "ASTM D3080" in s.warning()


def test_a_box_at_the_standard_meets_it_but_is_still_box_scale():
    s = box_scale(0.02, 0.012, np.full(100, 1e-3))  # exactly 10 x 6 d_max, W/H = 1.67
    assert s.astm_shortfalls == ["W/H = 1.667 < 2"]
    s = box_scale(0.024, 0.012, np.full(100, 1e-3))  # 12 x 6 d_max, W/H = 2
    assert s.meets_astm and s.warning() is None
    assert s.box_scale and s.label() == "box-scale"  # far below 60 d_max and 5000 disks
    # a box of W/H = 2 read back from its walls a few microns taller still meets the ratio
    read_back = box_scale(0.08, 0.0400015, np.full(100, 1e-3))
    assert read_back.astm_shortfalls == [] and read_back.warning() is None
    assert box_scale(0.08, 0.0401, np.full(100, 1e-3)).astm_shortfalls == ["W/H = 1.995 < 2"]


def test_a_large_box_with_many_disks_is_not_labelled():
    s = box_scale(0.13, 0.05, np.full(6000, 1e-3))  # 65 x 25 d_max, 6000 disks
    assert not s.box_scale and s.label() == ""
    assert "large enough" in s.note()
    few = box_scale(0.13, 0.05, np.full(2000, 1e-3))  # wide enough, too few disks
    assert few.box_scale


def test_the_record_reads_back_from_its_file():
    s = box_scale(0.08, 0.04, np.full(50, 1e-3))
    back = BoxScale.from_dict(s.to_dict())
    assert back.to_dict() == s.to_dict() and back.label() == s.label()


def test_a_series_records_and_prints_its_box_scale(specimen, tmp_path):
    from poro2d.shear import ShearSeriesCase, run_shear
    from poro2d.store import Store

    res = run_shear(
        ShearSeriesCase(specimen, [100], {"max_displacement": 0.0005, "peak_window": 2e-4}),
        Store(tmp_path / "s"),
        options=RunOptions(progress=False),
    )
    assert res.box_scale is not None and res.box_scale.box_scale  # the ~110-disk test box
    import json

    on_file = json.loads((tmp_path / "s" / "result.json").read_text())["box_scale"]
    assert on_file["disks"] == res.box_scale.disks > 0
