"""What a test folder holds: the record (``test.json``) that binds it to one test.

The record holds what a test's results depend on: a digest of the specimen's state, the
normal stress and the settings. It holds no path, so a moved or copied folder resumes
without recomputing; a folder whose work belongs to another test is refused.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from poro2d.errors import InputError
from poro2d.io_utils import provenance, write_json

RECORD = "test.json"


def content_record(specimen_digest: str, sigma_kpa: float, settings: dict) -> dict:
    """What a stored test must share with this one to be reused: content, never paths."""
    return {"specimen_digest": specimen_digest, "normal_stress_kpa": sigma_kpa, "settings": settings}


def work_started(out: Path) -> bool:
    """True once the folder holds more than the test's record (a stage has begun)."""
    return out.is_dir() and any(p.name != RECORD for p in out.iterdir())


def stale_reason(out: Path, record: dict) -> str | None:
    """Why the work in ``out`` belongs to another test, or None if it is this test's (or none)."""
    p = out / RECORD
    if not work_started(out):
        return None
    if not p.is_file():
        return "no record of its specimen and settings"
    old = json.loads(p.read_text()).get("run") or {}
    if "specimen_digest" not in old:
        return "no content key of its specimen (written by an older poro2d)"
    if old["specimen_digest"] != record["specimen_digest"]:
        return "another specimen (the content of the specimen file differs)"
    if old.get("normal_stress_kpa") != record["normal_stress_kpa"]:
        return f"another normal stress ({old.get('normal_stress_kpa')} kPa)"
    settings = old.get("settings") or {}
    now = record["settings"]
    changed = sorted(k for k in set(settings) | set(now) if settings.get(k) != now.get(k))
    if changed:
        return "other settings (" + ", ".join(changed) + ")"
    return None


def check_reusable(out: Path, record: dict) -> None:
    """Refuse an ``out`` that holds work of another specimen, normal stress or settings.

    Stale tests are not recomputed: their folder may hold hours of work the user still
    wants (a mistyped --specimen, say), so the choice of a new folder is left to the user.
    """
    reason = stale_reason(out, record)
    if reason is not None:
        raise InputError(
            "out", str(out), "an empty folder or one holding the same test",
            f"it holds a test of {reason}; use a new --out",
        )  # fmt: skip


def bind(out: Path, record: dict, specimen: Path) -> None:
    """Write the record to ``out/test.json`` (unless that folder already holds its work)."""
    if work_started(out) and (out / RECORD).is_file():
        return
    out.mkdir(parents=True, exist_ok=True)
    key = hashlib.sha256(json.dumps(record, sort_keys=True, separators=(",", ":")).encode()).hexdigest()
    data = {"key": key, "run": record, "specimen": str(specimen), "provenance": provenance()}
    write_json(out / RECORD, data, config=True)


__all__ = ["bind", "check_reusable", "content_record", "stale_reason", "work_started"]
