"""A specimen as plain numbers: what every export writes and every import reads.

:class:`SpecimenData` holds the disks (centre, radius, PFC 4.0's per-body density, kn, ks,
friction), the walls with their own, the disk thickness and the run settings another code needs
to continue from the same state. Velocities, spins and contact history are not part of it: an
exported specimen starts at rest with no shear force stored, in any code (docs/export.md).

It is a view in the files' terms, not a second engine record: an importer fills it unchecked,
so that :func:`poro2d.interop.validate.check_imported` can refuse a bad value naming its file and
line (the engine's ``Particles`` and ``Walls`` would refuse it first, in their own words).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from poro2d import __version__
from poro2d.dem import ContactModel, Particles, Simulation, Walls
from poro2d.dem.model import PER_BODY_RULE, ContactValues
from poro2d.dem.state import BOX_WALLS
from poro2d.errors import InputError
from poro2d.interop.origin import origin_lines
from poro2d.io_utils import CHECKPOINT_FILE_LIMIT, check_input_file
from poro2d.json_fields import number_at
from poro2d.specimen.box import box_faces
from poro2d.store import Store


@dataclass(frozen=True)
class ByPairType:
    """A contact's values per pair type: the disk-disk pair's (``disks``) and each wall's, by wall name."""

    disks: ContactValues
    walls: dict[str, ContactValues]


@dataclass
class WallData:
    """One wall segment from (x0, y0) to (x1, y1) with its per-body kn, ks (N/m) and friction."""

    name: str
    x0: float
    y0: float
    x1: float
    y1: float
    kn: float
    ks: float
    mu: float
    mu_r: float = 0.0  # rolling friction

    @property
    def numbers(self) -> tuple[float, ...]:
        """x0, y0, x1, y1, kn, ks, mu: the numbers every target writes of a wall, in this order."""
        return (self.x0, self.y0, self.x1, self.y1, self.kn, self.ks, self.mu)

    @property
    def horizontal(self) -> bool:
        return self.y0 == self.y1 and self.x0 != self.x1

    @property
    def vertical(self) -> bool:
        return self.x0 == self.x1 and self.y0 != self.y1


