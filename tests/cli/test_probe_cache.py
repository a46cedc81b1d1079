"""The probe's damaged caches, as a user meets them: one tiny ``poro2d calibrate`` run, its cache
damaged one way per test, and the same command run again on a copy.

Each damage is either refused on one line naming what is damaged (exit 2), or the damaged test is
computed again and the answer is the undamaged run's; never is a damaged file used, and no
worker's "Compute Failed" reaches the terminal. A folder's manifest (``.digests.json``) may be
lost with the damage: then the files themselves are checked (the peak against its curve,
finite values, readable states).
"""

from __future__ import annotations

import json
import shutil

import pytest

from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

#: what a calibration answers: a rerun on a damaged cache must answer the same
ANSWER = ("best", "intervals", "posterior", "evaluations", "fit")
LAB = "normal_stress_kpa,peak_shear_stress_kpa\n50,30\n100,60\n"
#: the tests of the calibration's cache: end to end, on one tiny calibration (36 shear tests) that
#: the module builds once
ON_THE_CALIBRATION = pytest.mark.scenario


def _argv(lab, specimens, out) -> list[str]:
    given = [a for s in specimens for a in ("--specimen", str(s))]
    return ["calibrate", "--lab", str(lab), *given, "--points", "9", "--refine", "0",
            "--max-displacement", "0.002", "--workers", "1", "--dashboard", "none", "--quiet",
            "--keep-box-dominated",
            "--out", str(out)]  # fmt: skip


def _run(argv, capfd) -> tuple[int, str]:
    """(exit code, standard error of this process and its workers) of the command."""
    capfd.readouterr()
    try:
        main(argv)
        code = 0
    except SystemExit as e:
        code = e.code or 0
    return code, capfd.readouterr().err.strip()


@pytest.fixture(scope="module")
def calibrated(specimen, tmp_path_factory):
    """One finished calibration of two tiny specimens at two stresses (36 cached tests)."""
    root = tmp_path_factory.mktemp("probe_cache")
    sim, rep = prepare_specimen(SpecimenSpec(width=0.06, height=0.03, layers=2), paper_grading(), 0.2, seed=1)
    assert rep.converged
    second = root / "seed1.npz"
    checkpoint.save(sim, second)
    lab = root / "lab.csv"
    lab.write_text(LAB)
    out = root / "cal"
    main(_argv(lab, [specimen, second], out))  # returns on success
    return {"lab": lab, "specimens": [specimen, second], "out": out,
            "answer": json.loads((out / "result.json").read_text())}  # fmt: skip


@pytest.fixture
def damaged(calibrated, tmp_path, capfd):
    """A copy of the calibration and the command that reruns it there: ``(entry, rerun)``.

    ``entry`` is the folder of one cached test (its result, curve and consolidated state);
    ``rerun()`` gives (exit code, standard error, result.json or None).
    """
    out = tmp_path / "cal"
    shutil.copytree(calibrated["out"], out)
    entry = sorted((out / "cache").iterdir())[4]

    def rerun():
        code, err = _run(_argv(calibrated["lab"], calibrated["specimens"], out), capfd)
        res = out / "result.json"
        return code, err, json.loads(res.read_text()) if code == 0 else None

    return entry, rerun


def _same_answer(calibrated, res: dict, ran: int) -> None:
    for key in ANSWER:
        assert res[key] == calibrated["answer"][key], key
    assert res["cluster"]["tests_run"] == ran and res["failures"] == []


def _refused(code: int, err: str, *names: str) -> None:
    assert code == 2 and len(err.splitlines()) == 1 and err.startswith("error:"), err
    for name in names:
        assert name in err, (name, err)


def _edit_peak(entry, value: str) -> None:
    path = entry / "result.json"
    data = json.loads(path.read_text())
    text = path.read_text().replace(
        f'"peak_shear_stress_kpa": {data["peak_shear_stress_kpa"]!r}', f'"peak_shear_stress_kpa": {value}'
    )
    assert text != path.read_text()
    path.write_text(text)


def _truncate(path, keep: int = 2000) -> None:
    path.write_bytes(path.read_bytes()[:keep])


@ON_THE_CALIBRATION
def test_a_peak_edited_by_hand_is_refused_naming_the_file(damaged):
    entry, rerun = damaged
    _edit_peak(entry, "150.0")
    code, err, _ = rerun()
    _refused(code, err, f"{entry.name}/result.json", "changed since it was written")


@ON_THE_CALIBRATION
def test_a_peak_edited_with_its_manifest_gone_is_computed_again(damaged, calibrated):
    entry, rerun = damaged
    _edit_peak(entry, "150.0")
    (entry / ".digests.json").unlink()
    code, err, res = rerun()
    assert code == 0 and err == "", err
    _same_answer(calibrated, res, ran=1)


@ON_THE_CALIBRATION
def test_a_peak_of_nan_with_its_manifest_gone_is_computed_again(damaged, calibrated):
    entry, rerun = damaged
    _edit_peak(entry, "NaN")
    (entry / ".digests.json").unlink()
    code, err, res = rerun()
    assert code == 0 and err == "", err
    _same_answer(calibrated, res, ran=1)


@ON_THE_CALIBRATION
def test_a_truncated_state_of_a_finished_test_changes_nothing(damaged, calibrated):
    entry, rerun = damaged
    _truncate(entry / "consolidated.npz")  # a finished test reads its result, never this state
    code, err, res = rerun()
    assert code == 0 and err == "", err
    _same_answer(calibrated, res, ran=0)


@ON_THE_CALIBRATION
def test_a_truncated_state_of_an_unfinished_test_is_refused_naming_it(damaged):
    entry, rerun = damaged
    _truncate(entry / "consolidated.npz")
    (entry / "result.json").unlink()
    code, err, _ = rerun()
    _refused(code, err, f"{entry.name}/consolidated.npz")


