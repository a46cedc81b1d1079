"""Sweeps on a two-process LocalCluster: criterion cases, worker loss, reruns, failures, config errors."""

import json
import os
import time
from pathlib import Path

import distributed
import pandas as pd
import pytest

from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.execute.dask_cluster import SINGLE_THREAD_ENV
from poro2d.execute.options import RunOptions
from poro2d.store import Store
from poro2d.store.folder import parquet_engine_available
from poro2d.sweep import SweepResult, parse_sweep, register_kind, run_sweep

QUIET = RunOptions(progress=False)

TINY = {"width": 0.05, "height": 0.025, "layers": 2}
# one trial and a short plate servo: each case takes about a second of DEM
FAST = {"max_iterations": 1, "max_plate_steps": 5000}


def probe(config: dict, store: Store) -> dict:
    """A cheap case kind: counts its runs, can fail, can kill its worker once."""
    p = config.get("probe", {})
    runs = int(store.read_text("runs.txt") or 0) + 1
    store.write_text("runs.txt", str(runs))
    marker = p.get("kill_marker")
    if marker and not Path(marker).exists():
        Path(marker).write_text(str(os.getpid()))
        os._exit(1)  # the worker process dies mid-task, as on a lost node
    if p.get("fail"):
        raise RuntimeError(f"probe failure x={p.get('x')}")
    time.sleep(p.get("seconds", 0.2))
    return {"value": 2 * p.get("x", 0), "runs": runs, "pid": os.getpid()}


register_kind("probe", probe, tables=("probe",))


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", env=SINGLE_THREAD_ENV
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def probe_cfg(xs, **extra):
    return {"sweep": {"kind": "probe", "probe": {"x": list(xs), **{k: [v] for k, v in extra.items()}}}}


def test_criterion_sweep_uses_both_workers_and_rerun_skips(client, tmp_path):
    cfg = {
        "seed": 0,
        "specimen": dict(TINY),
        "criterion": dict(FAST),
        "sweep": {
            "kind": "criterion",
            "n_lab": [0.33, 0.36, 0.39, 0.42],
            "specimen": {"friction_particle": [1.0, 3.0]},
        },
    }
    sweep = parse_sweep(cfg)
    assert len(sweep.cases) == 8 and sweep.axes == ["criterion.n_lab", "specimen.friction_particle"]
    t0 = time.perf_counter()
    res = run_sweep(sweep, Store(tmp_path), client=client, options=QUIET)
    wall = time.perf_counter() - t0
    assert [r.status for r in res.rows] == ["done"] * 8, [r.error for r in res.rows]
    # the result is sweep.json's content, typed, with the rows and the table beside the file
    assert isinstance(res, SweepResult) and res.to_dict() == json.loads((tmp_path / "sweep.json").read_text())
    assert res.status == "finished" and len(res.table) == 8 and res.failed == []
    pids = {r.pid for r in res.rows}
    assert len(pids) == 2, pids  # both worker processes ran cases
    print(
        f"\n8 criterion cases: wall {wall:.1f} s, case time {res.summary.case_time_sum_s:.1f} s, "
        f"efficiency {(res.summary.parallel_efficiency or 0):.0%}, pids {sorted(pids)}"
    )

    df = pd.read_csv(tmp_path / "results.csv")
    assert len(df) == 8
    if parquet_engine_available():  # the Parquet copy is optional (pyarrow, the parquet extra)
        assert len(pd.read_parquet(tmp_path / "results.parquet")) == 8
    for col in (
        "case_id",
        "criterion.n_lab",
        "specimen.friction_particle",
        "final_porosity",
        "converged",
        "iterations",
        "particle_count",
        "f_top_n_per_m",
        "f_bottom_n_per_m",
        "time_s",
        "error",
    ):
        assert col in df.columns, col
    assert df["error"].isna().all() and (df["particle_count"] > 0).all() and (df["iterations"] == 1).all()
    assert sorted(df["criterion.n_lab"].unique()) == [0.33, 0.36, 0.39, 0.42]
    for c in sweep.cases:
        d = tmp_path / "cases" / c.id
        assert json.loads((d / "params.json").read_text())["params"] == c.params
        assert (d / "run" / "result.json").is_file() and (d / "run" / "iterations.csv").is_file()
        assert res.case_store(c.id).has("result.json")  # the result hands out what the case wrote
    rec = json.loads((tmp_path / "sweep.json").read_text())
    assert (
        rec["status"] == "finished" and rec["summary"]["done"] == 8 and "poro2d_version" in rec["provenance"]
    )

    stamps = {c.id: (tmp_path / "cases" / c.id / "result.json").stat().st_mtime_ns for c in sweep.cases}
    again = run_sweep(parse_sweep(cfg), Store(tmp_path), client=client, options=QUIET)
    assert again.summary.ran == 0 and again.summary.reused == 8
    assert all(r.extra["reused"] for r in again.rows)
    for c in sweep.cases:
        assert (tmp_path / "cases" / c.id / "result.json").stat().st_mtime_ns == stamps[c.id]
    pd.testing.assert_series_equal(
        pd.read_csv(tmp_path / "results.csv")["final_porosity"], df["final_porosity"]
    )


