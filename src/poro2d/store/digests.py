"""What the store wrote, by content: a file read back is used only if it is what was written.

Each folder of results keeps a small manifest (``.digests.json``): for every file the store
wrote there, the SHA-256 of its bytes. Reading a file back compares its digest with the
manifest's. A file edited by hand, truncated by a full disk or replaced by another run's is
then *damaged*: the store reads it as missing, so a resumable stage computes it again
instead of using it (a cache never changes a result), and a loader that cannot recompute
refuses it on one line naming the file.

A file the manifest does not list (written by an earlier version, or by another tool) is
not checked here; the readers' own checks (JSON syntax, array shapes, finiteness) still
apply. A manifest that cannot be read lists nothing.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from poro2d.io_utils import atomic_path

MANIFEST = ".digests.json"

#: bytes read at a time while hashing (large specimen states are tens of megabytes)
_CHUNK = 1 << 20


def file_digest(path: str | os.PathLike) -> str:
    """The SHA-256 of the file's bytes, in hex."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(_CHUNK), b""):
            h.update(block)
    return h.hexdigest()


def _manifest(folder: Path) -> dict[str, str]:
    """The folder's manifest as it is on disk: file name -> SHA-256 (empty when missing or unreadable)."""
    try:
        data = json.loads((folder / MANIFEST).read_text())
    except (OSError, ValueError):
        return {}
    if not isinstance(data, dict):
        return {}
    return {k: v for k, v in data.items() if isinstance(k, str) and isinstance(v, str)}


def record(folder: str | os.PathLike, name: str) -> None:
    """Note the digest of ``folder/name``, just written, in the folder's manifest.

    ``name`` may lie in a sub-folder (``trials/01/trial.json``): the entry goes to the
    manifest of the folder that holds the file, so a sub-folder moved on its own keeps it.
    """
    path = Path(folder) / name
    entries = _manifest(path.parent)
    entries[path.name] = file_digest(path)
    _save(path.parent, entries)


def forget(folder: str | os.PathLike, name: str) -> None:
    """Drop ``name``'s entry (the file was removed)."""
    path = Path(folder) / name
    entries = _manifest(path.parent)
    if entries.pop(path.name, None) is not None:
        _save(path.parent, entries)


def _save(folder: Path, entries: dict[str, str]) -> None:
    with atomic_path(folder / MANIFEST) as tmp:
        tmp.write_text(json.dumps(entries, indent=1, sort_keys=True) + "\n")


def intact(folder: str | os.PathLike, name: str) -> bool:
    """False when the manifest lists ``name`` with another digest than its bytes have now
    (or lists it and it is gone or unreadable); True otherwise, unlisted files included."""
    path = Path(folder) / name
    expected = _manifest(path.parent).get(path.name)
    if expected is None:
        return True
    try:
        return file_digest(path) == expected
    except OSError:
        return False


__all__ = ["MANIFEST", "file_digest", "forget", "intact", "record"]
