"""Typed results read the files written before they existed and write them back unchanged.

The files under tests/data/before_typed_results/ were written by poro2d before results were
typed (a criterion run and a direct shear series on a 0.05 m x 0.025 m box, a series with
laboratory data and a rate check, ``poro2d paper --quick --replicates 1``); only the folder
part of their paths was shortened. Written before the sweeps' results were typed: the
density mode of ``poro2d criterion`` (density_state.json), ``poro2d sensitivity`` and
``poro2d relation --mode paper`` on that box, ``poro2d relation --preset paper --quick``
(relation_density_mode.json), and from ``poro2d paper --quick`` the replicate specimens'
shear summary and the accepted specimen's state and porosity files. Written before the
calibration's and the sand's results had typed parts: ``poro2d calibrate --preset paper --quick``
(calibration_result.json) and ``poro2d sand`` on a small toy soil (sand_result.json). Written before
biaxial series existed: a one-stress ``poro2d biaxial`` on a paper-size specimen (biaxial_result.json).
Written before the biaxial test recorded its stiffness number, overlap and plastic strains:
``poro2d biaxial --quick --confining 50,200 --replicates 2`` (biaxial_series_result.json, and its
first test at 50 kPa, biaxial_test_result.json).
"""

import dataclasses
import json
import pickle
import typing
from pathlib import Path

import pytest

from poro2d.biaxial.results import BiaxialResult, BiaxialSeriesResult, BiaxialTestResult
from poro2d.calibration.run import CalibrationResult
from poro2d.criterion.result import (
    CriterionResult,
    ReplicatesResult,
    SpecimenStateResult,
)
from poro2d.measure.specimen_porosity import SpecimenPorosity
from poro2d.paper import PaperSummary
from poro2d.record import Record
from poro2d.sand.result import SandResult
from poro2d.shear.parts import LabComparison
from poro2d.shear.results import ReplicateShearResult, ShearSeriesResult, ShearTestResult
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.sweep.results import DensityStateResult, RelationResult, SensitivityResult
from poro2d.typed_result import NOT_IN_FILE, TypedResult, with_fields

DATA = Path(__file__).parent / "data" / "before_typed_results"
FILES = [
    (CriterionResult, "criterion_result.json"),
    (ShearTestResult, "shear_test_result.json"),
    (ShearSeriesResult, "shear_series_result.json"),
    (PaperSummary, "paper_results.json"),
    (DensityStateResult, "density_state.json"),
    (RelationResult, "relation_paper_mode.json"),
    (RelationResult, "relation_density_mode.json"),
    (SensitivityResult, "sensitivity.json"),
    (ReplicateShearResult, "shear_replicates.json"),
    (SpecimenStateResult, "specimen_state.json"),
    (SpecimenPorosity, "specimen_porosity.json"),
    (CalibrationResult, "calibration_result.json"),
    (SandResult, "sand_result.json"),
    (BiaxialResult, "biaxial_result.json"),
    (BiaxialSeriesResult, "biaxial_series_result.json"),
    (BiaxialTestResult, "biaxial_test_result.json"),
]


@pytest.mark.parametrize(("cls", "name"), FILES)
def test_files_written_before_round_trip(cls, name):
    stored = json.loads((DATA / name).read_text())
    result = cls.from_dict(stored)
    assert result.to_dict() == stored
    assert list(result.to_dict()) == list(stored)  # the same order too
    assert not result.extra, "every key of the file is a field"
    assert json.loads(json.dumps(result.to_dict())) == stored


def _as_file(value):
    """``value`` as its file holds it: a typed part, or a list or map of them, as its dict(s)."""
    if isinstance(value, TypedResult | Record):
        return value.to_dict()
    if isinstance(value, list):
        return [_as_file(v) for v in value]
    if isinstance(value, dict):
        return {k: _as_file(v) for k, v in value.items()}
    return value


