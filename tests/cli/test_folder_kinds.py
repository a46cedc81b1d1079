"""A command refuses, before any work, a folder that belongs to another kind of run; a strength grid
larger than its budget is refused before any specimen is made."""

from __future__ import annotations

import pytest

from poro2d.cli import main
from poro2d.locks import KIND_NAME, output_folder

LAB = "normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n200,140\n"


def _refused(argv, capsys) -> str:
    with pytest.raises(SystemExit) as e:
        main([str(a) for a in argv])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error:"), err
    return err


def _folder_of(kind: str, path):
    with output_folder("--out", path, kind=kind):
        (path / "result.json").write_text("{}")
    return path


@pytest.mark.parametrize(
    ("owner", "argv"),
    [
        ("criterion", ["calibrate", "--lab", "{lab}", "--preset", "paper", "--quick", "--out", "{out}"]),
        ("calibrate", ["criterion", "--preset", "paper", "--out", "{out}", "--quiet"]),
        ("calibrate", ["relation", "--preset", "paper", "--quick", "--out", "{out}", "--quiet"]),
        ("sand", ["sensitivity", "--preset", "paper", "--quick", "--out", "{out}", "--quiet"]),
    ],
)
def test_a_folder_of_another_kind_is_refused_before_any_work(tmp_path, capsys, owner, argv):
    lab = tmp_path / "lab.csv"
    lab.write_text(LAB)
    out = _folder_of(owner, tmp_path / "out")
    before = sorted(p.name for p in out.iterdir())
    err = _refused([a.format(lab=lab, out=out) for a in argv], capsys)
    assert f"holds the results of a {owner} run" in err and "--out" in err
    assert sorted(p.name for p in out.iterdir()) == before  # nothing written
    assert (out / KIND_NAME).read_text().strip() == owner


def test_a_strength_grid_over_its_budget_is_refused_before_any_specimen(tmp_path, capsys):
    out = tmp_path / "s"
    mu = ",".join(f"{0.1 * k:.1f}" for k in range(11))
    err = _refused(["strength", "--quick", "--mu-r", mu, "--friction", "0.5,1,2,3", "--out", out], capsys)
    assert "--max-tests" in err and "396 tests" in err
    assert not out.exists()
