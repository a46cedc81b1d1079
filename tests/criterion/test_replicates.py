"""Replicate specimens: criterion runs of several seeds, in processes or one after the other."""

import numpy as np
import pytest

from poro2d.criterion import replicates
from poro2d.criterion.protocol import CriterionSettings
from poro2d.criterion.replicates import ReplicateCase, run_replicates
from poro2d.criterion.result import ReplicatesResult
from poro2d.dem import checkpoint
from poro2d.execute import RunOptions
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec
from poro2d.store import Store

#: the tests one after the other in this process, no bars
SERIAL = RunOptions(workers=1, progress=False)

SPEC = SpecimenSpec(width=0.05, height=0.025, layers=2, threads=2)
SETTINGS = CriterionSettings(force_fraction=0.05)
#: seeds 1 and 2 from n2D = 0.2
CASE = ReplicateCase(SPEC, paper_grading(), SETTINGS, 0.2, (1, 2))


def test_processes_give_the_specimens_of_a_serial_run(tmp_path, monkeypatch):
    """Two processes with one thread each build, seed for seed, the specimens of a serial run."""
    seeds = list(CASE.seeds)
    res = run_replicates(CASE, Store(tmp_path / "p"), options=RunOptions(progress=False))
    assert isinstance(res, ReplicatesResult)
    par, rows_par = res.specimens, res.rows
    res = run_replicates(CASE, Store(tmp_path / "s"), options=SERIAL)
    ser, rows_ser = res.specimens, res.rows
    assert [r.seed for r in rows_par] == seeds and [r.folder for r in rows_par] == ["seed1", "seed2"]
    for a, b in zip(rows_par, rows_ser, strict=True):
        assert (a.final_porosity, a.converged, a.trials) == (b.final_porosity, b.converged, b.trials)
    assert set(par) == {f"seed{s}" for s, r in zip(seeds, rows_par, strict=True) if r.converged}
    for label in par:
        pa, pb = checkpoint.load(par[label]).particles, checkpoint.load(ser[label]).particles
        np.testing.assert_array_equal(pa.pos, pb.pos)
        np.testing.assert_array_equal(pa.radius, pb.radius)
    # a rerun reads every seed back from its folder, with no job run
    monkeypatch.setattr(replicates, "_run_one", lambda *_: pytest.fail("a finished seed ran again"))
    res = run_replicates(CASE, Store(tmp_path / "p"), options=SERIAL)
    again, rows_again = res.specimens, res.rows
    assert again == par and [r.final_porosity for r in rows_again] == [r.final_porosity for r in rows_par]
