"""Atomic writes and result metadata shared by every layer."""

from __future__ import annotations

import csv
import json
import math
import os
import platform
import socket
import stat
import tempfile
import time
from collections.abc import Iterable, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from poro2d import __version__
from poro2d.json_types import as_json, json_value, to_json_types
from poro2d.typed_result import TypedResult


@contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None):
    """Yield a temporary path next to ``path``; rename it onto ``path`` on success.

    A crash leaves no file that looks complete: the final name only appears once
    the content is fully written. Temporaries of ``path`` left by a killed earlier
    write are removed first (never one whose writer still runs, see
    :func:`remove_stale_temporaries`), and the file gets the permissions of an ordinary
    new file (0666 less the umask), not the 0600 of a temporary.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    suffix = suffix if suffix is not None else path.suffix
    remove_stale_temporaries(path, suffix)
    fd, tmp = tempfile.mkstemp(prefix=_temp_prefix(path) + _writer_tag(), suffix=suffix, dir=path.parent)
    try:
        # results often go to shared folders: others must be able to read them
        os.fchmod(fd, 0o666 & ~current_umask())
    finally:
        os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


#: a temporary whose writer cannot be checked (another host, or an unnamed writer) is
#: taken for a leftover once it has not changed for this long (seconds)
FOREIGN_TEMPORARY_AGE = 24 * 3600.0


def _temp_prefix(path: Path) -> str:
    return f".{path.name}."


def _host_tag() -> str:
    """This host's name with every character but letters, digits and ``_`` as ``_``."""
    return "".join(c if c.isalnum() or c == "_" else "_" for c in socket.gethostname()) or "_"


def _writer_tag() -> str:
    """``<pid>-<host>-``: who writes a temporary, so that no other process removes it while it runs."""
    return f"{os.getpid()}-{_host_tag()}-"


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    except (OverflowError, ValueError):
        return False
    return True


def _is_leftover(entry: Path, middle: str) -> bool:
    """Whether the temporary ``entry`` (``middle``: between prefix and suffix) was left by a dead writer."""
    parts = middle.split("-")
    if len(parts) == 3 and parts[0].isdigit() and parts[1] == _host_tag():
        return not _pid_alive(int(parts[0]))
    try:  # another host's writer, or a name without one: only when long untouched
        return time.time() - entry.stat().st_mtime > FOREIGN_TEMPORARY_AGE
    except OSError:
        return False


def remove_stale_temporaries(path: str | os.PathLike, suffix: str | None = None) -> list[Path]:
    """Delete the temporaries of ``path`` that a killed write left behind; returns them.

    They are named ``.<name>.<pid>-<host>-<random><suffix>`` (see :func:`atomic_path`);
    that part never holds a dot, so the temporaries of ``a.png.b.png`` are not taken for
    those of ``a.png``. A temporary is removed only when its writer is known dead: its
    pid no longer runs on this host. Another host's (a shared cache on a cluster) or one
    without a writer is removed once untouched for ``FOREIGN_TEMPORARY_AGE``.
    """
    path = Path(path)
    suffix = suffix if suffix is not None else path.suffix
    prefix = _temp_prefix(path)
    removed = []
    if not path.parent.is_dir():
        return removed
    for entry in path.parent.iterdir():
        name = entry.name
        if not (name.startswith(prefix) and name.endswith(suffix)):
            continue
        middle = name[len(prefix) : len(name) - len(suffix)]
        if not middle or "." in middle or "/" in middle or not entry.is_file():
            continue
        if _is_leftover(entry, middle):
            try:
                entry.unlink()
                removed.append(entry)
            except FileNotFoundError:  # removed meanwhile
                pass
    return removed


def current_umask() -> int:
    """The process umask, read without changing it where the system allows."""
    try:
        # Linux reports it in /proc: reading it leaves the umask of other threads alone
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@dataclass(eq=False)
class Provenance(TypedResult):
    """The ``provenance`` record of a result file: which poro2d, Python and machine wrote it, and when.

    :meth:`now` gives the run at hand's; a file of another version keeps its other keys
    (``extra``) and lacks none it did not have.
    """

    poro2d_version: str
    python: str
    machine: str
    platform: str
    cpu_count: int | None
    created_utc: str

    @classmethod
    def now(cls) -> Provenance:
        """The record of the run at hand: this poro2d, Python and machine, the time in UTC."""
        return cls(
            poro2d_version=__version__,
            python=platform.python_version(),
            machine=platform.machine(),
            platform=platform.platform(),
            cpu_count=os.cpu_count(),
            created_utc=datetime.now(UTC).isoformat(timespec="seconds"),
        )


