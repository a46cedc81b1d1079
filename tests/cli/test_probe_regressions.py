"""Cases of the outside probe of the calibrate/strength/export surface, kept as a regression suite:
each is refused on one line (exit 2, no traceback) before any work, or handled with nothing lost.

The other groups of that probe have their tests beside the code they check: damaged caches
(tests/store/test_folder.py, tests/calibration/test_cache_damage.py, tests/shear/test_readback.py,
and as a user meets them, tests/cli/test_probe_cache.py), folders of another kind
(tests/cli/test_folder_kinds.py), rolling friction on export (tests/interop/test_rolling_export.py),
laboratory files (tests/shear/test_fit_lab.py), identifiability (tests/calibration/test_identifiability.py),
unaccepted specimens (tests/specimen/test_accepted.py, tests/specimen/test_specimen_set.py), the
over-full box with rolling friction (tests/criterion/test_overfull_rolling.py), dashboards and
schedulers (tests/ground/test_cluster_checks.py,
and for every command that takes them, tests/cli/test_probe_dask.py).
"""

from __future__ import annotations

import json
import shutil

import pytest

from poro2d.cli import main
from poro2d.cli.strength import one_box
from poro2d.dem import checkpoint
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store


def _refused(argv, capsys) -> str:
    with pytest.raises(SystemExit) as e:
        main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert e.value.code == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("error:"), err
    return err


@pytest.mark.parametrize("command", ["strength", "shear"])
def test_a_garbage_specimen_is_one_line(tmp_path, capsys, command):
    garbage = tmp_path / "specimen.npz"
    garbage.write_bytes(b"PK\x03\x04" + bytes(range(256)) * 8)
    extra = ["-n", "50"] if command == "shear" else []
    err = _refused([command, garbage, *extra, "--out", tmp_path / "o"], capsys)
    assert "specimen.npz" in err and not (tmp_path / "o").exists()


def test_strength_refuses_a_refused_trial_and_shears_the_accepted_one(specimen, tmp_path, capsys):
    trials = tmp_path / "crit" / "trials"
    for name, accepted in (("01_n0.14", False), ("02_n0.22", True)):
        (trials / name).mkdir(parents=True)
        shutil.copyfile(specimen, trials / name / "after_plate.npz")
        Store(trials / name).write_json("trial.json", {"accepted": accepted})
    out = tmp_path / "o"
    tiny = ["--mu-r", "0", "--friction", "0.5", "-n", "50", "--max-displacement", "0.002", "--workers", "1"]
    accepted, refused = trials / "02_n0.22" / "after_plate.npz", trials / "01_n0.14" / "after_plate.npz"
    err = _refused(["strength", accepted, refused, *tiny, "--out", out], capsys)
    assert "01_n0.14/trial.json says accepted = False" in err and not out.exists()
    main(["strength", str(accepted), *tiny, "--out", str(out), "--quiet"])
    result = json.loads((out / "strength.json").read_text())
    assert result["specimens"] == ["specimen1"] and len(result["cases"]) == 1
    assert 0.0 < result["cases"][0]["residual_friction_angle_mean_deg"] < 90.0  # one stress: no peak line


def test_a_strength_grid_over_its_budget_is_refused_before_any_specimen_is_read(tmp_path, capsys):
    garbage = tmp_path / "specimen.npz"
    garbage.write_bytes(b"not a checkpoint")
    mu = ",".join(f"{0.1 * k:.1f}" for k in range(10))
    stresses = ",".join(str(25 * k) for k in range(1, 11))
    err = _refused(["strength", garbage, "--mu-r", mu, "--friction", "0.5,1,2,3", "-n", stresses,
                    "--out", tmp_path / "o"], capsys)  # fmt: skip
    assert "--max-tests = 300" in err and "400 tests" in err and not (tmp_path / "o").exists()
    err = _refused(["strength", garbage, "--max-tests", "2000000", "--out", tmp_path / "o"], capsys)
    assert "--max-tests = 2000000" in err and "[1, 1000000]" in err


@pytest.mark.parametrize(
    ("rows", "words"),
    [
        ("50,1e300\n100,70\n200,140\n", ["strong"]),
        ("50,0\n100,70\n200,140\n", ["weak"]),
        ("50,500\n100,70\n200,140\n", ["(0, 2.5]"]),
        ("50,4_0\n100,70\n200,140\n", ["a number"]),
    ],
)
def test_a_laboratory_file_that_cannot_be_right_stops_calibrate_before_work(tmp_path, capsys, rows, words):
    lab = tmp_path / "lab.csv"
    lab.write_text("normal_stress_kpa,peak_shear_stress_kpa\n" + rows)
    err = _refused(
        ["calibrate", "--lab", lab, "--preset", "paper", "--quick", "--out", tmp_path / "o"], capsys
    )
    for w in words:
        assert w in err, (w, err)
    assert "line 2" in err and not (tmp_path / "o").exists()


def test_strength_refuses_specimens_of_two_boxes_as_seed_scatter(specimen, tmp_path, capsys):
    """A specimen of another box is not a seed of the same one: refused naming both boxes,
    before any test; seeds of one box whose plates settled apart by less than a disk are taken."""
    sim = checkpoint.load(specimen)
    sim.translate_wall("right", 0.01, 0.0)  # the same disks in a box 1 cm wider
    wider = checkpoint.save(sim, tmp_path / "wider.npz")
    sim.translate_wall("right", -0.01, 0.0)
    sim.translate_wall("top", 0.0, 1e-4)  # a plate a tenth of a millimetre higher: the same box
    taller = checkpoint.save(sim, tmp_path / "taller.npz")
    out = tmp_path / "o"
    tiny = ["--mu-r", "0", "--friction", "0.5", "-n", "50", "--max-displacement", "0.002", "--workers", "1"]
    err = _refused(["strength", specimen, wider, *tiny, "--out", out], capsys)
    assert "wider.npz" in err and "0.07 m x 0.03" in err and "that one's 0.06 m x 0.03" in err, err
    assert not out.exists()
    pair = SpecimenSet.accepted({"a": specimen, "b": taller}).read()
    assert one_box(pair) is pair