def test_killed_worker_does_not_lose_the_sweep(client, tmp_path):
    marker = tmp_path / "killed.txt"
    cfg = {
        "sweep": {
            "kind": "probe",
            "cases": [
                {"probe": {"x": 1}},
                {"probe": {"x": 2, "kill_marker": str(marker)}},
                {"probe": {"x": 3}},
                {"probe": {"x": 4}},
            ],
        }
    }
    res = run_sweep(parse_sweep(cfg), Store(tmp_path / "out"), client=client, options=QUIET)
    assert marker.is_file()  # the worker really died once
    assert [r.status for r in res.rows] == ["done"] * 4
    killed = res.rows[1]
    assert killed.results["runs"] == 2  # ran again after the worker was lost
    assert killed.pid != int(marker.read_text())  # on another (or a restarted) process
    assert [r.results["value"] for r in res.rows] == [2, 4, 6, 8]


def test_interrupted_sweep_rerun_skips_finished_cases(client, tmp_path):
    out = tmp_path / "out"
    first = run_sweep(parse_sweep(probe_cfg([1, 2])), Store(out), client=client, options=QUIET)
    assert first.summary.ran == 2
    # the "interrupted" sweep finished two of four cases; the rerun runs only the rest
    full = parse_sweep(probe_cfg([1, 2, 3, 4]))
    res = run_sweep(full, Store(out), client=client, options=QUIET)
    assert res.summary.reused == 2 and res.summary.ran == 2
    assert [r.extra["reused"] for r in res.rows] == [True, True, False, False]
    for c in full.cases:  # every case ran exactly once
        assert (out / "cases" / c.id / "run" / "runs.txt").read_text() == "1"
    df = pd.read_csv(out / "results.csv")
    assert list(df["probe.x"]) == [1, 2, 3, 4] and list(df["value"]) == [2, 4, 6, 8]
    if parquet_engine_available():  # the same table, typed, where pyarrow is installed
        pq = pd.read_parquet(out / "results.parquet")
        assert list(pq["probe.x"]) == [1, 2, 3, 4] and list(pq["value"]) == [2, 4, 6, 8]


def test_failing_case_is_reported_and_others_finish(client, tmp_path):
    cfg = {
        "sweep": {
            "kind": "probe",
            "cases": [
                {"probe": {"x": 1}},
                {"probe": {"x": 2, "fail": True}},
                {"probe": {"x": 3}},
            ],
        }
    }
    sweep = parse_sweep(cfg)
    res = run_sweep(sweep, Store(tmp_path), client=client, options=QUIET)
    assert [r.status for r in res.rows] == ["done", "failed", "done"]
    bad = tmp_path / "cases" / sweep.cases[1].id
    assert "RuntimeError: probe failure x=2" in (bad / "error.txt").read_text()
    assert "Traceback" in (bad / "error.txt").read_text()
    assert not (bad / "result.json").exists()  # not marked done: a rerun tries it again
    df = pd.read_csv(tmp_path / "results.csv")
    assert df["status"].tolist() == ["done", "failed", "done"]
    assert df["error"].isna().tolist() == [True, False, True]
    assert "probe failure" in df["error"][1]
    rerun = run_sweep(sweep, Store(tmp_path), client=client, options=QUIET)
    assert rerun.summary.reused == 2 and rerun.summary.ran == 1 and rerun.summary.failed == 1


def test_cli_sweep_on_its_own_local_cluster(tmp_path):
    cfg = tmp_path / "sweep.toml"
    cfg.write_text('[sweep]\nkind = "probe"\nprobe.x = [5, 6]\nprobe.seconds = [0.0]\n')
    main(["sweep", str(cfg), "--out", str(tmp_path / "out"), "--workers", "2", "--quiet"])
    df = pd.read_csv(tmp_path / "out" / "results.csv")
    assert list(df["value"]) == [10, 12] and (df["status"] == "done").all()
    rec = json.loads((tmp_path / "out" / "sweep.json").read_text())
    assert rec["cluster"]["workers"] == 2 and rec["cluster"]["local_cluster"]


