"""The loose-state study's criterion configs: built as density mode builds them (no DEM run)."""

import sys
from pathlib import Path

from poro2d.criterion.config import build
from poro2d.specimen.compaction import SpecimenSpec

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from loose_states import config  # noqa: E402


def test_the_paper_box_case_is_density_modes_fill_acceptance():
    spec, _, settings, seed = build(config(2.0, 0.0, 3, 0.222, keep=False, full=True))
    assert (spec.width, spec.height, spec.layers) == (0.305, 0.124, 4)
    assert spec.friction_prep == 2.0 and spec.rolling_friction_prep == 0.0 and spec.rolling_friction == 0.0
    assert settings.acceptance == "fill" and settings.trial_porosity == 0.222 and seed == 3
    # without --growth-steps the layers grow as every other run grows them
    assert spec.growth_steps == SpecimenSpec.growth_steps


def test_growth_steps_slow_the_layers_growth_and_nothing_else():
    gentle = config(2.0, 0.0, 0, 0.226, keep=False, full=True, growth_steps=600)
    plain = config(2.0, 0.0, 0, 0.226, keep=False, full=True)
    assert build(gentle)[0].growth_steps == 600
    assert {k: v for k, v in gentle["specimen"].items() if k != "growth_steps"} == plain["specimen"]
    assert gentle["criterion"] == plain["criterion"]
