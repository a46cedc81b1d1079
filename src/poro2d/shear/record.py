"""What a test folder holds: the record (``test.json``) that binds it to one test.

The record holds what a test's results depend on: a digest of the specimen's state, the
normal stress and the settings. It holds no path, so a moved or copied folder resumes
without recomputing; a folder whose work belongs to another test is refused. The rules
(record, markers, binding once work has started) are those of
:class:`poro2d.store.stage.ResumableStage`; this module words them for a test.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from poro2d.io_utils import Provenance
from poro2d.shear.settings import ShearSettings
from poro2d.store import Store
from poro2d.store.stage import Fingerprint, ResumableStage
from poro2d.typed_result import TypedResult

RECORD = "test.json"


#: settings added after tests were first recorded, left out of the record while they hold their
#: default (None: the specimen's own value, which the specimen's digest already covers), so
#: a folder written before they existed still resumes as the same test
LATER_SETTINGS = ("rolling_friction",)


@dataclass(eq=False)
class TestContent(TypedResult):
    """What a stored test must share with this one to be reused: content, never paths.

    The digest of the specimen's state, the normal stress (kPa) and the settings as recorded
    (the settings' record less the later settings at their default); ``to_dict()`` is the
    ``run`` of ``test.json``, the content its digest is taken of.
    """

    __test__ = False  # not a test class, for all its name

    specimen_digest: str
    normal_stress_kpa: float
    settings: ShearSettings

    PARTS: ClassVar[dict[str, type]] = {"settings": ShearSettings}


def content_record(
    specimen_digest: str, sigma_kpa: float, settings: ShearSettings | Mapping[str, Any]
) -> TestContent:
    """What a stored test must share with this one to be reused: content, never paths.

    ``settings``: the test's (or their dict, as a ``test.json`` holds it).
    """
    if isinstance(settings, ShearSettings):
        settings = settings.to_dict()
    kept = {k: v for k, v in settings.items() if not (k in LATER_SETTINGS and v is None)}
    return TestContent(specimen_digest, sigma_kpa, ShearSettings.from_dict(kept))


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


def folder_stage(store: Store, record: TestContent | Mapping, specimen: str) -> ResumableStage:
    """The stages of one test in ``store`` (consolidation, shearing), bound by ``test.json``.

    ``record``: :func:`content_record` (or its dict, as a ``test.json`` holds it under ``run``);
    the record file keeps its digest (``key``) and the specimen's path (for information: not
    compared) beside it.
    """
    content = record.to_dict() if isinstance(record, TestContent) else record
    fingerprint = Fingerprint(content, tables={"settings": ShearSettings})
    return store.stage(
        fingerprint,
        record=RECORD,
        key="run",
        extra={
            "key": fingerprint.digest,
            "specimen": str(specimen),
            "provenance": Provenance.now().to_dict(),
        },
        parameter="out",
        allowed="an empty folder or one holding the same test",
        explain=_explain,
        unrecorded="refuse",
    )


__all__ = ["TestContent", "content_record", "folder_stage", "stale_reason"]
