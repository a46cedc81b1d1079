"""Where a specimen's disks get raised inertial masses (``SpecimenSpec.mass_scaling``).

"auto" must leave the paper's grading and every narrow grading with their true masses (their
numbers bit for bit), and raise the sandy gravel G1-1's fines; the pre-flight must then
estimate with the shared step.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from poro2d.errors import InputError
from poro2d.grading import GradingCurve, draw_disks, preset_grading
from poro2d.specimen.compaction import (
    MASS_SCALING_TRIGGER,
    SpecimenSpec,
    grading_mass_scaling_step,
    mass_scaling_step,
    time_step,
)

SOILS = Path(__file__).parents[2] / "examples" / "soils"


def _soil(name: str, upscale: float) -> GradingCurve:
    return GradingCurve.from_config({"csv": f"{name}.csv", "upscale": upscale}, base_dir=SOILS)


NARROW = {
    "paper": lambda: preset_grading("paper"),
    "wide_cu4": lambda: preset_grading("wide_cu4"),
    "wide_cu6": lambda: preset_grading("wide_cu6"),
    "toyoura": lambda: _soil("toyoura_sand", 10),
    "cb-mix-2": lambda: _soil("cb-mix-2_sand", 4),
}


@pytest.mark.parametrize("name", list(NARROW))
def test_auto_keeps_the_true_masses_of_the_paper_and_narrower_gradings(name):
    spec = SpecimenSpec()
    radii = draw_disks(NARROW[name](), spec.width * spec.height * 0.85, 0)
    assert radii.mean() / radii.min() < MASS_SCALING_TRIGGER
    assert mass_scaling_step(spec, radii) is None


def test_auto_raises_the_gravel_fines_to_the_step_of_a_disk_half_the_mean_one():
    spec = SpecimenSpec()
    radii = draw_disks(_soil("g1-1_sandy_gravel", 1), spec.width * spec.height * 0.9, 0)
    dt = mass_scaling_step(spec, radii)
    assert dt == pytest.approx(time_step(spec, radii.mean()), rel=1e-12)  # a disk of radius r_mean / 2
    # the finest disk (0.1 mm) would step at a sixth of it
    assert 5.0 < dt / time_step(spec, 2.0 * radii.min()) < 8.0
    assert mass_scaling_step(replace(spec, mass_scaling="off"), radii) is None


def test_on_scales_below_the_trigger_and_not_when_no_disk_is_below_the_floor():
    spec = SpecimenSpec(mass_scaling="on")
    radii = draw_disks(preset_grading("paper"), spec.width * spec.height * 0.85, 0)
    assert mass_scaling_step(spec, radii) is None  # r_mean / 2 is below the finest paper disk
    spec = replace(spec, mass_scaling_ratio=1.0)
    assert mass_scaling_step(spec, radii) == pytest.approx(time_step(spec, 2.0 * radii.mean()))


def test_the_settings_are_checked_and_kept_in_the_spec_only_when_set():
    assert "mass_scaling" not in SpecimenSpec().to_dict()
    row = SpecimenSpec(mass_scaling="off").to_dict()
    assert row["mass_scaling"] == "off" and SpecimenSpec.from_dict(row).mass_scaling == "off"
    with pytest.raises(InputError, match="mass_scaling"):
        SpecimenSpec(mass_scaling="yes")
    with pytest.raises(InputError, match="mass_scaling_ratio"):
        SpecimenSpec(mass_scaling_ratio=0.5)


def test_a_gravel_specimen_is_built_with_the_shared_step():
    from poro2d.specimen.compaction import prepare_specimen

    spec = SpecimenSpec(width=0.02, height=0.01, layers=1, max_steps_per_stage=30_000, fallback_steps=500,
                        calm_steps=500, growth_increments=2, growth_steps=50)  # fmt: skip
    grading = GradingCurve.from_config(
        {"csv": "g1-1_sandy_gravel.csv", "upscale": 1, "d_max_mm": 2.0}, base_dir=SOILS
    )
    sim, _ = prepare_specimen(spec, grading, 0.2, 0)
    r = sim.particles.radius
    assert sim.mass_scaling_dt is not None and sim.mass_scaling.disks > 0
    assert sim.dt == pytest.approx(sim.mass_scaling_dt, rel=1e-9)
    # every disk lighter than the floor shares its inertial mass; the weight is the true one
    floor = 1.0 / sim.masses.inv_mass.max()
    light = sim.particles.mass < floor
    assert np.allclose(1.0 / sim.masses.inv_mass[light], floor, rtol=1e-12)
    assert np.array_equal(sim.masses.mass, sim.particles.mass) and r.mean() > 4.0 * r.min()


def test_the_preflight_estimates_gravel_with_the_shared_step_and_sand_with_its_own():
    spec = SpecimenSpec()
    gravel = _soil("g1-1_sandy_gravel", 1)
    assert grading_mass_scaling_step(spec, gravel, 0.11) > 5.0 * time_step(spec, gravel.d_min_m)
    assert grading_mass_scaling_step(spec, _soil("toyoura_sand", 10), 0.15) is None
