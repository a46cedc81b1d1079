"""``poro2d criterion`` is density-aware by default where the laboratory extremes are given."""

import pytest

from poro2d.criterion.run import CriterionCase
from poro2d.errors import InputError

SMALL = {"seed": 0, "specimen": {"width": 0.05, "height": 0.025, "layers": 2}, "grading": {"preset": "paper"},
         "criterion": {"n_lab": 0.40}}  # fmt: skip


def test_both_extremes_in_the_config_ask_for_density_mode():
    cfg = dict(SMALL, density={"n_max": 0.4571, "n_min": 0.3253})
    assert CriterionCase.from_config(cfg).mode == "density"


def test_both_extremes_as_options_ask_for_density_mode():
    assert CriterionCase.from_config(SMALL, n_max=0.4571, n_min=0.3253).mode == "density"


def test_without_extremes_paper_mode_stays_the_default():
    assert CriterionCase.from_config(SMALL).mode == "paper"
    assert CriterionCase.from_config(None).mode == "paper"  # the paper preset: its case, unchanged


def test_an_explicit_mode_wins_and_one_extreme_alone_is_refused():
    cfg = dict(SMALL, density={"mode": "paper"})
    assert CriterionCase.from_config(cfg).mode == "paper"
    with pytest.raises(InputError) as e:
        CriterionCase.from_config(SMALL, n_max=0.4571)
    assert e.value.parameter == "--n-max"


def test_paper_mode_says_its_answer_does_not_follow_the_density(tmp_path, capsys):
    from poro2d.cli import main

    cfg = tmp_path / "c.toml"
    cfg.write_text('seed = 0\n[specimen]\nwidth = 0.05\nheight = 0.025\nlayers = 2\n[criterion]\n'
                   'n_lab = 0.40\nforce_fraction = 0.05\n')  # fmt: skip
    try:
        main(["criterion", "--config", str(cfg), "--out", str(tmp_path / "o"), "--quiet"])
    except SystemExit as exc:
        assert exc.code in (0, 1)
    text = " ".join(capsys.readouterr().out.split())
    assert "paper mode: the specimen is prepared at the fixed friction_prep" in text
    assert "poro2d sand" in text


def test_a_relation_config_serves_the_criterion_too(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        "seed = 0\n[criterion]\nn_lab = 0.40\n[relation]\npoints = 3\nn_max = 0.4571\nn_min = 0.3253\n"
    )
    case = CriterionCase.from_config(cfg)
    assert case.mode == "paper" and case.config["relation"]["points"] == 3
