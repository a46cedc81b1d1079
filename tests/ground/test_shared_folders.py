"""Shared folders and caches: locks, temporaries, links out of --out, foreign inputs, faults.

The fault tests run real commands in separate processes on tiny specimens (a 0.05 m x
0.025 m box of 2 layers): two relations on one fresh cache, two criteria into one folder,
and a relation killed at seeded random moments and run again. Each compares its results
with an undisturbed run.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from poro2d.cli import main
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.locks import LOCK_NAME, cache_entry, check_no_escape, output_folder

SRC = Path(__file__).resolve().parents[2] / "src"
TINY_SPECIMEN = "seed = 0\n[specimen]\nwidth = 0.05\nheight = 0.025\nlayers = 2\n"
# a box this small cannot rest the lid of the fill acceptance: the paper's plate (docs/criterion.md)
TINY_RELATION = (
    TINY_SPECIMEN
    + '[criterion]\nacceptance = "plate"\n'
    + "[relation]\nn_max = 0.4571\nn_min = 0.3253\nmu_prep = [0.0, 0.3]\n"
)
RELATION_ARGS = ["--points", "2", "--seeds", "1", "--workers", "1", "--quiet"]
#: what differs between two runs of the same inputs: when and where they ran
RUN_RECORDS = ("provenance", "sweeps", "time_total_s", "time_prepare_s", "time_plate_s")


def _env(cache: Path | None = None) -> dict:
    env = dict(os.environ, PYTHONPATH=str(SRC))
    if cache is not None:
        env["PORO2D_CACHE"] = str(cache)
    return env


def _poro2d(*args, env: dict, **kw) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "poro2d.cli", *map(str, args)]
    return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def _relation(cfg: Path, out: Path, env: dict, **kw) -> subprocess.Popen:
    return _poro2d("relation", "--config", cfg, *RELATION_ARGS, "--out", out, env=env, **kw)


def _finish(proc: subprocess.Popen, timeout: float = 300) -> tuple[int, str]:
    try:
        _, err = proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return proc.returncode, err


def _wait_for(path: Path, proc: subprocess.Popen, timeout: float = 120) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, f"{path} never appeared"
        time.sleep(0.05)


def _without_run_records(data):
    """A result without the records of when and where it ran, at every depth."""
    if isinstance(data, dict):
        return {k: _without_run_records(v) for k, v in data.items() if k not in RUN_RECORDS}
    if isinstance(data, list):
        return [_without_run_records(v) for v in data]
    return data


def _result(path: Path) -> dict:
    return _without_run_records(json.loads(path.read_text()))


def _lock_files(*folders: Path) -> list[Path]:
    return [p for f in folders for p in f.rglob(".poro2d.lock*")]


# ----------------------------------------------------------------------------- the lock helper
_HOLDER = """
import sys, time
from pathlib import Path
from poro2d.locks import {kind}

folder, held, done = map(Path, sys.argv[1:4])
with {kind}(*{args}):
    held.touch()
    while not (folder.parent / "release").exists():
        time.sleep(0.02)
    done.touch()  # written last while holding: a waiter must see it once it gets the lock
