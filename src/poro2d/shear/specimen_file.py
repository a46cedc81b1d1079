"""The specimen a direct shear test starts from: where its file is and the size of its box."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from poro2d.errors import InputError
from poro2d.io_utils import CHECKPOINT_FILE_LIMIT, check_input_file
from poro2d.specimen.box import box_faces


def resolve_specimen(path: str | Path) -> Path:
    """A checkpoint file, or a criterion output folder holding ``specimen.npz``."""
    p = Path(path)
    if p.is_dir():
        p = p / "specimen.npz"
    if not p.is_file():
        raise InputError(
            "specimen",
            str(path),
            "a specimen checkpoint (.npz) or a criterion output folder with specimen.npz",
        )
    return check_input_file("specimen", p, CHECKPOINT_FILE_LIMIT)


def specimen_box(path: str | Path) -> tuple[float, float]:
    """(W, H) of a specimen checkpoint, from its right wall and top plate, without loading it."""
    with np.load(resolve_specimen(path)) as z:
        meta = json.loads(bytes(z["meta"]).decode())
        names = meta.get("wall_names", [])
        p0 = z["walls.p0"]
    _, right, _, top = box_faces(names, p0, "specimen walls", "a poro2d specimen")
    return right, top


__all__ = ["resolve_specimen", "specimen_box"]