def float_or_nan(value: Any) -> float:
    """A number read back from a result: NaN for ``None`` (how :func:`write_json` stores NaN)
    or for anything that is not a number (a value a failed case never wrote)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def write_json(path: str | os.PathLike, data: Mapping, *, config: bool = False) -> None:
    """Write ``data`` as JSON (atomically); the file is always valid, strict JSON.

    Results may hold NaN or infinities where a quantity is undefined: they are
    written as ``null``. With ``config=True`` the content is a configuration, whose
    numbers must all be finite: a non-finite one raises ``ValueError`` (validate
    configs before, see :func:`poro2d.config.check_finite`, for a clear message).
    """
    plain = to_json_types(data) if config else as_json(data)
    text = json.dumps(plain, indent=2, allow_nan=False)
    with atomic_path(path) as tmp:
        tmp.write_text(text + "\n")


def write_csv(path: str | os.PathLike, rows: Iterable[Mapping], header: list[str] | None = None) -> None:
    # a typed result or record is written as the dict of its file
    rows = [r.to_dict() if not isinstance(r, dict) and hasattr(r, "to_dict") else r for r in rows]
    if header is None:  # every row's keys, in the order they first appear
        header = list(dict.fromkeys(k for r in rows for k in r))
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=header, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(
                {
                    k: json_value(v) if not isinstance(v, (str, int, float, type(None))) else v
                    for k, v in r.items()
                }
            )


def write_texts(folder: str | os.PathLike, files: Iterable[tuple[str, str]]) -> list[Path]:
    """Each (name, text) of ``files`` written into ``folder``, atomically; returns their paths.

    For a writer that composes its files whole first (an export), so that what it refuses is
    refused before anything is written.
    """
    paths = []
    for name, text in files:
        with atomic_path(Path(folder) / name) as tmp:
            tmp.write_text(text)
        paths.append(Path(folder) / name)
    return paths


def check_output_dir(parameter: str, path: str | os.PathLike) -> Path:
    """Refuse an output folder that cannot be created or written, before any work starts.

    ``path`` may exist (a folder) or not (it is created later); an existing file of that
    name, a file where a parent folder should be, or a parent without write permission is
    an InputError naming ``parameter``. Nothing is created here.
    """
    from poro2d.errors import InputError

    p = Path(path)
    if p.exists() and not p.is_dir():
        raise InputError(parameter, str(p), "a folder (a file of that name exists)")
    existing = p
    while not existing.exists():  # the nearest part of the path that exists
        if existing.parent == existing:
            break
        existing = existing.parent
    if not existing.is_dir():
        raise InputError(parameter, str(p), "a path whose parents are folders", f"{existing} is a file")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(parameter, str(p), "a folder that can be written", f"{existing} is read-only")
    return p


#: the largest text table or config poro2d reads (a line of a specimen table or LAMMPS data
#: file takes about 100 bytes: several hundred thousand disks fit)
TEXT_FILE_LIMIT = 64 * 2**20
#: the largest checkpoint (.npz) poro2d reads (a few hundred bytes per disk)
CHECKPOINT_FILE_LIMIT = 1024 * 2**20


def _size_text(n: int) -> str:
    return f"{n // 2**20} MiB"


def check_input_file(parameter: str, path: str | os.PathLike, limit: int = TEXT_FILE_LIMIT) -> Path:
    """Refuse an input that is not a regular file, or one larger than ``limit`` bytes.

    Every file poro2d reads from the user passes here first: a device (``/dev/zero``), a
    FIFO or a folder would be read without end, and a huge file would fill the memory
    before any check of its content.
    """
    from poro2d.errors import InputError

    p = Path(path)
    allowed = f"a regular file of at most {_size_text(limit)}"
    try:
        st = p.stat()
    except OSError:
        raise InputError(parameter, str(p), allowed, "it does not exist or cannot be read") from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError(parameter, str(p), allowed, f"it is {_file_kind(st.st_mode)}")
    if st.st_size > limit:
        raise InputError(parameter, str(p), allowed, f"it holds {st.st_size:,} bytes")
    return p


def _file_kind(mode: int) -> str:
    kinds = [(stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
             (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
             (stat.S_ISSOCK, "a socket")]  # fmt: skip
    return next((name for test, name in kinds if test(mode)), "not a regular file")


def read_user_text(parameter: str, path: str | os.PathLike, kind: str) -> tuple[Path, str]:
    """The path and text of a ``kind`` file (TOML, CSV) the user named: one that is missing is
    refused as such before :func:`read_utf8` checks and reads it."""
    from poro2d.errors import InputError

    p = Path(path)
    if p.exists():  # a device, a FIFO or a folder is named as such
        check_input_file(parameter, p)
    if not p.is_file():
        raise InputError(parameter, str(p), f"an existing {kind} file")
    return p, read_utf8(parameter, p, f"a UTF-8 {kind} file")


def read_utf8(parameter: str, path: str | os.PathLike, allowed: str) -> str:
    """The text of a UTF-8 file (a regular file of a sane size: :func:`check_input_file`);
    a file of other bytes (binary, Latin-1) is an InputError.

    The message names the file and the line and column of the first byte that is not
    UTF-8, so the user can find it. A byte order mark at the start is dropped: spreadsheets
    write one before UTF-8 CSV files.
    """
    from poro2d.errors import InputError

    p = check_input_file(parameter, path)
    try:
        data = p.read_bytes()
    except OSError as exc:  # no permission, or gone since it was found
        raise InputError(parameter, str(p), allowed, exc.strerror or type(exc).__name__) from None
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        if data.startswith((b"\xff\xfe", b"\xfe\xff")):  # a spreadsheet's "Unicode text"
            where = "the file is UTF-16 text: save it as UTF-8, a spreadsheet's CSV UTF-8"
            raise InputError(parameter, str(p), allowed, where) from None
        line, column = text_position(data, exc.start)
        where = f"byte 0x{data[exc.start]:02x} at line {line}, column {column} is not UTF-8"
        raise InputError(parameter, str(p), allowed, where) from None


def text_position(data: bytes, offset: int) -> tuple[int, int]:
    """(line, column), both from 1, of byte ``offset`` of ``data``."""
    line_start = data.rfind(b"\n", 0, offset) + 1
    return data.count(b"\n", 0, offset) + 1, offset - line_start + 1