"""


def _holder(kind: str, args: str, folder: Path, tmp_path: Path) -> subprocess.Popen:
    code = _HOLDER.format(kind=kind, args=args)
    cmd = [sys.executable, "-c", code, str(folder), str(tmp_path / "held"), str(tmp_path / "done")]
    proc = subprocess.Popen(cmd, env=_env())
    _wait_for(tmp_path / "held", proc)
    return proc


def test_a_second_writer_of_an_output_folder_is_refused_on_one_line(tmp_path):
    folder = tmp_path / "out"
    proc = _holder("output_folder", "('--out', sys.argv[1])", folder, tmp_path)
    try:
        with pytest.raises(InputError) as e, output_folder("--out", folder):
            pass
        msg = str(e.value)
        assert f"pid {proc.pid}" in msg and "in use by another poro2d run" in msg and "\n" not in msg
    finally:
        (tmp_path / "release").touch()
        assert proc.wait(60) == 0
    with output_folder("--out", folder):  # free again
        with output_folder("--out", folder):  # re-entrant: an inner run of the same folder
            pass
        assert (folder / LOCK_NAME).is_file()  # still held once the inner run is done
    assert not (folder / LOCK_NAME).exists()  # no lock file among the results


def test_a_folder_made_for_a_refused_run_is_removed(tmp_path):
    with pytest.raises(InputError), output_folder("--out", tmp_path / "new"):
        raise InputError("--seed", -1, "an integer >= 0")
    assert not (tmp_path / "new").exists()


def test_a_cache_entry_held_elsewhere_is_waited_for(tmp_path):
    folder = tmp_path / "entry"
    proc = _holder("cache_entry", "(sys.argv[1],)", folder, tmp_path)
    try:
        (tmp_path / "release").touch()
        with cache_entry(folder):
            assert (tmp_path / "done").is_file()  # the holder finished before this got the entry
    finally:
        assert proc.wait(60) == 0


_CASE = {"id": "c1", "kind": "probe", "params": {}, "config": {"x": 1}}
_CASE_HOLDER = """
import json, sys, time
from pathlib import Path
from poro2d.io_utils import write_json
from poro2d.locks import cache_entry
from poro2d.store import Store
from poro2d.sweep.runner import RESULT, case_stage

folder, held = Path(sys.argv[1]), Path(sys.argv[2])
case = json.loads(sys.argv[3])
with cache_entry(folder, parameter="case folder"):  # a worker of a killed sweep, still running the case
    held.touch()
    time.sleep(1.0)  # computing
    case_stage(case, Store(folder)).bind()
    write_json(folder / RESULT, {"case_id": "c1", "status": "done", "results": {"by": "the first worker"}})
