"""Rolling resistance travels into the shear box, the settings, the command and the LAMMPS
round trip: a rolling specimen is sheared with its own mu_r unless the settings replace it."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.interop import lammps as lmp
from poro2d.interop.check import box_spec, build_simulation
from poro2d.interop.check import read_specimen as import_specimen
from poro2d.interop.specimen_data import from_checkpoint
from poro2d.shear import DirectShearTest, ShearCase, ShearSettings, build_split_box
from poro2d.shear.record import content_record
from poro2d.store.stage import Fingerprint


@pytest.fixture(scope="module")
def rolling_specimen(specimen, tmp_path_factory):
    """The small specimen with rolling friction 0.2 on its disks and walls."""
    sim = checkpoint.load(specimen)
    sim.set_rolling_friction(0.2, walls=0.2)
    path = tmp_path_factory.mktemp("rolling") / "specimen.npz"
    checkpoint.save(sim, path)
    return path


def test_split_box_keeps_the_specimens_rolling_friction(rolling_specimen):
    sim, _ = build_split_box(checkpoint.load(rolling_specimen), 0.01)
    assert np.all(sim.particles.mu_r == 0.2)
    # the walls take the disks' value: each disk-wall contact has the disk's own mu_r
    assert np.all(sim.walls.rolling_friction() == 0.2)


@pytest.mark.parametrize("mu_r", [0.0, 0.45])
def test_split_box_rolling_friction_replaces_the_specimens(rolling_specimen, specimen, mu_r):
    for source in (rolling_specimen, specimen):
        sim, _ = build_split_box(checkpoint.load(source), 0.01, rolling_friction=mu_r)
        assert np.all(sim.particles.mu_r == mu_r) and np.all(sim.walls.rolling_friction() == mu_r)


def test_a_shear_test_runs_with_the_rolling_friction_of_its_settings(specimen):
    settings = ShearSettings(max_displacement=0.002, rolling_friction=0.3, particle_friction=0.8)
    sim, _ = DirectShearTest(ShearCase.of(specimen, 50, settings)).consolidate()
    assert np.all(sim.particles.mu_r == 0.3) and np.all(sim.particles.mu == 0.8)
    disk_disk, disk_wall = sim.rolling_moments()
    assert np.abs(disk_disk).max() > 0.0 and np.abs(disk_wall).max() > 0.0


@pytest.mark.parametrize("value", [-0.1, 1.5, float("nan"), float("inf")])
def test_settings_refuse_a_rolling_friction_out_of_range(value):
    with pytest.raises(InputError, match=r"rolling_friction.*\[0.0, 1.0\]"):
        ShearSettings(rolling_friction=value)


def test_the_rolling_friction_is_part_of_what_a_test_is():
    base = ShearSettings().to_dict()
    # left out while it keeps the specimen's own: folders written before it existed resume
    assert "rolling_friction" not in content_record("d", 50.0, base).settings.to_dict()
    a = Fingerprint(content_record("d", 50.0, base).to_dict())
    b = Fingerprint(content_record("d", 50.0, dict(base, rolling_friction=0.1)).to_dict())
    c = Fingerprint(content_record("d", 50.0, dict(base, particle_friction=0.5)).to_dict())
    assert len({a.digest, b.digest, c.digest}) == 3
    assert b.differences(a.content) == ["settings.rolling_friction"]


@pytest.mark.parametrize(
    ("option", "value", "words"),
    [
        ("--rolling-friction", "1.5", ["--rolling-friction", "1.5", "[0.0, 1.0]"]),
        ("--rolling-friction", "-0.1", ["--rolling-friction", "-0.1"]),
        ("--particle-friction", "-1", ["--particle-friction", "-1", "[0.0, 10.0]"]),
        ("--particle-friction", "nan", ["--particle-friction", "nan"]),
    ],
)
def test_cli_friction_options_are_refused_on_one_line(specimen, tmp_path, capsys, option, value, words):
    dest = tmp_path / "out"
    with pytest.raises(SystemExit) as exc:
        main(["shear", "-s", str(specimen), "-n", "50", "--out", str(dest), "--quiet", option, value])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
    assert not dest.exists()


def test_config_shear_table_takes_the_frictions_and_the_cli_wins(specimen, tmp_path, capsys):
    cfg = tmp_path / "shear.toml"
    cfg.write_text(
        "[shear]\nmax_displacement = 0.001\npeak_window = 5e-4\ncheckpoint_interval = 5e-4\n"
        "particle_friction = 0.7\nrolling_friction = 0.05\n"
    )
    dest = tmp_path / "out"
    main(["shear", "-s", str(specimen), "-n", "50", "-c", str(cfg), "--out", str(dest), "--quiet",
          "--rolling-friction", "0.25", "--workers", "1"])  # fmt: skip
    result = json.loads((dest / "result.json").read_text())
    assert result["settings"]["particle_friction"] == 0.7
    assert result["settings"]["rolling_friction"] == 0.25
    assert result["config"]["cli"]["rolling_friction"] == 0.25
    test = json.loads((dest / "sn50kPa" / "test.json").read_text())
    assert test["run"]["settings"]["rolling_friction"] == 0.25
    # another rolling friction in the same folder is another test: refused, not resumed
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main(["shear", "-s", str(specimen), "-n", "50", "-c", str(cfg), "--out", str(dest), "--quiet",
              "--rolling-friction", "0.3", "--workers", "1"])  # fmt: skip
    assert exc.value.code == 2 and "rolling_friction" in capsys.readouterr().err


def test_config_refuses_a_rolling_friction_out_of_range(specimen, tmp_path, capsys):
    cfg = tmp_path / "shear.toml"
    cfg.write_text("[shear]\nrolling_friction = 3.0\n")
    with pytest.raises(SystemExit) as exc:
        main(
            [
                "shear",
                "-s",
                str(specimen),
                "-n",
                "50",
                "-c",
                str(cfg),
                "--out",
                str(tmp_path / "o"),
                "--quiet",
            ]
        )
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "rolling_friction" in err and "3.0" in err
    assert not (tmp_path / "o" / "result.json").exists()


# ------------------------------------------------------------------ LAMMPS round trip
def test_lammps_export_and_import_keep_the_rolling_friction(rolling_specimen, tmp_path):
    spec = from_checkpoint(rolling_specimen)
    spec = replace(spec, walls=[replace(w, mu_r=0.1 if w.name == "top" else 0.2) for w in spec.walls])
    lmp.write_specimen(spec, tmp_path)
    back = import_specimen(tmp_path / lmp.DATA_FILE)
    assert back.mu_r is not None and np.all(back.mu_r == 0.2)
    assert {w.name: w.mu_r for w in back.walls} == {w.name: w.mu_r for w in spec.walls}
    # the import check's simulation keeps them too
    sim = build_simulation(back, box_spec(back, 1e-3))
    assert np.all(sim.particles.mu_r == 0.2)
    by_name = dict(zip(sim.walls.names, sim.walls.rolling_friction(), strict=True))
    assert by_name["top"] == 0.1 and by_name["bottom"] == 0.2


def test_lammps_import_without_rolling_friction_has_none(specimen, tmp_path):
    lmp.write_specimen(from_checkpoint(specimen), tmp_path)
    assert "rolling_friction" not in (tmp_path / lmp.DATA_FILE).read_text()
    back = import_specimen(tmp_path / lmp.DATA_FILE)
    assert back.mu_r is None or not back.mu_r.any()


def test_a_bad_rolling_note_names_its_line_and_column(rolling_specimen, tmp_path):
    lmp.write_specimen(from_checkpoint(rolling_specimen), tmp_path)
    data = tmp_path / lmp.DATA_FILE
    lines = data.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("# poro2d rolling_friction"))
    words = lines[k].split()
    words[3] = "-0.2"
    lines[k] = " ".join(words)
    data.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=rf"line {k + 1} '# poro2d rolling_friction' column 4"):
        import_specimen(data)
