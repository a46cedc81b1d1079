"""VTU export (ParaView) through meshio, and CSV histories.

Three files per snapshot: ``<stem>_particles.vtu`` (one vertex per disk with radius,
velocity, spin), ``<stem>_walls.vtu`` (line segments) and ``<stem>_contacts.vtu``
(one line per touching contact, centre to centre, with its forces). In ParaView,
show particles with the "Point Gaussian" representation scaled by ``radius``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from poro2d.io_utils import atomic_path, write_csv


def _pad3(a: np.ndarray) -> np.ndarray:
    return np.column_stack([a, np.zeros(len(a))]) if len(a) else np.zeros((0, 3))


def write_vtu(sim, directory: str | os.PathLike, stem: str = "state") -> list[Path]:
    """Write particles, walls and the contact-force network as VTU files."""
    import meshio

    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    p = sim.particles
    out = []

    pts = _pad3(p.pos)
    cells = [("vertex", np.arange(p.n).reshape(-1, 1))]
    mesh = meshio.Mesh(
        pts,
        cells,
        point_data={
            "radius": p.radius,
            "velocity": _pad3(p.vel),
            "omega": p.omega,
            "theta": p.theta,
            "unbalanced_force": _pad3(sim.force),
            "mode": p.mode.astype(np.int32),
        },
    )
    out.append(_write(mesh, d / f"{stem}_particles.vtu"))

    w = sim.walls
    wpts = _pad3(np.vstack([w.p0, w.p1])) if w.n else np.zeros((0, 3))
    wcells = [("line", np.column_stack([np.arange(w.n), np.arange(w.n) + w.n]))]
    wmesh = meshio.Mesh(
        wpts, wcells,
        cell_data={"force": [_pad3(sim.wall_force_vec)], "velocity": [_pad3(w.vel)]},
    )  # fmt: skip
    out.append(_write(wmesh, d / f"{stem}_walls.vtu"))

    c = sim.contacts()
    pp = c.kind == 0
    a = p.pos[c.i[pp]]
    b = p.pos[c.j[pp]]
    wa = p.pos[c.i[~pp]]
    wb = c.point[~pp]
    ends = np.vstack([a, wa, b, wb])
    m = len(a) + len(wa)
    cpts = _pad3(ends)
    ccells = [("line", np.column_stack([np.arange(m), np.arange(m) + m]))]
    order = np.concatenate([np.nonzero(pp)[0], np.nonzero(~pp)[0]])
    cmesh = meshio.Mesh(
        cpts,
        ccells,
        cell_data={
            "fn": [c.fn[order]],
            "fs": [c.fs[order]],
            "force_magnitude": [c.magnitude[order]],
            "force": [_pad3(c.force[order])],
            "wall_contact": [(~pp)[order].astype(np.int32)],
        },
    )
    out.append(_write(cmesh, d / f"{stem}_contacts.vtu"))
    return out


def _write(mesh, path: Path) -> Path:
    import meshio

    with atomic_path(path, suffix=".vtu") as tmp:
        meshio.write(str(tmp), mesh, file_format="vtu")
    return path


class History:
    """Rows of named quantities recorded at Python events, written as CSV."""

    def __init__(self) -> None:
        self.rows: list[dict] = []

    def record(self, **values) -> None:
        self.rows.append(values)

    def column(self, name: str) -> np.ndarray:
        return np.array([r.get(name, np.nan) for r in self.rows], dtype=float)

    def write_csv(self, path: str | os.PathLike) -> None:
        write_csv(path, self.rows)
