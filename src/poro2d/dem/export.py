"""VTU export (ParaView) through meshio, and CSV histories.

A specimen's snapshot is three files (:func:`write_vtu`): ``<stem>_particles.vtu`` (one vertex
per disk with radius, velocity, spin), ``<stem>_walls.vtu`` (line segments) and
``<stem>_contacts.vtu`` (one line per touching contact, centre to centre, with its forces). In
ParaView, show particles with the "Point Gaussian" representation scaled by ``radius``.

A step of a run's time series is one file (:func:`step_mesh`): the disks, the walls and the
contact network of one :class:`Frame`, read from the walled engine (:func:`frame_of`) or the
periodic cell (:func:`frame_of_cell`); :func:`write_mesh` writes both kinds, atomically.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from poro2d.io_utils import atomic_path, write_csv

if TYPE_CHECKING:
    import meshio


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
    out.append(write_mesh(mesh, d / f"{stem}_particles.vtu"))

    w = sim.walls
    wpts = _pad3(np.vstack([w.p0, w.p1])) if w.n else np.zeros((0, 3))
    wcells = [("line", np.column_stack([np.arange(w.n), np.arange(w.n) + w.n]))]
    wmesh = meshio.Mesh(
        wpts, wcells,
        cell_data={"force": [_pad3(sim.wall_force_vec)], "velocity": [_pad3(w.vel)]},
    )  # fmt: skip
    out.append(write_mesh(wmesh, d / f"{stem}_walls.vtu"))

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
    out.append(write_mesh(cmesh, d / f"{stem}_contacts.vtu"))
    return out


def write_mesh(mesh: meshio.Mesh, path: str | os.PathLike) -> Path:
    """Write ``mesh`` as the VTU file ``path``, atomically (the one VTU writer of poro2d)."""
    import meshio

    path = Path(path)
    with atomic_path(path, suffix=".vtu") as tmp:
        meshio.write(str(tmp), mesh, file_format="vtu")
    return path


#: a time-series cell's ``cell_kind``: a disk (vertex), a wall (line), a contact between two
#: disks and a contact of a disk with a wall (lines)
DISK, WALL, DISK_CONTACT, WALL_CONTACT = 0, 1, 2, 3


@dataclass(frozen=True)
class Frame:
    """One moment of a run as arrays (SI units; forces in N on the run's thickness).

    Disks: ``pos`` (n x 2, m), ``radius`` (m), ``velocity`` (n x 2, m/s), ``omega`` (rad/s),
    ``theta`` (rad), ``contact_force`` (n x 2, N: the sum of the contact forces on the disk).
    Walls: segments ``wall_p0`` to ``wall_p1`` (w x 2, m) and the force on each (``wall_force``,
    w x 2, N). Contacts: disk ``contact_i`` touches disk or wall ``contact_j`` (``contact_wall``
    True for a wall); the line runs from disk i's centre to ``contact_end`` (disk j's centre, its
    periodic image, or the point on the wall); ``fn``, ``fs`` the normal and tangential forces
    (N; ``fs`` signed), ``contact_vector`` (k x 2, N) the force on disk i.
    """

    pos: np.ndarray
    radius: np.ndarray
    velocity: np.ndarray
    omega: np.ndarray
    theta: np.ndarray
    contact_force: np.ndarray
    wall_p0: np.ndarray
    wall_p1: np.ndarray
    wall_force: np.ndarray
    contact_i: np.ndarray
    contact_j: np.ndarray
    contact_wall: np.ndarray
    contact_end: np.ndarray
    fn: np.ndarray
    fs: np.ndarray
    contact_vector: np.ndarray


def resultant(n: int, i: np.ndarray, j: np.ndarray, force: np.ndarray, pair: np.ndarray) -> np.ndarray:
    """The sum of the contact forces on each of ``n`` disks (n x 2): ``force`` acts on disk ``i``
    and, where ``pair`` is True, its opposite on disk ``j`` (a wall takes its own share)."""
    out = np.zeros((n, 2))
    for axis in (0, 1):
        out[:, axis] = np.bincount(i, force[:, axis], minlength=n)
        out[:, axis] -= np.bincount(j[pair], force[pair, axis], minlength=n)
    return out


def frame_of(sim) -> Frame:
    """The walled engine's state now (a :class:`~poro2d.dem.simulation.Simulation`); reads only."""
    p, w, c = sim.particles, sim.walls, sim.contacts()
    pair = c.kind == 0
    end = np.where(pair[:, None], p.pos[np.where(pair, c.j, 0)], c.point)
    return Frame(
        pos=p.pos.copy(), radius=p.radius.copy(), velocity=p.vel.copy(), omega=p.omega.copy(),
        theta=p.theta.copy(), contact_force=resultant(p.n, c.i, c.j, c.force, pair),
        wall_p0=w.p0.copy(), wall_p1=w.p1.copy(), wall_force=np.array(sim.wall_force_vec, dtype=float),
        contact_i=c.i, contact_j=c.j, contact_wall=~pair, contact_end=end, fn=c.fn, fs=c.fs,
        contact_vector=c.force,
    )  # fmt: skip