@pytest.mark.parametrize(("cls", "name"), FILES)
def test_results_hold_the_files_values_as_their_attributes(cls, name):
    stored = json.loads((DATA / name).read_text())
    result = cls.from_dict(stored)
    assert cls.from_dict(stored).to_dict() == stored and len(result.to_dict()) == len(stored)
    for key, value in stored.items():
        assert _as_file(getattr(result, key)) == value, key
    assert "no such key" not in result.to_dict() and "no such key" not in result.extra
    assert not hasattr(result, "no_such_key")
    assert pickle.loads(pickle.dumps(result)).to_dict() == stored  # results cross process pools


def test_attributes_are_the_files_keys():
    stored = json.loads((DATA / "criterion_result.json").read_text())
    crit = CriterionResult.from_dict(stored)
    assert crit.converged and crit.final_porosity == stored["final_porosity"]
    assert len(crit.iterations) == len(stored["iterations"]) and crit.iterations[-1].decision.accepted
    series = ShearSeriesResult.from_dict(json.loads((DATA / "shear_series_result.json").read_text()))
    assert series.rate_check.tests and series.lab.friction_angle_deg is not None
    paper = PaperSummary.from_dict(json.loads((DATA / "paper_results.json").read_text()))
    assert paper.quick and paper.criterion.converged and paper.shear.tests


def test_optional_parts_are_written_only_when_present():
    stored = json.loads((DATA / "shear_series_result.json").read_text())
    bare = {k: v for k, v in stored.items() if k not in ("rate_check", "lab")}
    series = ShearSeriesResult.from_dict(bare)
    assert series.rate_check is None and series.to_dict() == bare and "lab" not in series.to_dict()
    series.lab = LabComparison.from_dict(stored["lab"])
    assert series.to_dict()["lab"] == stored["lab"] and list(series.to_dict())[-3] == "lab"


def test_unknown_keys_are_kept_and_missing_ones_stay_missing():
    stored = json.loads((DATA / "shear_test_result.json").read_text())
    newer = dict(stored, added_later={"x": 1})
    older = {k: v for k, v in stored.items() if k != "force_balance"}
    assert ShearTestResult.from_dict(newer).to_dict() == newer
    old = ShearTestResult.from_dict(older)
    assert old.to_dict() == older and "force_balance" not in old.to_dict() and old.force_balance is None


def test_a_subclass_is_a_dataclass_of_its_keys():
    from dataclasses import dataclass

    @dataclass(eq=False)
    class Small(TypedResult):
        a: int
        b: str = "x"

    s = Small(1)
    assert s.to_dict() == {"a": 1, "b": "x"} and (s.a, s.b) == (1, "x") and Small(2).to_dict() != s.to_dict()
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
    from poro2d.store import Store

    out = _folder(tmp_path, {"config.json": "criterion_config.json", "result.json": "criterion_result.json"})
    run = json.loads((out / "config.json").read_text())["run"]

    def crit(threads=1, **changes):
        spec = SpecimenSpec.from_dict(dict(run["specimen"], threads=threads))
        settings = CriterionSettings(**dict(run["criterion"], **changes))
        return PorosityCriterion(spec, paper_grading(), settings, seed=run["seed"], store=Store(out))

    stored = json.loads((DATA / "criterion_result.json").read_text())
    assert crit().run().to_dict() == stored  # read back, nothing computed
    assert crit(threads=2).stage().stored() == stored
    with pytest.raises(InputError, match=r"different config \(criterion.max_iterations\)"):
        crit(max_iterations=7).run()


def test_a_shear_test_folder_written_before_is_read_back_and_still_binds(tmp_path):
    from poro2d.errors import InputError
    from poro2d.shear import record
    from poro2d.store import Store

    out = _folder(tmp_path, {"test.json": "shear_test_record.json", "result.json": "shear_test_result.json"})
    old = json.loads((out / "test.json").read_text())
    stage = record.folder_stage(Store(out), old["run"], str(Path("moved") / "specimen.npz"))
    assert ShearTestResult.from_dict(stage.stored()).to_dict() == json.loads(
        (DATA / "shear_test_result.json").read_text()
    )
    assert record.folder_stage(Store(out), old["run"], "x").fingerprint.digest == old["key"]
    other = record.folder_stage(Store(out), dict(old["run"], normal_stress_kpa=100.0), "x")
    with pytest.raises(InputError, match=r"another normal stress \(50.0 kPa\); use a new --out"):
        other.check()
    older = dict(old, run={k: v for k, v in old["run"].items() if k != "specimen_digest"})
    (out / "test.json").write_text(json.dumps(older))
    with pytest.raises(InputError, match="written by an older poro2d"):
        stage.check()


