"""Trials denser than the grading packs, refusals before any DEM work, and wide gradings.

A trial below the grading's jamming porosity is an over-full box: the layers' bands (and
the lid) rise above H instead of failing to place the last layer, and the criterion's plate
stage measures it as Fig. 3 does. What can never work is refused within seconds, naming the
parameter, its value and the allowed range. A wide grading's preparation uses the settled
test unless the config says otherwise; the paper's grading keeps its numbers.
"""

from dataclasses import replace

import numpy as np
import pytest

from poro2d.criterion.config import build
from poro2d.dem import ContactModel, Particles, Simulation
from poro2d.errors import InputError
from poro2d.grading import GradingCurve, paper_grading, preset_grading
from poro2d.specimen.compaction import (
    BAND_FRACTION_MAX,
    EQUILIBRIUM_STEPS,
    SpecimenSpec,
    check_feasible,
    estimate_size,
    is_wide,
    layer_band,
    make_walls,
    preparation_note,
    prepare_specimen,
    time_step,
)

# the gravel of the report (0.1-18.9 mm, fines to 0.75 mm after up-scaling 1.5): the old
# preparation raised "radii = 'solid fraction 1.0480' is invalid" in layer 2 after 14 s
GRAVEL = {"sizes": [0.1, 0.5, 1, 2, 4.75, 9.5, 18.9], "percent": [0, 10, 15, 22, 38, 60, 100]}


def _gravel() -> GradingCurve:
    return GradingCurve.from_lists(GRAVEL["sizes"], GRAVEL["percent"], upscale=1.5, d_min_mm=0.75)


def _sim_with(spec: SpecimenSpec, pos, radii, lid: float) -> Simulation:
    p = Particles(np.asarray(pos, float), np.asarray(radii, float), spec.solid_density, spec.thickness,
                  spec.kn_particle, spec.ks_particle, spec.friction_prep)  # fmt: skip
    return Simulation(p, make_walls(spec, lid), ContactModel("per_body"), gravity=(0.0, -9.81))


def test_an_ordinary_band_is_the_planned_one():
    spec = SpecimenSpec(width=0.1, height=0.04, layers=2)
    tops = spec.layer_tops()
    r = np.full(50, 0.002)  # 50 disks of 2 mm radius: solid fraction 0.31 in a 0.1 x 0.02 band
    assert layer_band(None, spec, 0, r, tops) == (0.0, 0.02, 0.0)


def test_a_band_too_full_for_its_disks_rises_above_h():
    spec = SpecimenSpec(width=0.1, height=0.04, layers=2)
    tops = spec.layer_tops()
    # the first layer sprang up to 0.035 (a disk on top, inside the box), the second layer
    # holds 0.0016 m^2 of disks: the 0.005 m left below H cannot take them
    sim = _sim_with(spec, [[0.05, 0.03]], [0.005], lid=0.036)
    r = np.full(100, np.sqrt(0.0016 / (100 * np.pi)))
    y_bot, y_top, raised = layer_band(sim, spec, 1, r, tops)
    assert y_bot == pytest.approx(0.035)
    assert np.sum(np.pi * r * r) / (spec.width * (y_top - y_bot)) == pytest.approx(BAND_FRACTION_MAX)
    assert y_top > spec.height and raised == pytest.approx(y_top - spec.height)


def test_a_disk_squeezed_out_of_the_box_does_not_set_the_band():
    spec = SpecimenSpec(width=0.1, height=0.04, layers=2)
    sim = _sim_with(spec, [[0.05, 0.01], [0.02, 0.01]], [0.002, 0.001], lid=0.02)
    sim.particles.pos[1] = (-0.01, 1.1)  # squeezed out through a side wall, flying up
    y_bot, y_top, raised = layer_band(sim, spec, 1, np.full(10, 0.002), spec.layer_tops())
    assert (y_bot, y_top, raised) == (0.02, 0.04, 0.0)


