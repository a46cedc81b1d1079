"""The conformance battery: the same six checks on every protocol, as scikit-learn checks every estimator.

For each protocol of :data:`~tests.conformance.protocols.PROTOCOLS` (criterion, direct shear,
biaxial, critical state, sand, relation, one calibration unit), on its smallest real case:

1. the jobs it hands the executor pickle (a worker process or a Dask worker gets them so);
2. two runs give the same result (files compared as written, times and hosts aside);
3. ``store=None`` keeps nothing: no file in the working folder, none left in the temporary folder
   (where alone a sweep may work meanwhile);
4. a run killed between two of its files, rerun into its store, gives the uninterrupted result,
   and the rerun does not redo what the killed run had kept;
5. a bad input is refused with an ``InputError`` naming its parameter, before any file is written;
6. the result read back from its file is the result.

Each protocol runs three times, once per kind of run (kept, kept nowhere, killed and resumed),
shared by its checks (:class:`Runs`). A check that does not apply to a protocol is skipped with
the reason its row gives.
"""

from __future__ import annotations

import pickle
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from poro2d.errors import InputError
from poro2d.store import Store
from tests.conformance.harness import (
    Captured,
    comparable,
    counted_writes,
    differences,
    files_under,
    inline_jobs,
)
from tests.conformance.protocols import PROTOCOLS, Context, Protocol


@dataclass
class Run:
    """One run of a protocol: its result, the store it was kept in, its files and its jobs."""

    result: Any
    root: Path | None
    written: list[str] = field(default_factory=list)
    jobs: list = field(default_factory=list)


class Runs:
    """The runs of every protocol, each made once for the session and shared by the checks."""

    def __init__(self, ctx: Context, tmp: Path) -> None:
        self.ctx = ctx
        self.tmp = tmp
        self.made: dict[tuple[str, str], Any] = {}

    def get(self, protocol: Protocol, kind: str) -> Any:
        key = (protocol.name, kind)
        if key not in self.made:
            self.made[key] = getattr(self, kind)(protocol)
        return self.made[key]

    def folder(self, protocol: Protocol, kind: str) -> Path:
        return self.tmp / protocol.name / kind

    def run(self, protocol: Protocol, out: Path | None, kill_at: int | None = None) -> Run:
        """``protocol`` run into ``out`` (None: no store), its jobs inline, its cache beside it."""
        with pytest.MonkeyPatch.context() as mp:
            mp.setenv("PORO2D_CACHE", str(self.tmp / protocol.name / "cache"))
            if protocol.setup is not None:
                protocol.setup(mp)
            with inline_jobs(mp) as jobs, counted_writes(mp, kill_at) as written:
                result = protocol.run(self.ctx, None if out is None else Store(out))
        return Run(result, out, written, jobs.seen)

    def kept(self, protocol: Protocol) -> Run:
        """The reference: an uninterrupted run kept in its store."""
        return self.run(protocol, self.folder(protocol, "kept"))

    def again(self, protocol: Protocol) -> Run:
        """A second run: with ``store=None`` where the protocol takes it, in a folder of its own
        (the working folder and the temporary folder, both empty), else into another store."""
        if "store_none" in protocol.skip:
            return self.run(protocol, self.folder(protocol, "again"))
        here = self.folder(protocol, "none")
        scratch = self.folder(protocol, "none-tmp")
        here.mkdir(parents=True)
        scratch.mkdir()
        with pytest.MonkeyPatch.context() as mp:
            mp.chdir(here)
            mp.setattr(tempfile, "tempdir", str(scratch))
            run = self.run(protocol, None)
        run.root = here
        return run

    def resumed(self, protocol: Protocol) -> tuple[Run, Run]:
        """A run killed after about half its files, then rerun into the same store: (killed, rerun)."""
        out = self.folder(protocol, "killed")
        kill_at = max(1, len(self.get(protocol, "kept").written) // 2)
        with pytest.raises(KeyboardInterrupt):
            self.run(protocol, out, kill_at)
        killed = Run(protocol.read_back(self.ctx, Store(out), self.get(protocol, "kept").result), out)
        return killed, self.run(protocol, out)


@pytest.fixture(scope="session")
def runs(specimen, tmp_path_factory) -> Runs:
    return Runs(Context(specimen), tmp_path_factory.mktemp("conformance"))


def _applies(protocol: Protocol, check: str) -> None:
    if check in protocol.skip:
        pytest.skip(protocol.skip[check])


def _same(a: Run, b: Run, protocol: Protocol) -> None:
    """Two runs' results are the same file, what says when and where aside."""
    roots = [r for r in (a.root, b.root) if r is not None]
    left = comparable(a.result, *roots, volatile=protocol.volatile)
    right = comparable(b.result, *roots, volatile=protocol.volatile)
    assert left == right, differences(left, right)[:10]


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=str)
def test_its_jobs_pickle(protocol, runs, tmp_path, monkeypatch):
    _applies(protocol, "pickle")
    if protocol.jobs is None:
        jobs = runs.get(protocol, "kept").jobs
    else:  # the jobs it hands the executor, taken before any of them runs
        with inline_jobs(monkeypatch) as seen, pytest.raises(Captured):
            seen.capture_only = True
            protocol.jobs(runs.ctx, Store(tmp_path / "jobs"))
        jobs = seen.seen
    assert jobs, "the protocol handed the executor no job"
    for job in jobs:
        back = pickle.loads(pickle.dumps(job))
        assert back.func is job.func and back.label == job.label
        assert comparable(back.args) == comparable(job.args)


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=str)
def test_two_runs_give_the_same_result(protocol, runs):
    _applies(protocol, "deterministic")
    _same(runs.get(protocol, "kept"), runs.get(protocol, "again"), protocol)


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=str)
def test_store_none_writes_nothing(protocol, runs):
    _applies(protocol, "store_none")
    run = runs.get(protocol, "again")
    scratch = run.root.with_name("none-tmp")
    # a protocol may work in a scratch folder of its own (a sweep's cases), removed at its end
    assert [f for f in run.written if not Path(f).is_relative_to(scratch)] == []
    assert files_under(run.root) == [] and files_under(scratch) == []


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=str)
def test_a_killed_run_resumes_to_the_uninterrupted_result(protocol, runs):
    _applies(protocol, "resume")
    killed, rerun = runs.get(protocol, "resumed")
    assert killed.result is None, "the run was not stopped before its result was kept"
    _same(runs.get(protocol, "kept"), rerun, protocol)


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=str)
def test_a_rerun_reads_back_what_the_killed_run_kept(protocol, runs):
    _applies(protocol, "reads_back")
    _, rerun = runs.get(protocol, "resumed")
    assert len(rerun.written) < len(runs.get(protocol, "kept").written), "the rerun did all the work again"


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=str)
def test_a_bad_input_names_its_parameter(protocol, runs, tmp_path):
    _applies(protocol, "bad_input")
    out = tmp_path / "bad"
    with pytest.raises(InputError) as refused:
        protocol.bad(runs.ctx, Store(out))
    assert refused.value.parameter == protocol.parameter, refused.value
    assert files_under(out) == []


@pytest.mark.parametrize("protocol", PROTOCOLS, ids=str)
def test_the_result_round_trips_through_its_file(protocol, runs):
    _applies(protocol, "round_trip")
    kept = runs.get(protocol, "kept")
    back = protocol.read_back(runs.ctx, Store(kept.root), kept.result)
    assert back is not None, f"no result in {protocol.result_file}"
    left, right = comparable(back, keep_all=True), comparable(kept.result, keep_all=True)
    assert left == right, differences(left, right)[:10]
