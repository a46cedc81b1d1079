"""``poro2d sand``: a user's soil from its laboratory description to the density-aware answer."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from poro2d.criterion.density import Calibration
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.grading import paper_grading
from poro2d.report.grading_figure import draw_grading
from poro2d.sand import load_sand_case
from poro2d.sand import preflight as PF
from poro2d.sand.run import bracket, full_box_trial, predicted_mu
from poro2d.specimen.compaction import SpecimenSpec, estimate_size

QUIET = RunOptions(progress=False)

LAB = {"e_max": 0.977, "e_min": 0.597, "dr": 0.5}


def _config(**tables) -> dict:
    cfg = {"soil": {"name": "test sand"}, "grading": {"preset": "paper"}, "lab": dict(LAB)}
    cfg.update(tables)
    return cfg


def test_case_reads_the_laboratory_state_and_fills_density_defaults():
    case = load_sand_case(_config())
    assert case.lab.relative_density == pytest.approx(0.5)
    # e = 0.977 - 0.5 (0.977 - 0.597) = 0.787, n = e / (1 + e)
    assert case.lab.n_lab == pytest.approx(0.787 / 1.787)
    assert case.config.table("criterion")["n_lab"] == pytest.approx(0.787 / 1.787, abs=1e-6)
    assert case.config.table("criterion")["acceptance"] == "fill"  # density mode's defaults
    assert case.seeds == 3 and case.mus[0] == 0.0 and case.mus[-1] == 1.0
    assert case.calibration_seeds == 2
    assert load_sand_case(_config(sand={"calibration_seeds": 3})).calibration_seeds == 3


def test_calibration_cases_run_the_loosest_first():
    """The most frictional cases take longest: the workers start them first."""
    from poro2d.sweep.density import CalibrationCase

    case = load_sand_case(_config())
    calibration = CalibrationCase(case.config, (0.0, 0.1, 1.0), 2)
    listed = [c.params for c in calibration.sweep.cases]
    first = [c.params for c in replace(calibration, loosest_first=True).sweep.cases]
    assert [c["specimen.friction_prep"] for c in listed] == [0.0, 0.0, 0.1, 0.1, 1.0, 1.0]
    assert [c["specimen.friction_prep"] for c in first] == [1.0, 1.0, 0.1, 0.1, 0.0, 0.0]
    key = lambda c: (c["specimen.friction_prep"], c["seed"])  # noqa: E731
    assert sorted(first, key=key) == sorted(listed, key=key)  # the same cases, first trials included


@pytest.mark.parametrize(
    "cfg, parameter",
    [
        ({"lab": None}, "lab"),
        ({"lab": {"e": 0.7}}, "lab.e_max/e_min"),
        ({"density": {"n_max": 0.45}}, "config.density"),
        ({"sand": {"seeds": 0}}, "sand.seeds"),
        ({"sand": {"speed": 2}}, "sand.speed"),
        ({"sand": {"calibration_disks": 10}}, "sand.calibration_disks"),
        ({"sand": {"calibration_seeds": 0}}, "sand.calibration_seeds"),
        ({"soil": {"name": 3}}, "soil.name"),
        ({"criterion": {"n_lab": 0.30}}, "criterion.n_lab"),
    ],
)
def test_case_refuses_bad_input_naming_it(cfg, parameter):
    base = _config()
    for k, v in cfg.items():
        if v is None:
            base.pop(k)
        else:
            base[k] = v
    with pytest.raises(InputError) as e:
        load_sand_case(base)
    assert e.value.parameter == parameter


def test_time_step_is_the_engines():
    """The pre-flight's step (compaction.time_step) is the one the engine picks for the same smallest disk."""
    from poro2d.dem import Simulation
    from poro2d.dem.model import ContactModel
    from poro2d.specimen.compaction import _band_particles, make_walls

    spec = SpecimenSpec(width=0.05, height=0.03, layers=1)
    r = np.array([0.0005, 0.002])
    sim = Simulation(_band_particles(spec, np.array([[0.01, 0.01], [0.03, 0.01]]), r), make_walls(spec, 0.03),
                     ContactModel("per_body"), gravity=(0.0, -9.81), dt_safety=spec.dt_safety)  # fmt: skip
    assert PF.time_step(spec, 0.001) == pytest.approx(sim.dt, rel=1e-12)


