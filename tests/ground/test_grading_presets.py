"""The built-in gradings: the paper's reconstruction and the two wide illustrative curves."""

import pytest

from poro2d.errors import InputError
from poro2d.grading import GRADING_PRESETS, GradingCurve, paper_grading, preset_grading


@pytest.mark.parametrize(
    ("name", "cu", "span"),
    [("paper", 1.69, 3.55), ("wide_cu4", 4.26, 25.4), ("wide_cu6", 6.32, 25.0)],
)
def test_presets_have_their_stated_width(name, cu, span):
    g = preset_grading(name)
    assert g.uniformity == pytest.approx(cu, abs=0.01)
    assert g.d_max_m / g.d_min_m == pytest.approx(span, abs=0.05)
    assert GradingCurve.from_config({"preset": name}).sizes.tolist() == g.sizes.tolist()


def test_paper_preset_is_the_paper_grading():
    assert preset_grading("paper").sizes.tolist() == paper_grading().sizes.tolist()


def test_wide_presets_are_labelled_illustrative():
    for name in ("wide_cu4", "wide_cu6"):
        assert "illustrative" in preset_grading(name).source
    assert set(GRADING_PRESETS) == {"paper", "wide_cu4", "wide_cu6"}


def test_unknown_preset_is_refused_naming_the_choices():
    with pytest.raises(InputError, match="wide_cu6"):
        GradingCurve.from_config({"preset": "coarse"})
    with pytest.raises(InputError, match="grading preset"):
        preset_grading("coarse")
