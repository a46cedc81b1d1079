"""Atomic writes and result metadata shared by every layer."""

from __future__ import annotations

import csv
import json
import os
import platform
import tempfile
from collections.abc import Iterable, Mapping
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

from poro2d import __version__


@contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None):
    """Yield a temporary path next to ``path``; rename it onto ``path`` on success.

    A crash leaves no file that looks complete: the final name only appears once
    the content is fully written.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.name}.", suffix=suffix if suffix is not None else path.suffix, dir=path.parent
    )
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


def provenance() -> dict:
    """Version, machine and time stamp recorded in every result file."""
    return {
        "poro2d_version": __version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }


def _default(o):
    import numpy as np

    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o)}")


def write_json(path: str | os.PathLike, data: Mapping) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(data, indent=2, default=_default, allow_nan=True) + "\n")


def write_csv(path: str | os.PathLike, rows: Iterable[Mapping], header: list[str] | None = None) -> None:
    rows = list(rows)
    if header is None:
        header = []
        for r in rows:
            for k in r:
                if k not in header:
                    header.append(k)
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=header, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(
                {
                    k: _default(v) if not isinstance(v, (str, int, float, type(None))) else v
                    for k, v in r.items()
                }
            )


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