def test_calibration_box_holds_about_the_disks_asked_for():
    spec, g = SpecimenSpec(), paper_grading()
    box = PF.calibration_box(spec, g, 800, 0.17)
    assert box.disks == pytest.approx(800, rel=0.1)
    assert box.width / box.height == pytest.approx(spec.width / spec.height, rel=0.05)
    assert box.band_height >= 3 * g.d_max_m
    full = PF.calibration_box(spec, g, 100_000, 0.17)  # more than the full box holds: the full box
    assert (full.width, full.height, full.layers) == (spec.width, spec.height, spec.layers)
    assert full.disks == pytest.approx(estimate_size(spec, g, 0.17).disks)


def _calibration(means: dict[float, float]) -> Calibration:
    mus = sorted(means)
    return Calibration(mus, [[means[m] + d for d in (-0.001, 0.0, 0.001)] for m in mus], [0, 1, 2])


def test_predicted_friction_and_its_bracket():
    ends = _calibration({0.0: 0.16, 1.0: 0.22})
    assert predicted_mu(ends, 0.16) == 0.0 and predicted_mu(ends, 0.22) == 1.0
    mid = predicted_mu(ends, 0.19)
    # the rise is steep at low friction: half the range is reached well below mu = 0.5
    assert 0.05 < mid < 0.5
    assert bracket((0.0, 0.05, 0.1, 0.2, 0.5, 1.0), 0.15) == [0.0, 0.1, 0.2, 1.0]
    assert bracket((0.0, 0.05, 0.1, 0.2, 0.5, 1.0), 1.0) == [0.0, 1.0]
    assert bracket((0.0, 1.0), 0.3) == [0.0, 1.0]


def test_full_box_trial_removes_the_walls_extra_share():
    small = PF.BoxPlan(0.1, 0.04, 2, 1000)
    big = PF.BoxPlan(0.305, 0.124, 4, 10000)
    pf = type("P", (), {"calibration_box": small, "box": big})()
    # dense end 0.170 in the small box against a jamming porosity of 0.155: 0.015 from the walls,
    # of which the larger box keeps its perimeter-over-area share
    got = full_box_trial(0.19, 0.155, 0.170, pf)
    ratio = (2 * 0.305 + 2 * 0.124) / (0.305 * 0.124) / ((2 * 0.1 + 2 * 0.04) / (0.1 * 0.04))
    assert got == pytest.approx(0.19 - 0.015 * (1 - ratio))
    assert full_box_trial(0.19, None, 0.170, pf) == 0.19
    pf_same = type("P", (), {"calibration_box": big, "box": big})()
    assert full_box_trial(0.19, 0.155, 0.170, pf_same) == pytest.approx(0.19)


def test_first_trials_follow_the_gradings_jamming_porosity():
    from poro2d.sweep.density import FILL_FIRST_TRIALS, PAPER_JAMMING_POROSITY, first_trial

    crit = {"acceptance": "fill", "refine_tolerance": 0.002}
    assert first_trial(crit, 0.0) == pytest.approx(FILL_FIRST_TRIALS[0][1])  # the paper grading's, unchanged
    wide = first_trial(crit, 0.0, dense_end=0.12)
    assert wide == pytest.approx(FILL_FIRST_TRIALS[0][1] + 0.12 - PAPER_JAMMING_POROSITY, abs=0.0011)
    assert first_trial({"acceptance": "plate"}, 0.0, dense_end=0.12) == 0.19  # the plate's one start


