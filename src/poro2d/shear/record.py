"""What a test folder holds: the record (``test.json``) that binds it to one test.

The record holds what a test's results depend on: a digest of the specimen's state, the
normal stress and the settings. It holds no path, so a moved or copied folder resumes
without recomputing; a folder whose work belongs to another test is refused. The rules
(record, markers, binding once work has started, the refusal) are those of every laboratory
test's folder (:func:`poro2d.store.test_stage`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from poro2d.shear.settings import ShearSettings
from poro2d.store import Fingerprint, ResumableStage, Store, test_stage
from poro2d.typed_result import TypedResult

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


def folder_stage(store: Store, record: TestContent | Mapping, specimen: str) -> ResumableStage:
    """The stages of one test in ``store`` (consolidation, shearing), bound by ``test.json``
    (:func:`poro2d.store.test_stage`: a folder of another test is refused).

    ``record``: :func:`content_record` (or its dict, as a ``test.json`` holds it under ``run``).
    """
    content = record.to_dict() if isinstance(record, TestContent) else record
    fingerprint = Fingerprint(content, tables={"settings": ShearSettings})
    return test_stage(
        store.root, fingerprint, specimen=str(specimen), stress=("normal_stress_kpa", "normal stress"),
        parameter=store.parameter,
    )  # fmt: skip


__all__ = ["TestContent", "content_record", "folder_stage"]