def test_the_side_walls_reach_above_a_raised_lid():
    spec = SpecimenSpec(width=0.1, height=0.04, layers=2)
    sim = _sim_with(spec, [[0.05, 0.01]], [0.002], lid=0.02)
    sim.extend_wall_up("left", 0.5)
    sim.extend_wall_up("right", 0.5)
    w = sim.walls
    for side in ("left", "right"):
        i = w.index(side)
        assert max(w.p0[i, 1], w.p1[i, 1]) == pytest.approx(0.5)
    with pytest.raises(InputError, match="vertical"):
        sim.extend_wall_up("top", 1.0)


# ------------------------------------------------------------------ refusals before DEM work
def test_a_trial_far_below_the_densest_packing_is_refused_at_once():
    spec = SpecimenSpec(width=0.08, height=0.04, layers=2)
    with pytest.raises(InputError, match=r"trial porosity = 0\.055.*jamming porosity n_J = 0\.1") as e:
        check_feasible(spec, preset_grading("wide_cu4"), 0.055)
    assert "trial_porosity" in str(e.value) and "mm above H" in str(e.value)
    check_feasible(spec, preset_grading("wide_cu4"), 0.07)  # over-full, within the margin: it runs


def test_the_papers_first_trial_needs_no_jamming_estimate(monkeypatch):
    import poro2d.specimen.compaction as c

    def boom(_):
        raise AssertionError("no jamming estimate at 0.14")

    monkeypatch.setattr(c, "densest_porosity", boom)
    check_feasible(SpecimenSpec(), paper_grading(), 0.14)


def test_the_estimate_takes_the_time_step_of_the_smallest_disk():
    paper = estimate_size(SpecimenSpec(), paper_grading(), 0.15)
    assert paper.stage_steps == EQUILIBRIUM_STEPS  # the paper's numbers as before
    assert paper.steps == 4 * (40 * 150 + EQUILIBRIUM_STEPS) + EQUILIBRIUM_STEPS
    wide = estimate_size(SpecimenSpec(), preset_grading("wide_cu4"), 0.15)
    assert wide.dt_s == pytest.approx(time_step(SpecimenSpec(), 0.00063))
    assert wide.stage_steps == pytest.approx(EQUILIBRIUM_STEPS * 0.002 / 0.00063, rel=1e-3)


def test_a_time_step_too_small_for_the_step_budget_is_refused():
    fines = GradingCurve.from_lists([0.01, 0.02, 2.0, 4.0], [0, 0.0001, 1, 100])
    # with the true masses (mass_scaling "off"); "auto" raises the fines' inertial masses to one
    # shared step (docs/density-scaling.md), and then the same box fits the budget
    spec = SpecimenSpec(width=0.08, height=0.04, layers=2, max_steps_per_stage=100_000, mass_scaling="off")
    with pytest.raises(InputError, match=r"time step = .*smallest disk.*d_min_mm") as e:
        check_feasible(spec, fines, 0.2)
    assert "allowed: a step at which a stage comes to rest" in str(e.value)
    check_feasible(replace(spec, mass_scaling="auto"), fines, 0.2)


def test_a_preparation_of_more_than_six_hours_is_refused():
    fines = GradingCurve.from_lists([0.05, 0.1, 2.0], [0, 10, 100])  # about 0.7 million disks
    spec = SpecimenSpec(layers=8, max_steps_per_stage=10**8)
    with pytest.raises(InputError, match=r"specimen size = .*preparation estimated below 6\.0 h.*d_min_mm"):
        check_feasible(spec, fines, 0.2)


# ------------------------------------------------------------------ wide gradings
def test_wide_gradings_settle_unless_the_config_says_otherwise():
    paper_grade = paper_grading()
    assert not is_wide(paper_grade) and preparation_note(SpecimenSpec(), paper_grade) is None
    assert is_wide(preset_grading("wide_cu4"))
    spec, _, _, _ = build({"grading": {"preset": "wide_cu4"}})
    assert (spec.settle_drift, spec.equilibrium) == (1e-3, "loaded_max")
    assert "layers end once settled" in preparation_note(spec, preset_grading("wide_cu4"))
    kept, _, _, _ = build({"grading": {"preset": "wide_cu4"}, "specimen": {"equilibrium": "max"}})
    assert (kept.settle_drift, kept.equilibrium) == (None, "max")
    assert "the paper's maximum-ratio test" in preparation_note(kept, preset_grading("wide_cu4"))
    paper, _, _, _ = build({"grading": {"preset": "paper"}})
    assert paper == SpecimenSpec()  # the paper's grading: nothing changes
    assert SpecimenSpec().to_dict() == paper.to_dict()


