"""Typed results read the files written before they existed and write them back unchanged.

The files under tests/data/before_typed_results/ were written by poro2d before results were
typed (a criterion run and a direct shear series on a 0.05 m x 0.025 m box, a series with
laboratory data and a rate check, ``poro2d paper --quick --replicates 1``); only the folder
part of their paths was shortened.
"""

import json
import pickle
from pathlib import Path

import pytest

from poro2d.criterion.result import CriterionResult
from poro2d.paper import PaperSummary
from poro2d.shear.results import ShearSeriesResult, ShearTestResult
from poro2d.typed_result import TypedResult

DATA = Path(__file__).parent / "data" / "before_typed_results"
FILES = [
    (CriterionResult, "criterion_result.json"),
    (ShearTestResult, "shear_test_result.json"),
    (ShearSeriesResult, "shear_series_result.json"),
    (PaperSummary, "paper_results.json"),
]


@pytest.mark.parametrize(("cls", "name"), FILES)
def test_files_written_before_round_trip(cls, name):
    stored = json.loads((DATA / name).read_text())
    result = cls.from_dict(stored)
    assert result.to_dict() == stored
    assert list(result.to_dict()) == list(stored)  # the same order too
    assert not result.extra, "every key of the file is a field"
    assert json.loads(json.dumps(result.to_dict())) == stored


@pytest.mark.parametrize(("cls", "name"), FILES)
def test_results_read_as_the_dicts_they_were(cls, name):
    stored = json.loads((DATA / name).read_text())
    result = cls.from_dict(stored)
    assert result == stored and dict(result) == stored and len(result) == len(stored)
    for key, value in stored.items():
        assert result[key] == value and result.get(key) == value and key in result
    assert "no such key" not in result and result.get("no such key") is None
    with pytest.raises(KeyError):
        result["no such key"]
    assert pickle.loads(pickle.dumps(result)) == stored  # results cross process pools


def test_attributes_are_the_files_keys():
    crit = CriterionResult.from_dict(json.loads((DATA / "criterion_result.json").read_text()))
    assert crit.converged and crit.final_porosity == crit["final_porosity"]
    assert len(crit.iterations) == len(crit["iterations"]) and crit.iterations[-1]["accepted"]
    series = ShearSeriesResult.from_dict(json.loads((DATA / "shear_series_result.json").read_text()))
    assert series.rate_check["tests"] and series.lab["friction_angle_deg"] is not None
    paper = PaperSummary.from_dict(json.loads((DATA / "paper_results.json").read_text()))
    assert paper.quick and paper.criterion["converged"] and paper.shear["tests"]


def test_optional_parts_are_written_only_when_present():
    stored = json.loads((DATA / "shear_series_result.json").read_text())
    bare = {k: v for k, v in stored.items() if k not in ("rate_check", "lab")}
    series = ShearSeriesResult.from_dict(bare)
    assert series.rate_check is None and series.to_dict() == bare and "lab" not in series
    series.lab = stored["lab"]
    assert series["lab"] == stored["lab"] and list(series.to_dict())[-3] == "lab"


def test_unknown_keys_are_kept_and_missing_ones_stay_missing():
    stored = json.loads((DATA / "shear_test_result.json").read_text())
    newer = dict(stored, added_later={"x": 1})
    older = {k: v for k, v in stored.items() if k != "force_balance"}
    assert ShearTestResult.from_dict(newer).to_dict() == newer
    old = ShearTestResult.from_dict(older)
    assert old.to_dict() == older and "force_balance" not in old and old.force_balance is None


def test_a_subclass_is_a_dataclass_of_its_keys():
    from dataclasses import dataclass

    @dataclass(eq=False)
    class Small(TypedResult):
        a: int
        b: str = "x"

    s = Small(1)
    assert s.to_dict() == {"a": 1, "b": "x"} and s == {"a": 1, "b": "x"} and s != {"a": 2, "b": "x"}
    assert Small.from_dict({"b": "y", "a": 2, "c": 3}).to_dict() == {"a": 2, "b": "y", "c": 3}


def _folder(tmp_path, files: dict) -> Path:
    for dst, src in files.items():
        (tmp_path / dst).write_text((DATA / src).read_text())
    return tmp_path


def test_a_criterion_folder_written_before_is_read_back_and_still_binds(tmp_path):
    from poro2d.criterion import CriterionSettings, PorosityCriterion
    from poro2d.errors import InputError
    from poro2d.specimen import paper_grading
    from poro2d.specimen.compaction import SpecimenSpec

    out = _folder(tmp_path, {"config.json": "criterion_config.json", "result.json": "criterion_result.json"})
    run = json.loads((out / "config.json").read_text())["run"]

    def crit(threads=1, **changes):
        spec = SpecimenSpec.from_record(dict(run["specimen"], threads=threads))
        settings = CriterionSettings(**dict(run["criterion"], **changes))
        return PorosityCriterion(spec, paper_grading(), settings, seed=run["seed"], out=out)

    stored = json.loads((DATA / "criterion_result.json").read_text())
    assert crit().run() == stored  # read back, nothing computed
    assert crit(threads=2).stage().stored() == stored
    with pytest.raises(InputError, match=r"different config \(criterion.max_iterations\)"):
        crit(max_iterations=7).run()


def test_a_shear_test_folder_written_before_is_read_back_and_still_binds(tmp_path):
    from poro2d.errors import InputError
    from poro2d.shear import record

    out = _folder(tmp_path, {"test.json": "shear_test_record.json", "result.json": "shear_test_result.json"})
    old = json.loads((out / "test.json").read_text())
    stage = record.folder_stage(out, old["run"], Path("moved") / "specimen.npz")
    assert ShearTestResult.from_dict(stage.stored()) == json.loads(
        (DATA / "shear_test_result.json").read_text()
    )
    assert record.folder_stage(out, old["run"], Path("x")).fingerprint.digest == old["key"]
    other = record.folder_stage(out, dict(old["run"], normal_stress_kpa=100.0), Path("x"))
    with pytest.raises(InputError, match=r"another normal stress \(50.0 kPa\); use a new --out"):
        other.check()
    older = dict(old, run={k: v for k, v in old["run"].items() if k != "specimen_digest"})
    (out / "test.json").write_text(json.dumps(older))
    with pytest.raises(InputError, match="written by an older poro2d"):
        stage.check()