def test_jamming_cache_is_read_back_and_a_damaged_entry_recomputed(tmp_path, monkeypatch):
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path))
    monkeypatch.setattr(PF, "JAMMING_DISKS", 200)
    g = paper_grading()
    first = PF.jamming_of(g, seeds=1)
    assert first.porosity is not None and 0.1 < first.porosity < 0.2
    (entry,) = (tmp_path / "jamming").glob("[!.]*.json")  # not the store's manifest
    assert PF.jamming_of(g, seeds=1).to_dict() == first.to_dict()  # read back
    data = json.loads(entry.read_text())
    entry.write_text(json.dumps(dict(data, porosity=5.0)))
    again = PF.jamming_of(g, seeds=1)  # a damaged entry is computed again: the same numbers
    assert (again.porosity, again.sd, again.disks) == (first.porosity, first.sd, first.disks)


def test_preflight_reports_before_any_dem_work(tmp_path, monkeypatch):
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path))
    monkeypatch.setattr(PF, "JAMMING_DISKS", 200)
    case = load_sand_case(_config())
    pf = PF.preflight(case, workers=2, budget_minutes=1.0)
    assert pf.box.disks == pytest.approx(2560, rel=0.05)  # the paper's box at the first trial
    assert pf.first_trial < pf.eq12_trial
    assert pf.seconds.total > 60.0 and "exceeds the budget" in pf.suggestion
    assert math.isclose(pf.band_over_d_max, 0.031 / paper_grading().d_max_m, rel_tol=1e-9)


# the sand's whole path on a box small enough for a test: the paper's plate (a lid cannot rest
# in a box this small) and two calibration frictions
TINY = {
    "seed": 0,
    "soil": {"name": "tiny paper sand", "reference": "the paper's reconstructed grading"},
    "grading": {"preset": "paper"},
    "lab": {"n_max": 0.4571, "n_min": 0.3253, "n": 0.40},
    "specimen": {"width": 0.05, "height": 0.025, "layers": 2},
    "criterion": {"acceptance": "plate"},
    "sand": {"seeds": 2, "mu_prep": [0.0, 0.5], "calibration_disks": 10_000},
}


