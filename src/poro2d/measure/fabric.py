"""The fabric of a packing: how its contacts and their forces are oriented, and how many carry load.

In 2D the contact normals' orientation density is, to second order in a Fourier series,
P(theta) = (1 / 2 pi) [1 + a_c cos 2 (theta - theta_c)] (Rothenburg & Bathurst 1989,
Geotechnique 39(4), 601-614). Its anisotropy follows from the fabric tensor
R = <n (x) n> over the contacts: with eigenvalues l1 >= l2, a_c = 2 (l1 - l2) / (l1 + l2),
theta_c the major eigenvector's direction. The forces add their own anisotropies, read as
in Azema & Radjai's papers from the tensors of the normal force alone,
N = <f_n n (x) n> / <f_n>, and of the whole contact force, X = sym <f (x) n> / <f_n>
(f the force the contact carries, compression positive):

    a_c + a_n = 2 (N1 - N2) / (N1 + N2),    a_c + a_n + a_t = 2 (X1 - X2) / (X1 + X2),

so that the stress-force-fabric relation q / p = (a_c + a_n + a_t) / 2 holds exactly when
every branch vector has the same length (the branch lengths' anisotropy is left out: on this
project's sheared packings the relation holds to a few per cent, tests/measure/test_fabric.py).
Only disk-disk contacts enter the orientations: a flat wall's normals are fixed by the box,
not by the packing.

The mechanical coordination Z_m counts force-carrying contacts (f_n > 0) per disk after the
rattlers are removed: disks with fewer than two such contacts, left out repeatedly until
none remains (a disk losing a neighbour may become one). A disk-wall contact counts once,
for the disk, as a force-carrying contact, as :func:`poro2d.measure.coordination_number`
counts it: a disk held between a wall and one neighbour carries load and is no rattler. In
the periodic cell there are no walls, and the number is the usual one of rattler-free disks.

Everything here reads arrays: the walled engine's :class:`~poro2d.dem.contacts.ContactSet`
(:func:`measure_fabric`) or the periodic cell's contact arrays (:func:`cell_fabric`), never the
engine's modules.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from poro2d.measure.coordination import mechanical_coordination
from poro2d.typed_result import TypedResult

#: the file a test keeps its :class:`FabricRoses` in (the rose diagram's data)
ROSE_FILE = "fabric_rose.json"
#: bins of the orientation histogram over [0, 180) degrees (a normal and its opposite are one)
ROSE_BINS = 36


def _principal(tensor: np.ndarray) -> tuple[float, float, float]:
    """Major and minor eigenvalues of a symmetric 2 x 2 tensor and the major axis's angle in
    degrees, in [0, 180)."""
    (a, b), (_, d) = tensor
    centre, radius = 0.5 * (a + d), math.hypot(0.5 * (a - d), b)
    angle = 0.5 * math.degrees(math.atan2(2.0 * b, a - d))
    return centre + radius, centre - radius, angle % 180.0


def _anisotropy(tensor: np.ndarray) -> tuple[float, float]:
    """2 (l1 - l2) / (l1 + l2) and the major direction (degrees); NaN for a null tensor."""
    l1, l2, angle = _principal(tensor)
    return (2.0 * (l1 - l2) / (l1 + l2), angle) if l1 + l2 > 0.0 else (math.nan, math.nan)


def unit_normals(branch: np.ndarray) -> np.ndarray:
    """Branch vectors (k x 2) as unit vectors."""
    b = np.asarray(branch, float).reshape(-1, 2)
    return b / np.hypot(b[:, 0], b[:, 1])[:, None]


def fabric_tensor(normals: np.ndarray) -> np.ndarray:
    """R = <n (x) n> over unit normals (k x 2): trace 1, NaN without contacts."""
    n = np.asarray(normals, float).reshape(-1, 2)
    return n.T @ n / len(n) if len(n) else np.full((2, 2), math.nan)


def contact_anisotropy(normals: np.ndarray) -> tuple[float, float]:
    """a_c and theta_c (degrees, in [0, 180)) of unit normals (k x 2)."""
    return _anisotropy(fabric_tensor(normals)) if len(normals) else (math.nan, math.nan)


def force_tensors(normals: np.ndarray, fn: np.ndarray, fs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """N = <f_n n (x) n> / <f_n> and X = sym <f (x) n> / <f_n>, the force f = f_n n - f_s t with
    t = (-n_y, n_x) (the force a contact carries; the engines' force on disk i is its opposite)."""
    n = np.asarray(normals, float).reshape(-1, 2)
    t = np.column_stack([-n[:, 1], n[:, 0]])
    mean_fn = float(np.mean(fn))
    normal = (n * fn[:, None]).T @ n / (len(n) * mean_fn)
    full = (n * fn[:, None] - t * fs[:, None]).T @ n / (len(n) * mean_fn)
    return normal, 0.5 * (full + full.T)


def orientation_histogram(normals: np.ndarray, bins: int = ROSE_BINS) -> np.ndarray:
    """How many normals fall in each of ``bins`` equal sectors of [0, 180) degrees."""
    n = np.asarray(normals, float).reshape(-1, 2)
    angle = np.degrees(np.arctan2(n[:, 1], n[:, 0])) % 180.0
    return np.histogram(angle, bins=bins, range=(0.0, 180.0))[0]


def fourier_rose(angle_deg: np.ndarray, a_c: float, theta_c_deg: float) -> np.ndarray:
    """The second-order density 1 + a_c cos 2 (theta - theta_c) at ``angle_deg`` (times 1 / 2 pi)."""
    return (1.0 + a_c * np.cos(2.0 * np.radians(np.asarray(angle_deg) - theta_c_deg))) / (2.0 * math.pi)


@dataclass(frozen=True)
class Fabric:
    """The fabric of one state: anisotropies (directions in degrees, in [0, 180), counter-clockwise
    from +x), the mechanical coordination and the rattlers' share of the disks. NaN without
    force-carrying contacts (and in a curve of an earlier poro2d, which did not record them).
    Its fields are the trailing columns of every test's curve (put there by ``with_fields``)."""

    a_c: float = math.nan
    theta_c: float = math.nan
    a_n: float = math.nan
    theta_n: float = math.nan
    a_t: float = math.nan
    theta_t: float = math.nan
    z_mech: float = math.nan
    rattler_fraction: float = math.nan

    @classmethod
    def of(cls, normals, fn, fs, z_mech: float, rattlers: float) -> Fabric:
        """The anisotropies of the disk-disk contacts (unit ``normals``, forces ``fn``, ``fs``), with Z_m."""
        if not len(fn) or not np.sum(fn) > 0.0:
            return cls(z_mech=z_mech, rattler_fraction=rattlers)
        a_c, theta_c = contact_anisotropy(normals)
        normal, full = force_tensors(normals, fn, fs)
        cn, theta_n = _anisotropy(normal)
        cnt, theta_t = _anisotropy(full)
        return cls(a_c, theta_c, cn - a_c, theta_n, cnt - cn, theta_t, z_mech, rattlers)

    def row(self) -> dict[str, float]:
        """The values as a curve's columns (:data:`FABRIC_COLUMNS`)."""
        return {k: float(getattr(self, k)) for k in FABRIC_COLUMNS}


#: a curve's fabric columns, in order: the fields of :class:`Fabric`
FABRIC_COLUMNS = tuple(f.name for f in fields(Fabric))


@dataclass(eq=False)
class Rose(TypedResult):
    """The contact orientations of one record of a curve (``record``: its row, ``at``: the value of
    the curve's axis there) as counts in :data:`ROSE_BINS` sectors of [0, 180) degrees."""

    record: int
    at: float
    contacts: int
    counts: list[int]

    def fit(self) -> tuple[float, float]:
        """a_c and theta_c (degrees) of the histogram's second Fourier harmonic (the bins' centres)."""
        counts = np.asarray(self.counts, float)
        centre = np.radians((np.arange(len(counts)) + 0.5) * 180.0 / len(counts))
        z = np.sum(counts * np.exp(2j * centre)) / counts.sum() if counts.sum() else math.nan
        return 2.0 * abs(z), math.degrees(0.5 * np.angle(z)) % 180.0


@dataclass(eq=False)
class FabricRoses(TypedResult):
    """A test's orientation histograms at its peak and at its end (``fabric_rose.json``), the
    record's position read on ``axis`` (a column of its curve); either None when the run's
    record of it is not at hand (a shear test resumed from a checkpoint recorded after it)."""

    axis: str
    bins: int
    peak: Rose | None
    end: Rose | None

    PARTS = {"peak": Rose, "end": Rose}

    @classmethod
    def of(cls, axis: str, positions, roses: list[np.ndarray], peak: int) -> FabricRoses:
        """The roses of rows ``peak`` and the last of a curve whose positions on ``axis`` are
        ``positions``; ``roses``: the histograms of its last ``len(roses)`` rows."""
        first = len(positions) - len(roses)

        def rose(k: int) -> Rose | None:
            if k < first:
                return None
            counts = [int(c) for c in roses[k - first]]
            return Rose(record=k, at=float(positions[k]), contacts=sum(counts), counts=counts)

        return cls(axis=axis, bins=ROSE_BINS, peak=rose(peak), end=rose(len(positions) - 1))


def measure_fabric(contacts, disks: int) -> Fabric:
    """The fabric of a walled simulation's contacts (a :class:`~poro2d.dem.contacts.ContactSet`,
    ``Simulation.contacts()``) among ``disks`` disks; only force-carrying contacts count."""
    c = contacts
    on = c.fn > 0.0
    pp = on & (c.kind == 0)
    z, rattlers = mechanical_coordination(disks, c.i[pp], c.j[pp], c.i[on & (c.kind == 1)])
    return Fabric.of(unit_normals(c.branch[pp]), c.fn[pp], c.fs[pp], z, rattlers)


def rose(contacts) -> np.ndarray:
    """The orientation histogram of a walled simulation's force-carrying disk-disk contacts."""
    c = contacts
    pp = (c.fn > 0.0) & (c.kind == 0)
    return orientation_histogram(unit_normals(c.branch[pp]))


def cell_rose(contacts: dict) -> np.ndarray:
    """The orientation histogram of the periodic cell's force-carrying contacts."""
    return orientation_histogram(cell_normals(contacts)[contacts["fn"] > 0.0])


def cell_normals(contacts: dict) -> np.ndarray:
    """The unit normals of the periodic cell's contact arrays (``PeriodicCell.contacts()``)."""
    return unit_normals(np.column_stack([contacts["lx"], contacts["ly"]]))


def cell_fabric(contacts: dict, disks: int) -> Fabric:
    """The fabric of the periodic cell's contact arrays (``PeriodicCell.contacts()``: touching
    pairs, no walls) among ``disks`` disks."""
    on = contacts["fn"] > 0.0
    z, rattlers = mechanical_coordination(disks, contacts["i"][on], contacts["j"][on], np.zeros(0, np.int64))
    return Fabric.of(cell_normals(contacts)[on], contacts["fn"][on], contacts["fs"][on], z, rattlers)


__all__ = [
    "FABRIC_COLUMNS",
    "ROSE_BINS",
    "ROSE_FILE",
    "Fabric",
    "FabricRoses",
    "Rose",
    "cell_fabric",
    "cell_normals",
    "cell_rose",
    "contact_anisotropy",
    "fabric_tensor",
    "force_tensors",
    "fourier_rose",
    "measure_fabric",
    "rose",
    "orientation_histogram",
    "unit_normals",
]
