"""A command refuses, before any work, a folder that belongs to another kind of run; a strength grid
larger than its budget is refused before any specimen is made."""

from __future__ import annotations

from pathlib import Path

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


# ---------------------------------------------------------------- the probe: every command, every kind
ROOT = Path(__file__).resolve().parents[2]
#: every command that writes a folder, with arguments that pass its option checks; ``{o}`` the folder
COMMANDS = {
    "calibrate": ["calibrate", "--lab", "{lab}", "--specimen", "{s}", "--out", "{o}", "--quiet"],
    "criterion": ["criterion", "--preset", "paper", "--out", "{o}", "--quiet"],
    "shear": ["shear", "-s", "{s}", "-n", "50", "--out", "{o}"],
    "biaxial": ["biaxial", "--quick", "--out", "{o}"],
    "critical-state": ["critical-state", "--disks", "200", "--out", "{o}", "--quiet"],
    "strength": ["strength", "--quick", "--mu-r", "0", "--friction", "0.5", "--out", "{o}"],
    "relation": ["relation", "--preset", "paper", "--quick", "--out", "{o}", "--quiet"],
    "sweep": ["sweep", "{sweep}", "--out", "{o}", "--quiet"],
    "sand": ["sand", str(ROOT / "examples" / "soils" / "toyoura.toml"), "--out", "{o}", "--quiet"],
    "sensitivity": ["sensitivity", "--preset", "paper", "--quick", "--out", "{o}", "--quiet"],
    "paper": ["paper", "--quick", "--out", "{o}", "--quiet"],
    "export": ["export", "{s}", "--to", "csv", "--out", "{o}"],
    "import": ["import", "{disks}", "--out", "{o}"],
}
KINDS = list(COMMANDS)


@pytest.fixture
def inputs(specimen, tmp_path):
    lab, sweep, disks = tmp_path / "lab.csv", tmp_path / "sweep.toml", tmp_path / "disks.csv"
    lab.write_text(LAB)
    sweep.write_text('[specimen]\nlayers = 2\n[sweep]\nkind = "criterion"\nseed = [0, 1]\n')
    disks.write_text("x,y,r\n0.01,0.01,0.001\n")
    return {"s": specimen, "lab": lab, "sweep": sweep, "disks": disks}


def _argv(command: str, inputs: dict, out) -> list[str]:
    return [str(a).format(o=out, **inputs) for a in COMMANDS[command]]


@pytest.mark.parametrize("command", KINDS)
def test_every_command_refuses_a_folder_of_another_kind_before_any_work(command, inputs, tmp_path, capsys):
    owner = KINDS[(KINDS.index(command) + 1) % len(KINDS)]
    out = _folder_of(owner, tmp_path / "out")
    err = _refused(_argv(command, inputs, out), capsys)
    assert f"results of {'an' if owner[0] in 'aeiou' else 'a'} {owner} run" in err and "--out" in err
    assert sorted(p.name for p in out.iterdir()) == [KIND_NAME, "result.json"]
    assert (out / KIND_NAME).read_text().strip() == owner


@pytest.mark.parametrize(
    ("command", "owner", "sign"),
    [
        ("criterion", "calibrate", "calibrated.toml"),  # a calibration written before folders had kinds
        ("calibrate", "criterion", "iterations.csv"),
        ("shear", "criterion", "iterations.csv"),  # the criterion a calibration or the paper keeps inside
        ("shear", "paper", "conversions.json"),
        ("export", "sand", "sand.json"),
        ("paper", "shear", "peaks.csv"),
        ("biaxial", "critical-state", "critical_state.png"),
    ],
)
def test_a_folder_without_a_marker_is_known_by_its_files(command, owner, sign, inputs, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / sign).write_text("{}")
    err = _refused(_argv(command, inputs, out), capsys)
    assert f"holds the results of {'an' if owner[0] in 'aeiou' else 'a'} {owner} run" in err
    assert sorted(p.name for p in out.iterdir()) == [sign]  # no marker either


def test_a_folder_of_the_commands_own_files_is_marked_as_its(inputs, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "disks.csv").write_text("old")  # an export of an earlier version: exported again
    main(_argv("export", inputs, out))
    assert (out / KIND_NAME).read_text().strip() == "export"
    assert (out / "disks.csv").read_text() != "old"


@pytest.mark.parametrize("content", [KIND_NAME, "conversions.json", ".digests.json"])
def test_plot_refuses_a_folder_of_a_run(tmp_path, capsys, content):
    out = tmp_path / "conversions"
    out.mkdir()
    (out / content).write_text("paper\n" if content == KIND_NAME else "{}")
    err = _refused(["plot", "relations", "-o", out], capsys)
    assert "--out-dir" in err and "holds the results of" in err
    assert [p.name for p in out.iterdir()] == [content]


def test_plot_writes_into_a_folder_of_no_run(tmp_path):
    out = tmp_path / "figures"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    main(["plot", "relations", "-o", str(out)])
    assert (out / "fig1_relations.png").is_file() and not (out / KIND_NAME).exists()