@pytest.mark.slow
def test_sand_end_to_end_on_a_tiny_box(tmp_path, monkeypatch):
    from poro2d.sand import SandResult, run_sand
    from poro2d.sand.run import StageClock
    from poro2d.store import Store

    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(PF, "JAMMING_DISKS", 200)
    lines: list[str] = []
    seen = []
    out = tmp_path / "sand"
    res = run_sand(
        load_sand_case(TINY),
        Store(out),
        options=QUIET,
        announce=lines.append,
        on_preflight=lambda c, p: seen.append((c, p)),
    )
    assert not (out / "fig_grading.png").exists()  # drawn from the result, after the run
    draw_grading(res, seen[0][0], Store(out))
    stages = [line for line in lines if "left (estimate)" in line]
    assert isinstance(res, SandResult) and seen and len(stages) == 2 and "left (estimate)" in lines[0]
    assert isinstance(StageClock, type)
    assert (out / "preflight.json").is_file() and (out / "fig_grading.png").stat().st_size > 0
    data = json.loads((out / "sand.json").read_text())
    assert data["soil"]["name"] == "tiny paper sand" and data["provenance"]["poro2d_version"]
    assert data["calibration"]["mus"] == [0.0, 0.5]
    # how the workers were used, stage by stage: every case that ran, on the workers there were
    use = data["worker_use"]
    assert {"calibration ends", "specimens"} <= set(use)
    for stage in use.values():
        assert sum(stage["cases_per_worker"].values()) == stage["cases"] and stage["idle_core_s"] >= 0.0
    assert use["specimens"]["cases"] == 2 and any(
        line.startswith("specimens: 2 case(s) on") for line in lines
    )
    assert "| workers, specimens |" in (out / "summary.md").read_text()
    # every seed is recorded, accepted or not, with its folder or the reason it was refused
    assert [r["seed"] for r in data["seed_results"]] == [0, 1]
    assert all(r["accepted"] == bool(r["folder"]) for r in data["seed_results"])
    # where the time went: every trial of the 4 calibration cases and the 2 specimens, counted
    prof, spec_prof = data["calibration"]["time_profile"], data["calibration"]["specimens_time_profile"]
    assert prof["trials"] >= 4 and spec_prof["trials"] >= 2
    assert prof["plate"]["steps"] > 0 and prof["prepare"]["particle_steps_per_s"] > 0
    assert res.n2d_min < res.n2d_target < res.n2d_max
    # the answer's standard error, the calibration's seeds carried through mu_prep (two ends here)
    assert set(data["answer_error"]) == {"specimens_se", "mu_prep_se", "interior_slope", "calibration_se",
                                         "answer_se"}  # fmt: skip
    assert res.answer_error.mu_prep_se is None or res.answer_error.mu_prep_se >= 0.0
    # where the specimens landed: their Dr against the asked one, the interior porosity at the target
    reached = data["state_reached"]
    assert reached["relative_density_asked"] == pytest.approx(res.state.relative_density)
    assert reached["box_target"] == pytest.approx(res.first_trial_full_box)
    assert reached["box_mean"] == pytest.approx(res.box_porosity_mean)
    md = (out / "summary.md").read_text()
    accepted = [k for k in res.specimens if k.accepted]
    assert accepted, "no seed accepted"
    for k in accepted:
        assert (out / k.folder / "specimen.npz").is_file() and k.folder.startswith("specimens/Dr0.487-seed")
    assert res.box_porosity_mean == pytest.approx(np.mean([k.box_porosity for k in accepted]))
    # the box holds too few disks for an interior region away from the walls: no number, said so
    vals = [k.interior_porosity for k in accepted if k.interior_porosity is not None]
    if vals:
        assert res.interior_porosity_mean == pytest.approx(np.mean(vals))
    else:
        assert res.interior_porosity_mean is None and "n/a" in md.splitlines()[2]
    assert md.splitlines()[2].startswith("**Interior porosity")
    assert (
        (out / "summary.csv")
        .read_text()
        .startswith("soil,upscale,disks,n_lab,e,Dr,mu_prep,interior_porosity")
    )
    header = (out / "summary.csv").read_text().splitlines()[0]
    assert header.endswith("seeds_accepted,Dr_reached,interior_at_target,interior_at_target_se")
    # a rerun reads every finished case back: the same numbers
    again = run_sand(load_sand_case(TINY), Store(out), options=QUIET)
    assert again.box_porosity_mean == res.box_porosity_mean
    assert [k.box_porosity for k in again.specimens] == [k.box_porosity for k in res.specimens]
    assert again.mu_prep == res.mu_prep
    assert res.state_map is None and "state_map" not in data
    # a [state] table added afterwards reads the same run back and adds the state parameter only
    stated = run_sand(load_sand_case({**TINY, "state": {"lab_line": "toyoura"}}), Store(out), options=QUIET)
    assert stated.box_porosity_mean == res.box_porosity_mean and stated.n2d_target == res.n2d_target
    rec = stated.state_map
    assert rec.e2d_by_state is None and "poro2d critical-state" in rec.note
    assert rec.psi_norm_lab == pytest.approx(
        (0.40 / 0.60 - rec.e_cs_lab) / (0.4571 / 0.5429 - 0.3253 / 0.6747)
    )
    assert "## State parameter" in (out / "summary.md").read_text()


def test_preflight_says_what_a_cut_of_fines_does(tmp_path, monkeypatch):
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path))
    monkeypatch.setattr(PF, "JAMMING_DISKS", 200)
    cfg = _config(grading={"preset": "paper", "d_min_mm": 3.0})  # the up-scaled curve cut at 3 mm
    pf = PF.preflight(load_sand_case(cfg), workers=1)
    (note,) = [n for n in pf.notes if n.startswith("d_min_mm")]
    g = paper_grading()
    share = float(np.interp(np.log(0.003), np.log(g.sizes), g.percent))
    assert f"removes {share:.1f} % of the mass" in note and "same relative density" in note


