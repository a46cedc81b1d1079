"""One range for rolling friction everywhere it is accepted, printed as it is enforced.

Each command (the criterion's `[specimen] rolling_friction`, `shear --rolling-friction`,
`biaxial --rolling-friction`, `strength --mu-r`, `calibrate --mu-r-range`, a CSV specimen's
`mu_r` column on import) refuses the next number above the bound on one line; the range the
refusal prints is read back and must be [0, MAX_ROLLING_FRICTION]; the bound itself goes on to
the work (stopped there by a stand-in for the first step of work).
"""

from __future__ import annotations

import math
import re

import pytest

from poro2d.cli import main
from poro2d.dem.contact_law import MAX_ROLLING_FRICTION

ABOVE = math.nextafter(MAX_ROLLING_FRICTION, math.inf)


class Reached(Exception):
    """Raised by the stand-in for a command's first step of work: the input was accepted."""


def _stop(*args, **kwargs):
    raise Reached


def _criterion(tmp_path, value, monkeypatch):
    import poro2d.criterion.protocol as protocol

    monkeypatch.setattr(protocol.PorosityCriterion, "run", _stop)
    cfg = tmp_path / "rolling.toml"
    cfg.write_text(f"[specimen]\nrolling_friction = {value!r}\n")
    return ["criterion", "-c", cfg, "--out", tmp_path / "o", "--quiet"]


def _shear(tmp_path, value, monkeypatch):
    import poro2d.shear.run as run

    monkeypatch.setattr(run, "run_shear", _stop)
    return [
        "shear",
        "--specimen",
        tmp_path / "specimen.npz",
        "--rolling-friction",
        repr(value),
        "--out",
        tmp_path / "o",
    ]


def _biaxial(tmp_path, value, monkeypatch):
    import poro2d.biaxial as biaxial

    monkeypatch.setattr(biaxial, "run_biaxial", _stop)
    return ["biaxial", "--quick", "--rolling-friction", repr(value), "--out", tmp_path / "o", "--quiet"]


def _strength(tmp_path, value, monkeypatch):
    import poro2d.cli.strength as strength

    monkeypatch.setattr(strength, "quick_specimens", _stop)
    return ["strength", "--quick", "--mu-r", f"0,{value!r}", "--out", tmp_path / "o", "--quiet"]


def _calibrate(tmp_path, value, monkeypatch):
    import poro2d.calibration.model as model

    monkeypatch.setattr(model, "Ranges", _stop)
    lab = tmp_path / "lab.csv"
    lab.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n")
    return ["calibrate", "--lab", lab, "--preset", "paper", "--quick", "--mu-r-range", f"0,{value!r}",
            "--out", tmp_path / "o", "--quiet"]  # fmt: skip


COMMANDS = {"criterion": _criterion, "shear": _shear, "biaxial": _biaxial, "strength": _strength,
            "calibrate": _calibrate}  # fmt: skip


def printed_range(message: str) -> tuple[float, float]:
    """The first interval printed after 'allowed:', as numbers."""
    found = re.search(r"allowed: .*?[\[(]\s*([-+\d.e]+),\s*([-+\d.e]+)\s*[\])]", message)
    assert found, message
    return float(found.group(1)), float(found.group(2))


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_the_printed_range_is_the_enforced_one(command, tmp_path, capsys, monkeypatch, specimen):
    (tmp_path / "specimen.npz").write_bytes(specimen.read_bytes())
    for value in (ABOVE, -1e-12):
        with pytest.raises(SystemExit) as e:
            main([str(a) for a in COMMANDS[command](tmp_path, value, monkeypatch)])
        err = capsys.readouterr().err.strip()
        assert e.value.code == 2 and len(err.splitlines()) == 1, err
        assert printed_range(err) == (0.0, MAX_ROLLING_FRICTION), err
    with pytest.raises(Reached):  # the bound itself is accepted: the command goes on to its work
        main([str(a) for a in COMMANDS[command](tmp_path, MAX_ROLLING_FRICTION, monkeypatch)])


def test_a_csv_specimen_takes_the_same_range(tmp_path, specimen):
    from dataclasses import replace

    import numpy as np

    from poro2d.errors import InputError
    from poro2d.interop import csv_table
    from poro2d.interop.specimen_data import from_checkpoint

    defaults = {"thickness": 1.0, "gravity": 9.81, "local_damping": 0.7}
    spec = from_checkpoint(specimen)
    top = MAX_ROLLING_FRICTION
    csv_table.write_specimen(
        replace(spec, mu_r=np.full(spec.n, top), walls=[replace(w, mu_r=top) for w in spec.walls]), tmp_path
    )
    assert csv_table.read_specimen(tmp_path, defaults).mu_r.max() == top  # the bound reads back
    disks = tmp_path / "disks.csv"
    lines = disks.read_text().splitlines()
    row = next(k for k, line in enumerate(lines) if line.startswith("2,"))
    lines[row] = lines[row].rsplit(",", 1)[0] + "," + repr(ABOVE)
    disks.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as e:
        csv_table.read_specimen(tmp_path, defaults)
    assert printed_range(str(e.value)) == (0.0, MAX_ROLLING_FRICTION), str(e.value)


@pytest.mark.parametrize("command", ["strength", "calibrate"])
def test_a_rolling_friction_with_an_underscore_is_not_read_as_another_number(
    command, tmp_path, capsys, monkeypatch
):
    """float() reads "0_1" as 1, inside the range: refused as a number, not taken as 1."""
    argv = COMMANDS[command](tmp_path, 0.5, monkeypatch)
    argv = [a.replace("0.5", "0_1") if isinstance(a, str) else a for a in argv]
    with pytest.raises(SystemExit) as e:
        main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert e.value.code == 2 and "0_1" in err and "number" in err, err