@dataclass
class SpecimenData:
    """Disks and walls of a specimen, in SI units; arrays have one entry per disk."""

    x: np.ndarray
    y: np.ndarray
    radius: np.ndarray
    density: np.ndarray
    kn: np.ndarray
    ks: np.ndarray
    mu: np.ndarray
    thickness: float
    walls: list[WallData] = field(default_factory=list)
    gravity: tuple[float, float] = (0.0, -9.81)
    local_damping: float = 0.7
    dt: float | None = None
    contact: str = "per_body"
    source: str = ""
    mu_r: np.ndarray | None = None  # rolling friction per disk; None: 0 for every disk
    #: the normal dashpot's coefficient of restitution (``Simulation(restitution=)``); None: no dashpot
    restitution: float | None = None
    #: the criterion's window the specimen was accepted with (F_top below this fraction of G)
    force_fraction: float | None = None
    #: where the specimen came from (grading, laboratory state, mode, mu_prep, n2D, seed, version):
    #: the ``provenance:`` lines of :func:`poro2d.interop.origin.origin_lines`; None: not known
    origin: list[str] | None = None
    #: where each value was read (set by the importers): ``locate(quantity, disk_index)``
    locate: Callable[..., str] | None = field(default=None, repr=False, compare=False)

    @property
    def n(self) -> int:
        return int(self.x.shape[0])

    @property
    def rolled(self) -> bool:
        """True when any disk or wall has rolling friction (a target must carry it or refuse)."""
        return bool(np.any(self.rolling_friction > 0.0)) or any(w.mu_r > 0.0 for w in self.walls)

    @property
    def rolling_friction(self) -> np.ndarray:
        """The disks' rolling friction (0 for every disk when ``mu_r`` is None)."""
        return np.zeros(self.n) if self.mu_r is None else np.asarray(self.mu_r, dtype=float)

    @property
    def dashpot(self) -> bool:
        """True when the contacts have a normal dashpot (a restitution below 1)."""
        return self.restitution is not None and self.restitution < 1.0

    def refuse_dashpot(self, target: str) -> None:
        """Refuse (InputError) a specimen with a normal dashpot for ``target``, which cannot carry it.

        poro2d's dashpot never pulls, and its damping ratio is the one whose rebound is the
        restitution for such a dashpot (:func:`poro2d.dem.model.restitution_to_beta`): the
        viscous terms of LAMMPS, YADE and PFC set their coefficients otherwise, so no target
        but the CSV tables (a ``# poro2d restitution`` line) would give the same contacts.
        """
        if self.dashpot:
            raise InputError(
                "restitution", self.restitution, f"none (no normal dashpot) for {target}",
                f"{target} cannot express poro2d's no-tension dashpot; --to csv carries it",
            )  # fmt: skip

    @property
    def mass(self) -> np.ndarray:
        """Disk masses rho pi r^2 t (kg)."""
        return self.density * math.pi * self.radius**2 * self.thickness

    def wall(self, name: str) -> WallData:
        for w in self.walls:
            if w.name == name:
                return w
        raise InputError("wall", name, f"one of {[w.name for w in self.walls]}")

    def box(self) -> tuple[float, float, float, float]:
        """(xlo, xhi, ylo, yhi): the inner faces of the four box walls.

        Refused (InputError) unless the walls are a poro2d box: a horizontal bottom and
        top, a vertical left and right, the top above the bottom and the right of the left.
        """
        names = [w.name for w in self.walls]
        box = box_faces(names, [(w.x0, w.y0) for w in self.walls])
        b, r, t, lf = (self.wall(k) for k in BOX_WALLS)
        if not (b.horizontal and t.horizontal and r.vertical and lf.vertical):
            raise InputError("walls", names, "a box: horizontal bottom and top, vertical left and right")
        if not (box[1] > box[0] and box[3] > box[2]):
            raise InputError("box", box, "xlo < xhi and ylo < yhi (left of right, bottom below top)")
        return box

    def weight_per_thickness(self) -> float:
        """Self weight of the disks per metre of thickness (N/m): the paper's G."""
        g = math.hypot(*self.gravity)
        return float(np.sum(self.mass)) * g / self.thickness

    def contact_parameters(self) -> ByPairType:
        """The contact-level values of disk-disk contacts and of each wall's, mixed by the engine's
        own description of the law (:meth:`poro2d.dem.model.ContactModel.pair`: PFC 4.0's springs in
        series, the smaller friction and rolling friction).

        Engines that take one set per contact type need every disk alike: refused otherwise,
        naming the property that varies.
        """
        mu_r = self.rolling_friction
        varying = {"kn": self.kn, "ks": self.ks, "mu": self.mu, "density": self.density}
        for name, a in {**varying, "rolling friction": mu_r}.items():
            if self.n and np.ptp(a) != 0.0:
                raise InputError(
                    f"disk {name}", f"from {a.min():g} to {a.max():g}",
                    "one value for every disk (the target takes one set of contact properties)",
                )  # fmt: skip
        law = ContactModel()
        disk = ContactValues(*(float(a[0]) for a in (self.kn, self.ks, self.mu, mu_r)))
        walls = {w.name: law.pair(disk, ContactValues(*w.numbers[4:], w.mu_r), wall=True) for w in self.walls}
        return ByPairType(law.pair(disk, disk), walls)

    def header(self, comment: str) -> list[str]:
        """Lines that every exported file starts with: units, thickness convention, version."""
        lines = [
            f"poro2d {__version__} specimen: {self.n} disks, {len(self.walls)} walls",
            "units: SI (m, kg, s, N); stiffness N/m; friction coefficients",
            f"disk thickness t = {self.thickness!r} m: disk mass rho pi r^2 t, inertia m r^2 / 2",
            f"contact properties per body (PFC 4.0): {PER_BODY_RULE}",
            f"gravity {self.gravity[0]!r} {self.gravity[1]!r} m/s2; local damping {self.local_damping!r}"
            + (f"; time step {self.dt!r} s" if self.dt else ""),
        ]
        if self.source:
            lines.append(f"from {self.source}")
        lines += (
            self.origin
            if self.origin is not None
            else ["provenance: unknown (not read from a specimen's folder)"]
        )
        if self.force_fraction is not None:
            lines.append(
                f"accepted by the criterion with F_top below {self.force_fraction:g} of G (its window)"
            )
        lines += self.porosity_lines()
        return [f"{comment} {ln}" for ln in lines]

    def porosity_lines(self) -> list[str]:
        """The two porosities of the specimen, named so that neither is taken for the other.

        The box porosity is the paper's n' (box W x plate height, the gap under the plate
        included); the interior porosity is the packing's own, 2 d50 clear of every wall and
        of the free surface (:mod:`poro2d.measure.specimen_porosity`). None for a specimen
        without a box or too small to measure.
        """
        from poro2d.measure.specimen_porosity import measure_specimen

        try:
            xlo, xhi, ylo, yhi = self.box()
            pos = np.column_stack([self.x - xlo, self.y - ylo])
            m = measure_specimen(pos, self.radius, xhi - xlo, yhi - ylo)
        except (InputError, RuntimeError):  # no box, too small, or a degenerate tessellation
            return []
        return [
            f"box porosity n' = {m.box_porosity:.4f} (the paper's: box {xhi - xlo:.4g} m x {yhi - ylo:.4g} m "
            f"to the top plate, the gap under the plate included: mean {m.surface_gap_mean_d50:.2f} d50)",
            f"interior porosity = {m.interior_porosity:.4f} +- {m.interior_porosity_std:.4f} "
            f"({m.interior_regions} circles 2 d50 clear of walls and surface): the packing's own; "
            "generate this specimen elsewhere at this porosity (docs/porosity.md)",
        ]

    def to_simulation(self, dt: float | None = None, threads: int = 1) -> Simulation:
        """A poro2d Simulation at this state: disks at rest, no contact history, walls fixed."""
        p = Particles(
            np.column_stack([self.x, self.y]), self.radius, self.density, self.thickness,
            self.kn, self.ks, self.mu, mu_r=self.mu_r,
        )  # fmt: skip
        walls = Walls()
        for w in self.walls:
            walls.add((w.x0, w.y0), (w.x1, w.y1), w.kn, w.ks, w.mu, w.name, mu_r=w.mu_r)
        return Simulation(
            p, walls, ContactModel("per_body"), gravity=self.gravity, local_damping=self.local_damping,
            dt=dt, threads=threads, restitution=self.restitution,
        )  # fmt: skip


