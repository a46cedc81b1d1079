"""The executor's local backends (the shear tests, the replicates): job order, errors, messages, Ctrl-C."""

import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from poro2d import progress
from poro2d.errors import InputError
from poro2d.execute import Backend, Executor, Failed, Job, JobsFailed, RunOptions, results_or_raise
from tests.conftest import default_sigint

SRC = Path(__file__).resolve().parents[2] / "src"


def map_local(func, args, processes, **kw):
    """``func(arg, report)`` for every argument on ``processes`` local processes; the outcomes."""
    jobs = [Job(func, (a,), str(a), reports=True) for a in args]
    return Executor(Backend.local(processes)).map(jobs, **kw)


def square_late_first(job: int, report) -> tuple:
    """A job whose result depends on the job alone; the first jobs end last."""
    report("working", job / 10)
    time.sleep(0.05 * (4 - job))
    return job, job * job, os.getpid()


def fail_on_odd(job: int, report) -> int:
    if job == 3:
        raise InputError("--thing", 3, "an even number")
    if job % 2:
        raise ValueError(f"odd job {job}")
    return job


@pytest.mark.parametrize("processes", [1, 2, 3])
def test_results_come_in_job_order_whatever_the_process_count(processes):
    jobs = [0, 1, 2, 3]
    ended, messages = [], []
    results = map_local(
        square_late_first, jobs, processes, start_first=lambda j: -j.args[0],
        on_report=lambda i, *msg: messages.append((i, *msg)), on_done=lambda i, res: ended.append(i),
    )  # fmt: skip
    assert [r[:2] for r in results] == [(0, 0), (1, 1), (2, 4), (3, 9)]
    assert sorted(ended) == jobs
    assert sorted(messages) == [(j, "working", j / 10) for j in jobs]  # every job's message, tagged
    in_this_process = {r[2] for r in results} == {os.getpid()}
    assert in_this_process == (processes == 1)


@pytest.mark.parametrize("processes", [1, 2])
def test_failing_jobs_are_values_named_with_their_errors_after_every_job_ran(processes):
    ended = []
    jobs = [Job(fail_on_odd, (j,), name, reports=True) for j, name in zip([0, 1, 2, 5], "abcd", strict=True)]
    outcomes = Executor(Backend.local(processes)).map(jobs, on_done=lambda i, res: ended.append(i))
    assert sorted(ended) == [0, 1, 2, 3]  # every job ends, failed or not
    assert [o for o in outcomes if not isinstance(o, Failed)] == [0, 2]
    failed = [(o.label, str(o.error)) for o in outcomes if isinstance(o, Failed)]
    assert failed == [("b", "odd job 1"), ("d", "odd job 5")]
    with pytest.raises(JobsFailed) as err:
        results_or_raise(outcomes, "toy job(s)")
    assert str(err.value) == "2 toy job(s) failed: b: odd job 1; d: odd job 5"


def test_the_dask_backend_gives_the_same_outcomes_in_job_order():
    import distributed

    ended = []
    jobs = [Job(fail_on_odd, (j,), name, reports=True) for j, name in zip([0, 1, 2, 5], "abcd", strict=True)]
    with distributed.Client(
        processes=False, n_workers=1, threads_per_worker=2, dashboard_address=":0"
    ) as client:
        executor = Executor(Backend.dask(), client=client)
        outcomes = executor.map(jobs, on_done=lambda i, res: ended.append(i))
        assert executor.cluster_info().workers == 1 and not executor.cluster_info().local_cluster
        executor.close()  # a given client stays open
        assert client.status == "running"
    assert sorted(ended) == [0, 1, 2, 3]
    assert outcomes[0] == 0 and outcomes[2] == 2
    assert [(o.label, str(o.error)) for o in (outcomes[1], outcomes[3])] == [
        ("b", "odd job 1"),
        ("d", "odd job 5"),
    ]


def test_an_input_error_of_a_job_is_raised_as_it_is():
    with pytest.raises(InputError, match="--thing"):
        results_or_raise(map_local(fail_on_odd, [1, 3, 0], 2))


def test_one_message_per_phase_and_interval(monkeypatch):
    def chatty(job, report):
        for k in range(5):
            report("phase one", k / 5)
        report("phase two", 0.0)
        return job

    seen = []
    map_local(chatty, [7], 1, on_report=lambda i, *msg: seen.append(msg))
    assert seen == [("phase one", 0.0), ("phase two", 0.0)]


