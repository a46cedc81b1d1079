"""The one identity rule: marked fields never change a run's digest, every other field does.

Each place that decides "same run?" is checked on the description it builds: a criterion
folder's record, a sweep case's id, a cached calibration's key, a calibration unit's key, a
shear test's record and the twin detection of density checks.
"""

import dataclasses
import hashlib
import json

import pytest

from poro2d import __version__
from poro2d.calibration.units import unit_key
from poro2d.criterion.protocol import CriterionSettings, PorosityCriterion
from poro2d.grading import paper_grading
from poro2d.identity import identity_digest, outside_fields, outside_identity
from poro2d.shear.record import content_record, folder_stage
from poro2d.shear.settings import ShearSettings
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.store import Store
from poro2d.store.stage import Fingerprint
from poro2d.sweep.cases import Case, case_id
from poro2d.sweep.criterion_base import CriterionBase
from poro2d.sweep.density import CALIBRATION_REVISION, _run_key, calibration_key

#: values for fields whose default (None, 0, a name) cannot simply be scaled
OTHER = {
    "equilibrium": "mean",
    "settle_drift": 1e-3,
    "trial_porosity": 0.2,
    "refine_tolerance": 0.004,
    "acceptance": "fill",
    "particle_friction": 0.5,
    "rolling_friction": 0.1,
    "rolling_friction_prep": 0.1,
    "local_damping": 0.5,
    "undercompaction": 0.05,
    "gap": 1e-4,
    "particle_kn": 1e6,
    "particle_ks": 5e5,
    "mass_scaling": "off",
    "growth_friction": 0.0,
    "frictionless_fines": "off",
}


def other_value(cls: type, name: str):
    """A valid value of ``cls``'s field ``name`` other than its default."""
    if name in OTHER:
        return OTHER[name]
    value = getattr(cls(), name)
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 1
    return value * 1.1


def changed(cls: type, name: str):
    return cls(**{name: other_value(cls, name)})


def each_field(cls: type) -> list[str]:
    return [f.name for f in dataclasses.fields(cls)]


def table_of(name: str) -> tuple[str, type]:
    """The config table and dataclass of a specimen or criterion field."""
    if name in each_field(SpecimenSpec):
        return "specimen", SpecimenSpec
    return "criterion", CriterionSettings


def test_the_thread_count_is_the_marked_field():
    assert outside_fields(SpecimenSpec) == ("threads",)
    # and the ParaView series, an output (docs/paraview.md)
    assert outside_fields(CriterionSettings) == ("vtk_every",)
    assert outside_fields(ShearSettings) == ("vtk_every",)


def test_a_marked_field_is_recorded_but_not_compared():
    @dataclasses.dataclass
    class Run:
        size: float = 1.0
        workers: int = outside_identity(1)

    assert identity_digest(Run(workers=4)) == identity_digest(Run())
    assert identity_digest(Run(size=2.0)) != identity_digest(Run())
    # a plain table stands for its dataclass through ``tables``
    tables = {"run": Run}
    assert identity_digest({"run": {"size": 1.0, "workers": 4}}, tables=tables) == identity_digest(
        {"run": {"size": 1.0, "workers": 1}}, tables=tables
    )
    assert (
        Fingerprint({"run": {"size": 1.0, "workers": 4}}, tables=tables).differences(
            {"run": {"size": 1.0, "workers": 1}}
        )
        == []
    )


def criterion_digest(tmp_path, spec=SpecimenSpec(), settings=CriterionSettings()) -> str:
    """The digest of the record that binds a criterion folder (config.json)."""
    from poro2d.store import Store

    crit = PorosityCriterion(spec, paper_grading(), settings, seed=0, store=Store(tmp_path))
    return crit.stage().fingerprint.digest


@pytest.mark.parametrize("name", each_field(SpecimenSpec))
def test_criterion_folder_record_and_specimen_fields(tmp_path, name):
    same = name in outside_fields(SpecimenSpec) or name == "max_disks"  # a guard, left out of the record
    base = criterion_digest(tmp_path)
    assert (criterion_digest(tmp_path, spec=changed(SpecimenSpec, name)) == base) == same


@pytest.mark.parametrize("name", each_field(CriterionSettings))
def test_criterion_folder_record_and_criterion_fields(tmp_path, name):
    base = criterion_digest(tmp_path)
    same = name in outside_fields(CriterionSettings)
    assert (criterion_digest(tmp_path, settings=changed(CriterionSettings, name)) == base) == same


@pytest.mark.parametrize("name", each_field(SpecimenSpec))
def test_case_id_and_specimen_fields(name):
    base = {"seed": 0, "specimen": {}, "criterion": {"n_lab": 0.33}}
    cfg = dict(base, specimen={name: other_value(SpecimenSpec, name)})
    same = name in outside_fields(SpecimenSpec)
    assert (case_id("criterion", cfg) == case_id("criterion", base)) == same