def _stored(name: str) -> dict:
    return json.loads((DATA / name).read_text())


def test_a_relation_counts_its_failed_cases_in_either_mode():
    density, paper = RelationResult.from_dict(_stored("relation_density_mode.json")), None
    paper = RelationResult.from_dict(_stored("relation_paper_mode.json"))
    assert density.failed_cases == density.sweeps.failed_cases == 0
    assert paper.failed_cases == paper.sweep_summary.failed == 0 and paper.sweeps is None
    # each mode writes its own keys
    assert "sweeps" not in paper.to_dict() and "sweep_summary" not in density.to_dict()
    failed = dict(_stored("relation_paper_mode.json"))
    failed["sweep_summary"] = dict(failed["sweep_summary"], failed=2)
    assert RelationResult.from_dict(failed).failed_cases == 2


def test_a_density_relation_without_a_spread_still_writes_the_key():
    stored = dict(_stored("relation_density_mode.json"), spread=None)  # fewer than two converged states
    assert RelationResult.from_dict(stored).to_dict() == stored


def test_fields_not_in_the_file_stay_out_of_it(tmp_path):
    from poro2d.store import Store

    stored = _stored("shear_replicates.json")
    rep = ReplicateShearResult.from_dict(stored)
    assert rep.series == {}
    rep.series = {"seed0": ShearSeriesResult.from_dict(_stored("shear_series_result.json"))}
    assert rep.to_dict() == stored and "series" not in rep.to_dict() and rep.series["seed0"].tests
    # one accepted seed and one refused, as run_replicates reports them
    row = {"seed": 1, "final_porosity": 0.2, "converged": True, "trials": 2, "message": "", "folder": "seed1",
           "time_s": 1.0}  # fmt: skip
    rows = [row, dict(row, seed=2, final_porosity=None, converged=False, folder="seed2")]
    reps = ReplicatesResult.from_dict({"rows": rows})
    reps.store = Store(tmp_path / "reps")
    assert reps.to_dict() == {"rows": rows} and reps.rows[1].converged is False
    assert reps.specimens == SpecimenSet.made([("seed1", tmp_path / "reps" / "seed1" / "specimen.npz")])


@dataclasses.dataclass
class _Tail:
    """A group of fields several results share (typed_result.with_fields)."""

    processes: int
    config: dict
    note: str | None = None
    hidden: list = dataclasses.field(default_factory=list, metadata=NOT_IN_FILE)


@dataclasses.dataclass(eq=False)
@with_fields(_Tail, after="replicates")
class _GroupedResult(TypedResult):
    replicates: int
    label: str = "x"


def test_a_group_of_fields_stands_where_it_is_put():
    names = [f.name for f in dataclasses.fields(_GroupedResult) if f.name != "extra"]
    assert names == ["replicates", "processes", "config", "note", "hidden", "label"]
    r = _GroupedResult(replicates=2, processes=1, config={"a": 1})
    # hidden: not in the file
    assert list(r.to_dict()) == ["replicates", "processes", "config", "note", "label"]
    assert r.hidden == [] and r.hidden is not _GroupedResult(replicates=2, processes=1, config={}).hidden
    assert _GroupedResult.from_dict(r.to_dict()) == r
    assert typing.get_type_hints(_GroupedResult)["note"] == str | None
    # the group itself is left as it was
    assert [f.name for f in dataclasses.fields(_Tail)] == ["processes", "config", "note", "hidden"]