def test_jobs_progress_line_in_a_log(capsys):
    with progress.JobsProgress("direct shear", ["50 kPa", "100 kPa", "200 kPa"]) as bars:
        bars.update(0, "shearing", 0.42)
        bars.update(1, "consolidating")
        assert capsys.readouterr().err == ""  # less than an interval since the start
    (line,) = capsys.readouterr().err.splitlines()
    assert re.match(
        r"^direct shear: 50 kPa shearing 42 %, 100 kPa consolidating, 200 kPa waiting, elapsed [\d:]+$",
        line,
    )
    with progress.JobsProgress("direct shear", ["50 kPa", "100 kPa"]) as bars:
        bars.done(0)  # a job's end is written at once
        assert capsys.readouterr().err.startswith("direct shear: 50 kPa done, 100 kPa waiting, elapsed ")
    assert capsys.readouterr().err == ""  # nothing new at the end: no second line
    with progress.JobsProgress("direct shear", ["50 kPa"], enabled=False) as bars:
        bars.done(0)
    assert capsys.readouterr().err == ""


def test_progress_lines_share_one_format():
    assert progress.progress_line("sweep", ["3/10 cases (30 %)", "1 failed"], 760.0, 1773.0) == (
        "sweep: 3/10 cases (30 %), 1 failed, elapsed 0:12:40, eta 0:29:33"
    )
    assert progress.progress_line("drop", ["5 steps"], 3.0) == "drop: 5 steps, elapsed 0:00:03"


SLEEPER = """
    import sys, time
    from pathlib import Path
    from poro2d.execute import Backend, Executor, Job

    def sleep_long(path):
        Path(path).write_text("started")
        time.sleep(120)

    if __name__ == "__main__":
        try:
            jobs = [Job(sleep_long, (sys.argv[1] + "/" + name,), name) for name in "abc"]
            Executor(Backend.local(2)).map(jobs)
        except KeyboardInterrupt:
            print("interrupted", file=sys.stderr)
            sys.exit(130)
"""


def test_ctrl_c_ends_the_workers_and_starts_no_more_jobs(tmp_path):
    script = tmp_path / "sleeper.py"
    script.write_text(textwrap.dedent(SLEEPER))
    env = dict(os.environ, PYTHONPATH=str(SRC))
    proc = subprocess.Popen([sys.executable, str(script), str(tmp_path)], env=env, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, preexec_fn=default_sigint)  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not ((tmp_path / "a").exists() and (tmp_path / "b").exists()):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < deadline, "the jobs did not start"
            time.sleep(0.1)
        os.killpg(proc.pid, signal.SIGINT)  # what a Ctrl-C at a terminal does: the whole group
        _, err = proc.communicate(timeout=60)  # the jobs would sleep for minutes
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130 and err.strip() == "interrupted", err  # no worker's traceback
    assert not (tmp_path / "c").exists()  # the job not started stays so


# ------------------------------------------------------------------ RunOptions
@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"workers": 0}, "--workers"),
        ({"workers": 2.5}, "--workers"),
        ({"workers": 2, "scheduler": "tcp://127.0.0.1:8786"}, "--workers"),
        ({"scheduler": "http://host"}, "--scheduler"),
        ({"progress": None}, "progress"),
    ],
)
def test_run_options_refuse_bad_values_naming_them(kw, name):
    with pytest.raises(InputError, match=re.escape(name)):
        RunOptions(**kw)


def test_run_options_default_to_one_process_per_job_up_to_the_cores():
    cores = os.cpu_count() or 1
    assert RunOptions().local_workers(1) == 1 and RunOptions().local_workers(0) == 1
    assert RunOptions().local_workers(100) == cores
    assert RunOptions().local_workers(100, per_core=2) == 2 * cores
    assert RunOptions(workers=1).local_workers(100) == 1
    assert RunOptions(workers=1).test_backend(1).kind == "inline"
    assert RunOptions(scheduler="tcp://127.0.0.1:8786").test_backend(1).kind == "dask"


def test_a_laboratory_tests_jobs_run_on_a_running_scheduler_as_on_this_machine():
    """complete_jobs (the tests' batch) sends its jobs to ``options.scheduler`` when given: the
    same results, in job order, as one after the other here."""
    import distributed

    from poro2d.execute.batch import complete_jobs

    def jobs():
        return [Job(square_late_first, (j,), f"job {j}", reports=True) for j in (3, 1, 2)]

    here = complete_jobs(jobs(), title="t", what="job(s)", options=RunOptions(workers=1, progress=False),
                         workers=1)  # fmt: skip
    with distributed.LocalCluster(
        processes=False, n_workers=1, threads_per_worker=1, protocol="tcp", dashboard_address=None
    ) as cluster:
        there = complete_jobs(jobs(), title="t", what="job(s)", workers=1,
                              options=RunOptions(scheduler=cluster.scheduler_address,
                                                 progress=False))  # fmt: skip
    assert [r[:2] for r in there] == [r[:2] for r in here] == [(3, 9), (1, 1), (2, 4)]