def test_step_budgets_follow_the_time_step():
    from poro2d.grading import GradingCurve
    from poro2d.sand.case import STEP_BUDGETS, with_step_budgets
    from poro2d.sweep.criterion_base import CriterionBase

    spec = SpecimenSpec()
    paper = CriterionBase({"criterion": {}, "specimen": {}})
    assert with_step_budgets(paper, spec, paper_grading()) is paper  # the paper grading: the defaults
    fine = GradingCurve.from_lists([0.1, 0.2, 0.4], [0, 50, 100], upscale=10)  # d_min 1 mm: half the step
    slow = PF.time_step(spec, 0.002) / PF.time_step(spec, 0.001)
    assert slow == pytest.approx(2.0)
    cfg = with_step_budgets(CriterionBase({"criterion": {"max_plate_steps": 1234}}), spec, fine)
    assert cfg.table("criterion")["max_plate_steps"] == 1234  # what the user set stays
    for (table, key), default in STEP_BUDGETS.items():
        if (table, key) != ("criterion", "max_plate_steps"):
            assert cfg.table(table)[key] == pytest.approx(default * 2.0, rel=0.01)


def test_budget_suggestion_offers_only_what_fits_the_box():
    case = load_sand_case(_config())
    text = PF.budget_suggestion(case, 3600.0, 10.0, first=0.17, workers=2)
    assert text.startswith("estimate 60 min exceeds the budget of 10 min")
    assert "up-scale by" in text and "fewer seeds" in text
    assert PF.budget_suggestion(case, 300.0, 10.0) == "fits the budget of 10 min (estimate 5 min)"
    huge = load_sand_case(_config(grading={"preset": "paper", "upscale": 40}))  # d_max 28 mm in a 31 mm band
    assert "no up-scaling fits" in PF.budget_suggestion(huge, 3600.0, 10.0, first=0.17, workers=2)


def test_a_named_specimen_exports_with_its_soil(tmp_path, specimen):
    """A folder ``poro2d sand`` named carries the soil and state into every export header."""
    import shutil

    from poro2d.interop.origin import SOIL_FILE, origin_lines

    folder = tmp_path / "Dr0.800-seed1"
    folder.mkdir()
    shutil.copy(specimen, folder / "specimen.npz")
    soil = {"name": "Toyoura sand", "reference": "Verdugo & Ishihara (1996)"}
    state = {"n_lab": 0.4023, "relative_density": 0.8}
    (folder / SOIL_FILE).write_text(json.dumps({"soil": soil, "state": state, "mode": "density", "seed": 1}))
    lines = origin_lines(folder / "specimen.npz")
    assert lines[0] == "provenance: soil Toyoura sand (Verdugo & Ishihara (1996))"
    text = "\n".join(lines)
    assert "n_lab = 0.4023, relative density Dr = 0.8000; mode density" in text and "seed 1" in text


def test_frictional_first_trials_start_on_the_loose_side():
    from poro2d.sand.run import LOOSE_BIAS
    from poro2d.sweep.density import first_trial

    crit = {"acceptance": "fill", "refine_tolerance": 0.002}
    assert first_trial(crit, 0.0, 0.15, 0.01, LOOSE_BIAS) == first_trial(crit, 0.0, 0.15, 0.01)
    assert first_trial(crit, 1.0, 0.15, 0.01, LOOSE_BIAS) == pytest.approx(
        first_trial(crit, 1.0, 0.15, 0.01) + LOOSE_BIAS, abs=0.0011
    )


def test_a_sand_cases_config_and_case_ids_are_pinned():
    """The specimens' config (step budgets scaled for a fine grading) and the calibration's and
    states' case ids, which name cache folders, stay what they were when configs were dicts."""
    from types import SimpleNamespace

    from poro2d.criterion.density import StateTarget
    from poro2d.sand.run import calibration_config
    from poro2d.sweep.density import CalibrationCase, StateChecks

    fine = {"sizes_mm": [0.5, 1.0, 2.0], "percent_passing": [0, 50, 100]}
    case = load_sand_case(_config(grading=fine, specimen={"layers": 3}))
    assert json.dumps(case.config.as_config()) == (
        '{"grading": {"sizes_mm": [0.5, 1.0, 2.0], "percent_passing": [0, 50, 100]}, "specimen": '
        '{"settle_drift": 0.001, "layers": 3, "max_steps_per_stage": 1600000, "fallback_steps": 800000, '
        '"calm_steps": 200000}, "criterion": {"refine_tolerance": 0.002, "max_iterations": 10, '
        '"acceptance": "fill", "force_fraction": 0.02, "n_lab": 0.440403, "max_plate_steps": 2400000}}'
    )
    box = SimpleNamespace(calibration_box=SimpleNamespace(width=0.1, height=0.05, layers=2))
    calibration = CalibrationCase(calibration_config(case, box), (0.0, 1.0), 2).sweep
    ids = ["afc5b7896b1f", "a9325bb0389e", "511d1f4f81e3", "ce24f5fc7eec"]
    assert [c.id for c in calibration.cases] == ids
    states = StateChecks(case.config, (StateTarget(0.3, 0.5, 0.17, 0.3),), 2, 0.001).sweep
    assert [c.id for c in states.cases] == ["aed9d8864d02", "863f868d6f95"]