def exact(values, sep: str = " ") -> str:
    """Numbers as the exported files write them: ``repr`` of each float, which reads back the same."""
    return sep.join(repr(float(v)) for v in values)


def resolve_specimen(path: str | os.PathLike) -> Path:
    """A checkpoint file, or a folder holding ``specimen.npz`` (a criterion or paper output)."""
    p = Path(path)
    if p.is_dir():
        p = p / "specimen.npz"
    if not p.is_file():
        raise InputError(
            "SPECIMEN", str(path), "a specimen checkpoint (.npz) or a folder holding specimen.npz"
        )
    return check_input_file("SPECIMEN", p, CHECKPOINT_FILE_LIMIT)


def from_simulation(sim: Simulation, source: str = "") -> SpecimenData:
    """The disks and walls of ``sim`` (copies), with its gravity, damping and time step."""
    _check_per_body(sim.contact.convention, "'per_body' (the properties travel with the bodies)")
    p, w = sim.particles, sim.walls
    disks = {f: getattr(p, f) for f in _DISK_FIELDS}
    if p.mu_r.any():
        disks["mu_r"] = p.mu_r
    walls = {f: getattr(w, f) for f in _WALL_FIELDS} | {"mu_r": w.rolling_friction()}
    return _from_records(
        disks, walls, w.names, thickness=p.thickness, gravity=sim.gravity, local_damping=sim.local_damping,
        dt=sim.dt, source=source, restitution=sim.restitution,
    )  # fmt: skip