@ON_THE_CALIBRATION
def test_a_truncated_state_with_its_manifest_gone_is_consolidated_again(damaged, calibrated):
    entry, rerun = damaged
    _truncate(entry / "consolidated.npz")
    for name in ("result.json", "curve.csv", ".digests.json"):
        (entry / name).unlink()
    code, err, res = rerun()
    assert code == 0 and "Compute Failed" not in err and err == "", err
    _same_answer(calibrated, res, ran=1)


@ON_THE_CALIBRATION
def test_a_file_where_a_tests_folder_belongs_is_refused_naming_it(damaged):
    entry, rerun = damaged
    shutil.rmtree(entry)
    entry.write_text("junk")
    code, err, _ = rerun()
    _refused(code, err, entry.name, "a file")


@ON_THE_CALIBRATION
def test_a_file_where_the_cache_belongs_is_refused_naming_it(damaged):
    entry, rerun = damaged
    shutil.rmtree(entry.parent)
    entry.parent.write_text("junk")
    code, err, _ = rerun()
    _refused(code, err, "cal/cache", "a file")


@ON_THE_CALIBRATION
@pytest.mark.parametrize("name", ["result.json", "curve.csv"])
def test_a_missing_result_or_curve_is_computed_again(damaged, calibrated, name):
    entry, rerun = damaged
    (entry / name).unlink()
    code, err, res = rerun()
    assert code == 0 and err == "", err
    _same_answer(calibrated, res, ran=1)


@ON_THE_CALIBRATION
def test_a_missing_state_of_a_finished_test_changes_nothing(damaged, calibrated):
    entry, rerun = damaged
    (entry / "consolidated.npz").unlink()
    code, err, res = rerun()
    assert code == 0 and err == "", err
    _same_answer(calibrated, res, ran=0)


@ON_THE_CALIBRATION
def test_a_missing_record_of_a_test_is_refused_naming_its_folder(damaged):
    entry, rerun = damaged
    (entry / "test.json").unlink()
    (entry / "result.json").unlink()
    code, err, _ = rerun()
    _refused(code, err, entry.name, "without the record of its test")


@ON_THE_CALIBRATION
def test_a_curve_edited_by_hand_is_refused_naming_the_file(damaged):
    entry, rerun = damaged
    path = entry / "curve.csv"
    lines = path.read_text().splitlines()
    cells = lines[3].split(",")
    cells[2] = "999.0"  # the shear stress of one record
    lines[3] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    code, err, _ = rerun()
    _refused(code, err, f"{entry.name}/curve.csv")


@ON_THE_CALIBRATION
def test_a_curve_cut_short_with_its_manifest_gone_is_computed_again(damaged, calibrated):
    entry, rerun = damaged
    _truncate(entry / "curve.csv", 3000)  # ends inside a row
    (entry / ".digests.json").unlink()
    code, err, res = rerun()
    assert code == 0 and err == "", err
    _same_answer(calibrated, res, ran=1)


@ON_THE_CALIBRATION
def test_a_truncated_specimen_is_refused_naming_it(calibrated, tmp_path, capfd):
    bad = tmp_path / "seed1.npz"
    bad.write_bytes(calibrated["specimens"][1].read_bytes()[:5000])
    out = tmp_path / "cal"
    code, err = _run(_argv(calibrated["lab"], [calibrated["specimens"][0], bad], out), capfd)
    _refused(code, err, "seed1.npz")
    assert not out.exists()


@pytest.mark.parametrize(("damage", "words"), [("truncate", "changed"), ("delete", "missing")])
def test_a_kept_specimen_damaged_since_it_was_written_is_refused_naming_it(specimen, tmp_path, damage, words):
    # the preset's specimens are kept in the calibration's folder and read back on a rerun
    path = Store(specimen.parent).copy(specimen.name, Store(tmp_path / "specimens"))
    if damage == "truncate":
        path.write_bytes(path.read_bytes()[:5000])
    else:
        path.unlink()
    with pytest.raises(InputError, match=f"{words} since it was written") as e:
        SpecimenSet.accepted({"seed0": path}).read()
    assert str(path) in str(e.value)


# ------------------------------------------------------- a shear test resumed by ``poro2d shear``
@pytest.fixture(scope="module")
def sheared(specimen, tmp_path_factory):
    """One finished ``poro2d shear`` series (one test at 50 kPa) and its peak."""
    out = tmp_path_factory.mktemp("probe_shear") / "shear"
    main(_shear_argv(specimen, out))
    return out, json.loads((out / "result.json").read_text())["tests"][0]["peak_shear_stress_kpa"]


def _shear_argv(specimen, out) -> list[str]:
    return ["shear", "-s", str(specimen), "-n", "50", "--max-displacement", "0.002", "--out", str(out)]


@ON_THE_CALIBRATION
@pytest.mark.parametrize("damage", ["peak", "nan", "curve"])
def test_a_resumed_shear_test_damaged_with_its_manifest_gone_is_computed_again(
    damage, sheared, specimen, tmp_path, capfd
):
    out = tmp_path / "shear"
    shutil.copytree(sheared[0], out)
    test = out / "sn50kPa"
    if damage == "curve":
        _truncate(test / "curve.csv", 3000)
    else:
        _edit_peak(test, "150.0" if damage == "peak" else "NaN")
    (test / ".digests.json").unlink()
    code, err = _run(_shear_argv(specimen, out), capfd)
    assert code == 0, err
    assert json.loads((out / "result.json").read_text())["tests"][0]["peak_shear_stress_kpa"] == sheared[1]
