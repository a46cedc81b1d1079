"""Grading curves: validation, up-scaling and cut-offs, drawing disks, the paper grading."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poro2d.errors import InputError
from poro2d.grading import (
    GradingCurve,
    draw_disks,
    max_deviation,
    paper_grading,
    realised_curve,
)
from poro2d.report.grading_figure import plot_realised

W, H = 0.305, 0.124  # paper box, Table 1


def solid_area(n2d: float) -> float:
    return (1.0 - n2d) * W * H


def total_area(r: np.ndarray) -> float:
    return float(np.sum(np.pi * r * r))


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("sizes", "percent", "kwargs", "parameter"),
    [
        ([0.5], [100], {}, "sizes_mm"),  # fewer than 2 points
        ([], [], {}, "sizes_mm"),
        ([0.2, 0.5, 0.4], [0, 50, 100], {}, "sizes_mm"),  # non-monotone sizes
        ([0.2, 0.2, 0.4], [0, 50, 100], {}, "sizes_mm"),  # repeated size
        ([0.2, 0.3, 0.4], [0, 60, 50], {}, "percent_passing"),  # non-monotone percent
        ([0.2, 0.3, 0.4], [0, 50, 90], {}, "percent_passing"),  # never reaches 100
        ([0.2, 0.3, 0.4], [-5, 50, 100], {}, "percent_passing"),  # below 0
        ([0.2, 0.3, 0.4], [0, 50, 101], {}, "percent_passing"),  # above 100
        ([0.0, 0.3, 0.4], [0, 50, 100], {}, "sizes_mm"),  # zero size
        ([-0.1, 0.3, 0.4], [0, 50, 100], {}, "sizes_mm"),  # negative size
        ([0.2, 0.3, 0.4], [0, 100], {}, "percent_passing"),  # length mismatch
        ([0.2, 0.3, float("nan")], [0, 50, 100], {}, "sizes_mm"),
        ([0.2, 0.3, 0.4], [10, 50, 100], {}, "percent_passing"),  # fines without lower bound
        ([0.2, 0.3, 0.4], [0, 50, 100], {"upscale": 0.0}, "upscale"),
        ([0.2, 0.3, 0.4], [0, 50, 100], {"upscale": -10.0}, "upscale"),
        ([0.2, 0.3, 0.4], [0, 50, 100], {"upscale": float("inf")}, "upscale"),
        ([0.2, 0.3, 0.4], [0, 50, 100], {"d_min_mm": 0.4}, "d_min_mm"),  # nothing left
        ([0.2, 0.3, 0.4], [0, 50, 100], {"d_max_mm": 0.2}, "d_max_mm"),  # nothing left
        ([0.2, 0.3, 0.4], [0, 50, 100], {"d_min_mm": 0.35, "d_max_mm": 0.3}, "d_min_mm"),
        ([0.2, 0.3, 0.4], [0, 50, 100], {"d_min_mm": 0.0}, "d_min_mm"),
        ([0.2, 0.3, 0.4], [0, 0, 100], {"d_max_mm": 0.29}, "d_max_mm"),  # cut keeps no mass
        ([0.2, 0.3, 0.4], [0, 100, 100], {"d_min_mm": 0.31}, "d_min_mm"),  # cut keeps no mass
    ],
)
def test_invalid_curves_name_the_parameter(sizes, percent, kwargs, parameter):
    with pytest.raises(InputError) as err:
        GradingCurve.from_lists(sizes, percent, **kwargs)
    assert err.value.parameter == parameter
    assert parameter in str(err.value)


def test_direct_constructor_validates_model_sizes():
    with pytest.raises(InputError, match="sizes_m"):
        GradingCurve((0.004, 0.002), (0.0, 100.0))
    with pytest.raises(InputError, match="percent_passing"):
        GradingCurve((0.002, 0.004), (5.0, 100.0))
    with pytest.raises(InputError, match="upscale"):
        GradingCurve((0.002, 0.004), (0.0, 100.0), upscale=0.0)


def test_descending_table_is_accepted():
    a = GradingCurve.from_lists([0.4, 0.3, 0.2], [100, 40, 0])
    b = GradingCurve.from_lists([0.2, 0.3, 0.4], [0, 40, 100])
    assert a.sizes_m == b.sizes_m and a.percent_passing == b.percent_passing


def test_upscale_and_units():
    c = GradingCurve.from_lists([0.2, 0.4], [0, 100], upscale=10)
    assert c.sizes_m == pytest.approx((0.002, 0.004), rel=1e-15)
    assert c.upscale == 10.0
    assert c.d_min_m == pytest.approx(0.002) and c.d_max_m == pytest.approx(0.004)


def test_cutoffs_act_after_upscaling_and_renormalise():
    # up-scaled sizes 2, 4, 8 mm with 0, 50, 100 %
    c = GradingCurve.from_lists([1, 2, 4], [0, 50, 100], upscale=2, d_min_mm=4)
    assert c.sizes_m == pytest.approx((0.004, 0.008))
    assert c.percent_passing == (0.0, 100.0)
    # 4 * sqrt(2) mm is half way between 4 and 8 mm in log d: 75 % passing there
    c = GradingCurve.from_lists([1, 2, 4], [0, 50, 100], upscale=2, d_max_mm=4 * math.sqrt(2))
    assert c.sizes_m == pytest.approx((0.002, 0.004, 0.004 * math.sqrt(2)))
    assert c.percent_passing == pytest.approx((0.0, 50 / 75 * 100, 100.0))
    assert c.class_fractions.sum() == pytest.approx(1.0)


def test_cutoff_below_the_curve_is_a_no_op_and_cuts_fines():
    base = GradingCurve.from_lists([0.2, 0.3, 0.4], [0, 50, 100])
    same = GradingCurve.from_lists([0.2, 0.3, 0.4], [0, 50, 100], d_min_mm=0.1, d_max_mm=1.0)
    assert same.sizes_m == base.sizes_m and same.percent_passing == base.percent_passing
    # fines passing the smallest sieve are fine once d_min cuts them off
    c = GradingCurve.from_lists([0.2, 0.3, 0.4], [10, 55, 100], d_min_mm=0.3)
    assert c.sizes_m == pytest.approx((0.0003, 0.0004)) and c.percent_passing == (0.0, 100.0)


def test_empty_end_classes_are_trimmed():
    c = GradingCurve.from_lists([0.1, 0.2, 0.3, 0.4, 0.5], [0, 0, 50, 100, 100])
    assert c.sizes_m == pytest.approx((0.0002, 0.0003, 0.0004))


def test_csv_round_trip(tmp_path):
    p = tmp_path / "g.csv"
    p.write_text("# a comment line\nsize_mm, percent_passing\n0.2,0\n0.3,40\n\n0.4,100\n")
    c = GradingCurve.from_csv(p, upscale=10)
    assert c.sizes_m == pytest.approx((0.002, 0.003, 0.004))
    assert c.percent_passing == (0.0, 40.0, 100.0)
    assert c.source == str(p)


def test_csv_errors(tmp_path):
    with pytest.raises(InputError, match="csv"):
        GradingCurve.from_csv(tmp_path / "missing.csv")
    bad = tmp_path / "bad.csv"
    bad.write_text("d,p\n0.2,0\n0.4,100\n")
    with pytest.raises(InputError, match="size_mm,percent_passing"):
        GradingCurve.from_csv(bad)
    bad.write_text("size_mm,percent_passing\n0.2,zero\n0.4,100\n")
    with pytest.raises(InputError, match="csv"):
        GradingCurve.from_csv(bad)


def test_from_config(tmp_path):
    inline = GradingCurve.from_config(
        {"sizes_mm": [0.2, 0.4], "percent_passing": [0, 100], "upscale": 10, "d_max_mm": 3.0}
    )
    assert inline.sizes_m == pytest.approx((0.002, 0.003))
    (tmp_path / "g.csv").write_text("size_mm,percent_passing\n0.2,0\n0.4,100\n")
    from_file = GradingCurve.from_config({"csv": "g.csv", "upscale": 10}, base_dir=tmp_path)
    assert from_file.sizes_m == pytest.approx((0.002, 0.004))
    assert GradingCurve.from_config({"preset": "paper"}) == paper_grading()
    with pytest.raises(InputError, match="grading.sieves"):
        GradingCurve.from_config({"sieves": [1, 2]})
    with pytest.raises(InputError, match="grading"):
        GradingCurve.from_config({"upscale": 10})
    with pytest.raises(InputError, match="grading.preset"):
        GradingCurve.from_config({"preset": "other"})
    with pytest.raises(InputError, match="grading.percent_passing"):
        GradingCurve.from_config({"sizes_mm": [0.2, 0.4]})


def test_draw_disks_input_errors():
    c = paper_grading()
    with pytest.raises(InputError, match="solid_area"):
        draw_disks(c, 0.0, 1)
    with pytest.raises(InputError, match="solid_area"):
        draw_disks(c, -1.0, 1)
    with pytest.raises(InputError, match="solid_area"):
        draw_disks(c, 1e-12, 1)  # less than one disk
    with pytest.raises(InputError, match="seed"):
        draw_disks(c, 0.01, -3)
    with pytest.raises(InputError, match="seed"):
        draw_disks(c, 0.01, 1.5)
    with pytest.raises(InputError, match="within_class"):
        draw_disks(c, 0.01, 1, within_class="normal")
    with pytest.raises(InputError, match="curve"):
        draw_disks([1, 2], 0.01, 1)
    with pytest.raises(InputError, match="radii"):
        realised_curve(c, [])


# ----------------------------------------------------------------------------- drawing
@pytest.mark.parametrize("within", ["uniform", "loguniform"])
def test_draws_follow_the_curve(within):
    c = paper_grading()
    r = draw_disks(c, solid_area(0.15), 7, within_class=within)
    assert r.size > 2000
    assert max_deviation(c, r) < 1.0
    d = 2 * r
    assert d.min() >= c.d_min_m * (1 - 1e-3) and d.max() <= c.d_max_m * (1 + 1e-3)


def test_wide_grading_follows_the_curve():
    c = GradingCurve.from_lists(
        [1, 2, 4, 8, 16], [0, 10, 30, 75, 100], upscale=1, source="wide"
    )  # 1 to 16 mm
    r = draw_disks(c, 0.6, 3)
    assert r.size > 5000
    assert max_deviation(c, r) < 2.0
    assert np.mean(np.pi * r**2) == pytest.approx(c.mean_disk_area(), rel=0.03)


@settings(max_examples=25, deadline=None)
@given(
    area=st.floats(min_value=2e-4, max_value=5e-2),
    seed=st.integers(min_value=0, max_value=2**32 - 1),
)
def test_total_area_is_exact(area, seed):
    r = draw_disks(paper_grading(), area, seed)
    assert abs(total_area(r) - area) <= 1e-12 * area


def test_deterministic_with_seed_and_different_across_seeds():
    c = paper_grading()
    a = draw_disks(c, 0.01, 42)
    b = draw_disks(c, 0.01, 42)
    other = draw_disks(c, 0.01, 43)
    assert np.array_equal(a, b)
    assert a.size != other.size or not np.array_equal(a, other)
    g = draw_disks(c, 0.01, np.random.default_rng(42))
    assert np.array_equal(a, g)


def test_mean_disk_area_matches_draws():
    c = paper_grading()
    r = draw_disks(c, 0.2, 11)
    assert total_area(r) / r.size == pytest.approx(c.mean_disk_area(), rel=0.01)


def test_realised_curve_by_area():
    c = GradingCurve((0.002, 0.004, 0.008), (0.0, 50.0, 100.0))
    r = np.array([0.0015, 0.003])  # d = 3 mm and 6 mm: areas 1 : 4
    np.testing.assert_allclose(realised_curve(c, r), [0.0, 20.0, 100.0])
    assert max_deviation(c, r) == pytest.approx(30.0)


def test_plot_realised_writes_png(tmp_path):
    c = paper_grading()
    r = draw_disks(c, 0.005, 1)
    out = plot_realised(c, r, tmp_path / "sub" / "grading.png", title="paper grading")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ----------------------------------------------------------------------------- paper grading
def test_paper_grading_is_the_documented_reconstruction():
    c = paper_grading()
    assert c.upscale == 10.0
    assert c.sizes_m == pytest.approx((0.002, 0.0025, 0.00315, 0.004, 0.005, 0.0063, 0.0071))
    assert c.percent_passing == (0.0, 4.0, 15.0, 37.0, 65.0, 90.0, 100.0)
    assert c.mean_disk_area() == pytest.approx(1.256e-5, rel=1e-3)


@pytest.mark.parametrize(("n2d", "paper_count"), [(0.14, 2591), (0.15, 2552)])
def test_paper_grading_particle_counts(n2d, paper_count):
    c = paper_grading()
    counts = [draw_disks(c, solid_area(n2d), seed).size for seed in range(5)]
    assert abs(np.mean(counts) - paper_count) / paper_count < 0.015
    assert all(abs(n - paper_count) / paper_count < 0.015 for n in counts)
    assert abs(c.expected_count(solid_area(n2d)) - paper_count) / paper_count < 0.015


def test_log_linear_family_has_its_uniformity_and_mean_area():
    from poro2d.grading import draw_disks, log_linear_grading, paper_grading

    target = paper_grading().mean_disk_area()
    for cu in (1.5, 2.5, 4.0):
        g = log_linear_grading(cu, target)
        assert g.uniformity == pytest.approx(cu, rel=1e-9)
        assert g.d_max_m / g.d_min_m == pytest.approx(cu**2, rel=1e-9)
        radii = draw_disks(g, 2000 * target, np.random.default_rng(0))
        assert np.mean(np.pi * radii**2) == pytest.approx(target, rel=0.05)  # drawn, not assumed
    with pytest.raises(InputError, match="cu"):
        log_linear_grading(1.0, target)
