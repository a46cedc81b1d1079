"""Resumable stages: a finished stage is read back, an unfinished one computed and saved.

Long runs (the criterion's trials, a direct shear test, a sweep's case, the paper's case
study) write into an output folder and must survive a kill: the same command, run again,
continues where the last one stopped. They share one set of rules, kept here:

* What the results depend on, the *fingerprint* (the inputs and settings that change a
  number), is kept in the folder's *record* file. It holds no path, so a moved or copied
  folder resumes, and no setting that only changes the speed (the thread count), so a
  rerun on more threads resumes too.
* A stage's result is written atomically, after every file it refers to: this file, the
  stage's *marker*, present means the stage is done. A crash inside a stage leaves no
  marker, so the stage runs again (from its own checkpoints, if it keeps any).
* A rerun returns the stored result when the marker exists and the record holds the same
  fingerprint. A folder whose work belongs to another fingerprint is refused with an
  :class:`~poro2d.errors.InputError` naming the output parameter and the keys that differ:
  that work may be hours the user still wants, so choosing another folder is left to them.
  Otherwise the stage is computed, its marker written and its result returned.
* The record binds the folder only once work has started (the folder holds anything
  besides the record): a run refused or stopped before that leaves nothing to protect,
  and the next command (a corrected one, say) replaces the record.

One record may serve several stages in the same folder (a criterion run and each of its
trials, a shear test's consolidation and the test): each stage has its own marker.

A laboratory test's folder (a direct shear or a biaxial test) is bound by :func:`test_stage`,
the one policy for a folder holding another test: it is refused, naming the folder and the
test it holds; a rerun of the same test resumes.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from poro2d.errors import InputError
from poro2d.identity import identity_digest, identity_view
from poro2d.io_utils import Provenance, as_json, write_json
from poro2d.locks import is_lock_file
from poro2d.store import digests

#: ``explain(keys, stored)``: the InputError's hint for a refused folder; ``keys`` are the
#: fingerprint's differing keys, None when the folder's work has no record at all
Explain = Callable[[list[str] | None, Mapping | None], str]


def differing_keys(old: Any, new: Any, prefix: str = "") -> list[str]:
    """The dotted keys at which two JSON values differ (``criterion.max_iterations``), sorted.

    A key present on one side only counts as differing; lists are compared whole.
    """
    if not (isinstance(old, Mapping) and isinstance(new, Mapping)):
        return [] if old == new else [prefix[:-1] or "(all)"]
    keys: list[str] = []
    for k in sorted(set(old) | set(new), key=str):
        if k not in old or k not in new:
            keys.append(f"{prefix}{k}")
        else:
            keys += differing_keys(old[k], new[k], f"{prefix}{k}.")
    return keys


@dataclass(frozen=True)
class Fingerprint:
    """What a stage's results depend on, as a JSON-able dict.

    Compared and hashed by the one identity rule (:mod:`poro2d.identity`): ``tables`` names
    the dataclass each table of the content stands for (``{"specimen": SpecimenSpec}``), whose
    fields marked as not changing results (``specimen.threads``) are kept in the record but
    never compared; ``ignore``: further dotted keys kept but not compared (labels derived
    from the rest).
    """

    content: Mapping[str, Any]
    ignore: tuple[str, ...] = ()
    tables: Mapping[str, type] | None = None

    def compared(self, content: Mapping | None = None) -> Any:
        """``content`` (default: this fingerprint's) as JSON, without what is not compared."""
        data = self.content if content is None else content
        return identity_view(data, tables=self.tables, ignore=self.ignore)

    @property
    def digest(self) -> str:
        """The digest of the compared content (:func:`poro2d.identity.identity_digest`)."""
        return identity_digest(self.content, tables=self.tables, ignore=self.ignore)

    def differences(self, stored: Mapping) -> list[str]:
        """The keys in which a recorded fingerprint differs from this one (none: the same work)."""
        return differing_keys(self.compared(stored), self.compared())


class ResumableStage:
    """Stages of work in ``folder`` bound to ``fingerprint`` through the record file ``record``.

    ``key``: where the fingerprint sits in the record (``{"run": ...}``), with ``extra`` beside
    it (the config as given, provenance: recorded, never compared); None: the record is the
    fingerprint itself. ``parameter``, ``allowed`` and ``explain`` word the refusal.
    ``unrecorded``: what to do with a folder holding work but no record (written before
    records existed, or the record deleted): ``"refuse"`` it, or ``"adopt"`` it (its markers
    are not trusted, the record is written and the stages run, resuming what they can).
    """

    def __init__(
        self,
        folder: str | Path,
        fingerprint: Fingerprint,
        *,
        record: str = "stage.json",
        key: str | None = "run",
        extra: Mapping[str, Any] | None = None,
        parameter: str = "--out",
        allowed: str = "an empty folder or one holding work of the same inputs",
        explain: Explain | None = None,
        unrecorded: Literal["refuse", "adopt"] = "refuse",
    ) -> None:
        if key is None and extra:
            raise ValueError("a record without a key holds the fingerprint only: no extra")
        self.folder = Path(folder)
        self.fingerprint = fingerprint
        self.record = record
        self.key = key
        self.extra = dict(extra or {})
        self.parameter = parameter
        self.allowed = allowed
        self.explain = explain or self._explain
        self.unrecorded = unrecorded

    def _explain(self, keys: list[str] | None, stored: Mapping | None) -> str:
        """The default hint for a refused folder: the keys its work differs in, or that it has no record."""
        if keys is None:
            return f"it holds work without a record of its inputs; choose another {self.parameter}"
        return f"it holds results of other inputs ({', '.join(keys)}); choose another {self.parameter}"

    def work_started(self) -> bool:
        """True once the folder holds anything besides its record (and temporaries of it)."""
        if not self.folder.is_dir():
            return False
        temporary = f".{self.record}."  # see poro2d.io_utils.atomic_path
        return any(
            p.name not in (self.record, digests.MANIFEST)
            and not p.name.startswith(temporary)
            and not is_lock_file(p.name)
            for p in self.folder.iterdir()
        )

    def recorded(self) -> Mapping | None:
        """The fingerprint in the record (``{}`` for a record of another shape), None without one."""
        try:
            data = json.loads((self.folder / self.record).read_text())
        except (OSError, ValueError):
            return None
        if not isinstance(data, dict):
            return {}
        if self.key is None:
            return data
        part = data.get(self.key)
        return part if isinstance(part, Mapping) else {}

    def check(self) -> None:
        """Refuse the folder if its work belongs to another fingerprint; writes nothing."""
        if not self.work_started():
            return
        stored = self.recorded()
        if stored is None:
            if self.unrecorded == "adopt":
                return
            keys = None
        else:
            keys = self.fingerprint.differences(stored)
            if not keys:
                return
        raise InputError(self.parameter, str(self.folder), self.allowed, self.explain(keys, stored))

    def bind(self) -> None:
        """Write the record, unless the folder's work already carries one (checked by :meth:`check`)."""
        path = self.folder / self.record
        if self.work_started() and path.is_file():
            return
        content = self.fingerprint.content
        write_json(path, content if self.key is None else {self.key: content, **self.extra}, config=True)

    def stored(
        self, marker: str = "result.json", accept: Callable[[dict], bool] | None = None
    ) -> dict | None:
        """The result of a finished stage: its marker's raw JSON, if the record holds this fingerprint.

        The stage does not know the result's class: the caller reads the content with its own
        (:meth:`poro2d.shear.results.ShearTestResult.read`, say).

        ``marker`` is relative to the folder; ``accept(result)`` may refuse a marker of an
        unfinished shape (a failure written under the same name, a missing side file). None
        when the stage has to run.
        """
        path = self.folder / marker
        if not path.is_file() or not digests.intact(self.folder, marker):
            return None  # a marker changed since it was written is not trusted: the stage runs again
        stored = self.recorded()
        if stored is None or self.fingerprint.differences(stored):
            return None
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError):
            return None
        if not isinstance(data, dict) or (accept is not None and not accept(data)):
            return None
        return data

    def run(
        self,
        compute: Callable[[], Mapping],
        marker: str = "result.json",
        *,
        accept: Callable[[dict], bool] | None = None,
        decode: Callable[[dict], Any] | None = None,
    ) -> Any:
        """The stage's result: read back when finished, else ``compute()``d and saved (marker last).

        The result is returned as the marker holds it (``decode`` applied, e.g. a typed
        result's ``from_dict``), so a fresh run and a resumed one return the same types.
        """
        self.check()
        data = self.stored(marker, accept)
        if data is None:
            self.bind()
            data = as_json(compute())
            write_json(self.folder / marker, data)
            digests.record(self.folder, marker)
        return data if decode is None else decode(data)


