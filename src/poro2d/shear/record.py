"""What a test folder holds: the record (``test.json``) that binds it to one test.

The record holds what a test's results depend on: a digest of the specimen's state, the
normal stress and the settings. It holds no path, so a moved or copied folder resumes
without recomputing; a folder whose work belongs to another test is refused. The rules
(record, markers, binding once work has started) are those of
:class:`poro2d.store.stage.ResumableStage`; this module words them for a test.
"""

from __future__ import annotations

from collections.abc import Mapping

from poro2d.io_utils import provenance
from poro2d.shear.settings import ShearSettings
from poro2d.store import Store
from poro2d.store.stage import Fingerprint, ResumableStage

RECORD = "test.json"


#: settings added after tests were first recorded, left out of the record while they hold their
#: default (None: the specimen's own value, which the specimen's digest already covers), so
#: a folder written before they existed still resumes as the same test
LATER_SETTINGS = ("rolling_friction",)


def content_record(specimen_digest: str, sigma_kpa: float, settings: dict) -> dict:
    """What a stored test must share with this one to be reused: content, never paths."""
    kept = {k: v for k, v in settings.items() if not (k in LATER_SETTINGS and v is None)}
    return {"specimen_digest": specimen_digest, "normal_stress_kpa": sigma_kpa, "settings": kept}


def stale_reason(keys: list[str] | None, old: Mapping | None) -> str:
    """Why a folder's test is another one, from the keys its record differs in (None: no record)."""
    if keys is None or old is None:
        return "no record of its specimen and settings"
    if "specimen_digest" not in old:
        return "no content key of its specimen (written by an older poro2d)"
    if "specimen_digest" in keys:
        return "another specimen (the content of the specimen file differs)"
    if "normal_stress_kpa" in keys:
        return f"another normal stress ({old.get('normal_stress_kpa')} kPa)"
    return "other settings (" + ", ".join(k.removeprefix("settings.") for k in keys) + ")"


def _explain(keys: list[str] | None, old: Mapping | None) -> str:
    # stale tests are not recomputed: their folder may hold hours of work the user still
    # wants (a mistyped --specimen, say), so the choice of a new folder is left to the user
    return f"it holds a test of {stale_reason(keys, old)}; use a new --out"


def folder_stage(store: Store, record: dict, specimen: str) -> ResumableStage:
    """The stages of one test in ``store`` (consolidation, shearing), bound by ``test.json``.

    ``record``: :func:`content_record`; the record file keeps its digest (``key``) and the
    specimen's path (for information: not compared) beside it.
    """
    fingerprint = Fingerprint(record, tables={"settings": ShearSettings})
    return store.stage(
        fingerprint,
        record=RECORD,
        key="run",
        extra={"key": fingerprint.digest, "specimen": str(specimen), "provenance": provenance()},
        parameter="out",
        allowed="an empty folder or one holding the same test",
        explain=_explain,
        unrecorded="refuse",
    )


__all__ = ["content_record", "folder_stage", "stale_reason"]