def frame_of_cell(cell) -> Frame:
    """The periodic cell's state now (a :class:`~poro2d.dem.periodic.PeriodicCell`); reads only.

    A contact across the cell's boundary is drawn from disk i to the image of disk j it touches
    (outside the cell), so every line is as long as the contact's branch; the velocities are the
    absolute ones (the affine flow added).
    """
    c = cell.contacts()
    force = np.column_stack([c["fx"], c["fy"]])
    branch = np.column_stack([c["lx"], c["ly"]])
    none = np.zeros((0, 2))
    return Frame(
        pos=cell.pos.copy(), radius=cell.radius.copy(), velocity=cell.absolute_velocity(),
        omega=cell.omega.copy(), theta=cell.theta.copy(), contact_force=cell.forces()[0],
        wall_p0=none, wall_p1=none, wall_force=none, contact_i=c["i"], contact_j=c["j"],
        contact_wall=np.zeros(len(c["i"]), dtype=bool), contact_end=cell.pos[c["i"]] + branch,
        fn=c["fn"], fs=c["fs"], contact_vector=force,
    )  # fmt: skip


def step_mesh(frame: Frame) -> meshio.Mesh:
    """One step of a time series as one mesh: a vertex per disk, then one line per wall and per
    contact (in one block of lines; ``cell_kind`` tells them apart).

    Points: the disks' centres (point k is disk k), the walls' ends, each contact's far end.
    Point data (zero off the disks): ``radius``, ``velocity``, ``angular_velocity``, ``rotation``,
    ``contact_force``. Cell data: ``cell_kind`` (:data:`DISK` ...), ``body_i`` and ``body_j`` (a
    disk's or wall's own index and -1; a contact's disk and its disk or wall), ``normal_force``
    and ``tangential_force`` (a contact's magnitudes; zero for disks and walls), ``force`` (a
    disk's resultant, a wall's force, the force on a contact's disk i) and its ``force_magnitude``.
    The step's time and strain are the series' to list (meshio writes no field data to VTU).
    """
    import meshio

    f = frame
    n, w, k = len(f.radius), len(f.wall_p0), len(f.contact_i)
    points = _pad3(np.vstack([f.pos, f.wall_p0, f.wall_p1, f.contact_end]))
    walls = np.column_stack([np.arange(w), np.arange(w) + w]) + n
    contacts = np.column_stack([f.contact_i, np.arange(k) + n + 2 * w])
    lines = np.vstack([walls, contacts]).astype(np.int64)
    on_disks = np.zeros(len(points))
    on_disks[:n] = 1.0
    kind = np.concatenate([np.full(w, WALL), np.where(f.contact_wall, WALL_CONTACT, DISK_CONTACT)])
    force = np.vstack([f.wall_force, f.contact_vector])
    zeros_n = np.zeros(n)
    cell_data = {
        "cell_kind": [np.full(n, DISK, np.int32), kind.astype(np.int32)],
        "body_i": [
            np.arange(n, dtype=np.int32),
            np.concatenate([np.arange(w), f.contact_i]).astype(np.int32),
        ],
        "body_j": [np.full(n, -1, np.int32), np.concatenate([np.full(w, -1), f.contact_j]).astype(np.int32)],
        "normal_force": [zeros_n, np.concatenate([np.zeros(w), f.fn])],
        "tangential_force": [zeros_n, np.concatenate([np.zeros(w), np.abs(f.fs)])],
        "force": [_pad3(f.contact_force), _pad3(force)],
        "force_magnitude": [np.hypot(*f.contact_force.T), np.hypot(*force.T)],
    }
    cells = [("vertex", np.arange(n).reshape(-1, 1)), ("line", lines)]
    blocks = 2 if len(lines) else 1  # no empty block of lines: a cell without walls or contacts
    return meshio.Mesh(
        points,
        cells[:blocks],
        point_data={
            "radius": _on_points(f.radius, len(points)),
            "velocity": _pad3(_on_points(f.velocity, len(points))),
            "angular_velocity": _on_points(f.omega, len(points)),
            "rotation": _on_points(f.theta, len(points)),
            "contact_force": _pad3(_on_points(f.contact_force, len(points))),
        },
        cell_data={name: values[:blocks] for name, values in cell_data.items()},
    )


def _on_points(values: np.ndarray, count: int) -> np.ndarray:
    """``values`` of the disks (the first points), zero at the other ``count - n`` points."""
    out = np.zeros((count, *values.shape[1:]))
    out[: len(values)] = values
    return out


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
