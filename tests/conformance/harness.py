"""The tricks the conformance battery plays on every protocol alike.

* Every job a protocol hands the executor is recorded and run here, in this process, from its
  pickled copy, as a worker process or a Dask worker would run it (:func:`inline_jobs`): one
  core runs the whole battery, and a kill reaches the work wherever it stands.
* A "killed" run is one that raises ``KeyboardInterrupt`` right after its store has written its
  k-th file (:func:`killed_after`): the store is the only code that keeps a run's files, so
  this stops every protocol between two of its files, where a real kill leaves it.
* Results are compared as their files hold them, with what travels beside the file (a test's
  curve) (:func:`comparable`), and with what may differ between two runs of one case taken out:
  times, hosts, process ids, the output folder's path.
"""

from __future__ import annotations

import dataclasses
import json
import pickle
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from poro2d.execute import Backend, Executor
from poro2d.store import digests

#: keys whose values say when, where or how long, never what: left out of every comparison
VOLATILE = {
    "provenance",
    "host",
    "pid",
    "hostname",
    "python",
    "time_s",
    "created",
    "started",
    "finished",
    "worker_use",
    "lent_core_s",
}
#: key endings of rates, which vary between runs of one case (durations: a key with "time" ending "_s")
VOLATILE_SUFFIXES = ("per_s", "seconds", "elapsed_s")


class Captured(Exception):  # noqa: N818 - not an error: how a capture stops the run it captured
    """Raised by the executor when only the jobs were wanted: the run ends before any job runs."""

    def __init__(self, jobs: list) -> None:
        super().__init__(f"{len(jobs)} job(s) captured")
        self.jobs = jobs


@dataclasses.dataclass
class Jobs:
    """What the executor was handed while :func:`inline_jobs` held it."""

    seen: list = dataclasses.field(default_factory=list)
    #: True: stop the run at its first map (:class:`Captured`), no job runs
    capture_only: bool = False


@contextmanager
def inline_jobs(monkeypatch) -> Iterator[Jobs]:
    """Every executor made meanwhile runs its jobs inline, each from ``pickle.loads(pickle.dumps(job))``.

    Dask and process backends are replaced by the inline one (a job's result depends on the
    job alone, so the numbers are those of any backend), which keeps the battery on one core.
    """
    jobs = Jobs()
    original_init, original_map = Executor.__init__, Executor.map

    def init(self, backend, *, client=None):
        original_init(self, Backend("inline"))

    def map_(self, batch, **kw):
        batch = list(batch)
        jobs.seen.extend(batch)
        if jobs.capture_only:
            raise Captured(batch)
        return original_map(self, [pickle.loads(pickle.dumps(job)) for job in batch], **kw)

    monkeypatch.setattr(Executor, "__init__", init)
    monkeypatch.setattr(Executor, "map", map_)
    yield jobs
    monkeypatch.setattr(Executor, "__init__", original_init)
    monkeypatch.setattr(Executor, "map", original_map)


@contextmanager
def counted_writes(monkeypatch, kill_at: int | None = None) -> Iterator[list[str]]:
    """The files the store writes meanwhile (their paths, in order); with ``kill_at``, the run is
    interrupted (``KeyboardInterrupt``) right after its ``kill_at``-th file."""
    written: list[str] = []
    original = digests.record

    def record(folder, name):
        original(folder, name)
        written.append(str(Path(folder) / name))
        if kill_at is not None and len(written) == kill_at:
            raise KeyboardInterrupt(f"killed after {written[-1]}")

    monkeypatch.setattr(digests, "record", record)
    yield written
    monkeypatch.setattr(digests, "record", original)


def files_under(folder: Path) -> list[str]:
    """Every file and folder under ``folder``, relative to it, sorted (empty when it does not exist)."""
    if not folder.exists():
        return []
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def comparable(
    value: Any, *roots: Path, volatile: frozenset[str] = frozenset(), keep_all: bool = False
) -> Any:
    """``value`` as plain JSON data to compare: a result's file (``to_dict()``), a record's fields;
    arrays as lists; times, hosts and process ids left out (``volatile``: more keys to leave out;
    ``keep_all``: nothing left out); each of ``roots`` (output folders) written ``<out>``."""
    data = json.loads(json.dumps(_plain(value, carried=not keep_all), default=str, allow_nan=True))
    if not keep_all:
        data = _strip(data, VOLATILE | volatile)
    text = json.dumps(data)
    for root in roots:
        text = text.replace(str(root), "<out>")
    return json.loads(text)


def _plain(value: Any, carried: bool = True) -> Any:
    """``value`` as lists, dicts and scalars; a result as its file, with (``carried``) what travels
    with it beside the file (its fields marked ``NOT_IN_FILE``: a test's curve) under ``~name``."""
    if hasattr(value, "to_dict"):
        out = _plain(value.to_dict(), carried)
        if carried and dataclasses.is_dataclass(value):
            for f in dataclasses.fields(value):
                if f.metadata.get("in_file", True) is False:
                    out[f"~{f.name}"] = _plain(getattr(value, f.name), carried)
        return out
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name), carried) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): _plain(v, carried) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v, carried) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _duration(key: str) -> bool:
    """Whether ``key`` names a duration or a rate (``time_total_s``, ``wall_time_s``, ``steps_per_s``)."""
    return key.endswith(VOLATILE_SUFFIXES) or ("time" in key and key.endswith("_s"))


def differences(a: Any, b: Any, where: str = "") -> list[str]:
    """Where two comparable values differ (``iterations[0].plate_steps: 30500 != 30000``)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{where}.{k}: only in one" for k in a.keys() ^ b.keys()]
        for k in a.keys() & b.keys():
            out += differences(a[k], b[k], f"{where}.{k}")
        return out
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        pairs = enumerate(zip(a, b, strict=True))
        return [d for i, (x, y) in pairs for d in differences(x, y, f"{where}[{i}]")]
    return [] if a == b else [f"{where}: {str(a)[:80]} != {str(b)[:80]}"]


def _strip(data: Any, volatile: set[str] | frozenset[str]) -> Any:
    if isinstance(data, dict):
        return {k: _strip(v, volatile) for k, v in data.items() if k not in volatile and not _duration(k)}
    if isinstance(data, list):
        return [_strip(v, volatile) for v in data]
    return data


__all__ = ["Captured", "Jobs", "comparable", "differences", "counted_writes", "files_under", "inline_jobs"]
