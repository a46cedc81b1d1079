"""A trial of Fig. 3 as a typed record: its row reads back and writes out as its file had it."""

import json
from pathlib import Path

from poro2d.criterion.measures import Checks
from poro2d.criterion.protocol import CriterionSettings, closed_bracket
from poro2d.criterion.trial import Trial

DATA = Path(__file__).parent.parent / "data" / "before_typed_results"


def _rows() -> list[dict]:
    return json.loads((DATA / "criterion_result.json").read_text())["iterations"]


def test_a_row_written_before_reads_back_into_its_parts_and_writes_out_unchanged():
    for row in _rows():
        trial = Trial.from_dict(row)
        assert json.dumps(trial.to_dict()) == json.dumps(row)  # the same keys, values and order
        assert not trial.extra, "every key of the row is a part of the record"
        assert trial.plate.moved == row["plate_moved"] and trial.new_porosity == row["new_porosity"]
        assert trial.forces_after.f_top_n_per_m == row["f_top_after_n_per_m"]
        assert trial.decision.accepted == row["accepted"] and trial.checks == Checks(**row["checks"])
        assert trial.to_dict() == row  # its row


def test_an_older_row_without_some_keys_reads_back_without_them():
    older = {
        k: v for k, v in _rows()[0].items() if k not in ("force_limit_n_per_m", "time_plate_s", "checks")
    }
    older["from_another_tool"] = 1
    assert json.dumps(Trial.from_dict(older).to_dict()) == json.dumps(older)


def test_the_csv_row_spreads_the_checks_into_columns():
    row = _rows()[-1]
    flat = Trial.from_dict(row).flat()
    assert "checks" not in flat and all(flat[f"check_{k}"] == v for k, v in row["checks"].items())
    assert list(flat)[: len(row) - 1] == [k for k in row if k != "checks"]


def test_a_closed_bracket_adds_its_key_last_to_a_row_read_back():
    rows = [dict(r, converged=True, failed_check="", plate_settled=True) for r in _rows()]
    rows = [dict(r, porosity_change=0.004 - 0.001 * k) for k, r in enumerate(rows)]
    trials = [Trial.from_dict(r) for r in rows]
    best = closed_bracket(trials, CriterionSettings(refine_tolerance=0.002))
    assert best is trials[-1] and best.decision.accepted_at == "closed bracket"
    assert list(best.to_dict())[-1] == "accepted_at" and best.decision.accepted is True


def test_a_scaled_specimens_row_keeps_its_time_step_and_disks_and_a_true_one_has_no_such_keys():
    row = _rows()[0]
    assert "mass_scaling_dt_s" not in Trial.from_dict(row).to_dict()
    trial = Trial.from_dict(row)
    trial.mass_scaling_dt_s, trial.mass_scaled_disks = 1.57e-6, 412
    trial.order = None  # as a trial is made by the run, not read back
    written = trial.to_dict()
    assert written["mass_scaling_dt_s"] == 1.57e-6 and written["mass_scaled_disks"] == 412
    back = Trial.from_dict(json.loads(json.dumps(written)))
    assert back.mass_scaling_dt_s == 1.57e-6 and back.mass_scaled_disks == 412 and not back.extra
    assert back.flat()["mass_scaled_disks"] == 412  # a column of iterations.csv
