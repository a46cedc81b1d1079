"""What a biaxial test's folder holds: the record (``test.json``) that binds it to one test.

One test is one specimen at one confining stress with one set of settings. Its record holds
what its numbers depend on: the specimen's content digest (a file's state, or a quick
specimen's recipe), sigma_3 and the settings; no path, so a moved folder resumes. The rules
are those of every laboratory test's folder (:func:`poro2d.store.test_stage`): a folder holding
another test is refused, naming what it holds; the same test resumes. A folder of a test
written before records existed (a ``result.json`` without ``test.json``) is adopted: its
result is not trusted, the test runs again.
"""

from __future__ import annotations

from typing import Any

from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.store import Fingerprint, ResumableStage, Store, test_stage


def content_of(case: BiaxialCase) -> dict[str, Any]:
    """What a stored test must share with ``case`` to be reused (content, never paths)."""
    return {
        "specimen_digest": case.specimen.digest,
        "confining_kpa": case.confining_kpa,
        "settings": case.settings.to_dict(),
    }


def folder_stage(store: Store, case: BiaxialCase) -> ResumableStage:
    """The stage of ``case``'s test in ``store``, bound by ``test.json``."""
    fingerprint = Fingerprint(content_of(case), tables={"settings": BiaxialSettings})
    return test_stage(
        store.root, fingerprint, specimen=case.specimen.source, stress=("confining_kpa", "confining stress"),
        parameter=store.parameter, unrecorded="adopt",
    )  # fmt: skip


__all__ = ["content_of", "folder_stage"]
