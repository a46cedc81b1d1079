"""A saved specimen read once, then passed down as a value.

A shear series runs several tests on one specimen, in other processes, and a strength
study or a biaxial run does the same: the file is read (and checked, and hashed) once into
a :class:`Specimen`, and every test builds its simulation from that value instead of
opening the file again. Only specimens the criterion accepted are read
(:func:`poro2d.specimen.accepted.accepted_file`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from poro2d.dem import Simulation, checkpoint
from poro2d.specimen.accepted import accepted_file
from poro2d.specimen.box import box_faces
from poro2d.store import Store


@dataclass(frozen=True, eq=False)
class Specimen:
    """A specimen checkpoint's content: its metadata, its arrays and the digest of its state.

    ``source``: the file it was read from (recorded in results, for information only: a
    test's identity is ``digest``, :func:`poro2d.dem.checkpoint.state_digest`).
    """

    source: str
    meta: dict[str, Any]
    arrays: dict[str, np.ndarray]
    digest: str

    @classmethod
    def read(cls, path: str | Path, digest: str | None = None) -> Specimen:
        """The specimen at ``path`` (a checkpoint or a folder holding ``specimen.npz``), checked.

        ``digest``: the state's digest when the caller knows it already (it is not computed again).
        """
        p = accepted_file(path)
        meta, arrays = Store(p.parent, parameter="specimen").read_state(p.name)
        return cls(str(p), meta, arrays, digest or checkpoint.content_digest(meta, arrays))

    @classmethod
    def of(cls, specimen: Specimen | str | Path) -> Specimen:
        """``specimen`` as it is when a value, else read from its path."""
        return specimen if isinstance(specimen, Specimen) else cls.read(specimen)

    @property
    def extra(self) -> dict[str, Any]:
        """What the specimen's maker recorded with it (the checkpoint's ``extra``: each maker its keys)."""
        return self.meta.get("extra", {})

    def box(self) -> tuple[float, float]:
        """(W, H): the specimen box's right wall and top plate."""
        names = self.meta.get("wall_names", [])
        _, right, _, top = box_faces(names, self.arrays["walls.p0"], "specimen walls", "a poro2d specimen")
        return right, top

    def simulation(self, threads: int | None = None) -> Simulation:
        """A new simulation of the specimen's state (the value itself is left as read)."""
        return checkpoint.from_content(self.meta, self.arrays, threads=threads)


__all__ = ["Specimen"]
