"""A calibration leaves design points with box-dominated tests out of its fit, says how many, and
refuses when too few are left (poro2d.shear.box_dominated)."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from poro2d.calibration import model
from poro2d.calibration.box_dominated import BoxDominatedPoint, BoxDominatedPoints, with_box_note
from poro2d.calibration.case import MIN_POINTS, CalibrationCase, shear_base_settings
from poro2d.calibration.run import CalibrationResult, _infer, _units
from poro2d.calibration.units import CalibrationUnit, UnitRow
from poro2d.cli import main
from poro2d.paper_data import QUICK_BOX_SOIL_LIKE
from poro2d.report.calibration_report import box_dominated_note
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

RANGES = model.Ranges((0.3, 3.0), (0.0, 0.5))
STRESSES = [50.0, 100.0]
TARGETS = [("peak", 50.0, 40.0), ("peak", 100.0, 75.0)]
FOUND = SpecimenSet(tuple("ab"), tuple(Path(f"{k}.npz") for k in "ab"), tuple(k * 64 for k in "ab"))
BASE = shear_base_settings({"max_displacement": 0.002})
TRAVEL = QUICK_BOX_SOIL_LIKE["max_displacement"]  # m: long enough for the quick box to peak
CALIBRATION = "calibration_result.json"  # a calibration's file written before the flag


def _rows(design, box: set[int], absurd: float = 0.0) -> list[UnitRow]:
    """Rows of a smooth strength surface with a seed scatter; the first test of each point of ``box``
    is box-dominated and reads ``absurd`` kPa more (a box's strength, not the soil's)."""
    units = _units(design, FOUND, STRESSES, BASE)
    rows = []
    for k, u in enumerate(units):
        point, first = divmod(k, len(FOUND) * len(STRESSES))
        flagged = point in box and first == 0
        peak = u.sigma * (0.4 + 0.2 * u.fp) + 20.0 * u.mu_r + (1.0 if u.specimen == "b.npz" else -1.0)
        peak += absurd if flagged else 0.0
        note = (
            "box-dominated: the shear plane carries 2.00 times the plate's normal stress" if flagged else ""
        )
        rows.append(UnitRow(u.key, u.sigma, u.fp, u.mu_r, u.specimen, peak, peak, 1.0,
                            box_dominated=flagged, box_note=note))  # fmt: skip
    return rows


def test_box_dominated_points_are_left_out_of_the_fit_and_counted():
    design = model.space_filling(RANGES, 14, 0)
    box = {2, 5, 11}
    post, surrogates, table = _infer(RANGES, design, FOUND, STRESSES, _rows(design, box, 1e3), TARGETS, 0.0)
    # the fit is the fit of the other points alone: the box's absurd strengths leave no trace in it
    kept = [p for k, p in enumerate(design) if k not in box]
    clean, clean_surrogates, _ = _infer(RANGES, kept, FOUND, STRESSES, _rows(kept, set()), TARGETS, 0.0)
    for got, want in zip(surrogates, clean_surrogates, strict=True):
        np.testing.assert_allclose(got.coefficients, want.coefficients)
    assert post.best() == clean.best()
    left = post.box_dominated
    assert (left.flagged, left.left_out, left.design_points) == (3, 3, 14)
    assert [(p.particle_friction, p.rolling_friction) for p in left.points] == [
        design[k] for k in sorted(box)
    ]
    assert left.points[0].tests == 1 and "a.npz at 50 kPa" in left.points[0].note
    assert len(table) == 14  # every evaluated point is still in the result's evaluations
    assert clean.box_dominated.flagged == 0


def test_kept_box_dominated_points_are_fitted_and_still_counted():
    design = model.space_filling(RANGES, 12, 0)
    post, surrogates, _ = _infer(RANGES, design, FOUND, STRESSES, _rows(design, {1, 4}, 1e3), TARGETS, 0.0,
                                 keep_box_dominated=True)  # fmt: skip
    left_out, *_ = _infer(RANGES, design, FOUND, STRESSES, _rows(design, {1, 4}, 1e3), TARGETS, 0.0)
    assert (post.box_dominated.flagged, post.box_dominated.left_out) == (2, 0)
    assert left_out.box_dominated.left_out == 2
    assert post.best() != left_out.best()  # the box's strengths pull the fit when kept


def test_too_few_points_left_for_the_quadratic_is_no_answer_naming_why():
    design = model.space_filling(RANGES, MIN_POINTS + 1, 0)
    rows = _rows(design, {0, 3})
    with pytest.raises(RuntimeError) as exc:
        _infer(RANGES, design, FOUND, STRESSES, rows, TARGETS, 0.0)
    text = str(exc.value)
    assert "2 of 10 design points are box-dominated" in text and f"which needs {MIN_POINTS}" in text
    assert "0.7-1.3 times the plate's load" in text and "--keep-box-dominated" in text
    _infer(RANGES, design, FOUND, STRESSES, _rows(design, {0}), TARGETS, 0.0)  # 9 left: enough


def _record(flagged: int, left_out: int) -> BoxDominatedPoints:
    points = [BoxDominatedPoint(0.3, 0.25, 2, "a.npz at 50 kPa: box-dominated: no peak")] * flagged
    return BoxDominatedPoints(flagged, left_out, 12, [0.7, 1.3], points)


def test_the_note_says_how_many_were_left_out_and_what_the_quick_box_measures():
    plain = with_box_note(_record(3, 3), False, 201, TRAVEL)
    assert plain.note.startswith("3 of 12 design points were box-dominated (a test whose shear plane")
    assert plain.note.endswith("left out of the fit") and "quick box" not in plain.note
    quick = with_box_note(_record(3, 3), True, 201, TRAVEL).note
    fp, mu_r = QUICK_BOX_SOIL_LIKE["particle_friction"], QUICK_BOX_SOIL_LIKE["rolling_friction"]
    assert quick.startswith(f"the quick box (201 disks) measures soil-like strength only for f_p <= {fp:g}")
    assert f"mu_r <= {mu_r:g}" in quick and quick.endswith("left out of the fit")
    assert "end before their peak" not in quick
    # the quick calibration's own 4 mm are too short for its box to peak: the note says so
    short = with_box_note(_record(3, 3), True, 201, 0.004).note
    assert "its tests of 4 mm end before their peak (--max-displacement)" in short
    kept = with_box_note(_record(3, 0), False, 201, TRAVEL).note
    assert "kept in the fit (--keep-box-dominated)" in kept
    assert "left out" not in with_box_note(_record(0, 0), False, 201, TRAVEL).note


def test_a_calibration_file_keeps_the_record_typed_and_an_earlier_one_reads_without_it():
    data = json.loads((Path(__file__).parents[1] / "data" / "before_typed_results" / CALIBRATION).read_text())
    old = CalibrationResult.from_dict(data)
    assert old.box_dominated is None and box_dominated_note(old) is None
    new = CalibrationResult.from_dict(
        dict(data, box_dominated=with_box_note(_record(1, 1), False, 201, TRAVEL).to_dict())
    )
    assert isinstance(new.box_dominated, BoxDominatedPoints)
    assert isinstance(new.box_dominated.points[0], BoxDominatedPoint)
    assert new.to_dict()["box_dominated"]["left_out"] == 1
    assert box_dominated_note(new).startswith("1 of 12 design points were box-dominated")


def test_the_command_refuses_on_one_line_when_too_few_points_are_left(tmp_path, capsys, monkeypatch):
    import poro2d.calibration.run as run

    def refused(*args, **kwargs):
        design = model.space_filling(RANGES, MIN_POINTS, 0)
        _infer(RANGES, design, FOUND, STRESSES, _rows(design, set(range(MIN_POINTS))), TARGETS, 0.0)

    monkeypatch.setattr(run, "run_calibration", refused)
    monkeypatch.setattr(CalibrationCase, "of", classmethod(lambda cls, *args, **kwargs: None))
    lab = tmp_path / "lab.csv"
    lab.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n")
    with pytest.raises(SystemExit) as exc:
        main(["calibrate", "--lab", str(lab), "--specimen", "a.npz", "--out", str(tmp_path / "o"), "--quiet"])
    assert exc.value.code == 1
    out = [line for line in capsys.readouterr().out.splitlines() if line.strip()]
    assert len(out) == 1 and "9 of 9 design points are box-dominated" in out[0]


def test_a_unit_cached_before_the_flag_is_judged_from_its_curve_under_the_same_key(specimen, tmp_path):
    base = shear_base_settings({"max_displacement": 0.0005, "peak_window": 2e-4})
    found = SpecimenSet.named([specimen]).read()
    unit = CalibrationUnit.at(specimen, found.digest(next(iter(found))), 100.0, base, 0.5, 0.1)
    cache = Store(tmp_path / "cache")
    fresh = unit.compute(cache)
    store = unit.store(cache)
    stored = store.read_json("result.json")
    assert isinstance(stored["box_dominated"], bool)
    # as a unit finished before the flag existed wrote it (through the store: its manifest agrees)
    store.write_json(
        "result.json", {k: v for k, v in stored.items() if k not in ("box_dominated", "box_note")}
    )
    again = replace(unit)
    assert again.key == unit.key
    row = again.stored_row(cache)
    assert row is not None and row.peak == fresh.peak
    assert (row.box_dominated, row.box_note) == (fresh.box_dominated, fresh.box_note)