def test_a_wide_gradings_preparation_note_is_said_once_by_the_preflight(tmp_path, monkeypatch, caplog):
    """A sand run's cases each logged the wide grading's note as a warning: 4-5 copies of a
    four-line note on the terminal (G1-1). The pre-flight says it once; a case that does not
    talk (progress off) logs it below warning level."""
    import logging

    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.store import Store
    from poro2d.sweep.cases import criterion_objects

    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path))
    monkeypatch.setattr(PF, "JAMMING_DISKS", 200)
    pf = PF.preflight(load_sand_case(_config(grading={"preset": "wide_cu4"})), workers=1)
    assert sum(n.startswith("preparation: wide grading") for n in pf.notes) == 1
    narrow = PF.preflight(load_sand_case(_config()), workers=1)
    assert not any(n.startswith("preparation:") for n in narrow.notes)

    cfg = {"grading": {"preset": "wide_cu4"}, "specimen": {"width": 0.04, "height": 0.02, "layers": 1}}
    spec, grading, settings, seed = criterion_objects(cfg)
    for progress, level in ((False, logging.INFO), (True, logging.WARNING)):
        caplog.clear()
        crit = PorosityCriterion(spec, grading, settings, seed=seed, store=Store(tmp_path / str(progress)),
                                 progress=progress)  # fmt: skip
        monkeypatch.setattr(crit, "_trial", lambda k, n: (_ for _ in ()).throw(RuntimeError("stop")))
        with caplog.at_level(logging.INFO, logger="poro2d.criterion.protocol"), pytest.raises(RuntimeError):
            crit._search()
        (rec,) = [r for r in caplog.records if r.getMessage().startswith("preparation:")]
        assert rec.levelno == level


def test_the_frictions_around_the_state_start_from_the_measured_ends(monkeypatch):
    """The calibration stage hands the ends it measured to the frictions between them (their
    first trials, :func:`poro2d.sweep.density.bracket_first_trial`) and records them."""
    from poro2d.sand import run as R
    from poro2d.sweep.records import CalibrationRun

    ends = Calibration([0.0, 1.0], [[0.1632, 0.1633], [0.2197, 0.2176]], [0, 1])

    def record(mus):
        return CalibrationRun("key", "cases", 4, 0, "computed", [[0.16] * 2 for _ in mus])

    monkeypatch.setattr(R, "calibrate_ends", lambda *a, **k: (ends, (0.0, 0.05, 0.1, 1.0), record([0, 1])))
    handed = []

    def calibrate(case, pf, store, mus, name, cal_kw, placed=None):
        handed.append((list(mus), placed))
        samples = [[0.1632 + 0.056 * m**0.5] * 2 for m in mus]  # rising with friction
        return Calibration(list(mus), samples, [0, 1]), record(mus)

    monkeypatch.setattr(R, "_calibrate", calibrate)
    case = load_sand_case({**TINY, "sand": {"mu_prep": [0.0, 0.05, 0.1, 1.0]}})
    _, cal = R.calibration_stage(case, None, None, {})
    placed = ((0.0, ends.n2d_min), (1.0, ends.n2d_max))
    assert handed and handed[0][1] == placed and handed[0][0][0] == 0.0 and handed[0][0][-1] == 1.0
    assert cal.bracket_ends == [[0.0, ends.n2d_min], [1.0, ends.n2d_max]]