@dataclasses.dataclass(eq=False)
@with_fields(_Tail, after="replicates", optional=True)
class _LaterGroupedResult(TypedResult):
    replicates: int
    label: str = "x"

    OPTIONAL = ("processes", "config", "note")


def test_a_group_put_in_as_optional_is_none_unless_set():
    assert typing.get_type_hints(_LaterGroupedResult)["processes"] == int | None
    r = _LaterGroupedResult(replicates=2)
    assert r.processes is None and r.hidden is None and list(r.to_dict()) == ["replicates", "label"]
    full = _LaterGroupedResult(replicates=2, processes=1, config={"a": 1})
    assert list(full.to_dict()) == ["replicates", "processes", "config", "label"]
    assert _LaterGroupedResult.from_dict(full.to_dict()) == full
    # the group itself is left as it was
    assert typing.get_type_hints(_Tail)["processes"] is int


@dataclasses.dataclass(eq=False, kw_only=True)
@with_fields(_Tail, after="replicates")
class _KeywordGroupedResult(TypedResult):
    replicates: int


def test_a_group_in_a_keyword_only_class_is_keyword_only():
    # the group's own fields are positional: in a keyword-only class they are keyword-only too
    assert all(f.kw_only for f in dataclasses.fields(_KeywordGroupedResult))
    with pytest.raises(TypeError):
        _KeywordGroupedResult(2, 1, {})  # type: ignore[misc]


def _public_runs():
    from poro2d.calibration.run import CalibrationResult, run_calibration
    from poro2d.criterion.replicates import run_replicates
    from poro2d.criterion.run import run_criterion
    from poro2d.paper import run_paper
    from poro2d.shear.replicates import ReplicateShear
    from poro2d.shear.run import run_shear
    from poro2d.sweep.density_criterion import run_criterion_modes, run_density_criterion
    from poro2d.sweep.relation import run_relation
    from poro2d.sweep.sensitivity import run_sensitivity

    return [
        (run_criterion, CriterionResult), (run_density_criterion, DensityStateResult),
        (run_criterion_modes, CriterionResult | DensityStateResult),
        (run_replicates, ReplicatesResult), (run_shear, ShearSeriesResult),
        (ReplicateShear.run, ReplicateShearResult), (run_relation, RelationResult),
        (run_sensitivity, SensitivityResult), (run_paper, PaperSummary), (run_calibration, CalibrationResult),
    ]  # fmt: skip


def test_every_public_run_is_annotated_with_its_typed_result():
    import inspect
    import typing

    for func, cls in _public_runs():
        hint = typing.get_type_hints(inspect.unwrap(func))["return"]
        assert hint == cls, (func.__qualname__, hint)
        for part in typing.get_args(hint) or (hint,):
            assert issubclass(part, TypedResult), part


def _run_definitions() -> list[tuple[str, str]]:
    """(module, qualified name) of every public ``run_*`` function and method defined in src."""
    import ast

    src = Path(__file__).parent.parent / "src"
    found = []
    for path in sorted((src / "poro2d").rglob("*.py")):
        module = ".".join(path.relative_to(src).with_suffix("").parts)
        tree = ast.parse(path.read_text())
        defs = [("", node) for node in tree.body]
        defs += [(f"{c.name}.", node) for c in tree.body if isinstance(c, ast.ClassDef) for node in c.body]
        for prefix, node in defs:
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.name.startswith("run_"):
                found.append((module, prefix + node.name))
    return found


def test_every_run_defined_in_src_returns_a_typed_result():
    """A function named run_* is a run of the Python API: its result is typed (else name it otherwise)."""
    import importlib
    import inspect
    import types

    runs = _run_definitions()
    assert ("poro2d.sweep.runner", "run_sweep") in runs and ("poro2d.paper", "run_paper") in runs
    for module_name, qualname in runs:
        module = importlib.import_module(module_name)
        func = module
        for part in qualname.split("."):
            func = getattr(func, part)
        hint = inspect.unwrap(func).__annotations__.get("return")
        if isinstance(hint, str):  # postponed annotations: resolved in the defining module
            hint = eval(hint, vars(module))  # noqa: S307 - an annotation of our own source
        parts = typing.get_args(hint) if isinstance(hint, types.UnionType) else (hint,)
        assert all(isinstance(p, type) and issubclass(p, TypedResult) for p in parts), (
            module_name,
            qualname,
            hint,
        )


