"""Every contact property of a specimen leaves with it, or the target refuses it naming the property.

The CSV tables carry the whole contact law (per-body springs and friction, rolling friction,
the normal dashpot's restitution) and read back to the same numbers; LAMMPS, YADE and PFC2D
cannot express poro2d's no-tension dashpot and refuse a specimen with one before any file.
"""

from dataclasses import fields, replace

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.interop import csv_table, lammps, pfc, yade
from poro2d.interop.specimen_data import from_checkpoint

DEFAULTS = {"thickness": 1.0, "gravity": 9.81, "local_damping": 0.7}
#: what a file cannot hold as such: where it was read from and the provenance comment lines
NOT_CARRIED = {"source", "origin", "locate"}


@pytest.fixture(scope="module")
def full(saved):
    """The test specimen with every contact property set: per-disk rolling friction (two values),
    the walls' own, a normal dashpot and the criterion's window."""
    spec = from_checkpoint(saved)
    mu_r = np.where(np.arange(spec.n) % 2 == 0, 0.2, 0.35)
    walls = [replace(w, mu_r=0.05 * (k + 1)) for k, w in enumerate(spec.walls)]
    return replace(spec, mu_r=mu_r, walls=walls, restitution=0.6, force_fraction=0.01)


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return a is not None and b is not None and np.array_equal(a, b)
    return a == b


def test_csv_round_trip_is_exact_for_every_property_and_array(full, tmp_path):
    csv_table.write_specimen(full, tmp_path)
    back = csv_table.read_specimen(tmp_path, DEFAULTS)
    for f in fields(full):
        if f.name not in NOT_CARRIED:
            assert _same(getattr(back, f.name), getattr(full, f.name)), f.name
    assert back.to_simulation(dt=back.dt).restitution == 0.6  # the dashpot reaches the engine


def test_csv_without_a_dashpot_has_no_restitution_line(saved, tmp_path):
    spec = from_checkpoint(saved)
    assert spec.restitution is None and not spec.dashpot
    csv_table.write_specimen(spec, tmp_path)
    assert "restitution" not in (tmp_path / csv_table.DISKS_FILE).read_text()
    assert csv_table.read_specimen(tmp_path, DEFAULTS).restitution is None


@pytest.mark.parametrize(
    ("writer", "target"),
    [(lammps.write_specimen, "LAMMPS"), (yade.write_specimen, "YADE"), (pfc.write_specimen, "PFC2D")],
)
def test_a_dashpot_is_refused_by_every_other_target_before_any_file(full, tmp_path, writer, target):
    with pytest.raises(InputError, match=f"restitution = 0.6 is invalid; allowed: none .* for {target}"):
        writer(full, tmp_path)
    assert not any(tmp_path.iterdir())
    plain = replace(full, mu_r=None, walls=[replace(w, mu_r=0.0) for w in full.walls])
    writer(replace(plain, restitution=1.0), tmp_path)  # restitution 1: no dashpot, nothing lost


def test_export_of_a_checkpoint_with_a_dashpot(saved, tmp_path, capsys):
    spec = replace(from_checkpoint(saved), restitution=0.6)
    path = tmp_path / "damped" / "specimen.npz"
    checkpoint.save(spec.to_simulation(dt=spec.dt), path)
    assert from_checkpoint(path).restitution == 0.6
    with pytest.raises(SystemExit) as e:
        main(["export", str(path.parent), "--to", "lammps", "--out", str(tmp_path / "lmp")])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "restitution" in err and "LAMMPS" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "lmp").exists()  # refused before the folder was made
    main(["export", str(path.parent), "--to", "csv", "--out", str(tmp_path / "csv")])
    assert csv_table.read_specimen(tmp_path / "csv", DEFAULTS).restitution == 0.6