#: the record of a laboratory test's folder
TEST_RECORD = "test.json"


def other_test(keys: list[str] | None, old: Mapping | None, stress: tuple[str, str]) -> str:
    """The test a folder holds, as it differs from this one (``keys``: where its record differs;
    None: no record). ``stress``: the key of the test's stress in the record and its name."""
    key, name = stress
    if keys is None or old is None:
        return "no record of its specimen and settings"
    if "specimen_digest" not in old:
        return "no content key of its specimen (written by an older poro2d)"
    if "specimen_digest" in keys:
        return "another specimen (the content of the specimen file differs)"
    if key in keys:
        return f"another {name} ({old.get(key)} kPa)"
    return "other settings (" + ", ".join(k.removeprefix("settings.") for k in keys) + ")"


def test_stage(
    folder: str | Path,
    fingerprint: Fingerprint,
    *,
    specimen: str,
    stress: tuple[str, str],
    parameter: str = "--out",
    unrecorded: Literal["refuse", "adopt"] = "refuse",
) -> ResumableStage:
    """The stages of one laboratory test in ``folder``, bound by ``test.json`` to ``fingerprint``.

    A folder holding another test is refused (an :class:`~poro2d.errors.InputError` naming the
    folder and that test, :func:`other_test`): it may be hours of work the user still wants, so
    the choice of another folder is left to them. The same test resumes. The record keeps the
    fingerprint's digest (``key``), the specimen's path and the provenance beside it (not compared).
    """

    def explain(keys: list[str] | None, old: Mapping | None) -> str:
        return f"it holds a test of {other_test(keys, old, stress)}; use a new {parameter}"

    extra = {"key": fingerprint.digest, "specimen": specimen, "provenance": Provenance.now().to_dict()}
    return ResumableStage(
        folder, fingerprint, record=TEST_RECORD, key="run", extra=extra, parameter=parameter,
        allowed="an empty folder or one holding the same test", explain=explain, unrecorded=unrecorded,
    )  # fmt: skip


__all__ = ["TEST_RECORD", "Fingerprint", "ResumableStage", "differing_keys", "other_test", "test_stage"]