def test_a_settled_run_writes_the_keys_each_engine_reported():
    from poro2d.interop.settled import SettledRun

    forces = {"f_top_n_per_m": 1.0, "f_bottom_n_per_m": 2.0, "side_friction_up_n_per_m": 0.5}
    yade = SettledRun(**forces, unbalanced_force=1e-6, steps=10, converged=True, seconds=0.1,
                      yade_version="2023.02a", workdir="w")  # fmt: skip
    yade_keys = ["unbalanced_force", "steps", "converged", "seconds", "yade_version", "workdir"]
    assert list(yade.to_dict()) == [*forces, *yade_keys]
    ours = SettledRun(**forces, mean_contact_force_n=3.0, coordination_number=3.5, contacts=7, steps=10,
                      converged=True, max_ratio=1e-9, seconds=0.1)  # fmt: skip
    ours_keys = ["mean_contact_force_n", "coordination_number", "contacts", "steps", "converged", "max_ratio",
                 "seconds"]  # fmt: skip
    assert list(ours.to_dict()) == [*forces, *ours_keys]
    assert ours.contacts == 7 and "yade_version" not in ours.to_dict()
    assert pickle.loads(pickle.dumps(ours)).to_dict() == ours.to_dict()


def test_parts_of_a_result_are_typed_and_written_as_before():
    """Known structures inside a result (the paper summary's criterion, a calibration's posterior
    and cluster, the sand's calibration, time profiles and soil) are typed parts; the file is the same."""
    from poro2d.calibration.cluster import ClusterRecord
    from poro2d.calibration.run import PosteriorSummary
    from poro2d.sand.case import SoilRecord
    from poro2d.sand.profile import StageProfile
    from poro2d.sand.result import SandCalibration

    paper = PaperSummary.from_dict(json.loads((DATA / "paper_results.json").read_text()))
    assert isinstance(paper.criterion, CriterionResult) and paper.criterion.converged
    cal = CalibrationResult.from_dict(json.loads((DATA / "calibration_result.json").read_text()))
    assert isinstance(cal.posterior, PosteriorSummary) and isinstance(cal.cluster, ClusterRecord)
    assert cal.posterior.observables[0].observable == "peak" and cal.cluster.tests_run > 0
    sand_file = json.loads((DATA / "sand_result.json").read_text())
    sand = SandResult.from_dict(sand_file)
    assert isinstance(sand.calibration, SandCalibration) and isinstance(sand.soil, SoilRecord)
    assert isinstance(sand.calibration.time_profile, StageProfile)
    assert (
        sand.calibration.time_profile.plate.steps
        == sand_file["calibration"]["time_profile"]["plate"]["steps"]
    )
    for result, name in (
        (paper, "paper_results.json"),
        (cal, "calibration_result.json"),
        (sand, "sand_result.json"),
    ):
        assert json.dumps(result.to_dict(), indent=2) + "\n" == (DATA / name).read_text()


@pytest.mark.parametrize(
    ("cls", "name"),
    [(cls, name) for cls, name in FILES if "provenance" in json.loads((DATA / name).read_text())],
)
def test_provenance_is_a_record_written_as_before(cls, name):
    """Every result's ``provenance`` reads as a :class:`~poro2d.io_utils.Provenance` record that
    writes the file's keys back; a key of another version is kept, a missing one stays missing."""
    from poro2d.io_utils import Provenance

    stored = json.loads((DATA / name).read_text())
    result = cls.from_dict(stored)
    assert isinstance(result.provenance, Provenance) and result.provenance.poro2d_version
    assert result.provenance.python == stored["provenance"]["python"]
    assert json.dumps(result.to_dict(), indent=2) == json.dumps(stored, indent=2)
    keys = ["poro2d_version", "python", "machine", "platform", "cpu_count", "created_utc"]
    assert list(Provenance.now().to_dict()) == keys  # the keys every file has written
    older = Provenance.from_dict({"poro2d_version": "0.0.1", "host": "h"})
    assert older.to_dict() == {"poro2d_version": "0.0.1", "host": "h"}


