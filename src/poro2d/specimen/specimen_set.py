"""Replicate specimens as one value: labels in order, each with its file and, once read, its content.

A friction angle from one specimen is one sample of a chaotic packing, so a strength study,
a replicate shear series and a calibration each shear several specimens of one soil. They
name them by label (``seed1``, ``specimen2``: the labels name their folders and rows) and
need, by stage, the file (a worker reads it), the specimen read once for all its tests (its
shape and radii checked, its state's digest, which a calibration unit's key hashes: a
specimen moved to another folder is the same one). :class:`SpecimenSet` carries all three
and keeps the order given, so every table lists the specimens the same way.

Specimens that a user names are taken only when the criterion accepted them
(:func:`poro2d.specimen.accepted.accepted_file`), on one line before any work; those the
criterion has just accepted come in through :meth:`SpecimenSet.made`.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

from poro2d.errors import InputError
from poro2d.specimen.accepted import accepted_file
from poro2d.specimen.saved import Specimen


@dataclass(frozen=True)
class SpecimenSet:
    """Specimens by label, in order: ``paths`` always, ``digests`` and ``specimens`` once read.

    Iterating gives the labels; ``set[label]`` the file; ``len(set)`` how many.
    """

    labels: tuple[str, ...]
    paths: tuple[Path, ...]
    digests: tuple[str, ...] | None = None
    specimens: tuple[Specimen, ...] | None = None

    def __post_init__(self) -> None:
        n = len(self.labels)
        if len(set(self.labels)) != n:
            raise ValueError(f"specimen labels repeat: {self.labels}")
        for name in ("paths", "digests", "specimens"):
            value = getattr(self, name)
            if value is not None and len(value) != n:
                raise ValueError(f"{len(value)} {name} for {n} specimen labels")

    # ------------------------------------------------------------------ making one
    @classmethod
    def made(cls, pairs: Iterable[tuple[str, str | os.PathLike]]) -> SpecimenSet:
        """The specimens a run has just accepted, by label (taken as they are, not checked again)."""
        pairs = list(pairs)
        return cls(tuple(label for label, _ in pairs), tuple(Path(p) for _, p in pairs))

    @classmethod
    def accepted(cls, given: Mapping[str, str | os.PathLike], parameter: str = "specimens") -> SpecimenSet:
        """The specimens a user named, by label; each a checkpoint or a criterion folder the criterion
        accepted, refused on one line naming the file and why (:func:`accepted_file`)."""
        if not given:
            raise InputError(parameter, "none", "at least one specimen")
        return cls.made((label, accepted_file(path)) for label, path in given.items())

    @classmethod
    def named(cls, paths: Iterable[str | os.PathLike], parameter: str = "--specimen") -> SpecimenSet:
        """Accepted specimens labelled by their names: a criterion folder's name, else the file's stem,
        made unique by a count (``crit``, ``crit-2``)."""
        files = [accepted_file(p) for p in paths]
        if not files:
            raise InputError(parameter, "none", "at least one specimen (or --preset paper)")
        labels: list[str] = []
        for path in files:
            label = (path.parent.name if path.name == "specimen.npz" else path.stem) or "specimen"
            unique, k = label, 1
            while unique in labels:
                k += 1
                unique = f"{label}-{k}"
            labels.append(unique)
        return cls(tuple(labels), tuple(files))

    # ------------------------------------------------------------------ reading them
    def read(self) -> SpecimenSet:
        """The same specimens, each read once: checked whole (a damaged file is refused on one line) and
        hashed (:func:`poro2d.dem.checkpoint.state_digest` of its content)."""
        if self.specimens is not None:
            return self
        digests = self.digests or (None,) * len(self)
        found = tuple(Specimen.read(p, d) for p, d in zip(self.paths, digests, strict=True))
        return SpecimenSet(self.labels, self.paths, tuple(s.digest for s in found), found)

    def __add__(self, other: SpecimenSet) -> SpecimenSet:
        """These specimens, then ``other``'s (labels must differ); digests and reads are dropped."""
        return SpecimenSet(self.labels + other.labels, self.paths + other.paths)

    # ------------------------------------------------------------------ looking up
    def __len__(self) -> int:
        return len(self.labels)

    def __iter__(self) -> Iterator[str]:
        return iter(self.labels)

    def __contains__(self, label: object) -> bool:
        return label in self.labels

    def __getitem__(self, label: str) -> Path:
        return self.paths[self._index(label)]

    def digest(self, label: str) -> str:
        """The digest of specimen ``label``'s state (:meth:`read` first)."""
        if self.digests is None:
            raise ValueError("the specimens are not read yet: SpecimenSet.read()")
        return self.digests[self._index(label)]

    def contents(self) -> tuple[Specimen, ...]:
        """The specimens as read, in order (:meth:`read` first)."""
        if self.specimens is None:
            raise ValueError("the specimens are not read yet: SpecimenSet.read()")
        return self.specimens

    def specimen(self, label: str) -> Specimen | Path:
        """Specimen ``label`` as read, or its file when the set is not read (a worker reads it)."""
        k = self._index(label)
        return self.specimens[k] if self.specimens is not None else self.paths[k]

    def _index(self, label: str) -> int:
        try:
            return self.labels.index(label)
        except ValueError:
            raise KeyError(label) from None


__all__ = ["SpecimenSet"]
