"""The friction a layer grows at (``SpecimenSpec.growth_friction``, ``compaction.growth_friction``).

Radius growth with friction wedges a fine between two large disks closing on it: their nearly
opposite normals hold it, its overlaps grow past its own radius and it is shot out of the box.
The sandy gravel G1-1 (r_mean / r_min 13) lost a disk so in every calibration case at mu_prep
0.2 to 1.0. Unset, ``growth_friction`` grows such gradings frictionless (their settling keeps
the preparation friction) and every narrower grading at its preparation friction, as before.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.grading import GradingCurve, draw_disks, preset_grading
from poro2d.specimen.compaction import (
    FRICTIONLESS_GROWTH_TRIGGER,
    SpecimenSpec,
    growth_friction,
    prepare_specimen,
)

SOILS = Path(__file__).parents[2] / "examples" / "soils"


def _soil(name: str, upscale: float) -> GradingCurve:
    return GradingCurve.from_config({"csv": f"{name}.csv", "upscale": upscale}, base_dir=SOILS)


@pytest.mark.parametrize(
    "grading",
    [lambda: preset_grading("paper"), lambda: preset_grading("wide_cu4"), lambda: _soil("toyoura_sand", 10),
     lambda: _soil("cb-mix-2_sand", 4)],
    ids=["paper", "wide_cu4", "toyoura", "cb-mix-2"],
)  # fmt: skip
def test_narrower_gradings_grow_at_their_preparation_friction(grading):
    spec = SpecimenSpec(friction_prep=0.5)
    radii = draw_disks(grading(), spec.width * spec.height * 0.85, 0)
    assert radii.mean() / radii.min() < FRICTIONLESS_GROWTH_TRIGGER
    assert growth_friction(spec, radii) == 0.5


def test_the_gravel_grows_frictionless_unless_the_config_says_otherwise():
    spec = SpecimenSpec(friction_prep=0.5)
    radii = draw_disks(_soil("g1-1_sandy_gravel", 1), spec.width * spec.height * 0.9, 0)
    assert growth_friction(spec, radii) == 0.0
    assert growth_friction(replace(spec, growth_friction=0.3), radii) == 0.3
    with pytest.raises(InputError, match="growth_friction"):
        SpecimenSpec(growth_friction=-0.1)


def test_the_setting_is_recorded_only_when_set():
    assert "growth_friction" not in SpecimenSpec().to_dict()
    assert SpecimenSpec(growth_friction=0.2).to_dict()["growth_friction"] == 0.2


def _inside(sim, spec) -> bool:
    p = sim.particles
    x, y = p.pos[:, 0], p.pos[:, 1]
    return bool(np.all((x > 0.0) & (x < spec.width) & (y > 0.0)))


def test_a_frictional_gravel_layer_keeps_its_disks_in_the_box():
    """G1-1 at mu_prep 0.5 in a 0.08 m x 0.04 m box, trial 0.155, seed 0: grown at mu 0.5 one
    fine was shot out of the box (measured, the code before); grown frictionless none is."""
    spec = SpecimenSpec(width=0.08, height=0.04, layers=1, friction_prep=0.5, max_steps_per_stage=20_000,
                        fallback_steps=5_000, calm_steps=2_000)  # fmt: skip
    gravel = _soil("g1-1_sandy_gravel", 1)
    sim, _rep = prepare_specimen(spec, gravel, 0.155, seed=0)
    assert _inside(sim, spec)
    assert np.all(sim.particles.mu == spec.friction_particle)  # no disk left frictionless
    wedged, _ = prepare_specimen(replace(spec, growth_friction=0.5), gravel, 0.155, seed=0)
    assert not _inside(wedged, spec)