def test_known_structures_of_shear_and_paper_files_are_typed_parts():
    """The split box, laboratory peaks, a strength study's definitions and the case study's
    facts, timings, conversion rows and shear summary are typed parts; the files are the same."""
    from poro2d.labtest.records import BoxRecord
    from poro2d.paper import ConversionRow, PaperFacts, PaperTimings
    from poro2d.shear.parts import LabPeak, QuasiStatic, ShearTestSummary, StrengthDefinitions
    from poro2d.shear.results import StrengthResult

    test = ShearTestResult.from_dict(json.loads((DATA / "shear_test_result.json").read_text()))
    assert isinstance(test.consolidation.box, BoxRecord) and test.consolidation.box.width == 0.05
    series = ShearSeriesResult.from_dict(json.loads((DATA / "shear_series_result.json").read_text()))
    assert all(isinstance(p, LabPeak) for p in series.lab.peaks)
    assert series.lab.peaks[0].normal_stress_kpa == 50
    paper = PaperSummary.from_dict(json.loads((DATA / "paper_results.json").read_text()))
    assert isinstance(paper.paper, PaperFacts) and paper.paper.criterion.accepted_porosity == 0.15
    assert isinstance(paper.timings, PaperTimings) and paper.timings.shear_s > 0
    assert isinstance(paper.conversions.methods[0], ConversionRow)
    assert isinstance(paper.shear.tests[0], ShearTestSummary) and isinstance(
        paper.shear.quasi_static, QuasiStatic
    )
    for result, name in (
        (test, "shear_test_result.json"),
        (series, "shear_series_result.json"),
        (paper, "paper_results.json"),
    ):
        stored = json.loads((DATA / name).read_text())
        assert json.dumps(result.to_dict(), indent=2) == json.dumps(stored, indent=2)
    # a study without a converged criterion has no shear timings: they stay out of the file
    assert PaperTimings.from_dict({"conversions_s": 1.0, "criterion_s": 2.0}).to_dict() == {
        "conversions_s": 1.0,
        "criterion_s": 2.0,
    }
    strength = {"cases": [], "mu_r": [0.1], "particle_friction": [0.5], "specimens": ["s1"], "settings": {},
                "definitions": {"peak_friction_angle": "a", "residual_friction_angle": "b",
                                "max_dilation_angle": "c"}}  # fmt: skip
    read = StrengthResult.from_dict(strength)
    assert isinstance(read.definitions, StrengthDefinitions) and read.to_dict() == strength


def test_a_calibrations_per_parameter_values_are_typed_parts():
    """A calibration's best pair, intervals, ranges, posterior median and wide flags, its
    laboratory data and timings are typed parts; the file is the same."""
    from poro2d.calibration.model import Surrogate
    from poro2d.calibration.run import CalibrationTimings, ParameterValues
    from poro2d.shear.parts import LabRecord

    stored = json.loads((DATA / "calibration_result.json").read_text())
    cal = CalibrationResult.from_dict(stored)
    assert isinstance(cal.best, ParameterValues)
    assert cal.best.particle_friction == stored["best"]["particle_friction"]
    assert isinstance(cal.intervals, ParameterValues) and isinstance(cal.ranges, ParameterValues)
    assert cal.ranges.rolling_friction == [0.0, 0.5] and isinstance(cal.posterior.wide, ParameterValues)
    assert isinstance(cal.posterior.median, ParameterValues) and isinstance(cal.lab, LabRecord)
    assert isinstance(cal.timings, CalibrationTimings) and cal.timings.wall_time_s > 0
    assert isinstance(cal.fit["peak_50kPa"], Surrogate) and cal.fit["peak_50kPa"].replicates == 2
    assert json.dumps(cal.to_dict(), indent=2) == json.dumps(stored, indent=2)
    unknown = ParameterValues.from_dict({"particle_friction": None, "rolling_friction": None})
    assert unknown.to_dict() == {"particle_friction": None, "rolling_friction": None}
    assert unknown.rolling_friction is None


