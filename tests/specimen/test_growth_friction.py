"""The friction a layer grows at (``SpecimenSpec.growth_friction``, ``compaction.growth_friction``).

Radius growth with friction wedges a fine between two large disks closing on it: their nearly
opposite normals hold it, its overlaps grow past its own radius and it is shot out of the box.
The sandy gravel G1-1 (r_mean / r_min 13) lost a disk so in every calibration case of ``sand``
at mu_prep 0.2 to 1.0. ``growth_friction = 0`` keeps its disks in the box; unset, a layer grows
at its preparation friction, as every number so far was measured.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.grading import GradingCurve
from poro2d.specimen.compaction import SpecimenSpec, growth_friction, prepare_specimen

SOILS = Path(__file__).parents[2] / "examples" / "soils"


def _gravel() -> GradingCurve:
    return GradingCurve.from_config({"csv": "g1-1_sandy_gravel.csv", "upscale": 1}, base_dir=SOILS)


def test_unset_the_layers_grow_at_the_preparation_friction():
    spec = SpecimenSpec(friction_prep=0.5)
    assert growth_friction(spec) == 0.5
    assert growth_friction(replace(spec, growth_friction=0.0)) == 0.0
    with pytest.raises(InputError, match="growth_friction"):
        SpecimenSpec(growth_friction=-0.1)


def test_the_setting_is_recorded_only_when_set():
    assert "growth_friction" not in SpecimenSpec().to_dict()
    assert SpecimenSpec(growth_friction=0.0).to_dict()["growth_friction"] == 0.0


def _inside(sim, spec) -> bool:
    p = sim.particles
    x, y = p.pos[:, 0], p.pos[:, 1]
    return bool(np.all((x > 0.0) & (x < spec.width) & (y > 0.0)))


def test_a_frictionless_growth_keeps_the_gravels_disks_in_the_box():
    """G1-1 at mu_prep 0.5 in a 0.08 m x 0.04 m box, trial 0.155, seed 0: grown at mu 0.5 (the
    default) one fine is shot out of the box; grown frictionless none is, and no disk is left
    frictionless afterwards."""
    spec = SpecimenSpec(width=0.08, height=0.04, layers=1, friction_prep=0.5, max_steps_per_stage=20_000,
                        fallback_steps=5_000, calm_steps=2_000)  # fmt: skip
    wedged, _ = prepare_specimen(spec, _gravel(), 0.155, seed=0)
    assert not _inside(wedged, spec)
    free = replace(spec, growth_friction=0.0)
    sim, _ = prepare_specimen(free, _gravel(), 0.155, seed=0)
    assert _inside(sim, free)
    assert np.all(sim.particles.mu == free.friction_particle)