@pytest.mark.parametrize("name", each_field(SpecimenSpec) + each_field(CriterionSettings))
def test_calibration_key_and_fields(name):
    table, cls = table_of(name)
    base = {"specimen": {}, "criterion": {}}
    cfg = dict(base, **{table: {name: other_value(cls, name)}})
    # the calibration's own axis (friction_prep) and what only picks a first trial are not its identity
    same = name in (
        *outside_fields(SpecimenSpec),
        *outside_fields(CriterionSettings),
        "friction_prep",
        "n_lab",
        "trial_porosity",
    )
    assert (calibration_key(CriterionBase(cfg)) == calibration_key(CriterionBase(base))) == same


@pytest.mark.parametrize("name", each_field(ShearSettings))
def test_calibration_unit_and_shear_test_record_and_shear_fields(tmp_path, name):
    base, other = ShearSettings(), changed(ShearSettings, name)
    same = name in outside_fields(ShearSettings)
    assert (unit_key("abc", 50.0, other) == unit_key("abc", 50.0, base)) == same
    record = folder_stage(Store(tmp_path), content_record("abc", 50.0, base), "s.npz").fingerprint
    differ = [] if same else [f"settings.{name}"]
    assert record.differences(content_record("abc", 50.0, other).to_dict()) == differ


def twin_key(specimen: dict, criterion: dict) -> str:
    config = {"seed": 1, "specimen": specimen, "grading": {"preset": "paper"}, "criterion": criterion}
    return _run_key(Case("criterion", {}, config), None)


@pytest.mark.parametrize("name", each_field(SpecimenSpec) + each_field(CriterionSettings))
def test_twin_detection_and_fields(name):
    table, cls = table_of(name)
    first = {"trial_porosity": 0.19}  # every state check and calibration case has one
    base = {"specimen": {}, "criterion": first}
    given = dict(base, **{table: {**base[table], name: other_value(cls, name)}})
    # nLab only chooses the first trial, given here
    same = name in (*outside_fields(SpecimenSpec), *outside_fields(CriterionSettings), "n_lab")
    assert (twin_key(given["specimen"], given["criterion"]) == twin_key(base["specimen"], first)) == same


def test_digests_keep_the_values_that_name_existing_folders():
    # case folders and calibration units: literal values written by earlier versions
    config = {"seed": 1, "specimen": {"threads": 2, "width": 0.1}, "criterion": {"n_lab": 0.3}}
    assert case_id("criterion", config) == "fd3a63b4cb43"
    settings = {"velocity": 0.025, "particle_friction": 0.5, "rolling_friction": None}
    assert unit_key("abc", 50.0, settings) == "3e724192e6c8f8191f68"
    # cached calibrations: the version enters the key, so the former formula is restated here
    base = {"specimen": {"threads": 2, "friction_prep": 0.3, "width": 0.1}, "criterion": {"n_lab": 0.3}}
    former = {"base": {"specimen": {"width": 0.1}, "grading": {"preset": "paper"}, "criterion": {}},
              "version": __version__, "revision": CALIBRATION_REVISION}  # fmt: skip
    expected = hashlib.sha256(json.dumps(former, sort_keys=True, default=str).encode()).hexdigest()[:16]
    assert calibration_key(CriterionBase(base)) == expected


def test_specimen_records_keep_their_keys():
    # the former ``extra`` field could not be set; its key stays in records and result files
    assert SpecimenSpec().to_dict()["extra"] == {}
    assert "extra" not in each_field(SpecimenSpec)


def test_a_record_gives_back_its_spec():
    spec = SpecimenSpec(threads=2, layers=3)
    assert SpecimenSpec.from_dict(json.loads(json.dumps(spec.to_dict()))) == SpecimenSpec(threads=2, layers=3)


def test_a_calibration_names_its_grading_file_by_content_not_by_path(tmp_path):
    """The same curve by a relative path beside the config, by an absolute path, or copied to
    another folder: one calibration (each computed every case again before)."""
    rows = "size_mm,percent_passing\n1.0,0\n2.0,50\n4.0,100\n"
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "a" / "curve.csv").write_text(rows)
    (tmp_path / "b" / "copy.csv").write_text(rows)
    spec = {"width": 0.1}
    relative = CriterionBase({"specimen": spec, "grading": {"csv": "curve.csv"}}, tmp_path / "a")
    absolute = CriterionBase(
        {"specimen": spec, "grading": {"csv": str(tmp_path / "a" / "curve.csv")}}, tmp_path
    )
    copied = CriterionBase({"specimen": spec, "grading": {"csv": "copy.csv"}}, tmp_path / "b")
    assert calibration_key(relative) == calibration_key(absolute) == calibration_key(copied)
    (tmp_path / "b" / "copy.csv").write_text(rows.replace("2.0,50", "2.0,60"))
    assert calibration_key(copied) != calibration_key(relative)
    # the up-scaling stays in the key beside the file's content
    scaled = CriterionBase({"specimen": spec, "grading": {"csv": "curve.csv", "upscale": 2}}, tmp_path / "a")
    assert calibration_key(scaled) != calibration_key(relative)