def test_a_sands_laboratory_state_and_accepted_states_are_typed_parts():
    """``sand.json``'s state (and the soil's), and each accepted specimen's row, are typed parts."""
    from poro2d.lab_state import LabState
    from poro2d.sand.result import AcceptedState

    stored = json.loads((DATA / "sand_result.json").read_text())
    sand = SandResult.from_dict(stored)
    assert isinstance(sand.state, LabState) and sand.state.given == "Dr"
    assert isinstance(sand.soil.lab, LabState) and sand.soil.lab.n_lab == sand.state.n_lab
    assert all(isinstance(s, AcceptedState) for s in sand.states) and sand.states[1].seed == 1
    assert json.dumps(sand.to_dict(), indent=2) == json.dumps(stored, indent=2)


def test_shear_settings_are_a_record_that_keeps_the_keys_a_file_had():
    """A result's shear settings read as :class:`~poro2d.shear.settings.ShearSettings`; a file
    written before ``stop_after_peak`` and ``rolling_friction`` existed is written back without them."""
    from poro2d.shear.settings import ShearSettings

    stored = json.loads((DATA / "shear_test_result.json").read_text())
    test = ShearTestResult.from_dict(stored)
    assert (
        isinstance(test.settings, ShearSettings) and test.settings.velocity == stored["settings"]["velocity"]
    )
    assert "stop_after_peak" not in test.to_dict()["settings"] and test.to_dict() == stored
    cal = CalibrationResult.from_dict(json.loads((DATA / "calibration_result.json").read_text()))
    assert isinstance(cal.settings, ShearSettings) and cal.settings.stop_after_peak == 0.0
    fresh = ShearSettings(velocity=0.01)
    # every setting, in the class's order; the disks' stiffness and the ParaView series only when
    # given (earlier files' keys)
    omitted = ("particle_kn", "particle_ks", "vtk_every")
    given = {k: v for k, v in dataclasses.asdict(fresh).items() if k not in omitted}
    assert fresh.to_dict() == given and list(fresh.to_dict()) == list(given)
    stiff = ShearSettings(velocity=0.01, particle_ks=2e5).to_dict()
    assert stiff == dict(given, particle_ks=2e5) and "particle_kn" not in stiff
    assert ShearSettings.from_dict(fresh.to_dict()).to_dict() == fresh.to_dict()


def test_a_criterion_keeps_its_settings_and_specimen_as_the_runs_values():
    """A criterion result's settings and specimen are the run's own values, read back from the
    keys the file had: options left out at their default stay out, the specimen's former ``extra``
    key stays in, and a preparation rolling friction stands after the other settings."""
    from poro2d.criterion.settings import CriterionSettings
    from poro2d.specimen.compaction import SpecimenSpec

    stored = json.loads((DATA / "criterion_result.json").read_text())
    crit = CriterionResult.from_dict(stored)
    assert isinstance(crit.settings, CriterionSettings) and crit.settings.max_iterations == 6
    assert isinstance(crit.specimen, SpecimenSpec) and crit.specimen.width == 0.05
    assert json.dumps(crit.to_dict()) == json.dumps(stored)
    for made in (
        CriterionSettings(refine_tolerance=0.002),
        CriterionSettings(acceptance="fill"),
        SpecimenSpec(width=0.05, height=0.025, rolling_friction=0.1),
        SpecimenSpec(),
    ):
        row = made.to_dict()
        assert list(type(made).from_dict(row).to_dict().items()) == list(row.items())
    prep = dict(stored, specimen=SpecimenSpec(rolling_friction_prep=0.2).to_dict())
    keys = list(CriterionResult.from_dict(prep).to_dict()["specimen"])
    assert keys[-2:] == ["rolling_friction_prep", "extra"] and keys[-3] == "threads"


