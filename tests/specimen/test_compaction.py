"""Multilayer compaction: porosity after generation, force balance, bad configs."""

from dataclasses import replace

import numpy as np
import pytest

from poro2d.criterion.protocol import CriterionSettings, specimen_checks, wall_forces
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.specimen import GradingCurve, paper_grading
from poro2d.specimen.compaction import SpecimenSpec, check_feasible, prepare_specimen

SMALL = {"width": 0.06, "height": 0.03, "layers": 2}


@pytest.fixture(scope="module")
def loose():
    """A loose specimen: the lid carries almost nothing."""
    spec = SpecimenSpec(**SMALL)
    sim, rep = prepare_specimen(spec, paper_grading(), 0.22, seed=3)
    return spec, sim, rep


def test_box_porosity_equals_trial_after_generation(loose):
    spec, sim, rep = loose
    assert rep.converged
    assert rep.box_porosity == pytest.approx(0.22, abs=1e-12)
    # disks clipped exactly by the box: equal unless a disk pokes into a wall
    assert rep.measured_porosity == pytest.approx(0.22, abs=2e-3)
    assert sim.particles.area() == pytest.approx((1 - 0.22) * spec.width * spec.height, rel=1e-12)


def test_vertical_force_balance_with_side_friction(loose):
    spec, sim, rep = loose
    f = wall_forces(sim)
    weight = float(np.sum(sim.particles.mass)) * spec.gravity / spec.thickness
    assert weight == pytest.approx(spec.self_weight(0.22), rel=1e-12)
    lhs = f.f_bottom_n_per_m + f.side_friction_up_n_per_m
    assert lhs == pytest.approx(weight + f.f_top_n_per_m, rel=0.01)
    assert abs(f.side_friction_up_n_per_m) > 0.0  # frictional side walls take vertical load
    assert sim.unbalanced_ratios()[0] < spec.ratio


def test_frictionless_side_walls_put_the_weight_on_the_bottom():
    spec = SpecimenSpec(**SMALL, friction_wall=0.0)
    sim, rep = prepare_specimen(spec, paper_grading(), 0.22, seed=4)
    f = wall_forces(sim)
    assert abs(f.side_friction_up_n_per_m) < 1e-9
    assert f.f_bottom_n_per_m == pytest.approx(spec.self_weight(0.22) + f.f_top_n_per_m, rel=0.01)


def test_dense_trial_loads_the_top_plate():
    spec = SpecimenSpec(**SMALL)
    sim, rep = prepare_specimen(spec, paper_grading(), 0.14, seed=3)
    f = wall_forces(sim)
    assert f.f_top_n_per_m > 10 * spec.self_weight(0.14)
    # balance: bottom + side friction = weight + top, relative to the forces involved
    lhs = f.f_bottom_n_per_m + f.side_friction_up_n_per_m
    assert lhs == pytest.approx(spec.self_weight(0.14) + f.f_top_n_per_m, rel=1e-3)


def test_checks_hold_on_a_specimen_at_rest(loose):
    spec, sim, rep = loose
    checks, nums = specimen_checks(sim, spec, rep, 0.22, spec.height, wall_forces(sim), CriterionSettings())
    assert checks.to_dict() == dict.fromkeys(checks.to_dict(), True) and len(checks.to_dict()) == 5
    # the weight the balance uses, against rho_s g pi r^2 summed over the radii (per metre of thickness)
    weight = spec.solid_density * spec.gravity * np.pi * float(np.sum(sim.particles.radius**2))
    assert nums.weight_from_masses_n_per_m == pytest.approx(weight, rel=1e-12)
    assert nums.force_balance_error < 0.01
    assert nums.planned_particle_count == sim.particles.n and nums.disks_outside_box == 0
    assert nums.generation_porosity_error < 1e-3


def test_checks_catch_a_falling_or_broken_specimen(loose, tmp_path):
    spec, sim, rep = loose
    checkpoint.save(sim, tmp_path / "s.npz")
    falling = checkpoint.load(tmp_path / "s.npz", threads=1)
    falling.translate_wall("top", 0.0, 0.01)
    falling.particles.pos[:, 1] += 0.002  # off the bottom wall: the weight is not carried
    falling.particles_changed()
    falling.run(10)
    lifted = spec.height + 0.01
    checks, nums = specimen_checks(
        falling, spec, rep, 0.22, lifted, wall_forces(falling), CriterionSettings()
    )
    assert not checks.force_balance and nums.force_balance_error > 0.5
    assert checks.disks_inside_box and checks.all_disks_present
    # a disk missing from the plan, a specimen built for another porosity, a disk through the plate
    broken = replace(rep, planned_count=rep.particle_count + 3)
    checks, nums = specimen_checks(
        sim, spec, broken, 0.22 + 2e-3, 0.8 * spec.height, wall_forces(sim), CriterionSettings()
    )
    assert nums.porosity_after_generation == pytest.approx(0.22, abs=1e-12)  # whole disks, as drawn
    assert not checks.all_disks_present and not checks.porosity_after_generation
    assert not checks.disks_inside_box and nums.disks_outside_box > 0


def test_a_layer_short_of_steps_gets_the_fallback():
    # frictionless disks near their jamming density relax slowly: the second layer needs more
    # than the first budget, finishes in the second one, and the specimen is complete
    spec = SpecimenSpec(**SMALL, friction_prep=0.0, max_steps_per_stage=20_000)
    sim, rep = prepare_specimen(spec, paper_grading(), 0.20, seed=200_000)
    assert rep.converged and rep.failed_stage is None
    assert rep.particle_count == rep.planned_count == sim.particles.n
    first, second = rep.layers
    assert [a.attempt for a in first.attempts] == ["normal"]
    assert [a.attempt for a in second.attempts] == ["normal", "second budget"]
    assert second.attempts[0].max_ratio > 1e-3 > second.max_ratio
    assert second.converged and rep.final_stage.converged


