"""Ctrl-C during ``poro2d relation``: its one line only, whenever it comes.

The signal goes to the whole process group, as a terminal's Ctrl-C does: the command and
the worker processes of its local cluster. Nothing from Dask may come before or after the
command's message (tracebacks of workers that were starting, warnings of the shutdown).
The assertions are on what is printed, not on when: under load the signal may come while
the command still imports (its message is then the plain ``interrupted``).
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import default_sigint

pytestmark = pytest.mark.scenario

SRC = Path(__file__).resolve().parents[2] / "src"


@pytest.mark.parametrize("after_s", [2.0, 5.0, 12.0])
def test_ctrl_c_prints_one_line(tmp_path, after_s):
    out = tmp_path / "rel"
    env = dict(os.environ, PYTHONPATH=str(SRC), PORO2D_CACHE=str(tmp_path / "cache"))
    cmd = [sys.executable, "-m", "poro2d.cli", "relation", "--preset", "paper", "--quick", "--workers", "1",
           "--out", str(out), "--quiet"]  # fmt: skip
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=default_sigint)  # fmt: skip
    try:
        time.sleep(after_s)
        assert proc.poll() is None, proc.communicate()  # the quick relation takes minutes
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0] in (
        "interrupted",
        f"interrupted: finished cases are kept in {out}; rerun the same command to resume",
    )