def test_a_sands_calibration_record_and_seed_results_are_typed_parts():
    """The small box's calibration record and each seed's row are typed parts, written as before."""
    from poro2d.criterion.density import Calibration
    from poro2d.sand.result import SeedSpecimen

    stored = json.loads((DATA / "sand_result.json").read_text())
    sand = SandResult.from_dict(stored)
    assert isinstance(sand.calibration.calibration, Calibration)
    assert sand.calibration.calibration.mus == stored["calibration"]["calibration"]["mus"]
    assert "seed_results" not in sand.to_dict()  # a file written before the key stays without it
    seed = SeedSpecimen(1, True, 0.17, 0.16, 900, 2, "specimens/seed1")
    row = SeedSpecimen.from_dict(seed.to_dict())
    sand.seed_results = [row]
    assert sand.to_dict()["seed_results"] == [seed.to_dict()] and row.folder == "specimens/seed1"
    assert SandResult.from_dict(sand.to_dict()).seed_results[0].trials == 2


def test_a_sands_preflight_is_a_typed_part():
    """``sand.json``'s pre-flight (its boxes, jamming porosity and estimates) is a typed part."""
    from poro2d.sand.preflight import BoxPlan, Jamming, Preflight, StageEstimate

    stored = json.loads((DATA / "sand_result.json").read_text())
    pf = SandResult.from_dict(stored).preflight
    assert isinstance(pf, Preflight) and isinstance(pf.box, BoxPlan) and pf.box.layers == 4
    assert isinstance(pf.jamming, Jamming) and pf.jamming.seeds == 3
    assert isinstance(pf.seconds, StageEstimate)
    assert pf.seconds.total == stored["preflight"]["seconds"]["total"]
    assert "total" not in pf.particle_steps.to_dict() and pf.to_dict() == stored["preflight"]


def test_parts_are_read_by_the_base_class_singly_or_as_lists():
    """``PARTS`` names the fields whose file dicts (or lists of them) ``from_dict`` reads as records."""
    from dataclasses import dataclass as _dataclass

    from poro2d.typed_result import TypedResult as _TR

    @_dataclass(eq=False)
    class Row(_TR):
        x: float

    @_dataclass(eq=False)
    class Holder(_TR):
        one: Row | None
        many: list[Row] | None
        PARTS = {"one": Row, "many": Row}

    data = {"one": {"x": 1.0}, "many": [{"x": 2.0}, {"x": 3.0}]}
    held = Holder.from_dict(data)
    assert isinstance(held.one, Row) and [type(r) for r in held.many] == [Row, Row]
    assert held.to_dict() == data  # written back as the same dicts
    empty = Holder.from_dict({"one": None, "many": None})
    assert empty.one is None and empty.many is None


def test_a_map_of_parts_and_a_list_of_records_are_read_typed_and_written_back():
    """``Keyed`` reads a map of parts (names that vary, values of one class); a Record class
    with ``from_dict`` reads a list of rows: a calibration's surrogates and design points."""
    from poro2d.calibration.evaluations import DesignPoint, Observed
    from poro2d.calibration.model import Surrogate

    stored = json.loads((DATA / "calibration_result.json").read_text())
    cal = CalibrationResult.from_dict(stored)
    assert list(cal.fit) == list(stored["fit"]) and all(isinstance(v, Surrogate) for v in cal.fit.values())
    assert [type(e) for e in cal.evaluations] == [DesignPoint] * len(stored["evaluations"])
    first = cal.evaluations[0]
    assert first.observed[1] == Observed("peak", 100.0, stored["evaluations"][0]["peak_100kPa"])
    assert cal.to_dict() == stored and json.dumps(cal.to_dict()) == json.dumps(stored)  # keys in order too
    with pytest.raises(ValueError, match="not an observable"):
        DesignPoint.from_dict({"particle_friction": 1.0, "rolling_friction": 0.1, "note": [1.0]})
