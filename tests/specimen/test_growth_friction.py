"""The friction a layer grows at (``SpecimenSpec.growth_friction``, ``compaction.growth_friction``)
and its fines' (``SpecimenSpec.frictionless_fines``, ``compaction.growing_fines``).

Radius growth with friction wedges a fine between two large disks closing on it: their nearly
opposite normals hold it, its overlaps grow past its own radius and it is shot out of the box.
The sandy gravel G1-1 (r_mean / r_min 13) lost a disk so in every calibration case of ``sand``
at mu_prep 0.2 to 1.0. Its fines growing frictionless (the default for so wide a grading) keep
every disk in the box, as does ``growth_friction = 0``; a narrower grading grows at its
preparation friction, as every number of it was measured. A very wide grading's layers grow in
increments no larger than half its finest radius (``growth_increments``): a larger jump shot a
frictionless fine out of G1-1's box at mu_prep 0.297.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.grading import GradingCurve
from poro2d.specimen import compaction as C
from poro2d.specimen.compaction import (
    SpecimenSpec,
    growing_fines,
    growth_friction,
    growth_increments,
    prepare_specimen,
    slides_while_growing,
)

SOILS = Path(__file__).parents[2] / "examples" / "soils"


def _gravel() -> GradingCurve:
    return GradingCurve.from_config({"csv": "g1-1_sandy_gravel.csv", "upscale": 1}, base_dir=SOILS)


def test_unset_the_layers_grow_at_the_preparation_friction():
    spec = SpecimenSpec(friction_prep=0.5)
    assert growth_friction(spec) == 0.5
    assert growth_friction(replace(spec, growth_friction=0.0)) == 0.0
    with pytest.raises(InputError, match="growth_friction"):
        SpecimenSpec(growth_friction=-0.1)


def test_the_settings_are_recorded_only_when_set():
    assert "growth_friction" not in SpecimenSpec().to_dict()
    assert SpecimenSpec(growth_friction=0.0).to_dict()["growth_friction"] == 0.0
    assert "frictionless_fines" not in SpecimenSpec().to_dict()
    assert SpecimenSpec(frictionless_fines="off").to_dict()["frictionless_fines"] == "off"
    with pytest.raises(InputError, match="frictionless_fines"):
        SpecimenSpec(frictionless_fines="yes")


def test_the_fines_of_a_very_wide_grading_only_grow_frictionless():
    """Below r_mean / 2; only where r_mean / r_min is above 4 (mass scaling's trigger) under
    "auto"; "on" always, "off" never. The walls slide with them."""
    wide = np.array([0.1, 0.2, 0.5, 1.0, 2.0, 3.0])  # r_mean 1.13, r_min 0.1: 11 times finer
    narrow = np.array([0.3, 0.5, 1.0, 1.2])  # r_mean 0.75: 2.5 times the finest
    spec = SpecimenSpec()
    assert growing_fines(spec, wide, wide).tolist() == [True, True, True, False, False, False]
    assert growing_fines(spec, wide, wide[3:]).tolist() == [False, False, False]
    assert slides_while_growing(spec, wide) and not slides_while_growing(spec, narrow)
    assert not growing_fines(spec, narrow, narrow).any()
    on, off = replace(spec, frictionless_fines="on"), replace(spec, frictionless_fines="off")
    assert growing_fines(on, narrow, narrow).tolist() == [True, False, False, False]
    assert slides_while_growing(on, narrow)
    assert not growing_fines(off, wide, wide).any() and not slides_while_growing(off, wide)


def _inside(sim, spec) -> bool:
    p = sim.particles
    x, y = p.pos[:, 0], p.pos[:, 1]
    return bool(np.all((x > 0.0) & (x < spec.width) & (y > 0.0)))


def _coarse_steps(monkeypatch) -> None:
    """The growth as it was before ``GROWTH_SHARE_OF_FINEST``: always ``spec.growth_increments``."""
    monkeypatch.setattr(C, "GROWTH_SHARE_OF_FINEST", 1e9)


def test_frictionless_fines_keep_the_gravels_disks_in_the_box(monkeypatch):
    """G1-1 at mu_prep 0.5 in a 0.08 m x 0.04 m box, trial 0.155, seed 0, grown in the spec's 40
    increments: every disk grown at mu 0.5 (``frictionless_fines = "off"``) one fine is shot out
    of the box; the fines grown frictionless (the default) or every disk none is, and no disk or
    wall is left frictionless."""
    _coarse_steps(monkeypatch)
    spec = SpecimenSpec(width=0.08, height=0.04, layers=1, friction_prep=0.5, max_steps_per_stage=20_000,
                        fallback_steps=5_000, calm_steps=2_000)  # fmt: skip
    wedged, _ = prepare_specimen(replace(spec, frictionless_fines="off"), _gravel(), 0.155, seed=0)
    assert not _inside(wedged, spec)
    for free in (spec, replace(spec, frictionless_fines="off", growth_friction=0.0)):
        sim, _ = prepare_specimen(free, _gravel(), 0.155, seed=0)
        assert _inside(sim, free)
        assert np.all(sim.particles.mu == free.friction_particle)
        assert np.all(sim.walls.mu == free.friction_wall)


def test_a_layer_grows_in_steps_smaller_than_its_finest_disk():
    """One increment enlarges the largest growing disk by at most half the finest radius; never
    fewer than the spec's increments, so a grading not wide (d_max / d_min at most 20) keeps them
    at any placement scale, the paper's among them."""
    spec = SpecimenSpec()
    for scale in (0.01, 0.5, 0.68, 0.99):
        assert growth_increments(spec, scale, 20.0, 1.0) == 40
    # G1-1's layer 2 (seed 1, trial 0.131): 9.401 mm disks from 0.6730, fines of 0.0501 mm
    m = growth_increments(spec, 0.6730, 9.401e-3, 0.0501e-3)
    assert m == 123
    assert (1.0 - 0.6730) * 9.401e-3 / m <= C.GROWTH_SHARE_OF_FINEST * 0.0501e-3
    assert (1.0 - 0.6730) * 9.401e-3 / (m - 1) > C.GROWTH_SHARE_OF_FINEST * 0.0501e-3
    assert growth_increments(replace(spec, growth_increments=200), 0.6730, 9.401e-3, 0.0501e-3) == 200


def test_finer_growth_keeps_a_fine_in_the_box_and_is_recorded(monkeypatch):
    """G1-1 at mu_prep 0.297 (the state Dr 0.5 takes) in a 0.08 m x 0.04 m box, trial 0.131,
    seed 1, fines frictionless (the default): grown in the spec's 40 increments a fine is shot
    out of the box; in increments of half the finest radius every disk stays in. The layer's
    report records the increments and its steps count them."""
    spec = SpecimenSpec(width=0.08, height=0.04, layers=1, friction_prep=0.297, max_steps_per_stage=20_000,
                        fallback_steps=5_000, calm_steps=2_000)  # fmt: skip
    sim, rep = prepare_specimen(spec, _gravel(), 0.131, seed=1)
    assert _inside(sim, spec)
    layer = rep.layers[0]
    assert layer.growth_increments > spec.growth_increments
    assert layer.steps >= layer.growth_increments * spec.growth_steps
    assert "growth_increments" in layer.to_dict()
    _coarse_steps(monkeypatch)
    shot, coarse = prepare_specimen(spec, _gravel(), 0.131, seed=1)
    assert not _inside(shot, spec)
    assert coarse.layers[0].growth_increments is None
    assert "growth_increments" not in coarse.layers[0].to_dict()
