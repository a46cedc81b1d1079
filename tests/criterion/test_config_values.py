"""The criterion's config as a value: the paper's case, varied without editing a dict."""

import json

from poro2d.criterion.config import CriterionConfig, paper_config, paper_preset


def test_the_paper_cases_record_the_tables_they_always_did():
    """Result files record these tables and case ids hash them: their keys, order and values are pinned."""
    assert json.dumps(paper_preset().as_config()) == (
        '{"seed": 0, "specimen": {}, "grading": {"preset": "paper"}, "criterion": {"n_lab": 0.3434}}'
    )
    assert json.dumps(paper_config(False, 3).as_config()) == (
        '{"seed": 3, "specimen": {}, "grading": {"preset": "paper"}, "criterion": {"n_lab": 0.3434}}'
    )
    assert json.dumps(paper_config(True, 2).as_config()) == (
        '{"seed": 2, "specimen": {"width": 0.08, "height": 0.04, "layers": 2}, '
        '"grading": {"preset": "paper"}, '
        '"criterion": {"n_lab": 0.3434, "force_fraction": 0.05, "acceptance": "plate"}}'
    )


def test_a_variation_is_a_new_value_and_the_original_stays():
    base = paper_preset()
    quick = base.with_tables(specimen={"layers": 2}).with_seed(5)
    assert base.table("specimen") == {} and base.config["seed"] == 0
    assert quick.table("specimen") == {"layers": 2} and quick.config["seed"] == 5
    table = quick.table("criterion")
    table["n_lab"] = 0.5  # a copy: the value is not changed through it
    assert quick.table("criterion") == {"n_lab": 0.3434}
    spec, _, settings, seed = quick.build()
    assert spec.layers == 2 and settings.n_lab == 0.3434 and seed == 5
    assert CriterionConfig({"seed": 1}).with_seed(2).as_config() == {"seed": 2}