@pytest.mark.slow
def test_an_overfull_gravel_specimen_is_built_above_h_not_refused_mid_run():
    """The report's crash: layer 2 of the gravel at Eq. 12's 0.08 found no room below H."""
    spec = SpecimenSpec(max_steps_per_stage=20_000, fallback_steps=1_000, calm_steps=1_000)
    sim, rep = prepare_specimen(spec, _gravel(), 0.08, seed=80_000)
    assert rep.particle_count <= rep.planned_count
    raised = [layer for layer in rep.layers if "band_raised_m" in layer.to_dict()]
    assert raised, "a band rose above its planned top"
    if rep.converged:
        assert rep.overfull_m > 0.0
        assert rep.top_height_m == pytest.approx(float(sim.walls.p0[sim.walls.index("top"), 1]))


@pytest.mark.slow
def test_an_overfull_first_trial_ends_in_a_looser_accepted_trial(tmp_path):
    """Trial 0.07 of the wide grading (n_J about 0.11) in a small box: the specimen stands above
    H, the plate moves up, the next trial is looser and is accepted (measured: 0.07 -> n' 0.197,
    0.20 -> 0.194, 0.19 accepted; 40 s). The old preparation had no over-full box."""
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.store import Store

    cfg = {
        "grading": {"preset": "wide_cu4"},
        "specimen": {"width": 0.08, "height": 0.04, "layers": 2},
        "criterion": {"trial_porosity": 0.07, "force_fraction": 0.05, "max_iterations": 4},
    }
    spec, grading, settings, seed = build(cfg)
    res = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(tmp_path / "c")).run()
    first = res.iterations[0].to_dict()  # the trial's row
    assert first["overfull_m"] > 0.0 and first["plate_moved"] == "up"
    assert "over-full box" in first["reason"] and not first["refused"]
    assert first["new_porosity"] > 0.07 and first["checks"]["disks_inside_box"]
    assert res.iterations[1].trial_porosity > 0.07
    assert res.converged and res.final_porosity > 0.07
    assert "layers end once settled" in res.preparation_note
    assert res.to_dict()["preparation_note"] == res.preparation_note


@pytest.mark.slow
def test_an_overfull_first_trial_under_the_lid_leads_to_a_looser_trial(tmp_path):
    """The fill acceptance on the same over-full trial: the plate takes the specimen into the
    window, the lid rests on it, n' is measured under the lid and the next trial is looser
    (measured: 0.07 -> n' 0.178, then 0.18; 10 s for the first trial)."""
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.store import Store

    cfg = {
        "grading": {"preset": "wide_cu4"},
        "specimen": {"width": 0.08, "height": 0.04, "layers": 2},
        "criterion": {
            "trial_porosity": 0.07,
            "force_fraction": 0.05,
            "acceptance": "fill",
            "max_iterations": 2,
        },  # fmt: skip
    }
    spec, grading, settings, seed = build(cfg)
    res = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(tmp_path / "c")).run()
    first = res.iterations[0].to_dict()  # the trial's row
    assert first["overfull_m"] > 0.0 and first["plate_moved"] == "lid"
    assert not first["refused"] and first["checks"]["disks_inside_box"] and first["disks_outside_box"] == 0
    assert first["new_porosity"] > 0.07
    # the stage's steps are every step between the prepared specimen and the one after the top
    # stage: the plate's rise and the lid's rest together
    from poro2d.dem import checkpoint

    trial = tmp_path / "c" / "trials" / "01_n0.0700"
    stage = (
        checkpoint.load(trial / "after_plate.npz").step_count
        - checkpoint.load(trial / "prepared.npz").step_count
    )
    assert first["plate_steps"] == stage
    assert len(res.iterations) == 2 and res.iterations[1].trial_porosity > 0.07
    assert not res.iterations[1].decision.refused