def from_checkpoint(path: str | os.PathLike) -> SpecimenData:
    """The specimen saved at ``path`` (a checkpoint or a folder holding ``specimen.npz``).

    Read with :meth:`poro2d.store.Store.read_state`, which checks the whole file first: a
    damaged checkpoint is one InputError naming it.
    """
    p = resolve_specimen(path)
    meta, a = Store(p.parent).read_state(p.name)
    s = meta["settings"]
    convention = s["contact"]["convention"]
    _check_per_body(convention, "'per_body' (the PFC 4.0 properties that travel with the bodies)")
    # a checkpoint keys its arrays "particles.<field>" and "walls.<field>" (mu_r only with rolling resistance)
    disks = {k.removeprefix("particles."): v for k, v in a.items() if k.startswith("particles.")}
    walls = {k.removeprefix("walls."): v for k, v in a.items() if k.startswith("walls.")}
    return _from_records(
        disks, walls, list(meta["wall_names"]), thickness=float(meta["thickness"]),
        gravity=tuple(float(g) for g in s["gravity"]), local_damping=float(s["local_damping"]),
        dt=float(s["dt"]), source=str(p), force_fraction=accepted_window(p), origin=origin_lines(p),
        restitution=None if s.get("restitution") is None else float(s["restitution"]),
    )  # fmt: skip


#: the engine's fields a specimen file holds: its disks' (``Particles``) and walls' (``Walls``)
_DISK_FIELDS = ("pos", "radius", "density", "kn", "ks", "mu")
_WALL_FIELDS = ("p0", "p1", "kn", "ks", "mu")


def _check_per_body(convention: str, allowed: str) -> None:
    if convention != "per_body":
        raise InputError("contact convention", convention, allowed)


def _from_records(disks: dict, walls: dict, wall_names: list[str], **settings) -> SpecimenData:
    """The file view of the engine's disk and wall records, copied (the view shares no memory).

    ``disks`` and ``walls`` map the fields of ``Particles`` and ``Walls`` to arrays; ``mu_r``
    may be missing from either (no rolling resistance: None for the disks, 0 for the walls).
    ``settings``: the remaining fields of :class:`SpecimenData`, as they are.
    """
    p0, p1 = walls["p0"], walls["p1"]
    wall_mu_r = walls.get("mu_r", np.zeros(len(wall_names)))
    wall_list = [
        WallData(
            wall_names[k],
            *map(float, (*p0[k], *p1[k], walls["kn"][k], walls["ks"][k], walls["mu"][k], wall_mu_r[k])),
        )
        for k in range(len(wall_names))
    ]
    pos = disks["pos"]
    return SpecimenData(
        x=pos[:, 0].copy(), y=pos[:, 1].copy(), radius=disks["radius"].copy(),
        density=disks["density"].copy(), kn=disks["kn"].copy(), ks=disks["ks"].copy(), mu=disks["mu"].copy(),
        walls=wall_list,
        mu_r=disks["mu_r"].copy() if "mu_r" in disks else None, **settings,
    )  # fmt: skip


def accepted_window(checkpoint_path: Path) -> float | None:
    """The window the specimen was accepted with (its criterion's ``result.json``, beside it, says
    ``settings.force_fraction``: 1 % in the paper, 5 % for ``paper --quick``), None if none says."""
    result = Store(Path(checkpoint_path).parent).read_json("result.json")
    value = number_at(result, "settings", "force_fraction")
    return value if value is not None and 0.0 < value <= 1.0 else None
