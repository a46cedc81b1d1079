"""Running the exported YADE script in YADE and reading what it printed.

YADE is not a dependency of poro2d: the ``yade`` executable comes from the operating system
(Debian's package: ``apt-get install yade``), from ``$YADE_EXE`` or from the PATH. It runs
headless with ``-n`` (no window) and ``-x`` (exit when the script ends); a script that
raises makes it exit with a non-zero code.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import time
from pathlib import Path

from poro2d.interop import yade
from poro2d.interop.settled import RESULT_TAG, RestCase, SettledRun, result_numbers


class YadeError(RuntimeError):
    """YADE stopped with an error, or printed no result line."""


class YadeNotFound(YadeError, FileNotFoundError):
    """No YADE executable on this machine."""


def find_yade() -> str:
    """Path of the ``yade`` executable (``$YADE_EXE`` or the PATH)."""
    exe = os.environ.get("YADE_EXE") or shutil.which("yade")
    if not exe:
        raise YadeNotFound("no YADE executable: apt-get install yade (Debian), or set YADE_EXE")
    return exe


def yade_env(threads: int = 1) -> dict[str, str]:
    """Environment of the child process: YADE runs on the system's Python, so this
    process's module paths (a virtual environment, a source tree) are kept away from it."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["OMP_NUM_THREADS"] = str(max(1, int(threads)))
    return env


def execute_script(workdir: str | os.PathLike, settings: dict | None = None, timeout: float = 3600.0) -> str:
    """Run ``yade -n -x specimen_yade.py key=value ...`` in ``workdir``; returns its output.

    ``settings`` override the script's stop settings (ratio, max_steps, check_every).
    A non-zero exit or a missing result line raises :class:`YadeError`.
    """
    args = [f"{k}={v!r}" for k, v in (settings or {}).items()]
    cmd = [find_yade(), "-n", "-x", yade.SCRIPT_FILE, *args]
    proc = subprocess.run(cmd, cwd=workdir, env=yade_env(), capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0 or RESULT_TAG not in proc.stdout:
        tail = (proc.stderr.strip() or proc.stdout.strip())[-2000:]
        raise YadeError(f"YADE failed (rc={proc.returncode}): {tail}")
    return proc.stdout


def version_from_output(output: str) -> str:
    """YADE's version from its greeting (``Welcome to Yade 2023.02a``)."""
    m = re.search(r"Welcome to Yade (\S+)", output)
    return m.group(1) if m else "unknown"


def settle_yade(case: RestCase, workdir: str | os.PathLike) -> SettledRun:
    """YADE on the exported script in ``workdir``, run as written but for the stop settings.

    ``case.ratio`` is YADE's own measure of rest (``utils.unbalancedForce()``: the mean
    unbalanced force over the mean contact force).
    """
    yade.write_specimen(case.spec, workdir, ratio=case.ratio, max_steps=case.max_steps)
    t0 = time.perf_counter()
    output = execute_script(workdir)
    res = result_numbers(output, YadeError, "YADE's output")
    return SettledRun(
        f_top_n_per_m=res["f_top_n_per_m"],
        f_bottom_n_per_m=res["f_bottom_n_per_m"],
        side_friction_up_n_per_m=res["side_friction_up_n_per_m"],
        unbalanced_force=res["unbalanced_force"],
        steps=int(res["steps"]),
        converged=res["unbalanced_force"] < case.ratio,
        seconds=time.perf_counter() - t0,
        yade_version=version_from_output(output),
        workdir=str(Path(workdir)),
    )
