"""Locks on the folders poro2d writes: output folders and shared cache entries.

Two runs writing one folder at once would interleave their files, and on a cluster
several jobs share ``$PORO2D_CACHE``. Each folder poro2d writes is therefore held
through a lock file inside it (``.poro2d.lock``, an ``flock`` taken with the
``filelock`` library), released when the run ends, or by the kernel when the process
dies, so a killed run never leaves a folder locked. The lock files are removed on release.

- :func:`output_folder`: an ``--out`` folder (a run claims it through its store,
  :meth:`poro2d.store.Store.claim`). A second writer is refused at once
  (an :class:`~poro2d.errors.InputError` naming the holder's pid): its inputs may well
  differ, and waiting for hours behind a run the user forgot is worse than a clear line.
- :func:`cache_entry`: a cache entry. A second process waits, then reuses what the first
  computed: both asked for the same content, so waiting is never wasted.

Both check the folder first for symbolic links leading out of it (:func:`check_no_escape`),
so nothing poro2d writes there ends up elsewhere. An output folder also belongs to the kind
of run that made it (``criterion``, ``shear``, ``calibrate``...): a marker (``.poro2d-kind``)
written before any result says which, and a run of another kind refuses the folder on one
line before any work, rather than mixing its files with another command's. Locks are
re-entrant within a process: a run that calls another run on the same folder does not
refuse itself.
"""

from __future__ import annotations

import os
import socket
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from filelock import FileLock, Timeout

from poro2d.errors import InputError

LOCK_NAME = ".poro2d.lock"
#: who holds the lock (pid and host), for the refusal message; written once the lock is held
OWNER_NAME = ".poro2d.lock.owner"

#: the kind of run an output folder belongs to; written first, kept with the results
KIND_NAME = ".poro2d-kind"

#: folders this process holds: resolved path -> [lock, holders still inside]
_held: dict[Path, list] = {}
_guard = threading.Lock()


def is_lock_file(name: str) -> bool:
    """True for the lock's own files (and the temporaries of its owner file): never a result."""
    return (
        name in (LOCK_NAME, KIND_NAME)
        or name.startswith(OWNER_NAME)
        or name.startswith((f".{OWNER_NAME}.", f".{KIND_NAME}."))
    )


def owner_text(folder: Path) -> str:
    """'pid N on HOST' of the process holding ``folder``, as far as its owner file says."""
    try:
        pid, host = (folder / OWNER_NAME).read_text().split()[:2]
    except (OSError, ValueError):
        return "pid unknown"
    return f"pid {pid}" if host == socket.gethostname() else f"pid {pid} on {host}"


def _write_owner(folder: Path) -> None:
    from poro2d.io_utils import atomic_path

    with atomic_path(folder / OWNER_NAME, suffix="") as tmp:
        tmp.write_text(f"{os.getpid()} {socket.gethostname()}\n")


def check_no_escape(parameter: str, folder: str | os.PathLike) -> None:
    """Refuse ``folder`` if a symbolic link inside it leads outside it (or nowhere).

    poro2d writes through the paths of its output folder: ``out/trials -> /elsewhere``
    would put the trials elsewhere. ``folder`` itself may be a link (the user chose it);
    links inside that stay inside are followed as usual.
    """
    root = Path(folder)
    if not root.is_dir():
        return
    real_root = root.resolve()
    for here, dirs, files in os.walk(root, followlinks=False):
        for name in [*dirs, *files]:
            path = Path(here) / name
            if not path.is_symlink():
                continue
            target = path.resolve()
            if not target.is_relative_to(real_root):
                raise InputError(
                    parameter, str(root), "a folder whose symbolic links stay inside it",
                    f"{path} leads to {target}; poro2d would write there",
                )  # fmt: skip