def test_case_ids_are_stable_and_names_resolve():
    base = {"specimen": dict(TINY), "criterion": dict(FAST)}
    a = parse_sweep(dict(base, sweep={"n_lab": [0.33, 0.36]}))
    b = parse_sweep(dict(base, sweep={"criterion.n_lab": [0.33, 0.36]}))
    c = parse_sweep(dict(base, sweep={"cases": [{"criterion": {"n_lab": 0.33}}, {"n_lab": 0.36}]}))
    assert [x.id for x in a.cases] == [x.id for x in b.cases] == [x.id for x in c.cases]
    assert len({x.id for x in a.cases}) == 2
    assert a.cases[0].params == {"criterion.n_lab": 0.33}
    grid = parse_sweep(dict(base, sweep={"kn_particle": [2e5, 4e5], "friction_particle": [1.0, 3.0]}))
    assert len(grid.cases) == 4
    assert grid.cases[3].config["specimen"]["kn_particle"] == 4e5


def test_thread_count_is_not_part_of_a_case_id():
    # a rerun with another thread count finds the finished cases: threads never change results
    grid = {"n_lab": [0.33, 0.36]}
    runs = [parse_sweep({"specimen": dict(TINY, threads=t), "sweep": grid}) for t in (1, 2)]
    ids = [[c.id for c in run.cases] for run in runs]
    assert ids[0] == ids[1]
    other = parse_sweep({"specimen": dict(TINY, layers=3), "sweep": {"n_lab": [0.33, 0.36]}})
    assert [c.id for c in other.cases] != ids[0]


def test_non_finite_base_values_are_input_errors():
    with pytest.raises(InputError) as ei:
        parse_sweep({"specimen": dict(TINY, growth_steps=float("inf")), "sweep": {"n_lab": [0.33]}})
    assert ei.value.parameter == "config.specimen.growth_steps"


@pytest.mark.parametrize(
    "sweep, parameter",
    [
        ({"n_lbo": [0.3]}, "sweep.n_lbo"),
        ({"specimen": {"kn_particel": [1e5]}}, "specimen.kn_particel"),
        ({"frobnicate": {"x": [1]}}, "sweep.frobnicate.x"),
        ({"n_lab": 0.33}, "sweep.n_lab"),
        ({"n_lab": []}, "sweep.n_lab"),
        ({"kind": "nope", "n_lab": [0.3]}, "sweep.kind"),
        ({"retries": -1, "n_lab": [0.3]}, "sweep.retries"),
        ({"n_lab": [0.33], "cases": [{"n_lab": 0.3}]}, "sweep.cases"),
        ({"n_lab": [0.33, 1.5]}, "criterion.n_lab"),  # the axis as the cases name it
        ({"n_lab": [0.33, 0.33]}, "sweep"),
    ],
)
def test_bad_sweep_configs_are_input_errors(sweep, parameter):
    with pytest.raises(InputError) as ei:
        parse_sweep({"specimen": dict(TINY), "sweep": sweep})
    assert ei.value.parameter == parameter


def test_bad_top_level_key_and_cli_exit_code(tmp_path, capsys):
    with pytest.raises(InputError):
        parse_sweep({"sweeep": {}, "sweep": {"n_lab": [0.3]}})
    with pytest.raises(InputError):
        parse_sweep({"specimen": {"widht": 0.05}, "sweep": {"n_lab": [0.3]}})
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[sweep]\nn_lab = [0.3]\nnlab = [0.4]\n")
    with pytest.raises(SystemExit) as ei:
        main(["sweep", str(cfg), "--out", str(tmp_path / "o")])
    assert ei.value.code == 2
    assert "sweep.nlab" in capsys.readouterr().err


def test_worker_pins_numba_threads_so_a_compile_does_not_fail(monkeypatch):
    """A worker's environment may say another NUMBA_NUM_THREADS than the one its numba started
    with (the cluster's environment is applied after start-up); numba re-reads it when it
    compiles and refuses a change once its threads run, which failed every case of a sweep
    whose kernels were not cached yet. The worker pins the variable before a case runs."""
    import numba
    from numba.core.config import reload_config
    from numba.np.ufunc.parallel import _launch_threads

    from poro2d.execute.dask_cluster import pin_numba_threads

    _launch_threads()
    running = numba.config.NUMBA_NUM_THREADS
    monkeypatch.setenv("NUMBA_NUM_THREADS", str(running % 2 + 1))  # not the running value
    with pytest.raises(RuntimeError, match="NUMBA_NUM_THREADS"):
        reload_config()
    pin_numba_threads()
    reload_config()  # what every compile does: no error now
    assert numba.config.NUMBA_NUM_THREADS == running and numba.get_num_threads() == 1
    numba.set_num_threads(running)


