"""The box-size study's boxes: built as the paper's modes build theirs, only larger (no DEM run)."""

import dataclasses
import sys
import tomllib
from pathlib import Path

import pytest

from poro2d.criterion.config import build, paper_config

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from box_size import BOXES, config_text, mean_sd, text  # noqa: E402


def test_quick_box_is_the_quick_looks_config():
    """The quick box's specimen and criterion settings are those of ``poro2d paper --quick``."""
    ours = tomllib.loads(config_text(BOXES["quick"]))
    theirs = paper_config(quick=True, seed=0).as_config()
    assert build(ours)[0] == build(theirs)[0]
    assert build(ours)[2] == build(theirs)[2]


@pytest.mark.parametrize("name, factor", [("x1.5", 1.5), ("x2", 2.0)])
def test_larger_boxes_differ_from_the_paper_preset_only_in_size_and_layers(name, factor):
    paper = build(paper_config(quick=False, seed=0).as_config())
    ours = build(tomllib.loads(config_text(BOXES[name])))
    spec, base = ours[0], paper[0]
    assert spec.width == pytest.approx(factor * base.width)
    assert spec.height == pytest.approx(factor * base.height)
    # layers as high as the paper's (0.124 m in 4)
    assert spec.height / spec.layers == pytest.approx(base.height / base.layers, rel=1e-3)
    assert dataclasses.replace(spec, width=base.width, height=base.height, layers=base.layers) == base
    assert ours[1:] == paper[1:]  # grading, criterion settings, seed


def test_spread_over_seeds_leaves_out_tests_without_a_residual():
    assert mean_sd([0.3, 0.5, None]) == pytest.approx((0.4, 0.1414213562, 2))
    assert text([0.3, 0.5, None]) == "0.400 +- 0.141 (2/3)"
    assert text([None, None]) == "not reached"