#: files that only one kind of run writes at the top of its folder. A folder without a marker
#: is known by them: one written before markers existed, or one that a run keeps inside its
#: own (a calibration's criterion, the paper's shear replicates), which no command claims.
#: Every kind's files are listed here, below the packages, rather than registered by them: a
#: run must know another kind's folder even when that kind's package is not imported. Each
#: package names its kind by a ``KIND`` constant (``poro2d.shear.run.KIND``) for its claim.
#: A laboratory test's record, ``test.json``, is no sign: direct shear, biaxial and critical
#: state tests all write one; a direct shear test is known by its consolidated state instead.
KIND_SIGNS = {
    "calibrate": ("calibrated.toml",),
    "criterion": ("iterations.csv", "density.json"),
    "paper": ("paper.json", "conversions.json"),
    "shear": ("peaks.csv", "replicates.json", "consolidated.npz", "consolidation.json"),
    "strength": ("strength.json",),
    "relation": ("relation.json",),
    "sensitivity": ("sensitivity.json",),
    "sand": ("sand.json", "preflight.json"),
    "sweep": ("sweep.json",),
    "biaxial": ("biaxial.png",),
    "critical-state": ("critical_state.png", "critical_state_line.png", "series.csv"),
    "export": ("specimen.data", "specimen_yade.py", "specimen_pfc4.dat", "disks.csv"),
    "import": ("check.json",),
}

#: the store's manifest (poro2d.store.digests.MANIFEST): a folder holding one keeps a run's results
_MANIFEST = ".digests.json"


def folder_kind(folder: str | os.PathLike) -> str | None:
    """The kind of run ``folder`` belongs to (its marker), None without one."""
    try:
        return (Path(folder) / KIND_NAME).read_text().strip() or None
    except (OSError, UnicodeDecodeError):
        return None


def signed_kinds(folder: str | os.PathLike) -> list[str]:
    """The kinds of run whose own files (:data:`KIND_SIGNS`) lie at the top of ``folder``, sorted."""
    root = Path(folder)
    return sorted(k for k, names in KIND_SIGNS.items() if any((root / n).exists() for n in names))


def _a(kind: str) -> str:
    return f"an {kind}" if kind[:1] in "aeiou" else f"a {kind}"


def _mark_kind(parameter: str, folder: Path, kind: str) -> bool:
    """Mark ``folder`` as ``kind``'s, or refuse it if it belongs to another kind of run; True
    when the marker was written here.

    A folder without a marker belongs to the kind whose own files it holds (:func:`signed_kinds`),
    if any: it is marked when that is ``kind``, refused otherwise.
    """
    from poro2d.io_utils import atomic_path

    owner = folder_kind(folder)
    if owner is None:
        signed = signed_kinds(folder)
        owner = kind if not signed or kind in signed else signed[0]
        if owner == kind:
            with atomic_path(folder / KIND_NAME, suffix="") as tmp:
                tmp.write_text(kind + "\n")
            return True
    if owner != kind:
        raise InputError(
            parameter, str(folder), f"an empty folder or one of {_a(kind)} run",
            f"it holds the results of {_a(owner)} run; choose another folder",
        )  # fmt: skip
    return False


def check_no_run(parameter: str, folder: str | os.PathLike) -> None:
    """Refuse ``folder`` if it holds a run's results: for a command that writes loose files
    (figures) and keeps no folder of its own, which would otherwise replace a run's files."""
    root = Path(folder)
    owner = folder_kind(root) or next(iter(signed_kinds(root)), None)
    if owner is None and (root / _MANIFEST).is_file():
        owner = "poro2d"
    if owner is not None:
        raise InputError(
            parameter, str(root), "a folder that holds no poro2d run's results",
            f"it holds the results of {_a(owner)} run; choose another folder",
        )  # fmt: skip


@contextmanager
def output_folder(parameter: str, folder: str | os.PathLike, kind: str | None = None) -> Iterator[Path]:
    """Hold the output folder ``folder`` for the block; refuse it if another run holds it,
    or, given the run's ``kind``, if it belongs to another kind of run.

    The folder is created if needed and removed again if the block leaves nothing in it
    but the lock (a run refused for its inputs leaves no folder behind).
    """
    with _hold(parameter, Path(folder), wait=False, kind=kind) as path:
        yield path