def test_a_case_runs_in_this_process_once_and_its_folder_binds(tmp_path):
    from dataclasses import asdict

    from poro2d.sweep.runner import compute_case, finished_row

    case = asdict(parse_sweep(probe_cfg([3], seconds=0.0)).cases[0])
    case["config"]["specimen"] = {"threads": 1}
    d = tmp_path / case["id"]
    row = compute_case(case, Store(d), probe)
    assert row.status == "done" and row.results["value"] == 6
    # read back: ran once
    again = compute_case(case, Store(d), probe)
    assert again.to_dict() == row.to_dict() == finished_row(case, Store(d)).to_dict()
    assert (d / "run" / "runs.txt").read_text() == "1"
    assert json.loads((d / "params.json").read_text()) == case
    threads = dict(case, config=dict(case["config"], specimen={"threads": 2}))
    relabelled = dict(threads, params={"x": 3}, id="same-config")
    # labels and threads are not what the case depends on
    assert finished_row(relabelled, Store(d)).to_dict() == row.to_dict()
    other = dict(case, config={"probe": {"x": 4, "seconds": 0.0}})
    assert finished_row(other, Store(d)) is None
    failed = compute_case(other, Store(d), probe)  # a case folder holding another case
    assert failed.status == "failed" and "probe.x" in failed.error


def test_without_pyarrow_the_table_is_csv_only_said_once(client, tmp_path, monkeypatch, capsys):
    """No Parquet engine: results.csv as always, no results.parquet, and one line saying why."""
    from poro2d.store import folder

    monkeypatch.setattr(folder, "parquet_engine_available", lambda: False)
    res = run_sweep(parse_sweep(probe_cfg([1, 2])), Store(tmp_path), client=client, options=QUIET)
    assert [r.status for r in res.rows] == ["done", "done"]
    assert list(pd.read_csv(tmp_path / "results.csv")["value"]) == [2, 4]
    assert not (tmp_path / "results.parquet").exists()
    err = capsys.readouterr().err
    assert err.count("pyarrow is not installed") == 1 and "poro2d[parquet]" in err


def test_a_case_moved_with_its_curve_file_finds_its_folder(tmp_path):
    """A case's merged config holds its curve file's absolute path: the same curve in another
    folder is the same case (its calibration cases were all computed again before, in the
    same cache entry); another curve is another case."""
    from dataclasses import asdict

    from poro2d.sweep.cases import Case
    from poro2d.sweep.runner import compute_case, finished_row

    rows = "size_mm,percent_passing\n1.0,0\n2.0,50\n4.0,100\n"
    files = []
    for name in ("a", "b", "c"):
        (tmp_path / name).mkdir()
        files.append(tmp_path / name / "curve.csv")
        files[-1].write_text(rows if name != "c" else rows.replace("2.0,50", "2.0,60"))
    cases = [
        Case("probe", {"x": 3}, {"probe": {"x": 3, "seconds": 0.0}, "grading": {"csv": str(f)}})
        for f in files
    ]
    assert cases[0].id == cases[1].id != cases[2].id
    folder = Store(tmp_path / "cases" / cases[0].id)
    row = compute_case(asdict(cases[0]), folder, probe)
    assert row.status == "done"
    assert finished_row(asdict(cases[1]), folder).to_dict() == row.to_dict()  # read back, not run
    assert compute_case(asdict(cases[1]), folder, probe).to_dict() == row.to_dict()
    assert (folder.root / "run" / "runs.txt").read_text() == "1"
    record = json.loads((folder.root / "params.json").read_text())
    assert record["config"]["grading"]["csv"] == str(files[0])  # the path is kept, not compared
    assert finished_row(asdict(cases[2]), folder) is None  # another curve in the same folder
    # a grading without a file is bound as before: its record is the case itself
    preset = Case("probe", {}, {"probe": {"x": 1, "seconds": 0.0}, "grading": {"preset": "paper"}})
    compute_case(asdict(preset), Store(tmp_path / "p"), probe)
    assert json.loads((tmp_path / "p" / "params.json").read_text()) == asdict(preset)
