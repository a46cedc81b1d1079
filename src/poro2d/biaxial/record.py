"""What a biaxial test's folder holds: the record (``test.json``) that binds it to one test.

One test is one specimen at one confining stress with one set of settings. Its record holds
what its numbers depend on: the specimen's content digest (a file's state, or a quick
specimen's recipe), sigma_3 and the settings; no path, so a moved folder resumes. The rules
are :class:`poro2d.store.stage.ResumableStage`'s, and whether two tests are the same is the
one identity rule's (:class:`poro2d.store.Fingerprint`).

Unlike a direct shear folder, a test folder whose record names another test is not refused:
it is emptied and the test runs again. A biaxial test is seconds (the quick specimen) to
half a minute (a paper-size specimen), so a changed setting costs less than a refusal would,
and a study's folders follow the command that wrote them last. A folder of a test written
before records existed (a ``result.json`` without ``test.json``) is adopted: its result is
not trusted, the test runs again.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.errors import InputError
from poro2d.io_utils import Provenance
from poro2d.store import Fingerprint, ResumableStage, Store

#: the record of a test folder
RECORD = "test.json"
#: the files a test keeps (its marker, ``result.json``, last)
TEST_FILES = ("result.json", "curve.csv", RECORD)


def content_of(case: BiaxialCase) -> dict[str, Any]:
    """What a stored test must share with ``case`` to be reused (content, never paths)."""
    return {
        "specimen_digest": case.specimen.digest,
        "confining_kpa": case.confining_kpa,
        "settings": case.settings.to_dict(),
    }


def _explain(keys: list[str] | None, stored: Mapping | None) -> str:
    return f"it holds another test ({', '.join(keys or [])})"


def folder_stage(store: Store, case: BiaxialCase) -> ResumableStage:
    """The stage of ``case``'s test in ``store``, bound by ``test.json``."""
    fingerprint = Fingerprint(content_of(case), tables={"settings": BiaxialSettings})
    return store.stage(
        fingerprint, record=RECORD, key="run",
        extra={"key": fingerprint.digest, "specimen": case.specimen.source,
               "provenance": Provenance.now().to_dict()},
        allowed="a folder of the same test", explain=_explain, unrecorded="adopt",
    )  # fmt: skip


def claim(store: Store, stage: ResumableStage) -> None:
    """Make ``store`` the folder of ``stage``'s test: the files of another test are removed first."""
    try:
        stage.check()
    except InputError:
        for name in TEST_FILES:  # the marker first: a kill in between leaves an unfinished test
            store.remove(name)


__all__ = ["RECORD", "TEST_FILES", "claim", "content_of", "folder_stage"]