@contextmanager
def cache_entry(folder: str | os.PathLike, parameter: str = "PORO2D_CACHE") -> Iterator[Path]:
    """Hold the cache entry ``folder`` for the block; wait while another process holds it."""
    with _hold(parameter, Path(folder), wait=True) as path:
        yield path


@contextmanager
def _hold(parameter: str, folder: Path, *, wait: bool, kind: str | None = None) -> Iterator[Path]:
    from poro2d.io_utils import check_output_dir

    check_output_dir(parameter, folder)
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    key = folder.resolve()
    with _guard:
        held = _held.get(key)
        if held is not None:  # this process holds it already: an inner run of the same folder
            held[1] += 1
    marked = False
    if held is None:
        lock = _acquire(parameter, folder, wait=wait, created=created)
        try:
            check_no_escape(parameter, folder)
            marked = kind is not None and _mark_kind(parameter, folder, kind)
            _write_owner(folder)
        except BaseException:
            _release(lock, folder, created)
            raise
        held = [lock, 1]
        with _guard:
            _held[key] = held
    try:
        yield folder
    except InputError:
        if marked:  # a run refused for its inputs leaves no mark in a folder of other files either
            (folder / KIND_NAME).unlink(missing_ok=True)
        raise
    finally:
        with _guard:
            held[1] -= 1
            last = held[1] == 0
            if last:
                del _held[key]
        if last:  # the outermost holder lets go
            _release(held[0], folder, created)


def _acquire(parameter: str, folder: Path, *, wait: bool, created: bool) -> FileLock:
    lock = FileLock(folder / LOCK_NAME, thread_local=False)
    announced = False
    while True:
        folder.mkdir(parents=True, exist_ok=True)  # again: a holder removes a folder it made empty
        try:
            lock.acquire(timeout=1.0 if announced else 0)
            return lock
        except FileNotFoundError:
            continue
        except Timeout:
            pass
        if announced:
            continue
        holder = owner_text(folder)
        if not wait:
            if created:
                _remove_if_empty(folder)
            raise InputError(
                parameter, str(folder), "a folder no other poro2d run is writing",
                f"in use by another poro2d run ({holder}); wait for it or choose another folder",
            )  # fmt: skip
        print(
            f"{folder} is in use by another poro2d run ({holder}); waiting for it",
            file=sys.stderr,
            flush=True,
        )
        announced = True


def _release(lock: FileLock, folder: Path, created: bool) -> None:
    """Release the lock and leave the folder as the run made it: no lock files in the results.

    The files are removed while the lock is still held: a process that opened the lock file
    meanwhile finds it unlinked once it gets the lock, and starts over on a new one (filelock
    checks the link count after locking).
    """
    for name in (OWNER_NAME, LOCK_NAME):
        try:
            (folder / name).unlink(missing_ok=True)
        except OSError:
            pass
    _drop_lone_kind(folder)
    lock.release()
    if created:  # a run refused for its inputs leaves no empty folder behind
        _remove_if_empty(folder)


def _drop_lone_kind(folder: Path) -> None:
    """A folder left with its kind marker alone holds no work of that kind: no marker either."""
    try:
        if [p.name for p in folder.iterdir()] == [KIND_NAME]:
            (folder / KIND_NAME).unlink()
    except OSError:
        pass


def _remove_if_empty(folder: Path) -> None:
    try:
        folder.rmdir()
    except OSError:  # not empty (another run's lock, or files), or gone
        pass


__all__ = [
    "KIND_NAME",
    "LOCK_NAME",
    "KIND_SIGNS",
    "check_no_run",
    "folder_kind",
    "signed_kinds",
    "cache_entry",
    "check_no_escape",
    "is_lock_file",
    "output_folder",
]