"""


def test_a_case_still_running_elsewhere_is_waited_for_and_read_back(tmp_path):
    from poro2d.store import Store
    from poro2d.sweep.runner import compute_case

    folder = tmp_path / "cases" / "c1"
    cmd = [sys.executable, "-c", _CASE_HOLDER, str(folder), str(tmp_path / "held"), json.dumps(_CASE)]
    proc = subprocess.Popen(cmd, env=_env())
    try:
        _wait_for(tmp_path / "held", proc)
        row = compute_case(_CASE, Store(folder), lambda config, store: {"by": "a second worker"})
    finally:
        assert proc.wait(60) == 0
    assert row.results == {"by": "the first worker"}


def test_links_leading_out_of_the_output_folder_are_refused(tmp_path, capsys):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "trials").symlink_to(elsewhere)
    with pytest.raises(SystemExit) as e:
        main(["criterion", "--preset", "paper", "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert e.value.code == 2 and len(err.splitlines()) == 1
    assert "trials" in err and str(elsewhere) in err
    assert list(elsewhere.iterdir()) == [] and sorted(p.name for p in out.iterdir()) == ["trials"]


def test_links_inside_the_folder_and_a_linked_folder_are_fine(tmp_path):
    real = tmp_path / "real"
    (real / "a").mkdir(parents=True)
    (real / "b").symlink_to(real / "a")
    (tmp_path / "link").symlink_to(real)
    check_no_escape("--out", tmp_path / "link")
    (real / "c").symlink_to(tmp_path / "missing")  # a dangling link out of it
    with pytest.raises(InputError, match="missing"):
        check_no_escape("--out", tmp_path / "link")


# ------------------------------------------------------------------------- foreign input files
def _refused(argv, capsys) -> str:
    with pytest.raises(SystemExit) as e:
        main(argv)
    err = capsys.readouterr().err.strip()
    assert e.value.code == 2 and len(err.splitlines()) == 1, err
    return err


def _limited_memory() -> None:
    # a file read without end fails fast here instead of filling the machine's memory
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))


def _refused_elsewhere(*args) -> str:
    """Run poro2d in a process of limited memory and time; its one-line refusal (exit 2)."""
    cmd = [sys.executable, "-m", "poro2d.cli", *map(str, args)]
    run = subprocess.run(
        cmd, env=_env(), capture_output=True, text=True, timeout=120, preexec_fn=_limited_memory
    )
    err = run.stderr.strip()
    assert run.returncode == 2 and len(err.splitlines()) == 1, err
    return err


def test_devices_and_fifos_are_refused_before_reading(tmp_path):
    cfg = tmp_path / "g.toml"
    cfg.write_text('[grading]\ncsv = "/dev/zero"\n')
    err = _refused_elsewhere("criterion", "--config", cfg, "--out", tmp_path / "c")
    assert "/dev/zero" in err and "character device" in err and "64 MiB" in err
    err = _refused_elsewhere("import", "/dev/zero", "--out", tmp_path / "i")
    assert "/dev/zero" in err and "character device" in err
    fifo = tmp_path / "grading.csv"
    os.mkfifo(fifo)  # reading it would wait for a writer forever
    cfg.write_text(f'[grading]\ncsv = "{fifo}"\n')
    err = _refused_elsewhere("criterion", "--config", cfg, "--out", tmp_path / "f")
    assert "FIFO" in err
    assert not any((tmp_path / name).exists() for name in ("c", "i", "f"))


def test_a_huge_input_is_refused_before_reading(tmp_path, capsys):
    huge = tmp_path / "huge.toml"
    with open(huge, "wb") as fh:  # sparse: 65 MiB that take no room
        fh.truncate(65 * 2**20)
    err = _refused(["criterion", "--config", str(huge), "--out", str(tmp_path / "h")], capsys)
    assert "68,157,440 bytes" in err and "64 MiB" in err and not (tmp_path / "h").exists()


# --------------------------------------------------------------------------------- dashboard
def test_the_local_dashboard_listens_on_this_machine_only(monkeypatch):
    import distributed

    from poro2d.execute import cluster_options, dask_cluster

    seen = {}

    class FakeCluster:
        def __init__(self, **kw):
            seen.update(kw)

    monkeypatch.setattr(distributed, "LocalCluster", FakeCluster)
    monkeypatch.setattr(distributed, "Client", lambda cluster: None)
    dask_cluster.start_client(None, 1, 1)
    assert seen["dashboard_address"] == "127.0.0.1:0" and seen["scheduler_kwargs"] == {"dashboard": True}
    dask_cluster.start_client(None, 1, 1, dashboard=None)  # no dashboard: its web server stays local
    assert seen["dashboard_address"] == "127.0.0.1:0" and seen["scheduler_kwargs"] == {"dashboard": False}
    assert cluster_options.check_dashboard(None) == "127.0.0.1:0"
    free = _free_port()
    assert cluster_options.check_dashboard(f"0.0.0.0:{free}") == f"0.0.0.0:{free}"
    assert cluster_options.check_dashboard("none") is None
    for bad in ("8787", "host:port", "a b:1", "h:70000"):
        with pytest.raises(InputError, match="--dashboard"):
            cluster_options.check_dashboard(bad)


def _free_port() -> int:
    """A port no one listens on now (the system's pick, released)."""
    import socket

    with socket.socket() as s:
        s.bind(("0.0.0.0", 0))
        return s.getsockname()[1]


def test_a_bad_dashboard_address_is_refused_before_any_work(tmp_path, capsys):
    err = _refused(["relation", "--preset", "paper", "--dashboard", "nowhere", "--out", str(tmp_path / "r")],
                   capsys)  # fmt: skip
    assert "--dashboard" in err and not (tmp_path / "r").exists()


# ------------------------------------------------------- criteria: one folder, export of a refusal
@pytest.fixture(scope="module")
def criterion_reference(tmp_path_factory):
    """One undisturbed criterion run of the tiny specimen, in this process: only the run it is
    compared with needs a process of its own (its lock is what the second run meets)."""
    tmp = tmp_path_factory.mktemp("reference")
    cfg = tmp / "tiny.toml"
    cfg.write_text(TINY_SPECIMEN)
    main(["criterion", "--config", str(cfg), "--out", str(tmp / "crit"), "--quiet"])  # raises on failure
    return cfg, tmp / "crit"


def test_two_criteria_into_one_folder(criterion_reference, tmp_path, capsys):
    cfg, reference = criterion_reference
    out = tmp_path / "crit"
    first = _poro2d("criterion", "--config", cfg, "--out", out, "--quiet", env=_env())
    try:
        _wait_for(out / LOCK_NAME, first)
        # the second one, here (no start-up to wait for, so the first is surely still running)
        err = _refused(["criterion", "--config", str(cfg), "--out", str(out), "--quiet"], capsys)
        assert "in use by another poro2d run" in err and f"pid {first.pid}" in err
    finally:
        rc, err = _finish(first)
    assert rc == 0, err
    assert _result(out / "result.json") == _result(reference / "result.json")
    digest = checkpoint.state_digest
    assert digest(out / "specimen.npz") == digest(reference / "specimen.npz")
    assert _lock_files(out) == []


@pytest.mark.parametrize("change", ["unconverged", "no accepted trial"])
def test_export_refuses_a_specimen_the_criterion_did_not_accept(
    criterion_reference, tmp_path, change, capsys
):
    _, reference = criterion_reference
    crit = tmp_path / "crit"
    shutil.copytree(reference, crit)
    result = json.loads((crit / "result.json").read_text())
    if change == "unconverged":
        result["converged"] = False
    else:
        for row in result["iterations"]:
            row["accepted"] = False
    (crit / "result.json").write_text(json.dumps(result))
    err = _refused(["export", str(crit), "--to", "lammps", "--out", str(tmp_path / "lmp")], capsys)
    assert "result.json" in err and "changed since poro2d wrote it" in err  # edited by hand: not trusted
    (crit / ".digests.json").unlink()  # as an earlier version (no manifest) would have written it
    for specimen in (crit, crit / "specimen.npz"):
        err = _refused(["export", str(specimen), "--to", "lammps", "--out", str(tmp_path / "lmp")], capsys)
        assert "SPECIMEN" in err and ("converged = False" in err or "no accepted trial" in err)
        assert not (tmp_path / "lmp").exists()
    main(["export", str(reference), "--to", "csv", "--out", str(tmp_path / "ok")])  # the accepted one leaves


def test_export_refuses_a_rejected_trial(criterion_reference, tmp_path, capsys):
    _, reference = criterion_reference
    trials = sorted((reference / "trials").iterdir())
    rejected = next(t for t in trials if not json.loads((t / "trial.json").read_text())["accepted"])
    err = _refused(["export", str(rejected / "prepared.npz"), "--to", "csv", "--out", str(tmp_path / "x")],
                   capsys)  # fmt: skip
    assert "trial.json says accepted = False" in err and not (tmp_path / "x").exists()
    accepted = next(t for t in trials if json.loads((t / "trial.json").read_text())["accepted"])
    main(["export", str(accepted / "prepared.npz"), "--to", "csv", "--out", str(tmp_path / "ok")])
    assert (tmp_path / "ok" / "disks.csv").is_file()
    assert (tmp_path / "ok" / "disks.csv").is_file()


# ------------------------------------------------------------------------ relations: one cache
@pytest.fixture(scope="module")
def two_relations(tmp_path_factory):
    """Two relations started together on one fresh cache (the undisturbed reference of the kill test)."""
    tmp = tmp_path_factory.mktemp("relations")
    cfg = tmp / "tiny.toml"
    cfg.write_text(TINY_RELATION)
    env = _env(tmp / "cache")
    procs = [_relation(cfg, tmp / f"r{k}", env) for k in (1, 2)]
    ends = [_finish(p) for p in procs]
    return tmp, cfg, ends


@pytest.mark.scenario
def test_two_relations_on_one_fresh_cache(two_relations):
    tmp, _, ends = two_relations
    for rc, err in ends:
        assert rc == 0 and "Traceback" not in err, err
    first, second = (_result(tmp / f"r{k}" / "relation.json") for k in (1, 2))
    assert first == second and first["points"]
    # one of them computed the calibration; the other waited for it and read it back
    records = [json.loads((tmp / f"r{k}" / "calibration.json").read_text()) for k in (1, 2)]
    assert sorted(r["source"] for r in records) == ["cache", "computed"]
    assert sum(r["ran"] for r in records) == records[0]["ran"] + records[0]["reused"]
    assert _lock_files(tmp) == []


def _count(folder: Path, name: str) -> int:
    return sum(1 for _ in folder.rglob(name)) if folder.exists() else 0


def _kill_at(proc: subprocess.Popen, stage: str, delay: float, folders: list[Path], *, group: bool) -> None:
    """SIGKILL the run ``delay`` s after it reaches ``stage``: a case started (a new
    params.json) or a case finished (a new result.json). ``group``: the whole run, its
    cluster's workers with it, as when a job is killed; else the command alone, whose
    workers may go on with the cases they hold."""
    name = "params.json" if stage == "case started" else "result.json"
    before = sum(_count(f, name) for f in folders)
    deadline = time.monotonic() + 120
    while sum(_count(f, name) for f in folders) == before and proc.poll() is None:
        assert time.monotonic() < deadline, f"no {stage} within 120 s"
        time.sleep(0.05)
    time.sleep(delay)
    try:
        os.killpg(proc.pid, signal.SIGKILL) if group else proc.kill()
    except ProcessLookupError:
        pass
    proc.communicate()


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except ProcessLookupError:
        pass


@pytest.mark.scenario
def test_a_relation_killed_at_random_moments_resumes_to_the_same_result(two_relations, tmp_path):
    reference_dir, cfg, _ = two_relations
    env = _env(tmp_path / "cache")
    out = tmp_path / "rel"
    rng = random.Random(23)
    groups = []
    try:
        for group in (False, True):
            stage, delay = rng.choice(["case started", "case finished"]), rng.uniform(0.0, 1.5)
            proc = _relation(cfg, out, env, start_new_session=True)
            groups.append(proc.pid)
            _kill_at(proc, stage, delay, [out, tmp_path / "cache"], group=group)
            assert not (out / "relation.json").exists(), f"it ended before the kill ({stage} + {delay:.2f} s)"
        rc, err = _finish(_relation(cfg, out, env))
    finally:
        for pgid in groups:  # workers left by the command killed alone
            _kill_group(pgid)
    assert rc == 0 and "Traceback" not in err, err
    assert _result(out / "relation.json") == _result(reference_dir / "r1" / "relation.json")
    assert _lock_files(out, tmp_path / "cache") == []
    cases = list((tmp_path / "cache").rglob("params.json"))
    assert cases and all((c.parent / "result.json").is_file() for c in cases)  # every case finished


# ------------------------------------------------------- a folder belongs to one kind of run
def test_a_folder_of_another_kind_of_run_is_refused_before_any_work(tmp_path):
    from poro2d.locks import KIND_NAME, folder_kind, output_folder

    out = tmp_path / "out"
    with output_folder("--out", out, kind="criterion"):
        (out / "result.json").write_text("{}")
    assert folder_kind(out) == "criterion"
    with output_folder("--out", out, kind="criterion"):  # the same kind: resumes
        pass
    with pytest.raises(InputError, match="holds the results of a criterion run") as e:
        with output_folder("--out", out, kind="calibrate"):
            raise AssertionError("no work may start")
    assert e.value.parameter == "--out"
    assert sorted(p.name for p in out.iterdir()) == sorted([KIND_NAME, "result.json"])


def test_a_run_that_wrote_nothing_leaves_no_kind_behind(tmp_path):
    from poro2d.locks import output_folder

    empty = tmp_path / "given"
    empty.mkdir()
    with output_folder("--out", empty, kind="shear"):
        pass
    assert list(empty.iterdir()) == []  # a later run of any kind may use it
    with output_folder("--out", tmp_path / "new", kind="shear"):
        pass
    assert not (tmp_path / "new").exists()