def test_a_layer_that_fails_ends_the_preparation():
    spec = SpecimenSpec(**SMALL, max_steps_per_stage=200, fallback_steps=100, calm_steps=100)
    sim, rep = prepare_specimen(spec, paper_grading(), 0.20, seed=200_000)
    assert not rep.converged and rep.failed_stage == "layer 1" and rep.failed_max_ratio > 1e-3
    (only,) = rep.layers
    assert [a.attempt for a in only.attempts] == ["normal", "second budget", "calm", "normal again"]
    assert rep.particle_count == only.n_particles < rep.planned_count
    assert rep.final_stage is None  # the working friction is not applied to a broken specimen
    assert sim.local_damping == spec.local_damping  # the calm stage's damping is undone


def _deferred(sim) -> int:
    """Disks that wait for the second phase of a step (their pairs cross the partition cut)."""
    sim.run(1)
    return int(sim.work.dstart[-1])


def test_specimen_is_numbered_across_its_short_side(loose, tmp_path):
    # placed layer by layer in rows, renumbered after each layer in columns: the cut
    # between the two partitions runs across the height, not along the width
    _, sim, _ = loose
    checkpoint.save(sim, tmp_path / "s.npz")
    as_built = checkpoint.load(tmp_path / "s.npz", threads=1)
    in_rows = checkpoint.load(tmp_path / "s.npz", threads=1)
    p = in_rows.particles
    in_rows.reorder(np.lexsort((p.pos[:, 0], np.floor(p.pos[:, 1] / (4.0 * p.radius.max())))))
    assert _deferred(as_built) < 0.7 * _deferred(in_rows)


def test_layers_each_reach_equilibrium(loose):
    _, _, rep = loose
    assert [lay.layer for lay in rep.layers] == [1, 2]
    assert all(lay.converged and lay.max_ratio < 1e-3 for lay in rep.layers)
    assert sum(lay.n_particles for lay in rep.layers) == rep.particle_count


def test_undercompaction_band_tops():
    spec = SpecimenSpec(height=0.124, layers=4, undercompaction=0.15)
    tops = spec.layer_tops()
    h = 0.124 / 4
    assert tops[0] == pytest.approx(h * 1.15)
    assert tops[1] == pytest.approx(h * (1 + 1.10))
    assert tops[-1] == pytest.approx(0.124)
    assert np.all(np.diff(tops) > 0)
    np.testing.assert_allclose(SpecimenSpec(layers=4).layer_tops(), [0.031, 0.062, 0.093, 0.124])


def test_bad_configs_fail_before_simulating():
    g = paper_grading()
    with pytest.raises(InputError, match="box"):
        check_feasible(SpecimenSpec(width=0.005, height=0.124), g, 0.15)
    with pytest.raises(InputError, match="box"):
        check_feasible(SpecimenSpec(height=0.02, layers=4), g, 0.15)
    with pytest.raises(InputError, match="porosity"):
        check_feasible(SpecimenSpec(), g, 0.01)
    with pytest.raises(InputError, match="porosity"):
        check_feasible(SpecimenSpec(), g, 1.2)
    with pytest.raises(InputError, match="layers"):
        SpecimenSpec(layers=0)
    with pytest.raises(InputError, match="friction_prep"):
        SpecimenSpec(friction_prep=-1)
    with pytest.raises(InputError, match="fallback_steps"):
        SpecimenSpec(fallback_steps=0)
    with pytest.raises(InputError, match="calm_damping"):
        SpecimenSpec(calm_damping=1.0)
    big = GradingCurve.from_lists([40.0, 80.0], [0, 100])
    with pytest.raises(InputError, match="largest disk"):
        check_feasible(SpecimenSpec(), big, 0.15)


def test_the_specimen_row_keeps_the_run_identity():
    """The specimen's row binds stores and names cases: its digest is the one of earlier folders."""
    from poro2d.identity import identity_digest

    assert identity_digest(SpecimenSpec().to_dict()) == (
        "8b4c268a0eb4fc927eec732a9c31e4bbf427a8b286b1e18c59ed3beb98e50959"
    )
    changed = SpecimenSpec(equilibrium="mean", settle_drift=0.01, settle_window=5000, settle_checks=4,
                           rolling_friction=0.1)  # fmt: skip
    assert identity_digest(changed.to_dict()) == (
        "f385d7803ab25692d7becd84e32135ea94a9b8a4238cacc3718d46fefa6d8e30"
    )
    row, other = SpecimenSpec(max_disks=10**6).to_dict(), SpecimenSpec().to_dict()
    assert "max_disks" not in row and row["extra"] == {} and row["extra"] is not other["extra"]


def test_rolling_resistance_of_the_preparation_acts_while_layers_are_built_then_gives_way():
    from poro2d.specimen import paper_grading as grading

    spec = SpecimenSpec(width=0.05, height=0.025, layers=2, friction_prep=1.0, rolling_friction_prep=0.3)
    sim, rep = prepare_specimen(spec, grading(), 0.2, seed=0)
    assert rep.converged
    assert float(sim.particles.mu_r.max()) == 0.0  # the working material has none
    without = SpecimenSpec(width=0.05, height=0.025, layers=2, friction_prep=1.0)
    plain, _ = prepare_specimen(without, grading(), 0.2, seed=0)
    # the layers were built with it: the packing differs from one built without
    assert not np.array_equal(sim.particles.pos, plain.particles.pos)
    # recorded only when set, so the records (and digests) of every earlier specimen stay as they were
    assert spec.to_dict()["rolling_friction_prep"] == 0.3
    assert "rolling_friction_prep" not in SpecimenSpec().to_dict()
