"""Rolling friction survives every export, or the target refuses the specimen saying why."""

import hashlib
from dataclasses import replace

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.interop import csv_table, pfc, yade
from poro2d.interop.specimen_data import from_checkpoint

DEFAULTS = {"thickness": 1.0, "gravity": 9.81, "local_damping": 0.7}


@pytest.fixture(scope="module")
def rolled(saved):
    spec = from_checkpoint(saved)
    return replace(spec, mu_r=np.full(spec.n, 0.2), walls=[replace(w, mu_r=0.1) for w in spec.walls])


def test_csv_round_trip_keeps_rolling_friction(rolled, tmp_path):
    csv_table.write_specimen(rolled, tmp_path)
    back = csv_table.read_specimen(tmp_path, DEFAULTS)
    assert np.array_equal(back.mu_r, rolled.mu_r)
    assert [w.mu_r for w in back.walls] == [0.1] * len(rolled.walls)
    assert back.contact_parameters() == rolled.contact_parameters()


def test_csv_without_rolling_is_unchanged_and_reads_as_none(saved, tmp_path):
    spec = from_checkpoint(saved)
    csv_table.write_specimen(spec, tmp_path)
    assert "mu_r" not in (tmp_path / "disks.csv").read_text()
    assert csv_table.read_specimen(tmp_path, DEFAULTS).mu_r is None


def test_csv_refuses_negative_or_one_sided_rolling_friction(rolled, tmp_path):
    csv_table.write_specimen(rolled, tmp_path)
    disks = tmp_path / "disks.csv"
    lines = disks.read_text().splitlines()
    row = next(k for k, line in enumerate(lines) if line.startswith("2,"))
    lines[row] = lines[row].rsplit(",", 1)[0] + ",-0.5"
    disks.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"line \d+ column 9 \(mu_r\)"):
        csv_table.read_specimen(tmp_path, DEFAULTS)
    csv_table.write_specimen(replace(rolled, walls=[replace(w, mu_r=0.0) for w in rolled.walls]), tmp_path)
    walls = tmp_path / "walls.csv"  # the walls' table without its mu_r column
    rows = [
        line.rsplit(",", 1)[0] if not line.startswith("#") else line
        for line in walls.read_text().splitlines()
    ]
    walls.write_text("\n".join(rows) + "\n")
    with pytest.raises(InputError, match="mu_r column"):
        csv_table.read_specimen(tmp_path, DEFAULTS)


def test_pfc5_carries_rolling_friction_and_pfc4_is_not_written(rolled, tmp_path):
    paths = pfc.write_specimen(rolled, tmp_path)
    assert [p.name for p in paths] == [pfc.CURRENT_FILE]
    text = (tmp_path / pfc.CURRENT_FILE).read_text()
    assert "type 'ball-ball' model 'rrlinear'" in text and text.count("rr_fric") == 2
    assert "rr_fric 0.2" in text and "rr_fric 0.1" in text  # disk-disk 0.2, disk-wall min(0.2, 0.1)
    assert "rolling" in pfc.pfc4_refusal(rolled)
    with pytest.raises(InputError, match="PFC 4.0"):
        pfc.pfc4_commands(rolled)


def test_yade_carries_rolling_friction_per_disk_and_wall(rolled, tmp_path):
    (path,) = yade.write_specimen(rolled, tmp_path)
    text = path.read_text()
    values = {}
    exec(text.split("\nimport math\n", 1)[0], values)  # the literals at the top, without YADE
    assert values["DISK_ROLLING"] == [0.2] * rolled.n
    assert values["WALL_ROLLING"] == {w.name: 0.1 for w in rolled.walls}
    assert "Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True" in text
    assert 'PyRunner(command="rolling_contacts()", iterPeriod=1, initRun=True)' in text


#: SHA-256 of the script's text after its literals, as every export wrote it before rolling
#: friction reached YADE: a specimen without rolling friction still gets exactly that script
_UNROLLED_BODY = "90624d6244167fd1cf3f4efe29f7d9385a38f81cd6bf02c3c4e00b44c5efb721"


def test_yade_script_without_rolling_friction_is_unchanged(saved, tmp_path):
    (path,) = yade.write_specimen(from_checkpoint(saved), tmp_path)
    text = path.read_text()
    assert "ROLLING" not in text and "CohFrict" not in text
    body = "\nimport math\n" + text.split("\nimport math\n", 1)[1]
    assert hashlib.sha256(body.encode()).hexdigest() == _UNROLLED_BODY


def test_export_cli_says_what_each_target_does_with_rolling_friction(saved, tmp_path, capsys):
    sim = checkpoint.load(saved)
    sim.particles.mu_r[:] = 0.2
    path = tmp_path / "rolled" / "specimen.npz"
    checkpoint.save(sim, path)
    main(["export", str(path.parent), "--to", "pfc", "--out", str(tmp_path / "pfc")])
    assert "specimen_pfc4.dat not written" in capsys.readouterr().out
    assert "rr_fric 0.2" in (tmp_path / "pfc" / pfc.CURRENT_FILE).read_text()
    main(["export", str(path.parent), "--to", "csv", "--out", str(tmp_path / "csv")])
    assert np.all(csv_table.read_specimen(tmp_path / "csv", DEFAULTS).mu_r == 0.2)
    main(["export", str(path.parent), "--to", "yade", "--out", str(tmp_path / "yade")])
    assert "DISK_ROLLING = [\n    0.2," in (tmp_path / "yade" / yade.SCRIPT_FILE).read_text()
